"""rockfrag.report.answer_page - the answer page of each block, right after the title page.

Input : a ``Results`` bundle (its ``answers``: rockfrag.answer.block_answers at the study's return periods,
        with the verdict limits of ``[decision]``) and the block.
Output: the page's items (``answer_items``): the verdict in one sentence (saying when the hazard is the
        shipped example), which curve answers and why, the site's intensity at each return period and the
        largest recorded one, P(each damage state) there with its band, and per soil the probability of
        each state in the design life, its mean return period, and the verdict.

Where no record reached a state below the largest recorded intensity, the page says "not reached below X
in any record" and bounds its probability in the design life by that of exceeding X, never a fitted
median far beyond what any record did.
"""

from __future__ import annotations

import numpy as np

from rockfrag.answer import (
    ANCHOR,
    RECOMMENDED,
    BlockAnswer,
    display_scale,
    level_at_or_below,
    percent,
    verdict_sentence,
)
from rockfrag.fragility import first_overturn_outcomes  # the fits' counting rule (resurrection), in one place
from rockfrag.models.base import Outcome
from rockfrag.models.variants import split_variant
from rockfrag.report.adapters import (
    block_description,
    block_name,
    measure_label,
    model_info,
    planar_words,
    sliding_at,
    sliding_candidates,
    state_labels,
)
from rockfrag.report.text import Item, note, paragraph, strong, table
from rockfrag.report.words import state_short_label


def _number(value: float) -> str:
    return f"{value:.2g}" if np.isfinite(value) else "-"


def _years(frequency: float) -> str:
    """A mean annual frequency as its mean return period, rounded to two figures: "1 in 2,300 years"."""
    if not np.isfinite(frequency) or frequency <= 0:
        return ""
    years = float(f"{1.0 / frequency:.2g}")
    return f"once in {years:,.0f} years"


def _band_reach(cube, block=None) -> str:
    """A sentence on the cells where the bed could not reach the band's restitution (empty when it did).

    Of one block when ``block`` is given (its answer page), else of the whole study.
    """
    if cube is None or "restitution_requested" not in cube or "restitution_target" not in cube:
        return ""
    requested, target = cube.restitution_requested, cube.restitution_target
    if block is not None and "block" in requested.dims:
        requested, target = requested.sel(block=block), target.sel(block=block)
    short = (requested - target) > 5e-4  # the bed ran at a lower r than the band asked for
    if not bool(short.any()):
        return ""
    soils = [str(s) for s in cube.soil.values if bool(short.sel(soil=s).any())]
    asked, reached = float(requested.where(short).max()), float(target.where(short).max())
    return (f" On {', '.join(soils)} the bed cannot dissipate as little as the band's upper edge asks (r up to "
            f"{asked:.3f}; it reaches {reached:.3f} at most): those variants run at the nearest r it reaches, so "
            "β of the model there leaves out the less dissipative side of the band, the side on which a block "
            "rocks more.")


def _band_collapse(cube, block) -> str:
    """A sentence on the soils where the band's three runs of ``block`` are one run (empty where none are).

    The variants run the bed's damping ratio xi calibrated to their restitution; where the bed reaches none of the
    band's targets, all three run at the same xi: β of the model is 0 there because there is one run, not because
    the model is certain.
    """
    if cube is None or "damping_ratio_calibrated" not in cube:
        return ""
    band = [str(m) for m in cube.model.values if split_variant(str(m))[1] is not None]
    if len(band) < 2:
        return ""
    xi = cube.damping_ratio_calibrated.sel(block=block, model=band)
    collapsed = [str(s) for s in cube.soil.values
                 if np.isfinite(values := np.asarray(xi.sel(soil=s).values, float)).all()
                 and np.ptp(values) <= 1e-9 * max(abs(values).max(), 1.0)]
    if not collapsed:
        return ""
    values = sorted({f"{float(xi.sel(soil=s).isel(model=0)):.3g}" for s in collapsed})
    asked = ""
    if "restitution_requested" in cube:
        requested = cube.restitution_requested.sel(block=block, model=band, soil=collapsed)
        asked = f"r {float(requested.min()):.3f} to {float(requested.max()):.3f} asked"
        if "restitution_target" in cube:
            reached = cube.restitution_target.sel(block=block, model=band, soil=collapsed)
            asked += f"; it reaches {float(reached.max()):.3f} at most" if bool(reached.notnull().any()) \
                else "; it reaches none of them"
        asked = f" ({asked})"
    where = "every soil" if len(collapsed) == cube.soil.size else ", ".join(collapsed)
    return (f" On {where} the band collapses to one run for this block: the bed cannot tell the band's "
            f"restitutions apart{asked}, so its three runs use the same damping ratio ξ = {' / '.join(values)}; β "
            "of the model there is 0 because there is one run, not because the model is certain.")


