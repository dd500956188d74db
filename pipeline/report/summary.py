"""rockfrag.report.summary - the verdicts in the client's words: the one-page summary and each answer page's verdict.

Input : a ``Results`` bundle (its ``answers``: rockfrag.answer.block_answers, and ``fragility``: the betas of
        each fitted row).
Output: ``summary_items`` (the page after the title: one row per asset and soil with the action, the governing
        damage state, its probability at each return period and in the design life, one sentence of reason and
        the confidence), and the pieces the answer pages print for the same facts (``p_at_return_period``,
        ``p_in_life``, ``verdict_items``), so that a fact reads the same on every page (``Results.facts``).

Nothing here decides a verdict: rockfrag.answer does. This module only says it, reading the answer objects.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from rockfrag.answer import ANCHOR, CHECK_SLIDING, NO_ACTION, NO_VERDICT, display_scale
from rockfrag.report import numbers
from rockfrag.report.adapters import block_name, is_soil, short_block_name, state_labels
from rockfrag.report.text import Item, bullet, note, paragraph, strong, table
from rockfrag.report.words import listed

ACTION_WORDS = {ANCHOR: "anchor or restrain", CHECK_SLIDING: "specialist check",
                NO_ACTION: "no action", NO_VERDICT: "no verdict"}
"""The verdicts of rockfrag.answer as the client reads them (a verdict not listed prints as it is named)."""

BETA_PARTS = ("beta_record_to_record", "beta_model")
"""The two parts of a fitted row's total dispersion β, in the order the report prints them (records / model):
β = √(records² + model²), the model part the larger of the parameters' spread and the model form's rating."""

EXAMPLE_WARNING = ("The hazard of this report is the example hazard curve that comes with the tool, not a site's: "
                   "no verdict in this report applies to a real site. The probabilities show how the method reads a "
                   "hazard; a site's own hazard curve gives the verdicts. The other pages say this once more only as "
                   "'the example hazard (not a site's: see the summary)'.")
"""The summary's first line when the hazard is the shipped example: the report's one full statement of it."""

EXAMPLE_HAZARD_WORDS = "the example hazard (not a site's: see the summary)"
"""How every other page names the shipped example hazard: a reference to ``EXAMPLE_WARNING``, not a repeat."""


ILLUSTRATIVE = re.compile(r"illustrative|not the result of a hazard model|not site-specific|placeholder", re.I)
"""Words of a hazard file's own header that say it is not a site's hazard study (its first comment lines)."""


def _file_header(results) -> str:
    """The first comment lines of the study's hazard file ("" when it cannot be read)."""
    source = getattr(getattr(results, "hazard", None), "source", "") or ""
    config = getattr(results, "config", None)
    study = Path(str(getattr(config, "source", "") or ""))
    for path in (Path(source), study.parent / source):
        try:
            if path.is_file():
                with open(path, encoding="utf-8", errors="replace") as handle:
                    lines = [next(handle, "") for _ in range(5)]
                return " ".join(line for line in lines if line.lstrip().startswith("#"))
        except OSError:
            continue
    return ""


def illustrative_hazard(results) -> bool:
    """Whether the study's own hazard file says in its header that it is illustrative, not a site's hazard study."""
    answers = getattr(results, "answers", None) or []
    if not answers or any(answer.example_hazard for answer in answers):
        return False
    return bool(ILLUSTRATIVE.search(_file_header(results)))


ILLUSTRATIVE_WARNING = ("The hazard curve of this study is illustrative: its own file says it is not the result of a "
                        "hazard model. No verdict in this report applies to the site until the site's hazard study "
                        "replaces it; the probabilities show how the method reads a hazard. The other pages say this "
                        "once more only as 'the illustrative hazard (not for a verdict: see the summary)'.")
"""The summary's first line when the study's own hazard file says it is illustrative (the user-site example)."""

ILLUSTRATIVE_WORDS = "the illustrative hazard (not for a verdict: see the summary)"
"""How every other page names an illustrative hazard file: a reference to ``ILLUSTRATIVE_WARNING``."""


