"""rockfrag.config - study definition: shipped defaults plus a user TOML file, validated once.

Input : ``pipeline/defaults.toml`` and optionally a user study file with the same layout (a table or
        key in the user file replaces the default one; ``[soils_custom.NAME]``, ``[blocks_custom.NAME]``
        and ``[damage_states.NAME]`` entries are added to / replace the defaults by name).
Output: a frozen ``StudyConfig`` with SI values.

Validation happens here, once, before anything runs: every key at every level is checked against
``SCHEMA`` (unknown keys, TOML types, ranges), then the cross-references (soil, block and model names,
damage-state EDPs, the hazard file). Each mistake is one ``ConfigError`` naming the study file and
the field as the user wrote it (``soils_custom.loam.poison_ratio``, ``intensity.levels.start``).

Blocks: ``blocks = ["paper", "mine"]`` selects which blocks run, among the shipped presets and the
user's ``[blocks_custom.NAME]`` tables. A user file may instead define ``[blocks.NAME]`` tables (TOML
cannot hold both forms under one key): then exactly those blocks run, and the presets do not.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import hashlib
import json
import math
import tomllib
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

import numpy as np

from rockfrag.blocks import BLOCK_RANGES, Block
from rockfrag.damage_states import DEFAULT_LIMITS, EDPS, DamageState, damage_states_from_config
from rockfrag.errors import ConfigError, ManifestError, PipelineError
from rockfrag.hazard import check_site
from rockfrag.measures import MEASURES, scaling_measures
from rockfrag.models import BED_TYPES, MODELS, SWITCH_RULES, get_model
from rockfrag.models.options import HOUSNER
from rockfrag.models.variants import (
    DEFAULT_DESIGN,
    OLD_BAND_NAMES,
    RECOMMENDED,
    SampleDesign,
    sample_models,
)
from rockfrag.plausibility import ON_IMPLAUSIBLE, check_study
from rockfrag.site_amplification import REFERENCE_VS30, SCENARIO, VS30_SIGMA
from rockfrag.site_hazard import check_site_hazards
from rockfrag.soils import DEFAULT_FRICTION, SITE_CLASSES, SOIL_RANGES, SOILS, VS30_RANGE, SoilClass
from rockfrag.validation import (
    Checked,
    Either,
    Flag,
    Interval,
    NamedTables,
    Names,
    Number,
    Numbers,
    Table,
    Text,
    did_you_mean,
    schema_keys,
)
from rockfrag.validation import shown as _shown

SAMPLE = RECOMMENDED
"""``[solver] restitution = "recommended"``: the bed model runs as the recommended model, its central member
(``recommended``) and the designed sample over its epistemic parameters (``[uncertainty]``,
rockfrag.models.variants)."""
MODEL_QUALITY = ("superior", "good", "fair", "poor")
"""``[uncertainty] model_quality``: FEMA P-695's rating of the model (rockfrag.fragility.FORM_RATINGS)."""


def _removed(new: str):
    """A schema check that refuses a key the designed sample replaced, naming its replacement."""
    def refuse(value, field, source):
        raise ConfigError(field, f"removed: the restitution band gave way to the designed sample; use {new}",
                          source)
    return Checked(refuse, f"removed; use {new}")

FRICTION_MODES = ("recommended", "where-it-matters", "all", "none")
"""``[solver] friction``: which housner and winkler cells slide (rockfrag.study.cell_friction)."""

COMPONENTS = ("rotd50", "single")
"""``[intensity] component``: how a record's intensity is defined (rockfrag.study.record_intensities):
"rotd50" scales the two horizontal components of a station together by their pair's RotD50 (Boore 2010; a
record without a partner keeps its own component), "single" scales each component by its own measure."""

LEVEL_REFERENCES = ("", "uplift")
"""``relative_to`` of ``[intensity] levels``: "" = absolute levels, "uplift" = multiples of each block's
uplift intensity."""


# ---------------------------------------------------------------- the schema
# The schema classes are rockfrag.validation's; a study table adds one hint for a top-level key written
# below a [table] header (TOML puts it into that table).

def _misplaced(key: str) -> str:
    return " (top-level keys such as soils/models must come before the first [table])" if key in SCHEMA.fields else ""


def _table(fields: dict) -> Table:
    """A table of the study file (see ``_misplaced``)."""
    return Table(fields, misplaced=_misplaced)


TEXT = Text()
SOIL_TABLE = _table({**SOIL_RANGES, "vs30": VS30_RANGE, "why": TEXT})
# The ranges of a block are Block's own (pipeline/blocks.py BLOCK_RANGES), declared once for both.
BLOCK_TABLE = _table({**BLOCK_RANGES, "why": TEXT})
LEVEL = Number(0, 1e3, low_open=True)
"""An intensity level (g or m/s), or a multiple of a block's uplift intensity."""
LEVEL_TABLE = _table({"start": LEVEL, "stop": LEVEL, "count": Number(1, 1000, integer=True),
                      "spacing": Text(("log", "linear")), "values": Numbers(LEVEL),
                      "relative_to": Text(LEVEL_REFERENCES)})
"""``levels = { start, stop, count, spacing }`` or ``{ values, relative_to }``."""


def _damage_state_table() -> Table:
    keys = [f.name for f in dataclasses.fields(DamageState) if f.name != "name" and f.metadata.get("study_key", True)]
    kinds = {"threshold": Number(0, low_open=True), "edp": Text(tuple(EDPS))}
    return Table({key: kinds.get(key, TEXT) for key in keys})


