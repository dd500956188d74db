"""rockfrag.report.answer_page - the answer pages: one page of common text, then one page or two per block.

Input : a ``Results`` bundle (its ``answers``: rockfrag.answer.block_answers at the study's return periods,
        with the verdict limits of the study) and the block.
Output: ``reading_items``, what every answer page shares, said once (which curve answers, where the base
        friction comes from, how to read the tables, what each verdict asks for); ``answer_items``, the items of
        one block's page: its description, the verdict per soil with its reason (rockfrag.report.summary, the
        same words as the summary page), the site's intensity at each return period, P(each damage state) there,
        the records behind each number, what the block does, P in the design life and the verdict row.

Where no record reached a state at any level up to the credible cap, the page says "not reached" and bounds its
probability in the design life by that of exceeding the cap ("< X"), never a fitted median far beyond what any
record did.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from rockfrag.answer import ANCHOR, LEVEL_TOLERANCE, RECOMMENDED, BlockAnswer, display_scale, level_at_or_below
from rockfrag.damage_states import DAMAGE_STATES, NOT_APPLICABLE, TILT_WORDS
from rockfrag.fragility import exceedance, first_overturn_outcomes  # the fits' counting rules, in one place
from rockfrag.models.base import Outcome
from rockfrag.report import numbers
from rockfrag.report.adapters import (
    GOF_LEVEL,
    block_description,
    block_name,
    cell,
    intensity_name,
    measure_label,
    model_info,
    models_of,
    sliding_at,
    sliding_candidates,
)
from rockfrag.report.summary import (
    BOUND_POLICY,
    BOUND_WORDS,
    SLIP_NESTING,
    beta_words,
    hazard_words,
    labels_of,
    no_curve_words,
    p_at_return_period,
    say_p_at,
    say_p_in_life,
    short_names,
    soil_intensities,
    verdict_items,
)
from rockfrag.report.text import Item, heading, note, paragraph, table
from rockfrag.report.words import listed
from rockfrag.units import STANDARD_GRAVITY


def _years(frequency: float) -> str:
    """A mean annual frequency as its mean return period, rounded to two figures: "once in 2,300 years"."""
    if not np.isfinite(frequency) or frequency <= 0:
        return ""
    years = float(f"{1.0 / frequency:.2g}")
    return f"once in {years:,.0f} years"


def _restitution_runs(cube, name):
    """(requested, target, xi) of the recommended model's restitution runs (centre and the restitution members)."""
    parts = []
    for variable in ("restitution_requested", "restitution_target", "damping_ratio_calibrated"):
        if variable not in cube or RECOMMENDED not in cube.model.values:
            return None
        centre = cube[variable].sel(model=RECOMMENDED).drop_vars(["model", "model_label"], errors="ignore")
        centre = centre.expand_dims(run=["centre"])
        member = f"member_{variable}"
        if member in cube and "member" in cube.dims:
            ends = [m for m in ("restitution_low", "restitution_high") if m in cube.member.values]
            ends = cube[member].sel(member=ends).drop_vars("member_label", errors="ignore").rename(member="run")
            centre = xr.concat([centre, ends], dim="run")
        parts.append(centre)
    return parts


def _band_reach(cube, block=None, results=None) -> str:
    """A sentence on the cells where the bed could not reach the restitution range's ends (empty when it did).

    Of one block when ``block`` is given (its answer page), else of the whole study; with ``results`` too, what
    the best-estimate run leaves out where it runs below the middle (``restitution_effect_words``). Restitutions are the
    sample's inputs and targets; the damping ratio calibrated to them is not printed (the precision policy).
    """
    runs = None if cube is None else _restitution_runs(cube, RECOMMENDED)
    if runs is None:
        return ""
    requested, target, _ = runs
    if block is not None and "block" in requested.dims:
        requested, target = requested.sel(block=block), target.sel(block=block)
    short = (requested - target) > 5e-4  # the bed ran at a lower r than the sample asked for
    if not bool(short.any()):
        return ""
    soils = [str(s) for s in cube.soil.values if bool(short.sel(soil=s).any())]
    asked = float(requested.where(short).max())
    reached = _grouped({soil: float(target.sel(soil=soil).where(short.sel(soil=soil)).max()) for soil in soils})
    # cold read 9, user B1: "a bed can always dissipate less" -- say what bounds its damping from below
    text = (f" On {listed(soils)} the bed cannot dissipate as little as the restitution range's upper end asks "
            f"(r up to {asked:.3f}; it reaches at most {reached}): its damping has a floor, the least at which the "
            "block's free rocking on the bed is reproducible (below it the block bounces on a ringing bed and the "
            "measured r jumps between neighbouring dampings), and that floor already dissipates more. Those runs "
            "use the nearest r it reaches, so "
            "the restitution part of the model dispersion there leaves out the less dissipative side of the range, "
            "the side on which a block rocks more.")
    if "run" in requested.dims and "centre" in requested.run.values:
        centre_asked, centre_run = requested.sel(run="centre"), target.sel(run="centre")
        low = [str(s) for s in cube.soil.values
               if bool(((centre_asked.sel(soil=s) - centre_run.sel(soil=s)) > 5e-4).any())]
        if low:
            values = [f"{float(centre_run.sel(soil=soil).min()):.3f}" for soil in low]
            runs = values[0] if len(set(values)) == 1 else listed(values)
            text += (f" On {listed(low)} the best-estimate run uses r = {runs}, below the middle of the range, "
                     f"{float(centre_asked.max()):.3f}.")
            if results is not None and block is not None:
                text += restitution_effect_words(results, block, low, target)
        # cold read 12, default C3: gravel reached at most 0.742 yet was not listed beside rock's 0.728 below 0.746
        middle = float(centre_asked.max())
        near = {soil: float(target.sel(soil=soil).where(short.sel(soil=soil)).max()) for soil in soils
                if soil not in low and float(target.sel(soil=soil).where(short.sel(soil=soil)).max()) < middle - 5e-4}
        if near:
            from rockfrag.models.restitution import tolerance

            said = {f"{value:.3f}" for value in near.values()}
            said = said.pop() if len(said) == 1 else _grouped(near)
            text += (f" On {listed(near)} the bed's most, r {said}, lies within the calibration's tolerance of the "
                     f"middle (± {tolerance(middle):.3f}), so the best-estimate run counts as at the middle.")
    return text


def restitution_effect_words(results, block, low, target) -> str:
    """What the upper half of the restitution range is worth where the best-estimate run could not reach it.

    Measured on the soil whose bed reached furthest above the middle (``target``: the r each run reached, runs
    centre and restitution_high): the ratio of the restitution_high run's median to the best estimate's, per
    governing state of the soils in ``low``. The same ratio applied to those soils' medians (hazard, β and credible
    cap unchanged, rockfrag.fragility.capped_frequency) says whether any judged state would cross its limit: the
    size of what the best estimate leaves out and whether it could change a verdict (cold read 5, default B4).
    "" where no soil reached above the middle or no governing state has a median on both runs.
    """
    from rockfrag.fragility import capped_frequency
    from rockfrag.hazard import hazard_of
    from rockfrag.report.summary import governing
    from rockfrag.risk import probability_in_life

    fragility = results.fragility
    if "member_median" not in fragility or "restitution_high" not in fragility.member.values \
            or "run" not in target.dims or "restitution_high" not in target.run.values:
        return ""
    gain = {str(s): float(target.sel(run="restitution_high", soil=s) - target.sel(run="centre", soil=s))
            for s in target.soil.values if str(s) not in low}
    gain = {soil: value for soil, value in gain.items() if np.isfinite(value) and value > 5e-4}
    answer = next((a for a in (results.answers or ()) if a.block == str(block)), None)
    if not gain or answer is None:
        return ""
    proxy = max(gain, key=gain.get)
    reached = float(target.sel(run="restitution_high", soil=proxy))
    row = fragility.sel(block=block, soil=proxy)
    hazard = results.site_hazards or results.hazard
    cap = float(fragility.credible_max.sel(block=block)) if "credible_max" in fragility else np.inf
    labels, shifts, crossed = short_names(results), {}, []
    for soil in answer.soils:
        if soil.soil not in low or (state := governing(soil)) is None:
            continue
        centre = float(row["median"].sel(model=RECOMMENDED, damage_state=state.state))
        high = float(row["member_median"].sel(member="restitution_high", damage_state=state.state))
        if not (np.isfinite(centre) and np.isfinite(high) and centre > 0):
            continue
        ratio = high / centre
        shifts.setdefault(state.state, ratio)
        curve = hazard_of(hazard, soil.soil) if hazard is not None else None
        for judged in soil.states:
            if not judged.limit or not np.isfinite(judged.probability_in_life) or curve is None:
                continue
            fit = fragility.sel(block=block, soil=soil.soil, model=RECOMMENDED, damage_state=judged.state)
            median, beta = float(fit["median"]), float(fit["beta"])
            if not (np.isfinite(median) and np.isfinite(beta)):
                continue  # a bound, not a curve: the restitution does not move it here
            shifted = float(probability_in_life(capped_frequency(median * ratio, beta, curve, cap),
                                                answer.design_life))
            if (shifted > judged.limit) != judged.exceeds:
                crossed.append(f"{labels.get(judged.state, judged.state)} on {soil.soil}")
    if not shifts:
        return ""
    moves = listed([f"the median of {labels.get(state, state)} {'drops' if ratio < 1 else 'rises'} by "
                  f"{abs(100 * (ratio - 1)):.0f}%" for state, ratio in shifts.items()])
    same = "the same change" if len(shifts) == 1 else "the same changes"
    takes = "takes" if len(shifts) == 1 else "take"
    verdict = (f"{same} on {listed(low)} would take {listed(crossed)} across its limit." if crossed else
               f"{same} on {listed(low)} {takes} no damage state across its limit, so no verdict changes.")
    return (f" What that side is worth, measured on {proxy}, where the bed reaches r = {reached:.3f}: from the "
            f"best-estimate run to that one {moves}; {verdict}")


def _governing_fits(results, answer):
    """Per soil with a judged governing state that has a curve: (soil answer, its state row, the fit, curve, cap)."""
    from rockfrag.hazard import hazard_of
    from rockfrag.report.summary import governing

    fragility = results.fragility
    hazard = getattr(results, "site_hazards", None) or getattr(results, "hazard", None)
    if hazard is None or answer.model != RECOMMENDED:
        return []
    cap = float(fragility.credible_max.sel(block=answer.block)) if "credible_max" in fragility else np.inf
    found = []
    for soil in answer.soils:
        row = governing(soil)
        if row is None or not row.limit or not np.isfinite(row.probability_in_life) or row.below_lowest is not None:
            continue
        fit = fragility.sel(block=answer.block, soil=soil.soil, model=answer.model, damage_state=row.state)
        if not (np.isfinite(float(fit["median"])) and np.isfinite(float(fit["beta"]))) or float(fit["beta"]) <= 0:
            continue
        found.append((soil, row, fit, hazard_of(hazard, soil.soil), cap))
    return found


