"""pipeline.report - stage 9: the study's result files -> a numbered client report (PDF and HTML).

Input : the study configuration and the datasets written by the earlier stages: ``cube.nc``, ``ida.nc``,
        ``fragility.nc`` (with the risk variables), ``showcase.nc`` (record-set spectra and the showcase
        histories, written at study time by pipeline.showcase), optionally ``applicability.nc`` and
        ``efficiency.nc``. The report only reads; it never runs a solver.
Output: ``report.pdf`` (A4 landscape, every page numbered, contents on page 2),
        ``report.html`` (the same pages in the same order, figures embedded as PNG, a linked contents)
        and ``figures/NN-name.png`` (one per page). Neither file carries a creation date: the same
        results give the same files.

Page order: title, contents, summary, methods, limitations, records, showcase record, IDA, fragility,
outcomes, vertical component (a ``[study] vertical = true`` study: ``cube_without_vertical.nc`` beside
``cube.nc``; pipeline.report.vertical), applicability, measure efficiency. Pages for blocks, soils, models
and records come from the result files, so only what the study ran is shown.
"""

from __future__ import annotations

import base64
import html
import io
import math
import multiprocessing
import os
from dataclasses import replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import xarray as xr  # noqa: E402
from matplotlib.backends.backend_pdf import PdfPages  # noqa: E402
from tqdm import tqdm  # noqa: E402

from pipeline import __version__  # noqa: E402
from pipeline.config import StudyConfig  # noqa: E402
from pipeline.damage_states import damage_states_from_config  # noqa: E402
from pipeline.outputs import atomic_path  # noqa: E402
from pipeline.report import figures as pages  # noqa: E402
from pipeline.report.adapters import models_of, record_pga_g, short_label  # noqa: E402
from pipeline.report.layout import PAGE_SIZE, Page, add_footer, new_page  # noqa: E402
from pipeline.report.sections import Results, limitations_items, methods_items, summary_items, title_items  # noqa: E402
from pipeline.report.text import Item, draw_text_page, items_html, paginate, table  # noqa: E402
from pipeline.report.vertical import open_comparison, vertical_effect, vertical_items, vertical_page  # noqa: E402
from pipeline.units import STANDARD_GRAVITY  # noqa: E402

PNG_DPI = 100
G = STANDARD_GRAVITY


def _text_pages(name, section, title, items, caption=""):
    chunks = paginate(items)
    planned = []
    for number, chunk in enumerate(chunks, start=1):
        suffix = f" ({number}/{len(chunks)})" if len(chunks) > 1 else ""
        planned.append(Page(f"{name}-{number}" if len(chunks) > 1 else name, section, title + suffix,
                            lambda chunk=chunk, t=title + suffix: draw_text_page(t, chunk, caption),
                            caption, items_html(chunk)))
    return planned


def title_page(results: Results) -> Page:
    """Page 1: title, project and author large, then the study in a few lines."""
    settings = results.settings
    people = [(str(settings[key]), size) for key, size in (("project", 16), ("author", 12)) if settings.get(key)]
    items = title_items(results)

    def draw():
        figure = new_page("")
        figure.text(0.5, 0.66, results.title, fontsize=24, weight="bold", ha="center", va="bottom", wrap=True)
        y = 0.62
        for text, size in people:
            figure.text(0.5, y, text, fontsize=size, ha="center", va="top")
            y -= 0.05
        return draw_text_page("", items, top=y - 0.06, figure=figure)

    body = "".join(f"<p><strong>{html.escape(text)}</strong></p>" for text, _ in people)
    return Page("title", "Title", results.title, draw, "", body + items_html(items))


def _figure(name, section, title, function, *args, caption=""):
    return Page(name, section, title, lambda: function(*args, caption), caption)


