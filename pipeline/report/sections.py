"""pipeline.report.sections - the text of the report, generated from the study and its results.

Input : a ``Results`` bundle (study config, cube, ida, fragility + risk, showcase, output folder).
Output: lists of ``text.Item`` for the summary, methods and limitations pages. No number is typed in
        here: every value comes from the study configuration or the result files' attributes.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from pipeline import __version__
from pipeline.config import StudyConfig
from pipeline.fragility import STATUS
from pipeline.report.adapters import (
    OUTCOME_FAILED,
    OUTCOME_FREE_FLIGHT,
    block_levels,
    cell,
    extrapolation,
    friction_flag,
    measure_label,
    models_of,
    record_pga_g,
    run_fraction,
    state_labels,
    tension_flag,
    vertical_applied,
)
from pipeline.report.layout import pretty
from pipeline.report.text import Item, bullet, heading, note, paragraph, table
from pipeline.report.vertical import VerticalEffect

DEFAULT_FRICTION_COEFFICIENT = 0.5
EXTRAPOLATION_ROWS = 30


@dataclass
class Results:
    """Everything the report reads (datasets already opened)."""

    config: StudyConfig
    cube: xr.Dataset
    ida: xr.Dataset
    fragility: xr.Dataset  # fitted curves merged with the risk variables
    output: Path  # the study's output folder (fragility.csv is read from it)
    showcase: xr.Dataset | None = None
    applicability: xr.Dataset | None = None
    efficiency: xr.Dataset | None = None
    runtime_s: float = float("nan")  # wall time of the pipeline run [s]; NaN: not stated
    vertical: VerticalEffect | None = None  # [study] vertical = true: the runs with and without the verticals

    @property
    def settings(self) -> dict:
        """``[report]`` keys; title, project and author fall back to the ``[study]`` table's."""
        report = self.config.raw.get("report", {})
        study = self.config.raw.get("study", {})
        settings = {key: study.get(key) for key in ("title", "project", "author") if isinstance(study, dict)}
        settings.update({key: value for key, value in (report if isinstance(report, dict) else {}).items()
                         if value not in ("", None)})
        return settings

    @property
    def title(self) -> str:
        """The report's title: ``[report] title`` or ``[study] title``, else a generic one."""
        return str(self.settings.get("title") or "Seismic fragility of unanchored rocking blocks")

    @property
    def friction_coefficient(self) -> float:
        """The friction coefficient [-] the sliding check compares with (``[report] friction_coefficient``)."""
        return float(self.settings.get("friction_coefficient", DEFAULT_FRICTION_COEFFICIENT))


def _g(value):
    return f"{value:.3g}" if np.isfinite(value) else "-"


def _percent(value):
    return "-" if value is None or not np.isfinite(value) else f"{value:.0%}" if value >= 0.01 or value == 0 \
        else "<1%"


def n_runs(cube) -> int:
    """Solver runs of the study: rigid-base models once per block, the others once per soil."""
    per_soil = cube.sizes["record"] * cube.sizes["im_level"] * cube.sizes["block"]
    return int(sum(per_soil * (1 if m.rigid_base else cube.sizes["soil"]) for m in models_of(cube)))



def _result_files(results: Results) -> list[str]:
    """The result files this report read: the optional ones only when the run wrote them."""
    optional = {"showcase.nc": results.showcase, "applicability.nc": results.applicability,
                "efficiency.nc": results.efficiency}
    return ["cube.nc", "ida.nc", "fragility.nc"] + [name for name, dataset in optional.items()
                                                    if dataset is not None and len(dataset.data_vars)]

