"""The compiled `winkler` model against the independent scipy reference (tests/physics/winkler_reference.py,
DOP853 at rtol 1e-10 with events at every contact change) on real processed records, both beds, at
moderate scales where the block rocks but does not overturn (away from the chaotic threshold).

Requirement (issue 10): peak angle within 0.5%. The contact outputs (uplift, corner uplift, flights,
airborne time) are compared too.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from rockfrag.models import simulate

from .motions import BLOCK, TAIL, case_motion
from .winkler_reference import reference_winkler

# every case's reference is computed once (``both`` caches it) when one worker runs the module: split over two
# workers, each computed the cases both need (30 s of CPU instead of 22 s)
pytestmark = pytest.mark.xdist_group("winkler-vs-reference")


def stiffness(omega_over_p):
    return BLOCK.mass * (omega_over_p * BLOCK.p()) ** 2


@lru_cache(maxsize=None)
def both(record_id, bed, omega_over_p, scale):
    """(reference dict, product RockingResult) for one case, xi = 0.05."""
    ag, dt = case_motion(record_id, scale)
    t_end = (ag.size - 1) * dt + TAIL
    K = stiffness(omega_over_p)
    reference = reference_winkler(ag, dt, BLOCK.b, BLOCK.h, BLOCK.mass, K, 0.05, bed, t_end=t_end)
    product = simulate("winkler", ag, dt, BLOCK, k=K, xi=0.05, bed=bed, t_end=t_end)
    return reference, product


GROUNDED = [  # the block rocks, never leaves the ground entirely
    ("DUZCE/BOL090", "continuous", 30, 1.5),
    ("DUZCE/BOL090", "continuous", 100, 3.0),
    ("DUZCE/BOL090", "two-spring", 30, 3.0),
    ("LOMAP/CAP000", "two-spring", 30, 1.5),
    ("LOMAP/CAP000", "continuous", 30, 3.0),
]
FLYING = [  # the block leaves the ground: once, and ~120 times (stiff two-spring bed bouncing)
    ("LOMAP/CAP000", "two-spring", 30, 3.0),
    ("DUZCE/BOL090", "two-spring", 100, 3.0),
]


@pytest.mark.slow
@pytest.mark.parametrize("record_id, bed, omega_over_p, scale", GROUNDED + FLYING)
def test_peak_angle_matches_reference(record_id, bed, omega_over_p, scale):
    reference, product = both(record_id, bed, omega_over_p, scale)
    assert reference["peak_angle"] > 0.2 * BLOCK.alpha, "too close to the uplift threshold to mean anything"
    assert not reference["overturned"] and not product.overturned
    assert product.peak_angle == pytest.approx(reference["peak_angle"], rel=5e-3)  # requirement: 0.5 %
    achieved = 1e-4 if reference["n_flights"] == 0 else 2e-3  # what the kernel reaches (rtol 1e-6)
    assert product.peak_angle == pytest.approx(reference["peak_angle"], rel=achieved)


@pytest.mark.slow
@pytest.mark.parametrize("record_id, bed, omega_over_p, scale", GROUNDED)
def test_histories_and_contact_outputs_match_reference(record_id, bed, omega_over_p, scale):
    reference, product = both(record_id, bed, omega_over_p, scale)
    assert reference["n_flights"] == 0 and product.n_flights == 0 and product.airborne_time == 0.0
    assert product.uplifted and reference["uplifted"]
    assert product.peak_uplift == pytest.approx(reference["peak_uplift"], rel=1e-3)
    # whole histories, free rocking tail included (measured: 1e-6 continuous, 2.4e-3 two-spring at BOL090 x3)
    np.testing.assert_allclose(product.theta, reference["theta"], atol=5e-3 * reference["peak_angle"])
    y_scale = np.max(np.abs(reference["y"]))
    np.testing.assert_allclose(product.y, reference["y"], atol=1e-2 * y_scale)


@pytest.mark.slow
@pytest.mark.parametrize("record_id, bed, omega_over_p, scale", GROUNDED)
def test_time_of_uplift_matches_reference(record_id, bed, omega_over_p, scale):
    reference, product = both(record_id, bed, omega_over_p, scale)
    assert product.time_of_uplift == pytest.approx(reference["time_of_uplift"], abs=1e-4)


GRAZING_FLIGHT = pytest.mark.xfail(strict=True, reason=(
    "precision at the default tolerance (rtol 1e-6): one short grazing flight (CAP000 x3.0, two-spring, "
    "omega/p = 30) lasts 7.987 ms vs 8.380 ms in the reference (-4.7%); it converges with the tolerance "
    "(8.374 ms at rtol 1e-8, 8.380 ms at 1e-10; test below). Before kernel fedbacf it was 7.16 ms."))


@pytest.mark.slow
@pytest.mark.parametrize("record_id, bed, omega_over_p, scale", [
    pytest.param(*FLYING[0], marks=GRAZING_FLIGHT), FLYING[1]])
def test_flight_outputs_match_reference(record_id, bed, omega_over_p, scale):
    """Flights and airborne time to 0.5% (122 flights on BOL090 x3.0: 3.1905 s vs 3.1910 s)."""
    reference, product = both(record_id, bed, omega_over_p, scale)
    assert reference["n_flights"] >= 1
    assert abs(product.n_flights - reference["n_flights"]) <= max(1, 0.01 * reference["n_flights"])
    assert product.airborne_time == pytest.approx(reference["airborne_time"], rel=5e-3)


@pytest.mark.slow
def test_short_flight_converges_with_the_tolerance():
    reference, _ = both(*FLYING[0])
    ag, dt = case_motion(FLYING[0][0], FLYING[0][3])
    product = simulate("winkler", ag, dt, BLOCK, k=stiffness(FLYING[0][2]), xi=0.05, bed=FLYING[0][1],
                       t_end=(ag.size - 1) * dt + TAIL, rtol=1e-8, atol=1e-9)
    assert product.n_flights == reference["n_flights"] == 1
    assert product.airborne_time == pytest.approx(reference["airborne_time"], rel=5e-3)
    assert product.peak_angle == pytest.approx(reference["peak_angle"], rel=1e-5)
