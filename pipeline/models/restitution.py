"""rockfrag.models.restitution - the bed's dissipation anchored to a restitution, and radiation damping.

Input : a ``Block``, the bed's total vertical stiffness K [N/m] (eq. 19), a bed contact law name and a
        target effective restitution r (a number below 1, or "housner"); for radiation damping a block
        and a ``SoilClass``.
Output: ``calibrate_dissipation`` -> a ``Dissipation``: the damping ratio xi [-] of the calibrated law and what
        was decided (cached per block, K, bed, target and g); ``admissible_xi`` (where free rocking is
        reproducible); ``calibrated_law`` (the law a bed is calibrated with); ``reachable_range``;
        ``free_rocking_restitution`` (the measure); ``stability``; ``tolerance``; ``restitution_target``;
        ``radiation_damping`` (Lysmer).

The measure (the project's definition, benchmarks/winkler_restitution.py): the block starts on the
settled bed (y = m g / K) with the angular velocity that takes a rigid block on a rigid base to 0.6 alpha,
and rocks freely. Its successive peaks theta_k (above 0.1 alpha) give r_k = sqrt(drop_{k+1} / drop_k),
drop = cos(alpha - theta_k) - cos(alpha), the impact speed squared of the rigid block that peaks there,
the quantity Housner's r = 1 - 1.5 sin^2(alpha) predicts; r is the median of the first four impacts.

Tolerance (``tolerance``): on the loss 1 - r, not on r: 5 % of the target's loss 1 - r*, and at least 0.002
in r (1 % of r would be a loss of 0.5-2.5 % for a slender block at r = 0.985).

Admissible xi (``stability``, ``admissible_xi``): a xi is admissible only where the free-rocking r is
reproducible: r at launches 0.5 and 0.7 alpha and at half and double the output sampling within the
tolerance of the definition's r, no r_k above 1 among the impacts counted (above 1, the block bounces on a
ringing bed and vertical and rocking energy trade: r jumps between neighbouring xi), and either every run
rocks or every run dies below the measure's resolution (fewer than two peaks above 0.1 alpha: it loses at
least what the measure resolves). Every xi of the grid over the law's range (``XI_RANGE``, ratio
``GRID_RATIO``) is checked; the admissible xi are the runs of at least ``RUN`` neighbouring grid xi that pass
(a lone grid xi that passes between two that fail is not reproducible under a small change of the bed).
The study's floor of xi is this rule's consequence, per block and bed.

The calibration (``calibrate_dissipation``), the one rule of ``simulate(..., restitution=...)`` and of the
study: among the admissible xi, the smallest that hits the target within the tolerance (a grid xi within
it, or the root of r(xi) = target between two admissible grid xi, scanning up), re-checked at that xi: r of
every launch and sampling of the check within the tolerance of the target. A target reachable only at xi
that are not admissible, or outside the range the admissible xi reach, is one ``SolverError`` naming the
admissible range. A block whose free rocking dies below the
measure's resolution at every admissible xi (the squat skid, Housner's r 0.46), or a target below what the
measure resolves where the larger admissible xi die, runs at the smallest such xi: ``decision`` "dies" with
one ``note`` line, not an error.

Which law a bed is calibrated with (``calibrated_law``): ``two-spring`` its own Kelvin-Voigt xi;
``continuous`` and ``hunt-crossley`` the Hunt-Crossley damping (bed_hunt_crossley.py), because the
continuous Kelvin-Voigt dashpot leaves r at 0.96-0.98 whatever xi (docs/theory/bed.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
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
SHORT_FACTOR = 1.3     # another launch or sampling runs this many times as long as the definition's needed ...
SHORT_MARGIN = 1.5     # ... plus this many 1/p (a launch to 0.7 alpha rocks longer; too short: run again, whole)

CALIBRATED_LAWS = {CONTINUOUS: HUNT_CROSSLEY, TWO_SPRING: TWO_SPRING, HUNT_CROSSLEY: HUNT_CROSSLEY}
"""The law a bed's restitution target calibrates: the continuous bed takes Hunt-Crossley damping."""
XI_RANGE = {TWO_SPRING: (0.01, 0.99), HUNT_CROSSLEY: (0.01, MAX_XI[HUNT_CROSSLEY])}
"""The xi searched per calibrated law [-]; below 0.01 a stiff bed bounces and r jumps about."""
GRID_RATIO = 1.6       # successive grid values of xi differ by this factor (at most)
XTOL = 1e-4            # brentq's tolerance on xi, relative
LOSS_TOLERANCE = 0.05  # tolerance on r: 5 % of the loss 1 - r ...
MIN_TOLERANCE = 0.002  # ... and at least this much in r
STABILITY_LAUNCHES = (0.5, 0.7)  # launches (fractions of alpha) that must give the definition's r within tolerance
SAMPLINGS = (0.5, 2.0)  # output samplings (times the definition's) that must too
RUN = 2                # admissible xi come in runs of at least this many neighbouring grid xi that pass

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