def title_items(results: Results) -> list[Item]:
    """The title page below the title: study, size of the run, what the report holds."""
    config, cube = results.config, results.cube
    items = [
        paragraph(f"Study '{config.name}' ({config.source}); configuration hash {cube.attrs.get('config_hash', '')}; "
                  f"computed with rockfrag {cube.attrs.get('rockfrag_version', __version__)}."),
        paragraph(f"{cube.sizes['record']} record components, {cube.sizes['im_level']} intensity levels, "
                  f"{cube.sizes['soil']} soils ({', '.join(map(str, cube.soil.values))}), {cube.sizes['block']} "
                  f"blocks ({', '.join(map(str, cube.block.values))}) and {cube.sizes['model']} models: "
                  f"{n_runs(cube)} solver runs."),
        paragraph("This report states the fragility of each block on each soil for each model, the methods and "
                  "assumptions behind the numbers, and where the models are outside their validity (page "
                  "'Limitations'). Every number is read from the result files in the same folder "
                  f"({', '.join(_result_files(results))})."),
    ]
    if np.isfinite(results.runtime_s):
        items.append(note(f"Run time of the pipeline run that wrote this report: {results.runtime_s:.0f} s."))
    return items


def summary_items(results: Results) -> list[Item]:
    """Per block, model and soil: median/beta of the two most severe states, P(most severe in life)."""
    fragility = results.fragility
    labels = state_labels(fragility)
    states = [str(s) for s in fragility.damage_state.values][-2:]
    status = extrapolation(fragility, results.output).set_index(["soil", "block", "model", "damage_state"])["status"]
    unit = measure_label(fragility)
    life = fragility.attrs.get("design_life_years", results.config.design_life)
    header = ["block", "model", "soil"] + [f"{labels[s]}: median / β" for s in states]
    has_risk = "probability_in_life" in fragility
    if has_risk:
        header.append(f"P({states[-1]}) in {float(life):g} years")
    rows = []
    for block in fragility.block.values:
        for model in models_of(fragility):
            soils = ["(any)"] if model.rigid_base else list(fragility.soil.values)
            for soil in soils:
                picked = cell(fragility, model, block, None if model.rigid_base else soil)
                row = [str(block), model.name, str(soil)]
                for state in states:
                    median = float(picked["median"].sel(damage_state=state))
                    beta = float(picked["beta"].sel(damage_state=state))
                    flag = status.get((str(picked.soil.values), str(block), model.name, state), "within")
                    mark = "*" if flag not in ("within", "no fit") else ""
                    row.append(f"{_g(median)}{mark} / {_g(beta)}")
                if has_risk:
                    p = float(picked["probability_in_life"].sel(damage_state=states[-1]))
                    row.append(f"{p:.1e}" if np.isfinite(p) else "-")
                rows.append(row)
    items = [paragraph(f"Fitted lognormal fragility functions (median in {unit}, dispersion β). Rigid-base models "
                       "do not depend on the soil and have one row per block."), table(header, rows),
             note("* the median lies outside the studied intensity range (an extrapolation; see Limitations). "
                  "Confidence bounds and goodness of fit: fragility.csv.")]
    if has_risk:
        items.append(note(f"Hazard: {fragility.attrs.get('hazard_source', 'see Methods')}."))
    return items


def _processing_text(cube):
    try:
        recipe = json.loads(cube.attrs.get("processing", "{}"))
    except json.JSONDecodeError:
        recipe = {}
    steps = []
    for step in recipe.get("steps", []):
        options = ", ".join(f"{k} = {v}" for k, v in step.items() if k != "name")
        steps.append(f"{step.get('name')}" + (f" ({options})" if options else ""))
    return "; ".join(steps) or "not recorded in the cube"


def _vertical_outcome(cube) -> str:
    if not vertical_applied(cube):
        return "; the vertical ground motion is not applied (horizontal components only)"
    return ("; with the vertical component, free flight (g + a_v < 0: the pivot models stop there; censored "
            "in the fits, see Limitations)")


def _vertical_records(cube) -> str:
    """The records' vertical components, when the runs applied them."""
    if not vertical_applied(cube):
        return ""
    pga = np.asarray(cube.record_vertical_pga.values, float)
    return (f"Each runs with its station's vertical component (PGA {np.nanmin(pga):.3g} to {np.nanmax(pga):.3g} g), "
            "cut to the window the components share and processed alike, scaled by the record's factor; the same "
            "records without it are compared on the pages 'Vertical component'. ")


