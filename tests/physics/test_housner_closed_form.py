"""Housner solver against exact results: free-rocking period, impact amplitudes, uplift threshold
and the overturning threshold of a rectangular pulse."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq
from scipy.special import ellipkinc

from rockfrag.blocks import Block
from rockfrag.models import Outcome, simulate

G = 9.80665
BLOCK = Block(name="test", R=1.0, alpha=0.2, mass=1000.0)
P = BLOCK.p()


def quarter_period(theta0, alpha=BLOCK.alpha, p=P):
    """Exact time from rest at theta0 to the impact (theta = 0) of free rocking.

    phi = alpha - theta obeys phi'' = p^2 sin(phi) (an inverted pendulum), so
    t = int_{phi0}^{alpha} dphi / sqrt(2 p^2 (cos phi0 - cos phi)). With sinh-type substitution this is
    an incomplete elliptic integral; here the integral is evaluated by adaptive quadrature after the
    substitution phi = phi0 + u^2, which removes the end-point singularity (independent of the
    solver), and cross-checked against the elliptic form below.
    """
    phi0 = alpha - theta0

    def integrand(u):
        phi = phi0 + u * u
        return 2 * u / math.sqrt(2 * p * p * (math.cos(phi0) - math.cos(phi))) if u > 0 else \
            2 / math.sqrt(2 * p * p * math.sin(phi0))

    value, _ = quad(integrand, 0.0, math.sqrt(alpha - phi0), epsabs=1e-13, epsrel=1e-11, limit=200)
    return value


def quarter_period_elliptic(theta0, alpha=BLOCK.alpha, p=P):
    """Same quantity from Legendre's form: with psi = pi - phi the motion is an ordinary pendulum
    psi'' = -p^2 sin(psi) released at psi0 = pi - phi0 > pi/2; time from psi0 down to pi - alpha is
    [F(pi/2, k) - F(asin(sin((pi-alpha)/2)/k), k)] / p with k = sin(psi0/2)."""
    psi0 = math.pi - (alpha - theta0)
    psi1 = math.pi - alpha
    k = math.sin(psi0 / 2)
    return (ellipkinc(math.pi / 2, k * k) - ellipkinc(math.asin(math.sin(psi1 / 2) / k), k * k)) / p


def test_quadrature_and_elliptic_forms_agree():
    for theta0 in (0.01, 0.1, 0.19):
        assert quarter_period(theta0) == pytest.approx(quarter_period_elliptic(theta0), rel=1e-9)


@pytest.mark.parametrize("ratio", [0.05, 0.5, 0.95])
def test_free_rocking_impact_times_match_exact_period(ratio):
    theta0 = ratio * BLOCK.alpha
    # tight solver tolerances: steps span many samples, so the default rtol 1e-6 leaves ~1e-6 per excursion
    result = simulate("housner", np.zeros(2), 1e-3, BLOCK, theta0=theta0, restitution=1.0, t_end=12.0,
                      rtol=1e-10, atol=1e-10)
    quarter = quarter_period_elliptic(theta0)
    expected = quarter * (1 + 2 * np.arange(result.n_impacts))
    assert result.n_impacts >= 3
    np.testing.assert_allclose(result.impact_times, expected, rtol=1e-7)
    assert result.peak_angle == pytest.approx(theta0, rel=1e-7)


def test_linearised_formula_is_only_approximate_for_squat_blocks():
    """Housner's arccosh formula assumes small alpha; for alpha = 0.6 it is off by more than 1%."""
    squat = Block(name="squat", R=1.0, alpha=0.6, mass=1000.0)
    theta0 = 0.5 * squat.alpha
    result = simulate("housner", np.zeros(2), 1e-3, squat, theta0=theta0, restitution=1.0, t_end=3.0)
    exact = quarter_period_elliptic(theta0, squat.alpha, squat.p())
    linearised = math.acosh(1 / (1 - 0.5)) / squat.p()
    assert result.impact_times[0] == pytest.approx(exact, rel=1e-7)
    assert abs(linearised - exact) / exact > 0.01


