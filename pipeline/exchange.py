"""rockfrag.exchange - stage 8b: fragility dataset -> files for downstream tools.

Input : the fragility dataset (``rockfrag.fragility.fragility_dataset``: ``median`` and ``beta`` per
        soil x block x model x damage state, the row's ``status``, the block's studied range, the intensity
        measure and unit in its attributes; for rows ``censored-at-cap`` and ``above-range`` also
        ``intensity``, ``credible_max``, ``empirical_fraction`` and ``probability_at_cap`` with its bounds;
        optional ``beta_model``) and the study's Sa period [s].
Output: ``fragility_pelicun.csv``, pelicun 3.x damage-model parameters (``pelicun_table``), and
        ``fragility_openquake.xml``, an OpenQuake NRML 0.5 ``fragilityModel`` (``openquake_model``) of
        continuous lognormal functions and, for a cell with a row of records' fractions, a discrete one;
        ``write_exchange_files`` writes both beside ``fragility.csv``.

One pelicun component and one OpenQuake fragility function per block x soil x model, with the same ID
(``pelicun_id``), rows of the model "recommended" first; one limit state per damage state, in order of
severity. Slip states (``edp = "peak_slip"``) do not nest with the rocking states, so a cell that slides has
a second component, ``ID.SLIP``, and its functions go to ``fragility_openquake_slip.xml``
(``state_families``); a tied cell (slip rows ``not-applicable``) has none. The dispersion written is always
``beta`` (the total). A row is written by what it is
(``written_state``), the same way in both files where the consumers allow it:

- a lognormal (finite median, beta > 0): as it is; OpenQuake wants the mean and standard deviation of the
  intensity, mean = median exp(beta^2/2), stddev = mean sqrt(exp(beta^2) - 1);
- a step (beta = 0: the exact uplift threshold g tan(alpha), or perfectly separated counts): pelicun
  ``deterministic``; OpenQuake has no step in its continuous format, so a lognormal with ``STEP_BETA``;
- ``below-range`` (most records reached the state already at the lowest level studied, so no median):
  reached from the lowest level studied on (a step there);
- ``censored-at-cap`` (the fitted median lies above the credible cap, so no median; some records reached the
  state at the levels studied) and ``above-range`` (a few records reached it, only at the highest level
  studied): the records' fractions (``empirical_fraction``) at the levels at or below the cap, linear between
  levels (both consumers interpolate so), 0 below the lowest level (a rise over ``STEP_WIDTH`` below it where
  records reached the state there), and **held at the probability at the cap above it**: an assumption, since
  no level above the cap is credible; the true probability there is likely higher
  (``rockfrag.fragility.RISK_BOUND`` bounds it by 1 instead). The value at the cap is ``probability_at_cap``.
  pelicun: ``multilinear_CDF`` of the capacity, points (level, fraction) and the rest of the probability at
  the capacity ``inf``; pelicun wants that CDF strictly rising, so where the fraction falls from one level to
  the next the file keeps the higher earlier value (the running maximum, never below the records), and a level
  whose fraction repeats the previous one is written ``PELICUN_RISE`` higher (at most 14 x 1e-5 over a study's
  levels); the value at the cap is then ``probability_at_cap`` unless the fractions fall there. OpenQuake: the
  function of the cell becomes ``discrete`` (one format per function; one model may mix them, as OpenQuake's
  own qa_tests_data/scenario_damage/case_13 does): its IMLs are the study's levels up to the cap, each step's
  two points, and for each lognormal row points every beta/``DISCRETE_POINTS_PER_BETA`` (at most
  ``DISCRETE_MAX_SPACING`` in ln) over ``TAIL_SIGMAS`` beta either side (OpenQuake interpolates linearly
  between IMLs: within ``DISCRETE_ERROR`` of the lognormal), the fractions as they are (OpenQuake needs no
  monotone curve); risklib holds a discrete function at its last IML's value above it
  (``FragilityFunctionDiscrete``), which is the probability at the cap for the censored row and 1 (to 1e-9)
  for the others. The comment before the function says so;
- ``not-reached`` (no record reached the state at any level up to the cap): not reached. pelicun
  leaves the limit state out (empty family and parameters; it skips such a state). It cannot skip the
  first limit state of a component (its capacity anchors the others: an IndexError) nor all of them (a
  KeyError), so a state it needs is written ``deterministic`` with the capacity ``inf``: never reached.
  OpenQuake needs every limit state of a function: a step at twice ``maxIML`` (0 in a discrete function).

A file whose consumer has no such intensity measure (pelicun has no demand type for AvgSa, CAV or a plugin's
measure without ``pelicun_demand``; OpenQuake no IMT without ``openquake_imt``) cannot carry the rows: they are
left out, with one ``ExchangeWarning`` line for pelicun (the fragility stage says it for OpenQuake), and an
empty file is not written.

OpenQuake clamps the intensity to [minIML, maxIML]: a function is held at its value at minIML below it and
at maxIML above it. So minIML and maxIML are not the studied range (which the comment before each function
gives) but ``TAIL_SIGMAS`` beta beyond every curve of the function and the studied range: OpenQuake then
evaluates our lognormals wherever they differ from 0 and 1, as pelicun and ``rockfrag.risk`` do.
"""

