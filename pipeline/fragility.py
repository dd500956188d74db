"""pipeline.fragility - stage 8: the cube -> lognormal fragility functions per soil and damage state.

Input : the study cube (outcome, peak_angle_ratio over record x im_level x soil x block x model),
        the damage states (registry below, plus ``[damage_states.NAME]`` tables of the study file).
Output: ``reports/fragility.nc`` (median, beta, bootstrap confidence bounds, records, fit method and
        goodness of fit per soil x block x model x damage state; empirical exceedance fractions per
        level; the three-outcome probabilities) and CSV exports, including a pelicun fragility file.

Fits: maximum likelihood on the binomial counts over intensity levels (Baker 2015, Earthquake
Spectra 31(1)); for overturning also from the IDA capacities (first overturning level per record),
right-censored at the highest level for records that never overturn. Confidence bounds come from
resampling records (seeded). Ordered damage states must not cross: where independent fits would
cross inside the studied intensity range, the states are refitted jointly with a shared beta.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
import xarray as xr
from scipy.optimize import minimize
from scipy.special import log_ndtr, ndtr
from scipy.stats import chi2

from pipeline.cube import OUTCOME_FAILED, OUTCOME_NO_UPLIFT, OUTCOME_OVERTURNED, OUTCOME_ROCKING
from pipeline.errors import ConfigError
from pipeline.outputs import atomic_path


@dataclass(frozen=True)
class DamageState:
    """A limit state: ``edp`` >= ``threshold`` (overturning exceeds every rocking threshold)."""

    name: str
    edp: str  # "uplifted", "overturned", or a cube variable such as "peak_angle_ratio"
    threshold: float
    description: str


DAMAGE_STATES: dict[str, DamageState] = {}

DETERMINISTIC_BETA = 0.05
"""Fitted dispersions below this mark a deterministic threshold (a step), not a lognormal curve."""


def register_damage_state(state: DamageState) -> None:
    """Add a damage state; the registry order is the order of increasing severity."""
    DAMAGE_STATES[state.name] = state


register_damage_state(DamageState("uplift", "uplifted", 1.0, "rocking starts (the heel lifts off)"))
register_damage_state(DamageState("rocking-0.2", "peak_angle_ratio", 0.2, "theta_max/alpha >= 0.2"))
register_damage_state(DamageState("rocking-0.5", "peak_angle_ratio", 0.5, "theta_max/alpha >= 0.5"))
register_damage_state(DamageState("overturning", "overturned", 1.0, "the block overturns"))


def damage_states_from_config(raw: dict) -> list[DamageState]:
    """Defaults plus (or replaced by) the study's ``[damage_states.NAME]`` tables."""
    states = dict(DAMAGE_STATES)
    for name, spec in raw.get("damage_states", {}).items():
        edp = spec.get("edp", "peak_angle_ratio")
        if edp not in ("uplifted", "overturned", "peak_angle_ratio", "peak_angle", "peak_uplift", "n_impacts"):
            raise ConfigError(f"damage_states.{name}.edp", f"{edp!r}; allowed: uplifted, overturned, "
                              "peak_angle_ratio, peak_angle, peak_uplift, n_impacts")
        threshold = spec.get("threshold", 1.0)
        if not isinstance(threshold, (int, float)) or threshold <= 0:
            raise ConfigError(f"damage_states.{name}.threshold", f"{threshold!r}; allowed > 0")
        states[name] = DamageState(name, edp, float(threshold), spec.get("description", ""))
    order = {"uplifted": 0, "overturned": 2}
    return sorted(states.values(), key=lambda s: (order.get(s.edp, 1), s.threshold))


def exceedance(cube: xr.Dataset, state: DamageState) -> xr.DataArray:
    """1.0 where a run reached the damage state, 0.0 where not, NaN where the solver failed."""
    outcome = cube.outcome
    if state.edp == "uplifted":
        reached = outcome >= OUTCOME_ROCKING
    elif state.edp == "overturned":
        reached = outcome == OUTCOME_OVERTURNED
    else:
        reached = (cube[state.edp] >= state.threshold) | (outcome == OUTCOME_OVERTURNED)
    return reached.astype(float).where(outcome != OUTCOME_FAILED)


