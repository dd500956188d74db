"""rockfrag.records_report - the ``rockfrag records`` stage: record table and per-record figures.

Input : loaded ``Record`` objects and the processing recipe.
Output: a pandas table of catalogue metadata and intensity measures of the processed records
        (``reports/records.csv``: every record measure of the registry, an installed plugin's included),
        and optionally a PNG per record: raw vs processed acceleration,
        velocity and displacement, and the 5%-damped response spectrum, all labelled with units.

Each record is one component: the table's ``group`` numbers the records of one station and event
(``rockfrag.records.group_components``, counted from 1 in order of appearance) and ``axis`` says which
component a row is (``H1``, ``H2``, ``Z`` for the vertical), so the PGA of each component of a
three-component record reads off its rows.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd
from tqdm import tqdm

from rockfrag.errors import RecordError
from rockfrag.measures import intensity_measures, record_columns, response_spectrum
from rockfrag.outputs import atomic_path
from rockfrag.processing import integrate, process_record
from rockfrag.records import component_labels
from rockfrag.units import STANDARD_GRAVITY


def _table_columns() -> dict[str, str]:
    """Column -> heading of the table ``rockfrag records`` prints: the group, the axis, then every record measure.

    The measures are the registry's (``rockfrag.measures.record_columns``), headed by their label and SI unit;
    PGA is given in g too.
    """
    columns = {"group": "group", "axis": "axis"}
    for key, (measure, options) in record_columns().items():
        columns[key] = f"{measure.words or measure.short_label(**options)} [{measure.si_unit}]"
        if measure.name == "pga":
            columns["pga_g"] = "PGA [g]"
    return columns


TABLE_COLUMNS = _table_columns()
"""Column -> heading of the printed table (the registered measures at the time the module is imported)."""


def measures_row(raw, processed, group: int | None = None, axis: str | None = None) -> dict:
    """One table row: metadata, component, record length and the processed record's intensity measures.

    Parameters
    ----------
    raw, processed : Record
        The record as read and as processed.
    group : int, optional
        Number of the record's station-and-event group (``component_labels``).
    axis : str, optional
        The record's component in its group: ``H1``, ``H2``, ``Z``; ``raw.component`` if omitted.

    Returns
    -------
    dict
        Catalogue metadata, ``group``, ``axis``, ``orientation`` and ``azimuth_deg``, npts, dt [s],
        duration [s], the intensity measures (SI), PGA [g], the raw PGA [g], QA flags and the file.
    """
    measures = intensity_measures(processed.acceleration, processed.dt)
    row = {key: raw.metadata.get(key) for key in ("id", "event", "year", "magnitude", "station",
                                                   "component", "sets")}
    row.update({"group": group, "axis": axis or raw.component,
                "orientation": raw.metadata.get("orientation", "horizontal"),
                "azimuth_deg": raw.metadata.get("azimuth_deg")})
    row.update({"npts": processed.trace.stats.npts, "dt_s": processed.dt,
                "duration_s": processed.duration})
    row.update(measures)
    row["pga_g"] = measures["pga_m_s2"] / STANDARD_GRAVITY  # pga is a shipped measure (never a plugin's)
    row["raw_pga_g"] = float(np.max(np.abs(raw.acceleration))) / STANDARD_GRAVITY
    row["qa_flags"] = "; ".join(processed.trace.stats.get("qa", []))
    row["file"] = raw.metadata.get("file")
    return row


def write_table(rows: list[dict], path: str | os.PathLike) -> pd.DataFrame:
    """Write the rows of ``measures_row`` as ``path`` (CSV, 6 significant digits); returns the table."""
    table = pd.DataFrame(rows)
    with atomic_path(path) as temporary:
        table.to_csv(temporary, index=False, float_format="%.6g")
    return table


def plot_record(raw, processed, path):
    """PNG of raw vs processed acceleration, velocity, displacement and the 5% spectrum."""
    import matplotlib  # lazy: the records stage runs without matplotlib unless it plots

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(4, 1, figsize=(9, 10), constrained_layout=True)
    for record, label, style in ((raw, "raw (as published)", dict(color="0.6", lw=0.8)),
                                 (processed, "processed", dict(color="C0", lw=0.8))):
        time = np.arange(record.trace.stats.npts) * record.dt
        velocity, displacement = integrate(record.acceleration, record.dt)
        axes[0].plot(time, record.acceleration, label=label, **style)
        axes[1].plot(time, velocity, label=label, **style)
        axes[2].plot(time, displacement, label=label, **style)
    spectrum = response_spectrum(processed.acceleration, processed.dt)
    axes[3].loglog(spectrum["period"], spectrum["sa"], color="C0", label="Sa, 5% damping")
    axes[3].loglog(spectrum["period"], spectrum["psa"], color="C1", ls="--", label="PSa = ω²·Sd")
    for axis, ylabel in zip(axes[:3], ("acceleration [m/s²]", "velocity [m/s]", "displacement [m]")):
        axis.set_xlabel("time [s]")
        axis.set_ylabel(ylabel)
        axis.grid(alpha=0.3)
        axis.legend(loc="upper right", fontsize=8)
    axes[3].set_xlabel("period T [s]")
    axes[3].set_ylabel("spectral acceleration [m/s²]")
    axes[3].grid(alpha=0.3, which="both")
    axes[3].legend(fontsize=8)
    meta = raw.metadata
    pga_g = np.max(np.abs(processed.acceleration)) / STANDARD_GRAVITY
    figure.suptitle(f"{raw.id}: {meta.get('event', '')}, {meta.get('station', '')} "
                    f"{meta.get('component', '')} (PGA {pga_g:.3f} g)")
    with atomic_path(path) as temporary:
        figure.savefig(temporary, dpi=110, format="png")
    plt.close(figure)


def records_stage(records, recipe, output_dir, plot=False, progress=True, failures=None):
    """Process each record, tabulate its measures and component, optionally plot it; returns (table, png paths).

    A record that cannot be processed is left out; its ``RecordError`` is appended to ``failures``
    (raised if ``failures`` is None).
    """
    output_dir = Path(output_dir)
    records = list(records)
    rows, pngs = [], []
    labels = dict(zip((id(record) for record in records), component_labels(records)))
    for raw in tqdm(records, desc="records", unit="rec", disable=not progress):
        try:
            processed = process_record(raw, recipe)
        except RecordError as error:
            if failures is None:
                raise
            failures.append(error)
            continue
        rows.append(measures_row(raw, processed, *labels[id(raw)]))
        if plot:
            png = output_dir / "records" / (raw.id.replace("/", "_") + ".png")
            plot_record(raw, processed, png)
            pngs.append(png)
    table = write_table(rows, output_dir / "records.csv")
    return table, pngs
