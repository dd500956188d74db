"""rockfrag.report - stage 9: the study's result files -> a numbered client report (PDF and HTML).

Input : the study configuration and the datasets written by the earlier stages: ``cube.nc``, ``ida.nc``,
        ``fragility.nc`` (with the risk variables), ``showcase.nc`` (record-set spectra and the showcase
        histories, written at study time by rockfrag.showcase), optionally ``applicability.nc`` and
        ``efficiency.nc``. The report only reads; it never runs a solver.
Output: ``report.pdf`` (A4 landscape, every page numbered, the contents after the answer pages),
        ``report.html`` (the same pages in the same order: text pages as HTML text, figures embedded as
        PNG, a linked contents, an anchor per section and a way back to the contents from every page)
        and ``figures/NN-name.png`` (one per figure page). Neither file carries the date it was drawn: the
        same results give the same files (the title page gives the date the results were computed).

Page order: title, one answer page per block (rockfrag.report.answer_page), contents, summary, methods,
limitations, records, showcase record, IDA, fragility, outcomes, vertical component (a ``[study] vertical
= true`` study: ``cube_without_vertical.nc`` beside ``cube.nc``; rockfrag.report.vertical), applicability,
measure efficiency, glossary, references. Pages for blocks, soils, models and records come from the
result files, so only what the study ran is shown. Every intensity axis is logarithmic and marks the
site's return-period intensities and, shaded, the extrapolation by scaling beyond the largest recorded
intensity.
"""

from __future__ import annotations

import base64
import html
import io
import multiprocessing
import os
import re
import textwrap
from dataclasses import replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402
from matplotlib.backends.backend_pdf import PdfPages  # noqa: E402
from tqdm import tqdm  # noqa: E402

from rockfrag.answer import RECOMMENDED, display_scale  # noqa: E402
from rockfrag.config import StudyConfig  # noqa: E402
from rockfrag.damage_states import damage_states_from_config  # noqa: E402
from rockfrag.outputs import atomic_path  # noqa: E402
from rockfrag.report import figures as pages  # noqa: E402
from rockfrag.report import numbers  # noqa: E402
from rockfrag.report.adapters import (  # noqa: E402
    block_name,
    model_info,
    models_of,
    record_pga_g,
    short_label,
    soils_of,
)
from rockfrag.report.answer_page import SUFFICIENCY_LEVEL, answer_items, reading_items  # noqa: E402
from rockfrag.report.layout import Page, add_footer, new_page  # noqa: E402
from rockfrag.report.sections import (  # noqa: E402
    Results,
    fitted_items,
    limitations_items,
    methods_items,
    reproduce_items,
    title_items,
)
from rockfrag.report.summary import governing, summary_items  # noqa: E402
from rockfrag.report.text import Item, draw_text_page, items_html, note, paginate, table  # noqa: E402
from rockfrag.report.vertical import open_comparison, vertical_effect, vertical_items, vertical_page  # noqa: E402
from rockfrag.report.words import glossary_items, listed, references_items  # noqa: E402
from rockfrag.units import STANDARD_GRAVITY  # noqa: E402
from rockfrag.version import __version__  # noqa: E402

PNG_DPI = 100
G = STANDARD_GRAVITY


def _text_pages(name, section, title, items, caption=""):
    chunks = paginate(items)
    planned = []
    for number, chunk in enumerate(chunks, start=1):
        suffix = f" ({number}/{len(chunks)})" if len(chunks) > 1 else ""
        planned.append(Page(f"{name}-{number}" if len(chunks) > 1 else name, section, title + suffix,
                            lambda chunk=chunk, t=title + suffix: draw_text_page(t, chunk, caption),
                            caption, items_html(chunk), heading=title))
    return planned


def _packed_pages(parts) -> list[Page]:
    """Consecutive text sections on shared pages, so no page holds a few table rows or a single line alone.

    A section starts on the page where the previous one ends when it fits there, headed by its title.

    ``parts`` lists (name, section, title, items); a page is named and titled by the section it starts with,
    and lists the other sections that start on it in ``Page.also`` (the contents and the HTML anchors).
    """
    flow = []
    for index, (_, _, title, items) in enumerate(parts):
        if index:  # its anchor: the contents' link lands on this heading, not on the page's title above it
            flow.append(Item("heading", title, part=index, anchor=_slug(parts[index][1])))
        flow += [replace(item, part=index) for item in items]
    chunks = paginate(flow)
    first_part = [chunk[0].part if chunk else 0 for chunk in chunks]
    planned, counters = [], {}
    for number, chunk in enumerate(chunks):
        part = first_part[number]
        if chunk and chunk[0].kind == "heading" and chunk[0].part and chunk[0].text == parts[part][2] \
                and (number == 0 or first_part[number - 1] != part):
            chunk = chunk[1:]  # the page title says it
        name, section, title, _ = parts[part]
        holding = [n for n, other in enumerate(chunks) if any(item.part == part for item in other)]
        counters[part] = counters.get(part, 0) + 1
        suffix = f" ({holding.index(number) + 1}/{len(holding)})" if len(holding) > 1 else ""
        pages_of_part = sum(1 for p in first_part if p == part)
        others = list(dict.fromkeys(item.part for item in chunk if item.part != part))
        also = tuple(dict.fromkeys(parts[other][1] for other in others))
        headings = tuple(dict(zip((parts[other][1] for other in others), (parts[other][2] for other in others)))
                         .values())
        planned.append(Page(f"{name}-{counters[part]}" if pages_of_part > 1 else name, section, title + suffix,
                            lambda chunk=chunk, t=title + suffix: draw_text_page(t, chunk), "", items_html(chunk),
                            also=also, heading=title, also_headings=headings))
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


def governing_states(results: Results) -> dict:
    """{(block, soil): the damage state that governs its verdict} (the summary's), for the pages that draw it."""
    states = {}
    for answer in results.answers:
        for soil in answer.soils:
            row = governing(soil)
            if row is not None:
                states[(str(answer.block), str(soil.soil))] = str(row.state)
    return states


def _figure(page, section, title, function, *args, caption="", **options):
    return Page(page, section, title, lambda: function(*args, caption, **options), caption)