from __future__ import annotations

import re
import warnings
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr
from scipy.stats import norm

from rockfrag.damage_states import NOT_APPLICABLE, families_of
from rockfrag.errors import ConfigError
from rockfrag.measures import MEASURES, Measure, convert_units, unit_label
from rockfrag.models.variants import RECOMMENDED
from rockfrag.outputs import atomic_path

PELICUN_FILE = "fragility_pelicun.csv"
OPENQUAKE_FILE = "fragility_openquake.xml"
OPENQUAKE_SLIP_FILE = "fragility_openquake_slip.xml"



class ExchangeWarning(UserWarning):
    """An exchange file cannot carry some rows (its consumer has no such measure): they are left out, said once."""


STEP_BETA = 0.001
"""The lognormal dispersion that stands for a step (beta = 0) in OpenQuake's continuous format: the
probability rises from 0.1% to 99.9% within 0.3% of the step's intensity."""

TAIL_SIGMAS = 6.0
"""OpenQuake holds a continuous function at its value at minIML below minIML (and at maxIML above maxIML), so
both are set this many beta beyond every curve of the function (and beyond the studied range): there a
lognormal is within Phi(-6) = 1e-9 of 0 or 1. With minIML at the lowest level studied, a curve with P = 0.001
there would keep P = 0.001 down to zero intensity, and a classical damage calculation on a hazard curve that
starts at 0.005 g would find hundreds of times our annual frequency (docs/guide/exchange.md)."""

NRML_NAMESPACE = "http://openquake.org/xmlns/nrml/0.5"

STEP_WIDTH = 1e-3
"""A step in a piecewise-linear curve (pelicun's ``multilinear_CDF``, OpenQuake's discrete format) rises over
this fraction of its intensity below it: pelicun rewrites the points with 6 significant digits and wants them
strictly rising, so the two points of a step must differ in the 4th digit."""

PELICUN_RISE = 1e-5
"""pelicun wants a ``multilinear_CDF`` strictly rising (its points differing by more than 1e-8, after its
rewrite with 6 significant digits): a level whose records' fraction repeats the previous one's is written this
much higher (at most 1.4e-4 over 14 levels, against 1/44 between two counts of 44 records)."""

DISCRETE_POINTS_PER_BETA = 12
DISCRETE_MAX_SPACING = 0.1
"""In a discrete OpenQuake function, a lognormal row is sampled every beta/12 in ln(intensity), at most every
0.1, over ``TAIL_SIGMAS`` beta either side of its median; OpenQuake interpolates linearly in the intensity
between the points (the 0.1: for a wide curve that linear interpolation, not the curve's bend, sets the error)."""

DISCRETE_ERROR = 5e-4
"""The largest difference between a lognormal and its linear interpolation on those points: measured 4.6e-4
over beta 0.02-2 (2e5 intensities per curve; ``tests/test_openquake.py`` checks it on every written row)."""

OPENQUAKE_FORMS = {
    "lognormal": "",
    "step": f" (a step: beta {STEP_BETA:g})",
    "from-lowest": " (a step at the lowest level studied)",
    "censored": "",  # said in full by censored_note
    "not-reached": " (a step at twice maxIML: never reached)",
}
"""What the XML comment before each function says about a row written as each kind (``KINDS``)."""

KINDS = {
    "lognormal": "a lognormal fit (median, beta)",
    "step": "a step at the median (beta = 0)",
    "from-lowest": "reached by most records already at the lowest level studied: a step there",
    "censored": "no median, but reached by some records (censored at the credible cap, or reached only at the "
                "highest level): the records' fractions at the levels up to the cap, held at the probability at the "
                "cap above it",
    "not-reached": "not reached within the studied range",
}
"""How a fragility row is written (``written_state``), and what it means."""

RECORDS_FRACTIONS = {
    "censored-at-cap": "censored at the credible cap {cap} (median above it)",
    "above-range": "median above the levels studied (reached only at the highest)",
}
"""The statuses of rows without a median that records reached, written as the records' fractions (the kind
``censored``), and what their comments call them."""


@dataclass(frozen=True)
class WrittenState:
    """One fragility row as the exchange files write it.

    ``kind`` (see ``KINDS``), the median [the dataset's intensity unit; NaN when not reached] and the
    dispersion beta [-] (0: a step).
    """

    kind: str
    median: float
    beta: float


def written_state(median: float, beta: float, status: str, lowest: float) -> WrittenState:
    """How one fragility row is written to the exchange files (the rules: the module docstring).

    Parameters
    ----------
    median : float
        The row's median [intensity unit]; NaN when the fit has none.
    beta : float
        The row's total dispersion [-]; 0 for a step.
    status : str
        The row's status (``rockfrag.fragility.STATUS``).
    lowest : float
        The lowest intensity level studied for the block [intensity unit].

    Returns
    -------
    WrittenState
        The kind, median and beta to write.
    """
    if np.isfinite(median) and np.isfinite(beta):
        return WrittenState("lognormal", median, beta) if beta > 0 else WrittenState("step", median, 0.0)
    if status == "below-range":
        return WrittenState("from-lowest", lowest, 0.0)
    if status in RECORDS_FRACTIONS:
        return WrittenState("censored", np.nan, np.nan)
    return WrittenState("not-reached", np.nan, np.nan)