# ---------------------------------------------------------------- maximum-likelihood fits

def _negative_log_likelihood(params, log_im, exceed, total):
    log_median, log_beta = params
    z = (log_im - log_median) / np.exp(log_beta)
    return -np.sum(exceed * log_ndtr(z) + (total - exceed) * log_ndtr(-z))


def fit_binomial(im, exceed, total, beta_start=0.4):
    """Lognormal fragility (median [IM units], beta [-]) by MLE on counts per level (Baker 2015).

    NaN, NaN when the data cannot identify a curve (no exceedance, or exceedance everywhere).
    """
    im, exceed, total = (np.asarray(a, float) for a in (im, exceed, total))
    keep = total > 0
    im, exceed, total = im[keep], exceed[keep], total[keep]
    if exceed.sum() == 0 or np.all(exceed == total):
        return np.nan, np.nan
    fraction = exceed / total
    start = np.interp(0.5, np.maximum.accumulate(fraction), np.log(im)) if fraction.max() >= 0.5 \
        else np.log(im[-1]) + 0.5
    result = minimize(_negative_log_likelihood, x0=[start, np.log(beta_start)], args=(np.log(im), exceed, total),
                      method="L-BFGS-B", bounds=[(np.log(im[0]) - 5, np.log(im[-1]) + 5), (np.log(0.01), np.log(5.0))])
    return float(np.exp(result.x[0])), float(np.exp(result.x[1]))


def fit_censored_capacities(capacities, censor_at):
    """Lognormal fit of per-record capacities, right-censored at ``censor_at`` where NaN."""
    capacities = np.asarray(capacities, float)
    observed = capacities[np.isfinite(capacities)]
    n_censored = np.sum(~np.isfinite(capacities))
    if observed.size < 2:
        return np.nan, np.nan
    log_observed = np.log(observed)

    def negative(params):
        log_median, log_beta = params
        beta = np.exp(log_beta)
        z = (log_observed - log_median) / beta
        z_censor = (np.log(censor_at) - log_median) / beta
        return -(np.sum(-0.5 * z**2 - np.log(beta)) + n_censored * log_ndtr(-z_censor))

    start = [log_observed.mean(), np.log(max(log_observed.std(), 0.05))]
    result = minimize(negative, x0=start, method="L-BFGS-B",
                      bounds=[(log_observed.min() - 5, log_observed.max() + 10), (np.log(0.01), np.log(5.0))])
    return float(np.exp(result.x[0])), float(np.exp(result.x[1]))


def fit_shared_beta(im, exceed_by_state, total_by_state):
    """Joint MLE of one median per state and a common beta (non-crossing by construction)."""
    log_im = np.log(np.asarray(im, float))
    n = len(exceed_by_state)
    starts = [fit_binomial(im, e, t) for e, t in zip(exceed_by_state, total_by_state)]

    def negative(params):
        log_beta = params[-1]
        return sum(_negative_log_likelihood([params[i], log_beta], log_im, exceed_by_state[i], total_by_state[i])
                   for i in range(n))

    x0 = [np.log(m) for m, _ in starts] + [np.log(np.nanmean([b for _, b in starts]))]
    bounds = [(log_im[0] - 5, log_im[-1] + 5)] * n + [(np.log(0.01), np.log(5.0))]
    result = minimize(negative, x0=x0, method="L-BFGS-B", bounds=bounds)
    medians = np.maximum.accumulate(np.exp(result.x[:n]))  # ordered severity, ordered medians
    return medians, float(np.exp(result.x[-1]))


def lognormal_cdf(im, median, beta):
    return ndtr(np.log(np.asarray(im, float) / median) / beta)


