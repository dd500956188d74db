"""rockfrag.hazard - a site's hazard curve: read, checked against the study's measure, interpolated.

Input : a hazard curve file that states its intensity measure (and period for Sa), in one of three
        formats (``load_hazard``): rockfrag's CSV (``# measure = pga`` header lines, columns intensity
        and annual frequency of exceedance [1/yr]), OpenQuake's hazard-curve CSV export as it comes
        (probabilities of exceedance in the investigation time, converted to annual frequencies), or
        the USGS NSHMP hazard web-service JSON; optionally the study's site [lon, lat] (degrees), which
        picks the nearest site of a multi-site OpenQuake export or USGS file (``[hazard] site``).
Output: a ``HazardCurve`` (intensity in the measure's display unit, annual frequency [1/yr], and the
        chosen ``HazardSite`` with its great-circle distance [km] from the study's site) and lambda(im)
        by log-log interpolation (``hazard_frequency``).

Horizontal component: every curve states the definition of its horizontal intensity (``HazardCurve.component``,
``COMPONENTS``). A rockfrag CSV says it in a header line, ``# component = RotD50``; without one it is RotD50, the
definition of the NGA-West2 models. USGS NSHMP curves and OpenQuake curves are RotD50: both come from NGA-West2
ground motion models (an OpenQuake export does not name its models; a run with other models is the user's to
state by converting the curve to a rockfrag CSV with its component).

Every value of a file is a finite number: a NaN, an empty cell or a word where a number belongs is one
ConfigError naming the file, the line and the column (for a USGS JSON file, the line and column of the value in
the file and its place in the response).

A hazard curve for another measure (or another Sa period) than the study's is a ConfigError; the study
file's check (rockfrag.config) and the risk stage (rockfrag.risk) both read curves here. Measures,
their units, labels and OpenQuake IMT names come from the registry in rockfrag.measures. Beyond the
last tabulated intensity the curve is extended with the slope of its last segment (a power law), and
below the first point with the slope of its first.

A file with several sites (an OpenQuake regional run, USGS responses saved for several sites) needs the
study's site: without it, the file is refused with the number of sites and the fix. The distance to the
chosen site is the haversine great-circle distance on a sphere of the mean Earth radius; a site farther
than ``FAR_SITE_KM`` is a ``HazardSiteWarning`` when the study reads its hazard (``study_hazard``).
"""

from __future__ import annotations

import json
import math
import os
import re
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike

from rockfrag.errors import ConfigError
from rockfrag.measures import MEASURES, display_units, scaling_measures
from rockfrag.validation import Number, did_you_mean, shown

EXAMPLE_HAZARD = "hazard_example.csv"
"""Shipped example, PGA only: H(s) = 1e-4 s^-2.5 [1/yr], s = PGA [g] (Cornell et al. 2002 power-law form)."""
EXAMPLE_MEASURE = "pga"
"""The measure of the shipped example: a study of another measure needs its own hazard file for a risk."""

PERIOD_TOLERANCE = 1e-6

COMPONENTS = {
    "RotD50": "the median over all orientations of the two horizontal components' response (Boore 2010); the "
              "definition of the NGA-West2 ground motion models, hence of USGS NSHMP and most OpenQuake curves",
    "RotD100": "the largest over all orientations (Boore 2010): the maximum direction",
    "GMRotI50": "the orientation-independent geometric mean of Boore et al. (2006), the NGA-West1 definition",
    "geometric-mean": "the geometric mean of the two recorded horizontal components",
    "larger": "the larger of the two recorded horizontal components",
    "arbitrary": "one recorded horizontal component, its orientation arbitrary",
}
"""Horizontal-component definitions a hazard curve may state (``# component = NAME`` in a rockfrag CSV)."""
DEFAULT_COMPONENT = "RotD50"
"""The component of a curve that does not state one, and of USGS and OpenQuake curves (module docstring)."""

EARTH_RADIUS_KM = 6371.0088
"""Mean Earth radius R1 of the IUGG [km]: the sphere of the great-circle distances."""
FAR_SITE_KM = 50.0
"""A hazard site farther than this from the study's site [km] is warned about: at that distance the
curve is another site's (regional grids are typically 0.1-0.2 degrees, 10-20 km, apart)."""
SITE_LONGITUDE = Number(-180.0, 360.0, high_open=True, unit="degrees")
SITE_LATITUDE = Number(-90.0, 90.0, unit="degrees")


