"""rockfrag.study - stage 6: every record x intensity level x soil x block x model -> the cube.

Input : a ``StudyConfig`` (rockfrag.config).
Output: ``reports/cube.nc`` (see rockfrag.cube) and the ``xarray.Dataset``.

Levels: absolute (the same intensities for every block) or, with ``[intensity] levels.relative_to =
"uplift"``, multiples of each block's uplift intensity (``level_intensities``); scale factors are then
per (record, level, block).

Work unit: one record and one block at all its scale factors for all the cells (soil, model) it
still needs, run by the compiled batch solver. The same task then refines each cell's overturning
capacity adaptively (rockfrag.ida.capacity_from_stripes, to ``capacity_resolution``) and returns it
as a second checkpoint entry, so capacities come from runs, not from the grid. A cell's result is
checkpointed as one small file named by a hash of everything it depends on (record checksum,
processing recipe, intensity settings, levels, block, soil, model, solver settings, package version),
so an interrupted study resumes where it stopped and a changed input recomputes only the cells it
touches. A tied (no-sliding) housner result does not depend on the soil: it is computed once per block and
shared by every soil on which it does not slide.

Sliding (``[solver] friction``, ``cell_friction``): a housner or winkler cell runs with Coulomb friction at
the base, the soil's (mu_s, mu_k), where the study says it slides; its friction is part of its job and of its
checkpoint key (a tied cell's key is the same as before friction existed). A sliding housner cell is per soil.

Executors (rockfrag.executors): in-process (workers=1), all local cores (default, process pool), or
dask.distributed (``scheduler`` address of a running cluster, or ``dask_workers`` to start a
LocalCluster). Every executor runs the same pure task function, so the cube is identical whatever the
executor.

Reliability: checkpoints verify themselves (rockfrag.checkpoints; a damaged one is quarantined and
recomputed), the output folder is locked for the run (rockfrag.locking), pool workers die with the
study process (parent-death signal), cells of a worker that was killed are retried once in a fresh
pool and then reported (rockfrag.executors), and a record that cannot be processed or scaled is
skipped with its reason. The records are read and processed once per command (``study_records``,
a ``StudyRecords``) and shared with the showcase, efficiency and applicability stages.
"""

from __future__ import annotations

import hashlib
import json
import sys
import time
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from rockfrag import __version__
from rockfrag.blocks import Block
from rockfrag.checkpoints import FOLDER as CHECKPOINT_FOLDER
from rockfrag.checkpoints import CheckpointStore
from rockfrag.cube import COMPARISON_CUBE, build_cube
from rockfrag.damage_states import damage_states_from_config
from rockfrag.errors import PipelineError, RecordError
from rockfrag.executors import check_workers, make_executor, pool_executor, run_tasks
from rockfrag.ida import capacity_from_stripes, uniform_stripe_runs
from rockfrag.locking import output_lock
from rockfrag.measures import MEASURES, pga
from rockfrag.models import DEFAULT_ATOL, DEFAULT_RTOL, calibrated_law, get_model, simulate_batch
from rockfrag.models.base import Outcome
from rockfrag.models.fields import SUMMARY_DTYPE, new_summaries
from rockfrag.models.variants import (
    DEFAULT_DESIGN,
    SampleCalibration,
    calibrate_models,
    member_friction,
    member_stiffness,
    split_variant,
)
from rockfrag.outputs import write_dataset
from rockfrag.processing import ProcessingRecipe, load_recipe, process_records
from rockfrag.records import Record, group_components, load_records, split_vertical
from rockfrag.records.components import horizontal_partners, pair_window
from rockfrag.site_hazard import study_site_hazards
from rockfrag.soils import soil_block_stiffness
from rockfrag.steps import refine_steps


@dataclass(frozen=True)
class Cell:
    """One (block, soil, model) combination for one record.

    soil is None for a tied rigid-base model under ``[solver] friction = "none"`` (one cell for every soil);
    friction is the base's (mu_s, mu_k) [-], or None for a tied base. Cells of one key run once.
    """

    key: str
    block_index: int
    soil_index: int | None
    model: str
    friction: tuple[float, float] | None = None


def cell_friction(block, soil, model: str, mode: str, design=None) -> tuple[float, float] | None:
    """Whether, and with which (mu_s, mu_k) [-], a (block, soil, model) cell slides; None: the base is tied.

    Parameters
    ----------
    block : rockfrag.blocks.Block
        The block (half-width b and half-height h [m]).
    soil : rockfrag.soils.SoilClass or None
        The soil (``friction_static``, ``friction_kinetic``); None: no soil, a tied base.
    model : str
        The model's name; only models that slide (housner, winkler) take friction: ssi is always tied.
    mode : str
        ``[solver] friction``: "recommended" slides every cell of the bed model (the recommended fragility's) and a
        rigid base (a reference) where it matters; "where-it-matters" slides where the soil's mu_s < b/h (below
        it a block at rest slides before it can rock: Shenton 1996), "all" slides every cell of a model that
        slides, "none" none.
    design : rockfrag.models.variants.SampleDesign or None
        The study's sample design: a friction member of the recommended model runs the soil's friction times or
        divided by its factor (``variants.member_friction``). None: the default design.

    Returns
    -------
    (float, float) or None
        The soil's (mu_s, mu_k) (a friction member's own), or None.
    """
    if soil is None or mode == "none" or not get_model(model).slides:
        return None
    if mode == "all" or (mode == "recommended" and get_model(model).uses_bed) \
            or soil.friction_static < block.b / block.h:
        member = split_variant(model)[1]
        return soil.friction if member is None else member_friction(soil.friction, design or DEFAULT_DESIGN, member)
    return None


def model_stiffness(config) -> np.ndarray:
    """The bed stiffness K [N/m] every (soil, block, model) runs: eq. 19, a stiffness member's G scaled."""
    return np.array([[[member_stiffness(soil, block, config.design, split_variant(model)[1] or "centre")
                       for model in config.models] for block in config.blocks] for soil in config.soils])


def record_intensity(acceleration, dt, config, block=None) -> float:
    """The study's intensity measure of a processed record [SI] (for ``block`` if it is per block)."""
    return MEASURES[config.measure](acceleration, dt, block, **config.measure_options)


def record_intensities(records, config, partners=None) -> np.ndarray:
    """The intensity each record is scaled by, for every block, (n_record, n_block) [SI].

    With ``[intensity] component = "rotd50"`` a record that has a partner (``partners``, from
    ``rockfrag.records.components.horizontal_partners``) takes its pair's RotD50 of the measure (Boore 2010),
    computed once over the window the two share, so both components get the same value and the same scale
    factors. Any other record takes its own component's measure (``component_intensities``). One value per
    record, repeated over the blocks, unless the measure is defined per block.
    """
    measure = MEASURES[config.measure]
    values = component_intensities(records, config)
    if config.component != "rotd50" or partners is None:
        return values
    blocks = config.blocks if measure.per_block else [None]
    for r, partner in enumerate(partners):
        if partner is None or partner < r:
            continue
        first, second = records[r], records[partner]
        window = pair_window(first, second)
        values[r] = values[partner] = [measure.rotd(first.acceleration[window[0]], second.acceleration[window[1]],
                                                    first.dt, 50.0, block, **config.measure_options)
                                       for block in blocks]
    return values


