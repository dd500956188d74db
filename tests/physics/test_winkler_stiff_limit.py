"""Stiff limit of the `winkler` model: as K grows the block rocks like a rigid block on a rigid base, and
the energy lost per impact comes out of the bed's damping (an effective restitution, not an input).

Effective restitution: a rigid block that peaks at theta_k hits the ground with theta'^2 proportional
to cos(alpha - theta_k) - cos(alpha), so successive peaks give r_k = sqrt(drop_{k+1} / drop_k), the
quantity Housner's r = 1 - 1.5 sin^2(alpha) predicts. Numbers for all beds, xi and alpha:
benchmarks/winkler_restitution.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockfrag.blocks import Block
from rockfrag.models import simulate

from .winkler_reference import effective_restitution, rocking_peaks

G = 9.80665


def stiffness(block, omega_over_p):
    return block.mass * (omega_over_p * block.p()) ** 2


def launch_rate(block, fraction):
    """theta'(0) [rad/s] that takes a rigid block on a rigid base to fraction * alpha."""
    inertia_corner = 4 / 3 * block.mass * block.R**2
    drop = math.cos(block.alpha * (1 - fraction)) - math.cos(block.alpha)
    return math.sqrt(2 * block.mass * G * block.R * drop / inertia_corner)


def measured_restitution(block, omega_over_p, xi, bed, impacts=4):
    """Median effective restitution of the first impacts of free rocking launched to 0.6 alpha."""
    result = simulate("winkler", np.zeros(2), 1e-3, block, k=stiffness(block, omega_over_p), xi=xi, bed=bed,
                      thetadot0=-launch_rate(block, 0.6), t_end=6.0)
    peaks = rocking_peaks(result.theta)
    peaks = peaks[peaks > 0.1 * block.alpha]
    return float(np.median(effective_restitution(peaks, block.alpha)[:impacts])), result


def test_restitution_measure_recovers_housner_r_on_the_rigid_model():
    """The measuring stick: on Housner's own model it returns r = 1 - 1.5 sin^2(alpha)."""
    block = Block(name="rigid", R=2.0, alpha=0.25, mass=5000.0)
    result = simulate("housner", np.zeros(2), 1e-3, block, theta0=0.6 * block.alpha, t_end=6.0)
    peaks = rocking_peaks(result.theta)
    r = effective_restitution(peaks[peaks > 0.1 * block.alpha], block.alpha)
    np.testing.assert_allclose(r[:4], block.housner_restitution(), rtol=2e-4)


@pytest.mark.parametrize("alpha", [0.15, 0.25, 0.4])
def test_two_spring_restitution_tends_to_housner(alpha):
    """Two-spring bed, xi = 0.3: the effective r approaches Housner's r as omega/p goes 100 -> 1000."""
    block = Block(name="stiff", R=2.0, alpha=alpha, mass=5000.0)
    housner = block.housner_restitution()
    soft, _ = measured_restitution(block, 100, 0.3, "two-spring")
    stiff, _ = measured_restitution(block, 1000, 0.3, "two-spring")
    assert abs(stiff - housner) < 3e-3
    assert abs(stiff - housner) < abs(soft - housner)


def test_two_spring_without_damping_bounces():
    """xi = 0 dissipates nothing in the bed: the block bounces off the ground (flights) at every impact."""
    block = Block(name="stiff", R=2.0, alpha=0.25, mass=5000.0)
    _, result = measured_restitution(block, 1000, 0.0, "two-spring")
    assert result.n_flights >= 10 and result.airborne_time > 0.0


@pytest.mark.parametrize("xi", [0.1, 0.2, 0.3, 0.5])
def test_continuous_bed_impacts_lose_much_less_energy_than_housner(xi):
    """Continuous bed, stiff (omega/p = 1000): the heel lands on a spread bed and the contact rolls over,
    so impacts keep far more energy than Housner's r at any xi tried (a finding, see the module doc)."""
    block = Block(name="stiff", R=2.0, alpha=0.25, mass=5000.0)
    r, _ = measured_restitution(block, 1000, xi, "continuous")
    assert r > block.housner_restitution() + 0.03


def sine_pulse(amplitude, period, cycles, dt=1e-3):
    t = np.arange(0.0, cycles * period + dt / 2, dt)
    return amplitude * np.sin(2 * np.pi * t / period)


@pytest.mark.parametrize("amplitude, period, cycles", [(2.0, 0.5, 1), (5.0, 0.5, 1), (1.5, 1.0, 2), (3.0, 0.4, 3)])
def test_two_spring_peak_angles_approach_housner_under_pulses(amplitude, period, cycles):
    """At xi = 0.3 (whose effective r tends to Housner's, test above) the peak angle under sine pulses
    (amplitude in units of g tan(alpha); the peak comes after 1 to 5 impacts) tends to Housner's as K grows:
    within 1% at omega/p = 3000, and closer than at omega/p = 100 (the residual is the base-centre tie, see
    the spec)."""
    block = Block(name="pulse", R=2.0, alpha=0.25, mass=5000.0)
    ag = sine_pulse(amplitude * block.uplift_acceleration(), period, cycles)
    housner = simulate("housner", ag, 1e-3, block, t_end=6.0)
    assert not housner.overturned and housner.peak_angle > 0.1 * block.alpha
    assert np.any(housner.impact_times < housner.time_of_peak), "the peak must follow an impact"
    errors = []
    for omega_over_p in (100, 3000):
        winkler = simulate("winkler", ag, 1e-3, block, k=stiffness(block, omega_over_p), xi=0.3, bed="two-spring",
                           t_end=6.0)
        errors.append(abs(winkler.peak_angle / housner.peak_angle - 1))
    assert errors[1] < 0.01
    assert errors[1] <= errors[0]
