"""pipeline.processing - stage 2: raw acceleration trace -> corrected trace ready for analysis.

Input : a ``Record`` (obspy Trace of acceleration [m/s^2]) and a ``ProcessingRecipe`` (ordered list
        of named steps with parameters; defaults in ``pipeline/processing.toml``).
Output: a new ``Record`` whose trace is demeaned, detrended, tapered, zero-phase band-passed and
        baseline-corrected, with every step recorded in ``stats.processing`` and QA flags (tail drift
        of velocity/displacement, gmprocess ``check_tail`` style) in ``stats.qa``. Flags never drop
        a record. Inputs are not modified.

A step is one function registered with ``@processing_step``; its keyword parameters (with ranges
in ``PARAMETER_RANGES``) are what a recipe may set.
"""

from __future__ import annotations

import inspect
import math
import re
import tomllib
from dataclasses import dataclass, field
from importlib.resources import files

import numpy as np
from scipy.integrate import cumulative_trapezoid

from pipeline import __version__
from pipeline.errors import ConfigError, RecordError

PROCESSING_STEPS: dict = {}
PARAMETER_RANGES: dict[str, tuple[float, float]] = {}


def processing_step(**ranges):
    """Register a step; ``ranges`` gives the allowed (min, max) of numeric parameters."""

    def register(function):
        PROCESSING_STEPS[function.__name__] = function
        for parameter, bounds in ranges.items():
            PARAMETER_RANGES[f"{function.__name__}.{parameter}"] = bounds
        return function

    return register


def _provenance(trace, text):
    trace.stats.setdefault("processing", []).append(f"rockfrag {__version__}: {text}")


@processing_step()
def demean(trace, *, context=None):
    trace.detrend("demean")
    return trace


@processing_step()
def detrend(trace, *, context=None):
    trace.detrend("linear")
    return trace


@processing_step(max_percentage=(0.0, 0.5))
def taper(trace, *, max_percentage=0.05, type="hann", context=None):
    trace.taper(max_percentage=max_percentage, type=type)
    return trace


@processing_step(factor=(0.0, 20.0))
def pad(trace, *, factor=1.5, context=None):
    """Zero pads of factor * order / freqmin seconds at both ends (acausal filter transients)."""
    settings = context["bandpass"]
    seconds = factor * settings["corners"] / settings["freqmin"]
    n_pad = int(math.ceil(seconds / trace.stats.delta))
    trace.data = np.concatenate([np.zeros(n_pad), trace.data, np.zeros(n_pad)])
    context["n_pad"] = n_pad
    _provenance(trace, f"pad(samples={n_pad}, seconds={n_pad * trace.stats.delta:.3f})")
    return trace


@processing_step()
def unpad(trace, *, context=None):
    n_pad = context.pop("n_pad", 0)
    if n_pad:
        trace.data = trace.data[n_pad:-n_pad].copy()
        _provenance(trace, f"unpad(samples={n_pad})")
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


def bandpass_corners(trace, freqmin, freqmax, nyquist_fraction=0.8, use_header_corners=True):
    """Corners [Hz] actually used: header corners where stricter, low-pass below Nyquist."""
    nyquist = 0.5 / trace.stats.delta
    if use_header_corners:
        header_hp, header_lp = header_corners(trace)
        freqmin = max(freqmin, header_hp or 0.0)
        freqmax = min(freqmax, header_lp or math.inf)
    return freqmin, min(freqmax, nyquist_fraction * nyquist)


@processing_step(freqmin=(1e-3, 10.0), freqmax=(0.5, 1000.0), corners=(1, 10),
                 nyquist_fraction=(0.1, 0.99))
def bandpass(trace, *, freqmin=0.1, freqmax=25.0, corners=4, nyquist_fraction=0.8,
             use_header_corners=True, context=None):
    low, high = bandpass_corners(trace, freqmin, freqmax, nyquist_fraction, use_header_corners)
    trace.filter("bandpass", freqmin=low, freqmax=high, corners=int(corners), zerophase=True)
    return trace


@processing_step(order=(3, 12))
def baseline(trace, *, order=6, context=None):
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
    _provenance(trace, f"baseline(order={int(order)}, ends at rest)")
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
        return {"steps": [{"name": name, **params} for name, params in self.steps],
                "qa": dict(self.qa), "overrides": self.overrides}


QA_DEFAULTS = {"tail_seconds": 5.0, "velocity_ratio": 0.3, "displacement_ratio": 0.6}
QA_RANGES = {"tail_seconds": (0.1, 100.0), "velocity_ratio": (0.0, 10.0),
             "displacement_ratio": (0.0, 10.0)}


