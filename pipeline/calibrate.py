"""rockfrag.calibrate - fit a foundation model's interface stiffness k and damping ratio xi to a reference.

Input : a reference rotation history (a table of time and rotation, e.g. from LS-DYNA or a shake-table
        test; units from the header or flags), the ground motion that produced it [m/s^2] sampled at
        dt [s], the block and a model that needs a foundation (``ssi`` by default; any registered model
        whose ``needs_foundation`` is true, solver keywords such as winkler's ``bed=`` pass through).
Output: ``CalibrationResult``: the best grid point, the search's optimum over the whole reference and the
        estimate (k [N/m], xi [-]) with its confidence intervals (default 90 %) and the window that decided
        them, or "not identifiable from this reference" with the range of the fits that explain it equally;
        the paper's eq. 17 Pearson correlation between reference and model rotation (model interpolated onto
        the reference's own time steps), RMS error [rad], peak-angle error, the implied A/H of eq. 19 [m],
        the correlation surface of the grid; JSON/CSV and PNG writers. ``fit_intervals``: the profile
        intervals of one window around a given fit.

Why not a grid and one local search: the correlation surface of a rocking response is a needle field.
A few impacts after uplift, 1 % in k or 0.0005 in xi moves the impacts enough to drop eq. 17 from 1.0
to 0.75-0.9, so a grid finds the truth only by luck and a local search from a grid point stays where
it started. The search therefore grows the fitted time window (continuation in time):

1. One compiled batch call runs the coarse grid (``n_k`` log-spaced k times ``n_xi`` xi) over the whole
   reference; the objective of every grid point on every window is then a cheap array operation.
2. Windows end just after successive large peaks of the (smoothed) reference, then the whole record.
   On a short window the surface is smooth and its minimum is near the truth; each longer window
   sharpens the minimum, and the previous optimum lies inside its basin.
3. Per window, every candidate (the three survivors of the previous window plus the two best distinct
   basins of the grid on this window) is polished by a local batch grid (3 x 3 around survivors, 5 x 5
   around grid seeds; one compiled call) and a bounded Nelder-Mead search (scipy) in (log k, xi).
4. A window whose best objective doubles and exceeds three noise floors (the objective the true
   parameters would score, from the noise estimated in the reference) lost the basin: it is retried
   after an intermediate window.
5. The last window is the whole reference: the survivors are polished, a grid basin only if it scores
   better; the winner has the lowest objective there.

The objective is robust to noise and amplitude errors: (1 - correlation) + 0.5 ln(sigma_model /
sigma_reference)^2 on both signals low-passed at ``smoothing_hz`` (default 10 Hz, zero phase). The
correlation reported is the paper's eq. 17 on the unsmoothed reference at its own time steps.

The intervals (issue 34: profile-likelihood intervals of the whole record were point-like on chaotic
references and contained the truth in 0 of 14 cases). A long rocking record is chaotic in k and xi: past a
horizon a fit 0.05 % from the truth in k misses the reference by far more than its noise, and the set of
(k, xi) that reproduce it is a field of needles no search finds and no local curvature describes. The
likelihood is usable only on the windows [0, T] where the fit explains the reference at its noise level and
is regular at the interval's scale; the data say which (``_decide``; block comments "intervals" and "windows"):

1. Goodness of fit per window: the noise (variance, autocorrelation time) is the residual of the quiet start
   (before the reference reaches 20 % of its peak), at least ``NOISE_FLOOR`` (0.1 %) of the peak. A window
   is accepted when its least-squares fit (Gauss-Newton from the search's points) leaves no more than the
   chi^2 99.9 % quantile of that noise, in all and in the samples it adds. The quiet start itself is scanned
   over the whole search range first (a base fit in a wrong basin would read its misfit as noise). Where longer
   windows are not explained, the first of them is scanned for other basins and they are fitted again from
   those (the search may have tracked the wrong basin).
2. Regularity: the profile likelihood of the longest accepted window, else of the next shorter one: the
   response smooth at the interval's scale (its Jacobian at a quarter of the step within 30 %), the profiles
   rising monotonically and leaving the region once. That window decides; its least-squares point is the
   estimate, whatever the longer windows (the chaotic tail) would pull it to.
3. The decisive window's likelihood over the whole search range (a 121 x 21 scan, its basins polished):
   a better basin takes over; other basins that fit as well make the reference "not identifiable", with the
   range of every fit that explains the window as well as the estimate.
4. The profile deviance that bounds the intervals: chi^2_1, or the parametric bootstrap's quantile where
   larger (40 replicates of the fit plus AR(1) noise with the residuals' variance and lag-1 correlation,
   refitted by batched Gauss-Newton). The intervals are the union of the decisive window's and of the shorter
   regular windows' back to one whose interval is twice as wide: near the horizon the likelihood splits into
   narrow basins that fit equally well, and the interval of one of them shrinks from window to window far faster
   than information accrues.
5. Agreement: the estimate must explain every shorter accepted window (chi^2_2 99.9 %) and the two windows'
   intervals must meet; else "not identifiable", with the range of the fits of the windows that disagree.
6. No regular window at all (a response chaotic from the start of its rocking, e.g. many small impacts): the
   region is read off the likelihood itself on the shortest accepted window, without local curvature: every
   point of its 121 x 21 scan within a deviance limit of the scan's best, one scan step beyond, the limit a
   parametric bootstrap of that reading scored on the scan's grid (``_direct_region``).
7. Intervals that are still the whole search range in k or xi (a decisive window that ends soon after the rocking
   starts, at large or coloured noise, with other basins that explain it equally): the longest accepted window's
   region is read off the likelihood the same way (its rocking bounds what the short window did not).

Why not the alternatives alone: profile likelihood over the whole record is the old method; a parametric
bootstrap of the whole calibration (resimulate, search again) costs hundreds of searches of ~2,000
simulations and inherits each search's basin errors; the set of fits within the noise's tolerance over the
whole range needs a noise estimate that does not come from the fit (here the quiet start) and a search fine
enough to find needles (here a scan of the one window where they are wide). Each is used where it holds.
Coverage, measured on 120 references by ``benchmarks/calibration_coverage.py``: docs/theory/calibration.md.
"""

from __future__ import annotations

import json
import math
import re
import time as clock
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike
from scipy.optimize import minimize
from scipy.signal import butter, find_peaks, sosfiltfilt

from rockfrag.blocks import Block
from rockfrag.errors import ConfigError, PipelineError, RecordError
from rockfrag.models import SolverOptions, get_model, simulate_histories
from rockfrag.outputs import atomic_path
from rockfrag.records.text import bracketed_units, read_columns
from rockfrag.validation import Interval, Number, Table

_MICRO = ("us", "\u00b5s", "\u03bcs", "microsecond", "microseconds", "usec")
TIME_UNITS = {**{name: 1.0 for name in ("s", "sec", "secs", "second", "seconds")},
              **{name: 1e-3 for name in ("ms", "msec", "millisecond", "milliseconds")},
              **{name: 1e-6 for name in _MICRO},
              **{name: 60.0 for name in ("min", "mins", "minute", "minutes")}}
ANGLE_UNITS = {**{name: 1.0 for name in ("rad", "rads", "radian", "radians")},
               **{name: 1e-3 for name in ("mrad", "milliradian", "milliradians")},
               **{name: math.pi / 180.0 for name in ("deg", "degs", "degree", "degrees", "\u00b0")}}
DEFAULT_TIME_UNIT = "s"
DEFAULT_ANGLE_UNIT = "rad"
MAX_REFERENCE_ROWS = 5_000_000  # a table this long is a unit or export mistake, not a rocking test

SMOOTHING_HZ = 10.0  # low-pass of the search objective: keeps rocking, drops sensor/solver noise
AMPLITUDE_WEIGHT = 0.5  # weight of ln(sigma_model/sigma_reference)^2 against 1 - correlation
PEAK_FRACTION = 0.2  # window ends follow peaks of |reference| above this fraction of the largest
MAX_WINDOWS = 10
SURVIVORS = 3  # candidates carried from one window to the next
GRID_SEEDS = 2  # fresh candidates taken from the coarse grid at each window
LOCAL_OFFSETS = (-1.0, -0.5, 0.0, 0.5, 1.0)  # local batch grid around fresh seeds, in current steps
SURVIVOR_OFFSETS = (-0.5, 0.0, 0.5)  # local batch grid around survivors of the previous window
FLOOR_SLACK = 0.002  # objective allowed above three noise floors before a window counts as lost
MAX_EXTRA_WINDOWS = 12
NELDER_MEAD_EVALUATIONS = 30
MIN_STEP = 0.002  # smallest local step, as a fraction of the log k and xi ranges


@dataclass
class Reference:
    """A reference rotation history in SI units, with where it came from."""

    time: np.ndarray  # [s]
    rotation: np.ndarray  # [rad]
    path: str = ""
    time_column: str = "time"
    rotation_column: str = "rotation"
    time_unit: str = DEFAULT_TIME_UNIT
    angle_unit: str = DEFAULT_ANGLE_UNIT
    time_unit_source: str = "flag"  # "flag", "header" or "assumed"
    angle_unit_source: str = "flag"

    def __iter__(self):  # unpacks as (time, rotation)
        return iter((self.time, self.rotation))

    def describe_units(self) -> str:
        """Where each column's unit came from, e.g. ``time 'time [ms]' in ms (from the header)``."""

        def part(column, unit, source):
            origin = {"flag": "from the command line", "header": "from the header",
                      "assumed": "assumed: no unit in the header"}[source]
            return f"{column!r} in {unit} ({origin})"

        return (f"reference {self.path}: time {part(self.time_column, self.time_unit, self.time_unit_source)}, "
                f"rotation {part(self.rotation_column, self.angle_unit, self.angle_unit_source)}")


@dataclass
class CalibrationResult:
    """The outcome of ``calibrate``: the fitted foundation parameters, their quality and the search.

    Attributes
    ----------
    k_grid, xi_grid, correlation_grid : float
        The coarse grid's best interface stiffness [N/m], damping ratio [-] and eq. 17 correlation [-].
    k, xi, correlation : float
        The estimate: interface stiffness [N/m], damping ratio [-] (with intervals: the least-squares point of
        the decisive window) and its eq. 17 correlation over the whole reference [-].
    rms_error : float
        RMS difference of the fitted and the reference rotation [rad].
    peak_error : float
        (peak_model - peak_reference) / peak_reference [-].
    peak_reference, peak_model : float
        Largest |rotation| of the reference and of the fit [rad].
    area_over_depth : float or None
        A/H [m] from eq. 19 solved for the fitted k, when the soil shear modulus was given.
    soil_shear_modulus, block_modulus : float or None, float
        G_s and E_b [Pa] used for ``area_over_depth``.
    model, bed : str, str or None
        The calibrated model, and its bed type (None for models without a bed).
    objective : float
        The search objective at the fit (1 - correlation plus the amplitude term).
    n_simulations, n_windows : int
        Simulations run and time windows searched.
    seconds : float
        Wall time of the search [s].
    surface_k, surface_xi, surface : list
        The coarse grid's k [N/m] and xi [-] values and its eq. 17 correlations, (n_k, n_xi).
    confidence : float or None
        Two-sided level of the intervals [-]; None: not computed (``--grid-only``, or not asked).
    k_low, k_high, xi_low, xi_high : float or None
        Profile-likelihood confidence interval of k [N/m] and of xi [-] (each marginal); xi's are None
        when xi was fixed.
    interval_method : str
        How the intervals were computed.
    noise_rms : float or None
        RMS residual at the likelihood's best point [rad]: the noise the intervals assume.
    autocorrelation_time : float or None
        Integrated autocorrelation time of the residuals [samples of the search grid]; 1 for white noise.
    interval_notes : list of str
        Bounds that are the search range's (the reference does not bound the parameter there), a fit
        outside its own likelihood region, strongly correlated residuals.
    interval_simulations : int
        Simulations the intervals took (included in ``n_simulations``).
    identifiable : bool or None
        False: "not identifiable from this reference": the intervals are the range of the fits that explain it
        equally (other basins, windows that disagree, or no window with a regular likelihood); None: not computed.
    decisive_window : float or None
        End [s] of the window whose fit and likelihood decided (None: none did).
    windows : list of dict
        Each window fitted: ``end`` [s], ``k`` [N/m], ``xi`` [-] of its least-squares point, ``accepted`` (its fit
        explains it at the noise level), ``regular`` (its likelihood's verdict, None if not profiled) and ``reason``.
    k_search, xi_search : float or None
        The search's optimum over the whole reference [N/m], [-] (the estimate without intervals).
    deviance_limits : dict
        The profile deviance that bounds the interval of ``k`` and of ``xi`` [-]: chi^2_1 at the confidence, or
        the parametric bootstrap's quantile where that is larger.
    profile_k, profile_k_deviance, profile_xi, profile_xi_deviance : list
        The profiles: k [N/m] and xi [-] values and the profile deviance D [-] at each.
    """

    k_grid: float
    xi_grid: float
    correlation_grid: float
    k: float
    xi: float
    correlation: float
    rms_error: float
    peak_error: float
    peak_reference: float
    peak_model: float
    area_over_depth: float | None
    soil_shear_modulus: float | None
    block_modulus: float
    model: str = "ssi"
    bed: str | None = None  # winkler's bed type (continuous | two-spring); None for models without a bed
    objective: float = math.nan
    n_simulations: int = 0
    n_windows: int = 0
    seconds: float = 0.0
    surface_k: list = field(repr=False, default_factory=list)
    surface_xi: list = field(repr=False, default_factory=list)
    surface: list = field(repr=False, default_factory=list)
    confidence: float | None = None
    k_low: float | None = None
    k_high: float | None = None
    xi_low: float | None = None
    xi_high: float | None = None
    interval_method: str = ""
    noise_rms: float | None = None
    autocorrelation_time: float | None = None
    interval_notes: list = field(default_factory=list)
    interval_simulations: int = 0
    identifiable: bool | None = None
    decisive_window: float | None = None
    windows: list = field(default_factory=list)
    k_search: float | None = None
    xi_search: float | None = None
    deviance_limits: dict = field(default_factory=dict)
    profile_k: list = field(repr=False, default_factory=list)
    profile_k_deviance: list = field(repr=False, default_factory=list)
    profile_xi: list = field(repr=False, default_factory=list)
    profile_xi_deviance: list = field(repr=False, default_factory=list)

    PLOTTED = ("surface_k", "surface_xi", "surface", "profile_k", "profile_k_deviance", "profile_xi",
               "profile_xi_deviance")
    """Fields drawn in the figures and left out of ``summary``."""

    def summary(self) -> dict:
        """The fields without the surface and profiles, plus a ``units`` table (what calibration.json holds)."""
        data = asdict(self)
        for key in self.PLOTTED:
            data.pop(key)
        data["units"] = {"k": "N/m", "xi": "1", "correlation": "1 (paper eq. 17)", "rms_error": "rad",
                         "peak_error": "1 (relative)", "area_over_depth": "m", "soil_shear_modulus": "Pa",
                         "block_modulus": "Pa", "seconds": "s", "confidence": "1 (two-sided)", "k_low": "N/m",
                         "k_high": "N/m", "xi_low": "1", "xi_high": "1", "noise_rms": "rad",
                         "autocorrelation_time": "samples", "decisive_window": "s", "k_search": "N/m",
                         "xi_search": "1", "windows": "end s, k N/m, xi 1"}
        return data

    def interval_lines(self) -> list[str]:
        """The intervals as printed by ``rockfrag calibrate`` (empty when not computed)."""
        if self.confidence is None or self.k_low is None:
            return []
        k = (f"k {self.k_low:.5g} to {self.k_high:.5g} N/m ({self.k_low / self.k - 1:+.2%} / "
             f"{self.k_high / self.k - 1:+.2%})")
        xi = (f", xi {self.xi_low:.5f} to {self.xi_high:.5f} ({self.xi_low - self.xi:+.5f} / "
              f"{self.xi_high - self.xi:+.5f})" if self.xi_low is not None else ", xi fixed")
        if self.identifiable is False:
            lines = [f"{NOT_IDENTIFIABLE} ({self.confidence:.0%}): the fits that explain it equally span {k}{xi}"]
        else:
            lines = [f"{self.confidence:.0%} confidence ({self.interval_method}): {k}{xi}"]
        lines += self.window_lines()
        if self.noise_rms is not None:
            share = f" ({self.noise_rms / self.peak_reference:.2%} of the peak)" if self.peak_reference else ""
            lines.append(f"  noise the intervals assume: RMS {self.noise_rms:.3g} rad{share}, residual autocorrelation "
                         f"time {self.autocorrelation_time:.2g} samples ({self.interval_simulations} simulations)")
        return lines + [f"  note: {note}" for note in self.interval_notes]

    def window_lines(self) -> list[str]:
        """Which window decided the estimate and the intervals, and why not a longer one."""
        if not self.windows:
            return []
        end = self.windows[-1]["end"]
        refused = next((w for w in self.windows if w["end"] > (self.decisive_window or 0.0) and w["reason"]), None)
        why = f" (0-{refused['end']:.2f} s: {refused['reason']})" if refused else ""
        if self.decisive_window is None:
            return [f"  no window decided: none of the {len(self.windows)} fitted has a regular likelihood{why}"]
        if DIRECT_METHOD in self.interval_method:
            return [f"  decided by the window 0-{self.decisive_window:.2f} s of 0-{end:.2f} s: its likelihood region "
                    f"is read off a scan of the search range (no regular window bounds k and xi inside it; see the "
                    f"notes){why}"]
        return [f"  decided by the window 0-{self.decisive_window:.2f} s of 0-{end:.2f} s: the longest whose fit "
                f"explains the reference at the noise level and whose likelihood is regular{why}"]


