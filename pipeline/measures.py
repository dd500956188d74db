"""rockfrag.measures - stage 3: ground acceleration -> intensity measures.

Input : acceleration samples [m/s^2] (ndarray, shape (n,)) at a constant time step dt [s].
Output: scalar intensity measures in SI units (PGA [m/s^2], PGV [m/s], PGD [m], Arias intensity
        [m/s], CAV [m/s], significant duration D5-95 [s]) and 5%-damped response spectra for an
        array of periods (Sa [m/s^2], Sd [m]); measures made for rocking (PGA/(g tan alpha) and
        p PGV/(g tan alpha) per block, average spectral acceleration over a period range, the
        period and amplitude of the dominant velocity pulse).

``MEASURES`` registers every measure a study can scale records to or rank (rockfrag.efficiency) as
one ``Measure``: name, function, SI and display unit, long name, short label, pelicun demand type and
OpenQuake IMT. Every stage reads these (the study file's choices and units, the cube's metadata, the
report's axes, the hazard readers, the pelicun export): a new measure is one ``@define_measure``
function at the end of this module.
Two horizontal components of one station (a pair) have one intensity that does not depend on how the
instrument was turned: RotD50 and RotD100 (Boore 2010, BSSA 100(4)), the median and the largest over rotation
angles 0-179 deg (1 deg apart) of the peak of the rotated component a1 cos(theta) + a2 sin(theta). A measure
that has them says how (``Measure.histories``: the response histories, linear in the ground motion, whose
peaks make the measure; ``rotated``, ``rotd``): for Sa the oscillator responses of the two components are
rotated, as pyrotd does, since the oscillator is linear. Hazard curves of NGA-West2 models are in RotD50.
``Measure.cf_units``, ``file_units``, ``parse_units`` and ``convert_units`` are the one place for the
``units`` strings of result files (as UDUNITS parses them: g is "9.80665 m s-2") and for reading them back.

All functions are pure. The oscillator uses the exact solution for ground acceleration that is
linear between samples (Nigam & Jennings 1969); its recurrence coefficients come from the matrix
exponential of the augmented state matrix (a first-order-hold discretisation), which is that exact
solution written compactly.
"""

from __future__ import annotations

import math
import re
import string
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np
from numba import njit
from scipy.linalg import expm

from rockfrag.plugins import GROUPS, Registry
from rockfrag.processing import integrate
from rockfrag.units import STANDARD_GRAVITY

if TYPE_CHECKING:
    from rockfrag.blocks import Block

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


def _husid(acceleration, dt) -> tuple[np.ndarray | None, np.ndarray]:
    """The normalised Husid curve and the time of each sample [s].

    The curve is the cumulative integral of a^2 (trapezoidal), normalised to end at 1; None for a
    record without energy.
    """
    squared = np.asarray(acceleration, dtype=float) ** 2
    husid = np.concatenate([[0.0], np.cumsum(0.5 * (squared[1:] + squared[:-1]) * dt)])
    time = np.arange(husid.size) * dt
    if husid[-1] <= 0:
        return None, time
    return husid / husid[-1], time


def significant_window(acceleration, dt, start=0.05, end=0.95) -> tuple[float, float]:
    """Times [s] at which the Arias intensity reaches ``start`` and ``end`` of its final value.

    The Husid curve is interpolated linearly between samples; the window is the whole record,
    (0, (n - 1) dt), for a record without energy.
    """
    husid, time = _husid(acceleration, dt)
    if husid is None:
        return 0.0, float(time[-1])
    return float(np.interp(start, husid, time)), float(np.interp(end, husid, time))


