"""pipeline.blocks - rigid rocking blocks: geometry, mass, stiffness and named presets.

Input : either half-width b and half-height h [m], or the semi-diagonal R [m] and slenderness
        alpha [rad]; mass [kg]; block Young's modulus E_b [Pa]; footprint area A [m^2] and
        effective soil depth H [m] used by the interface stiffness (paper eq. 19).
Output: a frozen, validated ``Block`` with derived R, alpha, b, h and p = sqrt(3g/(4R)) [rad/s].
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from pipeline.errors import ConfigError
from pipeline.units import STANDARD_GRAVITY
from pipeline.validation import Number


def _check(name, value, low, high, unit, low_open=True):
    return Number(low, high, low_open=low_open, unit=unit).check(value, name, None)


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
        if geometry_bh and geometry_ra:
            # both given (e.g. dataclasses.replace of a validated block): accept only if consistent
            if not (math.isclose(math.hypot(self.b, self.h), self.R, rel_tol=1e-9)
                    and math.isclose(math.atan2(self.b, self.h), self.alpha, rel_tol=1e-9)):
                raise ConfigError(f"block {self.name}", "give either b and h, or R and alpha (not both)")
        elif not (geometry_bh or geometry_ra):
            raise ConfigError(f"block {self.name}", "give either b and h, or R and alpha")
        if geometry_bh:
            b = _check(f"block {self.name}.b", self.b, 0, 1e4, "m")
            h = _check(f"block {self.name}.h", self.h, 0, 1e4, "m")
            object.__setattr__(self, "R", math.hypot(b, h))
            object.__setattr__(self, "alpha", math.atan2(b, h))
        else:
            radius = _check(f"block {self.name}.R", self.R, 0, 1e4, "m")
            alpha = _check(f"block {self.name}.alpha", self.alpha, 0, math.pi / 2 - 1e-6, "rad")
            object.__setattr__(self, "b", radius * math.sin(alpha))
            object.__setattr__(self, "h", radius * math.cos(alpha))
        _check(f"block {self.name}.mass", self.mass, 0, 1e10, "kg")
        _check(f"block {self.name}.E_b", self.E_b, 0, 1e13, "Pa")
        _check(f"block {self.name}.soil_depth", self.soil_depth, 0, 1e4, "m")
        if self.footprint_area is None:
            # plane model: footprint 2b wide and 1 m deep out of plane
            object.__setattr__(self, "footprint_area", 2.0 * self.b * 1.0)
        _check(f"block {self.name}.footprint_area", self.footprint_area, 0, 1e8, "m^2")

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
