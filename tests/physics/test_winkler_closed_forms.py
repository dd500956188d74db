"""The `winkler` model against closed forms: statics, full-contact tilting frequency (with the
inverted-pendulum term), quasi-static uplift onset (kern b/3 for the continuous bed, b for two
springs) and energy conservation through contact opening, closing and flight with xi = 0.

Each check runs on the product (``simulate("winkler", ...)``) and on the independent scipy
reference (tests/physics/winkler_reference.py), so the reference is itself verified.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockfrag.blocks import Block

from .winkler_reference import bed_force, energy, solve

G = 9.80665
BLOCK = Block(name="closed-form", b=0.5, h=1.5, mass=1000.0)
SOLVERS = ["product", "reference"]
ROTATIONAL_FACTOR = {"continuous": 1 / 3, "two-spring": 1.0}  # K_r = factor * K b^2


def stiffness(omega_over_p, block=BLOCK):
    """Total bed stiffness K [N/m] whose vertical frequency is omega_over_p * p."""
    return block.mass * (omega_over_p * block.p()) ** 2


def zero_crossings(t, x):
    """Times [s] where x changes sign, linearly interpolated between samples."""
    i = np.flatnonzero(np.sign(x[:-1]) * np.sign(x[1:]) < 0)
    return t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])


@pytest.mark.parametrize("bed", ["continuous", "two-spring"])
def test_statics_no_motion_from_the_settled_start(bed):
    """ag = 0: the block stays at theta = 0, y = m g / K with uniform pressure (F = m g, M = 0)."""
    K = stiffness(30)
    response = solve("product", np.zeros(2001), 0.005, BLOCK.b, BLOCK.h, BLOCK.mass, K, 0.05, bed, t_end=10.0)
    y_static = BLOCK.mass * G / K
    assert np.max(np.abs(response["theta"])) <= 1e-12 * BLOCK.alpha
    np.testing.assert_allclose(response["y"], y_static, rtol=1e-10)
    assert not response["uplifted"] and response["n_flights"] == 0 and response["peak_uplift"] == 0.0
    force, moment = bed_force(0.0, 0.0, response["y"][-1], response["y_dot"][-1], BLOCK.b, K, 0.0, bed)
    assert force == pytest.approx(BLOCK.mass * G, rel=1e-10) and moment == 0.0
    assert response["min_support_force"] == pytest.approx(BLOCK.mass * G, rel=1e-9)


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("bed", ["continuous", "two-spring"])
def test_full_contact_tilting_frequency(solver, bed):
    """omega_theta^2 = (K_r - m g h) / J, J = m (b^2 + 4 h^2) / 3, from the period of small free
    tilting that never opens the contact (xi = 0)."""
    K = stiffness(30)
    J = BLOCK.mass * (BLOCK.b**2 + 4 * BLOCK.h**2) / 3
    rotational = ROTATIONAL_FACTOR[bed] * K * BLOCK.b**2
    expected = math.sqrt((rotational - BLOCK.mass * G * BLOCK.h) / J)
    without_pendulum = math.sqrt(rotational / J)
    amplitude = 0.2 * BLOCK.mass * G / (K * BLOCK.b)  # a fifth of the tilt that opens the contact
    response = solve(solver, np.zeros(2), 1e-3, BLOCK.b, BLOCK.h, BLOCK.mass, K, 0.0, bed, t_end=3.0,
                     thetadot0=amplitude * expected)
    assert not response["uplifted"]
    crossings = zero_crossings(response["t"], response["theta"])
    measured = math.pi / np.mean(np.diff(crossings))
    assert measured == pytest.approx(expected, rel=1e-4)
    assert abs(without_pendulum / expected - 1) > 20 * 1e-4  # the check can see the m g h term


def quasi_static_uplift_acceleration(bed, K, block=BLOCK):
    """Ground acceleration [m/s^2] at which the heel lifts under a slowly applied ag > 0.

    Equilibrium (theta' = theta'' = y'' = 0): F = m g, M = g h tan(theta) - h ag (per unit mass), in full
    contact y = m g / K and M = K_r sin(theta) / m. The +b corner lifts at sin(theta_u) = -m g / (K b),
    the kern (M/F = -b/3) for the continuous bed and M/F = -b for two springs."""
    sin_u = -block.mass * G / (K * block.b)
    return G * math.tan(math.asin(sin_u)) - ROTATIONAL_FACTOR[bed] * K * block.b**2 * sin_u / (block.mass * block.h)


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("bed, eccentricity", [("continuous", 1 / 3), ("two-spring", 1.0)])
def test_static_uplift_onset_under_slowly_applied_acceleration(solver, bed, eccentricity):
    """A smooth 20 s ramp of ag to 1.5 times the closed-form onset: the heel lifts at the closed-form
    acceleration (tilt included), where the eccentricity M/F is b/3 (continuous) or b (two-spring)."""
    K = stiffness(30)
    onset = quasi_static_uplift_acceleration(bed, K)
    assert abs(onset / (eccentricity * G * math.tan(BLOCK.alpha)) - 1) > 0.01  # the tilt term matters here
    duration, dt = 20.0, 0.01
    t = np.arange(0.0, duration + dt / 2, dt)
    ag = 1.5 * onset * 0.5 * (1 - np.cos(np.pi * t / duration))  # starts with zero slope: no transient
    response = solve(solver, ag, dt, BLOCK.b, BLOCK.h, BLOCK.mass, K, 0.0, bed, t_end=duration)
    assert response["uplifted"] and 0 < response["time_of_uplift"] < duration
    assert np.interp(response["time_of_uplift"], t, ag) == pytest.approx(onset, rel=1e-3)
    # eccentricity from the state just before the onset, with the spec's law (independent of the product)
    before = np.searchsorted(response["t"], response["time_of_uplift"]) - 1
    force, moment = bed_force(response["theta"][before], response["theta_dot"][before], response["y"][before],
                              response["y_dot"][before], BLOCK.b, K, 0.0, bed)
    assert -moment / force == pytest.approx(eccentricity * BLOCK.b, rel=2e-2)  # the last sample before onset
    assert force == pytest.approx(BLOCK.mass * G, rel=1e-3)


def rigid_launch_rate(fraction, block=BLOCK):
    """theta'(0) [rad/s] that would take a rigid block on a rigid base to fraction * alpha."""
    inertia_corner = 4 / 3 * block.mass * block.R**2
    return math.sqrt(2 * block.mass * G * block.R * (math.cos(block.alpha * (1 - fraction)) - math.cos(block.alpha))
                     / inertia_corner)


@pytest.mark.slow
@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("bed, omega_over_p", [("continuous", 30), ("continuous", 300), ("two-spring", 30),
                                                ("two-spring", 300)])
def test_energy_is_conserved_through_contact_changes(solver, bed, omega_over_p):
    """xi = 0, ag = 0, launched from the settled state: the contact opens and closes (and at the stiff bed
    the block flies), yet E = T + m g (h cos theta - y) + bed energy stays at its initial value."""
    K = stiffness(omega_over_p)
    launch = rigid_launch_rate(0.4)
    response = solve(solver, np.zeros(2), 1e-3, BLOCK.b, BLOCK.h, BLOCK.mass, K, 0.0, bed, t_end=4.0,
                     thetadot0=launch)
    e = energy(response["theta"], response["theta_dot"], response["y"], response["y_dot"], BLOCK.b, BLOCK.h,
               BLOCK.mass, K, bed)
    initial_kinetic = 0.5 * BLOCK.mass * (BLOCK.b**2 + 4 * BLOCK.h**2) / 3 * launch**2
    assert response["uplifted"] and not response["overturned"]
    assert np.sum(np.diff(np.sign(response["theta"])) != 0) >= 3, "too few contact changes to test"
    drift = np.max(np.abs(e - e[0])) / initial_kinetic
    assert drift < (1e-4 if solver == "product" else 1e-7)


@pytest.mark.parametrize("bed", ["continuous", "two-spring"])
def test_friction_demand_of_a_quasi_static_push_is_ag_over_g(bed):
    """Below uplift a slowly pushed block barely moves, so the base must hold H = m ag against N = m g:
    peak_friction_demand = max(ag) / g (tilt and inertia corrections are below 1e-3 here)."""
    K = stiffness(30)
    peak = 0.9 * quasi_static_uplift_acceleration(bed, K)
    duration, dt = 20.0, 0.01
    t = np.arange(0.0, duration + dt / 2, dt)
    ag = peak * 0.5 * (1 - np.cos(np.pi * t / duration))
    response = solve("product", ag, dt, BLOCK.b, BLOCK.h, BLOCK.mass, K, 0.05, bed, t_end=duration)
    assert not response["uplifted"]
    assert response["result"].peak_friction_demand == pytest.approx(peak / G, rel=1e-3)