def hazard_caveat(results) -> str:
    """The hazard in the few words every page after the summary uses, when it is not a site's ("" when it is)."""
    answers = getattr(results, "answers", None) or []
    if any(answer.example_hazard for answer in answers):
        return EXAMPLE_HAZARD_WORDS
    return ILLUSTRATIVE_WORDS if illustrative_hazard(results) else ""


EXAMPLE_TAG, ILLUSTRATIVE_TAG = "example hazard", "illustrative hazard"
"""Said beside every action the report prints when its hazard is not a site's: "no action (illustrative hazard)".
A cell copied out of the report keeps what the verdict rests on (cold read 3, user and default A1)."""


def hazard_tag(results) -> str:
    """The words beside each printed action: ``EXAMPLE_TAG``, ``ILLUSTRATIVE_TAG``, or "" for a site's hazard."""
    answers = getattr(results, "answers", None) or []
    if any(answer.example_hazard for answer in answers):
        return EXAMPLE_TAG
    return ILLUSTRATIVE_TAG if illustrative_hazard(results) else ""


def action(verdict: str, soil=None, hazard: str = "") -> str:
    """A verdict in the client's words ("anchor or restrain").

    With ``soil``: "(rocking only)" beside it where the study did not compute that base's sliding (``SoilAnswer.tied``).
    With ``hazard`` (``hazard_tag``): the hazard it rests on when that is not a site's ("no action (example hazard)").
    """
    words = ACTION_WORDS.get(verdict, str(verdict).replace("_", " "))
    notes = [ROCKING_ONLY] if _tied(soil) else []
    if hazard and verdict != NO_VERDICT:
        notes.append(hazard)
    return words + (f" ({'; '.join(notes)})" if notes else "")


ROCKING_ONLY = "rocking only"
"""Said beside a verdict whose base the study tied: its sliding was not computed, so it covers rocking only."""


def _tied(soil) -> bool:
    return bool(getattr(soil, "tied", False)) and getattr(soil, "verdict", None) != CHECK_SLIDING


def labels_of(results) -> dict:
    """Damage state -> its label in running text, lower case ("lift-off", "the block overturns")."""
    return {state: text[0].lower() + text[1:] for state, text in state_labels(results.fragility).items()}


def short_names(results) -> dict:
    """Damage state -> its short name for the answers' table cells and headers ("overturning", "θmax/α ≥ 0.5").

    A slip state reads "slip ≥ 0.30 m or overturning" where the study has overturning: the fits count a record
    that overturns as beyond every state, and the answers nest overturning under the slip states
    (rockfrag.answer.nested_families), so the label says what the number is.
    """
    from rockfrag.damage_states import DAMAGE_STATES, is_slip_state
    from rockfrag.report.words import state_short_label

    fragility = results.fragility
    descriptions = dict(zip(map(str, fragility.damage_state.values),
                            map(str, fragility["damage_state_description"].values))) \
        if "damage_state_description" in fragility.coords else {}
    overturns = "overturning" in descriptions or "overturning" in map(str, fragility.damage_state.values)
    names = {}
    for state in labels_of(results):
        name = state_short_label(state, descriptions.get(state, ""))
        registered = DAMAGE_STATES.get(state)
        if overturns and registered is not None and is_slip_state(registered):
            name += SLIP_OR_OVERTURNING
        names[state] = name
    return names


SLIP_OR_OVERTURNING = " or overturning"
"""Said after a slip state's name on the answers: a record that overturns counts as beyond it too."""

SLIP_NESTING = ("A slip state counts a record that overturns too (it is beyond every state), so 'slip ≥ 0.30 m or "
                "overturning' is never less likely than overturning; where a block overturns before it slides that "
                "far, the slip state is its overturning. Sliding and rocking are otherwise apart: a block can slide "
                "without lifting off, so a slip state may be more likely than uplift.")
"""How the slip states and overturning are ordered, said once on the page 'Reading the answer pages'."""

BOUND_WORDS = ("'< X': no record reached the state up to the highest intensity studied (Methods), so its "
               "probability is at most X, the site's chance of exceeding that intensity. '< 0.1%' alone is the print "
               "floor: a value below 0.1%, computed or bounded.")
