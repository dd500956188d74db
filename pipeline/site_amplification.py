"""rockfrag.site_amplification - a reference site's hazard carried to a soil's site: the NGA-West2 site term.

Input : the study's intensity measure (pga, pgv, sa at a period, avgsa over its periods, or the block-normalised
        pga_ratio and pgv_ratio), the Vs30 [m/s] of the hazard curve's reference site and of the soil's site, the
        spread of ln Vs30 of the soil's site [-], and intensities on the reference site [the measure's unit].
Output: ``SiteAmplification``: the median ln AF and its standard deviation at each reference intensity;
        ``convolve_hazard``: the site's annual frequency of exceedance lambda_site(z) [1/yr] from the reference
        curve lambda_ref(x) [1/yr] (Bazzurro & Cornell 2004).

The model is the site term F = F_lin + F_nl of Boore, Stewart, Seyhan & Atkinson (2014, BSSA14), which is the
site amplification model of Seyhan & Stewart (2014) for the NGA-West2 project, relative to Vref = 760 m/s:

    F_lin = c ln(min(Vs30, Vc) / Vref)
    F_nl  = f1 + f2 ln((PGAr + f3) / f3),   f2 = f4 (exp(f5 (min(Vs30, 760) - 360)) - exp(f5 (760 - 360)))

with f1 = 0, f3 = 0.1 g, and PGAr the median PGA [g] on the 760 m/s reference rock. Its coefficients per period
are in ``bssa14_coefficients.csv`` (source in its header); between tabulated periods they are interpolated
linearly in ln T. The basin term (F_dz1) is left out: a study states no basin depth, and BSSA14's term is zero at
the depth its Vs30-depth relation expects. Why this model: it is the published site term of an NGA-West2 model
(the models behind USGS and most OpenQuake hazard curves, so the reference curve and its amplification share one
site definition), it covers PGA, PGV and Sa from 0.01 to 10 s with one form, and it is nonlinear in the rock
motion. ASCE 7-22 has no site-coefficient tables (its site classes enter through the USGS multi-period spectra),
and ASCE 7-16's F_PGA (Table 11.8-1) covers PGA only; its F_a and F_v (Tables 11.4-1, 11.4-2) are for the design
spectrum's two periods, not for a hazard curve.

The measures: PGA, PGV and Sa(T) use their own rows. AvgSa, the geometric mean of Sa over its periods, gets the mean
of ln AF over those periods (exact for a geometric mean). pga_ratio = PGA/(g tan alpha) and pgv_ratio = p PGV/(g tan
alpha) are PGA and PGV divided by a constant of the block: their AF is that of PGA and PGV, and the nonlinear term's
PGAr needs that constant (``to_base``). For a measure other than PGA, PGAr is the reference intensity divided by
BSSA14's median ratio of that measure to PGA on rock at a stated scenario (``SCENARIO``: magnitude, Joyner-Boore
distance), since a hazard curve does not say which earthquake produced each intensity.

Outside the model's data (``VS30_DATA``; ``ROCK_PGA_LIMIT``) the study clips: a Vs30 below 150 or above 1500 m/s is
taken at the bound, with a ``SiteAmplificationWarning``; a rock PGA above ``ROCK_PGA_LIMIT`` enters the nonlinear
term at the limit (the factor is held at its value there), which the site hazard's notes state.

Dispersion: the reference curve already holds the ground motion model's aleatory variability, including its
site-to-site part for a site known by its Vs30, so the ergodic site term adds no variability of its own (adding
one would count it twice). What the study adds is the uncertainty of the site's Vs30 itself: a soil known only by
its site class has a Vs30 anywhere in the class. That spread, sigma_lnVs30 (``VS30_SIGMA``), is carried through the
site term, sigma_lnAF = |dF/dln Vs30| sigma_lnVs30, and into the site hazard by convolution.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from functools import cache
from importlib.resources import files

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import ndtr

REFERENCE_VS30 = 760.0
"""Vref of BSSA14 [m/s]: the site term is 0 (a factor of 1) there."""
VS30_DATA = (150.0, 1500.0)
"""Vs30 range of the data behind BSSA14's site term [m/s] (BSSA14, its limits of applicability: 150-1500 m/s)."""
ROCK_PGA_LIMIT = 1.0
"""Largest rock PGA [g] entered in the nonlinear term; above it the factor is held at its value at this PGA. A
stated choice: rock-site recordings above about 1 g are few in the NGA-West2 data the term was fitted with."""
VS30_SIGMA = 0.2
"""Default standard deviation of ln Vs30 of a soil's site [-]: a Vs30 known only to lie in a site class, uniform in
ln Vs30 over a class a factor of 2 wide (ASCE 7-16 classes B, C and D span factors of 2.0, 2.1 and 2.0):
ln 2 / sqrt(12) = 0.200. A measured Vs30 has less (``[hazard] vs30_sigma``)."""
SCENARIO = (7.0, 10.0)
"""(magnitude, Joyner-Boore distance [km]) at which BSSA14's rock medians give the ratio of a measure to PGA, from
which a non-PGA hazard's rock PGA follows (a stated choice: a large shallow crustal earthquake near the site, the
kind that dominates the hazard at the return periods of a design)."""

