"""The compiled kernels against an independent scipy solve_ivp reference (DOP853, rtol 1e-10)
on real processed records, away from the chaotic uplift threshold."""

from __future__ import annotations

import numpy as np
import pytest

from rockfrag.blocks import Block
from rockfrag.models import simulate
from rockfrag.processing import process_record
from rockfrag.records import load_records

from .reference import reference_response

BLOCK = Block(name="reference", R=2.0, alpha=0.25, mass=5000.0)

pytestmark = pytest.mark.filterwarnings("ignore:.*foundation spring in tension")


@pytest.fixture(scope="module")
def ground_motions():
    records, _ = load_records(["DUZCE/BOL090", "LOMAP/CAP000"])
    motions = {}
    for record in records:
        processed = process_record(record)
        motions[record.id] = (processed.acceleration[:3000], processed.dt)  # first 30 s
    return motions


CASES = [
    ("housner", "DUZCE/BOL090", 0.7, None),
    ("housner", "DUZCE/BOL090", 1.0, None),
    ("housner", "LOMAP/CAP000", 2.0, None),
    ("ssi", "DUZCE/BOL090", 0.7, 30.0),
    ("ssi", "DUZCE/BOL090", 1.0, 30.0),
]


@pytest.mark.slow
@pytest.mark.parametrize("model, record_id, scale, omega_over_p", CASES)
def test_peak_angle_and_impacts_match_reference(ground_motions, model, record_id, scale, omega_over_p):
    ag, dt = ground_motions[record_id]
    ag = ag * scale
    k = BLOCK.mass * (omega_over_p * BLOCK.p()) ** 2 if omega_over_p else None
    t_end = (ag.size - 1) * dt + 5.0
    ref_peak, ref_impacts, ref_overturned = reference_response(model, ag, dt, BLOCK, k=k, xi=0.05, t_end=t_end)
    result = simulate(model, ag, dt, BLOCK, k=k, xi=0.05, t_end=t_end)
    assert ref_peak > 0.05 * BLOCK.alpha, "case too close to the uplift threshold to be meaningful"
    assert result.overturned == ref_overturned
    assert result.peak_angle == pytest.approx(ref_peak, rel=5e-3)  # requirement: 0.5 %
    assert result.peak_angle == pytest.approx(ref_peak, rel=1e-5)  # what the kernel actually achieves
    n = min(10, ref_impacts.size)
    np.testing.assert_allclose(result.impact_times[:n], ref_impacts[:n], atol=1e-6)