"""What a "< X" cell means, on the summary and the answer pages (rockfrag.answer's not-reached limit)."""

BOUND_POLICY = ("One policy for bounds and nesting: where the records bound a probability ('< X', '≥ X') these pages "
                "print the bound, and a state is never printed less likely than a more severe one of its family; "
                "the result tables keep each curve's own fitted value and say where it is extrapolated or censored "
                "at the highest intensity studied, so a bound here and a fitted value there are one result read "
                "two ways. The verdicts use the values printed here.")
"""How the pages and the result files print the same quantity (said once, on the page 'Reading the answer pages')."""


STRUCTURAL_BASE_WORDS = ("'{names}': a steel plate at ground level under the reference site's motion, not a floor of a "
                         "structure (no floor spectrum).")
"""What a structural base of the study (steel) stands for, said once, in the summary's note (cold read 3, A2)."""


def structural_bases(results) -> list[str]:
    """The study's structural bases (steel: rockfrag.report.adapters.is_soil), in the study's order."""
    cube = getattr(results, "cube", None)
    if cube is None or "soil" not in cube.coords:
        return []
    return [str(soil) for soil in cube.soil.values if not is_soil(cube, soil)]


def structural_base_words(results) -> str:
    """``STRUCTURAL_BASE_WORDS`` for the study's structural bases ("" where it has none)."""
    bases = structural_bases(results)
    return STRUCTURAL_BASE_WORDS.format(names=listed(bases)) if bases else ""


def governing(soil) -> object | None:
    """The damage state that governs a block's verdict on one soil (a ``StateAnswer``), or None.

    An exceeded state with the largest probability over its limit; else the judged state nearest its limit among
    those with a computed probability (``GOVERNING_WORDS``): a state no record reached has only a bound ("< X"),
    which says how small it is, not how near its limit, so it governs only where every judged state is such a
    bound. None where no state is judged or none has a probability.
    """
    judged = [row for row in soil.states if row.limit and np.isfinite(row.probability_in_life)]
    if not judged:
        return None
    exceeded = [row for row in judged if row.exceeds]
    computed = [row for row in judged if row.not_reached_below is None
                and getattr(row, "above_cap_share", 0.0) <= BOUND_SHARE]
    return max(exceeded or computed or judged, key=lambda row: row.probability_in_life / row.limit)


BOUND_SHARE = 0.5
"""A state whose annual frequency is more than this share the bound for the hazard above the highest intensity
studied is ranked as a bound by ``governing`` (cold read 9: overturning governed the paper block on gravel at 4.7% of
its limit, 93% of it that bound, over a computed slip at 3.0%)."""

GOVERNING_WORDS = ("Governing: the state furthest above its limit; where none is above, the computed state nearest "
                   "its limit as a share of it, a value under the print floor at its own value. A bound (no record "
                   "reached the state, or its value is mostly the bound above the highest intensity studied) governs "
                   "only where every judged state is one.")
"""How the summary picks the state it prints (``governing``), said in its note."""


def p_in_life(row) -> str:
    """The probability of a state in the design life as every page prints it (a bound says so)."""
    if row.below_lowest is not None:
        return numbers.bound(row.probability_in_life, "≥")
    if row.not_reached_below is not None:
        return numbers.bound(row.probability_in_life, "<")
    return numbers.probability(row.probability_in_life)


def soil_intensities(answer, soil) -> tuple:
    """The site's intensity at each return period on ``soil`` (its own site hazard), else the block's."""
    return tuple(getattr(soil, "intensities", ()) or answer.intensities)


def p_at_return_period(row, index: int, intensities) -> str:
    """P(state) at return period ``index``'s intensity as every page prints it ("not reached", "≥ 61%", "-").

    ``intensities``: the soil's site intensity at each return period (``soil_intensities``).
    """
    p = row.at_return_periods[index][0]
    if row.not_reached_below is not None and intensities[index] <= row.not_reached_below:
        return "not reached"
    if row.below_lowest is not None:
        return numbers.bound(p, "≥") if np.isfinite(p) else "-"
    if p == 0 and row.records and row.records[index][0] == 0:  # no curve, no record at the level: the share
        return no_curve_cell(row.records[index][1])
    return numbers.probability(p)