def component_intensities(records, config) -> np.ndarray:
    """The study's measure of every record's own component for every block, (n_record, n_block) [SI]."""
    measure = MEASURES[config.measure]
    values = np.empty((len(records), len(config.blocks)))
    for r, record in enumerate(records):
        if measure.per_block:
            values[r] = [record_intensity(record.acceleration, record.dt, config, b) for b in config.blocks]
        else:
            values[r] = record_intensity(record.acceleration, record.dt, config)
    return values


def study_partners(records, config, log) -> list:
    """Each record's partner index for RotD50 scaling (None: scaled by its own component), and one log line.

    ``[intensity] component = "single"``: no partners. Stations whose horizontals cannot be paired are named.
    """
    label = MEASURES[config.measure].short_label(**config.measure_options)
    if config.component != "rotd50":
        log(f"intensity: each component scaled by its own {label} ([intensity] component = \"single\")")
        return [None] * len(records)
    partners, notes = horizontal_partners(records)
    for note in notes:
        log(f"rockfrag: {note}")
    paired = sum(p is not None for p in partners)
    single = [records[i].id for i, p in enumerate(partners) if p is None]
    parts = [f"RotD50 of {label} (Boore 2010) for {paired // 2} pairs of horizontal components ({paired} records, "
             "both components run, one scale factor per pair)"] if paired else []
    if single:
        shown = ", ".join(single[:5]) + (f" and {len(single) - 5} more" if len(single) > 5 else "")
        parts.append(f"{len(single)} without a partner scaled by their own component: {shown}")
    log("intensity: " + "; ".join(parts))
    return partners


def uplift_intensity(config, record_im, record_pga) -> np.ndarray:
    """Each block's uplift intensity in the study's measure, (n_block,) [SI].

    Under each component's own PGA it is exactly g tan(alpha) (Housner's rigid-base threshold; compliant
    bases uplift at about the same PGA); for PGA/(g tan alpha) it is 1. For any other measure, and for
    RotD50 scaling (where a component's PGA is 0.7-1.4 times its pair's RotD50), it is the record median
    of the intensity at which the record's component reaches PGA = g tan(alpha):
    median_r(IM_r / PGA_r) g tan(alpha) (record_im (n_record, n_block), record_pga (n_record,) [SI]); the
    relative levels are then multiples of an approximate uplift intensity.
    """
    uplift_pga = np.array([block.uplift_acceleration() for block in config.blocks])
    return np.median(record_im / np.asarray(record_pga)[:, None], axis=0) * uplift_pga


DEFAULT_CREDIBLE_REASON = (
    "3 g PGA: above the largest horizontal PGA ever recorded anywhere, 2.7 g (K-NET MYG004, N-S component, 2011 "
    "Tohoku earthquake), not a record of this study")
"""Why the shipped cap is 3 g PGA (``[intensity] credible_max``, ``credible_measure = "pga"``)."""


def credible_cap(config, record_im, record_pga, hazard=None) -> tuple[np.ndarray, str]:
    """The credible cap on each block's intensity [SI], (n_block,), and its reason in words.

    ``[intensity] credible_max`` in ``credible_measure``'s display unit: in the study's own measure it is the cap;
    stated in PGA for a study of another measure, its equivalent over the records, the median of IM/PGA times it
    (``uplift_intensity``'s conversion; for PGA/(g tan alpha) exactly 3 g/(g tan alpha) per block). A site hazard
    for the study's measure (``hazard``, rockfrag.hazard) raises it to the intensity exceeded at
    ``credible_frequency`` [1/yr] where that is higher ("unless the site's hazard says otherwise").

    Parameters
    ----------
    config : rockfrag.config.StudyConfig
        The study.
    record_im : numpy.ndarray
        (n_record, n_block) the intensity each record is scaled by [SI].
    record_pga : numpy.ndarray
        (n_record,) each record's own PGA [m/s^2].
    hazard : rockfrag.hazard.HazardCurve or mapping of soil to HazardCurve, optional
        The study's hazard curve, or each soil's site curve (rockfrag.site_hazard.study_site_hazards: the largest
        intensity at the frequency over the soils counts); intensities in the measure's display unit.

    Returns
    -------
    cap : numpy.ndarray
        (n_block,) [SI].
    reason : str
        Why, including the equivalent or the hazard when they set it.
    """
    measure = MEASURES[config.measure]
    stated = MEASURES[config.credible_measure]
    value = config.credible_max * stated.display_factor
    reason = config.credible_reason or (DEFAULT_CREDIBLE_REASON if (config.credible_measure, config.credible_max)
                                        == ("pga", 3.0) else "the study's [intensity] credible_max")
    label = measure.short_label(**config.measure_options)
    if config.credible_measure == config.measure:
        cap = np.full(len(config.blocks), value)
    else:  # stated in PGA: the records' median intensity per unit of their own PGA
        cap = np.median(np.asarray(record_im) / np.asarray(record_pga)[:, None], axis=0) * value
        reason += (f"; in {label}, the records' median of {label}/PGA times {config.credible_max:g} "
                   f"{stated.display_unit}")
    curves = dict(hazard) if isinstance(hazard, Mapping) else {"": hazard} if hazard is not None else {}
    if curves and config.credible_frequency > 0:
        at = {soil: _hazard_intensity_at(curve, config.credible_frequency) * measure.display_factor
              for soil, curve in curves.items()}
        soil = max(at, key=at.get)
        site = at[soil]
        if np.any(site > cap):
            where = f" ({soil})" if soil else ""
            reason = (f"the site hazard's {label}{where} at {config.credible_frequency:g}/yr, "
                      f"{site / measure.display_factor:.3g} {measure.display_unit}, above {reason}")
            cap = np.maximum(cap, site)
    return cap, reason


def _hazard_intensity_at(hazard, frequency) -> float:
    """The intensity [the curve's unit] exceeded at ``frequency`` [1/yr].

    The log-log inverse of the curve, power laws beyond both ends, as rockfrag.answer.intensity_at_frequency reads it.
    """
    x, y = np.log(hazard.intensity), np.log(hazard.annual_frequency)
    target = np.log(frequency)
    if target < y[-1]:
        return float(np.exp(x[-1] + (target - y[-1]) * (x[-1] - x[-2]) / (y[-1] - y[-2])))
    if target > y[0]:
        return float(np.exp(x[0] + (target - y[0]) * (x[1] - x[0]) / (y[1] - y[0])))
    return float(np.exp(np.interp(target, y[::-1], x[::-1])))


