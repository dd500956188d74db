"""rockfrag.plausibility - physical plausibility of a study's blocks, soils and their foundations.

Input : the study's blocks (``rockfrag.blocks.Block``: b, h, R [m], mass [kg], E_b [Pa], footprint
        area [m^2], soil depth [m]) and soils (``rockfrag.soils.SoilClass``: G_s [Pa]), and for each
        pair its ``rockfrag.soils.Foundation`` (k [N/m], static settlement m g / k [m], omega_v / p).
Output: one line per implausible value, naming the value with its unit, its consequence and the
        likely unit slip, e.g. ``block 'cabinet': E_b = 200 Pa is below 1 MPa (static settlement
        204 m on clay): did you mean 200 GPa?``. ``check_study`` raises the first as a ``ConfigError``
        naming the study file and field, or (``on_implausible="warn"``, for an expert) warns and goes on.

A check is one function ``(block, soil, foundation) -> str | None`` registered with
``@plausibility_check(name, field)`` in ``CHECKS``, in the order the checks are tried: the moduli and
sizes whose unit slips they name come before the density, settlement and frequency they cause (b and h
in mm are a size slip, not a mass one: the density check stays silent then). A block given
both ways (R and b/h) is refused when it is built (``rockfrag.blocks.geometry_conflict``): after that
the keys given are no longer known.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Callable, Iterable

from rockfrag.blocks import Block
from rockfrag.errors import ConfigError
from rockfrag.soils import Foundation, SoilClass, foundation

MIN_MODULUS = 1.0e6
"""Smallest plausible E_b and soil shear modulus G_s [Pa] (1 MPa; soft clay has G_s of ~5 MPa)."""

DENSITY_RANGE = (5.0, 8000.0)
"""Plausible mass per bounding volume (footprint area x 2h) [kg/m^3]: from hollow cabinets and crane
frames (a few tens) to solid steel (7850), with room on both sides."""

MAX_HALF_SIZE = 100.0
"""Largest plausible half-width b or half-height h [m] (a block 200 m tall is a building, not a rocking block):
beyond it b and h were most likely given in mm or cm."""

MAX_FOOTPRINT_DEPTH = 50.0
"""Largest depth out of plane of the footprint, footprint_area / 2b, as a multiple of the block's
largest in-plane dimension max(2b, 2h)."""

MAX_SOIL_DEPTH = 20.0
"""Largest effective soil depth H as a multiple of max(2b, 2h, 1 m): the soil a block loads reaches
about as deep as its base is wide."""

MAX_SETTLEMENT = 0.10
"""Largest static settlement m g / k as a fraction of the block's smaller half-dimension min(b, h)."""

MIN_FREQUENCY_RATIO = 3.0
"""Smallest vertical bed frequency omega_v = sqrt(k/m) as a multiple of Housner's p = sqrt(3g/(4R)):
below it the bed is as slow as the rocking, outside what a rocking-on-a-bed model describes."""

BLOCK_MODULI = (1e8, 1e12, 5e10)
"""(low, high, typical) Young's modulus of a block [Pa]: timber and plastics to steel."""

SOIL_MODULI = (1e6, 1e11, 1e8)
"""(low, high, typical) soil shear modulus [Pa]: soft clay to hard rock."""

ON_IMPLAUSIBLE = ("error", "warn")
"""What ``check_study`` does with an implausible value: stop (the default) or warn and go on."""

OVERRIDE_HINT = 'to run it anyway, set [checks] plausibility = "warn" or pass --force'
"""How an expert overrides the checks (the end of each error line)."""


class PlausibilityWarning(UserWarning):
    """An implausible block, soil or foundation value run anyway (``on_implausible="warn"``)."""


@dataclass(frozen=True)
class PlausibilityCheck:
    """One registered check.

    Attributes
    ----------
    name : str
        Short name, e.g. ``block modulus``.
    field : str
        The study field blamed, with ``{block}`` and ``{soil}`` placeholders, e.g. ``blocks.{block}.E_b``.
    function : callable
        ``(block, soil, foundation) -> str | None``: the message, or None when the value is plausible.
    """

    name: str
    field: str
    function: Callable[[Block, SoilClass, Foundation], str | None]


CHECKS: list[PlausibilityCheck] = []
"""The checks, in the order they are tried."""