def no_curve_cell(total: int) -> str:
    """The probability cell of a state without a curve that no record reached at the level: "≈ 0 (0/44)".

    Cold read 6 read '0%' as impossible, so the cell gave the count, "0 of 44"; cold read 9 read a count in a
    probability column. The cell is the records' share, 0/44, said to be about zero, not zero.
    """
    return f"≈ 0 (0/{int(total)})"


def say_p_in_life(results, answer, soil, row) -> str:
    """``p_in_life``, recorded in the ledger as this block's, soil's and state's probability in the design life."""
    return results.facts.say("P in the design life", (answer.block, soil.soil, row.state), p_in_life(row))


def no_curve_words(answer) -> str:
    """What a share of no records in a probability cell means ("≈ 0 (0/44)": ``no_curve_cell``)."""
    total = next((record[1] for soil in answer.soils for row in soil.states for record in row.records), None)
    example = f"'{no_curve_cell(total)}'" if total else "'≈ 0 (0/n)'"
    return (f"{example}: no fitted curve (its median lies above the highest intensity studied) and none of the "
            f"{total or 'n'} records reached the state at that level: small, not zero; the design-life value is "
            "estimated from the records' share at each level.")


def say_p_at(results, answer, soil, row, index: int) -> str:
    """``p_at_return_period``, recorded in the ledger."""
    return results.facts.say("P at a return period",
                             (answer.block, soil.soil, row.state, answer.return_periods[index]),
                             p_at_return_period(row, index, soil_intensities(answer, soil)))


def beta_words(results, answer, soil: str, state: str) -> str:
    """The total dispersion β of the answering row and its two parts: "0.53 (0.39 / 0.35)".

    The parts are the record-to-record β and the model's (``beta_model``), whose root sum of squares is the
    total; a row without a model part (a reference model's) prints its total alone. Cold read 8, user B3: naming
    only the larger part hid a model part nearly as large (0.39 records, 0.35 model).
    """
    fragility = results.fragility
    try:
        row = fragility.sel(model=answer.model, block=answer.block, soil=soil, damage_state=state)
    except KeyError:
        return "-"
    total = float(row["beta"]) if "beta" in row else np.nan
    if not np.isfinite(total):
        return "-"
    parts = [float(row[name]) if name in row else np.nan for name in BETA_PARTS]
    text = numbers.dispersion(total)
    if all(np.isfinite(parts)) and parts[1] > 0:
        text += " (" + " / ".join(numbers.dispersion(part) for part in parts) + ")"
    return results.facts.say("total beta", (answer.block, soil, state), text)


def weaker_direction_words(results) -> str:
    """A sentence naming each block whose depth out of plane is less than its width, "" where none.

    The planar model rocks it across its width only, and across its depth it is less stable (cold read 5: a 2 m
    deep skid judged across its 3 m width).

    "" where every block is at least as deep as it is wide (or its footprint is not stated).
    """
    said, strips = [], []
    for block in getattr(results.config, "blocks", ()) or ():
        area = getattr(block, "footprint_area", None)
        if not area or not hasattr(block, "b") or not hasattr(block, "h"):
            continue
        depth = area / (2 * block.b)
        if per_metre(depth):
            strips.append(short_block_name(results.config, block.name))
        elif depth < 2 * block.b * (1 - 1e-9):
            said.append(f"{short_block_name(results.config, block.name)} (b/h {depth / (2 * block.h):.2g} across its "
                        f"{depth:.3g} m depth)")
    text = ("Judged across the width only, not across a less stable depth: " + "; ".join(said) + ".") if said else ""
    if strips:
        # a sentence with its verb (cold read 9: "Per metre of a long wall-like block (...): solid block ..." had none)
        text += (" " if text else "") + (f"The {listed(strips)} {'is' if len(strips) == 1 else 'are'} computed per "
                                         "metre of a long wall-like block (the plane model; no less stable depth).")
    return text


