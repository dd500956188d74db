"""pipeline.hazard - a site's hazard curve: read, checked against the study's measure, interpolated.

Input : a hazard curve file that states its intensity measure (and period for Sa), in one of three
        formats (``load_hazard``): rockfrag's CSV (``# measure = pga`` header lines, columns intensity
        and annual frequency of exceedance [1/yr]), OpenQuake's hazard-curve CSV export as it comes
        (probabilities of exceedance in the investigation time, converted to annual frequencies), or
        the USGS NSHMP hazard web-service JSON.
Output: a ``HazardCurve`` (intensity in the measure's display unit, annual frequency [1/yr]) and
        lambda(im) by log-log interpolation (``hazard_frequency``).

A hazard curve for another measure (or another Sa period) than the study's is a ConfigError; the study
file's check (pipeline.config) and the risk stage (pipeline.risk) both read curves here. Measures,
their units, labels and OpenQuake IMT names come from the registry in pipeline.measures. Beyond the
last tabulated intensity the curve is extended with the slope of its last segment (a power law), and
below the first point with the slope of its first.
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike

from pipeline.errors import ConfigError
from pipeline.measures import MEASURES, display_units, scaling_measures

EXAMPLE_HAZARD = "hazard_example.csv"
"""Shipped example, PGA only: H(s) = 1e-4 s^-2.5 [1/yr], s = PGA [g] (Cornell et al. 2002 power-law form)."""
EXAMPLE_MEASURE = "pga"
"""The measure of the shipped example: a study of another measure needs its own hazard file for a risk."""

PERIOD_TOLERANCE = 1e-6


@dataclass(frozen=True)
class HazardCurve:
    """Mean annual frequency of exceedance [1/yr] of an intensity measure at one site."""

    intensity: np.ndarray  # in the measure's display unit (pipeline.measures.display_units)
    annual_frequency: np.ndarray  # 1/yr
    measure: str  # pga | sa | pgv
    period: float | None  # Sa period [s]; None for pga, pgv
    source: str
    notes: dict = field(default_factory=dict)

    @property
    def label(self) -> str:
        """"PGA", "Sa(1 s)": the registry's label of the curve's measure."""
        return measure_label(self.measure, self.period)


def measure_label(measure: str, period: float | None = None) -> str:
    """The registry's short label of ``measure`` at ``period`` [s] ("PGA", "Sa(1 s)").

    The upper-case name for an unknown measure, or for one defined at a period that is not given.
    """
    known = MEASURES.get(measure)
    if known is None or (known.uses_period and not period):
        return str(measure).upper()
    return known.short_label(period=period) if period else known.short_label()


def _fail(message, source):
    raise ConfigError("hazard.file", message, source)


def _measure_from_imt(imt: str, source: str) -> tuple[str, float | None, float]:
    """(measure, period [s], factor to our unit) of an OpenQuake or USGS intensity measure type.

    OpenQuake writes 'PGA', 'SA(1.0)', 'PGV', USGS 'PGA', 'SA1P0', 'SA0P2', 'PGV'; both are matched
    against the registry's ``openquake_imt`` ('SA(T)' for Sa).
    """
    text = imt.strip().upper()
    match = re.fullmatch(r"([A-Z]+)\(([0-9.]+)\)", text) or re.fullmatch(r"([A-Z]+?)([0-9]+)P([0-9]+)", text)
    period = None
    if match:
        digits = match.groups()[1:]
        period = float(digits[0]) if len(digits) == 1 else float(f"{digits[0]}.{digits[1]}")
        text = f"{match.group(1)}(T)"
    for measure in MEASURES.values():
        if measure.openquake_imt == text:
            return measure.name, period, measure.openquake_factor
    allowed = ", ".join(m.openquake_imt for m in MEASURES.values() if m.openquake_imt)
    _fail(f"intensity measure type {imt!r} not supported; allowed {allowed}", source)


def _read_rockfrag_csv(text: str, source: str):
    rows = [line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")]
    try:
        values = np.array([[float(v) for v in line.split(",")[:2]] for line in rows[1:]])
    except ValueError as error:
        _fail(f"not a table of numbers (intensity, annual frequency of exceedance): {error}", source)
    if values.ndim != 2 or values.shape[1] < 2:
        _fail("not a table of numbers: expected two columns, intensity and annual frequency of exceedance", source)
    header = dict(re.findall(r"^#\s*(measure|period|units)\s*[=:]\s*(\S+)", text, flags=re.M | re.I))
    header = {k.lower(): v for k, v in header.items()}
    if "measure" not in header:
        _fail("the file does not state its intensity measure; add a line '# measure = pga' (or sa, pgv; "
              "for sa also '# period = 1.0' [s])", source)
    measure = header["measure"].lower()
    allowed = scaling_measures()  # a study's measures; a hazard curve is in the study's display unit
    if measure not in allowed:
        _fail(f"measure {measure!r} unknown; allowed {', '.join(allowed)}", source)
    period = float(header["period"]) if "period" in header else None
    uses_period = MEASURES[measure].uses_period
    if uses_period and period is None:
        _fail(f"a hazard curve for {measure} must state its period: '# period = 1.0' [s]", source)
    display = display_units(measure)[0]
    unit = header.get("units", display)
    if unit != display:
        _fail(f"units {unit!r}; a {measure} hazard curve must be in {display}", source)
    return values[:, 0], values[:, 1], measure, (period if uses_period else None), {}


def _read_openquake_csv(text: str, source: str):
    """Read an OpenQuake hazard_curve-*.csv: lambda = -ln(1 - poe) / T (Poisson).

    The file holds a '#...investigation_time=T, imt='PGA'' line, then lon,lat,depth,poe-<level>,...
    """
    lines = [line for line in text.splitlines() if line.strip()]
    first = lines[0]
    time_match = re.search(r"investigation_time\s*=\s*([0-9.eE+-]+)", first)
    imt_match = re.search(r"imt\s*=\s*['\"]([^'\"]+)['\"]", first)
    if not (time_match and imt_match):
        _fail("OpenQuake header line without investigation_time and imt", source)
    investigation_time = float(time_match.group(1))
    measure, period, factor = _measure_from_imt(imt_match.group(1), source)
    columns = [c.strip() for c in lines[1].split(",")]
    poe_columns = [i for i, c in enumerate(columns) if c.startswith("poe-")]
    if not poe_columns:
        _fail("no 'poe-<level>' columns in the OpenQuake header", source)
    data = [line.split(",") for line in lines[2:]]
    if len(data) != 1:
        _fail(f"{len(data)} sites in the OpenQuake export; keep the one row of the study's site", source)
    intensity = np.array([float(columns[i][4:]) for i in poe_columns]) * factor
    poe = np.array([float(data[0][i]) for i in poe_columns])
    if np.any((poe < 0) | (poe >= 1)):
        _fail("probabilities of exceedance must lie in [0, 1)", source)
    keep = poe > 0  # a zero probability has no place on a log-log curve
    frequency = -np.log1p(-poe[keep]) / investigation_time
    notes = {"investigation_time_years": investigation_time, "imt": imt_match.group(1)}
    return intensity[keep], frequency, measure, period, notes


def _read_usgs_json(text: str, source: str):
    """Read a USGS NSHMP hazard web-service response: the 'Total' component of its one IMT.

    The JSON holds response[i].metadata.{imt, xvalues} and response[i].data[j].{component, yvalues};
    the file must hold exactly one IMT.
    """
    try:
        document = json.loads(text)
    except json.JSONDecodeError as error:
        _fail(f"not valid JSON: {error}", source)
    responses = document.get("response")
    if not isinstance(responses, list) or not responses:
        _fail("USGS hazard JSON without a 'response' list", source)
    if len(responses) != 1:
        _fail(f"{len(responses)} intensity measures in the USGS response; request one IMT", source)
    metadata, curves = responses[0].get("metadata", {}), responses[0].get("data", [])
    imt = metadata.get("imt", "")
    imt = imt.get("value", imt.get("id", "")) if isinstance(imt, dict) else imt
    measure, period, factor = _measure_from_imt(str(imt), source)
    total = [c for c in curves if c.get("component") == "Total"]
    if not total or "xvalues" not in metadata:
        _fail("USGS hazard JSON without metadata.xvalues and a 'Total' curve", source)
    intensity = np.asarray(metadata["xvalues"], float) * factor
    frequency = np.asarray(total[0]["yvalues"], float)
    keep = frequency > 0
    notes = {"imt": str(imt), "latitude": metadata.get("latitude"), "longitude": metadata.get("longitude")}
    return intensity[keep], frequency[keep], measure, period, notes


def _read_any(text: str, source: str):
    stripped = text.lstrip()
    if stripped.startswith("{"):
        return _read_usgs_json(text, source)
    first = stripped.splitlines()[0] if stripped else ""
    if "investigation_time" in first or "generated_by" in first:
        return _read_openquake_csv(text, source)
    return _read_rockfrag_csv(text, source)


def load_hazard(path: str | os.PathLike | None = None, measure: str = "pga",
                period: float | None = None) -> HazardCurve:
    """Read and check a hazard curve against the study's intensity ``measure`` (and Sa ``period`` [s]).

    Parameters
    ----------
    path : str or os.PathLike, optional
        A rockfrag CSV, an OpenQuake hazard-curve CSV or a USGS hazard JSON (module docstring); empty
        or None reads the shipped example (PGA only).
    measure : str, optional
        The study's intensity measure, a name of the registry (``pipeline.measures.MEASURES``).
    period : float, optional
        The study's Sa period [s]; checked only for a measure defined at a period.

    Returns
    -------
    HazardCurve
        Intensities in the measure's display unit (g for PGA and Sa, m/s for PGV), increasing, and
        their annual frequencies of exceedance [1/yr], decreasing.

    Raises
    ------
    ConfigError
        Field ``hazard.file``: the file is missing or malformed, has fewer than two points, is not
        monotone, or states another measure or period than the study's.
    """
    if path is None or str(path) == "":
        source_file = files("pipeline").joinpath(EXAMPLE_HAZARD)
        source = f"pipeline/{EXAMPLE_HAZARD} (example, not site-specific)"
    else:
        source_file, source = Path(path), str(path)
        if not source_file.is_file():
            _fail("file not found", source)
    text = source_file.read_text()
    intensity, frequency, file_measure, file_period, notes = _read_any(text, source)
    study = measure_label(measure, period)
    if file_measure != measure:
        found = measure_label(file_measure, file_period)
        example = f" (the shipped example is for {measure_label(EXAMPLE_MEASURE)} only)" if path in (None, "") else ""
        _fail(f"the curve is for {found} but the study's intensity measure is {study}; give a hazard curve "
              f"for {study}" + example, source)
    uses_period = measure in MEASURES and MEASURES[measure].uses_period
    if uses_period and period is not None and abs(file_period - period) > PERIOD_TOLERANCE * max(1.0, period):
        _fail(f"the curve is for {measure_label(file_measure, file_period)} but the study uses {study}", source)
    if intensity.size < 2:
        _fail("fewer than two points with a positive annual frequency", source)
    if np.any(intensity <= 0) or np.any(np.diff(intensity) <= 0):
        _fail("intensities must increase and be > 0", source)
    if np.any(frequency <= 0) or np.any(np.diff(frequency) > 0):
        _fail("annual frequency of exceedance must be > 0 and decrease with intensity", source)
    return HazardCurve(intensity, frequency, file_measure, file_period, source, notes)


def hazard_for(path: str | os.PathLike | None, measure: str, period: float | None = None) -> HazardCurve | None:
    """The hazard curve of a study of ``measure`` (at ``period`` [s] for Sa), or None (no risk).

    ``path`` is read and checked against the measure (``load_hazard``); without a path, the shipped
    example for a study of its measure, else None.
    """
    if not path and measure != EXAMPLE_MEASURE:
        return None
    uses_period = measure in MEASURES and MEASURES[measure].uses_period
    return load_hazard(path or None, measure, period if uses_period else None)


class HazardSettings(Protocol):
    """What ``study_hazard`` reads of a study; ``pipeline.config.StudyConfig`` has it."""

    @property
    def hazard_file(self) -> str:
        """The hazard curve file ("" for none)."""

    @property
    def measure(self) -> str:
        """The study's intensity measure (a name of ``pipeline.measures.MEASURES``)."""

    @property
    def period(self) -> float:
        """The Sa period [s] (unused for measures not defined at a period)."""