def robustness_words(results, answer) -> str:
    """How far each soil's verdict stands from its limit, and what adding the model's two parts would change.

    Cold read 12 (user B1, B4): the clay verdict rests on a slip median that planar, one-component runs without the
    vertical motion may overstate, and the model part of β is the larger of the form rating and the sensitivity
    spread where FEMA P695 and P-58 add such parts. Per soil: the factor on the governing median at which its
    probability in the design life reaches the limit (bisection on ``capped_frequency``), and that probability
    with β = √(β_records² + β_form² + β_parameters²). "" where no governing state has a curve.
    """
    from scipy.optimize import brentq

    from rockfrag.fragility import capped_frequency
    from rockfrag.risk import probability_in_life

    cases = _governing_fits(results, answer)
    if not cases:
        return ""
    labels, scale = short_names(results), display_scale(results.fragility["median"].attrs.get("units", ""))[0]
    margins, added, crossed = [], [], []
    for soil, row, fit, curve, cap in cases:
        median, beta = float(fit["median"]), float(fit["beta"])

        def excess(factor, median=median, beta=beta, curve=curve, cap=cap, limit=row.limit):
            return float(probability_in_life(capped_frequency(median * factor, beta, curve, cap),
                                             answer.design_life)) - limit

        name = labels.get(row.state, row.state)
        try:
            factor = brentq(excess, 0.02, 50.0, xtol=1e-4)
        except ValueError:
            factor = np.nan
        if np.isfinite(factor):
            way = f"fall {100 * (1 - factor):.0f}%" if factor < 1 else f"rise {100 * (factor - 1):.0f}%"
            margins.append(f"{way} on {soil.soil} ({name}, from {median * scale:#.3g} to "
                           f"{median * factor * scale:#.3g} {answer.unit})")  # 3 figures: the % reads off them
        parts = [float(fit[name]) for name in ("beta_record_to_record", "beta_form", "beta_parameters")
                 if name in fit]
        if len(parts) == 3 and all(np.isfinite(parts)):
            wider = float(np.sqrt(sum(part ** 2 for part in parts)))
            p = float(probability_in_life(capped_frequency(median, wider, curve, cap), answer.design_life))
            added.append(f"{numbers.probability(p)} on {soil.soil} (β {numbers.dispersion(wider)})")
            if (p > row.limit) != row.exceeds:
                crossed.append(soil.soil)
    text = ""
    if margins:
        text += (f"How far each verdict stands from its limit: the governing median would have to {listed(margins)} "
                 "for its probability in the design life to reach the limit. A bias in the median smaller than that "
                 "leaves the verdict as it is (the planar runs, one horizontal component at a time and without the "
                 "vertical motion, may understate the slip: Limitations, 'Sliding').")
    if added:
        text += (" The model part of β is the larger of the form rating and the sensitivity runs' spread, the "
                 "study's choice; FEMA P695 and P-58 add such parts (√ of the sum of squares). So added, the "
                 f"governing probabilities in the design life would be {listed(added)}: "
                 + (f"the verdict on {listed(crossed)} would change." if crossed else "no verdict changes."))
    return text.strip()


def _grouped(values: dict) -> str:
    """Soil -> r as "0.750 on sand, 0.742 on gravel and 0.728 on rock and steel" (equal values said once)."""
    groups: dict[str, list[str]] = {}
    for soil, value in values.items():
        groups.setdefault(f"{value:.3f}", []).append(soil)
    return listed([f"{value} on {listed(soils)}" for value, soils in groups.items()])


def _band_collapse(cube, block) -> str:
    """A sentence on the soils where the restitution runs of ``block`` are one run ("" where none are).

    Where the bed reaches none of the range's targets, the central member and the two restitution members are
    the same run: restitution moves the median by 0 there because there is one run, not because it is known.
    """
    runs = None if cube is None else _restitution_runs(cube, RECOMMENDED)
    if runs is None or runs[2].sizes.get("run", 0) < 2:
        return ""
    requested, target, xi = (run.sel(block=block) for run in runs)
    collapsed = [str(s) for s in cube.soil.values
                 if np.isfinite(values := np.asarray(xi.sel(soil=s).values, float)).all()
                 and np.ptp(values) <= 1e-9 * max(abs(values).max(), 1.0)]
    if not collapsed:
        return ""
    asked = f"r {float(requested.sel(soil=collapsed).min()):.3f} to {float(requested.sel(soil=collapsed).max()):.3f}"
    reached = target.sel(soil=collapsed)
    asked += (f" asked; it reaches {float(reached.max()):.3f} at most" if bool(reached.notnull().any())
              else " asked; it reaches none of them")
    where = "every soil" if len(collapsed) == cube.soil.size else listed(collapsed)
    text = (f" On {where} the restitution range collapses to one run for this block: the bed cannot tell its "
            f"restitutions apart ({asked}), so restitution adds nothing to the model dispersion there because there "
            "is one run, not because it is known; the model part of β there rests on FEMA P695's model-quality "
            "rating.")
    low = float(requested.sel(soil=collapsed).min())
    if bool(reached.notnull().any()) and low < float(reached.max()) - 5e-4:
        # cold read 9, user B1: the low end is within reach, so why one run?
        from rockfrag.models.restitution import LOSS_TOLERANCE, tolerance

        text += (f" The range's low end, r {low:.3f}, lies within the calibration's tolerance of the "
                 f"{float(reached.max()):.3f} the least damping gives (± {tolerance(low):.3f}: {LOSS_TOLERANCE:.0%} "
                 "of the loss 1 − r), so the calibration, which takes the least damping that hits a target, runs it "
                 "at that damping too.")
    if not bool(reached.notnull().any()) and "block_alpha" in cube.coords:
        from types import SimpleNamespace

        from rockfrag.models.restitution import resolution_bound

        bound = resolution_bound(SimpleNamespace(alpha=float(cube.block_alpha.sel(block=block))))
        middle = float(requested.sel(run="centre", soil=collapsed).max()) if "run" in requested.dims \
            else float(requested.sel(soil=collapsed).max())
        side = "below" if round(bound, 3) < round(middle, 3) else "at or above"
        text += (f" The best-estimate run uses the least bed damping at which this block's free rocking dies out below "
                 f"what the restitution measure resolves: its r is not measured but bounded, at most {bound:.3f}, "
                 f"{side} the middle of the range ({middle:.3f}).")
    return text


def curve_reason(results, model: str, block=None) -> str:
    """Which curve answers and why; with ``block``, what the restitution range could not do for that block."""
    if model == RECOMMENDED:
        text = ("The answers use the recommended curve: the tensionless Winkler bed with friction at the base, at "
                "the middle of the experimental range of impact restitution (where the bed reaches it: below, where "
                "not) and the soil's stated friction and stiffness (the best estimate). Its β adds the model "
                "dispersion to the record-to-record one: the larger of the spread of its median over sensitivity "
                "runs (restitution, friction and bed stiffness each at both ends of its range) and FEMA P695's "
                "rating of the model's form (a planar rigid block: no three-dimensional rocking, no flexible "
                "superstructure).")
        if block is not None:
            return (_band_reach(getattr(results, "cube", None), block, results)
                    + _band_collapse(getattr(results, "cube", None), block)).strip()
        models = {str(m) for m in results.fragility.model.values}
        if "housner" in models and any(m.startswith("ssi") for m in models):
            text += (" Housner's rigid base and the paper's model are references, not inputs: the first ignores "
                     "the foundation and the second's spring pulls on the block, which a soil cannot.")
        elif "housner" in models:
            text += " Housner's rigid base is a reference, not an input: it ignores the foundation."
        return text
    if block is not None:
        return ""
    if model == "winkler":
        return ("The answers use the tensionless Winkler bed: of the models this study ran, it is the one that "
                "stays within its own assumptions (its foundation never pulls on the block; see Limitations). "
                "Housner's rigid base and the paper's model are shown as references.")
    return (f"The answers use the {model_info(model).label}: the study did not run the tensionless Winkler bed, "
            "so read them with the limitations, which say where this model is outside its assumptions.")


FRICTION_MARK = "§"
"""Beside a design-life value of a rocking state or overturning on a soil where the block slides before it can rock
(``sliding_first_soils``): the value rests on the assumed base friction (cold read 3, user B1)."""

ROCKING_EDPS = ("peak_angle_ratio", "overturned")
"""The response quantities of the rocking states and overturning: what a base that slides instead of rocking moves."""


def sliding_first_soils(results, answer) -> list:
    """The soils (``SoilClass``) on which this block slides before it can rock: μ_s below b/h (Shenton 1996).

    Only soils whose answering runs have base friction (cube.nc ``friction_static`` finite): a tied base cannot slide.
    """
    cube, config = getattr(results, "cube", None), results.config
    if cube is None or "block_b" not in cube.coords and "block_b" not in cube:
        return []
    slender = float(cube.block_b.sel(block=answer.block)) / float(cube.block_h.sel(block=answer.block))
    soils = []
    for soil in config.soils:
        if soil.friction_static >= slender:
            continue
        if "friction_static" in cube and answer.model in cube.model.values:
            value = cube.friction_static.sel(model=answer.model, block=answer.block, soil=soil.name)
            if not np.isfinite(float(value)):
                continue  # a tied base: it cannot slide in these runs
        soils.append(soil)
    return soils


def _friction_driven_states(results) -> list[str]:
    """The damage states of the rocking family (rocking angles, overturning) in the study's fragility."""
    fragility = results.fragility
    edps = dict(zip(map(str, fragility.damage_state.values), map(str, fragility["damage_state_edp"].values))) \
        if "damage_state_edp" in fragility.coords else {}
    return [state for state in map(str, fragility.damage_state.values)
            if edps.get(state, getattr(DAMAGE_STATES.get(state), "edp", "")) in ROCKING_EDPS]


def slides_first_words(results, answer) -> str:
    """A sentence on the soils where this block slides before it can rock (μ_s below b/h), "" where none.

    There its rocking and overturning rest on the assumed friction: the design-life table marks those values
    (``FRICTION_MARK``) and ``friction_high_words`` gives what the designed sample's high-friction member does.
    """
    soils = sliding_first_soils(results, answer)
    if not soils:
        return ""
    cube = results.cube
    slender = float(cube.block_b.sel(block=answer.block)) / float(cube.block_h.sel(block=answer.block))
    listed = ", ".join(f"{soil.name} {soil.friction_static:g}" for soil in soils)
    return (f"On {_where(results, soils)} the soil's base friction (μ_s {listed}) is below this "
            f"block's b/h = {slender:.2f}: on a rigid base it would slide before it could rock (Shenton 1996). "
            + ("" if model_info(answer.model).rigid_base else
               "On the bed a corner can still lift: the block rocks on the bed's springs, and that motion can build "
               "up over cycles beyond what the friction-capped base shear gives at rest, so its lift-off is "
               "computed. ")
            + "Its rocking and overturning there rest on the assumed friction (the values marked "
            f"{FRICTION_MARK} in the design-life table are friction-driven); a base that grips more (a grout bed, "
            "a keyed plinth) would rock instead, and overturn more readily."
            + lift_off_by_soil_words(results, answer, soils))