def records_items(results: Results) -> list[Item]:
    """Intensity measures of the processed records (showcase.nc), or the cube's PGA when it is absent.

    Event and station names are shown whole: a cut name is a different station.
    """
    cube, showcase = results.cube, results.showcase
    meta = [(str(r), str(cube.record_event.values[i]) if "record_event" in cube.coords else "",
             str(cube.record_station.values[i]) if "record_station" in cube.coords else "")
            for i, r in enumerate(cube.record.values)]
    if showcase is not None and "record_pga" in showcase:
        measures = showcase.sel(record=cube.record.values)
        header = ["record", "event", "station", "PGA [g]", "PGV [m/s]", "Ia [m/s]", "D5-95 [s]", "Sa(1 s) [g]"]
        rows = [[*m, f"{float(measures.record_pga[i]) / G:.2f}", f"{float(measures.record_pgv[i]):.2f}",
                 f"{float(measures.record_arias[i]):.2g}", f"{float(measures.record_d5_95[i]):.0f}",
                 f"{float(measures.record_sa_1s[i]) / G:.2f}"] for i, m in enumerate(meta)]
    else:
        header = ["record", "event", "station", "PGA [g]"]
        rows = [[*m, f"{pga:.2f}"] for m, pga in zip(meta, record_pga_g(cube))]
    scaled = scaled_intensities(cube)
    if scaled is not None:  # the intensity the study scales by, where it is not the component's own PGA
        values, unit = scaled
        header = [*header[:4], f"scaled by: RotD50 PGA of the pair [{unit}]", *header[4:]]
        rows = [[*row[:4], f"{value:.2f}", *row[4:]] for row, value in zip(rows, values)]
    return [table(header, rows), note(STATION_NAMES)]


def scaled_intensities(cube) -> tuple[np.ndarray, str] | None:
    """Each record's unscaled intensity as the study scales it (``record_im``) and its unit, or None.

    Only where it is the pair's RotD50 PGA: it differs from the component's PGA the records table lists.
    """
    if "record_im" not in cube.variables or str(cube.attrs.get("intensity_measure", "")).lower() != "pga" \
            or str(cube.attrs.get("intensity_component", "")).upper() != "ROTD50":
        return None
    values = cube.record_im
    if "block" in values.dims:  # PGA needs no block: every block's column is the same
        values = values.isel(block=0)
    scale, unit = display_scale(str(values.attrs.get("units", "")))
    return np.asarray(values.values, float) * scale, unit


STATION_NAMES = ("Stations are named as the records' source catalogue spells them (FEMA P695 Table A-4, from PEER's "
                 "NGA database), its abbreviations included ('Beverly Hills - Mulhol'); the report does not shorten "
                 "them.")
"""The records table's note: the names are the source's own (abbreviated there), not cut by the report."""


CAPTIONS = {
    "hazard": "Read how often each intensity is exceeded at the site, per year: each soil's curve (its colour) and "
              "the reference site's it is carried from (black dashed); dotted, the frequencies of the return periods "
              "(a point where a curve crosses one: the site's intensity of that return period, as the answer pages "
              "print it); grey shading: beyond the largest recorded intensity; the axis ends at the highest "
              "intensity studied, and a curve that leaves the frequency axis (above or below) is cut by the axis "
              "only: the risk integral takes it to the highest intensity studied. A soft soil's curve can fall below "
              "the reference site's at strong shaking: the site term's nonlinear part de-amplifies it (Methods).",
    "spectra": "Read how strong and how varied the records are: each grey line is one record component "
               "unscaled (the Records section lists them); the 16% "
               "(blue dashed), 50% (black) and 84% (red dotted) fractiles. The study scales every record to each "
               "intensity level.",
    "showcase-processing": "Read what processing changes: raw as published (grey) and processed (blue: band-pass "
                           "filtered and baseline-corrected, Methods). The band-pass trims long-period content the "
                           "published record kept, which shows in the displacement; it is zero-phase, so acausal: "
                           "where the processed displacement moves before the shaking, that is its precursor, of "
                           "negligible acceleration. Where grey is hidden under blue the two are the same at this "
                           "scale.",
    "showcase-response": "Read how the soil changes the rocking under one real record, unscaled: θ (left, one scale "
                         "for all panels) and Δy (right), the vertical displacement from rest of the base's centre "
                         "on the tensionless bed, or of the active pivot in the paper's model, up +: a block rocking "
                         "about an edge lifts its base centre by about b·θ, so a rise is rocking, and a drop below "
                         "0 is the bed giving under the block; grey: the strong-motion window (5-95% Arias). As in "
                         "the paper's Figs. 4, 7 and 10. One record: how much the models differ under it need not "
                         "hold over the record set, which the IDA and fragility pages give.",
    "ida": "Read at which intensity the block starts to rock and where it overturns: thin grey lines, one record "
           "each; the 16% (blue dashed), 50% (black) and 84% (red dotted) fractiles of θmax/α. Overturning is drawn "
           "at the right edge. Dotted: the site's return-period intensities (the legend names them); shaded: "
           "beyond the largest recorded intensity (extrapolation by scaling). "
           "A block that slides instead of rocking stays at θmax/α = 0. Curves are not smoothed: a record may "
           "overturn at one level and survive a higher one; the lines and fractiles here show each run as it ran, "
           "while the fragility fits count such a record as overturned from its first overturning level on, so a "
           "fractile can stay below the edge where the fits count more records overturned.",
    "fragility-soils": "Read how likely each damage state is at the site's intensities (dotted lines) and whether "
                       "the soil changes it: points, the fraction of records reaching the state at each level (open "
                       "for the rigid base's); lines, "
                       "the fitted lognormal, {lines}, one colour per soil (where soils' lines coincide, the last "
                       "drawn shows); light shading around a line, the confidence bounds of its median; {rigid}. "
                       "Grey shading: extrapolation by scaling.",
    "fragility-models": "Read how much the choice of model moves the curves: top row the softest soil or base, "
                        "bottom the stiffest (by shear modulus). Points: records (open for the rigid base's); "
                        "lines: fits, one style per model (legend); light shading around a line: the confidence "
                        "bounds of its median. Dotted: the site's return-period intensities; grey shading: "
                        "extrapolation by scaling.",
    "outcomes": "Read what the block does at the site's intensities (dotted lines): solid, the probability that it "
                "lifts off (uplift: a base corner lifts at least the uplift size; a smaller lift is a tilt on the "
                "bed); dashed, that it overturns; between them it rocks and stays up{shading}. Grey shading: "
                "extrapolation by scaling. The intensity is the pair's "
                "RotD50, which one component can exceed: a rigid base may lift off a little below g·tanα. Sliding is "
                "not drawn here: a block that slides without lifting off stays at zero on these panels, and its slip "
                "states are on its fragility pages and answer page.",
    "vertical": "Read whether the vertical ground motion matters: solid with it, dashed without, the same records "
                "at the same levels. Top: median θmax/α (not drawn where most runs flew); bottom: fraction "
                "overturned and the fitted curves. Dotted: return-period intensities; shaded: extrapolation.",
    "applicability": "Read where the rigid-base model is good enough: each line (a point where one soil alone has a "
                     "ratio) is one foundation model (its colour and dashes) for one block (its marker): the median "
                     "peak angle of the runs between 1.2 and 3 times the block's uplift threshold over the rigid "
                     "base's. Grey shading: within 10% of the "
                     "rigid base. Green shading: 300-1000 MPa, the soil stiffness above which the paper finds the "
                     "rigid base good enough. Top axis: the study's soils. Lines that coincide hide each other. "
                     "These are the study's own runs: the recommended model's base has friction and its bed's "
                     "restitution is set within the experiments' range: where its block slides instead of rocking "
                     "(the answer pages name those soils) the ratio falls far below 1, which is sliding, not the "
                     "bed's stiffness; above 1 in the green band it does not confirm the paper's 'good enough'.",
    "applicability-sweep": "Read the soil stiffness above which the rigid base is good enough: the ratio of median "
                           "peak angles (model over rigid base) against the soil's shear modulus; grey: ±10%; "
                           "green: 300-1000 MPa, the stiffness above which the paper finds the rigid base good "
                           "enough; colours: the intensity level; solid concrete block, dashed steel block.",
    "sensitivity": "Read which uncertain parameter of the recommended model moves its median most on each soil, "
                   "for the damage state that governs that soil's verdict (named under each panel): each bar is "
                   "the σ of ln median over that parameter's range (restitution, friction, bed "
                   "stiffness), the others central; the dashed line is the model-form β (FEMA P695's rating). The "
                   "model part of β is the larger of the model-form β and the bars combined (√ of the sum of "
                   "squares): the rating covers the parameters, so it replaces their spread, it is not added.",
    "efficiency": "Read which intensity measure predicts overturning with the least scatter (top: lower bars are "
                  "better; each bar is the dispersion of ln capacity over the records that overturned by the "
                  "highest intensity studied, their number in the legend: those that did not are left out, so a "
                  "bar can lie below the fitted curve's β, which counts them too) and whether the capacity still "
                  "depends on magnitude, distance or pulse period (bottom: below the dashed line it does; the test "
                  "of Luco & Cornell 2007).",
}
"""What each figure page lets the reader read, one caption per kind of page."""