def methods_items(results: Results) -> list[Item]:
    """The methods pages: models, soils and blocks, records and processing, scaling, fits, hazard and risk."""
    config, cube, fragility = results.config, results.cube, results.fragility
    items = [heading("Models and their assumptions")]
    bed = (config.raw.get("solver", {}) or {}).get("bed", "continuous")
    for model in models_of(cube):
        if model.rigid_base:
            role = "rigid base: the result does not depend on the soil; computed once per block"
        else:
            rule = f"bed '{bed}'" if model.uses_bed else f"pivot switch rule '{config.switch}'"
            role = f"on a foundation of interface stiffness k (paper eq. 19) and the soil's damping ratio; {rule}"
        name = model.label if model.label.startswith(f"{model.name}:") else f"{model.label} [{model.name}]"
        items.append(bullet(pretty(f"{name.split(': ')[0]}: {model.description}; {role}.")))
    items.append(paragraph(
        f"All models: planar rocking of a rigid block; the base does not slide; "
        f"overturning when |θ| reaches {config.overturn_angle:.3g} rad (terminal); {config.tail:g} s of free "
        f"vibration after each record. Outcomes: no uplift, rocking without overturning, overturning, or a "
        f"failed integration (excluded from the fits){_vertical_outcome(cube)}."))
    stiffness = cube.interface_stiffness
    header = ["soil", "G_s [MPa]", "E_d [MPa]", "ξ [-]"] + [f"k, {b} [N/m]" for b in cube.block.values]
    rows = [[str(soil), _g(float(cube.soil_shear_modulus.sel(soil=soil)) / 1e6),
             _g(float(cube.soil_constrained_modulus.sel(soil=soil)) / 1e6),
             _g(float(cube.soil_damping_ratio.sel(soil=soil)))]
            + [_g(float(stiffness.sel(soil=soil, block=b))) for b in cube.block.values] for soil in cube.soil.values]
    items += [heading("Soils and blocks"), table(header, rows)]
    header = ["block", "b [m]", "h [m]", "R [m]", "α [rad]", "mass [kg]", "uplift threshold g·tanα [g]"]
    rows = [[str(b), _g(float(cube.block_b.sel(block=b))), _g(float(cube.block_h.sel(block=b))),
             _g(float(cube.block_R.sel(block=b))), _g(float(cube.block_alpha.sel(block=b))),
             _g(float(cube.block_mass.sel(block=b))), _g(math.tan(float(cube.block_alpha.sel(block=b))))]
            for b in cube.block.values]
    items.append(table(header, rows))

    pga = record_pga_g(cube)
    events = len(set(map(str, cube.record_event.values))) if "record_event" in cube.coords else "?"
    items += [heading("Record set and processing"),
              paragraph(f"Record sets {', '.join(config.record_sets)}: {cube.sizes['record']} horizontal components "
                        f"from {events} earthquake{'s' if events != 1 else ''}; PGA of the processed records "
                        f"{pga.min():.3g} to {pga.max():.3g} g. {_vertical_records(cube)}"
                        f"Every record is processed before use: {_processing_text(cube)}. Checksums of the record "
                        "files and each record's processing steps are stored in cube.nc.")]

    levels = cube.im_level.values
    spacing = "geometric" if levels.size > 2 and np.allclose(np.diff(np.log(levels)), np.log(levels[1] / levels[0]),
                                                              rtol=1e-3) else "as listed"
    measure = str(cube.im_level.attrs.get("long_name", "")).replace("intensity level: ", "")
    scale = cube.scale_factor.values
    relative = cube.im_level.attrs.get("units") == "1"
    text = (f"Each processed record is scaled linearly to {levels.size} levels of {measure} "
            f"({measure_label(cube)}), {levels.min():.3g} to {levels.max():.3g}"
            f"{' times the uplift intensity of each block' if relative else ''}, spacing {spacing}; scale factors "
            f"{np.nanmin(scale):.3g} to {np.nanmax(scale):.3g}.")
    if "intensity" in cube.variables and "block" in cube["intensity"].dims:
        ranges = ", ".join(f"{b}: {block_levels(cube, b).min():.3g}-{block_levels(cube, b).max():.3g}"
                           for b in cube.block.values)
        text += f" Each block has its own levels ({ranges})."
    items += [heading("Scaling (incremental dynamic analysis)"), paragraph(text)]

    labels = state_labels(fragility)
    methods = sorted(set(map(str, np.unique(fragility.fit_method.values))))
    items += [heading("Fragility fits"),
              paragraph(f"Damage states: {'; '.join(f'{n}: {t}' for n, t in labels.items())}. Each soil × block × "
                        "model × state is fitted by maximum likelihood on the binomial counts per level (Baker 2015); "
                        f"overturning by the {fragility.attrs.get('overturning_convention', 'outcomes as run')} "
                        f"({int(fragility.n_resurrected.sum()) if 'n_resurrected' in fragility else 0} here); the "
                        "refined IDA capacities are also fitted, as a check (capacity_median in fragility.csv). "
                        f"Confidence bounds ({config.confidence:.0%}) from "
                        f"{fragility.attrs.get('bootstrap_samples', '?')} "
                        f"bootstrap samples of the records (seed {fragility.attrs.get('bootstrap_seed', '?')}). States "
                        "that would cross inside the studied range are refitted with one shared β; a state reached at "
                        "one intensity by every record is a deterministic threshold. Fit methods used: "
                        f"{', '.join(methods)}.")]
    if "annual_frequency" in fragility:
        items += [heading("Hazard and risk"),
                  paragraph("Hazard curve: "
                            f"{fragility.attrs.get('hazard_source', config.hazard_file or 'shipped example')}. "
                            "Mean annual frequency of each damage state λ = ∫ P(DS | im) |dλ(im)|, the hazard "
                            "interpolated log-log; probability in the design life "
                            f"{float(fragility.attrs.get('design_life_years', config.design_life)):g} years: "
                            "1 − exp(−λ·years).")]
    return items


