"""pipeline.report.layout - one page size, colours and line styles for every page of the report.

Input : nothing (definitions). Output: ``Page`` (one report page: its place in the contents, the function
that draws its figure of the page size, a caption, an optional HTML body and, once rendered, its PNG),
``new_page`` and the shared styles.

Every page is A4 landscape (11.69 x 8.27 in). The title sits on top, the caption and the page footer
(title of the report, page N of M) at the bottom; figures keep their axes clear of both.
"""

from __future__ import annotations

import textwrap
from collections.abc import Callable
from dataclasses import dataclass, field

import matplotlib
import matplotlib.lines

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter  # noqa: E402

PAGE_SIZE = (11.69, 8.27)  # A4 landscape [in]
GRID = dict(left=0.07, right=0.835, bottom=0.145, top=0.885, wspace=0.2, hspace=0.32)  # axes area
LEGEND_ANCHOR = (0.85, 0.885)  # upper left corner of the page legend, right of the axes
CAPTION_Y = 0.07
FOOTER_Y = 0.012
TITLE_SIZE = 13

SOIL_COLOURS = {"clay": "#8c510a", "sand": "#d8a03a", "gravel": "#35978f", "rock": "#01665e",
                "steel": "#5e3c99"}
RIGID_STYLE = dict(color="black", ls="--", lw=1.5, zorder=4)  # on top: its dashes stay visible
MODEL_STYLES = [dict(color="#d62728", ls="-", lw=1.4), dict(color="#1f77b4", ls="-.", lw=1.4),
                dict(color="#2ca02c", ls=":", lw=1.6), dict(color="#9467bd", ls=(0, (5, 1, 1, 1)), lw=1.4),
                dict(color="#ff7f0e", ls="--", lw=1.4), dict(color="#8c564b", ls=(0, (3, 1, 1, 1, 1, 1)), lw=1.4)]
FRACTILE_STYLES = {0.16: dict(color="#1f77b4", ls="--", lw=1.5), 0.5: dict(color="black", ls="-", lw=2.2),
                   0.84: dict(color="#d62728", ls=":", lw=1.8)}
OUTCOME_COLOURS = {"no_uplift": "#c7e9c0", "rocking": "#fdae6b", "overturned": "#d7301f",
                   "free_flight": "#6baed6"}  # free flight: g + a_v < 0 stopped a pivot model (vertical component)


@dataclass(frozen=True)
class Page:
    """One page of the report: planned with ``draw``, rendered with its ``png`` filled in.

    Attributes
    ----------
    name : str
        File-name stem of its PNG.
    section : str
        Its heading in the contents.
    title : str
        The page title.
    draw : callable
        Draws the page: returns a new matplotlib figure of the page size (the caller closes it).
    caption : str
        One line under the figure.
    html : str or None
        The page's body as HTML for text pages; figure pages are embedded as their PNG.
    png : bytes
        The rendered page (empty until ``pipeline.report.render`` has drawn it).
    """

    name: str
    section: str
    title: str
    draw: Callable[[], Figure] = field(repr=False)
    caption: str = ""
    html: str | None = None
    png: bytes = field(default=b"", repr=False)


def new_page(title: str, caption: str = "") -> Figure:
    """A figure of the page size with its title and caption.

    No layout engine: every page has the same fixed margins, which is faster than constrained layout
    and keeps pages alike.
    """
    figure = plt.figure(figsize=PAGE_SIZE)
    figure.text(0.015, 0.975, title, fontsize=TITLE_SIZE, weight="bold", va="top", ha="left")
    if caption:
        figure.text(0.015, CAPTION_Y, "\n".join(textwrap.wrap(caption, 200)[:2]), fontsize=8, style="italic",
                    va="top", ha="left")
    return figure


def panels(figure, rows=1, columns=1, **options):
    """A grid of axes inside the page margins, the legend column on the right left free."""
    grid = dict(GRID)
    grid.update(options.pop("gridspec_kw", {}))
    return figure.subplots(rows, columns, squeeze=False, gridspec_kw=grid, **options)


def add_footer(figure, left: str, number: int, total: int) -> None:
    """Report title on the left, page number on the right, a rule above both."""
    figure.add_artist(matplotlib.lines.Line2D([0.015, 0.985], [FOOTER_Y + 0.02] * 2, color="0.6", lw=0.6,
                                              transform=figure.transFigure))
    figure.text(0.015, FOOTER_Y, left, fontsize=7.5, color="0.3", va="bottom", ha="left")
    figure.text(0.985, FOOTER_Y, f"page {number} of {total}", fontsize=7.5, color="0.3", va="bottom", ha="right")


def log_axis(axis) -> None:
    """Log x axis with plain-number tick labels at 1, 2, 5 x 10^n (no overlapping minor labels)."""
    axis.set_xscale("log")
    axis.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    axis.xaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    axis.xaxis.set_minor_formatter(NullFormatter())


def log_y_axis(axis) -> None:
    """Log y axis with plain-number tick labels at 1, 2, 5 x 10^n (the intensity axis of the IDA pages)."""
    axis.set_yscale("log")
    axis.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    axis.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    axis.yaxis.set_minor_formatter(NullFormatter())


def soil_colour(soil: str, index: int) -> str:
    """The colour of a soil: its own for the shipped soils, else the ``index``-th of matplotlib's cycle."""
    return SOIL_COLOURS.get(soil, f"C{index % 10}")


def outside_legend(figure, axes, **options):
    """One legend for the page, outside the data (right of the axes), without duplicate labels."""
    handles, labels, seen = [], [], set()
    for axis in axes:
        for handle, label in zip(*axis.get_legend_handles_labels()):
            if label not in seen and not label.startswith("_"):
                seen.add(label)
                handles.append(handle)
                labels.append(textwrap.fill(label, 26))
    if handles:
        figure.legend(handles, labels, loc="upper left", bbox_to_anchor=LEGEND_ANCHOR, fontsize=7.5, frameon=False,
                      **options)


def pretty(text: str) -> str:
    """Plain-ASCII symbols of the registries as a reader writes them (theta_max/alpha >= 0.2)."""
    for plain, symbol in (("theta_max", "θmax"), ("theta", "θ"), ("alpha", "α"), (">=", "≥"), ("<=", "≤")):
        text = text.replace(plain, symbol)
    return text