SENSITIVITY_MARK_WORDS = {
    "*": " A soil marked * ('no median') has no curve of its state below the highest intensity studied.",
    "≥": " A bar marked ≥ is a lower bound: one end of its range has no median below the highest intensity studied, "
         "so that end's median lies beyond it and the bar spans at least from the other end to that intensity (for "
         "friction, the answer page names such soils).",
    "0": " A bar marked 0 has no height: both ends of its range gave the same median (where the bed cannot tell "
         "them apart they are one run; the answer page says so).",
}
"""The sensitivity caption's sentence on each mark its page draws (``figures.sensitivity_marks``), said only then."""

OUTCOMES_SHADING = " (shaded orange where a panel has one pair of curves)"
"""The outcomes caption's words on the rocking band, on a page that shows it (``figures.rocking_shaded``)."""

NOTES_WORDS = " The notes under the legend say which series have points but no curve, and why."
"""A fragility caption's last sentence, on a page whose notes list such series (``figures.has_page_notes``)."""

SWEEP_NEXT = (" The next page ties every base and leaves the bed's damping uncalibrated, to isolate stiffness: the two "
              "pages differ by design.")
"""The applicability caption's last sentence, where the sweep's page follows it (a study run with the sweep)."""


def showcase_slide_words(results) -> str:
    """The showcase caption's sentence on soils where the block slides before it can rock ("" where none).

    Cold read 12, user B5: on clay the rigid base only slides, so its θ is 0 and hidden under the other lines, and
    the slip that governs clay's verdict is not drawn: the caption says both.
    """
    showcase, config = results.showcase, results.config
    block = next((b for b in config.blocks if showcase is not None
                  and b.name == showcase.attrs.get("showcase_block")), None)
    if block is None:
        return ""
    soils = [soil.name for soil in config.soils if soil.friction_static < block.b / block.h
             and soil.name in set(map(str, showcase.case_soil.values))]
    if not soils:
        return ""
    return (f" On {listed(soils)} the base friction is below b/h = {block.b / block.h:.2f}: the rigid base slides "
            "without rocking, so its θ stays 0 under the other lines; its slip is not drawn here (the answer page "
            "has the slip states).")


def kinetic_slip_words(results, block: str, model: str | None = None) -> str:
    """A caption sentence on the soils where ``block`` rocks at rest but, once its base slips, cannot tip ("" if none).

    μ_k < b/h <= μ_s (Shenton 1996): which records slip changes with the scaling, so the share that lifts off need
    not rise with the intensity, and the lift-off curve lies far from the rigid base's tied one (cold read 12,
    default figures B1: the paper block's lift-off on steel went 20, 17, 29, 22 of 44 over four levels).
    """
    config, cube = results.config, results.cube
    found = next((b for b in config.blocks if b.name == block), None)
    if found is None or "friction_static" not in cube:
        return ""
    slender = found.b / found.h
    friction = cube.friction_static.sel(block=block)
    if model is not None and "model" in friction.dims:  # only a model whose base can slide there
        friction = friction.sel(model=model) if model in friction.model.values else friction * np.nan
    soils = [soil for soil in config.soils if soil.name in cube.soil.values
             and soil.friction_kinetic < slender <= soil.friction_static
             and np.isfinite(friction.sel(soil=soil.name)).any()]
    fragility = results.fragility
    if not soils or "empirical_fraction" not in fragility or "uplift" not in fragility.damage_state.values:
        return ""
    n = int(fragility["n_records"]) if "n_records" in fragility else 0
    levels = np.asarray(fragility.intensity.sel(block=block).values if "intensity" in fragility.coords
                        and "block" in fragility.intensity.dims else [], float)
    scale, unit = display_scale(str(fragility.intensity.attrs.get("units", ""))) if levels.size else (1.0, "")
    said = []
    for soil in soils:  # only where the share does fall between levels (cold read 12, user round 3: sand's rose)
        share = fragility.empirical_fraction.sel(model=model or RECOMMENDED, block=block, soil=soil.name,
                                                 damage_state="uplift").values * n
        drops = [i for i in range(1, len(share)) if share[i] <= share[i - 1] - 2]
        if drops and levels.size:  # every fall, not the first alone (cold read 12, default figures round 3)
            falls = [f"from {share[i - 1]:.0f} to {share[i]:.0f} of {n} between {levels[i - 1] * scale:#.3g} and "
                     f"{levels[i] * scale:#.3g} {unit}" for i in drops]
            said.append(f"on {soil.name} (μ_k {soil.friction_kinetic:.3f} against {slender:.3f}) it falls "
                        + listed(falls))
    if not said:
        return ""
    return (f" Where the kinetic friction is below this block's b/h = {slender:.2f}, a base that slips cannot tip, "
            "and which records slip changes with the scaling, so the share that lifts off need not rise with the "
            f"intensity: {'; '.join(said)} (the answer page says why).")