def _counted_impacts(theta: np.ndarray, alpha: float, step: float) -> tuple[tuple[float, ...] | None, float]:
    """(r_k of the impacts counted, the time [in 1/p] the measure has seen all it needs; NaN: not within the run).

    None for r_k when the block overturned. The measure has seen all it needs once the excursion after the
    last peak it counts (the ``IMPACTS`` + 1-th above ``PEAK_FLOOR`` alpha, or the last one above it) has ended.
    """
    if not np.all(np.isfinite(theta)):
        return None, math.nan  # overturned or failed
    sign = np.sign(theta)
    changes = np.flatnonzero(sign[1:] * sign[:-1] < 0) + 1
    pieces = np.split(np.abs(theta), changes)
    peaks = np.array([piece.max() if piece.size else 0.0 for piece in pieces])
    counted = np.flatnonzero(peaks > PEAK_FLOOR * alpha)[:IMPACTS + 1]
    impacts = tuple(float(r) for r in effective_restitution(peaks[counted], alpha))
    after = (int(counted[-1]) if counted.size else 0) + 1  # the excursion after the last peak counted
    seen = float(changes[after]) * step if after < changes.size else math.nan  # ... ends at changes[after]
    return impacts, seen


@lru_cache(maxsize=16384)
def _free_rocking(block: Block, k: float, law: str, xi: float, g: float, fraction: float, sampling: float,
                  duration: float) -> tuple[tuple[float, ...] | None, float]:
    """One free-rocking run of ``duration`` / p [s]: ``_counted_impacts`` of its history (cached)."""
    table = fields.new_params(1)
    table[0], state = case_record(WINKLER, block, k, xi, SolverOptions(bed=law, g=g))
    state[1] = -launch_rate(block, fraction, g)
    step = SAMPLE_STEP / sampling
    n_samples = int(round(duration / step)) + 1
    history = np.empty((1, n_samples, fields.STATE_SIZE))
    kernels.run_cases(WINKLER.kernel_code, np.zeros((1, 2)), step / block.p(g), n_samples - 2, table,
                      state.reshape(1, -1), histories=history)
    return _counted_impacts(history[0, :, 0], block.alpha, step)


def free_rocking_impacts(block: Block, k: float, bed: str, xi: float, g: float = STANDARD_GRAVITY,
                         fraction: float = LAUNCH_FRACTION, sampling: float = 1.0) -> tuple[float, ...] | None:
    """The r_k of the impacts the measure counts (module docstring), or None when the block overturns.

    An empty tuple: fewer than two peaks above ``PEAK_FLOOR`` alpha (the rocking dies below the measure's
    resolution). The definition's run lasts ``DURATION`` / p; another launch or sampling of the same bed runs
    ``SHORT_FACTOR`` times as long as the definition's needed (plus ``SHORT_MARGIN`` / p), and again for the
    whole ``DURATION`` when that was not enough to see all it counts. Cached per argument set.

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
    sampling : float
        Output samples per ``SAMPLE_STEP`` / p (2: twice as many, 0.5: half as many) [-].

    Returns
    -------
    tuple of float or None
        r_k [-] of the first ``IMPACTS`` impacts counted, or None.
    """
    args = (block, float(k), bed, float(xi), float(g))
    nominal, seen = _free_rocking(*args, LAUNCH_FRACTION, 1.0, DURATION)
    if (float(fraction), float(sampling)) == (LAUNCH_FRACTION, 1.0):
        return None if nominal is None else nominal[:IMPACTS]
    if nominal is not None and math.isfinite(seen):
        duration = SHORT_FACTOR * seen + SHORT_MARGIN
        if duration < DURATION:
            impacts, enough = _free_rocking(*args, float(fraction), float(sampling), duration)
            if impacts is None or math.isfinite(enough):
                return None if impacts is None else impacts[:IMPACTS]
    impacts, _ = _free_rocking(*args, float(fraction), float(sampling), DURATION)
    return None if impacts is None else impacts[:IMPACTS]


