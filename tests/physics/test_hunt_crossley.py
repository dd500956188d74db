"""The ``hunt-crossley`` contact law (issue 18): the continuous bed's springs with Hunt-Crossley damping,
q(s) = max(0, k delta (1 + c delta')) while delta > 0, c = 2 xi omega / g.

Checked against the formula, not against the kernel's algebra:
* the force and moment equal the pointwise law summed by brute force (and the scipy reference's exact
  two-point Gauss-Legendre integral) at random full, partial, pulling and flight states;
* the law never pulls and its damping never adds energy (pointwise, brute force), and the settled bed
  damps as the Kelvin-Voigt bed of the same xi;
* free rocking loses energy monotonically, and the bed's impulse under shaking is never negative;
* the compiled kernel equals the independent scipy reference (tests/physics/winkler_reference.py) in
  free rocking and on a real record.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockfrag.blocks import Block
from rockfrag.models import SolverOptions, get_model, parameter_record, simulate
from rockfrag.models import bed_continuous as kelvin_voigt
from rockfrag.models import bed_hunt_crossley as law
from rockfrag.models.restitution import launch_rate

from . import winkler_reference as reference
from .motions import BLOCK as RECORD_BLOCK
from .motions import SAMPLES, TAIL, case_motion

G = 9.80665
BED = "hunt-crossley"
BLOCK = Block(name="hunt-crossley", R=2.0, alpha=0.25, mass=5000.0)


def stiffness(block, omega_over_p):
    return block.mass * (omega_over_p * block.p()) ** 2


def quadrature(theta, theta_dot, y, y_dot, b, K, c, points=200_001):
    """F [N], M [N m] and the damping's power [W]: the pointwise law summed on a fine midpoint grid."""
    edges = np.linspace(-b, b, points)
    s = 0.5 * (edges[1:] + edges[:-1])
    ds = edges[1] - edges[0]
    delta = y + s * math.sin(theta)
    rate = y_dot + s * math.cos(theta) * theta_dot
    spring = np.where(delta > 0, K / (2 * b) * delta, 0.0)
    q = np.where(delta > 0, np.maximum(K / (2 * b) * delta * (1 + c * rate), 0.0), 0.0)
    return q.sum() * ds, (q * s).sum() * ds, ((q - spring) * rate).sum() * ds


