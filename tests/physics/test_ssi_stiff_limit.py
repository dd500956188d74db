"""SSI-rocking: static start, uplift threshold, energy conservation, and the rigid limit -> Housner."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from rockfrag.blocks import Block
from rockfrag.models import Outcome, simulate

G = 9.80665
BLOCK = Block(name="test", R=1.0, alpha=0.2, mass=1000.0)
P = BLOCK.p()
THETA0 = 0.5 * BLOCK.alpha

pytestmark = pytest.mark.filterwarnings("ignore:.*foundation spring in tension")


def stiffness(ratio):
    """k [N/m] giving omega = ratio * p."""
    return BLOCK.mass * (ratio * P) ** 2


def second_peak(result):
    window = (result.t > result.impact_times[0]) & (result.t < result.impact_times[1])
    return np.max(np.abs(result.theta[window]))


def free(model, **kwargs):
    return simulate(model, np.zeros(2), 1e-3, BLOCK, theta0=THETA0, t_end=3.0, **kwargs)


@pytest.mark.parametrize("switch, restitution", [("consistent", None), ("continuous", 1.0)])
def test_stiff_foundation_converges_to_housner(switch, restitution):
    """consistent -> Housner with r = 1 - 1.5 sin^2(alpha); continuous -> Housner with r = 1.

    Errors in the second impact time and second excursion shrink at least like p/omega."""
    housner = free("housner", restitution=restitution)
    errors = []
    for ratio in (50, 100, 200, 400):
        ssi = free("ssi", k=stiffness(ratio), xi=0.05, switch=switch)
        errors.append((abs(ssi.impact_times[1] - housner.impact_times[1]),
                       abs(second_peak(ssi) - second_peak(housner))))
    errors = np.array(errors)
    assert np.all(errors[1:] < errors[:-1] / 1.6), errors  # halves (or better) per doubling of omega
    assert errors[-1, 0] < 2e-4 * housner.impact_times[1]
    assert errors[-1, 1] < 2e-3 * THETA0


def test_switch_rules_differ_as_documented():
    """In the stiff limit the consistent rule dissipates like Housner's r; continuous does not."""
    consistent = free("ssi", k=stiffness(400), xi=0.05, switch="consistent")
    continuous = free("ssi", k=stiffness(400), xi=0.05, switch="continuous")
    r = BLOCK.housner_restitution()
    alpha = BLOCK.alpha
    housner_second = alpha - math.acos(math.cos(alpha) + r**2 * (math.cos(alpha - THETA0) - math.cos(alpha)))
    assert second_peak(consistent) == pytest.approx(housner_second, rel=2e-3)
    assert second_peak(continuous) == pytest.approx(THETA0, rel=2e-3)


def total_energy(result, k):
    """T + V of the Lagrangian (paper eq. 9, exact T) along the sampled history [J]."""
    m, radius, alpha = BLOCK.mass, BLOCK.R, BLOCK.alpha
    theta, theta_dot, y, y_dot = result.theta, result.theta_dot, result.y, result.y_dot
    sigma = np.sign(theta)
    angle = sigma * alpha - theta
    kinetic = (0.5 * 4 / 3 * m * radius**2 * theta_dot**2 - m * radius * np.sin(angle) * theta_dot * y_dot
               + 0.5 * m * y_dot**2)
    potential = 0.5 * k * y**2 + m * G * (radius * np.cos(angle) - y)
    return kinetic + potential


def test_energy_is_conserved_without_damping_through_switches():
    k = stiffness(30)
    result = simulate("ssi", np.zeros(2), 1e-3, BLOCK, k=k, xi=0.0, theta0=THETA0, t_end=6.0)
    assert result.n_impacts >= 4
    energy = total_energy(result, k)
    valid = result.theta != 0  # sigma undefined exactly at a switch sample
    assert np.ptp(energy[valid]) < 1e-7 * abs(energy[0])


def test_static_start_and_uplift_threshold():
    k = stiffness(40)
    threshold = G * math.tan(BLOCK.alpha)
    below = simulate("ssi", np.full(300, 0.999 * threshold), 0.01, BLOCK, k=k, xi=0.05)
    assert below.status == Outcome.NO_UPLIFT
    y_static = BLOCK.mass * G / k
    np.testing.assert_allclose(below.y, y_static, rtol=1e-12)  # starts and stays at equilibrium
    above = simulate("ssi", np.full(300, -1.001 * threshold), 0.01, BLOCK, k=k, xi=0.05)
    assert above.uplifted and above.time_of_uplift < 0.011
    assert np.nanmax(above.theta) > 0  # ag < 0 rocks towards theta > 0


def test_soft_foundation_reports_settlement_and_support_force():
    result = free("ssi", k=stiffness(20), xi=0.05)
    assert result.peak_settlement > BLOCK.mass * G / stiffness(20)
    assert math.isfinite(result.min_support_force)


def test_paper_variant_does_not_converge_to_housner():
    """The printed equations (kappa = 3/7) give p^2 = 3g/(7R): a slower rocking period."""
    housner = free("housner", restitution=1.0)
    paper = free("ssi-paper", k=stiffness(400), xi=0.05, switch="continuous")
    ratio = paper.impact_times[0] / housner.impact_times[0]
    assert ratio == pytest.approx(math.sqrt(7 / 4), rel=0.02)


def test_tension_is_warned():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = free("ssi", k=stiffness(30), xi=0.0)
    if result.min_support_force < 0:
        assert any("tension" in str(w.message) for w in caught)
        assert "tension" in result.message