def test_amplitude_after_each_impact():
    """cos(alpha - theta_{n+1}) = cos(alpha) + r^2 (cos(alpha - theta_n) - cos(alpha))."""
    alpha = BLOCK.alpha
    r = BLOCK.housner_restitution()
    theta0 = 0.8 * alpha
    result = simulate("housner", np.zeros(2), 2e-4, BLOCK, theta0=theta0, t_end=6.0)
    amplitudes = [theta0]
    for n in range(min(4, result.n_impacts)):
        expected = alpha - math.acos(math.cos(alpha) + r**2 * (math.cos(alpha - amplitudes[-1]) - math.cos(alpha)))
        start = result.impact_times[n]
        end = result.impact_times[n + 1] if n + 1 < result.n_impacts else result.t[-1]
        window = (result.t > start) & (result.t < end)
        i = np.argmax(np.abs(result.theta[window]))
        index = np.flatnonzero(window)[i]
        # parabola through the three samples around the sampled maximum
        y0, y1, y2 = np.abs(result.theta[index - 1:index + 2])
        peak = y1 - (y0 - y2) ** 2 / (8 * (y0 - 2 * y1 + y2))  # vertex of the parabola
        assert peak == pytest.approx(expected, rel=1e-6), n
        amplitudes.append(expected)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_uplift_just_below_and_above_threshold(sign):
    threshold = G * math.tan(BLOCK.alpha)
    below = simulate("housner", sign * np.full(200, 0.999 * threshold), 0.01, BLOCK)
    above = simulate("housner", sign * np.full(200, 1.001 * threshold), 0.01, BLOCK)
    assert below.status == Outcome.NO_UPLIFT and not below.uplifted and below.peak_angle == 0.0
    assert above.uplifted and above.time_of_uplift == pytest.approx(0.0, abs=0.011)
    # rocking starts towards theta * ag < 0
    rocked = above.theta[np.nanargmax(np.abs(above.theta))]
    assert rocked * sign < 0


def critical_pulse_duration(amplitude, alpha=BLOCK.alpha, p=P):
    """Shortest rectangular pulse of ``amplitude`` [m/s^2] that overturns a block (exact).

    During the pulse 1/2 theta'^2 = p^2 [(a/g)(sin a - sin(a - th)) - (cos(a - th) - cos a)]; afterwards the
    block overturns if 1/2 theta_1'^2 >= p^2 (1 - cos(alpha - theta_1)). The pulse ends at the theta_1 where
    both are equal, reached after t = int_0^theta_1 dtheta / theta'.
    """
    ratio = amplitude / G

    def energy(theta):
        return p * p * (ratio * (math.sin(alpha) - math.sin(alpha - theta))
                        - (math.cos(alpha - theta) - math.cos(alpha)))

    theta1 = brentq(lambda th: energy(th) - p * p * (1 - math.cos(alpha - th)), 1e-9, alpha, xtol=1e-15)

    def integrand(u):  # theta = u^2
        theta = u * u
        if u == 0:
            return 2 / math.sqrt(2 * p * p * (ratio * math.cos(alpha) - math.sin(alpha)))
        return 2 * u / math.sqrt(2 * energy(theta))

    duration, _ = quad(integrand, 0, math.sqrt(theta1), epsabs=1e-13, epsrel=1e-12, limit=200)
    return duration


@pytest.mark.parametrize("factor", [1.5, 3.0])
def test_rectangular_pulse_overturning_threshold(factor):
    amplitude = factor * G * math.tan(BLOCK.alpha)
    critical = critical_pulse_duration(amplitude)
    dt = 1e-4
    for scale, overturns in ((0.99, False), (1.01, True)):
        n_pulse = int(round(scale * critical / dt))
        ag = np.zeros(n_pulse + 2)
        ag[:n_pulse + 1] = -amplitude  # constant from t = 0 to the end of the pulse
        result = simulate("housner", ag, dt, BLOCK, t_end=8.0)
        assert result.overturned == overturns, (scale, result.peak_angle_ratio)