def first_motion_ratio(config) -> np.ndarray:
    """Each block's first motion over its uplift intensity, (n_block,) [-]: min(1, mu_s / tan(alpha)).

    A block at rest on a soil whose static friction mu_s is below its b/h = tan(alpha) slides, at a component's
    PGA mu_s g, before it can rock (Shenton 1996). Where the study lets that soil's bed slide, the relative level
    grid starts at its fraction of this lower onset (the lowest mu_s of the study's soils): levels starting at half
    the uplift left the squat skid's site intensities below its lowest level on four soils while it already slid
    there (cold read 7). Relative listed levels stay as listed; "none" friction (every base tied) keeps 1.
    """
    ratios = []
    for block in config.blocks:
        frictions = [soil.friction_static for soil in config.soils
                     if config.friction != "none" and soil.friction_static < block.b / block.h]
        ratios.append(min(frictions, default=block.b / block.h) / (block.b / block.h))
    return np.array(ratios)


def level_intensities(config, record_im, record_pga, cap=None) -> np.ndarray:
    """The physical intensity of every (block, level), (n_block, n_level) [SI].

    With a credible ``cap`` [SI] (n_block,) a ``{ start, stop, count }`` grid whose top lies above it is re-spaced
    per block from its start to the cap, so all ``count`` levels lie in the credible range (``[intensity]
    beyond_credible = true`` keeps the grid as given). Listed levels stay as listed; those above the cap are
    beyond credible (the fits leave them out). A relative grid starts at ``start`` times the block's first motion,
    its uplift or, where it slides first, its sliding onset (``first_motion_ratio``).
    """
    base = uplift_intensity(config, record_im, record_pga) if config.relative_levels \
        else np.ones(len(config.blocks))
    scale = 1.0 if config.relative_levels else MEASURES[config.measure].display_factor
    if cap is None or config.level_range is None or config.beyond_credible:
        return base[:, None] * np.asarray(config.levels_si if not config.relative_levels else config.levels)[None, :]
    start, stop, count, spacing = config.level_range
    first = first_motion_ratio(config) if config.relative_levels else 1.0  # absolute levels are the user's
    low, high = start * scale * base * first, np.minimum(stop * scale * base, cap)
    if np.any(high <= low):
        block = config.blocks[int(np.argmax(high <= low))].name
        raise PipelineError(f"[intensity] levels: block {block}'s lowest level lies at or above the credible cap "
                            f"({config.credible_max:g} {MEASURES[config.credible_measure].display_unit} "
                            f"{config.credible_measure}); lower levels.start or raise intensity.credible_max")
    spaced = np.geomspace if spacing == "log" else np.linspace
    return np.array([spaced(lo, hi, count) for lo, hi in zip(low, high)])


def study_scale_factors(intensity, record_im) -> np.ndarray:
    """Scale factor of every (record, level, block): the level's intensity over the record's."""
    return intensity.T[None, :, :] / record_im[:, None, :]


def refines_capacity(model: str, friction: tuple[float, float] | None = None) -> bool:
    """Whether a cell refines its overturning capacities: not a sample member beside the centre, not a sliding base.

    The refined capacities check the stripe fit of the overturning curve (``capacity_median``). The recommended
    curve is the central member's fit; the other members give only its parameter dispersion (from their stripe
    fits), so their capacity runs would check a curve no output publishes. A block that slides (mu_s < b/h)
    overturns, if at all, only far beyond the credible intensities, and its sliding runs there cost 3-4 times a tied
    run (the squat skid's refining runs were half the default study's time): its stripe fit stands alone. Nor do the
    paper's spring models (``can_pull``): references whose runs after the spring pulls are not physical, so
    a 2% capacity would refine a number nobody should read.
    """
    return split_variant(model)[1] in (None, "centre") and friction is None and not get_model(model).can_pull


def capacity_key(key, resolution, limit=np.inf) -> str:
    """Checkpoint key of a cell's adaptive overturning capacity (``limit``: the scale factor where its hunt stops)."""
    return f"{key}-capacity-{resolution:g}" + (f"-limit-{float(limit):.12g}" if np.isfinite(limit) else "")


def _limit(capacity_limit, record, block) -> float:
    return np.inf if capacity_limit is None else float(capacity_limit[record, block])


def credible_line(config, cap, reason, intensity) -> str:
    """The run's line on the credible cap and the levels below it."""
    measure = MEASURES[config.measure]
    label, unit = measure.short_label(**config.measure_options), measure.display_unit
    caps = ", ".join(dict.fromkeys(f"{c / measure.display_factor:.3g}" for c in cap))
    top = intensity[:, -1] > cap * (1 + 1e-9)
    beyond = f"; levels above it run (beyond credible, not fitted) for {int(top.sum())} blocks" if top.any() else ""
    return f"credible intensities: {label} at most {caps} {unit} ({reason}){beyond}"


class _FreeFlight(Exception):
    """A refining run ended in free flight: whether it would have overturned is unknown."""


def cell_capacity(acceleration, dt, scales, summary, job, options, t_end, resolution, ag_vertical=None,
                  limit=np.inf):
    """[capacity, lower, upper, extra runs] of one cell as scale factors (see capacity_from_stripes).

    Free flight (a pivot model stopped where g + a_v < 0, ``Outcome.FREE_FLIGHT``) says nothing about
    overturning. The stripes from the first free-flight stripe on are left out: a record that overturned
    below it is bracketed as usual, and a refining run that ends in free flight stops the refinement with
    the bracket found so far (``_bracket_so_far``). A record that did not overturn below its first
    free-flight stripe has no capacity (NaN), censored at the highest stripe it survived below it
    (``lower``; NaN if none). Without free flight this is exactly ``capacity_from_stripes``. The hunt stops at the
    scale factor ``limit`` (the credible cap): stripes above it are left out, and a record that survives it is
    censored there (NaN capacity, ``lower`` the limit or the highest stripe below it).
    """
    _, model, block, k, xi, friction = job
    seen = []  # (scale, overturned) of each refining run

    def overturns(scale):
        result = simulate_batch(model, acceleration, dt, [scale], [(block, k, xi)], ag_vertical=ag_vertical,
                                t_end=t_end, **options, friction=friction)
        status = int(result[0, 0]["status"])
        if status == int(Outcome.FREE_FLIGHT):
            raise _FreeFlight
        seen.append((scale, status == int(Outcome.OVERTURNED)))
        return seen[-1][1]

    credible = np.asarray(scales, float) <= limit * (1 + 1e-9)
    status = summary["status"].astype(int)[credible]
    overturned = status == int(Outcome.OVERTURNED)
    scales = np.asarray(scales, float)[credible]
    if not scales.size:
        return np.array([np.nan, np.nan, np.nan, 0.0])
    flights = np.flatnonzero(status == int(Outcome.FREE_FLIGHT))
    if flights.size:
        scales, overturned = scales[:flights[0]], overturned[:flights[0]]
        if not overturned.any():
            return np.array([np.nan, scales[-1] if scales.size else np.nan, np.nan, 0.0])
    try:
        return np.array(capacity_from_stripes(scales, overturned, overturns, tolerance=resolution, limit=limit),
                        dtype=float)
    except _FreeFlight:
        return _bracket_so_far(scales, overturned, seen)