def curve_reason(results, model: str, block=None) -> str:
    """Which curve answers and why, in words: β ranges and the band's reach of ``block`` (every block: None)."""
    fragility = results.fragility
    if model == RECOMMENDED:
        text = ("The answer uses the recommended curve: the tensionless Winkler bed run over the experimental range "
                "of impact restitution (the edges and the centre of the band), its spread added to the "
                "record-to-record dispersion (FEMA P-58).")
        if "beta_model" in fragility and "beta_record_to_record" in fragility:
            rows = fragility.sel(model=RECOMMENDED) if block is None else fragility.sel(model=RECOMMENDED,
                                                                                         block=block)
            r2r, model_beta = rows.beta_record_to_record.values, rows.beta_model.values
            if np.isfinite(r2r).any() and np.isfinite(model_beta).any():
                text += (f" Here β from record to record is {np.nanmin(r2r):.2f} to {np.nanmax(r2r):.2f} and β of the "
                         f"model {np.nanmin(model_beta):.2f} to {np.nanmax(model_beta):.2f}.")
        text += _band_reach(getattr(results, "cube", None), block)
        if block is not None:
            text += _band_collapse(getattr(results, "cube", None), block)
        models = {str(m) for m in fragility.model.values}
        if "housner" in models and any(m.startswith("ssi") for m in models):
            text += (" Housner's rigid base and the paper's model are references, not inputs: the first ignores "
                     "the foundation and the second's spring pulls on the block, which a soil cannot.")
        elif "housner" in models:
            text += " Housner's rigid base is a reference, not an input: it ignores the foundation."
        return text
    if model == "winkler":
        return ("The answer uses the tensionless Winkler bed: of the models this study ran, it is the one that "
                "stays within its own assumptions (its foundation never pulls on the block; see Limitations). "
                "Housner's rigid base and the paper's model are shown as references. The recommended curve, which "
                "adds the uncertainty of the impact dissipation, was not in the results.")
    return (f"The answer uses the {model_info(model).label}: the study did not run the tensionless Winkler bed, "
            "so read it with the Limitations page, which says where this model is outside its assumptions.")


MODE_WORDS = {"time_at_rest": "at rest", "time_sliding": "slides", "time_rocking": "rocks",
              "time_slide_rocking": "slides and rocks", "time_in_flight": "flies", "overturns": "overturns"}
"""The contact modes of a run (the time fields rockfrag.models.fields.MODE_TIME_FIELDS) and overturning in words."""


MODE_SEVERITY = ("time_at_rest", "time_sliding", "time_rocking", "time_slide_rocking", "time_in_flight", "overturns")
"""The motions from the mildest to the most severe (a record's motion is the most severe it enters); the last is
overturning, read from the outcome as the fits read it (from a record's first overturning level on)."""

NO_LEVEL = "no level run this low"
"""A return-period intensity below every level run: the page says so (the P table's head does too), no motion."""


def _motions(runs, overturned) -> np.ndarray | None:
    """Each record's most severe motion (an index of ``MODE_SEVERITY``), -1 for a failed run.

    From the mode times where the base slides; from the outcome where it is tied (no mode times). ``overturned``:
    the record has overturned at this level or a lower one (``rockfrag.fragility.first_overturn_outcomes``).
    """
    outcome = np.asarray(runs.outcome.values)
    times = {field: np.asarray(runs[field].values, float) for field in MODE_SEVERITY[:-1] if field in runs}
    if len(times) == len(MODE_SEVERITY) - 1 and all(np.isfinite(v).any() for v in times.values()):
        entered = np.stack([np.nan_to_num(times[field]) > 0.0 for field in MODE_SEVERITY[:-1]])  # (mode, record)
        worst = np.max(np.where(entered, np.arange(len(MODE_SEVERITY) - 1)[:, None], 0), axis=0)
    else:
        worst = np.select([outcome == int(Outcome.ROCKING), outcome == int(Outcome.FREE_FLIGHT)],
                          [MODE_SEVERITY.index("time_rocking"), MODE_SEVERITY.index("time_in_flight")], 0)
    worst = np.where(overturned, len(MODE_SEVERITY) - 1, worst)
    return np.where(outcome == int(Outcome.FAILED), -1, worst)