MARGIN_MOVE = 0.10
"""A median that moves by more than this share between the central run and the low-friction run is named."""


def friction_margin_words(results, answer) -> str:
    """A sentence on the soils whose friction lies above b/h but within the sample's friction factor of it.

    There the block rocks at the stated friction and slides first at the low end of its range (cold read 9, user
    B2: sand's μ_s 0.45 is 12% above the enclosure's b/h 0.40, and its low-friction run, μ_s 0.375, moved the
    rocking median from 0.97 g to 2.97 g while only clay's friction dependence was said). The medians that move by
    more than ``MARGIN_MOVE`` are named, from the central run to the low-friction run. "" where no soil is that near.
    """
    fragility, cube, config = results.fragility, getattr(results, "cube", None), results.config
    design = getattr(config, "design", None)
    if (answer.model != RECOMMENDED or cube is None or design is None or "member_median" not in fragility
            or "friction_low" not in fragility.member.values):
        return ""
    slender = float(cube.block_b.sel(block=answer.block)) / float(cube.block_h.sel(block=answer.block))
    factor = float(design.friction_factor)
    scale = display_scale(fragility["median"].attrs.get("units", ""))[0]
    short = short_names(results)
    texts = []
    for soil in config.soils:
        if soil.name not in fragility.soil.values or not slender <= soil.friction_static < slender * factor:
            continue
        central = fragility["median"].sel(model=answer.model, block=answer.block, soil=soil.name)
        low = fragility["member_median"].sel(member="friction_low", block=answer.block, soil=soil.name)
        moves, lost = [], []
        for state in short:
            before, after = float(central.sel(damage_state=state)) * scale, float(low.sel(damage_state=state)) * scale
            if not np.isfinite(before):
                continue
            if not np.isfinite(after):
                lost.append(short[state])
            elif abs(after / before - 1.0) > MARGIN_MOVE:
                # a median just under the top level read "3.0 g", as if pinned there (cold read 12, user round 3)
                top = float(fragility.studied_im_max.sel(block=answer.block)) * scale \
                    if "studied_im_max" in fragility else np.inf
                near = after > 0.95 * top
                moves.append(f"{short[state]} from {numbers.intensity(before, answer.unit)} to "
                             + (f"{after:.3g} {answer.unit}, just below the highest level run" if near
                                else numbers.intensity(after, answer.unit)))
        if lost:
            moves.append(f"{listed(lost)} {'loses its median' if len(lost) == 1 else 'lose their medians'} (above "
                         "the highest intensity studied)")
        if not moves:
            continue
        texts.append(f"On {soil.name} the base friction (μ_s {soil.friction_static:g}) is only "
                     f"{numbers.two_figures(100 * (soil.friction_static / slender - 1))}% above this block's b/h = "
                     f"{slender:.2f}: at the low end of its range (μ_s {soil.friction_static / factor:.3g}, a "
                     f"sensitivity run) the block slides before it can rock, and its medians move: {'; '.join(moves)}. "
                     "Which side of b/h the real base friction falls on decides whether it rocks or slides there; a "
                     "measured friction settles it.")
    return " ".join(texts)


LIFTS = 0.25
"""Of the soils where a block slides first, those where at least this share of the records lifts off at some level
'lift off'; below it, but above none, 'hardly'."""


def lift_off_by_soil_words(results, answer, soils) -> str:
    """Where a block that slides first lifts off on the bed on some of those soils and never on others, why.

    Cold read 7 (default B): the squat skid lifts off on sand (48 % of the records at 3 g) and rock (80 %), on clay
    in 2 of 44, never on gravel and steel, which did not follow the soils' stiffness. It follows the bed's damping,
    calibrated per soil to the restitution (gravel's and steel's 1.6 times sand's and rock's), and the friction
    (clay's the lowest, so its base shear is capped lowest). Observed, not a proof: the page says what goes with what.
    """
    fragility, cube = results.fragility, getattr(results, "cube", None)
    if cube is None or "damping_ratio_calibrated" not in cube or model_info(answer.model).rigid_base:
        return ""
    share = {}
    for soil in soils:
        values = fragility.empirical_fraction.sel(model=answer.model, block=answer.block, soil=soil.name,
                                                  damage_state="uplift").values
        share[soil.name] = float(np.nanmax(values)) if np.isfinite(values).any() else np.nan
    lifts = [s for s in soils if share[s.name] >= LIFTS]
    never = [s for s in soils if share[s.name] == 0]
    hardly = [s for s in soils if 0 < share[s.name] < LIFTS]
    if not lifts or not (never or hardly):
        return ""

    def damping(group):
        return np.mean([float(cube.damping_ratio_calibrated.sel(model=answer.model, block=answer.block,
                                                                soil=s.name)) for s in group])

    text = (f" On the bed it lifts off on {listed([s.name for s in lifts])} (at most "
            f"{listed([numbers.probability(share[s.name]) for s in lifts])} of the records, at the highest levels)")
    if hardly:
        lowest = min(s.friction_static for s in config_soils(results))
        text += (f", hardly on {listed([s.name for s in hardly])}"
                 + (f" (its friction, μ_s {hardly[0].friction_static:g}, is the lowest: the friction caps the base "
                    "shear that builds the rocking)" if len(hardly) == 1 and hardly[0].friction_static == lowest
                    else ""))
    if never:
        ratio = damping(never) / damping(lifts)
        text += (f", and never on {listed([s.name for s in never])}"
                 + (f", whose bed damping, set per soil by its calibration to the restitution, is {ratio:.1f} times "
                    "that of "
                    f"{listed([s.name for s in lifts])}: the rocking that builds up on the springs dies out sooner"
                    if ratio >= 1.2 else ": the bed's stiffness and damping do not single these soils out"))
    return text + "."


def config_soils(results) -> list:
    """The study's soils (``SoilClass``)."""
    return list(results.config.soils)


KINETIC_SENSITIVE = 0.25
"""Where μ_k < b/h ≤ μ_s, the block's rocking rests on its friction when the high-friction sensitivity run's uplift
median differs from the best estimate's by more than this fraction (steel under the paper's block: 0.57 g against
1.5 g); where it does not (gravel: 0.2 g both), the block rocks before it ever slides and the friction is moot."""


def bearing_words(results, answer) -> str:
    """A sentence on the clays that carry this block at rest only if stiffer than the class's weaker end; "" else.

    Cold read 12 (default A1): the paper's block presses 400 kPa, which a clay carries only with s_u >= 78 kPa
    (Prandtl: 5.14 s_u), yet the clay's 'no action' said nothing of it. The limitations' 'Bearing' has every block
    and soil (``rockfrag.report.sections.bearing_items``).
    """
    from rockfrag.report.sections import clay_bearing_words, clay_class_strength
    from rockfrag.soils import CLAY_ADHESION, bearing_case

    block = next((block for block in results.config.blocks if block.name == answer.block), None)
    if block is None:
        return ""
    low, _ = clay_class_strength()
    adhesion = (CLAY_ADHESION["soft clay"][0], CLAY_ADHESION["stiff clay"][1])
    said, slips = [], []
    for soil in results.config.soils:
        if soil.name not in [s.soil for s in answer.soils]:
            continue
        case = bearing_case(soil, block)
        if case.kind == "clay" and case.needed_strength > low:
            said.append(f"on {soil.name} it presses {case.pressure / 1e3:,.0f} kPa at rest, which needs "
                        f"{clay_bearing_words(case)}")
        if case.kind == "clay" and soil.friction_static * case.pressure > adhesion[1]:
            # cold read 12 (default text, round 2): the limitations said this cell's slip is unconservative on
            # saturated clay, and its answer page did not
            slips.append(f"on {soil.name} the undrained adhesion of formed concrete ({adhesion[0] / 1e3:.0f}-"
                         f"{adhesion[1] / 1e3:.0f} kPa) is an equivalent friction of only "
                         f"{adhesion[0] / case.pressure:.2f}-{adhesion[1] / case.pressure:.2f} under its "
                         f"{case.pressure / 1e3:,.0f} kPa, against μ_s {soil.friction_static:g}")
    text = (f"Bearing: {'; '.join(said)}. The verdict there presumes ground or a foundation that carries the block "
            "(Limitations, 'Bearing').") if said else ""
    if slips:
        text += (f" Sliding on saturated clay: {'; '.join(slips)}. Where the base slides undrained it slides more "
                 "than computed here, so the verdict there holds for a drained base, or once a site's undrained "
                 "strength shows the adhesion is not lower (Limitations, 'Sliding').")
    return text.strip()


def slides_then_soils(results, answer) -> list:
    """The soils (``SoilClass``) on which this block rocks at rest but cannot while it slides, and does slide.

    μ_k < b/h ≤ μ_s: at rest the block tips before it slides (Shenton 1996), but once its base slips the friction
    force, μ_k m g at most, cannot tip it (that needs b/h m g); it counts where the high-friction sensitivity run
    shows the friction decides (``KINETIC_SENSITIVE``). Only soils whose runs have base friction.
    """
    return [soil for soil, decides in _kinetic_cases(results, answer) if decides]


def _kinetic_cases(results, answer) -> list:
    """(soil, whether the friction decides) for each soil with base friction where μ_k < b/h ≤ μ_s for this block."""
    cube, fragility = getattr(results, "cube", None), results.fragility
    if cube is None or "block_b" not in cube.coords and "block_b" not in cube or "member_median" not in fragility \
            or "friction_high" not in fragility.member.values:
        return []
    slender = float(cube.block_b.sel(block=answer.block)) / float(cube.block_h.sel(block=answer.block))
    soils = []
    for soil in results.config.soils:
        if not soil.friction_kinetic < slender <= soil.friction_static:
            continue
        if "friction_static" in cube and answer.model in cube.model.values and not np.isfinite(float(
                cube.friction_static.sel(model=answer.model, block=answer.block, soil=soil.name))):
            continue  # a tied base
        try:
            best = float(fragility["median"].sel(model=answer.model, block=answer.block, soil=soil.name,
                                                 damage_state="uplift"))
            high = float(fragility.member_median.sel(member="friction_high", block=answer.block, soil=soil.name,
                                                     damage_state="uplift"))
        except KeyError:
            continue
        if np.isfinite(best) and np.isfinite(high):
            soils.append((soil, abs(best - high) > KINETIC_SENSITIVE * min(best, high)))
    return soils


def friction_driven_soils(results, answer) -> list:
    """The soils where this block's rocking and overturning rest on its base friction (marked § on its page)."""
    return [*sliding_first_soils(results, answer), *slides_then_soils(results, answer)]