SCHEMA = Table({
    "soils": Names('["sand", "rock"]'),
    "models": Names('["housner", "ssi"]'),
    "blocks": Either(Names('["paper", "slender-cabinet"]'), NamedTables(BLOCK_TABLE)),
    "soils_custom": NamedTables(SOIL_TABLE),
    "blocks_custom": NamedTables(BLOCK_TABLE),
    "damage_states": NamedTables(_damage_state_table()),
    "study": _table({"name": Text(nonempty=True), "record_sets": Names('["far-field"]'), "processing": TEXT,
                     "output": Text(nonempty=True),
                     "units": TEXT, "dt": Number(0, 1, low_open=True, unit="s"), "vertical": Flag(),
                     # report metadata, read by rockfrag.report
                     "title": TEXT, "project": TEXT, "author": TEXT}),
    "intensity": _table({"measure": Text(scaling_measures()), "component": Text(COMPONENTS),
                         "period": Number(0.01, 20.0, unit="s"),
                         "damping": Number(0.0, 0.5),
                         "levels": Checked(lambda value, field, source: _levels(value, source, check_only=True),
                                           "a list of levels or { start, stop, count, spacing }"),
                         "capacity_resolution": Number(0.0, 0.5),
                         "credible_max": Number(0.0, 1e3, low_open=True),
                         "credible_measure": Text(scaling_measures()),
                         "credible_reason": TEXT,
                         "credible_frequency": Number(0.0, 1.0),
                         "beyond_credible": Flag(),
                         "period_range": Interval(Number(0.01, 20.0, unit="s"))}),
    "solver": _table({"switch": Text(tuple(SWITCH_RULES)), "tail": Number(0.0, 600.0, unit="s"),
                      "overturn_angle": Number(0.0, math.pi / 2, low_open=True, unit="rad"),
                      "bed": Text(tuple(BED_TYPES)),
                      "restitution": Checked(lambda value, field, source: _restitution(value, field, source),
                                             f"{SAMPLE!r}, {HOUSNER!r}, \"\" or a number > 0.0 and < 1.0"),
                      "restitution_band": _removed("[uncertainty] restitution_range"),
                      "friction": Text(FRICTION_MODES)}),
    "uncertainty": _table({"restitution_range": Interval(Number(0.5, 1.5), strict=False),
                           "friction_factor": Number(1.0, 3.0, low_open=True),
                           "stiffness_factor": Number(1.0, 10.0, low_open=True),
                           "model_quality": Text(MODEL_QUALITY)}),
    "hazard": _table({"file": Checked(lambda value, field, source: _hazard_files(value, field, source),
                                      "a file name, or a table of soil or site class = file name"),
                      "design_life": Number(0.0, 10000.0, low_open=True, unit="years"),
                      "return_periods": Numbers(Number(1.0, 1e6, unit="years")),  # the report's answer pages
                      "site": Checked(check_site, "[lon, lat] in degrees, lon >= -180 and < 360, lat -90 to 90"),
                      "reference_vs30": VS30_RANGE,
                      "vs30": Checked(lambda value, field, source: _named(value, field, source, VS30_RANGE),
                                      "a table of soil = its site's Vs30 [m/s]"),
                      "vs30_sigma": Number(0.0, 2.0),
                      "scenario_magnitude": Number(3.0, 8.5),
                      "scenario_distance": Number(0.0, 400.0, unit="km")}),
    "decision": _table({"max_probability_in_life": Checked(lambda value, field, source: _named(
                            value, field, source, Number(0.0, 1.0, low_open=True)),
                            "a table of damage state = probability, each > 0 and <= 1"),
                        "max_sliding_share": Number(0.0, 1.0)}),  # read by rockfrag.answer (verdicts)
    "fragility": _table({"bootstrap": Number(0, 100000, integer=True), "seed": Number(0, 2**32, integer=True),
                         "confidence": Number(0.0, 1.0, low_open=True, high_open=True)}),
    "checks": _table({"plausibility": Text(ON_IMPLAUSIBLE)}),
    "report": _table({"title": TEXT, "project": TEXT, "author": TEXT, "showcase_record": TEXT,
                      "showcase_block": TEXT,
                      "block_names": Checked(lambda value, field, source: _named(value, field, source, TEXT),
                                             "a table of block = the name the report gives it")}),
    "applicability": _table({
        "g_range": Interval(Number(0, 1e13, low_open=True, unit="Pa"), names=("G_min", "G_max")),
        "n_g": Number(2, 200, integer=True),
        "levels": Numbers(Number(0, 100, low_open=True)),
        "block_moduli": Numbers(Number(0, 1e13, low_open=True, unit="Pa")),
        "tolerance": Number(0, 10, low_open=True),
        "run": Flag(),  # read by rockfrag.cli (rockfrag fragility); absent: only the default study
    }),
})
"""Every key a study file may hold, with its type and range."""


def _restitution(value, field, source):
    """``[solver] restitution``: "recommended", "housner", "" (the soil's damping ratio) or a number in (0, 1)."""
    if value == "band":
        raise ConfigError(field, f"\"band\" was removed: the restitution band gave way to the designed sample; use "
                          f"{SAMPLE!r} (the recommended model and its sample, set in [uncertainty] "
                          "restitution_range, friction_factor, stiffness_factor, model_quality)", source)
    if isinstance(value, str):
        return Text((SAMPLE, HOUSNER, "")).check(value, field, source)
    return Number(0.0, 1.0, low_open=True, high_open=True).check(value, field, source)