def governing_modes(cube, block: str, model: str, soil: str, intensities, scale: float) -> list[str]:
    """What the block does at each intensity: the most severe motion that at least half the records reach.

    One definition, level and counting rule with the probability table (``rockfrag.answer``): each record's
    motion is the most severe it enters (a block that rocks for 2 s of a 40 s record rocks), ``MODE_SEVERITY``,
    overturning counted from the record's first overturning level on (as the fits count it: resurrection); the
    share is that of the records reaching the motion or a more severe one, so "at rest" is always 100%. Read at
    the level run nearest at or below each intensity (in the answer's unit, ``scale`` times the cube's), as the
    probability table reads its records; ``NO_LEVEL`` where no level lies that low. From the runs of ``model``
    (the recommended curve's: the band centre).
    """
    if cube is None or "intensity" not in cube:
        return ["-"] * len(intensities)
    centres = [str(m) for m in cube.model.values if split_variant(str(m))[1] == "centre"]  # the band's centre
    name = (centres[0] if centres else None) if model == RECOMMENDED else model
    if name is None or name not in cube.model.values:
        return ["-"] * len(intensities)
    levels = np.asarray(cube.intensity.sel(block=block).values, float) * scale
    cell = cube.sel(block=block, soil=soil, model=name)
    overturned = first_overturn_outcomes(cell).transpose("record", "im_level").values == int(Outcome.OVERTURNED)
    out = []
    for im in intensities:
        level = level_at_or_below(levels, im)
        if level is None:
            out.append(NO_LEVEL)
            continue
        worst = _motions(cell.isel(im_level=level), overturned[:, level])
        worst = worst[worst >= 0]
        if not worst.size:
            out.append("-")
            continue
        reach = [float(np.mean(worst >= m)) for m in range(len(MODE_SEVERITY))]
        mode = max(m for m in range(len(MODE_SEVERITY)) if reach[m] >= 0.5)
        text = f"{MODE_WORDS[MODE_SEVERITY[mode]]} ({percent(reach[mode])} of the records"
        out.append(text + (f"; overturns: {percent(reach[-1])})" if 0 < reach[-1] and mode < len(reach) - 1
                           else ")"))
    return out