@dataclass(frozen=True)
class CensoredRow:
    """What the records did for a row without a median (``RECORDS_FRACTIONS``), at the levels up to the cap.

    ``status`` the row's, ``levels`` [the dataset's intensity unit] with a known fraction, ``fractions`` [-]
    the records' fraction that reached the state at each, ``cap`` the credible cap [intensity unit], ``at_cap``
    (``probability_at_cap``, the fraction at the highest of the levels) with its bounds ``low`` and ``high`` and
    their ``confidence``.
    """

    status: str
    levels: np.ndarray
    fractions: np.ndarray
    cap: float
    at_cap: float
    low: float
    high: float
    confidence: str


def censored_row(cell: xr.Dataset, state: str) -> CensoredRow:
    """The records' fractions of one row of a cell (``dataset.sel(soil, block, model)``) without a median.

    Parameters
    ----------
    cell : xarray.Dataset
        One cell of the fragility dataset, with ``intensity``, ``empirical_fraction``, ``probability_at_cap``
        (and its bounds) and ``credible_max`` (absent: no cap).
    state : str
        The damage state.

    Returns
    -------
    CensoredRow
        The levels at or below the cap with a known fraction, their fractions and the probability at the cap.
    """
    cap = float(cell["credible_max"]) if "credible_max" in cell else np.inf
    levels = np.asarray(cell["intensity"].values, float)
    fractions = np.asarray(cell["empirical_fraction"].sel(damage_state=state).values, float)
    keep = (levels <= cap * (1 + 1e-9)) & np.isfinite(fractions)  # the same levels as the fits and the risk
    bound = cell["probability_at_cap_low"].attrs.get("long_name", "") if "probability_at_cap_low" in cell else ""
    confidence = re.search(r"\d+(\.\d+)?\s*%", bound)
    at_cap = {name: float(cell[name].sel(damage_state=state)) if name in cell else np.nan
              for name in ("probability_at_cap", "probability_at_cap_low", "probability_at_cap_high")}
    return CensoredRow(str(cell["status"].sel(damage_state=state).values), levels[keep], fractions[keep], cap,
                       at_cap["probability_at_cap"], at_cap["probability_at_cap_low"],
                       at_cap["probability_at_cap_high"], confidence.group(0).replace(" ", "") if confidence else "")


def censored_points(row: CensoredRow) -> tuple[np.ndarray, np.ndarray]:
    """The curve of a censored row as (intensity, probability) points, empty without a known fraction.

    0 below the lowest level (a rise over ``STEP_WIDTH`` below it), the records' fractions at the levels,
    linear between them; the reader holds the last value (the probability at the cap) above the last point
    (OpenQuake's discrete format).
    """
    if not row.levels.size:
        return np.array([]), np.array([])
    return (np.concatenate([[row.levels[0] * (1 - STEP_WIDTH)], row.levels]),
            np.concatenate([[0.0], row.fractions]))


def pelicun_points(row: CensoredRow) -> tuple[np.ndarray, np.ndarray]:
    """The censored row as the points of pelicun's ``multilinear_CDF`` of the capacity, empty as above.

    From 0 at the last point of ``censored_points`` whose running maximum is 0, strictly rising (the running
    maximum of the fractions, and ``PELICUN_RISE`` more where it repeats), then 1 at the capacity ``inf``
    (the probability not reached at the cap is never reached above it); 1 at the last level instead if the
    fractions reach 1 there.
    """
    x, y = censored_points(row)
    if not x.size:
        return np.array([]), np.array([])
    y = np.maximum.accumulate(y)
    start = int(np.flatnonzero(y == 0)[-1])
    points_x, points_y = [x[start]], [0.0]
    for level, fraction in zip(x[start + 1:], y[start + 1:]):
        value = max(fraction, points_y[-1] + PELICUN_RISE)
        if value >= 1 - 10 * PELICUN_RISE:  # certain from here on: the CDF ends at this level
            points_x.append(level)
            points_y.append(1.0)
            break
        points_x.append(level)
        points_y.append(value)
    if points_y[-1] < 1:
        points_x.append(np.inf)
        points_y.append(1.0)
    return np.array(points_x), np.array(points_y)


def censored_note(row: CensoredRow, unit: str, written: str) -> str:
    """What a censored row is, for the comments of both files: never "not reached"."""
    cap_level = f"{row.levels[-1]:.4g} {unit}" if row.levels.size else "the cap"
    interval = (f" ({row.confidence} interval {100 * row.low:.0f}-{100 * row.high:.0f} %)"
                if np.isfinite(row.low) and np.isfinite(row.high) else "")
    what = RECORDS_FRACTIONS.get(row.status, row.status).format(cap=f"{row.cap:.4g} {unit}")
    return (f"{what}: reached by {100 * row.at_cap:.0f} % of the records at {cap_level}{interval}; written as "
            f"{written}, held at {100 * row.at_cap:.0f} % above {cap_level} (assumed: no level above it is "
            "credible)")


