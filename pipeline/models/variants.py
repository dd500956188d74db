"""rockfrag.models.variants - the recommended model and its designed sample over the epistemic parameters.

Input : a registered bed model (``winkler``), the sample design (``SampleDesign``: the restitution range as
        multiples of Housner's restitution, the friction and stiffness factors), the blocks, their bed
        stiffnesses K [N/m] per soil (eq. 19) and the bed law.
Output: the sample's model names (``recommended``, the central member, and ``recommended-<member>``;
        ``sample_models``), the model a member runs (``split_variant``), each member's restitution target,
        friction and stiffness (``member_restitution``, ``member_friction``, ``member_stiffness_factor``), and
        per (soil, block) the requested target, the target used and the calibrated damping ratio xi of each
        member (``calibrate_models``).

The recommended model is the tensionless two-spring bed with friction at the base. Three of its parameters
are known only within a range (epistemic uncertainty):

- restitution of the impacts: experiments on rigid bases (ElGawady et al. 2011; Kalliontzis et al. 2016;
  Ther & Kollar 2017) find real blocks lose about as much as Housner predicts, or a few percent less: the
  range runs from Housner's r_H = 1 - 1.5 sin^2(alpha) to min(1.05 r_H, 0.99);
- the base friction (mu_s and mu_k together): the soil's stated pair x/÷ ``FRICTION_FACTOR`` = 1.2, the
  widest ratio of the ends of NAVFAC DM-7.02 (1986) Table 1's ranges for concrete on soil (fine to medium
  sand 0.45-0.55, ratio 1.22; medium stiff and stiff clay 0.30-0.35, 1.17; gravel 0.55-0.60, 1.09);
- the bed's stiffness K of eq. 19 through the soil's shear modulus G: x/÷ ``STIFFNESS_FACTOR`` = 2, the
  lower and upper bound of the best-estimate shear modulus, G/(1 + C_v) and G(1 + C_v) with C_v = 1 where
  the soil is not investigated at the site (ASCE 4-16 Seismic Analysis of Safety-Related Nuclear Structures,
  Section 5.1.7; ASCE 4-98 Section 3.3.1.7). This is the bed's stiffness, not the site's Vs30.

The contact law is not sampled: only the two-spring law reaches Housner's restitution on every bed (docs
site, theory/bed.md, "Contact laws"; the continuous bed loses more at every admissible xi), so only one law reaches
the range.

The design: one-at-a-time points at the two ends of each parameter's range, the others at their central
value (2n + 1 = 7 runs for n = 3 parameters; a point estimate in the manner of Rosenblueth 1981, "Two-point
estimates in probabilities", Appl. Math. Modelling 5, for uncorrelated variables). Each range is read as
uniform in the logarithm of the fragility median between its ends' medians, so parameter i adds
sigma_i = |ln(m_i,high / m_i,low)| / (2 sqrt 3) and beta_parameters = sqrt(sum sigma_i^2)
(rockfrag.fragility.MODEL_UNCERTAINTY). The central member is the soil's stated friction and G and the
middle of the restitution range: the recommended curve's run.

Each member's restitution target is calibrated by the one rule of ``simulate(..., restitution=r)``
(``restitution.calibrate_dissipation``: the smallest admissible xi, where free rocking is reproducible, that
hits the target within its tolerance). Where the admissible xi cannot reach a target (a stiff two-spring bed
stays near Housner's value), the target used is the nearest end of the range they reach: the one place a
target is moved (``simulate(..., restitution=r)`` still refuses an unreachable r). Each moved target is
written beside the requested one in the cube (``restitution_requested``, ``restitution_target``) and listed
by the study. Where free rocking dies below the measure's resolution at every admissible xi (the squat skid),
the member runs at the smallest admissible xi with a NaN target and one note.
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
"""The model name of the recommended model's central run (the cube's and fragility.nc's ``model``); its
sample members are ``recommended-<member>``."""
BED_MODEL = "winkler"
"""The solver model the recommended model and its members run."""
PARAMETERS = ("restitution", "friction", "stiffness")
"""The sampled epistemic parameters, in the design's order."""
MEMBERS = ("centre", *(f"{parameter}_{side}" for parameter in PARAMETERS for side in ("low", "high")))
"""The design's members: the centre, then each parameter at the low and high end of its range."""
MEMBER_LABELS = {"centre": "central member",
                 **{f"{p}_{side}": f"{p} at the {side} end" for p in PARAMETERS for side in ("low", "high")}}
RESTITUTION_CAP = 0.99
"""The range's ends are capped here: r = 1 would be a block that never loses energy at an impact."""
DEFAULT_RESTITUTION_RANGE = (1.0, 1.05)
"""The restitution range's ends as multiples of Housner's r (the experimental range on rigid bases)."""
FRICTION_FACTOR = 1.2
"""The friction members run the soil's (mu_s, mu_k) times and divided by this (NAVFAC DM-7.02 Table 1)."""
STIFFNESS_FACTOR = 2.0
"""The stiffness members run the soil's G times and divided by this (ASCE 4-16 5.1.7, C_v = 1)."""
MOVED_TOLERANCE = 5e-4
"""A target moved by less than this (into a reachable range that ends at it within the grid's resolution) is
reported as not moved."""
OLD_BAND_NAMES = ("winkler-low", "winkler-centre", "winkler-high")
"""The restitution band's variants before the designed sample (refused with the new names)."""