def records_items(results: Results) -> list[Item]:
    """Intensity measures of the processed records (showcase.nc), or the cube's PGA when it is absent."""
    cube, showcase = results.cube, results.showcase
    meta = [(str(r), str(cube.record_event.values[i])[:26] if "record_event" in cube.coords else "",
             str(cube.record_station.values[i])[:22] if "record_station" in cube.coords else "")
            for i, r in enumerate(cube.record.values)]
    if showcase is not None and "record_pga" in showcase:
        measures = showcase.sel(record=cube.record.values)
        header = ["record", "event", "station", "PGA [g]", "PGV [m/s]", "Ia [m/s]", "D5-95 [s]", "Sa(1 s) [g]"]
        rows = [[*m, f"{float(measures.record_pga[i]) / G:.3f}", f"{float(measures.record_pgv[i]):.3f}",
                 f"{float(measures.record_arias[i]):.2f}", f"{float(measures.record_d5_95[i]):.1f}",
                 f"{float(measures.record_sa_1s[i]) / G:.3f}"] for i, m in enumerate(meta)]
    else:
        header = ["record", "event", "station", "PGA [g]"]
        rows = [[*m, f"{pga:.3f}"] for m, pga in zip(meta, record_pga_g(cube))]
    return [table(header, rows)]


def plan(results: Results) -> list[Page]:
    """Every page of the report in order (contents excluded: it is made from this list)."""
    cube, ida, fragility, showcase = results.cube, results.ida, results.fragility, results.showcase
    planned = [title_page(results)]
    planned += _text_pages("summary", "Summary", "Summary of the fitted fragility functions", summary_items(results))
    planned += _text_pages("methods", "Methods", "Methods and assumptions", methods_items(results))
    planned += _text_pages("limitations", "Limitations", "Limitations: where the models are outside their validity",
                           limitations_items(results))
    planned += _text_pages("records-table", "Records", "Intensity measures of the processed records",
                           records_items(results),
                           "PGA, PGV, Arias intensity, significant duration and 5%-damped Sa(1 s) after processing.")
    if showcase is not None and "record_spectrum" in showcase:
        planned.append(_figure("spectra", "Records", "Response spectra of the record set", pages.spectra_page,
                               showcase, caption="Unscaled processed records; the study scales each record to "
                                                 "the intensity levels."))
    if showcase is not None and "theta" in showcase:
        record = showcase.attrs["showcase_record"]
        planned.append(_figure("showcase-processing", "Showcase record", f"{record}: raw and processed",
                               pages.showcase_ground_page, showcase,
                               caption="The whole record: processing removes the drift of the integrated "
                                       "displacement, so the record ends at rest."))
        planned.append(_figure("showcase-response", "Showcase record", f"{record}: rocking on each soil",
                               pages.showcase_response_page, showcase,
                               caption="Unscaled record. Time cropped to the strong motion (5-95% Arias window, "
                                       "grey) and the rocking after it; θ panels share one scale, settlement "
                                       "panels another. As in the paper's Figs. 4, 7 and 10."))
    blocks = list(map(str, cube.block.values))
    models = models_of(cube)
    soils = list(map(str, cube.soil.values))
    extremes = [soils[0], soils[-1]] if len(soils) > 1 else soils
    for block in blocks:
        planned.append(_figure(f"ida-{block}", "IDA curves", f"IDA curves: block '{block}'", pages.ida_page, ida, block,
                               caption="Thin lines: records; bold: fractiles of θmax/α given intensity. Overturning "
                                       "is drawn as the flatline. Curves are not smoothed: a record may overturn "
                                       "at one level and survive a higher one (resurrection)."))
    for block in blocks:
        for model in (m for m in models if not m.rigid_base):
            planned.append(_figure(f"fragility-soils-{block}-{model.name}", "Fragility",
                                   f"Fragility by soil: block '{block}', {short_label(model)}",
                                   pages.fragility_by_soil_page, fragility, block, model,
                                   caption="Points: fraction of records reaching the state at each level; lines: "
                                           "lognormal MLE; band: bootstrap confidence bounds of the median; black "
                                           "dashed: the rigid-base model (the same on every soil)."))
        planned.append(_figure(f"fragility-models-{block}", "Fragility", f"Fragility by model: block '{block}'",
                               pages.fragility_by_model_page, fragility, block, extremes,
                               caption="Top row: the softest soil of the study; bottom row: the stiffest. Points: "
                                       "empirical fractions; lines: lognormal fits; bands: confidence bounds."))
    for block in blocks:
        planned.append(_figure(f"outcomes-{block}", "Outcomes", f"Outcomes by intensity: block '{block}'",
                               pages.outcomes_page, fragility, block,
                               caption="Solid: probability that the block uplifts (rocks or overturns); dashed: "
                                       "probability that it overturns; between them it rocks without "
                                       "overturning."))
    if results.vertical is not None:
        planned += _text_pages("vertical", "Vertical component", "Vertical component: medians with and without it",
                               vertical_items(results.vertical))
        for block in blocks:
            planned.append(_figure(f"vertical-{block}", "Vertical component", f"Vertical component: block '{block}'",
                                   vertical_page, results.vertical, block,
                                   caption="The same records at the same levels: solid with the vertical component, "
                                           "dashed without it. Top: median θmax/α over the runs not stopped in free "
                                           "flight (not drawn where most flew). Bottom: points, fraction overturned "
                                           "among the known runs (filled: with); lines, lognormal fits."))
    if any(m.rigid_base for m in models) and any(not m.rigid_base for m in models):
        planned.append(_figure("applicability", "Applicability", "Applicability of the rigid-base model",
                               pages.applicability_page, cube,
                               caption="Medians over records and levels from 1.2 to 3 times each block's uplift "
                                       "threshold where both models rocked without overturning; top axis: the "
                                       "study's soils."))
    if results.applicability is not None and "peak_angle_ratio_to_housner" in results.applicability:
        planned.append(_figure("applicability-sweep", "Applicability", "Rigid-base error against soil stiffness",
                               pages.sweep_page, results.applicability,
                               caption=f"`rockfrag applicability`: median over "
                                       f"{results.applicability.attrs.get('n_records', '?')} records that survived in "
                                       "both models; solid: concrete block, dashed: steel block (relative "
                                       "stiffness E_b/G_s)."))
    efficiency = _efficiency_plotter(results)
    if efficiency is not None:
        planned.append(Page("efficiency", "Measure efficiency", "Efficiency of intensity measures", efficiency,
                            "From efficiency.nc."))
    return planned