def _fraction_table(fraction, soils, blocks):
    header = ["soil"] + [str(b) for b in blocks]
    rows = [[str(s)] + [_percent(float(fraction.sel(soil=s, block=b))) for b in blocks] for s in soils]
    return table(header, rows)


def limitations_items(results: Results) -> list[Item]:
    """The limitations pages: foundation tension, sliding, extrapolated medians, solver failures (from the results)."""
    cube, fragility = results.cube, results.fragility
    models = models_of(cube)
    items = [heading("Foundation tension")]
    flag = tension_flag(cube)
    found = False
    for model in models:
        if model.rigid_base or flag is None:
            continue
        fraction = run_fraction(cube, flag, model)
        if fraction is None:
            if not model.can_pull:
                items.append(paragraph(f"{model.label}: the foundation cannot pull (tensionless); the block "
                                       "lifts off instead."))
            continue
        found = True
        overall = float(fraction.mean())
        if float(fraction.max()) == 0:
            items.append(paragraph(f"{model.label}: the foundation never pulled on the block."))
            continue
        worst = fraction.where(fraction == fraction.max(), drop=True)
        items.append(paragraph(
            f"{model.label}: the foundation pulled on the block (negative support force) in {_percent(overall)} of "
            f"the runs, most often for block {worst.block.values[0]} on {worst.soil.values[0]} "
            f"({_percent(float(fraction.max()))}). A soil cannot pull: after the first tension these runs are not "
            "physical, and the model is outside its validity there. Fraction of runs with tension:"))
        items.append(_fraction_table(fraction, cube.soil.values, cube.block.values))
    if not found:
        items.append(paragraph("No model of this study reports the support force; tension was not checked."))

    coefficient = results.friction_coefficient
    items.append(heading("Sliding"))
    flag = friction_flag(cube, coefficient)
    found = False
    for model in models:
        fraction = None if flag is None else run_fraction(cube, flag, model)
        if fraction is None:
            continue
        found = True
        if float(fraction.max()) == 0:
            items.append(paragraph(f"{model.label}: the friction needed to hold the base never exceeded "
                                   f"μ = {coefficient:g}."))
            continue
        items.append(paragraph(
            f"Every model assumes the base does not slide. {model.label}: holding the base needed a friction "
            f"coefficient above μ = {coefficient:g} in {_percent(float(fraction.mean()))} of the runs; there the "
            "block would slide or slide-rock, which the rocking results do not describe. Fraction of runs above μ:"))
        items.append(_fraction_table(fraction, cube.soil.values, cube.block.values))
    if not found:
        items.append(paragraph("No model of this study reports the friction demand (|H|/N at the base); every model "
                               "assumes the base does not slide, which was not checked."))

    items.append(heading("Extrapolated fragility medians"))
    status = extrapolation(fragility, results.output)
    rigid = {m.name for m in models if m.rigid_base}
    first_soil = str(fragility.soil.values[0])
    status = status[~status.model.isin(rigid) | (status.soil == first_soil)]  # a rigid base once per block
    outside = status[~status.status.isin(["within", "no fit"])]
    unfitted = int((status.status == "no fit").sum())
    order = {name: {str(v): i for i, v in enumerate(fragility[name].values)} for name in ("block", "model", "soil")}
    outside = outside.sort_values(["block", "model", "soil"], key=lambda column: column.map(order[column.name]))
    if outside.empty:
        items.append(paragraph("Every fitted median lies inside the studied intensity range."))
    else:
        items.append(paragraph(
            f"{len(outside)} fitted medians lie outside the studied intensity range: they extrapolate the "
            "lognormal fit beyond the levels that were run and are marked * in the summary."))
        labels = state_labels(fragility)
        rows = []
        for row in outside.head(EXTRAPOLATION_ROWS).itertuples():
            levels = block_levels(fragility, row.block)
            rows.append([row.block, row.model, "(any)" if row.model in rigid else row.soil,
                         labels.get(row.damage_state, row.damage_state), _g(row.median),
                         f"{levels.min():.3g}-{levels.max():.3g}", row.status])
        items.append(table(["block", "model", "soil", "damage state", f"median [{measure_label(fragility)}]",
                            "studied range", "status"], rows))
        if len(outside) > EXTRAPOLATION_ROWS:
            items.append(note(f"... and {len(outside) - EXTRAPOLATION_ROWS} more: see fragility.csv."))
        for word in dict.fromkeys(outside.status):
            if word in STATUS:
                items.append(note(f"{word}: {STATUS[word]}."))
    if unfitted:
        items.append(note(f"{unfitted} curves could not be fitted (too few exceedances): no median is given."))

    items += free_flight_items(cube, models)
    items.append(heading("Solver"))
    failed = (cube.outcome == OUTCOME_FAILED)
    if int(failed.sum()) == 0:
        items.append(paragraph("Every run finished (no integration failure)."))
    else:
        for model in models:
            share = float(failed.sel(model=model.name).mean())
            if share > 0:
                items.append(paragraph(f"{model.label}: {_percent(share)} of the runs stopped (too many events or "
                                       "steps); they are left out of the fits."))
    return items