F1, F3 = 0.0, 0.1
"""BSSA14's f1 [-] and f3 [g], the same at every period."""
MREF, RREF = 4.5, 1.0
"""BSSA14's reference magnitude and distance [km] of its path term."""
PERIOD_RANGE = (0.01, 10.0)
"""Sa periods [s] of the coefficient table."""
PGV_UNIT = 0.01
"""m/s per cm/s: BSSA14 gives PGV in cm/s."""


class SiteAmplificationWarning(UserWarning):
    """A soil's site lies outside the site term's data; the study clips it to the data's range."""


@dataclass(frozen=True)
class Coefficients:
    """BSSA14 coefficients of one measure (one period for Sa): its rock median (unspecified mechanism) and site term."""

    e0: float
    e4: float
    e5: float
    e6: float
    Mh: float
    c1: float
    c2: float
    c3: float
    h: float
    c: float
    Vc: float
    f4: float
    f5: float


@cache
def _table() -> tuple[dict[str, Coefficients], np.ndarray, np.ndarray]:
    """(the pga and pgv rows by name, the Sa periods [s], the Sa rows as an array period x coefficient)."""
    lines = [line for line in files("rockfrag").joinpath("bssa14_coefficients.csv").read_text().splitlines()
             if line.strip() and not line.startswith("#")]
    names = lines[0].split(",")[1:]
    assert names == list(Coefficients.__dataclass_fields__), names  # the file's columns are the fields, in order
    named, periods, rows = {}, [], []
    for line in lines[1:]:
        key, *values = line.split(",")
        numbers = [float(v) for v in values]
        if key in ("pga", "pgv"):
            named[key] = Coefficients(*numbers)
        else:
            periods.append(float(key))
            rows.append(numbers)
    return named, np.array(periods), np.array(rows)


def coefficients(imt: str | float) -> Coefficients:
    """BSSA14's coefficients of ``"pga"``, ``"pgv"`` or Sa at a period [s].

    A period between two tabulated ones gets coefficients interpolated linearly in ln T.

    Raises
    ------
    ValueError
        A period outside the table's 0.01-10 s.
    """
    named, periods, rows = _table()
    if isinstance(imt, str):
        return named[imt]
    period = float(imt)
    if not PERIOD_RANGE[0] * (1 - 1e-9) <= period <= PERIOD_RANGE[1] * (1 + 1e-9):
        raise ValueError(f"Sa period {period:g} s is outside BSSA14's {PERIOD_RANGE[0]:g}-{PERIOD_RANGE[1]:g} s")
    log_period = np.log(np.clip(period, *PERIOD_RANGE))
    return Coefficients(*(float(np.interp(log_period, np.log(periods), column)) for column in rows.T))


def linear_term(co: Coefficients, vs30: ArrayLike) -> np.ndarray:
    """F_lin = c ln(min(Vs30, Vc) / Vref) [-] (BSSA14 eq. 6)."""
    return co.c * np.log(np.minimum(np.asarray(vs30, float), co.Vc) / REFERENCE_VS30)


