"""rockfrag.site_hazard - the hazard curve of every soil of a study: read per soil, or amplified from one site.

Input : the study's ``[hazard]`` (rockfrag.config): either one hazard curve for a reference site of Vs30
        ``reference_vs30`` [m/s] (the shipped example for a PGA study without a file), or one curve per soil or
        site class (``file = { clay = "...", D = "..." }``); each soil's site Vs30 [m/s] (rockfrag.soils) and the
        spread of ln Vs30 ``vs30_sigma`` [-]; the study's intensity measure (and period, blocks for the
        block-normalised measures).
Output: ``SiteHazards``, soil name -> ``HazardCurve`` of that soil's site (annual frequency of exceedance [1/yr]
        over intensity in the measure's unit), which rockfrag.risk and rockfrag.answer use soil by soil; and
        ``site_hazard_dataset``: the same curves on one intensity grid, ``site_hazard(soil, hazard_intensity)``
        [1/yr], with each soil's Vs30 and class, for fragility.nc.

A soil whose site is the reference site (a Vs30 equal to ``reference_vs30``, or none stated, as the steel deck)
keeps the reference curve as it is. Any other soil's curve is the reference curve carried through the NGA-West2
site term with its Vs30 dispersion by convolution (rockfrag.site_amplification), tabulated from a quarter of the
reference curve's lowest intensity to four times its highest (the site term's factors lie between 0.33 and 5.6
over its periods and Vs30 range); beyond, as for any curve, its end slopes extend it (rockfrag.hazard).
"""

from __future__ import annotations

import inspect
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace

import numpy as np
import xarray as xr

from rockfrag.errors import ConfigError
from rockfrag.hazard import HazardCurve, hazard_for, hazard_frequency, soil_file, warn_far_site
from rockfrag.measures import MEASURES, average_spectral_acceleration, avgsa_range, udunits
from rockfrag.site_amplification import (
    REFERENCE_VS30,
    ROCK_PGA_LIMIT,
    SCENARIO,
    VS30_SIGMA,
    SiteAmplification,
    amplification,
    clip_vs30,
    convolve_hazard,
)
from rockfrag.units import STANDARD_GRAVITY

GRID_POINTS = 241
"""Intensities of the site-hazard grid (log-spaced): 30 per factor of 2 over a factor of 16 x the curve's span."""
ROCK_STEP = 0.01
"""Step of ln(rock intensity) in the convolution [-]: its error is second order in it (below 1e-4 on a power law)."""
CHECK_FREQUENCY = 1.0 / 2475.0
"""Annual frequency [1/yr] at which the reference curve's rock PGA is compared with ``ROCK_PGA_LIMIT``: above it
at 2% in 50 years, the held nonlinear term shapes the answer's return periods and the study warns."""
AVGSA_PERIODS = inspect.signature(average_spectral_acceleration).parameters["count"].default
"""Periods AvgSa averages (rockfrag.measures.average_spectral_acceleration's count), log-spaced over its range."""


class SiteHazardWarning(UserWarning):
    """The reference curve reaches rock PGAs above the site term's data at the return periods of the answer."""


@dataclass(frozen=True)
class SiteHazards(Mapping):
    """Soil name -> the ``HazardCurve`` of that soil's site.

    Attributes
    ----------
    curves : dict of str to HazardCurve
        One per soil of the study, in the study's order.
    reference : HazardCurve or None
        The reference-site curve that was amplified; None when the study gives a curve per soil.
    reference_vs30 : float or None
        Vs30 of the reference site [m/s]; None with a curve per soil.
    how : dict of str to str
        Per soil, how its curve was made, in words.
    """

    curves: dict[str, HazardCurve]
    reference: HazardCurve | None = None
    reference_vs30: float | None = None
    how: dict[str, str] = field(default_factory=dict)

    def __getitem__(self, soil: str) -> HazardCurve:
        """The curve of ``soil``'s site."""
        return self.curves[soil]

    def __iter__(self) -> Iterator[str]:
        """The soils, in the study's order."""
        return iter(self.curves)

    def __len__(self) -> int:
        """The number of soils."""
        return len(self.curves)

    @property
    def first(self) -> HazardCurve:
        """The reference curve, else the first soil's: what a per-block statement of the hazard shows."""
        return self.reference if self.reference is not None else next(iter(self.curves.values()))

    @property
    def component(self) -> str:
        """The horizontal-component definition shared by every curve (``rockfrag.hazard.COMPONENTS``)."""
        return self.first.component

    @property
    def source(self) -> str:
        """The hazard in words: the reference file and how the soils' curves follow, or the file of each soil."""
        if self.reference is not None:
            return (f"{self.reference.source} (reference site, Vs30 {self.reference_vs30:g} m/s), carried to each "
                    "soil's site by the NGA-West2 site term (BSSA14)")
        return "per soil: " + "; ".join(f"{soil} {curve.source}" for soil, curve in self.curves.items())