def goodness_of_fit(im, exceed, total, median, beta):
    """(deviance p-value, max |fitted - empirical|) of a fitted curve against the counts."""
    if not np.isfinite(median):
        return np.nan, np.nan
    keep = total > 0
    im, exceed, total = im[keep], exceed[keep], total[keep]
    p = np.clip(lognormal_cdf(im, median, beta), 1e-12, 1 - 1e-12)
    with np.errstate(divide="ignore", invalid="ignore"):
        term1 = np.where(exceed > 0, exceed * np.log(exceed / (total * p)), 0.0)
        term2 = np.where(total - exceed > 0, (total - exceed) * np.log((total - exceed) / (total * (1 - p))), 0.0)
    deviance = 2 * np.sum(term1 + term2)
    dof = max(1, int(keep.sum()) - 2)
    return float(chi2.sf(deviance, dof)), float(np.max(np.abs(p - exceed / total)))


def curves_cross(im_grid, fits):
    """True if any less severe state's curve falls below a more severe one on the grid."""
    curves = [lognormal_cdf(im_grid, m, b) for m, b in fits if np.isfinite(m)]
    return any(np.any(lower < upper - 1e-9) for lower, upper in zip(curves, curves[1:]))


# ---------------------------------------------------------------- the whole cube

def fragility_dataset(cube: xr.Dataset, states=None, ida=None, n_bootstrap=100, seed=0,
                      confidence=0.90) -> xr.Dataset:
    """Fit every soil x block x model x damage state of a cube (see module docstring)."""
    states = states or list(DAMAGE_STATES.values())
    rng = np.random.default_rng(seed)
    levels = cube.im_level.values
    unit = cube.im_level.attrs.get("units", "")
    group_dims = ("soil", "block", "model")
    shape = tuple(cube.sizes[d] for d in group_dims) + (len(states),)
    names = ["median", "beta", "median_low", "median_high", "beta_low", "beta_high", "gof_p_value",
             "gof_max_error", "capacity_median", "capacity_beta"]
    out = {name: np.full(shape, np.nan) for name in names}
    method = np.full(shape, "mle-binomial", dtype=object)
    exceed_all = np.stack([exceedance(cube, s).transpose("record", "im_level", *group_dims).values
                           for s in states], axis=-1)  # (record, level, soil, block, model, state)
    fraction = np.nanmean(exceed_all, axis=0)
    grid = np.geomspace(levels[0], levels[-1], 200)
    n_records = cube.sizes["record"]
    first_overturn = None
    if ida is not None:
        first_overturn = ida.first_overturn_im.transpose("record", *group_dims).values
    tail = (1 - confidence) / 2
    for index in np.ndindex(*shape[:-1]):
        data = exceed_all[(slice(None), slice(None), *index)]  # (record, level, state)
        valid = np.isfinite(data)
        exceed = np.nansum(data, axis=0)
        total = valid.sum(axis=0).astype(float)
        fits = [fit_binomial(levels, exceed[:, s], total[:, s]) for s in range(len(states))]
        labels = ["mle-binomial" if np.isfinite(m) else "not-identifiable" for m, _ in fits]
        # A state reached at one intensity by every record (uplift under PGA scaling: g tan(alpha))
        # is a step, not a lognormal: keep it as a deterministic threshold, outside the ordering.
        for s, (median, beta) in enumerate(fits):
            if np.isfinite(beta) and beta < DETERMINISTIC_BETA:
                labels[s] = "deterministic-threshold"
        usable = [s for s in range(len(states)) if labels[s] == "mle-binomial"]
        if curves_cross(grid, [fits[s] for s in usable]):
            medians, beta = fit_shared_beta(levels, [exceed[:, s] for s in usable], [total[:, s] for s in usable])
            for s, median in zip(usable, medians):
                fits[s] = (median, beta)
                labels[s] = "mle-binomial-shared-beta"
        boot = np.full((n_bootstrap, len(states), 2), np.nan)
        for b in range(n_bootstrap):
            pick = rng.integers(0, n_records, n_records)
            sample = data[pick]
            e = np.nansum(sample, axis=0)
            t = np.isfinite(sample).sum(axis=0).astype(float)
            for s in range(len(states)):
                if np.isfinite(fits[s][0]):
                    boot[b, s] = fit_binomial(levels, e[:, s], t[:, s])
        for s, state in enumerate(states):
            median, beta = fits[s]
            key = (*index, s)
            out["median"][key], out["beta"][key] = median, beta
            method[key] = labels[s]
            if np.isfinite(median) and np.isfinite(boot[:, s, 0]).any():
                out["median_low"][key], out["median_high"][key] = np.nanquantile(boot[:, s, 0], [tail, 1 - tail])
                out["beta_low"][key], out["beta_high"][key] = np.nanquantile(boot[:, s, 1], [tail, 1 - tail])
            out["gof_p_value"][key], out["gof_max_error"][key] = goodness_of_fit(
                levels, exceed[:, s], total[:, s], median, beta)
            if state.edp == "overturned" and first_overturn is not None:
                out["capacity_median"][key], out["capacity_beta"][key] = fit_censored_capacities(
                    first_overturn[(slice(None), *index)], levels[-1])

    dims = (*group_dims, "damage_state")
    attrs = {
        "median": ("median intensity of the lognormal fragility (binomial MLE)", unit),
        "beta": ("lognormal dispersion beta (binomial MLE)", "1"),
        "median_low": (f"lower {confidence:.0%} bootstrap bound of the median (records resampled)", unit),
        "median_high": (f"upper {confidence:.0%} bootstrap bound of the median (records resampled)", unit),
        "beta_low": (f"lower {confidence:.0%} bootstrap bound of beta", "1"),
        "beta_high": (f"upper {confidence:.0%} bootstrap bound of beta", "1"),
        "gof_p_value": ("goodness of fit: deviance chi-square p-value of the binomial fit", "1"),
        "gof_max_error": ("goodness of fit: max |fitted - empirical| exceedance fraction", "1"),
        "capacity_median": ("median of the IDA overturning capacities (censored lognormal MLE)", unit),
        "capacity_beta": ("dispersion of the IDA overturning capacities (censored lognormal MLE)", "1"),
    }
    data_vars = {name: (dims, out[name], {"long_name": attrs[name][0], "units": attrs[name][1]}) for name in names}
    data_vars["fit_method"] = (dims, method.astype(str), {"long_name": "how the curve was fitted"})
    data_vars["n_records"] = ((), n_records, {"long_name": "number of records", "units": "1"})
    data_vars["empirical_fraction"] = (("im_level", *dims), fraction, {
        "long_name": "fraction of records reaching the damage state", "units": "1"})
    data_vars["outcome_probability"] = (("outcome_class", "im_level", *group_dims), three_outcomes(cube).values,
                                        {"long_name": "fraction of records in each outcome", "units": "1"})
    coords = {d: cube[d] for d in group_dims}
    coords.update({"im_level": cube.im_level, "damage_state": [s.name for s in states],
                   "damage_state_description": ("damage_state", [s.description for s in states]),
                   "outcome_class": ["no_uplift", "rocking", "overturned"]})
    dataset = xr.Dataset(data_vars, coords=coords)
    dataset.attrs = {"Conventions": "CF-1.12", "title": "rockfrag lognormal fragility functions",
                     "source": cube.attrs.get("source", ""), "config_hash": cube.attrs.get("config_hash", ""),
                     "intensity_measure": cube.attrs.get("intensity_measure", ""),
                     "bootstrap_samples": n_bootstrap, "bootstrap_seed": seed,
                     "references": "Baker (2015) Efficient analytical fragility function fitting using "
                                   "dynamic structural analysis. Earthquake Spectra 31(1)"}
    return dataset