class HazardSiteWarning(UserWarning):
    """The hazard file's nearest site is farther than ``FAR_SITE_KM`` from the study's site."""


def check_site(value: object, field: str = "hazard.site", source: str | None = None) -> tuple[float, float]:
    """The study's site ``[lon, lat]`` [degrees] as two floats, or a ``ConfigError`` naming ``field``.

    Parameters
    ----------
    value : object
        As written in the study file: a list of two finite numbers, longitude in [-180, 360) and
        latitude in [-90, 90].
    field, source : str
        The field and the file that an error names.

    Returns
    -------
    (float, float)
        Longitude and latitude [degrees].
    """
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise ConfigError(field, f"{shown(value)}; must be [lon, lat] in degrees, e.g. [-122.27, 38.1]", source)
    longitude = SITE_LONGITUDE.check(value[0], f"{field}[0] (longitude)", source)
    latitude = SITE_LATITUDE.check(value[1], f"{field}[1] (latitude)", source)
    return longitude, latitude


def great_circle_km(lon1: ArrayLike, lat1: ArrayLike, lon2: ArrayLike, lat2: ArrayLike) -> np.ndarray | float:
    """Great-circle distance [km] between points given in degrees (haversine, sphere of ``EARTH_RADIUS_KM``).

    Longitudes may use either convention (-180..180 or 0..360): only their difference enters, through
    its sine.
    """
    phi1, phi2 = np.radians(lat1), np.radians(lat2)
    half_dphi = 0.5 * (phi2 - phi1)
    half_dlambda = 0.5 * np.radians(np.asarray(lon2, float) - np.asarray(lon1, float))
    a = np.sin(half_dphi) ** 2 + np.cos(phi1) * np.cos(phi2) * np.sin(half_dlambda) ** 2
    return 2.0 * EARTH_RADIUS_KM * np.arcsin(np.sqrt(np.clip(a, 0.0, 1.0)))


@dataclass(frozen=True)
class HazardSite:
    """The site of a hazard file chosen for the study's ``[hazard] site``."""

    longitude: float  # of the file's site [degrees]
    latitude: float  # [degrees]
    distance_km: float  # great-circle distance from the study's site [km]
    requested: tuple[float, float]  # the study's [lon, lat] [degrees]
    index: int  # 0-based position among the file's sites
    count: int  # sites in the file

    def describe(self) -> str:
        """"site 3 of 10 (lon -122.27, lat 38.1), 1.2 km from the study's site [-122.26, 38.1]"."""
        return (f"site {self.index + 1} of {self.count} (lon {self.longitude:g}, lat {self.latitude:g}), "
                f"{self.distance_km:.1f} km from the study's site [{self.requested[0]:g}, {self.requested[1]:g}]")


@dataclass(frozen=True)
class HazardCurve:
    """Mean annual frequency of exceedance [1/yr] of an intensity measure at one site."""

    intensity: np.ndarray  # in the measure's display unit (rockfrag.measures.display_units)
    annual_frequency: np.ndarray  # 1/yr
    measure: str  # pga | sa | pgv
    period: float | None  # Sa period [s]; None for pga, pgv
    source: str
    notes: dict = field(default_factory=dict)
    site: HazardSite | None = None  # the file's site nearest the study's [hazard] site; None without one
    component: str = DEFAULT_COMPONENT  # the horizontal-component definition of the intensity (COMPONENTS)

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


def _number(cell: str, line: int, column: int, name: str, source: str) -> float:
    """A cell of a table as a finite float, or a ConfigError naming the file, line and column (1-based)."""
    text = cell.strip()
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        shown = repr(text) if text else "an empty cell"
        _fail(f"line {line}, column {column} ({name}): {shown} is not a number", source)
    return value