def _rigid_words(fragility, block) -> str:
    """How the fragility-by-soil page draws the rigid base of ``block``: the caption says the style it has."""
    rigid = [m for m in models_of(fragility) if m.rigid_base]
    if not rigid:
        return "no rigid-base reference in this study"
    per_soil = [m for m in rigid if soils_of(fragility, m, block, "median") != [None]]
    if not per_soil:
        return "black dashed: the rigid base (the same on every soil)"
    if len(per_soil) == len(rigid):
        return "dashed in each soil's colour: the rigid base (its base slides on some soils, so it differs by soil)"
    return ("dashed: the rigid base, black where it is the same on every soil, in each soil's colour where its base "
            "slides on some soils")


def _twins_words(efficiency) -> str:
    """The efficiency caption's sentence on the measures left out because they repeat another ("" if none)."""
    twins = pages.efficiency_twins(efficiency)
    if not twins:
        return ""
    pairs = "; ".join(f"{pages.measure_words(m)} repeats {pages.measure_words(o)}" for m, o in twins.items())
    defined = " (p = √(3g/4R), Housner's frequency parameter)" if "·p/" in pairs else ""  # cold read 12, user
    return f" Not drawn ({pairs}){defined}: identical by construction (a constant of the block divides them)."


def hazard_caption(results) -> str:
    """The hazard page's caption end: whose curve it is, in the summary's words."""
    from rockfrag.report.summary import hazard_caveat

    caveat = hazard_caveat(results)
    text = stiffer_site_words(results.config.soils, results.site_hazards)
    sites = results.site_hazards
    highest = max((float(v) for v in results.credible_limits.values()), default=np.inf) \
        if getattr(results, "credible_limits", None) else np.inf
    if sites is not None and sites.reference is not None and np.isfinite(highest) \
            and float(np.max(sites.reference.intensity)) < highest:  # cold read 12, default C5: said only then
        text += " A soil's curve stops where the given one ends, at its rarest frequency."
    return text + (f" The curve: {caveat}." if caveat else " The curve: the site's, given with the study (Methods).")


def stiffer_site_words(soils, sites) -> str:
    """The hazard caption's sentence on the soils whose site is stiffer than the reference's ("" when none is).

    Said only where such a site is drawn (cold read 11: the clause stood on the user study's page, which has none).
    """
    if sites is None or sites.reference is None:
        return ""
    stiffer = [soil.name for soil in soils
               if soil.vs30 is not None and soil.vs30 > sites.reference_vs30 and soil.name in sites]
    if not stiffer:
        return ""
    return (f" {listed(stiffer).capitalize()}: {'a site' if len(stiffer) == 1 else 'sites'} stiffer than the "
            "reference (a higher Vs30, legend), so the curve lies below the reference's: the ground amplifies the "
            "motion less.")


def sweep_words(applicability) -> str:
    """The sweep caption's sentences on what its ratio measures: tied bases and an uncalibrated dashpot.

    The sweep runs each foundation model with its base tied and its dashpot at the sweep's damping ratio, not
    calibrated to Housner's restitution. The tensionless bed so damped keeps more of its rocking speed at an impact
    than Housner's r (tests/test_report_signable.py checks it for the default blocks on the stiffest ground), so its
    ratio does not tend to 1 as the ground stiffens; the paper's model, whose dashpot takes out what the corner
    impact would, does.
    """
    xi = numbers.stated_probability(float(applicability.attrs.get("damping_ratio", 0.05)))
    models = {str(m) for m in applicability.model.values} if "model" in applicability.coords else set()
    text = (f" Every run here ties the base (no sliding) and gives the foundation's dashpot {xi} of critical "
            "damping, not calibrated to Housner's restitution: it isolates stiffness, and the page before compares "
            "the study's own runs.")
    if "winkler" in models:
        text += (" The tensionless bed so damped loses less energy at an impact than Housner's r = 1 − 1.5 sin²α, so "
                 "even on the stiffest ground its ratio stays above 1: it measures the bed's damping as well as its "
                 "stiffness.")
    if models & {"ssi", "ssi-paper"}:
        text += (" The paper's model, whose dashpot takes out what the corner impact would, comes closer to 1 on stiff "
                 "ground.")
    return text


def tested_cells_words(efficiency, names: dict | None = None) -> str:
    """What the efficiency page's bars and p-values rest on: independent tests, named in its legend.

    "Each bar is one independent test, named in the legend with the records that overturned in it; a tied rigid
    base's same runs on several soils count once; ..." ("" without a test). ``names`` is unused (the legend names).
    """
    if "dispersion" not in efficiency:
        return ""
    tests, total = pages.tests_drawn(efficiency)
    if not tests:
        return ""
    drawn = f" (the {len(tests)} with the most records drawn)" if total > len(tests) else ""
    copies = any(len(test.soils) > 1 for test in tests)
    return (f" Each bar is one independent test{drawn}, named in the legend with the records that overturned in it"
            + ("; a tied rigid base's same runs on several soils count once" if copies else "")
            + "; a test needs the overturning capacities refined between the levels, which the study computes only "
              "where the base is tied and the foundation cannot pull (not for a base that slides, nor for the "
              "paper's model), and enough records that overturn.")  # cold read 9, user B3: not 'too few records'