def nonlinear_slope(co: Coefficients, vs30: ArrayLike) -> np.ndarray:
    """f2 = f4 (exp(f5 (min(Vs30, 760) - 360)) - exp(f5 (760 - 360))) [-] (BSSA14 eq. 8): 0 at and above 760 m/s."""
    stiff = np.minimum(np.asarray(vs30, float), REFERENCE_VS30)
    return co.f4 * (np.exp(co.f5 * (stiff - 360.0)) - np.exp(co.f5 * (REFERENCE_VS30 - 360.0)))


def site_term(co: Coefficients, vs30: ArrayLike, rock_pga: ArrayLike) -> np.ndarray:
    """The site term ln AF = F_lin + F_nl [-] at ``vs30`` [m/s] for a median rock PGA ``rock_pga`` [g] (eqs. 5-8)."""
    nonlinear = F1 + nonlinear_slope(co, vs30) * np.log((np.asarray(rock_pga, float) + F3) / F3)
    return linear_term(co, vs30) + nonlinear


def site_term_vs30_slope(co: Coefficients, vs30: ArrayLike, rock_pga: ArrayLike) -> np.ndarray:
    """d(ln AF)/d(ln Vs30) [-] of ``site_term``: c below Vc, plus the nonlinear term's change below 760 m/s."""
    vs30 = np.asarray(vs30, float)
    linear = np.where(vs30 < co.Vc, co.c, 0.0)
    nonlinear = np.where(vs30 < REFERENCE_VS30, co.f4 * co.f5 * vs30 * np.exp(co.f5 * (vs30 - 360.0)), 0.0)
    return linear + nonlinear * np.log((np.asarray(rock_pga, float) + F3) / F3)


def rock_median(co: Coefficients, magnitude: float, distance: float) -> float:
    """BSSA14's median on the 760 m/s reference rock (g; cm/s for PGV), unspecified mechanism (eqs. 2-4).

    Parameters
    ----------
    co : Coefficients
        The measure's coefficients.
    magnitude : float
        Moment magnitude [-].
    distance : float
        Joyner-Boore distance [km].
    """
    dm = magnitude - co.Mh
    source = co.e0 + (co.e4 * dm + co.e5 * dm**2 if magnitude <= co.Mh else co.e6 * dm)
    r = math.hypot(distance, co.h)
    path = (co.c1 + co.c2 * (magnitude - MREF)) * math.log(r / RREF) + co.c3 * (r - RREF)
    return math.exp(source + path)


def clip_vs30(vs30: float, who: str) -> float:
    """``vs30`` [m/s] inside ``VS30_DATA``, with a ``SiteAmplificationWarning`` naming ``who`` when it was outside."""
    low, high = VS30_DATA
    if low <= vs30 <= high:
        return float(vs30)
    bound = low if vs30 < low else high
    warnings.warn(SiteAmplificationWarning(
        f"{who}: Vs30 {vs30:g} m/s is {'below' if vs30 < low else 'above'} the data of the NGA-West2 site term "
        f"(BSSA14, {low:g}-{high:g} m/s); its site is amplified as at {bound:g} m/s"), stacklevel=2)
    return float(bound)


