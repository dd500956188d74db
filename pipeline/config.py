"""pipeline.config - study definition: shipped defaults plus a user TOML file, validated once.

Input : ``pipeline/defaults.toml`` and optionally a user study file with the same layout (a table or
        key in the user file replaces the default one; ``[blocks]`` and ``[soils_custom]`` entries are
        added to / replace the defaults by name).
Output: a frozen ``StudyConfig`` with SI values; errors name the file, the field, the value and the
        allowed range.
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
import tomllib
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

import numpy as np

from pipeline.blocks import Block
from pipeline.errors import ConfigError, PipelineError
from pipeline.measures import MEASURES
from pipeline.models import MODELS, SWITCH_RULES
from pipeline.soils import SOILS, SoilClass

MEASURE_UNITS = {name: (m.display_unit, m.display_factor) for name, m in MEASURES.items() if m.scalable}
"""Measures a study can scale records to: name -> (display unit, SI value of one display unit)."""

LEVELS_RELATIVE_TO = ("", "uplift")
"""``[intensity] levels.relative_to``: "" = levels in the measure's unit, the same for every block;
"uplift" = multiples of each block's uplift intensity (pipeline.study.uplift_intensity)."""


@dataclass(frozen=True)
class StudyConfig:
    name: str
    record_sets: tuple[str, ...]
    processing: str
    output: Path
    measure: str
    period: float
    damping: float
    levels: tuple[float, ...]  # in the measure's display unit (g or m/s)
    soils: tuple[SoilClass, ...]
    blocks: tuple[Block, ...]
    models: tuple[str, ...]
    switch: str
    tail: float
    overturn_angle: float
    hazard_file: str
    design_life: float
    bootstrap: int
    seed: int
    confidence: float
    source: str
    raw: dict
    levels_relative_to: str = ""  # "" (absolute levels) or "uplift" (multiples of each block's uplift intensity)
    capacity_resolution: float = 0.02  # relative bracket of the adaptive overturning capacities; 0 = off
    period_range: tuple[float, float] | None = None  # AvgSa periods [s]; None = 0.2 T .. 3 T

    @property
    def relative_levels(self) -> bool:
        return self.levels_relative_to == "uplift"

    @property
    def measure_options(self) -> dict:
        """Options every ``pipeline.measures.Measure`` call of the study takes."""
        return {"period": self.period, "damping": self.damping, "period_range": self.period_range}

    @property
    def level_unit(self) -> str:
        return MEASURE_UNITS[self.measure][0]

    @property
    def levels_si(self) -> np.ndarray:
        """Absolute intensity levels in SI (m/s^2 for PGA and Sa, m/s for PGV); with relative levels
        the dimensionless multiples themselves (per-block intensities: pipeline.study.level_intensities)."""
        if self.relative_levels:
            return np.asarray(self.levels, dtype=float)
        return np.asarray(self.levels) * MEASURE_UNITS[self.measure][1]

    def as_json(self) -> str:
        return json.dumps(self.raw, sort_keys=True, default=str)

    @property
    def config_hash(self) -> str:
        return hashlib.sha256(self.as_json().encode()).hexdigest()[:16]


def _merge(default: dict, user: dict) -> dict:
    merged = copy.deepcopy(default)
    for key, value in user.items():
        if key in ("blocks", "soils_custom") and isinstance(value, dict):
            merged.setdefault(key, {}).update(value)
        elif isinstance(value, dict) and isinstance(merged.get(key), dict) and key != "levels":
            merged[key] = _merge(merged[key], value)
        else:
            merged[key] = value
    return merged


def _number(data, key, where, source, low, high, default=None, low_open=False):
    value = data.get(key, default)
    if value is None:
        raise ConfigError(f"{where}.{key}", "missing", source)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(f"{where}.{key}", f"{value!r} is not a number; allowed {low} to {high}", source)
    if (value <= low if low_open else value < low) or value > high:
        raise ConfigError(f"{where}.{key}", f"{value} out of range; allowed {low} to {high}", source)
    return float(value)