def free_flight_items(cube, models) -> list[Item]:
    """The limitations' free-flight count: runs stopped where g + a_v < 0, per model, soil and block."""
    if not vertical_applied(cube):
        return []
    items = [heading("Free flight (vertical component)")]
    flag = (cube.outcome == OUTCOME_FREE_FLIGHT).where(cube.outcome != OUTCOME_FAILED)
    total = int((cube.outcome == OUTCOME_FREE_FLIGHT).sum())
    if total == 0:
        return items + [paragraph("g + a_v(t) stayed above zero in every run: no block was thrown off the ground.")]
    items.append(paragraph(
        f"Where g + a_v(t) < 0 the ground falls faster than gravity and the block leaves it. The pivot models have "
        f"no flight phase and stop there (outcome free_flight, {total} runs); the Winkler bed flies on. The fits "
        "count such a run as uplifted, as reaching a rocking state only if it did before the stop, and as unknown "
        "for overturning (censored). Fraction of runs in free flight:"))
    for model in models:
        fraction = run_fraction(cube, flag, model)
        if fraction is None or float(fraction.max()) == 0:
            continue
        items.append(paragraph(f"{model.label}: {_percent(float(fraction.mean()))} of the runs."))
        items.append(_fraction_table(fraction, cube.soil.values, cube.block.values))
    return items
