"""A printed bound is still a bound (second cold read, default report B1: '≥ 20%' for 19.7%, '≥ 95%' for 94.6%).

``report.numbers.bound`` rounds its two significant figures away from the safe side: a lower bound down, an upper
bound up, so the printed number never claims more than the value.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from rockfrag.report.numbers import bound


@pytest.mark.parametrize("value, side, text", [
    (0.197, "≥", "≥ 19%"), (0.946, "≥", "≥ 94%"), (43 / 44, "≥", "≥ 97%"),
    (0.00812, "<", "< 0.82%"), (0.0081, "<", "< 0.81%"), (0.0005, "<", "< 0.1%"), (1.0, "≥", "100%"),
])
def test_the_cold_reads_cases(value, side, text):
    assert bound(value, side) == text


def test_every_printed_bound_holds():
    for value in np.geomspace(0.0011, 0.9999, 2000):
        for side in ("≥", "<"):
            text = bound(value, side)
            printed = float(re.search(r"([\d.]+)%", text).group(1)) / 100
            assert (printed <= value + 1e-12) if side == "≥" else (printed >= value - 1e-12), (value, side)


@pytest.mark.parametrize("value, text", [(0.6, "0.60 g"), (0.606, "0.61 g"), (0.3, "0.30 g"), (0.0995, "0.10 g"),
                                         (2.25, "2.2 g"), (3.0, "3.0 g"), (12.3, "12 g"), (1234.0, "1,200 g")])
def test_a_computed_intensity_prints_both_significant_figures(value, text):
    """Cold read 7: "0.6 g" and "0.3 g" stood beside "0.61 g" and "0.39 g" and read as coarser numbers."""
    from rockfrag.report.numbers import intensity

    assert intensity(value, "g") == text