def measure_choice_words(efficiency, names: dict, hazard: bool = True) -> str:
    """The efficiency caption's sentences: why the study's measure, what a better one would change, what it misses.

    Per independent test (``rockfrag.efficiency.independent_tests``), the measure with the smallest dispersion of
    the overturning capacity against the study's measure, said better only where their confidence bands do not
    overlap; the study's measure is the hazard's, which the fragility must share to be integrated with it. Where the
    study's measure fails the sufficiency test (p < 0.05 against the pulse period, magnitude or distance) in a test,
    the caption names the test (block, model, soils): the curves hold for records like the study's.
    """
    from rockfrag.efficiency import dispersion_interval

    study = str(efficiency.attrs.get("study_measure", ""))
    if not study or study not in efficiency.measure.values or "dispersion" not in efficiency:
        return ""
    twins = pages.efficiency_twins(efficiency)
    measures = [str(m) for m in efficiency.measure.values if str(m) not in twins]
    tests, _ = pages.tests_drawn(efficiency)
    words = pages.measure_words(study)
    better, unresolved, failing = [], [], []
    for test in tests:
        where = dict(soil=test.soils[0], block=test.block, model=test.model)
        cell = efficiency.sel(where)
        values = dict(zip(measures, np.asarray(cell.dispersion.sel(measure=measures).values, float)))
        name = names.get(test.block, test.block)
        if np.isfinite(values.get(study, np.nan)):
            best = min((m for m in measures if np.isfinite(values[m])), key=values.get)
            if best != study:
                said = (f"{pages.measure_words(best)} for the {name} ({numbers.dispersion(values[best])} against "
                        f"{numbers.dispersion(values[study])})")
                if "n_records" in cell:
                    counts = [float(cell.n_records.sel(measure=m)) for m in (best, study)]
                    low, high = dispersion_interval([values[best], values[study]], counts)
                    if high[0] >= low[1]:  # the bands overlap: the records cannot tell the two apart
                        unresolved.append(f"{said[:-1]}, {test.records} records)")
                        continue
                def failing_tests(measure, cell=cell):
                    return [what.removeprefix("against ") for variable, _, _, what in pages.P_MARKERS
                            if variable in cell and float(cell[variable].sel(measure=measure)) < SUFFICIENCY_LEVEL]

                fails = failing_tests(best)
                if fails:  # less scatter is no reason to switch where the measure misses what the records carry
                    said += f", though it fails the sufficiency test too (against {' and '.join(fails)})"
                    # cold read 12, default figures B2: PGV, less scatter too and sufficient, went unnamed
                    for other in sorted((m for m in measures if m not in (best, study) and np.isfinite(values[m])
                                         and values[m] < values[study]), key=values.get):
                        if "n_records" in cell:
                            counts = [float(cell.n_records.sel(measure=m)) for m in (other, study)]
                            low, high = dispersion_interval([values[other], values[study]], counts)
                            if high[0] >= low[1]:
                                continue
                        if not failing_tests(other):
                            said += (f"; {pages.measure_words(other)} ({numbers.dispersion(values[other])}) has less "
                                     "scatter too and passes every sufficiency test")
                            break
                better.append(said)
        failed = [what.removeprefix("against ") for variable, _, _, what in pages.P_MARKERS if variable in cell
                  and float(cell[variable].sel(measure=study)) < SUFFICIENCY_LEVEL]
        if failed:
            model = short_label(model_info(test.model))
            failing.append(f"the {name}, {model}, {pages.soils_words(test.soils, list(efficiency.soil.values))}"
                           f" (against {' and '.join(failed)})")
    text = (f" The curves are in {words} because the site's hazard is (a curve must share the hazard's measure; "
            "a site hazard in another measure would let the study use it)."
            if hazard else f" The curves are in {words}, the study's measure.")
    if better:
        text += f" Less scatter than {words}: {'; '.join(better)}; in {words} those curves are wider, not shifted."
    if unresolved:
        text += f" Within {words}'s confidence band, so not shown better: {'; '.join(unresolved)}."
    text += tested_cells_words(efficiency, names)
    if failing:
        text += (f" {words} fails the sufficiency test (bottom) for {'; '.join(failing)}: those curves hold for "
                 "records like the study's, biased by an amount not sized here where the site's motions differ (near "
                 "a fault).")
    return text


