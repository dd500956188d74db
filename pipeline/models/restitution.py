"""rockfrag.models.restitution - the bed's dissipation anchored to a restitution, and radiation damping.

Input : a ``Block``, the bed's total vertical stiffness K [N/m] (eq. 19), a bed contact law name and a
        target effective restitution r (a number below 1, or "housner"); for radiation damping a block
        and a ``SoilClass``.
Output: ``calibrate_dissipation`` -> the damping ratio xi [-] of the calibrated law (cached per block,
        K, bed, target and g); ``calibrated_law`` (the law a bed is calibrated with); ``reachable_range``;
        ``free_rocking_restitution`` (the measure); ``restitution_target``; ``radiation_damping`` (Lysmer).

The measure (the project's definition, benchmarks/winkler_restitution.py): the block starts on the
settled bed (y = m g / K) with the angular velocity that takes a rigid block on a rigid base to 0.6 alpha,
and rocks freely. Its successive peaks theta_k (above 0.1 alpha) give r_k = sqrt(drop_{k+1} / drop_k),
drop = cos(alpha - theta_k) - cos(alpha), the impact speed squared of the rigid block that peaks there,
the quantity Housner's r = 1 - 1.5 sin^2(alpha) predicts; r is the median of the first four impacts.

The calibration: r is measured on a geometric grid of xi over the law's range (``XI_RANGE``; cached per
block, K, law and g, so several targets share it); the reachable range is the span of those values, and
a target outside it is one ``SolverError`` naming the range (never clamped). Inside it:
1. plateau: when r stays within the band (0.5% of the target and 5% of its loss 1 - r) from some grid
   point to the end of the grid, over ``PLATEAU_POINTS`` points or more (a stiff two-spring bed near
   Housner's value), the first of those points: the smallest xi (within a grid step) within the band;
2. else the smallest xi where r crosses the target (brentq on the first bracketing grid interval,
   scanning up from small xi; a crossing that is a jump, where r misses the target by more than
   the band, is skipped);
3. else (the target within the band of an end of the range) the smallest grid xi within the band.

Which law a bed is calibrated with (``calibrated_law``): ``two-spring`` its own Kelvin-Voigt xi;
``continuous`` and ``hunt-crossley`` the Hunt-Crossley damping (bed_hunt_crossley.py), because the
continuous Kelvin-Voigt dashpot leaves r at 0.96-0.98 whatever xi (README, "The models").
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy.optimize import brentq

from rockfrag.blocks import Block
from rockfrag.errors import SolverError
from rockfrag.models import fields, kernels
from rockfrag.models.bed_continuous import NAME as CONTINUOUS
from rockfrag.models.bed_hunt_crossley import NAME as HUNT_CROSSLEY
from rockfrag.models.bed_two_spring import NAME as TWO_SPRING
from rockfrag.models.options import BED_TYPES, HOUSNER, MAX_XI, SolverOptions, case_record
from rockfrag.models.winkler import MODEL as WINKLER
from rockfrag.soils import SoilClass, soil_block_stiffness
from rockfrag.units import STANDARD_GRAVITY

LAUNCH_FRACTION = 0.6  # the launch takes a rigid block to this fraction of alpha
PEAK_FLOOR = 0.1       # peaks below this fraction of alpha are not counted (elastic tilting on the bed)
IMPACTS = 4            # r is the median of the first IMPACTS impacts
DURATION = 24.0        # free rocking simulated for DURATION / p [s] (five peaks at r = 0.99 need ~16 / p)
SAMPLE_STEP = 0.01     # history sampled every SAMPLE_STEP / p [s]: peaks read to ~1e-5 alpha

CALIBRATED_LAWS = {CONTINUOUS: HUNT_CROSSLEY, TWO_SPRING: TWO_SPRING, HUNT_CROSSLEY: HUNT_CROSSLEY}
"""The law a bed's restitution target calibrates: the continuous bed takes Hunt-Crossley damping."""
XI_RANGE = {TWO_SPRING: (0.01, 0.99), HUNT_CROSSLEY: (0.01, MAX_XI[HUNT_CROSSLEY])}
"""The xi searched per calibrated law [-]; below 0.01 a stiff bed bounces and r jumps about."""
GRID_RATIO = 1.6       # successive grid values of xi differ by this factor (at most)
BAND = 5e-3            # "within 0.5% of the target" ...
LOSS_BAND = 0.05       # ... and within 5% of its loss 1 - r (alpha 0.1: 1 - r is only 1.5%)
PLATEAU_POINTS = 3     # a plateau spans at least this many grid points
XTOL = 1e-4            # brentq's tolerance on xi, relative