def slides_then_words(results, answer) -> str:
    """A sentence on the soils of ``slides_then_soils``, with the uplift medians that show it; "" where none."""
    soils = slides_then_soils(results, answer)
    if not soils:
        return ""
    cube, fragility = results.cube, results.fragility
    slender = float(cube.block_b.sel(block=answer.block)) / float(cube.block_h.sel(block=answer.block))
    scale = display_scale(fragility["median"].attrs.get("units", ""))[0]
    said = []
    for soil in soils:
        best, high = (float(fragility[name].sel(block=answer.block, soil=soil.name, damage_state="uplift",
                                                **selection)) * scale
                      for name, selection in (("median", {"model": answer.model}),
                                              ("member_median", {"member": "friction_high"})))
        said.append(f"on {soil.name} (μ_s {soil.friction_static:g}, μ_k {soil.friction_kinetic:g}) it lifts off at "
                    f"a median of {numbers.intensity(best, answer.unit)}, and at "
                    f"{numbers.intensity(high, answer.unit)} with the friction at the high end of its range")
    text = (f"On {listed([soil.name for soil in soils])} the base friction at rest is at least this block's "
            f"b/h = {slender:.2f}, so at rest it rocks before it slides, but its kinetic friction is below b/h: once "
            "the base slips, the friction force can no longer tip the block, which slides instead of rocking. "
            f"The friction decides what it does there: {'; '.join(said)}. Its rocking and "
            f"overturning there rest on the assumed friction (marked {FRICTION_MARK} in the design-life table).")
    # cold read 12, default C1: gravel's μ_k 0.47 is below b/h 0.471 too, and nothing said why it does not matter
    calm = [soil for soil, decides in _kinetic_cases(results, answer) if not decides]
    if calm:  # three digits: "μ_k 0.47 below b/h 0.47" read as a slip (cold read 12, default figures round 2)
        pairs = [f"{soil.name} (μ_k {soil.friction_kinetic:.3f} against b/h {slender:.3f})" for soil in calm]
        text += (f" On {listed(pairs)} "
                 "the kinetic friction is below b/h too, by a hair's breadth, but the friction at the high end of its "
                 "range hardly moves the lift-off there: the friction does not decide.")
    return text


def _where(results, soils) -> str:
    """The soils by name, or "every soil" when they are all the study's (said once, not soil by soil)."""
    every = len(soils) == len(results.config.soils) and len(soils) > 1
    return "every soil" if every else listed([soil.name for soil in soils])


def friction_high_words(results, answer) -> str:
    """The note under the design-life table: what the marked values become with the friction at its range's high end.

    The medians of the designed sample's high-friction member (fragility.nc ``member_median``, member
    ``friction_high``) of each rocking state and overturning on each soil where the block slides first; said once
    where no such state has a median below the credible cap on any of them. "" where no soil is marked.
    """
    first, then = sliding_first_soils(results, answer), slides_then_soils(results, answer)
    soils = [*first, *then]
    if not soils:
        return ""
    names = _where(results, soils)
    rigid = "would slide before it could rock on a rigid base"  # on the bed a corner can still lift (cold read 7)
    how = rigid if not then else "cannot rock while it slides" if not first else \
        f"{rigid} ({listed([soil.name for soil in first])}) or cannot rock while it slides " \
        f"({listed([soil.name for soil in then])})"
    text = f"{FRICTION_MARK} friction-driven: on {names} the block {how}, so these values rest on the assumed base " \
           "friction."
    fragility, cube = results.fragility, results.cube
    states = _friction_driven_states(results)
    if "member_median" not in fragility or "friction_high" not in fragility.member.values or not states:
        return text
    short = short_names(results)
    scale = display_scale(fragility["median"].attrs.get("units", ""))[0]
    parts = []
    for soil in soils:
        medians = [(state, float(fragility.member_median.sel(member="friction_high", soil=soil.name,
                                                             block=answer.block, damage_state=state)) * scale)
                   for state in states]
        shown = [f"{short[state]} at {numbers.intensity(value, answer.unit)}" for state, value in medians
                 if np.isfinite(value)]
        friction = ""
        if "member_friction_static" in cube:
            high = cube.member_friction_static.sel(soil=soil.name, block=answer.block, member="friction_high")
            friction = f" (μ_s {float(high):.2f})"
        parts.append((soil.name, friction, shown))
    if not any(shown for _, _, shown in parts):
        where = "on any soil" if names == "every soil" else "on any of them" if len(soils) > 1 else f"on {names}"
        return (text + " With the friction at the high end of its range (a sensitivity run), no rocking state "
                f"and no overturning has a median below the highest intensity studied {where}.")
    nothing = "none below the highest intensity studied"
    said = "; ".join(f"on {soil}{friction}: " + (", ".join(shown) if shown else nothing)
                     for soil, friction, shown in parts)
    return (text + f" With the friction at the high end of its range (a sensitivity run) the medians are, {said}."
            + _friction_high_verdict(results, answer, [soil.name for soil in soils], states))


def _friction_high_verdict(results, answer, soils, states) -> str:
    """What the high-friction medians give in the design life for the judged states, and whether within the limits.

    The marked soils have no curve of these states (no record reached them, or a curve of a base that slides), so
    the dispersion is borrowed: the largest β of the state's recommended curves on the block's other soils (a
    median far above the hazard's intensities gives a larger probability with a larger β). Integrated over the
    soil's hazard up to the credible cap like every row (rockfrag.fragility.capped_frequency); "" without a hazard
    or a borrowed β (cold read 5, user C6: the medians alone did not say what they mean for the verdict).
    """
    from rockfrag.fragility import capped_frequency
    from rockfrag.hazard import hazard_of
    from rockfrag.risk import probability_in_life

    fragility = results.fragility
    hazard = getattr(results, "site_hazards", None) or getattr(results, "hazard", None)
    if hazard is None or not answer.return_periods:
        return ""
    cap = float(fragility.credible_max.sel(block=answer.block)) if "credible_max" in fragility else np.inf
    short, found, betas = short_names(results), [], []
    for soil in answer.soils:
        if soil.soil not in soils:
            continue
        for row in soil.states:
            if row.state not in states or not row.limit:
                continue
            median = float(fragility.member_median.sel(member="friction_high", soil=soil.soil, block=answer.block,
                                                       damage_state=row.state))
            others = fragility["beta"].sel(model=answer.model, block=answer.block, damage_state=row.state)
            others = others.sel(soil=[s for s in map(str, fragility.soil.values) if s not in soils]).values
            if not np.isfinite(median) or not np.isfinite(others).any():
                continue
            beta = float(np.nanmax(others))
            value = float(probability_in_life(capped_frequency(median, beta, hazard_of(hazard, soil.soil), cap),
                                              answer.design_life))
            found.append((soil.soil, row, value))
            betas.append(beta)
    if not found:
        return ""
    where = len({soil for soil, _, _ in found}) > 1
    values = listed([f"{numbers.probability(value)} for {short[row.state]}" + (f" on {soil}" if where else "")
                   for soil, row, value in found])
    above = [f"{short[row.state]}" + (f" on {soil}" if where else "") for soil, row, value in found
             if value > row.limit]
    judged = f"above its limit: {listed(above)}" if above else "within the limits"
    spread = f"{min(betas):.2f}" if round(min(betas), 2) == round(max(betas), 2) else \
        f"{min(betas):.2f} to {max(betas):.2f}"
    return (f" In {numbers.years(answer.design_life)} these medians give {values} (each with the largest β of its "
            f"state's curves on the other soils, {spread}): {judged}.")


SPECTRUM_BAND = 0.8
"""The records' strongest band: the periods where their mean spectrum (each record's scaled to its PGA, geometric
mean) is within this fraction of its peak."""


def records_band(showcase) -> tuple[float, float] | None:
    """(shortest, longest) period [s] of the records' strongest band (``SPECTRUM_BAND``), None without spectra."""
    if showcase is None or "record_spectrum" not in showcase or "record_pga" not in showcase:
        return None
    spectra = np.asarray(showcase.record_spectrum.transpose("record", "period").values, float)
    pga = np.asarray(showcase.record_pga.values, float)[:, None]
    keep = np.isfinite(spectra).all(axis=1) & (pga[:, 0] > 0)
    if not keep.any():
        return None
    mean = np.exp(np.log(spectra[keep] / pga[keep]).mean(axis=0))
    periods = np.asarray(showcase.period.values, float)[mean >= SPECTRUM_BAND * mean.max()]
    return float(periods.min()), float(periods.max())


def bed_frequencies(config, block, soil) -> tuple[float, float, float]:
    """(vertical, rocking) frequency [Hz] of ``block`` on its bed over ``soil``, and its static settlement [m].

    Vertical: sqrt(k/m) (rockfrag.soils.foundation). Rocking: small tilts about the base centre with the whole base
    down, sqrt((K_r/m - g h) / j), K_r the study's contact law's rocking stiffness (its ``full_contact``: K b² for
    the two corner springs, K b²/3 for the continuous bed) and j = (b² + 4h²)/3 the block's inertia about its base
    centre per unit mass (rockfrag.models.winkler). NaN where the bed cannot hold the block upright.
    """
    from rockfrag.models.contact import CONTACT_LAWS
    from rockfrag.models.restitution import calibrated_law
    from rockfrag.soils import foundation

    found = foundation(soil, block)
    law = CONTACT_LAWS[calibrated_law(config.bed) if config.calibrates_bed else config.bed]
    full_contact = getattr(law.full_contact, "py_func", law.full_contact)  # the plain function: one call
    rocking, _ = full_contact(np.zeros(4), {"omega": found.vertical_frequency, "b": block.b}, 0.0)
    tilt = rocking - STANDARD_GRAVITY * block.h
    j = (block.b ** 2 + 4.0 * block.h ** 2) / 3.0
    omega_r = np.sqrt(tilt / j) if tilt > 0 else np.nan
    return found.vertical_frequency / (2 * np.pi), omega_r / (2 * np.pi), found.settlement


def _lift_setting(results, answer, needs=()):
    """(block, g·tanα in g, soils by stiffness, lift-off medians) for the lift-off sentences, or None.

    None unless the answer is the recommended model's, in g of PGA, on a calibrated bed, with an uplift state and
    the cube variables ``needs``: the conditions ``early_lift_words`` and ``late_lift_words`` share.
    """
    fragility, cube, config = results.fragility, getattr(results, "cube", None), results.config
    if (answer.model != RECOMMENDED or "uplift" not in fragility.damage_state.values or cube is None
            or any(name not in cube for name in needs)
            or str(cube.attrs.get("intensity_measure", "")).lower() != "pga" or answer.unit != "g"
            or not getattr(config, "calibrates_bed", False)):
        return None
    block = next((block for block in config.blocks if block.name == answer.block), None)
    if block is None:
        return None
    soils, medians = uplift_by_stiffness(results, answer)
    return block, block.b / block.h, soils, medians


def uplift_by_stiffness(results, answer) -> tuple[list, dict]:
    """The study's soils by shear modulus and the answering curve's lift-off median on each [shown unit]."""
    fragility = results.fragility
    soils = sorted((soil for soil in results.config.soils if soil.name in fragility.soil.values),
                   key=lambda soil: soil.shear_modulus)
    scale = display_scale(fragility["median"].attrs.get("units", ""))[0]
    return soils, {soil.name: float(fragility["median"].sel(model=answer.model, block=answer.block, soil=soil.name,
                                                            damage_state="uplift")) * scale for soil in soils}