def pelicun_id(block: str, soil: str, model: str) -> str:
    """The component ID of one block x soil x model in both files (pelicun splits IDs on '-', so '_' instead).

    Parameters
    ----------
    block, soil, model : str
        The cell's names.

    Returns
    -------
    str
        ``ROCK.<block>.<soil>.<model>`` with '-' and spaces replaced by '_'.
    """
    return ".".join(["ROCK", *(str(part).replace("-", "_").replace(" ", "_") for part in (block, soil, model))])


def intensity_unit_label(dataset: xr.Dataset) -> str:
    """The intensity unit as tables show it, from a fragility dataset's attributes.

    Parameters
    ----------
    dataset : xarray.Dataset
        A fragility dataset (``intensity_unit_label``, else ``intensity_unit`` in its attributes).

    Returns
    -------
    str
        "g", "m/s", ...
    """
    return dataset.attrs.get("intensity_unit_label") or unit_label(dataset.attrs.get("intensity_unit", ""))


def write_csv(table: pd.DataFrame, path: str | Path) -> None:
    """Write ``table`` to the CSV file ``path`` atomically (6 significant digits, no index).

    Parameters
    ----------
    table : pandas.DataFrame
        The table.
    path : str or pathlib.Path
        The file to write.

    Returns
    -------
    None
    """
    with atomic_path(path) as temporary:
        table.to_csv(temporary, index=False, float_format="%.6g")


SLIP_SUFFIX = ".SLIP"
"""The component ID of a cell's slip states: ``pelicun_id(...) + SLIP_SUFFIX`` (a family of its own)."""


def state_families(dataset: xr.Dataset) -> dict[str, list[str]]:
    """The damage states by family, each in order of severity: {"": rocking states, SLIP_SUFFIX: slip states}.

    A component's limit states must nest (each more severe one reached later), which the rocking and the slip
    states do not; so each family is a component (pelicun) or a file (OpenQuake) of its own. The family of a
    state is that of its EDP (``damage_state_edp``; rockfrag.damage_states.families_of).
    """
    states = [str(s) for s in dataset.damage_state.values]
    edps = dataset["damage_state_edp"].values if "damage_state_edp" in dataset.coords else ["uplifted"] * len(states)
    suffix = {"rocking": "", "slip": SLIP_SUFFIX}
    return {suffix[family]: [states[i] for i in members] for family, members in families_of(edps).items()}


def _applies(cell: xr.Dataset, states: list[str]) -> bool:
    """Whether a cell has rows of ``states`` (a tied cell's slip rows are ``not-applicable``)."""
    return any(str(cell["status"].sel(damage_state=s).values) != NOT_APPLICABLE for s in states)


def exchange_cells(dataset: xr.Dataset) -> list[tuple[str, str, str]]:
    """(soil, block, model) of every component, in the order both files list them.

    Parameters
    ----------
    dataset : xarray.Dataset
        The fragility dataset.

    Returns
    -------
    list of tuple of str
        Rows of the model "recommended" first; then the dataset's order (soil, then block, then model).

    Raises
    ------
    ConfigError
        Two cells that give the same ``pelicun_id``.
    """
    cells = [(str(soil), str(block), str(model)) for soil in dataset.soil.values for block in dataset.block.values
             for model in dataset.model.values]
    cells.sort(key=lambda cell: cell[2] != RECOMMENDED)  # stable: the rest keep their order
    seen: dict[str, tuple[str, str, str]] = {}
    for soil, block, model in cells:
        component = pelicun_id(block, soil, model)
        if component in seen:
            raise ConfigError("blocks/soils/models", f"names {seen[component]} and {(block, soil, model)} "
                              f"give the same component ID {component}; rename one")
        seen[component] = (block, soil, model)
    return cells


def _consumer_values(dataset: xr.Dataset, measure: Measure | None, values) -> np.ndarray:
    """``values`` in the dataset's intensity unit, expressed in the measure's display unit (g, m/s)."""
    values = np.asarray(values, float)
    if measure is None:
        return values
    try:
        return np.asarray(convert_units(values, dataset.attrs.get("intensity_unit", ""),
                                        measure.cf_units(display=True)), float)
    except ValueError:  # no unit, or one of another quantity: the values as the dataset has them
        return values


def _cell_notes(cell: xr.Dataset, state: str) -> str:
    """The row's status, and its dispersion parts when the dataset has them (comments only)."""
    status = str(cell["status"].sel(damage_state=state).values)
    parts = [f"{name} {float(cell[name].sel(damage_state=state)):.3g}"
             for name in ("beta_record_to_record", "beta_model") if name in cell
             and np.isfinite(float(cell[name].sel(damage_state=state)))]
    return status + (f" (beta is the total; {', '.join(parts)})" if parts else "")


# ---------------------------------------------------------------- pelicun damage-model parameters

