"""Figures without defects (issue 36, item 4): a layout check of every figure page of the small study, shown to
fail on seeded defects. It measures the drawn figure (matplotlib's extents of texts, legends and data paths in
pixels), never the code's own layout numbers:

- a legend (or any text) that runs past the page edge;
- a text over plotted data (a line, its markers, a shaded band or bar of an axes) or over another text;
- an axes with nothing drawn inside it and no note saying why.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.container import BarContainer
from matplotlib.transforms import Bbox

from tests.test_report_client import tool_syntax
from tests.test_report_legibility import _shown_texts, off_page, overprinted

EDGE = 1.5
"""Pixels a box is shrunk by before it counts as touching: a text set beside a line does not overlap it."""


def _shrunk(box: Bbox, by: float = EDGE) -> Bbox:
    return Bbox.from_extents(box.x0 + by, box.y0 + by, box.x1 - by, box.y1 - by)


def _inside(points: np.ndarray, box: Bbox) -> np.ndarray:
    return (points[:, 0] > box.x0) & (points[:, 0] < box.x1) & (points[:, 1] > box.y0) & (points[:, 1] < box.y1)


def _dense(points: np.ndarray, step: float = 1.0) -> np.ndarray:
    """A polyline's points at most ``step`` pixels apart (NaN breaks it into pieces), for tests against a box."""
    points = np.asarray(points, float)
    finite = np.isfinite(points).all(axis=1)
    if len(points) < 2:
        return points[finite]
    start, end = points[:-1], points[1:]
    keep = finite[:-1] & finite[1:]
    start, end = start[keep], end[keep]
    counts = np.maximum(2, np.ceil(np.hypot(*(end - start).T) / step).astype(int) + 1)
    segment = np.repeat(np.arange(len(start)), counts)
    fraction = (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)) / np.repeat(counts - 1,
                                                                                                    counts)
    dense = start[segment] + fraction[:, None] * (end[segment] - start[segment])
    return np.concatenate([dense, points[finite]])


def data_points(axis, references: bool = True) -> np.ndarray:
    """Pixels of everything plotted in ``axis``: its lines (drawn segments and markers), filled bands, scatter
    points and bars, densified to one pixel, clipped to the axes. Spans (axvspan/axhspan shading) are not data;
    reference lines across the axes (axvline/axhline: the site's intensities) are, unless ``references`` is
    False (they alone do not fill a panel)."""
    box = axis.get_window_extent()
    points = []
    for line in axis.get_lines():
        if not line.get_visible() or (not references and line.get_transform() != axis.transData):
            continue
        xy = line.get_transform().transform(np.asarray(line.get_xydata(), float))
        if line.get_linestyle() not in ("None", "none", "", " "):
            points.append(_dense(xy))
        elif line.get_marker() not in (None, "None", "none", "", " "):
            points.append(xy[np.isfinite(xy).all(axis=1)])
    for collection in axis.collections:
        if not collection.get_visible():
            continue
        transform = collection.get_transform()
        for path in collection.get_paths():
            if len(path.vertices):
                points.append(_dense(transform.transform(path.vertices)))
        offsets = collection.get_offsets()
        if len(offsets) and collection.get_offset_transform() is not None:
            points.append(collection.get_offset_transform().transform(np.asarray(offsets, float)))
    for container in axis.containers:
        if isinstance(container, BarContainer):
            for patch in container.patches:
                corners = patch.get_window_extent().corners()[[0, 1, 3, 2, 0]]
                points.append(_dense(corners))
    if not points:
        return np.empty((0, 2))
    points = np.concatenate(points)
    return points[_inside(points, box)]


