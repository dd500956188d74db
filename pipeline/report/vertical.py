"""rockfrag.report.vertical - the effect of the vertical component: the same records with and without it.

Input : the study cube ``cube.nc`` of a ``[study] vertical = true`` study (every record run with its
        station's vertical component), its comparison cube ``cube_without_vertical.nc``
        (``rockfrag.cube.COMPARISON_CUBE``: the same records, levels and scale factors, horizontal components
        alone) and the study's damage states.
Output: ``VerticalEffect`` (both cubes and their fits), the figure page of a block (``vertical_page``: median
        IDA curves and overturning fractions with and without the vertical, per soil) and the table of the
        report's "Vertical component" page (``vertical_items``: fragility medians and median capacities with
        and without, per block, model and soil, with the share of runs in free flight).

Both sides are fitted alike (rockfrag.fragility.fragility_dataset, no bootstrap: the point estimates are
those of fragility.nc for cube.nc), the capacities of both from their refined IDA runs (rockfrag.ida). Runs
that stopped in free flight (g + a_v < 0 under a pivot model) are censored by ``fragility.exceedance``;
where most runs of a level flew, the pivot models say nothing about overturning there, and the page says so.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from rockfrag.cube import COMPARISON_CUBE, OUTCOME_FAILED, OUTCOME_FREE_FLIGHT, OUTCOME_OVERTURNED, VERTICAL_APPLIED
from rockfrag.damage_states import DamageState
from rockfrag.fragility import exceedance, first_overturn_outcomes, fragility_dataset, lognormal_cdf
from rockfrag.ida import ida_dataset
from rockfrag.report.adapters import (
    block_levels,
    cell,
    measure_label,
    model_styles,
    models_of,
    panel_label,
    soils_of,
)
from rockfrag.report.figures import axis_range, mark_intensities
from rockfrag.report.layout import OUTCOME_COLOURS, log_axis, log_y_axis, new_page, outside_legend, panels
from rockfrag.report.text import Item, heading, note, paragraph, table

IDA_CAP = 1.6  # theta_max/alpha drawn for overturned runs (as on the IDA pages)
MOST_FLEW = 0.5  # a level's median IDA point is not drawn where more than this share of the runs flew
MAX_SOILS = 3  # soil columns of the figure page (the softest, ..., the stiffest)
FLIGHT_MARKERS = ("x", "+", "1", "2")  # the free-flight share of each model, in the outcome colour of free flight


@dataclass(frozen=True)
class VerticalEffect:
    """A ``[study] vertical = true`` study's two cubes and their fits.

    Attributes
    ----------
    cube, comparison : xarray.Dataset
        ``cube.nc`` (with the vertical components) and ``cube_without_vertical.nc``.
    fits : dict
        ``True``/``False`` (with/without the vertical) -> the fragility dataset of that cube (no bootstrap,
        with the refined-capacity check ``capacity_median``).
    """

    cube: xr.Dataset
    comparison: xr.Dataset
    fits: dict


def open_comparison(cube: xr.Dataset, output) -> xr.Dataset | None:
    """The comparison cube beside ``cube.nc`` in ``output``, or None.

    None unless ``cube`` applied the vertical components and the file is that study's (same configuration
    hash, same records): a file an earlier study left in the folder is not read.
    """
    path = Path(output) / COMPARISON_CUBE
    if cube.attrs.get("vertical") != VERTICAL_APPLIED or not path.is_file():
        return None
    with xr.open_dataset(path) as dataset:
        comparison = dataset.load()
    same = (comparison.attrs.get("config_hash") == cube.attrs.get("config_hash")
            and list(map(str, comparison.record.values)) == list(map(str, cube.record.values)))
    return comparison if same else None


def vertical_effect(cube: xr.Dataset, comparison: xr.Dataset, states: list[DamageState]) -> VerticalEffect:
    """Fit both cubes alike (``fragility_dataset`` with the refined capacities of ``ida_dataset``, no bootstrap).

    Parameters
    ----------
    cube, comparison : xarray.Dataset
        ``cube.nc`` (with the verticals) and ``cube_without_vertical.nc``.
    states : list of DamageState
        The study's damage states (``rockfrag.damage_states.damage_states_from_config``).

    Returns
    -------
    VerticalEffect
    """
    fits = {applied: fragility_dataset(dataset, states, ida=ida_dataset(dataset), n_bootstrap=0)
            for applied, dataset in ((True, cube), (False, comparison))}
    return VerticalEffect(cube, comparison, fits)


def free_flight_share(cube: xr.Dataset) -> xr.DataArray:
    """Share of the runs that did not fail and stopped in free flight, per level, soil, block and model."""
    outcome = cube.outcome
    valid = outcome != OUTCOME_FAILED
    return (outcome == OUTCOME_FREE_FLIGHT).sum("record") / valid.sum("record").where(valid.sum("record") > 0)


def median_ida(cube: xr.Dataset) -> xr.DataArray:
    """Median theta_max/alpha over the records per level (inf: overturned), the first-overturn convention.

    Runs that stopped in free flight are left out (their peak angle is only a lower bound); NaN at levels
    where more than ``MOST_FLEW`` of the runs flew, or none is known.
    """
    outcome = first_overturn_outcomes(cube)
    edp = cube.peak_angle_ratio.where(outcome != OUTCOME_OVERTURNED, np.inf)
    known = (outcome != OUTCOME_FAILED) & (outcome != OUTCOME_FREE_FLIGHT)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a level with no known run: NaN
        median = edp.where(known).reduce(np.nanmedian, dim="record")
    return median.where(free_flight_share(cube) <= MOST_FLEW)


def _capped(values):
    return np.where(np.isnan(values), np.nan, np.minimum(values, IDA_CAP))


def _soils_shown(cube) -> list[str]:
    soils = list(map(str, cube.soil.values))
    if len(soils) <= MAX_SOILS:
        return soils
    return [soils[round(i * (len(soils) - 1) / (MAX_SOILS - 1))] for i in range(MAX_SOILS)]


def vertical_page(effect: VerticalEffect, block, caption, marks=None, name: str | None = None):
    """One column per soil: the median IDA curves (top) and the overturning fractions and fits (bottom).

    Every model in its colour, solid with the vertical, dashed without it; the share of runs in free
    flight in the outcome colour of free flight.
    """
    cube = effect.cube
    models = models_of(cube)
    styles = model_styles(models)
    soils = _soils_shown(cube)
    figure = new_page(f"Vertical component: {name or block}", caption)
    axes = panels(figure, 2, len(soils), sharey="row", gridspec_kw=dict(hspace=0.38))
    levels = block_levels(cube, block)
    medians = {applied: median_ida(dataset) for applied, dataset in ((True, cube), (False, effect.comparison))}
    overturning = {applied: exceedance(dataset, _overturning(effect.fits[applied]))
                   for applied, dataset in ((True, cube), (False, effect.comparison))}
    flew = free_flight_share(cube)
    grid = np.geomspace(levels[0], levels[-1], 200)
    for column, soil in enumerate(soils):
        top, bottom = axes[0, column], axes[1, column]
        for model in models:
            colour = styles[model.name]["color"]
            for applied, dash in ((True, "-"), (False, "--")):
                label = f"{panel_label(model)}, {'with' if applied else 'without'} the vertical"
                curve = cell(medians[applied].to_dataset(name="m"), model, block, soil)["m"].values
                top.plot(_capped(curve), levels, color=colour, ls=dash, lw=1.4, marker="o", ms=2.5, label=label)
                fraction = cell(overturning[applied].mean("record").to_dataset(name="p"), model, block, soil)["p"]
                bottom.plot(levels, fraction.values, "o" if applied else "s", ms=3, color=colour, alpha=0.7,
                            mfc=colour if applied else "none")
                fit = cell(effect.fits[applied], model, block, soil).sel(damage_state=_overturning(
                    effect.fits[applied]).name)
                median, beta = float(fit["median"]), float(fit["beta"])
                if np.isfinite(median) and np.isfinite(beta) and beta > 0:
                    bottom.plot(grid, lognormal_cdf(grid, median, beta), color=colour, ls=dash, lw=1.4)
            share = cell(flew.to_dataset(name="f"), model, block, soil)["f"].values
            if np.nansum(share) > 0:
                bottom.plot(levels, share, color=OUTCOME_COLOURS["free_flight"], ls=":", lw=2.0,
                            marker=FLIGHT_MARKERS[models.index(model) % len(FLIGHT_MARKERS)], ms=5,
                            label=f"{panel_label(model)}: share of runs in free flight (with the vertical)")
        top.axvline(IDA_CAP, color="0.3", lw=0.6, ls=":")
        top.set_xlim(0, IDA_CAP * 1.05)
        log_y_axis(top, axis_range(levels, marks))
        mark_intensities(top, marks, along="y", soil=soil)
        top.set_title(f"median IDA curve on {soil}", fontsize=9)
        top.set_xlabel("median θmax/α [-]")
        top.grid(alpha=0.3, which="both")
        log_axis(bottom, axis_range(levels, marks))
        mark_intensities(bottom, marks, along="x", soil=soil)
        bottom.set_ylim(-0.02, 1.02)
        bottom.set_title(f"overturning on {soil}", fontsize=9)
        bottom.set_xlabel(measure_label(cube))
        bottom.grid(alpha=0.3, which="both")
    axes[0, 0].set_ylabel(measure_label(cube))
    axes[1, 0].set_ylabel("probability of overturning [-]")
    axes[0, 0].plot([], [], color="0.3", lw=0.6, ls=":", label=f"overturned (drawn at {IDA_CAP})")
    outside_legend(figure, list(axes.flat))
    return figure


def _overturning(fragility) -> DamageState:
    """The overturning state of a fragility dataset (edp ``overturned``)."""
    names = [str(s) for s in fragility.damage_state.values]
    name = "overturning" if "overturning" in names else names[-1]
    return DamageState(name, "overturned", 1.0, "")


def _pair(with_value, without_value) -> str:
    def shown(value):
        return f"{value:.3g}" if np.isfinite(value) else "-"

    text = f"{shown(with_value)} / {shown(without_value)}"
    if np.isfinite(with_value) and np.isfinite(without_value) and without_value > 0:
        text += f" ({with_value / without_value - 1:+.0%})"
    return text


def vertical_items(effect: VerticalEffect, names: dict | None = None) -> list[Item]:
    """The table page: per block, model and soil, medians with / without the vertical and the free-flight share.

    ``names``: block -> the name the client knows it by (``[report] block_names``).
    """
    from rockfrag.report.adapters import short_label, state_labels
    from rockfrag.report.layout import pretty

    cube, fits = effect.cube, effect.fits
    states = [str(s) for s in fits[True].damage_state.values]
    shown_states = states[-2:]
    labels = state_labels(fits[True]) if "damage_state_description" in fits[True].coords else {}
    unit = measure_label(cube)
    flew = free_flight_share(cube)
    header = ["block", "model", "soil"] + [f"{pretty(labels.get(s, s))}: median with / without"
                                           for s in shown_states] + [
        "capacity median with / without", "runs in free flight"]
    rows = []
    for block in map(str, cube.block.values):
        for model in models_of(cube):
            own = soils_of(fits[True], model, block, "median")  # [None]: a rigid base the same on every soil
            for soil in ["(any)" if s is None else s for s in own]:
                picked = {applied: cell(fits[applied], model, block, None if soil == "(any)" else soil)
                          for applied in (True, False)}
                row = [(names or {}).get(block, block), short_label(model), soil]
                for state in shown_states:
                    row.append(_pair(*(float(picked[a]["median"].sel(damage_state=state)) for a in (True, False))))
                row.append(_pair(*(float(picked[a]["capacity_median"].sel(damage_state=shown_states[-1]))
                                   for a in (True, False))))
                share = float(cell(flew.mean("im_level").to_dataset(name="f"), model, block,
                                   None if soil == "(any)" else soil)["f"])
                row.append(f"{share:.0%}" if np.isfinite(share) else "-")
                rows.append(row)
    n_with = int(cube.vertical_applied.sum()) if "vertical_applied" in cube else cube.sizes["record"]
    ratio = (np.asarray(cube.record_vertical_pga.values, float) / np.asarray(cube.record_pga.values, float)
             if "record_vertical_pga" in cube.coords else np.array([np.nan]))
    return [
        paragraph(f"The {n_with} records of this study ran twice at the same levels and scale factors: with their "
                  "station's vertical component (gravity g + a_v(t) in every model, a_v scaled with the "
                  f"horizontal, so the vertical-to-horizontal PGA ratio, {np.nanmin(ratio):.2f} to "
                  f"{np.nanmax(ratio):.2f} here, is kept) and without it. Medians in {unit} "
                  "(stripe fits of both cubes alike; capacity: lognormal fit of the refined overturning "
                  "capacities), with / without the vertical, and the change in percent."),
        table(header, rows),
        heading("Free flight"),
        note("Where g + a_v(t) < 0 the ground falls faster than gravity and the block leaves it: the pivot models "
             "(Housner, SSI) have no flight phase and stop there (free flight); the Winkler bed flies on. "
             "Such a run counts as uplifted, as reaching a rocking state only if it did before the stop, and as "
             "unknown for overturning (censored). A '-' with the vertical where the run without it has a median: "
             "the free-flight runs left too few known outcomes for a fit. Share of runs in free flight: over all "
             "levels of the block."),
    ]