def _levels(spec, source, unit):
    """Levels as given (display unit, or multiples when relative): a list, or {start, stop, count,
    spacing} or {values}, each optionally with ``relative_to``."""
    where = "intensity.levels"
    if isinstance(spec, dict) and "values" in spec:
        spec = spec["values"]
    if isinstance(spec, list):
        if not spec:
            raise ConfigError(where, "empty list", source)
        values = [_number({"v": v}, "v", where, source, 0, 1e3, low_open=True) for v in spec]
    elif isinstance(spec, dict):
        start = _number(spec, "start", where, source, 0, 1e3, low_open=True)
        stop = _number(spec, "stop", where, source, 0, 1e3, low_open=True)
        count = spec.get("count", 40)
        if not isinstance(count, int) or not 1 <= count <= 1000:
            raise ConfigError(f"{where}.count", f"{count!r}; allowed a whole number 1 to 1000", source)
        if stop <= start:
            raise ConfigError(where, f"stop {stop} must exceed start {start} [{unit}]", source)
        spacing = spec.get("spacing", "log")
        if spacing not in ("log", "linear"):
            raise ConfigError(f"{where}.spacing", f"{spacing!r}; allowed 'log' or 'linear'", source)
        values = (np.geomspace if spacing == "log" else np.linspace)(start, stop, count).tolist()
    else:
        raise ConfigError(where, "expected a list of levels or {start, stop, count, spacing}", source)
    if sorted(values) != values or len(set(values)) != len(values):
        raise ConfigError(where, "levels must increase strictly", source)
    return tuple(float(v) for v in values)


def _block(name, data, source):
    known = {"b", "h", "R", "alpha", "mass", "E_b", "footprint_area", "soil_depth", "why"}
    unknown = set(data) - known
    if unknown:
        raise ConfigError(f"blocks.{name}.{sorted(unknown)[0]}", f"unknown key; allowed: {', '.join(sorted(known))}",
                          source)
    try:
        return Block(name=name, b=data.get("b"), h=data.get("h"), R=data.get("R"), alpha=data.get("alpha"),
                     mass=data.get("mass", 1e5), E_b=data.get("E_b", 30e9),
                     footprint_area=data.get("footprint_area"), soil_depth=data.get("soil_depth", 2.0),
                     description=data.get("why", ""))
    except ConfigError as error:
        raise ConfigError(error.field, error.reason, source) from None


ALLOWED_KEYS = {
    "": {"study", "intensity", "soils", "models", "solver", "blocks", "soils_custom", "damage_states",
         "hazard", "fragility"},
    "study": {"name", "record_sets", "processing", "output"},
    "intensity": {"measure", "period", "damping", "levels", "capacity_resolution", "period_range"},
    "solver": {"switch", "tail", "overturn_angle"},
    "hazard": {"file", "design_life"},
    "fragility": {"bootstrap", "seed", "confidence"},
}


def _check_keys(data, source):
    for table, allowed in ALLOWED_KEYS.items():
        section = data if table == "" else data.get(table, {})
        if not isinstance(section, dict):
            raise ConfigError(table, "expected a table", source)
        for key in section:
            if key not in allowed:
                where = f"{table}.{key}" if table else key
                hint = " (top-level keys such as soils/models must come before the first [table])" \
                    if key in ALLOWED_KEYS[""] else ""
                raise ConfigError(where, f"unknown key; allowed: {', '.join(sorted(allowed))}{hint}", source)