def plan(results: Results) -> list[Page]:
    """Every page of the report in order (contents excluded: it is made from this list)."""
    cube, ida, fragility, showcase = results.cube, results.ida, results.fragility, results.showcase
    config = results.config
    blocks = list(map(str, cube.block.values))
    names = {block: block_name(config, block) for block in blocks}
    planned = [title_page(results)]
    with results.facts.writing("Summary"):
        planned += _text_pages("summary", "Summary", "Summary: the action for each asset and soil",
                               summary_items(results))
    answers = []
    if results.answers:
        with results.facts.writing("Answers"):
            answers.append(("answers", "Answers", "Reading the answer pages", reading_items(results)))
        for answer in results.answers:
            name = names.get(answer.block, answer.block)
            with results.facts.writing(f"Answer: {name}"):
                answers.append((f"answer-{answer.block}", f"Answer: {name}", f"Answer: {name}",
                                answer_items(results, answer)))
    with results.facts.writing("Fitted curves"):
        fitted = fitted_items(results)
    with results.facts.writing("Limitations"):
        limitations = limitations_items(results)
    planned += _packed_pages([  # one run of text: a section starts where the one before ends (no near-empty page)
        *answers,
        ("fitted", "Fitted curves", "Fitted fragility functions", fitted),
        ("methods", "Methods", "Methods and assumptions", methods_items(results)),
        ("limitations", "Limitations", "Limitations: where the models are outside their validity", limitations),
        ("records-table", "Records", "Intensity measures of the processed records",
         [*records_items(results), note("PGA, PGV, Arias intensity, significant duration and 5%-damped Sa(1 s) "
                                        "of each component after processing" + (
                                            "; 'scaled by': the intensity the study scales the record by, the "
                                            "RotD50 PGA of its station's pair (Methods), one value per pair"
                                            if scaled_intensities(cube) is not None else "") + ".")])])
    if results.site_hazards is not None and results.answers and results.return_periods:
        planned.append(_figure("hazard", "Site hazard", "Site hazard: the hazard curve of each soil's site",
                               pages.hazard_page, results.site_hazards, results.return_periods,
                               caption=CAPTIONS["hazard"] + hazard_caption(results),
                               unit=results.answers[0].unit, **hazard_marks(results)))
    if showcase is not None and "record_spectrum" in showcase:
        planned.append(_figure("spectra", "Record spectra", "Response spectra of the record set", pages.spectra_page,
                               showcase, caption=CAPTIONS["spectra"]))
    if showcase is not None and "theta" in showcase:
        record = pages.record_words(showcase)
        showcase_name = names.get(str(showcase.attrs.get("showcase_block", "")))
        planned.append(_figure("showcase-processing", "Showcase record", f"{record}: raw and processed",
                               pages.showcase_ground_page, showcase, caption=CAPTIONS["showcase-processing"]))
        planned.append(_figure("showcase-response", "Showcase record",
                               pages.showcase_response_title(showcase, showcase_name),
                               pages.showcase_response_page, showcase,
                               caption=CAPTIONS["showcase-response"] + pages.quiet_words(showcase)
                               + showcase_slide_words(results),
                               name=showcase_name))
    models = models_of(cube)
    soils = list(map(str, cube.soil.values))
    extremes = [soils[0], soils[-1]] if len(soils) > 1 else soils
    for block in blocks:
        planned.append(_figure(f"ida-{block}", "IDA curves", f"IDA curves: {names[block]}", pages.ida_page, ida, block,
                               caption=CAPTIONS["ida"], marks=results.marks(block), name=names[block]))
    for block in blocks:
        for model in (m for m in models_of(fragility) if not m.rigid_base):
            planned.append(_figure(f"fragility-soils-{block}-{model.name}", "Fragility",
                                   pages.fragility_by_soil_title(fragility, block, model, names[block]),
                                   pages.fragility_by_soil_page, fragility, block, model,
                                   caption=CAPTIONS["fragility-soils"].format(rigid=_rigid_words(fragility, block),
                                                                              lines=pages.line_words(fragility, model))
                                   + kinetic_slip_words(results, block, model.name)
                                   + (NOTES_WORDS if pages.has_page_notes(
                                       fragility, block, [model, *(m for m in models_of(fragility) if m.rigid_base)])
                                      else ""),
                                   marks=results.marks(block), name=names[block]))
        planned.append(_figure(f"fragility-models-{block}", "Fragility", f"Fragility by model: {names[block]}",
                               pages.fragility_by_model_page, fragility, block, extremes,
                               caption=CAPTIONS["fragility-models"]
                               + (NOTES_WORDS if pages.has_page_notes(fragility, block, soils=extremes) else ""),
                               marks=results.marks(block), name=names[block]))
    if "median_sensitivity" in fragility:
        governing_by_soil = governing_states(results)
        planned.append(_figure("sensitivity", "Fragility", pages.sensitivity_title(fragility, governing_by_soil),
                               pages.sensitivity_page, fragility, names=names,
                               caption=CAPTIONS["sensitivity"] + "".join(
                                   SENSITIVITY_MARK_WORDS[mark]
                                   for mark in pages.sensitivity_marks(fragility, governing_by_soil)),
                               governing=governing_by_soil))
    for block in blocks:
        planned.append(_figure(f"outcomes-{block}", "Outcomes", f"Outcomes by intensity: {names[block]}",
                               pages.outcomes_page, fragility, block,
                               caption=CAPTIONS["outcomes"].format(
                                   shading=OUTCOMES_SHADING if pages.rocking_shaded(fragility, block) else "")
                               + kinetic_slip_words(results, block),
                               marks=results.marks(block), name=names[block]))
    if results.vertical is not None:
        planned += _text_pages("vertical", "Vertical component", "Vertical component: medians with and without it",
                               vertical_items(results.vertical, names))
        for block in blocks:
            planned.append(_figure(f"vertical-{block}", "Vertical component", f"Vertical component: {names[block]}",
                                   vertical_page, results.vertical, block, caption=CAPTIONS["vertical"],
                                   marks=results.marks(block), name=names[block]))
    if any(m.rigid_base for m in models) and any(not m.rigid_base for m in models):
        planned.append(_figure("applicability", "Applicability", pages.applicability_title(cube),
                               pages.applicability_page, cube, caption=CAPTIONS["applicability"]
                               + (SWEEP_NEXT if results.applicability is not None
                                  and "peak_angle_ratio_to_housner" in results.applicability else ""),
                               names=names))
    if results.applicability is not None and "peak_angle_ratio_to_housner" in results.applicability:
        planned.append(_figure("applicability-sweep", "Applicability", pages.sweep_title(results.applicability),
                               pages.sweep_page, results.applicability,
                               caption=CAPTIONS["applicability-sweep"] + sweep_words(results.applicability)
                                       + " Median over the records (of "
                                       f"{results.applicability.attrs.get('n_records', '?')}) that survived in "
                                       "both models at each level: at the higher levels, fewer.",
                               names=names))
    if results.efficiency is not None and "dispersion" in results.efficiency:
        planned.append(_figure("efficiency", "Measure efficiency", pages.EFFICIENCY_TITLE,
                               pages.efficiency_page, results.efficiency,
                               caption=CAPTIONS["efficiency"] + _twins_words(results.efficiency)
                               + measure_choice_words(results.efficiency, names, results.hazard is not None),
                               names=names))
    glossary, reproduce = glossary_items(), reproduce_items(results)
    cited = " ".join([*(f"{page.html or ''} {page.caption or ''}" for page in planned),
                      *(item.text for item in glossary + reproduce)])
    planned += _packed_pages([("glossary", "Glossary", "Glossary", glossary),
                              ("references", "References", "References", references_items(cited)),
                              ("reproduce", "How to reproduce this report", "How to reproduce this report",
                               reproduce)])
    return planned


def hazard_marks(results) -> dict:
    """The site hazard page's marks (``hazard_page``), in the answer pages' unit.

    The highest level run, the largest unscaled record, each soil's site intensity at each return period.
    """
    answer = results.answers[0]
    scale = display_scale(str(results.cube["intensity"].attrs.get("units", "")))[0] \
        if "intensity" in results.cube else 1.0
    highest = float(results.cube["intensity"].max()) * scale if "intensity" in results.cube else None
    largest = max(results.largest_recorded.values()) if results.largest_recorded else None
    by_soil = {soil.soil: tuple(soil.intensities) for soil in answer.soils if soil.intensities}
    return {"highest": highest, "largest": largest, "site_intensities": by_soil}


def _slug(text: str) -> str:
    return "section-" + re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")


CONTENTS_LINES = 36  # lines per column of the contents page
CONTENTS_WIDTH = 62  # characters per line of a contents column (two columns); longer titles wrap, never cut
CONTENTS_WIDTH_THREE = 52  # the same in three columns of smaller type (a long study: the default has 54 pages)
BOLD_NUMBERED_NARROWER = 8  # a bold section title with its page number on its line wraps this much earlier


def contents_rows(planned: list[Page], position: int = 2) -> list[tuple[str, str, int]]:
    """The contents' rows: ("section" or "page", title, the number of the page it starts on).

    The contents itself is page ``position``. A section that starts part-way down a page (``Page.also``) is
    listed with that page, its title too: not with the next page, where its text continues.
    """
    first_heading = {}  # a section's title: the heading of its first own page
    for page in planned:
        first_heading.setdefault(page.section, page.heading or page.title)
    rows, last, listed = [], None, None
    for number, page in enumerate(planned, start=1):
        shown = number + (1 if number >= position else 0)  # the contents is inserted at ``position``
        heading = page.heading or page.title
        if page.section != last:
            rows.append(("section", page.section, shown))
            last = page.section
        if heading != listed and heading != page.section:  # a text section over pages: once, without "(2/5)"
            rows.append(("page", heading, shown))
        listed = heading
        for index, section in enumerate(page.also):  # a section that starts part-way down this page
            rows.append(("section", section, shown))
            printed = page.also_headings[index] if index < len(page.also_headings) else section
            last, listed = section, first_heading.get(section, printed)
            if listed != section:
                rows.append(("page", listed, shown))
    return rows