def _to_base(config, measure: str) -> float:
    """The study's measure in g (PGV: m/s) per unit: 1, or the blocks' shared constant of a block-normalised one."""
    if measure not in ("pga_ratio", "pgv_ratio"):
        return 1.0
    constants = {round(block.uplift_acceleration() / (block.p() if measure == "pgv_ratio" else STANDARD_GRAVITY), 12)
                 for block in config.blocks}
    if len(constants) != 1:
        raise ConfigError("hazard.file", f"one hazard curve of {measure} is one block's (the measure divides by each "
                          "block's own constant), and the study's blocks differ; give a curve per soil for a study "
                          "of one block, or study pga or pgv", config.source)
    return constants.pop()


def _periods(config) -> tuple[float, ...]:
    if config.measure == "sa":
        return (float(config.period),)
    if config.measure == "avgsa":
        return tuple(float(t) for t in np.geomspace(*avgsa_range(config.measure_options), AVGSA_PERIODS))
    return ()


def study_amplification(config, vs30: float, who: str) -> SiteAmplification:
    """The site term of the study's measure from its reference site to a site of ``vs30`` [m/s] (``who`` is warned of).

    Raises
    ------
    ConfigError
        Field ``hazard.file``: the measure has no site term here (its period outside 0.01-10 s, a measure other
        than pga, pgv, sa, avgsa, pga_ratio, pgv_ratio), or blocks that differ under a block-normalised measure.
    """
    reference = float(getattr(config, "reference_vs30", REFERENCE_VS30))
    try:
        return amplification(config.measure, clip_vs30(vs30, who),
                             clip_vs30(reference, "the hazard's reference site ([hazard] reference_vs30)"),
                             float(getattr(config, "vs30_sigma", VS30_SIGMA)), _periods(config),
                             _to_base(config, config.measure), tuple(getattr(config, "scenario", SCENARIO)))
    except ValueError as error:
        raise ConfigError("hazard.file", f"{error}; give a hazard curve per soil instead, [hazard] file = "
                          "{ clay = \"clay.csv\", ... }", config.source) from None


def amplified_curve(reference: HazardCurve, site: SiteAmplification, grid: np.ndarray) -> np.ndarray:
    """lambda_site [1/yr] on ``grid`` [the measure's unit] of the reference curve through ``site``'s site term."""
    low, high = grid[0] / 32.0, grid[-1] * 32.0  # AF 0.33-5.6 times 4 sigma of spread (e^1.2): a factor 32 spans it
    rock = np.exp(np.arange(np.log(low), np.log(high) + ROCK_STEP, ROCK_STEP))
    median, sigma = site(rock)
    return convolve_hazard(rock, hazard_frequency(reference, rock), median, sigma, grid)


def _site_grid(curves) -> np.ndarray:
    low = min(float(curve.intensity[0]) for curve in curves)
    high = max(float(curve.intensity[-1]) for curve in curves)
    return np.geomspace(low, high, GRID_POINTS)


