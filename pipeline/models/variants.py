"""rockfrag.models.variants - a bed model run at the edges and centre of a restitution band.

Input : a registered bed model (``winkler``), the band's edges as multiples of Housner's restitution
        (``[solver] restitution_band``), the blocks, their bed stiffnesses K [N/m] per soil and the bed law.
Output: the variant names (``winkler-low``, ``winkler-centre``, ``winkler-high``; ``band_variants``), the
        model a variant runs (``split_variant``), and per (soil, block) the requested target, the target used
        and the calibrated damping ratio xi of each variant (``calibrate_models``).

Why a band: the restitution of a real block's impacts is measured, not free. Experiments on rigid bases
(ElGawady et al. 2011; Kalliontzis et al. 2016; Ther & Kollar 2017) find real blocks lose about as much as
Housner predicts, or a few percent less; the band runs the admissible model from Housner's value
r_H = 1 - 1.5 sin^2(alpha) to min(1.05 r_H, 0.99) and its spread is the model uncertainty of the recommended
fragility (rockfrag.fragility). The centre is the arithmetic middle of the two edges.

Each variant is calibrated by the one rule of ``simulate(..., restitution=r)``
(``restitution.calibrate_dissipation``: the smallest admissible xi, where free rocking is reproducible, that
hits the target within its tolerance); the floor of xi is that rule's consequence per block and bed
(``restitution.admissible_xi``), not a constant. Where the admissible xi cannot reach an edge (a stiff
two-spring bed stays near Housner's value), the target used is the nearest end of the range they reach.
This is the one place a target is moved: a ``simulate(..., restitution=r)`` call still refuses an
unreachable r. Each moved target is written beside the requested one in the cube
(``restitution_requested``, ``restitution_target``) and listed by the study. Where free rocking dies below
the measure's resolution at every admissible xi (the squat skid), the variant runs at the smallest admissible
xi with a NaN target and one note.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rockfrag.blocks import Block
from rockfrag.errors import SolverError
from rockfrag.models.restitution import admissible_xi, calibrate_dissipation, calibrated_law, restitution_target
from rockfrag.units import STANDARD_GRAVITY

RECOMMENDED = "recommended"
"""The model name of the recommended curves the fragility stage combines from a band's variants
(rockfrag.fragility.with_recommended); every output that carries them uses this name."""
BAND_ROLES = {"low": 0.0, "centre": 0.5, "high": 1.0}
"""A variant's position in the band, from the low edge (Housner's value) to the high edge."""
BAND_LABELS = {"low": "band low edge", "centre": "band centre", "high": "band high edge"}
RESTITUTION_CAP = 0.99
"""The band's edges are capped here: r = 1 would be a block that never loses energy at an impact."""
DEFAULT_BAND = (1.0, 1.05)
MOVED_TOLERANCE = 5e-4
"""A target moved by less than this (into a reachable range that ends at it within the grid's resolution) is
reported as not moved."""
"""The band's edges as multiples of Housner's r (the experimental range on rigid bases)."""


def variant_name(model: str, role: str) -> str:
    """The name of ``model`` run at a band position: ``winkler-low``, ``winkler-centre``, ``winkler-high``."""
    return f"{model}-{role}"


def split_variant(name: str) -> tuple[str, str | None]:
    """(model, role) of a variant name; (name, None) for a name that is not a variant."""
    model, _, role = str(name).rpartition("-")
    return (model, role) if model and role in BAND_ROLES else (str(name), None)


def band_variants(model: str) -> list[str]:
    """The variants of ``model`` a band runs, low edge first."""
    return [variant_name(model, role) for role in BAND_ROLES]


def band_target(block: Block, band: tuple[float, float], role: str) -> float:
    """The restitution a variant asks for [-]: its position between the edges, each edge capped at 0.99.

    Parameters
    ----------
    block : Block
        The block (Housner's r from its alpha).
    band : (float, float)
        The edges as multiples of Housner's r.
    role : str
        ``low``, ``centre`` or ``high``.

    Returns
    -------
    float
        The requested effective restitution [-].
    """
    housner = block.housner_restitution()
    low, high = (min(factor * housner, RESTITUTION_CAP) for factor in band)
    return low + BAND_ROLES[role] * (high - low)