def contents_width(columns: int) -> int:
    """Characters per line of a contents column when the contents has ``columns`` columns."""
    if columns <= 2:
        return CONTENTS_WIDTH
    three = 0.97 / 3 - 0.03  # a column's text width (page fractions) in three columns, as drawn
    return int(CONTENTS_WIDTH_THREE * (0.97 / columns - 0.03) / three)


def contents_layout(rows, width: int = CONTENTS_WIDTH) -> list[tuple[int, int, str, str, int | None, bool]]:
    """Where each line of the contents goes: (column, line, kind, text, page number or None, continues).

    ``continues``: the line continues a wrapped title (drawn with a hanging indent). Titles wrap at ``width``
    characters, a bold section title with its page number a little shorter (bold is wider and the number sits on
    its line: cold read 12, the number ran into "... (R = 9.39"); an entry's lines (and a section heading with the
    page row below it) stay in one column: the column break never cuts an entry (cold read 8, user C13: "... 1.2 m
    × 3.0" ended one column and "m, 4.5 t)" began the next).
    """
    entries = []  # the lines of each entry; a section heading without a number joins the page row below it
    for index, (kind, text, number) in enumerate(rows):
        heads = kind == "section" and index + 1 < len(rows) and rows[index + 1][0] == "page"
        if heads:
            number = None  # the page row below carries it
        narrower = 2 if kind == "page" else (BOLD_NUMBERED_NARROWER if number is not None else 0)
        wrapped = textwrap.wrap(text, width - narrower, break_on_hyphens=False) or [""]
        lines = [(kind, line, number if index == 0 else None, index > 0) for index, line in enumerate(wrapped)]
        if entries and entries[-1][1]:
            entries[-1][0].extend(lines)
            entries[-1][1] = False
        else:
            entries.append([lines, heads])
    placed, slot = [], 0
    for lines, _ in entries:
        column, line = divmod(slot, CONTENTS_LINES)
        if line + len(lines) > CONTENTS_LINES and line:
            slot = (column + 1) * CONTENTS_LINES
        placed += [(*divmod(slot + offset, CONTENTS_LINES), *entry) for offset, entry in enumerate(lines)]
        slot += len(lines)
    return placed


