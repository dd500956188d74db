"""rockfrag.blocks - rigid rocking blocks: geometry, mass, stiffness and named presets.

Input : either half-width b and half-height h [m], or the semi-diagonal R [m] and slenderness
        alpha [rad]; mass [kg]; block Young's modulus E_b [Pa]; footprint area A [m^2] and
        effective soil depth H [m] used by the interface stiffness (paper eq. 19).
Output: a frozen, validated ``Block`` with derived R, alpha, b, h and p = sqrt(3g/(4R)) [rad/s].
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from rockfrag.errors import ConfigError
from rockfrag.units import STANDARD_GRAVITY
from rockfrag.validation import Number

BLOCK_RANGES: dict[str, Number] = {
    "b": Number(0, 1e4, low_open=True, unit="m"),
    "h": Number(0, 1e4, low_open=True, unit="m"),
    "R": Number(0, 1e4, low_open=True, unit="m"),
    "alpha": Number(0, math.pi / 2 - 1e-6, low_open=True, unit="rad"),
    "mass": Number(0, 1e10, low_open=True, unit="kg"),
    "E_b": Number(0, 1e13, low_open=True, unit="Pa"),
    "footprint_area": Number(0, 1e8, low_open=True, unit="m^2"),
    "soil_depth": Number(0, 1e4, low_open=True, unit="m"),
}
"""What each number of a block must be (SI units; b, h: half-width and half-height): checked by ``Block`` and
by the study schema (rockfrag.config), and listed by ``rockfrag study --keys``."""


def _check(name: str, value: object, key: str) -> float:
    return BLOCK_RANGES[key].check(value, name, None)


def geometry_conflict(name: str, b: float | None, h: float | None, R: float | None,
                      alpha: float | None) -> str | None:
    """Why a block's geometry is given twice, or None.

    A block is given by its half-width and half-height (``b``, ``h``) or by its semi-diagonal and
    slenderness (``R``, ``alpha``). A key of the other pair beside a complete one would be silently
    overwritten, so it is refused, e.g. ``R = 2 m`` with ``b = 0.3 m, h = 1.5 m``. All four keys are
    accepted only when they agree (``dataclasses.replace`` of a validated block passes all four).

    Parameters
    ----------
    name : str
        The block's name, for the message.
    b, h : float or None
        Half-width and half-height [m] as given.
    R : float or None
        Semi-diagonal [m] as given.
    alpha : float or None
        Slenderness angle [rad] as given.

    Returns
    -------
    str or None
        One line naming the keys given and what to give instead.
    """
    given_bh = [f"{key} = {_number(value)} m" for key, value in (("b", b), ("h", h)) if value is not None]
    given_ra = [f"{key} = {_number(value)} {unit}" for key, value, unit in (("R", R, "m"), ("alpha", alpha, "rad"))
                if value is not None]
    if not (given_bh and given_ra):
        return None
    if len(given_bh) == 2 and len(given_ra) == 2 and _agree(b, h, R, alpha):
        return None
    complete = "b and h" if len(given_bh) == 2 else "R and alpha" if len(given_ra) == 2 else None
    ignored = ", ".join(given_ra if complete == "b and h" else given_bh)
    if complete and len(given_bh) + len(given_ra) < 4:
        why = f"{ignored} would be ignored (the geometry comes from {complete})"
    elif complete:
        why = "the two pairs disagree"
    else:
        why = "neither pair is complete"
    return (f"{', '.join(given_bh)} and {', '.join(given_ra)} given: {why}; "
            "give either b and h, or R and alpha (not both)")


def _number(value) -> str:
    try:
        return f"{float(value):g}"
    except (TypeError, ValueError):
        return repr(value)


def _agree(b, h, R, alpha) -> bool:
    try:
        return (math.isclose(math.hypot(b, h), R, rel_tol=1e-9)
                and math.isclose(math.atan2(b, h), alpha, rel_tol=1e-9))
    except TypeError:
        return False


@dataclass(frozen=True)
class Block:
    """A rigid rectangular block rocking on its base corners.

    Give either ``b`` and ``h`` or ``R`` and ``alpha``. Units: m, rad, kg, Pa, m^2.
    """

    name: str = "block"
    b: float | None = None
    h: float | None = None
    R: float | None = None
    alpha: float | None = None
    mass: float = 1.0e5
    E_b: float = 30.0e9
    footprint_area: float | None = None
    soil_depth: float = 2.0
    description: str = field(default="", compare=False)

    def __post_init__(self):
        geometry_bh = self.b is not None and self.h is not None
        geometry_ra = self.R is not None and self.alpha is not None
        conflict = geometry_conflict(self.name, self.b, self.h, self.R, self.alpha)
        if conflict:
            raise ConfigError(f"block {self.name}", conflict)
        if not (geometry_bh or geometry_ra):
            raise ConfigError(f"block {self.name}", "give either b and h, or R and alpha")
        if geometry_bh:
            b = _check(f"block {self.name}.b", self.b, "b")
            h = _check(f"block {self.name}.h", self.h, "h")
            object.__setattr__(self, "R", math.hypot(b, h))
            object.__setattr__(self, "alpha", math.atan2(b, h))
        else:
            radius = _check(f"block {self.name}.R", self.R, "R")
            alpha = _check(f"block {self.name}.alpha", self.alpha, "alpha")
            object.__setattr__(self, "b", radius * math.sin(alpha))
            object.__setattr__(self, "h", radius * math.cos(alpha))
        _check(f"block {self.name}.mass", self.mass, "mass")
        _check(f"block {self.name}.E_b", self.E_b, "E_b")
        _check(f"block {self.name}.soil_depth", self.soil_depth, "soil_depth")
        if self.footprint_area is None:
            # plane model: footprint 2b wide and 1 m deep out of plane
            object.__setattr__(self, "footprint_area", 2.0 * self.b * 1.0)
        _check(f"block {self.name}.footprint_area", self.footprint_area, "footprint_area")

    def p(self, g=STANDARD_GRAVITY) -> float:
        """Frequency parameter p = sqrt(3g / (4R)) [rad/s] (paper eq. 3)."""
        return math.sqrt(0.75 * g / self.R)

    def uplift_acceleration(self, g=STANDARD_GRAVITY) -> float:
        """Housner's uplift threshold g tan(alpha) [m/s^2] (paper eq. 4)."""
        return g * math.tan(self.alpha)

    def housner_restitution(self) -> float:
        """Housner's coefficient of restitution r = 1 - 1.5 sin^2(alpha) (paper eq. 6)."""
        return 1.0 - 1.5 * math.sin(self.alpha) ** 2


# Paper block: R = 9.39 m, alpha = 0.44 rad (paper Figs. 6, 7, 9, 10). Mass: a solid block of
# density 2400 kg/m^3, 1 m out of plane (the paper gives none).
PAPER_BLOCK = Block(name="paper", R=9.39, alpha=0.44, mass=2400.0 * 4 * 9.39**2 * math.sin(0.44) * math.cos(0.44),
                    E_b=210e9, soil_depth=2.0,
                    description="the paper's block (R = 9.39 m, alpha = 0.44 rad), steel E_b")