def _bracket_so_far(scales, overturned, seen) -> np.ndarray:
    """[capacity, lower, upper, runs] from the stripes and the refining runs before one ended in free flight.

    upper: the lowest scale seen to overturn (the first overturning stripe or a refining run below it);
    lower: the highest scale seen to survive below it. No overturning seen: NaN capacity, censored at the
    highest survival. runs: the refining runs, the free-flight one included.
    """
    hits = np.flatnonzero(overturned)
    stripes = [(float(scale), False) for scale in scales[:hits[0] if hits.size else scales.size]]
    if hits.size:
        stripes.append((float(scales[hits[0]]), True))
    runs = [*stripes, *seen]
    upper = min((scale for scale, over in runs if over), default=np.nan)
    below = [scale for scale, over in runs if not over and not scale >= upper]
    lower = max(below, default=np.nan)
    capacity = 0.5 * (lower + upper)
    return np.array([capacity, lower, upper, float(len(seen) + 1)])


def _hash(payload) -> str:
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=str).encode()).hexdigest()[:40]


def cells_for_record(record, config, recipe, block_scales=None, vertical=None) -> list[Cell]:
    """The cells of one record with their checkpoint keys.

    ``block_scales`` holds the record's scale factors per block, (n_level, n_block), part of each
    cell's key. ``vertical`` (``vertical_key``; a ``[study] vertical = true`` study only) says whether and
    which vertical component the cells apply; None (horizontal-only studies) leaves the keys as they were.
    """
    common = {"version": __version__, "record": record.metadata.get("sha256", record.id),
              "recipe": recipe.as_dict(), "measure": config.measure, "period": config.period,
              "damping": config.damping, "levels": list(config.levels_si),
              "solver": {**solver_options(config), "tail": config.tail, "rtol": DEFAULT_RTOL, "atol": DEFAULT_ATOL},
              "summary": list(SUMMARY_DTYPE.names)}  # a new summary field is a new cell, not a damaged checkpoint
    if vertical is not None:
        common["vertical"] = vertical
    cells = []
    for block_index, block in enumerate(config.blocks):
        block_spec = {k: v for k, v in asdict(block).items() if k not in ("name", "description")}
        if block_scales is not None:
            block_spec["scales"] = [float(f"{v:.12g}") for v in block_scales[:, block_index]]
        for model in config.models:
            rigid = get_model(model).is_rigid_base
            if rigid and config.friction == "none":
                cells.append(Cell(_hash({**common, "block": block_spec, "model": model}), block_index, None, model))
                continue
            dissipation = restitution_key(config, model)
            for soil_index, soil in enumerate(config.soils):
                friction = cell_friction(block, soil, model, config.friction, config.design)
                # the friction enters the key only where the cell slides: a tied cell keeps its old key, and a
                # tied rigid-base cell the key it shares with every soil
                slip = {} if friction is None else {"friction": list(friction)}
                if rigid and friction is None:
                    key = _hash({**common, "block": block_spec, "model": model})
                elif rigid:
                    key = _hash({**common, "block": block_spec, "model": model, **slip})
                else:
                    soil_spec = {k: v for k, v in asdict(soil).items() if k not in SOIL_KEY_EXCLUDED}
                    key = _hash({**common, "block": block_spec, "soil": soil_spec, "model": model, **dissipation,
                                 **slip})
                cells.append(Cell(key, block_index, soil_index, model, friction))
    return cells


SOIL_KEY_EXCLUDED = ("name", "description", "friction_static", "friction_kinetic", "vs30")
"""Soil fields left out of a cell's checkpoint key: labels, the friction (in the key only where a cell slides), and
the site's Vs30 (it sets the site's hazard, not a run)."""


def friction_grid(config) -> np.ndarray:
    """Every cell's base friction, (2, soil, block, model): mu_s and mu_k [-], NaN where the base is tied.

    Parameters
    ----------
    config : rockfrag.config.StudyConfig
        The study (soils, blocks, models and ``[solver] friction``).

    Returns
    -------
    numpy.ndarray
        ``cell_friction`` of each (soil, block, model).
    """
    grid = np.full((2, len(config.soils), len(config.blocks), len(config.models)), np.nan)
    for s, soil in enumerate(config.soils):
        for b, block in enumerate(config.blocks):
            for m, model in enumerate(config.models):
                friction = cell_friction(block, soil, model, config.friction, config.design)
                if friction is not None:
                    grid[:, s, b, m] = friction
    return grid


def vertical_key(record, vertical, applied) -> dict:
    """The part of a cell's checkpoint key that says whether and which vertical component it applies.

    ``record`` and ``vertical`` are the processed horizontal and vertical components, cut to the window they
    share (``StudyRecords``); that window is part of the key since it changes the processed samples.
    """
    stats = record.trace.stats
    return {"applied": bool(applied),
            "component": vertical.metadata.get("sha256", vertical.id) if applied else None,
            "window": [str(stats.starttime), int(stats.npts), float(stats.delta)]}


def restitution_key(config, model) -> dict:
    """The part of a bed model's checkpoint key that says how its damping is set (empty: the soil's xi)."""
    if not (config.calibrates_bed and get_model(model).uses_bed):
        return {}
    member = split_variant(model)[1]
    design = config.design
    return {"restitution": config.restitution,
            "design": None if member is None else [list(design.restitution_range), design.friction_factor,
                                                   design.stiffness_factor]}


def solver_options(config) -> dict:
    """The study's solver settings as ``simulate_batch`` keywords (rockfrag.models.SolverOptions).

    With a restitution target the bed runs the law its damping was calibrated with
    (``restitution.calibrated_law``: the continuous bed takes Hunt-Crossley damping).
    """
    bed = calibrated_law(config.bed) if config.calibrates_bed else config.bed
    return {"switch": config.switch, "bed": bed, "overturn_angle": config.overturn_angle}


def bed_calibration(config, stiffness) -> SampleCalibration | None:
    """The calibrated damping of every bed model on every (soil, block), or None without a restitution target.

    ``stiffness`` (soil, block, model): ``model_stiffness``. A sample member whose target the bed cannot reach
    runs at the nearest reachable one; the study lists those (``calibration_lines``) and the cube keeps both
    (rockfrag.models.variants).
    """
    indices = [m for m, name in enumerate(config.models) if get_model(name).uses_bed]
    if not (config.calibrates_bed and indices):
        return None
    return calibrate_models(list(config.blocks), [soil.name for soil in config.soils], stiffness[:, :, indices],
                            [config.models[m] for m in indices], config.restitution, config.design, config.bed)