def lift_off_dips(soils, medians) -> list[int]:
    """The indices of the soils whose lift-off median lies below both its neighbours' in stiffness."""
    return [index for index in range(1, len(soils) - 1)
            if np.isfinite(values := [medians[soil.name] for soil in soils[index - 1:index + 2]]).all()
            and values[1] < min(values[0], values[2])]


def bed_resonance_words(results, answer) -> str:
    """A sentence for each soil where the block lifts off at a lower median than on both its neighbours in stiffness.

    Lift-off on a bed is not monotonic in its stiffness there, so the page gives the bed's vertical and rocking
    frequencies under the block against the records' strongest band (``records_band``), says where the bed's
    damping calibrated to the restitution is the block's lowest (its value is not printed: the precision policy),
    and from where a lift is measured: the bed's unloaded surface (loss of contact), so a corner first rises by
    the static settlement. "" where the medians rise with the stiffness, or without the recommended curve.
    """
    fragility, cube, config = results.fragility, getattr(results, "cube", None), results.config
    if answer.model != RECOMMENDED or "uplift" not in fragility.damage_state.values or cube is None:
        return ""
    soils, medians = uplift_by_stiffness(results, answer)
    band = records_band(getattr(results, "showcase", None))
    block = next(block for block in config.blocks if block.name == answer.block)
    texts = []
    for index in lift_off_dips(soils, medians):
        low, soil, high = soils[index - 1], soils[index], soils[index + 1]
        values = [medians[low.name], medians[soil.name], medians[high.name]]
        vertical, rocking, settlement = bed_frequencies(config, block, soil)

        def inside(frequency):
            return band is not None and band[0] <= 1.0 / frequency <= band[1]

        grounds = [(soil.name, rocking)] + [(g.name, bed_frequencies(config, block, g)[1]) for g in (low, high)]
        text = (f"On {soil.name} this block lifts off at a lower median than on {low.name} and {high.name} "
                f"({numbers.intensity(values[1], answer.unit)} against {numbers.intensity(values[0], answer.unit)} "
                f"and {numbers.intensity(values[2], answer.unit)}).")
        if "damping_ratio_calibrated" in cube and answer.model in cube.model.values:
            xi = cube.damping_ratio_calibrated.sel(model=answer.model, block=answer.block)
            if "soil" in xi.dims and str(xi.idxmin("soil").values) == soil.name:
                # "this block's", not "the study's": another block's bed can be less damped (cold read 12, round 3)
                text += (f" A likely reason: the bed's damping, calibrated to the impact restitution, is this "
                         f"block's lowest on {soil.name}, and a less damped bed lets the block rebound off it sooner.")
        hz = numbers.two_figures  # "2.0 Hz", not "2 Hz": both figures (cold read 8)
        text += (f" The bed on {soil.name} has a vertical frequency of {hz(vertical)} Hz and a rocking frequency "
                 f"(whole base down) of {hz(rocking)} Hz, {hz(1.0 / rocking)} s "
                 f"({'; '.join(f'{n} {hz(f)} Hz, {hz(1.0 / f)} s' for n, f in grounds[1:])})")
        if band is not None:
            inner = [name for name, frequency in grounds if inside(frequency)]
            said = ("all within" if len(inner) == len(grounds) else f"{listed(inner)} within" if inner
                    else "none within")
            text += (f", {said} the records' strongest band, {band[0]:.2g} to {band[1]:.2g} s (their mean spectrum "
                     f"within {SPECTRUM_BAND:.0%} of its peak)")
            if len(inner) == len(grounds):
                text += f": the band does not single {soil.name} out"
        text += (f". A lift counts from the bed's unloaded surface (loss of contact), not from rest: a corner first "
                 f"rises by the static settlement, {settlement * 1000:.2g} mm on {soil.name}.")
        texts.append(text)
    return " ".join(texts)


EARLY_LIFT = 0.8
"""A lift-off median below this share of the rigid base's g·tanα is explained on the answer page (early_lift_words)."""
LATE_LIFT = 1.1
"""A lift-off median above this share of g·tanα on a bed is explained on the answer page (late_lift_words)."""


def late_lift_words(results, answer) -> str:
    """A sentence on the soils where the block lifts off above g·tanα on its bed, with the runs that show why.

    Cold read 12 (default B3): the cabinet lifted off at 0.243 g on the steel base, 22% above the rigid base's
    0.20 g, against "earlier on a compliant bed". On a bed a lift counts only once a base corner rises the uplift
    size (``rockfrag.damage_states.uplift_lift``), where a rigid base counts any pivoting: at the first level above
    g·tanα the page counts the records whose corner rose at all and those that rose that far (cube.nc
    ``peak_uplift``). "" for a PGA-less measure, a model without a bed, or where no median is that high.
    """
    from rockfrag.damage_states import uplift_lift

    setting = _lift_setting(results, answer, needs=("peak_uplift",))
    if setting is None:
        return ""
    block, rigid, soils, medians = setting
    cube = results.cube
    sliding = {soil.name for soil in friction_driven_soils(results, answer)}  # their lift waits on the friction
    late = [soil for soil in soils if np.isfinite(medians[soil.name]) and medians[soil.name] > LATE_LIFT * rigid
            and soil.friction_kinetic >= rigid and soil.name not in sliding]
    if not late:
        return ""
    scale = display_scale(cube.intensity.attrs.get("units", ""))[0]
    levels = np.asarray(cube.intensity.sel(block=answer.block).values if "block" in cube.intensity.dims
                        else cube.intensity.values, float) * scale
    above = np.flatnonzero(levels > rigid)
    if not above.size:
        return ""
    level, size = int(above[0]), uplift_lift(block.b)
    said = []
    for soil in late:
        lift = np.asarray(cube.peak_uplift.sel(model=answer.model, block=answer.block, soil=soil.name)
                          .isel(im_level=level).values, float)
        lift = lift[np.isfinite(lift)]
        said.append(f"on {soil.name} at a median of {numbers.intensity(medians[soil.name], answer.unit)}; at "
                    f"{numbers.intensity(levels[level], answer.unit)} a corner of {int((lift > 0).sum())} of "
                    f"{lift.size} records rose, of {int((lift >= size).sum())} by the uplift size")
    return (f"Above the rigid base's g·tanα = {numbers.intensity(rigid, answer.unit)}: this block lifts off "
            f"{'; '.join(said)}. On a bed a lift counts only once a base corner rises the uplift size "
            f"({size * 1000:.2g} mm here), where the rigid base counts any pivoting: the block first rocks through "
            "angles too small for that (a tilt on the bed), so its lift-off is counted later.")


def early_lift_words(results, answer) -> str:
    """A sentence on the soils where the block lifts off well below g·tanα, the rigid base's uplift acceleration.

    Cold read 8 (default C7): the cabinet lifted off at 0.097 g on clay, half its 0.20 g, and the page said only
    "earlier on a compliant bed". On the two-spring bed the static give lowers lift-off by g·tanα·h·δ/b² (δ the
    static settlement: under 2 % for every shipped block and soil), so the reason is dynamic: the block rocks on the
    springs before a corner lifts, and where that mode's period lies in the records' strongest band the ground
    builds the rocking up. Soils ``bed_resonance_words`` explains (a median below both neighbours') are left to
    it. "" for a PGA-less measure, a model without a bed, or where every median is at least ``EARLY_LIFT`` of it.
    """
    setting = _lift_setting(results, answer)
    if setting is None:
        return ""
    block, rigid, soils, medians = setting
    fragility, config = results.fragility, results.config
    explained = {soils[i].name for i in lift_off_dips(soils, medians)}
    early = [soil for soil in soils if np.isfinite(medians[soil.name]) and medians[soil.name] < EARLY_LIFT * rigid
             and soil.name not in explained]
    if not early:
        return ""
    band = records_band(getattr(results, "showcase", None))
    scale = display_scale(fragility["median"].attrs.get("units", ""))[0]
    lowest = float(fragility.studied_im_min.sel(block=answer.block)) * scale if "studied_im_min" in fragility \
        else np.nan
    below = [soil for soil in early if medians[soil.name] < lowest * (1 - 1e-9)]  # the fit's extrapolation
    values = listed([f"{numbers.intensity(medians[soil.name], answer.unit)} on {soil.name}"
                     + (BELOW_LOWEST_MARK if soil in below else "") for soil in early])
    shares = listed([f"{medians[soil.name] / rigid:.2f}" for soil in early])
    modes = []
    frequencies = {soil.name: bed_frequencies(config, block, soil) for soil in early}
    for soil in early:
        _, rocking, _ = frequencies[soil.name]
        if np.isfinite(rocking):
            inside = band is not None and band[0] <= 1.0 / rocking <= band[1]
            outside = "" if inside or band is None else ", outside the band"
            modes.append(f"{soil.name} {numbers.two_figures(rocking)} Hz, {numbers.two_figures(1.0 / rocking)} s"
                         f"{outside}")
    give = max(block.h * frequencies[soil.name][2] / block.b ** 2 for soil in early)
    text = (f"Below the rigid base's g·tanα = {numbers.intensity(rigid, answer.unit)}: this block lifts off at a "
            f"median of {values} ({shares} times g·tanα). On its bed it rocks on the springs before a corner lifts")
    if modes:
        text += f" (rocking frequency with the whole base down: {'; '.join(modes)}"
        text += (f"; the records' strongest band {band[0]:.2g} to {band[1]:.2g} s)" if band is not None else ")")
    text += (", and ground motion near that period builds the rocking up until a corner loses contact; on a rigid "
             "base the block does not rock before the ground reaches g·tanα. The bed's static give alone lowers "
             f"the lift-off by the share h·δ/b² of it (δ the static settlement), {numbers.two_figures(100 * give)}% "
             "at most here.")
    if below:  # cold read 12, default B1: 0.097 g quoted plainly below the lowest level run, 0.0995 g
        n_records = int(fragility["n_records"]) if "n_records" in fragility else 0
        counts = []
        for soil in below:
            share = float(fragility.empirical_fraction.isel(im_level=0).sel(
                model=answer.model, block=answer.block, soil=soil.name, damage_state="uplift"))
            counts.append(f"{numbers.count(int(round(share * n_records)), n_records)}"
                          f"{' records' if not counts else ''} on {soil.name}")
        text += (f" {BELOW_LOWEST_MARK.strip()} below the lowest level run, {lowest:.3g} {answer.unit}: the fit's "
                 f"extrapolation, where {listed(counts)} already lift off (the fitted table marks such a median).")
    return text


BELOW_LOWEST_MARK = " (*)"
"""Beside a lift-off median below the lowest level run (``early_lift_words``): the fit's extrapolation there."""


MOTIONS = ("at rest", TILT_WORDS, "slides", "rocks", "slides and rocks", "flies", "overturns")
"""What a run does, from the mildest to the most severe (a record's motion is the most severe it enters). A lift of
a base corner below the uplift size of the damage-state registry (rockfrag.damage_states.uplift_lift) is a tilt on
the bed, not rocking; "rocks", "slides and rocks" and "flies" need the lift, and overturning is counted from a
record's first overturning level on (as the fits count it: resurrection)."""

