"""rockfrag.answer - the answer of a study: in the terminal, and on the report's answer pages.

Input : the fragility dataset (``fragility.nc``, with the risk variables of rockfrag.risk merged in, as
        ``fragility_stage`` returns and writes it) and the paths of the main outputs; for the answer pages
        also the site's hazard curve (rockfrag.hazard), the return periods and the verdict limits of the
        study (``[hazard] return_periods``, ``[decision]``), the largest recorded intensity of each block
        and the share of runs that would slide.
Output: ``answer_table``, a short text table, one row per block and soil, that ``rockfrag fragility``
        prints at its end (``--quiet`` suppresses it): the overturning median of the answer model with its
        bootstrap bounds and beta, the probability of overturning in the design life when a hazard curve
        was used, and where the full results are. ``block_answers``: per block and soil, the intensity at
        each return period, P(each damage state) there with its band, the annual frequency and the
        probability in the design life of each state, and the verdict ("anchor", "check sliding",
        "no action"); ``verdict_sentence`` says it in words (rockfrag.report draws it).

The answer model is the first of ``ANSWER_MODELS`` the study ran: the ``recommended`` rows (the
central member of the tensionless bed's designed sample, its model dispersion in beta) when the study
ran them, else ``winkler``, the admissible tensionless bed. The median is the fragility's own
(the lognormal MLE over the stripes, ``median`` in fragility.nc and fragility.csv). Accelerations are
shown in g, whatever unit the file states them in; other measures keep their unit.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import xarray as xr

from rockfrag.damage_states import DEFAULT_LIMITS, nesting_chains  # limits: the damage-state registry's
from rockfrag.hazard import EXAMPLE_HAZARD, HazardCurve, hazard_frequency, hazard_of
from rockfrag.lognormal_fit import lognormal_cdf
from rockfrag.models.variants import RECOMMENDED
from rockfrag.risk import annual_frequency as risk_annual_frequency
from rockfrag.risk import probability_in_life as risk_probability_in_life
from rockfrag.units import STANDARD_GRAVITY

ANSWER_MODELS = (RECOMMENDED, "winkler", "ssi", "ssi-paper", "housner")
"""Models the answer is given for, in order of preference: the first one the study ran is used."""

DEFAULT_RETURN_PERIODS = (475.0, 975.0, 2475.0)
"""Return periods [years] of the answer pages when the study gives none (10%, 5%, 2% in 50 years)."""

DEFAULT_SLIDING_SHARE = 0.10
"""``[decision] max_sliding_share`` when the study gives none."""

ANCHOR, CHECK_SLIDING, NO_ACTION, NO_VERDICT = "anchor", "check sliding", "no action", "no verdict"
"""The verdicts of the answer pages (NO_VERDICT: no hazard curve for the study's measure)."""

ANSWER_STATE = "overturning"
"""The damage state of the answer (rockfrag.fragility's overturning state)."""

_IN_M_S2 = {"g": STANDARD_GRAVITY, "m s-2": 1.0, "m/s^2": 1.0, "m/s2": 1.0, "m/s**2": 1.0}
"""Acceleration units a result file may state, as m/s^2 per unit (UDUNITS spelling or rockfrag's)."""

_STATUS_NOTES = {
    "extrapolated": "median outside the studied levels",
    "separated": "step between two levels (beta 0)",
    "above-range": "reached only at the highest level",
    "not-reached": "no record overturned",
    "below-range": "most records overturn at the lowest level",
    "censored-at-cap": "median above the highest intensity studied",
}


def display_scale(units: str) -> tuple[float, str]:
    """The factor turning values in ``units`` into the shown unit, and that unit's label.

    Accelerations are shown in g: ``"g"``, ``"m s-2"``, ``"9.80665 m s-2"`` (a multiple of a unit) and
    rockfrag's ``"m/s^2"`` all become g; any other unit is kept as it is (factor 1).

    Parameters
    ----------
    units : str
        The ``units`` attribute of a variable.

    Returns
    -------
    tuple of (float, str)
        Factor and unit label.
    """
    text = " ".join(str(units).split())
    multiple, _, rest = text.partition(" ")
    try:
        factor, unit = float(multiple), rest
    except ValueError:
        factor, unit = 1.0, text
    if unit in _IN_M_S2:
        return factor * _IN_M_S2[unit] / STANDARD_GRAVITY, "g"
    return 1.0, text or "-"


def answer_model(fragility: xr.Dataset) -> str:
    """The model the answer is given for: the first of ``ANSWER_MODELS`` in the dataset, else its first."""
    models = [str(m) for m in fragility.model.values]
    return next((m for m in ANSWER_MODELS if m in models), models[0])


def _confidence_label(variable: xr.DataArray) -> str:
    found = re.match(r"\s*(\d+(?:\.\d+)?)% two-sided", variable.attrs.get("long_name", ""))
    return f"{found.group(1)}%" if found else "bootstrap"


def _number(value: float) -> str:
    return f"{value:.3g}" if np.isfinite(value) else "-"


def answer_rows(fragility: xr.Dataset) -> list[dict]:
    """One dict per block and soil: the overturning row of the answer model, in the shown unit.

    Parameters
    ----------
    fragility : xarray.Dataset
        ``fragility.nc`` as written by ``rockfrag.fragility.fragility_stage`` (risk variables optional).

    Returns
    -------
    list of dict
        Keys block, soil, median, median_low, median_high, beta, probability (NaN without a hazard
        curve), status, studied_min, studied_max (the highest level at or below the credible cap), and the
        fraction of records overturned there with its bounds (probability_at_cap, _low, _high; NaN where the
        file has none); intensities in the unit of ``display_scale``.
    """
    model = answer_model(fragility)
    row = fragility.sel(model=model, damage_state=ANSWER_STATE)
    scale, _ = display_scale(fragility["median"].attrs.get("units", fragility.attrs.get("intensity_unit", "")))
    rows = []
    for block in fragility.block.values:
        for soil in fragility.soil.values:
            cell = row.sel(block=block, soil=soil)
            value = {name: float(cell[name]) * scale for name in ("median", "median_low", "median_high")}
            probability = float(cell["probability_in_life"]) if "probability_in_life" in cell else np.nan
            at_cap = {name: float(cell[name]) if name in cell else np.nan
                      for name in ("probability_at_cap", "probability_at_cap_low", "probability_at_cap_high")}
            rows.append({"block": str(block), "soil": str(soil), **value, **at_cap, "beta": float(cell["beta"]),
                         "probability": probability, "status": str(cell["status"].values),
                         "studied_min": float(fragility.studied_im_min.sel(block=block)) * scale,
                         "studied_max": float(fragility.studied_im_max.sel(block=block)) * scale})
    return rows


def _median_cell(row: dict) -> str:
    if row["status"] in ("not-reached", "above-range", "censored-at-cap"):
        return f"> {_number(row['studied_max'])}"
    if row["status"] == "below-range":
        return f"< {_number(row['studied_min'])}"
    return _number(row["median"])


def answer_table(fragility: xr.Dataset, outputs: Sequence[Path | str] = ()) -> str:
    """The answer as text: a heading, one line per block and soil, notes and the output paths.

    Parameters
    ----------
    fragility : xarray.Dataset
        ``fragility.nc``, as ``rockfrag.run_fragility`` returns and writes it.
    outputs : sequence of path
        Files to name at the end (e.g. the report, fragility.csv, fragility.nc).

    Returns
    -------
    str
        The table, lines separated by newlines, without a trailing newline.
    """
    if ANSWER_STATE not in fragility.damage_state.values:
        return f"(no '{ANSWER_STATE}' damage state in the fragility results: no answer table)"
    model = answer_model(fragility)
    rows = answer_rows(fragility)
    _, unit = display_scale(fragility["median"].attrs.get("units", fragility.attrs.get("intensity_unit", "")))
    measure = str(fragility.attrs.get("intensity_measure", "")).upper() or "intensity"
    confidence = _confidence_label(fragility["median_low"])
    life = float(fragility.attrs.get("design_life_years", np.nan))
    hazard = str(fragility.attrs.get("hazard_source", ""))
    with_risk = any(np.isfinite(r["probability"]) for r in rows)
    example = EXAMPLE_HAZARD in hazard
    probability_header = f"P({life:g} yr{', example hazard' if example else ''})"
    header = ["block", "soil", f"median {measure} [{unit}]", f"{confidence} bounds [{unit}]", "beta"]
    header += [probability_header] if with_risk else []
    header += ["note"]
    table = []
    for row in rows:
        bounds = (f"{_number(row['median_low'])}-{_number(row['median_high'])}"
                  if np.isfinite(row["median_low"]) and np.isfinite(row["median_high"]) else "-")
        line = [row["block"], row["soil"], _median_cell(row), bounds, _number(row["beta"])]
        line += [f"{row['probability']:.2g}" if np.isfinite(row["probability"]) else "-"] if with_risk else []
        note = _STATUS_NOTES.get(row["status"], "")
        if row["status"] == "censored-at-cap" and np.isfinite(row["probability_at_cap"]):
            note += (f": {row['probability_at_cap']:.0%} of the records overturned at {_number(row['studied_max'])} "
                     f"{unit} ({row['probability_at_cap_low']:.0%}-{row['probability_at_cap_high']:.0%})")
        line += [note]
        table.append(line)
    widths = [max(len(str(cells[i])) for cells in [header, *table]) for i in range(len(header))]
    lines = [f"Overturning, model {model} ({int(fragility.n_records)} records): lognormal median {measure} in "
             f"{unit}, {confidence} bootstrap bounds of the median, dispersion beta"]
    for cells in [header, *table]:
        lines.append("  ".join(str(cell).ljust(width) for cell, width in zip(cells, widths)).rstrip())
    if with_risk:
        lines.append(f"P: probability of overturning in {life:g} years with the hazard curve {hazard}"
                     + (": set your site's as [hazard] file" if example else ""))
    cap = fragility.attrs.get("credible_intensity_max")
    if cap is not None and np.all(np.isfinite(np.atleast_1d(cap))):
        scale, _ = display_scale(fragility["median"].attrs.get("units", fragility.attrs.get("intensity_unit", "")))
        shown = ", ".join(dict.fromkeys(_number(float(c) * scale) for c in np.atleast_1d(cap)))
        lines.append(f"Credible cap: {measure} at most {shown} {unit} "
                     f"({fragility.attrs.get('credible_intensity_reason', '')}); no level, fit or median above it"
                     + ("; P adds the hazard's exceedance of the cap as an upper bound" if with_risk else ""))
    if outputs:
        lines.append("Results: " + ", ".join(str(path) for path in outputs))
    return "\n".join(lines)


# ---------------------------------------------------------------- the answer pages: return periods and verdicts

def intensity_at_frequency(hazard: HazardCurve, frequency: float) -> float:
    """The intensity whose annual frequency of exceedance is ``frequency`` [1/yr].

    The inverse of ``rockfrag.hazard.hazard_frequency``: log-log interpolation, power laws beyond both ends.

    Parameters
    ----------
    hazard : HazardCurve
        The site's curve (intensities increasing, frequencies decreasing).
    frequency : float
        Annual frequency of exceedance [1/yr], e.g. 1/475.

    Returns
    -------
    float
        The intensity in the curve's unit.
    """
    x, y = np.log(hazard.intensity), np.log(hazard.annual_frequency)
    target = np.log(frequency)
    if target < y[-1]:  # rarer than the last point: the last segment's power law
        return float(np.exp(x[-1] + (target - y[-1]) * (x[-1] - x[-2]) / (y[-1] - y[-2])))
    if target > y[0]:
        return float(np.exp(x[0] + (target - y[0]) * (x[1] - x[0]) / (y[1] - y[0])))
    return float(np.exp(np.interp(target, y[::-1], x[::-1])))


@dataclass(frozen=True)
class StateAnswer:
    """One damage state of one block on one soil.

    Attributes
    ----------
    state : str
        The damage state's name.
    at_return_periods : tuple of (float, float, float)
        P(state | intensity) at each return period's intensity, with the low and high ends of its band
        (from the confidence bounds of the median; NaN where there is none).
    annual_frequency, probability_in_life : float
        Mean annual frequency [1/yr] and probability in the design life [-] (NaN without a hazard);
        for a state not reached below ``not_reached_below``, the upper bound P(intensity > that limit).
    limit : float or None
        The study's largest acceptable probability in the design life; None: the state is not judged.
    not_reached_below : float or None
        The largest recorded intensity when no record reached the state at any level up to it (the
        fitted curve there would be an extrapolation by scaling); None when some record did.
    records : tuple of (int, int, float)
        Per return period, what the records did at the level run nearest at or below its intensity: how
        many reached the state, of how many, and that level (shown unit); (-1, n, NaN) where no level
        lies at or below the intensity, and an empty tuple without the records' fractions.
    first_reached : float or None
        The lowest level (shown unit) at which a record reached the state; None: no record did.
    supported_probability : float
        The probability in the design life from the intensities at and above ``first_reached`` only (0
        when no record reached the state, NaN when unknown): what is left when the fitted curve's tail
        below the data is cut off.
    above_cap_share : float
        The share of ``annual_frequency`` that is the bound for the hazard above the highest intensity studied
        (every stronger motion counted as reaching the state: fragility.nc ``annual_frequency_above_cap``); a
        value that is mostly this term is a bound, not a computed probability (cold read 9).
    records_above : tuple of (int, int, float) or None
        What the records did at the level run next above the largest return period's intensity (as ``records``):
        with the last of ``records``, the two levels either side of it (cold read 12, user B1: "0 of 44 at 0.52 g"
        for a 0.60 g intensity, where 1 of 44 overturned at 0.65 g). None where no level lies above it.
    below_lowest : tuple of (float, int, int) or None
        Where the fitted median lies below the lowest level run (the records reached the state already
        there): that level (shown unit) and how many of how many records reached the state at it. The
        fitted curve below it is an extrapolation, so the probabilities are lower bounds from the records:
        at each return period the fraction at the level at or below it, in the design life that fraction at
        the lowest level times P(intensity > that level). None otherwise.
    """

    state: str
    at_return_periods: tuple
    annual_frequency: float
    probability_in_life: float
    limit: float | None
    not_reached_below: float | None
    records: tuple = ()
    first_reached: float | None = None
    supported_probability: float = float("nan")
    below_lowest: tuple | None = None
    above_cap_share: float = 0.0
    records_above: tuple | None = None

    @property
    def exceeds(self) -> bool:
        """True when the probability in the design life is above the study's limit."""
        return self.limit is not None and bool(np.isfinite(self.probability_in_life)) \
            and self.probability_in_life > self.limit

    @property
    def tail_only(self) -> bool:
        """True when the state exceeds its limit only through the fitted curve's tail below every record.

        Without the intensities below the lowest level at which a record reached the state, the
        probability in the design life would be within the limit.
        """
        return self.exceeds and self.not_reached_below is None and bool(np.isfinite(self.supported_probability)) \
            and self.supported_probability <= self.limit

    def fit_only(self, index: int) -> bool:
        """True when no record reached the state at any level at or below return period ``index``'s intensity."""
        if not self.records:
            return False
        level = self.records[index][2]
        return self.first_reached is None or not np.isfinite(level) or self.first_reached > level * (1 + 1e-9)


@dataclass(frozen=True)
class SoilAnswer:
    """One block on one soil: its states, the share of records that would slide, and the verdict.

    ``sliding_share`` is read at ``sliding_level`` (shown unit), the level run at or below the decision's
    return-period intensity (the largest of the study's; NaN where no level lies that low). ``tied``: the study
    did not compute sliding for the answer model on this soil (its slip states are ``not-applicable``: ``[solver]
    friction`` tied the base), so the verdict does not cover sliding and says so.
    """

    soil: str
    states: tuple
    sliding_share: float
    verdict: str
    sliding_level: float = float("nan")
    intensities: tuple = ()  # the soil's site intensity at each return period (shown unit); its states' P use them
    tied: bool = False


@dataclass(frozen=True)
class BlockAnswer:
    """The answer page of one block.

    Attributes
    ----------
    block, model : str
        The block and the model whose curves answer (``answer_model``).
    return_periods, intensities : tuple of float
        Return periods [years] and the hazard's intensity at each (shown unit; the reference site's when each
        soil has its own curve, whose intensities are ``SoilAnswer.intensities``); empty without a hazard.
    soils : tuple of SoilAnswer
    example_hazard : bool
        The hazard is the shipped example, not the site's.
    design_life : float
        Years of the probability in life.
    unit : str
        The shown unit of the intensities (``display_scale``).
    max_sliding_share : float
        ``[decision] max_sliding_share``: above it a tied base that needs more friction is told to check sliding.
    """

    block: str
    model: str
    return_periods: tuple
    intensities: tuple
    soils: tuple
    example_hazard: bool
    design_life: float
    unit: str
    max_sliding_share: float = DEFAULT_SLIDING_SHARE


def _empirical(fragility: xr.Dataset, model: str, block, soil, state) -> np.ndarray:
    """Fraction of records reaching the state per level; the recommended rows fall back on the bed's runs."""
    if "empirical_fraction" not in fragility:
        return np.array([])
    candidates = [model] + [str(m) for m in fragility.model.values if str(m).startswith("winkler")]
    for name in candidates:
        values = fragility.empirical_fraction.sel(model=name, block=block, soil=soil, damage_state=state).values
        if np.isfinite(values).any():
            return np.asarray(values, float)
    return np.asarray(values, float)


def records_reaching(fraction: float, n_records: int) -> int:
    """How many of ``n_records`` records a fraction of them is (the fractions of fragility.nc are counts over n)."""
    return int(round(float(fraction) * n_records))


LEVEL_TOLERANCE = 0.005
"""A level at most this fraction above a site intensity counts as at it: 0.5 %, below the precision intensities are
printed with (two or three significant figures) and far below the levels' spacing (a factor of 1.1 or more). Without
it a site intensity of 0.3721 g read the level below 0.3722 g, and its records were those of a much lower level."""


def level_at_or_below(levels: np.ndarray, intensity: float) -> int | None:
    """Index of the level run nearest at or below ``intensity`` (same unit; None where every level is above it).

    The one reading of "the records at a return period's intensity": the probability table, the motion table and
    the sliding share all count the records of this level. A level within ``LEVEL_TOLERANCE`` above the intensity
    counts as at it.
    """
    below = np.flatnonzero(np.asarray(levels, float) <= intensity * (1 + LEVEL_TOLERANCE))
    return int(below[-1]) if below.size else None


def _records_at(levels: np.ndarray, empirical: np.ndarray, n_records: int, im: float) -> tuple:
    """(records reaching the state, of how many, the level) at the level nearest at or below ``im``."""
    level = level_at_or_below(levels, im)
    if level is None or not empirical.size or not np.isfinite(empirical[level]):
        return (-1, n_records, float("nan"))
    return (records_reaching(empirical[level], n_records), n_records, float(levels[level]))


def _records_above(levels: np.ndarray, empirical: np.ndarray, n_records: int, im: float) -> tuple | None:
    """(records reaching the state, of how many, the level) at the level next above ``im``; None: none above."""
    at_or_below = level_at_or_below(levels, im)
    above = 0 if at_or_below is None else at_or_below + 1
    if above >= len(levels) or not empirical.size or not np.isfinite(empirical[above]):
        return None
    return (records_reaching(empirical[above], n_records), n_records, float(levels[above]))


def _first_reached(levels: np.ndarray, empirical: np.ndarray) -> float | None:
    reached = np.flatnonzero(np.nan_to_num(empirical) > 0) if empirical.size else np.array([], int)
    return float(levels[reached[0]]) if reached.size else None


def _levels(fragility: xr.Dataset, block, scale: float) -> np.ndarray:
    if "intensity" in fragility.variables and "block" in fragility["intensity"].dims:
        return np.asarray(fragility["intensity"].sel(block=block).values, float) * scale
    return np.asarray(fragility.im_level.values, float) * scale


def _at(row: xr.Dataset, im: float, scale: float, levels: np.ndarray, empirical: np.ndarray):
    """(P, low, high) at ``im`` from the row's lognormal.

    Without a curve: the records' fraction at the highest level not above ``im`` (no band).
    """
    median, beta = float(row["median"]) * scale, float(row["beta"])
    if np.isfinite(median) and np.isfinite(beta):
        p = float(lognormal_cdf(im, median, beta))
        low_median = float(row["median_low"]) * scale if "median_low" in row else np.nan
        high_median = float(row["median_high"]) * scale if "median_high" in row else np.nan
        if np.isfinite(low_median) and np.isfinite(high_median):
            return p, float(lognormal_cdf(im, high_median, beta)), float(lognormal_cdf(im, low_median, beta))
        return p, np.nan, np.nan
    level = level_at_or_below(levels, im)
    if level is not None and empirical.size and np.isfinite(empirical[level]):
        return float(empirical[level]), np.nan, np.nan
    return np.nan, np.nan, np.nan


def _lower_bound(levels: np.ndarray, empirical: np.ndarray, im: float) -> tuple:
    """(the records' fraction at the level at or below ``im``, NaN, NaN): a lower bound on P(state | im).

    Exceedance grows with the intensity, so the fraction at a lower level bounds it; NaN where no level lies that low.
    """
    level = level_at_or_below(levels, im)
    return (float(empirical[level]) if level is not None else np.nan, np.nan, np.nan)


def nested_families(fragility: xr.Dataset) -> list[list[int]]:
    """Indices of the damage states that nest, each chain in the dataset's order of severity.

    ``damage_states.nesting_chains``: the rocking states; the slip states followed by overturning. The fits count a
    record that overturns as beyond every state, the slip states included (``rockfrag.fragility``, first-overturn
    convention), so a slip state reads "slides that far or overturns" and is never less likely than overturning.
    Sliding and lift-off stay apart: a block can slide without lifting off.
    """
    edps = [str(edp) for edp in fragility["damage_state_edp"].values] if "damage_state_edp" in fragility.coords \
        else ["uplifted"] * fragility.damage_state.size
    return nesting_chains(edps)


def nested(rows: list[StateAnswer], families: list[list[int]]) -> list[StateAnswer]:
    """The states' probabilities made to nest: P(a state) is at least that of every more severe one of its family.

    A block that overturns has also rocked past every angle and uplifted, and counts in every slip state; one that
    slid 30 cm has slid 5 cm: exceeding a state implies exceeding the milder ones of its chain.
    Curves fitted one by one may cross in a tail below
    the data (where the fit keeps them apart only from the first level a severe state is reached,
    ``rockfrag.fragility``); the answer reads each state as "this state or worse", the largest of its own and
    the more severe states' values, as pelicun reads the limit states of one component.
    """
    rows = list(rows)
    for family in families:
        for position in range(len(family) - 2, -1, -1):
            milder, severe = rows[family[position]], rows[family[position + 1]]
            if severe.not_reached_below is not None:
                continue  # its value is an upper bound P(intensity > the limit), not a probability of the state
            if not np.isfinite(milder.probability_in_life) and not np.isfinite(
                    np.asarray(milder.at_return_periods, float)).any():
                continue  # not computed (a slip state of a tied base): unknown stays unknown
            periods = tuple(tuple(np.fmax(np.asarray(a, float), np.asarray(b, float)))
                            for a, b in zip(milder.at_return_periods, severe.at_return_periods))
            frequency = float(np.fmax(milder.annual_frequency, severe.annual_frequency))
            probability = float(np.fmax(milder.probability_in_life, severe.probability_in_life))
            supported = float(np.fmax(milder.supported_probability, severe.supported_probability))
            rows[family[position]] = replace(milder, at_return_periods=periods, annual_frequency=frequency,
                                             probability_in_life=probability, not_reached_below=None,
                                             supported_probability=supported)
    return rows


def block_answers(fragility: xr.Dataset, hazard: HazardCurve | Mapping[str, HazardCurve] | None,
                  return_periods: Sequence[float] = DEFAULT_RETURN_PERIODS,
                  limits: Mapping[str, float] | None = None, design_life: float | None = None,
                  largest_recorded: Mapping[str, float] | None = None,
                  sliding: Mapping[tuple[str, str], float] | None = None,
                  max_sliding_share: float = DEFAULT_SLIDING_SHARE) -> list[BlockAnswer]:
    """The answer of every block: return-period intensities, probabilities, design-life risk, verdicts.

    Parameters
    ----------
    fragility : xarray.Dataset
        ``fragility.nc`` (risk variables optional: computed here from ``hazard`` where missing).
    hazard : HazardCurve, mapping of soil to HazardCurve, or None
        The hazard curve of each soil's site for the study's measure (``rockfrag.site_hazard.study_site_hazards``),
        or one curve for every soil; None: no return-period intensities, no risk, verdict ``NO_VERDICT``.
    return_periods : sequence of float
        Return periods [years].
    limits : mapping, optional
        Damage state -> largest acceptable probability in the design life (``DEFAULT_LIMITS``).
    design_life : float, optional
        Years; default the fragility's ``design_life_years`` attribute, else 50.
    largest_recorded : mapping, optional
        Block -> the largest intensity of the unscaled records (shown unit): below it the levels are
        what records did; a state no record reached below it is "not reached below" it.
    sliding : mapping, optional
        (block, soil) -> share of the records of a tied base that need more base friction than the soil's
        coefficient, at the level run at or below the largest return-period intensity (the decision's;
        ``rockfrag.report.adapters.sliding_share``); NaN or absent: unknown, or the cell runs with friction
        and its slip states answer.
    max_sliding_share : float, optional
        Above this share the verdict is ``CHECK_SLIDING``.

    Returns
    -------
    list of BlockAnswer
        One per block, in the dataset's order.
    """
    limits = DEFAULT_LIMITS if limits is None else dict(limits)
    design_life = float(fragility.attrs.get("design_life_years", 50.0) if design_life is None else design_life)
    model = answer_model(fragility)
    scale, unit = display_scale(fragility["median"].attrs.get("units", fragility.attrs.get("intensity_unit", "")))
    periods = tuple(float(t) for t in return_periods) if hazard is not None else ()
    shown = (getattr(hazard, "first", None) or next(iter(hazard.values()))) if isinstance(hazard, Mapping) else hazard
    intensities = tuple(intensity_at_frequency(shown, 1.0 / t) for t in periods)
    states = [str(s) for s in fragility.damage_state.values]
    families = nested_families(fragility)
    n_records = int(fragility["n_records"]) if "n_records" in fragility else 0
    answers = []
    for block in map(str, fragility.block.values):
        levels = _levels(fragility, block, scale)
        decided = level_at_or_below(levels, intensities[-1]) if intensities else None
        decision_level = float(levels[decided]) if decided is not None else np.nan  # the level the sliding share reads
        credible = (largest_recorded or {}).get(block)
        soils = []
        for soil in map(str, fragility.soil.values):
            rows = []
            site = hazard_of(hazard, soil)  # this soil's site curve: its probabilities and return-period intensities
            at_site = tuple(intensity_at_frequency(site, 1.0 / t) for t in periods)
            for state in states:
                row = fragility.sel(model=model, block=block, soil=soil, damage_state=state)
                empirical = _empirical(fragility, model, block, soil, state)
                not_reached = None
                if credible is not None and empirical.size:
                    inside = levels <= credible * (1 + 1e-9)
                    known = empirical[inside]
                    if inside.any() and np.isfinite(known).any() and np.nanmax(known) == 0:
                        not_reached = float(credible)
                frequency = float(row["annual_frequency"]) if "annual_frequency" in row else np.nan
                if not np.isfinite(frequency) and site is not None:
                    frequency = risk_annual_frequency(float(row["median"]) * scale, float(row["beta"]), site)
                if not_reached is not None and site is not None:  # no curve below the limit: P(im > limit)
                    frequency = float(hazard_frequency(site, not_reached))
                probability = float(risk_probability_in_life(frequency, design_life)) if np.isfinite(frequency) \
                    else np.nan
                first = _first_reached(levels, empirical)
                supported = np.nan
                if site is not None and empirical.size and np.isfinite(probability):
                    # the curve's tail below the first level any record reached it cut off
                    supported = 0.0 if first is None else float(risk_probability_in_life(risk_annual_frequency(
                        float(row["median"]) * scale, float(row["beta"]), site, lower=first), design_life))
                records = tuple(_records_at(levels, empirical, n_records, im) for im in at_site) \
                    if n_records and empirical.size else ()
                records_above = _records_above(levels, empirical, n_records, at_site[-1]) \
                    if records and len(at_site) else None
                at = tuple(_at(row, im, scale, levels, empirical) for im in at_site)
                below = None
                median = float(row["median"]) * scale
                if empirical.size and levels.size and np.isfinite(empirical[0]) and empirical[0] > 0 \
                        and np.isfinite(median) and median < levels[0] * (1 - 1e-9):
                    # the fit's median below every level run: its tail there is no data; bound it by the records
                    below = (float(levels[0]), records_reaching(empirical[0], n_records), n_records)
                    at = tuple(_lower_bound(levels, empirical, im) for im in at_site)
                    if site is not None:
                        frequency = float(empirical[0] * hazard_frequency(site, float(levels[0])))
                        probability = float(risk_probability_in_life(frequency, design_life))
                        supported = probability
                above = float(row["annual_frequency_above_cap"]) if "annual_frequency_above_cap" in row else 0.0
                cap_share = above / frequency if np.isfinite(above) and frequency > 0 and below is None \
                    and not_reached is None else 0.0
                rows.append(StateAnswer(state, at, frequency, probability, limits.get(state), not_reached, records,
                                        first, supported, below, cap_share, records_above))
            rows = nested(rows, families)
            share = float((sliding or {}).get((block, soil), np.nan))
            if hazard is None:
                verdict = NO_VERDICT
            elif any(r.exceeds for r in rows):  # anchoring also stops the sliding: it never hides behind it
                verdict = ANCHOR
            elif np.isfinite(share) and share > max_sliding_share:
                verdict = CHECK_SLIDING
            else:
                verdict = NO_ACTION
            edps = [str(e) for e in fragility.damage_state_edp.values] if "damage_state_edp" in fragility.coords \
                else ["peak_slip" if state.startswith("slip") else "" for state in states]
            slip = [str(fragility.status.sel(model=model, block=block, soil=soil, damage_state=state).values)
                    for state, edp in zip(states, edps) if edp == "peak_slip"] if "status" in fragility else []
            tied = bool(slip) and all(status == "not-applicable" for status in slip)
            soils.append(SoilAnswer(soil, tuple(rows), share, verdict, decision_level, at_site, tied))
        example = shown is not None and EXAMPLE_HAZARD in shown.source
        answers.append(BlockAnswer(block, model, periods, intensities, tuple(soils), example, design_life, unit,
                                   float(max_sliding_share)))
    return answers


def percent(value: float) -> str:
    """A probability rounded to what it supports: "12%", "3.4%", "0.21%", "<0.01%", "-" for NaN."""
    if value is None or not np.isfinite(value):
        return "-"
    if value == 0:
        return "0%"
    shown = 100 * value
    if shown >= 99.5:
        return ">99%" if value < 1 else "100%"
    if shown >= 10:
        return f"{shown:.0f}%"
    if shown >= 0.01:
        return f"{shown:.2g}%"
    return "<0.01%"


def verdict_sentence(answer: BlockAnswer, name: str, labels: Mapping[str, str] | None = None) -> str:
    """The verdict of one block in one sentence, grouping the soils by verdict.

    Parameters
    ----------
    answer : BlockAnswer
        The block's answer (``block_answers``).
    name : str
        The block as the client knows it ("crane portal (the paper's block)").
    labels : mapping, optional
        Damage state -> its words ("the block overturns").

    Returns
    -------
    str
        E.g. "With the shipped example hazard curve (not this site's), the verdict for the slender
        electrical cabinet is: anchor it on clay (P(the block overturns) in 50 years 2.2%, above the 1%
        limit); no action on rock."
    """
    labels = labels or {}
    if not answer.soils:
        return f"No verdict for the {name}: the study has no soil."
    if answer.soils[0].verdict == NO_VERDICT:
        return (f"No verdict for the {name}: the study has no hazard curve for its intensity measure, so no "
                "probability in the design life; give one as [hazard] file.")
    groups: dict[str, list[SoilAnswer]] = {}
    for soil in answer.soils:
        groups.setdefault(soil.verdict, []).append(soil)
    def exceeded(soils) -> str:
        reasons = []
        for state in dict.fromkeys(r.state for s in soils for r in s.states if r.exceeds):
            values = [r.probability_in_life for s in soils for r in s.states if r.state == state and r.exceeds]
            limit = next(r.limit for s in soils for r in s.states if r.state == state)
            def near(value, limit=limit):  # a value that rounds to the limit is shown to three digits
                return f"{100 * value:.3g}%" if percent(value) == percent(limit) else percent(value)
            shown = near(min(values)) if len(values) == 1 else f"{near(min(values))} to {near(max(values))}"
            if any(r.below_lowest is not None for s in soils for r in s.states if r.state == state and r.exceeds):
                shown = f"at least {shown}"  # a lower bound from the records at the lowest level (StateAnswer)
            reasons.append(f"P({labels.get(state, state)}) in {answer.design_life:g} years {shown}, above the "
                           f"{percent(limit)} limit{tail_words(soils, state)}")
        return "; ".join(reasons)

    def tail_words(soils, state) -> str:
        """Where the exceedance comes from the fitted curve's tail below every record alone, say so."""
        tails = [(s.soil, r) for s in soils for r in s.states if r.state == state and r.tail_only]
        if not tails:
            return ""
        where = f" on {_and([soil for soil, _ in tails])}" if len(soils) > 1 else ""
        firsts = sorted({f"{r.first_reached:.2g} {answer.unit}" for _, r in tails if r.first_reached is not None})
        below = f"below {_and(firsts)}" if firsts else "at any level"
        kept = ", ".join(percent(r.supported_probability) for _, r in tails)
        return (f", a verdict that rests on the fitted curve's tail alone{where}: no record reached the state "
                f"{below}, and the intensities from there on give {kept}, within the limit")

    parts = []
    for verdict in (CHECK_SLIDING, ANCHOR, NO_ACTION):
        soils = groups.get(verdict, [])
        if not soils:
            continue
        where = "on " + _and([s.soil for s in soils])
        if verdict == ANCHOR:
            parts.append(f"anchor it {where} ({exceeded(soils)}; the anchorage holds it against sliding too)")
        elif verdict == CHECK_SLIDING:
            shares = [s.sliding_share for s in soils]
            shown = percent(min(shares)) if len(shares) == 1 else f"{percent(min(shares))} to {percent(max(shares))}"
            level = sorted({f"{s.sliding_level:.2g} {answer.unit}" for s in soils if np.isfinite(s.sliding_level)})
            at = f" at {_and(level)}, the level run at or below" if level else " at"
            text = (f"check sliding {where} ({shown} of the records{at} the {answer.return_periods[-1]:,.0f}-year "
                    f"intensity{',' if level else ''} need more base friction than the soil's μ_s, above the "
                    f"{percent(answer.max_sliding_share)} the study allows ([decision] max_sliding_share = "
                    f"{answer.max_sliding_share:g}, the "
                    "study's choice): the block would slide, and this study did not compute sliding there (its "
                    "[solver] friction setting ties that base), so no slip state backs the verdict)")
            rocking = exceeded(soils)
            parts.append(text + (f", and anchor it against rocking there ({rocking})" if rocking else ""))
        else:
            parts.append(f"no action {where}")
    tied = [s.soil for s in answer.soils if s.tied and s.verdict != CHECK_SLIDING]
    if tied:
        parts.append(f"sliding was not computed on {_and(tied)}: the study's [solver] friction setting ties the base "
                     "there, so these verdicts cover rocking and overturning only")
    lead = (f"With the shipped example hazard curve (not this site's: the study must name the site's curve), the "
            f"verdict for the {name} is: " if answer.example_hazard else f"Verdict for the {name}: ")
    return lead + "; ".join(parts) + "."


def _and(words: Sequence[str]) -> str:
    words = list(words)
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


__all__ = ["ANCHOR", "ANSWER_MODELS", "ANSWER_STATE", "CHECK_SLIDING", "NO_ACTION", "NO_VERDICT", "RECOMMENDED",
           "BlockAnswer", "SoilAnswer", "StateAnswer", "answer_model", "answer_rows", "answer_table", "block_answers",
           "nested", "records_reaching",
           "display_scale", "intensity_at_frequency", "percent", "verdict_sentence"]