def study_hazard(config: HazardSettings) -> HazardCurve | None:
    """The study's hazard curve: its ``hazard.file`` checked against its measure.

    Parameters
    ----------
    config : HazardSettings
        The study (``pipeline.config.StudyConfig``): ``hazard_file``, ``measure`` and ``period`` [s].

    Returns
    -------
    HazardCurve or None
        The curve (``load_hazard``); without a file, the shipped example for a PGA study and None
        (no risk computed) for another measure.

    Raises
    ------
    ConfigError
        The file is missing or malformed, or is for another measure or period (``load_hazard``).
    """
    return hazard_for(config.hazard_file, config.measure, config.period)


def hazard_frequency(hazard: HazardCurve, intensity: ArrayLike) -> np.ndarray | float:
    """lambda(im) [1/yr] at ``intensity`` [the curve's unit]: log-log interpolation, power laws beyond both ends."""
    x = np.log(hazard.intensity)
    y = np.log(hazard.annual_frequency)
    log_im = np.log(np.asarray(intensity, float))
    values = np.interp(log_im, x, y)
    slope_high = (y[-1] - y[-2]) / (x[-1] - x[-2])
    slope_low = (y[1] - y[0]) / (x[1] - x[0])
    values = np.where(log_im > x[-1], y[-1] + slope_high * (log_im - x[-1]), values)
    values = np.where(log_im < x[0], y[0] + slope_low * (log_im - x[0]), values)
    return np.exp(values)