NO_LEVEL = "no level run this low"
"""A return-period intensity below every level run: the page says so (the tables' heads do too)."""


def _motions(runs, lifted) -> np.ndarray:
    """Each record's most severe motion at one level (an index of ``MOTIONS``), -1 for a failed run.

    ``runs`` is one cell at one level with the first-overturn outcome; ``lifted`` where its records lift off by the
    damage-state registry's rule (``exceedance`` of the uplift state, the fits' own). The mode times (where the
    base slides) say whether the block slid while it rocked, and whether a bed's flight lifted it; a tied base
    has none.
    """
    outcome = np.asarray(runs.outcome.values)
    times = {field: np.nan_to_num(np.asarray(runs[field].values, float)) > 0
             for field in ("time_sliding", "time_slide_rocking", "time_in_flight") if field in runs}
    none = np.zeros(outcome.shape, bool)
    slid = times.get("time_sliding", none) | times.get("time_slide_rocking", none)
    worst = np.where(slid, MOTIONS.index("slides"), np.where(outcome == int(Outcome.ROCKING),
                                                               MOTIONS.index(TILT_WORDS), 0))
    rocked = np.where(times.get("time_in_flight", none), MOTIONS.index("flies"),
                      np.where(times.get("time_slide_rocking", none), MOTIONS.index("slides and rocks"),
                               MOTIONS.index("rocks")))
    worst = np.where(lifted, rocked, worst)
    worst = np.where(outcome == int(Outcome.FREE_FLIGHT), MOTIONS.index("flies"), worst)
    worst = np.where(outcome == int(Outcome.OVERTURNED), MOTIONS.index("overturns"), worst)
    return np.where(outcome == int(Outcome.FAILED), -1, worst)


def motion_tallies(cube, block: str, model: str, soil: str, intensities, scale: float) -> list:
    """How many records enter each motion at each intensity: a dict motion -> count per intensity.

    Each record is counted once, at its most severe motion (``MOTIONS``), at the level run nearest at or below
    each intensity (in the answer's unit, ``scale`` times the cube's), the level whose records the probability
    table counts; ``NO_LEVEL`` where no level lies that low, "-" where nothing is known. The records that lift off
    (rocks, slides and rocks, flies, overturns) are the uplift count of that table. From the runs of ``model``
    (the recommended curve's: its central member).
    """
    if cube is None or "intensity" not in cube:
        return ["-"] * len(intensities)
    name = model
    if name not in cube.model.values:
        return ["-"] * len(intensities)
    levels = np.asarray(cube.intensity.sel(block=block).values, float) * scale
    cell = cube.sel(block=block, soil=soil, model=name)
    lifted = exceedance(cell, DAMAGE_STATES["uplift"]).fillna(0.0) > 0  # the fits' rule, overturning from the first
    cell = cell.assign(outcome=first_overturn_outcomes(cell))
    out = []
    for im in intensities:
        level = level_at_or_below(levels, im)
        if level is None:
            out.append(NO_LEVEL)
            continue
        worst = _motions(cell.isel(im_level=level), np.asarray(lifted.isel(im_level=level).values))
        worst = worst[worst >= 0]
        if not worst.size:
            out.append("-")
            continue
        out.append({MOTIONS[m]: int(np.sum(worst == m)) for m in range(len(MOTIONS))})
    return out


def motion_counts(cube, block: str, model: str, soil: str, intensities, scale: float) -> list[str]:
    """``motion_tallies`` in words: "at rest 34, tilts on the bed 6, rocks 4 (of 44)" per intensity."""
    return [tally if isinstance(tally, str) else
            ", ".join(f"{words} {n}" for words, n in tally.items() if n) + f" (of {sum(tally.values())})"
            for tally in motion_tallies(cube, block, model, soil, intensities, scale)]


FLIGHT_SHARE = 0.25
"""Above this share of the records flying at a return period's level, the answer page says what the hops are (and
then names every soil on which any record flies: cold read 12, default B2 found 7 of 44 flying on rock and steel
unnamed beside gravel's 40)."""


def flight_words(results, answer, scale: float) -> str:
    """What 'flies' is where many records make the block fly, and whether it moves the verdict; "" elsewhere.

    Cold reads 7 (user B1, default B): 38 of 44 records made the enclosure 'fly' on sand at the 2,475-year level
    while 3 reached θmax/α 0.2; a client asks whether the hops are real. They are the bed's rebound after an impact,
    set by the damping calibrated to the rocking restitution, not by a measured property of the ground; a real
    footing's radiation damping (Gazetas 1991) would damp them more. Where the rigid base (which cannot hop) has an
    overturning median, the page compares the recommended one with it on the soil where most records fly.
    """
    cube = getattr(results, "cube", None)
    if cube is None:
        return ""
    most = {}
    for soil in answer.soils:
        tallies = motion_tallies(cube, answer.block, answer.model, soil.soil, soil_intensities(answer, soil), scale)
        shares = [tally["flies"] / max(sum(tally.values()), 1) for tally in tallies if isinstance(tally, dict)]
        if shares and max(shares) > 0:
            most[soil.soil] = (max(shares), [tally["flies"] for tally in tallies if isinstance(tally, dict)])
    if not most or max(share for share, _ in most.values()) <= FLIGHT_SHARE:
        return ""
    soils = listed(most)
    text = (f"'Flies' on {soils}: after an impact the block rebounds off the bed's springs in short hops, how much "
            "set by the bed damping calibrated to keep the rocking restitution, not by a measured property of the "
            "ground; a real footing also radiates energy into the ground (radiation damping, Gazetas 1991), which "
            "would damp the rebound more, so these counts are likely high. The hops are not a damage state: the "
            "verdicts count lift-off, the rocking angle and overturning.")
    fragility = results.fragility
    worst = max(most, key=lambda name: most[name][0])
    rigid = next((m for m in models_of(fragility) if m.rigid_base), None)
    if rigid is None or "overturning" not in map(str, fragility.damage_state.values):
        return text
    ours = float(fragility["median"].sel(model=answer.model, block=answer.block, soil=worst,
                                         damage_state="overturning"))
    theirs = float(cell(fragility, rigid, answer.block, worst)["median"].sel(damage_state="overturning"))
    own = display_scale(fragility["median"].attrs.get("units", ""))[0]  # the fits' unit, not the cube's
    ours, theirs = ours * own, theirs * own
    if np.isfinite(ours) and np.isfinite(theirs) and theirs > 0:
        change = ours / theirs - 1
        side = "below" if change < 0 else "above"
        text += (f" On {worst}, where most records hop, the overturning median, "
                 f"{ours:#.3g} {answer.unit}, lies {abs(change):.0%} {side} the rigid base's {theirs:#.3g} "
                 f"{answer.unit} (the fitted table's medians), which cannot hop.")
    return text


def motion_table(cube, answer, scale: float) -> Item | None:
    """The motions of the records per soil: a column per motion any record enters, the return periods in a cell.

    "25 / 14 / 3": at rest in 25, 14 and 3 records at the three return periods' levels (short cells: the table fits
    the page whatever the counts). None when nothing is known.
    """
    tallies = {soil.soil: motion_tallies(cube, answer.block, answer.model, soil.soil, soil_intensities(answer, soil),
                                         scale) for soil in answer.soils}
    known = [tally for row in tallies.values() for tally in row if isinstance(tally, dict)]
    if not known:
        return None
    shown = [motion for motion in MOTIONS if any(tally[motion] for tally in known)]
    total = max(sum(tally.values()) for tally in known)
    rows = [[soil, *(_joined(str(tally[motion]) if isinstance(tally, dict) else "-" for tally in row)
                     for motion in shown)] for soil, row in tallies.items()]
    return table([f"soil (of {total} records)", *shown], rows)