LYSMER_FACTOR = 3.4    # Lysmer's analog wave velocity V_La = 3.4 V_s / (pi (1 - nu))


def launch_rate(block: Block, fraction: float = LAUNCH_FRACTION, g: float = STANDARD_GRAVITY) -> float:
    """theta'(0) [rad/s] that takes a rigid block on a rigid base to ``fraction`` * alpha (I_O = 4/3 m R^2).

    Parameters
    ----------
    block : Block
        The block (R [m], alpha [rad]).
    fraction : float
        Peak angle of the rigid block as a fraction of alpha [-].
    g : float
        Gravity [m/s^2].

    Returns
    -------
    float
        The launch rate [rad/s] (positive; the measure launches towards -theta).
    """
    drop = math.cos(block.alpha * (1.0 - fraction)) - math.cos(block.alpha)
    return math.sqrt(2.0 * g * block.R * drop / (4.0 / 3.0 * block.R ** 2))


def rocking_peaks(theta: np.ndarray) -> np.ndarray:
    """Peak |theta| [rad] of each excursion (between sign changes) of a rotation history (NaN dropped)."""
    theta = np.asarray(theta, dtype=float)
    theta = theta[np.isfinite(theta)]
    sign = np.sign(theta)
    changes = np.flatnonzero(sign[1:] * sign[:-1] < 0) + 1
    return np.array([piece.max() for piece in np.split(np.abs(theta), changes) if piece.size])


def effective_restitution(peaks: np.ndarray, alpha: float) -> np.ndarray:
    """r_k = sqrt(drop_{k+1} / drop_k), drop = cos(alpha - theta_k) - cos(alpha), of successive peaks [-]."""
    drop = np.cos(alpha - np.asarray(peaks, dtype=float)) - math.cos(alpha)
    return np.sqrt(drop[1:] / drop[:-1])


@lru_cache(maxsize=4096)
def free_rocking_restitution(block: Block, k: float, bed: str, xi: float, g: float = STANDARD_GRAVITY,
                             fraction: float = LAUNCH_FRACTION) -> float:
    """Effective restitution of free rocking on the bed (module docstring).

    The median r of the first four impacts; NaN when the block overturns or makes fewer than two peaks
    above 0.1 alpha. Cached per argument set.

    Parameters
    ----------
    block : Block
        The block.
    k : float
        Total vertical stiffness of the bed [N/m].
    bed : str
        The bed's contact law (rockfrag.models.contact), used as given (no calibration).
    xi : float
        Its damping ratio [-].
    g : float
        Gravity [m/s^2].
    fraction : float
        Launch to this fraction of alpha (rigid block) [-].

    Returns
    -------
    float
        r [-], or NaN.
    """
    table = fields.new_params(1)
    table[0], state = case_record(WINKLER, block, k, xi, SolverOptions(bed=bed, g=g))
    state[1] = -launch_rate(block, fraction, g)
    p = block.p(g)
    dt = SAMPLE_STEP / p
    n_samples = int(round(DURATION / SAMPLE_STEP)) + 1
    history = np.empty((1, n_samples, fields.STATE_SIZE))
    kernels.run_cases(WINKLER.kernel_code, np.zeros((1, 2)), dt, n_samples - 2, table, state.reshape(1, -1),
                      histories=history)
    history = history[0]
    if not np.all(np.isfinite(history[:, 0])):
        return math.nan  # overturned or failed
    peaks = rocking_peaks(history[:, 0])
    r = effective_restitution(peaks[peaks > PEAK_FLOOR * block.alpha], block.alpha)[:IMPACTS]
    return float(np.median(r)) if r.size else math.nan


def calibrated_law(bed: str) -> str:
    """The contact law a restitution target on ``bed`` calibrates (continuous: ``hunt-crossley``)."""
    if bed not in BED_TYPES:
        raise SolverError(f"bed {bed!r} unknown; valid beds are: {', '.join(BED_TYPES)}")
    if bed not in CALIBRATED_LAWS:
        raise SolverError(f"bed {bed!r} has no restitution calibration; calibrated beds: {', '.join(CALIBRATED_LAWS)}")
    return CALIBRATED_LAWS[bed]