def _read_rockfrag_csv(text: str, source: str):
    numbered = [(number, line) for number, line in enumerate(text.splitlines(), start=1)
                if line.strip() and not line.lstrip().startswith("#")]
    if len(numbered) < 2:
        _fail("not a table of numbers: expected a header line and rows of intensity, annual frequency of exceedance",
              source)
    names = [c.strip() or f"column {i + 1}" for i, c in enumerate(numbered[0][1].split(","))] + ["", ""]
    rows = []
    for number, line in numbered[1:]:
        cells = line.split(",")
        if len(cells) < 2:
            _fail(f"line {number}: {len(cells)} column; expected two, intensity and annual frequency of exceedance",
                  source)
        rows.append([_number(cells[i], number, i + 1, names[i], source) for i in (0, 1)])
    values = np.array(rows)
    header = dict(re.findall(r"^#\s*(measure|period|units|component)\s*[=:]\s*(\S+)", text, flags=re.M | re.I))
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
    component = header.get("component", DEFAULT_COMPONENT)
    if component not in COMPONENTS:
        known = {name.lower(): name for name in COMPONENTS}
        if component.lower() not in known:
            _fail(f"component {component!r} unknown{did_you_mean(component, COMPONENTS)}; allowed "
                  f"{', '.join(COMPONENTS)}", source)
        component = known[component.lower()]
    stated = "stated in the file" if "component" in header else "not stated in the file: RotD50 taken"
    notes = {"component": component, "component_basis": stated}
    return [(None, None, values[:, 0], values[:, 1])], measure, (period if uses_period else None), notes


def _read_openquake_csv(text: str, source: str):
    """Read an OpenQuake hazard_curve-*.csv: lambda = -ln(1 - poe) / T (Poisson), one curve per site row.

    The file holds a '#...investigation_time=T, imt='PGA'' line, then a header naming lon, lat (and
    depth, sometimes custom_site_id) and the poe-<level> columns, then one row per site.
    """
    lines = [(number, line) for number, line in enumerate(text.splitlines(), start=1) if line.strip()]
    first = lines[0][1]
    time_match = re.search(r"investigation_time\s*=\s*([0-9.eE+-]+)", first)
    imt_match = re.search(r"imt\s*=\s*['\"]([^'\"]+)['\"]", first)
    if not (time_match and imt_match):
        _fail("OpenQuake header line without investigation_time and imt", source)
    investigation_time = float(time_match.group(1))
    measure, period, factor = _measure_from_imt(imt_match.group(1), source)
    columns = [c.strip() for c in lines[1][1].split(",")] if len(lines) > 1 else []
    poe_columns = [i for i, c in enumerate(columns) if c.startswith("poe-")]
    if not poe_columns:
        _fail("no 'poe-<level>' columns in the OpenQuake header", source)
    if "lon" not in columns or "lat" not in columns:
        _fail("no 'lon' and 'lat' columns in the OpenQuake header", source)
    if len(lines) < 3:
        _fail("no site rows below the OpenQuake header", source)
    header_line = lines[1][0]
    intensity = np.array([_number(columns[i][4:], header_line, i + 1, columns[i], source) for i in poe_columns])
    intensity = intensity * factor
    sites = []
    for number, line in lines[2:]:
        cells = line.split(",")
        if len(cells) < len(columns):
            _fail(f"line {number}: {len(cells)} columns where the header has {len(columns)}", source)
        lon, lat = (_number(cells[columns.index(name)], number, columns.index(name) + 1, name, source)
                    for name in ("lon", "lat"))
        poe = np.array([_number(cells[i], number, i + 1, columns[i], source) for i in poe_columns])
        outside = np.flatnonzero((poe < 0) | (poe >= 1))
        if outside.size:
            column = poe_columns[outside[0]]
            _fail(f"line {number}, column {column + 1} ({columns[column]}): {poe[outside[0]]:g}; probabilities of "
                  "exceedance must lie in [0, 1)", source)
        keep = poe > 0  # a zero probability has no place on a log-log curve
        sites.append((lon, lat, intensity[keep], -np.log1p(-poe[keep]) / investigation_time))
    notes = {"investigation_time_years": investigation_time, "imt": imt_match.group(1),
             "component": DEFAULT_COMPONENT,
             "component_basis": "an OpenQuake curve from NGA-West2 ground motion models (the export names none)"}
    return sites, measure, period, notes


def _usgs_imt(metadata: dict) -> str:
    imt = metadata.get("imt", "")
    return str(imt.get("value", imt.get("id", "")) if isinstance(imt, dict) else imt)


_JSON_NUMBER = re.compile(r"-?(?:0|[1-9][0-9]*)(?:\.[0-9]+)?(?:[eE][+-]?[0-9]+)?")
_JSON_ARRAY = re.compile(r'"([xy]values)"\s*:\s*\[([^\]]*)\]')