def free_rocking_restitution(block: Block, k: float, bed: str, xi: float, g: float = STANDARD_GRAVITY,
                             fraction: float = LAUNCH_FRACTION, sampling: float = 1.0) -> float:
    """Effective restitution of free rocking on the bed (module docstring): the median r of the first four impacts.

    NaN when the block overturns or makes fewer than two peaks above 0.1 alpha. Cached per argument set
    (``free_rocking_impacts``).

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
    sampling : float
        Output samples per ``SAMPLE_STEP`` / p [-] (1: the definition's).

    Returns
    -------
    float
        r [-], or NaN.
    """
    impacts = free_rocking_impacts(block, float(k), bed, float(xi), float(g), float(fraction), float(sampling))
    return float(np.median(impacts)) if impacts else math.nan


def tolerance(restitution: float) -> float:
    """The tolerance on a restitution r [-]: ``LOSS_TOLERANCE`` of its loss 1 - r, at least ``MIN_TOLERANCE``.

    Parameters
    ----------
    restitution : float
        r [-] (a target, or a measured value).

    Returns
    -------
    float
        The tolerance in r [-].
    """
    return max(LOSS_TOLERANCE * (1.0 - restitution), MIN_TOLERANCE)


def resolution_bound(block: Block) -> float:
    """The largest r [-] that free rocking which dies below the measure's resolution can have.

    The second peak below ``PEAK_FLOOR`` alpha after a launch to ``LAUNCH_FRACTION`` alpha (a rigid block):
    r < sqrt(drop(0.1 alpha) / drop(0.6 alpha)), drop(theta) = cos(alpha - theta) - cos(alpha).
    """
    alpha = block.alpha

    def drop(fraction):
        return math.cos(alpha * (1.0 - fraction)) - math.cos(alpha)

    return math.sqrt(drop(PEAK_FLOOR) / drop(LAUNCH_FRACTION))


@dataclass(frozen=True)
class Stability:
    """Whether free rocking at one xi is reproducible (module docstring, "Admissible xi").

    Attributes
    ----------
    xi : float
        The damping ratio [-].
    restitution : float
        r [-] of the definition (launch 0.6 alpha, nominal sampling); NaN when the rocking dies or overturns.
    spread : float
        The largest |r - r of the definition| over the other launches and samplings [-] (0 when it dies).
    largest_impact : float
        The largest r_k among the impacts counted, over all runs [-] (NaN when none).
    tolerance : float
        The tolerance the spread is held to [-].
    admissible : bool
        Reproducible: every run within the tolerance, no r_k above 1, and all runs rock (or all die).
    dies : bool
        Every run dies below the measure's resolution (admissible: it loses at least what the measure
        resolves).
    reason : str
        Why not admissible ("" when admissible).
    measures : tuple of float
        r [-] of every run made (the definition's first; NaN where it dies).
    """

    xi: float
    restitution: float
    spread: float
    largest_impact: float
    tolerance: float
    admissible: bool
    dies: bool
    reason: str
    measures: tuple = ()