def calibration_lines(config, calibration: SampleCalibration | None) -> list[str]:
    """At most two lines per block: where the bed cannot reach a restitution target, and where rocking dies.

    The first names the soils where the bed at its admissible xi cannot reach a member's target, the second those
    where free rocking dies below what the measure resolves; each names the sample members concerned.

    One line per (block, member) repeated the same sentence for every member (19 lines for the default study);
    the members concerned are named in brackets instead ("every member" where all of them are).
    """
    if calibration is None:
        return []
    names = [_member_name(model) for model in calibration.variants]
    lines = []
    for b, block in enumerate(config.blocks):
        moved, dying, reached, targets, xi = {}, {}, [], [], []
        for s, soil in enumerate(config.soils):
            for v, name in enumerate(names):
                if not calibration.moved[s, b, v]:
                    continue
                if np.isfinite(calibration.target[s, b, v]):
                    moved.setdefault(soil.name, []).append(name)
                    reached.append(calibration.target[s, b, v])
                    targets.append(calibration.requested[0, b, v])
                else:
                    dying.setdefault(soil.name, []).append(name)
                    xi.append(calibration.xi[s, b, v])
        if moved:
            lines.append(f"rockfrag: block {block.name}: at its admissible xi (where free rocking is reproducible) "
                         f"the bed cannot reach the restitution target ({_span(targets)}) on "
                         f"{_soils_by_members(moved, names)}; those runs use the nearest r it reaches "
                         f"({_span(reached)})")
        if dying:
            lines.append(f"rockfrag: block {block.name}: free rocking loses more at every admissible xi than the "
                         f"restitution measure resolves (at least about Housner's r = "
                         f"{block.housner_restitution():.3f}) on {_soils_by_members(dying, names)}; it runs at the "
                         f"smallest admissible xi ({_span(xi, '.3g')})")
    return lines


def _member_name(model: str) -> str:
    """A sample member's name as the lines print it: the central member is the recommended model."""
    member = split_variant(model)[1]
    return "recommended" if member in (None, "centre") else member


def _span(values, spec=".3f") -> str:
    low, high = min(values), max(values)
    return f"{low:{spec}}" if f"{low:{spec}}" == f"{high:{spec}}" else f"{low:{spec}}-{high:{spec}}"


def _soils_by_members(members_of_soil: dict, every: list) -> str:
    """'rock, steel (every member but restitution_low); sand (restitution_high)': soils grouped by members."""
    groups = {}
    for soil, members in members_of_soil.items():
        groups.setdefault(tuple(members), []).append(soil)

    def members_words(members):
        missing = [name for name in every if name not in members]
        if not missing:
            return "every member"
        return f"every member but {', '.join(missing)}" if len(missing) < len(members) else ", ".join(members)

    return "; ".join(f"{', '.join(soils)} ({members_words(members)})" for members, soils in groups.items())


def compute_cells(acceleration, dt, scales, jobs, options, tail, capacity_resolution=0.0, ag_vertical=None,
                  capacity_limit=np.inf):
    """Pure task function (runs in a worker): summaries for each job.

    jobs : list of (key, model, block, k, xi, friction), friction the base's (mu_s, mu_k) or None (tied);
    options : ``solver_options``; ag_vertical : the record's
    vertical component [m/s^2, up positive], sampled as ``acceleration`` and scaled by the same factors, or None.
    Returns {key: summary records (n_scale,)} and, when ``capacity_resolution`` > 0,
    {capacity_key(key, ..., capacity_limit): [capacity, lower, upper, runs]} (scale factors; the hunt stops at
    ``capacity_limit``, the scale factor of the credible cap).
    """
    results = {}
    t_end = (acceleration.size - 1) * dt + tail
    by_model = {}  # friction is a solver option: one batch per (model, friction)
    for key, model, block, k, xi, friction in jobs:
        by_model.setdefault((get_model(model).name, friction), []).append((key, block, k, xi))
    for (model, friction), group in by_model.items():
        # members whose targets the bed reaches at the same xi (moved to one end of its range) run once
        cases = list(dict.fromkeys((b, k, xi) for _, b, k, xi in group))
        summaries = dict(zip(cases, simulate_batch(model, acceleration, dt, scales, cases, ag_vertical=ag_vertical,
                                                   t_end=t_end, **options, friction=friction)))
        for key, b, k, xi in group:
            results[key] = summaries[(b, k, xi)]
    if capacity_resolution > 0:
        refined = {}
        for key, model, block, k, xi, friction in jobs:
            if not refines_capacity(model, friction):
                continue
            case = (get_model(model).name, block, k, xi, friction)
            if case not in refined:
                refined[case] = cell_capacity(acceleration, dt, scales, results[key], (key, *case), options, t_end,
                                              capacity_resolution, ag_vertical, capacity_limit)
            results[capacity_key(key, capacity_resolution, capacity_limit)] = refined[case]
    return results


def _warm_up(models, options):
    """Compile (or load from the on-disk cache) the kernels once before starting workers."""
    block = Block(name="warm-up", R=1.0, alpha=0.2, mass=1.0)
    for model in {get_model(name).name for name in models}:
        simulate_batch(model, np.zeros(3), 0.01, [1.0], [(block, 1e4, 0.05)], **options)


@dataclass(frozen=True)
class StudyRecords:
    """A study's records, read and processed once and handed to every stage that needs them.

    Attributes
    ----------
    records : list of rockfrag.records.Record
        The processed records, in the study's order: acceleration [m/s^2] sampled every ``dt`` [s],
        with the processing provenance in ``trace.stats.processing``.
    failures : list of rockfrag.errors.RecordError
        The records that could not be read or processed, each with its one-line reason.
    recipe : rockfrag.processing.ProcessingRecipe
        The processing recipe applied (part of every cell's checkpoint key and of the outputs' hashes).
    verticals : list of rockfrag.records.Record, or None
        ``[study] vertical = true``: the processed vertical component of each record's station (up
        positive), in the order of ``records``; each record and its vertical are cut to the window they
        share (``ComponentGroup.aligned``) before processing, so they have one start, time step and
        length. None in a horizontal-only study.
    """

    records: list[Record]
    failures: list[RecordError]
    recipe: ProcessingRecipe
    verticals: list[Record] | None = None