def significant_duration(acceleration, dt, start=0.05, end=0.95) -> float:
    """Time between ``start`` and ``end`` fractions of the Arias intensity (D5-95 by default) [s].

    The length of ``significant_window``; 0 for a record without energy.
    """
    husid, time = _husid(acceleration, dt)
    if husid is None:
        return 0.0
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
def _oscillator_step(phi, gamma0, gamma1, j, a_now, a_next, u, v):
    """One sample of period j's exact recurrence (piecewise-linear ground acceleration): (u, v) at the next."""
    ramp = a_next - a_now
    return (phi[j, 0, 0] * u + phi[j, 0, 1] * v + gamma0[j, 0] * a_now + gamma1[j, 0] * ramp,
            phi[j, 1, 0] * u + phi[j, 1, 1] * v + gamma0[j, 1] * a_now + gamma1[j, 1] * ramp)


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
            u, v = _oscillator_step(phi, gamma0, gamma1, j, acceleration[k], acceleration[k + 1], u, v)
            if abs(u) > peak_u:
                peak_u = abs(u)
            total = abs(-2.0 * damping * omega[j] * v - omega[j] ** 2 * u)
            if total > peak_a:
                peak_a = total
        peak_displacement[j] = peak_u
        peak_total_acceleration[j] = peak_a
    return peak_displacement, peak_total_acceleration


@njit(cache=True)
def _oscillator_histories(acceleration, phi, gamma0, gamma1, omega, damping):
    n_periods = phi.shape[0]
    history = np.zeros((n_periods, acceleration.size))
    for j in range(n_periods):
        u = 0.0
        v = 0.0
        history[j, 0] = acceleration[0]  # as _oscillator_peaks: the first sample counts as the ground's
        for k in range(acceleration.size - 1):
            u, v = _oscillator_step(phi, gamma0, gamma1, j, acceleration[k], acceleration[k + 1], u, v)
            history[j, k + 1] = -2.0 * damping * omega[j] * v - omega[j] ** 2 * u
    return history


def _oscillator_arrays(periods, damping, dt):
    """The recurrence coefficients of every period, stacked: phi (m, 2, 2), gamma0 and gamma1 (m, 2)."""
    coefficients = [oscillator_coefficients(float(period), float(damping), float(dt)) for period in periods]
    return (np.array([c[0] for c in coefficients]), np.array([c[1] for c in coefficients]),
            np.array([c[2] for c in coefficients]))


def oscillator_accelerations(acceleration, dt, periods, damping=0.05) -> np.ndarray:
    """Absolute acceleration histories of linear oscillators under ``acceleration`` [m/s^2], (m, n).

    The same exact recurrence as ``response_spectrum`` (its peaks are the rows' peaks); linear in the ground
    motion, so the histories of two components rotate as the components do (``rotated``).
    """
    periods = np.atleast_1d(np.asarray(periods, dtype=float))
    phi, gamma0, gamma1 = _oscillator_arrays(periods, damping, dt)
    return _oscillator_histories(np.ascontiguousarray(acceleration, dtype=np.float64), phi, gamma0, gamma1,
                                 2.0 * np.pi / periods, float(damping))


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
    phi, gamma0, gamma1 = _oscillator_arrays(periods, damping, dt)
    omega = 2.0 * np.pi / periods
    sd, sa = _oscillator_peaks(np.ascontiguousarray(acceleration, dtype=np.float64), phi, gamma0,
                               gamma1, omega, float(damping))
    return {"period": periods, "sa": sa, "sd": sd, "psa": omega**2 * sd}


def spectral_acceleration(acceleration, dt, period, damping=0.05) -> float:
    """Sa(T, zeta) [m/s^2]: peak absolute acceleration of the oscillator of period ``period``."""
    return float(response_spectrum(acceleration, dt, [period], damping)["sa"][0])


RECORD_PERIODS = (0.2, 1.0, 2.0)
"""Periods [s] at which a record's table gives the measures defined at one period (Sa)."""


