"""The `winkler` model's equations: an Euler-Lagrange residual (sympy) for the contact phase, and the bed's
resultant force and moment against a brute-force quadrature of the pointwise tensionless law.

sympy builds T and V from the positions of the centre of mass and of a base point (not from the
spec's printed T), takes the bed's generalised forces from the virtual work of a vertical point
force at the base, and solves the Euler-Lagrange equations for theta'' and y''. The product's
``rockfrag.models.winkler.accelerations`` (and the scipy reference's) must match at random states.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pytest
import sympy as sp

from rockfrag.blocks import Block
from rockfrag.models import SolverOptions, get_model, parameter_record
from rockfrag.models import winkler as product

from . import winkler_reference as reference

G = 9.80665


@lru_cache(maxsize=1)
def lagrange_accelerations():
    """(theta'', y'') as functions of (theta, theta', y, y', ag, F/m, M/m, b, h, g), from sympy."""
    t = sp.symbols("t")
    m, b, h, g, force, moment, ag = sp.symbols("m b h g F M a_g", real=True)
    theta = sp.Function("theta")(t)
    y = sp.Function("y")(t)
    x_ground = sp.Function("x_g")(t)
    # base centre at (x_g, -y); theta > 0 tilts the block towards +x (the +b corner presses in)
    x_centre = x_ground + h * sp.sin(theta)
    z_centre = -y + h * sp.cos(theta)
    inertia_centre = m * (b**2 + h**2) / 3  # rectangle 2b x 2h about its centroid
    kinetic = (m * (sp.diff(x_centre, t) ** 2 + sp.diff(z_centre, t) ** 2)
               + inertia_centre * sp.diff(theta, t) ** 2) / 2
    lagrangian = kinetic - m * g * z_centre
    # the bed: an upward point force f at body coordinate s is equivalent to F = f, M = f s
    s = moment / force
    z_base_point = -y - s * sp.sin(theta)
    generalised = {q: force * sp.diff(z_base_point, q) for q in (theta, y)}
    theta_dd, y_dd, th, thd, yy, yd = sp.symbols("theta_dd y_dd th thd yy yd")
    replace = {sp.diff(x_ground, t, 2): ag, sp.diff(theta, t, 2): theta_dd, sp.diff(y, t, 2): y_dd,
               sp.diff(theta, t): thd, sp.diff(y, t): yd}
    equations = []
    for q in (theta, y):
        residual = sp.diff(sp.diff(lagrangian, sp.diff(q, t)), t) - sp.diff(lagrangian, q) - generalised[q]
        equations.append(sp.expand(residual.subs(replace).subs({theta: th, y: yy}) / m))
    solution = sp.solve(equations, [theta_dd, y_dd], dict=True)[0]
    per_mass = {force: sp.Symbol("F_m") * m, moment: sp.Symbol("M_m") * m}
    arguments = (th, thd, yy, yd, ag, sp.Symbol("F_m"), sp.Symbol("M_m"), b, h, g)
    return tuple(sp.lambdify(arguments, sp.simplify(solution[q].subs(per_mass)), "math")
                 for q in (theta_dd, y_dd))


def random_states(count, seed):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        b, h = rng.uniform(0.1, 3.0), rng.uniform(0.2, 8.0)
        yield dict(theta=rng.uniform(-1.4, 1.4), theta_dot=rng.normal(0, 2.0), y=rng.uniform(-0.02, 0.05),
                   y_dot=rng.normal(0, 0.3), ag=rng.normal(0, 8.0), force=rng.uniform(0.01, 80.0),
                   moment=rng.normal(0, 40.0) * b, b=b, h=h)


@pytest.mark.parametrize("implementation", ["product", "reference"])
def test_contact_phase_accelerations_are_euler_lagrange(implementation):
    """theta'' and y'' of the product's (and the reference's) right-hand side make the Euler-Lagrange
    residual vanish at 300 random states (any bed force F >= 0 and moment M)."""
    theta_dd, y_dd = lagrange_accelerations()
    for state in random_states(300, seed=2024):
        j = (state["b"] ** 2 + 4 * state["h"] ** 2) / 3
        arguments = (state["theta"], state["theta_dot"], state["y"], state["y_dot"], state["ag"],
                     state["force"], state["moment"], state["h"])
        if implementation == "product":
            got = product.accelerations(*arguments, j, G)
        else:
            got = reference.accelerations(state["theta"], state["theta_dot"], state["y"], state["ag"],
                                          state["force"], state["moment"], state["h"], j, G)
        lagrange = (state["theta"], state["theta_dot"], state["y"], state["y_dot"], state["ag"], state["force"],
                    state["moment"], state["b"], state["h"], G)
        scale = G + state["force"] + abs(state["ag"]) + state["h"] * state["theta_dot"] ** 2
        assert got[0] == pytest.approx(theta_dd(*lagrange), abs=1e-10 * scale / state["h"])
        assert got[1] == pytest.approx(y_dd(*lagrange), abs=1e-10 * scale)


def test_flight_is_ballistic_and_rigid_rotation_limit():
    """Spot checks of the sympy derivation itself: with F = M = 0 and theta = 0 the block falls at g;
    with y'' forced to 0 the rotation equation is that of a block about its base centre."""
    theta_dd, y_dd = lagrange_accelerations()
    assert y_dd(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 2.0, G) == pytest.approx(G)
    b, h, ag = 0.5, 2.0, 1.3
    j = (b * b + 4 * h * h) / 3
    assert theta_dd(0.0, 0.0, 0.0, 0.0, ag, G, 0.0, b, h, G) == pytest.approx(-h * ag / j)


def quadrature_bed(theta, theta_dot, y, y_dot, b, K, C, bed, points=200_001):
    """F [N] and M [N m] by summing the pointwise law on a fine grid (continuous) or at the corners."""
    if bed == "two-spring":
        s = np.array([-b, b])
        delta = y + s * math.sin(theta)
        law = 0.5 * K * delta + 0.5 * C * (y_dot + s * math.cos(theta) * theta_dot)
        f = np.where(delta > 0, np.maximum(law, 0.0), 0.0)
        return f.sum(), (f * s).sum()
    edges = np.linspace(-b, b, points)
    s = 0.5 * (edges[1:] + edges[:-1])
    ds = edges[1] - edges[0]
    delta = y + s * math.sin(theta)
    law = K / (2 * b) * delta + C / (2 * b) * (y_dot + s * math.cos(theta) * theta_dot)
    q = np.where(delta > 0, np.maximum(law, 0.0), 0.0)
    return q.sum() * ds, (q * s).sum() * ds


@pytest.mark.parametrize("bed", ["continuous", "two-spring"])
def test_bed_force_is_the_tensionless_law_integrated(bed):
    """The product's bed_force (per unit mass) equals the pointwise law max(0, k delta + c delta') on
    delta > 0, integrated by brute force, at random full, partial, pulling and flight states."""
    rng = np.random.default_rng(7)
    model = get_model("winkler")
    states = 0
    for _ in range(150):
        block = Block(name="q", b=rng.uniform(0.2, 2.0), h=rng.uniform(0.3, 5.0), mass=rng.uniform(1e2, 1e6))
        omega = rng.uniform(10.0, 2000.0)
        xi = rng.choice([0.0, rng.uniform(0.0, 0.6)])
        K = block.mass * omega**2
        C = 2 * xi * math.sqrt(K * block.mass)
        params, _ = parameter_record(model, block, K, xi, SolverOptions(bed=bed))
        y_static = G / omega**2
        x = np.array([rng.uniform(-0.5, 0.5) * rng.choice([1e-3, 1e-2, 1.0]) * block.alpha, rng.normal(0, 0.5),
                      y_static * rng.uniform(-3.0, 3.0), y_static * omega * rng.normal(0, 1.0)])
        force, moment = product.bed_force(x, params)
        want_force, want_moment = quadrature_bed(*x, block.b, K, C, bed)
        exact_force, exact_moment = reference.bed_force(*x, block.b, K, C, bed)
        scale = K * (abs(x[2]) + block.b * abs(math.sin(x[0]))) + C * (abs(x[3]) + block.b * abs(x[1])) + 1e-300
        tolerance = 1e-8 if bed == "two-spring" else 2e-5  # midpoint rule across the kinks
        assert force * block.mass == pytest.approx(want_force, abs=tolerance * scale)
        assert moment * block.mass == pytest.approx(want_moment, abs=tolerance * scale * block.b)
        assert force * block.mass == pytest.approx(exact_force, abs=1e-10 * scale)
        assert moment * block.mass == pytest.approx(exact_moment, abs=1e-10 * scale * block.b)
        assert force >= 0.0
        states += want_force > 0
    assert states > 30, "too few loaded states drawn to mean anything"


@pytest.mark.parametrize("bed, rotational_factor", [("continuous", 1 / 3), ("two-spring", 1.0)])
def test_static_state_has_uniform_pressure_and_rotational_stiffness(bed, rotational_factor):
    """At y = m g / K, theta = 0: F = m g and M = 0; a small tilt gives M = K_r theta with
    K_r = K b^2 / 3 (continuous) or K b^2 (two-spring)."""
    block = Block(name="s", b=0.6, h=1.7, mass=3000.0)
    K = 4e8
    params, state = parameter_record(get_model("winkler"), block, K, 0.05, SolverOptions(bed=bed))
    assert state[2] == pytest.approx(block.mass * G / K, rel=1e-12)
    force, moment = product.bed_force(state, params)
    assert force == pytest.approx(G, rel=1e-12)
    assert moment == pytest.approx(0.0, abs=1e-12 * G * block.b)
    tilt = 1e-3 * state[2] / block.b
    _, moment = product.bed_force(np.array([tilt, 0.0, state[2], 0.0]), params)
    assert moment * block.mass == pytest.approx(rotational_factor * K * block.b**2 * math.sin(tilt), rel=1e-9)
