"""rockfrag.fragility - stage 8: the cube -> lognormal fragility functions per soil and damage state.

Input : the study cube (outcome, peak_angle_ratio over record x im_level x soil x block x model; the
        intensity of each level per block, see ``intensity_levels``), the damage states
        (``rockfrag.damage_states``: the registry plus ``[damage_states.NAME]`` tables of the study file).
Output: ``reports/fragility.nc`` (median, beta, bootstrap bounds, fit method, ``status``, the
        ``extrapolated`` flag, goodness of fit, the non-crossing rule's deviance cost and the studied
        range per soil x block x model x damage state; empirical fractions per level; the three-outcome
        probabilities), ``fragility.csv``, and through ``rockfrag.exchange`` the files for pelicun and OpenQuake.

Fits (Baker 2015, Earthquake Spectra 31(1); the numerics on arrays are in ``rockfrag.lognormal_fit``):
binomial maximum likelihood on the counts per level, a probit regression solved by vectorised Fisher
scoring. Overturning follows the IDA capacity convention of Vamvatsikos & Cornell (2002): a record
counts as overturned at every level from its first overturning level on (``OVERTURNING_CONVENTION``);
a record that survives a higher level (resurrection) is counted per cell (``n_resurrected``) and
named in a warning, not fitted. These stripe fits (``median``, ``beta``) are the answer: the CSV, the
pelicun file, the risk and the report carry them. For overturning the refined capacities of
``ida.nc`` (the first overturning transition bisected to ``capacity_resolution``) are also fitted, a
censored lognormal MLE (``capacity_median``, ``capacity_beta``; ``CAPACITY_FIT``) that checks the
stripe fit. Every row says what it is (``STATUS``):
- uplift of a model whose uplift is the rigid-body threshold (a tied base, PGA, no vertical) is known per record:
  a component lifts when its own scaled PGA exceeds g tan(alpha) (``exact_uplift_thresholds``). Under each
  component's own PGA that is the exact step g tan(alpha) (``deterministic-threshold``, beta = 0), not a fit;
  under RotD50 pair scaling (the cube's ``intensity_component``) each record lifts at g tan(alpha) times its
  pair's RotD50 over its own PGA (0.7-1.4 g tan(alpha)), and the row is the lognormal fit of those exact
  thresholds (``exact-thresholds``), of which the stripes are a coarse sample (checked level by level);
- perfectly separated counts have no lognormal MLE: a step between the two bracketing levels,
  beta = 0, status ``separated`` and a warning (never a silent small beta);
- a median outside the studied range is flagged ``extrapolated``; a state no record reached is
  ``not-reached`` (median NaN).
Credible intensities: the fits use only the levels at or below the cube's credible cap
(``credible_intensity_max``, rockfrag.study.credible_cap); a row whose fitted median lies above the cap is
``censored-at-cap``: no median (NaN), and ``probability_at_cap`` with its bounds (the records that reached the
state at the highest level at or below the cap) says what the records did. The risk stops at the cap and adds
the hazard's exceedance of the cap as a stated upper bound (``capped_risk``).
Ordered states must not cross where the data can tell (from the lowest level at which the more severe
state has exceedances up to the highest level); states that do are refitted with a shared beta and
the deviance this costs is reported. Bootstrap bounds resample records and refit each row with the
same estimator as its point estimate (the shared fit for shared-beta rows). Fewer than
``SMALL_SAMPLE`` records give a warning on every row.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr
from scipy.stats import beta as beta_distribution
from tqdm.auto import tqdm

from rockfrag.config import StudyConfig
from rockfrag.cube import (
    COMPONENT_DEFINITIONS,
    COMPONENT_SINGLE,
    OUTCOME_FAILED,
    OUTCOME_FREE_FLIGHT,
    OUTCOME_NO_UPLIFT,
    OUTCOME_OVERTURNED,
    OUTCOME_ROCKING,
    STEP_LEVEL,
    member_cube,
)
from rockfrag.damage_states import (
    DAMAGE_STATES,
    NOT_APPLICABLE,
    DamageState,
    damage_states_from_config,
    is_slip_state,
    nesting_chains,
    uplift_lift,
)
from rockfrag.exchange import (  # noqa: F401 (pelicun_id, pelicun_table: re-exported)
    OPENQUAKE_FILE,
    pelicun_id,
    pelicun_table,
    write_csv,
    write_exchange_files,
)
from rockfrag.exchange import intensity_unit_label as _unit_label
from rockfrag.hazard import hazard_frequency
from rockfrag.ida import resurrected
from rockfrag.lognormal_fit import (  # noqa: F401
    CROSSING_TOLERANCE,
    curves_cross,
    deviance,
    fit_binomial,
    fit_censored_capacities,
    fit_independent,
    fit_shared_beta,
    goodness_of_fit,
    lognormal_cdf,
    separation,
)
from rockfrag.measures import MEASURES, convert_units, parse_units, udunits, unit_label
from rockfrag.models import MODELS
from rockfrag.models.variants import PARAMETERS, RECOMMENDED, split_variant
from rockfrag.outputs import write_dataset
from rockfrag.risk import annual_frequency, probability_in_life, risk_dataset
from rockfrag.site_hazard import site_hazard_dataset, study_site_hazards
from rockfrag.units import STANDARD_GRAVITY

STATUS = {
    "fitted": "lognormal fitted by maximum likelihood; median inside the studied range",
    "extrapolated": "lognormal fitted, but the median lies outside the studied range",
    "not-reached": "no record reached the state at any level; no curve",
    "below-range": "most records reached the state already at the lowest level: the median is below the range",
    "above-range": "a few records reached the state, only at the highest level: the median is above the range",
    "deterministic-threshold": "an exact step at g tan(alpha) (uplift under each component's own PGA), beta = 0",
    "separated": "perfectly separated counts: a step between two levels, beta = 0 (not identifiable)",
    "censored-at-cap": "the fitted median lies above the credible cap on the intensity: no median is given; the row "
                       "gives the probability at the cap (probability_at_cap, with its bounds)",
    NOT_APPLICABLE: "a slip state of a cell whose base is tied (no friction, no sliding: [solver] friction); "
                      "no curve",
}
"""The ``status`` of a fragility row and what it means (the report prints these)."""

SMALL_SAMPLE = 10
"""Fewer records than this give a warning on every fitted row."""

RIGID_UPLIFT_MODELS = ("housner", "ssi", "ssi-paper")
"""Fallback when a model object does not say ``uplift_is_rigid_threshold``."""

OVERTURNING_CONVENTION = (
    "first-overturn convention (Vamvatsikos & Cornell 2002): a record counts as overturned, and as beyond "
    "every damage state, at every level from its first overturning level on; records that survive a higher "
    "level (resurrection) are counted in n_resurrected, not fitted")
"""How the fits count overturning (a global attribute of fragility.nc; the report quotes it)."""

CAPACITY_FIT = (
    "capacity_median/capacity_beta: lognormal MLE of the refined overturning capacities of ida.nc (the first "
    "overturning transition bisected to capacity_resolution), right-censored at the highest intensity a "
    "record was seen to survive where it never overturned; a check of the stripe fit. median/beta, the "
    "answer carried by fragility.csv, the pelicun file, the risk and the report: binomial MLE on the stripes")
"""Which fit is which (a global attribute of fragility.nc)."""


def first_overturn_outcomes(cube: xr.Dataset) -> xr.DataArray:
    """The cube's ``outcome`` with every level from a record's first overturning level on set to overturned.

    This is ``OVERTURNING_CONVENTION``; levels increase along ``im_level``.
    """
    since = (cube.outcome == OUTCOME_OVERTURNED).cumsum("im_level") > 0
    return cube.outcome.where(~since, OUTCOME_OVERTURNED)


def tilts(cube: xr.Dataset, outcome: xr.DataArray) -> xr.DataArray | bool:
    """True for the runs that only tilt on a compliant bed: a corner lifted less than the uplift size, no more.

    The size is the damage-state registry's (``rockfrag.damage_states.uplift_lift``). A pivot model (Housner, the
    paper's model: ``uplift_is_rigid_threshold``) lifts a corner only by pivoting about the other one, at
    g tan(alpha): it has no tilt, and any lift is rocking. False where the cube has no corner lift.
    """
    if "peak_uplift" not in cube or "block_b" not in cube or "model" not in cube.coords:
        return False
    models = cube.model
    bed = xr.DataArray(np.array([not uplift_is_rigid_threshold(str(m)) for m in np.atleast_1d(models.values)]
                                ).reshape(models.shape), dims=models.dims, coords=models.coords)
    return (outcome == OUTCOME_ROCKING) & bed & (cube.peak_uplift < uplift_lift(cube.block_b))


def exceedance(cube: xr.Dataset, state: DamageState, outcome: xr.DataArray | None = None) -> xr.DataArray:
    """1.0 where a run reached the damage state, 0.0 where not, NaN where unknown.

    A record is beyond every state from its first overturning level on (``first_overturn_outcomes``).
    Unknown: the solver failed, or the run stopped in free flight (``free_flight``: g + a_v < 0 under a
    pivot model, which has no flight phase) before it could tell. Such a run did leave the ground, so it
    counts as uplifted; it reached a rocking state when its response before the stop already did (peak
    values only grow), else it is unknown; whether it would have overturned is unknown. The fits count
    the known runs only (censored), level by level.

    Slip states (``edp = "peak_slip"``): reached where the peak slip is at least the threshold [m] or the block
    overturned; known only in the cells that run with friction (the cube's ``friction_static`` finite): a
    tied cell's runs are all unknown, and its row is ``not-applicable``. ``outcome``: the cube's
    ``first_overturn_outcomes`` when the caller has them already.
    """
    outcome = first_overturn_outcomes(cube) if outcome is None else outcome
    if is_slip_state(state):
        if state.edp not in cube or "friction_static" not in cube:  # a cube from before sliding: every base tied
            return xr.full_like(outcome, np.nan, dtype=float)
        reached = (cube[state.edp] >= state.threshold) | (outcome == OUTCOME_OVERTURNED)
        known = (outcome != OUTCOME_FAILED) & (~(outcome == OUTCOME_FREE_FLIGHT) | reached) \
            & np.isfinite(cube.friction_static)
        return reached.astype(float).where(known)
    flight = outcome == OUTCOME_FREE_FLIGHT
    if state.edp == "uplifted":
        reached = outcome >= OUTCOME_ROCKING  # rocking, overturned or free flight (failed: masked below)
        reached = reached & ~tilts(cube, outcome)
        known = outcome != OUTCOME_FAILED
    elif state.edp == "overturned":
        reached = outcome == OUTCOME_OVERTURNED
        known = (outcome != OUTCOME_FAILED) & ~flight
    else:
        reached = (cube[state.edp] >= state.threshold) | (outcome == OUTCOME_OVERTURNED)
        known = (outcome != OUTCOME_FAILED) & (~flight | reached)
    return reached.astype(float).where(known)


# ---------------------------------------------------------------- intensity levels of a cube

def intensity_levels(cube: xr.Dataset) -> tuple[np.ndarray, str]:
    """The physical intensity of every (block, im_level) in the study's display unit, and its ``units``.

    The ``units`` are as UDUNITS parses them ("9.80665 m s-2" for g; ``rockfrag.measures.Measure.cf_units``).
    Works for both cube layouts: one physical ``im_level`` coordinate shared by all blocks, or a
    dimensionless ``im_level`` with the physical intensity as a (block, im_level) coordinate (``intensity``,
    or any other found by its dims and units, in any unit ``rockfrag.measures.parse_units`` reads: g
    multiples, SI, or an older file's "g"). Returns (n_block, n_level).
    """
    n_block, n_level = cube.sizes["block"], cube.sizes["im_level"]
    measure = MEASURES.get(cube.attrs.get("intensity_measure", "pga"))
    target = measure.cf_units() if measure is not None else ""

    def in_display(values, units):
        parsed, wanted = parse_units(units), parse_units(target)
        if parsed is not None and wanted is not None and parsed[1] == wanted[1]:
            return np.asarray(convert_units(values, units, target), float), target
        return values, units if parsed is None else udunits(parsed[1], parsed[0])

    per_block = [name for name, coord in cube.coords.items() if set(coord.dims) == {"block", "im_level"}]
    for name in sorted(per_block, key=lambda n: n not in ("intensity", "im_intensity")):
        units = cube[name].attrs.get("units", "")
        if parse_units(units) is not None:
            return in_display(cube[name].transpose("block", "im_level").values.astype(float), units)
    levels = cube.im_level.values.astype(float)
    values, units = in_display(levels, cube.im_level.attrs.get("units", ""))
    return np.broadcast_to(values, (n_block, n_level)).copy(), units


def merged_runs(cube: xr.Dataset, intensity: np.ndarray, unit: str, names=None) -> tuple[xr.Dataset, np.ndarray]:
    """The cube's runs with each cell's step runs (``rockfrag.steps``) merged in between its levels, and its levels.

    Parameters
    ----------
    cube : xarray.Dataset
        The study cube; its step runs, if any, are ``step_X`` over (record, step_level, soil, block, model) at
        ``step_intensity`` (``rockfrag.cube.STEP_LEVEL``).
    intensity : numpy.ndarray
        (n_block, n_level) the levels [``unit``] (``intensity_levels``).
    unit : str
        The levels' unit.
    names : collection of str, optional
        The per-run variables to merge (default: all; the others are left out of ``runs``).

    Returns
    -------
    runs : xarray.Dataset
        The per-run variables over (record, im_level, soil, block, model), each cell's runs in increasing
        intensity (so the first-overturn convention reads them in order), with the cube's other variables; a
        cube without step runs is returned as it is.
    levels : numpy.ndarray
        (soil, block, model, n_level + n_step) each cell's intensities [``unit``], increasing; inf where the cell
        has no run (its outcome there is failed: unknown, left out of every count).
    """
    shape = (cube.sizes["soil"], cube.sizes["block"], cube.sizes["model"])
    grid = np.broadcast_to(intensity[None, :, None, :], (*shape, intensity.shape[1])).copy()
    if STEP_LEVEL not in cube.dims or "step_intensity" not in cube:
        return cube, grid
    step = cube["step_intensity"]
    step = np.asarray(convert_units(step.transpose("soil", "block", "model", STEP_LEVEL).values,
                                    step.attrs.get("units", unit), unit), float)
    levels = np.concatenate([grid, np.where(np.isfinite(step), step, np.inf)], axis=-1)
    order = np.argsort(levels, axis=-1, kind="stable")
    dims = ("record", "soil", "block", "model")
    runs = cube.drop_dims(["im_level", STEP_LEVEL])
    for name, variable in cube.data_vars.items():
        if set(variable.dims) != {"record", "im_level", *dims[1:]} or (names is not None and name not in names):
            continue
        values = variable.transpose(*dims, "im_level").values
        stepped = f"step_{name}"
        if stepped in cube:
            extra = cube[stepped].transpose(*dims, STEP_LEVEL).values.astype(values.dtype)
        else:
            extra = np.full((*values.shape[:-1], step.shape[-1]), OUTCOME_FAILED if name == "outcome" else np.nan,
                            dtype=values.dtype if name == "outcome" else float)
        merged = np.take_along_axis(np.concatenate([values, extra], axis=-1), order[None], axis=-1)
        runs[name] = (("record", "im_level", *dims[1:]), np.moveaxis(merged, -1, 1), variable.attrs)
    return runs, np.take_along_axis(levels, order, axis=-1)


def scaled_by_own_component(cube: xr.Dataset) -> bool:
    """Whether every record of the cube is scaled by its own component (a cube from before pairs: yes)."""
    return cube.attrs.get("intensity_component", COMPONENT_SINGLE) == COMPONENT_SINGLE


def component_attributes(cube: xr.Dataset) -> dict:
    """The cube's statement of the intensity's component definition, for fragility.nc (an older cube: single)."""
    kind = cube.attrs.get("intensity_component", COMPONENT_SINGLE)
    return {"intensity_component": kind,
            "intensity_component_definition": cube.attrs.get("intensity_component_definition",
                                                             COMPONENT_DEFINITIONS.get(kind, ""))}


def credible_caps(cube: xr.Dataset, unit: str) -> np.ndarray:
    """The credible cap of each block in ``unit``, (n_block,); inf for a cube without one (every level fitted)."""
    if "credible_intensity_max" not in cube:
        return np.full(cube.sizes["block"], np.inf)
    values = cube["credible_intensity_max"]
    return np.asarray(convert_units(values.values, values.attrs.get("units", unit), unit), float)


def clopper_pearson(reached, total, confidence):
    """Two-sided ``confidence`` bounds of a binomial fraction (Clopper & Pearson 1934); NaN where total is 0."""
    reached, total = np.asarray(reached, float), np.asarray(total, float)
    tail = (1 - confidence) / 2
    with np.errstate(invalid="ignore", divide="ignore"):
        low = np.where(reached > 0, beta_distribution.ppf(tail, reached, total - reached + 1), 0.0)
        high = np.where(reached < total, beta_distribution.ppf(1 - tail, reached + 1, total - reached), 1.0)
    return np.where(total > 0, low, np.nan), np.where(total > 0, high, np.nan)


def uplift_is_rigid_threshold(model_name: str) -> bool:
    """Does the model's uplift happen exactly at g tan(alpha) under PGA scaling? Asks the model."""
    model = MODELS.get(model_name)
    if model is None:  # a cube of a model this installation does not know: fall back on its name
        return model_name in RIGID_UPLIFT_MODELS
    return model.uplift_is_rigid_threshold


def exact_uplift_thresholds(cube: xr.Dataset, unit: str) -> np.ndarray | None:
    """Each record's exact uplift intensity for every block, (n_record, n_block) [``unit``], or None.

    A pivot model at rest (Housner, the paper's ``ssi`` on a tied base) starts to rock the first time a sample of
    the scaled ground acceleration exceeds g tan(alpha) (the kernel's rest phase, ``rest_until_uplift``): a record
    scaled by s lifts exactly when s PGA_r > g tan(alpha), i.e. at the intensity g tan(alpha) IM_r / PGA_r, IM_r
    the record's intensity as the study scales it (``record_im``) and PGA_r its own component's (``record_pga``).
    Scaled by its own PGA that is g tan(alpha) for every record; by its pair's RotD50 PGA, 0.7-1.4 times it, one
    threshold per record (checked against runs in tests/test_steps.py). None when the measure is not PGA, when a
    record ran with its vertical component (it lifts at (g + a_v) tan(alpha)), or when the cube cannot tell.
    """
    if cube.attrs.get("intensity_measure", "pga") != "pga":
        return None
    if "vertical_applied" in cube and np.any(cube["vertical_applied"].values):
        return None
    threshold = uplift_threshold(cube, unit)
    if threshold is None:
        return None
    n_record = cube.sizes["record"]
    if "record_im" not in cube.variables or "record_pga" not in cube.variables:
        # a cube from before pairs: every record scaled by its own component, or nothing is known
        return np.broadcast_to(threshold, (n_record, threshold.size)).copy() if scaled_by_own_component(cube) \
            else None
    record_im, pga = cube["record_im"], cube["record_pga"]
    if "block" not in record_im.dims:
        record_im = record_im.expand_dims(block=cube.block.values)
    im = np.asarray(convert_units(record_im.transpose("record", "block").values, record_im.attrs.get("units", unit),
                                  "m s-2"), float)
    own = np.asarray(convert_units(pga.values, pga.attrs.get("units", unit), "m s-2"), float)
    return threshold[None, :] * im / own[:, None]


def fit_exact_thresholds(thresholds, cap=np.inf, weights=None):
    """Lognormal (median, beta) of exact per-record thresholds [their unit], right-censored at the credible ``cap``.

    The closed-form MLE (median exp(mean ln t), beta the standard deviation of ln t with divisor n) or, with
    thresholds above the cap, the censored MLE (``fit_censored_capacities``). ``weights`` (n_sample, n_record):
    record multiplicities of bootstrap samples; returns arrays (n_sample,) then, else floats.
    """
    thresholds = np.asarray(thresholds, float)
    above = thresholds > cap * (1 + 1e-9)
    if weights is None:
        if above.any():
            return fit_censored_capacities(np.where(above, np.nan, thresholds), cap)
        logs = np.log(thresholds)
        return float(np.exp(logs.mean())), float(logs.std())
    weights = np.asarray(weights, float)
    if above.any():
        fits = [fit_censored_capacities(np.repeat(np.where(above, np.nan, thresholds), w.astype(int)), cap)
                for w in weights]
        return np.array([f[0] for f in fits]), np.array([f[1] for f in fits])
    logs = np.log(thresholds)
    mean = weights @ logs / weights.sum(1)
    spread = np.sqrt(np.maximum(weights @ logs**2 / weights.sum(1) - mean**2, 0.0))
    return np.exp(mean), spread


def uplift_threshold(cube: xr.Dataset, unit: str) -> np.ndarray | None:
    """G tan(alpha) per block in the study's intensity ``unit``, or None when the cube cannot tell.

    ``unit`` is an acceleration unit ``parse_units`` reads; None too when it is no acceleration.
    """
    parsed = parse_units(unit)
    if parsed is None or parsed[1] != udunits("m/s^2"):
        return None
    if "block_uplift_acceleration" in cube.coords:
        values = cube.block_uplift_acceleration
        return np.asarray(convert_units(values.values, values.attrs.get("units", "m s-2"), unit), float)
    if "block_alpha" in cube.coords:
        return np.asarray(convert_units(STANDARD_GRAVITY * np.tan(cube.block_alpha.values), "m s-2", unit), float)
    return None


# ---------------------------------------------------------------- one soil x block x model cell

@dataclass
class RowFit:
    """The fit of one damage state in one cell, and what it is."""

    median: float = np.nan
    beta: float = np.nan
    method: str = "none"
    status: str = "not-reached"
    warnings: tuple = ()
    deviance_cost: float = 0.0
    step_method: str = ""  # how a step (beta = 0) was placed; "" for a curve

    def warn(self, message: str) -> None:
        """Append ``message`` to the row's warnings."""
        self.warnings = (*self.warnings, message)


def _crosses_where_data_tell(levels, exceed_severe, lower_fit, upper_fit):
    """Whether two fitted curves cross where the data can tell.

    That is between the lowest level at which the more severe state has exceedances and the highest
    level (below it both are zero by the data; tails there are arithmetic).
    """
    reached = np.flatnonzero(exceed_severe > 0)
    if reached.size == 0:
        return False
    grid = np.geomspace(levels[reached[0]], levels[-1], 200) if levels[-1] > levels[reached[0]] else levels[-1:]
    return curves_cross(grid, [lower_fit, upper_fit])


def _shared_fit(levels, exceed, total, group):
    medians, beta = fit_shared_beta(levels, exceed[group], total[group])
    return [(float(m), float(beta)) for m in medians]


def noncrossing_groups(levels, exceed, total, fits, usable, chains=None):
    """Merge fitted states into shared-beta groups until no two neighbours of a chain cross where the data can tell.

    ``chains``: lists of state indices in order of severity whose states nest (``damage_states.nesting_chains``:
    the rocking states; the slip states followed by overturning); default one chain of ``usable``. Overturning ends
    both chains, so a slip state that crosses it joins its group, and a group can hold states of both families.
    Returns (groups, fits): the groups (lists of state indices in increasing order) and the refitted (median,
    beta) of grouped states.
    """
    usable = list(usable)
    chains = [usable] if chains is None else [[s for s in chain if s in usable] for chain in chains]
    group_of = {s: frozenset([s]) for s in usable}
    fits = dict(fits)
    changed = True
    while changed:
        changed = False
        for chain in chains:
            for milder, severe in zip(chain, chain[1:]):
                if group_of[milder] is group_of[severe] or \
                        not _crosses_where_data_tell(levels, exceed[severe], fits[milder], fits[severe]):
                    continue
                merged = group_of[milder] | group_of[severe]
                members = sorted(merged)
                for s, fit in zip(members, _shared_fit(levels, exceed, total, members)):
                    fits[s] = fit
                for s in members:
                    group_of[s] = merged
                changed = True
                break
            if changed:
                break
    groups = sorted({group_of[s] for s in usable}, key=min)
    return [sorted(group) for group in groups], fits


@dataclass(frozen=True)
class StepContext:
    """What a cell's step rows need to say how they were placed (``step_refinement``).

    grid : the cell's credible levels [the fit's unit] (the other intensities it ran are step runs);
    refined : whether the study bisected the cell's separated rows (``rockfrag.steps``); resolution : the relative
    width it bisects to; reason : why a cell's rows were not refined ("" when they were); n_records : records per run.
    """

    grid: np.ndarray
    refined: bool = False
    resolution: float = 0.0
    reason: str = ""
    n_records: int = 0


NOT_REFINED = {
    "off": "the study ran no runs between the levels (capacity_resolution = 0, or a cube from before them)",
    "member": "the study refines the published rows only (housner, ssi, the recommended central member), not a "
              "sample member beside the centre",
}
"""Why a cell's steps were not refined by runs between the levels (besides a cube's own ``step_not_refined``)."""


def step_refinement(cube: xr.Dataset) -> Callable[[tuple, np.ndarray], StepContext]:
    """``context(index, grid)``: the ``StepContext`` of the cell ``index`` = (soil, block, model) of ``cube``.

    The study says which cells it refined (``step_refined``, with ``step_resolution`` and ``step_not_refined``
    among the cube's attributes, rockfrag.steps).
    """
    resolution = float(cube.attrs.get("step_resolution", 0.0) or 0.0)
    flags = cube["step_refined"].transpose("soil", "block", "model").values if "step_refined" in cube else None
    n_records = cube.sizes["record"]

    def context(index, grid):
        if resolution <= 0:
            return StepContext(grid, reason=NOT_REFINED["off"], n_records=n_records)
        if flags is None:
            return StepContext(grid, reason=NOT_REFINED["member"], n_records=n_records)
        refined = bool(flags[index])
        return StepContext(grid, refined, resolution, "" if refined else cube.attrs.get("step_not_refined", ""),
                           n_records)
    return context


def step_bracket(levels, exceed, total) -> tuple[float, float, float]:
    """(lower, upper, mixed) of a separated row's step.

    lower: the highest intensity with no record in the state, upper: the lowest with every record, mixed: the one
    intensity between them where some were (NaN: none, or the bracket is open there).
    """
    known = total > 0
    levels, exceed, total = levels[known], exceed[known], total[known]
    some, not_all = np.flatnonzero(exceed > 0), np.flatnonzero(exceed < total)
    if not some.size or not not_all.size:
        return np.nan, np.nan, np.nan
    first, last = some[0], not_all[-1]
    if last < first:
        return float(levels[last]), float(levels[first]), np.nan
    lower = float(levels[first - 1]) if first > 0 else np.nan
    upper = float(levels[first + 1]) if first + 1 < levels.size else np.nan
    return lower, upper, float(levels[first])


def _step_method(levels, exceed, total, unit, context: StepContext | None = None) -> str:
    """How a separated row's step was placed: bisected between the levels by runs, or from the levels alone.

    The step is the geometric middle of the bracket between the highest intensity with no record in the state and
    the lowest with every record, or the one intensity where some records were; ``context`` says which intensities
    are the levels and which are step runs, and why a row was not refined.
    """
    context = context or StepContext(levels, reason=NOT_REFINED["off"])
    lower, upper, mixed = step_bracket(levels, exceed, total)
    on_grid = np.isclose(levels[:, None], np.asarray(context.grid)[None, :], rtol=1e-12, atol=0).any(1)
    grid_lower, grid_upper, grid_mixed = step_bracket(levels[on_grid], exceed[on_grid], total[on_grid])
    low_end = grid_lower if np.isfinite(grid_lower) else -np.inf
    high_end = grid_upper if np.isfinite(grid_upper) else np.inf
    between = ~on_grid & (total > 0) & (levels > low_end) & (levels < high_end)
    count = int(between.sum())
    if count:  # runs between the levels placed it
        runs = f"{count * context.n_records} runs at {count} intensities"
        short = "" if upper - lower <= context.resolution * upper * (1 + 1e-9) else \
            " (stopped before the resolution: the study's round limit)"
        if np.isfinite(mixed):
            return (f"bisected: the one intensity where some records were in the state ({mixed:.4g} {unit}; none at "
                    f"{lower:.4g}, all at {upper:.4g} {unit}), found by {runs} between the levels {grid_lower:.3g}-"
                    f"{grid_upper:.3g} {unit}{short}")
        return (f"bisected to {context.resolution:.0%}: geometric middle of the bracket {lower:.4g}-{upper:.4g} "
                f"{unit} (no record in the state at the lower intensity, every record at the upper), narrowed from "
                f"the levels {grid_lower:.3g}-{grid_upper:.3g} {unit} by {runs}{short}")
    if context.refined:
        reason = "the bracket is open at the edge of the levels" if not (np.isfinite(lower) and np.isfinite(upper)) \
            else f"the levels bracket it to the {context.resolution:.0%} resolution already" \
            if upper - lower <= context.resolution * upper * (1 + 1e-9) else "no run between the levels"
    else:
        reason = context.reason or "no run between the levels"
    if np.isfinite(mixed):
        return f"the one level where some records were in the state ({mixed:.3g} {unit}); not refined: {reason}"
    return (f"geometric middle of the bracket {lower:.3g}-{upper:.3g} {unit} (no record in the state at the lower "
            f"level, every record at the upper); not refined by runs between them: {reason}")


def exact_uplift_row(levels, exceed, total, thresholds, unit="", cap=np.inf) -> RowFit:
    """The uplift row of a cell whose records lift at known intensities (``exact_uplift_thresholds``).

    One threshold for every record (each scaled by its own PGA): the exact step g tan(alpha), beta = 0. Thresholds
    that differ (RotD50 pair scaling): the lognormal fit of the exact thresholds (``fit_exact_thresholds``), which
    the stripes only sample: their counts at every level are the records whose threshold lies below it. Either way
    the runs are checked against the thresholds, level by level (a warning where they disagree).
    exceed, total : (n_level,) the stripes' counts; thresholds : float or (n_record,) [the levels' unit].
    """
    thresholds = np.atleast_1d(np.asarray(thresholds, float))
    row = RowFit()
    if np.ptp(thresholds) <= 1e-9 * thresholds.max():
        row.median, row.beta, row.method, row.status = float(thresholds[0]), 0.0, "exact-g-tan-alpha", \
            "deterministic-threshold"
        row.step_method = "exact: g tan(alpha), a rigid base's uplift under each component's own PGA"
    else:
        row.median, row.beta = fit_exact_thresholds(thresholds, cap)
        row.method, row.status = "exact-thresholds", "fitted"
    # the runs: a record at rest lifts where its threshold lies below the level (at it, it stays at rest)
    expected = (levels[:, None] > thresholds[None, :]).sum(1) if thresholds.size > 1 else \
        (levels > thresholds[0]) * total
    clear = (total > 0) & np.all(np.abs(levels[:, None] / thresholds[None, :] - 1) > 1e-6, axis=1)
    unknown = (thresholds.size - total) if thresholds.size > 1 else 0.0  # failed runs: reached or not, unknown
    disagree = int(np.sum(clear & ((exceed > expected) | (exceed < expected - unknown))))
    if disagree:
        what = "exact g tan(alpha) step" if row.method == "exact-g-tan-alpha" else \
            "records' exact uplift thresholds g tan(alpha) x their intensity / their own PGA"
        row.warn(f"at {disagree} levels the runs disagree with the {what}")
    return row


def fit_cell(levels, exceed, total, states, threshold=None, n_records=None, unit="", cap=np.inf, context=None):
    """Fit every damage state of one cell. exceed, total : (n_state, n_level) counts per level.

    threshold : the exact uplift intensity of each record (n_record,), or one for all (g tan(alpha)), when uplift
    is a rigid threshold under this scaling (``exact_uplift_thresholds``), else None. cap : the credible cap [the
    levels' unit]: the levels are those at or below it, and a
    median above it is censored (``censored-at-cap``). context : the cell's ``StepContext`` (which levels are step
    runs; default: none are). Returns (rows, groups): a RowFit per state and the
    estimator groups (lists of state indices; more than one state = a shared-beta fit), which the bootstrap reuses.
    """
    medians, betas = fit_independent(levels, exceed, total)
    rows = []
    span = f"{levels[0]:.3g}-{levels[-1]:.3g} {unit}".strip()
    for s, state in enumerate(states):
        row = RowFit()
        has_data = total[s] > 0
        if is_slip_state(state) and not has_data.any():
            row.status = NOT_APPLICABLE
            row.warn("the base is tied in this cell (no friction): it does not slide")
        elif state.edp == "uplifted" and threshold is not None:
            row = exact_uplift_row(levels, exceed[s], total[s], threshold, unit, cap)
        elif not (exceed[s][has_data] > 0).any():
            row.warn(f"not reached by any record within the studied range {span}")
        elif np.isnan(medians[s]) and exceed[s][has_data][0] >= 0.5 * total[s][has_data][0]:
            row.status = "below-range"
            row.warn(f"reached by most records already at the lowest level; the median lies below "
                     f"{levels[0]:.3g} {unit}")
        elif np.isnan(medians[s]):
            row.status = "above-range"
            row.warn(f"reached only at the highest level by {int(exceed[s][has_data][-1])} of "
                     f"{int(total[s][has_data][-1])} records; the median lies above {levels[-1]:.3g} {unit}")
        elif betas[s] == 0:
            row.median, row.beta, row.method, row.status = medians[s], 0.0, "step-between-levels", "separated"
            row.step_method = _step_method(levels, exceed[s], total[s], unit, context)
            row.warn("perfectly separated counts: no lognormal MLE exists; reported as a step at "
                     f"{medians[s]:.3g} {unit} with beta = 0")
        else:
            row.median, row.beta, row.method, row.status = medians[s], betas[s], "mle-binomial", "fitted"
        rows.append(row)
    usable = [s for s, row in enumerate(rows) if row.method == "mle-binomial"]
    groups, fits = noncrossing_groups(levels, exceed, total, {s: (rows[s].median, rows[s].beta) for s in usable},
                                      usable, nesting_chains([state.edp for state in states]))
    for group in groups:
        if len(group) < 2:
            continue
        for s in group:
            row = rows[s]
            independent = deviance(levels, exceed[s], total[s], row.median, row.beta)
            row.median, row.beta = fits[s]
            row.method = "mle-binomial-shared-beta"
            row.deviance_cost = deviance(levels, exceed[s], total[s], row.median, row.beta) - independent
    grouped = {s for group in groups for s in group}
    groups = [group for group in groups] + [[s] for s in range(len(states)) if s not in grouped]
    for row in rows:
        if np.isfinite(row.median) and row.median > cap * (1 + 1e-9):  # never a median above the credible cap
            row.median, row.beta, row.method, row.status = np.nan, np.nan, "censored-at-cap", "censored-at-cap"
            row.warn(f"the fitted median lies above the credible cap {cap:.3g} {unit}: censored there "
                     "(probability_at_cap)")
            continue
        if row.method.startswith("mle") and not levels[0] <= row.median <= levels[-1]:
            row.status = "extrapolated"
            row.warn(f"median {row.median:.3g} {unit} outside the studied range {span} (extrapolated)")
        if row.method == "exact-thresholds" and not levels[0] <= row.median <= levels[-1]:
            row.status = "extrapolated"
            row.warn(f"median {row.median:.3g} {unit} outside the studied range {span} (from the exact thresholds)")
        if n_records is not None and n_records < SMALL_SAMPLE and row.method != "exact-g-tan-alpha" \
                and np.isfinite(row.median):
            row.warn(f"only {n_records} records (fewer than {SMALL_SAMPLE}): beta and the bounds are rough")
    return rows, groups


def bootstrap_cell(levels, exceed, total, rows, groups, weights=None, thresholds=None, cap=np.inf):
    """Refit resampled counts with each row's own estimator. exceed, total : (n_boot, n_state, n_level).

    An ``exact-thresholds`` row refits the resampled records' exact ``thresholds`` (n_record,) with their
    multiplicities ``weights`` (n_boot, n_record). Returns medians, betas of shape (n_boot, n_state) (NaN where a
    sample cannot identify the curve).
    """
    n_boot, n_state = exceed.shape[:2]
    medians, betas = np.full((n_boot, n_state), np.nan), np.full((n_boot, n_state), np.nan)
    independent = [g[0] for g in groups if len(g) == 1 and rows[g[0]].method in ("mle-binomial", "step-between-levels")]
    if independent:  # all independently fitted states of the cell in one batch, warm-started at the point
        start_median = np.tile([rows[s].median for s in independent], (n_boot, 1))
        start_beta = np.tile([rows[s].beta if rows[s].beta > 0 else 0.4 for s in independent], (n_boot, 1))
        medians[:, independent], betas[:, independent] = fit_independent(
            levels, exceed[:, independent], total[:, independent], start=(start_median, start_beta))
    for group in groups:
        first = rows[group[0]]
        if len(group) == 1 and first.method == "exact-g-tan-alpha":
            medians[:, group[0]], betas[:, group[0]] = first.median, 0.0
        elif len(group) == 1 and first.method == "exact-thresholds" and weights is not None:
            medians[:, group[0]], betas[:, group[0]] = fit_exact_thresholds(thresholds, cap, weights)
        elif len(group) > 1:
            e, t = exceed[:, group], total[:, group]
            separated, *_ = separation(e, t)
            identifiable = ((e > 0) & (t > 0)).any(-1) & ((e < t) & (t > 0)).any(-1) & ~separated
            regular = identifiable.all(-1)
            if regular.any():
                start = (np.tile([rows[s].median for s in group], (int(regular.sum()), 1)),
                         np.full(int(regular.sum()), first.beta))
                m, b = fit_shared_beta(levels, e[regular], t[regular], start=start)
                medians[np.ix_(regular, group)] = m
                betas[np.ix_(regular, group)] = b[:, None]
    return medians, betas


# ---------------------------------------------------------------- the whole cube

@dataclass
class FitInputs:
    """What every cell's fit reads, computed once for a cube (``fit_inputs``).

    intensity : (n_block, n_level) the levels [unit]; caps : (n_block,) the credible caps [unit]; credible :
    (n_block, n_level) the levels at or below the cap; levels : (soil, block, model, n) each cell's levels with its
    step runs between them (``merged_runs``); usable : where those are finite and credible; reached, valid :
    (record, n, soil, block, model, state) each run's exceedance (0/1) and whether it is known; fractions :
    (n_level, soil, block, model, state) the empirical fraction on the levels; thresholds : (record, block) the
    exact uplift intensities or None; exact : (soil, block, model) where they apply (a tied pivot model).
    """

    intensity: np.ndarray
    unit: str
    caps: np.ndarray
    credible: np.ndarray
    levels: np.ndarray
    usable: np.ndarray
    reached: np.ndarray
    valid: np.ndarray
    fractions: np.ndarray
    thresholds: np.ndarray | None
    exact: np.ndarray
    context: Callable[[tuple, np.ndarray], StepContext]
    n_records: int

    def cell(self, index: tuple):
        """(levels, data, exceed, total, threshold) of the cell ``index`` = (soil, block, model).

        levels (n,) [unit]; data indexes ``reached``/``valid`` down to (record, n, state); exceed, total (state, n)
        counts; threshold (n_record,) the exact uplift intensities or None.
        """
        block = index[1]
        levels = self.levels[index][self.usable[index]]
        data = (slice(None), self.usable[index], *index)
        exceed = self.reached[data].sum(0).T
        total = self.valid[data].sum(0).T.astype(float)
        threshold = self.thresholds[:, block] if self.thresholds is not None and self.exact[index] else None
        return levels, data, exceed, total, threshold

    def fit(self, index: tuple, states: list[DamageState]):
        """``fit_cell`` of the cell ``index``: (rows, groups)."""
        levels, _, exceed, total, threshold = self.cell(index)
        block = index[1]
        return fit_cell(levels, exceed, total, states, threshold, self.n_records, unit_label(self.unit),
                        self.caps[block], self.context(index, self.intensity[block][self.credible[block]]))


def fit_inputs(cube: xr.Dataset, states: list[DamageState], fractions: bool = True) -> FitInputs:
    """The ``FitInputs`` of a cube for ``states`` (the fragility stage's, and rockfrag.steps' in the study).

    ``fractions``: compute the empirical fractions on the levels (else NaN: the study's steps do not need them).
    """
    intensity, unit = intensity_levels(cube)
    group_dims = ("soil", "block", "model")
    models = [str(m) for m in cube.model.values]
    sliding = np.isfinite(cube["friction_static"].transpose(*group_dims).values) if "friction_static" in cube \
        else np.zeros(tuple(cube.sizes[d] for d in group_dims), bool)
    # the exact uplift is the rigid base's only where the base is tied: one that slides before it can rock (base
    # friction, Shenton 1996) need not lift at g tan(alpha), so its uplift is fitted from its runs
    rigid = np.array([uplift_is_rigid_threshold(m) for m in models])
    exact = rigid[None, None, :] & ~sliding

    read = {"outcome", "peak_uplift", *(s.edp for s in states)}  # the per-run variables exceedance reads

    def exceedances(runs):  # (record, level, soil, block, model, state)
        # only what exceedance reads: xarray aligns every coordinate of every operand (the cube has dozens)
        runs = runs[[name for name in (*read, "friction_static") if name in runs]]
        runs = runs.drop_vars([name for name in runs.coords if name not in runs.dims and name != "block_b"])
        outcome = first_overturn_outcomes(runs)
        return np.stack([exceedance(runs, s, outcome).transpose("record", "im_level", *group_dims).values
                         for s in states], axis=-1)

    runs, levels = merged_runs(cube, intensity, unit, read)  # the levels with each cell's step runs between them
    exceed_all = exceedances(runs)
    if fractions:
        on_levels = exceed_all if runs is cube else exceedances(cube)  # the empirical fractions are the levels' own
        with np.errstate(invalid="ignore"):
            fractions = np.nan_to_num(on_levels).sum(0) / np.isfinite(on_levels).sum(0)
    else:
        fractions = np.full(exceed_all.shape[1:], np.nan)
    caps = credible_caps(cube, unit)
    return FitInputs(
        intensity=intensity, unit=unit, caps=caps, credible=intensity <= caps[:, None] * (1 + 1e-9),
        levels=levels, usable=np.isfinite(levels) & (levels <= caps[None, :, None, None] * (1 + 1e-9)),
        reached=np.nan_to_num(exceed_all), valid=np.isfinite(exceed_all), fractions=fractions,
        thresholds=exact_uplift_thresholds(cube, unit), exact=exact, context=step_refinement(cube),
        n_records=cube.sizes["record"])


ROW_VARIABLES = {
    "median": ("median intensity of the lognormal fragility", None),
    "beta": ("lognormal dispersion beta (0 = a step)", "1"),
    "median_low": ("lower bootstrap bound of the median (records resampled)", None),
    "median_high": ("upper bootstrap bound of the median (records resampled)", None),
    "beta_low": ("lower bootstrap bound of beta", "1"),
    "beta_high": ("upper bootstrap bound of beta", "1"),
    "gof_p_value": ("goodness of fit: deviance chi-square p-value of the binomial fit", "1"),
    "gof_max_error": ("goodness of fit: max |fitted - empirical| exceedance fraction", "1"),
    "noncrossing_deviance_cost": ("binomial deviance added by the shared-beta (non-crossing) refit", "1"),
    "capacity_median": ("median of the refined IDA overturning capacities (censored lognormal MLE; see the "
                        "capacity_fit attribute)", None),
    "capacity_beta": ("dispersion of the refined IDA overturning capacities (censored lognormal MLE)", "1"),
}


def record_resamples(n_records, n_bootstrap, seed):
    """(n_bootstrap, n_records) multiplicities of each record in each bootstrap sample (seeded)."""
    rng = np.random.default_rng(seed)
    picks = rng.integers(0, n_records, (n_bootstrap, n_records))
    weights = np.zeros((n_bootstrap, n_records))
    np.add.at(weights, (np.repeat(np.arange(n_bootstrap), n_records), picks.ravel()), 1.0)
    return weights


def refined_capacities(ida: xr.Dataset | None, unit: str) -> tuple[np.ndarray, np.ndarray] | None:
    """The refined overturning capacities of ``ida.nc`` in ``unit``, and where each record is censored.

    Both are (record, soil, block, model). A record that never overturned is censored at the highest
    intensity it was seen to survive (``capacity_lower``; NaN where unknown). None without refined
    capacities.
    """
    if ida is None or "capacity" not in ida:
        return None
    out = []
    for name in ("capacity", "capacity_lower"):
        if name not in ida:
            out.append(np.full(out[0].shape, np.nan))
            continue
        values = ida[name].transpose("record", "soil", "block", "model")
        out.append(np.asarray(convert_units(values.values, values.attrs.get("units", unit), unit), float))
    capacity, lower = out
    return capacity, np.where(np.isfinite(capacity), np.nan, lower)


def overturning_checks(row: RowFit, out: dict, key: tuple, n_resurrected: int, n_records: int, unit: str,
                       capacities: list | None, top: float) -> None:
    """The overturning row of one cell: its capacity fit into ``out``, and warnings on ``row``.

    The capacity fit is of the cell's refined capacities (see ``CAPACITY_FIT``); the warnings are for
    resurrection and for a capacity median outside the stripe fit's bootstrap bounds (when the stripe
    fit has a spread: beta > 0 and distinct bounds).

    capacities : [capacity, censor point] per record [unit] or None; top : the cell's highest credible level,
    where a record that never overturned (or overturned only above it) is censored.
    """
    if n_resurrected:
        row.warn(f"{n_resurrected} of {n_records} records survived a level above their first overturning level "
                 "(resurrection): counted as overturned from their first overturning level on")
    if capacities is None:
        return
    capacity, censor = capacities
    beyond = capacity > top * (1 + 1e-9)  # a capacity above the credible cap (runs beyond it) is censored there
    capacity, censor = np.where(beyond, np.nan, capacity), np.where(beyond, top, censor)
    median, beta = fit_censored_capacities(capacity, np.where(np.isfinite(censor), censor, top))
    if median > top * (1 + 1e-9):  # never a median above the cap
        median, beta = np.nan, np.nan
    out["capacity_median"][key], out["capacity_beta"][key] = median, beta
    low, high = out["median_low"][key], out["median_high"][key]
    if row.beta > 0 and np.isfinite(median) and low < high and not low <= median <= high:
        row.warn(f"the refined capacities' median {median:.3g} {unit} lies outside the bounds "
                 f"{low:.3g}-{high:.3g} {unit} of the stripe fit")


def fragility_dataset(cube: xr.Dataset, states: list[DamageState] | None = None, ida: xr.Dataset | None = None,
                      n_bootstrap: int = 100, seed: int = 0, confidence: float = 0.90,
                      progress: bool = False, quality: str = "fair") -> xr.Dataset:
    """Fit every soil x block x model x damage state of a cube (the estimators: see the module docstring).

    Parameters
    ----------
    cube : xarray.Dataset
        The study cube (``cube.nc``): outcome and peak angle ratio over record x im_level x soil x block x model,
        intensities in the units the cube states (multiples of g for accelerations).
    states : list of DamageState, optional
        Damage states in order of severity; default: the registry (``rockfrag.damage_states.DAMAGE_STATES``).
    ida : xarray.Dataset, optional
        ``ida.nc``: its refined overturning capacities are fitted as the check ``capacity_median``/``capacity_beta``.
    n_bootstrap : int
        Record resamples for the confidence bounds of the median (0: no bounds).
    seed : int
        Seed of the record resampling (same seed, same bounds).
    confidence : float
        Two-sided confidence level of the bounds, in (0, 1).
    progress : bool
        Show a progress bar over the cells.
    quality : str
        FEMA P-695's rating of the recommended model's form (``FORM_RATINGS``; ``with_recommended``).

    Returns
    -------
    xarray.Dataset
        ``fragility.nc``'s content: median [the cube's intensity unit], beta [-], bounds, status, fit method,
        warnings and empirical fractions per soil x block x model x damage state.
    """
    states = states or list(DAMAGE_STATES.values())
    inputs = fit_inputs(cube, states)
    intensity, unit, caps, reached, valid = inputs.intensity, inputs.unit, inputs.caps, inputs.reached, inputs.valid
    measure = cube.attrs.get("intensity_measure", "")
    group_dims = ("soil", "block", "model")
    shape = tuple(cube.sizes[d] for d in group_dims) + (len(states),)
    out = {name: np.full(shape, np.nan) for name in ROW_VARIABLES}
    text = {name: np.full(shape, "", dtype=object) for name in ("fit_method", "status", "fit_warning", "step_method")}
    extrapolated = np.zeros(shape, np.int8)
    fraction = inputs.fractions
    n_records = cube.sizes["record"]
    weights = record_resamples(n_records, n_bootstrap, seed)
    n_resurrected = resurrected(cube.outcome.transpose("record", *group_dims, "im_level").values).sum(0)
    capacities = refined_capacities(ida, unit)
    credible = inputs.credible
    label = unit_label(unit)
    tail = (1 - confidence) / 2
    at_cap = {name: np.full(shape, np.nan) for name in ("probability_at_cap", "probability_at_cap_low",
                                                         "probability_at_cap_high")}
    cells = list(np.ndindex(*shape[:-1]))
    for index in tqdm(cells, desc="fragility fits + bootstrap", unit="cell", disable=not progress):
        soil, block, model = index
        levels, data, exceed, total, threshold = inputs.cell(index)
        if levels.size:  # the records that reached each state at the highest credible level, with bounds
            last = total[:, -1]
            with np.errstate(invalid="ignore"):
                at_cap["probability_at_cap"][index] = np.where(last > 0, exceed[:, -1] / last, np.nan)
            at_cap["probability_at_cap_low"][index], at_cap["probability_at_cap_high"][index] = clopper_pearson(
                exceed[:, -1], last, confidence)
        rows, groups = inputs.fit(index, states)
        if n_bootstrap:
            boot_exceed = np.einsum("br,rls->bsl", weights, reached[data])
            boot_total = np.einsum("br,rls->bsl", weights, valid[data].astype(float))
            boot_median, boot_beta = bootstrap_cell(levels, boot_exceed, boot_total, rows, groups, weights,
                                                    threshold, caps[block])
        for s, (state, row) in enumerate(zip(states, rows)):
            key = (*index, s)
            out["median"][key], out["beta"][key] = row.median, row.beta
            out["noncrossing_deviance_cost"][key] = row.deviance_cost if np.isfinite(row.median) else np.nan
            text["fit_method"][key], text["status"][key] = row.method, row.status
            text["step_method"][key] = row.step_method
            extrapolated[key] = row.status == "extrapolated"
            if n_bootstrap and np.isfinite(row.median) and np.isfinite(boot_median[:, s]).any():
                out["median_low"][key], out["median_high"][key] = np.nanquantile(boot_median[:, s], [tail, 1 - tail])
                out["beta_low"][key], out["beta_high"][key] = np.nanquantile(boot_beta[:, s], [tail, 1 - tail])
            out["gof_p_value"][key], out["gof_max_error"][key] = goodness_of_fit(
                levels, exceed[s], total[s], row.median, row.beta)
            if state.edp == "overturned":
                overturning_checks(row, out, key, n_resurrected[index], n_records, label,
                                   None if capacities is None else [c[(slice(None), *index)] for c in capacities],
                                   levels[-1])
            text["fit_warning"][key] = "; ".join(row.warnings)

    dims = (*group_dims, "damage_state")
    data_vars = {}
    for name, (long_name, units) in ROW_VARIABLES.items():
        if name in ("median_low", "median_high", "beta_low", "beta_high"):
            long_name = f"{confidence:.0%} two-sided interval: {long_name}"
        data_vars[name] = (dims, out[name], {"long_name": long_name, "units": unit if units is None else units})
    data_vars["fit_method"] = (dims, text["fit_method"].astype(str), {
        "long_name": "estimator: mle-binomial | mle-binomial-shared-beta | exact-g-tan-alpha | exact-thresholds "
                     "(lognormal MLE of the records' exact uplift intensities) | step-between-levels | none"})
    data_vars["status"] = (dims, text["status"].astype(str), {
        "long_name": "what the row is: " + " | ".join(STATUS),
        "description": json.dumps(STATUS)})
    data_vars["extrapolated"] = (dims, extrapolated, {
        "long_name": "1 where the fitted median lies outside the studied intensity range of its block",
        "units": "1", "flag_values": np.array([0, 1], np.int8), "flag_meanings": "inside_range extrapolated"})
    data_vars["fit_warning"] = (dims, text["fit_warning"].astype(str), {"long_name": "warnings about the fit"})
    data_vars["step_position"] = (dims, np.where(text["step_method"] != "", out["median"], np.nan), {
        "long_name": "intensity of a step row (beta = 0): where the state's threshold is placed (NaN: a curve)",
        "units": unit})
    data_vars["step_method"] = (dims, text["step_method"].astype(str), {
        "long_name": "how the step was placed: exact (g tan alpha) or from the levels that bracket it"})
    data_vars["studied_im_min"] = (("block",), intensity[:, 0], {
        "long_name": "lowest intensity level studied for the block", "units": unit})
    highest = np.array([levels[keep][-1] if keep.any() else np.nan for levels, keep in zip(intensity, credible)])
    data_vars["studied_im_max"] = (("block",), highest, {
        "long_name": "highest intensity level studied for the block (at or below the credible cap)", "units": unit})
    data_vars["credible_max"] = (("block",), caps, {
        "long_name": "credible cap on the intensity: fits, risk and exchange files use only the levels at or below "
                     "it (inf: none)", "units": unit})
    for name, long_name in (("probability_at_cap", "fraction of records that reached the state at the highest level "
                                                   "at or below the credible cap"),
                            ("probability_at_cap_low", f"lower {confidence:.0%} Clopper-Pearson bound of "
                                                       "probability_at_cap"),
                            ("probability_at_cap_high", f"upper {confidence:.0%} Clopper-Pearson bound of "
                                                        "probability_at_cap")):
        data_vars[name] = (dims, at_cap[name], {"long_name": long_name, "units": "1"})
    data_vars["n_records"] = ((), n_records, {"long_name": "number of records", "units": "1"})
    data_vars["n_resurrected"] = (group_dims, n_resurrected.astype(np.int32), {
        "long_name": "records that survived a level above their first overturning level (resurrection; counted "
                     "as overturned from their first overturning level on)", "units": "1"})
    data_vars["empirical_fraction"] = (("im_level", *dims), fraction, {
        "long_name": "fraction of records reaching the damage state (first-overturn convention)", "units": "1"})
    data_vars["outcome_probability"] = (("outcome_class", "im_level", *group_dims), three_outcomes(cube).values,
                                        {"long_name": "fraction of records in each outcome (a record is "
                                                      "overturned from its first overturning level on; a tilt on "
                                                      "a bed below the uplift size is no uplift)",
                                         "units": "1"})
    im_level = cube.im_level
    if parse_units(im_level.attrs.get("units", "")) == parse_units(unit):
        im_level = im_level.assign_attrs(units=unit)  # an older file's "g": the same unit, spelled as UDUNITS reads
    coords = {d: cube[d] for d in group_dims}
    coords.update({"im_level": im_level, "damage_state": [s.name for s in states],
                   "damage_state_description": ("damage_state", [s.description for s in states]),
                   "damage_state_edp": ("damage_state", [s.edp for s in states], {
                       "long_name": "engineering demand parameter of the damage state (peak_slip: the slip family)"}),
                   "outcome_class": ["no_uplift", "rocking", "overturned"],
                   "intensity": (("block", "im_level"), intensity, {
                       "long_name": f"intensity of each level ({measure})", "units": unit})})
    sample = member_cube(cube)  # the recommended model's other members: their medians only (no bootstrap)
    members = None if sample is None else fragility_dataset(sample, states, n_bootstrap=0, seed=seed,
                                                            confidence=confidence)
    dataset = with_recommended(xr.Dataset(data_vars, coords=coords), members, quality)
    warnings = warning_summary(dataset)
    dataset.attrs = {"Conventions": "CF-1.12", "title": "rockfrag lognormal fragility functions",
                     "source": cube.attrs.get("source", ""), "config_hash": cube.attrs.get("config_hash", ""),
                     "intensity_measure": measure, "intensity_unit": unit, "intensity_unit_label": label,
                     **component_attributes(cube),
                     "credible_intensity_max": float(caps[0]) if np.allclose(caps, caps[0]) else caps,
                     "credible_intensity_reason": cube.attrs.get("credible_intensity_reason",
                                                                 "none: the cube states no credible cap"),
                     "overturning_convention": OVERTURNING_CONVENTION,
                     "capacity_fit": CAPACITY_FIT if capacities is not None else
                     "capacity_median/capacity_beta: none (no refined capacities: capacity_resolution = 0 or no "
                     "ida.nc)",
                     "bootstrap_samples": n_bootstrap, "bootstrap_seed": seed,
                     "fit_warnings": json.dumps(warnings),
                     "references": "Baker (2015) Efficient analytical fragility function fitting using "
                                   "dynamic structural analysis. Earthquake Spectra 31(1)"}
    return dataset


# ---------------------------------------------------------------- the recommended curve and its model uncertainty

FORM_RATINGS = {"superior": 0.10, "good": 0.20, "fair": 0.35, "poor": 0.50}
"""beta of FEMA P-695's quality rating of a nonlinear model, superior (A) to poor (D): FEMA P-695 (2009)
Quantification of Building Seismic Performance Factors, Section 5.7 (the model's rating from its accuracy and
robustness and its representation of the behaviour) and Section 7.3.1 (beta_MDL combined with the others by
the square root of the sum of squares)."""
DEFAULT_QUALITY = "fair"
"""The recommended model's rating (docs/theory/model-uncertainty.md): verified against closed forms and an
independent reference, calibrated to the experiments' restitution (accuracy medium), but planar and rigid: no
three-dimensional rocking (wobbling, twisting), no flexible superstructure, no yielding of the bed or the base
(representation medium): P-695's medium/medium cell is "fair"."""
MODEL_UNCERTAINTY = (
    "recommended = the central member of the recommended model's designed sample (rockfrag.models.variants): "
    "median and beta_record_to_record are its fit. beta_parameters is the spread of the median over the sample: "
    "each parameter's range (restitution, friction, bed stiffness) read as uniform in ln(median) between its ends' "
    "medians, sigma_i = |ln(m_high / m_low)| / (2 sqrt 3) (one end with no median by the highest intensity "
    "studied: at least the other end's distance to that intensity, and at least twice its distance to the centre: "
    "a lower bound), "
    "beta_parameters = sqrt(sum sigma_i^2). beta_form is FEMA P-695's model-quality rating (Section 5.7; "
    "superior 0.10, good 0.20, fair 0.35, poor 0.50) for what the sample cannot represent: a planar rigid block, "
    "no three-dimensional rocking, no flexible superstructure. That rating covers a model's parameters too, so it "
    "is not added to their sampled spread: beta_model = max(beta_form, beta_parameters) (the rating replaces the "
    "spread, unless the sample alone shows more). beta = sqrt(beta_record_to_record^2 + beta_model^2) (FEMA P-695 "
    "Section 7.3.1; FEMA P-58). The references (housner, ssi) carry their fitted beta only (beta_model 0).")
UNIFORM_SPREAD = 2.0 * np.sqrt(3.0)  # the standard deviation of a uniform variable is its range / (2 sqrt 3)


def parameter_spread(low: np.ndarray, centre: np.ndarray, high: np.ndarray,
                     highest: np.ndarray | float = np.nan) -> np.ndarray:
    """The sigma of ln(median) over one parameter's range, from its ends' medians.

    An end without a median never reached the state by the highest intensity studied (``highest``, same unit):
    its median lies beyond it, so the range is at least from the other end to ``highest``, and it is taken as no
    less than twice the other end's distance to the centre either (a lower bound, not an estimate: cold read 9,
    user B4, a friction end below the cap read 0.04 where the range to the cap gives 0.14). Both missing: NaN.
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        both = np.abs(np.log(high / low)) / UNIFORM_SPREAD
        known = np.where(np.isfinite(low), low, high)
        twice = 2.0 * np.abs(np.log(known / centre)) / UNIFORM_SPREAD
        to_highest = np.abs(np.log(highest / known)) / UNIFORM_SPREAD
        one = np.where(np.isfinite(to_highest), np.fmax(twice, to_highest), twice)
    return np.where(np.isfinite(low) & np.isfinite(high), both, one)


def with_recommended(dataset: xr.Dataset, members: xr.Dataset | None = None,
                     quality: str = DEFAULT_QUALITY) -> xr.Dataset:
    """Every row with its beta split; the recommended rows with the model uncertainty of the designed sample.

    Every row gains ``beta_record_to_record`` (its fitted beta), ``beta_parameters``, ``beta_form`` and
    ``beta_model`` (0 on the references). The ``recommended`` rows, given the members' fits, take
    ``MODEL_UNCERTAINTY``: beta_model = max(beta_form, beta_parameters) and beta = sqrt(beta_rtr^2 + beta_model^2);
    the dataset gains ``member_median`` (member, soil, block, damage_state), ``median_sensitivity`` (parameter,
    soil, block, damage_state: each parameter's sigma of ln median) and ``sensitivity_leading_parameter``.

    Parameters
    ----------
    dataset : xarray.Dataset
        The fits over (soil, block, model, damage_state).
    members : xarray.Dataset, optional
        The members' fits (``model`` = ``recommended-<member>``); None: no sample (beta_model 0 everywhere).
    quality : str
        FEMA P-695's rating of the model's form (``FORM_RATINGS``).

    Returns
    -------
    xarray.Dataset
        ``dataset`` with the beta parts.
    """
    zero = xr.zeros_like(dataset.beta).where(np.isfinite(dataset.beta))
    dataset = dataset.assign(
        beta_record_to_record=dataset.beta.assign_attrs(
            long_name="record-to-record dispersion: the fitted lognormal beta"),
        beta_parameters=zero.assign_attrs(long_name="dispersion of the median over the designed sample of the "
                                                    "recommended model's parameters (0: not sampled)", units="1"),
        beta_form=zero.assign_attrs(long_name="model-form dispersion: FEMA P-695 model-quality rating (0: not "
                                              "rated, a reference)", units="1"),
        beta_model=zero.assign_attrs(long_name="model dispersion: max(beta_form, beta_parameters), the rating "
                                               "replaces the sampled spread (0: a reference)", units="1"))
    names = [str(m) for m in dataset.model.values]
    if members is None or RECOMMENDED not in names:
        return dataset
    centre = dataset["median"].sel(model=RECOMMENDED).transpose("soil", "block", "damage_state").values
    member_median = members["median"].transpose("model", "soil", "block", "damage_state")
    roles = [split_variant(str(m))[1] for m in member_median.model.values]
    median_of = dict(zip(roles, member_median.values))
    nan = np.full_like(centre, np.nan)
    highest = (dataset["studied_im_max"].broadcast_like(dataset["median"].sel(model=RECOMMENDED))
               .transpose("soil", "block", "damage_state").values if "studied_im_max" in dataset else np.nan)
    spreads = np.stack([np.where(np.isfinite(centre), parameter_spread(
        median_of.get(f"{p}_low", nan), centre, median_of.get(f"{p}_high", nan), highest), np.nan)
        for p in PARAMETERS])
    known = np.isfinite(spreads)
    beta_parameters = np.where(np.isfinite(centre), np.sqrt((np.where(known, spreads, 0.0) ** 2).sum(0)), np.nan)
    beta_form = np.where(np.isfinite(centre), FORM_RATINGS[quality], np.nan)
    beta_model = np.fmax(beta_form, beta_parameters)
    beta_rtr = dataset.beta.sel(model=RECOMMENDED).transpose("soil", "block", "damage_state").values
    beta = np.where(np.isfinite(beta_rtr) & np.isfinite(beta_model), np.hypot(beta_rtr, beta_model), beta_rtr)
    unknown = np.isfinite(centre) & ~known.all(0)
    note = np.where(unknown, "a sample member did not reach the state in the studied range: its parameter's "
                    "spread is left out of beta_parameters", "")
    m = names.index(RECOMMENDED)
    for name, values in (("beta", beta), ("beta_parameters", beta_parameters), ("beta_form", beta_form),
                         ("beta_model", beta_model)):
        variable = dataset[name].transpose("soil", "block", "model", "damage_state")
        data = variable.values.copy()
        data[:, :, m] = values
        dataset[name] = variable.copy(data=data)
    warning = dataset.fit_warning.transpose("soil", "block", "model", "damage_state")
    text = warning.values.astype(object)
    text[:, :, m] = np.array(["; ".join(part for part in (str(a), str(b)) if part)
                              for a, b in zip(text[:, :, m].ravel(), note.ravel())], dtype=object).reshape(note.shape)
    dataset["fit_warning"] = warning.copy(data=text.astype(str))
    for name in ("beta_low", "beta_high"):  # the bootstrap bounds are of the record-to-record beta alone
        if name in dataset:
            dataset[name].attrs["long_name"] += " (record-to-record part; the recommended rows' beta adds beta_model)"
    dims = ("soil", "block", "damage_state")
    dataset["member_median"] = (("member", *dims), member_median.values, {
        "long_name": "median of each member of the recommended model's designed sample",
        "units": dataset["median"].attrs.get("units", "")})
    dataset = dataset.assign_coords(member=("member", roles, {
        "long_name": "member of the recommended model's designed sample (one parameter at an end of its range)"}))
    dataset["median_sensitivity"] = (("parameter", *dims), spreads, {
        "long_name": "sensitivity of the recommended median to each sampled parameter: sigma of ln(median) over "
                     "its range, |ln(m_high / m_low)| / (2 sqrt 3) (NaN: not reached)", "units": "1"})
    dataset = dataset.assign_coords(parameter=("parameter", list(PARAMETERS), {
        "long_name": "sampled epistemic parameter of the recommended model"}))
    moves = np.where(known, spreads, 0.0).max(0) > 0  # no member moved the median: no parameter leads
    leading = np.where(moves & np.isfinite(centre),
                       np.array(PARAMETERS, dtype=object)[np.argmax(np.where(known, spreads, -1.0), axis=0)], "")
    dataset["sensitivity_leading_parameter"] = (dims, leading.astype(str), {
        "long_name": "the sampled parameter that moves the recommended median most (empty: no median, or no "
                     "member moved it)"})
    dataset.attrs["recommended"] = MODEL_UNCERTAINTY
    dataset.attrs["model_quality"] = f"{quality} (FEMA P-695 Section 5.7: beta_form = {FORM_RATINGS[quality]:g})"
    return dataset


def warning_summary(dataset: xr.Dataset) -> list[str]:
    """Plain lines for the console: what the fits could not do, and whether the user must act.

    Each line says what happened, what the study did about it, and where the rows are marked; the messages and
    what to do about each are listed in the documentation (docs/warnings.md).
    """
    status = dataset.status.values.ravel()
    warnings = dataset.fit_warning.values.ravel()
    total = status.size
    lines = []
    for name, what in (
            ("extrapolated", "the median lies outside the studied intensities, so it is extrapolated from the "
                             "fitted curve (status 'extrapolated'); read those medians as estimates"),
            ("separated", "every record changed state between the same two levels, so the curve is a step there "
                          "(dispersion 0; status 'separated'); nothing to do unless the step's position matters"),
            ("not-reached", "no record reached the state at any level up to the credible cap, so there is no curve "
                            "(status 'not-reached'); expected for states the shaking cannot cause"),
            ("below-range", "every record was already in the state at the lowest level, so there is no curve "
                            "(status 'below-range'); start the intensity levels lower to fit one"),
            ("above-range", "records reached the state only at the highest level, so the median lies above the "
                            "levels and there is no curve (status 'above-range')")):
        count = int(np.sum(status == name))
        if count:
            lines.append(f"{count} of {total} fragility rows: {what}")
    small = int(np.sum(["fewer than" in w for w in warnings]))
    if small:
        lines.append(f"only {int(dataset.n_records)} records (fewer than {SMALL_SAMPLE}): the dispersion and the "
                     f"confidence bounds of {small} rows are rough; use more records for a design answer")
    disagree = int(np.sum(["disagree" in w for w in warnings]))
    if disagree:
        lines.append(f"{disagree} uplift rows: the runs disagree with the closed-form uplift threshold "
                     "g tan(alpha); check the block's geometry (details in each row's fit_warning)")
    if "n_resurrected" in dataset:
        cells = int(np.sum(dataset.n_resurrected.values > 0))
        if cells:
            lines.append(f"{cells} of {dataset.n_resurrected.size} block, soil and model combinations: "
                         f"{int(dataset.n_resurrected.sum())} records overturned at one level but not at a higher "
                         "one (usual for rocking, whose response is not monotonic in the intensity); each counts as "
                         "overturned from its first overturning level on, which is conservative; nothing to do")
    outside = int(np.sum(["refined capacities' median" in w for w in warnings]))
    if outside:
        lines.append(f"{outside} overturning rows: the median of the records' refined overturning intensities lies "
                     "outside the confidence bounds of the fitted curve; the curve may be a poor fit there "
                     "(details in each row's fit_warning)")
    return lines


def three_outcomes(cube: xr.Dataset) -> xr.DataArray:
    """P(no uplift), P(rocking without overturning), P(overturning) per level, from the cube.

    A record is overturned from its first overturning level on (``first_overturn_outcomes``). Failed runs and
    runs stopped in free flight before any overturning (their overturning is unknown) are left out of the total.
    A run that only tilts on a bed (``tilts``: a corner lifted less than the uplift size) is no uplift, as the
    uplift damage state and the report count it (cold read 7: the file counted 17 of 44 rocking where the report's
    motion table and outcomes page, from the same runs, count 4).
    """
    outcome = first_overturn_outcomes(cube)
    tilted = tilts(cube, outcome)
    if isinstance(tilted, xr.DataArray):
        outcome = outcome.where(~tilted, OUTCOME_NO_UPLIFT)
    valid = (outcome != OUTCOME_FAILED) & (outcome != OUTCOME_FREE_FLIGHT)
    counts = [((outcome == code) & valid).sum("record") for code in
              (OUTCOME_NO_UPLIFT, OUTCOME_ROCKING, OUTCOME_OVERTURNED)]
    total = valid.sum("record")
    stacked = xr.concat([c / total for c in counts], dim="outcome_class")
    return stacked.transpose("outcome_class", "im_level", "soil", "block", "model")


TABLE_COLUMNS = ["median", "beta", "beta_record_to_record", "beta_parameters", "beta_form", "beta_model", "status",
                 "extrapolated", "fit_method", "median_low", "median_high", "beta_low",
                 "beta_high", "gof_p_value", "gof_max_error", "noncrossing_deviance_cost", "capacity_median",
                 "capacity_beta", "probability_at_cap", "probability_at_cap_low", "probability_at_cap_high",
                 "step_position", "step_method", "fit_warning"]


def fragility_table(dataset: xr.Dataset) -> pd.DataFrame:
    """One row per soil x block x model x damage state, with the studied range of the block."""
    table = dataset[TABLE_COLUMNS].to_dataframe().reset_index()
    per_block = ["studied_im_min", "studied_im_max", *(["credible_max"] if "credible_max" in dataset else [])]
    studied = dataset[per_block].to_dataframe().reset_index()
    table = table.merge(studied.rename(columns={"studied_im_min": "im_lowest", "studied_im_max": "im_highest"}),
                        on="block")
    if "credible_max" not in table:
        table["credible_max"] = np.inf
    table["im_units"] = _unit_label(dataset)
    table["n_records"] = int(dataset.n_records)
    resurrections = ["n_resurrected"] if "n_resurrected" in dataset else []
    if resurrections:
        table = table.merge(dataset["n_resurrected"].to_dataframe().reset_index(), on=["soil", "block", "model"])
    keep = ["soil", "block", "model", "damage_state", *TABLE_COLUMNS[:-1], *resurrections, "im_lowest", "im_highest",
            "credible_max", "im_units", "n_records", "fit_warning"]
    return table[keep]


RISK_BOUND = (
    "annual_frequency integrates P(state | im) over the hazard up to the credible cap (credible_max) and adds the "
    "hazard's exceedance of the cap, lambda(cap), as if every intensity above it reached the state: an upper bound "
    "on the part above the cap (annual_frequency_above_cap). A row censored at the cap (no median) integrates the "
    "records' fractions at the levels below it instead of a fitted curve")
"""How the risk treats the credible cap (fragility.nc's ``risk_bound`` attribute)."""


def capped_frequency(median: float, beta: float, hazard, cap: float, levels=None, fractions=None) -> float:
    """Lambda of one row [1/yr] up to the credible ``cap`` plus lambda(cap), the stated upper bound above it.

    A row with a curve (finite median and beta): its lognormal integrated up to the cap
    (``rockfrag.risk.annual_frequency`` with and without ``lower = cap``); a row without one but with the
    records' ``fractions`` at ``levels`` (a censored row): each fraction held from its level to the next one.
    NaN without a hazard, or with neither.
    """
    if hazard is None:
        return np.nan
    above = float(hazard_frequency(hazard, cap)) if np.isfinite(cap) else 0.0
    if np.isfinite(median) and np.isfinite(beta):
        whole = annual_frequency(median, beta, hazard)
        if not np.isfinite(cap):
            return whole
        if beta == 0:  # a step: every intensity from its median on reaches the state, the cap's exceedance included
            return float(hazard_frequency(hazard, min(median, cap)))
        return whole - annual_frequency(median, beta, hazard, lower=cap) + above
    if levels is None or not np.isfinite(cap):
        return np.nan
    known = np.isfinite(fractions)
    levels, fractions = np.asarray(levels, float)[known], np.asarray(fractions, float)[known]
    if not levels.size:
        return np.nan
    edges = np.append(levels, cap)
    drops = hazard_frequency(hazard, edges[:-1]) - hazard_frequency(hazard, edges[1:])
    return float(np.sum(fractions * drops)) + above


def capped_risk(fragility: xr.Dataset, risk: xr.Dataset, hazard_of, design_life: float) -> xr.Dataset:
    """``risk`` (rockfrag.risk.risk_dataset) with every row's integral stopped at its block's credible cap.

    ``hazard_of(soil) -> HazardCurve or None``: the hazard each soil's rows use. Adds
    ``annual_frequency_above_cap`` [1/yr], the bound lambda(cap) (``RISK_BOUND``); a fragility without a cap
    (``credible_max`` inf or absent) keeps ``risk`` as it is.
    """
    if "credible_max" not in fragility or not np.isfinite(fragility.credible_max.values).any():
        return risk
    frequency = risk.annual_frequency.copy()
    above = xr.full_like(frequency, np.nan)
    levels = fragility["intensity"] if "intensity" in fragility.variables else None
    for soil in fragility.soil.values:
        hazard = hazard_of(str(soil))
        for block in fragility.block.values:
            cap = float(fragility.credible_max.sel(block=block))
            for model in fragility.model.values:
                for state in fragility.damage_state.values:
                    where = dict(soil=soil, block=block, model=model, damage_state=state)
                    row = fragility.sel(**where)
                    block_levels = levels.sel(block=block).values if levels is not None else None
                    fractions = row.empirical_fraction.values if "empirical_fraction" in row else None
                    credible = None if block_levels is None else block_levels <= cap * (1 + 1e-9)
                    frequency.loc[where] = capped_frequency(
                        float(row["median"]), float(row["beta"]), hazard, cap,
                        None if credible is None else block_levels[credible],
                        None if credible is None or fractions is None else fractions[credible])
                    above.loc[where] = float(hazard_frequency(hazard, cap)) if hazard is not None else np.nan
    risk = risk.assign(annual_frequency=frequency.assign_attrs(risk.annual_frequency.attrs),
                       probability_in_life=(frequency.dims, probability_in_life(frequency.values, design_life),
                                            risk.probability_in_life.attrs),
                       annual_frequency_above_cap=above.assign_attrs(
                           long_name="the hazard's exceedance of the credible cap, added to annual_frequency as an "
                                     "upper bound on the part above the cap", units="yr-1"))
    risk.attrs["risk_bound"] = RISK_BOUND
    return risk


TEXT_LABELS = {
    "model": "rocking model whose runs the row fits (housner: rigid base; ssi: the paper's spring-dashpot "
             "foundation; recommended: the tensionless bed the answer uses, the central member of its sample)",
    "model_label": "the model's name in words",
    "damage_state": "damage state (rockfrag.damage_states: its measure and threshold)",
    "damage_state_description": "what the damage state means, in words",
    "outcome_class": "outcome of a run: no_uplift, rocking (lifted, not overturned) or overturned",
    "fit_warning": "warnings about the fit, in words (empty: none)",
}
"""CF long names of fragility.nc's text coordinates and variables (units: none, they are labels)."""


def label_text_variables(dataset: xr.Dataset) -> xr.Dataset:
    """``dataset`` with a CF ``long_name`` on each text coordinate and variable that lacks one (``TEXT_LABELS``)."""
    labelled = dataset.copy()
    for name, words in TEXT_LABELS.items():
        if name in labelled.variables and "long_name" not in labelled[name].attrs:
            labelled[name].attrs["long_name"] = words
    return labelled


def fragility_stage(cube: xr.Dataset, ida: xr.Dataset, config: StudyConfig, output: str | Path,
                    progress: bool | None = None,
                    log: Callable[[str], object] | None = None) -> tuple[xr.Dataset, xr.Dataset]:
    """Fit, add the risk, and write fragility.nc, fragility.csv and the exchange files (``rockfrag.exchange``).

    The hazard curve of each soil's site is read (and checked against the study's intensity measure) before any
    fit (rockfrag.site_hazard); each soil's risk uses its own, and fragility.nc holds them as ``site_hazard``.
    Fit warnings are printed to ``log`` (stderr by default) and kept in the dataset.

    Parameters
    ----------
    cube : xarray.Dataset
        The study cube (``cube.nc``).
    ida : xarray.Dataset
        The IDA curves and refined capacities (``ida.nc``).
    config : StudyConfig
        The study: damage states, bootstrap size and seed, confidence, hazard file and design life [years].
    output : str or pathlib.Path
        The output folder; the three files are written atomically into it.
    progress : bool, optional
        Show a progress bar; default: when stderr is a terminal.
    log : callable, optional
        Receives one line per fit warning; default: print to stderr.

    Returns
    -------
    fragility : xarray.Dataset
        The fits merged with the risk (as written to ``fragility.nc``).
    risk : xarray.Dataset
        The annual frequency and the probability in the design life per row.

    Raises
    ------
    ConfigError
        A hazard curve that does not load or is for another intensity measure; clashing pelicun IDs.
    """
    log = log or (lambda message: print(message, file=sys.stderr))
    progress = sys.stderr.isatty() if progress is None else progress
    output = Path(output)
    hazard = study_site_hazards(config)  # each soil's site curve
    states = damage_states_from_config(config.raw)
    dataset = fragility_dataset(cube, states=states, ida=ida, n_bootstrap=config.bootstrap, seed=config.seed,
                                confidence=config.confidence, progress=progress, quality=config.model_quality)
    for line in json.loads(dataset.attrs["fit_warnings"]):
        log(f"fragility note: {line}")
    # each soil's risk stops at its block's credible cap and adds the cap's exceedance as a bound (capped_risk)
    risk = capped_risk(dataset, risk_dataset(dataset, hazard, config.design_life),
                       lambda soil: hazard[soil] if isinstance(hazard, Mapping) else hazard, config.design_life)
    # the curve each soil's risk used: site_hazard(soil, hazard_intensity)
    sites = site_hazard_dataset(hazard, config.soils, config.measure) if hazard is not None else xr.Dataset()
    combined = dataset.merge(risk).merge(sites)
    combined.attrs.update(dataset.attrs)
    combined.attrs.update(risk.attrs)
    combined.attrs.update(sites.attrs)
    write_dataset(label_text_variables(combined), output / "fragility.nc")
    table = fragility_table(dataset)
    table = table.merge(risk.to_dataframe().reset_index(), on=["soil", "block", "model", "damage_state"])
    write_csv(table, output / "fragility.csv")
    if output / OPENQUAKE_FILE not in write_exchange_files(dataset, output, getattr(config, "period", None)):
        log(f"rockfrag: no {OPENQUAKE_FILE}: OpenQuake has no intensity measure type for "
            f"{dataset.attrs.get('intensity_measure')}")
    return combined, risk
