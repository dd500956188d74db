"""rockfrag.report.layout - one page size, colours and line styles for every page of the report.

Input : nothing (definitions). Output: ``Page`` (one report page: its place in the contents, the function
that draws its figure of the page size, a caption, an optional HTML body and, once rendered, its PNG),
``new_page`` and the shared styles.

Every page is A4 landscape (11.69 x 8.27 in). The title sits on top, the caption and the page footer
(title of the report, page N of M) at the bottom; figures keep their axes clear of both.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Callable
from dataclasses import dataclass, field

import matplotlib
import matplotlib.lines

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.font_manager import FontProperties  # noqa: E402
from matplotlib.ticker import FixedLocator, FuncFormatter, Locator, LogLocator, NullFormatter  # noqa: E402

PAGE_SIZE = (11.69, 8.27)  # A4 landscape [in]
GRID = dict(left=0.07, right=0.835, bottom=0.145, top=0.885, wspace=0.2, hspace=0.32)  # axes area
LEGEND_ANCHOR = (0.85, 0.885)  # upper left corner of the page legend, right of the axes
LEGEND_CHARS = 23  # characters of 7.5 pt per legend line: the entry, its line sample and the padding fit the page
CAPTION_Y = 0.082
CAPTION_SIZE = 7.5
CAPTION_WRAP = 205  # characters of 7.5 pt italic across the page width (tests check the drawn extent)
CAPTION_LINES = 3  # lines between the axes' labels and the footer
FOOTER_Y = 0.008
FOOTER_RULE = FOOTER_Y + 0.018  # the rule above the footer: nothing of the page's own is drawn below it
FOOTER_ID = "footer"  # the footer's artists carry it (gid): a layout check tells them from the page's own
TITLE_SIZE = 13
TITLE_CHARS = 95  # characters of a bold 13 pt title across the page; a longer title is set smaller

SOIL_COLOURS = {"clay": "#8c510a", "sand": "#56b4e9", "gravel": "#4d9221", "rock": "#5e3c99",
                "steel": "#666666"}
"""Five hues apart (brown, sky blue, green, purple, grey): cold read 8 could not tell the user study's clay and sand
apart when they were two shades of brown; no soil is red (the recommended curve's) or black (the rigid base's)."""
RIGID_STYLE = dict(color="black", ls="--", lw=1.5, zorder=4)  # on top: its dashes stay visible
RECOMMENDED_STYLE = dict(color="#d62728", ls="-", lw=2.8, zorder=5)  # the only solid coloured line: the answer
MODEL_STYLES = [dict(color="#1f77b4", ls="-.", lw=1.4), dict(color="#2ca02c", ls=":", lw=1.6),
                dict(color="#9467bd", ls=(0, (5, 1, 1, 1)), lw=1.4), dict(color="#ff7f0e", ls="--", lw=1.4),
                dict(color="#8c564b", ls=(0, (3, 1, 1, 1, 1, 1)), lw=1.4),
                dict(color="#e377c2", ls=(0, (1, 1)), lw=1.6)]
"""Models other than the rigid base and the recommended curve: none solid, none red."""
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
        The rendered page (empty until ``rockfrag.report.render`` has drawn it).
    also : tuple of str
        Further sections that start on this page (text sections packed onto one page when they fit).
    also_headings : tuple of str
        The heading each of ``also`` is printed under on this page, in the same order.
    heading : str
        The title without the PDF's page count ("Limitations", not "Limitations (2/9)"): the HTML heading,
        printed once for a text section that runs over several PDF pages ("" when it is the title).
    """

    name: str
    section: str
    title: str
    draw: Callable[[], Figure] = field(repr=False)
    caption: str = ""
    html: str | None = None
    png: bytes = field(default=b"", repr=False)
    also: tuple[str, ...] = ()
    heading: str = ""
    also_headings: tuple[str, ...] = ()  # the heading each of ``also`` starts with on this page (the contents')


CAPTION_LINE = CAPTION_SIZE * 1.25 / (PAGE_SIZE[1] * 72.0)  # one caption line, as a fraction of the page height