PLANE_DEPTH = 1.0
"""[m] The out-of-plane depth of the plane model per metre of length (a block's footprint when none is given,
rockfrag.blocks: 2b x 1 m): a block of this depth is a strip of a long block, not an object 1 m deep (cold read 7:
the summary called the paper block's 1 m 'a less stable depth' while its description says per metre)."""


def per_metre(depth: float) -> bool:
    """Whether an out-of-plane ``depth`` [m] is the plane model's per metre of length (``PLANE_DEPTH``).

    To 1 %: a footprint stated as 8.0 m² under b = R sin α = 3.999 m is 1.0002 m deep.
    """
    return abs(depth - PLANE_DEPTH) <= 0.01 * PLANE_DEPTH


FRACTIONS_REASON = "no fit"
"""The summary's reason where the governing state has no fitted curve (its median lies above the highest level)."""


def reason(results, answer, soil) -> str:
    """One short sentence: what in the records (or the fit) the verdict on this soil rests on.

    The probability and its limit are in the row already; the sentence says where they come from: how many
    records reach the governing state at the level run at or below the largest return period's intensity (the
    level the sliding check reads too; where none do there but some at the level next above, both levels), or
    that none did up to the largest recorded intensity, or that the verdict rests on the fitted curve's tail or on
    a bound. Short enough for one line of the summary's table.
    """
    row = governing(soil)
    unit = answer.unit
    if soil.verdict == NO_VERDICT:
        return "no hazard curve for the study's measure"
    if soil.verdict == CHECK_SLIDING:
        share = results.facts.say("sliding share", (answer.block, soil.soil), numbers.probability(soil.sliding_share))
        return f"{share} of records at {numbers.intensity(soil.sliding_level, unit)} would slide"
    if row is None:
        return "no state judged against a limit"
    if row.not_reached_below is not None:
        up_to = numbers.intensity(row.not_reached_below, unit)
        return f"bound only: none reached it up to {up_to}" if row.exceeds else f"no record reached it up to {up_to}"
    if row.below_lowest is not None:
        level, reached, total = row.below_lowest
        return f"{numbers.count(reached, total)} records already at {numbers.intensity(level, unit)}: a bound"
    censored = _censored_at_cap(results, answer, soil, row)
    if censored is not None:
        # the cap is a stated input: "3 g" as everywhere else, not the computed "3.0 g"
        return f"{FRACTIONS_REASON} (median above {numbers.as_stated(round(censored, 6))} {unit})"  # the note says
    if row.tail_only:
        first = numbers.intensity(row.first_reached, unit) if row.first_reached is not None else "any level"
        return f"fitted tail only: no record below {first}"
    if row.records and row.records[-1][0] >= 0:
        reached, total, level = row.records[-1]
        results.facts.say("records reaching", (answer.block, soil.soil, row.state, answer.return_periods[-1]),
                          str(reached))
        above = row.records_above
        if above is not None and (reached, above[0]) != (0, 0):
            # the levels either side of the intensity (cold read 12: "0 of 44 at 0.52 g" for 0.60 g, where 1 of 44
            # overturned at 0.65 g; "14 of 44 at 0.37 g" for 0.45 g, 20 at 0.48 g)
            counts = f"{reached}" if reached == above[0] else f"{reached}-{above[0]}"
            return (f"{counts} of {total} at {numbers.intensity(level, unit).removesuffix(' ' + unit)}-"
                    f"{numbers.intensity(above[2], unit)}")
        if reached == 0:  # a non-zero P beside "0 of 44" says where it comes from
            return f"{numbers.count(reached, total)} at {numbers.intensity(level, unit)}: fitted tail"
        return f"{numbers.count(reached, total)} reach it at {numbers.intensity(level, unit)}"
    return "from the fitted curve"