@dataclass(frozen=True)
class BandCalibration:
    """Per (soil, block, variant): the requested restitution, the one used, and the calibrated xi [-].

    Arrays of shape (n_soil, n_block, n_variant), variants in ``variants`` order.
    """

    variants: tuple[str, ...]
    law: str
    requested: np.ndarray
    target: np.ndarray
    xi: np.ndarray
    reachable: np.ndarray  # (n_soil, n_block, 2): the range of r the admissible xi reach [-]
    smallest_xi: np.ndarray  # (n_soil, n_block): the smallest admissible xi [-] (restitution.admissible_xi)
    notes: tuple = ()  # one line per cell that runs where free rocking dies below the measure's resolution

    @property
    def moved(self) -> np.ndarray:
        """True where the target used is not the requested one (outside the reachable range, or NaN)."""
        return ~np.isclose(self.requested, self.target, rtol=0, atol=MOVED_TOLERANCE)


def calibrate_models(blocks: list[Block], soil_names: list[str], stiffness: np.ndarray, models: list[str],
                     restitution: str | float, band: tuple[float, float], bed: str,
                     g: float = STANDARD_GRAVITY) -> BandCalibration:
    """Calibrate the bed's damping of every bed model (or band variant) on every (soil, block).

    Parameters
    ----------
    blocks : list of Block
        The study's blocks.
    soil_names : list of str
        The soils' names (for errors).
    stiffness : ndarray, shape (n_soil, n_block)
        The bed's total vertical stiffness K [N/m] of each soil under each block (eq. 19).
    models : list of str
        The bed models to calibrate: band variants (``band_variants``) or plain bed models.
    restitution : str or float
        ``[solver] restitution``: a plain bed model takes this target ("housner" or a number) and refuses it
        where the bed cannot reach it; a band variant takes its place in ``band`` (moved into reach).
    band : (float, float)
        The band's edges as multiples of Housner's r.
    bed : str
        The bed law of the study (``[solver] bed``); calibrated with ``calibrated_law(bed)``.
    g : float
        Gravity [m/s^2].

    Returns
    -------
    BandCalibration
        Requested and used targets, calibrated xi and the reachable range of each cell.

    Raises
    ------
    SolverError
        A plain target the bed cannot reach on a (soil, block): the message names both and the range.
    """
    n_soil, n_block = stiffness.shape
    shape = (n_soil, n_block, len(models))
    requested, target, xi = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    reachable = np.full((n_soil, n_block, 2), np.nan)
    smallest = np.full((n_soil, n_block), np.nan)
    notes = []
    for s in range(n_soil):
        for b, block in enumerate(blocks):
            k = float(stiffness[s, b])
            where = f"block {block.name!r} on soil {soil_names[s]!r} (K = {k:.3g} N/m)"
            admissible = admissible_xi(block, k, bed, g)
            reachable[s, b] = admissible.reachable
            smallest[s, b] = admissible.smallest if admissible.smallest is not None else np.nan
            for v, name in enumerate(models):
                role = split_variant(name)[1]
                wanted = restitution_target(block, restitution) if role is None else band_target(block, band, role)
                requested[s, b, v] = wanted
                try:
                    dissipation = calibrate_to_target(block, k, bed, wanted, admissible.reachable,
                                                      movable=role is not None, g=g)
                except SolverError as error:
                    raise SolverError(f"{where}, model {name!r}: {error}") from None
                xi[s, b, v] = dissipation.xi
                # "dies": the measure cannot resolve r there (NaN); it loses at least about Housner's value
                target[s, b, v] = dissipation.target if dissipation.decision == "hit" else np.nan
                if dissipation.note:
                    notes.append(f"{where}, model {name!r}: {dissipation.note}")
    return BandCalibration(tuple(models), calibrated_law(bed), requested, target, xi, reachable, smallest,
                           tuple(dict.fromkeys(notes)))