@dataclass(frozen=True)
class SampleDesign:
    """The ranges of the recommended model's sampled parameters (``[uncertainty]`` of a study).

    Attributes
    ----------
    restitution_range : (float, float)
        The restitution range's ends as multiples of Housner's r (each capped at 0.99).
    friction_factor : float
        The friction members' factor on the soil's (mu_s, mu_k) [-], > 1.
    stiffness_factor : float
        The stiffness members' factor on the soil's G (so on K, eq. 19 with a rigid block) [-], > 1.
    """

    restitution_range: tuple[float, float] = DEFAULT_RESTITUTION_RANGE
    friction_factor: float = FRICTION_FACTOR
    stiffness_factor: float = STIFFNESS_FACTOR


DEFAULT_DESIGN = SampleDesign()


def member_model(member: str) -> str:
    """The model name of a member: ``recommended`` for the centre, ``recommended-<member>`` otherwise."""
    return RECOMMENDED if member == "centre" else f"{RECOMMENDED}-{member}"


def sample_models() -> list[str]:
    """The model names of the recommended model's sample, the central member first."""
    return [member_model(member) for member in MEMBERS]


def split_variant(name: str) -> tuple[str, str | None]:
    """(solver model, member) of a sample member's name; (name, None) for a name that is not one."""
    name = str(name)
    if name == RECOMMENDED:
        return BED_MODEL, "centre"
    prefix, _, member = name.partition("-")
    return (BED_MODEL, member) if prefix == RECOMMENDED and member in MEMBERS[1:] else (name, None)


def _side(member: str, parameter: str) -> int:
    """-1, 0 or +1: where ``member`` puts ``parameter`` (the low end, the centre, the high end)."""
    return {f"{parameter}_low": -1, f"{parameter}_high": 1}.get(member, 0)


def member_restitution(block: Block, design: SampleDesign, member: str) -> float:
    """The restitution a member asks for [-]: an end of the range, or its middle (each end capped at 0.99).

    Parameters
    ----------
    block : Block
        The block (Housner's r from its alpha).
    design : SampleDesign
        The range's ends as multiples of Housner's r.
    member : str
        A member of ``MEMBERS``.

    Returns
    -------
    float
        The requested effective restitution [-].
    """
    housner = block.housner_restitution()
    low, high = (min(factor * housner, RESTITUTION_CAP) for factor in design.restitution_range)
    return low + 0.5 * (1 + _side(member, "restitution")) * (high - low)


def member_friction(friction: tuple[float, float], design: SampleDesign, member: str) -> tuple[float, float]:
    """A member's base friction (mu_s, mu_k) [-]: the soil's, times or divided by the friction factor."""
    factor = design.friction_factor ** _side(member, "friction")
    return float(friction[0]) * factor, float(friction[1]) * factor


def member_stiffness_factor(design: SampleDesign, member: str) -> float:
    """A member's factor on the bed's stiffness K [-] (eq. 19 scales with G for a rigid block)."""
    return design.stiffness_factor ** _side(member, "stiffness")


def member_stiffness(soil, block: Block, design: SampleDesign, member: str) -> float:
    """A member's bed stiffness K [N/m]: eq. 19 with the soil's G times or divided by the stiffness factor."""
    from dataclasses import replace

    from rockfrag.soils import soil_block_stiffness  # soils imports the models' registry

    factor = member_stiffness_factor(design, member)
    return float(soil_block_stiffness(replace(soil, shear_modulus=soil.shear_modulus * factor), block))


@dataclass(frozen=True)
class SampleCalibration:
    """Per (soil, block, model): the requested restitution, the one used, and the calibrated xi [-].

    Arrays of shape (n_soil, n_block, n_model), models in ``variants`` order.
    """

    variants: tuple[str, ...]
    law: str
    requested: np.ndarray
    target: np.ndarray
    xi: np.ndarray
    reachable: np.ndarray  # (n_soil, n_block, 2): the range of r the admissible xi reach on the soil's K [-]
    smallest_xi: np.ndarray  # (n_soil, n_block): the smallest admissible xi on the soil's K [-]
    notes: tuple = ()  # one line per cell that runs where free rocking dies below the measure's resolution

    @property
    def moved(self) -> np.ndarray:
        """True where the target used is not the requested one (outside the reachable range, or NaN)."""
        return ~np.isclose(self.requested, self.target, rtol=0, atol=MOVED_TOLERANCE)


