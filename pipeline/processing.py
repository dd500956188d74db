"""rockfrag.processing - stage 2: raw acceleration trace -> corrected trace ready for analysis.

Input : a ``Record`` (obspy Trace of acceleration [m/s^2]) and a ``ProcessingRecipe`` (ordered list
        of named steps with parameters; the shipped one is ``pipeline/processing.toml``).
Output: a new ``Record`` whose trace is demeaned, detrended, tapered, zero-phase band-passed and
        baseline-corrected, with every step recorded in ``stats.processing`` and QA flags (tail drift
        of velocity/displacement, gmprocess ``check_tail`` style) in ``stats.qa``. Flags never drop
        a record. Inputs are not modified.

A step is one function registered with ``@processing_step``, which declares the schema of each keyword
parameter (rockfrag.validation): what a recipe may set. A parameter without a default must be set by
the recipe (the band-pass corners: the recipe file is their one authority). Steps talk through the
trace: ``pad`` records the samples it added in ``stats.padding`` and ``unpad`` removes them; a step
that depends on another step's settings names it in ``reads`` and receives that step's parameters
(``pad`` reads ``bandpass``: its length depends on the filter's corner). The decorator records each
step in ``stats.processing`` after it succeeds, as obspy's ``_add_processing_info`` does.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import math
import os
import re
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib.resources import files
from typing import Any

import numpy as np
from scipy.integrate import cumulative_trapezoid

from rockfrag.errors import ConfigError, RecordError
from rockfrag.records import Record
from rockfrag.validation import Checked, Flag, Number, Table, Text, shown
from rockfrag.version import __version__


@dataclass(frozen=True)
class ProcessingStep:
    """A registered step: the function (wrapped to record provenance) and what a recipe may set."""

    name: str
    run: Callable[..., Any]
    parameters: Table
    """Schema of the parameters a recipe may set; ``required``: those without a default."""
    reads: tuple[str, ...] = ()
    """Steps whose parameters this step receives, as keywords named after them."""
    defaults: dict = field(default_factory=dict)
    """The defaults of the function's signature (parameters without one are required)."""

    def arguments(self, params: dict) -> dict:
        """The step's parameters with the defaults of its signature filled in."""
        return {**self.defaults, **params}


PROCESSING_STEPS: dict[str, ProcessingStep] = {}
"""The registered steps by name (``@processing_step``)."""


def processing_step(reads: tuple[str, ...] = (), **parameters):
    """Register a step ``function(trace, *, parameter=default, ...)`` that works on the trace in place.

    Parameters
    ----------
    reads : tuple of str
        Steps whose parameters (with their defaults) the function receives, one keyword per step.
    **parameters
        The schema of each keyword parameter a recipe may set (``Number``, ``Text``, ``Flag`` ...);
        every keyword parameter of the function but ``reads`` needs one.

    The registered function appends ``"rockfrag VERSION: name(parameter=value, ...)"`` (and
    ``"; npts N -> M"`` if the step changed the length) to ``trace.stats.processing`` once the step has
    succeeded.
    """

    def register(function):
        signature = inspect.signature(function)
        settable = [name for name in signature.parameters if name != "trace" and name not in reads]
        if sorted(settable) != sorted(parameters):
            raise TypeError(f"step {function.__name__}: declare a schema for each of its parameters "
                            f"({', '.join(settable) or 'none'}); got {', '.join(parameters) or 'none'}")
        defaults = {name: signature.parameters[name].default for name in settable
                    if signature.parameters[name].default is not inspect.Parameter.empty}
        required = tuple(name for name in settable if name not in defaults)

        @functools.wraps(function)
        def run(trace, **arguments):
            npts = trace.stats.npts
            trace = function(trace, **arguments)
            given = {**defaults, **arguments}
            used = ", ".join(f"{name}={given[name]!r}" for name in settable if name in given)
            resized = f"; npts {npts} -> {trace.stats.npts}" if trace.stats.npts != npts else ""
            trace.stats.setdefault("processing", []).append(
                f"rockfrag {__version__}: {function.__name__}({used}){resized}")
            return trace

        PROCESSING_STEPS[function.__name__] = ProcessingStep(
            function.__name__, run, Table(parameters, required, what=f"parameter of step {function.__name__!r}"),
            tuple(reads), defaults)
        return run

    return register


