"""Report legibility (issue 20, "Words a client reads"; the client read's FINDINGS 12, 18, 22, 24-28, 30, 32):
one test per defect, each able to catch it again. Overprinting is measured on the drawn figure (matplotlib's
text extents), never from the code's own layout numbers; the figures come from the small study's results
(fixture ``small_pipeline``) or from hand-made datasets."""

from __future__ import annotations

import html as html_module
import re

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

from rockfrag.report import figures
from rockfrag.report.layout import add_footer, log_ticks, new_page
from rockfrag.report.text import draw_text_page, heading, paragraph, table
from tests.helpers import pipeline_results

# ---------------------------------------------------------------- what the drawn page shows


def _shown_texts(figure, drawn=False):
    """Every text a reader sees on the drawn figure, with its extent in pixels.

    Tick labels count only for the ticks inside the axis's view (matplotlib keeps the others, undrawn).
    ``drawn``: the figure was just drawn on its canvas at its own dpi (saved as the report's PNG), so the extents
    are measured on that drawing, without drawing it again.
    """
    if not drawn:
        figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    all_ticks, drawn_ticks = set(), set()
    for axis in [a for parent in figure.axes for a in (parent, *parent.child_axes)]:
        for side in (axis.xaxis, axis.yaxis):
            for tick in side.get_major_ticks() + side.get_minor_ticks():
                all_ticks.update((id(tick.label1), id(tick.label2)))
            if axis.get_visible():
                for tick in side._update_ticks():  # the ticks matplotlib draws
                    drawn_ticks.update((id(tick.label1), id(tick.label2)))
    shown = []
    for text in figure.findobj(plt.Text):
        if not text.get_visible() or not text.get_text().strip():
            continue
        if id(text) in all_ticks and id(text) not in drawn_ticks:
            continue
        if text.axes is not None and not text.axes.get_visible():
            continue
        shown.append((text, text.get_window_extent(renderer)))
    return shown


def overprinted(figure, shown=None) -> list[tuple[str, str]]:
    """Pairs of texts whose boxes overlap by more than a pixel each way (a sweep along x: fast on tables)."""
    shown = sorted(shown if shown is not None else _shown_texts(figure), key=lambda item: item[1].x0)
    pairs = []
    for index, (first, box) in enumerate(shown):
        for second, other in shown[index + 1:]:
            if other.x0 >= box.x1 - 1:
                break
            common_width = min(box.x1, other.x1) - max(box.x0, other.x0)
            common_height = min(box.y1, other.y1) - max(box.y0, other.y0)
            if common_width > 1 and common_height > 1:
                pairs.append((first.get_text()[:40], second.get_text()[:40]))
    return pairs


def off_page(figure, shown=None) -> list[str]:
    """Texts that run past an edge of the page."""
    width, height = figure.bbox.width, figure.bbox.height
    return [text.get_text()[:50] for text, box in (shown if shown is not None else _shown_texts(figure))
            if box.x0 < -0.5 or box.y0 < -0.5 or box.x1 > width + 0.5 or box.y1 > height + 0.5]


def _assert_legible(figure, name):
    """No overprinted text and none off the page, with the footer drawn."""
    add_footer(figure, "a report title", 1, 1)
    assert overprinted(figure) == [], name
    assert off_page(figure) == [], name


def test_the_overprint_check_catches_overprinted_texts():
    """The check itself can fail: two labels at one place, and one running off the page."""
    figure = new_page("A title")
    figure.text(0.5, 0.5, "2,475 yr")
    figure.text(0.5, 0.5, "975 yr")
    figure.text(0.99, 0.3, "a label that runs past the right edge of the page")
    try:
        assert overprinted(figure) == [("2,475 yr", "975 yr")]
        assert off_page(figure) == ["a label that runs past the right edge of the page"]
    finally:
        plt.close(figure)


