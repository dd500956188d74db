"""rockfrag.report.adapters - what the report asks of the result files, whatever their layout.

Input : the study's datasets (cube, ida, fragility + risk) and the model registry.
Output: small answers the pages draw: model labels and roles (rigid base or on a foundation), the
        intensity levels of a block (per-block ``intensity`` coordinate when present, else ``im_level``),
        the axis label of the intensity measure, human labels of the damage states, whether a fitted
        median is extrapolated, and run fractions of the limitation checks.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from rockfrag.answer import level_at_or_below
from rockfrag.damage_states import DAMAGE_STATES
from rockfrag.errors import SolverError
from rockfrag.measures import MEASURES, convert_units, file_units, parse_units, unit_label
from rockfrag.measures import short_label as measure_short_label
from rockfrag.models import get_model, model_label
from rockfrag.models.base import Outcome
from rockfrag.models.variants import RECOMMENDED
from rockfrag.report.layout import MODEL_STYLES, RECOMMENDED_STYLE, RIGID_STYLE, pretty
from rockfrag.report.words import formulas
from rockfrag.soils import DEFAULT_FRICTION

OUTCOME_ROCKING, OUTCOME_FAILED, OUTCOME_FREE_FLIGHT = int(Outcome.ROCKING), int(Outcome.FAILED), \
    int(Outcome.FREE_FLIGHT)


@dataclass(frozen=True)
class ModelInfo:
    """What the report shows of a model: its registry name, label and role.

    Attributes
    ----------
    name : str
        The registry name (``housner``, ``ssi``, ...).
    label : str
        The registry label, or "name: description" when the model has none.
    rigid_base : bool
        The result does not depend on the soil (computed once per block).
    description : str
        The registry description ("" for a model no longer registered).
    can_pull : bool
        The foundation can pull on the block (tension).
    uses_bed : bool
        The model rests on a bed of springs (``solver.bed``), not on the pivot-switch rule.
    """

    name: str
    label: str
    rigid_base: bool
    description: str
    can_pull: bool = False
    uses_bed: bool = False  # a bed of springs (solver.bed), not the pivot-switch rule



STIFF_BASE = 1e10
"""Shear modulus [Pa] above which a "soil" of the study is a structural base (steel), not a soil."""


def is_soil(cube, soil) -> bool:
    """True for a soil, False for a structural base such as steel (shear modulus above ``STIFF_BASE``)."""
    if "soil_shear_modulus" not in cube.variables:
        return True
    return float(cube.soil_shear_modulus.sel(soil=soil)) < STIFF_BASE

def model_info(name: str) -> ModelInfo:
    """Label and role of a model from the registry (a model no longer registered keeps its name).

    ``recommended`` (the central member of the recommended model's designed sample, whose beta carries the model
    dispersion) is labelled in words; a sample member (``recommended-<member>``) is the bed model, labelled with
    what it changes (``rockfrag.models.model_label``).
    """
    if name == RECOMMENDED:
        return ModelInfo(name, "Recommended (tensionless bed with friction, best estimate)", False,
                         "the tensionless Winkler bed with friction at the base, at the middle of the experimental "
                         "range of impact restitution and the soil's stated friction and stiffness; its model "
                         "dispersion (the sensitivity runs' spread or FEMA P695's rating) added to beta", False,
                         True)
    try:
        model = get_model(name)
    except SolverError:  # a model no longer registered
        return ModelInfo(name, name, False, "")
    label = model_label(name) if model.label else f"{name}: {model.description.split(';')[0]}"
    return ModelInfo(name, label, model.is_rigid_base, model.description, model.can_pull, model.uses_bed)


def models_of(dataset) -> list[ModelInfo]:
    """Models of a dataset: rigid-base models first (the reference), then the others in study order."""
    infos = [model_info(str(m)) for m in dataset.model.values]
    return [m for m in infos if m.rigid_base] + [m for m in infos if not m.rigid_base]


def model_styles(models) -> dict:
    """Line style per model: rigid base black dashed, the recommended curve thick solid red.

    The others get distinct colours and dash patterns, none solid.
    """
    styles, index = {}, 0
    for model in models:
        if model.rigid_base:
            styles[model.name] = dict(RIGID_STYLE)
        elif model.name == RECOMMENDED:
            styles[model.name] = dict(RECOMMENDED_STYLE)
        else:
            styles[model.name] = dict(MODEL_STYLES[index % len(MODEL_STYLES)])
            index += 1
    return styles


def short_label(model: ModelInfo) -> str:
    """A label short enough for a legend: the registry label, or the name for long descriptions."""
    return model.label if len(model.label) <= 50 else model.name


def panel_label(model: ModelInfo) -> str:
    """The registry label without its parenthesis, for panel titles: "SSI, paper's model", "Housner"."""
    return model.label.split(" (")[0]


def cell(dataset, model: ModelInfo, block, soil=None):
    """The results of one model and block on ``soil``; without a soil, on the first.

    A rigid base's soils are equal unless base friction lets it slide on some: then the caller names the soil
    (``soils_of`` says which soils a model's results need).
    """
    if "soil" in dataset.dims and soil is None:
        soil = dataset.soil.values[0]
    selection = {"model": model.name, "block": block}
    if "soil" in dataset.dims:
        selection["soil"] = soil
    return dataset.sel(selection)


def differs_by_soil(values) -> bool:
    """True when a DataArray with a ``soil`` dimension differs between its soils (NaNs equal)."""
    if "soil" not in values.dims:
        return False
    rows = np.asarray(values.transpose("soil", ...).values)
    return any(not np.array_equal(rows[0], other, equal_nan=True) for other in rows[1:])


def soils_of(dataset, model: ModelInfo, block, variable: str) -> list:
    """The soils whose results of ``model`` a page shows: every soil, or [None] (once) for a rigid base.

    A rigid base's results are the same on every soil unless base friction lets the block slide on some (the
    friction differs by soil): then each soil has its own results, and each is shown (``variable`` says which
    results are compared).
    """
    soils = list(map(str, dataset.soil.values)) if "soil" in dataset.dims else [None]
    if not model.rigid_base:
        return soils
    picked = dataset[variable].sel(model=model.name, block=block)
    return soils if differs_by_soil(picked) else [None]


def block_levels(dataset, block) -> np.ndarray:
    """Intensity levels of a block: the per-block ``intensity`` coordinate, or the shared ``im_level``."""
    if "intensity" in dataset.variables and "block" in dataset["intensity"].dims:
        return np.asarray(dataset["intensity"].sel(block=block).values, dtype=float)
    return np.asarray(dataset.im_level.values, dtype=float)


def measure_label(dataset) -> str:
    """Axis label of the intensity measure with units, e.g. 'PGA [g]' (the file's "9.80665 m s-2" shown as g)."""
    source = dataset["intensity"] if "intensity" in dataset.variables else dataset.im_level
    unit = unit_label(source.attrs.get("units", dataset.im_level.attrs.get("units", "")))
    measure = str(dataset.attrs.get("intensity_measure", "")).lower()
    long_name = str(dataset.im_level.attrs.get("long_name", ""))
    return f"{measure_short_label(measure, long_name)} [{unit}]"  # the registry's label (rockfrag.measures)


def intensity_name(dataset) -> str:
    """What the study's intensities are, in a few words: "the pair's RotD50 PGA" or "the component's PGA".

    The methods define it in full (``rockfrag.report.sections.intensity_definition``); pages that print an
    intensity beside a component's peak name it with these words.
    """
    measure = measure_label(dataset).split(" [")[0]
    if str(dataset.attrs.get("intensity_component", "")).upper() == "ROTD50":
        return f"the pair's RotD50 {measure}"
    return f"the component's {measure}"


def state_title(label: str) -> str:
    """A damage state's label shortened for a panel title: up to its first colon or parenthesis."""
    return re.split(r":| \(", label, maxsplit=1)[0].strip()


def state_labels(fragility) -> dict:
    """Human label of each damage state: the registry's description with its symbols."""
    labels = {}
    descriptions = (fragility["damage_state_description"].values if "damage_state_description" in fragility.coords
                    else [""] * fragility.sizes["damage_state"])
    for name, description in zip(fragility.damage_state.values, descriptions):
        description = str(description) or getattr(DAMAGE_STATES.get(str(name)), "description", "") or str(name)
        text = pretty(description)
        labels[str(name)] = text[0].upper() + text[1:] if text[:1].isascii() else text
    return labels


def extrapolation(fragility, output=None) -> pd.DataFrame:
    """One row per fitted median: soil, block, model, damage_state, median, status.

    The status is ``within``, ``above-range``, ``below-range``, ``extrapolated`` or ``no fit``.
    ``fragility.csv``'s ``status`` or ``extrapolated`` column is used when present; otherwise the median
    is compared with the block's studied levels.
    """
    table = fragility["median"].to_dataframe().reset_index()[["soil", "block", "model", "damage_state", "median"]]
    csv = Path(output) / "fragility.csv" if output is not None else None
    if csv is not None and csv.is_file():
        written = pd.read_csv(csv)
        keys = ["soil", "block", "model", "damage_state"]
        if "status" in written.columns:
            merged = table.merge(written[keys + ["status"]], on=keys, how="left")
            merged["status"] = merged["status"].fillna("").astype(str)
            merged["status"] = [_status_word(s, m) for s, m in zip(merged["status"], merged["median"])]
            return merged
        if "extrapolated" in written.columns:
            merged = table.merge(written[keys + ["extrapolated"]], on=keys, how="left")
            merged["status"] = np.where(merged["extrapolated"].astype(str).str.lower().isin(["true", "1", "yes"]),
                                        "extrapolated", "within")
            return merged.drop(columns="extrapolated")
    status = []
    for row in table.itertuples():
        levels = block_levels(fragility, row.block)
        if not np.isfinite(row.median):
            status.append("no fit")
        elif row.median > levels.max():
            status.append("above-range")
        elif row.median < levels.min():
            status.append("below-range")
        else:
            status.append("within")
    table["status"] = status
    return table


def _status_word(status: str, median: float) -> str:
    text = status.lower()
    if not np.isfinite(median):
        return "no fit"
    if "extrapol" in text or "above" in text or "below" in text:
        return "below-range" if "below" in text else ("above-range" if "above" in text else "extrapolated")
    return "within"


def run_fraction(cube, flag, model: ModelInfo):
    """Fraction of a model's valid runs where ``flag`` (a boolean DataArray over the cube) holds.

    Per soil and block (soil collapsed for rigid-base models); None when the flag is all NaN.
    """
    valid = cube.outcome.sel(model=model.name) != OUTCOME_FAILED
    values = flag.sel(model=model.name)
    known = values.notnull() & valid
    if int(known.sum()) == 0:
        return None
    hits = (values.fillna(0).astype(bool) & known).sum(("record", "im_level"))
    total = known.sum(("record", "im_level"))
    return (hits / total.where(total > 0)).transpose("soil", "block")


def tension_flag(cube):
    """1 where the foundation pulled on the block, 0 where not, NaN where not computed."""
    if "support_tension" in cube:  # flags -1 not applicable, 0 no tension, 1 tension (or NaN)
        flag = cube.support_tension
        return flag.where(flag >= 0)
    if "min_support_force" in cube:
        force = cube.min_support_force
        return (force < 0).where(force.notnull())
    return None


def soil_friction(cube):
    """Each soil's static friction coefficient mu_s [-] (the cube's ``soil_friction_static``; an older cube: 0.5)."""
    if "soil_friction_static" in cube.variables:
        return cube.soil_friction_static
    return DEFAULT_FRICTION[0]


def tied(cube):
    """True in the (soil, block, model) cells whose base is tied (no friction), False where the runs slide."""
    if "friction_static" not in cube:
        return True
    return ~np.isfinite(cube.friction_static)


def friction_flag(cube, coefficient=None):
    """1 where holding a tied base needed more than ``coefficient`` (default: each soil's mu_s), NaN where unknown.

    Runs with friction at the base (they slide where they need more) are NaN: their slip is in the cube.
    """
    if "peak_friction_demand" not in cube:
        return None
    demand = cube.peak_friction_demand.where(tied(cube))
    limit = soil_friction(cube) if coefficient is None else coefficient
    return (demand > limit).where(demand.notnull())


def uplift_intensity(cube, block) -> float:
    """Intensity at which the block starts to rock, in the unit of its levels (g tan(alpha) for PGA)."""
    if "block_uplift_intensity" in cube.variables:
        return float(cube.block_uplift_intensity.sel(block=block))
    uplift = cube.block_uplift_acceleration
    levels = cube["intensity"] if "intensity" in cube.variables else cube.im_level
    target = levels.attrs.get("units", "")
    if parse_units(target) is None or parse_units(target)[1] != parse_units(file_units("m/s^2"))[1]:
        target = file_units("m/s^2")  # levels of another quantity: the threshold in g
    return float(convert_units(float(uplift.sel(block=block)), uplift.attrs.get("units", "m s-2"), target))


def record_pga_g(cube) -> np.ndarray:
    """PGA of each processed record of the cube [g], whatever unit the file states (an older cube: m/s^2)."""
    pga = cube.record_pga
    return np.asarray(convert_units(pga.values, pga.attrs.get("units", "m s-2"), MEASURES["pga"].cf_units()), float)


def vertical_applied(cube) -> bool:
    """True when the cube's runs applied the records' vertical components (``[study] vertical = true``)."""
    return "vertical_applied" in cube and bool(int(cube.vertical_applied.sum()))


def largest_recorded(cube, block) -> float:
    """The largest intensity of the unscaled records for a block [the unit of its levels].

    Below it the levels are intensities the records themselves reached; above it every run is a
    record scaled up beyond anything it recorded (extrapolation by scaling). ``record_im`` when the cube
    has it, else each level's intensity over its scale factor.
    """
    if "record_im" in cube.variables:
        values = cube.record_im.sel(block=block) if "block" in cube.record_im.dims else cube.record_im
        target = (cube["intensity"] if "intensity" in cube.variables else cube.im_level).attrs.get("units", "")
        source = values.attrs.get("units", target)
        if source and target and source != target and parse_units(source) and parse_units(target):
            return float(np.nanmax(convert_units(np.asarray(values.values, float), source, target)))
        return float(np.nanmax(values.values))
    levels = block_levels(cube, block)
    scale = cube.scale_factor.sel(block=block).transpose("record", "im_level").values
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(np.nanmax(np.nanmedian(levels[None, :] / scale, axis=1)))


def scale_factor_summary(cube) -> tuple[float, float]:
    """(median, maximum) of the factors applied to the processed records over every block and level."""
    values = np.asarray(cube.scale_factor.values, float)
    return float(np.nanmedian(values)), float(np.nanmax(values))


def sliding_candidates(cube, model: str) -> list[str]:
    """The models whose runs tell whether a tied base slides, first preferred: the answer's, then the bed's."""
    return [model, RECOMMENDED, "winkler", *[str(m) for m in cube.model.values if str(m).startswith("winkler")]]


def sliding_at(cube, models, block, soil, intensity: float, coefficient: float | None = None) -> tuple:
    """(share, level, computed): the records whose tied base needs more friction than ``coefficient`` at a level.

    The level is the one run nearest at or below ``intensity`` (unit of the levels), as the answer page's
    probability table reads its records; ``share`` is the fraction of that level's valid records whose peak friction
    demand exceeds ``coefficient`` (None: the soil's mu_s). From the first of ``models`` that the cube holds.
    ``computed`` is True where that model's cell runs with friction (it slides where it must, and its slip damage
    states answer: share NaN). Share and level are NaN where no level lies at or below ``intensity`` or the cube
    has no friction demand.
    """
    names = [m for m in models if m in set(map(str, cube.model.values))]
    if not names:
        return float("nan"), float("nan"), False
    name = names[0]
    ties = tied(cube)
    if ties is not True and not bool(ties.sel(model=name, block=block, soil=soil)):
        return float("nan"), float("nan"), True
    levels = block_levels(cube, block)
    level = level_at_or_below(levels, intensity)
    if "peak_friction_demand" not in cube or level is None:
        return float("nan"), float("nan"), False
    if coefficient is None:
        friction = soil_friction(cube)
        coefficient = float(friction.sel(soil=soil)) if hasattr(friction, "sel") else float(friction)
    demand = cube.peak_friction_demand.sel(model=name, block=block, soil=soil).isel(im_level=level)
    valid = demand.notnull() & (cube.outcome.sel(model=name, block=block, soil=soil).isel(im_level=level)
                                != OUTCOME_FAILED)
    if int(valid.sum()) == 0:
        return float("nan"), float(levels[level]), False
    return float(((demand > coefficient) & valid).sum() / valid.sum()), float(levels[level]), False


def sliding_share(cube, models, block, soil, coefficient: float | None, up_to: float) -> float:
    """Share of the records at the level at or below ``up_to`` that need more friction than ``coefficient``.

    ``sliding_at``'s share: the decision's return-period intensity ``up_to`` (unit of the levels) read at one
    level, as the probability table reads it, not an average over the levels below it (which depended on the grid's
    spacing). NaN where the cell runs with friction (its slip damage states answer) or no level lies that low.
    """
    return sliding_at(cube, models, block, soil, up_to, coefficient)[0]


def block_name(config, block) -> str:
    """The block as a client knows it: its ``[report] block_names`` entry, else its name."""
    names = ((config.raw.get("report") or {}).get("block_names") or {}) if config is not None else {}
    return str(names.get(str(block)) or block)


def short_block_name(config, block) -> str:
    """The block's name in running text: ``block_name`` without a closing parenthesis of sizes.

    "enclosure E-1 (a solid block 1.2 m × 3.0 m, 4.5 t)" reads "enclosure E-1" inside a sentence; titles, tables
    and the summary keep the whole name, which says what is modelled (cold read 8, user C1: the whole name stood
    about 30 times, inside sentences too). A name that is only a parenthesis stays whole.
    """
    name = block_name(config, block)
    return re.sub(r"\s*\([^()]*\)$", "", name) or name


def block_description(config, block) -> str:
    """The study's description of the block (its ``why``), or ""."""
    for item in getattr(config, "blocks", ()) or ():
        if item.name == str(block):
            return pretty(formulas(item.description))
    return ""


def planar_words(cube, block) -> str:
    """The planar model's limitation for one block in one sentence, naming the direction its b is taken in.

    The answer pages and the limitations page state it (one place).
    """
    b, h = float(cube.block_b.sel(block=block)), float(cube.block_h.sel(block=block))
    return (f"Planar model: the block rocks about one bottom edge, in the vertical plane across that edge, in which "
            f"b = {b:.3g} m is its half-width (h = {h:.3g} m its half-height); rocking in the other direction, "
            "twisting (wobbling) and three-dimensional rocking on a corner are not modelled: check the other "
            "direction as a block of its own b.")


@dataclass(frozen=True)
class CredibleMarks:
    """What a figure marks on a block's intensity axis (in the unit of the result files' levels).

    Attributes
    ----------
    return_periods : tuple of float
        Return periods [years] of the site hazard (empty: no hazard curve).
    intensities : tuple of float
        The site's intensity at each return period.
    largest : float or None
        The largest intensity the unscaled records reached; beyond it, extrapolation by scaling.
    by_soil : tuple of (str, tuple of float)
        Each soil's own site intensity at each return period (its site hazard), where the soils differ; empty
        when one hazard serves every soil (then ``intensities`` are every soil's).
    tag : str
        Beside the return periods where the hazard is not a site's ("(example hazard)"; ``summary.hazard_tag``).
    """

    return_periods: tuple = ()
    intensities: tuple = ()
    largest: float | None = None
    by_soil: tuple = ()
    tag: str = ""

    def for_soil(self, soil) -> CredibleMarks:
        """The marks of a panel of one soil: that soil's own site intensities (unchanged for an unknown soil)."""
        own = dict(self.by_soil).get(None if soil is None else str(soil))
        return self if own is None else CredibleMarks(self.return_periods, tuple(own), self.largest, tag=self.tag)


GOF_LEVEL = 0.05
"""Below this goodness-of-fit p-value (fragility.nc ``gof_p_value``) a fitted curve is marked ‡: in the tables, on
the answer pages and on its fragility pages."""