@processing_step()
def demean(trace):
    """Remove the mean."""
    trace.detrend("demean")
    return trace


@processing_step()
def detrend(trace):
    """Remove a straight line fitted to the whole record."""
    trace.detrend("linear")
    return trace


TAPER_TYPES = ("hann", "cosine", "barthann", "bartlett", "blackman", "blackmanharris", "bohman", "boxcar",
               "flattop", "hamming", "nuttall", "parzen", "triang")
"""obspy ``Trace.taper`` windows that need no further parameter."""


@processing_step(max_percentage=Number(0.0, 0.5), type=Text(TAPER_TYPES))
def taper(trace, *, max_percentage=0.05, type="hann"):
    """Taper ``max_percentage`` of the record at each end (obspy ``Trace.taper``)."""
    trace.taper(max_percentage=max_percentage, type=type)
    return trace


@processing_step(reads=("bandpass",), factor=Number(0.0, 20.0))
def pad(trace, *, factor=1.5, bandpass):
    """Zero pads of factor * order / freqmin seconds at both ends (acausal filter transients, Boore 2005).

    ``bandpass`` holds the parameters of the recipe's band-pass step for this record; freqmin is the
    corner that step will use (see ``bandpass_corners``). The samples added at each end go to
    ``stats.padding``, for ``unpad``.
    """
    freqmin = bandpass_corners(trace, bandpass["freqmin"], bandpass["freqmax"], bandpass["nyquist_fraction"],
                               bandpass["use_header_corners"])[0]
    seconds = factor * bandpass["corners"] / freqmin
    n_pad = int(math.ceil(seconds / trace.stats.delta))
    trace.data = np.concatenate([np.zeros(n_pad), trace.data, np.zeros(n_pad)])
    trace.stats.padding = trace.stats.get("padding", 0) + n_pad
    return trace


@processing_step()
def unpad(trace):
    """Remove the zeros ``pad`` added (``stats.padding`` samples at each end)."""
    n_pad = trace.stats.pop("padding", 0)
    if n_pad:
        trace.data = trace.data[n_pad:-n_pad].copy()
    return trace


_HEADER_POLE = re.compile(r"(-?\d+)\s*POLE\s*@\s*([0-9.]+)", re.IGNORECASE)


def header_corners(trace):
    """(highpass, lowpass) corners [Hz] written by PEER into an NGA-West2 header, or (None, None).

    NGA-West2 writes e.g. ``4 POLE @ 40.0 HZ, -5 POLE @ .20``: positive poles are the low-pass, negative
    the high-pass filter; ``0 POLE`` means no filter.
    """
    text = trace.stats.get("peer_at2", {}).get("filter", "")
    highpass = lowpass = None
    for poles, frequency in _HEADER_POLE.findall(text):
        poles, frequency = int(poles), float(frequency)
        if poles < 0 and frequency > 0:
            highpass = frequency
        elif poles > 0 and frequency > 0:
            lowpass = frequency
    return highpass, lowpass


def bandpass_corners(trace, freqmin: float, freqmax: float, nyquist_fraction: float,
                     use_header_corners: bool) -> tuple[float, float]:
    """Corners [Hz] actually used: header corners where stricter, low-pass below Nyquist.

    Parameters
    ----------
    trace : obspy.Trace
        The record (its sampling interval and, for NGA-West2 files, its header's filter corners).
    freqmin, freqmax : float
        High-pass and low-pass corners the recipe asks for [Hz].
    nyquist_fraction : float
        The low-pass is kept at or below this fraction of the Nyquist frequency [-].
    use_header_corners : bool
        Raise the high-pass and lower the low-pass to the corners PEER wrote into the header.
    """
    nyquist = 0.5 / trace.stats.delta
    if use_header_corners:
        header_hp, header_lp = header_corners(trace)
        freqmin = max(freqmin, header_hp or 0.0)
        freqmax = min(freqmax, header_lp or math.inf)
    return freqmin, min(freqmax, nyquist_fraction * nyquist)


