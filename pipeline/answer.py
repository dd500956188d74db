"""pipeline.answer - the answer of a study in the terminal: overturning per block and soil.

Input : the fragility dataset (``fragility.nc``, with the risk variables of pipeline.risk merged in, as
        ``fragility_stage`` returns and writes it) and the paths of the main outputs.
Output: a short text table, one row per block and soil, that ``rockfrag fragility`` prints at its end
        (``--quiet`` suppresses it): the overturning median of the answer model with its bootstrap
        bounds and beta, the probability of overturning in the design life when a hazard curve was
        used, and where the full results are.

The answer model is the first of ``ANSWER_MODELS`` the study ran: ``winkler``, the admissible
tensionless bed, until a recommended model exists. The median is the fragility's own (the lognormal
MLE over the stripes, ``median`` in fragility.nc and fragility.csv). Accelerations are shown in g,
whatever unit the file states them in; other measures keep their unit.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import xarray as xr

from pipeline.hazard import EXAMPLE_HAZARD
from pipeline.units import STANDARD_GRAVITY

ANSWER_MODELS = ("winkler", "ssi", "ssi-paper", "housner")
"""Models the answer is given for, in order of preference: the first one the study ran is used."""

ANSWER_STATE = "overturning"
"""The damage state of the answer (pipeline.fragility's overturning state)."""

_IN_M_S2 = {"g": STANDARD_GRAVITY, "m s-2": 1.0, "m/s^2": 1.0, "m/s2": 1.0, "m/s**2": 1.0}
"""Acceleration units a result file may state, as m/s^2 per unit (UDUNITS spelling or rockfrag's)."""

_STATUS_NOTES = {
    "extrapolated": "median outside the studied levels",
    "separated": "step between two levels (beta 0)",
    "above-range": "reached only at the highest level",
    "not-reached": "no record overturned",
    "below-range": "most records overturn at the lowest level",
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
        ``fragility.nc`` as written by ``pipeline.fragility.fragility_stage`` (risk variables optional).

    Returns
    -------
    list of dict
        Keys block, soil, median, median_low, median_high, beta, probability (NaN without a hazard
        curve), status, studied_min, studied_max; intensities in the unit of ``display_scale``.
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
            rows.append({"block": str(block), "soil": str(soil), **value, "beta": float(cell["beta"]),
                         "probability": probability, "status": str(cell["status"].values),
                         "studied_min": float(fragility.studied_im_min.sel(block=block)) * scale,
                         "studied_max": float(fragility.studied_im_max.sel(block=block)) * scale})
    return rows


def _median_cell(row: dict) -> str:
    if row["status"] in ("not-reached", "above-range"):
        return f"> {_number(row['studied_max'])}"
    if row["status"] == "below-range":
        return f"< {_number(row['studied_min'])}"
    return _number(row["median"])


def answer_table(fragility: xr.Dataset, outputs: Sequence[Path | str] = ()) -> str:
    """The answer as text: a heading, one line per block and soil, notes and the output paths.

    Parameters
    ----------
    fragility : xarray.Dataset
        ``fragility.nc`` as written by ``pipeline.fragility.fragility_stage``.
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
        line += [_STATUS_NOTES.get(row["status"], "")]
        table.append(line)
    widths = [max(len(str(cells[i])) for cells in [header, *table]) for i in range(len(header))]
    lines = [f"Overturning, model {model} ({int(fragility.n_records)} records): lognormal median {measure} in "
             f"{unit}, {confidence} bootstrap bounds of the median, dispersion beta"]
    for cells in [header, *table]:
        lines.append("  ".join(str(cell).ljust(width) for cell, width in zip(cells, widths)).rstrip())
    if with_risk:
        lines.append(f"P: probability of overturning in {life:g} years with the hazard curve {hazard}"
                     + (": set your site's as [hazard] file" if example else ""))
    if outputs:
        lines.append("Results: " + ", ".join(str(path) for path in outputs))
    return "\n".join(lines)


__all__ = ["ANSWER_MODELS", "ANSWER_STATE", "answer_model", "answer_rows", "answer_table", "display_scale"]