@pytest.mark.slow
def test_each_kind_of_page_drawn_again_from_the_files_is_legible_and_the_same(small_pipeline, monkeypatch, tmp_path):
    """One page of each kind (the first block's; every text page) of the small study's report, drawn again as the
    report draws it (footer included) from the result files alone, every solver forbidden. One drawing serves
    two checks:

    - FINDINGS 24-28, 12: panel titles, return-period labels, y labels, subtitles, legend entries and table
      cells never overlap, and no text is cut at the page edge;
    - the report is made from its files: each figure page drawn here is, byte for byte, the PNG the fragility
      run drew from its datasets in memory, and report.html (every text page, caption and heading, the PNGs
      embedded) is, character for character, the one planned from the files. The run time and the run's
      statistics, which the title and provenance pages state, are read back from the run's HTML.
    """
    import shutil
    from dataclasses import replace

    import rockfrag.models as models
    from rockfrag.config import load_study
    from rockfrag.report import (
        PNG_DPI,
        build_plan,
        figure_file,
        figure_png,
        html_document,
        report_footer,
        report_results,
    )

    output, study, _ = small_pipeline

    def forbidden(*args, **kwargs):
        raise AssertionError("the report ran a solver")

    for name in ("simulate", "simulate_batch", "simulate_histories"):
        monkeypatch.setattr(models, name, forbidden)
    copy = tmp_path / "copy"  # the result files without the report the run wrote
    shutil.copytree(output, copy, ignore=shutil.ignore_patterns("report.pdf", "report.html", "figures"))
    written = (output / "report.html").read_text()
    opened = {name: xr.load_dataset(copy / f"{name}.nc") for name in ("cube", "ida", "fragility")}
    config = load_study(study)
    runtime, run = _run_statement(written)
    results = report_results(config, opened["cube"], opened["ida"], opened["fragility"], None, copy, runtime_s=runtime,
                             run=run)
    planned, footer = build_plan(results), report_footer(results)
    assert {"ida-paper", "showcase-response", "applicability", "efficiency"} <= {page.name for page in planned}
    figure_files = [figure_file(number, page) for number, page in enumerate(planned, start=1) if page.html is None]
    assert sorted(path.name for path in (output / "figures").glob("*.png")) == figure_files
    blocks = [block.name for block in config.blocks]
    kinds, rendered = set(), []
    for number, page in enumerate(planned, start=1):
        png = b"" if page.html is not None else (output / "figures" / figure_file(number, page)).read_bytes()
        kind = page.name
        for block in blocks:
            kind = kind.replace(block, "")
        if page.html is not None or kind not in kinds:
            kinds.add(kind)
            figure = page.draw()
            try:
                add_footer(figure, footer, number, len(planned))
                if page.html is None:
                    assert figure.dpi == PNG_DPI  # the PNG's drawing is the figure's own: its texts are measured on it
                    assert figure_png(figure) == png, f"page {number} ({page.name}) drawn from the files differs"
                shown = _shown_texts(figure, drawn=page.html is None)
                assert overprinted(figure, shown) == [], page.name
                assert off_page(figure, shown) == [], page.name
            finally:
                plt.close(figure)
        rendered.append(replace(page, png=png))
    assert html_document(results.title, rendered) == written
    assert b"/CreationDate" not in (output / "report.pdf").read_bytes()  # the same files, the same PDF
    assert plt.get_fignums() == []


def _run_statement(html: str) -> tuple[float, dict | None]:
    """The run time [s] and the run's statistics (``runs_computed``, ``cells_reused``, ``cells``) that a report's
    title and provenance pages state, read back from its HTML (NaN and None where it states none)."""
    runtime = re.search(r"<td>run time</td><td>(\d+) s up to this report", html)  # the provenance page
    computed = re.search(r"([\d,]+) of them were computed for this report, the results of (\d+) of its (\d+) ", html)
    run = {"runs_computed": int(computed.group(1).replace(",", "")), "cells_reused": int(computed.group(2)),
           "cells": int(computed.group(3))} if computed else \
        {"runs_computed": 1, "cells_reused": 0, "cells": 1} if "all computed for this report" in html else \
        {"runs_computed": 0, "cells_reused": 1, "cells": 1} if "computed in an earlier run" in html else None
    return float(runtime.group(1)) if runtime else float("nan"), run


# ---------------------------------------------------------------- IDA pages (FINDINGS 24)

def _marked_axis(intensities, low=0.1, high=50.0):
    figure = new_page("marks")
    axis = figure.add_axes([0.1, 0.2, 0.3, 0.2])
    axis.set_yscale("log")
    axis.set_ylim(low, high)
    marks = figures.CredibleMarks(tuple(range(len(intensities))), tuple(intensities), None)
    return figure, axis, marks