def calibrate_to_target(block: Block, k: float, bed: str, wanted: float, reachable: tuple[float, float], *,
                        movable: bool, g: float = STANDARD_GRAVITY):
    """The calibrated dissipation of one (block, bed) for one restitution target: the one rule of the study.

    A band position (``movable``) the admissible xi cannot reach runs at the nearest r they reach (the study
    lists it); a plain target is refused (``restitution.calibrate_dissipation``'s error).

    Parameters
    ----------
    block : Block
        The block.
    k : float
        The bed's total vertical stiffness [N/m].
    bed : str
        The bed law the target is calibrated on (``[solver] bed``).
    wanted : float
        The requested effective restitution [-].
    reachable : (float, float)
        The range of r the admissible xi reach (``restitution.admissible_xi(...).reachable``).
    movable : bool
        True for a band position (moved into reach), False for a plain target (refused out of reach).
    g : float
        Gravity [m/s^2].

    Returns
    -------
    rockfrag.models.restitution.Dissipation
        The calibrated damping ratio xi, its decision and the target it hit.
    """
    try:
        return calibrate_dissipation(block, k, bed, wanted, g=g)
    except SolverError:
        low, high = reachable
        if not movable or not math.isfinite(low):
            raise
        return calibrate_dissipation(block, k, bed, min(max(wanted, low), high), g=g)


RECOMMENDED_BED = "two-spring"
"""The recommended model's bed law (the study's default ``[solver] bed``; a test checks they agree)."""


@dataclass(frozen=True)
class CentralMember:
    """The recommended model's run on one (block, soil), as the study's cells and ``simulate`` run it.

    Attributes
    ----------
    model : str
        The solver model it runs (``winkler``, the tensionless bed).
    k : float
        The bed's total vertical stiffness [N/m] (eq. 19, the soil's G and the block's modulus).
    xi : float
        The bed's damping ratio [-], calibrated to ``restitution_target`` by the study's one rule.
    bed : str
        The contact law the bed runs (``restitution.calibrated_law`` of ``RECOMMENDED_BED``).
    friction : (float, float)
        The base's (mu_s, mu_k) [-]: the soil's stated friction (the recommended model always slides).
    restitution_requested : float
        The centre of the experimental restitution band [-].
    restitution_target : float
        The restitution the calibration hit [-]; NaN where free rocking dies below the measure's resolution.
    """

    model: str
    k: float
    xi: float
    bed: str
    friction: tuple[float, float]
    restitution_requested: float
    restitution_target: float


def central_member(block: Block, soil, *, bed: str = RECOMMENDED_BED, band: tuple[float, float] = DEFAULT_BAND,
                   g: float = STANDARD_GRAVITY) -> CentralMember:
    """The recommended model's central run of ``block`` on ``soil`` (the band's centre; see ``band_member``)."""
    return band_member(block, soil, "centre", bed=bed, band=band, g=g)


def band_member(block: Block, soil, role: str, *, bed: str = RECOMMENDED_BED,
                band: tuple[float, float] = DEFAULT_BAND, g: float = STANDARD_GRAVITY) -> CentralMember:
    """The recommended model's run of ``block`` on ``soil`` at a band position.

    The one definition the study's calibration (``calibrate_models``, through ``calibrate_to_target``) and the API
    (``simulate("recommended", ...)``) share.

    Parameters
    ----------
    block : Block
        The block.
    soil : rockfrag.soils.SoilClass
        The soil (shear modulus, friction).
    role : str
        ``low``, ``centre`` (the central run) or ``high``.
    bed : str
        The bed law (``[solver] bed``), default the study's.
    band : (float, float)
        The restitution band's edges as multiples of Housner's r.
    g : float
        Gravity [m/s^2].

    Returns
    -------
    CentralMember
        Its stiffness, calibrated damping, contact law and friction.

    Raises
    ------
    SolverError
        The bed cannot be calibrated on this block (no admissible xi).
    """
    from rockfrag.soils import soil_block_stiffness  # soils imports the models' registry

    k = float(soil_block_stiffness(soil, block))
    wanted = band_target(block, band, role)
    dissipation = calibrate_to_target(block, k, bed, wanted, admissible_xi(block, k, bed, g).reachable,
                                      movable=True, g=g)
    target = dissipation.target if dissipation.decision == "hit" else float("nan")
    return CentralMember(model="winkler", k=k, xi=float(dissipation.xi), bed=calibrated_law(bed),
                         friction=tuple(soil.friction), restitution_requested=wanted, restitution_target=target)