def restitution_target(block: Block, restitution: float | str) -> float:
    """A restitution target as a number for ``block``: "housner" is 1 - 1.5 sin^2(alpha); it must be in (0, 1).

    Parameters
    ----------
    block : Block
        The block (alpha [rad]).
    restitution : float or str
        The target [-] or "housner".

    Returns
    -------
    float
        The target [-].
    """
    if isinstance(restitution, str):
        if restitution != HOUSNER:
            raise SolverError(f"restitution {restitution!r} unknown; give a number below 1 or {HOUSNER!r}")
        return block.housner_restitution()
    target = float(restitution)
    if not target < 1.0:
        raise SolverError(f"restitution target {target:g} for block {block.name!r}: must be < 1 "
                          "(an effective restitution >= 1 would gain energy at every impact)")
    if not target > 0.0:
        raise SolverError(f"restitution target {target:g} for block {block.name!r}: must be > 0")
    return target


@lru_cache(maxsize=1024)
def restitution_grid(block: Block, k: float, law: str, g: float = STANDARD_GRAVITY) -> tuple[tuple, tuple]:
    """(xi grid, r on it) of ``law`` (a calibrated law, ``XI_RANGE``): the values the calibration searches."""
    low, high = XI_RANGE[law]
    xis = np.geomspace(low, high, int(math.ceil(math.log(high / low) / math.log(GRID_RATIO))) + 1)
    return tuple(float(xi) for xi in xis), tuple(free_rocking_restitution(block, k, law, float(xi), g) for xi in xis)


def _floored(grid: tuple[tuple, tuple], xi_floor: float | None) -> tuple[tuple, tuple]:
    """The grid points at xi >= ``xi_floor`` (all of them for None)."""
    if xi_floor is None:
        return grid
    keep = [i for i, xi in enumerate(grid[0]) if xi >= xi_floor]
    return tuple(grid[0][i] for i in keep), tuple(grid[1][i] for i in keep)


def reachable_range(block: Block, k: float, bed: str, g: float = STANDARD_GRAVITY,
                    xi_floor: float | None = None) -> tuple[float, float]:
    """(lowest, highest) effective restitution [-] that a target on ``bed`` can be calibrated to.

    The span of r over the law's xi grid (from ``xi_floor`` up, if given); (NaN, NaN) when the measure is
    undefined at every xi.
    """
    _, rs = _floored(restitution_grid(block, float(k), calibrated_law(bed), float(g)), xi_floor)
    finite = [r for r in rs if math.isfinite(r)]
    return (min(finite), max(finite)) if finite else (math.nan, math.nan)


def calibrate_dissipation(block: Block, k: float, bed: str, restitution: float | str,
                          g: float = STANDARD_GRAVITY, xi_floor: float | None = None) -> float:
    """The damping ratio xi [-] of ``calibrated_law(bed)`` that gives free rocking the target restitution.

    The calibration of the module docstring, cached per block, k, bed, target and g.

    Parameters
    ----------
    block : Block
        The block.
    k : float
        Total vertical stiffness of the bed [N/m] (eq. 19).
    bed : str
        ``two-spring``, ``continuous`` (calibrated with Hunt-Crossley damping) or ``hunt-crossley``.
    restitution : float or str
        Target effective restitution [-] (below 1), or "housner" (1 - 1.5 sin^2(alpha)).
    g : float
        Gravity [m/s^2].
    xi_floor : float, optional
        Search xi only from this value up (the study's band: below it a block bounces on a stiff bed and r
        jumps between grid points; rockfrag.models.variants).

    Returns
    -------
    float
        xi [-]: ``simulate("winkler", ..., k=k, xi=xi, bed=calibrated_law(bed))`` rocks with that restitution.

    Raises
    ------
    SolverError
        A target >= 1, or outside the range the law reaches on this bed (the message names the range).
    """
    return _calibrated(block, float(k), calibrated_law(bed), restitution_target(block, restitution), float(g), bed,
                       xi_floor)