def _check_json_arrays(text: str, source: str) -> None:
    """Every value of the file's ``xvalues`` and ``yvalues`` arrays is a JSON number.

    NaN, Infinity (which Python's json reads), null and strings are a ConfigError naming the line and column of
    the value in the file, the array and the value's index in it.
    """
    for array in _JSON_ARRAY.finditer(text):
        start = array.start(2)
        offset = 0
        for index, item in enumerate(array.group(2).split(",")):
            value = item.strip()
            if value and not _JSON_NUMBER.fullmatch(value) or not value and array.group(2).strip():
                at = start + offset + (len(item) - len(item.lstrip()))
                line = text.count("\n", 0, at) + 1
                column = at - (text.rfind("\n", 0, at) + 1) + 1
                shown = value if value else "an empty value"
                _fail(f"line {line}, column {column} ({array.group(1)}[{index}]): {shown} is not a number", source)
            offset += len(item) + 1


def _read_usgs_json(text: str, source: str):
    """Read USGS NSHMP hazard web-service responses: the 'Total' curve of one IMT per site.

    A response holds response[i].metadata.{imt, xvalues, longitude, latitude} and
    response[i].data[j].{component, yvalues}. The file may hold one response or a JSON list of them
    (one per site, e.g. saved from a loop over the sites of a region); each site must hold exactly one IMT.
    """
    _check_json_arrays(text, source)
    try:
        document = json.loads(text)
    except json.JSONDecodeError as error:
        _fail(f"not valid JSON: {error}", source)
    documents = document if isinstance(document, list) else [document]
    entries = []
    for item in documents:
        responses = item.get("response") if isinstance(item, dict) else None
        if not isinstance(responses, list) or not responses:
            _fail("USGS hazard JSON without a 'response' list", source)
        entries += responses
    by_site: dict = {}
    for entry in entries:
        metadata = entry.get("metadata", {}) if isinstance(entry, dict) else {}
        by_site.setdefault((metadata.get("longitude"), metadata.get("latitude")), []).append(entry)
    for (lon, lat), found in by_site.items():
        if len(found) != 1:
            where = "" if len(by_site) == 1 else f" at lon {lon}, lat {lat}"
            _fail(f"{len(found)} intensity measures in the USGS response{where}; request one IMT", source)
    imts = {_usgs_imt(found[0].get("metadata", {})) for found in by_site.values()}
    if len(imts) != 1:
        _fail(f"the USGS responses are for different intensity measures ({', '.join(sorted(imts))}); "
              "give one IMT", source)
    imt = imts.pop()
    measure, period, factor = _measure_from_imt(imt, source)
    sites = []
    for (lon, lat), (entry,) in by_site.items():
        metadata, curves = entry.get("metadata", {}), entry.get("data", [])
        total = [c for c in curves if c.get("component") == "Total"]
        if not total or "xvalues" not in metadata:
            _fail("USGS hazard JSON without metadata.xvalues and a 'Total' curve", source)
        intensity = np.asarray(metadata["xvalues"], float) * factor
        frequency = np.asarray(total[0]["yvalues"], float)
        keep = frequency > 0
        located = isinstance(lon, (int, float)) and isinstance(lat, (int, float))
        sites.append((float(lon) if located else None, float(lat) if located else None,
                      intensity[keep], frequency[keep]))
    first = next(iter(by_site))
    notes = {"imt": imt, "latitude": first[1], "longitude": first[0]} if len(sites) == 1 else {"imt": imt}
    notes.update({"component": DEFAULT_COMPONENT,
                  "component_basis": "a USGS NSHMP curve, from NGA-West2 ground motion models"})
    return sites, measure, period, notes