def _hazard_files(value, field, source):
    """``[hazard] file``: a file name ("" for the shipped example), or a table of soil or site class = file name."""
    if isinstance(value, dict):
        if not value:
            raise ConfigError(field, "empty table; name a file for each soil or site class", source)
        return _named(value, field, source, Text(nonempty=True))
    return TEXT.check(value, field, source)


def _named(value, field, source, item):
    """A table of any names, each value checked by ``item`` (``[decision] max_probability_in_life``)."""
    if not isinstance(value, dict):
        raise ConfigError(field, f"{_shown(value)}; must be a table {{ name = value }}", source)
    return {name: item.check(entry, f"{field}.{name}", source) for name, entry in value.items()}


REMOVED_KEYS = {
    ("report", "friction_coefficient"): "removed: the base friction is per soil now, friction_static and "
    "friction_kinetic of each soil class (pipeline/soils.py; a [soils_custom.NAME] table may set them), and "
    "[solver] friction says which runs slide",
}
"""Keys a study file may no longer hold, with what replaces them."""


def validate(data: dict, source: str) -> None:
    """Check keys, TOML types and ranges of a (possibly partial) study dict, as the user wrote it."""
    for (table, key), reason in REMOVED_KEYS.items():
        if isinstance(data.get(table), dict) and key in data[table]:
            raise ConfigError(f"{table}.{key}", reason, source)
    SCHEMA.check(data, "", source)
    blocks = data.get("blocks")
    for table, tables in (("blocks", blocks if isinstance(blocks, dict) else {}),
                          ("blocks_custom", data.get("blocks_custom", {}))):
        for name, spec in tables.items():
            _block(table, name, spec, source)  # Block's own ranges, with the user's field names
    for name, spec in data.get("soils_custom", {}).items():
        _soil(name, spec, source)


# ---------------------------------------------------------------- the study

@dataclass(frozen=True)
class ApplicabilitySettings:
    """The soil-stiffness sweep of ``rockfrag applicability`` (``[applicability]``; one definition)."""

    g_range: tuple[float, float] = (10e6, 100e9)
    n_g: int = 13
    levels: tuple[float, ...] = (1.5, 2.5, 4.0)
    block_moduli: tuple[float, ...] = (30e9, 210e9)
    tolerance: float = 0.10

    @property
    def shear_moduli(self) -> np.ndarray:
        """The swept soil shear moduli G_s [Pa]: ``n_g`` values log-spaced over ``g_range``."""
        return np.geomspace(self.g_range[0], self.g_range[1], self.n_g)


