"""rockfrag.exchange - stage 8b: fragility dataset -> files for downstream tools.

Input : the fragility dataset (``rockfrag.fragility.fragility_dataset``: ``median`` and ``beta`` per
        soil x block x model x damage state, the row's ``status``, the block's studied range, the intensity
        measure and unit in its attributes; optional ``beta_model``) and the study's Sa period [s].
Output: ``fragility_pelicun.csv``, pelicun 3.x damage-model parameters (``pelicun_table``), and
        ``fragility_openquake.xml``, an OpenQuake NRML 0.5 ``fragilityModel`` of continuous lognormal
        functions (``openquake_model``); ``write_exchange_files`` writes both beside ``fragility.csv``.

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
- ``not-reached`` and ``above-range`` (no record, or a few only at the highest level): not reached. pelicun
  leaves the limit state out (empty family and parameters; it skips such a state). It cannot skip the
  first limit state of a component (its capacity anchors the others: an IndexError) nor all of them (a
  KeyError), so a state it needs is written ``deterministic`` with the capacity ``inf``: never reached.
  OpenQuake needs every limit state of a function: a step at twice ``maxIML``.

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

OPENQUAKE_FORMS = {
    "lognormal": "",
    "step": f" (a step: beta {STEP_BETA:g})",
    "from-lowest": " (a step at the lowest level studied)",
    "not-reached": " (a step at twice maxIML: never reached)",
}
"""What the XML comment before each function says about a row written as each kind (``KINDS``)."""

KINDS = {
    "lognormal": "a lognormal fit (median, beta)",
    "step": "a step at the median (beta = 0)",
    "from-lowest": "reached by most records already at the lowest level studied: a step there",
    "not-reached": "not reached within the studied range",
}
"""How a fragility row is written (``written_state``), and what it means."""


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
    return WrittenState("not-reached", np.nan, np.nan)


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
            if form.kind == "from-lowest":
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
        f"the studied range." + (f" Limit states renamed: {renamed}." if renamed else ""))
    ElementTree.SubElement(model, "limitStates").text = " ".join(limit_states)
    for soil, block, model_name in cells:
        cell = dataset.sel(soil=soil, block=block, model=model_name)
        low, high = (float(_consumer_values(dataset, measure, cell[v])) / measure.openquake_factor
                     for v in ("studied_im_min", "studied_im_max"))
        forms = [written_state(float(cell["median"].sel(damage_state=s)), float(cell["beta"].sel(damage_state=s)),
                               str(cell["status"].sel(damage_state=s).values), float(cell.studied_im_min))
                 for s in states]
        curves = [(float(_consumer_values(dataset, measure, f.median)) / measure.openquake_factor,
                   f.beta if f.kind == "lognormal" else STEP_BETA) for f in forms]
        spans = [(m * np.exp(-TAIL_SIGMAS * b), m * np.exp(TAIL_SIGMAS * b)) for m, b in curves if np.isfinite(m)]
        min_iml = min([low, *(span[0] for span in spans)])
        max_iml = max([high, *(span[1] for span in spans)])
        curves = [(m, b) if np.isfinite(m) else (2 * max_iml, STEP_BETA) for m, b in curves]
        notes = [f"{s}: {_cell_notes(cell, s)}{OPENQUAKE_FORMS[form.kind]}" for s, form in zip(states, forms)]
        model.append(ElementTree.Comment(
            f" {pelicun_id(block, soil, model_name) + family}: {block} on {soil}, model {model_name}; studied range "
            f"{low:.4g}-{high:.4g} {unit}; " + "; ".join(notes) + " "))
        function = ElementTree.SubElement(model, "fragilityFunction", {
            "id": pelicun_id(block, soil, model_name) + family, "format": "continuous", "shape": "logncdf"})
        ElementTree.SubElement(function, "imls", {"imt": imt, "minIML": f"{min_iml:.10g}",
                                                  "maxIML": f"{max_iml:.10g}"})
        for limit_state, (median, beta) in zip(limit_states, curves):
            mean, stddev = openquake_mean_stddev(median, beta)
            ElementTree.SubElement(function, "params", {"ls": limit_state, "mean": f"{mean:.10g}",
                                                        "stddev": f"{stddev:.10g}"})
    tree = ElementTree.ElementTree(root)
    ElementTree.indent(tree, space="  ")
    return tree


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
