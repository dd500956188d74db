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
from pipeline.models import BED_TYPES, MODELS, SWITCH_RULES
from pipeline.soils import SOILS, SoilClass
from pipeline.units import STANDARD_GRAVITY

MEASURE_UNITS = {"pga": ("g", STANDARD_GRAVITY), "sa": ("g", STANDARD_GRAVITY), "pgv": ("m/s", 1.0)}


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
    bed: str
    tail: float
    overturn_angle: float
    hazard_file: str
    design_life: float
    bootstrap: int
    seed: int
    confidence: float
    source: str
    raw: dict

    @property
    def level_unit(self) -> str:
        return MEASURE_UNITS[self.measure][0]

    @property
    def levels_si(self) -> np.ndarray:
        """Intensity levels in SI (m/s^2 for PGA and Sa, m/s for PGV)."""
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
    where = "intensity.levels"
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
    "intensity": {"measure", "period", "damping", "levels"},
    "solver": {"switch", "bed", "tail", "overturn_angle"},
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
    models = data.get("models", ["housner", "ssi", "winkler"])
    for name in models:
        if name not in MODELS:
            raise ConfigError("models", f"unknown model {name!r}; available: {', '.join(MODELS)}", source)
    blocks = [_block(name, spec, source) for name, spec in data.get("blocks", {}).items()]
    if not blocks:
        raise ConfigError("blocks", "no block defined", source)
    switch = solver.get("switch", "consistent")
    if switch not in SWITCH_RULES:
        raise ConfigError("solver.switch", f"{switch!r}; allowed: {', '.join(SWITCH_RULES)}", source)
    bed = solver.get("bed", "continuous")
    if bed not in BED_TYPES:
        raise ConfigError("solver.bed", f"{bed!r}; allowed: {', '.join(BED_TYPES)}", source)
    if not soils or not models:
        raise ConfigError("soils" if not soils else "models", "empty list", source)
    return StudyConfig(
        name=str(study.get("name", "study")), record_sets=tuple(str(s) for s in record_sets),
        processing=str(study.get("processing", "")), output=Path(study.get("output", "reports")),
        measure=measure,
        period=_number(intensity, "period", "intensity", source, 0.01, 20.0, default=1.0),
        damping=_number(intensity, "damping", "intensity", source, 0.0, 0.5, default=0.05),
        levels=_levels(intensity.get("levels", {"start": 0.05, "stop": 3.0, "count": 40}), source, unit),
        soils=tuple(soils), blocks=tuple(blocks), models=tuple(models), switch=switch, bed=bed,
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
        source=source, raw=data)


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