def _efficiency_plotter(results):
    if results.efficiency is None:
        return None
    from pipeline.efficiency import plot_efficiency  # lazy: tests/test_report.py swaps the module in sys.modules

    def draw():
        figure = plot_efficiency(results.efficiency)
        figure = getattr(figure, "figure", figure)  # a function may return its axes
        figure.set_size_inches(*PAGE_SIZE)
        if figure.get_layout_engine() is not None:  # keep clear of the page footer
            figure.get_layout_engine().set(rect=(0, 0.05, 1, 0.95))
        return figure

    return draw


def contents_page(planned: list[Page], title: str) -> Page:
    """Page 2: every section and page title with its page number (the contents itself is page 2)."""
    rows, last = [], None
    for number, page in enumerate(planned, start=1):
        shown = number + (1 if number > 1 else 0)  # the contents is inserted as page 2
        if page.section != last:
            rows.append(("section", page.section, shown))
            last = page.section
        rows.append(("page", page.title, shown))

    def draw():
        figure = new_page("Contents")
        per_column = 36
        columns = max(1, math.ceil(len(rows) / per_column))
        size = 9 if columns <= 2 else 7.5
        step = 0.85 / min(len(rows), per_column) if rows else 0.02
        step = min(step, 0.024)
        width = 0.97 / columns
        for index, (kind, text, number) in enumerate(rows):
            column, line = divmod(index, per_column)
            x, y = 0.02 + column * width, 0.925 - line * step
            weight = "bold" if kind == "section" else "normal"
            indent = 0.0 if kind == "section" else 0.012
            limit = int(130 / columns)
            shown = text if len(text) <= limit else text[:limit - 1] + "…"
            figure.text(x + indent, y, shown, fontsize=size, weight=weight, va="top")
            if kind == "page":
                figure.text(x + width - 0.03, y, str(number), fontsize=size, va="top", ha="right")
        return figure

    items = []
    for kind, text, number in rows:
        if kind == "section":
            items.append(f"<li class='section'>{html.escape(text)}</li>")
        else:
            items.append(f"<li><a href='#page-{number}'>{html.escape(text)}</a> <span>{number}</span></li>")
    return Page("contents", "Contents", "Contents", draw, "", "<ul class='contents'>" + "".join(items) + "</ul>")


