"""pipeline.measures - stage 3: ground acceleration -> intensity measures.

Input : acceleration samples [m/s^2] (ndarray, shape (n,)) at a constant time step dt [s].
Output: scalar intensity measures in SI units (PGA [m/s^2], PGV [m/s], PGD [m], Arias intensity
        [m/s], CAV [m/s], significant duration D5-95 [s]) and 5%-damped response spectra for an
        array of periods (Sa [m/s^2], Sd [m]); measures made for rocking (PGA/(g tan alpha) and
        p PGV/(g tan alpha) per block, average spectral acceleration over a period range, the
        period and amplitude of the dominant velocity pulse).

``MEASURES`` registers every measure a study can scale records to or rank (pipeline.efficiency) as
one ``Measure``: name, function, SI unit, display unit, long name and pelicun demand type. A new
measure is one ``register_measure(Measure(...))`` call.

All functions are pure. The oscillator uses the exact solution for ground acceleration that is
linear between samples (Nigam & Jennings 1969); its recurrence coefficients come from the matrix
exponential of the augmented state matrix (a first-order-hold discretisation), which is that exact
solution written compactly.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

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


@lru_cache(maxsize=4096)
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
    # cached (records share dt and periods): hand out read-only arrays
    parts = exponential[:2, :2].copy(), exponential[:2, 2].copy(), exponential[:2, 3].copy()
    for part in parts:
        part.flags.writeable = False
    return parts


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
    coefficients = [oscillator_coefficients(float(period), float(damping), float(dt)) for period in periods]
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


def average_spectral_acceleration(acceleration, dt, low, high, damping=0.05, count=10) -> float:
    """AvgSa [m/s^2]: geometric mean of Sa at ``count`` log-spaced periods from ``low`` to ``high`` [s]
    (Eads et al. 2015; Kohrangi et al. 2016)."""
    if not 0 < low < high:
        raise ValueError(f"AvgSa period range {low}..{high} s; need 0 < low < high")
    spectrum = response_spectrum(acceleration, dt, np.geomspace(low, high, count), damping)
    return float(np.exp(np.mean(np.log(spectrum["sa"]))))


def velocity_pulse(acceleration, dt) -> tuple[float, float, float]:
    """The dominant velocity pulse: (period Tp [s], velocity amplitude v_p [m/s], acceleration
    amplitude a_p [m/s^2]).

    A deliberately simple, documented estimator (not Baker's 2007 wavelet extraction): the half
    cycle of ground velocity that holds the PGV runs between the zero crossings on either side of
    the peak; the pulse is taken as one full sine cycle of velocity v_p sin(w_p t), so
    Tp = 2 x (half-cycle duration), v_p = PGV and a_p = w_p v_p = 2 pi v_p / Tp (the acceleration
    amplitude of the equivalent cosine pulse of Makris & Vassiliou). Exact for such a pulse; for
    recorded pulse-like motions Tp tracks the period of the largest velocity half cycle.
    """
    velocity = integrate(np.asarray(acceleration, dtype=float), dt)[0]
    peak = int(np.argmax(np.abs(velocity)))
    v_p = float(abs(velocity[peak]))
    if v_p == 0.0:
        return math.nan, 0.0, 0.0
    sign = np.sign(velocity[peak])
    same_side = sign * velocity > 0
    start = peak
    while start > 0 and same_side[start - 1]:
        start -= 1
    end = peak
    while end < velocity.size - 1 and same_side[end + 1]:
        end += 1
    # crossings linearly interpolated between the last sample on each side and its neighbour
    t_start = _zero_crossing(velocity, start - 1, start, dt) if start > 0 else 0.0
    t_end = _zero_crossing(velocity, end, end + 1, dt) if end < velocity.size - 1 else end * dt
    period = 2.0 * (t_end - t_start)
    return float(period), v_p, float(2.0 * math.pi * v_p / period)


def _zero_crossing(series, i, j, dt) -> float:
    """Time at which the straight line from sample i to sample j crosses zero [s]."""
    a, b = series[i], series[j]
    return (i + a / (a - b) * (j - i)) * dt if a != b else i * dt


# ------------------------------------------------------------------ the measure registry

@dataclass(frozen=True)
class Measure:
    """One intensity measure.

    ``function(acceleration [m/s^2], dt [s], block, options) -> value [si_unit]``; ``block`` is a
    ``pipeline.blocks.Block`` for per-block measures (ignored otherwise); ``options`` holds the
    study's ``period`` [s], ``damping`` [-] and ``period_range`` ((low, high) [s] or None).
    ``scaling_exponent`` n: IM(lambda a) = lambda^n IM(a); a study scales records to measures with
    n = 1 only, and a record's capacity re-expressed in the measure is scale x IM (n = 1).
    ``display_factor`` is the SI value of one display unit (9.80665 for g).
    """

    name: str
    function: Callable[..., float]
    si_unit: str
    display_unit: str
    display_factor: float
    long_name: str
    pelicun_demand: tuple[str, str] | None = None  # (pelicun demand type, pelicun unit), None: none
    per_block: bool = False
    scaling_exponent: float = 1.0

    @property
    def scalable(self) -> bool:
        return self.scaling_exponent == 1.0

    def __call__(self, acceleration, dt, block=None, **options) -> float:
        if self.per_block and block is None:
            raise ValueError(f"measure {self.name!r} is defined per block; pass the block")
        return float(self.function(acceleration, dt, block, _options(options)))

    def describe(self, **options) -> str:
        """Long name with the study's options filled in."""
        options = _options(options)
        low, high = avgsa_range(options)
        return self.long_name.format(period=options["period"], damping=options["damping"], low=low, high=high)


def _options(options) -> dict:
    return {"period": 1.0, "damping": 0.05, "period_range": None, **options}


def avgsa_range(options) -> tuple[float, float]:
    """AvgSa period range [s]: the study's ``period_range``, else 0.2 T .. 3 T around ``period``."""
    given = options.get("period_range")
    if given:
        return float(given[0]), float(given[1])
    return 0.2 * options["period"], 3.0 * options["period"]


MEASURES: dict[str, Measure] = {}
"""Registered measures by name (``register_measure``)."""


def register_measure(measure: Measure) -> None:
    MEASURES[measure.name] = measure


def _rocking_pga(a, dt, block, o):
    return pga(a) / block.uplift_acceleration()


def _rocking_pgv(a, dt, block, o):
    return block.p() * pgv(a, dt) / block.uplift_acceleration()


register_measure(Measure("pga", lambda a, dt, block, o: pga(a), "m/s^2", "g", STANDARD_GRAVITY,
                         "peak ground acceleration", ("Peak Ground Acceleration", "g")))
register_measure(Measure("pgv", lambda a, dt, block, o: pgv(a, dt), "m/s", "m/s", 1.0,
                         "peak ground velocity", ("Peak Ground Velocity", "mps")))
register_measure(Measure("sa", lambda a, dt, block, o: spectral_acceleration(a, dt, o["period"], o["damping"]),
                         "m/s^2", "g", STANDARD_GRAVITY, "spectral acceleration Sa({period:g} s, {damping:.0%})",
                         ("Spectral Acceleration", "g")))
register_measure(Measure("avgsa", lambda a, dt, block, o: average_spectral_acceleration(
    a, dt, *avgsa_range(o), damping=o["damping"]), "m/s^2", "g", STANDARD_GRAVITY,
    "average spectral acceleration AvgSa({low:g}-{high:g} s, {damping:.0%})"))
register_measure(Measure("pga_ratio", _rocking_pga, "1", "1", 1.0,
                         "PGA over the block's uplift acceleration, PGA/(g tan alpha)", per_block=True))
register_measure(Measure("pgv_ratio", _rocking_pgv, "1", "1", 1.0,
                         "p PGV/(g tan alpha), p = sqrt(3g/4R) (Makris & Vassiliou)", per_block=True))
register_measure(Measure("pulse_amplitude", lambda a, dt, block, o: velocity_pulse(a, dt)[2], "m/s^2", "g",
                         STANDARD_GRAVITY, "acceleration amplitude a_p = 2 pi PGV/Tp of the dominant velocity pulse"))
register_measure(Measure("pulse_period", lambda a, dt, block, o: velocity_pulse(a, dt)[0], "s", "s", 1.0,
                         "period Tp of the dominant velocity pulse (a record property: does not scale)",
                         scaling_exponent=0.0))