def random_cases(count, seed=11):
    """(block, K, xi, c, state) at random full, partial, pulling and flight states."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        block = Block(name="q", b=rng.uniform(0.2, 2.0), h=rng.uniform(0.3, 5.0), mass=rng.uniform(1e2, 1e6))
        omega = rng.uniform(10.0, 2000.0)
        xi = float(rng.choice([0.0, rng.uniform(0.0, 0.5), rng.uniform(0.5, 10.0)]))
        y_static = G / omega**2
        state = np.array([rng.uniform(-0.5, 0.5) * rng.choice([1e-3, 1e-2, 1.0]) * block.alpha, rng.normal(0, 0.5),
                          y_static * rng.uniform(-3.0, 3.0), y_static * omega * rng.normal(0, 1.0)])
        yield block, block.mass * omega**2, xi, 2 * xi * omega / G, state


def test_force_is_the_law_integrated():
    model = get_model("winkler")
    loaded = 0
    for block, K, xi, c, x in random_cases(150):
        params, _ = parameter_record(model, block, K, xi, SolverOptions(bed=BED))
        force, moment = law.force(x, params, math.sin(x[0]), math.cos(x[0]))
        want_force, want_moment, _ = quadrature(*x, block.b, K, c)
        exact_force, exact_moment = reference.bed_force(*x, block.b, K, K * c, BED)
        scale = K * (abs(x[2]) + block.b * abs(math.sin(x[0]))) * (1 + c * (abs(x[3]) + block.b * abs(x[1]))) + 1e-300
        assert force * block.mass == pytest.approx(want_force, abs=2e-5 * scale)
        assert moment * block.mass == pytest.approx(want_moment, abs=2e-5 * scale * block.b)
        assert force * block.mass == pytest.approx(exact_force, abs=1e-10 * scale)
        assert moment * block.mass == pytest.approx(exact_moment, abs=1e-10 * scale * block.b)
        loaded += want_force > 0
    assert loaded > 30, "too few loaded states drawn to mean anything"


def test_never_pulls_and_never_adds_energy():
    """Pointwise: the pressure is never negative, and the damping's power int (q - k delta+) delta' ds is
    never negative (where the clip acts it removes the spring, k delta |delta'| >= 0)."""
    clipped = 0
    for block, K, xi, c, x in random_cases(150, seed=5):
        force, _, power = quadrature(*x, block.b, K, c, points=20_001)
        assert force >= 0.0
        scale = K * (abs(x[2]) + block.b * abs(x[0])) * (abs(x[3]) + block.b * abs(x[1])) + 1e-300
        assert power >= -1e-12 * scale
        delta = x[2] + np.array([-block.b, block.b]) * math.sin(x[0])
        rate = x[3] + np.array([-block.b, block.b]) * math.cos(x[0]) * x[1]
        clipped += bool(np.any((delta > 0) & (1 + c * rate < 0)))
    assert clipped > 5, "the clip (a point leaving faster than 1/c) was never exercised"


@pytest.mark.parametrize("xi", [0.05, 0.3, 0.9])
def test_settled_bed_damps_as_the_kelvin_voigt_bed(xi):
    """Level base at any settlement y and rate y': F = K y (1 + c y') = K y + (K y c) y', so at the static
    y = m g / K the damping force is C y' with C = 2 xi sqrt(K m), as for the continuous Kelvin-Voigt bed."""
    K = stiffness(BLOCK, 300)
    model = get_model("winkler")
    hunt, state = parameter_record(model, BLOCK, K, xi, SolverOptions(bed=BED))
    kelvin, _ = parameter_record(model, BLOCK, K, xi, SolverOptions(bed="continuous"))
    omega = math.sqrt(K / BLOCK.mass)
    for rate in (-0.3, -0.01, 0.0, 0.02, 0.5):
        x = np.array([0.0, 0.0, state[2], rate * G / omega / 10])
        if 1 + 2 * xi * omega / G * x[3] <= 0:
            continue
        assert law.force(x, hunt, 0.0, 1.0)[0] == pytest.approx(kelvin_voigt.force(x, kelvin, 0.0, 1.0)[0], rel=1e-12)


def free_rocking(omega_over_p, xi, solver):
    K = stiffness(BLOCK, omega_over_p)
    dt, t_end = 0.01 / BLOCK.p(), 12.0 / BLOCK.p()
    rate = -launch_rate(BLOCK)
    if solver == "reference":
        return reference.reference_winkler(np.zeros(2), dt, BLOCK.b, BLOCK.h, BLOCK.mass, K, xi, BED, t_end=t_end,
                                           thetadot0=rate)
    return simulate("winkler", np.zeros(2), dt, BLOCK, k=K, xi=xi, bed=BED, thetadot0=rate, t_end=t_end)


@pytest.mark.parametrize("omega_over_p, xi", [(100, 1.2), (300, 0.05)])
def test_free_rocking_energy_never_increases(omega_over_p, xi):
    """Kinetic + gravity + spring energy along the kernel's free rocking: never up (beyond the integration
    error, 1e-6 of the launch energy per sample), and down by a tenth of it or more over the first impacts."""
    result = free_rocking(omega_over_p, xi, "product")
    energy = reference.energy(result.theta, result.theta_dot, result.y, result.y_dot, BLOCK.b, BLOCK.h, BLOCK.mass,
                              stiffness(BLOCK, omega_over_p), "continuous")
    launch = energy[0] - reference.energy(0.0, 0.0, result.y[0], 0.0, BLOCK.b, BLOCK.h, BLOCK.mass,
                                          stiffness(BLOCK, omega_over_p), "continuous")
    assert np.max(np.diff(energy)) <= 1e-6 * launch
    assert energy[0] - energy[-1] > 0.1 * launch


def test_the_bed_never_pulls_under_shaking():
    """The bed's impulse over each sample interval, m (g dt - delta(y' + h sin(theta) theta')) from the
    momentum of the centre of mass, is never negative (tests/physics/test_winkler_never_pulls.py)."""
    dt = 0.01
    t = np.arange(0.0, 4.0, dt)
    ag = 2.5 * BLOCK.uplift_acceleration() * np.sin(2 * np.pi * 1.5 * t) * np.sin(np.pi * t / 4.0) ** 2
    for xi in (0.1, 3.0):
        response = simulate("winkler", ag, dt, BLOCK, k=stiffness(BLOCK, 100), xi=xi, bed=BED, t_end=6.0)
        assert response.uplifted and response.min_support_force >= 0.0
        finite = np.isfinite(response.theta)
        falling = response.y_dot[finite] + BLOCK.h * np.sin(response.theta[finite]) * response.theta_dot[finite]
        impulses = BLOCK.mass * (G * dt - np.diff(falling))
        assert impulses.min() >= -1e-4 * BLOCK.mass * G * dt


@pytest.mark.parametrize("omega_over_p, xi", [(100, 1.2), (300, 0.05)])
def test_free_rocking_matches_reference(omega_over_p, xi):
    product = free_rocking(omega_over_p, xi, "product")
    exact = free_rocking(omega_over_p, xi, "reference")
    assert product.peak_angle == pytest.approx(exact["peak_angle"], rel=1e-4)
    np.testing.assert_allclose(product.theta, exact["theta"], atol=5e-3 * exact["peak_angle"])
    peaks = [reference.rocking_peaks(theta) for theta in (product.theta, exact["theta"])]
    peaks = [p[p > 0.1 * BLOCK.alpha] for p in peaks]
    assert len(peaks[0]) == len(peaks[1]) >= 3
    np.testing.assert_allclose(reference.effective_restitution(peaks[0], BLOCK.alpha),
                               reference.effective_restitution(peaks[1], BLOCK.alpha), atol=1e-4)


@pytest.mark.slow
@pytest.mark.parametrize("record_id, omega_over_p, scale, xi", [("DUZCE/BOL090", 100, 3.0, 1.0),
                                                                 ("LOMAP/CAP000", 30, 3.0, 1.5)])
def test_record_matches_reference(record_id, omega_over_p, scale, xi):
    """A real processed record (tests/physics/test_winkler_vs_reference.py's cases): peak angle to 1e-4
    (requirement 0.5%), histories, uplift time and corner uplift."""
    ag, dt = case_motion(record_id, scale)
    assert ag.size == SAMPLES
    t_end = (ag.size - 1) * dt + TAIL
    block = RECORD_BLOCK
    K = stiffness(block, omega_over_p)
    exact = reference.reference_winkler(ag, dt, block.b, block.h, block.mass, K, xi, BED, t_end=t_end)
    product = simulate("winkler", ag, dt, block, k=K, xi=xi, bed=BED, t_end=t_end)
    assert exact["peak_angle"] > 0.2 * block.alpha and not exact["overturned"] and not product.overturned
    achieved = 1e-4 if exact["n_flights"] == 0 else 2e-3
    assert product.peak_angle == pytest.approx(exact["peak_angle"], rel=achieved)
    np.testing.assert_allclose(product.theta, exact["theta"], atol=5e-3 * exact["peak_angle"])
    assert product.time_of_uplift == pytest.approx(exact["time_of_uplift"], abs=1e-4)
    assert product.peak_uplift == pytest.approx(exact["peak_uplift"], rel=1e-3)
