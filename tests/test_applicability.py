"""Applicability sweep: SSI tends to Housner on stiff soil and departs on soft soil."""

from __future__ import annotations

import numpy as np
import pytest

from rockfrag.applicability import run_applicability, threshold_modulus
from rockfrag.blocks import PAPER_BLOCK
from rockfrag.processing import process_record
from rockfrag.records import load_records


def test_threshold_interpolates_the_last_crossing():
    moduli = np.array([1e7, 1e8, 1e9, 1e10])
    assert threshold_modulus(moduli, [1.5, 1.3, 1.05, 1.0], 0.10) == pytest.approx(
        np.exp(np.log(1e8) + (0.3 - 0.1) / (0.3 - 0.05) * np.log(10)))
    assert threshold_modulus(moduli, [1.0, 1.0, 1.0, 1.0], 0.10) == 1e7
    assert np.isnan(threshold_modulus(moduli, [1.5, 1.3, 1.2, 1.2], 0.10))
    # a ratio that leaves the band again at a stiffer modulus moves the threshold up
    assert threshold_modulus(moduli, [1.0, 1.3, 1.0, 1.0], 0.10) > 1e8


@pytest.mark.slow
def test_stiff_soil_recovers_housner_and_soft_soil_does_not():
    records, _ = load_records("bolu")
    processed = [process_record(r) for r in records]
    dataset = run_applicability(processed, [PAPER_BLOCK], shear_moduli=[10e6, 100e9], block_moduli=(210e9,),
                                level_factors=(2.5,), workers=1, progress=False)
    ratio = dataset.peak_angle_ratio_to_housner.sel(model="ssi").isel(block=0, block_modulus=0, level=0).values
    correlation = dataset.history_correlation.sel(model="ssi").isel(block=0, block_modulus=0, level=0).values
    assert ratio[1] == pytest.approx(1.0, abs=0.05)
    assert correlation[1] > 0.95
    assert ratio[0] > 1.1 and correlation[0] < correlation[1]
    assert dataset.threshold_shear_modulus.attrs["units"] == "Pa"
