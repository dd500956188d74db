"""pipeline.soils - soil classes and the interface stiffness of the SSI-rocking model.

Input : a soil class (shear modulus G_s [Pa], Poisson's ratio, density, damping ratio) and a
        ``Block`` (E_b [Pa], footprint area A [m^2], effective soil depth H [m]).
Output: the interface stiffness k [N/m] of paper eq. 19, k = (A/H) / (1/G_s + 1/E_b), the vertical
        circular frequency w = sqrt(k/m) [rad/s] and dashpot c = 2 xi w m [N s/m] (eq. 10); with
        ``foundation`` also the static settlement m g / k [m] and w / p, which pipeline.plausibility checks.

The paper's "dynamic elastic modulus" E_d of eq. 7 / Table 1, E_d = 2G(1-nu)/(1-2nu), is the
constrained (oedometric, P-wave) modulus, not Young's modulus; it is labelled so here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pipeline.errors import ConfigError
from pipeline.units import STANDARD_GRAVITY
from pipeline.validation import Number

SOIL_RANGES = {
    "shear_modulus": Number(0, 1e13, low_open=True, unit="Pa"),
    "poisson_ratio": Number(0, 0.5, high_open=True),
    "density": Number(0, 1e5, low_open=True, unit="kg/m^3"),
    "damping_ratio": Number(0, 1, high_open=True),
}
"""Allowed values of a soil's numbers (also the study file's ``[soils_custom.NAME]`` ranges)."""


@dataclass(frozen=True)
class SoilClass:
    """A foundation material (SI units)."""

    name: str
    shear_modulus: float  # G_s [Pa]
    poisson_ratio: float  # nu [-]
    density: float  # rho [kg/m^3]
    damping_ratio: float = 0.05  # xi of the vertical dashpot [-]
    description: str = ""

    def __post_init__(self):
        for key, allowed in SOIL_RANGES.items():
            allowed.check(getattr(self, key), f"soil {self.name}.{key}", None)

    @property
    def constrained_modulus(self) -> float:
        """E_d = 2 G (1 - nu) / (1 - 2 nu) [Pa]: the paper's 'dynamic elastic modulus' (eq. 7)."""
        nu = self.poisson_ratio
        return 2.0 * self.shear_modulus * (1.0 - nu) / (1.0 - 2.0 * nu)

    @property
    def youngs_modulus(self) -> float:
        """E = 2 G (1 + nu) [Pa]."""
        return 2.0 * self.shear_modulus * (1.0 + self.poisson_ratio)


def interface_stiffness(shear_modulus, block_modulus, footprint_area, soil_depth) -> float:
    """Paper eq. 19: k = (A/H) / (1/G_s + 1/E_b) [N/m] (soil and block in series)."""
    if min(shear_modulus, block_modulus, footprint_area, soil_depth) <= 0:
        raise ConfigError("interface_stiffness", "G_s, E_b, A and H must all be > 0")
    return footprint_area / soil_depth / (1.0 / shear_modulus + 1.0 / block_modulus)


def soil_block_stiffness(soil: SoilClass, block) -> float:
    """Interface stiffness k [N/m] of ``block`` standing on ``soil`` (eq. 19)."""
    return interface_stiffness(soil.shear_modulus, block.E_b, block.footprint_area, block.soil_depth)


@dataclass(frozen=True)
class Foundation:
    """A block standing on a soil: the interface stiffness and what it implies (SI units).

    Attributes
    ----------
    stiffness : float
        Interface stiffness k of eq. 19 [N/m].
    settlement : float
        Static settlement under the block's weight, m g / k [m].
    vertical_frequency : float
        Circular frequency of the block bouncing on the bed, omega_v = sqrt(k/m) [rad/s].
    frequency_ratio : float
        omega_v / p, the bed's vertical frequency over Housner's frequency parameter [-].
    """

    stiffness: float
    settlement: float
    vertical_frequency: float
    frequency_ratio: float


def foundation(soil: SoilClass, block, g: float = STANDARD_GRAVITY) -> Foundation:
    """The interface stiffness of ``block`` on ``soil`` and its static settlement and frequencies.

    Parameters
    ----------
    soil : SoilClass
        The foundation material (shear modulus G_s [Pa]).
    block : pipeline.blocks.Block
        The block (mass [kg], E_b [Pa], footprint area [m^2], soil depth [m], R [m]).
    g : float
        Gravity [m/s^2].

    Returns
    -------
    Foundation
        k [N/m], m g / k [m], omega_v [rad/s] and omega_v / p [-].
    """
    stiffness = soil_block_stiffness(soil, block)
    omega = math.sqrt(stiffness / block.mass)
    return Foundation(stiffness=stiffness, settlement=block.mass * g / stiffness, vertical_frequency=omega,
                      frequency_ratio=omega / block.p(g))


def _from_constrained(name, constrained_mpa, nu, density, description):
    shear = constrained_mpa * 1e6 * (1 - 2 * nu) / (2 * (1 - nu))
    return SoilClass(name, shear, nu, density, 0.05, description)


# Paper Table 1 (G_max, nu, rho); clay from the text (E_d = 130 MPa, nu = 0.3 assumed).
SOILS = {
    "clay": _from_constrained("clay", 130.0, 0.3, 1800.0, "soft clay, E_d = 130 MPa (paper Figs. 9-11)"),
    "sand": SoilClass("sand", 80e6, 0.3, 1900.0, 0.05, "sand, G = 80 MPa (paper Table 1)"),
    "gravel": SoilClass("gravel", 300e6, 0.3, 2000.0, 0.05, "gravel, G = 300 MPa (paper Table 1)"),
    "rock": SoilClass("rock", 1000e6, 0.3, 2500.0, 0.05, "rock, G = 1000 MPa (paper Table 1)"),
    "steel": SoilClass("steel", 80e9, 0.3, 7800.0, 0.05, "steel base, G = 80 GPa (paper Table 1)"),
}