def calibrate_models(blocks: list[Block], soil_names: list[str], stiffness: np.ndarray, models: list[str],
                     restitution: str | float, design: SampleDesign, bed: str,
                     g: float = STANDARD_GRAVITY) -> SampleCalibration:
    """Calibrate the bed's damping of every bed model (or sample member) on every (soil, block).

    Parameters
    ----------
    blocks : list of Block
        The study's blocks.
    soil_names : list of str
        The soils' names (for errors).
    stiffness : ndarray, shape (n_soil, n_block, n_model)
        The bed's total vertical stiffness K [N/m] of each model on each soil under each block (eq. 19; a
        stiffness member's own, ``member_stiffness``).
    models : list of str
        The bed models to calibrate: sample members (``sample_models``) or plain bed models.
    restitution : str or float
        ``[solver] restitution``: a plain bed model takes this target ("housner" or a number) and refuses it
        where the bed cannot reach it; a sample member takes its place in the design's range (moved into reach).
    design : SampleDesign
        The restitution range's ends as multiples of Housner's r.
    bed : str
        The bed law of the study (``[solver] bed``); calibrated with ``calibrated_law(bed)``.
    g : float
        Gravity [m/s^2].

    Returns
    -------
    SampleCalibration
        Requested and used targets, calibrated xi and the reachable range of each cell.

    Raises
    ------
    SolverError
        A plain target the bed cannot reach on a (soil, block): the message names both and the range.
    """
    n_soil, n_block = stiffness.shape[:2]
    shape = (n_soil, n_block, len(models))
    requested, target, xi = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    reachable = np.full((n_soil, n_block, 2), np.nan)
    smallest = np.full((n_soil, n_block), np.nan)
    notes = []
    for s in range(n_soil):
        for b, block in enumerate(blocks):
            for v, name in enumerate(models):
                k = float(stiffness[s, b, v])
                where = f"block {block.name!r} on soil {soil_names[s]!r} (K = {k:.3g} N/m)"
                admissible = admissible_xi(block, k, bed, g)
                member = split_variant(name)[1]
                if member in (None, "centre"):
                    reachable[s, b] = admissible.reachable
                    smallest[s, b] = admissible.smallest if admissible.smallest is not None else np.nan
                wanted = (restitution_target(block, restitution) if member is None
                          else member_restitution(block, design, member))
                requested[s, b, v] = wanted
                try:
                    dissipation = calibrate_to_target(block, k, bed, wanted, admissible.reachable,
                                                      movable=member is not None, g=g)
                except SolverError as error:
                    raise SolverError(f"{where}, model {name!r}: {error}") from None
                xi[s, b, v] = dissipation.xi
                # "dies": the measure cannot resolve r there (NaN); it loses at least about Housner's value
                target[s, b, v] = dissipation.target if dissipation.decision == "hit" else np.nan
                if dissipation.note:
                    notes.append(f"{where}, model {name!r}: {dissipation.note}")
    return SampleCalibration(tuple(models), calibrated_law(bed), requested, target, xi, reachable, smallest,
                             tuple(dict.fromkeys(notes)))


def calibrate_to_target(block: Block, k: float, bed: str, wanted: float, reachable: tuple[float, float], *,
                        movable: bool, g: float = STANDARD_GRAVITY):
    """The calibrated dissipation of one (block, bed) for one restitution target: the one rule of the study.

    A sample member's target (``movable``) the admissible xi cannot reach runs at the nearest r they reach (the
    study lists it); a plain target is refused (``restitution.calibrate_dissipation``'s error).

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
        True for a sample member (moved into reach), False for a plain target (refused out of reach).
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
        The middle of the experimental restitution range [-].
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


def central_member(block: Block, soil, *, bed: str = RECOMMENDED_BED, design: SampleDesign = DEFAULT_DESIGN,
                   g: float = STANDARD_GRAVITY) -> CentralMember:
    """The recommended model's central run of ``block`` on ``soil`` (see ``sample_member``)."""
    return sample_member(block, soil, "centre", bed=bed, design=design, g=g)


def sample_member(block: Block, soil, member: str, *, bed: str = RECOMMENDED_BED,
                  design: SampleDesign = DEFAULT_DESIGN, g: float = STANDARD_GRAVITY) -> CentralMember:
    """The recommended model's run of ``block`` on ``soil`` as one member of the designed sample.

    The one definition the study's calibration (``calibrate_models``, through ``calibrate_to_target``) and the API
    (``simulate("recommended", ...)``) share.

    Parameters
    ----------
    block : Block
        The block.
    soil : rockfrag.soils.SoilClass
        The soil (shear modulus, friction).
    member : str
        A member of ``MEMBERS`` (``centre``: the central run).
    bed : str
        The bed law (``[solver] bed``), default the study's.
    design : SampleDesign
        The sampled ranges.
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
    k = member_stiffness(soil, block, design, member)
    wanted = member_restitution(block, design, member)
    dissipation = calibrate_to_target(block, k, bed, wanted, admissible_xi(block, k, bed, g).reachable,
                                      movable=True, g=g)
    target = dissipation.target if dissipation.decision == "hit" else float("nan")
    return CentralMember(model=BED_MODEL, k=k, xi=float(dissipation.xi), bed=calibrated_law(bed),
                         friction=member_friction(soil.friction, design, member), restitution_requested=wanted,
                         restitution_target=target)