@dataclass(frozen=True)
class StudyConfig:
    """A validated study: the defaults merged with the user's file (``load_study``), frozen.

    Attributes
    ----------
    name : str
        The study's name (``[study] name``).
    record_sets : tuple of str
        Record sets, record ids, folders or files (``rockfrag.records.load_records``).
    processing : str
        The processing recipe file; "" for the shipped ``pipeline/processing.toml``.
    output : Path
        Folder of the study's outputs.
    measure, period, damping : str, float, float
        The intensity measure (``pga``, ``pgv``, ``sa``, ...), the oscillator period [s] and damping
        ratio [-] of Sa.
    credible_max, credible_measure, credible_reason, credible_frequency : float, str, str, float
        The credible cap on the intensity (``[intensity] credible_*``; rockfrag.study.credible_cap): at most
        ``credible_max`` in ``credible_measure``'s display unit (3 g PGA by default; for another study measure its
        equivalent over the records), raised to the site hazard's intensity at ``credible_frequency`` [1/yr] (0:
        not) when that is higher, with the reason stated ("" for the shipped one).
    beyond_credible : bool
        Run the level grid past the cap as given (IDA to overturning, for research); fits, risk and exchange
        files still use only the levels at or below it.
    level_range : (float, float, int, str) or None
        ``levels = { start, stop, count, spacing }``: the grid the cap re-spaces per block (None: listed levels).
    component : str
        ``[intensity] component``: "rotd50" (each station's two horizontal components scaled together by the
        pair's RotD50, Boore 2010; a record without a partner by its own component) or "single" (each
        component by its own measure; ``COMPONENTS``).
    levels : tuple of float
        Intensity levels in the measure's display unit (g or m/s), or multiples of each block's uplift
        intensity when ``levels_relative_to`` is ``"uplift"`` (SI values: ``levels_si``).
    soils, blocks, models : tuple
        The ``SoilClass`` and ``Block`` objects and the model names that run.
    switch, bed : str
        ssi pivot-switch rule (consistent | continuous) and winkler bed law (two-spring | continuous |
        hunt-crossley).
    restitution : str or float
        The bed models' restitution target (``[solver] restitution``): "recommended" (``models`` then holds the
        bed model's designed sample, ``recommended`` and ``recommended-<member>``), "housner", a number, or ""
        (no target: the bed's damping ratio is the soil's ``damping_ratio``).
    design : rockfrag.models.variants.SampleDesign
        ``[uncertainty]``: the restitution range (multiples of Housner's r), the friction and stiffness factors.
    model_quality : str
        ``[uncertainty] model_quality``: FEMA P-695's rating of the model's form (rockfrag.fragility).
    friction : str
        ``[solver] friction``, which housner and winkler cells run with Coulomb friction at the base (each
        soil's ``friction_static``/``friction_kinetic``): "recommended" (every winkler cell, and housner where the
        soil's mu_s is below the block's b/h), "where-it-matters" (both only there), "all" or "none" (every
        base tied). ssi is always tied (rockfrag.study.cell_friction).
    tail : float
        Free vibration simulated after the record [s].
    overturn_angle : float
        |theta| at which a block has overturned [rad].
    hazard_file : str or dict
        The reference site's hazard curve file ("" for the shipped example), or a table soil or site class ->
        file (a curve per soil; rockfrag.site_hazard).
    reference_vs30 : float
        Vs30 of the hazard curve's site [m/s] (``[hazard] reference_vs30``), from which each soil's curve is
        amplified.
    vs30_sigma : float
        Standard deviation of ln Vs30 of each soil's site [-] (``[hazard] vs30_sigma``).
    scenario : (float, float)
        Magnitude and Joyner-Boore distance [km] of the rock medians that relate a non-PGA measure to the rock PGA
        of the site term (``[hazard] scenario_magnitude``, ``scenario_distance``).
    hazard_site : (float, float) or None
        ``[hazard] site``: the study's [lon, lat] [degrees], which picks the nearest site of a multi-site file.
    design_life : float
        Design life [years] for the probability of each damage state.
    bootstrap, seed, confidence : int, int, float
        Bootstrap samples, their generator's seed, and the two-sided confidence level [-] of the bounds.
    source : str
        The study file (or ``pipeline/defaults.toml``) that errors name.
    raw : dict
        The merged study as a dict (``as_json``, ``config_hash``).
    levels_relative_to : str
        "" (absolute levels) or "uplift".
    capacity_resolution : float
        Relative bracket of the adaptive overturning capacities [-]; 0 turns them off.
    period_range : (float, float) or None
        AvgSa periods [s]; None for 0.2 to 3 times ``period``.
    record_units : str
        Acceleration units of the user's record files that do not state them ("" if not given).
    record_dt : float or None
        Time step of the user's one-column text records [s]; None: from the files.
    applicability : ApplicabilitySettings
        The soil-stiffness sweep (``[applicability]``).
    vertical : bool
        ``[study] vertical``: each horizontal component runs with its station's vertical component (g + a_v(t)
        in every model) and, for comparison, without it (rockfrag.study). False: horizontal components only.
    """

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
    hazard_file: str | dict[str, str]
    design_life: float
    bootstrap: int
    seed: int
    confidence: float
    source: str
    raw: dict
    bed: str = "continuous"
    levels_relative_to: str = ""  # "" (absolute levels) or "uplift" (multiples of each block's uplift intensity)
    capacity_resolution: float = 0.02  # relative bracket of the adaptive overturning capacities; 0 = off
    period_range: tuple[float, float] | None = None  # AvgSa periods [s]; None = 0.2 T .. 3 T
    record_units: str = ""
    record_dt: float | None = None  # time step of one-column text records [s]; None: from the files
    applicability: ApplicabilitySettings = ApplicabilitySettings()
    vertical: bool = False  # apply each record's vertical component (and compare with the run without it)
    hazard_site: tuple[float, float] | None = None  # [lon, lat] [degrees]; picks a multi-site file's nearest site
    restitution: str | float = ""  # bed models' restitution target: "recommended", "housner", a number, "" (none)
    design: SampleDesign = DEFAULT_DESIGN  # [uncertainty]: the recommended model's sampled ranges
    model_quality: str = "fair"  # [uncertainty]: FEMA P-695's rating of the model's form
    friction: str = "recommended"  # which cells slide: recommended | where-it-matters | all | none
    reference_vs30: float = REFERENCE_VS30  # Vs30 of the hazard curve's site [m/s]
    vs30_sigma: float = VS30_SIGMA  # standard deviation of ln Vs30 of each soil's site [-]
    scenario: tuple[float, float] = SCENARIO  # (magnitude, Joyner-Boore distance [km]) of the rock-PGA ratio
    component: str = "rotd50"  # the records' intensity: rotd50 (pairs) | single (each component its own)
    credible_max: float = 3.0  # in credible_measure's display unit
    credible_measure: str = "pga"
    credible_reason: str = ""  # "" = the shipped reason (rockfrag.study.DEFAULT_CREDIBLE_REASON)
    credible_frequency: float = 1e-5  # [1/yr]; 0 = the hazard does not raise the cap
    beyond_credible: bool = False
    level_range: tuple | None = None  # (start, stop, count, spacing) of a { start, stop, count } grid

    @property
    def calibrates_bed(self) -> bool:
        """True when the bed models' damping is calibrated to a restitution target (not the soil's xi)."""
        return self.restitution != ""

    @property
    def relative_levels(self) -> bool:
        """True when the levels are multiples of each block's uplift intensity."""
        return self.levels_relative_to == "uplift"

    @property
    def measure_options(self) -> dict:
        """Options every ``rockfrag.measures.Measure`` call of the study takes."""
        return {"period": self.period, "damping": self.damping, "period_range": self.period_range}

    @property
    def levels_si(self) -> np.ndarray:
        """Absolute intensity levels in SI (m/s^2 for PGA and Sa, m/s for PGV).

        With relative levels, the dimensionless multiples themselves (per-block intensities:
        rockfrag.study.level_intensities).
        """
        if self.relative_levels:
            return np.asarray(self.levels, dtype=float)
        return np.asarray(self.levels) * MEASURES[self.measure].display_factor

    def as_json(self) -> str:
        """The merged study dict as canonical JSON (sorted keys)."""
        return json.dumps(self.raw, sort_keys=True, default=str)

    @property
    def config_hash(self) -> str:
        """The first 16 hex digits of the sha256 of ``as_json``."""
        return hashlib.sha256(self.as_json().encode()).hexdigest()[:16]