def test_close_return_period_marks_share_one_label_and_far_ones_keep_their_own():
    """On a probability panel (intensity along x) the return periods are named above the axes, outside the data,
    each label over its own lines; close lines share one label. On an IDA panel (intensity along y) the legend
    names them (issue 36: a label on the 0.82 g line instead of the hazard lines)."""
    marks = figures.CredibleMarks((475.0, 975.0, 2475.0, 10000.0), (0.30, 0.39, 0.57, 20.0), None)
    figure = new_page("marks")
    axis = figure.add_axes([0.1, 0.2, 0.3, 0.2])
    axis.set_xscale("log")
    axis.set_xlim(0.1, 50.0)
    try:
        groups = figures.mark_groups(axis, marks, along="x")
        assert [label for _, label in groups] == ["475 / 975 / 2,475 yr", "10,000 yr"]
        figures.mark_intensities(axis, marks, along="x")
        assert len(axis.texts) == 0  # nothing over the data
        top = axis.child_axes[0]
        figure.canvas.draw()
        labels = [t.get_text() for t in top.get_xticklabels() if t.get_text()]
        assert labels == ["475 / 975 / 2,475 yr", "10,000 yr"]
        assert overprinted(figure) == []
        for intensity in marks.intensities:  # every intensity keeps its own line
            assert any(np.allclose(line.get_xdata(), intensity) for line in axis.lines)
    finally:
        plt.close(figure)
    figure, axis, _ = _marked_axis([])
    try:
        figures.mark_intensities(axis, marks, along="y")
        assert len(axis.texts) == 0 and len(axis.child_axes) == 0
        legend = " ".join(axis.get_legend_handles_labels()[1])
        assert "475, 975, 2,475, 10,000 years (from the lowest line up)" in legend
    finally:
        plt.close(figure)


@pytest.mark.parametrize("low, high", [(0.3, 0.9), (0.1, 20.0), (0.235, 47.1), (0.06, 0.11), (2.0, 2000.0)])
def test_a_log_axis_always_has_tick_values(low, high):
    """FINDINGS 24 (p. 23: the PGA axis had no tick values): at least two labelled ticks on any range that holds
    two of 1-9 x 10^n, each of that form and inside the range."""
    values = log_ticks(low, high)
    assert len(values) >= 2
    for value in values:
        assert low <= value <= high
        mantissa = value / 10 ** np.floor(np.log10(value) + 1e-12)
        assert abs(mantissa - round(mantissa)) < 1e-9


def test_drawn_log_axes_label_their_ticks_on_a_short_range():
    figure = new_page("short range")
    axis = figure.add_axes([0.1, 0.2, 0.2, 0.15])
    axis.plot([1, 2], [0.3, 0.9])
    from rockfrag.report.layout import log_y_axis

    log_y_axis(axis, (0.3, 0.9))
    try:
        shown = [text.get_text() for text, _ in _shown_texts(figure) if text in axis.get_yticklabels()]
        assert len([t for t in shown if t]) >= 2
        assert all(0.3 <= float(t) <= 0.9 for t in shown)
    finally:
        plt.close(figure)


def test_long_captions_are_wrapped_whole_inside_the_page():
    """FINDINGS 24: captions were cut at the page edge (and at two lines): every word is drawn, inside the page,
    clear of the footer."""
    from rockfrag.report import CAPTIONS

    caption = CAPTIONS["ida"] + " " + CAPTIONS["fragility-soils"][:220]  # longer than any caption of the report
    figure = new_page("A page", caption)
    try:
        add_footer(figure, "a report title", 3, 9)
        drawn = next(t for t in figure.texts if t.get_text().startswith(caption[:20]))
        assert drawn.get_text().split() == caption.split()
        assert off_page(figure) == [] and overprinted(figure) == []
    finally:
        plt.close(figure)


# ---------------------------------------------------------------- response page (FINDINGS 25)

def test_the_ground_motion_shares_the_time_axis_of_the_response_and_has_one(small_pipeline):
    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    figure = figures.showcase_response_page(results.showcase, "")
    try:
        figure.canvas.draw()
        ground = [a for a in figure.axes if a.get_ylabel().startswith("ground") or
                  "ground acceleration" in a.get_title()]
        response = [a for a in figure.axes if a.get_ylabel().startswith(("θ", "Δy"))]
        assert len(ground) == 1 and response  # once, above the θ column (read 3, user C6: two were the same)
        for axis in ground:
            assert axis.get_xlim() == response[0].get_xlim()
            assert axis.get_xlabel() == "time [s]"
            assert [t.get_text() for t in axis.get_xticklabels() if t.get_visible() and t.get_text()]
            # above its column, as wide as it: one time on the page is one time in the ground and the response
            column = [a for a in response if abs(a.get_position().x0 - axis.get_position().x0) < 1e-6]
            assert column and abs(column[0].get_position().width - axis.get_position().width) < 1e-6
    finally:
        plt.close(figure)