def layout_defects(figure) -> list[str]:
    """Every layout defect of the figure, in words (empty: none).

    The figure is laid out as for drawing (``draw_without_rendering``: every position and extent, no pixels).
    """
    figure.draw_without_rendering()
    shown = _shown_texts(figure, drawn=True)
    defects = [f"off the page: {text}" for text in off_page(figure, shown)]
    defects += [f"text over text: {first!r} / {second!r}" for first, second in overprinted(figure, shown)]
    page = figure.bbox
    for legend in [*figure.legends, *(axis.get_legend() for axis in figure.axes if axis.get_legend())]:
        box = legend.get_window_extent()
        if box.x0 < page.x0 - 0.5 or box.y0 < page.y0 - 0.5 or box.x1 > page.x1 + 0.5 or box.y1 > page.y1 + 0.5:
            defects.append(f"legend clipped: {box.x0:.0f}-{box.x1:.0f} px across a page of {page.x1:.0f} px")
    defects += footer_defects(figure, shown)
    axes = [axis for axis in figure.axes if axis.get_visible() and axis.axison and not _is_secondary(axis)]
    defects += cut_markers(axes)
    data = {axis: data_points(axis) for axis in axes}
    for text, box in shown:
        inner = _shrunk(box)
        if inner.width <= 0 or inner.height <= 0:
            continue
        for axis, points in data.items():
            if points.size and box.overlaps(axis.get_window_extent()) and _inside(points, inner).any():
                defects.append(f"text over data: {text.get_text()[:40]!r}")
                break
    for axis in data:
        inner = _shrunk(axis.get_window_extent())
        points = data_points(axis, references=False)
        if len(points) and _inside(points, inner).any():
            continue
        notes = [text for text, box in shown if inner.contains(*box.get_points().mean(axis=0))]
        if not notes:
            defects.append(f"empty axes without a note: {axis.get_title()!r}")
    return defects


def footer_defects(figure, shown) -> list[str]:
    """Texts, legends and axes of the page that reach below the footer's rule (over the footer) or off the page.

    The footer (its rule, the report title, the page number: ``FOOTER_ID``) owns the strip under the rule; a
    caption too long for its lines, or a figure too tall, runs into it and both become unreadable.
    """
    from rockfrag.report.layout import FOOTER_ID, FOOTER_RULE

    page = figure.bbox
    rule = page.y0 + FOOTER_RULE * page.height
    defects = [f"over the footer: {text.get_text()[:50]!r}" for text, box in shown
               if text.get_gid() != FOOTER_ID and box.y0 < rule - 0.5]
    for legend in [*figure.legends, *(axis.get_legend() for axis in figure.axes if axis.get_legend())]:
        if legend.get_window_extent().y0 < rule - 0.5:
            defects.append("legend over the footer")
    for axis in figure.axes:
        if not axis.get_visible():
            continue
        box = axis.get_window_extent()
        if box.y0 < rule - 0.5:
            defects.append(f"axes over the footer: {axis.get_title()!r}")
        if box.x0 < page.x0 - 0.5 or box.x1 > page.x1 + 0.5 or box.y1 > page.y1 + 0.5:
            defects.append(f"axes off the page: {axis.get_title()!r}")
    return defects


def cut_markers(axes) -> list[str]:
    """Markers (the records' fractions, a model's points) that the frame of their axes cuts: a point at the last
    level drawn on the right frame is half a disc, and it is the evidence a censored curve rests on."""
    defects = []
    for axis in axes:
        box = axis.get_window_extent()
        for line in axis.get_lines():
            if not line.get_visible() or line.get_marker() in (None, "None", "none", "", " "):
                continue
            xy = line.get_transform().transform(np.asarray(line.get_xydata(), float))
            xy = xy[np.isfinite(xy).all(axis=1)]
            radius = line.get_markersize() / 2.0 * axis.figure.dpi / 72.0
            # a point on the frame (centre at the axis limit) is cut; one wholly beyond the view is a choice of range
            seen = _inside(xy, Bbox.from_extents(box.x0 - 1, box.y0 - 1, box.x1 + 1, box.y1 + 1))
            cut = seen & ((xy[:, 0] - radius < box.x0 - 0.5) | (xy[:, 0] + radius > box.x1 + 0.5)
                          | (xy[:, 1] - radius < box.y0 - 0.5) | (xy[:, 1] + radius > box.y1 + 0.5))
            if cut.any():
                defects.append(f"marker cut by the frame: {axis.get_title()[:40]!r}")
    return defects


def _is_secondary(axis) -> bool:
    """A secondary axis (secondary_xaxis/_yaxis) carries labels only: it is not a panel."""
    return type(axis).__name__ == "SecondaryAxis"