def three_outcomes(cube: xr.Dataset) -> xr.DataArray:
    """P(no uplift), P(rocking without overturning), P(overturning) per level, from the cube."""
    valid = cube.outcome != OUTCOME_FAILED
    counts = [((cube.outcome == code) & valid).sum("record") for code in
              (OUTCOME_NO_UPLIFT, OUTCOME_ROCKING, OUTCOME_OVERTURNED)]
    total = valid.sum("record")
    stacked = xr.concat([c / total for c in counts], dim="outcome_class")
    return stacked.transpose("outcome_class", "im_level", "soil", "block", "model")


def write_fragility(dataset: xr.Dataset, path) -> None:
    encoding = {name: {"zlib": True, "complevel": 4} for name, var in dataset.data_vars.items()
                if var.dtype.kind == "f"}
    with atomic_path(path) as temporary:
        dataset.to_netcdf(temporary, engine="netcdf4", encoding=encoding)


def fragility_table(dataset: xr.Dataset) -> pd.DataFrame:
    """One row per soil x block x model x damage state."""
    columns = ["median", "beta", "median_low", "median_high", "beta_low", "beta_high", "gof_p_value",
               "gof_max_error", "capacity_median", "capacity_beta", "fit_method"]
    table = dataset[columns].to_dataframe().reset_index()
    table["im_units"] = dataset.im_level.attrs.get("units", "")
    table["n_records"] = int(dataset.n_records)
    keep = ["soil", "block", "model", "damage_state", *columns, "im_units", "n_records"]
    return table[keep]