def _pelicun_censored(dataset: xr.Dataset, measure: Measure | None, cell: xr.Dataset, state: str, unit: str,
                      note: str) -> tuple[str, float | str, str]:
    """The pelicun family, Theta_0 and comment of a row of the kind ``censored`` (``pelicun_points``)."""
    row = censored_row(cell, state)
    x, y = pelicun_points(row)
    if not x.size:  # no record's outcome known at a credible level (a fit needs some: not seen)
        return "deterministic", np.inf, note + (", no median and no record's fraction known up to the "
                                                "cap: written with the capacity inf")
    x = _consumer_values(dataset, measure, x)
    theta_0 = ",".join(f"{v:.8g}" for v in x) + "|" + ",".join(f"{v:.8g}" for v in y)
    note += ", " + censored_note(row, unit, "a multilinear_CDF through the records' fractions up to the cap, "
                                            "the rest at the capacity inf")
    held = y[-2] if np.isinf(x[-1]) else 1.0
    if abs(held - row.at_cap) > 10 * PELICUN_RISE:
        note += (f"; the fractions fall before the cap, and pelicun's curve must rise: it keeps the earlier "
                 f"{100 * held:.0f} % there")
    return "multilinear_CDF", theta_0, note


def pelicun_table(dataset: xr.Dataset, period: float | None = None) -> pd.DataFrame:
    """The pelicun damage-model table: one component per block x soil x model, LS1..LSn the damage states.

    ``Demand-Directional = 1``: the demand is the scaled component itself, so pelicun must not apply its
    non-directional factor (1.2 x the larger of two directions) to it. Every component is complete
    (``Incomplete = 0``) and computes: how each row is written is in the module docstring (a state not
    reached is left out where pelicun allows it, else it has the capacity ``inf``). The ``Comment`` column
    says what each LS is, its status and the studied range.

    Parameters
    ----------
    dataset : xarray.Dataset
        The fragility dataset (``fragility_dataset``).
    period : float, optional
        The Sa period [s], for measures that have one (it becomes part of pelicun's demand type).

    Returns
    -------
    pandas.DataFrame
        One row per component, in pelicun's damage-model column layout (medians in pelicun's unit: g for
        accelerations, m/s for velocities); empty, with an ``ExchangeWarning``, when pelicun has no demand type
        for the measure (``Measure.pelicun_demand`` is None).

    Raises
    ------
    ConfigError
        Two (block, soil, model) cells that map to the same component ID.
    """
    name = dataset.attrs.get("intensity_measure", "pga")
    measure = MEASURES.get(name)
    if measure is None or measure.pelicun_demand is None:  # pelicun 3.10 refuses an empty Demand-Type
        count = len(exchange_cells(dataset))
        warnings.warn(f"{PELICUN_FILE}: pelicun has no demand type for the measure {name!r}; its {count} rows "
                      "(block x soil x model) left out, no file written", ExchangeWarning, stacklevel=2)
        return pd.DataFrame()
    demand_type, demand_unit = measure.pelicun_demand
    if measure.uses_period and period:
        demand_type = f"{demand_type}|{period:g}"
    unit = intensity_unit_label(dataset)
    rows = []
    for (soil, block, model), (suffix, states) in ((c, f) for f in state_families(dataset).items()
                                                   for c in exchange_cells(dataset)):
        cell = dataset.sel(soil=soil, block=block, model=model)
        if not _applies(cell, states):
            continue
        low, high = float(cell.studied_im_min), float(cell.studied_im_max)
        written = [written_state(float(cell["median"].sel(damage_state=s)), float(cell["beta"].sel(damage_state=s)),
                                 str(cell["status"].sel(damage_state=s).values), low) for s in states]
        last = max((k for k, w in enumerate(written) if w.kind != "not-reached"), default=0)
        row = {"ID": pelicun_id(block, soil, model) + suffix, "Incomplete": 0, "Demand-Type": demand_type,
               "Demand-Unit": demand_unit, "Demand-Offset": 0, "Demand-Directional": 1}
        notes = [f"rockfrag {name} fragility of {block} on {soil}, model {model}, studied range "
                 f"{low:.4g}-{high:.4g} {unit}"]
        for level, (state, form) in enumerate(zip(states, written), start=1):
            median = float(_consumer_values(dataset, measure, form.median))
            family, theta_0, theta_1 = {"lognormal": ("lognormal", median, form.beta),
                                        "step": ("deterministic", median, np.nan),
                                        "from-lowest": ("deterministic", median, np.nan)}.get(
                form.kind, ("", np.nan, np.nan))
            note = f"LS{level} {state}: {_cell_notes(cell, state)}"
            if form.kind == "censored":
                family, theta_0, note = _pelicun_censored(dataset, measure, cell, state, unit, note)
            elif form.kind == "from-lowest":
                note += f", written as reached from the lowest level studied ({low:.4g} {unit})"
            elif form.kind == "not-reached" and level - 1 <= last:  # pelicun needs it: never reached
                family, theta_0 = "deterministic", np.inf
                note += ", written as never reached (capacity inf)"
            elif form.kind == "not-reached":
                note += ", left out (not reached)"
            notes.append(note)
            row.update({f"LS{level}-Family": family, f"LS{level}-Theta_0": theta_0, f"LS{level}-Theta_1": theta_1,
                        f"LS{level}-DamageStateWeights": ""})
        row["Comment"] = "; ".join(notes)
        rows.append(row)
    return pd.DataFrame(rows)