def _merge(default: dict, user: dict) -> dict:
    merged = copy.deepcopy(default)
    for key, value in user.items():
        if key in ("blocks_custom", "soils_custom", "damage_states") and isinstance(value, dict):
            merged.setdefault(key, {}).update(value)
        elif isinstance(value, dict) and isinstance(merged.get(key), dict) and key not in ("levels", "blocks"):
            merged[key] = _merge(merged[key], value)
        else:
            merged[key] = value
    return merged


def _blocks_as_selector(data: dict) -> dict:
    """``[blocks.NAME]`` tables -> ``blocks = [NAME, ...]`` plus ``[blocks_custom.NAME]`` (a copy)."""
    if not isinstance(data.get("blocks"), dict):
        return data
    data = dict(data)
    tables = data.pop("blocks")
    data["blocks_custom"] = {**data.get("blocks_custom", {}), **tables}
    data["blocks"] = list(tables)
    return data


def _user_blocks(default: dict, user: dict) -> dict:
    """The user's file with its block choice made explicit: defining blocks without a selector runs them only."""
    user = _blocks_as_selector(user)
    if "blocks" not in user and user.get("blocks_custom"):
        user["blocks"] = list(user["blocks_custom"])
    return user


def _levels(spec, source, check_only=False):
    """Check ``[intensity] levels``: a list, or ``{start, stop, count, spacing, relative_to}``.

    Levels are in g or m/s, or multiples of each block's uplift intensity with ``relative_to = "uplift"``.

    Returns (levels, relative_to, level_range), level_range (start, stop, count, spacing) of a range spec
    (None for listed values); with ``check_only`` the spec unchanged.
    """
    where = "intensity.levels"
    relative_to = ""
    level_range = None
    if isinstance(spec, list):
        if not spec:
            raise ConfigError(where, "empty list; give at least one level", source)
        values = [LEVEL.check(v, f"{where}[{i}]", source) for i, v in enumerate(spec)]
    elif isinstance(spec, dict):
        LEVEL_TABLE.check(spec, where, source)
        relative_to = spec.get("relative_to", "")
        if "values" in spec:  # { values = [...], relative_to = "uplift" }: listed multiples or levels
            values = [float(v) for v in spec["values"]]
        else:
            for key in ("start", "stop"):
                if key not in spec:
                    raise ConfigError(f"{where}.{key}", f"missing; must be {LEVEL.describe()}", source)
            start, stop, count = float(spec["start"]), float(spec["stop"]), int(spec.get("count", 40))
            if stop <= start:
                raise ConfigError(where, f"stop {stop:g} must exceed start {start:g}", source)
            spacing = spec.get("spacing", "log")
            values = (np.geomspace if spacing == "log" else np.linspace)(start, stop, count).tolist()
            level_range = (start, stop, count, spacing)
    else:
        raise ConfigError(where, f"{_shown(spec)}; must be a list of levels or "
                          "{ start, stop, count, spacing }", source)
    if sorted(values) != values or len(set(values)) != len(values):
        raise ConfigError(where, "levels must increase strictly", source)
    if check_only:
        return spec
    return tuple(float(v) for v in values), relative_to, level_range


def _block(table, name, data, source) -> Block:
    try:
        return Block(name=name, b=data.get("b"), h=data.get("h"), R=data.get("R"), alpha=data.get("alpha"),
                     mass=data.get("mass", 1e5), E_b=data.get("E_b", 30e9),
                     footprint_area=data.get("footprint_area"), soil_depth=data.get("soil_depth", 2.0),
                     description=data.get("why", ""))
    except ConfigError as error:  # Block names fields "block NAME.key"; the user wrote "blocks.NAME.key"
        key = error.field.rsplit(".", 1)[1] if error.field.startswith(f"block {name}.") else None
        field = f"{table}.{name}.{key}" if key else f"{table}.{name}"
        raise ConfigError(field, error.reason, source) from None


def _soil(name, data, source) -> SoilClass:
    try:
        return SoilClass(name, float(data["shear_modulus"]), float(data.get("poisson_ratio", 0.3)),
                         float(data.get("density", 2000.0)), float(data.get("damping_ratio", 0.05)),
                         data.get("why", "user soil"), float(data.get("friction_static", DEFAULT_FRICTION[0])),
                         float(data.get("friction_kinetic", DEFAULT_FRICTION[1])),
                         float(data["vs30"]) if "vs30" in data else None)
    except KeyError:
        raise ConfigError(f"soils_custom.{name}.shear_modulus", "missing; must be a number > 0 [Pa]",
                          source) from None
    except ConfigError as error:
        raise ConfigError(f"soils_custom.{name}.{error.field.rsplit('.', 1)[1]}", error.reason, source) from None


def _select(kind, names, available, source):
    unknown = [n for n in names if n not in available]
    if unknown:
        raise ConfigError(kind, f"unknown {kind[:-1]} {unknown[0]!r}{did_you_mean(unknown[0], available)}; "
                          f"available: {', '.join(available)}", source)
    if len(set(names)) != len(names):
        raise ConfigError(kind, f"{[n for n in names if names.count(n) > 1][0]!r} named twice", source)
    return tuple(available[n] for n in names)


def _check_damage_states(data, source):
    """The study's damage states as the fragility stage will read them (its own EDP list).

    The verdict limits ``[decision] max_probability_in_life`` may name only those states.
    """
    try:
        names = [state.name for state in damage_states_from_config(data)]
    except ConfigError as error:
        raise ConfigError(error.field, error.reason, source) from None
    for name in data.get("decision", {}).get("max_probability_in_life", {}):
        if name not in names:
            raise ConfigError(f"decision.max_probability_in_life.{name}", f"not a damage state of the study; "
                              f"the states are {', '.join(names)}", source)