def _png(figure) -> bytes:
    buffer = io.BytesIO()
    figure.savefig(buffer, dpi=PNG_DPI, format="png")
    return buffer.getvalue()


HTML_STYLE = """body{font-family:system-ui,sans-serif;max-width:1180px;margin:2em auto;padding:0 1em;color:#222}
section{border-top:1px solid #bbb;margin-top:2em;padding-top:.5em}img{width:100%;height:auto}
table{border-collapse:collapse;font-size:.85em}td,th{padding:.15em .6em;border-bottom:1px solid #ddd;text-align:left}
.note{font-style:italic;font-size:.9em}.caption{font-style:italic;color:#444}.pageno{float:right;color:#777}
ul.contents{list-style:none;padding-left:0}ul.contents li.section{font-weight:bold;margin-top:.5em}
ul.contents li span{color:#777}"""


def html_document(title: str, rendered: list[Page]) -> str:
    """A self-contained HTML file: each page a section with an anchor, in the PDF's order."""
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
             f"<style>{HTML_STYLE}</style></head><body>"]
    for number, page in enumerate(rendered, start=1):
        parts.append(f"<section id='page-{number}'><span class='pageno'>page {number} of {len(rendered)}</span>"
                     f"<h2>{html.escape(page.title)}</h2>")
        if page.html is not None:
            parts.append(page.html)
        else:
            encoded = base64.b64encode(page.png).decode("ascii")
            parts.append(f"<img alt='{html.escape(page.title)}' src='data:image/png;base64,{encoded}'>")
        if page.caption:
            parts.append(f"<p class='caption'>{html.escape(page.caption)}</p>")
        parts.append("</section>")
    parts.append(f"<footer><p class='note'>rockfrag {__version__}</p></footer></body></html>")
    return "\n".join(parts)


_PLANNED: list = []  # the pages of the report being rendered, for the forked PNG worker


def _page_png(task) -> bytes:
    """Draw page ``index`` again in a worker process and return it as PNG (with its footer)."""
    index, footer, total = task
    figure = _PLANNED[index].draw()
    try:
        add_footer(figure, footer, index + 1, total)
        return _png(figure)
    finally:
        plt.close(figure)


def _png_pages(planned, footer, workers):
    """PNG bytes of every page, in order, and the pool drawing them (None: drawn here).

    The pages are drawn in one forked worker process while this process writes the PDF (both cores
    busy; about 40% less wall time), or here, page by page, when ``workers`` is 1 or the platform
    cannot fork.
    """
    tasks = [(index, footer, len(planned)) for index in range(len(planned))]
    if workers == 1 or "fork" not in multiprocessing.get_all_start_methods():
        return None, (_page_png(task) for task in tasks)
    pool = multiprocessing.get_context("fork").Pool(1)
    return pool, pool.imap(_page_png, tasks)


def render(planned: list[Page], footer: str, output_dir, progress=True, workers=None) -> list[Page]:
    """Draw each page, number it, write it to the PDF and its PNG, close it; one figure open at a time."""
    global _PLANNED
    output_dir = Path(output_dir)
    figure_dir = output_dir / "figures"
    figure_dir.mkdir(parents=True, exist_ok=True)
    for stale in figure_dir.glob("*.png"):  # a previous report may have had other pages
        stale.unlink()
    rendered = []
    _PLANNED = planned
    pool, pngs = _png_pages(planned, footer, workers)
    try:
        with atomic_path(output_dir / "report.pdf") as temporary:
            with PdfPages(temporary, metadata={"Title": footer, "Creator": f"rockfrag {__version__}",
                                               "CreationDate": None}) as document:
                for number, page in enumerate(tqdm(planned, desc="report", unit="page", disable=not progress),
                                              start=1):
                    figure = page.draw()
                    try:
                        add_footer(figure, footer, number, len(planned))
                        document.savefig(figure)
                    finally:
                        plt.close(figure)
                    png = next(pngs)
                    with atomic_path(figure_dir / f"{number:02d}-{page.name}.png") as path:
                        path.write_bytes(png)
                    rendered.append(replace(page, png=png))
    finally:
        if pool is not None:
            pool.terminate()
            pool.join()
        _PLANNED = []
    return rendered