def answer_items(results, answer: BlockAnswer) -> list[Item]:
    """The items of one block's answer page (the common text is on the page before: ``reading_items``).

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
    fragility, cube = results.fragility, getattr(results, "cube", None)
    name = block_name(results.config, answer.block)
    short = short_names(results)
    measure = measure_label(fragility).split(" [")[0]
    unit = answer.unit
    items = []
    description = block_description(results.config, answer.block)
    if description:
        items.append(paragraph(f"{name[0].upper() + name[1:]}: {description}."))
    items += verdict_items(results, answer)
    sufficiency = sufficiency_words(results.efficiency, answer.block, cube.attrs.get("intensity_measure", "")
                                    if cube is not None else "", measure_label(cube).split(" [")[0]
                                    if cube is not None else measure, answer.model)
    # one paragraph per subject (restitution, friction, the bed's lift-off, the measure): not one wall of text
    # the friction's margin above b/h and its kinetic part are one subject: one paragraph (cold read 12, default C1)
    friction = " ".join(filter(None, (friction_margin_words(results, answer).strip(),
                                      slides_then_words(results, answer).strip())))
    for text in (curve_reason(results, answer.model, answer.block), slides_first_words(results, answer),
                 friction, bearing_words(results, answer), bed_resonance_words(results, answer),
                 early_lift_words(results, answer), late_lift_words(results, answer), sufficiency):
        if text:
            items.append(paragraph(text.strip()))
    if not answer.return_periods:
        items.append(paragraph(f"The study has no hazard curve for {measure}: no return-period intensities and no "
                               "probability in the design life. The fragility curves are on the pages that follow."))
        return items
    largest = results.largest_recorded.get(answer.block)
    periods = answer.return_periods
    items.append(heading(f"At the site's intensity of each return period ({' / '.join(map(numbers.years, periods))})"))
    named = intensity_name(cube) if cube is not None else measure
    items.append(paragraph(f"The largest intensity of the records, unscaled ({named}): "
                           f"{numbers.intensity(largest, unit)}."))  # short: it stands on every answer page
    sites = [[soil.soil, " / ".join(results.facts.say("site intensity", (answer.block, soil.soil, t),
                                                      numbers.intensity(im, unit))
                                    for t, im in zip(periods, soil_intensities(answer, soil))),
              _levels_read(answer, soil)] for soil in answer.soils]
    if len({tuple(row[1:]) for row in sites}) == 1:  # one site hazard for every soil: one row
        sites = [["every soil", *sites[0][1:]]]
    items.append(table(["soil", f"site {measure}", "records counted at the level"], sites))
    if cube is not None and "intensity" in cube:
        edge = knife_edge_words(answer, np.asarray(cube.intensity.sel(block=answer.block).values, float)
                                * display_scale(cube.intensity.attrs.get("units", ""))[0])
        if edge:
            items.append(paragraph(edge))
    header = ["damage state", *(f"on {soil.soil}" for soil in answer.soils)]
    rows = [[short[state], *(_not_computed(results, answer, soil.soil, state)
                             or _joined(_below_levels_mark(say_p_at(results, answer, soil, soil.states[index], i),
                                                           soil.states[index], i)
                                        for i in range(len(periods)))
                             + _poor_fit_mark(results, answer, soil, soil.states[index]) for soil in answer.soils)]
            for index, state in enumerate(short)]
    items.append(table(header, rows))
    if any(BELOW_LEVELS_MARK in cell for row in rows for cell in row[1:]):
        items.append(note(BELOW_LEVELS_WORDS))
    if any(cell.endswith(POOR_FIT_MARK) for row in rows for cell in row[1:]):
        items.append(note(POOR_FIT_WORDS.format(level=GOF_LEVEL)))
    counts = [[short[state], *(_joined(results.facts.say("records reaching", (answer.block, soil.soil, state, t),
                                                         _records_cell(soil.states[index], i))
                                       for i, t in enumerate(periods)) for soil in answer.soils)]
              for index, state in enumerate(short)]
    n = int(fragility["n_records"]) if "n_records" in fragility else None
    if any(cell.strip(" /-") for row in counts for cell in row[1:]):
        items.append(paragraph(f"Records that reached each state at those levels{f' (of {n})' if n else ''}:"))
        items.append(table(header, counts))
    scale = display_scale(cube.intensity.attrs.get("units", ""))[0] if cube is not None and "intensity" in cube \
        else 1.0
    motions = motion_table(cube, answer, scale)
    if motions is not None:
        items.append(paragraph("What the records make the block do at those levels, each record at its most severe "
                               "motion:"))
        items.append(motions)
        flights = flight_words(results, answer, scale)
        if flights:
            items.append(note(flights))
    sliding = sliding_rows(cube, answer, scale)
    if any(cell not in ("-", NO_LEVEL) for row in sliding for cell in row[1:]):
        items.append(paragraph("Records whose tied base would slide (it needs more friction than the soil "
                               "offers), at those levels:"))
        items.append(table(["soil", *map(numbers.years, periods)], sliding))
    life = numbers.years(answer.design_life)
    limits = results.decision["max_probability_in_life"]
    items.append(heading(f"In the design life of {life}"))
    header = ["damage state", "limit", *(f"on {soil.soil}" for soil in answer.soils)]
    rows = []
    driven = {soil.name for soil in friction_driven_soils(results, answer)}
    driven_states = _friction_driven_states(results)
    for index, state in enumerate(short):
        cells = [short[state], numbers.stated_probability(limits[state]) if state in limits else "none"]
        for soil in answer.soils:
            row = soil.states[index]
            text = _not_computed(results, answer, soil.soil, state) or say_p_in_life(results, answer, soil, row)
            if row.not_reached_below is None and row.below_lowest is None and np.isfinite(row.probability_in_life) \
                    and (row.probability_in_life >= numbers.FLOOR or _has_curve(results, answer, soil.soil, state)):
                # a value under the floor from the records' shares alone (no curve) gets no return period: "once
                # in 7,800,000 years" from 0 of 44 near the site read as spurious precision (cold read 8, user B2)
                text += f", {_years(row.annual_frequency)}" if _years(row.annual_frequency) else ""
            if row.below_lowest is not None and _fitted_beside_bound(results, answer, soil.soil, state) != \
                    f" (fitted curve: {text.lstrip('≥ ')})":
                text += _fitted_beside_bound(results, answer, soil.soil, state)
            if soil.soil in driven and state in driven_states and np.isfinite(row.probability_in_life):
                text += f" {FRICTION_MARK}"
            if not _not_computed(results, answer, soil.soil, state):
                text += _poor_fit_mark(results, answer, soil, row)
            cells.append(text)
        rows.append(cells)
    rows.append(["β of the governing state's curve", "", *(_beta_cell(results, answer, soil) for soil in answer.soils)])
    from rockfrag.report.summary import action, hazard_tag

    tag = hazard_tag(results)
    rows.append(["action", "", *(action(soil.verdict, soil, tag) for soil in answer.soils)])
    items.append(table(header, rows))
    if driven:
        items.append(note(friction_high_words(results, answer)))
    if below_floor_with_period(rows):
        items.append(note(FLOOR_WITH_PERIOD_WORDS))
    robust = robustness_words(results, answer)
    if robust:
        items.append(paragraph(robust))
    return items


def _fitted_beside_bound(results, answer, soil: str, state: str) -> str:
    """" (fitted curve: 57%)" beside a design-life lower bound '≥ X' (fragility.nc ``probability_in_life``), else "".

    The bound (the records' fraction at the lowest level times the chance of exceeding that level) leaves out every
    intensity below the lowest level; the fitted curve's value, which does not, can be far above it (cold read 5:
    the paper block's uplift on gravel, '≥ 19%' beside clay's fitted 19%, where its curve gives 57%).
    """
    fragility = results.fragility
    if "probability_in_life" not in fragility:
        return ""
    try:
        fitted = float(fragility.probability_in_life.sel(model=answer.model, block=answer.block, soil=soil,
                                                         damage_state=state))
    except KeyError:
        return ""
    return f" (fitted curve: {numbers.probability(fitted)})" if np.isfinite(fitted) else ""


def _has_curve(results, answer, soil: str, state: str) -> bool:
    """Whether the answering model has a fitted curve (a median) of ``state`` on ``soil``."""
    try:
        return bool(np.isfinite(float(results.fragility["median"].sel(model=answer.model, block=answer.block,
                                                                      soil=soil, damage_state=state))))
    except KeyError:
        return False


def below_floor_with_period(rows) -> bool:
    """True where a design-life cell prints a computed value under the print floor with its return period."""
    return any(cell.startswith(f"{numbers.probability(numbers.FLOOR / 2)}, once in") for row in rows
               for cell in row[2:])


FLOOR_WITH_PERIOD_WORDS = ("'< 0.1%, once in ... years': a value computed from the fitted curve, below the print floor "
                           "of 0.1%; its return period says how far below. '< 0.1%' alone where the state has no "
                           "curve: the share of records that reached it at each level, over the site's hazard, gives "
                           "no more than that.")
"""The note under the design-life table where a computed probability below the print floor has its return period."""


CERTAINTY_WORDS = ("'100%': every record reached the state (a count), or a certainty; '> 99%': a fitted value above "
                   "99%, which two figures would round to 100%.")
"""The two forms of a probability near one (rockfrag.report.numbers), said once on 'Reading the answer pages'."""


POOR_FIT_MARK = "‡"
"""Beside a probability read from a fitted curve that fails its goodness-of-fit test (as the fitted table marks it)."""

POOR_FIT_WORDS = ("‡ read from a fitted curve that fails its goodness-of-fit test (p < {level:g}, as the fitted "
                  "table marks it): the lognormal follows the records' fractions poorly there; the records that "
                  "reached the state at each level (the table below) are the firmer evidence.")
"""The note under an answer page's probability table where a cell carries ``POOR_FIT_MARK`` (cold read 3, C5)."""


BELOW_LEVELS_MARK = "*"
"""Beside a probability read at a site intensity below the block's lowest level: the fit extrapolated, as the fitted
table's '*' marks a median outside the studied range (cold read 7, default B: the squat block's 475-year values)."""

BELOW_LEVELS_WORDS = ("* read at a site intensity below the lowest level run ('no level run this low' above): the "
                      "fitted curve carried below the studied range, an extrapolation; the records say nothing there "
                      "('-' in the table of records).")
"""The note under an answer page's probability table where a cell carries ``BELOW_LEVELS_MARK``."""


def _below_levels_mark(text: str, row, index: int) -> str:
    """``text``, a probability cell's value at return period ``index``, marked where read below every level.

    ``BELOW_LEVELS_MARK`` is added where the site's intensity there lies below every level run and the value is the
    fitted curve's (a percentage, not "not reached", a count, a bound from the records or "-").
    """
    fitted = text.endswith("%") and (text[:1].isdigit() or text.startswith("<"))
    if not fitted or not row.records or np.isfinite(row.records[index][2]):
        return text
    return text + BELOW_LEVELS_MARK


def _poor_fit_mark(results, answer, soil, row) -> str:
    """" ‡" where the cell's probabilities come from a curve that fails its goodness-of-fit test, else ""."""
    fragility = results.fragility
    if "gof_p_value" not in fragility or row.not_reached_below is not None or row.below_lowest is not None:
        return ""
    try:
        p = float(fragility.gof_p_value.sel(model=answer.model, block=answer.block, soil=soil.soil,
                                            damage_state=row.state))
    except KeyError:
        return ""
    return f" {POOR_FIT_MARK}" if np.isfinite(p) and p < GOF_LEVEL else ""


def _not_computed(results, answer, soil: str, state: str) -> str:
    """The cell of a state with no fit by design (a slip state of a tied base): "not computed (base tied)", else ""."""
    fragility = results.fragility
    if "status" not in fragility:
        return ""
    status = str(fragility["status"].sel(model=answer.model, block=answer.block, soil=soil,
                                         damage_state=state).values)
    return "not computed (base tied)" if status == NOT_APPLICABLE else ""


def _joined(cells) -> str:
    """The cells of the return periods in one: "5.6% / 17% / 43%"; said once when all are the same."""
    cells = list(cells)
    return cells[0] if len(set(cells)) == 1 else " / ".join(cells)


def _beta_cell(results, answer, soil) -> str:
    """The β of the governing state's curve on one soil, as the summary prints it."""
    from rockfrag.report.summary import governing

    row = governing(soil)
    if row is None or row.not_reached_below is not None:  # a bound from the records: no curve to spread
        return "-"
    return beta_words(results, answer, soil.soil, row.state)


def _levels_read(answer, soil) -> str:
    """The levels whose records the tables count on ``soil``, one per return period ("0.24 / 0.31 / 0.54 g")."""
    for state in soil.states:
        if state.records:
            values = [record[2] for record in state.records]
            return " / ".join(numbers.intensity(v, answer.unit) if np.isfinite(v) else NO_LEVEL for v in values)
    return "-"


def knife_edge_words(answer, levels) -> str:
    """A note where a site intensity prints as the level just above it (two figures) while below it, "" elsewhere.

    The tables then read the level below, which a reader of "0.37 g" beside "0.37 g" takes for a contradiction
    (cold read 3, user C1): the note gives both to the figures that tell them apart. ``levels``: the block's
    levels in the answer's unit.
    """
    levels = np.sort(np.asarray(levels, float)[np.isfinite(levels)])
    said = []
    for soil in answer.soils:
        for period, site in zip(answer.return_periods, soil_intensities(answer, soil)):
            above = levels[levels > site * (1 + LEVEL_TOLERANCE)]  # a level within the tolerance is read as at it
            if not above.size or numbers.intensity(site, answer.unit) != numbers.intensity(above[0], answer.unit):
                continue
            digits = next(d for d in range(4, 10) if f"{site:.{d}g}" != f"{above[0]:.{d}g}")
            below = levels[levels <= site * (1 + LEVEL_TOLERANCE)]
            read = f"the level below it, {numbers.intensity(below[-1], answer.unit)}" if below.size \
                else "no level (none was run that low)"
            said.append(f"on {soil.soil} the {numbers.as_stated(period)}-year intensity, {site:.{digits}g} "
                        f"{answer.unit}, lies just below the level {above[0]:.{digits}g} {answer.unit} (both print "
                        f"{numbers.intensity(site, answer.unit)}), so the tables read {read}")
    text = "; ".join(said)
    return (text[0].upper() + text[1:] + ".") if said else ""