def _choose_site(sites: list, site: tuple[float, float] | None, source: str):
    """(intensity, frequency, HazardSite or None) of the file's site nearest the study's ``site``.

    Without ``site`` the file must hold one site. With it, the file must state its sites' coordinates.
    """
    if site is None:
        if len(sites) != 1:
            lons = [s[0] for s in sites if s[0] is not None]
            lats = [s[1] for s in sites if s[1] is not None]
            span = (f" (lon {min(lons):g} to {max(lons):g}, lat {min(lats):g} to {max(lats):g})"
                    if lons and lats else "")
            _fail(f"{len(sites)} sites in the file{span}; set the study's site, [hazard] site = [lon, lat] "
                  "(degrees), to use the nearest", source)
        return sites[0][2], sites[0][3], None
    if any(s[0] is None or s[1] is None for s in sites):
        _fail(f"[hazard] site = [{site[0]:g}, {site[1]:g}] is set but the file states no site coordinates (a "
              "rockfrag CSV has none); remove [hazard] site or give an OpenQuake or USGS file", source)
    distances = great_circle_km(site[0], site[1], np.array([s[0] for s in sites]), np.array([s[1] for s in sites]))
    index = int(np.argmin(distances))
    lon, lat, intensity, frequency = sites[index]
    chosen = HazardSite(longitude=lon, latitude=lat, distance_km=float(distances[index]),
                        requested=(float(site[0]), float(site[1])), index=index, count=len(sites))
    return intensity, frequency, chosen


def _read_any(text: str, source: str):
    stripped = text.lstrip()
    if stripped.startswith(("{", "[")):
        return _read_usgs_json(text, source)
    first = stripped.splitlines()[0] if stripped else ""
    if "investigation_time" in first or "generated_by" in first:
        return _read_openquake_csv(text, source)
    return _read_rockfrag_csv(text, source)


def load_hazard(path: str | os.PathLike | None = None, measure: str = "pga",
                period: float | None = None, site: tuple[float, float] | None = None) -> HazardCurve:
    """Read and check a hazard curve against the study's intensity ``measure`` (and Sa ``period`` [s]).

    Parameters
    ----------
    path : str or os.PathLike, optional
        A rockfrag CSV, an OpenQuake hazard-curve CSV or a USGS hazard JSON (module docstring); empty
        or None reads the shipped example (PGA only).
    measure : str, optional
        The study's intensity measure, a name of the registry (``rockfrag.measures.MEASURES``).
    period : float, optional
        The study's Sa period [s]; checked only for a measure defined at a period.
    site : (float, float), optional
        The study's site, longitude and latitude [degrees] (``[hazard] site``): picks the file's nearest
        site (great-circle distance). Required for a file of several sites.

    Returns
    -------
    HazardCurve
        Intensities in the measure's display unit (g for PGA and Sa, m/s for PGV), increasing, and
        their annual frequencies of exceedance [1/yr], decreasing; with ``site``, the chosen site and
        its distance [km] (``HazardCurve.site``).

    Raises
    ------
    ConfigError
        Field ``hazard.file``: the file is missing or malformed, has fewer than two points, is not
        monotone, or states another measure or period than the study's; holds several sites and no
        ``site`` is given; or ``site`` is given and the file states no coordinates.
    """
    if path is None or str(path) == "":
        source_file = files("rockfrag").joinpath(EXAMPLE_HAZARD)
        source = f"pipeline/{EXAMPLE_HAZARD} (example, not site-specific)"
    else:
        source_file, source = Path(path), str(path)
        if not source_file.is_file():
            _fail("file not found", source)
    text = source_file.read_text()
    sites, file_measure, file_period, notes = _read_any(text, source)
    study = measure_label(measure, period)
    if file_measure != measure:
        found = measure_label(file_measure, file_period)
        example = f" (the shipped example is for {measure_label(EXAMPLE_MEASURE)} only)" if path in (None, "") else ""
        _fail(f"the curve is for {found} but the study's intensity measure is {study}; give a hazard curve "
              f"for {study}" + example, source)
    uses_period = measure in MEASURES and MEASURES[measure].uses_period
    if uses_period and period is not None and abs(file_period - period) > PERIOD_TOLERANCE * max(1.0, period):
        _fail(f"the curve is for {measure_label(file_measure, file_period)} but the study uses {study}", source)
    intensity, frequency, chosen = _choose_site(sites, None if site is None else check_site(site), source)
    where = source if chosen is None else f"{source}, site {chosen.index + 1} of {chosen.count}"
    if intensity.size < 2:
        _fail("fewer than two points with a positive annual frequency", where)
    if np.any(intensity <= 0) or np.any(np.diff(intensity) <= 0):
        _fail("intensities must increase and be > 0", where)
    if np.any(frequency <= 0) or np.any(np.diff(frequency) > 0):
        _fail("annual frequency of exceedance must be > 0 and decrease with intensity", where)
    return HazardCurve(intensity, frequency, file_measure, file_period, source, notes, chosen,
                       notes.get("component", DEFAULT_COMPONENT))