def caption_room(lines: int) -> float:
    """How much higher than the usual the caption (and the axes above it) start on a page with ``lines`` lines."""
    return max(0, lines - CAPTION_LINES) * CAPTION_LINE


def new_page(title: str, caption: str = "", caption_lines: int = CAPTION_LINES) -> Figure:
    """A figure of the page size with its title and caption.

    No layout engine: every page has the same fixed margins, which is faster than constrained layout
    and keeps pages alike. A page whose caption needs more than ``CAPTION_LINES`` lines asks for them
    (``caption_lines``) and keeps its axes ``caption_room(caption_lines)`` higher; a caption longer than its
    lines even in 6 pt type runs into the footer (the layout test fails on it).
    """
    figure = plt.figure(figsize=PAGE_SIZE)
    size = TITLE_SIZE if len(title) <= TITLE_CHARS else max(9.0, TITLE_SIZE * TITLE_CHARS / len(title))
    figure.text(0.015, 0.975, title, fontsize=size, weight="bold", va="top", ha="left")
    if caption:
        for size in (CAPTION_SIZE, 7.0, 6.5, 6.0):  # a long caption in smaller type: its lines above the footer
            lines = textwrap.wrap(caption, int(CAPTION_WRAP * CAPTION_SIZE / size))
            if len(lines) <= caption_lines:
                break
        figure.text(0.015, CAPTION_Y + caption_room(caption_lines), "\n".join(lines), fontsize=size,
                    style="italic", va="top", ha="left", linespacing=1.25)
    return figure


def panels(figure, rows=1, columns=1, **options):
    """A grid of axes inside the page margins, the legend column on the right left free."""
    grid = dict(GRID)
    grid.update(options.pop("gridspec_kw", {}))
    return figure.subplots(rows, columns, squeeze=False, gridspec_kw=grid, **options)


def add_footer(figure, left: str, number: int, total: int) -> None:
    """Report title on the left, page number on the right, a rule above both."""
    figure.add_artist(matplotlib.lines.Line2D([0.015, 0.985], [FOOTER_RULE] * 2, color="0.6", lw=0.6,
                                              transform=figure.transFigure, gid=FOOTER_ID))
    figure.text(0.015, FOOTER_Y, left, fontsize=7.5, color="0.3", va="bottom", ha="left", gid=FOOTER_ID)
    figure.text(0.985, FOOTER_Y, f"page {number} of {total}", fontsize=7.5, color="0.3", va="bottom", ha="right",
                gid=FOOTER_ID)


def log_ticks(low: float, high: float, most: int = 8) -> list[float]:
    """Tick values of a log axis from ``low`` to ``high``: 1, 2, 3, 5 x 10^n, or 1, 2, 5 x 10^n, or all 1-9 x 10^n.

    1, 2, 3, 5 x 10^n where four to six of them fit (about a decade: cold read 5, the fragility pages' 0.22-3.3 g
    showed only 0.5, 1, 2), else 1, 2, 5 x 10^n, or every 1-9 x 10^n on a short range.

    Parameters
    ----------
    low, high : float
        The axis limits (positive).
    most : int, optional
        At most this many ticks; a wide range keeps the decades (or every other 1-2-5 value) only.

    Returns
    -------
    list of float
        At least two values inside ``[low, high]`` whenever the range holds two of 1-9 x 10^n.
    """
    low, high = sorted((float(low), float(high)))
    decades = range(math.floor(math.log10(low)) - 1, math.ceil(math.log10(high)) + 1)
    denser = [float(f"{m}e{d}") for d in decades for m in (1, 2, 3, 5)]
    denser = [v for v in denser if low * (1 - 1e-9) <= v <= high * (1 + 1e-9)]
    if 4 <= len(denser) <= min(most, 6):  # a range of about a decade: 0.3 labelled too (site intensities sit there)
        return denser
    for mantissas in ((1, 2, 5), (1, 2, 3, 5, 7), tuple(range(1, 10))):
        values = [float(f"{m}e{d}") for d in decades for m in mantissas]
        values = [v for v in values if low * (1 - 1e-9) <= v <= high * (1 + 1e-9)]
        if len(values) >= 3 or mantissas[-1] == 9:
            break
    if len(values) > most:
        decade_ticks = [v for v in values if f"{v:g}".lstrip("0.").startswith("1")]
        values = decade_ticks if len(decade_ticks) >= 3 else values[::2]
    return values