# ---------------------------------------------------------------- fragility pages (FINDINGS 26)

def test_the_recommended_curve_has_a_style_of_its_own():
    from rockfrag.report.adapters import model_styles, models_of

    names = ["housner", "recommended", "ssi", "winkler", "ssi-paper"]
    models = models_of(xr.Dataset(coords={"model": names}))
    styles = model_styles(models)
    keys = {name: (style["color"], str(style["ls"])) for name, style in styles.items()}
    assert len(set(keys.values())) == len(names)
    solid = [name for name, (_, ls) in keys.items() if ls in ("-", "solid")]
    assert solid == ["recommended"]  # the answer's curve is the only solid one
    assert styles["recommended"]["lw"] > max(s["lw"] for n, s in styles.items() if n != "recommended")


@pytest.mark.slow
def test_every_fragility_panel_has_x_tick_values(small_pipeline):
    """FINDINGS 26: the top-row panels had no x tick labels. About 1 s."""
    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    block = str(results.cube.block.values[0])
    soils = [str(s) for s in results.cube.soil.values]
    figure = figures.fragility_by_model_page(results.fragility, block, [soils[0], soils[-1]], "",
                                             marks=results.marks(block))
    try:
        figure.canvas.draw()
        for axis in (a for a in figure.axes if a.get_visible()):
            labels = [t.get_text() for t in axis.get_xticklabels() if t.get_visible() and t.get_text()]
            assert len(labels) >= 2, axis.get_title()
    finally:
        plt.close(figure)


# ---------------------------------------------------------------- applicability and efficiency (FINDINGS 27, 28)

def test_the_applicability_legend_names_each_model_each_block_and_each_band(small_pipeline):
    from rockfrag.report.adapters import models_of, short_label

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    figure = figures.applicability_page(results.cube, "")
    try:
        labels = [t.get_text().replace("\n", " ") for legend in figure.legends for t in legend.get_texts()]
        for model in (m for m in models_of(results.cube) if not m.rigid_base):
            assert sum(label == short_label(model) for label in labels) == 1, labels
        for block in results.cube.block.values:
            assert sum(label.startswith(f"block: {block}") for label in labels) == 1, labels
        assert any("300-1000 MPa" in label and "paper" in label and "rigid base" in label for label in labels)
        assert any("±10%" in label for label in labels)
    finally:
        plt.close(figure)


def _efficiency(measures=("pga", "pgv", "pga_ratio")):
    rng = np.random.default_rng(0)
    shape = (len(measures), 2, 2, 2)  # measure, block, soil, model
    dispersion = rng.uniform(0.2, 0.9, shape)
    if "pga_ratio" in measures:  # PGA divided by a constant of the block: the same dispersion
        dispersion[measures.index("pga_ratio")] = dispersion[measures.index("pga")]
    p = rng.uniform(0.0, 1.0, shape)
    dims = ("measure", "block", "soil", "model")
    return xr.Dataset({"dispersion": (dims, dispersion), "p_magnitude": (dims, p), "p_distance": (dims, p[::-1])},
                      coords={"measure": list(measures), "block": ["paper", "cabinet"], "soil": ["sand", "rock"],
                              "model": ["housner", "ssi"]})


def test_efficiency_leaves_out_a_measure_identical_by_construction_and_says_why():
    from rockfrag.report import _twins_words

    dataset = _efficiency()
    assert figures.efficiency_twins(dataset) == {"pga_ratio": "pga"}
    assert figures.efficiency_twins(_efficiency(("pga", "pgv"))) == {}
    equal = _efficiency(("pga", "pgv"))
    equal["dispersion"][:] = 0.4
    assert figures.efficiency_twins(equal) == {}  # equal by chance, not by construction: both drawn
    figure = figures.efficiency_page(dataset, "caption")
    try:
        top = figure.axes[0]
        assert [t.get_text() for t in top.get_xticklabels()] == ["PGA", "PGV"]
        bars = {patch.get_facecolor() for patch in top.patches}
        markers = {tuple(c) for collection in figure.axes[1].collections for c in collection.get_facecolor()}
        assert not bars & markers  # p-value markers do not reuse the blocks' colours
        _assert_legible(figure, "efficiency")
    finally:
        plt.close(figure)
    words = _twins_words(dataset)
    assert "PGA/(g·tanα) repeats PGA" in words and "identical by construction" in words