# ---------------------------------------------------------------- OpenQuake NRML fragility model

def openquake_imt(measure: str, period: float | None = None) -> str | None:
    """The OpenQuake intensity measure type of a study's measure ("PGA", "SA(0.5)"), from the registry.

    Parameters
    ----------
    measure : str
        The study's intensity measure (a ``rockfrag.measures.MEASURES`` name).
    period : float, optional
        The Sa period [s], for measures that have one.

    Returns
    -------
    str or None
        None when OpenQuake has no such measure, or the measure needs a period and none is given.
    """
    registered = MEASURES.get(measure)
    if registered is None or not registered.openquake_imt:
        return None
    if "(T)" not in registered.openquake_imt:
        return registered.openquake_imt
    if not period:
        return None
    text = f"{float(period):g}"
    return registered.openquake_imt.replace("(T)", f"({text}{'' if '.' in text or 'e' in text else '.0'})")


def openquake_limit_state(name: str) -> str:
    """A damage state's name as an OpenQuake limit state.

    Parameters
    ----------
    name : str
        The damage state ("rocking-0.2").

    Returns
    -------
    str
        The name with every character OpenQuake does not accept in a limit state (anything but letters,
        digits, '_', '-' and ':') replaced by '_': "rocking-0_2".
    """
    return re.sub(r"[^\w\-:]", "_", name)


def openquake_mean_stddev(median: float, beta: float) -> tuple[float, float]:
    """OpenQuake's (mean, standard deviation) of the intensity of a lognormal (median, beta).

    Parameters
    ----------
    median : float
        The median intensity.
    beta : float
        The standard deviation of its logarithm, > 0.

    Returns
    -------
    tuple of float
        mean = median exp(beta^2/2), stddev = mean sqrt(exp(beta^2) - 1).
    """
    mean = median * np.exp(beta ** 2 / 2)
    return float(mean), float(mean * np.sqrt(np.expm1(beta ** 2)))