@processing_step(freqmin=Number(1e-3, 10.0, unit="Hz"), freqmax=Number(0.5, 1000.0, unit="Hz"),
                 corners=Number(1, 10, integer=True), nyquist_fraction=Number(0.1, 0.99), use_header_corners=Flag())
def bandpass(trace, *, freqmin, freqmax, corners=4, nyquist_fraction=0.8, use_header_corners=True):
    """Zero-phase Butterworth band-pass of order ``corners`` per pass, at ``bandpass_corners``.

    freqmin and freqmax have no default: the recipe sets them (``pipeline/processing.toml``).
    """
    low, high = bandpass_corners(trace, freqmin, freqmax, nyquist_fraction, use_header_corners)
    trace.filter("bandpass", freqmin=low, freqmax=high, corners=int(corners), zerophase=True)
    return trace


@processing_step(order=Number(3, 12, integer=True))
def baseline(trace, *, order=6):
    """Remove d''(t) of a polynomial d(t) = sum_{k=2..order} c_k t^k fitted to the displacement.

    No constant or linear term, so the correction starts from rest (PEER / Ancheta et al. 2014).
    The least-squares fit is constrained to match the final displacement and velocity, so the
    corrected record ends at rest (zero velocity and displacement).
    """
    dt = trace.stats.delta
    time = np.arange(trace.stats.npts) * dt
    velocity, displacement = integrate(trace.data, dt)
    duration = time[-1] if time[-1] > 0 else 1.0
    tau = time / duration  # fit in t/T for conditioning
    powers = np.arange(2, int(order) + 1)
    basis = tau[:, None] ** powers[None, :]
    # equality constraints at tau = 1: d_fit(T) = d(T) and d_fit'(T) = v(T)
    constraints = np.vstack([np.ones(powers.size), powers / duration])
    targets = np.array([displacement[-1], velocity[-1]])
    n = powers.size
    kkt = np.zeros((n + 2, n + 2))
    kkt[:n, :n] = basis.T @ basis
    kkt[:n, n:] = constraints.T
    kkt[n:, :n] = constraints
    rhs = np.concatenate([basis.T @ displacement, targets])
    coefficients = np.linalg.solve(kkt, rhs)[:n]
    second_derivative = ((powers * (powers - 1)) * coefficients
                         * tau[:, None] ** (powers - 2)).sum(axis=1) / duration**2
    trace.data = trace.data - second_derivative
    return trace


# ---------------------------------------------------------------- recipe

@dataclass(frozen=True)
class ProcessingRecipe:
    """Ordered processing steps, QA thresholds and per-record step overrides (validated)."""

    steps: tuple[tuple[str, dict], ...]
    qa: dict = field(default_factory=dict)
    overrides: dict = field(default_factory=dict)
    source: str = "pipeline/processing.toml"

    def as_dict(self) -> dict:
        """The recipe as plain data (``steps``, ``qa``, ``overrides``): JSON for provenance and cache keys."""
        return {"steps": [{"name": name, **params} for name, params in self.steps],
                "qa": dict(self.qa), "overrides": self.overrides}

    def steps_for(self, record_id: str) -> list[tuple[str, dict]]:
        """The steps as they run on one record: each step's parameters with the record's overrides."""
        overrides = self.overrides.get(record_id, {})
        return [(name, {**params, **overrides.get(name, {})}) for name, params in self.steps]


QA_DEFAULTS = {"tail_seconds": 5.0, "velocity_ratio": 0.3, "displacement_ratio": 0.6}
QA_TABLE = Table({"tail_seconds": Number(0.1, 100.0, unit="s"), "velocity_ratio": Number(0.0, 10.0),
                  "displacement_ratio": Number(0.0, 10.0)})
"""``[qa]``: the arguments of ``tail_checks``."""


def _step(name, field, source) -> ProcessingStep:
    if name not in PROCESSING_STEPS:
        raise ConfigError(field, f"unknown step {name!r}; available: {', '.join(PROCESSING_STEPS)}", source)
    return PROCESSING_STEPS[name]