def hazard_for(path: str | os.PathLike | None, measure: str, period: float | None = None,
               site: tuple[float, float] | None = None) -> HazardCurve | None:
    """The hazard curve of a study of ``measure`` (at ``period`` [s] for Sa), or None (no risk).

    ``path`` is read and checked against the measure, at the file's site nearest ``site`` [lon, lat in
    degrees] if given (``load_hazard``); without a path, the shipped example for a study of its
    measure, else None.
    """
    if not path and measure != EXAMPLE_MEASURE:
        return None
    uses_period = measure in MEASURES and MEASURES[measure].uses_period
    return load_hazard(path or None, measure, period if uses_period else None, site)


class HazardSettings(Protocol):
    """What ``study_hazard`` reads of a study; ``rockfrag.config.StudyConfig`` has it."""

    @property
    def hazard_file(self) -> str | Mapping[str, str]:
        """The hazard curve file ("" for none), or a table soil or site class -> file."""

    @property
    def measure(self) -> str:
        """The study's intensity measure (a name of ``rockfrag.measures.MEASURES``)."""

    @property
    def period(self) -> float:
        """The Sa period [s] (unused for measures not defined at a period)."""

    @property
    def hazard_site(self) -> tuple[float, float] | None:
        """The study's site [lon, lat] in degrees (``[hazard] site``), or None; optional (read with getattr)."""


def study_hazard(config: HazardSettings) -> HazardCurve | None:
    """The study's hazard curve: its ``hazard.file`` checked against its measure, at its site.

    The reference-site curve the soils' curves are amplified from; with a curve per soil (``hazard.file`` a
    table), the first soil's (none: the shipped example's rules). Every soil's own curve:
    rockfrag.site_hazard.study_site_hazards.

    Parameters
    ----------
    config : HazardSettings
        The study (``rockfrag.config.StudyConfig``): ``hazard_file``, ``measure``, ``period`` [s] and,
        if it has one, ``hazard_site`` ([lon, lat] in degrees, or None).

    Returns
    -------
    HazardCurve or None
        The curve (``load_hazard``); without a file, the shipped example for a PGA study and None
        (no risk computed) for another measure. A chosen site farther than ``FAR_SITE_KM`` from the
        study's is a ``HazardSiteWarning``.

    Raises
    ------
    ConfigError
        The file is missing or malformed, or is for another measure or period, or holds several sites
        and the study gives none (``load_hazard``).
    """
    path = config.hazard_file
    if isinstance(path, Mapping):
        found = soil_file(path, config.soils[0])
        path = found[1] if found is not None else ""
    hazard = hazard_for(path, config.measure, config.period, getattr(config, "hazard_site", None))
    warn_far_site(hazard)
    return hazard


def soil_file(files: Mapping[str, str], soil) -> tuple[str, str] | None:
    """(key, file) naming ``soil``'s curve in a table of curves (``[hazard] file``): by soil name, else site class.

    ``soil`` is a ``rockfrag.soils.SoilClass`` (its ``name`` and ``site_class``); None when neither is a key.
    """
    for key in (soil.name, soil.site_class):
        if key and key in files:
            return key, files[key]
    return None


def warn_far_site(hazard: HazardCurve | None) -> None:
    """A ``HazardSiteWarning`` when the file's site chosen for the study is farther than ``FAR_SITE_KM`` from it."""
    if hazard is not None and hazard.site is not None and hazard.site.distance_km > FAR_SITE_KM:
        warnings.warn(HazardSiteWarning(
            f"the hazard file's nearest site is {hazard.site.distance_km:.0f} km from the study's site (more than "
            f"{FAR_SITE_KM:g} km): {hazard.source}, {hazard.site.describe()}; its curve is another site's"))
        # stacklevel 1: one location, so the CLI's read and the fragility stage's re-read warn once


def hazard_of(hazard: HazardCurve | Mapping[str, HazardCurve] | None, soil: str) -> HazardCurve | None:
    """``soil``'s curve: ``hazard[soil]`` of a per-soil mapping (rockfrag.site_hazard.SiteHazards), else ``hazard``."""
    return hazard[soil] if isinstance(hazard, Mapping) else hazard


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