class InView(Locator):
    """Another locator's tick values inside the axis's view only.

    matplotlib makes a tick (two lines, a grid line and two labels) for every value a locator returns, drawn or
    not, and a log axis's minor locator returns a decade beyond each end: those undrawn ticks were a sixth of
    the report's drawing time. The page looks the same, pixel for pixel.
    """

    def __init__(self, locator: Locator):
        self.locator = locator

    def set_axis(self, axis) -> None:
        """Attach both locators to the matplotlib Axis."""
        super().set_axis(axis)
        self.locator.set_axis(axis)

    def __call__(self):
        """The tick values inside the current view."""
        low, high = sorted(self.axis.get_view_interval())
        return [value for value in self.locator() if low <= value <= high]

    def tick_values(self, vmin, vmax):
        """The wrapped locator's values from ``vmin`` to ``vmax``."""
        low, high = sorted((vmin, vmax))
        return [value for value in self.locator.tick_values(vmin, vmax) if low <= value <= high]


def log_minor_ticks(axis) -> None:
    """Minor ticks at 2-9 x 10^n (LogLocator ``subs="auto"``), unlabelled, on one matplotlib Axis (x or y)."""
    axis.set_minor_locator(InView(LogLocator(subs="auto")))
    axis.set_minor_formatter(NullFormatter())


def _log_ticks_on(axis, limits) -> None:
    """Fixed tick values of ``log_ticks`` on one matplotlib Axis (x or y), labelled as plain numbers.

    As many values as fit the axis's length: 2.2 label heights apart on a y axis, 3.5 on an x axis.
    """
    figure, box = axis.axes.figure, axis.axes.get_position()
    vertical = axis.axis_name == "y"
    length = (box.height * figure.get_figheight() if vertical else box.width * figure.get_figwidth()) * 72.0
    # the style's tick-label size: asking the axis for its labels would first make the default locator's ticks
    # (a log axis's minor ticks: about 50 ms an axis, a fifth of a fragility page's drawing)
    size = FontProperties(size=matplotlib.rcParams[f"{axis.axis_name}tick.labelsize"]).get_size_in_points()
    most = max(3, int(length / ((2.2 if vertical else 3.5) * float(size))))
    axis.set_major_locator(FixedLocator(log_ticks(*limits, most=most)))
    axis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    log_minor_ticks(axis)


def log_axis(axis, limits: tuple[float, float] | None = None) -> None:
    """Log x axis with plain-number tick values (``log_ticks``) over ``limits`` (default: the current limits).

    Call it after the limits are set, or give them: a short range gets 1-9 x 10^n labels, never none.
    """
    axis.set_xscale("log")
    if limits is not None:
        axis.set_xlim(*limits)
    _log_ticks_on(axis.xaxis, axis.get_xlim())


def log_y_axis(axis, limits: tuple[float, float] | None = None) -> None:
    """Log y axis with plain-number tick values (``log_ticks``) over ``limits`` (default: the current limits)."""
    axis.set_yscale("log")
    if limits is not None:
        axis.set_ylim(*limits)
    _log_ticks_on(axis.yaxis, axis.get_ylim())


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
                labels.append(textwrap.fill(label, LEGEND_CHARS))
    if handles:
        figure.legend(handles, labels, loc="upper left", bbox_to_anchor=LEGEND_ANCHOR, fontsize=7.5, frameon=False,
                      **options)


def chars_across(axis, size: float) -> int:
    """How many characters of ``size`` pt fit across an axes (for wrapping panel titles and notes)."""
    width_pt = axis.get_position().width * axis.figure.get_figwidth() * 72.0
    return max(12, int(width_pt / (0.6 * size)))


def pretty(text: str) -> str:
    """Plain-ASCII symbols of the registries as a reader writes them (theta_max/alpha >= 0.2)."""
    for plain, symbol in (("theta_max", "θmax"), ("theta", "θ"), ("alpha", "α"), (">=", "≥"), ("<=", "≤")):
        text = text.replace(plain, symbol)
    return text