def _per_soil(config, files: Mapping) -> SiteHazards:
    site = getattr(config, "hazard_site", None)
    curves, how = {}, {}
    for soil in config.soils:
        found = soil_file(files, soil)
        if found is None:
            reason = ("its site is the reference site, which a table of curves does not have: name it, or state its "
                      f"Vs30, [hazard] vs30 = {{ {soil.name} = ... }}, and give its class's curve"
                      if soil.vs30 is None else f"name it or its site class {soil.site_class}")
            raise ConfigError("hazard.file", f"no hazard curve for the soil {soil.name}: {reason}", config.source)
        key, path = found
        curve = hazard_for(path, config.measure, config.period, site)
        if curve is None:
            raise ConfigError(f"hazard.file.{key}", "empty; give the curve's file", config.source)
        curves[soil.name] = curve
        how[soil.name] = f"read from {path} ([hazard] file.{key})"
    components = {curve.component for curve in curves.values()}
    if len(components) > 1:
        raise ConfigError("hazard.file", "the soils' curves state different horizontal components ("
                          + ", ".join(f"{s} {c.component}" for s, c in curves.items())
                          + "); give curves of one definition", config.source)
    return SiteHazards(curves, how=how)


def _amplified(config, reference: HazardCurve) -> SiteHazards:
    reference_vs30 = float(getattr(config, "reference_vs30", REFERENCE_VS30))
    grid = None
    curves, how = {}, {}
    for soil in config.soils:
        if soil.vs30 is None or soil.vs30 == reference_vs30:
            curves[soil.name] = reference
            how[soil.name] = ("the reference curve: no site Vs30 stated, so the reference site"
                              if soil.vs30 is None else "the reference curve: its site is the reference site")
            continue
        site = study_amplification(config, soil.vs30, f"soil {soil.name}")
        if grid is None:
            grid = np.geomspace(reference.intensity[0] / 4.0, reference.intensity[-1] * 4.0, GRID_POINTS)
            _warn_rock_pga(reference, site)
        frequency = amplified_curve(reference, site, grid)
        keep = frequency > 0  # an amplified curve can end where the reference's mass runs out
        notes = {**reference.notes, "site_vs30_m_s": soil.vs30, "site_class": soil.site_class,
                 "reference_vs30_m_s": reference_vs30}
        curves[soil.name] = replace(reference, intensity=grid[keep], annual_frequency=frequency[keep],
                                    source=f"{reference.source}, amplified to {soil.name}'s site", notes=notes)
        how[soil.name] = (f"amplified from the reference site (Vs30 {reference_vs30:g} m/s) to Vs30 {site.vs30:g} m/s "
                          f"(class {soil.site_class}), sigma_lnVs30 {site.vs30_sigma:g}")
    return SiteHazards(curves, reference, reference_vs30, how)


def _warn_rock_pga(reference: HazardCurve, site: SiteAmplification) -> None:
    x = np.exp(np.interp(np.log(CHECK_FREQUENCY), np.log(reference.annual_frequency[::-1]),
                         np.log(reference.intensity[::-1])))
    rock_pga = float(site.rock_pga(x))
    if rock_pga > ROCK_PGA_LIMIT:
        warnings.warn(SiteHazardWarning(
            f"the reference hazard's rock PGA at 2% in 50 years is {rock_pga:.2g} g, above the {ROCK_PGA_LIMIT:g} g "
            "up to which the site term's nonlinear part is fitted; above it the soils' factors are held at their "
            f"value at {ROCK_PGA_LIMIT:g} g"), stacklevel=3)


def check_site_hazards(config) -> None:
    """Check the study's hazard as ``study_site_hazards`` reads it, without the convolutions (rockfrag.config).

    Every curve loads and is for the study's measure; every soil has a curve; the measure has a site term where a
    soil's curve must be amplified (a Vs30 outside the term's data is warned about here, once).

    Raises
    ------
    ConfigError
        As ``study_site_hazards``.
    """
    files = config.hazard_file
    if isinstance(files, Mapping):
        _per_soil(config, files)
        return
    if hazard_for(files, config.measure, config.period, getattr(config, "hazard_site", None)) is None:
        return
    reference_vs30 = float(getattr(config, "reference_vs30", REFERENCE_VS30))
    for soil in config.soils:
        if soil.vs30 is not None and soil.vs30 != reference_vs30:
            study_amplification(config, soil.vs30, f"soil {soil.name}")