def _censored_at_cap(results, answer, soil, row) -> float | None:
    """The credible cap (shown unit) where the governing row's median lies above it (status censored-at-cap)."""
    fragility = getattr(results, "fragility", None)
    if fragility is None or "status" not in fragility or not hasattr(results, "credible_limits"):
        return None
    try:
        status = str(fragility.status.sel(model=answer.model, block=answer.block, soil=soil.soil,
                                          damage_state=row.state).values)
    except KeyError:
        return None
    return results.credible_limits.get(answer.block) if status == "censored-at-cap" else None


def hazard_words(results, answer) -> str:
    """The hazard the probabilities come from, named: the shipped example or the site's, per soil or not."""
    if not answer.return_periods:
        return "no hazard curve"
    source = EXAMPLE_HAZARD_WORDS if answer.example_hazard else (ILLUSTRATIVE_WORDS if illustrative_hazard(results)
                                                                  else "the site's hazard")
    sites = getattr(results, "site_hazards", None)
    if sites is None or len(sites) < 2:
        return source
    if sites.reference is not None:
        return f"each soil's site hazard: {source}, carried to the soil's site class"
    return "each soil's own site hazard, as the study gives it" + (f" ({EXAMPLE_HAZARD_WORDS})"
                                                                  if answer.example_hazard else "")


def summary_items(results) -> list[Item]:
    """The summary page: a first line on the hazard, then one row per asset and soil, then how to read it."""
    answers = results.answers
    if not answers:
        return [paragraph("The study has no block, so no verdict.")]
    first = answers[0]
    items = []
    if any(answer.example_hazard for answer in answers):
        items.append(strong(EXAMPLE_WARNING))
    elif illustrative_hazard(results):
        items.append(strong(ILLUSTRATIVE_WARNING))
    periods = first.return_periods
    life = numbers.years(first.design_life)
    header = ["asset, soil", "action", "governing damage state", *(f"P at {numbers.years(t)}" for t in periods),
              f"P in {life} (limit)", "β (records / model)", "reason"]
    rows = []
    for answer in answers:
        rows.append([block_name(results.config, answer.block)] + [""] * (len(header) - 1))
        for line in verdict_rows(results, answer):
            rows.append([line["soil"], line["action"] + drained_words(results, answer.block, line["soil"]),
                         line["state"], *line["at"], line["life"], line["beta"], line["reason"]])
    items.append(paragraph(
        f"Per asset and soil: the action, the governing damage state, its probability at each return period's site "
        f"intensity and in the design life of {life} ({hazard_words(results, first)}), the β of its curve with its "
        "two parts, and what the verdict rests on."))
    items.append(table(header, rows))
    used = {line[1] for line in rows}
    legend = [("anchor or restrain", "'Anchor or restrain': a probability in the design life is above its limit; the "
                                     "block must not stand free."),
              ("specialist check", "'Specialist check': the base would slide, and its sliding was not computed."),
              ("no action", "'No action': every judged damage state is within its limit, a verdict on the "
                            "computed risk; a code's anchorage rule (IEEE 693, ASCE 7 Ch. 13) still applies."),
              (ROCKING_ONLY, "'Rocking only': the study did not compute this base's sliding, so the verdict covers "
                             "rocking and overturning only."),
              (EXAMPLE_TAG, "'(Example hazard)': not a site's verdict."),
              (ILLUSTRATIVE_TAG, "'(Illustrative hazard)': not the site's verdict.")]
    said = " ".join(words for key, words in legend if any(key in cell for cell in used))
    cells = " ".join(cell for row in rows for cell in row[3:3 + len(periods) + 1])
    bounds = " ".join(words for words, shown in ((BOUND_WORDS, "< "), (no_curve_words(first), "≈ 0 ("))
                      if shown in cells)
    if any(row[-1].startswith(FRACTIONS_REASON) for row in rows):
        bounds += (" 'No fit' (reason): the same, with the design-life value from the records' share at each level."
                   if "≈ 0 (" in cells else " 'No fit' (reason): the state's median lies above the highest intensity "
                   "studied, so no curve is fitted; its probabilities come from the records' share at each level.")
    items.append(note(" ".join(filter(None, [
        said, GOVERNING_WORDS, bounds, scaled_medians_words(results), structural_base_words(results),
        weaker_direction_words(results), representative_soils_words(results),
        DRAINED_NOTE if any(row[1].endswith(DRAINED_WORDS) for row in rows) else "",
        "Reason: the records that reach the state at the levels run either side of the largest return period's "
        "intensity; where none reach it at the level below, its probabilities are the fitted curve's tail. β "
        "(records / model): the total, √(records² + model²), of the record-to-record and the model's own "
        "variability."
    ]))))
    return items