# ----------------------------------------------------------------------------------------- reading


def _unit_in_header(column, units, path, quantity):
    """(unit, found) from a header such as 'time [ms]', 'theta (deg)', 'rotation_rad', 'time s'."""
    name = str(column).strip()
    bracketed = bracketed_units(name)
    if bracketed:
        unit = bracketed[0]
        key = unit if unit in units else unit.lower()
        if key not in units:
            raise ConfigError(f"column {name!r}", f"{quantity} unit {unit!r} unknown; allowed: "
                              f"{', '.join(units)}", str(path))
        return key, True
    suffix = re.split(r"[_\s/-]+", name)[-1] if re.search(r"[_\s/-]", name) else ""
    key = suffix if suffix in units else suffix.lower()
    if key in units:
        return key, True
    return None, False


def _resolve_unit(flag, column, units, default, path, quantity):
    if flag is not None:
        key = flag if flag in units else str(flag).lower()
        if key not in units:
            raise ConfigError(f"{quantity}_unit", f"{flag!r}; allowed: {', '.join(units)}", str(path))
        return key, "flag"
    unit, found = _unit_in_header(column, units, path, quantity)
    return (unit, "header") if found else (default, "assumed")


REFERENCE_COLUMNS = "two columns (time, rotation)"
MIN_REFERENCE_ROWS = 10


def load_reference(path, time_unit=None, angle_unit=None) -> Reference:
    """Reference (time [s], rotation [rad]) from a text table: column 1 time, column 2 rotation.

    The table is read by ``rockfrag.records.text.read_columns`` (comma, semicolon, tab or space separated,
    ``#`` comments, header lines above the numbers; further columns are left out). Units come from the
    flags, else from the headers ('time [ms]', 'theta (deg)', 'rotation_rad'; see ``TIME_UNITS``/
    ``ANGLE_UNITS``), else s and rad are assumed (``Reference.describe_units`` says which). A text cell
    in either column is an error naming its line; an unknown unit is an error naming the column. The
    result unpacks as ``time, rotation``.
    """
    path = Path(path)
    if not path.is_file():
        raise PipelineError(f"{path}: reference file not found")
    table = read_columns(path, REFERENCE_COLUMNS, counts=(2,), extra=True, header_lines=1,
                         max_rows=MAX_REFERENCE_ROWS)
    if len(table.values) < MIN_REFERENCE_ROWS:
        raise RecordError(path, f"{len(table.values)} rows; expected {REFERENCE_COLUMNS} and at least "
                          f"{MIN_REFERENCE_ROWS} rows")
    time_name, angle_name = table.name(0), table.name(1)
    time_key, time_source = _resolve_unit(time_unit, time_name, TIME_UNITS, DEFAULT_TIME_UNIT, path, "time")
    angle_key, angle_source = _resolve_unit(angle_unit, angle_name, ANGLE_UNITS, DEFAULT_ANGLE_UNIT, path,
                                            "angle")
    time = table.time(0) * TIME_UNITS[time_key]
    rotation = table.values[:, 1] * ANGLE_UNITS[angle_key]
    return Reference(time=time, rotation=rotation, path=str(path), time_column=time_name,
                     rotation_column=angle_name, time_unit=time_key, angle_unit=angle_key,
                     time_unit_source=time_source, angle_unit_source=angle_source)


def check_reference(ref_time, ref_rotation, record_duration, dt, source="reference", time_unit="s"):
    """Refuse references that cannot belong to the record (usually a wrong time or angle unit)."""
    duration = float(ref_time[-1] - ref_time[0])
    hint = f" (time read in {time_unit}; check the unit or --time-unit)"
    if ref_time[0] < -dt or ref_time[0] > record_duration:
        raise ConfigError("time", f"the reference starts at {ref_time[0]:.4g} s; it must start within the "
                          f"record, 0 to {record_duration:.4g} s{hint}", source)
    if duration < 10 * dt:
        raise ConfigError("time", f"the reference lasts {duration:.3g} s, less than 10 record steps "
                          f"({10 * dt:.3g} s){hint}", source)
    if ref_time[-1] > 2 * record_duration + 60.0:
        raise ConfigError("time", f"the reference ends at {ref_time[-1]:.4g} s, far beyond the record's "
                          f"{record_duration:.4g} s{hint}", source)
    peak = float(np.max(np.abs(ref_rotation)))
    if not peak > 0 or np.ptp(ref_rotation) == 0:
        raise ConfigError("rotation", "the reference rotation is constant (all zero?); nothing to fit", source)
    if peak > math.pi:
        raise ConfigError("rotation", f"peak |rotation| {peak:.4g} rad exceeds pi (check the angle unit)", source)


# ----------------------------------------------------------------------------------------- objective


def correlation(reference, model):
    """Pearson correlation of paper eq. 17 (0 if either series is constant)."""
    reference = reference - reference.mean()
    model = model - model.mean()
    denominator = math.sqrt(float(np.sum(reference**2) * np.sum(model**2)))
    return float(np.sum(reference * model) / denominator) if denominator > 0 else 0.0


def _fill_overturned(theta, overturn_angle=math.pi / 2):
    """NaN after overturning -> +-overturn_angle with the sign of the last finite value."""
    missing = np.isnan(theta)
    if not missing.any():
        return theta
    index = np.where(~missing, np.arange(theta.shape[1]), 0)
    np.maximum.accumulate(index, axis=1, out=index)
    last = np.take_along_axis(theta, index, axis=1)
    filled = np.where(missing, np.copysign(overturn_angle, np.nan_to_num(last, nan=1.0)), theta)
    return filled


def _interpolate(theta, dt, times):
    """Histories sampled at i*dt [s] (rows) interpolated linearly onto ``times`` [s]."""
    position = np.clip(times / dt, 0.0, theta.shape[1] - 1.000001)
    lower = position.astype(np.int64)
    weight = position - lower
    return theta[:, lower] * (1.0 - weight) + theta[:, lower + 1] * weight


class _Objective:
    """Robust search objective on windows [0, T] of a uniformly resampled reference."""

    def __init__(self, times, reference, smoothing_hz):
        self.times = times
        self.reference = reference
        step = float(times[1] - times[0])
        nyquist = 0.5 / step
        self.sos = None
        if smoothing_hz and smoothing_hz < 0.8 * nyquist:
            self.sos = butter(4, smoothing_hz, fs=1.0 / step, output="sos")
        self.smoothed_reference = self.smooth(reference)
        self._centred_windows = {}  # n -> (the smoothed, centred reference over [0, n), its RMS)
        # white-noise variance left inside the pass band, estimated from what the low-pass removed
        self.noise_variance = 0.0
        if self.sos is not None:
            removed = float(np.var(reference - self.smoothed_reference))
            self.noise_variance = removed * smoothing_hz / (nyquist - smoothing_hz)

    def noise_floor(self, n):
        """Objective expected for the true parameters on the first n samples.

        That is 1 - correlation of a signal with itself plus the in-band noise: about half the
        noise-to-signal variance ratio.
        """
        signal_variance = float(np.var(self.smoothed_reference[:n]))
        return 0.5 * self.noise_variance / signal_variance if signal_variance > 0 else math.inf

    def smooth(self, values):
        if self.sos is None or values.shape[-1] < 30:
            return values
        return sosfiltfilt(self.sos, values, axis=-1)

    def _centred_window(self, n):
        """The reference over the first n samples, smoothed as the models are and centred, with its RMS.

        Each window's once: a search evaluates thousands of points on a handful of windows.
        """
        if n not in self._centred_windows:
            reference = self.smooth(self.reference[:n])
            reference = reference - reference.mean()
            self._centred_windows[n] = reference, math.sqrt(float(np.mean(reference**2)))
        return self._centred_windows[n]

    def __call__(self, model_on_times, n):
        """Objective per row of ``model_on_times`` (already on ``times``) over the first n samples."""
        reference, sigma_reference = self._centred_window(n)
        model = self.smooth(model_on_times[:, :n])
        model = model - model.mean(axis=1, keepdims=True)
        sigma_model = np.sqrt(np.mean(model**2, axis=1))
        with np.errstate(divide="ignore", invalid="ignore"):
            corr = np.where(sigma_model > 0, (model @ reference) / n / (sigma_model * sigma_reference), 0.0)
            amplitude = np.log(np.maximum(sigma_model, 1e-30) / sigma_reference) ** 2
        return (1.0 - corr) + AMPLITUDE_WEIGHT * np.minimum(amplitude, 100.0)


def _window_ends(smoothed_reference, step, max_windows=MAX_WINDOWS):
    """Sample counts of the fitting windows: just after large peaks of |reference|, then all."""
    size = smoothed_reference.size
    magnitude = np.abs(smoothed_reference - smoothed_reference[0])
    peaks, _ = find_peaks(magnitude, height=PEAK_FRACTION * magnitude.max())
    ends = [int(p + max(1, round(0.1 / step))) for p in peaks]
    ends = [e for e in ends if e < 0.95 * size]
    if len(ends) > max_windows - 1:
        picks = np.unique(np.round(np.geomspace(1, len(ends), max_windows - 1)).astype(int) - 1)
        ends = [ends[i] for i in picks]
    return sorted(set(ends)) + [size]


# ----------------------------------------------------------------------------------------- search


class _Search:
    """Simulations in normalised coordinates u = log-k fraction, v = xi fraction (both 0..1)."""

    def __init__(self, model, ag, dt, block, k_range, xi_range, switch, solver_options):
        self.model, self.ag, self.dt, self.block = model, ag, dt, block
        self.log_k = (math.log(k_range[0]), math.log(k_range[1]))
        self.xi_range = xi_range
        self.options = dict(solver_options, switch=switch)
        self.count = 0

    def physical(self, point):
        u, v = float(np.clip(point[0], 0, 1)), float(np.clip(point[1], 0, 1))
        return (math.exp(self.log_k[0] + u * (self.log_k[1] - self.log_k[0])),
                self.xi_range[0] + v * (self.xi_range[1] - self.xi_range[0]))

    def histories(self, points, t_end):
        cases = [(self.block, *self.physical(p)) for p in points]
        self.count += len(cases)
        with warnings.catch_warnings():  # tension/overturning warnings are outcomes while searching
            warnings.simplefilter("ignore")
            _, theta, _, _ = simulate_histories(self.model, self.ag, self.dt, cases, t_end=t_end, **self.options)
        return _fill_overturned(theta)