def answer_items(results, answer: BlockAnswer) -> list[Item]:
    """The items of one block's answer page.

    Parameters
    ----------
    results : Results
        The study's results (rockfrag.report.sections.Results).
    answer : BlockAnswer
        The block's answer (``results.answers``).

    Returns
    -------
    list of Item
    """
    fragility = results.fragility
    name = block_name(results.config, answer.block)
    labels = state_labels(fragility)
    descriptions = {s: str(d) for s, d in zip(map(str, fragility.damage_state.values),
                                               fragility["damage_state_description"].values)} \
        if "damage_state_description" in fragility.coords else {}
    short = {s: state_short_label(s, descriptions.get(s, "")) for s in labels}
    words = {s: text[0].lower() + text[1:] for s, text in labels.items()}
    measure = measure_label(fragility).split(" [")[0]
    unit = answer.unit
    items = []
    description = block_description(results.config, answer.block)
    if description:
        items.append(paragraph(f"{name[0].upper() + name[1:]}: {description}."))
    items.append(strong(verdict_sentence(answer, name, words)))
    items.append(paragraph(curve_reason(results, answer.model, answer.block)))
    items.append(paragraph(planar_words(results.cube, answer.block)))
    sufficiency = sufficiency_words(results.efficiency, answer.block, results.cube.attrs.get("intensity_measure", ""),
                                    measure_label(results.cube).split(" [")[0])
    if sufficiency:
        items.append(paragraph(sufficiency))
    items.append(paragraph(results.friction_words))
    largest = results.largest_recorded.get(answer.block)
    hazard = results.hazard
    if answer.return_periods:
        at = ", ".join(f"{im:.2g} {unit} at {t:,.0f} years" for t, im in zip(answer.return_periods,
                                                                              answer.intensities))
        source = ("the shipped example curve, not site-specific" if answer.example_hazard else
                  f"from {hazard.source}") if hazard is not None else ""
        items.append(paragraph(f"Site hazard ({source}): {measure} {at}. The largest {measure} of the records, "
                               f"unscaled, is {largest:.2g} {unit}; above it every result comes from records scaled "
                               "up beyond what they recorded (extrapolation by scaling)."))
        for soil in answer.soils:  # one table per soil, the states down the side: as wide for 3 soils as for 1
            header = [f"on {soil.soil}: P(damage state)"] + [_period_header(answer, soil, index, measure)
                                                            for index in range(len(answer.return_periods))]
            rows = [[short[state.state], *(_at_cell(state, index, answer)
                                           for index in range(len(answer.return_periods)))]
                    for state in soil.states]
            items.append(table(header, rows))
        items.append(note(f"P(damage state) at each return period's intensity, in brackets its band: the "
                          f"{_confidence(fragility)} confidence bounds of the median, records resampled. Then how "
                          "many records reached the state at the level run nearest at or below that intensity "
                          "(in the column's head); 'fit only': no record reached it at or below that level, so the "
                          f"value is the fitted curve's tail alone. 'not reached': no record reached the state up "
                          f"to {largest:.2g} {unit}."))
        cube = getattr(results, "cube", None)
        scale = display_scale(cube.intensity.attrs.get("units", ""))[0] if cube is not None and "intensity" in cube \
            else 1.0
        modes = [[soil.soil, *governing_modes(cube, answer.block, answer.model, soil.soil, answer.intensities, scale)]
                 for soil in answer.soils]
        if any(cell != "-" for row in modes for cell in row[1:]):
            items.append(paragraph("What the block does at each return period's intensity, at the level run "
                                   "nearest at or below it (the level whose records the table above counts): the "
                                   "most severe motion that at least half the records reach (at rest, slides, "
                                   "rocks, slides and rocks, flies, overturns), with the share of records that "
                                   "reach it or a more severe one. A record that overturned at a lower level "
                                   "counts as overturned, as in the table above. The probabilities above read "
                                   "each state as 'this state or worse', so a milder state is never less likely "
                                   "than a more severe one:"))
            items.append(table(["soil", *(f"{t:,.0f} years" for t in answer.return_periods)], modes))
        sliding = sliding_rows(cube, answer, scale)
        if sliding:
            items.append(paragraph("Share of the records whose tied base needs more base friction than the soil's "
                                   f"μ_s ({results.friction_text}), at the level run at or below each return "
                                   "period's intensity (the verdict reads the "
                                   f"{answer.return_periods[-1]:,.0f}-year one):"))
            items.append(table(["soil", *(f"{t:,.0f} years" for t in answer.return_periods)], sliding))
        limits = {s: s_limit for s, s_limit in results.decision["max_probability_in_life"].items() if s in labels}
        life = f"{answer.design_life:g} years"
        header = ["damage state", f"limit in {life}", *(f"on {soil.soil}" for soil in answer.soils)]
        rows = []
        for index, state in enumerate(labels):
            cells = [short[state], percent(limits[state]) if state in limits else "none"]
            for soil in answer.soils:
                row = soil.states[index]
                if row.below_lowest is not None:
                    cells.append(_below_lowest(row, unit))
                elif row.not_reached_below is not None:
                    cells.append(f"<{percent(row.probability_in_life)}, not reached below "
                                 f"{row.not_reached_below:.2g} {unit}")
                elif np.isfinite(row.probability_in_life):
                    cells.append(f"{percent(row.probability_in_life)}, {_years(row.annual_frequency)}"
                                 + (" (fit's tail)" if row.tail_only else ""))
                else:
                    cells.append(_no_curve(fragility, answer, soil.soil, row.state, unit))
            rows.append(cells)
        rows.append(["verdict", "", *(soil.verdict for soil in answer.soils)])
        items.append(paragraph(f"Probability of each damage state in the design life of {life} (and how often it "
                               "happens on average), per soil:"))
        items.append(table(header, rows))
        if any(soil.verdict.startswith(ANCHOR) for soil in answer.soils):
            items.append(paragraph(ANCHOR_DESIGN))
        judged = ", ".join(f"{short[s]} {percent(v)}" for s, v in limits.items())
        items.append(note(f"Verdict: 'anchor' where a probability in {life} exceeds the study's limit "
                          f"({judged or 'none set'}; an anchorage holds the block against sliding too); else 'check "
                          f"sliding' where more than {percent(answer.max_sliding_share)} ([decision] "
                          f"max_sliding_share = {answer.max_sliding_share:g}, the study's choice) of the records at "
                          "the level run at or below the "
                          f"{answer.return_periods[-1]:,.0f}-year intensity need a base friction above the soil's "
                          f"μ_s ({results.friction_text}) on a tied base, where sliding was not computed (compute "
                          'it with [solver] friction = "all"); where the base runs with friction, its slip damage '
                          "states give the verdict; else 'no action'. States "
                          "without a limit are reported, not judged. 'not reached below X': no record reached the "
                          "state at any level up to X, so its probability is at most that of exceeding X. 'fit's "
                          "tail': above the limit only through intensities below every record that reached the "
                          "state (the verdict says so). '\u2265' with the records at the lowest level run: the fitted "
                          "median lies below every level run, so instead of the fit's extrapolated tail the page "
                          "gives the records' fraction at the level (in life: times the probability of exceeding "
                          "the lowest level), a lower bound."))
    else:
        items.append(paragraph(f"The study has no hazard curve for {measure}: no return-period intensities and no "
                               "probability in the design life. The fragility curves are on the pages that follow."))
    return items