def study_records(config, log=print) -> StudyRecords:
    """The study's records, processed with its recipe.

    Every stage that needs the study's records (study, showcase, applicability, efficiency) takes them
    from here, so ``rockfrag fragility`` reads and processes them once. A record that cannot be read or
    processed is skipped and reported (``log``); the others go on. Vertical components are never
    horizontal inputs: a horizontal-only study leaves them out (one line to ``log``); a ``[study] vertical
    = true`` study pairs each horizontal with its station's vertical (``pair_verticals``) and skips, with
    its reason, a horizontal that has none.

    Parameters
    ----------
    config : rockfrag.config.StudyConfig
        The study (record sets, record units and dt, processing recipe, ``vertical``).
    log : callable
        Receives one line per skipped record.

    Returns
    -------
    StudyRecords
        The processed records (and their verticals), the skipped ones with their reasons, and the recipe.

    Raises
    ------
    PipelineError
        When no record could be read and processed.
    """
    recipe = load_recipe(config.processing or None)
    raw_records, failures = load_records(list(config.record_sets), units=config.record_units or None,
                                         dt=config.record_dt)
    if config.vertical:
        pairs, pairing_failures = pair_verticals(raw_records)
        failures = [*failures, *pairing_failures]
        processed, verticals, processing_failures = _process_pairs(pairs, recipe)
    else:
        raw_records, left_out = split_vertical(raw_records)
        if left_out:
            log(f"rockfrag: {len(left_out)} vertical component{'s' if len(left_out) > 1 else ''} left out "
                f"(horizontal inputs only; [study] vertical = true applies them): "
                f"{', '.join(r.id for r in left_out)}")
        processed, processing_failures = process_records(raw_records, recipe)
        verticals = None
    failures = [*failures, *processing_failures]
    for failure in failures:
        log(f"rockfrag: skipped {failure}")
    if not processed:
        raise PipelineError("no record could be read; nothing to run")
    return StudyRecords(processed, failures, recipe, verticals)


def pair_verticals(records) -> tuple[list[tuple[Record, Record]], list[RecordError]]:
    """Each horizontal component with its station's vertical, both cut to the window they share.

    Parameters
    ----------
    records : list of rockfrag.records.Record
        Read (unprocessed) records; components of one station and event are grouped by
        ``group_components``.

    Returns
    -------
    pairs : list of (Record, Record)
        (horizontal, vertical) in the order of the horizontals, each cut by ``ComponentGroup.aligned``
        (same start, time step and length); horizontals of one station share one vertical object.
    failures : list of rockfrag.errors.RecordError
        One per horizontal without a vertical among ``records``, or whose components share no window or
        time step.
    """
    horizontals, _ = split_vertical(records)
    group_of = {}
    for group in group_components(records):
        for label, record in group.components.items():
            group_of[id(record)] = (group, label)
    aligned, pairs, failures = {}, [], []
    for record in horizontals:
        group, label = group_of[id(record)]
        where = record.metadata.get("file") or record.id
        if group.z is None:
            failures.append(RecordError(where, f"record {record.id}: no vertical component of station "
                                               f"{group.station or '?'} ({group.event or 'event unknown'}) "
                                               "among the study's records; [study] vertical = true needs one "
                                               "(add it to record_sets, or set vertical = false)"))
            continue
        try:
            if id(group) not in aligned:
                aligned[id(group)] = group.aligned()
        except RecordError as error:
            failures.append(RecordError(where, f"record {record.id}: {error.reason}"))
            continue
        pairs.append((aligned[id(group)][label], aligned[id(group)]["Z"]))
    return pairs, failures


def _process_pairs(pairs, recipe):
    """Process each (horizontal, vertical) pair with the recipe, each vertical once.

    Returns (horizontals, verticals, failures); a pair whose horizontal or vertical cannot be processed
    is skipped with the reason.
    """
    done = {}
    horizontals, verticals, failures = [], [], []
    for horizontal, vertical in pairs:
        if id(vertical) not in done:
            done[id(vertical)] = process_records([vertical], recipe)
        processed_vertical, vertical_failures = done[id(vertical)]
        processed, own_failures = process_records([horizontal], recipe)
        if own_failures:
            failures += own_failures
        elif vertical_failures:
            failures.append(RecordError(horizontal.metadata.get("file") or horizontal.id,
                                        f"record {horizontal.id}: its vertical {vertical.id} cannot be processed "
                                        f"({vertical_failures[0].reason})"))
        elif processed[0].trace.stats.npts != processed_vertical[0].trace.stats.npts:
            failures.append(RecordError(horizontal.metadata.get("file") or horizontal.id,
                                        f"record {horizontal.id}: processing left it and its vertical {vertical.id} "
                                        "with different lengths"))
        else:
            horizontals.append(processed[0])
            verticals.append(processed_vertical[0])
    return horizontals, verticals, failures


def _scalable(records, record_im, log):
    """Split records into those whose intensity (per block) is positive and finite, and the rest.

    ``record_im`` is (n_record, n_block) [SI]; the rest come back as ``RecordError``.
    """
    keep, failures = [], []
    for index, (record, im) in enumerate(zip(records, np.atleast_2d(record_im.T).T)):
        if np.all(np.isfinite(im)) and np.all(im > 0):
            keep.append(index)
        else:
            failure = RecordError(record.metadata.get("file") or record.id,
                                  f"record {record.id}: intensity measure is {np.min(im):g}; it cannot be scaled")
            log(f"rockfrag: skipped {failure}")
            failures.append(failure)
    return keep, failures


def _to_stderr(message):
    print(message, file=sys.stderr)


def run_study(config, *, output=None, workers=None, scheduler=None, dask_workers=None,
              progress=True, log=print, loaded=None, wait=False, warn=_to_stderr):
    """Run (or resume) a study and write ``cube.nc``; returns (dataset, statistics dict).

    ``loaded`` may pass the study's ``StudyRecords`` (``study_records``) to avoid reading the records again.
    ``log`` receives progress lines, ``warn`` one line per skipped record or damaged checkpoint.
    The output folder is locked for the run (a second run stops, or waits with ``wait=True``).
    """
    check_workers(workers, dask_workers)
    output = Path(output or config.output)
    with output_lock(output, wait=wait):
        return _run_locked(config, output, workers, scheduler, dask_workers, progress, log, warn, loaded)


