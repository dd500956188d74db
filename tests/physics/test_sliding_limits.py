"""Friction limits and balances: a large mu gives the tied base exactly where the block never flies (rigid base
and both beds, on real records), and on a bed without damping the friction's work closes the energy balance.
"""

from __future__ import annotations

import numpy as np
import pytest

from rockfrag.blocks import Block
from rockfrag.models import simulate

from .test_sliding_vs_reference import case_motion

BLOCK = Block(name="reference", R=2.0, alpha=0.25, mass=5000.0)
LARGE = (1e3, 1.0)  # mu_s far above any friction demand of a grounded block


def stiffness(omega_over_p):
    return BLOCK.mass * (omega_over_p * BLOCK.p()) ** 2


@pytest.mark.parametrize("model, options", [("housner", {}), ("winkler", {"bed": "continuous"}),
                                            ("winkler", {"bed": "two-spring"})])
@pytest.mark.parametrize("record_id, scale", [("DUZCE/BOL090", 3.0), ("LOMAP/CAP000", 1.5)])
def test_large_mu_gives_the_tied_base(model, options, record_id, scale):
    ag, dt = case_motion(record_id, scale)
    if model == "winkler":
        options = {**options, "k": stiffness(30.0)}
    tied = simulate(model, ag, dt, BLOCK, t_end=(ag.size - 1) * dt + 5.0, **options)
    sliding = simulate(model, ag, dt, BLOCK, t_end=(ag.size - 1) * dt + 5.0, friction=LARGE, **options)
    assert tied.n_flights == 0 and tied.peak_angle > 0.1 * BLOCK.alpha
    assert sliding.peak_slip == 0.0 and sliding.mode_times["slide"] == sliding.mode_times["slide_rock"] == 0.0
    assert sliding.peak_angle == pytest.approx(tied.peak_angle, rel=1e-6)
    np.testing.assert_allclose(sliding.theta, tied.theta, atol=1e-6 * tied.peak_angle)
    assert sum(sliding.mode_times.values()) == pytest.approx(tied.t[-1], rel=1e-9)


def test_a_flying_block_slides_in_the_air():
    """Where the tied bed flies, the base is free in the air: the same block with large mu slides there."""
    ag, dt = case_motion("DUZCE/BOL090", 3.0)
    options = {"k": stiffness(100.0), "bed": "two-spring"}
    tied = simulate("winkler", ag, dt, BLOCK, **options)
    sliding = simulate("winkler", ag, dt, BLOCK, friction=LARGE, **options)
    assert tied.n_flights > 10 and sliding.mode_times["flight"] > 0.0
    assert sliding.peak_slip > 0.0


def test_friction_work_closes_the_energy_balance():
    """Two-spring bed with xi = 0: the only loss is the friction, mu_k F |u'| (per unit mass).

    E = 1/2 |v_c|^2 + 1/2 j_c theta'^2 + g z_c + springs, in the ground's frame (v_c = (u' + h cos th th',
    -(y' + h sin th th'))); its change equals the work of the inertial force, -ag x_c', minus the friction's.
    Integrated by the trapezoidal rule on the 0.2 ms sample grid.
    """
    dt = 2e-4
    t = np.arange(int(round(1.5 / dt)) + 1) * dt
    period = 0.6
    ag = np.where(t <= period, 2.0 * BLOCK.uplift_acceleration() * np.sin(2 * np.pi * t / period), 0.0)
    K = stiffness(30.0)
    mu_k = 0.2
    r = simulate("winkler", ag, dt, BLOCK, k=K, xi=0.0, bed="two-spring", friction=(0.3, mu_k), t_end=2.5)
    assert r.peak_slip > 0.01 and r.uplifted and r.mode_times["slide_rock"] > 0.0
    b, h = BLOCK.b, BLOCK.h
    theta, rate, y, y_dot, u_dot = r.theta, r.theta_dot, r.y, r.y_dot, r.u_dot
    omega2 = K / BLOCK.mass
    depth = np.stack([y - b * np.sin(theta), y + b * np.sin(theta)])
    force = 0.5 * omega2 * np.clip(depth, 0.0, None).sum(axis=0)            # F per unit mass (xi = 0)
    springs = 0.25 * omega2 * (np.clip(depth, 0.0, None) ** 2).sum(axis=0)  # (K/2)/m delta^2 / 2 per corner
    x_rate = u_dot + h * np.cos(theta) * rate
    energy = (0.5 * (x_rate**2 + (y_dot + h * np.sin(theta) * rate) ** 2) + 0.5 * (b * b + h * h) / 3 * rate**2
              + 9.80665 * (h * np.cos(theta) - y) + springs)
    ground = np.zeros_like(r.t)
    ground[:ag.size] = ag[:r.t.size]
    work_in = np.trapezoid(-ground * x_rate, r.t)
    friction = np.trapezoid(mu_k * force * np.abs(u_dot), r.t)
    assert friction > 0.2 * work_in > 0
    assert energy[-1] - energy[0] == pytest.approx(work_in - friction, abs=1e-5 * work_in)  # measured 1.3e-7
    # and with the friction left out the balance is far off
    assert abs(energy[-1] - energy[0] - work_in) > 0.1 * work_in