def _site_vs30(soils, overrides: dict, source) -> tuple[SoilClass, ...]:
    """The soils with ``[hazard] vs30`` applied: each named soil's site Vs30 [m/s] replaced."""
    names = [soil.name for soil in soils]
    for name in overrides:
        if name not in names:
            raise ConfigError(f"hazard.vs30.{name}", f"not a soil of the study{did_you_mean(name, names)}; the soils "
                              f"are {', '.join(names)}", source)
    return tuple(dataclasses.replace(soil, vs30=float(overrides[soil.name])) if soil.name in overrides else soil
                 for soil in soils)


def _check_hazard(config: StudyConfig) -> None:
    """Check the hazard as the risk stage reads it (rockfrag.site_hazard.check_site_hazards).

    Every curve loads (the file exists, is numeric, its frequencies decrease), is for the study's measure, and every
    soil has one; a soil amplified from the reference site has a site term for the measure. No file and a measure
    other than the shipped example's: no risk, nothing to check (rockfrag.hazard.hazard_for).
    """
    files = config.hazard_file if isinstance(config.hazard_file, dict) else {"": config.hazard_file}
    for key, path in files.items():
        if path and Path(path).is_dir():
            raise ConfigError(f"hazard.file{'.' + key if key else ''}", f"{path} is a folder; expected a CSV file",
                              config.source)
    names = {soil.name for soil in config.soils}
    for key in files:
        if key and key not in names and key not in SITE_CLASSES:
            raise ConfigError(f"hazard.file.{key}", f"neither a soil of the study nor a site class"
                              f"{did_you_mean(key, [*names, *SITE_CLASSES])}; the soils are "
                              f"{', '.join(sorted(names))}, the classes {', '.join(SITE_CLASSES)}", config.source)
    try:
        check_site_hazards(config)
    except ConfigError as error:
        reason = error.reason if error.source == config.source else f"{error.source}: {error.reason}"
        raise ConfigError(error.field, reason, config.source) from None
    except (ValueError, UnicodeDecodeError, OSError) as error:
        reason = str(error).splitlines()[0] if str(error) else type(error).__name__
        raise ConfigError("hazard.file", f"not a table of numbers (intensity, annual frequency) ({reason})",
                          config.source) from None


def _check_bed_dissipation(data, soils, models, restitution, source):
    """Refuse a user soil's explicit ``damping_ratio`` where a restitution target calibrates the bed's instead.

    With ``[solver] restitution`` set, every bed model (winkler) runs at the damping ratio calibrated to that
    target, never at the soil's: an explicit ``damping_ratio`` of a soil the study runs would be ignored there
    without a word. ``rockfrag.models.simulate`` refuses the same pair (``xi`` with ``restitution``).
    """
    if restitution == "" or not any(get_model(name).uses_bed for name in models):
        return
    custom = data.get("soils_custom", {})
    for soil in soils:
        if "damping_ratio" in custom.get(soil.name, {}):
            target = f"{restitution!r}" if isinstance(restitution, str) else f"{restitution:g}"
            raise ConfigError(f"soils_custom.{soil.name}.damping_ratio",
                              f"{soil.damping_ratio:g} together with [solver] restitution = {target}: the target "
                              "calibrates the bed models' damping ratio, so winkler would not use this one; remove "
                              "damping_ratio, or set [solver] restitution = \"\" to run the bed at the soil's "
                              "damping ratio", source)


STUDY_FILE_PATHS = (("study", "processing"), ("hazard", "file"))
"""The keys of a study file that name an input file, or a table of them (``[hazard] file`` per soil or site
class), besides the folders and files in ``study.record_sets``.

A relative path there is relative to the folder of the study file that holds it, so a study folder copied
elsewhere runs from any working folder; the same option on the command line (``--processing``, ``--set``) is
relative to the working folder. ``study.output`` is an output, relative to the working folder (as ``--output``).
"""


def _relative_to_study(user: dict, folder: Path) -> dict:
    """The user's study with the relative input paths it names joined to its own folder ``folder``.

    In ``study.record_sets`` record-set names and catalogue record ids stay as written, and so does a bare
    name (no folder separator, no suffix) that is no file or folder in ``folder``: it is a misspelt set name
    more likely than a path (the error then offers the nearest set). Absolute paths stay; ``~`` is the user's
    home folder. A joined path under the working folder is written relative to it (messages stay short).
    """
    def joined(text: str) -> str:
        path = Path(text).expanduser()
        if path.is_absolute():
            return str(path)
        path = folder / path
        if path.is_absolute():
            with contextlib.suppress(ValueError):
                path = path.relative_to(Path.cwd())
        return str(path)

    def is_path(text: str) -> bool:
        path = Path(text)
        return len(path.parts) > 1 or bool(path.suffix) or text.startswith((".", "~")) or (folder / path).exists()

    resolved = copy.deepcopy(user)
    for table, key in STUDY_FILE_PATHS:
        value = resolved.get(table, {}).get(key)
        if isinstance(value, str) and value.strip():
            resolved[table][key] = joined(value)
        elif isinstance(value, dict):  # a file per soil or site class ([hazard] file)
            resolved[table][key] = {name: joined(text) if isinstance(text, str) and text.strip() else text
                                    for name, text in value.items()}
    selection = resolved.get("study", {}).get("record_sets")
    if isinstance(selection, list) and selection:
        names = _catalogue_names()
        resolved["study"]["record_sets"] = [joined(entry) if entry not in names and is_path(entry) else entry
                                            for entry in selection]
    return resolved