def plausibility_check(name: str, field: str) -> Callable:
    """Register the decorated function as a check of ``CHECKS`` (see ``PlausibilityCheck``)."""
    def register(function):
        CHECKS.append(PlausibilityCheck(name, field, function))
        return function
    return register


# ---------------------------------------------------------------- the likely unit slips

def _modulus_slip(value: float, moduli: tuple[float, float, float], units: tuple[str, ...]) -> str:
    """``did you mean 200 GPa?``: the unit that puts ``value`` nearest the typical modulus."""
    low, high, typical = moduli
    factors = {"GPa": 1e9, "MPa": 1e6, "kPa": 1e3}
    fits = [(abs(math.log10(value * factors[unit] / typical)), unit) for unit in units
            if low <= value * factors[unit] <= high]
    if not fits:
        return "give it in Pa (e.g. 30e9 for concrete, 80e6 for sand)"
    return f"did you mean {value:g} {min(fits)[1]}?"


def _mass_slip(block: Block, density: float) -> str:
    low, high = DENSITY_RANGE
    if low <= density * 1e3 <= high:
        return f"did you mean {block.mass:g} t = {block.mass * 1e3:g} kg?"
    if low <= density / 1e3 <= high:
        return f"did you mean {block.mass:g} g = {block.mass / 1e3:g} kg?"
    return "check mass [kg], footprint_area [m^2] and h [m]"


def _length_slip(block: Block) -> str:
    """``did you mean mm (b = 0.5 m, h = 1 m)?``: the unit that brings b and h nearest a 1 m block."""
    largest = max(block.b, block.h)
    fits = [(abs(math.log10(largest / factor)), unit, factor) for unit, factor in (("mm", 1e3), ("cm", 1e2))
            if largest / factor <= MAX_HALF_SIZE]
    if not fits:
        return "give the half-width b and half-height h in m"
    _, unit, factor = min(fits)
    return f"did you mean {unit} (b = {block.b / factor:g} m, h = {block.h / factor:g} m)?"


def _area_slip(block: Block) -> str:
    """``did you mean 800000 mm^2 = 0.8 m^2?``: the unit giving a base nearest a square 2b x 2b.

    Of the units that give a plausible base, the one whose depth out of plane is nearest the block's width
    2b, not merely the first that passes.
    """
    width = 2.0 * block.b
    fits = [(abs(math.log10(block.footprint_area / factor / width / width)), unit, factor)
            for unit, factor in (("cm^2", 1e4), ("mm^2", 1e6))
            if block.footprint_area / factor / width <= MAX_FOOTPRINT_DEPTH * _size(block)]
    if not fits:
        return "give the base area in m^2 (2b times the depth out of plane)"
    _, unit, factor = min(fits)
    return f"did you mean {block.footprint_area:g} {unit} = {block.footprint_area / factor:g} m^2?"


def _foundation_slip(block: Block, soil: SoilClass) -> str:
    """The inputs of k = (A/H) / (1/G_s + 1/E_b) and m g, with their units, to check."""
    return (f"check mass = {block.mass:g} kg, E_b = {block.E_b:g} Pa, soil {soil.name!r} shear_modulus = "
            f"{soil.shear_modulus:g} Pa, footprint_area = {block.footprint_area:g} m^2 and soil_depth = "
            f"{block.soil_depth:g} m")


def _size(block: Block) -> float:
    """The block's largest in-plane dimension max(2b, 2h) [m]."""
    return 2.0 * max(block.b, block.h)


def _density(block: Block) -> float:
    """Mass per bounding volume, mass / (footprint_area x 2h) [kg/m^3]."""
    return block.mass / (block.footprint_area * 2.0 * block.h)


# ---------------------------------------------------------------- the checks, in the order tried

@plausibility_check("block modulus", "blocks.{block}.E_b")
def block_modulus(block: Block, soil: SoilClass, found: Foundation) -> str | None:
    """E_b below 1 MPa: a modulus in GPa or MPa written as Pa."""
    if block.E_b >= MIN_MODULUS:
        return None
    return (f"block {block.name!r}: E_b = {block.E_b:g} Pa is below 1 MPa (static settlement "
            f"{found.settlement:.3g} m on {soil.name}): {_modulus_slip(block.E_b, BLOCK_MODULI, ('GPa', 'MPa'))}")