PELICUN_DEMAND = {"pga": ("Peak Ground Acceleration", "g"), "sa": ("Spectral Acceleration", "g"),
                  "pgv": ("Peak Ground Velocity", "mps")}


def pelicun_table(dataset: xr.Dataset) -> pd.DataFrame:
    """pelicun fragility CSV: one component per soil/block/model, LS1..LSn = damage states."""
    demand_type, demand_unit = PELICUN_DEMAND.get(dataset.attrs.get("intensity_measure", "pga"), ("", ""))
    rows = []
    for soil in dataset.soil.values:
        for block in dataset.block.values:
            for model in dataset.model.values:
                row = {"ID": f"ROCK.{block}.{soil}.{model}", "Incomplete": 0, "Demand-Type": demand_type,
                       "Demand-Unit": demand_unit, "Demand-Offset": 0, "Demand-Directional": 0}
                cell = dataset.sel(soil=soil, block=block, model=model)
                level = 0
                for state in dataset.damage_state.values:
                    median = float(cell["median"].sel(damage_state=state))
                    if not np.isfinite(median):
                        row["Incomplete"] = 1
                        continue
                    level += 1
                    row[f"LS{level}-Family"] = "lognormal"
                    row[f"LS{level}-Theta_0"] = median
                    row[f"LS{level}-Theta_1"] = float(cell["beta"].sel(damage_state=state))
                    row[f"LS{level}-DamageStateWeights"] = ""
                rows.append(row)
    return pd.DataFrame(rows)


def write_csv(table: pd.DataFrame, path) -> None:
    with atomic_path(path) as temporary:
        table.to_csv(temporary, index=False, float_format="%.6g")


def fragility_stage(cube: xr.Dataset, ida: xr.Dataset, config, output):
    """Fit, add the risk, and write fragility.nc, fragility.csv, fragility_pelicun.csv and risk.csv."""
    from pathlib import Path

    from pipeline.risk import load_hazard, risk_dataset

    output = Path(output)
    states = damage_states_from_config(config.raw)
    dataset = fragility_dataset(cube, states=states, ida=ida, n_bootstrap=config.bootstrap, seed=config.seed,
                                confidence=config.confidence)
    hazard = load_hazard(config.hazard_file or None)
    risk = risk_dataset(dataset, hazard, config.design_life)
    combined = dataset.merge(risk)
    combined.attrs.update(dataset.attrs)
    combined.attrs.update(risk.attrs)
    write_fragility(combined, output / "fragility.nc")
    table = fragility_table(dataset)
    table = table.merge(risk.to_dataframe().reset_index(), on=["soil", "block", "model", "damage_state"])
    write_csv(table, output / "fragility.csv")
    write_csv(pelicun_table(dataset), output / "fragility_pelicun.csv")
    return combined, risk