@lru_cache(maxsize=4096)
def _calibrated(block: Block, k: float, law: str, target: float, g: float, bed: str,
                xi_floor: float | None = None) -> float:
    xis, rs = _floored(restitution_grid(block, k, law, g), xi_floor)
    finite = [i for i, r in enumerate(rs) if math.isfinite(r)]
    where = (f"the {bed} bed (law {law}) for block {block.name!r} (K = {k:.4g} N/m, "
             f"omega_v/p = {math.sqrt(k / block.mass) / block.p(g):.0f})")
    if not finite:
        raise SolverError(f"{where[0].upper()}{where[1:]}: the block overturns or does not rock when launched to "
                          f"{LAUNCH_FRACTION} alpha at every xi from {xis[0]:g} to {xis[-1]:g}; its free-rocking "
                          "restitution is not defined")
    low, high = min(rs[i] for i in finite), max(rs[i] for i in finite)

    band = min(BAND * target, LOSS_BAND * (1.0 - target))

    def within(r: float) -> bool:
        return math.isfinite(r) and abs(r - target) <= band

    def measure(xi: float) -> float:
        return free_rocking_restitution(block, k, law, xi, g)

    # 1. plateau: r within the band at every grid point from some index on: the first of them
    start = len(rs)
    while start > 0 and (within(rs[start - 1]) or not math.isfinite(rs[start - 1])):
        start -= 1
    if sum(within(rs[i]) for i in range(start, len(rs))) >= PLATEAU_POINTS:
        return next(xis[i] for i in range(start, len(rs)) if within(rs[i]))
    # 2. the smallest crossing
    jumps = []
    for left, right in zip(finite, finite[1:]):
        if right != left + 1 or (rs[left] - target) * (rs[right] - target) > 0.0:
            continue
        xi = _root(measure, target, xis[left], xis[right])
        if xi is not None and within(measure(xi)):
            return xi
        jumps.append(f"{xis[left]:.3g}-{xis[right]:.3g}")
    # 3. the target within the band of an end of the range
    for i in finite:
        if within(rs[i]):
            return xis[i]
    reach = (f"the range {low:.4f} to {high:.4f} that {where} reaches (xi {xis[0]:g} to {xis[-1]:g}, free rocking "
             f"launched to {LAUNCH_FRACTION} alpha; Housner's value is {block.housner_restitution():.4f})")
    if jumps:
        raise SolverError(f"restitution target {target:.4f} is not reached within {band:.2g}: r jumps across it "
                          f"(xi {', '.join(jumps)}: the block bounces on the bed) in {reach}")
    raise SolverError(f"restitution target {target:.4f} is outside {reach}")


def _root(measure, value: float, low: float, high: float) -> float | None:
    """The xi in [low, high] where measure(xi) = value (brentq), or None when the measure is undefined there."""
    def gap(xi: float) -> float:
        r = measure(xi)
        if not math.isfinite(r):
            raise ValueError("undefined")
        return r - value

    try:
        if gap(low) == 0.0:
            return low
        if gap(high) == 0.0:
            return high
        return float(brentq(gap, low, high, xtol=XTOL * low, rtol=1e-10, maxiter=60))
    except ValueError:
        return None


def radiation_damping(block: Block, soil: SoilClass) -> float:
    """Damping ratio xi [-] of the vertical mode from Lysmer's analog.

    A dashpot rho V_La per unit footprint area, V_La = 3.4 V_s / (pi (1 - nu)), V_s = sqrt(G / rho), on the
    eq. 19 stiffness K: xi = rho V_La A / (2 sqrt(K m)).

    Parameters
    ----------
    block : Block
        The block (mass [kg], footprint area A [m^2], E_b, soil depth: eq. 19).
    soil : SoilClass
        The soil (G [Pa], nu [-], rho [kg/m^3]).

    Returns
    -------
    float
        xi [-], below 1.

    Raises
    ------
    SolverError
        xi >= 1: the half-space idealisation behind Lysmer's analog does not hold (e.g. a steel deck).
    """
    stiffness = soil_block_stiffness(soil, block)
    shear_velocity = math.sqrt(soil.shear_modulus / soil.density)
    analog_velocity = LYSMER_FACTOR * shear_velocity / (math.pi * (1.0 - soil.poisson_ratio))
    xi = soil.density * analog_velocity * block.footprint_area / (2.0 * math.sqrt(stiffness * block.mass))
    if xi >= 1.0:
        raise SolverError(f"radiation damping of block {block.name!r} on soil {soil.name!r}: xi = {xi:.3g} >= 1 "
                          "(Lysmer's analog over eq. 19's stiffness); the half-space idealisation does not apply "
                          "here (a steel deck is not a half-space): give the soil a damping ratio")
    return xi