@lru_cache(maxsize=4096)
def stability(block: Block, k: float, law: str, xi: float, g: float = STANDARD_GRAVITY,
              tolerance_r: float | None = None) -> Stability:
    """Free rocking at ``xi`` measured at launches 0.5, 0.6, 0.7 alpha and at half and double the sampling.

    Cheapest checks first: the definition's own run (overturning, r_k above 1), then the launches, then the
    samplings; the first failure is the reason.

    Parameters
    ----------
    block : Block
        The block.
    k : float
        Total vertical stiffness of the bed [N/m].
    law : str
        The contact law, used as given (a calibrated law: ``calibrated_law``).
    xi : float
        Its damping ratio [-].
    g : float
        Gravity [m/s^2].
    tolerance_r : float, optional
        The tolerance on r [-]; default ``tolerance`` of the definition's r.

    Returns
    -------
    Stability
        The measures and the verdict.
    """
    runs = [((LAUNCH_FRACTION, 1.0), free_rocking_impacts(block, k, law, xi, g, LAUNCH_FRACTION, 1.0))]

    def verdict(reason, r=math.nan, spread=math.nan, dies=False):
        counted = [r_k for _, impacts in runs if impacts for r_k in impacts]
        largest = max(counted) if counted else math.nan
        measures = tuple(float(np.median(run)) if run else math.nan for _, run in runs)
        return Stability(xi, r, spread, largest, tol, not reason, dies, reason, measures)

    impacts = runs[0][1]
    r = float(np.median(impacts)) if impacts else math.nan
    tol = tolerance_r if tolerance_r is not None else tolerance(r if math.isfinite(r) else 0.0)
    if impacts is None:
        return verdict(f"the block overturns when launched to {LAUNCH_FRACTION} alpha")
    spread = 0.0
    variants = [(f, 1.0) for f in STABILITY_LAUNCHES] + [(LAUNCH_FRACTION, s) for s in SAMPLINGS]
    for fraction, sampling in [(None, None)] + variants:  # None: the definition's run, already made
        bounce = max((r_k for _, run in runs if run for r_k in run), default=0.0)
        if bounce > 1.0:
            return verdict(f"the block bounces on the bed (an impact with r_k = {bounce:.3f} > 1)", r, spread)
        if fraction is None:
            continue
        run = free_rocking_impacts(block, k, law, xi, g, fraction, sampling)
        runs.append(((fraction, sampling), run))
        how = (f"launched to {fraction} alpha" if sampling == 1.0 else
               f"sampled {'twice as finely' if sampling > 1 else 'half as finely'}")
        if run is None:
            return verdict(f"the block overturns {how}", r)
        if bool(run) != bool(impacts):
            return verdict(f"the rocking {'dies below' if not run else 'rises above'} the measure's resolution "
                           f"{how}", r)
        if run:
            spread = max(spread, abs(float(np.median(run)) - r))
            if spread > tol:
                return verdict(f"r moves by {spread:.4f} (more than {tol:.4f}) {how}", r, spread)
    bounce = max((r_k for _, run in runs if run for r_k in run), default=0.0)
    if bounce > 1.0:
        return verdict(f"the block bounces on the bed (an impact with r_k = {bounce:.3f} > 1)", r, spread)
    return verdict("", r, spread, dies=not impacts)


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


@dataclass(frozen=True)
class Admissible:
    """The xi at which free rocking on a bed is reproducible (module docstring, "Admissible xi").

    Attributes
    ----------
    law : str
        The calibrated contact law.
    grid : tuple of float
        The xi grid [-] (``XI_RANGE``, ``GRID_RATIO``).
    restitution : tuple of float
        r [-] on the grid (NaN: dies or overturns).
    passed : tuple of bool
        Whether each grid xi passes ``stability``.
    reasons : tuple of str
        Why each grid xi does not ("" where it does).
    """

    law: str
    grid: tuple
    restitution: tuple
    passed: tuple
    reasons: tuple

    @property
    def indices(self) -> list[int]:
        """The grid indices of the admissible xi: runs of at least ``RUN`` neighbours that pass, low to high."""
        chosen, run = [], []
        for i, ok in enumerate(self.passed + (False,)):
            if ok:
                run.append(i)
                continue
            if len(run) >= RUN:
                chosen += run
            run = []
        return chosen

    @property
    def runs(self) -> list[tuple[float, float]]:
        """The admissible xi as ranges (first, last) [-] of neighbouring grid xi."""
        ranges, indices = [], self.indices
        for position, i in enumerate(indices):
            if position and indices[position - 1] == i - 1:
                ranges[-1] = (ranges[-1][0], self.grid[i])
            else:
                ranges.append((self.grid[i], self.grid[i]))
        return ranges

    @property
    def smallest(self) -> float | None:
        """The smallest admissible xi [-]; None when none is."""
        indices = self.indices
        return self.grid[indices[0]] if indices else None

    @property
    def rejected(self) -> str:
        """Why the grid xi just below the smallest admissible one is not admissible ("" when none is below)."""
        indices = self.indices
        below = [i for i in range(indices[0] if indices else len(self.grid)) if not self.passed[i]]
        if not below:
            return "" if indices else "; ".join(sorted(set(r for r in self.reasons if r)))
        return f"at xi = {self.grid[below[-1]]:.3g} {self.reasons[below[-1]]}"

    @property
    def reachable(self) -> tuple[float, float]:
        """(lowest, highest) r [-] measured at the admissible grid xi; (NaN, NaN) where every one dies."""
        finite = [self.restitution[i] for i in self.indices if math.isfinite(self.restitution[i])]
        return (min(finite), max(finite)) if finite else (math.nan, math.nan)

    @property
    def dies(self) -> bool:
        """Free rocking dies below the measure's resolution at every admissible xi."""
        return self.smallest is not None and not any(math.isfinite(self.restitution[i]) for i in self.indices)

    def describe(self) -> str:
        """"xi 0.099 to 0.99 (r 0.7142 to 0.8503)", for messages."""
        if self.smallest is None:
            return "no admissible xi"
        low, high = self.reachable
        reach = (f"r {low:.4f} to {high:.4f}" if math.isfinite(low) else
                 "where free rocking dies below the measure's resolution")
        ranges = ", ".join(f"{a:.3g} to {b:.3g}" for a, b in self.runs)
        return f"xi {ranges} ({reach})"