# ---------------------------------------------------------------- the check can fail: seeded defects

def _clean_figure():
    from rockfrag.report.layout import new_page, outside_legend, panels

    figure = new_page("A page", "Read the caption.")
    left, right = panels(figure, 1, 2)[0]
    x = np.linspace(0.0, 1.0, 50)
    left.plot(x, x ** 2, label="a curve")
    right.plot(x, 1 - x, label="another curve")
    outside_legend(figure, [left, right])
    return figure, left, right


def test_a_clean_page_has_no_layout_defect():
    figure, _, _ = _clean_figure()
    try:
        assert layout_defects(figure) == []
    finally:
        plt.close(figure)


def test_the_layout_check_fails_on_a_clipped_legend():
    figure, _, _ = _clean_figure()
    try:
        figure.legends[0].set_bbox_to_anchor((0.97, 0.885), transform=figure.transFigure)
        assert any(defect.startswith("legend clipped") for defect in layout_defects(figure))
    finally:
        plt.close(figure)


def test_the_layout_check_fails_on_a_note_over_data_and_on_overlapping_texts():
    figure, left, right = _clean_figure()
    try:
        left.text(0.5, 0.25, "no curve: not reached", transform=left.transAxes, ha="center", va="center",
                  bbox=dict(facecolor="white"))  # over x**2 at x = 0.5
        right.text(0.2, 0.2, "one label", transform=right.transAxes)
        right.text(0.21, 0.2, "another label", transform=right.transAxes)
        defects = layout_defects(figure)
        assert "text over data: 'no curve: not reached'" in defects
        assert "text over text: 'one label' / 'another label'" in defects
    finally:
        plt.close(figure)


def test_the_layout_check_fails_on_an_empty_panel_without_a_note_and_passes_with_one():
    figure, _, right = _clean_figure()
    try:
        right.lines[0].set_ydata(np.full(50, np.nan))  # nothing to draw
        right.set_title("slip on clay")
        assert "empty axes without a note: 'slip on clay'" in layout_defects(figure)
        right.text(0.5, 0.5, "not computed: base tied", transform=right.transAxes, ha="center")
        assert layout_defects(figure) == []
    finally:
        plt.close(figure)


def test_lines_drawn_on_the_frame_do_not_fill_a_panel():
    """An IDA panel whose records never rock draws every curve at θmax/α = 0, on the frame: it looks empty."""
    figure, left, _ = _clean_figure()
    try:
        left.set_xlim(0.0, 1.0)
        left.set_ylim(0.0, 1.0)
        left.lines[0].set_data(np.zeros(50), np.linspace(0.0, 1.0, 50))
        left.set_title("on clay")
        assert "empty axes without a note: 'on clay'" in layout_defects(figure)
    finally:
        plt.close(figure)


# ---------------------------------------------------------------- every figure page of the small study

@pytest.mark.slow
def test_every_figure_of_the_small_study_is_free_of_layout_defects(small_pipeline):
    """Every figure page as the report draws it (the footer included), and its words: no tool syntax either."""
    import xarray as xr

    from rockfrag.config import load_study
    from rockfrag.report import build_plan, report_results
    from rockfrag.report.layout import add_footer

    output = small_pipeline.output
    opened = {name: xr.load_dataset(output / f"{name}.nc") for name in ("cube", "ida", "fragility")}
    results = report_results(load_study(small_pipeline.study), opened["cube"], opened["ida"], opened["fragility"],
                             None, output)  # every result file the run wrote: the applicability sweep too
    planned = build_plan(results)
    figures = [page for page in planned if page.html is None]
    assert len(figures) >= 15
    found = {}
    for number, page in enumerate(planned, start=1):
        if page.html is not None:
            continue
        figure = page.draw()
        try:
            add_footer(figure, "a report title", number, len(planned))
            defects = layout_defects(figure)
            words = " ".join(text.get_text() for text in figure.findobj(plt.Text))
            defects += [f"tool syntax: {found}" for found in tool_syntax(f"{words} {page.caption}")]
            if defects:
                found[page.name] = defects
        finally:
            plt.close(figure)
    assert found == {}