def record_columns(sa_periods=RECORD_PERIODS) -> dict[str, tuple[Measure, dict]]:
    """The columns of a record's measures: ``name_unit`` (``pga_m_s2``, ``sa_1s_m_s2``) -> (measure, options).

    Every registered measure that needs no block: one defined at the study's period (Sa) at each of
    ``sa_periods`` [s]; one over a period range (AvgSa) or of a block (PGA/(g tan alpha)) is left out. The
    registry is the only list: a measure an installed package adds has its column too.
    """
    columns = {}
    for name, measure in MEASURES.items():
        if measure.per_block or _fields(measure.label) - {"period", "damping"}:
            continue
        unit = measure.si_unit.replace("/", "_").replace("^", "")
        suffix = f"_{unit}" if unit != "1" else ""
        if measure.uses_period:
            columns.update({f"{name}_{period:g}s{suffix}": (measure, {"period": float(period)})
                            for period in sa_periods})
        else:
            columns[f"{name}{suffix}"] = (measure, {})
    return columns


def intensity_measures(acceleration, dt, sa_periods=RECORD_PERIODS) -> dict:
    """Every measure of one record that needs no block (``record_columns``), SI values keyed ``name_unit``."""
    return {key: measure(acceleration, dt, **options) for key, (measure, options) in record_columns(sa_periods).items()}


AVGSA_PERIODS = 10
"""Periods of AvgSa, log-spaced over its range."""


def average_spectral_acceleration(acceleration, dt, low, high, damping=0.05, count=AVGSA_PERIODS) -> float:
    """AvgSa [m/s^2]: geometric mean of Sa at ``count`` log-spaced periods from ``low`` to ``high`` [s].

    After Eads et al. (2015) and Kohrangi et al. (2016).
    """
    if not 0 < low < high:
        raise ValueError(f"AvgSa period range {low}..{high} s; need 0 < low < high")
    spectrum = response_spectrum(acceleration, dt, np.geomspace(low, high, count), damping)
    return float(np.exp(np.mean(np.log(spectrum["sa"]))))