@plausibility_check("soil modulus", "soils_custom.{soil}.shear_modulus")
def soil_modulus(block: Block, soil: SoilClass, found: Foundation) -> str | None:
    """Soil G_s below 1 MPa: a modulus in MPa, GPa or kPa written as Pa."""
    if soil.shear_modulus >= MIN_MODULUS:
        return None
    slip = _modulus_slip(soil.shear_modulus, SOIL_MODULI, ("MPa", "GPa", "kPa"))
    return (f"soil {soil.name!r}: shear_modulus = {soil.shear_modulus:g} Pa is below 1 MPa (static settlement "
            f"{found.settlement:.3g} m under block {block.name!r}): {slip}")


@plausibility_check("size", "blocks.{block}")
def block_size(block: Block, soil: SoilClass, found: Foundation) -> str | None:
    """Half-width or half-height over 100 m: lengths in mm or cm written as m (tried before the density)."""
    if max(block.b, block.h) <= MAX_HALF_SIZE:
        return None
    return (f"block {block.name!r}: half-width b = {block.b:g} m and half-height h = {block.h:g} m make a block "
            f"{2 * block.b:g} m wide and {2 * block.h:g} m tall, over {MAX_HALF_SIZE:g} m (Housner's p = "
            f"{block.p():.3g} rad/s): {_length_slip(block)}")


@plausibility_check("footprint", "blocks.{block}.footprint_area")
def footprint(block: Block, soil: SoilClass, found: Foundation) -> str | None:
    """A footprint far larger than the block's base: an area in cm^2 or mm^2 written as m^2."""
    width = 2.0 * block.b
    depth = block.footprint_area / width
    if depth <= MAX_FOOTPRINT_DEPTH * _size(block):
        return None
    slip = _area_slip(block)
    return (f"block {block.name!r}: footprint_area = {block.footprint_area:g} m^2 is a base {width:g} m wide and "
            f"{depth:.3g} m deep, over {MAX_FOOTPRINT_DEPTH:g} x the block's size {_size(block):g} m (k = "
            f"{found.stiffness:.3g} N/m, a nearly rigid bed with omega_v/p = {found.frequency_ratio:.3g}): {slip}")


@plausibility_check("density", "blocks.{block}.mass")
def density(block: Block, soil: SoilClass, found: Foundation) -> str | None:
    """Mass per bounding volume above steel's density or below a hollow cabinet's: kg vs t or g."""
    rho = _density(block)
    low, high = DENSITY_RANGE
    if low <= rho <= high or block_size(block, soil, found):  # b and h in mm: the mass is not to blame
        return None
    volume = f"footprint_area x 2h = {block.footprint_area:g} m^2 x {2 * block.h:g} m"
    if rho < low:
        where = f"below {low:g} kg/m^3, lighter than any hollow cabinet (omega_v/p = {found.frequency_ratio:.3g}: " \
                "a needlessly stiff bed and slow runs)"
    else:
        where = f"above steel's 7850 kg/m^3 (static settlement {found.settlement:.3g} m on {soil.name})"
    return (f"block {block.name!r}: mass = {block.mass:g} kg in {volume} is {rho:.3g} kg/m^3, {where}: "
            f"{_mass_slip(block, rho)}")


@plausibility_check("soil depth", "blocks.{block}.soil_depth")
def soil_depth(block: Block, soil: SoilClass, found: Foundation) -> str | None:
    """An effective soil depth far deeper than the block is wide: a depth in mm or cm written as m."""
    limit = MAX_SOIL_DEPTH * max(_size(block), 1.0)
    if block.soil_depth <= limit:
        return None
    slip = next((f"did you mean {block.soil_depth:g} {unit} = {block.soil_depth / factor:g} m?"
                 for unit, factor in (("mm", 1e3), ("cm", 1e2)) if block.soil_depth / factor <= limit),
                "give the depth of soil the block loads in m")
    return (f"block {block.name!r}: soil_depth = {block.soil_depth:g} m is over {limit:g} m, {MAX_SOIL_DEPTH:g} x "
            f"the block's size (k = {found.stiffness:.3g} N/m, static settlement {found.settlement:.3g} m on "
            f"{soil.name}): {slip}")