# ---------------------------------------------------------------- text pages (FINDINGS 12, 32)

def test_table_headers_wrap_and_are_never_cut():
    """FINDINGS 12: "P(the block ove": a last header past the page edge. Every header word is drawn, inside."""
    header = ["block", "model", "soil", "θmax/α ≥ 0.5: median / β", "The block overturns: median / β",
              "P(the block overturns) in 50 years"]
    rows = [["squat machinery skid", "Winkler bed, tensionless, band high edge (restitution band)", "gravel",
             "203† / 1.41", "203† / 1.27", "<0.01%"]] * 3
    figure = draw_text_page("Summary", [table(header, rows)])
    try:
        drawn = " ".join(t.get_text() for t in figure.texts)
        for title in header:
            assert all(word in drawn.split() for word in title.split()), title
        assert off_page(figure) == [] and overprinted(figure) == []
    finally:
        plt.close(figure)


def test_a_short_section_shares_the_page_of_the_one_before():
    """FINDINGS 32: pages holding a few rows or one line. The next section starts where the last one ends."""
    from rockfrag.report import _packed_pages, contents_page, html_document

    long_rows = [[f"row {n}", "x"] for n in range(45)]
    parts = [("limitations", "Limitations", "Limitations", [heading("Tension"), table(["a", "b"], long_rows),
                                                             heading("Solver"), paragraph("Every run finished.")]),
             ("records-table", "Records", "Intensity measures of the records", [table(["record"], [["r1"], ["r2"]])])]
    pages = _packed_pages(parts)
    assert len(pages) == 2
    assert pages[1].section == "Limitations" and pages[1].also == ("Records",)
    assert "Every run finished." in pages[1].html and "r2" in pages[1].html
    assert pages[0].title == "Limitations (1/2)" and pages[1].title == "Limitations (2/2)"
    contents = contents_page(pages, "Report")
    assert "href='#section-records'" in contents.html
    document = html_document("Report", [contents, *pages])
    assert "id='section-records'" in document


def test_what_is_left_of_a_run_goes_on_its_last_page_when_it_overflows_a_little():
    """FINDINGS 32 (a page with 2 records of a table): a few rows more than a page hold go on it, set closer,
    inside the page; many more start a page of their own."""
    from rockfrag.report.text import BOTTOM, LINE, STRETCH, TOP, paginate

    capacity = int((TOP - BOTTOM) / LINE)
    rows = [[f"record {n}", "0.41"] for n in range(capacity - 4 + STRETCH)]  # heading 2, header 1, gap 1
    assert len(paginate([heading("Records"), table(["record", "PGA [g]"], rows)])) == 1
    figure = draw_text_page("Records", [heading("Records"), table(["record", "PGA [g]"], rows)])
    try:
        add_footer(figure, "a report title", 1, 1)
        assert overprinted(figure) == [] and off_page(figure) == []
        last = next(t for t in figure.texts if t.get_text() == rows[-1][0])
        assert last.get_position()[1] > BOTTOM - 0.01  # above the caption and footer area
    finally:
        plt.close(figure)
    more = [[f"record {n}", "0.41"] for n in range(capacity + 2 * STRETCH)]
    pages = paginate([heading("Records"), table(["record", "PGA [g]"], more)])
    assert len(pages) == 2 and len(pages[1][0].rows) > STRETCH


def test_a_table_too_wide_for_the_page_is_set_smaller_not_cut():
    from rockfrag.report.text import TABLE_SIZE, table_layout

    wide = table(["block", "model", "why no median"], [["squat machinery skid", "Winkler bed, tensionless, band high "
                                                        "edge (restitution band)", "reached only at the highest "
                                                        "levels: median above the studied range " * 2]])
    _, _, size = table_layout(wide)
    assert size < TABLE_SIZE
    figure = draw_text_page("Limitations", [wide])
    try:
        assert off_page(figure) == []
    finally:
        plt.close(figure)


