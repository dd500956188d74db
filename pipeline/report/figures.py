"""rockfrag.report.figures - the figure pages of the report, each drawn on one A4-landscape page.

Input : the opened result datasets (cube, ida, fragility, showcase, applicability) and labels from the
        registries (rockfrag.report.adapters). Output: matplotlib figures of the page size (layout.new_page)
        with axis labels in units, one legend outside the data, and a caption. Nothing is simulated.
"""

from __future__ import annotations

import math
import re
import textwrap

import numpy as np
import xarray as xr

from rockfrag.damage_states import NOT_APPLICABLE
from rockfrag.fragility import lognormal_cdf
from rockfrag.measures import MEASURES
from rockfrag.report.adapters import (
    GOF_LEVEL,
    OUTCOME_ROCKING,
    CredibleMarks,
    block_levels,
    cell,
    is_soil,
    measure_label,
    model_styles,
    models_of,
    panel_label,
    short_label,
    soils_of,
    state_labels,
    state_title,
    uplift_intensity,
)
from rockfrag.report.layout import (
    CAPTION_Y,
    FRACTILE_STYLES,
    GRID,
    LEGEND_ANCHOR,
    caption_room,
    chars_across,
    log_axis,
    log_minor_ticks,
    log_y_axis,
    new_page,
    outside_legend,
    panels,
    pretty,
    soil_colour,
)
from rockfrag.report.words import plain, state_short_label
from rockfrag.units import STANDARD_GRAVITY

G = STANDARD_GRAVITY
IDA_CAP = 1.6  # theta_max/alpha drawn for overturned runs (the flatline)
WINDOW_BEFORE, WINDOW_AFTER = 3.0, 8.0  # s around the strong-motion window on the time axes


MARK_COLOUR = "#6a3d9a"  # the site's return-period intensities
EXTRAPOLATION = dict(color="0.55", alpha=0.13, lw=0, zorder=0)  # beyond the largest recorded intensity


MARK_SIZE = 6.5  # pt, the return-period labels


def mark_groups(axis, marks: CredibleMarks, along: str = "x") -> list[tuple[list[float], str]]:
    """The return-period marks inside the axis, grouped where their labels would overlap.

    Marks closer on the page than one label's width (a label set across the axis, above it) or 1.4 label
    heights (along a y axis) share one label ("475 / 975 / 2,475 yr", in the order of the lines along the
    axis), so labels never overprint. Needs the axis limits and scale set.

    Returns
    -------
    list of (intensities, label)
        One entry per label: the intensities it names (increasing) and its text.
    """
    low, high = axis.get_xlim() if along == "x" else axis.get_ylim()
    inside = sorted((im, t) for t, im in zip(marks.return_periods, marks.intensities) if low <= im <= high)
    if not inside:
        return []
    to_pixels = axis.transData.transform
    where = [to_pixels((im, 1.0) if along == "x" else (1.0, im))[0 if along == "x" else 1] for im, _ in inside]
    pixels = axis.figure.dpi / 72.0 * MARK_SIZE
    groups = [[0]]
    for index in range(1, len(inside)):
        room = 1.4 * pixels if along == "y" else \
            0.3 * pixels * (len(f"{inside[index][1]:,.0f} yr") + len(f"{inside[groups[-1][-1]][1]:,.0f} yr"))
        if abs(where[index] - where[groups[-1][-1]]) < room:
            groups[-1].append(index)
        else:
            groups.append([index])
    return [([inside[i][0] for i in group], " / ".join(f"{inside[i][1]:,.0f}" for i in group) + " yr")
            for group in groups]


HAZARD_LABEL = "dotted: the site's intensity at each return period"
"""The legend's entry for the return-period lines (each is named on the axis, outside the data, or in the caption)."""


def mark_intensities(axis, marks: CredibleMarks | None, along: str = "x", soil=None) -> None:
    """Mark the site's return-period intensities and the extrapolation by scaling on an intensity axis.

    Dotted lines at the return-period intensities; beyond the largest recorded intensity, a shade; ``along`` is
    the intensity axis ("x" or "y"). On an x axis the return periods are named above the panel, outside the data,
    each over its own line (close lines share a label: ``mark_groups``); on a y axis (IDA panels) the lines are
    named in the legend, from the lowest up. Call it after the axis limits and scale are set: the shading runs to
    the axis end. Where each soil has its own site hazard, a panel of one ``soil`` marks that soil's intensities;
    a panel of every soil (``soil`` None) marks each soil's in the soil's colour (``soil_marks``).
    """
    if marks is None:
        return
    colour, label = MARK_COLOUR, HAZARD_LABEL
    if soil is not None:
        soils = [name for name, _ in marks.by_soil]
        if str(soil) in soils:  # the page marks each soil's own intensities: in that soil's colour everywhere
            colour, label = soil_colour(str(soil), soils.index(str(soil))), SOIL_HAZARD_LABEL
        marks = marks.for_soil(soil)
    elif marks.by_soil:
        soil_marks(axis, marks, along)
        return
    low, high = axis.get_xlim() if along == "x" else axis.get_ylim()
    line = axis.axvline if along == "x" else axis.axhline
    if marks.largest is not None and np.isfinite(marks.largest) and marks.largest < high:
        span = axis.axvspan if along == "x" else axis.axhspan
        span(max(marks.largest, low), high, **EXTRAPOLATION, label="beyond the largest recorded intensity: "
                                                                   "extrapolation by scaling")
        line(marks.largest, color="0.35", lw=0.9, ls="-", label="largest recorded intensity (unscaled records)")
    groups = mark_groups(axis, marks, along)
    periods = sorted(float(t) for t in marks.return_periods)
    named = ", ".join(f"{t:,.0f}" for t in periods) + " years" + (f" ({marks.tag})" if marks.tag else "")
    for intensities, _ in groups:
        for intensity in intensities:
            line(intensity, color=colour, lw=0.9, ls=":", label=None if label != HAZARD_LABEL else
                 f"{HAZARD_LABEL}: {named}" + (" (from the lowest line up)" if along == "y" else ""))
    if label != HAZARD_LABEL and groups:  # one legend entry with the panels of every soil (``soil_marks``)
        line(np.nan, color="0.3", lw=0.9, ls=":", label=f"{SOIL_HAZARD_LABEL}: {named}")
    if along == "x" and groups:
        centres = [float(np.exp(np.mean(np.log(intensities)))) for intensities, _ in groups]
        width = axis.get_position().width * axis.figure.get_figwidth() * 72.0  # pt
        texts = [text if 0.6 * MARK_SIZE * len(text) < 0.8 * width or " / " not in text
                 else f"{text.split(' / ')[0]}-{text.split(' / ')[-1]}" for _, text in groups]  # narrow: first-last
        top = axis.secondary_xaxis("top")
        top.set_xticks(centres, texts)
        top.minorticks_off()
        top.tick_params(labelsize=MARK_SIZE, colors=MARK_COLOUR, length=2, pad=1)
        top.spines["top"].set_visible(False)


SOIL_HAZARD_LABEL = "dotted, in each soil's colour: that soil's site intensity at each return period"
"""The legend's entry for the return-period lines of a panel of every soil, where each soil has its own hazard."""


def soil_marks(axis, marks: CredibleMarks, along: str = "x") -> None:
    """Each soil's own return-period intensities on a panel of every soil: dotted lines in the soil's colour.

    The extrapolation shade as ``mark_intensities``; the return periods are named once each (above the panel on
    an x axis, at the geometric mean of the soils' intensities; on a y axis in the legend).
    """
    low, high = axis.get_xlim() if along == "x" else axis.get_ylim()
    line = axis.axvline if along == "x" else axis.axhline
    mark_intensities(axis, CredibleMarks(largest=marks.largest), along)  # the shade and the largest recorded
    periods = ", ".join(f"{float(t):,.0f}" for t in sorted(marks.return_periods)) + " years" + (
        f" ({marks.tag})" if marks.tag else "")
    for index, (soil, intensities) in enumerate(marks.by_soil):
        for intensity in intensities:
            if low <= intensity <= high:
                line(intensity, color=soil_colour(soil, index), lw=0.8, ls=":", alpha=0.9)
    line(np.nan, color="0.3", lw=0.9, ls=":", label=f"{SOIL_HAZARD_LABEL}: {periods}")  # the legend's entry
    if along != "x":
        return
    names = CredibleMarks(marks.return_periods, tuple(
        float(np.exp(np.mean(np.log([values[i] for _, values in marks.by_soil]))))
        for i in range(len(marks.return_periods))), None)
    groups = mark_groups(axis, names, along)
    if groups:
        centres = [float(np.exp(np.mean(np.log(intensities)))) for intensities, _ in groups]
        top = axis.secondary_xaxis("top")
        top.set_xticks(centres, [text for _, text in groups])
        top.minorticks_off()
        top.tick_params(labelsize=MARK_SIZE, colors=MARK_COLOUR, length=2, pad=1)
        top.spines["top"].set_visible(False)


LEVEL_MARGIN = 1.1
"""Factor the intensity axes reach beyond the lowest and highest level: a level's point (the records' fraction at
the credible cap, the only evidence of a censored curve) is drawn whole, not cut in half by the frame."""


def curve_range(levels, marks: CredibleMarks | None) -> tuple[float, float]:
    """The intensities a fitted curve is drawn over: the block's levels, widened to the return-period intensities."""
    low, high = float(levels[0]), float(levels[-1])
    shown = [] if marks is None else [*marks.intensities, *(im for _, values in marks.by_soil for im in values)]
    if shown:
        low = min(low, 0.9 * min(shown))
        high = max(high, 1.1 * max(shown))
    return low, high


def axis_range(levels, marks: CredibleMarks | None) -> tuple[float, float]:
    """The intensity range of a block's axes: ``curve_range`` with a margin beyond the lowest and highest level.

    The margin keeps the points at the first and last level (the credible cap) inside the frame; no curve is drawn
    into it beyond the cap (``curve_range``).
    """
    low, high = curve_range(levels, marks)
    return min(low, float(levels[0]) / LEVEL_MARGIN), max(high, float(levels[-1]) * LEVEL_MARGIN)


def _grid(n):
    """(rows, columns) for n panels on a landscape page."""
    columns = n if n <= 3 else 2 if n == 4 else 3
    return math.ceil(n / columns), columns


