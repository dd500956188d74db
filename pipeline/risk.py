"""pipeline.risk - fragility x site hazard -> mean annual frequency and probability in a design life.

Input : a hazard curve file that states its intensity measure (and period for Sa), in one of three
        formats (``load_hazard``): rockfrag's CSV (``# measure = pga`` header lines, columns intensity
        and annual frequency of exceedance [1/yr]), OpenQuake's hazard-curve CSV export as it comes
        (probabilities of exceedance in the investigation time, converted to annual frequencies), or
        the USGS NSHMP hazard web-service JSON; and lognormal fragility parameters (median [IM units],
        beta [-], beta = 0 a step).
Output: lambda_DS = integral P(DS | im) |d lambda(im)| [1/yr] and P(DS in T years) = 1 - exp(-lambda_DS T).

A hazard curve for another measure (or another Sa period) than the study's is a ConfigError before any
run. The hazard is interpolated log-log and integrated on a fine logarithmic grid; beyond the last
tabulated intensity the curve is extended with the slope of its last segment (a power law), and below
the first point with the slope of its first.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path

import numpy as np
import xarray as xr
from scipy.special import ndtr

from pipeline.config import MEASURE_UNITS
from pipeline.errors import ConfigError

EXAMPLE_HAZARD = "hazard_example.csv"
"""Shipped example, PGA only: H(s) = 1e-4 s^-2.5 [1/yr], s = PGA [g] (Cornell et al. 2002 power-law form)."""

UNITS = {measure: unit for measure, (unit, _) in MEASURE_UNITS.items()}
"""The intensity unit of each measure in a hazard curve (the study's display unit)."""

PERIOD_TOLERANCE = 1e-6


@dataclass(frozen=True)
class HazardCurve:
    """Mean annual frequency of exceedance [1/yr] of an intensity measure at one site."""

    intensity: np.ndarray  # in UNITS[measure]
    annual_frequency: np.ndarray  # 1/yr
    measure: str  # pga | sa | pgv
    period: float | None  # Sa period [s]; None for pga, pgv
    source: str
    notes: dict = field(default_factory=dict)

    @property
    def label(self) -> str:
        return f"Sa({self.period:g} s)" if self.measure == "sa" else self.measure.upper()


def _fail(message, source):
    raise ConfigError("hazard.file", message, source)


def _measure_from_imt(imt: str, source: str) -> tuple[str, float | None, float]:
    """(measure, period, factor to our unit) from an OpenQuake IMT ('PGA', 'SA(1.0)', 'PGV') or a USGS
    IMT id ('PGA', 'SA1P0', 'SA0P2', 'PGV')."""
    text = imt.strip().upper()
    if text == "PGA":
        return "pga", None, 1.0
    if text == "PGV":
        return "pgv", None, 0.01  # OpenQuake and USGS give PGV in cm/s
    match = re.fullmatch(r"SA\(([0-9.]+)\)", text) or re.fullmatch(r"SA([0-9]+)P([0-9]+)", text)
    if match:
        period = float(match.group(1)) if len(match.groups()) == 1 else float(f"{match.group(1)}.{match.group(2)}")
        return "sa", period, 1.0
    _fail(f"intensity measure type {imt!r} not supported; allowed PGA, PGV, SA(T)", source)


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
    if measure not in UNITS:
        _fail(f"measure {measure!r} unknown; allowed pga, sa, pgv", source)
    period = float(header["period"]) if "period" in header else None
    if measure == "sa" and period is None:
        _fail("an Sa hazard curve must state its period: '# period = 1.0' [s]", source)
    unit = header.get("units", UNITS[measure])
    if unit != UNITS[measure]:
        _fail(f"units {unit!r}; a {measure} hazard curve must be in {UNITS[measure]}", source)
    return values[:, 0], values[:, 1], measure, (period if measure == "sa" else None), {}


def _read_openquake_csv(text: str, source: str):
    """OpenQuake hazard_curve-*.csv: '#...investigation_time=T, imt='PGA'' line, then lon,lat,depth,poe-...;
    lambda = -ln(1 - poe) / T (Poisson)."""
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
    """USGS NSHMP hazard web service: response[i].metadata.{imt, xvalues}, response[i].data[j].{component,
    yvalues}; the 'Total' component, one IMT (the file must hold exactly one)."""
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


def load_hazard(path=None, measure="pga", period=None) -> HazardCurve:
    """Read and check a hazard curve against the study's intensity ``measure`` (and Sa ``period`` [s]).

    ``path`` empty or None reads the shipped example (PGA only). Raises ConfigError naming the file
    when the file is missing or malformed, or states another measure or period than the study's.
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
    study = f"Sa({period:g} s)" if measure == "sa" and period else str(measure).upper()
    if file_measure != measure:
        found = f"Sa({file_period:g} s)" if file_measure == "sa" else file_measure.upper()
        _fail(f"the curve is for {found} but the study's intensity measure is {study}; give a hazard curve "
              f"for {study}" + (" (the shipped example is for PGA only)" if path in (None, "") else ""), source)
    if measure == "sa" and period is not None and abs(file_period - period) > PERIOD_TOLERANCE * max(1.0, period):
        _fail(f"the curve is for Sa({file_period:g} s) but the study uses Sa({period:g} s)", source)
    if intensity.size < 2:
        _fail("fewer than two points with a positive annual frequency", source)
    if np.any(intensity <= 0) or np.any(np.diff(intensity) <= 0):
        _fail("intensities must increase and be > 0", source)
    if np.any(frequency <= 0) or np.any(np.diff(frequency) > 0):
        _fail("annual frequency of exceedance must be > 0 and decrease with intensity", source)
    return HazardCurve(intensity, frequency, file_measure, file_period, source, notes)


def study_hazard(config) -> HazardCurve | None:
    """The study's hazard curve: its ``hazard.file`` checked against its measure; without a file the
    shipped example for a PGA study, and None (no risk computed) for another measure."""
    if not config.hazard_file and config.measure != "pga":
        return None
    return load_hazard(config.hazard_file or None, config.measure, config.period if config.measure == "sa" else None)


def hazard_frequency(hazard: HazardCurve, intensity):
    """lambda(im) [1/yr], log-log interpolation, power-law extrapolation at both ends."""
    x = np.log(hazard.intensity)
    y = np.log(hazard.annual_frequency)
    log_im = np.log(np.asarray(intensity, float))
    values = np.interp(log_im, x, y)
    slope_high = (y[-1] - y[-2]) / (x[-1] - x[-2])
    slope_low = (y[1] - y[0]) / (x[1] - x[0])
    values = np.where(log_im > x[-1], y[-1] + slope_high * (log_im - x[-1]), values)
    values = np.where(log_im < x[0], y[0] + slope_low * (log_im - x[0]), values)
    return np.exp(values)


def annual_frequency(median, beta, hazard: HazardCurve, points=4000) -> float:
    """Mean annual frequency of reaching a damage state with a lognormal fragility [1/yr].

    beta = 0 is a step at the median: lambda_DS = lambda(median).
    """
    if hazard is None or not (np.isfinite(median) and np.isfinite(beta)):
        return np.nan
    if beta == 0:
        return float(hazard_frequency(hazard, median))
    low = min(hazard.intensity[0], median * np.exp(-8 * beta))
    high = median * np.exp(8 * beta)
    grid = np.geomspace(low, high, points)
    frequency = hazard_frequency(hazard, grid)
    probability = ndtr(np.log(grid / median) / beta)
    # sum of P at the segment midpoints times the drop in lambda over the segment, plus the tail
    middle = 0.5 * (probability[1:] + probability[:-1])
    return float(np.sum(middle * (frequency[:-1] - frequency[1:])) + probability[-1] * frequency[-1])


def probability_in_life(frequency, years):
    """Poisson probability of at least one occurrence in ``years``."""
    return 1.0 - np.exp(-np.asarray(frequency) * years)


def risk_dataset(fragility: xr.Dataset, hazard: HazardCurve | None, design_life=50.0) -> xr.Dataset:
    """lambda_DS and P(DS in design_life) for every soil x block x model x damage state (NaN without a
    hazard curve for the study's measure)."""
    medians = fragility["median"].values
    betas = fragility["beta"].values
    rate = np.vectorize(lambda m, b: annual_frequency(m, b, hazard), otypes=[float])(medians, betas) \
        if medians.size else medians
    dims = fragility["median"].dims
    dataset = xr.Dataset({
        "annual_frequency": (dims, rate, {"long_name": "mean annual frequency of reaching the damage state",
                                          "units": "yr-1"}),
        "probability_in_life": (dims, probability_in_life(rate, design_life),
                                {"long_name": f"probability of reaching the damage state in {design_life:g} years",
                                 "units": "1"}),
    }, coords={d: fragility[d] for d in dims})
    source = hazard.source if hazard is not None else \
        f"none: no hazard curve for {fragility.attrs.get('intensity_measure', '?')} (risk not computed)"
    dataset.attrs = {"hazard_source": source, "design_life_years": design_life,
                     "hazard_measure": hazard.label if hazard is not None else ""}
    return dataset
