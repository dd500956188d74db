"""The SSI kernel's right-hand side is the Euler-Lagrange equation of the paper's Lagrangian.

T = 1/2 I_O theta'^2 - m R sin(A) theta' y' + 1/2 m y'^2 (I_O = 4/3 m R^2, A = sigma alpha - theta),
V = 1/2 k y^2 + m g (R cos A - y) (paper eq. 9), dashpot -c y', ground-inertia moment -m ag R cos A.
sympy derives the equations; the compiled kernel must make their residual vanish.

The ground also moves vertically, by z_g(t) with z_g'' = a_v (up positive): the centre of mass is at
height z_g - y + R cos A, T is built from its absolute velocity and V = 1/2 k y^2 + m g z_c with the
spring on the relative settlement y. The kernel takes a_v as the effective gravity g + a_v.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from rockfrag.models import kernels
from rockfrag.models.fields import HOUSNER, SSI, new_params


def _lagrange_accelerations():
    t = sp.symbols("t")
    m, radius, alpha, g, k, c, ag, av, sigma = sp.symbols("m R alpha g k c a_g a_v sigma", real=True)
    theta = sp.Function("theta")(t)
    y = sp.Function("y")(t)
    z_ground = sp.Function("z_g")(t)  # vertical ground displacement, up positive
    angle = sigma * alpha - theta
    # centre of mass, pivot at (x_p, z_g - y): independent of the printed eq. 8; horizontally in the ground
    # frame (the ground's horizontal inertia is the generalised force below), vertically absolute
    x_c = -radius * sp.sin(angle)
    z_c = z_ground - y + radius * sp.cos(angle)
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
    substitutions = {sp.diff(theta, t, 2): theta_dd, sp.diff(y, t, 2): y_dd, sp.diff(z_ground, t, 2): av,
                     sp.diff(theta, t): thd, sp.diff(y, t): yd}
    equations = [sp.expand(e.subs(substitutions).subs({theta: th, y: yy})) for e in equations]
    assert not any(e.has(z_ground) for e in equations), "the ground's vertical position or velocity left over"
    solution = sp.solve(equations, [theta_dd, y_dd], dict=True)[0]
    arguments = (th, thd, yy, yd, m, radius, alpha, g, k, c, ag, av, sigma)
    return (sp.lambdify(arguments, solution[theta_dd], "numpy"),
            sp.lambdify(arguments, solution[y_dd], "numpy"), kinetic, x_c)


def test_kinetic_energy_is_the_issue_form():
    """T equals 1/2 I_O theta'^2 - m R sin(A) theta' y' + 1/2 m y'^2 with I_O = 4/3 m R^2."""
    t = sp.symbols("t")
    m, radius, alpha, sigma = sp.symbols("m R alpha sigma", real=True)
    theta = sp.Function("theta")(t)
    y = sp.Function("y")(t)
    _, _, kinetic, _ = _lagrange_accelerations()
    kinetic = kinetic.subs({sp.Symbol("m", real=True): m, sp.Function("z_g")(t): 0})  # the ground at rest
    angle = sigma * alpha - theta
    expected = (sp.Rational(2, 3) * m * radius**2 * sp.diff(theta, t) ** 2
                - m * radius * sp.sin(angle) * sp.diff(theta, t) * sp.diff(y, t)
                + sp.Rational(1, 2) * m * sp.diff(y, t) ** 2)
    assert sp.simplify(sp.expand_trig(kinetic - expected)) == 0


@pytest.mark.parametrize("vertical", [False, True])
@pytest.mark.parametrize("sigma", [1.0, -1.0])
def test_kernel_rhs_is_euler_lagrange(sigma, vertical):
    """Rocking and, with the ground moving vertically too, gravity g + a_v in both equations."""
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
        av = rng.normal(0, 5.0) if vertical else 0.0
        params = new_params(1)[0]
        for name, value in zip(("R", "alpha", "g", "kappa", "omega", "xi"), (radius, alpha, g, 0.75, omega, xi)):
            params[name] = value
        kernels.rhs(SSI, kernels.ROCKING, sigma, state, accel, g + av, params, out)
        arguments = (state[0], state[1], state[2], state[3], m, radius, alpha, g, k, c, accel, av, sigma)
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
    kernels.rhs(HOUSNER, kernels.ROCKING, 1.0, state, 1.5, g, params, out)
    p2 = 3 * g / (4 * radius)
    assert out[1] == pytest.approx(-p2 * (np.sin(alpha - 0.1) + 1.5 / g * np.cos(alpha - 0.1)), rel=1e-14)


@pytest.mark.parametrize("sigma", [1.0, -1.0])
def test_housner_rhs_is_the_rigid_limit_of_the_lagrangian_with_vertical_motion(sigma):
    """The Lagrangian with the spring held (y = y' = y'' = 0, k -> inf): its theta equation, solved by sympy
    with the ground moving vertically, is the Housner kernel's under gravity g + a_v."""
    t = sp.symbols("t")
    m, radius, alpha, g, ag, av = sp.symbols("m R alpha g a_g a_v", real=True)
    theta = sp.Function("theta")(t)
    z_ground = sp.Function("z_g")(t)
    angle = sigma * alpha - theta
    x_c = -radius * sp.sin(angle)
    z_c = z_ground + radius * sp.cos(angle)
    kinetic = m * (sp.diff(x_c, t) ** 2 + sp.diff(z_c, t) ** 2) / 2 + m * radius**2 / 6 * sp.diff(theta, t) ** 2
    lagrangian = kinetic - m * g * z_c
    residual = (sp.diff(sp.diff(lagrangian, sp.diff(theta, t)), t) - sp.diff(lagrangian, theta)
                + m * ag * sp.diff(x_c, theta))
    theta_dd, th, thd = sp.symbols("theta_dd th thd")
    residual = residual.subs({sp.diff(theta, t, 2): theta_dd, sp.diff(z_ground, t, 2): av}).subs(
        {sp.diff(theta, t): thd}).subs({theta: th})
    expected = sp.lambdify((th, thd, radius, alpha, g, ag, av), sp.solve(residual, theta_dd)[0], "math")
    params = new_params(1)[0]
    rng = np.random.default_rng(99)
    out = np.empty(4)
    for _ in range(50):
        radius_value, alpha_value, g_value = rng.uniform(0.5, 20.0), rng.uniform(0.05, 1.2), 9.80665
        for name, value in zip(("R", "alpha", "g", "kappa"), (radius_value, alpha_value, g_value, 0.75)):
            params[name] = value
        state = np.array([sigma * rng.uniform(0, alpha_value), rng.normal(0, 1.0), 0.0, 0.0])
        accel, vertical = rng.normal(0, 5.0), rng.normal(0, 5.0)
        kernels.rhs(HOUSNER, kernels.ROCKING, sigma, state, accel, g_value + vertical, params, out)
        want = expected(state[0], state[1], radius_value, alpha_value, g_value, accel, vertical)
        assert out[1] == pytest.approx(want, rel=1e-10, abs=1e-12 * g_value / radius_value)