def _validate_step(name, params, source, where):
    if name not in PROCESSING_STEPS:
        raise ConfigError(where, f"unknown step {name!r}; available: {', '.join(PROCESSING_STEPS)}", source)
    allowed = [p for p in inspect.signature(PROCESSING_STEPS[name]).parameters if p not in ("trace", "context")]
    for key, value in params.items():
        if key not in allowed:
            raise ConfigError(f"{where}.{key}", f"not a parameter of step {name!r}; allowed: "
                              f"{', '.join(allowed) or 'none'}", source)
        bounds = PARAMETER_RANGES.get(f"{name}.{key}")
        if bounds is not None:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ConfigError(f"{where}.{key}", f"{value!r} is not a number; allowed range "
                                  f"{bounds[0]} to {bounds[1]}", source)
            if not bounds[0] <= value <= bounds[1]:
                raise ConfigError(f"{where}.{key}", f"{value} is out of range; allowed "
                                  f"{bounds[0]} to {bounds[1]}", source)


def recipe_from_dict(data: dict, source="<dict>") -> ProcessingRecipe:
    """Validate a recipe given as a dict (the TOML layout) and freeze it."""
    raw_steps = data.get("steps")
    if not isinstance(raw_steps, list) or not raw_steps:
        raise ConfigError("steps", "expected a non-empty list of [[steps]] tables", source)
    steps = []
    for index, raw in enumerate(raw_steps):
        where = f"steps[{index}]"
        if not isinstance(raw, dict) or not isinstance(raw.get("name"), str):
            raise ConfigError(where, "each step needs a name (text)", source)
        params = {k: v for k, v in raw.items() if k != "name"}
        _validate_step(raw["name"], params, source, where)
        steps.append((raw["name"], params))
    names = [name for name, _ in steps]
    if "pad" in names and "bandpass" not in names:
        raise ConfigError("steps", "step 'pad' needs a 'bandpass' step (its length depends on freqmin)", source)
    if names.count("pad") != names.count("unpad"):
        raise ConfigError("steps", "every 'pad' step needs a matching 'unpad' step", source)
    for table in ("qa", "overrides"):
        if not isinstance(data.get(table, {}), dict):
            raise ConfigError(table, f"{data[table]!r} is not a table; expected [{table}]", source)
    unknown = sorted(set(data) - {"steps", "qa", "overrides"})
    if unknown:
        raise ConfigError(unknown[0], "unknown key; allowed: steps, qa, overrides", source)
    qa = dict(QA_DEFAULTS)
    for key, value in data.get("qa", {}).items():
        if key not in QA_RANGES:
            raise ConfigError(f"qa.{key}", f"unknown QA setting; allowed: {', '.join(QA_RANGES)}", source)
        low, high = QA_RANGES[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not low <= value <= high:
            raise ConfigError(f"qa.{key}", f"{value!r} out of range; allowed {low} to {high}", source)
        qa[key] = float(value)
    overrides = data.get("overrides", {})
    for record_id, by_step in overrides.items():
        if not isinstance(by_step, dict):
            raise ConfigError(f"overrides.{record_id}", "expected a table of steps", source)
        for step_name, params in by_step.items():
            if not isinstance(params, dict):
                raise ConfigError(f"overrides.{record_id}.{step_name}", "expected a table of parameters", source)
            if step_name not in names:
                raise ConfigError(f"overrides.{record_id}.{step_name}", "step not in the recipe; "
                                  f"steps: {', '.join(names)}", source)
            _validate_step(step_name, params, source, f"overrides.{record_id}.{step_name}")
    return ProcessingRecipe(tuple(steps), qa, overrides, source)


def load_recipe(path=None) -> ProcessingRecipe:
    """The shipped default recipe, or a user TOML file with the same layout (validated)."""
    if path is None:
        text = files("pipeline").joinpath("processing.toml").read_text()
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


def process_record(record, recipe: ProcessingRecipe | None = None):
    """Apply the recipe to a copy of the record; return the new, corrected ``Record``.

    Raises ``RecordError`` (naming the record's file and the step) when the record cannot be
    processed: a numerical failure of a step, or a result that is not finite or is all zero.
    """
    recipe = recipe or load_recipe()
    source = record.metadata.get("file") or record.id
    trace = record.trace.copy()
    trace.data = np.asarray(trace.data, dtype=np.float64)
    overrides = recipe.overrides.get(record.id, {})
    steps = [(name, {**params, **overrides.get(name, {})}) for name, params in recipe.steps]
    context = {"bandpass": {"corners": 4, "freqmin": 0.1,
                            **next((p for n, p in steps if n == "bandpass"), {})}}
    context["bandpass"]["freqmin"] = bandpass_corners(
        trace, context["bandpass"]["freqmin"], context["bandpass"].get("freqmax", 25.0),
        context["bandpass"].get("nyquist_fraction", 0.8),
        context["bandpass"].get("use_header_corners", True))[0]
    for name, params in steps:
        try:
            with np.errstate(over="raise", invalid="raise", divide="raise"):
                trace = PROCESSING_STEPS[name](trace, context=context, **params)
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
