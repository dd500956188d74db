"""pipeline.measures - stage 3: ground acceleration -> intensity measures.

Input : acceleration samples [m/s^2] (ndarray, shape (n,)) at a constant time step dt [s].
Output: scalar intensity measures in SI units (PGA [m/s^2], PGV [m/s], PGD [m], Arias intensity
        [m/s], CAV [m/s], significant duration D5-95 [s]) and 5%-damped response spectra for an
        array of periods (Sa [m/s^2], Sd [m]).

All functions are pure. The oscillator uses the exact solution for ground acceleration that is
linear between samples (Nigam & Jennings 1969); its recurrence coefficients come from the matrix
exponential of the augmented state matrix (a first-order-hold discretisation), which is that exact
solution written compactly.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.linalg import expm

from pipeline.processing import integrate
from pipeline.units import STANDARD_GRAVITY

DEFAULT_PERIODS = np.round(np.geomspace(0.02, 10.0, 60), 4)
"""Periods of the default response spectrum [s]."""


def pga(acceleration) -> float:
    """Peak ground acceleration max|a| [m/s^2]."""
    return float(np.max(np.abs(acceleration)))


def pgv(acceleration, dt) -> float:
    """Peak ground velocity [m/s] (trapezoidal integration from rest)."""
    return float(np.max(np.abs(integrate(acceleration, dt)[0])))


def pgd(acceleration, dt) -> float:
    """Peak ground displacement [m]."""
    return float(np.max(np.abs(integrate(acceleration, dt)[1])))


def arias_intensity(acceleration, dt, g=STANDARD_GRAVITY) -> float:
    """Arias intensity Ia = pi/(2g) * integral a^2 dt [m/s]."""
    return float(np.pi / (2.0 * g) * np.trapezoid(np.asarray(acceleration) ** 2, dx=dt))


def cav(acceleration, dt) -> float:
    """Cumulative absolute velocity integral |a| dt [m/s]."""
    return float(np.trapezoid(np.abs(acceleration), dx=dt))


def significant_duration(acceleration, dt, start=0.05, end=0.95) -> float:
    """Time between ``start`` and ``end`` fractions of the Arias intensity (D5-95 by default) [s]."""
    squared = np.asarray(acceleration, dtype=float) ** 2
    husid = np.concatenate([[0.0], np.cumsum(0.5 * (squared[1:] + squared[:-1]) * dt)])
    if husid[-1] <= 0:
        return 0.0
    husid /= husid[-1]
    time = np.arange(husid.size) * dt
    return float(np.interp(end, husid, time) - np.interp(start, husid, time))


def oscillator_coefficients(period, damping, dt):
    """Exact recurrence for x = [u, v] of u'' + 2 zeta w u' + w^2 u = -a_g, a_g linear in a step.

    Returns ``phi`` (2, 2), ``gamma0`` (2,), ``gamma1`` (2,) such that
    x[k+1] = phi @ x[k] + gamma0 * a[k] + gamma1 * (a[k+1] - a[k]).
    """
    omega = 2.0 * np.pi / period
    system = np.array([[0.0, 1.0], [-omega**2, -2.0 * damping * omega]])
    forcing = np.array([0.0, -1.0])
    augmented = np.zeros((4, 4))
    augmented[:2, :2] = system * dt
    augmented[:2, 2] = forcing * dt
    augmented[2, 3] = 1.0  # the ramp: input grows by (a[k+1]-a[k]) over the step
    exponential = expm(augmented)
    return exponential[:2, :2], exponential[:2, 2], exponential[:2, 3]


@njit(cache=True)
def _oscillator_peaks(acceleration, phi, gamma0, gamma1, omega, damping):
    n_periods = phi.shape[0]
    peak_displacement = np.zeros(n_periods)
    peak_total_acceleration = np.zeros(n_periods)
    for j in range(n_periods):
        u = 0.0
        v = 0.0
        peak_u = 0.0
        peak_a = abs(acceleration[0])
        for k in range(acceleration.size - 1):
            ramp = acceleration[k + 1] - acceleration[k]
            u_next = phi[j, 0, 0] * u + phi[j, 0, 1] * v + gamma0[j, 0] * acceleration[k] + gamma1[j, 0] * ramp
            v_next = phi[j, 1, 0] * u + phi[j, 1, 1] * v + gamma0[j, 1] * acceleration[k] + gamma1[j, 1] * ramp
            u = u_next
            v = v_next
            if abs(u) > peak_u:
                peak_u = abs(u)
            total = abs(-2.0 * damping * omega[j] * v - omega[j] ** 2 * u)
            if total > peak_a:
                peak_a = total
        peak_displacement[j] = peak_u
        peak_total_acceleration[j] = peak_a
    return peak_displacement, peak_total_acceleration


def response_spectrum(acceleration, dt, periods=DEFAULT_PERIODS, damping=0.05):
    """Elastic response spectrum of a linear SDOF oscillator.

    Parameters
    ----------
    acceleration : ndarray, shape (n,)
        Ground acceleration [m/s^2], linear between samples.
    dt : float
        Time step [s].
    periods : array_like, shape (m,)
        Oscillator periods [s], > 0.
    damping : float
        Damping ratio [-] (0.05 = 5%).

    Returns
    -------
    dict with ``period`` [s], ``sa`` (peak absolute acceleration) [m/s^2], ``sd`` (peak relative
    displacement) [m] and ``psa`` = w^2 Sd [m/s^2], each shape (m,).
    """
    periods = np.atleast_1d(np.asarray(periods, dtype=float))
    if np.any(periods <= 0):
        raise ValueError("periods must be positive [s]")
    if not 0 <= damping < 1:
        raise ValueError(f"damping ratio {damping} out of range; allowed 0 <= damping < 1")
    coefficients = [oscillator_coefficients(period, damping, dt) for period in periods]
    phi = np.array([c[0] for c in coefficients])
    gamma0 = np.array([c[1] for c in coefficients])
    gamma1 = np.array([c[2] for c in coefficients])
    omega = 2.0 * np.pi / periods
    sd, sa = _oscillator_peaks(np.ascontiguousarray(acceleration, dtype=np.float64), phi, gamma0,
                               gamma1, omega, float(damping))
    return {"period": periods, "sa": sa, "sd": sd, "psa": omega**2 * sd}


def spectral_acceleration(acceleration, dt, period, damping=0.05) -> float:
    """Sa(T, zeta) [m/s^2]: peak absolute acceleration of the oscillator of period ``period``."""
    return float(response_spectrum(acceleration, dt, [period], damping)["sa"][0])


def intensity_measures(acceleration, dt, sa_periods=(0.2, 1.0, 2.0)) -> dict:
    """All scalar measures of one record as a dict of SI values, keys with units."""
    spectrum = response_spectrum(acceleration, dt, sa_periods)
    measures = {
        "pga_m_s2": pga(acceleration),
        "pgv_m_s": pgv(acceleration, dt),
        "pgd_m": pgd(acceleration, dt),
        "arias_m_s": arias_intensity(acceleration, dt),
        "cav_m_s": cav(acceleration, dt),
        "d5_95_s": significant_duration(acceleration, dt),
    }
    for period, value in zip(spectrum["period"], spectrum["sa"]):
        measures[f"sa_{period:g}s_m_s2"] = float(value)
    return measures


MEASURES = {
    "pga": lambda a, dt, **options: pga(a),
    "pgv": lambda a, dt, **options: pgv(a, dt),
    "sa": lambda a, dt, period=1.0, damping=0.05, **options: spectral_acceleration(a, dt, period, damping),
}
"""Intensity measures a study can scale records to: name -> f(acceleration [m/s^2], dt [s], **options)
returning SI values. A new scaling measure is one entry here plus its unit in config.MEASURE_UNITS."""