def _check_steps(value, field, source) -> list:
    """Check ``[[steps]]``: a non-empty list of tables, each a step's name and its schema's parameters.

    Parameters without a default are required; a step that reads another needs it; pads and unpads
    pair up.
    """
    if not isinstance(value, list) or not value:
        raise ConfigError(field, f"{shown(value)}; expected a non-empty list of [[steps]] tables", source)
    names = []
    for index, raw in enumerate(value):
        where = f"{field}[{index}]"
        if not isinstance(raw, dict) or not isinstance(raw.get("name"), str):
            raise ConfigError(where, "each step needs a name (text)", source)
        step = _step(raw["name"], where, source)
        step.parameters.check({k: v for k, v in raw.items() if k != "name"}, where, source)
        names.append(step.name)
    for name in dict.fromkeys(names):
        for other in PROCESSING_STEPS[name].reads:
            if other not in names:
                raise ConfigError(field, f"step {name!r} needs a {other!r} step (it reads that step's parameters)",
                                  source)
    if names.count("pad") != names.count("unpad"):
        raise ConfigError(field, "every 'pad' step needs a matching 'unpad' step", source)
    return value


def _check_overrides(value, field, source) -> dict:
    """``[overrides."RECORD_ID".STEP]``: parameters of one step for one record (none required)."""
    if not isinstance(value, dict):
        raise ConfigError(field, f"{shown(value)}; expected tables [overrides.\"RECORD_ID\".STEP]", source)
    for record_id, by_step in value.items():
        if not isinstance(by_step, dict):
            raise ConfigError(f"{field}.{record_id}", "expected a table of steps", source)
        for name, params in by_step.items():
            where = f"{field}.{record_id}.{name}"
            if not isinstance(params, dict):
                raise ConfigError(where, "expected a table of parameters", source)
            dataclasses.replace(_step(name, where, source).parameters, required=()).check(params, where, source)
    return value


RECIPE = Table({"steps": Checked(_check_steps, "a non-empty list of [[steps]] tables"), "qa": QA_TABLE,
                "overrides": Checked(_check_overrides, 'tables [overrides."RECORD_ID".STEP]')},
               required=("steps",))
"""The schema of a recipe file (``pipeline/processing.toml``)."""


def recipe_from_dict(data: dict, source="<dict>") -> ProcessingRecipe:
    """Validate a recipe given as a dict (the TOML layout) and freeze it."""
    RECIPE.check(data, "", source)
    steps = tuple((raw["name"], {k: v for k, v in raw.items() if k != "name"}) for raw in data["steps"])
    names = [name for name, _ in steps]
    overrides = data.get("overrides", {})
    for record_id, by_step in overrides.items():
        for name in by_step:
            if name not in names:
                raise ConfigError(f"overrides.{record_id}.{name}", f"step not in the recipe; steps: "
                                  f"{', '.join(names)}", source)
    qa = {**QA_DEFAULTS, **{key: float(value) for key, value in data.get("qa", {}).items()}}
    return ProcessingRecipe(steps, qa, overrides, source)