def _run_locked(config, output, workers, scheduler, dask_workers, progress, log, warn, loaded):
    started = time.perf_counter()
    loaded = loaded or study_records(config, warn)
    records, failures, recipe = loaded.records, list(loaded.failures), loaded.recipe
    verticals = loaded.verticals
    if config.vertical and verticals is None:
        raise PipelineError("[study] vertical = true, but the records were read without their verticals "
                            "(rockfrag.study.study_records of a horizontal-only study)")
    keep, unscalable = _scalable(records, component_intensities(records, config), warn)
    failures += unscalable
    if not keep:
        raise PipelineError(f"no record has a positive intensity measure {config.measure}; nothing to run")
    records = [records[i] for i in keep]
    verticals = [verticals[i] for i in keep] if verticals is not None else None
    partners = study_partners(records, config, log)
    record_im = record_intensities(records, config, partners)
    component_im = component_intensities(records, config)
    partner_ids = [records[p].id if p is not None else "" for p in partners]
    record_pga = np.array([pga(r.acceleration) for r in records])
    cap, cap_reason = credible_cap(config, record_im, record_pga,
                                   study_site_hazards(config) if config.credible_frequency > 0 else None)
    intensity = level_intensities(config, record_im, record_pga, cap)
    uplift = uplift_intensity(config, record_im, record_pga) if config.relative_levels else None
    scale_factors = study_scale_factors(intensity, record_im)
    # the capacity hunt stops at the cap (records that survive it are censored there), unless runs beyond it
    # are asked for
    capacity_limit = np.full(record_im.shape, np.inf) if config.beyond_credible else cap[None, :] / record_im
    log(credible_line(config, cap, cap_reason, intensity))
    resolution = config.capacity_resolution
    stiffness = np.array([[soil_block_stiffness(soil, block) for block in config.blocks] for soil in config.soils])
    stiffness_of_model = model_stiffness(config)
    calibration = bed_calibration(config, stiffness_of_model)
    for line in calibration_lines(config, calibration):
        warn(line)

    n_levels = len(config.levels)
    store = CheckpointStore(output / CHECKPOINT_FOLDER, log=warn)
    variants = (True, False) if config.vertical else (False,)  # with the vertical (cube.nc), then without it
    all_cells = {variant: [cells_for_record(record, config, recipe, scale_factors[index],
                                            vertical_key(record, verticals[index], variant) if config.vertical
                                            else None)
                           for index, record in enumerate(records)] for variant in variants}
    keys = list(dict.fromkeys(c.key for variant in variants for cells in all_cells[variant] for c in cells))
    results = store.load_verified(keys, (n_levels,), SUMMARY_DTYPE)
    if resolution > 0:
        refining = list(dict.fromkeys((c.key, r, c.block_index) for variant in variants
                                      for r, cells in enumerate(all_cells[variant]) for c in cells
                                      if refines_capacity(c.model, c.friction)))
        results.update(store.load_verified([capacity_key(k, resolution, capacity_limit[r, b])
                                            for k, r, b in refining], (4,), np.float64))
    tasks = [(*task, variant) for variant in variants
             for task in block_tasks(all_cells[variant], results, config, stiffness_of_model, resolution, calibration,
                                     capacity_limit)]
    n_cells = len(keys)
    n_missing = sum(len(task[2]) for task in tasks)
    runs_total = n_missing * n_levels
    log(f"study '{config.name}': {len(records)} records x {n_levels} levels x {len(config.soils)} soils x "
        f"{len(config.blocks)} blocks x {len(config.models)} models"
        f"{' x 2 (with and without the vertical component)' if config.vertical else ''}; "
        f"{n_cells - n_missing} of {n_cells} cells from checkpoints, {runs_total} runs to do")

    lost = []
    if tasks:
        _warm_up(config.models, solver_options(config))
        with tqdm(total=runs_total, unit="run", desc="study", disable=not progress, smoothing=0.1) as bar:
            def keep_result(task, computed):
                for key, summary in computed.items():
                    store.save(key, summary)
                    results[key] = summary
                bar.update(len(task[2]) * n_levels)  # capacity runs are not counted ahead

            lost = run_tasks(tasks,
                             lambda task: (records[task[0]].acceleration, records[task[0]].dt,
                                           scale_factors[task[0], :, task[1]], task[2], solver_options(config),
                                           config.tail, resolution,
                                           verticals[task[0]].acceleration if task[3] else None,
                                           capacity_limit[task[0], task[1]]),
                             lambda: make_executor(compute_cells, workers, scheduler, dask_workers), keep_result,
                             describe=lambda task: f"record {records[task[0]].id}, block {config.blocks[task[1]].name}"
                                                   f"{', with its vertical' if task[3] else ''}",
                             isolate=None if scheduler or dask_workers else lambda: pool_executor(compute_cells, 1))
    if lost:
        lost_indices = {task[0] for task in lost}
        for index in sorted(lost_indices):
            record = records[index]
            failure = RecordError(record.metadata.get("file") or record.id,
                                  f"record {record.id}: a worker process died twice while computing its cells "
                                  "(out of memory?); finished cells are kept, rerun to retry")
            warn(f"rockfrag: skipped {failure}")
            failures.append(failure)
        kept = [i for i in range(len(records)) if i not in lost_indices]
        if not kept:
            raise PipelineError("every record's computation was lost (worker processes killed); "
                                "finished cells are kept, rerun to continue")
        # the levels stay those of the whole record set (relative levels use its median)
        records, record_im, scale_factors = [records[i] for i in kept], record_im[kept], scale_factors[kept]
        component_im, partner_ids = component_im[kept], [partner_ids[i] for i in kept]
        capacity_limit = capacity_limit[kept]
        verticals = [verticals[i] for i in kept] if verticals is not None else None
        all_cells = {variant: [cells[i] for i in kept] for variant, cells in all_cells.items()}

    provenance = {"processing": recipe.as_dict(),
                  "processing_steps": {r.id: list(r.trace.stats.get("processing", [])) for r in records}}
    cubes = {}
    for variant in variants:
        summaries = _gather_summaries(all_cells[variant], results, config, len(records), n_levels)
        capacities, stats = gather_capacities(all_cells[variant], results, config, intensity, resolution,
                                              capacity_limit)
        if stats and stats['capacity_runs']:  # no refining run: nothing worth a line
            log(f"overturning intensities refined to {resolution:.0%}"
                f"{' without the vertical' if config.vertical and not variant else ''}: "
                f"{stats['capacity_runs']} extra runs beside the {stats['grid_runs']} runs at the levels (levels as "
                f"fine would need {stats['uniform_runs']} runs: the refinement saves "
                f"{stats['runs_saved_fraction']:.0%} of them)")
        cubes[variant] = (build_cube(config, records, record_im, scale_factors, summaries, stiffness, provenance,
                                     intensity=intensity, capacities=capacities, capacity_stats=stats,
                                     calibration=calibration, friction=friction_grid(config),
                                     model_stiffness=stiffness_of_model,
                                     verticals=verticals, vertical_applied=variant, partners=partner_ids,
                                     component_im=component_im, uplift=uplift, credible=(cap, cap_reason,
                                                                                         config.beyond_credible)),
                        stats)
    dataset, capacity_stats = cubes[variants[0]]
    if resolution > 0:  # the separated rows' steps, bisected by runs between the levels (rockfrag.steps)
        dataset = refine_steps(dataset, damage_states_from_config(config.raw), config.blocks, resolution,
                               lambda requests: step_runs(requests, records, all_cells[variants[0]], record_im,
                                                          config, store, stiffness_of_model, calibration,
                                                          verticals if variants[0] else None,
                                                          lambda: make_executor(compute_cells, workers, scheduler,
                                                                                dask_workers)), log)
    if config.vertical:  # the comparison first: a cube.nc on disk always has its comparison beside it
        comparison = cubes[False][0]
        comparison.attrs["title"] += " without the vertical components (compare with cube.nc)"
        write_dataset(comparison, output / COMPARISON_CUBE)
        dataset.attrs["vertical_comparison"] = COMPARISON_CUBE
    write_dataset(dataset, output / "cube.nc")
    elapsed = time.perf_counter() - started
    capacity_stats["step_runs"] = int(dataset.attrs.get("step_runs", 0))
    statistics = {"runs_computed": runs_total, "cells_reused": n_cells - n_missing, "cells": n_cells,
                  "seconds": elapsed, "failures": [str(f) for f in failures],
                  "checkpoints_quarantined": [str(p) for p in store.quarantined], **capacity_stats}
    if config.vertical:
        statistics["comparison"] = output / COMPARISON_CUBE
    return dataset, statistics


