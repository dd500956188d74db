"""The SSI kernel's right-hand side is the Euler-Lagrange equation of the paper's Lagrangian.

T = 1/2 I_O theta'^2 - m R sin(A) theta' y' + 1/2 m y'^2 (I_O = 4/3 m R^2, A = sigma alpha - theta),
V = 1/2 k y^2 + m g (R cos A - y) (paper eq. 9), dashpot -c y', ground-inertia moment -m ag R cos A.
sympy derives the equations; the compiled kernel must make their residual vanish.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from pipeline.models import kernels
from pipeline.models.fields import HOUSNER, SSI, new_params


def _lagrange_accelerations():
    t = sp.symbols("t")
    m, radius, alpha, g, k, c, ag, sigma = sp.symbols("m R alpha g k c a_g sigma", real=True)
    theta = sp.Function("theta")(t)
    y = sp.Function("y")(t)
    angle = sigma * alpha - theta
    # centre of mass in the ground frame, pivot at (x_p, -y): independent of the printed eq. 8
    x_c = -radius * sp.sin(angle)
    z_c = -y + radius * sp.cos(angle)
    inertia_centre = sp.Rational(1, 3) * m * radius**2  # rectangle 2b x 2h about its centre
    kinetic = sp.Rational(1, 2) * m * (sp.diff(x_c, t) ** 2 + sp.diff(z_c, t) ** 2) \
        + sp.Rational(1, 2) * inertia_centre * sp.diff(theta, t) ** 2
    potential = sp.Rational(1, 2) * k * y**2 + m * g * z_c
    lagrangian = kinetic - potential
    forces = {theta: -m * ag * sp.diff(x_c, theta), y: -c * sp.diff(y, t)}
    equations = []
    for q in (theta, y):
        equations.append(sp.diff(sp.diff(lagrangian, sp.diff(q, t)), t) - sp.diff(lagrangian, q) - forces[q])
    theta_dd, y_dd = sp.symbols("theta_dd y_dd")
    th, thd, yy, yd = sp.symbols("th thd yy yd")
    substitutions = {sp.diff(theta, t, 2): theta_dd, sp.diff(y, t, 2): y_dd,
                     sp.diff(theta, t): thd, sp.diff(y, t): yd}
    equations = [e.subs(substitutions).subs({theta: th, y: yy}) for e in equations]
    solution = sp.solve(equations, [theta_dd, y_dd], dict=True)[0]
    arguments = (th, thd, yy, yd, m, radius, alpha, g, k, c, ag, sigma)
    return (sp.lambdify(arguments, solution[theta_dd], "numpy"),
            sp.lambdify(arguments, solution[y_dd], "numpy"), kinetic, x_c)


def test_kinetic_energy_is_the_issue_form():
    """T equals 1/2 I_O theta'^2 - m R sin(A) theta' y' + 1/2 m y'^2 with I_O = 4/3 m R^2."""
    t = sp.symbols("t")
    m, radius, alpha, sigma = sp.symbols("m R alpha sigma", real=True)
    theta = sp.Function("theta")(t)
    y = sp.Function("y")(t)
    _, _, kinetic, _ = _lagrange_accelerations()
    kinetic = kinetic.subs({sp.Symbol("m", real=True): m})
    angle = sigma * alpha - theta
    expected = (sp.Rational(2, 3) * m * radius**2 * sp.diff(theta, t) ** 2
                - m * radius * sp.sin(angle) * sp.diff(theta, t) * sp.diff(y, t)
                + sp.Rational(1, 2) * m * sp.diff(y, t) ** 2)
    assert sp.simplify(sp.expand_trig(kinetic - expected)) == 0


@pytest.mark.parametrize("sigma", [1.0, -1.0])
def test_kernel_rhs_is_euler_lagrange(sigma):
    theta_dd, y_dd, _, _ = _lagrange_accelerations()
    rng = np.random.default_rng(12345)
    out = np.empty(4)
    for _ in range(200):
        m = rng.uniform(1e3, 1e6)
        radius = rng.uniform(0.5, 20.0)
        alpha = rng.uniform(0.05, 1.2)
        g = 9.80665
        omega = rng.uniform(5.0, 500.0)
        xi = rng.uniform(0.0, 0.2)
        k = m * omega**2
        c = 2 * xi * omega * m
        state = np.array([sigma * rng.uniform(0, alpha), rng.normal(0, 1.0),
                          rng.uniform(-0.01, 0.05), rng.normal(0, 0.1)])
        accel = rng.normal(0, 5.0)
        params = new_params(1)[0]
        for name, value in zip(("R", "alpha", "g", "kappa", "omega", "xi"), (radius, alpha, g, 0.75, omega, xi)):
            params[name] = value
        kernels.rhs(SSI, kernels.ROCKING, sigma, state, accel, params, out)
        arguments = (state[0], state[1], state[2], state[3], m, radius, alpha, g, k, c, accel, sigma)
        expected_theta = theta_dd(*arguments)
        expected_y = y_dd(*arguments)
        assert out[1] == pytest.approx(expected_theta, rel=1e-9, abs=1e-9 * abs(g / radius))
        assert out[3] == pytest.approx(expected_y, rel=1e-9, abs=1e-9 * g)
        assert out[0] == state[1] and out[2] == state[3]


def test_stiff_limit_of_rhs_is_housner_eq1():
    """With y'' = 0 imposed (rigid base), the theta equation is Housner's eq. 1."""
    params = new_params(1)[0]
    radius, alpha, g = 3.0, 0.3, 9.80665
    for name, value in zip(("R", "alpha", "g", "kappa"), (radius, alpha, g, 0.75)):
        params[name] = value
    out = np.empty(4)
    state = np.array([0.1, 0.2, 0.0, 0.0])
    kernels.rhs(HOUSNER, kernels.ROCKING, 1.0, state, 1.5, params, out)
    p2 = 3 * g / (4 * radius)
    assert out[1] == pytest.approx(-p2 * (np.sin(alpha - 0.1) + 1.5 / g * np.cos(alpha - 0.1)), rel=1e-14)
