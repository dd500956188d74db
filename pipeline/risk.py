"""pipeline.risk - fragility x site hazard -> mean annual frequency and probability in a design life.

Input : a hazard curve table (intensity in the study's IM units, mean annual frequency of exceedance
        [1/yr]; CSV as exported by USGS or OpenQuake, '#' comments allowed) and lognormal fragility
        parameters (median [IM units], beta [-]).
Output: lambda_DS = integral P(DS | im) |d lambda(im)| [1/yr] and P(DS in T years) = 1 - exp(-lambda_DS T).

The hazard is interpolated log-log and integrated on a fine logarithmic grid; beyond the last tabulated
intensity the curve is extended with the slope of its last segment (a power law), and below the first
point P(DS) is taken as the value there times the frequency (conservative).
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr
from scipy.special import ndtr

from pipeline.errors import ConfigError

EXAMPLE_HAZARD = "hazard_example.csv"
"""Shipped example: H(s) = 1e-4 s^-2.5 [1/yr], s = PGA [g] (Cornell et al. 2002 power-law form)."""


def load_hazard(path=None) -> pd.DataFrame:
    """A hazard curve as a DataFrame with columns ``intensity`` and ``annual_frequency`` (validated)."""
    if path is None or str(path) == "":
        source = files("pipeline").joinpath(EXAMPLE_HAZARD)
        name = f"pipeline/{EXAMPLE_HAZARD} (example, not site-specific)"
    else:
        source, name = Path(path), str(path)
        if not source.is_file():
            raise ConfigError("hazard.file", "file not found", name)
    with source.open() as handle:
        table = pd.read_csv(handle, comment="#")
    if table.shape[1] < 2:
        raise ConfigError("hazard.file", "expected two columns: intensity, annual frequency of exceedance", name)
    table = table.iloc[:, :2].astype(float)
    table.columns = ["intensity", "annual_frequency"]
    if (table <= 0).any().any() or not table["intensity"].is_monotonic_increasing:
        raise ConfigError("hazard.file", "intensities must increase and all values must be > 0", name)
    if not table["annual_frequency"].is_monotonic_decreasing:
        raise ConfigError("hazard.file", "annual frequency of exceedance must decrease with intensity", name)
    table.attrs["source"] = name
    return table


def hazard_frequency(hazard: pd.DataFrame, intensity):
    """lambda(im) [1/yr], log-log interpolation, power-law extrapolation at both ends."""
    x = np.log(hazard["intensity"].to_numpy())
    y = np.log(hazard["annual_frequency"].to_numpy())
    log_im = np.log(np.asarray(intensity, float))
    values = np.interp(log_im, x, y)
    slope_high = (y[-1] - y[-2]) / (x[-1] - x[-2])
    slope_low = (y[1] - y[0]) / (x[1] - x[0])
    values = np.where(log_im > x[-1], y[-1] + slope_high * (log_im - x[-1]), values)
    values = np.where(log_im < x[0], y[0] + slope_low * (log_im - x[0]), values)
    return np.exp(values)


def annual_frequency(median, beta, hazard: pd.DataFrame, points=4000) -> float:
    """Mean annual frequency of reaching a damage state with a lognormal fragility [1/yr]."""
    if not (np.isfinite(median) and np.isfinite(beta)):
        return np.nan
    beta = max(beta, 1e-3)
    low = min(hazard["intensity"].iloc[0], median * np.exp(-8 * beta))
    high = median * np.exp(8 * beta)
    grid = np.geomspace(low, high, points)
    frequency = hazard_frequency(hazard, grid)
    probability = ndtr(np.log(grid / median) / beta)
    # sum of P at the segment midpoints times the drop in lambda over the segment, plus the tail
    middle = 0.5 * (probability[1:] + probability[:-1])
    return float(np.sum(middle * (frequency[:-1] - frequency[1:])) + probability[-1] * frequency[-1])


def probability_in_life(frequency, years):
    """Poisson probability of at least one occurrence in ``years``."""
    return 1.0 - np.exp(-np.asarray(frequency) * years)


def risk_dataset(fragility: xr.Dataset, hazard: pd.DataFrame, design_life=50.0) -> xr.Dataset:
    """lambda_DS and P(DS in design_life) for every soil x block x model x damage state."""
    medians = fragility["median"].values
    betas = fragility["beta"].values
    rate = np.vectorize(lambda m, b: annual_frequency(m, b, hazard))(medians, betas) if medians.size else medians
    dims = fragility["median"].dims
    dataset = xr.Dataset({
        "annual_frequency": (dims, rate, {"long_name": "mean annual frequency of reaching the damage state",
                                          "units": "yr-1"}),
        "probability_in_life": (dims, probability_in_life(rate, design_life),
                                {"long_name": f"probability of reaching the damage state in {design_life:g} years",
                                 "units": "1"}),
    }, coords={d: fragility[d] for d in dims})
    dataset.attrs = {"hazard_source": hazard.attrs.get("source", ""), "design_life_years": design_life}
    return dataset