def openquake_model(dataset: xr.Dataset, period: float | None = None,
                    family: str = "") -> ElementTree.ElementTree | None:
    """The NRML 0.5 ``fragilityModel``: one continuous lognormal function per block x soil x model.

    Its limit states are the damage states (``openquake_limit_state``); each function's ``imls`` carry the
    OpenQuake IMT of the study's measure and the block's studied range as minIML/maxIML, in OpenQuake's
    units (g for PGA and SA, cm/s for PGV). How each row is written: the module docstring. An XML comment
    before each function says what its limit states are.

    Parameters
    ----------
    dataset : xarray.Dataset
        The fragility dataset (``fragility_dataset``).
    period : float, optional
        The Sa period [s], for measures that have one.
    family : str
        The family of damage states (``state_families``): "" the rocking states, ``SLIP_SUFFIX`` the slip
        states (their own file: one model's functions share its limit states), written for the cells that
        slide.

    Returns
    -------
    xml.etree.ElementTree.ElementTree or None
        The document; None when OpenQuake has no intensity measure type for the study's measure, or no cell
        has states of the family.

    Raises
    ------
    ConfigError
        Two (block, soil, model) cells with the same component ID, or two damage states with the same
        OpenQuake name.
    """
    name = dataset.attrs.get("intensity_measure", "pga")
    imt = openquake_imt(name, period)
    if imt is None:
        return None
    measure = MEASURES[name]
    states = state_families(dataset).get(family, [])
    cells = [c for c in exchange_cells(dataset) if states and _applies(dataset.sel(soil=c[0], block=c[1],
                                                                                   model=c[2]), states)]
    if not cells:
        return None
    limit_states = [openquake_limit_state(s) for s in states]
    if len(set(limit_states)) < len(states):
        raise ConfigError("damage_states", f"{states} give clashing OpenQuake limit states {limit_states}; "
                          "rename one")
    unit = measure.display_unit if measure.openquake_factor == 1 else \
        f"{measure.openquake_factor:g} {measure.display_unit}"  # OpenQuake's unit: g, or cm/s for PGV
    root = ElementTree.Element("nrml", {"xmlns": NRML_NAMESPACE})
    model = ElementTree.SubElement(root, "fragilityModel",
                                   {"id": "rockfrag", "assetCategory": "buildings", "lossCategory": "structural"})
    renamed = ", ".join(f"{o} = {s}" for o, s in zip(limit_states, states) if o != s)
    ElementTree.SubElement(model, "description").text = (
        f"rockfrag fragility of rocking blocks in {imt} [{unit}]: one function per block x soil x model, with the "
        f"component ID of fragility_pelicun.csv (ROCK.block.soil.model). mean and stddev are those of the "
        f"intensity of a lognormal with the fitted median and total beta. A step (beta = 0) is a lognormal with "
        f"beta = {STEP_BETA:g}; a state most records reached already at the lowest level studied is a step at that "
        f"level; a state not reached within the studied range is a step at twice maxIML (never reached). "
        f"OpenQuake holds a function at its value at minIML (maxIML) below (above) them, so they are set "
        f"{TAIL_SIGMAS:g} beta beyond every curve and the studied range; the comment before each function gives "
        f"the studied range. A state censored at the credible cap (its fitted median above the cap) or reached "
        f"only at the highest level studied is the records' fractions at the levels studied up to the cap, held at "
        f"the probability at the cap above it (an assumption: no level above the cap is credible); a function with "
        f"such a state is discrete (P at its IMLs, linear between them), its other states sampled on its IMLs." +
        (f" Limit states renamed: {renamed}." if renamed else ""))
    ElementTree.SubElement(model, "limitStates").text = " ".join(limit_states)
    for soil, block, model_name in cells:
        cell = dataset.sel(soil=soil, block=block, model=model_name)
        low, high = (float(_consumer_values(dataset, measure, cell[v])) / measure.openquake_factor
                     for v in ("studied_im_min", "studied_im_max"))
        forms = [written_state(float(cell["median"].sel(damage_state=s)), float(cell["beta"].sel(damage_state=s)),
                               str(cell["status"].sel(damage_state=s).values), float(cell.studied_im_min))
                 for s in states]
        component = pelicun_id(block, soil, model_name) + family
        if any(form.kind == "censored" for form in forms):
            _discrete_function(model, dataset, measure, cell, states, forms, component, imt, unit,
                               f" {component}: {block} on {soil}, model {model_name}; studied range {low:.4g}-"
                               f"{high:.4g} {unit}; ")
            continue
        curves = [(float(_consumer_values(dataset, measure, f.median)) / measure.openquake_factor,
                   f.beta if f.kind == "lognormal" else STEP_BETA) for f in forms]
        spans = [(m * np.exp(-TAIL_SIGMAS * b), m * np.exp(TAIL_SIGMAS * b)) for m, b in curves if np.isfinite(m)]
        min_iml = min([low, *(span[0] for span in spans)])
        max_iml = max([high, *(span[1] for span in spans)])
        curves = [(m, b) if np.isfinite(m) else (2 * max_iml, STEP_BETA) for m, b in curves]
        notes = [f"{s}: {_cell_notes(cell, s)}{OPENQUAKE_FORMS[form.kind]}" for s, form in zip(states, forms)]
        model.append(ElementTree.Comment(
            f" {component}: {block} on {soil}, model {model_name}; studied range "
            f"{low:.4g}-{high:.4g} {unit}; " + "; ".join(notes) + " "))
        function = ElementTree.SubElement(model, "fragilityFunction", {
            "id": component, "format": "continuous", "shape": "logncdf"})
        # 1e-9 outward: the 10 digits written must not round the studied range's ends inside it
        ElementTree.SubElement(function, "imls", {"imt": imt, "minIML": f"{min_iml * (1 - 1e-9):.10g}",
                                                  "maxIML": f"{max_iml * (1 + 1e-9):.10g}"})
        for limit_state, (median, beta) in zip(limit_states, curves):
            mean, stddev = openquake_mean_stddev(median, beta)
            ElementTree.SubElement(function, "params", {"ls": limit_state, "mean": f"{mean:.10g}",
                                                        "stddev": f"{stddev:.10g}"})
    tree = ElementTree.ElementTree(root)
    ElementTree.indent(tree, space="  ")
    return tree