def sliding_rows(cube, answer: BlockAnswer, scale: float) -> list[list[str]]:
    """Per soil, the share of records whose tied base needs more friction than μ_s at each return period's level.

    ``rockfrag.report.adapters.sliding_at`` at the level run at or below each intensity (``scale``: the answer's
    unit per the cube's); "sliding computed" where the cell runs with friction (its slip states answer). Empty
    when the cube has no friction demand.
    """
    if cube is None or "peak_friction_demand" not in cube or not answer.intensities:
        return []
    candidates = sliding_candidates(cube, answer.model)
    rows = []
    for soil in answer.soils:
        cells = []
        for im in answer.intensities:
            share, level, computed = sliding_at(cube, candidates, answer.block, soil.soil, im / scale)
            if computed:
                cells.append("sliding computed: see the slip states")
            elif not np.isfinite(level):
                cells.append(NO_LEVEL)
            else:
                cells.append(f"{percent(share)} (records at {level * scale:.2g}\u00a0{answer.unit})")
        rows.append([soil.soil, *cells])
    return rows


def _period_header(answer: BlockAnswer, soil, index: int, measure: str) -> str:
    """A return period's column head: its intensity, and the level run whose records the cells count."""
    head = f"{answer.return_periods[index]:,.0f} years, {measure} {answer.intensities[index]:.2g} {answer.unit}"
    levels = [state.records[index][2] for state in soil.states if state.records]
    level = next((value for value in levels if np.isfinite(value)), np.nan)
    if np.isfinite(level):
        return f"{head} (records at {level:.2g}\u00a0{answer.unit})"
    return f"{head} ({NO_LEVEL})" if levels else head


def _at_least(p: float) -> str:
    """A lower bound as printed: "\u226561%"; every record (p = 1) is a certainty, "100%", not "\u2265100%"."""
    text = percent(p)
    return text if p >= 1 or text.startswith(">") else f"\u2265{text}"


def _at_cell(state, index: int, answer: BlockAnswer) -> str:
    """P(state) at a return period's intensity with its band, and what the records did there.

    "24% (9.3%-40%); 2 of 10 records", or where no record reached the state at or below the intensity
    "2.2% (0.6%-6.1%); fit only, 0 of 10 records": the value is the fitted curve's tail alone.
    """
    p, low, high = state.at_return_periods[index]
    im = answer.intensities[index]
    if state.not_reached_below is not None and im <= state.not_reached_below:
        return "not reached"
    if state.below_lowest is not None:  # the fit's median is below every level: the records' fraction bounds P
        if not np.isfinite(p) or not state.records:
            return NO_LEVEL if not np.isfinite(p) else _at_least(p)
        reached, total, _ = state.records[index]
        return f"{_at_least(p)}; {reached} of {total} records"
    if not np.isfinite(p):
        return "-"
    text = percent(p)
    if np.isfinite(low) and np.isfinite(high) and high - low > 0.005:
        text += f" ({percent(low)}-{percent(high)})"
    if not state.records:
        return text
    reached, total, _ = state.records[index]
    if state.fit_only(index):
        return text + (f"; fit only, {max(reached, 0)} of {total} records" if reached >= 0 else "; fit only")
    return text + f"; {reached} of {total} records"