def _catalogue_names() -> set[str]:
    """The record-set names and record ids of the catalogue (none when there is no catalogue to read)."""
    from rockfrag.records import catalogue, record_sets

    try:
        return {*record_sets(), *(entry.id for entry in catalogue())}
    except ManifestError:
        return set()


def _period_range(value) -> tuple[float, float] | None:
    """``[intensity] period_range`` (AvgSa periods [s], checked by ``SCHEMA``): (low, high), or None."""
    return None if value is None else (float(value[0]), float(value[1]))


def study_from_dict(data: dict, source="<dict>") -> StudyConfig:
    """Validate a complete study dict (defaults already merged) and build the ``StudyConfig``."""
    validate(data, source)
    data = _blocks_as_selector(data)
    study = data.get("study", {})
    intensity = data.get("intensity", {})
    solver = data.get("solver", {})
    hazard = data.get("hazard", {})
    fragility = data.get("fragility", {})
    uncertainty = data.get("uncertainty", {})
    measure = intensity.get("measure", "pga")
    component = intensity.get("component", "rotd50")
    if component == "rotd50" and not MEASURES[measure].rotatable:
        raise ConfigError("intensity.component", f"\"rotd50\": {measure} has no RotD50 form (it is defined per "
                          "component); use \"single\"", source)

    custom = {name: _soil(name, spec, source) for name, spec in data.get("soils_custom", {}).items()}
    soils = _select("soils", data.get("soils", list(SOILS)), {**SOILS, **custom}, source)
    soils = _site_vs30(soils, hazard.get("vs30", {}), source)
    old = [name for name in data.get("models", []) if name in OLD_BAND_NAMES]
    if old:
        raise ConfigError("models", f"{old[0]!r} was removed: the restitution band gave way to the designed sample; "
                          f"list \"winkler\" with [solver] restitution = {SAMPLE!r} (the recommended model, "
                          f"{RECOMMENDED!r}, and its sample; [uncertainty] sets the ranges)", source)
    models = _select("models", data.get("models", ["housner", "ssi", "winkler"]), {m: m for m in MODELS}, source)
    restitution = solver.get("restitution", "")
    _check_bed_dissipation(data, soils, models, restitution, source)
    if restitution == SAMPLE:
        models = tuple(variant for name in models
                       for variant in (sample_models() if get_model(name).uses_bed else [name]))
    library = {name: _block("blocks_custom", name, spec, source)
               for name, spec in data.get("blocks_custom", {}).items()}
    if "blocks" not in data:
        raise ConfigError("blocks", "no block defined; add [blocks.NAME] tables", source)
    blocks = _select("blocks", data["blocks"], library, source)
    check_study(blocks, soils, data.get("checks", {}).get("plausibility", "error"), source)
    levels, relative_to, level_range = _levels(intensity.get("levels", {"start": 0.05, "stop": 3.0, "count": 40}),
                                               source)
    credible_measure = intensity.get("credible_measure", "pga")
    if credible_measure not in ("pga", measure):
        raise ConfigError("intensity.credible_measure", f"{credible_measure!r}: the cap is stated in the study's "
                          f"measure ({measure!r}) or in PGA (converted over the records)", source)
    _check_damage_states(data, source)
    site = check_site(hazard["site"], "hazard.site", source) if "site" in hazard else None
    sweep = data.get("applicability", {})
    defaults = ApplicabilitySettings()
    config = StudyConfig(
        name=study.get("name", "study"), record_sets=tuple(study.get("record_sets", ["far-field"])),
        processing=study.get("processing", ""), output=Path(study.get("output", "reports")),
        measure=measure, component=component, period=float(intensity.get("period", 1.0)),
        damping=float(intensity.get("damping", 0.05)),
        levels=levels, levels_relative_to=relative_to, level_range=level_range,
        credible_max=float(intensity.get("credible_max", 3.0)), credible_measure=credible_measure,
        credible_reason=intensity.get("credible_reason", ""),
        credible_frequency=float(intensity.get("credible_frequency", 1e-5)),
        beyond_credible=bool(intensity.get("beyond_credible", False)),
        capacity_resolution=float(intensity.get("capacity_resolution", 0.02)),
        period_range=_period_range(intensity.get("period_range")),
        soils=soils, blocks=blocks, models=models,
        switch=solver.get("switch", "consistent"), bed=solver.get("bed", "continuous"),
        restitution=restitution, design=SampleDesign(
            restitution_range=tuple(uncertainty.get("restitution_range", DEFAULT_DESIGN.restitution_range)),
            friction_factor=float(uncertainty.get("friction_factor", DEFAULT_DESIGN.friction_factor)),
            stiffness_factor=float(uncertainty.get("stiffness_factor", DEFAULT_DESIGN.stiffness_factor))),
        model_quality=uncertainty.get("model_quality", "fair"),
        friction=solver.get("friction", "recommended"),
        tail=float(solver.get("tail", 10.0)), overturn_angle=float(solver.get("overturn_angle", math.pi / 2)),
        hazard_file=hazard.get("file", ""), design_life=float(hazard.get("design_life", 50.0)), hazard_site=site,
        reference_vs30=float(hazard.get("reference_vs30", REFERENCE_VS30)),
        vs30_sigma=float(hazard.get("vs30_sigma", VS30_SIGMA)),
        scenario=(float(hazard.get("scenario_magnitude", SCENARIO[0])),
                  float(hazard.get("scenario_distance", SCENARIO[1]))),
        bootstrap=int(fragility.get("bootstrap", 100)), seed=int(fragility.get("seed", 0)),
        confidence=float(fragility.get("confidence", 0.9)),
        record_units=study.get("units", ""), record_dt=study.get("dt"), vertical=bool(study.get("vertical", False)),
        applicability=ApplicabilitySettings(
            g_range=tuple(float(g) for g in sweep.get("g_range", defaults.g_range)),
            n_g=int(sweep.get("n_g", defaults.n_g)),
            levels=tuple(float(v) for v in sweep.get("levels", defaults.levels)),
            block_moduli=tuple(float(v) for v in sweep.get("block_moduli", defaults.block_moduli)),
            tolerance=float(sweep.get("tolerance", defaults.tolerance))),
        source=source, raw=data)
    _check_hazard(config)
    return config