def test_the_layout_check_fails_on_a_caption_over_the_footer_and_on_a_figure_run_into_it():
    """Cold read 3 (user B4, default B3): the efficiency page's caption, six lines long, was printed over the page
    footer. A caption of that length, and an axes reaching below the footer's rule, are defects."""
    from rockfrag.report.layout import add_footer, new_page, outside_legend, panels

    figure = new_page("A page", "A sentence of a caption that goes on. " * 40)
    axis = panels(figure)[0, 0]
    axis.plot([0, 1], [0, 1], label="a curve")
    outside_legend(figure, [axis])
    add_footer(figure, "a report title", 1, 2)
    try:
        assert any(defect.startswith("over the footer: 'A sentence") for defect in layout_defects(figure))
    finally:
        plt.close(figure)
    figure, left, _ = _clean_figure()
    add_footer(figure, "a report title", 1, 2)
    try:
        assert layout_defects(figure) == []  # the footer itself is no defect
        left.set_position([0.07, 0.01, 0.3, 0.5])
        assert "axes over the footer: ''" in layout_defects(figure)
    finally:
        plt.close(figure)


def test_the_layout_check_fails_on_a_marker_cut_by_the_frame():
    """Cold read 3 (user B6, default B7): the records' fraction at the highest level (the credible cap) sat on the
    right frame of every fragility panel, half a disc. A marker on the frame is a defect; inside, none."""
    figure, left, _ = _clean_figure()
    try:
        left.plot([0.2, 0.5, 1.0], [0.1, 0.3, 0.6], "o", ms=3)
        left.set_xlim(0.0, 1.0)
        left.set_title("overturning")
        assert "marker cut by the frame: 'overturning'" in layout_defects(figure)
        left.set_xlim(0.0, 1.08)
        assert layout_defects(figure) == []
    finally:
        plt.close(figure)


def _default_efficiency():
    from pathlib import Path

    import xarray as xr

    return xr.load_dataset(Path(__file__).parent / "data" / "efficiency_default_study.nc")


def test_the_efficiency_page_of_the_default_study_counts_each_test_once_and_keeps_off_the_footer():
    """Cold read 3 (default B2, B3; user B4, B5). The page drew bars as medians over 8 cells that were 2 tests
    copied across soils (one on 5 records, without a band), titled its p-values 'median over soils, models and
    blocks', and its caption ran over the footer. Drawn from the default study's efficiency.nc with the caption the
    report writes: one bar per independent test and measure, each with its confidence band, the records behind each
    test in the legend, and no layout defect with the footer drawn."""
    from rockfrag.config import load_study
    from rockfrag.report import CAPTIONS, _twins_words, figures, measure_choice_words
    from rockfrag.report.adapters import block_name
    from rockfrag.report.layout import add_footer

    dataset = _default_efficiency()
    config = load_study(None)
    names = {str(b): block_name(config, b) for b in dataset.block.values}
    caption = CAPTIONS["efficiency"] + _twins_words(dataset) + measure_choice_words(dataset, names, True)
    figure = figures.efficiency_page(dataset, caption, names=names)
    add_footer(figure, "Seismic fragility of unanchored rocking blocks · study 'default'", 44, 49)
    try:
        assert layout_defects(figure) == []
        top, bottom = figure.axes[:2]
        measures = len(top.get_xticks())
        bars = [container for container in top.containers if isinstance(container, BarContainer)]
        assert len(bars) == 2 and all(len(container.patches) == measures for container in bars)
        whiskers = [container for container in top.containers if type(container).__name__ == "ErrorbarContainer"]
        assert sum(1 for c in whiskers if c.has_yerr and len(c.lines[2][0].get_segments()) == measures) == 2
        legend = " ".join(text.get_text().replace("\n", " ") for text in figure.legends[0].get_texts())
        assert "44 records overturned" in legend and "5 records overturned" in legend
        assert "on every soil (the same runs)" in legend and "on gravel, rock, steel" in legend
        assert "median p-value over" not in bottom.get_title()
        assert "Housner (rigid base)" in caption and "count once" in caption
        assert "8 of 45 cells" not in caption
    finally:
        plt.close(figure)