def write_report(planned: list[Page], output_dir, title="rockfrag report", footer=None, progress=True,
                 workers=None):
    """Write report.pdf, report.html and figures/*.png; returns (pdf path, png paths).

    ``workers=1`` draws everything in this process (no forked PNG worker).
    """
    output_dir = Path(output_dir)
    rendered = render(planned, footer or title, output_dir, progress, workers)
    with atomic_path(output_dir / "report.html") as temporary:
        temporary.write_text(html_document(title, rendered), encoding="utf-8")
    pngs = [output_dir / "figures" / f"{n:02d}-{p.name}.png" for n, p in enumerate(rendered, start=1)]
    return output_dir / "report.pdf", pngs


def build_plan(results: Results) -> list[Page]:
    """The numbered page list: the contents inserted as page 2."""
    planned = plan(results)
    return [planned[0], contents_page(planned, results.title), *planned[1:]]


def _open_optional(path):
    path = Path(path)
    if not path.is_file():
        return None
    with xr.open_dataset(path) as dataset:
        return dataset.load()


def report_stage(config: StudyConfig, cube: xr.Dataset, ida: xr.Dataset, fragility: xr.Dataset,
                 risk: xr.Dataset | None, output: str | os.PathLike, runtime_s: float = float("nan"),
                 applicability: xr.Dataset | None = None, progress: bool = True,
                 workers: int | None = None) -> tuple[Path, list[Path]]:
    """Read what the report needs beyond the given datasets from ``output`` and write the report.

    The report reads ``showcase.nc`` for the records, never the records themselves, and runs no solver.

    Parameters
    ----------
    config : StudyConfig
        The study (its ``[report]`` table gives the title, project and author).
    cube, ida, fragility : xarray.Dataset
        The opened ``cube.nc``, ``ida.nc`` and ``fragility.nc`` of the study.
    risk : xarray.Dataset or None
        The risk variables (``pipeline.risk.risk_dataset``), merged into ``fragility`` when they are a
        separate dataset; None when ``fragility`` holds them or there is no risk.
    output : str or os.PathLike
        The study's output folder: ``showcase.nc``, ``efficiency.nc``, ``applicability.nc`` and, when
        ``cube`` applied the vertical components, ``cube_without_vertical.nc`` are read from it when present,
        and the report is written to it.
    runtime_s : float, optional
        Wall time of the pipeline run [s], stated on the title page; NaN leaves it out.
    applicability : xarray.Dataset, optional
        The applicability sweep; None reads ``applicability.nc`` if there is one.
    progress : bool, optional
        Show a progress bar over the pages.
    workers : int, optional
        1 draws every page in this process; otherwise the PNGs are drawn in one forked worker.

    Returns
    -------
    pdf : pathlib.Path
        ``output/report.pdf`` (``report.html`` beside it).
    pngs : list of pathlib.Path
        ``output/figures/NN-name.png``, one per page in page order.
    """
    output = Path(output)
    if risk is not None and risk is not fragility and "probability_in_life" not in fragility:
        fragility = fragility.merge(risk, combine_attrs="override")
        fragility.attrs.update(risk.attrs)
    efficiency = _open_optional(output / "efficiency.nc")
    if applicability is None:
        applicability = _open_optional(output / "applicability.nc")
    comparison = open_comparison(cube, output)
    vertical = None if comparison is None else vertical_effect(cube, comparison, damage_states_from_config(config.raw))
    results = Results(config, cube, ida, fragility, output, showcase=_open_optional(output / "showcase.nc"),
                      applicability=applicability, efficiency=efficiency, runtime_s=runtime_s, vertical=vertical)
    settings = results.settings
    footer = " · ".join(str(part) for part in (settings.get("project"), results.title, f"study '{config.name}'")
                        if part)
    return write_report(build_plan(results), output, results.title, footer, progress, workers)


__all__ = ["Page", "Results", "build_plan", "plan", "report_stage", "write_report"]
