"""rockfrag.steps - stage 6b: the study's separated fragility rows -> runs between the levels that place each step.

Input : the study's cube before it is written (``rockfrag.cube``), its damage states, the blocks, the resolution
        (``[intensity] capacity_resolution``) and ``run(requests)``: the study's solvers running every record of a
        cell at each requested intensity, from checkpoints where they exist (``rockfrag.study.step_runs``).
Output: the cube with the step runs (``step_intensity`` and ``step_X`` over ``rockfrag.cube.STEP_LEVEL``), the cells
        whose rows were refined (``step_refined``) and what it took (attributes ``step_resolution``, ``step_runs``,
        ``step_rows``). ``rockfrag.fragility`` merges the runs between the levels and says in each step row's
        ``step_method`` how it was placed.

A row whose counts are perfectly separated (no record in the state at one level, every record at the next, or one
mixed level between them: ``rockfrag.lognormal_fit.separation``) has no lognormal MLE: it is a step (beta = 0), and
the levels only bracket its threshold. The study bisects each such row of the cube's models (housner, ssi, the
recommended central member: the published fits; the sample members beside the centre live apart and are not
refined) as it bisects the overturning capacities (``rockfrag.ida.fill``): every record of the cell runs at the
geometric middle of the bracket; none in the state raises the lower end, all lowers the upper end; some gives the row
a mixed intensity, and it is then fitted as a curve where the counts allow one, or stays a step at that intensity,
whose bracket is bisected on (its wider side first). It stops when upper - lower <= resolution x upper. A run at one
intensity counts for every damage state of its cell (as a level does), so rows that share a bracket share the runs.
Rows placed exactly need none: a tied pivot model's uplift under PGA (``rockfrag.fragility.exact_uplift_thresholds``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import xarray as xr

from rockfrag.cube import STEP_LEVEL, STEP_RUN_VARIABLES, summaries_to_variables
from rockfrag.damage_states import DamageState
from rockfrag.fragility import fit_inputs, intensity_levels, step_bracket
from rockfrag.measures import parse_units
from rockfrag.models.base import Outcome
from rockfrag.models.fields import SUMMARY_DTYPE, new_summaries

MAX_ROUNDS = 12
"""Bisection rounds at most (a bracket 30% wide reaches 2% in 4; a mixed intensity splits it in two)."""

Request = tuple[tuple[int, int, int], float]
"""One intensity to run every record of a cell at: ((soil, block, model) indices, intensity [SI])."""


def bisection_intensity(levels, exceed, total, resolution) -> float | None:
    """The next intensity [the levels' unit] at which a separated row's records run, or None: done.

    The geometric middle of the bracket (``rockfrag.fragility.step_bracket``), or with a mixed intensity inside it
    the middle of its wider side. None when the bracket is open (the step lies at the edge of the levels) or already
    within the resolution (upper - lower <= resolution x upper).
    """
    lower, upper, mixed = step_bracket(np.asarray(levels, float), np.asarray(exceed, float),
                                       np.asarray(total, float))
    if not (np.isfinite(lower) and np.isfinite(upper)) or upper - lower <= resolution * upper * (1 + 1e-9):
        return None
    if np.isfinite(mixed):
        lower, upper = (lower, mixed) if mixed / lower >= upper / mixed else (mixed, upper)
    return float(np.sqrt(lower * upper))


def requested_runs(cube: xr.Dataset, states: list[DamageState], resolution: float, refine: np.ndarray
                   ) -> tuple[list[Request], dict]:
    """The intensities every cell still needs for its separated rows, and a count of the rows by status.

    ``refine`` (soil, block, model): the cells to refine. Rows are fitted as the fragility stage fits them
    (``rockfrag.fragility.fit_inputs``), step runs so far included.
    """
    inputs = fit_inputs(cube, states, fractions=False)
    si = parse_units(inputs.unit)[0]  # SI value of one display unit
    requests, separated = [], 0
    for index in zip(*np.nonzero(refine)):
        index = tuple(int(i) for i in index)
        rows, _ = inputs.fit(index, states)
        levels, _, exceed, total, _ = inputs.cell(index)
        wanted = []
        for s, row in enumerate(rows):
            if row.status != "separated":
                continue
            separated += 1
            target = bisection_intensity(levels, exceed[s], total[s], resolution)
            if target is not None and not any(np.isclose(target, w, rtol=1e-9) for w in wanted):
                wanted.append(target)
        requests += [(index, w * si) for w in wanted]
    return requests, {"separated": separated}


def with_step_runs(cube: xr.Dataset, found: dict, blocks: Sequence, refine: np.ndarray, states: list[DamageState]
                   ) -> xr.Dataset:
    """``cube`` with the step runs ``found`` {(soil, block, model): [(intensity [SI], summaries (n_record,))]}.

    Adds ``step_intensity`` [the levels' display unit], ``step_X`` for the per-run variables the damage states read
    (``rockfrag.cube.STEP_RUN_VARIABLES`` and each state's measure) and ``step_refined`` (``refine``).
    """
    _, unit = intensity_levels(cube)
    si = parse_units(unit)[0]
    cube = cube.drop_dims(STEP_LEVEL, errors="ignore")
    n_step = max([len(runs) for runs in found.values()], default=0)
    shape = (cube.sizes["soil"], cube.sizes["block"], cube.sizes["model"])
    summaries = new_summaries((cube.sizes["record"], max(n_step, 1), *shape))
    summaries["status"] = int(Outcome.FAILED)  # no run: unknown, left out of every count
    intensity = np.full((max(n_step, 1), *shape), np.nan)
    for index, runs in found.items():
        for j, (value, summary) in enumerate(sorted(runs, key=lambda run: run[0])):
            intensity[(j, *index)] = value / si
            summaries[(slice(None), j, *index)] = summary
    friction = np.stack([cube[name].transpose("soil", "block", "model").values if name in cube
                         else np.full(shape, np.nan) for name in ("friction_static", "friction_kinetic")])
    variables = summaries_to_variables(summaries, list(blocks), [str(m) for m in cube.model.values], friction)
    names = dict.fromkeys([*STEP_RUN_VARIABLES, *(state.edp for state in states)])
    dims = ("record", STEP_LEVEL, "soil", "block", "model")
    data = {"step_intensity": ((STEP_LEVEL, "soil", "block", "model"), intensity, {
        "long_name": "intensity at which every record of the cell ran to place a separated row's step between the "
                     "levels (NaN: no run)", "units": unit})}
    for name in names:
        if name in variables and name in cube:
            attrs = dict(cube[name].attrs)
            attrs["long_name"] = f"step run: {attrs.get('long_name', name)}"
            data[f"step_{name}"] = (dims, variables[name], attrs)
    data["step_refined"] = (("soil", "block", "model"), refine.astype(np.int8), {
        "long_name": "1 where the study bisected the cell's separated rows between the levels by runs",
        "units": "1", "flag_values": np.array([0, 1], np.int8), "flag_meanings": "not_refined refined"})
    return cube.assign(data)


def refine_steps(cube: xr.Dataset, states: list[DamageState], blocks: Sequence, resolution: float,
                 run: Callable[[list[Request]], np.ndarray], log: Callable[[str], object] | None = None,
                 refine: np.ndarray | None = None) -> xr.Dataset:
    """Bisect every separated row of ``cube`` by runs between its levels (see the module docstring).

    Parameters
    ----------
    cube : xarray.Dataset
        The study's cube (its ``model`` coordinate holds the published models; the sample members live apart).
    states : list of DamageState
        The study's damage states (``rockfrag.damage_states.damage_states_from_config``).
    blocks : sequence of rockfrag.blocks.Block
        The cube's blocks, in its order.
    resolution : float
        Relative width of the final bracket (``capacity_resolution``); 0: no runs (the rows keep the levels' bracket).
    run : callable
        ``run(requests)`` -> summaries (n_record, n_request) of ``rockfrag.models.fields.SUMMARY_DTYPE``: every
        record of each request's cell run at its intensity [SI] (a failed or lost run: status failed).
    log : callable, optional
        Receives one line on the runs taken.
    refine : numpy.ndarray, optional
        (soil, block, model) the cells to refine; default every cell.

    Returns
    -------
    xarray.Dataset
        ``cube`` with the step runs (``with_step_runs``) and the attributes ``step_resolution``, ``step_runs`` (solver
        runs requested, from checkpoints or run) and ``step_rows`` (the rows' counts in words).
    """
    shape = (cube.sizes["soil"], cube.sizes["block"], cube.sizes["model"])
    refine = np.ones(shape, bool) if refine is None or resolution <= 0 else np.asarray(refine, bool)
    if resolution <= 0:
        return cube.assign_attrs(step_resolution=0.0, step_runs=0)
    found: dict = {}
    initial = None
    n_runs = n_intensities = 0
    current = cube
    for _ in range(MAX_ROUNDS):
        requests, counts = requested_runs(current, states, resolution, refine)
        initial = counts["separated"] if initial is None else initial
        if not requests:
            break
        summaries = np.asarray(run(requests))
        n_runs += summaries.shape[0] * len(requests)
        n_intensities += len(requests)
        for j, (index, value) in enumerate(requests):
            found.setdefault(index, []).append((value, summaries[:, j].astype(SUMMARY_DTYPE)))
        current = with_step_runs(cube, found, blocks, refine, states)
    current = with_step_runs(cube, found, blocks, refine, states)
    _, counts = requested_runs(current, states, resolution, refine)
    rows = "no separated row" if not initial else (
        f"{initial} separated rows before the runs, {counts['separated']} after (the others gained a mixed intensity "
        "and are fitted curves)")
    if log is not None and initial:
        log(f"steps of separated fragility rows bisected to {resolution:.0%} between the levels: {n_runs} runs at "
            f"{n_intensities} intensities; {rows}")
    return current.assign_attrs(step_resolution=float(resolution), step_runs=int(n_runs), step_rows=rows)