def contents_page(planned: list[Page], title: str, position: int = 2) -> Page:
    """The contents: every section and page title with its page number (the contents itself is page ``position``).

    Titles are wrapped, never cut; the HTML links every page and every section.
    """
    rows = contents_rows(planned, position)
    placed, columns = contents_layout(rows), 2
    while placed and placed[-1][0] + 1 > columns and columns < 4:  # more columns: narrower, smaller type, wrap earlier
        columns = placed[-1][0] + 1
        placed = contents_layout(rows, contents_width(columns))
    slot = placed[-1][0] * CONTENTS_LINES + placed[-1][1] + 1 if placed else 0

    def draw():
        figure = new_page("Contents")
        columns = max(1, -(-slot // CONTENTS_LINES))
        size = 8.5 if columns <= 2 else 7
        step = min(0.85 / min(slot, CONTENTS_LINES) if placed else 0.02, 0.024)
        width = 0.97 / columns
        for column, line, kind, text, number, continues in placed:
            x, y = 0.02 + column * width, 0.925 - line * step
            indent = (0.0 if kind == "section" else 0.012) + (0.012 if continues else 0.0)  # a hanging indent
            figure.text(x + indent, y, text, fontsize=size, weight="bold" if kind == "section" else "normal",
                        va="top")
            if number is not None:
                figure.text(x + width - 0.03, y, str(number), fontsize=size, va="top", ha="right")
        return figure

    items, last, shown = [], None, None  # the HTML: one link per section and per heading, no "(2/9)"
    for number, page in enumerate(planned, start=1):
        number += 1 if number >= position else 0
        if page.section != last:
            items.append(f"<li class='section'><a href='#{_slug(page.section)}'>{html.escape(page.section)}</a></li>")
        heading = page.heading or page.title
        if heading != shown:
            items.append(f"<li><a href='#page-{number}'>{html.escape(heading)}</a></li>")
        shown = heading
        for section in page.also:  # its link lands on its heading part-way down the page
            items.append(f"<li class='section'><a href='#{_slug(section)}'>{html.escape(section)}</a></li>")
        last = page.also[-1] if page.also else page.section
    return Page("contents", "Contents", "Contents", draw, "", "<ul class='contents'>" + "".join(items) + "</ul>")


def figure_file(number: int, page: Page) -> str:
    """The file name of a figure page's PNG in ``figures/``: its page number, then its name (``14-spectra.png``)."""
    return f"{number:02d}-{page.name}.png"


def figure_png(figure) -> bytes:
    """The figure as the report's PNG (``PNG_DPI``), as bytes."""
    buffer = io.BytesIO()
    figure.savefig(buffer, dpi=PNG_DPI, format="png")
    return buffer.getvalue()


HTML_STYLE = """body{font-family:system-ui,sans-serif;max-width:1180px;margin:2em auto;padding:0 1em;color:#222}
section{border-top:1px solid #bbb;margin-top:2em;padding-top:.5em}img{width:100%;height:auto}
table{border-collapse:collapse;font-size:.85em}td,th{padding:.15em .6em;border-bottom:1px solid #ddd;text-align:left}
.note{font-style:italic;font-size:.9em}.caption{font-style:italic;color:#444}.pageno{float:right;color:#777}
ul.contents{list-style:none;padding-left:0}ul.contents li.section{font-weight:bold;margin-top:.5em}
ul.contents li span{color:#777}nav.back{font-size:.85em;margin:.3em 0}.verdict{font-size:1.05em}"""


def html_document(title: str, rendered: list[Page]) -> str:
    """A self-contained HTML file: each page a section with an anchor, in the PDF's order.

    Each section's anchor (``section-NAME``, the contents links it) sits on its own heading: before the page
    it starts, or on its heading part-way down a page. A text section over several PDF pages has one heading,
    without the PDF's "(2/9)" or "page N of M". Every page but the contents links back to the contents. Text
    pages are HTML text, figure pages their PNG with an alternative text.
    """
    contents = next((n for n, page in enumerate(rendered, start=1) if page.name == "contents"), None)
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
             f"<style>{HTML_STYLE}</style></head><body>"]
    last, shown = None, None
    for number, page in enumerate(rendered, start=1):
        if page.section != last:  # a section starting part-way down a page: its heading carries the anchor
            parts.append(f"<div id='{_slug(page.section)}'></div>")
        last = page.also[-1] if page.also else page.section
        heading = page.heading or page.title
        parts.append(f"<section id='page-{number}'>")
        if heading != shown:  # a text section over several PDF pages: one heading, no "(2/9)", no "page N of M"
            parts.append(f"<h2>{html.escape(heading)}</h2>")
        shown = heading
        if contents is not None and number != contents:
            parts.append(f"<nav class='back'><a href='#page-{contents}'>Back to the contents</a></nav>")
        if page.html is not None:
            parts.append(page.html)
        else:
            encoded = base64.b64encode(page.png).decode("ascii")
            alt = page.title + (f". {page.caption}" if page.caption else "")
            parts.append(f"<img alt='{html.escape(alt, quote=True)}' src='data:image/png;base64,{encoded}'>")
        if page.caption:
            parts.append(f"<p class='caption'>{html.escape(page.caption)}</p>")
        parts.append("</section>")
    parts.append("</body></html>")
    return "\n".join(parts)


_PLANNED: list = []  # the pages of the report being rendered, for the forked PNG worker


def _page_png(task) -> bytes:
    """Draw page ``index`` again in a worker process and return it as PNG (with its footer)."""
    index, footer, total = task
    figure = _PLANNED[index].draw()
    try:
        add_footer(figure, footer, index + 1, total)
        return figure_png(figure)
    finally:
        plt.close(figure)


def _png_pages(planned, footer, workers):
    """The pool drawing every figure page's PNG and the PNG bytes in page order, or (None, None).

    (None, None): there is no pool, and the PNGs are saved from the PDF's figures.

    A text page (``Page.html`` set) is HTML text in report.html and a page of report.pdf: it has no PNG (its
    image was used nowhere, and drawing text pages at 100 dpi was a third of the report's drawing time).

    The pages are drawn again in one forked worker process while this process writes the PDF (both cores
    busy; about 40% less wall time). When ``workers`` is 1 or the platform cannot fork, there is no pool: each
    figure is drawn once, for its PDF page and its PNG.
    """
    if workers == 1 or "fork" not in multiprocessing.get_all_start_methods():
        return None, None
    tasks = [(index, footer, len(planned)) for index, page in enumerate(planned) if page.html is None]
    pool = multiprocessing.get_context("fork").Pool(1)
    return pool, pool.imap(_page_png, tasks)


def render(planned: list[Page], footer: str, output_dir, progress=True, workers=None) -> list[Page]:
    """Draw each page, number it, write it to the PDF and (a figure page) its PNG, close it: one at a time."""
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
                    figure, png = page.draw(), None
                    try:
                        add_footer(figure, footer, number, len(planned))
                        document.savefig(figure)
                        if page.html is None and pngs is None:  # no PNG worker: this drawing makes the PNG
                            png = figure_png(figure)
                    finally:
                        plt.close(figure)
                    if page.html is None and png is None:
                        png = next(pngs)
                    if png is not None:
                        with atomic_path(figure_dir / figure_file(number, page)) as path:
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
    pngs = [output_dir / "figures" / figure_file(n, p) for n, p in enumerate(rendered, start=1)
            if p.png is not None]
    return output_dir / "report.pdf", pngs


FRONT = ("Title", "Summary")
"""The sections before the contents: the title page and the one-page summary."""


def build_plan(results: Results) -> list[Page]:
    """The numbered page list: the title, the summary, then the contents and the rest."""
    planned = plan(results)
    position = 1 + next((i for i, page in enumerate(planned) if page.section not in FRONT), len(planned))
    return [*planned[:position - 1], contents_page(planned, results.title, position), *planned[position - 1:]]


def _open_optional(path):
    path = Path(path)
    if not path.is_file():
        return None
    with xr.open_dataset(path) as dataset:
        return dataset.load()


def report_stage(config: StudyConfig, cube: xr.Dataset, ida: xr.Dataset, fragility: xr.Dataset,
                 risk: xr.Dataset | None, output: str | os.PathLike, runtime_s: float = float("nan"),
                 applicability: xr.Dataset | None = None, progress: bool = True,
                 workers: int | None = None, run: dict | None = None) -> tuple[Path, list[Path]]:
    """Read what the report needs beyond the given datasets from ``output`` and write the report.

    The report reads ``showcase.nc`` for the records, never the records themselves, and runs no solver.

    Parameters
    ----------
    config : StudyConfig
        The study (its ``[report]`` table gives the title, project and author).
    cube, ida, fragility : xarray.Dataset
        The opened ``cube.nc``, ``ida.nc`` and ``fragility.nc`` of the study.
    risk : xarray.Dataset or None
        The risk variables (``rockfrag.risk.risk_dataset``), merged into ``fragility`` when they are a
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
    run : dict, optional
        The study's statistics (``rockfrag.study.run_study``: ``runs_computed``, ``cells_reused``, ``cells``):
        the title page says how many runs this run computed and how many cells came from checkpoints.

    Returns
    -------
    pdf : pathlib.Path
        ``output/report.pdf`` (``report.html`` beside it).
    pngs : list of pathlib.Path
        ``output/figures/NN-name.png``, one per figure page (NN its page number), in page order.
    """
    results = report_results(config, cube, ida, fragility, risk, output, runtime_s, applicability, run)
    return write_report(build_plan(results), output, results.title, report_footer(results), progress, workers)


def report_results(config: StudyConfig, cube: xr.Dataset, ida: xr.Dataset, fragility: xr.Dataset,
                   risk: xr.Dataset | None, output: str | os.PathLike, runtime_s: float = float("nan"),
                   applicability: xr.Dataset | None = None, run: dict | None = None) -> Results:
    """What the report is drawn from: the given datasets and what ``report_stage`` reads from ``output``.

    The arguments are those of ``report_stage`` (which see); nothing is drawn or written, no solver runs.

    Returns
    -------
    Results
        The study's datasets (risk merged into ``fragility``), ``showcase.nc``, ``efficiency.nc``,
        ``applicability.nc`` (unless given) and the vertical component's effect when ``cube_without_vertical.nc``
        is there.
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
    return Results(config, cube, ida, fragility, output, showcase=_open_optional(output / "showcase.nc"),
                   applicability=applicability, efficiency=efficiency, runtime_s=runtime_s, vertical=vertical,
                   run=None if run is None else {key: run[key] for key in ("runs_computed", "cells_reused", "cells")
                                                 if key in run})


def report_footer(results: Results) -> str:
    """The left footer of every page: project and report title, joined by a middle dot.

    Not the study's file name ("study 'user-site'"): a tool's word on every client page (cold read 3, C4/C6);
    the appendix 'How to reproduce this report' names the study file.
    """
    parts = (results.settings.get("project"), results.title)
    return " · ".join(str(part) for part in parts if part)


__all__ = ["Page", "Results", "build_plan", "figure_file", "figure_png", "plan", "report_footer", "report_results",
           "report_stage", "write_report"]