# ---------------------------------------------------------------- title page and provenance (FINDINGS 22)

@pytest.mark.slow
def test_the_title_page_has_no_code_identifiers_and_the_appendix_keeps_them(small_pipeline):
    from rockfrag.report.sections import reproduce_items, run_time_words, title_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study, runtime_s=0.0)
    title = " ".join(item.text for item in title_items(results))
    fingerprint = str(results.cube.attrs["config_hash"])
    for word in (fingerprint, "hash", "rockfrag", "seed", ".toml", "Run time"):
        assert word not in title, word
    appendix = reproduce_items(results)
    cells = " ".join(cell for item in appendix for row in item.rows for cell in row)
    assert fingerprint in cells and "configuration fingerprint" in cells
    assert str(results.fragility.attrs["bootstrap_seed"]) in cells
    run_time = next(row[1] for item in appendix for row in item.rows if row[0] == "run time")
    assert run_time.startswith("not recorded") and "0 s" not in run_time
    assert run_time_words(315.0) == "5 min" and run_time_words(42.0) == "42 s"


# ---------------------------------------------------------------- sources and references (FINDINGS 28, 30, 18)

CITATION = re.compile(r"\b((?:[A-Z][\w-]*(?: et al\.| & [A-Z][\w-]*)?) (?:19|20)\d\d)\b")


@pytest.mark.slow
def test_every_reference_is_cited_and_every_citation_listed(small_pipeline):
    """FINDINGS 30: works listed but never cited (ElGawady, ASCE 7-22, Chopra & Yim, Shenton, Makris &
    Vassiliou) and a citation never listed (Luco & Cornell 2007). Read from the report's HTML."""
    from rockfrag.report.words import REFERENCES

    html = (small_pipeline.output / "report.html").read_text()
    text = html_module.unescape(re.sub(r"<[^>]+>", " ", re.sub(r"<img[^>]*>", " ", html)))
    references = text.index("The pages cite these works")
    appendix = text.index("How to reproduce this report", references)
    body = text[:references] + text[appendix:]
    listed = [key for key in REFERENCES if key != "paper" and f"{key}: " in text[references:appendix]]
    assert len(listed) >= 10  # the page lists what the pages cite (a study without steel: no AISC 360-16)
    for key in listed:
        assert key in body, f"{key} is listed but never cited"
    for cited in set(CITATION.findall(body)):
        assert cited in REFERENCES, f"{cited} is cited but not listed"


def test_the_stated_limits_and_values_carry_their_source(small_pipeline):
    """FINDINGS 30, 18: the 1% and 10% limits, the 50-year life, μ per soil, the moduli: a source or the study's
    choice in plain words."""
    from rockfrag.report.sections import sources_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    bullets = [item.text for item in sources_items(results)]
    overturning = next(b for b in bullets if "overturns" in b and "1%" in b)
    assert "ASCE 7-22" in overturning
    assert any("θmax/α ≥ 0.5" in b and "10%" in b and "study's choice" in b for b in bullets)
    assert any(b.startswith("Design life 50 years") and "study's choice" in b for b in bullets)
    friction = next(b for b in bullets if "μ_s" in b)
    assert "NAVFAC DM-7.02" in friction and results.friction_text in friction
    assert any("Table 1" in b and "moduli" in b for b in bullets)


# ---------------------------------------------------------------- table type size (issue 20: 6 pt answer tables)

SMALLEST_TABLE_TYPE = 7.5  # pt: the client could not read the 6 pt answer tables in print