def _distinct(points, scores, steps, count, taken=()):
    """The ``count`` best points at least half a step (in each coordinate) away from each other."""
    chosen = list(taken)
    picked = []
    for index in np.argsort(scores):
        point = points[index]
        if all(np.max(np.abs(point - other) / steps) > 0.5 for other in chosen):
            chosen.append(point)
            picked.append((float(scores[index]), point))
            if len(picked) >= count:
                break
    return picked


def _grid_basins(scores, n_k, n_xi, points, count):
    """Local minima of the grid objective (best first): one seed per basin."""
    surface = scores.reshape(n_k, n_xi)
    basins = []
    for index in np.argsort(scores):
        i, j = divmod(int(index), n_xi)
        if surface[i, j] <= surface[max(0, i - 1):i + 2, max(0, j - 1):j + 2].min():
            basins.append(points[index])
            if len(basins) >= count:
                break
    return basins


def _index_of(points, point):
    return int(np.argmin(np.max(np.abs(points - point), axis=1)))


def _local_offsets(values, fixed_xi):
    return np.array([(a, 0.0 if fixed_xi else b) for a in values for b in ((0.0,) if fixed_xi else values)])


def _refine(search, objective, seeds, n, t_end, fixed_xi, evaluations):
    """Polish seeds (point, local offsets, steps) on the window of n samples.

    A local batch grid around every seed runs in one compiled call, then bounded Nelder-Mead starts
    from each block's best point.
    """
    blocks = [np.clip(point + _local_offsets(offsets, fixed_xi) * steps, 0.0, 1.0) for point, offsets, steps in seeds]
    theta = search.histories(np.concatenate(blocks), t_end)
    scores = objective(_interpolate(theta, search.dt, objective.times[:n]), n)

    def cost(point):
        history = search.histories([np.clip(point, 0.0, 1.0)], t_end)
        return float(objective(_interpolate(history, search.dt, objective.times[:n]), n)[0])

    refined, offset = [], 0
    for block, (_, _, steps) in zip(blocks, seeds):
        block_scores = scores[offset:offset + len(block)]
        offset += len(block)
        best = int(np.argmin(block_scores))
        start, start_score = block[best], float(block_scores[best])
        point, value = _nelder_mead(cost, start, steps, fixed_xi, evaluations)
        refined.append((value, point) if value < start_score else (start_score, start))
    return refined


def _nelder_mead(cost, start, steps, fixed_xi, evaluations):
    """Bounded Nelder-Mead in the unit box from ``start`` with an initial simplex of half a step."""
    options = {"xatol": 1e-5, "fatol": 1e-7, "maxfev": evaluations}
    if fixed_xi:
        u = start[0] + steps[0] / 2 if start[0] + steps[0] / 2 <= 1 else start[0] - steps[0] / 2
        result = minimize(lambda x: cost([x[0], start[1]]), start[:1], method="Nelder-Mead", bounds=[(0.0, 1.0)],
                          options={**options, "initial_simplex": np.array([[start[0]], [u]])})
        return np.array([float(np.clip(result.x[0], 0, 1)), start[1]]), float(result.fun)
    simplex = np.array([start, start + [steps[0] / 2, 0.0], start + [0.0, steps[1] / 2]])
    for corner, direction in ((1, 0), (2, 1)):
        if simplex[corner, direction] > 1.0:
            simplex[corner, direction] = start[direction] - steps[direction] / 2
    result = minimize(cost, start, method="Nelder-Mead", bounds=[(0.0, 1.0), (0.0, 1.0)],
                      options={**options, "initial_simplex": simplex})
    return np.clip(result.x, 0.0, 1.0), float(result.fun)