def load_recipe(path: str | os.PathLike | None = None) -> ProcessingRecipe:
    """The shipped default recipe, or a user TOML file with the same layout (validated).

    Parameters
    ----------
    path : str or os.PathLike, optional
        A recipe TOML file (the layout of ``pipeline/processing.toml``: ``[[steps]]`` in order, each a
        ``@processing_step`` name with its parameters, optional ``[qa]`` limits and ``[overrides."RECORD_ID".step]``
        per record). None: the shipped recipe.

    Returns
    -------
    ProcessingRecipe
        The validated steps, QA limits and per-record overrides, for ``process_record``.

    Raises
    ------
    ConfigError
        Field ``processing``: the file cannot be read or is not TOML; or a step, parameter or value the recipe
        names is unknown or out of its range.
    """
    if path is None:
        text = files("rockfrag").joinpath("processing.toml").read_text()
        source = "pipeline/processing.toml"
    else:
        try:
            with open(path, encoding="utf-8") as handle:
                text = handle.read()
        except OSError as error:
            raise ConfigError("processing", f"cannot read recipe: {error.strerror}", str(path)) from None
        except UnicodeDecodeError:
            raise ConfigError("processing", "not a text file; expected a TOML recipe", str(path)) from None
        source = str(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ConfigError("processing", f"not valid TOML ({error})", source) from None
    return recipe_from_dict(data, source)


# ---------------------------------------------------------------- running it

def integrate(acceleration, dt):
    """Velocity [m/s] and displacement [m] from acceleration [m/s^2] (trapezoidal, from rest)."""
    velocity = cumulative_trapezoid(acceleration, dx=dt, initial=0.0)
    displacement = cumulative_trapezoid(velocity, dx=dt, initial=0.0)
    return velocity, displacement


def tail_checks(acceleration, dt, tail_seconds=5.0, velocity_ratio=0.3, displacement_ratio=0.6):
    """QA flags for velocity/displacement drift at the end of a record (empty list if it passes)."""
    velocity, displacement = integrate(acceleration, dt)
    n_tail = max(1, min(len(acceleration), int(round(tail_seconds / dt))))
    flags = []
    for name, series, limit in (("velocity", velocity, velocity_ratio),
                                ("displacement", displacement, displacement_ratio)):
        peak = np.max(np.abs(series))
        ratio = np.max(np.abs(series[-n_tail:])) / peak if peak > 0 else 0.0
        if ratio > limit:
            flags.append(f"{name} tail drift: max|{name}| in the last {tail_seconds:g} s is "
                         f"{ratio:.2f} of its peak (limit {limit:g})")
    return flags


def process_record(record: Record, recipe: ProcessingRecipe | None = None) -> Record:
    """Apply the recipe to a copy of the record; return the new, corrected ``Record``.

    Parameters
    ----------
    record : Record
        A record as read (``rockfrag.records``): ground acceleration [m/s^2] in ``record.trace``.
        It is not modified.
    recipe : ProcessingRecipe, optional
        The steps to run (``load_recipe``); the shipped ``pipeline/processing.toml`` if omitted. The
        record's entry in ``recipe.overrides`` changes its steps' parameters.

    Returns
    -------
    Record
        A new record with the same id and metadata whose trace holds the corrected acceleration
        [m/s^2], one ``stats.processing`` line per step and the tail-drift flags in ``stats.qa``.

    Raises
    ------
    RecordError
        Naming the record's file and the step, when the record cannot be processed: a numerical
        failure of a step, or a result that is not finite or is all zero.
    """
    recipe = recipe or load_recipe()
    source = record.metadata.get("file") or record.id
    trace = record.trace.copy()
    trace.data = np.asarray(trace.data, dtype=np.float64)
    steps = recipe.steps_for(record.id)
    for name, params in steps:
        step = PROCESSING_STEPS[name]
        read = {other: PROCESSING_STEPS[other].arguments(next(p for n, p in steps if n == other))
                for other in step.reads}
        try:
            with np.errstate(over="raise", invalid="raise", divide="raise"):
                trace = step.run(trace, **params, **read)
        except PROCESSING_FAILURES as error:
            raise RecordError(source, f"record {record.id} cannot be processed: step {name!r} failed "
                              f"({type(error).__name__}: {str(error)[:200]})") from None
    if not np.all(np.isfinite(trace.data)):
        raise RecordError(source, f"record {record.id}: processing gave non-finite accelerations")
    if not np.any(trace.data):
        raise RecordError(source, f"record {record.id}: processed accelerations are all zero")
    trace.stats.qa = tail_checks(trace.data, trace.stats.delta, **recipe.qa)
    return record.with_trace(trace)


PROCESSING_FAILURES = (ValueError, ArithmeticError, np.linalg.LinAlgError, MemoryError)
"""What a step raises on a record it cannot handle (too short, degenerate sampling, overflow)."""


def process_records(records, recipe: ProcessingRecipe | None = None):
    """Process each record; one that cannot be processed is skipped: (processed, failures).

    ``failures`` holds one ``RecordError`` per skipped record, with its reason.
    """
    processed, failures = [], []
    for record in records:
        try:
            processed.append(process_record(record, recipe))
        except RecordError as error:
            failures.append(error)
        except Exception as error:  # a bug: say which record it met (shown by the CLI's rc-3 line)
            error.add_note(f"record {record.id} ({record.metadata.get('file', '')})")
            raise
    return processed, failures