def test_a_table_too_wide_at_the_smallest_type_is_split_by_columns_and_nothing_is_cut():
    from rockfrag.report.text import fit_table, table_layout

    header = ["damage state"] + [f"on soil number {n}: P in 50 years" for n in range(7)]
    rows = [[f"state {r}"] + [f"<0.01%, not reached below 0.82 g ({r}{n})" for n in range(7)] for r in range(4)]
    wide = table(header, rows)
    parts = fit_table(wide)
    assert len(parts) > 1 and all(part.header[0] == "damage state" for part in parts)  # the key repeated
    assert [h for part in parts for h in part.header[1:]] == header[1:]
    assert all(table_layout(part)[2] >= SMALLEST_TABLE_TYPE for part in parts)
    long_cell = table(["block", "why"], [["skid", "reached only at the highest levels " * 8]])
    (wrapped,) = fit_table(long_cell)
    assert len(wrapped.rows) > 1 and " ".join(r[1] for r in wrapped.rows).split() == long_cell.rows[0][1].split()
    for items in ([wide], [long_cell]):
        figure = draw_text_page("Answer", items)
        try:
            sizes = [t.get_fontsize() for t in figure.texts if t.get_text() and t.get_fontsize() < 9.5]
            assert min(sizes) >= SMALLEST_TABLE_TYPE
            drawn = " ".join(t.get_text() for t in figure.texts)
            assert all(cell in drawn for row in rows for cell in row) if items == [wide] else True
            assert off_page(figure) == [] and overprinted(figure) == []
        finally:
            plt.close(figure)


@pytest.mark.slow
def test_no_table_of_the_report_is_set_below_the_smallest_type(small_pipeline):
    """The small study's answer pages were set in 7.4 pt and its limitations in 6.8 pt."""
    from rockfrag.report import build_plan

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    for page in build_plan(results):
        if page.html is None:
            continue
        figure = page.draw()
        try:
            small = {t.get_text() for t in figure.texts if t.get_text() and t.get_fontsize() < SMALLEST_TABLE_TYPE}
            assert not small, (page.name, sorted(small)[:3])
        finally:
            plt.close(figure)


def test_a_log_axis_of_about_a_decade_labels_the_site_intensities_range():
    """Cold read 5 (default figures, pp. 30-38): a PGA axis from 0.22 to 3.3 g labelled only 0.5, 1 and 2, so every
    site intensity (0.24-0.67 g) sat where no tick was labelled. About a decade gets 1, 2, 3, 5 x 10^n."""
    assert log_ticks(0.22, 3.3) == [0.3, 0.5, 1.0, 2.0, 3.0]
    assert log_ticks(0.22, 3.3, most=3) == [0.5, 1.0, 2.0]  # a short axis keeps fewer


def test_the_shipped_soils_colours_differ_in_hue_not_shade():
    """Cold read 8, user C3: clay (#8c510a) and sand (#d8a03a) were two browns; a two-soil study could not tell its
    curves apart. Each pair of soil colours differs by at least 40 degrees of hue, or one of them is a grey; none is
    the recommended curve's red or the rigid base's black."""
    import colorsys
    import itertools

    from matplotlib.colors import to_rgb

    from rockfrag.report.layout import RECOMMENDED_STYLE, RIGID_STYLE, SOIL_COLOURS

    def hue_saturation(colour):
        hue, _, saturation = colorsys.rgb_to_hls(*to_rgb(colour))
        return hue * 360, saturation

    for (soil_a, a), (soil_b, b) in itertools.combinations(SOIL_COLOURS.items(), 2):
        (hue_a, sat_a), (hue_b, sat_b) = hue_saturation(a), hue_saturation(b)
        if min(sat_a, sat_b) < 0.1:  # a grey against a colour: told apart by saturation
            assert max(sat_a, sat_b) > 0.3, (soil_a, soil_b)
            continue
        apart = min(abs(hue_a - hue_b), 360 - abs(hue_a - hue_b))
        assert apart >= 40, (soil_a, a, soil_b, b, apart)
    assert not {c.lower() for c in SOIL_COLOURS.values()} & {RECOMMENDED_STYLE["color"], RIGID_STYLE["color"],
                                                             "#000000", "black"}


def test_the_contents_column_break_never_cuts_an_entry():
    """Cold read 8, user C13: a wrapped contents entry ("Fragility by model: enclosure E-1 (a solid block 1.2 m ×
    3.0" / "m, 4.5 t)") was cut by the column break. Wherever the break falls, each entry's lines, and a section
    heading with the page row under it, stay in one column; every line is placed once, in order."""
    from rockfrag.report import CONTENTS_LINES, contents_layout

    long = "Fragility by model: enclosure E-1 (a solid block 1.2 m × 3.0 m, 4.5 t), with a title that wraps"
    for lead in range(CONTENTS_LINES - 4, CONTENTS_LINES + 1):
        rows = [("page", f"page {i}", i) for i in range(lead)] + [("section", "Fragility", lead),
                                                                  ("page", long, lead), ("page", long, lead + 1)]
        placed = contents_layout(rows)
        order = [column * CONTENTS_LINES + line for column, line, *_ in placed]
        assert order == sorted(set(order)) and all(line < CONTENTS_LINES for _, line, *_ in placed)
        section = next(p for p in placed if p[3] == "Fragility")
        first_entry = [p for p in placed if p[2] == "page" and not p[3].startswith("page ")]
        wraps = len(first_entry) // 2
        assert wraps >= 2, first_entry  # the long title wraps: the test can fail
        assert {p[0] for p in first_entry[:wraps]} == {section[0]}, (lead, placed[-8:])
        assert len({p[0] for p in first_entry[wraps:]}) == 1, (lead, placed[-8:])