@lru_cache(maxsize=1024)
def admissible_xi(block: Block, k: float, bed: str, g: float = STANDARD_GRAVITY) -> Admissible:
    """The xi at which free rocking on ``bed`` is reproducible, for ``block`` on a bed of stiffness ``k``.

    Every xi of the grid of ``restitution_grid`` is checked (``stability``); the admissible xi are the runs of
    at least ``RUN`` neighbouring grid xi that pass (a single grid xi that passes between two that do not is
    not reproducible under a small change of the bed). Cached per block, k, bed and g.

    Parameters
    ----------
    block : Block
        The block.
    k : float
        Total vertical stiffness of the bed [N/m] (eq. 19).
    bed : str
        ``two-spring``, ``continuous`` (calibrated with Hunt-Crossley damping) or ``hunt-crossley``.
    g : float
        Gravity [m/s^2].

    Returns
    -------
    Admissible
        The grid, r on it and the verdict of each grid xi.
    """
    law = calibrated_law(bed)
    xis, rs = restitution_grid(block, float(k), law, float(g))
    verdicts = [stability(block, float(k), law, xi, float(g)) for xi in xis]
    return Admissible(law, xis, rs, tuple(v.admissible for v in verdicts), tuple(v.reason for v in verdicts))


def reachable_range(block: Block, k: float, bed: str, g: float = STANDARD_GRAVITY) -> tuple[float, float]:
    """(lowest, highest) effective restitution [-] that a target on ``bed`` can be calibrated to.

    The span of r over the admissible xi (``admissible_xi``); (NaN, NaN) when the measure is undefined at
    every admissible xi, or no xi is admissible.
    """
    return admissible_xi(block, float(k), bed, float(g)).reachable


@dataclass(frozen=True)
class Dissipation:
    """What ``calibrate_dissipation`` decided.

    Attributes
    ----------
    xi : float
        The damping ratio [-] of ``law``.
    law : str
        The contact law it is for (``calibrated_law`` of the bed).
    target : float
        The target r [-].
    tolerance : float
        The tolerance on r [-] (``tolerance`` of the target).
    restitution : float
        r [-] of free rocking at ``xi`` (the definition's); NaN when it dies below the measure's resolution.
    decision : str
        ``"hit"`` (r within the tolerance of the target, xi admissible) or ``"dies"`` (free rocking dies below
        the measure's resolution at every admissible xi, or the target is below what the measure resolves:
        the smallest such admissible xi; ``note`` says so).
    admissible : Admissible
        The admissible xi of this bed.
    note : str
        One line for ``"dies"``; "" otherwise.
    """

    xi: float
    law: str
    target: float
    tolerance: float
    restitution: float
    decision: str
    admissible: Admissible
    note: str = ""