DRAINED_WORDS = " ◊"
"""Beside a clay verdict that holds for a drained base only (``drained_words``); the summary's note says what."""
DRAINED_NOTE = "◊ for a drained base: undrained, the clay's adhesion holds the block less (answer page)."


def drained_words(results, block: str, soil: str) -> str:
    """``DRAINED_WORDS`` where the block's μ_s p on this clay exceeds any clay's undrained adhesion, else "".

    Cold read 12 (default text, round 3): the paper block's clay verdict holds for a drained base only (undrained,
    its adhesion is an equivalent friction of 0.03-0.15 under 400 kPa, against μ_s 0.35); its answer page said so,
    its summary row did not. The answer page's ``bearing_words`` gives the numbers.
    """
    from rockfrag.soils import CLAY_ADHESION, bearing_case

    config = getattr(results, "config", None)
    found = next((b for b in getattr(config, "blocks", ()) or () if b.name == block), None)
    clay = next((s for s in getattr(config, "soils", ()) or () if s.name == soil), None)
    if found is None or clay is None:
        return ""
    case = bearing_case(clay, found)
    return DRAINED_WORDS if case.kind == "clay" and clay.friction_static * case.pressure > \
        CLAY_ADHESION["stiff clay"][1] else ""


def representative_soils_words(results) -> str:
    """The summary's sentence on soils that are the shipped classes, not the site's measurements ("" when none).

    Cold read 12, user B4: the verdicts are on "the site's clay and sand", whose moduli are the paper's
    representative values and whose friction is a class's; only the methods said so, not the page that is signed.
    """
    from rockfrag.soils import SOILS

    config = getattr(results, "config", None)
    names = [soil.name for soil in getattr(config, "soils", ()) or ()
             if SOILS.get(soil.name) == soil and is_soil(results.cube, soil.name)]
    if not names:
        return ""
    return (f"{listed(names).capitalize()}: representative class{'' if len(names) == 1 else 'es'} of ground, not "
            "site measurements (Methods).")


def scaled_medians_words(results) -> str:
    """How many governing curves have their median above the largest recorded intensity, "" where none.

    Cold read 8, user B6: both 'no action' verdicts of the user study rest on medians (1.56 g, 2.00 g) from records
    scaled up to 15.9 times beyond the largest unscaled 0.78 g, which only the fitted table's dagger said.
    """
    fragility = results.fragility
    scale = display_scale(fragility["median"].attrs.get("units", ""))[0]
    scaled, total, largest = 0, 0, []
    for answer in results.answers:
        recorded = results.largest_recorded.get(str(answer.block), np.inf)
        for soil in answer.soils:
            row = governing(soil)
            if row is None or row.not_reached_below is not None:
                continue
            median = float(fragility["median"].sel(model=answer.model, block=answer.block, soil=soil.soil,
                                                   damage_state=row.state)) * scale
            if not np.isfinite(median):
                continue
            total += 1
            if median > recorded:
                scaled += 1
                largest.append(recorded)
    if not scaled:
        return ""
    every = "All" if scaled == total else f"{scaled} of {total}"
    unit = results.answers[0].unit
    return (f"{every} governing medians exceed the largest recorded intensity, "
            f"{numbers.intensity(max(largest), unit)} (extrapolation by scaling, † in the fitted table).")