@dataclass(frozen=True)
class SiteAmplification:
    """The site term of one measure, from the hazard's reference site to a soil's site.

    Attributes
    ----------
    terms : tuple of Coefficients
        One row per period the measure averages (one for PGA, PGV, Sa).
    rock_ratio : float
        Median of the base measure per g of rock PGA on the reference rock at ``SCENARIO`` (1 for PGA; g/g for Sa
        and AvgSa, m/s per g for PGV).
    to_base : float
        The study's measure in the base measure's unit (g, or m/s for PGV) per unit of the measure: 1, or the
        block's constant for pga_ratio and pgv_ratio.
    vs30, reference_vs30 : float
        Vs30 of the soil's site and of the hazard's reference site [m/s], inside ``VS30_DATA``.
    vs30_sigma : float
        Standard deviation of ln Vs30 of the soil's site [-].
    """

    terms: tuple[Coefficients, ...]
    rock_ratio: float
    to_base: float
    vs30: float
    reference_vs30: float
    vs30_sigma: float

    def rock_pga(self, intensity: ArrayLike) -> np.ndarray:
        """Median PGA [g] on the 760 m/s rock behind reference intensities ``intensity`` [the measure's unit].

        On the 760 m/s reference site it is the intensity over ``rock_ratio``; on another reference site the
        site term of that site is taken out first (solved by bisection in ln PGA: the reference intensity
        grows with the rock PGA at every Vs30 of the data).
        """
        base = np.log(np.asarray(intensity, float) * self.to_base / self.rock_ratio)
        if self.reference_vs30 == REFERENCE_VS30:
            return np.exp(base)
        low, high = base - 6.0, base + 6.0
        for _ in range(60):  # bracket 12 wide in ln PGA: 60 halvings leave 1e-17
            middle = 0.5 * (low + high)
            above = middle + self._mean_term(self.reference_vs30, np.exp(middle)) > base
            low, high = np.where(above, low, middle), np.where(above, middle, high)
        return np.exp(0.5 * (low + high))

    def _mean_term(self, vs30: float, rock_pga: np.ndarray) -> np.ndarray:
        held = np.minimum(rock_pga, ROCK_PGA_LIMIT)
        return np.mean([site_term(co, vs30, held) for co in self.terms], axis=0)

    def __call__(self, intensity: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(median ln AF, standard deviation of ln AF) [-] at reference intensities ``intensity``."""
        rock_pga = self.rock_pga(intensity)
        median = self._mean_term(self.vs30, rock_pga) - self._mean_term(self.reference_vs30, rock_pga)
        held = np.minimum(rock_pga, ROCK_PGA_LIMIT)
        slope = np.mean([site_term_vs30_slope(co, self.vs30, held) for co in self.terms], axis=0)
        return median, np.abs(slope) * self.vs30_sigma


def amplification(measure: str, vs30: float, reference_vs30: float = REFERENCE_VS30,
                  vs30_sigma: float = VS30_SIGMA, periods: tuple[float, ...] = (), to_base: float = 1.0,
                  scenario: tuple[float, float] = SCENARIO) -> SiteAmplification:
    """The site term of ``measure`` from a reference site of ``reference_vs30`` to a site of ``vs30`` [m/s].

    Parameters
    ----------
    measure : str
        pga, pgv, sa, avgsa, pga_ratio or pgv_ratio.
    vs30, reference_vs30 : float
        Vs30 of the soil's site and of the hazard's reference site [m/s]; each is taken inside ``VS30_DATA``
        (the caller warns, ``clip_vs30``).
    vs30_sigma : float
        Standard deviation of ln Vs30 of the soil's site [-].
    periods : tuple of float
        Sa's period [s] (one), or AvgSa's periods [s].
    to_base : float
        The measure in g (PGV: m/s) per unit of the measure: 1; for pga_ratio tan(alpha), for pgv_ratio
        g tan(alpha) / p [m/s].
    scenario : (float, float)
        Magnitude and Joyner-Boore distance [km] of the rock medians' ratio to PGA.

    Returns
    -------
    SiteAmplification

    Raises
    ------
    ValueError
        A measure without a site term here, or a period outside 0.01-10 s.
    """
    base = {"pga": "pga", "pga_ratio": "pga", "pgv": "pgv", "pgv_ratio": "pgv", "sa": "sa", "avgsa": "sa"}.get(measure)
    if base is None:
        raise ValueError(f"no site amplification model for the measure {measure!r}; it has one for pga, pgv, sa, "
                         "avgsa, pga_ratio and pgv_ratio")
    if base == "sa" and not periods:
        raise ValueError(f"{measure} needs its period(s)")
    terms = tuple(coefficients(t) for t in periods) if base == "sa" else (coefficients(base),)
    pga = rock_median(coefficients("pga"), *scenario)
    medians = [rock_median(co, *scenario) for co in terms]
    ratio = float(np.exp(np.mean(np.log(medians)))) / pga  # geometric mean: AvgSa's own definition
    if base == "pgv":
        ratio *= PGV_UNIT
    low, high = VS30_DATA
    return SiteAmplification(terms, 1.0 if base == "pga" else ratio, float(to_base),
                             float(np.clip(vs30, low, high)), float(np.clip(reference_vs30, low, high)),
                             float(vs30_sigma))


def _ramp_integral(t: np.ndarray) -> np.ndarray:
    """G(t) = t Phi(t) + phi(t), the integral of the standard normal CDF Phi from -inf to t."""
    return t * ndtr(t) + np.exp(-0.5 * t * t) / math.sqrt(2.0 * math.pi)


def convolve_hazard(rock_intensity: ArrayLike, rock_frequency: ArrayLike, log_amplification: ArrayLike,
                    sigma: ArrayLike, site_intensity: ArrayLike) -> np.ndarray:
    """The site's hazard lambda_site(z) = integral of P(AF x > z | x) |d lambda_ref(x)| [1/yr] (Bazzurro & Cornell).

    The reference curve is a sum of bins between consecutive ``rock_intensity`` values, each holding the drop of
    lambda over it. A bin's rock intensities carry their median site intensity ln x + ln AF(x), spread evenly
    between the bin's edges; ln AF given x is normal with the bin's mean ``sigma``. Then P(site > z) of a bin is
    the mean over the bin of Phi((y - ln z) / sigma), in closed form: sigma / dy [G(t_hi) - G(t_lo)],
    G(t) = t Phi(t) + phi(t). With sigma = 0 the bin's share above ln z, so a deterministic factor maps the curve
    point by point. The frequency beyond the last intensity sits at the last one.

    Parameters
    ----------
    rock_intensity : array_like, shape (n,)
        Increasing reference intensities x [the measure's unit], spanning those whose amplified values reach the
        site intensities (a few standard deviations below and above).
    rock_frequency : array_like, shape (n,)
        lambda_ref(x) [1/yr], decreasing.
    log_amplification, sigma : array_like, shape (n,)
        Median ln AF(x) and its standard deviation [-] at each x.
    site_intensity : array_like, shape (m,)
        Intensities z on the site [the measure's unit].

    Returns
    -------
    numpy.ndarray, shape (m,)
        lambda_site(z) [1/yr].
    """
    x = np.asarray(rock_intensity, float)
    frequency = np.asarray(rock_frequency, float)
    median = np.log(x) + np.asarray(log_amplification, float)
    sigma = np.broadcast_to(np.asarray(sigma, float), x.shape)
    target = np.log(np.asarray(site_intensity, float))[:, None]
    low, high = np.minimum(median[:-1], median[1:]), np.maximum(median[:-1], median[1:])
    width = np.maximum(high - low, 1e-300)
    spread = 0.5 * (sigma[:-1] + sigma[1:])
    mass = frequency[:-1] - frequency[1:]
    smooth = spread > 1e-9
    safe = np.where(smooth, spread, 1.0)
    above_smooth = safe / width * (_ramp_integral((high - target) / safe) - _ramp_integral((low - target) / safe))
    above_sharp = np.clip((high - target) / width, 0.0, 1.0)
    above = np.clip(np.where(smooth, above_smooth, above_sharp), 0.0, 1.0)
    tail = ndtr((median[-1] - target[:, 0]) / sigma[-1]) if sigma[-1] > 1e-9 else (median[-1] >= target[:, 0]) * 1.0
    return above @ mass + tail * frequency[-1]


__all__ = ["REFERENCE_VS30", "ROCK_PGA_LIMIT", "SCENARIO", "VS30_DATA", "VS30_SIGMA", "Coefficients",
           "SiteAmplification", "SiteAmplificationWarning", "amplification", "clip_vs30", "coefficients",
           "convolve_hazard", "linear_term", "nonlinear_slope", "rock_median", "site_term", "site_term_vs30_slope"]