def study_site_hazards(config) -> SiteHazards | None:
    """The hazard curve of every soil of the study (module docstring), or None when the study has no hazard.

    Parameters
    ----------
    config : rockfrag.config.StudyConfig
        ``hazard_file`` (a path, "" for the shipped example, or a table soil or site class -> path),
        ``reference_vs30`` [m/s], ``vs30_sigma`` [-], ``scenario``, ``measure``, ``period`` [s], ``soils``
        (their ``vs30`` [m/s]), ``blocks``, ``hazard_site``.

    Returns
    -------
    SiteHazards or None
        None for a study of a measure the shipped example does not cover and no file (no risk).

    Raises
    ------
    ConfigError
        A curve that does not load or is for another measure; a soil without a curve; a measure or period without
        a site term when the curve must be amplified.
    """
    files = config.hazard_file
    site = getattr(config, "hazard_site", None)
    if isinstance(files, Mapping):
        hazards = _per_soil(config, files)
    else:
        reference = hazard_for(files, config.measure, config.period, site)
        if reference is None:
            return None
        hazards = _amplified(config, reference)
    warn_far_site(hazards.first)
    return hazards


def site_hazard_dataset(hazards: SiteHazards, soils, measure: str) -> xr.Dataset:
    """``site_hazard(soil, hazard_intensity)`` [1/yr] of every soil on one grid, with each site's Vs30 and class.

    Parameters
    ----------
    hazards : SiteHazards
        The study's curves (``study_site_hazards``).
    soils : sequence of rockfrag.soils.SoilClass
        The study's soils, in its order.
    measure : str
        The study's measure (a name of ``rockfrag.measures.MEASURES``): the grid's units.

    Returns
    -------
    xarray.Dataset
        ``site_hazard`` [yr-1] over (soil, hazard_intensity), ``hazard_intensity`` in the measure's display unit,
        ``site_vs30`` [m s-1] (NaN for the reference site) and ``site_class`` per soil; attributes
        ``hazard_component``, ``site_hazard_source`` and ``site_amplification`` (the model and its limits).
    """
    grid = _site_grid(hazards.values())
    values = np.array([hazard_frequency(hazards[soil.name], grid) for soil in soils])
    known = MEASURES.get(measure)
    units = known.cf_units(display=True) if known is not None else udunits("1")
    label = hazards.first.label
    dataset = xr.Dataset(
        {"site_hazard": (("soil", "hazard_intensity"), values,
                         {"long_name": f"annual frequency of exceedance of {label} at each soil's site",
                          "units": "yr-1", "how": "; ".join(f"{s}: {h}" for s, h in hazards.how.items())}),
         "site_vs30": ("soil", [np.nan if soil.vs30 is None else soil.vs30 for soil in soils],
                       {"long_name": "Vs30 of each soil's site (NaN: the hazard's reference site)", "units": "m s-1"}),
         "site_class": ("soil", [soil.site_class for soil in soils],
                        {"long_name": "ASCE 7-16 site class of each soil's site (empty: the reference site)"})},
        coords={"soil": [soil.name for soil in soils],
                "hazard_intensity": ("hazard_intensity", grid, {"long_name": f"{label} at the site", "units": units})})
    dataset.attrs = {
        "hazard_component": hazards.component,
        "site_hazard_source": hazards.source,
        "site_amplification": (
            "Boore et al. (2014) NGA-West2 site term (Seyhan & Stewart 2014), Vref 760 m/s, Vs30 clipped to 150-1500 "
            f"m/s, rock PGA held at {ROCK_PGA_LIMIT:g} g in its nonlinear term; the Vs30 spread carried by "
            "convolution (Bazzurro & Cornell 2004)" if hazards.reference is not None else "none: a curve per soil"),
    }
    if hazards.reference_vs30 is not None:
        dataset.attrs["reference_vs30_m_s"] = hazards.reference_vs30
    return dataset


__all__ = ["SiteHazardWarning", "SiteHazards", "amplified_curve", "check_site_hazards", "site_hazard_dataset",
           "study_amplification", "study_site_hazards"]