def study_from_dict(data: dict, source="<dict>") -> StudyConfig:
    _check_keys(data, source)
    study = data.get("study", {})
    intensity = data.get("intensity", {})
    solver = data.get("solver", {})
    measure = intensity.get("measure", "pga")
    if measure not in MEASURE_UNITS:
        raise ConfigError("intensity.measure", f"{measure!r}; allowed: {', '.join(MEASURE_UNITS)}", source)
    unit = MEASURE_UNITS[measure][0]
    record_sets = study.get("record_sets", ["far-field"])
    if isinstance(record_sets, str):
        record_sets = [record_sets]
    if not record_sets:
        raise ConfigError("study.record_sets", "empty; name at least one record set", source)

    custom = {}
    for name, soil in data.get("soils_custom", {}).items():
        try:
            custom[name] = SoilClass(name, _number(soil, "shear_modulus", f"soils_custom.{name}", source, 0, 1e13, low_open=True),
                                     float(soil.get("poisson_ratio", 0.3)), float(soil.get("density", 2000.0)),
                                     float(soil.get("damping_ratio", 0.05)), soil.get("why", "user soil"))
        except ConfigError as error:
            raise ConfigError(error.field, error.reason, source) from None
    available = {**SOILS, **custom}
    soils = []
    for name in data.get("soils", list(SOILS)):
        if name not in available:
            raise ConfigError("soils", f"unknown soil {name!r}; available: {', '.join(available)}", source)
        soils.append(available[name])
    models = data.get("models", ["housner", "ssi"])
    for name in models:
        if name not in MODELS:
            raise ConfigError("models", f"unknown model {name!r}; available: {', '.join(MODELS)}", source)
    blocks = [_block(name, spec, source) for name, spec in data.get("blocks", {}).items()]
    if not blocks:
        raise ConfigError("blocks", "no block defined", source)
    switch = solver.get("switch", "consistent")
    if switch not in SWITCH_RULES:
        raise ConfigError("solver.switch", f"{switch!r}; allowed: {', '.join(SWITCH_RULES)}", source)
    if not soils or not models:
        raise ConfigError("soils" if not soils else "models", "empty list", source)
    return StudyConfig(
        name=str(study.get("name", "study")), record_sets=tuple(str(s) for s in record_sets),
        processing=str(study.get("processing", "")), output=Path(study.get("output", "reports")),
        measure=measure,
        period=_number(intensity, "period", "intensity", source, 0.01, 20.0, default=1.0),
        damping=_number(intensity, "damping", "intensity", source, 0.0, 0.5, default=0.05),
        levels=_levels(intensity.get("levels", {"start": 0.05, "stop": 3.0, "count": 40}), source, unit),
        soils=tuple(soils), blocks=tuple(blocks), models=tuple(models), switch=switch,
        tail=_number(solver, "tail", "solver", source, 0.0, 600.0, default=10.0),
        overturn_angle=_number(solver, "overturn_angle", "solver", source, 0.0, math.pi / 2,
                               default=math.pi / 2, low_open=True),
        hazard_file=str(data.get("hazard", {}).get("file", "")),
        design_life=_number(data.get("hazard", {}), "design_life", "hazard", source, 0.0, 10000.0, default=50.0,
                            low_open=True),
        bootstrap=int(_number(data.get("fragility", {}), "bootstrap", "fragility", source, 0, 100000, default=100)),
        seed=int(_number(data.get("fragility", {}), "seed", "fragility", source, 0, 2**32, default=0)),
        confidence=_number(data.get("fragility", {}), "confidence", "fragility", source, 0.0, 1.0, default=0.9,
                           low_open=True),
        source=source, raw=data, **_intensity_extras(intensity, source))


def _intensity_extras(intensity, source) -> dict:
    """The per-block level, adaptive-capacity and AvgSa settings of ``[intensity]``."""
    levels = intensity.get("levels", {})
    relative_to = levels.get("relative_to", "") if isinstance(levels, dict) else ""
    if relative_to not in LEVELS_RELATIVE_TO:
        raise ConfigError("intensity.levels.relative_to", f"{relative_to!r}; allowed: \"\" (absolute levels) "
                          "or \"uplift\" (multiples of each block's uplift intensity)", source)
    if isinstance(levels, dict):
        unknown = set(levels) - {"start", "stop", "count", "spacing", "values", "relative_to"}
        if unknown:
            raise ConfigError(f"intensity.levels.{sorted(unknown)[0]}", "unknown key; allowed: start, stop, "
                              "count, spacing, values, relative_to", source)
    resolution = _number(intensity, "capacity_resolution", "intensity", source, 0.0, 0.5, default=0.02)
    period_range = intensity.get("period_range")
    if period_range is not None:
        if (not isinstance(period_range, list) or len(period_range) != 2
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in period_range)
                or not 0.01 <= period_range[0] < period_range[1] <= 20.0):
            raise ConfigError("intensity.period_range", f"{period_range!r}; allowed [low, high] in s with "
                              "0.01 <= low < high <= 20", source)
        period_range = (float(period_range[0]), float(period_range[1]))
    return {"levels_relative_to": relative_to, "capacity_resolution": resolution, "period_range": period_range}


def load_study(path=None, overrides: dict | None = None) -> StudyConfig:
    """Defaults merged with a user study file (and a dict of overrides, e.g. from the CLI)."""
    default = tomllib.loads(files("pipeline").joinpath("defaults.toml").read_text())
    source = "pipeline/defaults.toml"
    merged = default
    if path is not None:
        path = Path(path)
        try:
            user = tomllib.loads(path.read_text())
        except FileNotFoundError:
            raise PipelineError(f"{path}: study file not found") from None
        except tomllib.TOMLDecodeError as error:
            raise ConfigError("study", f"not valid TOML ({error})", str(path)) from None
        merged = _merge(default, user)
        source = str(path)
    if overrides:
        merged = _merge(merged, overrides)
    return study_from_dict(merged, source)
