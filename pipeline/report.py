"""pipeline.report - stage 9: cube, IDA and fragility results -> PNG figures and one PDF report.

Input : the study configuration, the processed records, and the datasets of the earlier stages
        (cube, ida, fragility, risk).
Output: ``reports/figures/NN-name.png`` (one per figure) and ``reports/report.pdf`` (one page per
        figure, in the same order). Every figure has a title, axis labels with units, a legend where
        several series are drawn, and a one-line caption. The PDF carries no creation date, so the
        same results give the same file content.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.backends.backend_pdf import PdfPages  # noqa: E402

from pipeline import __version__  # noqa: E402
from pipeline.measures import response_spectrum  # noqa: E402
from pipeline.outputs import atomic_path  # noqa: E402
from pipeline.processing import integrate  # noqa: E402
from pipeline.units import STANDARD_GRAVITY  # noqa: E402

SOIL_COLOURS = {"clay": "#8c510a", "sand": "#d8b365", "gravel": "#5ab4ac", "rock": "#01665e", "steel": "#4d4d4d"}
MODEL_STYLES = {"housner": dict(ls="--"), "ssi": dict(ls="-"), "ssi-paper": dict(ls=":")}
OUTCOME_COLOURS = ["#c7e9c0", "#fdae6b", "#d7301f"]


@dataclass
class Figure:
    name: str
    figure: object
    caption: str


def _colour(soil, index):
    return SOIL_COLOURS.get(soil, f"C{index}")


def _caption(fig, text):
    engine = fig.get_layout_engine()
    if engine is not None:  # keep the caption clear of the axes' labels
        engine.set(rect=(0, 0.045, 1, 0.955))
    fig.text(0.01, 0.005, text, fontsize=8, style="italic", ha="left", va="bottom", wrap=True)


def summary_page(config, cube, fragility, risk, runtime_s) -> Figure:
    fig = plt.figure(figsize=(11.7, 8.3))
    n_runs = int(np.prod([cube.sizes[d] for d in ("record", "im_level", "block")])) * \
        sum(1 if m == "housner" else cube.sizes["soil"] for m in cube.model.values)
    lines = [
        f"rockfrag {__version__} - study '{config.name}'   (config hash {cube.attrs.get('config_hash', '')})",
        f"Record sets: {', '.join(config.record_sets)}  ({cube.sizes['record']} components)",
        f"Intensity: {config.measure.upper()} at {cube.sizes['im_level']} levels, "
        f"{config.levels[0]:.3g}-{config.levels[-1]:.3g} {config.level_unit}",
        f"Soils: {', '.join(cube.soil.values)}    Blocks: {', '.join(cube.block.values)}    "
        f"Models: {', '.join(cube.model.values)}",
        f"Solver runs: {n_runs} (Housner runs are soil-independent)    Runtime of this pipeline run: {runtime_s:.0f} s",
        f"Hazard: {risk.attrs.get('hazard_source', '')}; design life {risk.attrs.get('design_life_years', 50):g} years",
    ]
    fig.text(0.03, 0.96, "Seismic fragility of unanchored rocking blocks: summary", fontsize=15, weight="bold", va="top")
    for i, line in enumerate(lines):
        fig.text(0.03, 0.91 - 0.03 * i, line, fontsize=9.5, va="top")
    table_rows = []
    for block in cube.block.values:
        for soil in cube.soil.values:
            row = [block, soil]
            for model in cube.model.values:
                cell = fragility.sel(block=block, soil=soil, model=model, damage_state="overturning")
                r50 = fragility.sel(block=block, soil=soil, model=model, damage_state="rocking-0.5")
                p_life = float(risk.probability_in_life.sel(block=block, soil=soil, model=model,
                                                            damage_state="overturning"))
                row += [f"{float(r50['median']):.2f} / {float(r50['beta']):.2f}",
                        f"{float(cell['median']):.2f} / {float(cell['beta']):.2f}",
                        f"{p_life:.1e}" if np.isfinite(p_life) else "-"]
            table_rows.append(row)
    header = ["block", "soil"]
    for model in cube.model.values:
        header += [f"{model}\nθ/α≥0.5: median/β", f"{model}\noverturning: median/β", f"{model}\nP(overturning in life)"]
    axis = fig.add_axes([0.02, 0.06, 0.96, 0.62])
    axis.axis("off")
    table = axis.table(cellText=table_rows, colLabels=header, loc="upper center", cellLoc="center")
    table.auto_set_font_size(False)
    table.set_fontsize(7.5)
    table.scale(1, 1.25)
    for (row, _), cell in table.get_celld().items():
        if row == 0:
            cell.set_height(cell.get_height() * 2)
    axis.set_title(f"Fitted lognormal fragility (median in {config.level_unit}, dispersion β) and probability of "
                   "overturning in the design life", fontsize=10)
    _caption(fig, "Medians above the highest level are extrapolations; see fragility.csv for confidence bounds "
                  "and goodness of fit.")
    return Figure("summary", fig, "Summary of the study and the fitted fragility parameters.")


ROWS_PER_TABLE_PAGE = 45


def records_tables(records, measures) -> list[Figure]:
    """Intensity-measure table of the record set, ROWS_PER_TABLE_PAGE records per page."""
    header = ["record", "event", "station", "PGA [g]", "PGV [m/s]", "Ia [m/s]", "D5-95 [s]", "Sa(1s) [g]"]
    rows = [[r.id, str(r.metadata.get("event", ""))[:24], str(r.metadata.get("station", ""))[:20],
             f"{m['pga_m_s2'] / STANDARD_GRAVITY:.3f}", f"{m['pgv_m_s']:.3f}", f"{m['arias_m_s']:.2f}",
             f"{m['d5_95_s']:.1f}", f"{m['sa_1s_m_s2'] / STANDARD_GRAVITY:.3f}"] for r, m in zip(records, measures)]
    pages = [rows[i:i + ROWS_PER_TABLE_PAGE] for i in range(0, len(rows), ROWS_PER_TABLE_PAGE)] or [[]]
    figures = []
    for number, page in enumerate(pages, start=1):
        fig = plt.figure(figsize=(11.7, 8.3))
        axis = fig.add_axes([0.01, 0.05, 0.98, 0.88])
        axis.axis("off")
        table = axis.table(cellText=page or [[""] * len(header)], colLabels=header, loc="upper center",
                           cellLoc="left")
        table.auto_set_font_size(False)
        table.set_fontsize(6 if len(page) > 30 else 8)
        table.scale(1, 0.95 if len(page) > 30 else 1.2)
        suffix = f" ({number}/{len(pages)})" if len(pages) > 1 else ""
        axis.set_title(f"Intensity measures of the processed records{suffix}", fontsize=12)
        _caption(fig, "PGA, PGV, Arias intensity, significant duration and 5%-damped Sa(1 s) after processing "
                      "(demean, detrend, taper, zero-phase band-pass, baseline).")
        figures.append(Figure("records-table" + (f"-{number}" if len(pages) > 1 else ""), fig,
                              "Intensity measures of the record set."))
    return figures


def spectra(records) -> Figure:
    fig, axis = plt.subplots(figsize=(9, 6), constrained_layout=True)
    periods = np.geomspace(0.02, 10, 60)
    values = []
    for record in records:
        sa = response_spectrum(record.acceleration, record.dt, periods)["sa"] / STANDARD_GRAVITY
        values.append(sa)
        axis.loglog(periods, sa, color="0.7", lw=0.6)
    values = np.array(values)
    for q, style in ((0.5, dict(color="k", lw=2.2, label="median")),
                     (0.16, dict(color="C3", lw=1.5, ls="--", label="16% / 84%")), (0.84, dict(color="C3", lw=1.5, ls="--"))):
        axis.loglog(periods, np.quantile(values, q, axis=0), **style)
    axis.plot([], [], color="0.7", lw=0.6, label="individual records")
    axis.set_xlabel("period T [s]")
    axis.set_ylabel("spectral acceleration Sa(T, 5%) [g]")
    axis.set_title(f"5%-damped response spectra of the record set ({len(records)} components)")
    axis.grid(alpha=0.3, which="both")
    axis.legend()
    _caption(fig, "Unscaled processed records; the study scales each record to the intensity levels.")
    return Figure("spectra", fig, "Response spectra of the record set.")


def bolu_processing(raw, processed) -> Figure:
    fig, axes = plt.subplots(3, 1, figsize=(10, 8), sharex=True, constrained_layout=True)
    for record, label, style in ((raw, "raw (as published)", dict(color="0.55", lw=0.8)),
                                 (processed, "processed", dict(color="C0", lw=0.9))):
        time = np.arange(record.trace.stats.npts) * record.dt
        velocity, displacement = integrate(record.acceleration, record.dt)
        for axis, series in zip(axes, (record.acceleration / STANDARD_GRAVITY, velocity, displacement)):
            axis.plot(time, series, label=label, **style)
    for axis, label in zip(axes, ("acceleration [g]", "velocity [m/s]", "displacement [m]")):
        axis.set_ylabel(label)
        axis.grid(alpha=0.3)
        axis.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(f"Düzce 1999, Bolu {raw.metadata.get('component', '')}: raw and processed")
    _caption(fig, "Processing removes the drift of the integrated displacement; the record ends at rest.")
    return Figure("bolu-processing", fig, "The Bolu record before and after processing.")


def bolu_comparison(processed, block, soils, stiffness_of, switch) -> Figure:
    from pipeline.models import simulate
    import warnings

    fig, axes = plt.subplots(len(soils) + 1, 1, figsize=(10, 2.0 * (len(soils) + 1)), sharex=True,
                             constrained_layout=True)
    t_end = processed.duration + 10.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        housner = simulate("housner", processed.acceleration, processed.dt, block, t_end=t_end)
        for axis, soil in zip(axes, soils):
            k = stiffness_of(soil)
            ssi = simulate("ssi", processed.acceleration, processed.dt, block, k=k, xi=soil.damping_ratio,
                           switch=switch, t_end=t_end)
            axis.plot(housner.t, housner.theta, color="k", ls="--", lw=0.9, label="Housner (rigid base)")
            axis.plot(ssi.t, ssi.theta, color=_colour(soil.name, 0), lw=1.0, label=f"SSI-rocking on {soil.name}")
            axis.set_ylabel("θ [rad]")
            axis.set_title(f"{soil.name}: G = {soil.shear_modulus / 1e6:.0f} MPa, k = {k:.3g} N/m", fontsize=9)
            axis.legend(loc="upper right", fontsize=7)
            axis.grid(alpha=0.3)
            axes[-1].plot(ssi.t, (ssi.y - ssi.y[0]) * 1000, color=_colour(soil.name, 0), lw=0.8, label=soil.name)
    axes[-1].set_ylabel("y - y_static [mm]")
    axes[-1].set_xlabel("time [s]")
    axes[-1].set_title("vertical displacement of the active pivot (SSI)", fontsize=9)
    axes[-1].legend(loc="upper right", fontsize=7, ncol=len(soils))
    axes[-1].grid(alpha=0.3)
    fig.suptitle(f"Bolu record, block '{block.name}' (R = {block.R:.2f} m, α = {block.alpha:.2f} rad): "
                 "Housner vs SSI-rocking")
    _caption(fig, "As in the paper's Figures 4, 7 and 10: the softer the soil, the larger the departure "
                  "from the rigid-base response.")
    return Figure("bolu-housner-vs-ssi", fig, "Rocking time histories on each soil.")


def ida_figure(ida, block) -> Figure:
    soils = list(ida.soil.values)
    models = list(ida.model.values)
    fig, axes = plt.subplots(len(models), len(soils), figsize=(3.0 * len(soils), 3.3 * len(models)),
                             sharex=True, sharey=True, squeeze=False, constrained_layout=True)
    levels = ida.im_level.values
    cap = 1.6
    for i, model in enumerate(models):
        for j, soil in enumerate(soils):
            axis = axes[i, j]
            curves = ida.edp.sel(block=block, soil=soil, model=model).values
            for curve in curves:
                shown = np.where(np.isfinite(curve), np.minimum(curve, cap), cap)
                axis.plot(shown, levels, color="0.6", lw=0.5, alpha=0.7)
            for q, width in zip(ida.fractile.values, (1.4, 2.4, 1.4)):
                fractile = ida.edp_fractile.sel(block=block, soil=soil, model=model, fractile=q).values
                shown = np.where(np.isfinite(fractile), np.minimum(fractile, cap), cap)
                axis.plot(shown, levels, color="C3" if q != 0.5 else "k", lw=width,
                          label=f"{q:.0%} fractile" if j == 0 and i == 0 else None)
            axis.axvline(cap, color="C3", lw=0.6, ls=":")
            axis.set_title(f"{model}, {soil}", fontsize=9)
            axis.grid(alpha=0.3)
            if i == len(models) - 1:
                axis.set_xlabel("θmax/α [-]")
            if j == 0:
                axis.set_ylabel(f"{ida.im_level.attrs.get('long_name', 'IM').split(': ')[-1]} "
                                f"[{ida.im_level.attrs.get('units', '')}]")
            axis.set_xlim(0, cap * 1.05)
    axes[0, 0].plot([], [], color="0.6", lw=0.5, label="records")
    axes[0, 0].legend(fontsize=7, loc="lower right")
    fig.suptitle(f"IDA curves, block '{block}': overturning drawn as the flatline at θmax/α = {cap}")
    _caption(fig, "Curves are not smoothed: a record may overturn at one level and survive a higher one "
                  "(resurrection).")
    return Figure(f"ida-{block}", fig, f"IDA curves for block {block}.")


def _fragility_panel(axis, fragility, levels, block, soil, model, state, colour, style, label):
    from pipeline.fragility import lognormal_cdf

    cell = fragility.sel(block=block, soil=soil, model=model, damage_state=state)
    grid = np.geomspace(levels[0], levels[-1], 200)
    median, beta = float(cell["median"]), float(cell["beta"])
    axis.plot(levels, cell.empirical_fraction.values, "o", ms=2.5, color=colour, alpha=0.7)
    if np.isfinite(median):
        axis.plot(grid, lognormal_cdf(grid, median, beta), color=colour, label=label, **style)
        low, high = float(cell.median_low), float(cell.median_high)
        if np.isfinite(low) and np.isfinite(high) and beta > 0.05:
            axis.fill_between(grid, lognormal_cdf(grid, high, beta), lognormal_cdf(grid, low, beta),
                              color=colour, alpha=0.12, lw=0)
    else:
        axis.plot([], [], color=colour, label=f"{label} (no fit)", **style)


def _fragility_figure(fragility, block, series, title, caption, name) -> Figure:
    """One panel per damage state; ``series`` is a list of (soil, model, colour, line style, label)."""
    states = list(fragility.damage_state.values)
    levels = fragility.im_level.values
    fig, axes = plt.subplots(1, len(states), figsize=(3.4 * len(states), 3.8), sharey=True, squeeze=False,
                             constrained_layout=True)
    for axis, state in zip(axes[0], states):
        for soil, model, colour, style, label in series:
            _fragility_panel(axis, fragility, levels, block, soil, model, state, colour, style, label)
        axis.set_xscale("log")
        axis.set_title(state, fontsize=10)
        axis.set_xlabel(f"{fragility.attrs.get('intensity_measure', 'IM').upper()} "
                        f"[{fragility.im_level.attrs.get('units', '')}]")
        axis.grid(alpha=0.3, which="both")
    axes[0, 0].set_ylabel("P(damage state | IM) [-]")
    axes[0, -1].legend(fontsize=7, loc="upper left")
    fig.suptitle(title)
    _caption(fig, caption)
    return Figure(name, fig, title)


def fragility_by_soil(fragility, block, model) -> Figure:
    series = [(soil, model, _colour(soil, i), MODEL_STYLES.get(model, {}), soil)
              for i, soil in enumerate(fragility.soil.values)]
    return _fragility_figure(fragility, block, series, f"Fragility by soil: block '{block}', model {model}",
                             "Points: fraction of records reaching the state at each level; lines: lognormal MLE; "
                             "band: bootstrap confidence bounds of the median.", f"fragility-soils-{block}")


def fragility_by_model(fragility, block, soils) -> Figure:
    series = [(soil, model, _colour(soil, i), MODEL_STYLES.get(model, {}), f"{model}, {soil}")
              for i, soil in enumerate(soils) for model in fragility.model.values]
    return _fragility_figure(fragility, block, series,
                             f"Fragility by model: block '{block}', softest and stiffest soil",
                             "Dashed: Housner (rigid base); solid: SSI-rocking.", f"fragility-models-{block}")


def three_outcome_figure(fragility, block) -> Figure:
    soils = list(fragility.soil.values)
    models = list(fragility.model.values)
    levels = fragility.im_level.values
    fig, axes = plt.subplots(len(models), len(soils), figsize=(3.0 * len(soils), 3.0 * len(models)),
                             sharex=True, sharey=True, squeeze=False, constrained_layout=True)
    for i, model in enumerate(models):
        for j, soil in enumerate(soils):
            axis = axes[i, j]
            probability = fragility.outcome_probability.sel(block=block, soil=soil, model=model).values
            axis.stackplot(levels, probability, colors=OUTCOME_COLOURS,
                           labels=["no uplift", "rocking, no overturning", "overturned"])
            axis.set_xscale("log")
            axis.set_title(f"{model}, {soil}", fontsize=9)
            axis.set_xlim(levels[0], levels[-1])
            axis.set_ylim(0, 1)
            if i == len(models) - 1:
                axis.set_xlabel(f"{fragility.attrs.get('intensity_measure', 'IM').upper()} "
                                f"[{fragility.im_level.attrs.get('units', '')}]")
            if j == 0:
                axis.set_ylabel("probability [-]")
    axes[0, -1].legend(fontsize=7, loc="center left")
    fig.suptitle(f"Outcomes by intensity: block '{block}'")
    _caption(fig, "Fractions of records with no uplift, rocking without overturning, and overturning.")
    return Figure(f"outcomes-{block}", fig, "Three-outcome probabilities.")


def applicability_figure(cube, limit=0.10) -> Figure:
    """Ratio of SSI to Housner median peak angle against soil shear modulus, per block."""
    fig, axis = plt.subplots(figsize=(9, 6), constrained_layout=True)
    shear = cube.soil_shear_modulus.values / 1e6
    order = np.argsort(shear)
    for index, block in enumerate(cube.block.values):
        sub = cube.sel(block=block)
        uplift_g = float(cube.block_uplift_acceleration.sel(block=block)) / STANDARD_GRAVITY
        band = (cube.im_level >= 1.2 * uplift_g) & (cube.im_level <= 3.0 * uplift_g)
        survived = sub.outcome.sel(model=["housner", "ssi"]).isin([1]).all("model")
        angle = sub.peak_angle.where(survived & band)
        if int(band.sum()) == 0:
            continue
        ratio = (angle.sel(model="ssi").median(["record", "im_level"]) /
                 angle.sel(model="housner").median(["record", "im_level"])).values
        axis.semilogx(shear[order], ratio[order], "o-", color=f"C{index}", label=block)
    axis.axhspan(1 - limit, 1 + limit, color="0.85", label=f"within ±{limit:.0%} of Housner")
    axis.axvspan(300, 1000, color="C2", alpha=0.12, label="paper's limit: G = 300-1000 MPa")
    axis.axhline(1.0, color="k", lw=0.8)
    axis.set_xlabel("soil shear modulus G_s [MPa]")
    axis.set_ylabel("median θmax (SSI) / median θmax (Housner) [-]")
    axis.set_title("Applicability of the rigid-base assumption")
    axis.grid(alpha=0.3, which="both")
    axis.legend(fontsize=8)
    _caption(fig, "Medians over records and levels from 1.2 to 3 times each block's uplift threshold where "
                  "neither model overturned; `rockfrag applicability` sweeps G_s finely.")
    return Figure("applicability", fig, "SSI/Housner ratio against soil stiffness.")


def write_report(figures, output_dir) -> tuple[Path, list[Path]]:
    """Write one PNG per figure and a PDF with one page per figure (atomically)."""
    output_dir = Path(output_dir)
    figure_dir = output_dir / "figures"
    figure_dir.mkdir(parents=True, exist_ok=True)
    pngs = []
    for number, item in enumerate(figures, start=1):
        png = figure_dir / f"{number:02d}-{item.name}.png"
        with atomic_path(png) as temporary:
            item.figure.savefig(temporary, dpi=120, format="png")
        pngs.append(png)
    pdf = output_dir / "report.pdf"
    with atomic_path(pdf) as temporary:
        with PdfPages(temporary, metadata={"Title": "rockfrag report", "Creator": f"rockfrag {__version__}",
                                           "CreationDate": None}) as document:
            for item in figures:
                document.savefig(item.figure)
    for item in figures:
        plt.close(item.figure)
    return pdf, pngs


def build_figures(config, cube, ida, fragility, risk, records, measures, raw_bolu, processed_bolu,
                  runtime_s, stiffness_of, applicability=None) -> list[Figure]:
    """All figures of the report, in order."""
    figures = [summary_page(config, cube, fragility, risk, runtime_s), *records_tables(records, measures),
               spectra(records)]
    if raw_bolu is not None:
        figures.append(bolu_processing(raw_bolu, processed_bolu))
        block = config.blocks[0]
        figures.append(bolu_comparison(processed_bolu, block, config.soils, lambda soil: stiffness_of(soil, block),
                                       config.switch))
    for block in cube.block.values:
        figures.append(ida_figure(ida, block))
    for block in cube.block.values:
        for model in cube.model.values:
            if model != "housner":
                figures.append(fragility_by_soil(fragility, block, model))
        soils = [cube.soil.values[0], cube.soil.values[-1]] if cube.sizes["soil"] > 1 else list(cube.soil.values)
        figures.append(fragility_by_model(fragility, block, soils))
        figures.append(three_outcome_figure(fragility, block))
    if {"housner", "ssi"} <= set(cube.model.values):
        figures.append(applicability_figure(cube))
    if applicability is not None:
        from pipeline.applicability import sweep_figure

        figures.append(Figure("applicability-sweep", sweep_figure(applicability),
                              "Rigid-base error against a fine sweep of soil stiffness."))
    return figures


def report_stage(config, cube, ida, fragility, risk, output, runtime_s, applicability=None, loaded=None):
    """Build every figure (records from ``loaded`` = ``study.study_records(config)``, or read them),
    write the PNGs and the PDF."""
    import warnings

    from pipeline.measures import intensity_measures
    from pipeline.processing import process_record
    from pipeline.records import load_records
    from pipeline.soils import soil_block_stiffness
    from pipeline.study import study_records

    records, _, recipe = loaded or study_records(config, log=lambda message: None)
    measures = [intensity_measures(r.acceleration, r.dt, sa_periods=(1.0,)) for r in records]
    raw_bolu = processed_bolu = None
    try:
        bolu, _ = load_records("DUZCE/BOL090")
        raw_bolu = bolu[0]
        processed_bolu = process_record(raw_bolu, recipe)
    except Exception as error:  # the catalogue may be absent for a user's own record folder
        warnings.warn(f"Bolu record not available for the comparison figure: {error}")
    figures = build_figures(config, cube, ida, fragility, risk, records, measures, raw_bolu, processed_bolu,
                            runtime_s, soil_block_stiffness, applicability)
    return write_report(figures, output)