def _continuation(search, objective, grid, grid_on_times, shape, windows, steps, fixed_xi, log):
    """Track the optimum through growing windows; returns (point, objective on the whole reference, history).

    ``history`` holds (samples, best point) of each window accepted, shortest first.

    Seeds: the survivors of the previous window and the coarse grid's best basins on this window. A
    window whose best objective more than doubles and exceeds three times the noise floor (what the
    true parameters would score, given the noise estimated in the reference) lost the optimum's basin:
    it is retried after an intermediate window, at most MAX_EXTRA_WINDOWS times.
    """
    pending = list(windows)
    candidates, previous_n, previous_score, extra, number = [], 0, math.inf, 0, 0
    history = []  # (samples, best point) of every window accepted
    while pending:
        n = pending[0]
        last = len(pending) == 1
        survivors = [point for _, point in candidates[:2 if last else SURVIVORS]]
        grid_scores = objective(grid_on_times, n)
        if last and survivors:  # the longest, dearest window: polish the survivors, a grid basin only if better
            seeds = [(point, (0.0,), steps) for point in survivors]
            survivor_best = float(np.min(objective(_interpolate(search.histories(survivors, float(
                objective.times[n - 1]) + search.dt), search.dt, objective.times[:n]), n)))
            fresh = [p for p in _grid_basins(grid_scores, *shape, grid, GRID_SEEDS)
                     if grid_scores[_index_of(grid, p)] < survivor_best]
        else:
            seeds = [(point, SURVIVOR_OFFSETS, steps) for point in survivors]
            fresh = _grid_basins(grid_scores, *shape, grid, GRID_SEEDS + len(seeds))
        fresh = [p for p in fresh if all(np.max(np.abs(p - s[0]) / steps) > 0.5 for s in seeds)][:GRID_SEEDS]
        seeds += [(point, LOCAL_OFFSETS, steps) for point in fresh]
        refined = _refine(search, objective, seeds, n, float(objective.times[n - 1]) + search.dt, fixed_xi,
                          NELDER_MEAD_EVALUATIONS)
        best = min(score for score, _ in refined)
        lost = candidates and best > 2.0 * previous_score and best > 3.0 * objective.noise_floor(n) + FLOOR_SLACK
        if lost and extra < MAX_EXTRA_WINDOWS and n - previous_n > 20:
            pending.insert(0, (previous_n + n) // 2)
            extra += 1
            continue
        pending.pop(0)
        number += 1
        points = np.array([point for _, point in refined])
        candidates = _distinct(points, np.array([score for score, _ in refined]), steps, SURVIVORS)
        previous_n, previous_score = n, candidates[0][0]
        history.append((n, candidates[0][1]))
        if log:
            k_now, xi_now = search.physical(candidates[0][1])
            log(f"window {number} (0-{objective.times[n - 1]:.2f} s, {len(pending)} to go): best k = {k_now:.4g} "
                f"N/m, xi = {xi_now:.4f}, objective {candidates[0][0]:.4f}")
        steps = np.maximum(steps * 0.7, MIN_STEP)
    return candidates[0][1], candidates[0][0], history


# ----------------------------------------------------------------------------------------- intervals
# Profile likelihood of one window. The reference is read as the model's rotation plus Gaussian noise of unknown
# variance: with sigma profiled out, -2 ln(likelihood ratio) is D = n_eff ln(RSS / RSS_min), RSS the sum of squared
# residuals on the uniform search grid plus the floor's n sigma_floor^2. Wilks: {k : min over xi of D <= limit}
# is the interval of k (limit chi2_1(confidence), or the bootstrap's), and likewise for xi (each a marginal
# interval, not a joint region). n_eff = n / tau, tau the integrated autocorrelation time of the residuals (1 for
# white noise): residuals that are smooth (model error, coloured noise) carry fewer independent samples and widen
# the intervals.
# k and xi trade off (a stiffer, more damped interface rocks alike): their estimates are correlated beyond
# 0.99, so the profile follows a narrow diagonal ridge. Every minimisation is therefore Gauss-Newton on the
# residuals, with finite-difference Jacobians (the response is smooth at the scale of the interval on a regular
# window, which ``_profiles_around`` checks): first from the fit to the maximum-likelihood point, then over xi at
# each profiled k (and over k at each profiled xi), all rows of a profile in one batch.

CONFIDENCE = 0.90
"""Default two-sided confidence level of the intervals of k and xi."""
PROFILE_POINTS = 11  # values of the profiled parameter per profile (0.5 Wald half-widths apart)
PROFILE_SPAN = 2.5  # half-span of a profile, in linearised (Wald) half-widths
INNER_ITERATIONS = 3  # Gauss-Newton steps of the inner minimisation per profile
MLE_ITERATIONS = 8
FIRST_STEP = 1e-5  # first finite-difference step in the unit box, then a quarter of the conditional half-width
RESOLUTION = 1e-6  # the solver's resolution in the unit box (its response is jagged below; ~2e-6 in k, 6e-8 in xi)
MAX_WIDENINGS = 3
PROFILE_BATCH = 256  # simulations per compiled call while profiling (memory: batch x samples)
RESTARTS = 1  # new starts from a better point the profiles found (a nonlinear surface: model error, big noise)
RESTART_DEVIANCE = 0.1
WIDENING_NOTED = 0.05  # a widening to the region's simulated points beyond this fraction of the width is noted


def autocorrelation_time(residual: ArrayLike) -> float:
    """Integrated autocorrelation time [samples] of a series: 1 + 2 sum of rho_k while rho_k >= 2/sqrt(n).

    At least the AR(1) value (1 + rho_1) / (1 - rho_1): the sum cut where rho_k drops into its sampling noise
    leaves out the tail of an AR(1) series (for phi = 0.8 and 600 samples it gives a median of 8.0 for 9, and
    fewer independent samples counted means intervals that are too narrow); the AR(1) value has no such cut.

    Parameters
    ----------
    residual : array_like
        The series (residuals of the fit on a uniform time grid).

    Returns
    -------
    float
        tau >= 1; about 1 for white noise, n / tau independent samples.
    """
    values = np.asarray(residual, float)
    values = values - values.mean()
    n = values.size
    spectrum = np.fft.rfft(values, 2 * n)
    autocovariance = np.fft.irfft(spectrum * np.conj(spectrum))[:n]
    if n < 3 or autocovariance[0] <= 0:
        return 1.0
    rho = autocovariance[1:] / autocovariance[0]
    # sum up to the first lag indistinguishable from white noise (|rho| < 2/sqrt(n)): white noise gives 1
    # (a cut at the first negative rho would add its random positive lags, ~10 % at n = 1000)
    small = np.flatnonzero(rho < 2.0 / math.sqrt(n))
    lags = int(small[0]) if small.size else rho.size
    lag_one = min(max(float(rho[0]), 0.0), AR1_MAX)
    return max(1.0, 1.0 + 2.0 * float(np.sum(rho[:lags])), (1.0 + lag_one) / (1.0 - lag_one))


AR1_MAX = 0.99  # the largest lag-1 correlation the AR(1) autocorrelation time takes (tau 199)


class _Likelihood:
    """Residuals (model - reference on the uniform grid) of points of the unit box, and the lowest RSS seen."""

    def __init__(self, search, times, reference, t_end, floor=0.0):
        self.search, self.times, self.reference, self.t_end = search, times, reference, t_end
        self.floor = floor  # added to every RSS: the noise floor's n sigma_floor^2 (rockfrag.calibrate.NOISE_FLOOR)
        self.best_rss, self.best_point = math.inf, None
        self.seen_points, self.seen_rss = [], []  # every evaluation: the region's points bound the intervals

    def residuals(self, points):
        points = np.atleast_2d(np.clip(np.asarray(points, float), 0.0, 1.0))
        chunks = np.array_split(points, math.ceil(len(points) / PROFILE_BATCH))
        values = np.concatenate([_interpolate(self.search.histories(chunk, self.t_end), self.search.dt, self.times)
                                 for chunk in chunks]) - self.reference
        rss = np.sum(values**2, axis=1) + self.floor
        self.seen_points.append(points)
        self.seen_rss.append(rss)
        best = int(np.argmin(rss))
        if rss[best] < self.best_rss:
            self.best_rss, self.best_point = float(rss[best]), points[best]
        return values, rss

    def jacobian(self, points, steps, axes):
        """Residuals, RSS and central-difference Jacobians (n_points, n_samples, len(axes)) in one batch.

        At an edge of the unit box the difference is one-sided (divided by the shift that remains).
        """
        points = np.clip(np.atleast_2d(np.asarray(points, float)), 0.0, 1.0)
        stencil, shifts = _stencil(points, steps, axes)
        values, rss = self.residuals(np.concatenate([points] + stencil))
        m = len(points)
        jacobian = np.stack([(values[(1 + 2 * i) * m:(2 + 2 * i) * m] - values[(2 + 2 * i) * m:(3 + 2 * i) * m])
                             / shift[:, None] for i, shift in enumerate(shifts)], axis=-1)
        return values[:m], rss[:m], jacobian


def _stencil(points, steps, axes):
    """Central-difference neighbours of ``points``: [plus, minus] per axis, and the shift between them per axis.

    At an edge of the unit box a neighbour stays on the edge (the difference is one-sided, over the shift left).
    """
    stencil, shifts = [], []
    for axis in axes:
        plus, minus = points.copy(), points.copy()
        plus[:, axis] = np.minimum(points[:, axis] + steps[axis], 1.0)
        minus[:, axis] = np.maximum(points[:, axis] - steps[axis], 0.0)
        stencil += [plus, minus]
        shifts.append(plus[:, axis] - minus[:, axis])
    return stencil, shifts


def _gauss_newton_step(residual, jacobian):
    """The least-squares step -(J^T J)^+ J^T r of one point."""
    return -np.linalg.pinv(jacobian.T @ jacobian) @ (jacobian.T @ residual)


def _maximum_likelihood(likelihood, point, axes, threshold, n_eff):
    """Gauss-Newton from ``point`` to the least-squares point: (point, steps, J, residual, RSS) there.

    The finite-difference steps become a quarter of each coordinate's conditional half-width (where D
    reaches the threshold along that axis): inside the linear range, far above the solver's noise.
    """
    steps = np.full(2, FIRST_STEP)
    residual, rss, jacobian = likelihood.jacobian([point], steps, axes)
    for iteration in range(MLE_ITERATIONS):
        curvature = np.sum(jacobian[0] ** 2, axis=0)  # d RSS / d offset^2 along each axis
        width = np.sqrt(threshold * rss[0] / n_eff / np.maximum(curvature, 1e-300))
        adapted = steps.copy()
        adapted[list(axes)] = np.clip(width / 4.0, RESOLUTION, 1e-2)
        trials = np.repeat(point[None, :], 3, axis=0)
        trials[:, list(axes)] += np.outer([1.0, 0.5, 0.25], _gauss_newton_step(residual[0], jacobian[0]))
        _, trial_rss = likelihood.residuals(trials)
        best = int(np.argmin(trial_rss))
        gain = n_eff * math.log(rss[0] / trial_rss[best]) if trial_rss[best] > 0 else math.inf
        if gain > 0:
            point = np.clip(trials[best], 0.0, 1.0)
        if gain <= 0 and iteration > 0 and np.allclose(adapted, steps, rtol=0.5):
            break  # no better point with a Jacobian already at the right scale
        steps = adapted
        residual, rss, jacobian = likelihood.jacobian([point], steps, axes)
        if 0 < gain < 1e-4:
            break  # converged: the deviance moves by less than 1e-4
    return point, steps, jacobian[0], residual[0], float(rss[0])


def _profile_rss(likelihood, positions, axis, start, steps, fixed_other):
    """Profile RSS of ``axis`` at ``positions``: minimised over the other coordinate by batched Gauss-Newton."""
    other = 1 - axis
    points = np.zeros((positions.size, 2))
    points[:, axis] = positions
    points[:, other] = start
    if fixed_other:
        return likelihood.residuals(points)[1]
    best = np.full(positions.size, np.inf)
    for _ in range(INNER_ITERATIONS):
        residual, rss, jacobian = likelihood.jacobian(points, steps, (other,))
        best = np.minimum(best, rss)
        move = -np.einsum("ij,ij->i", jacobian[:, :, 0], residual) / np.maximum(
            np.einsum("ij,ij->i", jacobian[:, :, 0], jacobian[:, :, 0]), 1e-300)
        points[:, other] = np.clip(points[:, other] + move, 0.0, 1.0)
    return np.minimum(best, likelihood.residuals(points)[1])


def _bounds(positions, deviance, threshold):
    """(low, high) positions where the profile deviance crosses ``threshold`` on each side of its minimum.

    A side without a crossing gives None.
    """
    centre = int(np.argmin(deviance))
    high = _first_crossing(positions[centre:], deviance[centre:], threshold)
    low = _first_crossing(positions[:centre + 1][::-1], deviance[:centre + 1][::-1], threshold)
    return low, high


def _first_crossing(offsets, deviance, threshold):
    """The offset at which ``deviance`` (ordered by growing distance) first reaches ``threshold``; None if never.

    Interpolated linearly in the root deviance sqrt(D), which is linear in the parameter where the profile is
    quadratic (the signed root of Venzon & Moolgavkar 1988), so that a coarse profile still finds its crossing.
    """
    above = np.flatnonzero(deviance >= threshold)
    if not above.size:
        return None
    i = int(above[0])
    if i == 0:
        return float(offsets[0])
    root_low, root_high = math.sqrt(max(deviance[i - 1], 0.0)), math.sqrt(deviance[i])
    fraction = (math.sqrt(threshold) - root_low) / (root_high - root_low)
    return float(offsets[i - 1] + fraction * (offsets[i] - offsets[i - 1]))


def _profiles_around(likelihood, start, axes, threshold, tau, fixed_xi, reach=None):
    """Least-squares point from ``start``, then the profile of each free coordinate around it.

    ``reach`` (default ``threshold``) is the deviance the profiles must reach on both sides.

    Returns ({axis: (positions, profile RSS)}, notes, tau, n_eff, RSS at the least-squares point, rough), rough
    saying why the response is not smooth at the interval's scale (None when it is): the Jacobian at a quarter
    of the finite-difference step (a quarter of the conditional half-width) or at four times it (across the
    interval: Wilks needs the response about linear there) differs from it by more than ``ROUGHNESS`` (a jump,
    a chaotic wiggle, narrow basins side by side), or the interval is at the solver's resolution.
    """
    samples = likelihood.times.size
    mle, steps, jacobian, residual, mle_rss = _maximum_likelihood(likelihood, start, axes, threshold, samples / tau)
    # at the least-squares point, where only noise and model error remain (the floor counts as white noise)
    tau = _floored_tau(residual, likelihood.floor)
    n_eff = samples / tau
    rough = None
    norms = np.linalg.norm(jacobian, axis=0)
    for factor, what in ((0.25, "a quarter of it"), (4.0, "four times it (the interval's half-width)")):
        other = likelihood.jacobian([mle], np.minimum(steps * factor, 0.25), axes)[2][0]
        change = np.linalg.norm(other - jacobian, axis=0) / np.maximum(norms, 1e-300)
        if rough is None and np.any((change > ROUGHNESS) & (norms > 0)):
            rough = (f"the response is not smooth at the interval's scale (its derivative in "
                     f"{', '.join(('k', 'xi')[a] for a, c in zip(axes, change) if c > ROUGHNESS)} changes by "
                     f"{float(np.max(change)):.0%} from a step to {what})")
    # linearised covariance: sigma^2 tau (J^T J)^-1, sigma^2 = RSS/n; its diagonal sets each profile's span,
    # its regression of one coordinate on the other the ridge the inner minimisation starts from
    covariance = np.linalg.pinv(jacobian.T @ jacobian) * mle_rss / n_eff
    profiles, notes = {}, []
    for index, axis in enumerate(axes):
        other = 1 - axis
        if not np.any(jacobian[:, index]):  # the window does not depend on this parameter: profile the whole range
            half_width, covariance[index, index] = 0.5, math.inf
        else:
            half_width = min(math.sqrt(threshold * max(covariance[index, index], 0.0)), 0.5)
        if half_width < 4 * RESOLUTION:
            rough = rough or f"the {('k', 'xi')[axis]} interval would be at the solver's resolution"
            half_width = 4 * RESOLUTION
        ridge = (covariance[1 - index, index] / covariance[index, index]
                 if len(axes) == 2 and 0 < covariance[index, index] < math.inf else 0.0)
        span = PROFILE_SPAN
        for _ in range(MAX_WIDENINGS + 1):
            positions = np.unique(np.clip(mle[axis] + span * half_width * np.linspace(-1, 1, PROFILE_POINTS), 0, 1))
            starts = np.clip(mle[other] + ridge * (positions - mle[axis]), 0.0, 1.0)
            rss = _profile_rss(likelihood, positions, axis, starts, steps, fixed_xi)
            low, high = _bounds(positions, n_eff * np.log(rss / likelihood.best_rss), reach or threshold)
            if not ((low is None and positions[0] > 0.0) or (high is None and positions[-1] < 1.0)):
                break
            span *= 2.0  # the profile is flatter than its linearisation: look wider
        profiles[axis] = (positions, rss)
    return profiles, notes, tau, n_eff, mle_rss, rough


def _profile_intervals(search, times: np.ndarray, reference: np.ndarray, point: ArrayLike, fixed_xi: bool,
                      confidence: float, t_end: float, noise_floor: float = 0.0,
                      limits: dict | None = None) -> dict:
    """Profile-likelihood intervals of k and xi around a fit on one window (see the block comment above).

    Parameters
    ----------
    search : _Search
        The simulations of the calibration (model, record, block, search box).
    times, reference : ndarray
        The uniform search grid [s] of the window and the reference rotation on it [rad].
    point : array_like
        The fit in the unit box (u = log-k fraction, v = xi fraction).
    fixed_xi : bool
        xi is fixed: only k is profiled.
    confidence : float
        Two-sided level in (0, 1).
    t_end : float
        End of the simulations [s].
    noise_floor : float
        The least noise RMS the intervals assume [rad] (``NOISE_FLOOR`` of the peak in ``calibrate``).
    limits : dict, optional
        The profile deviance that bounds each interval, per axis (0: k, 1: xi); default chi^2_1(confidence)
        (``calibrate`` passes the parametric bootstrap's, ``_bootstrap_limits``).

    Returns
    -------
    dict
        ``k_low``, ``k_high`` [N/m], ``xi_low``, ``xi_high`` [-] (None for a fixed xi), ``noise_rms``
        [rad], ``autocorrelation_time`` [samples], ``notes`` (bounds that are the search box's, a fit
        outside its own region, correlated residuals), the profiles (``profile_k``,
        ``profile_k_deviance``, ``profile_xi``, ``profile_xi_deviance``), ``point`` (the likelihood's best
        point in the unit box), ``at_fit`` (the deviance of ``point`` given) and ``irregular`` (why the
        likelihood is not regular at the interval's scale, or None; ``_irregularity``).
    """
    from scipy.stats import chi2

    threshold = float(chi2.ppf(confidence, 1))
    axes = (0,) if fixed_xi else (0, 1)
    limits = {axis: max(threshold, (limits or {}).get(axis, threshold)) for axis in axes}
    start = np.clip(np.asarray(point, float), 0.0, 1.0)
    likelihood = _Likelihood(search, times, reference, t_end, floor=times.size * noise_floor**2)
    tau = autocorrelation_time(likelihood.residuals([start])[0][0])
    origin = start
    for attempt in range(RESTARTS + 1):
        profiles, notes, tau, n_eff, mle_rss, rough = _profiles_around(likelihood, origin, axes, threshold, tau,
                                                                       fixed_xi, max(limits.values()))
        # a point better than the least-squares point found: Gauss-Newton stopped short on a nonlinear surface
        if n_eff * math.log(mle_rss / likelihood.best_rss) <= RESTART_DEVIANCE:
            break
        origin = likelihood.best_point

    lowest = min(likelihood.best_rss, *(float(np.min(rss)) for _, rss in profiles.values()))
    out = {"noise_rms": math.sqrt(max(lowest - likelihood.floor, 0.0) / times.size), "autocorrelation_time": tau,
           "notes": notes, "point": np.array(likelihood.best_point, float)}
    irregular = [rough] if rough else []
    # min over xi of D at k is at most D at any (k, xi): every evaluated point inside the joint region lies inside
    # both intervals. Where the profiles' local minimisation falls short (a nonlinear surface), this widens them.
    seen = np.concatenate(likelihood.seen_points)
    seen_deviance = n_eff * np.log(np.concatenate(likelihood.seen_rss) / lowest)
    for axis, (positions, rss) in profiles.items():
        inside = seen[seen_deviance <= limits[axis]]
        name, unit = ("k", " N/m") if axis == 0 else ("xi", "")

        def physical(x, axis=axis):
            return search.physical((x, 0.0) if axis == 0 else (0.0, x))[axis]

        # against the profile's own minimum: the same as the lowest RSS where the response is smooth, and the
        # only consistent reference where it is not (a noise-free reference at the solver's resolution)
        deviance = n_eff * np.log(rss / float(np.min(rss)))
        reason = _irregularity(deviance, threshold)
        if reason:
            irregular.append(f"the {name} profile {reason}")
        bounds = list(_bounds(positions, deviance, limits[axis]))
        for side, edge in enumerate((positions[0], positions[-1])):
            if bounds[side] is None:
                bounds[side] = edge
                where = "search range's" if edge in (0.0, 1.0) else "profile's last point"
                out["notes"].append(f"the {('lower', 'upper')[side]} bound of {name} is the {where} "
                                    f"({physical(edge):.4g}{unit}): the reference does not bound {name} there")
        if inside.size:
            widened = [min(bounds[0], inside[:, axis].min()), max(bounds[1], inside[:, axis].max())]
            growth = (widened[1] - widened[0]) / max(bounds[1] - bounds[0], 1e-300) - 1.0
            if growth > WIDENING_NOTED:
                out["notes"].append(f"the {name} interval is widened by {growth:.0%} to every simulated point inside "
                                    "the likelihood region (the surface is not quadratic at this scale): read its "
                                    "width as a lower bound")
            if growth > IRREGULAR_WIDENING:
                irregular.append(f"simulated points inside the likelihood region lie {growth:.0%} beyond the {name} "
                                 "profile's interval")
            bounds = widened
        out[f"{name}_low"], out[f"{name}_high"] = (float(physical(bound)) for bound in bounds)
        out[f"{name}_span"] = tuple(float(physical(bound)) for bound in bounds)
        out[f"profile_{name}"] = [float(physical(x)) for x in positions]
        out[f"profile_{name}_deviance"] = [float(v) for v in deviance]
    if fixed_xi:
        out["xi_low"] = out["xi_high"] = None
    at_fit = n_eff * math.log(float(likelihood.residuals([start])[1][0]) / lowest)
    out["at_fit"] = at_fit
    if at_fit > threshold:
        k_best, xi_best = search.physical(likelihood.best_point)
        out["notes"].append(f"the fit lies outside its own {confidence:.0%} likelihood region (deviance "
                            f"{at_fit:.3g} > {threshold:.3g}); the likelihood's best point is k = {k_best:.6g} N/m, "
                            f"xi = {xi_best:.5f}")
    if tau > 2.0:
        out["notes"].append(f"the residuals are correlated over {tau:.0f} samples (model error or coloured noise): "
                            f"the intervals count {n_eff:.0f} of {times.size} samples as independent")
    out["irregular"] = "; ".join(irregular) or None
    return out


ROUGHNESS = 0.3  # a Jacobian that changes by more than this fraction from a step to a quarter of it: not smooth
DIP = 1.0  # a profile that falls by more than this deviance (or DIP_FRACTION of its climb) on its way out is jagged
DIP_FRACTION = 0.25
JAGGED_LEVEL = 4.0  # dips count while the profile has climbed no higher than this many thresholds (the region's
# neighbourhood; further out, another basin above the threshold does not move the interval)
IRREGULAR_WIDENING = 1.0  # region points beyond the profile's interval by this fraction of its width: not regular


def _irregularity(deviance, threshold):
    """Why a profile deviance is not that of a regular likelihood, or None.

    A regular likelihood rises monotonically away from its minimum along the profile. A chaotic window's
    profile is jagged (it falls back by more than ``DIP`` or ``DIP_FRACTION`` of what it had climbed) or
    leaves the region and comes back into it (several basins within the profile's span).
    """
    deviance = np.asarray(deviance, float)
    centre = int(np.argmin(deviance))
    for side in (deviance[centre:], deviance[:centre + 1][::-1]):
        climbed, left = 0.0, False
        for value in side:
            if left and value < threshold:
                return "leaves the likelihood region and comes back into it (several basins)"
            if climbed <= JAGGED_LEVEL * threshold and value < climbed - max(DIP, DIP_FRACTION * climbed):
                return f"is jagged (falls from {climbed:.3g} to {value:.3g} on its way out)"
            climbed, left = max(climbed, value), left or value >= threshold
    return None


# ----------------------------------------------------------------------------------------- windows
# Which window decides. A window's likelihood is usable when the model explains the window at the noise level
# (goodness of fit) and the likelihood is regular at the interval's scale (the profiles rise monotonically).
# The windows are walked from the shortest up; each one's least-squares point is found by Gauss-Newton from the
# search's point on that window and from the previous window's least-squares point. A window is accepted while
# the growth of its least RSS over the previous accepted window's, ΔRSS, is what the noise explains: ΔRSS /
# sigma^2 below the chi^2 quantile GOODNESS of (new samples)/tau degrees of freedom (times tau), sigma^2 and tau
# from the previous accepted window's residuals. Past the point where the response turns chaotic at the noise's
# scale, the best fit of the longer window no longer follows the reference, ΔRSS jumps, and the walk stops.
# The last accepted window whose profiles are regular decides: its least-squares point is the estimate, its
# profile intervals are the intervals.

NOISE_FLOOR = 1e-3
"""The least noise RMS the intervals assume, as a fraction of the reference's peak |rotation|: no measurement
or export is read as more precise than this (a noise-free reference would otherwise give intervals at the
solver's resolution that the fit's own round-off can miss)."""
MISMATCH = 0.1  # a reference may differ from the model by this fraction of its noise RMS (interpolated, rounded)
GOODNESS = 0.999  # level of the chi^2 test of a window's fit against the noise (a false alarm only shortens it)
AGREEMENT = 0.999  # level of the chi^2_2 test that the decisive fit explains the shorter accepted windows
NOT_IDENTIFIABLE = "not identifiable from this reference"


@dataclass
class _Window:
    """One fitting window [0, times[n - 1]]: its least-squares point and what the walk decided."""

    n: int
    end: float  # [s]
    point: np.ndarray
    rss: float  # least RSS, floor included [rad^2]
    tau: float
    residual: np.ndarray
    accepted: bool = False
    reason: str = ""


def _window_fit(search, times, reference, n, starts, axes, threshold, floor, dt):
    """The least-squares point of the window of n samples, Gauss-Newton from the best of ``starts``."""
    likelihood = _Likelihood(search, times[:n], reference[:n], float(times[n - 1]) + dt, floor=floor)
    starts = np.clip(np.array(starts, float), 0.0, 1.0)
    values, rss = likelihood.residuals(starts)
    best = int(np.argmin(rss))
    tau = _floored_tau(values[best], floor)
    point, _, _, residual, rss = _maximum_likelihood(likelihood, starts[best], axes, threshold, n / tau)
    if likelihood.best_rss < rss:  # a trial point better than where Gauss-Newton stopped
        point = likelihood.best_point
        residual = likelihood.residuals([point])[0][0]
        rss = float(likelihood.best_rss)
    return _Window(n, float(times[n - 1]), np.array(point, float), float(rss), _floored_tau(residual, floor),
                   residual)


def _floored_tau(residual, floor):
    """The autocorrelation time of the residuals plus the white noise floor (floor = n sigma_floor^2)."""
    variance = float(np.mean(residual**2))
    noise_share = variance / (variance + floor / residual.size) if variance > 0 else 0.0
    return 1.0 + (autocorrelation_time(residual) - 1.0) * noise_share


def _explained(base: _Window, previous: _Window, window: _Window) -> tuple[bool, str]:
    """(accepted, why not): does ``window``'s fit explain its samples at the noise of ``base``, beyond it and added.

    The noise variance and autocorrelation time tau are the base window's (``_window_walk``), itself a sample:
    the mean square the fit leaves in the samples beyond the base, and in those beyond the previous accepted
    window, over the base's, is F-distributed with (samples / tau, base samples / tau) degrees of freedom for
    a fit that explains them; both must stay below the ``GOODNESS`` quantile, times (1 + ``MISMATCH``)^2.
    """
    from scipy.stats import f as fisher

    variance = base.rss / base.n
    base_dof = max(base.n / base.tau, 1.0)
    for label, samples, excess in (("beyond the quiet start", window.n - base.n, window.rss - base.rss),
                                   ("it adds", window.n - previous.n, window.rss - previous.rss)):
        if samples <= 0 or (label == "it adds" and previous is base):
            continue
        ratio = excess / samples / variance
        limit = float(fisher.ppf(GOODNESS, max(samples / base.tau, 1.0), base_dof)) * (1.0 + MISMATCH) ** 2
        if ratio > limit:
            return False, (f"its best fit leaves {ratio:.3g} times the noise variance unexplained in the {samples} "
                           f"samples {label} (limit {limit:.3g}: F {GOODNESS:.1%} and {MISMATCH:.0%} of the noise "
                           "for interpolation)")
    return True, ""


def _quiet_samples(smoothed: np.ndarray, fraction: float = PEAK_FRACTION) -> int:
    """Samples before the (smoothed) reference first reaches ``fraction`` of its peak: the block barely moves."""
    magnitude = np.abs(smoothed - smoothed[0])
    return int(np.argmax(magnitude >= fraction * magnitude.max()))


def _window_walk(search, times, reference, history, full_point, axes, threshold, floor_rms, dt, quiet, log):
    """The windows of the search with their least-squares points, accepted from the shortest up (block comment).

    The base window is the reference before it first reaches ``PEAK_FRACTION`` of its peak (``quiet`` samples;
    else the search's first window), fitted from every point the search found: its residual variance (with
    the floor) and its residuals' autocorrelation time are the noise every window is tested against
    (``_explained``). Gauss-Newton starts from the best of the search's points on this window and the next two
    (the search's estimate sharpens as its windows grow) and the previous accepted window's least-squares
    point. A window the noise does not explain is left out. When the longer windows are not explained, the
    first of them is scanned over the whole search range (``_scan``) and they are fitted again from every
    basin that fits it better (at most ``RESCANS`` times): the search may have tracked the wrong one.

    Returns
    -------
    (list of _Window, dict)
        The windows, and the scans {samples: _Scan} of the windows scanned.
    """
    starts = dict(history)
    starts[times.size] = full_point
    ends = sorted(starts)
    if MIN_BASE_SAMPLES <= quiet < ends[0]:
        ends = [quiet] + ends
        starts[quiet] = starts[ends[1]]
    fitted, scans = {}, {}
    # the base from every point the search found (its later ones are the best informed, even on the quiet start)
    base = _window_fit(search, times, reference, ends[0], [starts[m] for m in ends], axes, threshold,
                       ends[0] * floor_rms**2, dt)
    # and from every basin of the whole search range that fits it better: a base fit in a wrong basin would read
    # its misfit as noise, and every window after it would be tested against that inflated noise
    scan = scans[ends[0]] = _scan(search, times, reference, ends[0], ends[0] * floor_rms**2, dt, axes)
    better = [point for point, value in zip(scan.points, scan.rss) if value < base.rss]
    if better:
        rescanned = _window_fit(search, times, reference, ends[0], better, axes, threshold, ends[0] * floor_rms**2,
                                dt)
        base = rescanned if rescanned.rss < base.rss else base
    base.accepted = True
    fitted[ends[0]] = previous = base
    extra_starts = []
    for attempt in range(RESCANS + 1):
        for position, n in enumerate(ends):
            if n <= previous.n:
                continue
            candidates = [starts[m] for m in ends[position:position + 3]] + [previous.point] + extra_starts
            window = _window_fit(search, times, reference, n, candidates, axes, threshold, n * floor_rms**2, dt)
            window.accepted, window.reason = _explained(base, previous, window)
            if n not in fitted or window.accepted or window.rss < fitted[n].rss:
                fitted[n] = window
            if window.accepted:
                previous = window
        if previous.n == ends[-1] or attempt == RESCANS:
            break
        # the longer windows are not explained from the basin tracked: scan the first of them for other basins
        failed = min(n for n in ends if n > previous.n)
        if failed in scans:
            break
        scan = scans[failed] = _scan(search, times, reference, failed, failed * floor_rms**2, dt, axes)
        others = [point for point, value in sorted(zip(scan.points, scan.rss), key=lambda pair: pair[1])
                  if value < fitted[failed].rss and np.max(np.abs(point - fitted[failed].point)) > SAME_BASIN]
        if not others:
            break
        extra_starts = others
    windows = [fitted[n] for n in sorted(fitted)]
    if log:
        last = [w for w in windows if w.accepted][-1]
        log(f"windows: the fits explain the reference at the noise level up to {last.end:.2f} s "
            f"({sum(w.accepted for w in windows)} of {len(windows)} windows; {len(scans)} scan(s))")
    return windows, scans


def _scan(search, times, reference, n, floor, dt, axes):
    """The basins of the window of n samples over the whole search range, each polished by Gauss-Newton.

    A dense grid (``SCAN_K`` log-spaced k times ``SCAN_XI`` xi) in compiled batches; its local minima (best
    first, at most ``SCAN_BASINS``) are the basins. Returns (points in the unit box, least RSS of each).
    """
    u = np.linspace(0.0, 1.0, SCAN_K)
    v = np.linspace(0.0, 1.0, SCAN_XI) if len(axes) == 2 else np.array([0.0])  # a fixed xi is v = 0
    grid = np.array([(a, b) for a in u for b in v])
    likelihood = _Likelihood(search, times[:n], reference[:n], float(times[n - 1]) + dt, floor=floor)
    residuals, rss = likelihood.residuals(grid)
    seeds = _grid_basins(rss, u.size, v.size, grid, SCAN_BASINS)
    threshold = 2.706
    points, values = [], []
    for seed in seeds:
        window = _window_fit(search, times, reference, n, [seed], axes, threshold, floor, dt)
        if all(np.max(np.abs(window.point - p)) > SAME_BASIN for p in points):
            points.append(window.point)
            values.append(window.rss)
    return _Scan(np.array(points), np.array(values), grid, rss, residuals.astype(np.float32))


@dataclass
class _Scan:
    """A window's scan: its basins (points in the unit box, least RSS) and the grid's points and RSS."""

    points: np.ndarray
    rss: np.ndarray
    grid: np.ndarray
    grid_rss: np.ndarray
    grid_residuals: np.ndarray = field(repr=False, default=None)  # (grid points, samples): model - reference

    def region(self, best: float, variance: float, level: float) -> np.ndarray:
        """Basins and grid points whose deviance against RSS ``best`` is within ``level``, and their box's corners.

        The corners are moved out by one scan step, as in ``_direct_region``: the region's edge lies between the
        last grid point inside and the first outside, and a needle of the likelihood between them is not seen.
        """
        points = np.concatenate([self.points.reshape(-1, 2), self.grid])
        rss = np.concatenate([self.rss, self.grid_rss])
        inside = points[(rss - best) / variance <= level]
        if not inside.size:
            return inside
        steps = np.array([1.0 / (SCAN_K - 1), 1.0 / (SCAN_XI - 1)])
        corners = np.clip([inside.min(axis=0) - steps, inside.max(axis=0) + steps], 0.0, 1.0)
        return np.concatenate([inside, corners])


MIN_BASE_SAMPLES = 20  # a quiet start shorter than this is no base: the search's first window is
REFINEMENTS = 5  # windows bisecting the gap past the decisive one
SECOND_TRIES = 6  # shorter accepted windows profiled for the union of the intervals
UNION_RATIO = 2.0  # the union goes back to a shorter regular window whose interval is this many times as wide
LINEAR_PROFILES = 6  # irregular windows profiled one by one down the list before bisection takes over
RESCANS = 2  # scans of the last accepted window for other basins when the longer windows are not explained
SCAN_K, SCAN_XI = 121, 21  # the scan's grid: k log-spaced (1.8 % apart over 1e8-9e8 N/m) times xi
SCAN_BASINS = 8  # local minima of the scan polished by Gauss-Newton
SAME_BASIN = 0.01  # points closer than this in both coordinates of the unit box are one basin


def _decide(search, times, reference, history, full_point, fixed_xi, confidence, floor_rms, quiet, log):
    """The decisive window, its estimate and intervals, or "not identifiable" with the range of fits (block comment).

    Returns
    -------
    dict
        ``point`` (the estimate, unit box), ``end`` [s] of the decisive window (None when no window's likelihood
        is regular), ``identifiable``, ``range_points`` (fits that explain the decisive window as well as the
        estimate), the interval fields of ``_profile_intervals`` and ``notes``, and ``windows`` (end [s],
        k [N/m], xi [-], accepted, regular, reason per window fitted).
    """
    from scipy.stats import chi2

    threshold = float(chi2.ppf(confidence, 1))
    axes = (0,) if fixed_xi else (0, 1)
    dt = search.dt
    windows, scans = _window_walk(search, times, reference, history, full_point, axes, threshold, floor_rms, dt,
                                  quiet, log)
    accepted = [w for w in windows if w.accepted]
    base = accepted[0]
    variance = base.rss / base.n * base.tau

    def profile_of(window):
        return _profile_intervals(search, times[:window.n], reference[:window.n], window.point, fixed_xi,
                                  confidence, window.end + dt, floor_rms)

    # the longest accepted window whose profiles are regular: the longest first, then down the list (a window is
    # regular up to where the response turns chaotic at the interval's scale, mostly); after ``LINEAR_PROFILES``
    # irregular ones, by bisection of the rest
    chosen, profile, irregular, profiles = None, None, {}, {}
    low, high = 0, len(accepted) - 1
    while low <= high:
        middle = high if len(profiles) < LINEAR_PROFILES else (low + high + 1) // 2
        result = profiles[accepted[middle].n] = profile_of(accepted[middle])
        if result["irregular"] is None:
            chosen, profile, low = accepted[middle], result, middle + 1
        else:
            irregular[accepted[middle].n] = result["irregular"]
            high = middle - 1
    # the search's windows end after large peaks and may leave a long gap past the decisive one: bisect it in
    # time (at most ``REFINEMENTS`` windows, each fitted from the decisive fit, tested and profiled)
    following = [w for w in windows if chosen is not None and w.n > chosen.n]
    limit = following[0].n if following else None
    for _ in range(REFINEMENTS if chosen is not None else 0):
        if limit is None or limit - chosen.n < 2 * MIN_BASE_SAMPLES:
            break
        n = (chosen.n + limit) // 2
        window = _window_fit(search, times, reference, n, [chosen.point] + [w.point for w in following[:1]], axes,
                             threshold, n * floor_rms**2, dt)
        window.accepted, window.reason = _explained(base, chosen, window)
        windows.append(window)
        if window.accepted:
            accepted.append(window)
            result = profiles[n] = profile_of(window)
            if result["irregular"] is None:
                chosen, profile = window, result
                continue
            irregular[n] = result["irregular"]
        limit = n
    windows.sort(key=lambda w: w.n)
    accepted.sort(key=lambda w: w.n)

    def table():
        return [{"end": w.end, "k": search.physical(w.point)[0], "xi": search.physical(w.point)[1],
                 "accepted": w.accepted, "regular": (w is chosen) if (w is chosen or w.n in irregular) else None,
                 "reason": w.reason or irregular.get(w.n, "")} for w in windows]

    def scan_of(window):
        if window.n not in scans:
            scans[window.n] = _scan(search, times, reference, window.n, window.n * floor_rms**2, dt, axes)
        return scans[window.n]

    def region_of(window, best=None):
        """The fits that explain ``window`` as well as its best (chi^2_2 at the confidence): its scan's."""
        scan = scan_of(window)
        best = min(window.rss, float(np.min(scan.rss)) if scan.rss.size else math.inf) if best is None else best
        return scan.region(best, window.rss / window.n * window.tau, chi2.ppf(confidence, len(axes)))

    if chosen is None:
        # no window's likelihood is regular at its interval's scale: no local curvature describes it, so the
        # region is read off the likelihood itself over the whole search range, on the shortest accepted window
        # (the least chaotic), or a longer one where that does not bound k and xi inside the range
        # then the longest accepted ones: the most informative, where the short ones leave k or xi unbounded
        tries = accepted[:DIRECT_TRIES] + [w for w in accepted[DIRECT_TRIES:][::-1]][:DIRECT_TRIES]
        for window in tries:
            out = _direct_region(search, times, reference, window, scan_of(window), axes, confidence, floor_rms)
            if not out["whole_range"]:
                break
        reason = irregular.get(out["window"].n) or next(iter(irregular.values()))
        if out["window"].n in profiles:  # the profiles drawn are that window's, although they do not bound it
            out.update({key: value for key, value in profiles[out["window"].n].items()
                        if key.startswith("profile_")})
        out["notes"].insert(0, f"no window's likelihood is regular at the interval's scale ({reason}): the intervals "
                            f"are its likelihood region on 0-{out['end']:.2f} s by direct evaluation over the search "
                            "range")
        out.update(windows=table())
        return out

    notes, identifiable = list(profile["notes"]), True
    point = np.array(profile["point"], float)
    window_rss = float(_Likelihood(search, times[:chosen.n], reference[:chosen.n], chosen.end + dt,
                                   chosen.n * floor_rms**2).residuals([point])[1][0])
    # the whole search range on the decisive window: other basins that explain it as well
    scan = scan_of(chosen)
    best = min(window_rss, float(np.min(scan.rss))) if scan.rss.size else window_rss
    if window_rss - best > RESTART_DEVIANCE * variance:
        # a better basin than the tracked one: it decides (its profile, if regular)
        better = _Window(chosen.n, chosen.end, scan.points[int(np.argmin(scan.rss))], best, chosen.tau,
                         chosen.residual)
        result = profile_of(better)
        if result["irregular"] is None:
            profile, point, window_rss = result, np.array(result["point"], float), best
            notes = list(profile["notes"]) + [f"the scan of 0-{chosen.end:.2f} s found a better basin than the "
                                              "search's"]
    # the limits of the profile deviance from a parametric bootstrap of the window (chi^2_1 where it is quadratic)
    steps = np.array([max((_unit(search, axis, profile[f"{name}_high"]) - _unit(search, axis, profile[f"{name}_low"]))
                          / 8.0, RESOLUTION) if profile.get(f"{name}_low") is not None else FIRST_STEP
                      for axis, name in ((0, "k"), (1, "xi"))])
    limits = _bootstrap_limits(search, times, reference, chosen.n, point, steps, fixed_xi, confidence, floor_rms, dt)
    if any(limit > threshold * (1 + 1e-9) for limit in limits.values()):
        bounded = _profile_intervals(search, times[:chosen.n], reference[:chosen.n], point, fixed_xi, confidence,
                                     chosen.end + dt, floor_rms, limits)
        profile = dict(bounded, irregular=profile["irregular"])
        notes = [note for note in notes if note not in profile["notes"]] + list(profile["notes"])
    profile["limits"] = limits
    if log:
        log(f"bootstrap of 0-{chosen.end:.2f} s ({BOOTSTRAP} replicates): profile deviance limits "
            + ", ".join(f"{('k', 'xi')[axis]} {limit:.3g}" for axis, limit in limits.items())
            + f" (chi2_1 {threshold:.3g})")
    region = [p for p, value in zip(scan.points, scan.rss) if (value - best) / variance <= threshold
              and np.max(np.abs(p - point)) > SAME_BASIN]
    box = np.array([[_unit(search, axis, profile[f"{name}_low"]), _unit(search, axis, profile[f"{name}_high"])]
                    if profile.get(f"{name}_low") is not None else [0.0, 1.0] for axis, name in ((0, "k"), (1, "xi"))])
    width = np.maximum(box[:, 1] - box[:, 0], 1e-9)
    far = [p for p in region if np.any((p < box[:, 0] - width) | (p > box[:, 1] + width))]
    range_points = [point] + region
    if far:
        identifiable = False
        k_values = [search.physical(p)[0] for p in far]
        notes.append(f"{len(far)} other basin(s) of the search range fit 0-{chosen.end:.2f} s as well as the "
                     f"estimate (k {min(k_values):.4g} to {max(k_values):.4g} N/m): the range holds every fit that "
                     "explains it as well")
        range_points += list(region_of(chosen, best))
    elif region:
        notes.append(f"the intervals are widened to {len(region)} fit(s) near them that explain 0-{chosen.end:.2f} s "
                     "as well (the surface is not quadratic at this scale)")
    # shorter regular windows: near the chaotic horizon the likelihood splits into narrow basins that fit equally
    # well (the longest window's may not be the truth's; its interval shrinks from one window to the next far
    # faster than information accrues). A window before the split has an interval at least ``UNION_RATIO`` times
    # as wide, which holds them: the intervals are the union of the decisive window's and of the shorter regular
    # windows' back to the first that wide (not one that bounds nothing: the search range). Intervals that do not
    # meet disagree.
    def width(result, axis, name):
        return _unit(search, axis, result[f"{name}_high"]) - _unit(search, axis, result[f"{name}_low"])

    free = [(axis, name) for axis, name in ((0, "k"), (1, "xi")) if profile.get(f"{name}_low") is not None]
    own = {name: max(width(profile, axis, name), RESOLUTION) for axis, name in free}
    index, joined = accepted.index(chosen), []
    for earlier in reversed(accepted[max(0, index - SECOND_TRIES):index]):
        second = profiles.get(earlier.n) or profile_of(earlier)
        if second["irregular"] is not None:
            continue
        if any(width(second, axis, name) >= 1.0 - 1e-9 for axis, name in free):
            break  # a window that does not bound k or xi inside the search range holds nothing the union needs
        meet = all(second[f"{name}_low"] <= profile[f"{name}_high"] and profile[f"{name}_low"] <= second[f"{name}_high"]
                   for _, name in free)
        for _, name in free:
            profile[f"{name}_low"] = min(profile[f"{name}_low"], second[f"{name}_low"])
            profile[f"{name}_high"] = max(profile[f"{name}_high"], second[f"{name}_high"])
        joined.append(earlier.end)
        if not meet:
            identifiable = False
            notes.append(f"the windows disagree: the intervals of 0-{chosen.end:.2f} s and 0-{earlier.end:.2f} s do "
                         "not meet")
        if any(width(second, axis, name) >= UNION_RATIO * own[name] for axis, name in free):
            break
    if joined:
        notes.append(f"the intervals are the union of those of 0-{chosen.end:.2f} s and of the shorter regular "
                     f"window(s) 0-{', 0-'.join(f'{end:.2f}' for end in joined)} s (back to one whose interval is "
                     f"{UNION_RATIO:g} times as wide: near the chaotic horizon the likelihood splits into narrow "
                     "basins)")
    # the decisive fit must explain the shorter accepted windows too (nested data: a fit outside their regions
    # means the windows disagree beyond their intervals)
    for window in accepted:
        if window.n >= chosen.n:
            break
        value = float(_Likelihood(search, times[:window.n], reference[:window.n], window.end + dt,
                                  window.n * floor_rms**2).residuals([point])[1][0])
        deviance = (value - window.rss) / (window.rss / window.n * window.tau)
        if deviance > chi2.ppf(AGREEMENT, len(axes)):
            identifiable = False
            notes.append(f"the windows disagree: the fit of 0-{chosen.end:.2f} s lies outside the likelihood region "
                         f"of 0-{window.end:.2f} s (deviance {deviance:.3g}); the range holds every fit that explains "
                         f"0-{window.end:.2f} s as well as its best")
            range_points += list(region_of(window))
            break
    decision = dict(profile, end=chosen.end, identifiable=identifiable, windows=table(), notes=notes, point=point,
                    range_points=np.array(range_points))
    unbounded = _spans_search_range(search, decision, axes)
    if not unbounded:
        return decision
    # the decisive window (short: the likelihood turns irregular soon after the rocking starts, at large or coloured
    # noise) bounds k or xi only by the search range once the fits that explain it equally are counted. A longer
    # accepted window carries the information its rocking adds, though no local curvature describes its likelihood:
    # its region is read off a scan of the search range (``_direct_region``), the longest first.
    for window in [w for w in accepted if w.n > chosen.n][::-1][:DIRECT_TRIES]:
        out = _direct_region(search, times, reference, window, scan_of(window), axes, confidence, floor_rms)
        if out["whole_range"]:
            continue
        out["notes"] = [f"the decisive window 0-{chosen.end:.2f} s bounds {' and '.join(unbounded)} only by the "
                        "search range (its fits that explain it equally span it): the intervals are the likelihood "
                        f"region of the longer accepted window 0-{out['end']:.2f} s by direct evaluation over the "
                        "search range"] + out["notes"]
        out.update({key: value for key, value in profile.items() if key.startswith("profile_")}, windows=table())
        return out
    return decision


def _spans_search_range(search, decision, axes):
    """The names of the parameters ("k", "xi") whose interval in ``decision`` is the whole search range."""
    names = []
    for axis in axes:
        name = ("k", "xi")[axis]
        values = [float(p[axis]) for p in decision["range_points"]]
        if decision.get(f"{name}_low") is not None:
            values += [_unit(search, axis, decision[f"{name}_low"]), _unit(search, axis, decision[f"{name}_high"])]
        if min(values) <= 1e-9 and max(values) >= 1.0 - 1e-9:
            names.append(name)
    return names


DIRECT_TRIES = 3  # accepted windows tried, shortest first, for a direct region that bounds k and xi
DIRECT_METHOD = "likelihood region by direct evaluation (the likelihood is not regular)"
CLUSTER_GAP = 3  # scan steps between region points that make them separate basins
DIRECT_BOOTSTRAP = 200  # replicates of the direct region's bootstrap (scored on the scan's grid: no simulations)


def _direct_region(search, times, reference, window, scan, axes, confidence, floor_rms):
    """The likelihood region of one window read off a scan of the whole search range (no local curvature).

    The window's least-squares point f is refitted from its own and from the scan's best basin; sigma^2 tau is
    that fit's residual variance times their autocorrelation time. The region is every grid point of the scan
    whose RSS is within ``limit`` sigma^2 tau of the grid's least, with f; each bound moves out by one scan step
    (the region's edge lies between the last point inside and the first outside). The limit is a parametric
    bootstrap of exactly that reading: ``DIRECT_BOOTSTRAP`` replicates f + AR(1) noise (the residuals' variance
    and lag-1 correlation, seeded) are scored against every grid point at once (the grid's histories do not
    change), and the limit is the ``confidence`` quantile of how far the best of the four grid points around
    f (the scan cell that holds the truth of the replicate) lies above the replicate's best grid point: where
    the window is rugged the grid's best point fits the noise better than the truth does, and the limit grows
    with it (at least chi^2_1). Points that fall apart by more than ``CLUSTER_GAP`` steps are separate basins:
    "not identifiable", with the range that holds them all.

    Returns
    -------
    dict
        A decision as ``_decide`` returns it: ``point``, ``end`` [s], ``identifiable``, ``range_points`` (the
        region's box corners in the unit box), ``noise_rms`` [rad], ``autocorrelation_time``, ``notes``,
        ``limits``, ``method``, and ``window`` and ``whole_range`` (the box spans the search range in k or xi).
    """
    from scipy.stats import chi2

    threshold = float(chi2.ppf(confidence, 1))
    n, floor = window.n, window.n * floor_rms**2
    starts = [window.point] + ([scan.points[int(np.argmin(scan.rss))]] if scan.rss.size else [])
    fit = _window_fit(search, times, reference, n, starts, axes, threshold, floor, search.dt)
    variance = fit.rss / n * fit.tau
    steps = np.array([1.0 / (SCAN_K - 1), 1.0 / (SCAN_XI - 1) if len(axes) == 2 else 1.0])
    # replicate b is f + e_b = reference + x_b: its RSS at grid point m is |R_m - x_b|^2, R the scan's residuals
    replicates = fit.residual[None, :] + _ar1_noise(-fit.residual, DIRECT_BOOTSTRAP, BOOTSTRAP_SEED)
    grid_residuals = scan.grid_residuals.astype(float)
    replicate_rss = (np.sum(grid_residuals**2, axis=1)[:, None] - 2.0 * grid_residuals @ replicates.T
                     + np.sum(replicates**2, axis=1)[None, :])
    cell = np.all(np.abs(scan.grid - fit.point) <= steps * (1 + 1e-9), axis=1)
    excess = (replicate_rss[cell].min(axis=0) - replicate_rss.min(axis=0)) / variance
    limit = max(threshold, float(np.quantile(excess, confidence)))
    inside = scan.grid[(scan.grid_rss - float(scan.grid_rss.min())) / variance <= limit]
    region = np.concatenate([inside, fit.point[None, :]])
    corners = np.array([np.clip(region.min(axis=0) - steps, 0.0, 1.0), np.clip(region.max(axis=0) + steps, 0.0, 1.0)])
    if len(axes) == 1:
        corners[:, 1] = fit.point[1]
    split = [axis for axis in axes if np.any(np.diff(np.unique(region[:, axis])) > CLUSTER_GAP * steps[axis])]
    notes = [f"the region's deviance limit is {limit:.3g} (chi^2_1 {threshold:.3g}; a bootstrap of {DIRECT_BOOTSTRAP} "
             "replicates of the scan: the grid's best point fits the noise better than the truth does)"]
    if split:
        notes.append(f"the region falls apart into separate basins along {' and '.join(('k', 'xi')[a] for a in split)}"
                     f" on 0-{window.end:.2f} s: the range holds every fit that explains it as well as the best")
    if fit.tau > 2.0:
        notes.append(f"the residuals are correlated over {fit.tau:.0f} samples (model error or coloured noise): the "
                     f"region counts {n / fit.tau:.0f} of {n} samples as independent")
    whole = any(corners[0, axis] <= 0.0 and corners[1, axis] >= 1.0 for axis in axes)
    return {"point": np.array(fit.point, float), "end": window.end, "identifiable": not split,
            "range_points": corners, "noise_rms": math.sqrt(max(fit.rss - floor, 0.0) / n),
            "autocorrelation_time": fit.tau, "notes": notes, "limits": {axis: limit for axis in axes},
            "method": DIRECT_METHOD, "window": window, "whole_range": whole}


def _ar1_noise(residual, count, seed):
    """``count`` series of AR(1) noise with the variance and lag-1 correlation of ``residual`` (seeded)."""
    centred = residual - residual.mean()
    n = centred.size
    variance = float(np.mean(centred**2))
    phi = float(np.clip(np.sum(centred[1:] * centred[:-1]) / max(np.sum(centred**2), 1e-300), 0.0, 0.99))
    rng = np.random.default_rng(seed)
    shocks = rng.normal(0.0, math.sqrt(variance * (1.0 - phi**2)), (count, n))
    noise = np.empty_like(shocks)
    noise[:, 0] = rng.normal(0.0, math.sqrt(variance), count)
    for i in range(1, n):
        noise[:, i] = phi * noise[:, i - 1] + shocks[:, i]
    return noise


def _bootstrap_limits(search, times, reference, n, point, steps, fixed_xi, confidence, floor_rms, dt):
    """The profile deviances that bound the intervals, per axis: parametric bootstrap of the decisive window.

    The window's fit plus ``BOOTSTRAP`` noise series (AR(1) with the lag-1 autocorrelation and the variance of
    the fit's residuals; seeded) are refitted by batched Gauss-Newton from the fit, in all coordinates and with
    each coordinate held at its true (the fit's) value; the ``confidence`` quantile of each profile deviance
    n/tau ln(RSS_held / RSS_free) is its limit (at least chi^2_1). Where the likelihood is quadratic and the
    noise AR(1) this is chi^2_1; where the response is barely regular, a fit chases the noise into the
    response's wiggles and the deviance at the truth is larger, which the limit then carries.

    Returns
    -------
    dict
        {axis: limit} for k (0) and, unless fixed, xi (1).
    """
    from scipy.stats import chi2

    axes = (0,) if fixed_xi else (0, 1)
    floor = n * floor_rms**2
    t_end = float(times[n - 1]) + dt
    likelihood = _Likelihood(search, times[:n], reference[:n], t_end, floor=floor)
    values = likelihood.residuals([point])[0][0]
    fit = reference[:n] + values
    data = fit[None, :] + _ar1_noise(-values, BOOTSTRAP, BOOTSTRAP_SEED)
    start = np.repeat(np.asarray(point, float)[None, :], BOOTSTRAP, axis=0)
    free, free_rss, free_residual = _batch_gauss_newton(search, times[:n], t_end, data, start, axes, steps, floor,
                                                        BOOTSTRAP_ITERATIONS)
    tau = np.array([_floored_tau(r, floor) for r in free_residual])
    limits = {}
    for axis in axes:
        held = [a for a in axes if a != axis]
        held_rss = (_batch_gauss_newton(search, times[:n], t_end, data, start, tuple(held), steps, floor,
                                        BOOTSTRAP_ITERATIONS - 1)[1] if held else
                    np.sum((fit[None, :] - data) ** 2, axis=1) + floor)
        deviance = n / tau * np.log(np.maximum(held_rss, free_rss) / free_rss)
        limits[axis] = max(float(chi2.ppf(confidence, 1)), float(np.quantile(deviance, confidence)))
    return limits


def _batch_gauss_newton(search, times, t_end, data, points, axes, steps, floor, iterations):
    """Gauss-Newton of many replicates at once (replicate b fits ``data[b]``): (points, RSS, residuals).

    Each iteration runs every replicate's finite-difference stencil in one batch and tries the full, half and
    quarter step; a replicate keeps the best point it has seen.
    """
    points = np.array(points, float)
    count, axes = len(points), list(axes)

    def residuals(batch, rows):
        chunks = np.array_split(np.clip(batch, 0.0, 1.0), max(1, math.ceil(len(batch) / PROFILE_BATCH)))
        model = np.concatenate([_interpolate(search.histories(chunk, t_end), search.dt, times) for chunk in chunks])
        return model - data[rows]

    rows = np.arange(count)
    values = residuals(points, rows)
    rss = np.sum(values**2, axis=1) + floor
    for _ in range(iterations):
        stencil, shifts = _stencil(points, steps, axes)
        shifted = residuals(np.concatenate(stencil), np.tile(rows, 2 * len(axes)))
        jacobian = np.stack([(shifted[(2 * i) * count:(2 * i + 1) * count] - shifted[(2 * i + 1) * count:(2 * i + 2) *
                                                                                     count]) / shift[:, None]
                             for i, shift in enumerate(shifts)], axis=-1)
        moves = np.zeros((count, 2))
        for b in range(count):
            moves[b, axes] = _gauss_newton_step(values[b], jacobian[b])
        trials = np.concatenate([np.clip(points + factor * moves, 0.0, 1.0) for factor in (1.0, 0.5, 0.25)])
        trial_values = residuals(trials, np.tile(rows, 3))
        trial_rss = np.sum(trial_values**2, axis=1) + floor
        for factor in range(3):
            part = slice(factor * count, (factor + 1) * count)
            better = trial_rss[part] < rss
            points[better], rss[better] = trials[part][better], trial_rss[part][better]
            values[better] = trial_values[part][better]
    return points, rss, values


BOOTSTRAP = 40  # replicates of the parametric bootstrap of the decisive window
BOOTSTRAP_ITERATIONS = 5  # Gauss-Newton iterations per replicate (one fewer with a coordinate held)
BOOTSTRAP_SEED = 34  # the bootstrap's noise is seeded: the same reference gives the same intervals


def _unit(search, axis, value):
    """A physical k [N/m] (axis 0) or xi [-] (axis 1) in the unit box."""
    if axis == 0:
        return (math.log(value) - search.log_k[0]) / (search.log_k[1] - search.log_k[0])
    low, high = search.xi_range
    return (value - low) / (high - low) if high > low else 0.0


CALIBRATION_OPTIONS = Table({
    "n_k": Number(2, integer=True),
    "n_xi": Number(1, integer=True),
    "k_range": Interval(Number(0.0, low_open=True, unit="N/m"), names=("k_min", "k_max")),
    "xi_range": Interval(Number(0.0, 1.0, high_open=True), names=("xi_min", "xi_max"), strict=False),
    "confidence": Number(0.0, 1.0, low_open=True, high_open=True),
})
"""The search settings of ``calibrate`` (rockfrag.validation): grid sizes, the search box, the confidence."""


def _validate(model, ref_time, ref_rotation, ag, dt, k_range, xi_range, n_k, n_xi, confidence=None):
    spec = get_model(model)
    if not spec.needs_foundation:
        raise ConfigError("model", f"{model!r} has no foundation parameters to calibrate; choose a model with a "
                          "foundation (e.g. ssi)")
    options = {"n_k": n_k, "n_xi": n_xi, "k_range": k_range, "xi_range": xi_range}
    CALIBRATION_OPTIONS.check(options if confidence is None else {**options, "confidence": confidence}, "", None)
    ref_time = np.asarray(ref_time, float)
    ref_rotation = np.asarray(ref_rotation, float)
    if ref_time.ndim != 1 or ref_time.shape != ref_rotation.shape or ref_time.size < 10:
        raise ConfigError("reference", "time and rotation must be 1-D arrays of equal length >= 10")
    if not (np.all(np.isfinite(ref_time)) and np.all(np.isfinite(ref_rotation))):
        raise ConfigError("reference", "time and rotation must be finite")
    if np.any(np.diff(ref_time) <= 0):
        raise ConfigError("reference", "time must increase strictly")
    check_reference(ref_time, ref_rotation, (len(ag) - 1) * dt, dt)
    return ref_time, ref_rotation


def calibrate(ref_time: ArrayLike, ref_rotation: ArrayLike, ag: ArrayLike, dt: float, block: Block, *,
              model: str = "ssi", k_range: tuple[float, float] = (1e8, 1e9),
              xi_range: tuple[float, float] = (0.01, 0.07), n_k: int = 25, n_xi: int = 7,
              soil_shear_modulus: float | None = None, switch: str = "consistent", local: bool = True,
              smoothing_hz: float | None = SMOOTHING_HZ, log: Callable[[str], object] | None = None,
              confidence: float | None = CONFIDENCE, **solver_options: object) -> CalibrationResult:
    """Find (k, xi) maximising eq. 17's correlation between the reference and ``model``'s rotation.

    Parameters
    ----------
    ref_time, ref_rotation : array_like
        Reference time [s] (from the start of ``ag``) and rotation [rad], 1-D, equal length >= 10,
        time strictly increasing.
    ag : array_like
        Ground acceleration [m/s^2] that produced the reference.
    dt : float
        Time step of ``ag`` [s].
    block : Block
        The rocking block (geometry, mass, block modulus ``E_b`` [Pa]).
    model : str
        A registered model with a foundation (``ssi``, ``ssi-paper``, ``winkler``, ...).
    k_range : (float, float)
        Search range of the interface stiffness k [N/m] (min, max), searched in log space.
    xi_range : (float, float)
        Search range of the damping ratio xi [-] (min, max); min == max fixes xi.
    n_k, n_xi : int
        Coarse grid points (n_k >= 2, n_xi >= 1).
    soil_shear_modulus : float, optional
        Soil shear modulus G_s [Pa]; if given, the result also holds A/H [m] from eq. 19.
    switch : str
        ssi pivot-switch rule (``consistent`` or ``continuous``).
    local : bool
        False: the coarse grid only (the paper's procedure).
    smoothing_hz : float or None
        Low-pass of the search objective [Hz]; None searches on the raw signals.
    log : callable, optional
        Receives one line per search stage.
    confidence : float or None
        Two-sided level of the profile-likelihood intervals of k and xi (default 0.9); None skips them.
        Not computed with ``local=False``.
    **solver_options
        Passed to ``simulate_histories`` (e.g. ``bed=`` for winkler, ``restitution=``).

    Returns
    -------
    CalibrationResult
        The fitted k [N/m] and xi [-] with their confidence intervals, the eq. 17 correlation, errors
        against the reference and the coarse grid's correlation surface.

    Raises
    ------
    ConfigError
        ``model`` has no foundation, the search settings are out of range, or the reference cannot
        belong to the record (arrays of different length, not finite, time not increasing, starting
        outside the record, constant or larger than pi: usually a wrong unit).
    """
    started = clock.perf_counter()
    ref_time, ref_rotation = _validate(model, ref_time, ref_rotation, ag, dt, k_range, xi_range, n_k, n_xi,
                                       confidence)
    fixed_xi = xi_range[0] == xi_range[1] or n_xi == 1
    n_xi = 1 if fixed_xi else n_xi
    search = _Search(model, np.asarray(ag, float), dt, block, k_range, xi_range, switch, solver_options)
    t_end = float(ref_time[-1]) + dt

    times, step = _uniform_times(ref_time, dt)
    objective = _Objective(times, np.interp(times, ref_time, ref_rotation), smoothing_hz)
    windows = _window_ends(objective.smoothed_reference, step) if local else [times.size]

    u_grid = np.linspace(0.0, 1.0, n_k)
    v_grid = np.linspace(0.0, 1.0, n_xi) if n_xi > 1 else np.array([0.0])
    grid = np.array([(u, v) for u in u_grid for v in v_grid])
    grid_theta = search.histories(grid, t_end)
    grid_on_times = _interpolate(grid_theta, dt, times)
    # eq. 17 at the reference's own steps, one row at a time (a long reference times the grid is too big)
    surface = np.array([correlation(ref_rotation, _interpolate(grid_theta[i:i + 1], dt, ref_time)[0])
                        for i in range(len(grid))])
    full_scores = objective(grid_on_times, times.size)
    grid_best = int(np.argmin(full_scores))
    if log:
        log(f"coarse grid: {len(grid)} simulations; best k = {search.physical(grid[grid_best])[0]:.4g} N/m, "
            f"xi = {search.physical(grid[grid_best])[1]:.4f}, correlation {surface[grid_best]:.4f}")

    steps = np.array([1.0 / (n_k - 1), 1.0 / (n_xi - 1) if n_xi > 1 else 1.0])
    best_point, best_score = grid[grid_best], float(full_scores[grid_best])
    history = []
    if local:
        point, score, history = _continuation(search, objective, grid, grid_on_times, (n_k, n_xi), windows,
                                              steps, fixed_xi, log)
        if score < best_score:
            best_point, best_score = point, score

    k_search, xi_search = search.physical(best_point)
    intervals, before = {}, search.count
    if local and confidence is not None:
        peak = float(np.max(np.abs(ref_rotation)))
        decision = _decide(search, times, objective.reference, history, best_point, fixed_xi,
                           confidence, NOISE_FLOOR * peak,
                           _quiet_samples(objective.smoothed_reference), log)
        best_point = decision["point"]
        intervals = _interval_fields(search, decision, fixed_xi, confidence, peak)
        intervals["interval_simulations"] = search.count - before
        if log:
            log(f"intervals: {search.count - before} simulations ({intervals['interval_method']}, {confidence:.0%})")
    k_fit, xi_fit = search.physical(best_point)
    theta = search.histories([best_point], t_end)
    model_on_reference = _interpolate(theta, dt, ref_time)[0]
    score = correlation(ref_rotation, model_on_reference)
    rms = float(np.sqrt(np.mean((model_on_reference - ref_rotation) ** 2)))
    peak_model = float(np.max(np.abs(model_on_reference)))
    peak_reference = float(np.max(np.abs(ref_rotation)))
    area_over_depth = None
    if soil_shear_modulus:
        area_over_depth = k_fit * (1.0 / soil_shear_modulus + 1.0 / block.E_b)  # eq. 19 solved for A/H
    k_grid, xi_grid = search.physical(grid[grid_best])
    return CalibrationResult(
        k_grid=float(k_grid), xi_grid=float(xi_grid), correlation_grid=float(surface[grid_best]),
        k=float(k_fit), xi=float(xi_fit), correlation=score, rms_error=rms,
        peak_error=(peak_model - peak_reference) / peak_reference, peak_reference=peak_reference,
        peak_model=peak_model, area_over_depth=area_over_depth, soil_shear_modulus=soil_shear_modulus,
        block_modulus=block.E_b, model=model, bed=_bed_of(model, solver_options), objective=best_score,
        n_simulations=search.count, n_windows=len(history), k_search=float(k_search), xi_search=float(xi_search),
        seconds=clock.perf_counter() - started,
        surface_k=[search.physical((u, 0))[0] for u in u_grid],
        surface_xi=[search.physical((0, v))[1] for v in v_grid],
        surface=surface.reshape(n_k, n_xi).tolist(), **intervals)


def _interval_fields(search, decision, fixed_xi, confidence, peak):
    """``CalibrationResult`` fields of the intervals from ``_decide``'s decision."""
    notes = list(decision["notes"])
    fields = {key: decision.get(key) for key in ("noise_rms", "autocorrelation_time", "profile_k",
                                                 "profile_k_deviance", "profile_xi", "profile_xi_deviance")}
    fields = {key: value for key, value in fields.items() if value is not None}
    noise = fields.get("noise_rms", 0.0)
    if noise < NOISE_FLOOR * peak:
        notes.append(f"the reference has almost no noise (residual RMS {noise:.3g} rad, {noise / peak:.2%} of its "
                     f"peak): the intervals assume {NOISE_FLOOR:.1%} of the peak, {NOISE_FLOOR * peak:.3g} rad, and "
                     "say how precisely the model reproduces the reference rather than how well k and xi are known")
    bounds = {}
    for axis, name in ((0, "k"), (1, "xi")):
        if axis == 1 and fixed_xi:
            bounds.update(xi_low=None, xi_high=None)
            continue
        values = [search.physical(p)[axis] for p in decision["range_points"]]
        if decision.get(f"{name}_low") is not None:
            values += [decision[f"{name}_low"], decision[f"{name}_high"]]
        bounds[f"{name}_low"], bounds[f"{name}_high"] = float(min(values)), float(max(values))
    method = decision.get("method", "profile likelihood on the decisive window")
    if not decision["identifiable"]:
        method = f"{NOT_IDENTIFIABLE}: the range of fits that explain it equally ({method})"
    limits = {("k", "xi")[axis]: float(limit) for axis, limit in decision.get("limits", {}).items()}
    return dict(fields, **bounds, confidence=float(confidence), interval_method=method, interval_notes=notes,
                identifiable=bool(decision["identifiable"]), decisive_window=decision["end"],
                windows=decision["windows"], deviance_limits=limits)


def _uniform_times(ref_time, dt):
    """The uniform search grid [s] and its step: the reference's own, no finer than dt/2 (finer adds nothing)."""
    step = max(float(np.median(np.diff(ref_time))), dt / 2)
    times = np.arange(ref_time[0], ref_time[-1] + 0.5 * step, step)
    return times[times <= ref_time[-1]], step


def fit_intervals(ref_time: ArrayLike, ref_rotation: ArrayLike, ag: ArrayLike, dt: float, block: Block, k: float,
                  xi: float, *, model: str = "ssi", k_range: tuple[float, float] = (1e8, 9e8),
                  xi_range: tuple[float, float] = (0.01, 0.07), confidence: float = CONFIDENCE,
                  switch: str = "consistent", **solver_options: object) -> dict:
    """Profile-likelihood confidence intervals of k and xi around a fit (k, xi), as ``calibrate`` computes them.

    Parameters
    ----------
    ref_time, ref_rotation : array_like
        Reference time [s] and rotation [rad] (as for ``calibrate``).
    ag : array_like
        Ground acceleration [m/s^2]; ``dt`` its step [s].
    dt : float
        Time step of ``ag`` [s].
    block : Block
        The rocking block.
    k, xi : float
        The fit: interface stiffness [N/m] and damping ratio [-]; the intervals start from it and move to
        the maximum-likelihood point first, so any start in the optimum's basin gives the same intervals.
    model, k_range, xi_range, switch, **solver_options
        As for ``calibrate``; the intervals stay inside the search range (xi_range min == max fixes xi).
    confidence : float
        Two-sided level in (0, 1).

    Returns
    -------
    dict
        ``k_low``, ``k_high`` [N/m], ``xi_low``, ``xi_high`` [-], ``noise_rms`` [rad],
        ``autocorrelation_time`` [samples], ``notes`` and the profiles (``_profile_intervals``).
    """
    fixed_xi = xi_range[0] == xi_range[1]
    ref_time, ref_rotation = _validate(model, ref_time, ref_rotation, ag, dt, k_range, xi_range, 2, 1, confidence)
    search = _Search(model, np.asarray(ag, float), dt, block, k_range, xi_range, switch, solver_options)
    times, _ = _uniform_times(ref_time, dt)
    u = math.log(k / k_range[0]) / math.log(k_range[1] / k_range[0])
    v = 0.0 if fixed_xi else (xi - xi_range[0]) / (xi_range[1] - xi_range[0])
    return _profile_intervals(search, times, np.interp(times, ref_time, ref_rotation), (u, v), fixed_xi, confidence,
                             float(ref_time[-1]) + dt)


def _bed_of(model, solver_options):
    """The bed type a calibration of ``model`` ran with (None when the model has no bed)."""
    if not get_model(model).uses_bed:
        return None
    return solver_options.get("bed", SolverOptions.bed)


# ----------------------------------------------------------------------------------------- outputs


def write_outputs(result: CalibrationResult, ref_time, ref_rotation, ag, dt, block, output, switch="consistent",
                  **solver_options):
    """calibration.json, calibration.csv, calibration-fit.png, calibration-surface.png, calibration-profile.png.

    The profile figure (the profile deviance of k and of xi, the threshold and the intervals) only when the
    intervals were computed.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    summary = result.summary()
    with atomic_path(output / "calibration.json") as temporary:
        temporary.write_text(json.dumps(summary, indent=2))
    with atomic_path(output / "calibration.csv") as temporary:
        pd.DataFrame([{k: v for k, v in summary.items() if k != "units"}]).to_csv(temporary, index=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t, th, _, _ = simulate_histories(result.model, ag, dt, [(block, result.k, result.xi)], switch=switch,
                                         t_end=float(ref_time[-1]) + dt, **solver_options)
    label = getattr(get_model(result.model), "label", result.model)
    if result.bed:
        label += f" ({result.bed} bed)"
    figure, axis = plt.subplots(figsize=(10, 4.5), constrained_layout=True)
    axis.plot(ref_time, ref_rotation, color="k", lw=1.0, label="reference")
    axis.plot(t, th[0], color="C3", lw=0.9, ls="--", label=f"{label}, {_fit_label(result)}")
    axis.set_xlabel("time [s]")
    axis.set_ylabel("rotation θ [rad]")
    axis.set_title(f"Calibration: correlation (eq. 17) {result.correlation:.3f}, RMS error {result.rms_error:.2e} "
                   f"rad, peak error {result.peak_error:+.1%}")
    axis.grid(alpha=0.3)
    axis.legend(loc="upper right", fontsize=8)
    with atomic_path(output / "calibration-fit.png") as temporary:
        figure.savefig(temporary, dpi=120, format="png")
    plt.close(figure)
    figure, axis = plt.subplots(figsize=(7, 5), constrained_layout=True)
    surface = np.array(result.surface)
    xi_percent = np.array(result.surface_xi) * 100
    if xi_percent.size == 1:  # one xi: draw the k profile as a one-column strip
        xi_percent = np.array([xi_percent[0] - 0.5, xi_percent[0] + 0.5])
        surface = np.repeat(surface, 2, axis=1)
    mesh = axis.pcolormesh(xi_percent, np.array(result.surface_k), surface, shading="nearest", cmap="viridis")
    axis.set_yscale("log")
    axis.plot(result.xi * 100, result.k, "r*", ms=14, label="optimum")
    if result.k_low is not None:  # the intervals: usually far smaller than a grid cell, drawn all the same
        axis.plot([result.xi * 100] * 2, [result.k_low, result.k_high], "r-", lw=1.5,
                  label=f"{result.confidence:.0%} intervals")
        if result.xi_low is not None:
            axis.plot([result.xi_low * 100, result.xi_high * 100], [result.k] * 2, "r-", lw=1.5)
    axis.plot(result.xi_grid * 100, result.k_grid, "wo", ms=7, mfc="none", label="best grid point")
    axis.set_xlabel("damping ratio ξ [%]")
    axis.set_ylabel("interface stiffness k [N/m]")
    axis.set_title("Correlation with the reference on the coarse grid (paper eq. 17)")
    axis.legend(fontsize=8)
    figure.colorbar(mesh, label="Pearson correlation [-]")
    with atomic_path(output / "calibration-surface.png") as temporary:
        figure.savefig(temporary, dpi=120, format="png")
    plt.close(figure)
    names = ["calibration.json", "calibration.csv", "calibration-fit.png", "calibration-surface.png"]
    if result.profile_k:
        _plot_profiles(result, output / "calibration-profile.png")
        names.append("calibration-profile.png")
    return [output / name for name in names]


def _fit_label(result: CalibrationResult) -> str:
    """"k = 4.6e+08 N/m [4.59e+08, 4.61e+08], ξ = 0.0270 [0.0268, 0.0272] (90 %)", without brackets if none."""
    if result.k_low is None:
        return f"k = {result.k:.4g} N/m, ξ = {result.xi:.4f}"
    xi = f" [{result.xi_low:.4f}, {result.xi_high:.4f}]" if result.xi_low is not None else " (fixed)"
    return (f"k = {result.k:.4g} N/m [{result.k_low:.4g}, {result.k_high:.4g}], ξ = {result.xi:.4f}{xi} "
            f"({result.confidence:.0%} intervals)")


def _plot_profiles(result: CalibrationResult, path: Path) -> None:
    """The profile deviance of k and of xi with the chi-square threshold and the intervals shaded."""
    import matplotlib.pyplot as plt
    from scipy.stats import chi2

    threshold = chi2.ppf(result.confidence, 1)
    panels = [("k", np.array(result.profile_k), result.profile_k_deviance, result.k, result.k_low, result.k_high,
               "interface stiffness k [N/m]")]
    if result.profile_xi:
        panels.append(("xi", np.array(result.profile_xi), result.profile_xi_deviance, result.xi, result.xi_low,
                       result.xi_high, "damping ratio ξ [-]"))
    figure, axes = plt.subplots(1, len(panels), figsize=(5.5 * len(panels), 4.2), constrained_layout=True,
                                squeeze=False)
    for axis, (name, values, deviance, fit, low, high, xlabel) in zip(axes[0], panels):
        axis.plot(values, deviance, "k.-", lw=1.0, ms=4, label="profile deviance")
        axis.axhline(threshold, color="C3", lw=0.9, ls="--", label=f"χ²₁ {result.confidence:.0%} = {threshold:.2f}")
        axis.axvspan(low, high, color="C0", alpha=0.15, label=f"{result.confidence:.0%} interval")
        axis.axvline(fit, color="C3", lw=0.8, label="estimate")
        axis.set_xlabel(xlabel)
        axis.set_ylabel("profile deviance D = n_eff ln(RSS / RSS_min) [-]")
        axis.set_ylim(0, max(3 * threshold, 1.0))
        axis.grid(alpha=0.3)
        axis.legend(fontsize=8)
    figure.suptitle(f"Profile likelihood of the calibration: the {result.confidence:.0%} interval is where the "
                    "curve stays below the line", fontsize=10)
    with atomic_path(path) as temporary:
        figure.savefig(temporary, dpi=120, format="png")
    plt.close(figure)