@plausibility_check("settlement", "blocks.{block}")
def settlement(block: Block, soil: SoilClass, found: Foundation) -> str | None:
    """A static settlement m g / k beyond a small fraction of the block's size: the block would sink."""
    limit = MAX_SETTLEMENT * min(block.b, block.h)
    if found.settlement <= limit:
        return None
    return (f"block {block.name!r} on soil {soil.name!r}: static settlement m g / k = {found.settlement:.3g} m "
            f"(k = {found.stiffness:.3g} N/m) is over {MAX_SETTLEMENT:.0%} of the block's min(b, h) = "
            f"{min(block.b, block.h):g} m, so the block would sink rather than rock: {_foundation_slip(block, soil)}")


@plausibility_check("frequency ratio", "blocks.{block}")
def frequency_ratio(block: Block, soil: SoilClass, found: Foundation) -> str | None:
    """omega_v / p below a few: the bed as slow as the rocking, outside a rocking-on-a-bed model.

    (omega_v / p)^2 = 4 R / (3 m g / k): the same fact as the settlement seen from the rocking side. With
    the limits above a settlement over 10% of min(b, h) <= 0.71 R always comes first (omega_v / p < 3 needs
    m g / k > 4R/27); this check states the model's range on its own terms, and holds if MAX_SETTLEMENT grows.
    """
    if found.frequency_ratio >= MIN_FREQUENCY_RATIO:
        return None
    return (f"block {block.name!r} on soil {soil.name!r}: vertical bed frequency omega_v = sqrt(k/m) = "
            f"{found.vertical_frequency:.3g} rad/s is only {found.frequency_ratio:.3g} x Housner's p = "
            f"{block.p():.3g} rad/s, below {MIN_FREQUENCY_RATIO:g} (static settlement {found.settlement:.3g} m): "
            f"the block would bounce on the bed rather than rock; {_foundation_slip(block, soil)}")


# ---------------------------------------------------------------- a study's blocks and soils

def implausibilities(blocks: Iterable[Block], soils: Iterable[SoilClass]) -> list[tuple[str, str]]:
    """(field, message) of every implausible value of the blocks on the soils.

    Each check reports a field once (a block's E_b on its first soil, a settlement on the first soil
    where it is too large), in the order blocks, soils and ``CHECKS`` come.

    Parameters
    ----------
    blocks : iterable of Block
        The study's blocks.
    soils : iterable of SoilClass
        The study's soils.

    Returns
    -------
    list of (str, str)
        The study field blamed (e.g. ``blocks.cabinet.E_b``) and the one-line message.
    """
    soils = list(soils)
    found, seen = [], set()
    for block in blocks:
        for soil in soils:
            pair = foundation(soil, block)
            for check in CHECKS:
                field = check.field.format(block=block.name, soil=soil.name)
                if (check.name, field) in seen:
                    continue
                message = check.function(block, soil, pair)
                if message:
                    seen.add((check.name, field))
                    found.append((field, message))
    return found


def check_study(blocks: Iterable[Block], soils: Iterable[SoilClass], on_implausible: str = "error",
                source: str | None = None) -> list[str]:
    """Refuse (or, for an expert, warn about) physically implausible blocks, soils and foundations.

    Parameters
    ----------
    blocks : iterable of Block
        The study's blocks.
    soils : iterable of SoilClass
        The study's soils.
    on_implausible : {"error", "warn"}
        ``"error"``: raise the first implausible value; ``"warn"``: one ``PlausibilityWarning`` each,
        and go on (the study key ``[checks] plausibility``, or ``--force``).
    source : str, optional
        The study file, named in the error.

    Returns
    -------
    list of str
        The messages warned about (empty when everything is plausible).

    Raises
    ------
    ConfigError
        With ``on_implausible="error"``, naming the file, the field, the value, its consequence and the
        likely unit slip; or for an ``on_implausible`` that is neither ``"error"`` nor ``"warn"``.
    """
    if on_implausible not in ON_IMPLAUSIBLE:
        raise ConfigError("checks.plausibility", f"{on_implausible!r}; must be one of "
                          f"{', '.join(repr(o) for o in ON_IMPLAUSIBLE)}", source)
    found = implausibilities(blocks, soils)
    if found and on_implausible == "error":
        field, message = found[0]
        others = len(found) - 1
        more = f" (and {others} more implausible value{'s' if others > 1 else ''})" if others else ""
        raise ConfigError(field, f"{message}{more}; {OVERRIDE_HINT}", source)
    prefix = f"{source}: " if source else ""
    for field, message in found:
        warnings.warn(PlausibilityWarning(f"{prefix}{field}: {message} (running anyway, as asked)"), stacklevel=2)
    return [message for _, message in found]