def discrete_curves(forms: list[WrittenState], censored: dict[int, tuple[np.ndarray, np.ndarray]],
                    studied: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """A function's limit states on one grid of intensities, for OpenQuake's discrete format.

    The rules: the module docstring.

    Parameters
    ----------
    forms : list of WrittenState
        How each row is written, medians in OpenQuake's unit.
    censored : dict
        Row index -> (intensities, probabilities) of each ``censored`` row (``censored_points``, in OpenQuake's
        unit).
    studied : tuple of float
        The studied range (lowest, highest level) in OpenQuake's unit: always on the grid.

    Returns
    -------
    imls : numpy.ndarray
        The grid, strictly rising and distinct at 10 significant digits (as the file writes them).
    poes : numpy.ndarray
        (row, iml) P(reaching the row's state | iml).
    """
    points = [np.asarray(studied, float)]
    for k, form in enumerate(forms):
        if form.kind == "lognormal":
            step = min(form.beta / DISCRETE_POINTS_PER_BETA, DISCRETE_MAX_SPACING)
            offsets = np.arange(-TAIL_SIGMAS * form.beta, TAIL_SIGMAS * form.beta + step / 2, step)
            points.append(form.median * np.exp(offsets))
        elif form.kind in ("step", "from-lowest"):
            points.append(form.median * np.array([1 - STEP_WIDTH, 1.0]))
        elif k in censored:
            points.append(censored[k][0])
    imls = np.unique(np.array([float(f"{v:.10g}") for v in np.concatenate(points) if np.isfinite(v) and v > 0]))
    poes = np.zeros((len(forms), imls.size))
    for k, form in enumerate(forms):
        if form.kind == "lognormal":
            poes[k] = norm.cdf(np.log(imls / form.median) / form.beta)
        elif form.kind in ("step", "from-lowest"):
            poes[k] = np.interp(imls, form.median * np.array([1 - STEP_WIDTH, 1.0]), [0.0, 1.0])
        elif k in censored and censored[k][0].size:
            x, y = censored[k]
            poes[k] = np.interp(imls, x, y, left=0.0, right=y[-1])  # held at the probability at the cap above
    return imls, poes


def _discrete_function(model: ElementTree.Element, dataset: xr.Dataset, measure: Measure, cell: xr.Dataset,
                       states: list[str], forms: list[WrittenState], component: str, imt: str, unit: str,
                       heading: str) -> None:
    """Append to ``model`` the discrete function of a cell with a censored row (``discrete_curves``)."""
    def oq(values):  # the dataset's intensities -> OpenQuake's unit
        return np.asarray(_consumer_values(dataset, measure, values), float) / measure.openquake_factor

    forms = [WrittenState(f.kind, float(oq(f.median)), f.beta) for f in forms]
    rows = {k: censored_row(cell, s) for k, (s, f) in enumerate(zip(states, forms)) if f.kind == "censored"}
    censored = {k: (oq(x), y) for k, (x, y) in ((k, censored_points(r)) for k, r in rows.items())}
    imls, poes = discrete_curves(forms, censored, (float(oq(cell.studied_im_min)), float(oq(cell.studied_im_max))))
    data_unit = intensity_unit_label(dataset)
    discrete_forms = {"lognormal": f" (the lognormal at IMLs every beta/{DISCRETE_POINTS_PER_BETA} over "
                                   f"{TAIL_SIGMAS:g} beta either side: within {DISCRETE_ERROR:g} of it between them)",
                      "step": " (a step)", "from-lowest": " (a step at the lowest level studied)",
                      "not-reached": " (0 at every IML: not reached)"}
    notes = []
    for k, (state, form) in enumerate(zip(states, forms)):
        note = f"{state}: {_cell_notes(cell, state)}"
        if form.kind == "censored":
            note += ", " + censored_note(rows[k], data_unit, "the records' fractions up to the cap, linear between "
                                         "levels, 0 below the lowest")
        else:
            note += discrete_forms[form.kind]
        notes.append(note)
    model.append(ElementTree.Comment(
        heading + "discrete: P(limit state) at the IMLs, linear between them (OpenQuake's interpolation), held at "
        "the last IML's value above it (risklib's FragilityFunctionDiscrete); " + "; ".join(notes) + " "))
    function = ElementTree.SubElement(model, "fragilityFunction", {"id": component, "format": "discrete"})
    ElementTree.SubElement(function, "imls", {"imt": imt}).text = " ".join(f"{v:.10g}" for v in imls)
    for state, row in zip(states, poes):
        ElementTree.SubElement(function, "poes", {"ls": openquake_limit_state(state)}).text = " ".join(
            f"{v:.8g}" for v in row)


def write_openquake(dataset: xr.Dataset, path: str | Path, period: float | None = None, family: str = "") -> bool:
    """Write ``openquake_model`` to ``path`` atomically (UTF-8 XML).

    Parameters
    ----------
    dataset : xarray.Dataset
        The fragility dataset.
    path : str or pathlib.Path
        The file to write.
    period : float, optional
        The Sa period [s], for measures that have one.

    Returns
    -------
    bool
        False (and nothing written, an older file at ``path`` removed) when OpenQuake has no intensity
        measure type for the study's measure.
    """
    tree = openquake_model(dataset, period, family)
    if tree is None:
        Path(path).unlink(missing_ok=True)
        return False
    with atomic_path(path) as temporary:
        tree.write(temporary, encoding="utf-8", xml_declaration=True)
    return True


def write_exchange_files(dataset: xr.Dataset, output: str | Path, period: float | None = None) -> list[Path]:
    """Write ``fragility_pelicun.csv`` and ``fragility_openquake.xml`` into ``output``.

    Parameters
    ----------
    dataset : xarray.Dataset
        The fragility dataset (``fragility_dataset``).
    output : str or pathlib.Path
        The output folder.
    period : float, optional
        The study's Sa period [s].

    Returns
    -------
    list of pathlib.Path
        The files written (no OpenQuake file for a measure OpenQuake does not have, e.g. AvgSa; no pelicun file
        for one pelicun does not have).

    Raises
    ------
    ConfigError
        Clashing component IDs or OpenQuake limit-state names.
    """
    output = Path(output)
    written = []
    table = pelicun_table(dataset, period)
    if table.empty:  # nothing pelicun can read: no file, and no older run's file left to be taken for this one's
        (output / PELICUN_FILE).unlink(missing_ok=True)
    else:
        write_csv(table, output / PELICUN_FILE)
        written.append(output / PELICUN_FILE)
    if write_openquake(dataset, output / OPENQUAKE_FILE, period):
        written.append(output / OPENQUAKE_FILE)
    if write_openquake(dataset, output / OPENQUAKE_SLIP_FILE, period, SLIP_SUFFIX):
        written.append(output / OPENQUAKE_SLIP_FILE)
    return written