def calibrate_dissipation(block: Block, k: float, bed: str, restitution: float | str,
                          g: float = STANDARD_GRAVITY) -> Dissipation:
    """The damping ratio xi of ``calibrated_law(bed)`` that gives free rocking the target restitution.

    The rule of the module docstring: among the admissible xi (``admissible_xi``), the smallest whose free
    rocking hits the target within ``tolerance(target)``, itself checked for stability. Cached per block, k,
    bed, target and g. ``simulate(..., restitution=...)`` and the study (rockfrag.models.variants) both call it.

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

    Returns
    -------
    Dissipation
        xi [-] (``simulate("winkler", ..., k=k, xi=xi, bed=law)`` rocks with the target restitution) and
        what was decided.

    Raises
    ------
    SolverError
        A target >= 1; a target reachable only at xi that are not admissible, or outside the range the
        admissible xi reach (one error naming the admissible range); no admissible xi at all.
    """
    return _calibrated(block, float(k), calibrated_law(bed), restitution_target(block, restitution), float(g), bed)


@lru_cache(maxsize=4096)
def _calibrated(block: Block, k: float, law: str, target: float, g: float, bed: str) -> Dissipation:
    admissible = admissible_xi(block, k, bed, g)
    xis, rs = admissible.grid, admissible.restitution
    band = tolerance(target)
    where = (f"the {bed} bed (law {law}) for block {block.name!r} (K = {k:.4g} N/m, "
             f"omega_v/p = {math.sqrt(k / block.mass) / block.p(g):.0f})")
    if admissible.smallest is None:
        raise SolverError(f"restitution target {target:.4f}: free rocking on {where} is not reproducible at any xi "
                          f"from {xis[0]:g} to {xis[-1]:g} ({admissible.rejected})")

    def within(r: float) -> bool:
        return math.isfinite(r) and abs(r - target) <= band

    def measure(xi: float) -> float:
        return free_rocking_restitution(block, k, law, xi, g)

    def admitted(xi: float) -> Stability | None:
        """The verdict at xi when it is admissible and every run of the check hits the target, else None."""
        verdict = stability(block, k, law, xi, g, band)
        return verdict if verdict.admissible and all(within(r) for r in verdict.measures) else None

    indices = admissible.indices
    # the smallest admissible xi that hits: grid points within the tolerance and crossings between neighbours
    for i in indices:
        if within(rs[i]) and admitted(xis[i]):
            return Dissipation(xis[i], law, target, band, rs[i], "hit", admissible)
        following = i + 1 if i + 1 in indices else None
        if following is None or not (math.isfinite(rs[i]) and math.isfinite(rs[following])):
            continue
        if (rs[i] - target) * (rs[following] - target) < 0.0:
            xi = _root(measure, target, xis[i], xis[following])
            verdict = admitted(xi) if xi is not None else None
            if verdict:
                return Dissipation(xi, law, target, band, verdict.restitution, "hit", admissible)
    low, high = admissible.reachable
    resolved = resolution_bound(block)
    dying = [xis[i] for i in indices if not math.isfinite(rs[i])]
    if dying and (admissible.dies or target < low) and target <= resolved + band:
        xi = dying[0] if not admissible.dies else admissible.smallest
        note = (f"free rocking of block {block.name!r} on {where} dies below the measure's resolution (its second "
                f"peak under {PEAK_FLOOR} alpha: r below about {resolved:.2f}) at "
                f"{'every admissible xi' if admissible.dies else f'the admissible xi from {xi:.3g} up'}: it loses at "
                f"least what the measure resolves; target {target:.4f} runs at xi = {xi:.3g}")
        return Dissipation(xi, law, target, band, math.nan, "dies", admissible, note)
    elsewhere = [i for i in range(len(xis)) if i not in indices and within(rs[i])]
    crossing = [i for i in range(len(xis) - 1) if not {i, i + 1} <= set(indices) and math.isfinite(rs[i])
                and math.isfinite(rs[i + 1]) and (rs[i] - target) * (rs[i + 1] - target) < 0.0]
    if elsewhere or crossing:
        reached = sorted({xis[i] for i in elsewhere} | {xis[i] for i in crossing})
        raise SolverError(f"restitution target {target:.4f} is reached only at xi where free rocking is not "
                          f"reproducible (near xi {', '.join(f'{x:.3g}' for x in reached)}; {admissible.rejected}); "
                          f"the admissible {admissible.describe()} of {where} do not reach it")
    raise SolverError(f"restitution target {target:.4f} is outside the reach of {where}: its admissible "
                      f"{admissible.describe()} (tolerance {band:.4f}; Housner's value is "
                      f"{block.housner_restitution():.4f})")


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