def step_runs(requests, records, all_cells, record_im, config, store, stiffness, calibration, verticals,
              executor) -> np.ndarray:
    """Summaries (n_record, n_request) of every record at each ``rockfrag.steps`` request ((soil, block, model), SI).

    Each run is a checkpoint of its own (the cell's key, "-step-" and the scale factor), so a resumed study redoes
    none; the missing ones run as the study's tasks do (``compute_cells`` on ``executor()``). A run lost with its
    worker reads as failed (unknown). ``verticals``: each record's vertical component, or None (not applied).
    """
    cube_models = [str(m) for m in config.models if split_variant(str(m))[1] in (None, "centre")]
    runs, pending = {}, {}
    for j, ((soil, block, model), intensity) in enumerate(requests):
        name = cube_models[model]
        for r, cells in enumerate(all_cells):
            cell = next(c for c in cells if c.block_index == block and c.model == name
                        and c.soil_index in (None, soil))
            scale = float(intensity / record_im[r, block])
            step = Cell(f"{cell.key}-step-{scale:.12g}", block, cell.soil_index, name, cell.friction)
            runs[(r, j)] = step.key
            pending.setdefault((r, block, scale), {})[step.key] = step
    results = store.load_verified(list(dict.fromkeys(runs.values())), (1,), SUMMARY_DTYPE)
    tasks = []
    for (r, block, scale), cells in pending.items():
        listing = [[] for _ in records]
        listing[r] = list(cells.values())
        tasks += [(*task, scale) for task in block_tasks(listing, results, config, stiffness, 0.0, calibration)]

    def keep(task, computed):
        for key, summary in computed.items():
            store.save(key, summary)
            results[key] = summary

    if tasks:
        run_tasks(tasks, lambda task: (records[task[0]].acceleration, records[task[0]].dt, [task[3]], task[2],
                                       solver_options(config), config.tail, 0.0,
                                       verticals[task[0]].acceleration if verticals is not None else None),
                  executor, keep, describe=lambda task: f"record {records[task[0]].id}, a step run")
    out = new_summaries((len(records), len(requests)))
    out["status"] = int(Outcome.FAILED)
    for (r, j), key in runs.items():
        if key in results:
            out[r, j] = results[key][0]
    return out


def _gather_summaries(all_cells, results, config, n_records, n_levels) -> np.ndarray:
    """The summary records of every cell, (record, level, soil, block, model); a cell without soil on every soil."""
    summaries = new_summaries((n_records, n_levels, len(config.soils), len(config.blocks), len(config.models)))
    for r, cells in enumerate(all_cells):
        for cell in cells:
            model_index = config.models.index(cell.model)
            result = results[cell.key]
            if cell.soil_index is None:
                summaries[r, :, :, cell.block_index, model_index] = result[:, None]
            else:
                summaries[r, :, cell.soil_index, cell.block_index, model_index] = result
    return summaries


def block_tasks(all_cells, available, config, stiffness, resolution, calibration=None, capacity_limit=None) -> list:
    """(record index, block index, jobs) for every record and block with cells still to run.

    Cells still to run are those not in ``available``, the verified checkpoints; a job is
    (key, model, block, k, xi, friction), xi the soil's damping ratio or, for a bed model with a restitution
    target, its calibrated one (``calibration``, a ``SampleCalibration``), k from ``stiffness`` (soil, block,
    model; ``model_stiffness``), friction the cell's (mu_s, mu_k) or None
    (``cell_friction``). Grouped by block because scale factors are per block; cells of one key (a tied housner
    cell on several soils) are one job. A rigid-base model's k and xi are None. ``capacity_limit`` (n_record,
    n_block): the scale factor at the credible cap, where the capacity hunt stops (None: no limit).
    """
    def damping(cell):
        if calibration is not None and cell.model in calibration.variants:
            return float(calibration.xi[cell.soil_index, cell.block_index, calibration.variants.index(cell.model)])
        return config.soils[cell.soil_index].damping_ratio

    def rigid(cell):
        return cell.soil_index is None or get_model(cell.model).is_rigid_base

    tasks = []
    for index, cells in enumerate(all_cells):
        by_block = {}
        for cell in {c.key: c for c in cells}.values():
            limit = np.inf if capacity_limit is None else capacity_limit[index, cell.block_index]
            done = cell.key in available and (resolution <= 0 or not refines_capacity(cell.model, cell.friction)
                                              or capacity_key(cell.key, resolution, limit) in available)
            if not done:
                by_block.setdefault(cell.block_index, []).append(cell)
        for block_index, missing in by_block.items():
            jobs = [(c.key, c.model, config.blocks[c.block_index],
                     None if rigid(c) else stiffness[c.soil_index, c.block_index, config.models.index(c.model)],
                     None if rigid(c) else damping(c), c.friction)
                    for c in missing]
            tasks.append((index, block_index, jobs))
    return tasks


def gather_capacities(all_cells, available, config, intensity, resolution, capacity_limit=None):
    """Adaptive capacities as scale factors, and the run accounting.

    The capacities are (4, record, soil, block, model): capacity, lower, upper, extra runs. The
    accounting compares with uniform stripes of the same resolution (a dict, empty when capacities
    are off).
    """
    shape = (4, len(all_cells), len(config.soils), len(config.blocks), len(config.models))
    capacities = np.full(shape, np.nan)
    if resolution <= 0:
        return None, {}
    for r, cells in enumerate(all_cells):
        for cell in cells:
            if not refines_capacity(cell.model, cell.friction):
                continue
            result = available[capacity_key(cell.key, resolution, _limit(capacity_limit, r, cell.block_index))]
            soils = slice(None) if cell.soil_index is None else cell.soil_index
            capacities[:, r, soils, cell.block_index, config.models.index(cell.model)] = result[:, None] \
                if cell.soil_index is None else result
    # the run accounting counts each computed cell once (a tied housner cell shared by soils is one)
    unique = [(r, c) for r, cells in enumerate(all_cells) for c in {c.key: c for c in cells}.values()
              if refines_capacity(c.model, c.friction)]
    extra = sum(int(available[capacity_key(c.key, resolution, _limit(capacity_limit, r, c.block_index))][3])
                for r, c in unique)
    unique = [c for _, c in unique]
    n_cells = len(unique)
    n_levels = intensity.shape[1]
    uniform = sum(uniform_stripe_runs(intensity[c.block_index, 0], intensity[c.block_index, -1], resolution)
                  for c in unique)
    grid = n_cells * n_levels
    return capacities, {"capacity_runs": extra, "grid_runs": grid, "uniform_runs": uniform,
                        "capacity_resolution": resolution,
                        "runs_saved_fraction": 1.0 - (grid + extra) / uniform if uniform else 0.0}