def _records_cell(row, index: int) -> str:
    """How many records reached a state at the level read for a return period ("14"), "-" where unknown."""
    if not row.records:
        return "-"
    reached = row.records[index][0]
    return str(reached) if reached >= 0 else "-"


def _example_cell(answers) -> str:
    """The reading page's example of a cell, taken from this report: " (for example 22% / 30% / 42%)".

    The first cell of the answer tables with a probability at every return period, all different and none a
    bound; "" where there is none.
    """
    for answer in answers:
        for soil in answer.soils:
            for row in soil.states:
                cells = [p_at_return_period(row, i, soil_intensities(answer, soil))
                         for i in range(len(answer.return_periods))]
                if len(cells) > 1 and len(set(cells)) == len(cells) and all(
                        cell.endswith("%") and cell[0].isdigit() for cell in cells):
                    return f" (for example {_joined(cells)})"
    return ""


def reading_items(results) -> list[Item]:
    """What every answer page shares, said once: the curve, the base friction, the tables, the verdicts."""
    answers = results.answers
    if not answers:
        return []
    model = answers[0].model
    labels = labels_of(results)
    limits = {state: limit for state, limit in results.decision["max_probability_in_life"].items() if state in labels}
    short = short_names(results)
    judged = ", ".join(f"{short[state]} {numbers.stated_probability(limit)}"
                       for state, limit in limits.items()) or "none"
    life = numbers.years(answers[0].design_life)
    items = [paragraph(curve_reason(results, model)),
             paragraph(results.friction_words),
             paragraph("Each block rocks in one vertical plane about one bottom edge (a planar model): the "
                       "limitations name the half-width b each block rocks across, and what that leaves out."),
             heading("The tables of each answer page"),
             paragraph(f"The site's intensity at each return period ({hazard_words(results, answers[0])}), on each "
                       "soil, and the level run nearest at or below it (a level at most "
                       f"{LEVEL_TOLERANCE:.1%} above it counts as at it): the tables count the records of that level. "
                       "Above the largest intensity of the unscaled records every result comes from records scaled "
                       "up (extrapolation by scaling)."),
             paragraph("P(damage state) at the site's intensity of each return period, the three return periods in "
                       f"one cell{_example_cell(answers)}, each read as 'this state or worse' within its "
                       "family: uplift, the rocking angles and overturning; the slip states and overturning. Within "
                       "a family a milder state is never less likely than a more severe one."),
             paragraph(SLIP_NESTING),
             paragraph("Marks: 'not reached': no record reached the state at any level up to "
                       "the highest intensity studied (Methods). '≥ X': the fitted median lies below every level "
                       "run, and the records at the lowest level give a lower bound instead of the fit's tail (in the "
                       "design life: their fraction times the yearly rate of exceeding that level, over the design "
                       "life, with the fitted curve's "
                       "own value beside it). "
                       f"{no_curve_words(answers[0])} '-': no level was run as low as that intensity, so the records "
                       "say nothing there; a probability printed at such an intensity is the fitted curve's, "
                       f"extrapolated below the levels run, and carries '{BELOW_LEVELS_MARK}' (as a median outside the "
                       "levels does in the fitted table)."),
             paragraph("Beside the probabilities, how many records reached each state at those levels: a "
                       "probability where none did is the fitted curve's tail alone. The recommended curve's β "
                       "includes the model's uncertainty besides the records' scatter, so at low intensity its "
                       "probability can exceed the share of records that reached the state."),
             paragraph(f"Uplift means lift-off: {DAMAGE_STATES['uplift'].description.split(': ', 1)[-1]}. On a bed "
                       "the lift is the corner's height above the bed's unloaded surface, where the tensionless bed "
                       "lets go (loss of contact), not a rise from rest: a corner first rises by the block's static "
                       f"settlement. A smaller lift off a bed is not rocking: the block {TILT_WORDS} (the bed gives "
                       "under its toe). The "
                       "motion table counts each record once, at its most severe motion; the records that rock, "
                       "slide and rock, fly or overturn there are the records that reach uplift. 'Flies' on a bed "
                       "is the block bouncing clear of its bed after an impact (the vertical ground motion is not "
                       "applied), not a loss of support: often a series of short hops (tens of milliseconds) as the "
                       "block chatters on the bed's springs, judged through the rocking states, not by itself."),
             paragraph(f"The probability in the design life of {life} is the fitted curve integrated over the site's "
                       f"hazard, with how often the state happens on average. It weighs every intensity by how often "
                       "it comes, not only the return periods' intensities: on a soil whose hazard curve is flat "
                       "(the soft soils' site term lifts the frequent, weaker shaking most) it can exceed the "
                       "probability at the 475-year intensity, and on a steeper one fall below it. "
                       f"{BOUND_WORDS} {CERTAINTY_WORDS} "
                       f"{BOUND_POLICY}"),
             heading("The verdicts"),
             paragraph(f"'Anchor or restrain' where a probability in {life} exceeds the study's limit ({judged}; "
                       "an anchorage holds the block against sliding too). 'Specialist check of sliding' where "
                       f"more than {numbers.probability(answers[0].max_sliding_share)} of the records at the level "
                       "run at or below the largest return period's intensity need more base friction than the "
                       "soil offers on a base whose sliding was not "
                       "computed; where the base runs with friction, its slip damage states judge it. Else 'no "
                       "action'. States without a limit are reported, not judged. 'No action' is a verdict on the "
                       "computed risk only: it does not replace an anchorage that the governing code requires (ASCE "
                       "7-22 Chapter 13 does not count on friction from gravity to resist seismic forces) or that the "
                       "equipment's qualification standard asks for (IEEE 693 for substation equipment).")]
    if any(soil.verdict == ANCHOR for answer in answers for soil in answer.soils):
        items.append(paragraph(ANCHOR_DESIGN))
    return items


def sliding_rows(cube, answer: BlockAnswer, scale: float) -> list[list[str]]:
    """Per soil, the share of records whose tied base needs more friction than μ_s at each return period's level.

    ``rockfrag.report.adapters.sliding_at`` at the level run at or below each intensity (``scale``: the answer's
    unit per the cube's); "sliding computed" where the cell runs with friction (its slip states answer). Empty
    when the cube has no friction demand, or when every cell runs with friction.
    """
    if cube is None or "peak_friction_demand" not in cube or not answer.return_periods:
        return []
    candidates = sliding_candidates(cube, answer.model)
    rows, tied = [], False
    for soil in answer.soils:
        cells = []
        for im in soil_intensities(answer, soil):
            share, level, computed = sliding_at(cube, candidates, answer.block, soil.soil, im / scale)
            if computed:
                cells.append("sliding computed")
            elif not np.isfinite(level):
                cells.append(NO_LEVEL)
                tied = True
            else:
                cells.append(numbers.probability(share))
                tied = True
        rows.append([soil.soil, *cells])
    return rows if tied else []


ANCHOR_DESIGN = ("'Anchor or restrain' says that the block must not stand free; it does not size the anchorage. "
                 "Design it as a nonstructural component fixed to its support (ASCE 7-22 Chapter 13: the horizontal "
                 "design force F_p from the site's design spectral acceleration S_DS, with the overturning moment "
                 "and uplift it causes on the anchors; or the equipment's own seismic qualification standard, e.g. "
                 "IEEE 693 for substation equipment). Once anchored the block no longer rocks, so this report's "
                 "curves no longer apply to it.")
"""What an 'anchor' verdict asks for and where its design comes from (the report computes no anchor force)."""

SUFFICIENCY_PARAMETERS = {"p_pulse_period": "the records' pulse period", "p_magnitude": "the earthquake's magnitude",
                          "p_distance": "the distance to the fault"}
"""The efficiency stage's sufficiency tests (efficiency.nc, Luco & Cornell 2007) and the words for each."""

SUFFICIENCY_LEVEL = 0.05
"""Below this p-value the overturning capacity in the study's measure still depends on the parameter."""


def sufficiency_words(efficiency, block: str, study_measure: str, measure: str, model: str | None = None) -> str:
    """One sentence when the study's measure is not sufficient for this block's overturning ("" when it is).

    Reads the smallest p-value over the block's soils and models of each parameter of ``SUFFICIENCY_PARAMETERS``
    for the study's measure (``study_measure``, its name in efficiency.nc; ``measure``, its label). A parameter
    with p < 0.05 still moves the capacity at a given intensity: the curve holds for records like the study's.
    The p-values themselves are on the measure-efficiency page, not here.
    """
    if efficiency is None or study_measure not in efficiency.coords.get("measure", []) \
            or block not in efficiency.block.values:
        return ""
    failing, cells = [], set()
    for variable, words in SUFFICIENCY_PARAMETERS.items():
        if variable not in efficiency:
            continue
        values = efficiency[variable].sel(block=block, measure=study_measure)
        if np.isfinite(values.values).any() and float(np.nanmin(values.values)) < SUFFICIENCY_LEVEL:
            failing.append(words)
            below = values.where(values < SUFFICIENCY_LEVEL).stack(cell=("model", "soil")).dropna("cell")
            cells.update((str(m), str(s)) for m, s in below.cell.values)
    if not failing:
        return ""
    tested = {str(m) for m in efficiency.model.values
              if np.isfinite(efficiency[next(v for v in SUFFICIENCY_PARAMETERS if v in efficiency)]
                             .sel(block=block, measure=study_measure, model=m).values).any()}
    where = ""
    if model is not None and model not in tested:
        runs = []
        for name in sorted({m for m, _ in cells}):
            soils = sorted({s for m, s in cells if m == name}, key=list(map(str, efficiency.soil.values)).index)
            on = "" if len(soils) == efficiency.sizes["soil"] else f" on {listed(soils)}"
            runs.append(f"{model_info(name).label}{on}")
        # cold read 12 (default text, round 2): "the test", "refines overturning capacities" were the tool's words
        where = (f" in the runs of {listed(runs)}, the only model for which this was checked (the check needs each "
                 "record's exact overturning intensity, which the study finds only for a base held against "
                 "sliding); for the recommended model, whose base slides, it is not known")
    return (f"Whether {measure} alone predicts this block's overturning: at a given {measure} the overturning still "
            f"depends on {' and '.join(failing)}{where} (the measure-efficiency page; Luco & Cornell 2007). These "
            "curves hold for ground motions like the study's records; for a site near a fault, whose motions carry "
            "velocity pulses, the study must be run again with pulse-type records (FEMA P695's near-field set).")


__all__ = ["ANCHOR_DESIGN", "MOTIONS", "NO_LEVEL", "answer_items", "curve_reason", "motion_counts",
           "p_at_return_period", "reading_items", "sliding_rows", "sufficiency_words"]