def read_study_file(path) -> dict:
    """A user study file as a dict; unreadable, binary or non-TOML files are one ``ConfigError``."""
    path = Path(path)
    try:
        text = path.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise PipelineError(f"{path}: study file not found") from None
    except IsADirectoryError:
        raise ConfigError("study file", "is a folder; expected a TOML file", str(path)) from None
    except UnicodeDecodeError:
        raise ConfigError("study file", "not a text file (binary content); expected a TOML study file",
                          str(path)) from None
    except OSError as error:
        raise ConfigError("study file", f"cannot read it ({error.strerror})", str(path)) from None
    if "\x00" in text:
        raise ConfigError("study file", "not a text file (binary content); expected a TOML study file", str(path))
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ConfigError("study", f"not valid TOML ({error})", str(path)) from None


def load_study(path: str | Path | None = None, overrides: dict | None = None) -> StudyConfig:
    """Defaults merged with a user study file (and a dict of overrides, e.g. from the CLI).

    The user file is validated on its own first, so errors name its fields as written; the override
    dict is validated the same way (source "command line").

    Parameters
    ----------
    path : str or Path, optional
        A TOML study file with the layout of ``pipeline/defaults.toml`` (SI units unless a key says
        otherwise: levels of PGA and Sa in g). None: the shipped default study. The input files it names
        (``study.record_sets`` folders and files, ``study.processing``, ``hazard.file``) are relative to its
        folder; ``study.output`` is relative to the working folder.
    overrides : dict, optional
        Tables and keys replacing those of the file, in the same layout (``{"study": {"output": ...}}``).

    Returns
    -------
    StudyConfig
        The validated, frozen study.

    Raises
    ------
    PipelineError
        The study file does not exist.
    ConfigError
        The file cannot be read or is not TOML, or a key is unknown, of the wrong type or out of
        range; the message names the file and the field as written.
    """
    default = tomllib.loads(files("rockfrag").joinpath("defaults.toml").read_text())
    default.setdefault("decision", {}).setdefault("max_probability_in_life", dict(DEFAULT_LIMITS))  # the registry's
    source = "pipeline/defaults.toml"
    merged = _blocks_as_selector(default)
    if path is not None:
        user = read_study_file(path)
        source = str(path)
        validate(user, source)
        user = _relative_to_study(user, Path(path).parent)
        merged = _merge(merged, _user_blocks(default, user))
    if overrides:
        validate(overrides, "command line")
        merged = _merge(merged, _user_blocks(default, overrides))
    return study_from_dict(merged, source)


def study_keys(config: StudyConfig | None = None) -> list[tuple[str, str, str, str, str]]:
    """Every study key with its value, the shipped default, what it must be, and the shipped file's note.

    Parameters
    ----------
    config : StudyConfig, optional
        A loaded study: its values fill the value column; default: the shipped default study.

    Returns
    -------
    list of (key, value, default, allowed, note)
        ``key`` dotted as in the study file (``intensity.levels``; ``NAME`` for a table name of your own),
        ``value`` the study's value and ``default`` the shipped default study's (JSON; "" if unset), ``allowed``
        the schema's type, range and unit, ``note`` the comment of that key in ``pipeline/defaults.toml`` (where
        the shipped file states units and choices; a comment continued on the lines below is joined).
    """
    shipped = load_study().raw
    raw = config.raw if config is not None else shipped
    notes = _default_notes()
    return [(key, _value_at(raw, key), _value_at(shipped, key), allowed, notes.get(key, ""))
            for key, allowed in schema_keys(SCHEMA)]


def _value_at(raw: dict, key: str) -> str:
    """The value of a dotted key in a study dict as JSON, or "" if it is not set."""
    value: object = raw
    for part in key.split("."):
        value = value.get(part) if isinstance(value, dict) else None
    return "" if value is None else json.dumps(value, default=str)


def _default_notes() -> dict[str, str]:
    """The end-of-line comments of ``pipeline/defaults.toml`` by dotted key (``# key = ...`` lines included).

    A comment continued on the next lines (indented lines holding only a comment) is joined to it.
    """
    notes, table, last = {}, "", None
    for line in files("rockfrag").joinpath("defaults.toml").read_text().splitlines():
        if last and line[:1].isspace() and line.lstrip().startswith("#"):
            notes[last] = f"{notes[last]} {line.strip().lstrip('#').strip()}".strip()
            continue
        last = None
        text = line.strip().lstrip("# ").strip() if line.lstrip().startswith("# ") else line.strip()
        if text.startswith("[") and text.endswith("]") and "=" not in text:
            table = text.strip("[]").split(".")[0]
            table = f"{table}.NAME" if "." in text else table
            continue
        if "=" in text and "#" in text.split("=", 1)[1]:
            key = text.split("=", 1)[0].strip()
            if key.replace("_", "").isalnum():
                last = f"{table}.{key}" if table else key
                notes[last] = text.split("=", 1)[1].split("#", 1)[1].strip()
    return notes
