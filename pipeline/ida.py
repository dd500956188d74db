"""rockfrag.ida - stage 7: the cube -> incremental dynamic analysis (IDA) curves and capacities.

Input : the study cube (``cube.nc``): peak_angle_ratio and outcome over (record, im_level, soil,
        block, model).
Output: ``reports/ida.nc`` with, per soil, block and model:
        - ``edp``: the IDA curve of each record, theta_max/alpha against the intensity level, with
          overturned runs as +inf (the flatline) and NOT smoothed: a record may overturn at one level
          and survive a higher one ("resurrection"), and that stays visible;
        - ``edp_fractile``: 16/50/84% fractiles of the response given intensity (counted, inf-aware);
        - ``im_fractile``: 16/50/84% fractiles of the intensity given response (from each record's
          first crossing of the response level);
        - ``first_overturn_im`` and ``last_resurrection_free_im``: per-record overturning capacity, as
          the first overturning level and the level above which every level overturns;
        - ``capacity``: per-record overturning capacity from the study's adaptive runs (the stripes
          refined by bisection to the study's ``capacity_resolution``), its bracket
          ``capacity_lower``/``capacity_upper`` (the highest intensity seen to survive below it, the
          lowest seen to overturn), the runs it took and, as attributes, the runs saved against
          uniform stripes of the same resolution.
Intensities are per block: the cube's (block, im_level) coordinate ``intensity``, in the measure's display
unit, written as UDUNITS parses it ("9.80665 m s-2" for g; ``rockfrag.measures.parse_units``).

Capacity convention (Vamvatsikos & Cornell 2002): a record's overturning capacity is its FIRST
overturning intensity; a record that survives a higher level (resurrection) is still taken to have
overturned there. The refinement bisects the gap between the first overturning stripe and the stripe
below it, so a refined capacity never exceeds ``first_overturn_im``.
``hunt_and_fill`` traces one record's overturning capacity adaptively (Vamvatsikos & Cornell 2004).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import xarray as xr

from rockfrag.cube import OUTCOME_FAILED, OUTCOME_FREE_FLIGHT, OUTCOME_OVERTURNED
from rockfrag.measures import convert_units, parse_units, udunits
from rockfrag.outputs import write_dataset

FRACTILES = (0.16, 0.50, 0.84)
FRACTILE_ATTRS = {"long_name": "fractile (non-exceedance probability) over the records", "units": "1"}
RESPONSE_LEVELS = np.round(np.concatenate([np.linspace(0.05, 1.0, 20), np.linspace(1.5, 5.0, 8)]), 4)
"""Response levels theta_max/alpha at which the intensity-given-response fractiles are computed."""


def ida_edp(cube: xr.Dataset) -> xr.DataArray:
    """theta_max/alpha per run, +inf where the block overturned (the IDA flatline)."""
    edp = cube.peak_angle_ratio.where(cube.outcome != OUTCOME_OVERTURNED, np.inf)
    edp.attrs = {"long_name": "peak rocking angle over alpha (inf = overturned)", "units": "1"}
    return edp


def first_crossing_im(edp, levels, threshold):
    """Per record: the intensity at which the IDA curve first reaches ``threshold``.

    Linear interpolation between the last level below and the first level at or above; where the
    first level at or above is the overturning flatline, that level. NaN if never reached.
    edp : (n_record, n_level); levels : (n_level,).
    """
    capacity = np.full(edp.shape[0], np.nan)
    for r, curve in enumerate(edp):
        above = np.flatnonzero(curve >= threshold)
        if above.size == 0:
            continue
        j = above[0]
        if j == 0 or not np.isfinite(curve[j]):
            capacity[r] = levels[j]
            continue
        lower, upper = curve[j - 1], curve[j]  # lower < threshold <= upper
        capacity[r] = levels[j - 1] + (threshold - lower) / (upper - lower) * (levels[j] - levels[j - 1])
    return capacity


def overturning_capacities(outcome, levels):
    """Per record: the first overturning level, and the lowest level from which every higher level overturns.

    The second has no resurrection above it. NaN where the block does not overturn / still survives at
    the highest level. outcome : (n_record, n_level) integer outcome codes.
    """
    overturned = outcome == OUTCOME_OVERTURNED
    first = np.full(overturned.shape[0], np.nan)
    stable = np.full(overturned.shape[0], np.nan)
    for r, row in enumerate(overturned):
        hits = np.flatnonzero(row)
        if hits.size == 0:
            continue
        first[r] = levels[hits[0]]
        if row[-1]:
            survivors = np.flatnonzero(~row)
            stable[r] = levels[survivors[-1] + 1] if survivors.size else levels[0]
    return first, stable


def resurrected(outcome) -> np.ndarray:
    """1 where a record survived a level above its first overturning level (resurrection), else 0.

    outcome : (..., n_level) integer outcome codes over increasing levels; a failed run is no survival, nor
    is a run stopped in free flight (g + a_v < 0: whether it would have overturned is unknown).
    Returns an int8 array of shape (...,).
    """
    outcome = np.asarray(outcome)
    overturned = outcome == OUTCOME_OVERTURNED
    after_first = np.cumsum(overturned, axis=-1) > 0
    survived = ~overturned & (outcome != OUTCOME_FAILED) & (outcome != OUTCOME_FREE_FLIGHT)
    return np.any(after_first & survived, axis=-1).astype(np.int8)


def block_intensities(cube: xr.Dataset) -> tuple[np.ndarray, str]:
    """(n_block, n_level) intensity of every level for every block [display unit], and its ``units``.

    Reads the (block, im_level) coordinate ``intensity`` (rockfrag.cube); a cube without it (absolute
    levels from an older layout) has the same levels ``im_level`` for every block. The units come back as
    UDUNITS parses them (an older file's "g" becomes "9.80665 m s-2").
    """
    if "intensity" in cube.coords or "intensity" in cube:
        values = cube["intensity"].transpose("block", "im_level").values
        return values, _canonical(cube["intensity"].attrs.get("units", ""))
    levels = cube.im_level.values
    return np.broadcast_to(levels, (cube.sizes["block"], levels.size)), _canonical(cube.im_level.attrs.get("units", ""))


def _canonical(units: str) -> str:
    """``units`` as UDUNITS writes it (``rockfrag.measures.udunits``), unchanged when not an intensity unit."""
    parsed = parse_units(units)
    return units if parsed is None else udunits(parsed[1], parsed[0])


def adaptive_capacities(cube: xr.Dataset) -> xr.Dataset | None:
    """Overturning capacity of every (record, soil, block, model) from the adaptive runs, with its bracket.

    In the study's measure [the unit of the cube's ``intensity``]: scale factor x the record's measure.
    None without adaptive runs. Variables ``capacity``, ``capacity_lower`` and ``capacity_upper``.
    """
    if "capacity_scale_factor" not in cube:
        return None
    _, units = block_intensities(cube)
    record_im = cube["record_im"]
    record_im = record_im.copy(data=convert_units(record_im.values, record_im.attrs.get("units", ""), units))
    resolution = cube.attrs.get("capacity_resolution", float("nan"))
    out = {}
    for name, source, long_name in (
            ("capacity", "capacity_scale_factor",
             f"overturning capacity from adaptive runs, bracketed to {resolution:.0%} (NaN: no overturning found)"),
            ("capacity_lower", "capacity_scale_lower", "highest intensity seen to survive below the capacity"),
            ("capacity_upper", "capacity_scale_upper", "lowest intensity seen to overturn (the capacity bracket)")):
        capacity = (cube[source] * record_im).transpose("record", "soil", "block", "model")
        capacity.attrs = {"long_name": long_name, "units": units}
        out[name] = capacity
    return xr.Dataset(out)


def ida_dataset(cube: xr.Dataset) -> xr.Dataset:
    """All IDA products of a cube (see the module docstring)."""
    edp = ida_edp(cube)
    intensities, unit = block_intensities(cube)
    edp_fractile = xr.DataArray(
        np.quantile(edp.values, FRACTILES, axis=0, method="inverted_cdf"),
        dims=("fractile", *edp.dims[1:]),
        coords={"fractile": ("fractile", list(FRACTILES), FRACTILE_ATTRS), **{d: cube[d] for d in edp.dims[1:]}},
        attrs={"long_name": "fractile of theta_max/alpha given intensity (inf = overturned)", "units": "1"})
    stack_dims = ("soil", "block", "model")
    block_axis = stack_dims.index("block")
    shape = tuple(cube.sizes[d] for d in stack_dims)
    first = np.full((cube.sizes["record"], *shape), np.nan)
    stable = np.full_like(first, np.nan)
    im_given_edp = np.full((len(FRACTILES), RESPONSE_LEVELS.size, *shape), np.nan)
    edp_t = edp.transpose("record", "im_level", *stack_dims).values
    outcome_t = cube.outcome.transpose("record", "im_level", *stack_dims).values
    for index in np.ndindex(*shape):
        levels = intensities[index[block_axis]]
        curves = edp_t[(slice(None), slice(None), *index)]
        first[(slice(None), *index)], stable[(slice(None), *index)] = overturning_capacities(
            outcome_t[(slice(None), slice(None), *index)], levels)
        for j, response in enumerate(RESPONSE_LEVELS):
            capacity = first_crossing_im(curves, levels, response)
            # records that never reach the response are above the highest level: inf for fractiles
            capacity = np.where(np.isnan(capacity), np.inf, capacity)
            im_given_edp[(slice(None), j, *index)] = np.quantile(capacity, FRACTILES, method="inverted_cdf")
    im_given_edp[~np.isfinite(im_given_edp)] = np.nan
    coords = {d: cube[d] for d in ("record", "im_level", *stack_dims)}
    if parse_units(cube.im_level.attrs.get("units", "")) == parse_units(unit):
        coords["im_level"] = cube.im_level.assign_attrs(units=unit)  # an older file's "g", spelled as UDUNITS reads
    if "intensity" in cube.coords:
        coords["intensity"] = cube["intensity"].assign_attrs(units=unit)
    data_vars = {
        "edp": edp,
        "edp_fractile": edp_fractile,
        "im_fractile": (("fractile", "response_level", *stack_dims), im_given_edp,
                        {"long_name": "fractile of the intensity at which theta_max/alpha is first reached "
                                      "(NaN: above the highest level)", "units": unit}),
        "first_overturn_im": (("record", *stack_dims), first,
                              {"long_name": "first intensity level at which the block overturned", "units": unit}),
        "last_resurrection_free_im": (("record", *stack_dims), stable,
                                      {"long_name": "intensity above which every level overturns "
                                                    "(no resurrection)", "units": unit}),
        "resurrected": (("record", *stack_dims), resurrected(np.moveaxis(outcome_t, 1, -1)),
                        {"long_name": "1 if the block survived a level above its first overturning level",
                         "units": "1"}),
    }
    capacities = adaptive_capacities(cube)
    attrs = {"Conventions": "CF-1.12", "title": "rockfrag IDA curves",
             "source": cube.attrs.get("source", ""), "config_hash": cube.attrs.get("config_hash", "")}
    if capacities is not None:
        data_vars.update(capacities.data_vars)
        data_vars["capacity_runs"] = cube["capacity_runs"]
        for ida_key, cube_key in (("capacity_resolution", "capacity_resolution"),
                                  ("capacity_refining_runs", "capacity_runs"),
                                  ("capacity_stripe_runs", "grid_runs"),
                                  ("capacity_uniform_stripe_runs", "uniform_runs"),
                                  ("capacity_runs_saved_fraction", "runs_saved_fraction")):
            if cube_key in cube.attrs:
                attrs[ida_key] = cube.attrs[cube_key]
    dataset = xr.Dataset(data_vars, coords={**coords, "fractile": ("fractile", list(FRACTILES), FRACTILE_ATTRS),
                         "response_level": ("response_level", RESPONSE_LEVELS,
                                            {"long_name": "theta_max/alpha", "units": "1"})})
    dataset.attrs = attrs
    return dataset


def fill(overturns, lower, upper, tolerance=0.02, max_runs=200):
    """Bisect a bracket (``lower`` survives, ``upper`` overturns) until (upper - lower) <= tolerance x upper.

    Returns (lower, upper, runs).
    """
    runs = 0
    while (upper - lower) > tolerance * upper and runs < max_runs:
        middle = 0.5 * (lower + upper)
        runs += 1
        if overturns(middle):
            upper = middle
        else:
            lower = middle
    return lower, upper, runs


def hunt_and_fill(overturns, start, step=0.1, growth=1.5, tolerance=0.02, max_runs=200, lower=0.0,
                  limit=math.inf):
    """Adaptive overturning capacity of one record (hunt up, then fill by bisection).

    Parameters
    ----------
    overturns : callable(im) -> bool
        Runs the analysis at intensity ``im`` and says whether the block overturned.
    start : float
        First intensity to try (below the expected capacity).
    step, growth : float
        First hunting increment and its growth factor per step (Vamvatsikos & Cornell).
    tolerance : float
        Relative width of the final bracket [-].
    lower : float
        An intensity known to survive (below ``start``).
    limit : float
        The highest intensity the hunt may try (the credible cap): a record that survives it is censored there.

    Returns
    -------
    (capacity, lower, upper, runs): capacity is the bracket midpoint of the first overturning
    intensity found by the hunt (NaN if none within ``max_runs`` or up to ``limit``; ``lower`` is then the
    highest intensity seen to survive).
    """
    runs = 0
    im, increment = min(start, limit), step
    while runs < max_runs:
        if im <= lower * (1 + 1e-9):  # the limit lies at (or below) an intensity already seen to survive
            return math.nan, lower, math.nan, runs
        runs += 1
        if overturns(im):
            upper = im
            break
        lower = im
        if im >= limit:
            return math.nan, lower, math.nan, runs
        im = min(im + increment, limit)
        increment *= growth
    else:
        return math.nan, lower, math.nan, runs
    lower, upper, fill_runs = fill(overturns, lower, upper, tolerance, max_runs - runs)
    return 0.5 * (lower + upper), lower, upper, runs + fill_runs


def capacity_from_stripes(scales, overturned, overturns, tolerance=0.02, max_runs=60, limit=math.inf):
    """Overturning capacity of one record as a scale factor, refining the study's stripes.

    The stripes already ran (``overturned[j]`` at ``scales[j]``, increasing) and are the hunt:
    the first overturning stripe and the stripe below it bracket the first overturning intensity,
    which ``fill`` then bisects to ``tolerance``. A record that survives every stripe is hunted on
    upwards from the top stripe (``hunt_and_fill``); one that overturns at the lowest stripe is
    bracketed downwards by halving. ``overturns(scale) -> bool`` runs the solver. The hunt stops at ``limit``
    (the credible cap as a scale factor): a record that survives it is censored there (NaN capacity).

    Returns (capacity, lower, upper, runs): capacity is the bracket midpoint (NaN if the record
    never overturned within ``max_runs`` extra runs); runs counts the extra solver runs only.
    """
    scales = np.asarray(scales, float)
    hits = np.flatnonzero(np.asarray(overturned, bool))
    if hits.size == 0:
        top = scales[-1]
        step = top * (scales[-1] / scales[-2] - 1.0) if scales.size > 1 else 0.1 * top
        return hunt_and_fill(overturns, top + step, step=step, growth=1.5, tolerance=tolerance,
                             max_runs=max_runs, lower=top, limit=limit)
    upper = scales[hits[0]]
    runs = 0
    if hits[0] > 0:
        lower = scales[hits[0] - 1]
    else:
        lower = 0.5 * upper
        while runs < max_runs:
            runs += 1
            if not overturns(lower):
                break
            upper, lower = lower, 0.5 * lower
    lower, upper, fill_runs = fill(overturns, lower, upper, tolerance, max_runs - runs)
    return 0.5 * (lower + upper), lower, upper, runs + fill_runs


def uniform_stripe_runs(bottom, top, tolerance) -> int:
    """Stripes per record a uniform (geometric) grid needs from ``bottom`` to ``top``.

    Neighbouring stripes are then ``tolerance`` apart, i.e. the resolution ``capacity_from_stripes`` gives.
    """
    return int(math.ceil(math.log(top / bottom) / math.log(1.0 + tolerance))) + 1


def ida_stage(cube: xr.Dataset, output: str | Path) -> xr.Dataset:
    """Compute the IDA products of a cube and write ``ida.nc`` into ``output``."""
    dataset = ida_dataset(cube)
    write_dataset(dataset, Path(output) / "ida.nc")
    return dataset
