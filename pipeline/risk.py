"""rockfrag.risk - fragility x site hazard -> mean annual frequency and probability in a design life.

Input : lognormal fragility parameters (median [IM units], beta [-], beta = 0 a step) and the hazard curve of
        each soil's site for the study's intensity measure (rockfrag.site_hazard; one curve for every soil is
        also taken), read and checked by ``rockfrag.hazard``.
Output: lambda_DS = integral P(DS | im) |d lambda(im)| [1/yr] and P(DS in T years) = 1 - exp(-lambda_DS T), each
        row with its own soil's curve.

The hazard is interpolated log-log (``rockfrag.hazard.hazard_frequency``) and integrated on a fine
logarithmic grid.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike
from scipy.special import ndtr

from rockfrag.hazard import HazardCurve, hazard_frequency, hazard_of
from rockfrag.hazard import study_hazard as study_hazard  # re-exported: cli.py imports it from here


def annual_frequency(median: float, beta: float, hazard: HazardCurve | None, points: int = 4000,
                     lower: float | None = None) -> float:
    """Mean annual frequency of reaching a damage state with a lognormal fragility [1/yr].

    Parameters
    ----------
    median : float
        The fragility's median, in the hazard curve's intensity unit (g for PGA and Sa).
    beta : float
        Its lognormal dispersion [-]; 0 is a step at the median: lambda_DS = lambda(median).
    hazard : HazardCurve or None
        The site's hazard curve (``rockfrag.load_hazard``); None gives NaN.
    points : int, optional
        Points of the logarithmic integration grid over median x exp(+-8 beta) (default 4000).
    lower : float, optional
        Keep only the intensities from ``lower`` on (IM units): the part of lambda_DS above the lowest level at
        which a record reached the state (rockfrag.answer), the rest being the fitted curve's tail alone.

    Returns
    -------
    float
        lambda_DS = integral of P(DS | im) |d lambda(im)| [1/yr]; NaN without a hazard or a finite median and beta.
    """
    if hazard is None or not (np.isfinite(median) and np.isfinite(beta)):
        return np.nan
    if beta == 0:
        return float(hazard_frequency(hazard, median if lower is None else max(median, lower)))
    low = min(hazard.intensity[0], median * np.exp(-8 * beta))
    high = median * np.exp(8 * beta)
    if lower is not None:
        if lower >= high:
            return float(ndtr(np.log(lower / median) / beta) * hazard_frequency(hazard, lower))
        low = max(low, lower)
    grid = np.geomspace(low, high, points)
    frequency = hazard_frequency(hazard, grid)
    probability = ndtr(np.log(grid / median) / beta)
    # sum of P at the segment midpoints times the drop in lambda over the segment, plus the tail
    middle = 0.5 * (probability[1:] + probability[:-1])
    return float(np.sum(middle * (frequency[:-1] - frequency[1:])) + probability[-1] * frequency[-1])


def probability_in_life(frequency: ArrayLike, years: float) -> np.ndarray:
    """Poisson probability [-] of at least one occurrence in ``years`` at ``frequency`` [1/yr].

    Parameters
    ----------
    frequency : array_like
        Mean annual frequencies [1/yr] (``annual_frequency``).
    years : float
        The design life [years].

    Returns
    -------
    numpy.ndarray
        1 - exp(-frequency x years) [-], shaped as ``frequency``.
    """
    return 1.0 - np.exp(-np.asarray(frequency) * years)


def risk_dataset(fragility: xr.Dataset, hazard: HazardCurve | Mapping[str, HazardCurve] | None,
                 design_life: float = 50.0) -> xr.Dataset:
    """lambda_DS and P(DS in design_life) for every soil x block x model x damage state, each with its soil's hazard.

    Parameters
    ----------
    fragility : xarray.Dataset
        The fitted fragility (``rockfrag.fragility``): ``median`` [the measure's display unit, as the
        hazard curve] and ``beta`` [-] over (soil, block, model, damage_state); beta = 0 is a step.
    hazard : HazardCurve, mapping of soil to HazardCurve, or None
        The hazard curve of each soil's site (``rockfrag.site_hazard.study_site_hazards``), or one curve for every
        soil; None: no risk computed, every value NaN.
    design_life : float, optional
        Years of the probability in life (default 50).

    Returns
    -------
    xarray.Dataset
        ``annual_frequency`` [1/yr] and ``probability_in_life`` [-] on the dimensions of ``median``,
        with the attributes ``hazard_source``, ``design_life_years``, ``hazard_measure`` and ``hazard_component``;
        with a ``[hazard] site``, also the chosen site (in ``hazard_source`` and ``hazard_site_longitude_deg``,
        ``hazard_site_latitude_deg``, ``hazard_site_distance_km``, ``study_site_longitude_deg``/``_latitude_deg``).
    """
    dims = fragility["median"].dims
    if isinstance(hazard, Mapping) and "soil" not in dims:
        raise ValueError("a hazard curve per soil needs a fragility over soils")
    by_soil = "soil" in dims
    medians = np.moveaxis(fragility["median"].values, dims.index("soil"), 0) if by_soil \
        else fragility["median"].values[None]
    betas = np.moveaxis(fragility["beta"].values, dims.index("soil"), 0) if by_soil else fragility["beta"].values[None]
    soils = [str(s) for s in fragility["soil"].values] if by_soil else [None]
    rate = np.full(medians.shape, np.nan)
    for index, soil in enumerate(soils):
        curve = hazard_of(hazard, soil) if soil is not None else hazard
        if medians[index].size:
            rate[index] = np.vectorize(lambda m, b, c=curve: annual_frequency(m, b, c),
                                       otypes=[float])(medians[index], betas[index])
    rate = np.moveaxis(rate, 0, dims.index("soil")) if by_soil else rate[0]
    dataset = xr.Dataset({
        "annual_frequency": (dims, rate, {"long_name": "mean annual frequency of reaching the damage state",
                                          "units": "yr-1"}),
        "probability_in_life": (dims, probability_in_life(rate, design_life),
                                {"long_name": f"probability of reaching the damage state in {design_life:g} years",
                                 "units": "1"}),
    }, coords={d: fragility[d] for d in dims})
    first = (getattr(hazard, "first", None) or next(iter(hazard.values()), None)) if isinstance(hazard, Mapping) \
        else hazard
    source = getattr(hazard, "source", first.source if first is not None else "") if hazard is not None else \
        f"none: no hazard curve for {fragility.attrs.get('intensity_measure', '?')} (risk not computed)"
    dataset.attrs = {"hazard_source": source, "design_life_years": design_life,
                     "hazard_measure": first.label if first is not None else "",
                     "hazard_component": first.component if first is not None else ""}
    site = first.site if first is not None else None
    if site is not None:  # [hazard] site picked one site of a multi-site file: say which, and how far
        dataset.attrs.update({
            "hazard_source": f"{source}, {site.describe()}", "hazard_site_distance_km": site.distance_km,
            "hazard_site_longitude_deg": site.longitude, "hazard_site_latitude_deg": site.latitude,
            "study_site_longitude_deg": site.requested[0], "study_site_latitude_deg": site.requested[1]})
    return dataset