def _below_lowest(row, unit: str) -> str:
    """The design-life cell of a state whose fitted median lies below the lowest level run: a lower bound.

    "≥98%, every record at the lowest level run (0.1 g)": the fitted curve below that level is an extrapolation,
    so the page gives the records' fraction there times P(intensity above it), mirroring "not reached below X".
    """
    level, reached, total = row.below_lowest
    who = "every record" if reached == total else f"{reached} of {total} records"
    return f"{_at_least(row.probability_in_life)}, {who} at the lowest level run ({level:.2g} {unit})"


def _confidence(fragility) -> str:
    text = str(fragility["median_low"].attrs.get("long_name", "")) if "median_low" in fragility else ""
    return text.split(" two-sided")[0] if "two-sided" in text else "bootstrap"


def _no_curve(fragility, answer: BlockAnswer, soil, state, unit) -> str:
    """The cell of a state without a curve: reached by most records at the lowest level, or not at all."""
    status = str(fragility.status.sel(model=answer.model, block=answer.block, soil=soil, damage_state=state).values) \
        if "status" in fragility else ""
    if status == "below-range" and "studied_im_min" in fragility:
        scale, _ = display_scale(fragility.studied_im_min.attrs.get("units", ""))
        lowest = float(fragility.studied_im_min.sel(block=answer.block)) * scale
        return f"most records already at {lowest:.2g} {unit}"
    if status == "deterministic-threshold":
        return "at the uplift threshold"
    return "-"


ANCHOR_DESIGN = ("'Anchor' says that the block must not stand free; it does not size the anchorage. Design it as a "
                 "nonstructural component fixed to its support (ASCE 7-22 Chapter 13: the horizontal design force "
                 "F_p from the site's design spectral acceleration S_DS, with the overturning moment and uplift it "
                 "causes on the anchors; or the equipment's own seismic qualification standard, e.g. IEEE 693 for "
                 "substation equipment). Once anchored the block no longer rocks, so this report's curves no "
                 "longer apply to it.")
"""What an 'anchor' verdict asks for and where its design comes from (the report computes no anchor force)."""

SUFFICIENCY_PARAMETERS = {"p_pulse_period": "the records' pulse period", "p_magnitude": "the earthquake's magnitude",
                          "p_distance": "the distance to the fault"}
"""The efficiency stage's sufficiency tests (efficiency.nc, Luco & Cornell 2007) and the words for each."""

SUFFICIENCY_LEVEL = 0.05
"""Below this p-value the overturning capacity in the study's measure still depends on the parameter."""


def sufficiency_words(efficiency, block: str, study_measure: str, measure: str) -> str:
    """One sentence when the study's measure is not sufficient for this block's overturning ("" when it is).

    Reads the smallest p-value over the block's soils and models of each parameter of ``SUFFICIENCY_PARAMETERS``
    for the study's measure (``study_measure``, its name in efficiency.nc; ``measure``, its label). A parameter
    with p < 0.05 still moves the capacity at a given intensity: the curve holds for records like the study's.
    """
    if efficiency is None or study_measure not in efficiency.coords.get("measure", []) \
            or block not in efficiency.block.values:
        return ""
    failing = []
    for variable, words in SUFFICIENCY_PARAMETERS.items():
        if variable not in efficiency:
            continue
        values = efficiency[variable].sel(block=block, measure=study_measure).values
        if np.isfinite(values).any() and float(np.nanmin(values)) < SUFFICIENCY_LEVEL:
            smallest = float(np.nanmin(values))
            failing.append(f"{words} (p {'< 0.001' if smallest < 0.001 else f'= {smallest:.2g}'})")
    if not failing:
        return ""
    return (f"Sufficiency: at a given {measure} the overturning capacity still depends on {' and '.join(failing)} "
            "(the smallest p of its soils and models on the measure-efficiency page; Luco & Cornell 2007), so these "
            "curves hold for ground motions like the "
            "study's records; for a site whose motions differ in that (near a fault: velocity pulses), run the "
            "study with records like the site's (e.g. the near-field set).")