def velocity_pulse(acceleration, dt) -> tuple[float, float, float]:
    """The dominant velocity pulse: (period Tp [s], velocity v_p [m/s], acceleration a_p [m/s^2]).

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


# ------------------------------------------------------------------ two horizontal components: RotD50, RotD100

ROTATION_ANGLES = np.arange(180.0)
"""Rotation angles of RotD50 and RotD100 [deg]: 0 to 179, 1 deg apart (Boore 2010)."""

_ROTATION_CHUNK = 2_000_000
"""Most rotated samples held at once (angles x samples), to bound the memory of long records."""


def rotated_peaks(first, second, angles=ROTATION_ANGLES) -> np.ndarray:
    """Peak over time of |first cos(theta) + second sin(theta)| at each rotation angle theta.

    Parameters
    ----------
    first, second : array_like, shape (..., n)
        Histories of the two horizontal components (or of their linear responses), sampled alike.
    angles : array_like, shape (m,)
        Rotation angles [deg].

    Returns
    -------
    numpy.ndarray, shape (..., m)
        The peak of the rotated history at each angle [the histories' unit].
    """
    first, second = np.asarray(first, float), np.asarray(second, float)
    if first.shape != second.shape:
        raise ValueError(f"the two components have different shapes {first.shape} and {second.shape}; "
                         "cut them to the window they share first")
    radians = np.radians(np.asarray(angles, float))
    cos, sin = np.cos(radians), np.sin(radians)
    step = max(1, _ROTATION_CHUNK // max(1, first.shape[-1]))
    peaks = np.empty((*first.shape[:-1], radians.size))
    for start in range(0, radians.size, step):
        part = slice(start, start + step)
        rotated = cos[part, None] * first[..., None, :] + sin[part, None] * second[..., None, :]
        peaks[..., part] = np.max(np.abs(rotated), axis=-1)
    return peaks


def rotated(first, second, percentile=50.0, angles=ROTATION_ANGLES) -> np.ndarray:
    """RotD``percentile`` (Boore 2010) of two histories: that percentile of ``rotated_peaks`` over the angles.

    ``percentile`` 50 is RotD50 (the median, linear interpolation between the two middle angles' peaks), 100 is
    RotD100 (the largest). Returns shape (...,) for histories (..., n).
    """
    return np.percentile(rotated_peaks(first, second, angles), percentile, axis=-1)


# ------------------------------------------------------------------ the measure registry

MeasureFunction = Callable[[np.ndarray, float, "Block | None", dict], float]
"""``function(acceleration [m/s^2], dt [s], block, options) -> value [si_unit]``."""


@dataclass(frozen=True)
class Measure:
    """One intensity measure: the one place every stage reads it from.

    ``function(acceleration [m/s^2], dt [s], block, options) -> value [si_unit]``; ``block`` is a
    ``rockfrag.blocks.Block`` for per-block measures (ignored otherwise); ``options`` holds the
    study's ``period`` [s], ``damping`` [-] and ``period_range`` ((low, high) [s] or None).
    ``long_name`` and ``label`` are templates filled with the options by ``describe`` and
    ``short_label`` (fields ``period``, ``damping``, ``low``, ``high``): the long name for netCDF
    metadata, the label for axes, tables and messages ("Sa({period:g} s)").
    ``display_factor`` is the SI value of one display unit (``STANDARD_GRAVITY`` for g).
    ``pelicun_demand`` is (pelicun demand type, pelicun unit), None when pelicun has no such demand;
    ``openquake_imt`` the intensity measure type as OpenQuake and the USGS hazard service write it
    ("SA(T)" for a period-dependent one), and ``openquake_factor`` the display units per unit of
    their files (PGV comes in cm/s: 0.01).
    ``scaling_exponent`` n: IM(lambda a) = lambda^n IM(a); a study scales records to measures with
    n = 1 only, and a record's capacity re-expressed in the measure is scale x IM (n = 1).
    ``histories(acceleration, dt, block, options) -> (n_channel, n)``: the histories, linear in the ground
    motion, whose peaks make the measure (its value is the geometric mean over the channels of their peaks:
    one channel for PGA, the oscillator's absolute acceleration at each period for AvgSa); None where the
    measure has no rotated form (``rotd``).
    ``words``: how a page names the measure where its label is a symbol or a formula ("pulse period" for Tp);
    None: the label. ``normalises``: the measure this one divides by a constant of the block (PGA/(g tan alpha)
    divides "pga"): within a block the two rank alike, and the efficiency page draws one of them.
    """

    name: str
    function: MeasureFunction
    si_unit: str
    display_unit: str
    display_factor: float
    long_name: str
    label: str
    pelicun_demand: tuple[str, str] | None = None
    openquake_imt: str | None = None
    openquake_factor: float = 1.0
    per_block: bool = False
    scaling_exponent: float = 1.0
    histories: Callable | None = None
    words: str | None = None
    normalises: str | None = None

    @property
    def rotatable(self) -> bool:
        """Whether the measure has RotD50/RotD100 forms for a pair of horizontal components (``rotd``)."""
        return self.histories is not None

    @property
    def scalable(self) -> bool:
        """Whether a study can scale records to this measure (scaling exponent 1)."""
        return self.scaling_exponent == 1.0

    @property
    def uses_period(self) -> bool:
        """Whether the measure is defined at the study's one oscillator ``period`` (Sa(T))."""
        return "period" in _fields(self.label)

    def __call__(self, acceleration, dt, block=None, **options) -> float:
        """The measure of one record.

        Parameters
        ----------
        acceleration : array_like
            Ground acceleration [m/s^2].
        dt : float
            Time step [s].
        block : rockfrag.blocks.Block, optional
            The block, required for a per-block measure (ignored otherwise).
        **options
            The study's ``period`` [s], ``damping`` [-] and ``period_range`` ((low, high) [s]).

        Returns
        -------
        float
            The value in the measure's ``si_unit``.
        """
        if self.per_block and block is None:
            raise ValueError(f"measure {self.name!r} is defined per block; pass the block")
        return float(self.function(acceleration, dt, block, _options(options)))

    def rotd(self, first, second, dt, percentile=50.0, block=None, **options) -> float:
        """RotD``percentile`` of the measure for a pair of horizontal components (Boore 2010).

        Parameters
        ----------
        first, second : array_like
            The two horizontal components' accelerations [m/s^2], sampled alike over one window.
        dt : float
            Time step [s].
        percentile : float
            50 for RotD50 (the median over rotation angles 0-179 deg), 100 for RotD100 (the largest).
        block : rockfrag.blocks.Block, optional
            The block, required for a per-block measure.
        **options
            The study's ``period`` [s], ``damping`` [-] and ``period_range`` ((low, high) [s]).

        Returns
        -------
        float
            The value in the measure's ``si_unit``: for each channel of ``histories`` the percentile over the
            angles of the rotated pair's peak, then their geometric mean (AvgSa: of RotD50 Sa at its periods).

        Raises
        ------
        ValueError
            The measure has no rotated form, a per-block measure has no block, or the components differ in
            length.
        """
        if self.histories is None:
            raise ValueError(f"measure {self.name!r} has no RotD form (it is defined per component)")
        if self.per_block and block is None:
            raise ValueError(f"measure {self.name!r} is defined per block; pass the block")
        options = _options(options)
        first, second = np.asarray(first, float), np.asarray(second, float)
        if first.shape != second.shape:
            raise ValueError(f"the two components have {first.size} and {second.size} samples; RotD needs one "
                             "window")
        per_channel = rotated(self.histories(first, dt, block, options),
                              self.histories(second, dt, block, options), percentile)
        return float(per_channel[0]) if per_channel.size == 1 else float(np.exp(np.mean(np.log(per_channel))))

    def cf_units(self, display: bool = True) -> str:
        """The measure's ``units`` attribute in result files, as UDUNITS parses it.

        The display unit ("9.80665 m s-2" for g, "m s-1" for m/s; see ``udunits``) or, with
        ``display=False``, the SI unit.
        """
        return udunits(self.si_unit, self.display_factor if display else 1.0)

    def describe(self, **options) -> str:
        """Long name with the study's options filled in."""
        return _fill(self.long_name, options)

    def short_label(self, **options) -> str:
        """Label with the study's options filled in: "PGA", "Sa(1 s)", "AvgSa(0.2-3 s)"."""
        return _fill(self.label, options)

    def label_in(self, described: str) -> str | None:
        """The label with the options read back from ``described``, a text ``describe`` wrote.

        ``described`` is, for example, the ``long_name`` of a cube's ``im_level``: "Sa(0.5 s)" from
        "intensity level: spectral acceleration Sa(0.5 s, 5%)". None when ``described`` does not hold
        this measure's long name.
        """
        pattern, named = "", set()
        for literal, field, _, _ in string.Formatter().parse(self.long_name):
            pattern += re.escape(literal)
            if field is not None:
                pattern += f"(?P<{field}>[^()]+?)" if field not in named else "[^()]+?"
                named.add(field)
        found = re.search(pattern, described)
        if found is None:
            return None
        try:
            values = {key: float(found.group(key)) for key in _fields(self.label)}
        except (IndexError, ValueError):
            return None
        return self.label.format(**values)


def _fields(template: str) -> set[str]:
    return {field for _, field, _, _ in string.Formatter().parse(template) if field}


def _options(options) -> dict:
    return {"period": 1.0, "damping": 0.05, "period_range": None, **options}


def _fill(template: str, options) -> str:
    options = _options(options)
    low, high = avgsa_range(options)
    return template.format(period=options["period"], damping=options["damping"], low=low, high=high)


def avgsa_range(options) -> tuple[float, float]:
    """AvgSa period range [s]: the study's ``period_range``, else 0.2 T .. 3 T around ``period``."""
    given = options.get("period_range")
    if given:
        return float(given[0]), float(given[1])
    return 0.2 * options["period"], 3.0 * options["period"]


MEASURES: Registry = Registry(GROUPS["measures"], Measure)
"""Registered measures by name (``register_measure``, ``define_measure``), in registration order; then those of
the installed packages (entry-point group ``rockfrag.measures``, rockfrag.plugins)."""


def register_measure(measure: Measure) -> Measure:
    """Add ``measure`` to ``MEASURES`` (replacing one of the same name) and return it."""
    MEASURES[measure.name] = measure
    return measure


def define_measure(name: str, *, si_unit: str, long_name: str, label: str, display_unit: str | None = None,
                   display_factor: float = 1.0, pelicun_demand: tuple[str, str] | None = None,
                   openquake_imt: str | None = None, openquake_factor: float = 1.0, per_block: bool = False,
                   scaling_exponent: float = 1.0, histories: Callable | None = None, words: str | None = None,
                   normalises: str | None = None) -> Callable[[MeasureFunction], MeasureFunction]:
    """Decorator: register the decorated ``function(acceleration, dt, block, options)`` as measure ``name``.

    Parameters
    ----------
    name : str
        The measure's name in study files (``[intensity] measure``) and result files.
    si_unit, display_unit : str
        Unit of the function's value, and of levels and tables (default: the SI unit).
    display_factor : float
        SI value of one display unit (``STANDARD_GRAVITY`` for g).
    long_name, label : str
        Templates (fields ``period``, ``damping``, ``low``, ``high``) of the netCDF long name and of the
        short label for axes and messages.
    pelicun_demand, openquake_imt, openquake_factor, per_block, scaling_exponent, histories, words, normalises
        See ``Measure``.

    Returns
    -------
    callable
        The decorator; it returns the function unchanged.
    """
    def register(function: MeasureFunction) -> MeasureFunction:
        register_measure(Measure(name, function, si_unit, si_unit if display_unit is None else display_unit,
                                 display_factor, long_name, label, pelicun_demand, openquake_imt,
                                 openquake_factor, per_block, scaling_exponent, histories, words, normalises))
        return function

    return register


def scaling_measures() -> tuple[str, ...]:
    """Names of the registered measures a study can scale records to (scaling exponent 1)."""
    return tuple(name for name, measure in MEASURES.items() if measure.scalable)


def display_units(name: str) -> tuple[str, float]:
    """(display unit, SI value of one display unit) of a measure a study can scale to; ("", 1.0) otherwise."""
    measure = MEASURES.get(name)
    if measure is None or not measure.scalable:
        return "", 1.0
    return measure.display_unit, measure.display_factor


def short_label(name: str, described: str = "") -> str:
    """Short label of measure ``name`` for axes and text ("PGA", "Sa(1 s)").

    Its options are read from ``described`` (see ``Measure.label_in``). For an unknown or empty name:
    the label of the first registered measure whose long name ``described`` holds; else the upper-case
    name, or "intensity".
    """
    measure = MEASURES.get(name)
    for candidate in [measure] if measure is not None else MEASURES.values():
        label = candidate.label_in(described)
        if label is not None:
            return label
    if measure is not None and not _fields(measure.label):
        return measure.label
    return name.upper() or "intensity"


# ------------------------------------------------------------------ units in result files
#
# Result files store every quantity of an intensity measure's SI unit in the display unit of the
# registered measures of that unit (accelerations in multiples of g, velocities in m/s), the same in
# every variable of a file, and write it as UDUNITS parses it: UDUNITS (netCDF, CF, cf-units, xarray's
# unit-aware tools) reads "g" as grams, so g is "9.80665 m s-2".

_UDUNITS_SPELLING = {"m/s^2": "m s-2", "m/s**2": "m s-2", "m/s2": "m s-2", "m/s": "m s-1", "N/m": "N m-1",
                     "1/yr": "yr-1"}
"""Our SI spellings (the registry's ``si_unit``) that UDUNITS writes differently."""


def udunits(unit: str, factor: float = 1.0) -> str:
    """``unit`` scaled by ``factor``, as a UDUNITS ``units`` string.

    ``unit`` is an SI unit as the registry spells it ("m/s^2", "m/s", "1", "s", ...):
    ``udunits("m/s^2") == "m s-2"``, ``udunits("m/s^2", STANDARD_GRAVITY) == "9.80665 m s-2"`` (g),
    ``udunits("1", 2.0) == "2"``.
    """
    base = _UDUNITS_SPELLING.get(unit, unit)
    if factor == 1.0:
        return base
    return f"{factor:.10g}" if base == "1" else f"{factor:.10g} {base}"


def file_units(si_unit: str) -> str:
    """The ``units`` of a quantity of SI unit ``si_unit`` in result files.

    The display unit of the first registered measure of that SI unit ("9.80665 m s-2" for any
    acceleration: record PGAs, levels, uplift thresholds), else the SI unit (``udunits``).
    """
    for measure in MEASURES.values():
        if measure.si_unit == si_unit:
            return measure.cf_units(display=True)
    return udunits(si_unit)


def parse_units(units: str) -> tuple[float, str] | None:
    """(SI value of one unit, SI unit in UDUNITS spelling) of an intensity-like ``units`` attribute.

    "9.80665 m s-2" -> (9.80665, "m s-2"), "m/s^2" -> (1.0, "m s-2"), "m s-1" -> (1.0, "m s-1"),
    "1" -> (1.0, "1"); "g" (files written before the UDUNITS spellings, where it meant standard gravity)
    -> (9.80665, "m s-2"). None for anything else (an empty string included).
    """
    text = str(units).strip()
    if not text:
        return None
    if text == "g":
        return STANDARD_GRAVITY, "m s-2"
    number, _, rest = text.partition(" ")
    try:
        factor = float(number)
    except ValueError:
        factor, rest = 1.0, text
    rest = rest.strip() or "1"
    base = _UDUNITS_SPELLING.get(rest, rest)
    if base not in {udunits(measure.si_unit) for measure in MEASURES.values()}:
        return None
    return factor, base


def convert_units(values, units: str, to: str):
    """``values`` given in ``units`` expressed in ``to`` (both forms ``parse_units`` reads).

    Raises
    ------
    ValueError
        When either is not such a unit or they measure different quantities.
    """
    source, target = parse_units(units), parse_units(to)
    if source is None or target is None or source[1] != target[1]:
        raise ValueError(f"cannot convert intensity values from units {units!r} to {to!r}")
    if source[0] == target[0]:
        return values
    return np.asarray(values, float) * (source[0] / target[0])


def unit_label(units: str) -> str:
    """The unit as tables and axes show it.

    The registered display or SI unit whose ``units`` string this is ("9.80665 m s-2" -> "g",
    "m s-1" -> "m/s", "m s-2" -> "m/s^2"); else ``units`` unchanged.
    """
    parsed = parse_units(units)
    if parsed is None:
        return str(units)
    for measure in MEASURES.values():
        if parse_units(measure.cf_units(display=True)) == parsed:
            return measure.display_unit
        if parse_units(measure.cf_units(display=False)) == parsed:
            return measure.si_unit
    return str(units)


def _ground_acceleration(acceleration, dt, block, options):
    return np.asarray(acceleration, float)[None, :]


def _ground_velocity(acceleration, dt, block, options):
    return integrate(np.asarray(acceleration, float), dt)[0][None, :]


def _oscillator_at_period(acceleration, dt, block, options):
    return oscillator_accelerations(acceleration, dt, [options["period"]], options["damping"])


def _oscillators_over_range(acceleration, dt, block, options):
    return oscillator_accelerations(acceleration, dt, np.geomspace(*avgsa_range(options), AVGSA_PERIODS),
                                    options["damping"])


def _acceleration_over_uplift(acceleration, dt, block, options):
    return _ground_acceleration(acceleration, dt, block, options) / block.uplift_acceleration()


def _rocking_velocity(acceleration, dt, block, options):
    return block.p() * _ground_velocity(acceleration, dt, block, options) / block.uplift_acceleration()


@define_measure("pga", si_unit="m/s^2", display_unit="g", display_factor=STANDARD_GRAVITY,
                long_name="peak ground acceleration", label="PGA",
                pelicun_demand=("Peak Ground Acceleration", "g"), openquake_imt="PGA", histories=_ground_acceleration)
def _pga(acceleration, dt, block, options):
    return pga(acceleration)


@define_measure("pgv", si_unit="m/s", long_name="peak ground velocity", label="PGV",
                pelicun_demand=("Peak Ground Velocity", "mps"), openquake_imt="PGV", openquake_factor=0.01,
                histories=_ground_velocity)
def _pgv(acceleration, dt, block, options):
    return pgv(acceleration, dt)


@define_measure("sa", si_unit="m/s^2", display_unit="g", display_factor=STANDARD_GRAVITY,
                long_name="spectral acceleration Sa({period:g} s, {damping:.0%})", label="Sa({period:g} s)",
                pelicun_demand=("Spectral Acceleration", "g"), openquake_imt="SA(T)", histories=_oscillator_at_period)
def _sa(acceleration, dt, block, options):
    return spectral_acceleration(acceleration, dt, options["period"], options["damping"])


@define_measure("avgsa", si_unit="m/s^2", display_unit="g", display_factor=STANDARD_GRAVITY,
                long_name="average spectral acceleration AvgSa({low:g}-{high:g} s, {damping:.0%})",
                label="AvgSa({low:g}-{high:g} s)", histories=_oscillators_over_range)
def _avgsa(acceleration, dt, block, options):
    return average_spectral_acceleration(acceleration, dt, *avgsa_range(options), damping=options["damping"])


@define_measure("pga_ratio", si_unit="1", long_name="PGA over the block's uplift acceleration, PGA/(g tan alpha)",
                label="PGA/(g tan alpha)", per_block=True, histories=_acceleration_over_uplift,
                words="PGA/(g·tanα)", normalises="pga")
def _rocking_pga(acceleration, dt, block, options):
    return pga(acceleration) / block.uplift_acceleration()


@define_measure("pgv_ratio", si_unit="1", long_name="p PGV/(g tan alpha), p = sqrt(3g/4R) (Makris & Vassiliou)",
                label="p PGV/(g tan alpha)", per_block=True, histories=_rocking_velocity,
                words="PGV·p/(g·tanα)", normalises="pgv")
def _rocking_pgv(acceleration, dt, block, options):
    return block.p() * pgv(acceleration, dt) / block.uplift_acceleration()


@define_measure("pulse_amplitude", si_unit="m/s^2", display_unit="g", display_factor=STANDARD_GRAVITY,
                long_name="acceleration amplitude a_p = 2 pi PGV/Tp of the dominant velocity pulse", label="a_p",
                words="pulse acceleration")
def _pulse_amplitude(acceleration, dt, block, options):
    return velocity_pulse(acceleration, dt)[2]


@define_measure("pulse_period", si_unit="s",
                long_name="period Tp of the dominant velocity pulse (a record property: does not scale)",
                label="Tp", scaling_exponent=0.0, words="pulse period")
def _pulse_period(acceleration, dt, block, options):
    return velocity_pulse(acceleration, dt)[0]


@define_measure("pgd", si_unit="m", long_name="peak ground displacement", label="PGD")
def _pgd(acceleration, dt, block, options):
    return pgd(acceleration, dt)


@define_measure("arias", si_unit="m/s", long_name="Arias intensity", label="Ia", scaling_exponent=2.0,
                words="Arias intensity")
def _arias(acceleration, dt, block, options):
    return arias_intensity(acceleration, dt)


@define_measure("cav", si_unit="m/s", long_name="cumulative absolute velocity", label="CAV")
def _cav(acceleration, dt, block, options):
    return cav(acceleration, dt)


@define_measure("d5_95", si_unit="s", long_name="significant duration D5-95 (a record property: does not scale)",
                label="D5-95", scaling_exponent=0.0)
def _significant_duration(acceleration, dt, block, options):
    return significant_duration(acceleration, dt)