def spectra_page(showcase, caption):
    """A page figure of the record set's 5%-damped spectra and their fractiles.

    ``showcase`` is the opened ``showcase.nc`` (``record_spectrum`` [m/s^2] over ``period`` [s]); drawn
    log-log in g, under the page title and ``caption``.
    """
    figure = new_page("Response spectra of the record set", caption)
    axis = panels(figure)[0, 0]
    periods = showcase.period.values
    spectra = showcase.record_spectrum.values / G
    for row in spectra:
        axis.loglog(periods, row, color="0.75", lw=0.6)
    axis.plot([], [], color="0.75", lw=0.6, label=f"each record component ({spectra.shape[0]})")
    for q, style in FRACTILE_STYLES.items():
        axis.loglog(periods, np.quantile(spectra, q, axis=0), label=f"{q:.0%} fractile", **style)
    axis.set_xlabel("period T [s]")
    axis.set_ylabel("spectral acceleration Sa(T, 5%) [g]")
    finish_log_log(figure, axis, plain_y=True)
    return figure


def finish_log_log(figure, axis, plain_y: bool) -> None:
    """A log-log page axis finished: plain-number ticks, minor ticks, grid, legend outside.

    Periods and intensities on x read "0.1", "1", "3", never 10^n; so does y where ``plain_y`` (accelerations;
    an annual frequency keeps 10^n, the hazard curve's convention). Call it after the data and the limits are
    set: the tick values are chosen over the limits.
    """
    log_axis(axis)
    if plain_y:
        log_y_axis(axis)
    else:
        log_minor_ticks(axis.yaxis)
    axis.grid(alpha=0.3, which="both")
    outside_legend(figure, [axis])


def given_part(curve, reference=None) -> tuple[np.ndarray, np.ndarray]:
    """The part of a soil's site curve (intensity, annual frequency) that rests on the hazard given.

    A soil's curve carried from a reference curve (site amplification) is computed on a wider grid; below the
    reference curve's rarest frequency it rests on an extrapolation of the reference beyond its last point, which
    nobody gave: it is not drawn. A curve given for the soil itself (or without a reference) is drawn whole.
    """
    intensity, frequency = np.asarray(curve.intensity, float), np.asarray(curve.annual_frequency, float)
    if reference is None or curve is reference:
        return intensity, frequency
    given = np.asarray(reference.annual_frequency, float)
    given = given[given > 0]
    keep = (frequency >= given.min() * (1 - 1e-9)) & (frequency <= given.max() * (1 + 1e-9))
    return intensity[keep], frequency[keep]


def site_label(soil: str, curve) -> str:
    """A soil's hazard legend entry: its name, and its site's Vs30 where the curve was carried to it.

    "rock (Vs30 1,080 m/s)": beside the reference site's, it says why a stiffer site's curve lies below the
    reference's (default figures C, p. 23).
    """
    vs30 = (getattr(curve, "notes", None) or {}).get("site_vs30_m_s")
    return f"{soil} (Vs30 {float(vs30):,.0f} m/s)" if vs30 is not None and np.isfinite(float(vs30)) else soil


def hazard_page(sites, return_periods, caption, unit: str = "g", highest: float | None = None,
                largest: float | None = None, site_intensities: dict | None = None):
    """The hazard behind every probability: annual frequency of exceedance against the intensity, log-log.

    ``sites`` is the study's ``rockfrag.site_hazard.SiteHazards`` (each soil's curve, and the reference site's it
    was carried from, if any); the return periods' frequencies 1/T are dotted. A soil whose curve is the reference
    one is named in the reference curve's legend entry. In the unit of the curves: ``highest`` the highest
    intensity the study ran (the axis ends there: no verdict reads the curve beyond it), ``largest`` the largest
    intensity of the unscaled records (shaded beyond, as on every intensity axis), ``site_intensities`` {soil:
    its intensity at each return period}, drawn as points on its curve (cold read 9: the axis ran to 10 g and
    marked no intensity).
    """
    figure = new_page("Site hazard: the hazard curve of each soil's site", caption)
    axis = panels(figure)[0, 0]
    reference = getattr(sites, "reference", None)
    same = [soil for soil, curve in sites.items() if reference is not None and curve is reference]
    shown = reference if reference is not None else next(iter(sites.values()))
    if reference is not None:
        vs30 = getattr(sites, "reference_vs30", None)
        label = "reference site" + (f" (Vs30 {vs30:,.0f} m/s)" if vs30 else "") + (
            f": also {', '.join(same)}" if same else "")
        axis.loglog(reference.intensity, reference.annual_frequency, color="black", ls="--", lw=1.2, label=label)
    for index, (soil, curve) in enumerate(sites.items()):
        if soil in same:
            continue
        intensity, frequency = given_part(curve, reference)
        axis.loglog(intensity, frequency, color=soil_colour(soil, index), lw=1.4, label=site_label(soil, curve))
    periods = [float(t) for t in return_periods]
    for t in periods:
        axis.axhline(1.0 / t, color=MARK_COLOUR, ls=":", lw=0.9)
    if periods:
        axis.plot([], [], color=MARK_COLOUR, ls=":", lw=0.9,
                  label="dotted: once in " + ", ".join(f"{t:,.0f}" for t in periods) + " years (1/T)")
    drawn = [given_part(curve, reference) for curve in sites.values()]
    frequencies = np.concatenate([frequency for _, frequency in drawn])
    frequencies = frequencies[frequencies > 0]
    low = min(frequencies.min(), 0.2 / max(periods)) if periods else frequencies.min()
    bottom, top = max(low, 1e-7), min(frequencies.max() * 2, 1.0)
    axis.set_ylim(bottom, top)
    inside = np.concatenate([intensity[(frequency >= bottom) & (frequency <= 0.1)] for intensity, frequency in drawn])
    if inside.size:  # the intensities between 0.1/yr and the rarest frequency shown: the range a verdict reads
        right = min(inside.max(), highest) if highest else inside.max()
        axis.set_xlim(inside.min(), right)
    if largest is not None:  # the shading and line every intensity axis has (no return-period lines: 1/T is)
        mark_intensities(axis, CredibleMarks(largest=largest))
    points = [(soil, values) for soil, values in (site_intensities or {}).items() if soil in sites]
    for index, (soil, values) in enumerate(points):
        soils = list(sites)
        colour = "black" if soil in same else soil_colour(soil, soils.index(soil))
        axis.plot(list(values), [1.0 / t for t in periods][:len(values)], ls="none", marker="o", ms=4.5,
                  color=colour, zorder=6)
    if points:
        axis.plot([], [], ls="none", marker="o", ms=4.5, color="0.3",
                  label="points: each soil's site intensity at those return periods (the answer pages' site "
                        f"{shown.label.split(' [')[0]})")
    axis.set_xlabel(f"{shown.label} [{unit}]")
    axis.set_ylabel("annual frequency of exceedance [1/yr]")
    finish_log_log(figure, axis, plain_y=False)
    return figure