def verdict_rows(results, answer) -> list[dict]:
    """The summary's facts of one block, a dict per soil: the words every page and the terminal print.

    Keys: ``soil``, ``action``, ``state`` (the governing damage state's short name), ``at`` (its P at each return
    period), ``life`` (its P in the design life with the limit), ``beta`` and ``reason``.
    """
    short = short_names(results)
    periods = answer.return_periods
    tag = hazard_tag(results)
    lines = []
    for soil in answer.soils:
        row = governing(soil)
        if soil.verdict == CHECK_SLIDING:
            state, at, life_text, beta = "sliding", ["-"] * len(periods), "-", "-"
        elif row is None:
            state, at, life_text, beta = "-", ["-"] * len(periods), "-", "-"
        else:
            state = short[row.state]
            at = [say_p_at(results, answer, soil, row, i) for i in range(len(periods))]
            life_text = f"{say_p_in_life(results, answer, soil, row)} ({numbers.stated_probability(row.limit)})"
            beta = beta_words(results, answer, soil.soil, row.state) if row.not_reached_below is None else "-"
        lines.append({"soil": soil.soil, "action": action(soil.verdict, soil, tag), "state": state, "at": at,
                      "life": life_text, "beta": beta,
                      "reason": reason(results, answer, soil)})
    return lines


def terminal_verdicts(results) -> str:
    """The verdict per asset and soil as plain text for the terminal, in the summary page's words.

    One line per block and soil: the action, the governing damage state, its probability in the design life
    (with the limit) and the reason the summary gives (which says where a bound, the credible cap or the fitted
    tail decides); a line naming the hazard first. The same functions make the summary page, so the words agree.
    """
    answers = results.answers
    if not answers:
        return "Verdict: the study has no block, so no verdict."
    first = answers[0]
    life = numbers.years(first.design_life)
    lines = [f"Verdict per asset and soil (probabilities in {life} with {hazard_words(results, first)}):"]
    if any(answer.example_hazard for answer in answers):
        lines.append(EXAMPLE_WARNING)
    elif illustrative_hazard(results):
        lines.append(ILLUSTRATIVE_WARNING)
    header = ["asset", "soil", "action", "governing damage state", f"P in {life} (limit)", "reason"]
    table = []
    for answer in answers:
        name = block_name(results.config, answer.block)
        for line in verdict_rows(results, answer):
            table.append([name, line["soil"], line["action"], line["state"], line["life"], line["reason"]])
            name = ""
    widths = [max(len(str(cells[i])) for cells in [header, *table]) for i in range(len(header) - 1)]
    for cells in [header, *table]:
        lines.append("  ".join(str(cell).ljust(width) for cell, width in zip(cells, widths)) + "  " + cells[-1])
    return "\n".join(lines)


def verdict_items(results, answer) -> list[Item]:
    """The answer page's verdict: the summary's rows of this block, as a sentence per soil group."""
    name = short_block_name(results.config, answer.block)
    groups: dict[str, list] = {}
    for soil in answer.soils:
        groups.setdefault(soil.verdict, []).append(soil)
    caveat = hazard_caveat(results)
    lead = f"With {caveat}, the {name}: " if caveat else f"Verdict for the {name}: "
    parts = []
    for verdict, soils in groups.items():
        where = listed([soil.soil for soil in soils])
        parts.append(f"{action(verdict, hazard=hazard_tag(results))} on {where}")
    tied = [soil.soil for soil in answer.soils if _tied(soil)]
    if tied:
        parts.append(f"sliding was not computed on {listed(tied)} (the study ties the base there), so those verdicts "
                     "cover rocking and overturning only")
    items = [strong(lead + "; ".join(parts) + ".")]
    for soil in answer.soils:
        row = governing(soil)
        state = f" ({short_names(results)[row.state]})" if row is not None and soil.verdict != CHECK_SLIDING else ""
        items.append(bullet(f"On {soil.soil}{state}: {reason(results, answer, soil)}"))
    return items


__all__ = ["ACTION_WORDS", "EXAMPLE_TAG", "GOVERNING_WORDS", "ILLUSTRATIVE_TAG", "PLANE_DEPTH",
           "STRUCTURAL_BASE_WORDS", "action", "beta_words", "governing", "hazard_tag", "p_at_return_period",
           "p_in_life", "per_metre", "reason", "structural_bases", "summary_items", "terminal_verdicts",
           "verdict_items", "verdict_rows"]
