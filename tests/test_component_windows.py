"""Components of one record that cover different windows: a harmless cut to the window they share is stated, a
cut that would change the record (its PGA, its strong motion) is an error naming the file and the channels
(issue 33: a vertical holding only its first 10 s cut the horizontals to pre-event noise without a word)."""

from __future__ import annotations

import numpy as np
import pytest

from rockfrag.errors import RecordError
from rockfrag.records import group_components, load_records
from rockfrag.records.components import KEPT_ARIAS
from rockfrag.study import pair_verticals
from rockfrag.units import STANDARD_GRAVITY


@pytest.fixture(scope="module")
def clc():
    """CI.CLC's three CSMIP components (32080, 31932 and 32190 samples from one start)."""
    records, failures = load_records("ridgecrest-2019")
    assert not failures
    return [record for record in records if record.station == "CI.CLC"]


def _with_short_vertical(records, seconds=10.0):
    """The records with the vertical cut to its first ``seconds`` (pre-event noise), as a damaged file holds it."""
    short = []
    for record in records:
        if record.is_vertical:
            trace = record.trace.copy()
            trace.data = trace.data[:int(seconds / record.dt) + 1]
            record = record.with_trace(trace)
        short.append(record)
    return short


def test_a_harmless_cut_is_made_and_stated_in_the_provenance(clc):
    [group] = group_components(clc)
    aligned = group.aligned()
    assert {record.trace.stats.npts for record in aligned.values()} == {31932}
    for label, record in aligned.items():
        line = record.trace.stats.processing[-1]
        removed = group.components[label].trace.stats.npts - 31932
        assert "cut_to_shared_window(start=" in line and f"samples_removed={removed}," in line, line
        peak = np.max(np.abs(group.components[label].acceleration)) / STANDARD_GRAVITY
        assert f"pga_g={peak:.4g}->{peak:.4g}" in line  # the peak is inside the shared window
        assert float(line.split("arias_kept=")[1].rstrip(")")) >= KEPT_ARIAS


def test_components_of_equal_windows_are_left_as_they_are():
    records, _ = load_records("south-napa-2014")
    [group] = group_components(records)
    for label, record in group.aligned().items():
        assert not any("cut_to_shared_window" in line for line in record.trace.stats.get("processing", []))
        np.testing.assert_array_equal(record.acceleration, group.components[label].acceleration)


def test_a_cut_that_changes_the_record_is_an_error_naming_file_and_channels(clc):
    [group] = group_components(_with_short_vertical(clc))
    with pytest.raises(RecordError) as caught:
        group.aligned()
    message = str(caught.value)
    assert message.startswith(str(clc[0].metadata["file"]))
    assert "components of CI.CLC differ in length" in message and "cut to the 10 s they share" in message
    for record in clc:
        if not record.is_vertical:  # each horizontal named with its channel and what the cut does to its PGA
            label = next(k for k, v in group.components.items() if v.id == record.id)
            peak = np.max(np.abs(record.acceleration)) / STANDARD_GRAVITY
            assert f"{label} ({record.metadata['channel_code']})'s PGA {peak:.3g} g -> " in message


def test_a_cut_asked_for_is_made_and_states_its_effect_on_pga(clc):
    [group] = group_components(_with_short_vertical(clc))
    aligned = group.aligned(cut=True)
    line = aligned["H1"].trace.stats.processing[-1]
    before = np.max(np.abs(group.h1.acceleration)) / STANDARD_GRAVITY
    after = np.max(np.abs(aligned["H1"].acceleration)) / STANDARD_GRAVITY
    assert after < 0.1 * before and f"pga_g={before:.4g}->{after:.4g}" in line


def test_a_vertical_study_skips_such_a_record_with_the_reason(clc):
    """The study's pairing (``[study] vertical = true``) skips the horizontals with the error: nothing runs on noise."""
    pairs, failures = pair_verticals(_with_short_vertical(clc))
    assert pairs == [] and len(failures) == 2
    assert all("differ in length" in failure.reason and "PGA" in failure.reason for failure in failures)