def showcase_ground_page(showcase, caption):
    """A page figure of the showcase record, raw and processed, over its whole length.

    ``showcase`` is the opened ``showcase.nc``: acceleration (drawn in g), velocity [m/s] and
    displacement [m] against time [s], under the page title and ``caption``.
    """
    title = f"{record_words(showcase)}: raw and processed"
    figure = new_page(title, caption)
    axes = panels(figure, 3, 1, sharex=True, gridspec_kw=dict(hspace=0.12))[:, 0]
    time = showcase.time_ground.values
    for axis, quantity, unit, factor in zip(axes, ("acceleration", "velocity", "displacement"),
                                            ("g", "m/s", "m"), (1 / G, 1.0, 1.0)):
        axis.plot(time, showcase[f"ground_{quantity}_raw"].values * factor, color="0.55", lw=0.8,
                  label="raw (as published)")
        axis.plot(time, showcase[f"ground_{quantity}_processed"].values * factor, color="#1f77b4", lw=0.9,
                  label="processed")
        axis.set_ylabel(f"{quantity} [{unit}]")
        axis.grid(alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    axes[-1].set_xlim(time[0], time[-1])
    outside_legend(figure, axes)
    return figure


def record_words(showcase) -> str:
    """The showcase record as a reader names it: "Duzce 1999, Bolu, component 090" (its id when unnamed)."""
    attrs = showcase.attrs
    event, station = str(attrs.get("showcase_event", "")).strip(), str(attrs.get("showcase_station", "")).strip()
    component = str(attrs.get("showcase_component", "")).strip()
    component = re.sub(r"^[A-Za-z_-]+(?=\d)", "", component)  # BOL090 -> 090: the station is named already
    if not (event or station):
        return f"record {attrs.get('showcase_record', '')}"
    words = ", ".join(part for part in (event, f"{station} station" if station else "") if part)
    return words + (f", component {component}" if component else "")


def _time_window(showcase):
    start = float(showcase.attrs.get("strong_motion_start_s", 0.0)) - WINDOW_BEFORE
    end = float(showcase.attrs.get("strong_motion_end_s", showcase.time.values[-1])) + WINDOW_AFTER
    return max(start, 0.0), min(end, float(showcase.time.values[-1]))


def quiet_soils(showcase, share: float = 0.1) -> list[str]:
    """The soils on which no model's rocking angle under the showcase record reaches ``share`` of the page's largest.

    Their panels look flat at the page's one θ scale; the caption says so (a flat panel is a result, not a missing
    run). A rigid base tied on every soil (case soil "") counts on each soil.
    """
    theta = np.abs(np.asarray(showcase.theta.values, float))
    if not np.isfinite(theta).any():
        return []
    peak = np.nanmax(theta)
    case_soils = np.asarray(list(map(str, showcase.case_soil.values)))
    soils = [s for s in dict.fromkeys(case_soils) if s]
    quiet = []
    for soil in soils:
        rows = theta[(case_soils == soil) | (case_soils == "")]
        if peak > 0 and np.nanmax(rows, initial=0.0) < share * peak:
            quiet.append(soil)
    return quiet


def quiet_words(showcase) -> str:
    """The showcase caption's sentence on flat panels ("" where every soil's panel shows rocking)."""
    quiet = quiet_soils(showcase)
    if not quiet:
        return ""
    soils = " and ".join([", ".join(quiet[:-1]), quiet[-1]] if len(quiet) > 1 else quiet)
    return (f" On {soils} the block hardly lifts off under this record (θ below a tenth of the page's largest): "
            "the flat panels are a result, not a missing run.")


def showcase_response_title(showcase, name: str | None = None) -> str:
    """The showcase response page's title, as drawn and as the contents lists it.

    "<record>: the <block> rocking on each soil", the block's R and α after a name that does not give them (commas,
    not a second pair of parentheses after a name with its own).
    """
    block = showcase.attrs["showcase_block"]
    size = f"R = {float(showcase.attrs['block_R_m']):.3g} m, α = {float(showcase.attrs['block_alpha_rad']):.3g}"
    shown = name or block
    return (f"{record_words(showcase)}: the {shown}" + ("" if "R = " in shown else f", {size} rad,")
            + " rocking on each soil")


def showcase_response_page(showcase, caption, name: str | None = None):
    """Ground motion on top, then per soil theta(t) (left) and the rise of the base centre or pivot, up + (right).

    One y-scale per column, time cropped to the strong motion.
    """
    figure = new_page(showcase_response_title(showcase, name), caption)
    soils = [s for s in dict.fromkeys(map(str, showcase.case_soil.values)) if s] or [""]
    models = models_of(xr.Dataset(coords={"model": list(dict.fromkeys(map(str, showcase.case_model.values)))}))
    styles = model_styles(models)
    start, end = _time_window(showcase)
    margins = dict(left=0.075, right=GRID["right"], wspace=0.22)
    # the ground motion once, above the θ column, on the same time axis as the panels below it (the Δy column below
    # it shares that axis: a second copy of the same record said nothing more)
    ground = figure.add_subplot(figure.add_gridspec(1, 2, top=GRID["top"], bottom=0.785, **margins)[0, 0])
    ground.plot(showcase.time_ground.values, showcase.ground_acceleration_processed.values / G, color="0.35", lw=0.7)
    ground.axvspan(float(showcase.attrs["strong_motion_start_s"]), float(showcase.attrs["strong_motion_end_s"]),
                   color="0.9", zorder=0, label="strong-motion window (5-95% Arias intensity)")
    ground.set_xlim(start, end)
    ground.grid(alpha=0.3)
    ground.tick_params(labelsize=8)
    ground.set_xlabel("time [s]", fontsize=8, labelpad=1)
    ground.set_title("ground acceleration (processed record, unscaled)", fontsize=9)
    ground.set_ylabel("ground [g]", fontsize=9)
    grid = figure.add_gridspec(len(soils), 2, top=0.69, bottom=GRID["bottom"], hspace=0.12, **margins)
    peak = np.nanmax(np.abs(showcase.theta.values)) if np.isfinite(showcase.theta.values).any() else 0.0
    scale, unit = (1000.0, "mrad") if peak < 0.1 else (1.0, "rad")
    theta_axes, settle_axes = [], []
    for row, soil in enumerate(soils):
        theta_axis = figure.add_subplot(grid[row, 0], sharex=ground, sharey=theta_axes[0] if theta_axes else None)
        settle_axis = figure.add_subplot(grid[row, 1], sharex=ground, sharey=settle_axes[0] if settle_axes else None)
        theta_axes.append(theta_axis)
        settle_axes.append(settle_axis)
        for model in models:
            # a rigid base tied on every soil is one case (soil ""), drawn on each; one that slides is per soil
            of_model = showcase.case_model.values == model.name
            mask = of_model & (showcase.case_soil.values == soil)
            if model.rigid_base and not mask.any():
                mask = of_model & (showcase.case_soil.values == "")
            if not mask.any():
                continue
            index = int(np.flatnonzero(mask)[0])
            theta_axis.plot(showcase.time.values, showcase.theta.values[index] * scale, label=short_label(model),
                            **styles[model.name])
            if not model.rigid_base:  # showcase.nc's y - y_static is positive down (a settlement): drawn up +
                settle_axis.plot(showcase.time.values, -showcase.settlement.values[index] * 1000,
                                 **styles[model.name])
        theta_axis.set_ylabel(f"θ [{unit}]", fontsize=9)
        settle_axis.set_ylabel("Δy [mm]", fontsize=9)
        theta_axis.text(0.01, 0.92, soil, transform=theta_axis.transAxes, fontsize=9, weight="bold", va="top",
                        bbox=dict(facecolor="white", edgecolor="none", alpha=0.8, pad=1))
        for axis in (theta_axis, settle_axis):
            axis.axvspan(float(showcase.attrs["strong_motion_start_s"]), float(showcase.attrs["strong_motion_end_s"]),
                         color="0.95", zorder=0)
            axis.grid(alpha=0.3)
            axis.tick_params(labelbottom=row == len(soils) - 1)
    rigid_per_soil = any(model.rigid_base and bool(((showcase.case_model.values == model.name)
                                                    & (showcase.case_soil.values != "")).any()) for model in models)
    theta_axes[0].set_title("rocking angle θ" + (" (the rigid base slides on some soils: drawn per soil)"
                                                 if rigid_per_soil else " (the rigid base: the same on every soil)"),
                            fontsize=9)
    settle_axes[0].set_title("Δy: rise of the base centre (bed) or pivot (paper's model) from rest, up +", fontsize=9)
    theta_axes[-1].set_xlabel("time [s]")
    settle_axes[-1].set_xlabel("time [s]")
    outside_legend(figure, [ground, *theta_axes])
    return figure


def _finite_capped(values):
    return np.where(np.isfinite(values), np.minimum(values, IDA_CAP), IDA_CAP)


ROW_GAP = 0.5  # in between two rows of IDA panels: the row's heading and the panels' titles
VISIBLE_ROCKING = 0.05  # θmax/α: below it an IDA curve lies on its panel's frame (3 px of a 1.7-wide axis)


def frame_note(edp, fractiles, q: float = 0.84) -> str:
    """The note of an IDA panel whose curves lie on its frame, else "" ("not run" without a run).

    On the frame: θmax/α below ``VISIBLE_ROCKING`` at every level in every record, or in the records below the
    highest fractile (most records).

    Parameters
    ----------
    edp : numpy.ndarray
        θmax/α of every record and level (NaN: not run; inf: overturned).
    fractiles : numpy.ndarray
        The panel's highest fractile curve over the levels.
    q : float, optional
        That fractile (0.84).
    """
    run = edp[~np.isnan(edp)]
    if not run.size:
        return "not run"
    if not (run >= VISIBLE_ROCKING).any():
        return f"θmax/α below {VISIBLE_ROCKING:g} in every record at every level: the curves lie on the left axis"
    highest = np.asarray(fractiles, float)
    if np.isfinite(highest).all() and (highest < VISIBLE_ROCKING).all():
        return (f"θmax/α below {VISIBLE_ROCKING:g} in most records ({q:.0%} fractile): on the left axis; "
                f"{int((run >= VISIBLE_ROCKING).sum())} of {run.size} runs "
                f"{'reaches' if int((run >= VISIBLE_ROCKING).sum()) == 1 else 'reach'} more")
    return ""


RIGID_SAME = "rigid base: its rocking is the same on every soil"
RIGID_SLIDES = ("rigid base: it slides on every soil (μ_s below b/h), so it does not rock: its slip is on its "
                "fragility pages")
"""The IDA page's heading of the shared rigid-base row: a block that slides on every soil never rocks there, and
'the same on every soil' alone hid its sliding (cold read 9, the squat skid)."""


def _ida_rows(models, soils, per_soil=(), most_columns=5, slides_everywhere=False):
    """The IDA page's rows: (heading, [(model, soil or None), ...]).

    The rigid-base models share the first row, except those in ``per_soil`` (their runs differ by soil:
    base friction lets the block slide on some soils), which get a row of their own like the foundation
    models.
    """
    rigid = [m for m in models if m.rigid_base and m.name not in per_soil]
    founded = [m for m in models if not m.rigid_base or m.name in per_soil]
    columns = min(max(len(soils) if founded else 1, len(rigid), 1), most_columns)
    rows = []
    for start in range(0, len(rigid), columns):
        rows.append((RIGID_SLIDES if slides_everywhere else RIGID_SAME,
                     [(m, None) for m in rigid[start:start + columns]]))
    for model in founded:
        heading = panel_label(model)
        if model.rigid_base:
            heading += " (rigid base; base friction: it slides on some soils)"
        for start in range(0, len(soils), columns):
            rows.append((heading, [(model, soil) for soil in soils[start:start + columns]]))
    return rows, columns


def ida_page(ida, block, caption, marks: CredibleMarks | None = None, name: str | None = None):
    """One row of panels per foundation model (a panel per soil), the rigid-base models in the first row.

    Each row is headed by its model, each panel titled by its soil. Intensity on a log axis, the site's
    return-period intensities and the extrapolation by scaling marked.
    """
    models = models_of(ida)
    soils = list(map(str, ida.soil.values))
    per_soil = [m.name for m in models if m.rigid_base and soils_of(ida, m, block, "edp") != [None]]
    slides = False
    if "soil_friction_static" in ida.coords and "block_b" in ida.coords:
        ratio = float(ida.block_b.sel(block=block)) / float(ida.block_h.sel(block=block))
        rigid = [m.name for m in models if m.rigid_base and m.name not in per_soil]
        still = all(np.nan_to_num(np.asarray(ida.edp.sel(model=m, block=block).values, float)).max() <= 1e-9
                    for m in rigid) if rigid and "edp" in ida else False  # it never rocked: its base slid (or not)
        slides = still and bool((np.asarray(ida.soil_friction_static.values, float) < ratio).all())
    rows, columns = _ida_rows(models, soils, per_soil, slides_everywhere=slides)
    figure = new_page(f"IDA curves: {name or block}", caption)
    top, bottom = 0.86, GRID["bottom"]
    height = (top - bottom) * figure.get_figheight()
    panel_height = (height - (len(rows) - 1) * ROW_GAP) / len(rows)
    axes = panels(figure, len(rows), columns, sharex=True, sharey=True,
                  gridspec_kw=dict(top=top, hspace=ROW_GAP / panel_height))
    levels = block_levels(ida, block)
    span = axis_range(levels, marks)
    drawn = []
    for row, (heading, cells) in enumerate(rows):
        for column in range(columns):
            axis = axes[row, column]
            if column >= len(cells):
                axis.set_visible(False)
                continue
            model, soil = cells[column]
            axis.rockfrag_soil = soil  # its soil's own site intensities are marked on it (None: every soil's)
            drawn.append(axis)
            picked = cell(ida, model, block, soil)
            edp = np.asarray(picked.edp.values, float)
            highest = float(ida.fractile.values.max())
            note = frame_note(edp, picked.edp_fractile.sel(fractile=highest).values, highest)
            axis.rockfrag_note = note  # every panel whose curves lie on the frame says so, the same way (below)
            for curve in picked.edp.transpose("record", "im_level").values:
                axis.plot(_finite_capped(curve), levels, color="0.65", lw=0.5, alpha=0.7)
            for q in ida.fractile.values:
                style = FRACTILE_STYLES.get(round(float(q), 2), dict(color="C4", lw=1.2))
                axis.plot(_finite_capped(picked.edp_fractile.sel(fractile=q).values), levels,
                          label=f"{float(q):.0%} fractile", **style)
            axis.axvline(IDA_CAP, color="0.3", lw=0.6, ls=":")
            axis.set_title(short_label(model) if soil is None else f"on {soil}", fontsize=8, pad=3)
            axis.grid(alpha=0.3, which="both")
            axis.set_xlim(0, IDA_CAP * 1.05)
            axis.set_xticks([0, 0.5, 1.0, 1.5])
            axis.tick_params(labelsize=8)
            if column == 0:
                axis.set_ylabel(measure_label(ida), fontsize=8)
            if row == len(rows) - 1 or (row + 1 < len(rows) and column >= len(rows[row + 1][1])):
                axis.set_xlabel("θmax/α [-]")
                axis.tick_params(labelbottom=True)
        first = axes[row, 0].get_position()
        figure.text(first.x0, first.y1 + 0.027, heading, fontsize=9, weight="bold", va="bottom", ha="left")
    for axis in drawn:
        log_y_axis(axis, span)
    for axis in drawn:
        mark_intensities(axis, marks, along="y", soil=axis.rockfrag_soil)  # on every panel (cold read 5)
        if axis.rockfrag_note:  # placed above the marks, clear of them
            keep_inside(axis, empty_note(axis, axis.rockfrag_note, x=0.6, width=0.8, y=_above_the_marks(axis)))
    drawn[0].plot([], [], color="0.65", lw=0.5, label="one record")
    drawn[0].plot([], [], color="0.3", lw=0.6, ls=":", label=f"overturned (drawn at θmax/α = {IDA_CAP})")
    outside_legend(figure, drawn)  # every panel: an empty first one has no marks
    return figure


def _fragility_series(axis, fragility, levels, picked, state, style, label, span=None, hollow=False):
    """Points and the fitted curve of one model (and soil) for one state; the reason when there is no curve.

    ``hollow``: the records' points open (white inside), as a reference's are beside the model a page is about
    (cold read 12, user C8: the recommended model's and the rigid base's points on one soil looked alike).

    Returns
    -------
    tuple of (str, str) or str
        "" when the curve is drawn (or nothing is drawn), else the series' label and why it has no curve (the
        page's notes list it).
    """
    values = picked.sel(damage_state=state)
    grid = np.geomspace(*(span or (levels[0], levels[-1])), 200)
    median, beta = float(values["median"]), float(values["beta"])
    colour = style.get("color")
    axis.plot(levels, values.empirical_fraction.values, "o", ms=3.4, color=colour, alpha=0.8,
              mfc="white" if hollow else colour, zorder=style.get("zorder", 2))
    if np.isfinite(median) and np.isfinite(beta):
        axis.plot(grid, lognormal_cdf(grid, median, beta), label=label, **style)
        soil = getattr(axis, "rockfrag_soil", None)
        if "status" in values and str(values["status"].values) == "extrapolated":  # the page's notes say so
            outside = getattr(axis.figure, "rockfrag_outside", {})
            outside.setdefault(str(values.damage_state.values), []).append(label + (f" on {soil}" if soil else ""))
            axis.figure.rockfrag_outside = outside
        if poor_fit(values):  # the tables mark it ‡; the page's notes say so where the curve is read
            failing = getattr(axis.figure, "rockfrag_poor_fit", {})
            failing.setdefault(str(values.damage_state.values), []).append(label + (f" on {soil}" if soil else ""))
            axis.figure.rockfrag_poor_fit = failing
        low, high = float(values.median_low), float(values.median_high)
        if np.isfinite(low) and np.isfinite(high) and beta > 0.05:
            axis.fill_between(grid, lognormal_cdf(grid, high, beta), lognormal_cdf(grid, low, beta),
                              color=colour, alpha=0.12, lw=0)
        return ""
    axis.plot([], [], label=label, **style)  # listed once in the legend; the page's notes say why there is no curve
    reason = no_curve_reason(values)
    return (label, reason) if reason else ""


def poor_fit(values) -> bool:
    """Whether one series' fitted curve fails its goodness-of-fit test (p below the tables' ‡ level)."""
    if "gof_p_value" not in values:
        return False
    p = float(values["gof_p_value"])
    return bool(np.isfinite(p) and p < GOF_LEVEL)


def no_curve_reason(values) -> str:
    """Why one series (a model, block and soil's fragility of one state) has points but no curve; "" otherwise.

    "" where the curve is fitted, and where nothing is drawn (a slip state of a model run with a tied base, or no
    point at all: the empty panel says why). The page's notes list the others (``page_notes``).
    """
    if np.isfinite(float(values["median"])) and np.isfinite(float(values["beta"])):
        return ""
    status = str(values["status"].values) if "status" in values else ""
    if status == NOT_APPLICABLE or not np.isfinite(values.empirical_fraction.values).any():
        return ""
    return {"below-range": "reached by most records at the lowest level",
            "not-reached": "not reached at any level"}.get(status, plain(status) if status else "no fit")


def has_page_notes(fragility, block, models=None, soils=None) -> bool:
    """True when a fragility page of ``block`` will list a series without a curve under its legend (``page_notes``).

    ``models`` and ``soils`` are the page's (default: every one). Its caption then says where the notes are.
    """
    names = [m.name for m in models] if models is not None else list(map(str, fragility.model.values))
    soils = list(map(str, fragility.soil.values)) if soils is None else list(soils)
    picked = fragility.sel(block=block)
    return any(no_curve_reason(picked.sel(model=model, soil=soil, damage_state=state))
               for model in names for soil in soils for state in fragility.damage_state.values)


NOTE_SIZE = 6.5  # pt, the notes of a page: under its legend, or inside an empty panel


def _no_curve_note(axis, reasons, state: str, soil: str = "") -> None:
    """Keep which series of a panel (``state``, on ``soil``) have points but no curve, and why.

    The notes go under the page's legend (``page_notes``), never over the data. A panel with nothing drawn
    says why inside it (``empty_note``).
    """
    notes = getattr(axis.figure, "rockfrag_notes", {})
    for series, reason in dict.fromkeys(r for r in reasons if r):
        notes.setdefault(reason, {}).setdefault(series, []).append((soil, state))
    axis.figure.rockfrag_notes = notes


def empty_note(axis, text: str, x: float = 0.5, width: float = 1.0, y: float = 0.5):
    """Say inside a panel with nothing drawn why it is empty ("not computed: the base is tied"); the text artist.

    ``x``, ``y`` are the note's centre (axes fraction) and ``width`` its share of the panel's width (a note beside
    curves on the frame).
    """
    return axis.text(x, y, textwrap.fill(text, int(width * chars_across(axis, NOTE_SIZE)) - 4),
                     transform=axis.transAxes, fontsize=NOTE_SIZE + 1, ha="center", va="center", color="0.3")


def keep_inside(axis, text, margin: float = 0.02) -> None:
    """Move a note placed by ``empty_note`` down so that its top stays inside the axes (below the panel's title)."""
    renderer = axis.figure.canvas.get_renderer()
    box = text.get_window_extent(renderer).transformed(axis.transAxes.inverted())
    if box.y1 > 1.0 - margin:
        x, y = text.get_position()
        text.set_position((x, y - (box.y1 - (1.0 - margin))))


def _above_the_marks(axis) -> float:
    """The height (axes fraction) midway between a panel's highest horizontal reference line and its top.

    An IDA panel's note sits there, clear of the site's return-period lines and the largest recorded intensity
    below it (the lines lie at low intensities; the note would otherwise cover them, so they were not drawn).
    """
    heights = []
    for line in axis.get_lines():
        if line.get_transform() is axis.transData or not len(line.get_ydata()):
            continue
        value = float(np.asarray(line.get_ydata(), float)[0])
        if np.isfinite(value) and value > 0:
            heights.append(axis.transAxes.inverted().transform(axis.transData.transform((1.0, value)))[1])
    inside = [h for h in heights if 0.0 <= h <= 1.0]
    return (max(inside) + 1.0) / 2.0 if inside else 0.5


def _panel_words(panels_of) -> str:
    """The (state, soil) panels of a page's note in words.

    "slip ≥ 0.05 m, slip ≥ 0.30 m on clay and sand" where every state is on every soil, else each panel as
    "state on soil"; the states alone on a page of every soil (soil None).
    """
    states, soils = list(dict.fromkeys(s for s, _ in panels_of)), list(dict.fromkeys(o for _, o in panels_of if o))
    if not soils:
        return ", ".join(states)
    if len(set(panels_of)) == len(states) * len(soils):
        return f"{', '.join(states)} on {' and '.join(soils)}"
    return ", ".join(f"{s} on {o}" for s, o in dict.fromkeys(panels_of))


def _series_words(series, order=None) -> str:
    """Series labels in a note, one model's soils joined: "Housner (rigid base) on clay, sand, rock; recommended".

    Ten series listed one by one overflowed the legend's column (default C, pp. 30, 36: the notes fell back to a
    count); grouped by model they fit.
    """
    grouped: dict[str, list[str]] = {}
    for label in series:
        model, _, soil = label.rpartition(" on ") if " on " in label else (label, "", "")
        grouped.setdefault(model, []).extend([soil] if soil else [])
    rank = {soil: index for index, soil in enumerate(order or ())}  # the report's soil order (cold read 12)
    return "; ".join(f"{model} on {', '.join(sorted(dict.fromkeys(soils), key=lambda s: rank.get(s, len(rank))))}"
                     if soils else model for model, soils in grouped.items())


def page_notes(figure) -> None:
    """The page's notes (``_no_curve_note``) under its legend, in the legend's column.

    Which curves could not be fitted, and why, with the panels they concern.
    """
    notes = getattr(figure, "rockfrag_notes", {})
    tied = getattr(figure, "rockfrag_tied", {})
    outside = getattr(figure, "rockfrag_outside", {})
    failing = getattr(figure, "rockfrag_poor_fit", {})
    if not notes and not tied and not outside and not failing:
        return
    renderer = figure.canvas.get_renderer()
    bottom = LEGEND_ANCHOR[1]
    if figure.legends:
        bottom = figure.transFigure.inverted().transform(figure.legends[0].get_window_extent(renderer))[0][1]
    width = int((0.99 - LEGEND_ANCHOR[0]) * figure.get_figwidth() * 72.0 / (0.62 * NOTE_SIZE)) - 1
    # models whose runs tie the base have no slip series at all: said first, it is short and always fits
    first = [line for model, panels_of in tied.items() for line in textwrap.wrap(
        f"{model}: no points in the {_panel_words(panels_of)} panels: its base is tied (no sliding).", width)]
    # a fitted median outside the levels run: the curve there is the fit's tail, not the records' (default C, p. 31)
    short = getattr(figure, "rockfrag_short", {})
    if outside:
        first += textwrap.wrap("Median outside the levels run (read the curve there as the fit's tail): " + "; ".join(
            f"{', '.join(dict.fromkeys(series))} ({short.get(state, state)})" for state, series in outside.items())
            + ".", width)
    if failing:  # default p. 32-33: the answer table marked steel's lift-off ‡, its figure said nothing
        first += textwrap.wrap("‡ The fit fails its goodness-of-fit test (as the tables mark it): read the points, "
                               "not the curve: " + "; ".join(f"{', '.join(dict.fromkeys(series))} "
                                                             f"({short.get(state, state)})"
                                                             for state, series in failing.items()) + ".", width)
    lines = textwrap.wrap("No curve, points only (the limitations list each):", width) if notes else []
    for reason, series in notes.items():
        lines += textwrap.wrap(f"{reason}: {_series_words(series, getattr(figure, 'rockfrag_soil_order', None))}.",
                               width, initial_indent="- ",
                               subsequent_indent="  ")
    room = (bottom - 0.015 - (CAPTION_Y + 0.015)) * figure.get_figheight() * 72.0 / (1.2 * NOTE_SIZE)  # lines
    if notes and len(first) + len(lines) > room:  # more than the column holds: the count, and where the list is
        count = sum(len(series) for series in notes.values())
        lines = textwrap.wrap(f"No curve, points only: {count} series on this page; the limitations list each, with "
                              "why.", width)
    top = bottom - 0.015
    if lines:
        listed = figure.text(LEGEND_ANCHOR[0] + 0.005, top, "\n".join(lines), fontsize=NOTE_SIZE, va="top",
                             ha="left", color="0.25")
        top = figure.transFigure.inverted().transform(listed.get_window_extent(renderer))[0][1] - 0.015
    if first:
        figure.text(LEGEND_ANCHOR[0] + 0.005, top, "\n".join(first), fontsize=NOTE_SIZE, va="top", ha="left",
                    color="0.25")


def short_states(fragility) -> dict:
    """Damage state -> its short name ("uplift", "θmax/α ≥ 0.5", "slip ≥ 0.05 m", "overturning")."""
    descriptions = fragility["damage_state_description"].values if "damage_state_description" in fragility.coords \
        else [""] * fragility.sizes["damage_state"]
    return {str(s): state_short_label(str(s), str(d)) for s, d in zip(fragility.damage_state.values, descriptions)}


def tied_models(fragility, block, state, models, soil=None) -> list:
    """The ``models`` whose runs tie the base on ``soil`` (on every soil if None).

    ``state`` (a slip state) has no points for them there.
    """
    return [m for m in models if tied_soils(fragility, block, state, m) and (
        soil in tied_soils(fragility, block, state, m) if soil is not None
        else len(tied_soils(fragility, block, state, m)) == fragility.sizes["soil"])]


def tied_soils(fragility, block, state, model) -> list[str]:
    """The soils on which ``model``'s runs tie the base, so ``state`` (a slip state) is not computed there."""
    if "status" not in fragility or model.name not in fragility.model.values:
        return []
    status = fragility["status"].sel(block=block, damage_state=state, model=model.name)
    return [str(soil) for soil, value in zip(fragility.soil.values, status.values) if value == NOT_APPLICABLE]


TIED_WORDS = "not computed: the base is tied (no sliding) in these runs"
"""Why a slip panel, or one model's series in it, has nothing drawn."""


def _empty_if_nothing(axis, fragility, block, state, models, soil=None, short: str = "") -> None:
    """An empty panel's note: why no series of ``models`` has a point for ``state``.

    In a panel with points, the models among ``models`` that tie the base there are kept for the page's notes
    (``page_notes``: their series is missing by design, not lost); ``short`` is the state's short name.
    """
    where = dict(block=block, damage_state=state, model=[m.name for m in models], **({} if soil is None
                                                                                     else {"soil": soil}))
    if np.isfinite(fragility.empirical_fraction.sel(where).values).any():
        tied = getattr(axis.figure, "rockfrag_tied", {})
        for model in models:
            soils = tied_soils(fragility, block, state, model)
            if soil is not None and soil in soils:
                tied.setdefault(panel_label(model), []).append((short or state, soil))
            elif soil is None and soils:  # a page of every soil: the series missing are this model's on ``soils``
                every = len(soils) == fragility.sizes["soil"]
                label = panel_label(model) + ("" if every else f" on {', '.join(soils)}")
                tied.setdefault(label, []).append((short or state, None))
        axis.figure.rockfrag_tied = tied
        return
    status = fragility["status"].sel(where) if "status" in fragility else None
    tied = status is not None and bool((status == NOT_APPLICABLE).all())
    empty_note(axis, TIED_WORDS if tied else "no run to count")
    axis.rockfrag_empty = True  # nothing to read against the site's intensities: no marks over the note


def _state_axes(figure, fragility, n_rows=1):
    states = [str(s) for s in fragility.damage_state.values]
    if n_rows == 1:
        rows, columns = _grid(len(states))
    else:
        rows, columns = n_rows, len(states)
    axes = panels(figure, rows, columns, sharex=True, sharey=True,
                  gridspec_kw=dict(hspace=0.6 if n_rows > 1 else 0.55))
    for axis in axes.flat[len(states) * (1 if n_rows == 1 else n_rows):]:
        axis.set_visible(False)
    return states, axes


def _probability_axes(axes, levels, x_label: str, y_label: str, marks: CredibleMarks | None = None) -> None:
    """Probability against intensity on every visible panel.

    Log x over the block's levels (widened to the return-period intensities), y from 0 to 1, a grid, the
    marks of ``mark_intensities``; the y label on the first column, the x label on the last row.
    """
    span = axis_range(levels, marks)
    for axis in axes.flat:
        if not axis.get_visible():
            continue
        log_axis(axis, span)
        axis.set_ylim(-0.02, 1.02)
        axis.grid(alpha=0.3, which="both")
        if not getattr(axis, "rockfrag_empty", False):  # a panel of one soil: that soil's site intensities
            mark_intensities(axis, marks, along="x", soil=getattr(axis, "rockfrag_soil", None))
        axis.tick_params(labelbottom=True, labelsize=8)  # every row: a panel is read on its own
    rows = axes.shape[0]
    # up to two rows each row's label fits beside it; from three rows on (seven damage states or more: a plugin's,
    # or a study's own) the label is longer than a row is high, so one label, beside the middle row, says it
    for axis in axes[:, 0] if rows < 3 else axes[rows // 2:rows // 2 + 1, 0]:
        axis.set_ylabel(y_label)
    for axis in axes.flat:
        if axis.get_visible():
            axis.set_xlabel(x_label, fontsize=8, labelpad=1)


LINE_WORDS = {"-": "solid", "--": "dashed", "-.": "dash-dot", ":": "dotted"}
"""A model's line style in a caption's words; other dash patterns are 'patterned (legend)'."""


def line_words(fragility, model) -> str:
    """How the fitted curves of ``model`` are drawn (its style in ``model_styles``): 'solid', 'dash-dot', ..."""
    style = model_styles(models_of(fragility))[model.name]
    words = LINE_WORDS.get(style.get("ls", "-"), "patterned (legend)") if isinstance(style.get("ls", "-"), str) \
        else "patterned (legend)"
    return ("thick " if style.get("lw", 1.5) >= 2.5 else "") + words


def fragility_by_soil_title(fragility, block, model, name: str | None = None) -> str:
    """The by-soil page's title: the block, the page's model and the rigid-base references it draws beside it.

    Cold read 7, user C4: "..., SSI, paper's model" over panels that draw Housner too.
    """
    references = [short_label(m) for m in models_of(fragility) if m.rigid_base and m.name != model.name]
    return (f"Fragility by soil: {name or block}, {short_label(model)}"
            + (f", with {' and '.join(references)} for reference" if references else ""))


def fragility_by_soil_page(fragility, block, model, caption, marks: CredibleMarks | None = None,
                           name: str | None = None):
    """Panels per damage state; the soils in colours, rigid-base models once as the black dashed reference."""
    models = models_of(fragility)
    styles = model_styles(models)
    figure = new_page(fragility_by_soil_title(fragility, block, model, name), caption)
    states, axes = _state_axes(figure, fragility)
    labels, short = state_labels(fragility), short_states(fragility)
    figure.rockfrag_short = short
    figure.rockfrag_soil_order = list(map(str, fragility.soil.values))
    levels = block_levels(fragility, block)
    span = curve_range(levels, marks)  # the curves; the axes get a margin
    for axis, state in zip(axes.flat, states):
        reasons = []
        for index, soil in enumerate(map(str, fragility.soil.values)):
            style = dict(styles[model.name], color=soil_colour(soil, index))
            reasons.append(_fragility_series(axis, fragility, levels, cell(fragility, model, block, soil), state,
                                             style, f"{panel_label(model)} on {soil}", span))
        for reference in (m for m in models if m.rigid_base):
            own = soils_of(fragility, reference, block, "median")  # [None]: the same on every soil
            for index, soil in enumerate(own):
                style = dict(styles[reference.name], **({} if soil is None else {"color": soil_colour(soil, index)}))
                label = short_label(reference) + ("" if soil is None else f" on {soil}")
                reasons.append(_fragility_series(axis, fragility, levels, cell(fragility, reference, block, soil),
                                                 state, style, label, span, hollow=True))
        title = state_title(labels[state])
        _no_curve_note(axis, reasons, short[state])
        _empty_if_nothing(axis, fragility, block, state, [model, *(m for m in models if m.rigid_base)],
                          short=short[state])
        axis.set_title(textwrap.fill(title, chars_across(axis, 9)), fontsize=9)
    figure.rockfrag_panels = len(states)
    _probability_axes(axes, levels, measure_label(fragility), "probability of the damage state [-]", marks)
    outside_legend(figure, list(axes.flat))
    page_notes(figure)
    return figure


def fragility_by_model_page(fragility, block, soils, caption, marks: CredibleMarks | None = None,
                            name: str | None = None):
    """Rows: the softest and stiffest soil; columns: damage states; models in their own colours and styles."""
    models = models_of(fragility)
    styles = model_styles(models)
    figure = new_page(f"Fragility by model: {name or block}", caption)
    states, axes = _state_axes(figure, fragility, n_rows=len(soils))
    labels, short = state_labels(fragility), short_states(fragility)
    figure.rockfrag_short = short
    figure.rockfrag_soil_order = list(map(str, fragility.soil.values))
    levels = block_levels(fragility, block)
    span = curve_range(levels, marks)  # the curves; the axes get a margin
    for row, soil in enumerate(soils):
        for column, state in enumerate(states):
            # one soil: _state_axes lays the states out on a grid, not in one row
            axis = axes[row, column] if len(soils) > 1 else axes.flat[column]
            axis.rockfrag_soil = soil
            reasons = [_fragility_series(axis, fragility, levels, cell(fragility, model, block, soil), state,
                                         styles[model.name], short_label(model), span, hollow=model.rigid_base)
                       for model in models]
            title = f"{state_title(labels[state])} on {soil}"
            _no_curve_note(axis, reasons, short[state], soil)
            _empty_if_nothing(axis, fragility, block, state, models, soil, short=short[state])
            axis.set_title(textwrap.fill(title, chars_across(axis, 8.5)), fontsize=8.5)
    figure.rockfrag_panels = len(soils) * len(states)
    _probability_axes(axes, levels, measure_label(fragility), "probability of the damage state [-]", marks)
    outside_legend(figure, list(axes.flat))
    page_notes(figure)
    return figure


def _uplift_fraction(fragility, model, block, soil) -> np.ndarray | None:
    """The records' fraction reaching the uplift damage state per level (its size rule: a tilt is not uplift).

    None when the fragility has no uplift state or no fraction for this model (e.g. a combined curve).
    """
    if "damage_state_edp" not in fragility.coords or "empirical_fraction" not in fragility:
        return None
    states = [str(s) for s, edp in zip(fragility.damage_state.values, fragility.damage_state_edp.values)
              if str(edp) == "uplifted"]
    if not states:
        return None
    values = cell(fragility, model, block, soil).empirical_fraction.sel(damage_state=states[0]).values
    return np.asarray(values, float) if np.isfinite(values).any() else None


def one_line_title(model, axis, size: float) -> str:
    """A panel's title naming ``model`` on one line, level with its neighbours' (user C5).

    The model's short label, or without its parenthesis where that would wrap ("SSI, paper's model"; the
    fragility pages' legends give the whole label).
    """
    title = short_label(model) if len(short_label(model)) <= chars_across(axis, size) else panel_label(model)
    return textwrap.fill(title, chars_across(axis, size))


def _outcome_pairs(fragility, block) -> list:
    """Per model drawn on the outcomes page: the model and its soils' (soil, index, uplift, overturning) fractions.

    A rigid base the same on every soil has the one soil None.
    """
    models = [m for m in models_of(fragility) if m.name in set(map(str, fragility.outcome_probability.model.values))
              and np.isfinite(fragility.outcome_probability.sel(model=m.name).values).any()]
    probability = fragility.outcome_probability.to_dataset(name="p")
    pairs = []
    for model in models:
        curves = []
        for index, soil in enumerate(soils_of(probability, model, block, "p")):
            picked = cell(probability, model, block, soil)["p"]
            uplift = _uplift_fraction(fragility, model, block, soil)
            if uplift is None:  # no uplift state: any lift of the outcome
                uplift = 1 - picked.sel(outcome_class="no_uplift").values
            curves.append((soil, index, uplift, picked.sel(outcome_class="overturned").values))
        pairs.append((model, curves))
    return pairs


def rocking_shaded(fragility, block) -> bool:
    """True when the outcomes page of ``block`` shades rocking without overturning somewhere visibly.

    The band is drawn where a panel holds one pair of curves (a rigid base the same on every soil, or one soil)
    and shows where uplift exceeds overturning by more than 1 %. The caption names the shading only then.
    """
    return any(len(curves) == 1 and np.nanmax(np.asarray(up, float) - np.asarray(over, float), initial=0.0) > 0.01
               for _, curves in _outcome_pairs(fragility, block) for _, _, up, over in curves)


def outcomes_page(fragility, block, caption, marks: CredibleMarks | None = None, name: str | None = None):
    """One panel per model: P(uplift) solid and P(overturning) dashed per soil; the gap is rocking."""
    pairs = _outcome_pairs(fragility, block)
    rows, columns = _grid(len(pairs))
    figure = new_page(f"Outcomes by intensity: {name or block}", caption)
    axes = panels(figure, rows, columns, sharex=True, sharey=True)
    for axis in axes.flat[len(pairs):]:
        axis.set_visible(False)
    levels = block_levels(fragility, block)
    for axis, (model, curves) in zip(axes.flat, pairs):
        for soil, index, uplift, overturn in curves:
            colour = "black" if soil is None else soil_colour(soil, index)
            axis.plot(levels, uplift, color=colour, ls="-", lw=1.5,
                      label="any soil (rigid base)" if soil is None else soil)
            axis.plot(levels, overturn, color=colour, ls="--", lw=1.5)
            if len(curves) == 1:
                axis.fill_between(levels, overturn, uplift, color="#fdae6b", alpha=0.35, lw=0)
        axis.set_title(one_line_title(model, axis, 9.5), fontsize=9.5)
    shaded = rocking_shaded(fragility, block)
    _probability_axes(axes, levels, measure_label(fragility), "probability [-]", marks)
    axes[0, 0].plot([], [], color="0.3", ls="-", label="P(uplift): lift-off, rocking or overturning")
    axes[0, 0].plot([], [], color="0.3", ls="--", label="P(overturning)")
    if shaded:  # the band is drawn only where one curve pair is on its panel (a legend entry only if it shows)
        axes[0, 0].fill_between([], [], [], color="#fdae6b", alpha=0.35, lw=0, label="rocking without overturning")
    for axis in axes.flat:
        if axis.get_visible():
            axis.tick_params(labelbottom=True)
    outside_legend(figure, list(axes.flat))
    coinciding = coinciding_words(pairs)
    if coinciding:  # under the legend, off the data (cold read 7, default p. 41: one line showed for three soils)
        renderer = figure.canvas.get_renderer()
        bottom = figure.transFigure.inverted().transform(figure.legends[0].get_window_extent(renderer))[0][1] \
            if figure.legends else LEGEND_ANCHOR[1]
        width = int((0.99 - LEGEND_ANCHOR[0]) * figure.get_figwidth() * 72.0 / (0.62 * NOTE_SIZE)) - 1
        figure.text(LEGEND_ANCHOR[0] + 0.005, bottom - 0.015, textwrap.fill(coinciding, width), fontsize=NOTE_SIZE,
                    va="top", ha="left", color="0.25")
    return figure


def coinciding_words(pairs) -> str:
    """The soils whose outcome curves coincide in a panel, so that only the last drawn shows; "" where none do.

    "Lines that coincide (the last drawn hides the others): Housner: clay = sand, gravel = rock = steel; SSI, paper's
    model: P(uplift) on every soil."
    """
    said = []
    for model, curves in pairs:
        if len(curves) < 2:
            continue
        for what, position in (("", None), ("P(uplift) ", 2), ("P(overturning) ", 3)):
            groups: dict[bytes, list[str]] = {}
            for curve in curves:
                values = np.asarray(curve[2:4] if position is None else curve[position], float)
                groups.setdefault(np.round(np.nan_to_num(values, nan=-1.0), 6).tobytes(), []).append(str(curve[0]))
            same = [soils for soils in groups.values() if len(soils) > 1]
            if same:
                words = ", ".join("every soil" if len(soils) == len(curves) else " = ".join(soils) for soils in same)
                said.append(f"{panel_label(model)}: {what}{'on ' if what and words == 'every soil' else ''}{words}")
                break  # both curves coincide: the pair is said once, not again per curve
    return ("Lines that coincide (the last drawn hides the others): " + "; ".join(said) + ".") if said else ""


def no_ratio_reason(cube, block, soil, models, band) -> str:
    """Why a soil has no point of ``block`` on the applicability page: which model never rocked there, and why.

    ``models`` are the rigid-base reference and the foundation models compared with it, ``band`` the levels (a boolean
    mask) the ratio reads. A model whose runs never rock in the band (no run ends rocking without overturning) leaves
    no ratio; a rigid base with base friction below tan α slides instead (the limitations' 'Sliding').
    """
    sub = cube.sel(block=block, soil=soil).isel(im_level=np.flatnonzero(band))
    for model in models:
        if (sub.outcome.sel(model=model.name) == OUTCOME_ROCKING).any():
            continue
        who = "the rigid base" if model.rigid_base else panel_label(model)
        friction = float(cube.friction_static.sel(soil=soil, block=block, model=model.name)) \
            if "friction_static" in cube else np.nan
        alpha = float(cube.block_alpha.sel(block=block)) if "block_alpha" in cube.coords else np.nan
        if np.isfinite(friction) and np.isfinite(alpha) and friction < np.tan(alpha):
            return f"{who} slides there and never rocks"
        return f"{who} never rocks there without overturning"
    return "no run rocked without overturning in both models there"


def applicability_title(cube) -> str:
    """The applicability page's title, as drawn and as the contents lists it."""
    reference = next(m for m in models_of(cube) if m.rigid_base)
    return f"Applicability of the rigid base: each foundation model over {panel_label(reference)}"


def applicability_page(cube, caption, limit=0.10, names: dict | None = None):
    """Median peak angle of each foundation model over the rigid-base reference against G_s, per block.

    A model keeps its colour and dashes, a block its marker; the legend lists the models and the blocks
    apart (blocks without a run in the band are left out and named in the legend), each model drawn as it is on the
    axes (a line only where it joins two points). The soils are named on the top axis; a soil without a point says
    so there, and the legend says why (``no_ratio_reason``).
    """
    models = models_of(cube)
    reference = next(m for m in models if m.rigid_base)
    founded = [m for m in models if not m.rigid_base]
    styles = model_styles(models)
    names = names or {}
    figure = new_page(applicability_title(cube), caption)
    axis = panels(figure, gridspec_kw=dict(top=0.85))[0, 0]
    shear = cube.soil_shear_modulus.values / 1e6
    order = np.argsort(shear)
    markers = "os^Dv"
    drawn_blocks, missing = [], []
    joined, pointless = {model.name: False for model in founded}, set(map(str, cube.soil.values))
    for b_index, block in enumerate(cube.block.values):
        uplift = uplift_intensity(cube, block)
        levels = block_levels(cube, block)
        band = (levels >= 1.2 * uplift) & (levels <= 3.0 * uplift)
        sub = cube.sel(block=block).isel(im_level=np.flatnonzero(band)) if band.any() else None
        drew, with_ratio = False, np.zeros(cube.sizes["soil"], bool)
        for model in founded if sub is not None else []:
            rigid_angle = sub.peak_angle.sel(model=reference.name)
            survived = (sub.outcome.sel(model=[reference.name, model.name]) == OUTCOME_ROCKING).all("model")
            ratio = (sub.peak_angle.sel(model=model.name).where(survived).median(["record", "im_level"]) /
                     rigid_angle.where(survived).median(["record", "im_level"])).values
            if not np.isfinite(ratio).any():
                continue
            drew, with_ratio = True, with_ratio | np.isfinite(ratio)
            joined[model.name] |= bool(np.isfinite(ratio).sum() >= 2)
            style = styles[model.name]
            # a structural base (steel) stands apart, not joined: no run lies between it and rock (cold read 12,
            # default figures round 3: the line read as a stiffness trend nobody computed)
            ground = np.array([is_soil(cube, str(soil)) for soil in cube.soil.values])[order]
            x, y = shear[order], ratio[order]
            axis.plot(x[ground], y[ground], marker=markers[b_index % len(markers)], ms=5, mfc="white",
                      color=style["color"], ls=style["ls"], lw=1.3)
            if (~ground).any():
                axis.plot(x[~ground], y[~ground], marker=markers[b_index % len(markers)], ms=5, mfc="white",
                          color=style["color"], ls="none")
        name = names.get(str(block), str(block))
        gaps = [str(soil) for soil, has in zip(cube.soil.values, with_ratio) if not has]
        pointless -= {str(soil) for soil, has in zip(cube.soil.values, with_ratio) if has}
        if drew and gaps:  # a soil without a point says why in the legend, not as a gap in the line
            reasons = {}
            for soil in gaps:
                reasons.setdefault(no_ratio_reason(cube, block, soil, [reference, *founded], band), []).append(soil)
            name += " (no point on " + "; ".join(f"{', '.join(soils)}: {reason}" for reason, soils in
                                                reasons.items()) + ", so no ratio)"
        (drawn_blocks if drew else missing).append((name, markers[b_index % len(markers)]))
    single = drawn_blocks[0][1] if len(drawn_blocks) == 1 else "o"
    for model in founded:
        style = styles[model.name]
        # drawn as it is on the axes: its dashes where it joins two points, else its marker alone
        axis.plot([], [], color=style["color"], ls=style["ls"] if joined[model.name] else "none", lw=1.3,
                  marker=None if joined[model.name] else single, ms=5, mfc="white", label=short_label(model))
    for name, marker in drawn_blocks:
        axis.plot([], [], ls="none", marker=marker, ms=5, mfc="white", color="0.2", label=f"block: {name}")
    for name, _ in missing:
        axis.plot([], [], ls="none", label=f"block: {name}: no point (no run rocked without overturning in both "
                                         "models between 1.2 and 3 times its uplift threshold)")
    axis.axhspan(1 - limit, 1 + limit, color="0.88", label=f"within ±{limit:.0%} of the rigid base", zorder=0)
    axis.axvspan(300, 1000, color="#2ca02c", alpha=0.12, zorder=0,
                 label="300-1000 MPa: above it the paper finds the rigid base good enough")
    axis.axhline(1.0, color="k", lw=0.8)
    log_axis(axis, (0.7 * min(shear.min(), 300.0), 1.4 * max(shear.max(), 1000.0)))  # every soil on the top axis
    axis.set_xlabel("soil shear modulus $G_s$ [MPa]")
    axis.set_ylabel(f"median θmax (model) / median θmax ({panel_label(reference)}) [-]")
    axis.grid(alpha=0.3, which="both")
    top = axis.secondary_xaxis("top")
    top.set_xticks(shear, [f"{soil}\n(no point)" if str(soil) in pointless else str(soil)
                           for soil in cube.soil.values], fontsize=8)
    top.minorticks_off()
    outside_legend(figure, [axis])
    return figure


def sweep_title(dataset) -> str:
    """The stiffness sweep page's title, as drawn and as the contents lists it."""
    tolerance = float(dataset.attrs.get("tolerance", 0.1))
    return f"Rigid-base error against soil stiffness (grey: ±{tolerance:.0%}; green: paper's 300-1000 MPa)"


def sweep_page(dataset, caption, names: dict | None = None):
    """The fine G_s sweep of `rockfrag applicability`: rows are the compliant models, columns the blocks."""
    tolerance = float(dataset.attrs.get("tolerance", 0.1))
    blocks = list(dataset.block.values)
    models = list(dataset.model.values)
    figure = new_page(sweep_title(dataset), caption)
    axes = panels(figure, len(models), len(blocks), sharey=True, gridspec_kw=dict(hspace=0.6, top=0.8))  # 3-line titles
    shear = dataset.shear_modulus.values / 1e6
    dash = ["-", "--", ":", "-."]
    for row, model in enumerate(models):
        label = str(dataset.model_label.values[row]) if "model_label" in dataset.coords else str(model)
        for axis, block in zip(axes[row], blocks):
            ratios = dataset.peak_angle_ratio_to_housner.sel(model=model, block=block).values
            for e_index, modulus in enumerate(dataset.block_modulus.values):
                for l_index, level in enumerate(dataset.level.values):
                    axis.plot(shear, ratios[e_index, l_index], color=f"C{l_index}", ls=dash[e_index % 4],
                              marker=".",
                              label=f"block modulus $E_b$ = {modulus / 1e9:.0f} GPa, PGA = {level:g}·g·tanα")
            axis.axhspan(1 - tolerance, 1 + tolerance, color="0.8", zorder=0)
            axis.axvspan(300, 1000, color="#2ca02c", alpha=0.12, zorder=0)
            axis.axhline(1.0, color="k", lw=0.7)
            axis.set_title(textwrap.fill(f"{(names or {}).get(str(block), block)}: {label}", chars_across(axis, 9)),
                           fontsize=9)
            log_axis(axis)
            axis.set_xlabel("soil shear modulus $G_s$ [MPa]")
            axis.grid(alpha=0.3, which="both")
        axes[row, 0].set_ylabel("median θmax model / Housner [-]")
    ratios = np.asarray(dataset.peak_angle_ratio_to_housner.values, float)
    ratios = ratios[np.isfinite(ratios) & (ratios > 0)]
    low = min(0.8, 0.9 * ratios.min()) if ratios.size else 0.8
    high = max(1.25, 1.1 * ratios.max()) if ratios.size else 1.25
    for axis in axes.flat:  # log: the ±10% band keeps its height however large the ratios run
        log_y_axis(axis, (low, high))
    outside_legend(figure, [axes.flat[0]])
    return figure


P_FLOOR = 1e-3  # p-values below this are drawn at it: "below 0.001" is all such a number supports


P_MARKERS = (("p_magnitude", "o", "black", "against magnitude"), ("p_distance", "s", "0.55", "against distance"),
             ("p_pulse_period", "^", "#6a3d9a", "against pulse period"))
"""Sufficiency p-values: marker, colour (none of the blocks' bar colours) and what each tests."""


def measure_words(measure: str) -> str:
    """An intensity measure as the efficiency page names it."""
    registered = MEASURES.get(measure)
    if registered is None:
        return measure.replace("_", " ")
    return registered.words or pretty(registered.short_label())


def efficiency_twins(dataset) -> dict[str, str]:
    """Normalised measures (``Measure.normalises``) whose results repeat their measure's in every cell: measure -> it.

    Dividing an intensity by a constant of the block (g·tanα, the uplift acceleration) changes no
    dispersion or p-value within a block, so PGA/(g·tanα) repeats PGA; the page draws one of each pair.
    A pair that differs (a file written otherwise) is kept.
    """
    measures = [str(m) for m in dataset.measure.values]
    twins = {}
    normalised = {name: MEASURES[name].normalises for name in measures if name in MEASURES}
    for measure, base in normalised.items():
        if base is not None and base in measures:
            values = [np.asarray(dataset.dispersion.sel(measure=m).values, float) for m in (measure, base)]
            if np.allclose(*values, rtol=1e-6, atol=1e-9, equal_nan=True):
                twins[measure] = base
    return twins


MAX_TESTS = 6
"""Independent tests drawn on the efficiency page at most (those with the most overturning records; the caption
says how many were left out)."""

EFFICIENCY_CAPTION_LINES = 6  # the efficiency caption says which tests the bars rest on: three lines more


def tests_drawn(dataset):
    """The independent tests the efficiency page draws, and how many there are in all.

    At most ``MAX_TESTS`` of ``rockfrag.efficiency.independent_tests``, those with the most records first.
    """
    from rockfrag.efficiency import independent_tests

    tests = independent_tests(dataset)
    return tests[:MAX_TESTS], len(tests)


def soils_words(soils, every) -> str:
    """The soils one test rests on: "every soil (the same runs)", "gravel, rock, steel (the same runs)", "sand"."""
    if len(soils) > 1 and len(soils) == len(every):
        return "every soil (the same runs)"
    return ", ".join(soils) + (" (the same runs)" if len(soils) > 1 else "")


def test_words(test, dataset, names: dict | None = None) -> str:
    """One independent test as the efficiency page names it: block, model, soils and the records behind it."""
    from rockfrag.report.adapters import model_info

    names = names or {}
    model = short_label(model_info(test.model))
    records = f": {test.records} records overturned" if test.records else ""
    return (f"{names.get(test.block, test.block)}, {model}, on "
            f"{soils_words(test.soils, list(dataset.soil.values))}{records}")


EFFICIENCY_TITLE = "Efficiency of intensity measures: which one predicts overturning best"


def efficiency_page(dataset, caption, names: dict | None = None):
    """Which intensity measure predicts overturning best, from ``efficiency.nc``: one bar per independent test.

    A test is one block and model's overturning capacities on the soils where they are the same runs
    (``rockfrag.efficiency.independent_tests``: a tied rigid base is one test, not one per soil). Top: the
    dispersion of the capacity per measure, whiskers its 90% confidence band (chi-square on the records that
    overturned: a test on few records has a wide band); smaller is better. Bottom: each test's sufficiency p-values
    against magnitude, distance and pulse period, under its bar, on a log axis floored at ``P_FLOOR``. A measure that
    repeats another within every block (``efficiency_twins``) is left out; the caption says why.
    """
    from rockfrag.efficiency import CONFIDENCE, dispersion_interval

    names = names or {}
    figure = new_page(EFFICIENCY_TITLE, caption,
                      caption_lines=EFFICIENCY_CAPTION_LINES)
    room = caption_room(EFFICIENCY_CAPTION_LINES)
    top, bottom = panels(figure, 2, 1, gridspec_kw=dict(hspace=0.45, left=0.085, bottom=GRID["bottom"] + room))[:, 0]
    twins = efficiency_twins(dataset)
    measures = [str(m) for m in dataset.measure.values if str(m) not in twins]
    labels = [measure_words(m) for m in measures]
    tests, _ = tests_drawn(dataset)
    x = np.arange(len(measures))
    width = 0.8 / max(len(tests), 1)
    offsets = [(index - (len(tests) - 1) / 2) * width for index in range(len(tests))]
    for index, (test, offset) in enumerate(zip(tests, offsets)):
        where = dict(soil=test.soils[0], block=test.block, model=test.model, measure=measures)
        dispersion = np.asarray(dataset.dispersion.sel(where).values, float)
        records = np.asarray(dataset.n_records.sel(where).values, float) if "n_records" in dataset else None
        band = None
        if records is not None:
            low, high = dispersion_interval(dispersion, records)
            band = [dispersion - low, high - dispersion]
        top.bar(x + offset, dispersion, width, yerr=band, capsize=2, color=f"C{index % 10}",
                error_kw=dict(lw=0.9), label=test_words(test, dataset, names))
    if tests and "n_records" in dataset:  # an errorbar proxy: listed after the bars
        top.errorbar([], [], yerr=[], color="black", capsize=2, lw=0.9, ls="none", label=f"whiskers: {CONFIDENCE:.0%} "
                     "confidence band of the dispersion (from the records overturned)")
    if not tests:
        empty_note(top, "no dispersion: no block's overturning capacity was found in enough records to measure one")
    top.set_xticks(x, labels, fontsize=8)
    top.set_ylabel("dispersion of ln capacity [-]", fontsize=9)
    top.set_title("Efficiency: dispersion of the overturning capacity, one bar per independent test (smaller is "
                  "better)", fontsize=10)
    top.grid(alpha=0.3, axis="y")
    top.set_ylim(bottom=0.0)
    tested = False
    for order, (name, marker, colour, what) in enumerate(P_MARKERS):
        if name not in dataset:
            continue
        spread = (order - (len(P_MARKERS) - 1) / 2) * width / 4  # side by side in the test's column: none hidden
        for index, (test, offset) in enumerate(zip(tests, offsets)):
            p = np.asarray(dataset[name].sel(soil=test.soils[0], block=test.block, model=test.model,
                                             measure=measures).values, float)
            tested |= bool(np.isfinite(p).any())
            bottom.scatter(x + offset + spread, np.clip(p, P_FLOOR, 1.0), marker=marker, color=colour, s=22,
                           label=f"p-value {what}" if index == 0 else None, zorder=3)
    for index, offset in enumerate(offsets if len(tests) > 1 else []):  # which test a column of p-values is
        bottom.bar(x + offset, 1.0, width * 0.9, bottom=P_FLOOR * 0.7, color=f"C{index % 10}", alpha=0.12, zorder=0)
    if not tested:
        empty_note(bottom, "no p-value: too few records overturned for the test (it needs their capacities)")
    bottom.axhline(0.05, color="k", lw=0.8, ls="--", label="0.05: below it the measure is not sufficient")
    bottom.set_yscale("log")
    bottom.set_ylim(P_FLOOR * 0.7, 1.5)
    bottom.set_yticks([P_FLOOR, 0.01, 0.05, 0.1, 1.0], ["≤ 0.001", "0.01", "0.05", "0.1", "1"])
    bottom.minorticks_off()
    bottom.set_xticks(x, labels, fontsize=8)
    bottom.set_ylabel("p-value [-]", fontsize=9)
    whose = ("the one test's p-values" if len(tests) == 1 else
             "each test's p-values, under its bar and in its colour")
    bottom.set_title(f"Sufficiency (Luco & Cornell 2007): does the capacity still depend on the earthquake? ({whose})",
                     fontsize=10)
    bottom.grid(alpha=0.3, axis="y")
    outside_legend(figure, [top, bottom])
    return figure


def sensitivity_state(fragility) -> str:
    """The damage state the sensitivity page draws: overturning where the study has it, else its most severe."""
    states = [str(s) for s in fragility.damage_state.values]
    return "overturning" if "overturning" in states else states[-1]


def sensitivity_title(fragility, governing: dict | None = None) -> str:
    """The model-uncertainty page's title, as drawn and as the contents lists it."""
    what = "each soil's governing damage state" if governing else sensitivity_state(fragility)
    return f"Model uncertainty: which parameter moves the recommended median ({what})"


SPREAD_BOUND_MARK = "≥"
"""Above a sensitivity bar that is a lower bound (one end of the range has no median by the highest intensity)."""
SPREAD_ZERO_MARK = "0"
"""Above a sensitivity bar of zero height: both ends of the range gave the same median."""


def _one_end_missing(fragility, block: str, soils: list[str], states: list[str], parameters: list[str]) -> np.ndarray:
    """(soil, parameter): whether that bar rests on one end of the range alone (a lower bound, ``parameter_spread``)."""
    bounds = np.zeros((len(soils), len(parameters)), dtype=bool)
    if "member_median" not in fragility:
        return bounds
    members = [str(m) for m in fragility.member.values]
    for row, (soil, state) in enumerate(zip(soils, states)):
        medians = fragility.member_median.sel(block=block, soil=soil, damage_state=state)
        for column, parameter in enumerate(parameters):
            ends = [float(medians.sel(member=f"{parameter}_{end}")) if f"{parameter}_{end}" in members else np.nan
                    for end in ("low", "high")]
            bounds[row, column] = int(np.isfinite(ends).sum()) == 1
    return bounds


def _sensitivity_bars(fragility, block: str, soils: list[str], states: list[str], parameters: list[str]):
    """(spread, bounds), each (soil, parameter): the bars' heights and which are lower bounds."""
    spread = np.array([fragility.median_sensitivity.sel(block=block, soil=soil, damage_state=state,
                                                        parameter=parameters).values
                       for soil, state in zip(soils, states)])
    return spread, _one_end_missing(fragility, block, soils, states, parameters)


def _bar_mark(value: float, bound: bool) -> str:
    """The mark above one bar: ≥ on a lower bound, 0 on a bar too low to see, else ""."""
    if not np.isfinite(value):
        return ""
    return SPREAD_BOUND_MARK if bound else (SPREAD_ZERO_MARK if value < 5e-4 else "")


def sensitivity_marks(fragility, governing: dict | None = None) -> list[str]:
    """The marks the sensitivity page draws, in this order, so its caption explains only those.

    "*": a soil with no median; ``SPREAD_BOUND_MARK``: a lower bound; ``SPREAD_ZERO_MARK``: a bar of no height.
    """
    governing, default = governing or {}, sensitivity_state(fragility)
    parameters, soils = [str(p) for p in fragility.parameter.values], list(map(str, fragility.soil.values))
    used = set()
    for block in map(str, fragility.block.values):
        states = [governing.get((block, soil), default) for soil in soils]
        spread, bounds = _sensitivity_bars(fragility, block, soils, states, parameters)
        missing = [not np.isfinite(row).any() for row in spread]
        if any(missing) and not all(missing):
            used.add("*")
        used.update(_bar_mark(v, b) for v, b in zip(spread.ravel(), bounds.ravel()))
    return [mark for mark in ("*", SPREAD_BOUND_MARK, SPREAD_ZERO_MARK) if mark in used]


def sensitivity_page(fragility, caption, names: dict | None = None, governing: dict | None = None):
    """Which sampled parameter moves the recommended median most, per block and soil (``median_sensitivity``).

    One panel per block: for each soil, a bar per parameter (restitution, friction, bed stiffness) of the sigma of
    ln(median) over its range, and the model-form term beta_form as a dashed line (beta_model is the larger of it
    and the parameters' combined spread). ``governing`` {(block, soil): state} draws each soil's governing damage
    state (the summary's), named under the soil; without it, ``sensitivity_state`` on every soil (cold read 7: clay's
    panel was empty for overturning while its verdict rests on slip >= 0.30 m, whose spread the file has).
    """
    names, governing = names or {}, governing or {}
    default = sensitivity_state(fragility)
    blocks = list(map(str, fragility.block.values))
    figure = new_page(sensitivity_title(fragility, governing), caption)
    rows, columns = _grid(len(blocks))
    grid = dict(hspace=0.7 if governing else 0.55, wspace=0.3)
    if governing:  # the governing states' words under each panel need room above the caption
        grid["bottom"] = GRID["bottom"] + 0.05
    axes = panels(figure, rows, columns, gridspec_kw=grid).ravel()
    parameters = [str(p) for p in fragility.parameter.values]
    soils = list(map(str, fragility.soil.values))
    short = short_states(fragility)
    width = 0.8 / max(len(parameters), 1)
    x = np.arange(len(soils))
    for axis, block in zip(axes, blocks):
        states = [governing.get((block, soil), default) for soil in soils]
        spread, bounds = _sensitivity_bars(fragility, block, soils, states, parameters)  # (soil, parameter)
        for index, parameter in enumerate(parameters):
            centres = x + (index - (len(parameters) - 1) / 2) * width
            axis.bar(centres, np.nan_to_num(spread[:, index]), width, label=f"{parameter}", color=f"C{index % 10}")
            for centre, value, bound in zip(centres, spread[:, index], bounds[:, index]):
                mark = _bar_mark(value, bound)
                if mark:  # a lower bound, or a bar too low to see (both ends alike)
                    axis.annotate(mark, (centre, value), xytext=(0, 2), textcoords="offset points", ha="center",
                                  va="bottom", fontsize=8)
        form = np.nanmax([fragility.beta_form.sel(model="recommended", block=block, damage_state=state).max().item()
                          for state in set(states)] + [np.nan]) if "beta_form" in fragility else np.nan
        if np.isfinite(form):
            axis.axhline(form, color="k", lw=0.9, ls="--", label=f"model-form β {form:.2f} (FEMA P695 rating)")
        if not np.isfinite(spread).any():
            empty_note(axis, "no median below the highest intensity studied (not reached, or its median lies above it)")
            axis.set_ylim(0.0, max(form, 0.1) * 1.3 if np.isfinite(form) else 1.0)
        missing = [not np.isfinite(row).any() for row in spread]
        missing = missing if not all(missing) else [False] * len(soils)  # an empty panel says so once, inside
        if governing:  # which state each soil's bars are of, under the soils (a tick label per soil overlapped)
            axis.set_xticks(x, [f"{soil}*" if gone else soil for soil, gone in zip(soils, missing)], fontsize=8)
            by_state: dict[str, list[str]] = {}
            for soil, state in zip(soils, states):
                by_state.setdefault(short.get(state, state), []).append(soil)
            words = "; ".join(f"{state} on {', '.join(names_)}" if len(names_) < len(soils) else
                              f"{state} on every soil" for state, names_ in by_state.items())
            words += "; * no median" if any(missing) else ""
            axis.set_xlabel(textwrap.fill(f"governing state: {words}", chars_across(axis, 7)), fontsize=7)
        else:
            axis.set_xticks(x, [f"{soil}\n(no median)" if gone else soil for soil, gone in zip(soils, missing)],
                            fontsize=8)
        axis.set_ylabel("σ of ln median [-]", fontsize=9)
        axis.set_title(textwrap.fill(names.get(block, block), chars_across(axis, 10)), fontsize=10)
        axis.grid(alpha=0.3, axis="y")
    for axis in axes[len(blocks):]:
        axis.set_visible(False)
    outside_legend(figure, list(axes[:len(blocks)]))
    return figure