def test_a_contents_title_never_runs_into_its_page_number():
    """Cold read 12 (coordinator's look at the default report's three-column contents): the bold answer headings
    wrapped at the two-column width, so "... (0.6 m × 3.0 m, 2" ran up to its page number "9". In two and in three
    columns, every title line ends at least two character widths before the page number on its line."""
    from rockfrag.report import contents_page
    from rockfrag.report.layout import Page

    long_block = "slender solid block, cabinet-sized (0.6 m × 3.0 m, 2 t)"
    for count in (12, 24):  # two columns; three columns
        planned = [Page("title", "Title", "Seismic fragility of unanchored rocking blocks", draw=lambda: None)]
        planned += [Page(f"answer-{i}", f"Answer: {long_block} number {i}", f"Answer {i}", draw=lambda: None,
                         heading=f"Answer: {long_block} number {i}") for i in range(count // 4)]
        planned += [Page(f"fig-{i}", "Fragility", f"Fragility by soil: {long_block}, recommended, with Housner "
                                                  f"(rigid base) for reference {i}", draw=lambda: None)
                    for i in range(count)]
        figure = contents_page(planned, 2).draw()
        try:
            shown = _shown_texts(figure)
            numbers = [(t, box) for t, box in shown if t.get_text().isdigit() and t.get_ha() == "right"]
            titles = [(t, box) for t, box in shown if not t.get_text().isdigit() and t.get_text() != "Contents"]
            assert len(numbers) >= count
            em = figure.dpi * 8.5 / 72 * 0.6  # about one character of the contents' largest type, in pixels
            for number, box in numbers:
                same_line = [other for _, other in titles if abs(other.y1 - box.y1) < 2 and other.x0 < box.x0
                             and box.x0 - other.x0 < figure.bbox.width / 2]
                assert same_line, number.get_text()
                gap = box.x0 - max(other.x1 for other in same_line)
                assert gap >= 2 * em, (count, number.get_text(), gap)
        finally:
            plt.close(figure)


def test_a_section_that_starts_part_way_down_a_page_is_listed_with_the_heading_it_prints():
    """Cold read 12, user C2: 'Fitted curves ... 8' stood in the contents with no entry under it, while page 8 heads
    that section 'Fitted fragility functions'. The contents list the heading the page prints."""
    from rockfrag.report import contents_rows
    from rockfrag.report.layout import Page

    planned = [Page("answer", "Answer: enclosure", "Answer: enclosure (4/4)", draw=lambda: None,
                    heading="Answer: enclosure", also=("Fitted curves",),
                    also_headings=("Fitted fragility functions",))]
    assert contents_rows(planned, 2)[-2:] == [("section", "Fitted curves", 1),
                                              ("page", "Fitted fragility functions", 1)]


def test_a_short_table_goes_whole_to_the_next_page_rather_than_split():
    """Cold read 12 (default text, second round): a design-life table's steel part was split after its six state
    rows, so its β and action rows stood alone under a repeated header on the next page. A table of at most
    SHORT_TABLE rows that fits a page is not split: it starts the next page whole."""
    from rockfrag.report.text import SHORT_TABLE, paginate, paragraph, table

    rows = [[f"state {i}", f"{i}%"] for i in range(8)]
    assert len(rows) <= SHORT_TABLE
    for lead in range(25, 40):
        items = [paragraph(f"line {i}") for i in range(lead)] + [table(["damage state", "on steel"], rows)]
        pages = paginate(items)
        holding = [index for index, page in enumerate(pages) if any(item.kind == "table" for item in page)]
        assert len(holding) == 1, (lead, holding)
        placed = next(item for item in pages[holding[0]] if item.kind == "table")
        assert placed.rows == rows
