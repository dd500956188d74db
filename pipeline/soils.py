"""rockfrag.soils - soil classes and the interface stiffness of the SSI-rocking model.

Input : a soil class (shear modulus G_s [Pa], Poisson's ratio, density, damping ratio) and a
        ``Block`` (E_b [Pa], footprint area A [m^2], effective soil depth H [m]).
Output: the interface stiffness k [N/m] of paper eq. 19, k = (A/H) / (1/G_s + 1/E_b), the vertical
        circular frequency w = sqrt(k/m) [rad/s] and dashpot c = 2 xi w m [N s/m] (eq. 10); with
        ``foundation`` also the static settlement m g / k [m] and w / p, which rockfrag.plausibility checks.

Site: each soil class also states the Vs30 [m/s] of the site it stands for (``vs30``): the time-averaged shear-wave
velocity of the top 30 m of the ground profile, which sets how the ground shakes (rockfrag.site_amplification), not
the stiffness of the 1-2 m bed under the block (``shear_modulus``). ``site_class`` gives its ASCE 7-16 class
(``SITE_CLASSES``); ``vs30 = None`` means the reference site of the hazard curve itself (a steel deck: its site is
the ground below the structure, which the user states).

Base friction: each soil class also carries the Coulomb friction coefficients of a block's base on it,
static ``friction_static`` and kinetic ``friction_kinetic`` [-] (``FRICTION_SOURCES``), which the study uses
for the runs that slide (rockfrag.study.cell_friction).

The paper's "dynamic elastic modulus" E_d of eq. 7 / Table 1, E_d = 2G(1-nu)/(1-2nu), is the
constrained (oedometric, P-wave) modulus, not Young's modulus; it is labelled so here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rockfrag.errors import ConfigError
from rockfrag.units import STANDARD_GRAVITY
from rockfrag.validation import Number

MAX_KINETIC_FRICTION = 4.0 / 3.0
"""Largest kinetic coefficient a soil may state: a rigid base's limit. Above it a block rocking on a sliding corner
can meet Painleve's paradox (no solution of its equations; pipeline/models/housner.py). The models read it from here
(rockfrag.models.options.RIGID_BASE_MAX_KINETIC_FRICTION)."""

VS30_RANGE = Number(0, 5000, low_open=True, unit="m/s")
"""Allowed Vs30 of a soil's site (``vs30``, ``[soils_custom.NAME] vs30``, ``[hazard] vs30``)."""

SITE_CLASSES = {"A": (1500.0, math.inf), "B": (760.0, 1500.0), "C": (360.0, 760.0), "D": (180.0, 360.0),
                "E": (0.0, 180.0)}
"""Site classes by Vs30 [m/s], (lower, upper], ASCE 7-16 Table 20.3-1 (NEHRP 2015; the same bounds as ASCE 7-10): A
hard rock > 5,000 ft/s (1500 m/s); B rock 2,500-5,000 ft/s (760-1500 m/s); C very dense soil and soft rock
1,200-2,500 ft/s (360-760 m/s); D stiff soil 600-1,200 ft/s (180-360 m/s); E soft clay < 600 ft/s (180 m/s). The
SI bounds as printed beside the ft/s ones (e.g. UFC 3-310-03A's copy of the NEHRP table). ASCE 7-22 splits them
into nine (A, B, BC, C, CD, D, DE, E) with other bounds; the A-E classes are the ones site coefficients and most
hazard tools still name."""

SITE_CLASS_VS30 = {"A": 2000.0, "B": 1080.0, "C": 530.0, "D": 260.0, "E": 150.0}
"""The Vs30 [m/s] that stands for each site class: the values the USGS hazard tools use (nshmp-haz, enum
``gov.usgs.earthquake.nshmp...SiteClass``, the 2018 'new' column: B 1080, C 530, D 260, E 150; A 2000): the
geometric mean of the class bounds in ft/s (D: sqrt(600 x 1200) x 0.3048 = 259 m/s), and 150 m/s for E, the lowest
Vs30 of the NGA-West2 site term's data (rockfrag.site_amplification.VS30_DATA)."""


EC8_GROUND_TYPES = {"A": (800.0, math.inf), "B": (360.0, 800.0), "C": (180.0, 360.0), "D": (0.0, 180.0)}
"""Ground types by Vs30 [m/s], (lower, upper], EN 1998-1:2004 (Eurocode 8) Table 3.1: A rock > 800; B very dense
sand, gravel or very stiff clay 360-800; C dense or medium-dense sand, gravel or stiff clay 180-360; D loose-to-
medium cohesionless or soft-to-firm cohesive soil < 180. E, S1 and S2 are defined by the profile (a 5-20 m alluvium
layer over rock; soft high-plasticity clays; liquefiable soils), not by Vs30 alone: a site investigation names them.
A Vs30 on a bound is given the softer type, as ``site_class`` does."""


def ec8_ground_type(vs30: float | None) -> str:
    """The Eurocode 8 ground type ("A"-"D", ``EC8_GROUND_TYPES``) of a site's Vs30 [m/s]; "" for None."""
    if vs30 is None:
        return ""
    return next(name for name, (low, high) in EC8_GROUND_TYPES.items() if low < vs30 <= high)


def site_class(vs30: float | None) -> str:
    """The ASCE 7-16 site class ("A"-"E", ``SITE_CLASSES``) of a site's Vs30 [m/s]; "" for None (the reference site).

    A Vs30 on a bound belongs to the softer class, as ASCE 7-16 writes 2,500 < v_s <= 5,000 ft/s for B: 760 m/s
    is C.
    """
    if vs30 is None:
        return ""
    return next(name for name, (low, high) in SITE_CLASSES.items() if low < vs30 <= high)


SOIL_RANGES = {
    "shear_modulus": Number(0, 1e13, low_open=True, unit="Pa"),
    "poisson_ratio": Number(0, 0.5, high_open=True),
    "density": Number(0, 1e5, low_open=True, unit="kg/m^3"),
    "damping_ratio": Number(0, 1, high_open=True),
    "friction_static": Number(0, 1.5, low_open=True),
    "friction_kinetic": Number(0, MAX_KINETIC_FRICTION, low_open=True),
}
"""Allowed values of a soil's numbers (also the study file's ``[soils_custom.NAME]`` ranges)."""


KINETIC_OVER_STATIC = 0.85
"""mu_k / mu_s of the shipped soils: a modelling choice inside the 0.8-0.9 that the study's design takes for
concrete and steel sliding on soil and rock (no table of NAVFAC DM-7.02 gives kinetic values)."""
CLAY_ADHESION = {"soft clay": (10e3, 35e3), "stiff clay": (35e3, 60e3)}
"""Ultimate adhesion c_a [Pa] of formed concrete against clay, undrained, whatever the weight: NAVFAC DM-7.02 (1986)
Table 1 ('soft clay and clayey silt', 'stiff and hard clay'), in kPa as Carter & Bentley (1991) Table 11.1 give it.
The report compares it with mu_s times a block's contact pressure: which of the two holds a base on clay."""
UNDRAINED_BEARING_FACTOR = 2.0 + math.pi
"""N_c of a strip on the surface of undrained clay (Prandtl 1921): q_ult = N_c s_u, no embedment, no shape factor."""
CLAY_STRENGTH = {"soft": (12.5e3, 25e3), "medium stiff": (25e3, 50e3), "stiff": (50e3, 100e3),
                 "very stiff": (100e3, 200e3)}
"""Undrained shear strength s_u [Pa] of clay by consistency: half the unconfined compressive strength of Terzaghi &
Peck's (1967) classes (soft 25-50 kPa, medium 50-100, stiff 100-200, very stiff 200-400)."""
SAND_BEARING_FRICTION_ANGLE = 30.0
"""phi [deg] of the drained bearing check on sand and gravel: a loose-to-medium sand's, the low side of the
granular classes (the friction factor 0.45-0.60 of NAVFAC DM-7.02 is an interface's, not the soil's phi)."""


def undrained_bearing(strength: float) -> float:
    """Ultimate bearing pressure [Pa] of a surface strip on clay of undrained strength ``strength`` [Pa] (Prandtl)."""
    return UNDRAINED_BEARING_FACTOR * strength


def drained_bearing(density: float, width: float, friction_angle: float = SAND_BEARING_FRICTION_ANGLE) -> float:
    """Ultimate bearing pressure [Pa] of a surface strip ``width`` [m] wide on sand: 0.5 gamma B N_gamma.

    N_gamma = 2 (N_q + 1) tan phi, N_q = e^(pi tan phi) tan^2(45 + phi/2) (Vesic 1973; 22.4 at 30 degrees); gamma =
    rho g of the soil, dry (a water table at the base would halve it).
    """
    phi = math.radians(friction_angle)
    n_q = math.exp(math.pi * math.tan(phi)) * math.tan(math.pi / 4 + phi / 2) ** 2
    return 0.5 * density * STANDARD_GRAVITY * width * 2.0 * (n_q + 1.0) * math.tan(phi)


ROCK_MODULUS = 1e9
"""G [Pa] from which a bed is rock or a structural base: its bearing is far above any block's contact pressure."""


@dataclass(frozen=True)
class BearingCase:
    """A block's contact pressure at rest on a soil and what carries it (a static check, not a design).

    Attributes
    ----------
    pressure : float
        m g / A [Pa], the block's weight over its footprint.
    kind : str
        "clay" (undrained: ``needed_strength``), "granular" (drained: ``capacity``) or "rock" (no check).
    needed_strength : float
        The undrained strength s_u [Pa] a clay needs for its ultimate bearing to equal the pressure (NaN otherwise).
    capacity : float
        The ultimate bearing pressure [Pa] of a sand or gravel under the block's width (NaN otherwise).
    """

    pressure: float
    kind: str
    needed_strength: float = math.nan
    capacity: float = math.nan


def contact_pressure(block) -> float:
    """The contact pressure m g / A [Pa] of a block at rest: its weight over its footprint."""
    return block.mass * STANDARD_GRAVITY / block.footprint_area


def bearing_case(soil: SoilClass, block) -> BearingCase:
    """The static bearing check of ``block`` at rest on ``soil``: clay by its name, rock by ``ROCK_MODULUS``."""
    pressure = contact_pressure(block)
    if soil.shear_modulus >= ROCK_MODULUS:
        return BearingCase(pressure, "rock")
    if "clay" in soil.name.lower():
        return BearingCase(pressure, "clay", needed_strength=pressure / UNDRAINED_BEARING_FACTOR)
    return BearingCase(pressure, "granular", capacity=drained_bearing(soil.density, 2.0 * block.b))


DEFAULT_FRICTION = (0.5, 0.4)
"""(mu_s, mu_k) of a soil that does not state its own (a ``[soils_custom.NAME]`` table without them): the
steel-on-steel pair below, and the coefficient the report's sliding check used before friction was per soil."""
FRICTION_SOURCES = (
    "Soils and rock: the ultimate friction factor tan(delta) of mass concrete on the material, NAVFAC DM-7.02 "
    "(1986) Foundations and Earth Structures, Table 1 'Ultimate friction factors and adhesion for dissimilar "
    "materials': clean sound rock 0.70; clean gravel, gravel-sand mixtures, coarse sand 0.55-0.60 (0.55 taken); "
    "clean fine to medium sand 0.45-0.55 (0.45 taken); medium stiff and stiff clay 0.30-0.35 (0.35 taken). "
    "Gravel and sand take the lower end of their ranges (less friction, more sliding); clay takes the upper end of "
    "its range, below the 0.40-0.50 of very stiff clay. "
    f"Kinetic = {KINETIC_OVER_STATIC} x "
    "static (rounded to 0.01). Steel base on a steel deck: 0.50 static, the slip coefficient of blast-cleaned "
    "steel faying surfaces (AISC 360-16 Specification for Structural Steel Buildings, J3.8, class B surfaces), "
    "the study's choice of the clause's two classes: class A (unpainted clean mill scale) is 0.30, under which "
    "a block with b/h between 0.30 and 0.50 (the paper's block, 0.47) slides before it can rock; both lie "
    "below the 0.74 of clean dry mild steel in the laboratory (Marks' Standard Handbook for Mechanical "
    "Engineers, Table 3.2.1); 0.40 kinetic (0.8 x static).")
"""Where the shipped soils' friction coefficients come from (docs/theory/sliding.md)."""


@dataclass(frozen=True)
class SoilClass:
    """A foundation material (SI units)."""

    name: str
    shear_modulus: float  # G_s [Pa]
    poisson_ratio: float  # nu [-]
    density: float  # rho [kg/m^3]
    damping_ratio: float = 0.05  # xi of the vertical dashpot [-]
    description: str = ""
    friction_static: float = DEFAULT_FRICTION[0]  # mu_s of a block's base on this soil [-]
    friction_kinetic: float = DEFAULT_FRICTION[1]  # mu_k [-], at most mu_s
    vs30: float | None = None  # Vs30 of the site [m/s]; None: the hazard curve's reference site

    def __post_init__(self):
        for key, allowed in SOIL_RANGES.items():
            allowed.check(getattr(self, key), f"soil {self.name}.{key}", None)
        if self.vs30 is not None:
            VS30_RANGE.check(self.vs30, f"soil {self.name}.vs30", None)
        if self.friction_kinetic > self.friction_static:
            raise ConfigError(f"soil {self.name}.friction_kinetic",
                              f"{self.friction_kinetic:g} exceeds friction_static {self.friction_static:g}; "
                              "must be > 0 and <= friction_static")

    @property
    def site_class(self) -> str:
        """The ASCE 7-16 site class of the soil's site ("A"-"E"); "" when it is the hazard's reference site."""
        return site_class(self.vs30)

    @property
    def friction(self) -> tuple[float, float]:
        """(mu_s, mu_k) [-] of a block's base on this soil (the solver's ``friction`` option)."""
        return self.friction_static, self.friction_kinetic

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


def half_space_stiffness(shear_modulus: float, poisson_ratio: float, length: float, width: float) -> float:
    """Static vertical stiffness [N/m] of a rigid rectangular surface footing on an elastic half-space.

    The footing is ``length`` x ``width`` [m] (Gazetas 1991, Table 1; NIST GCR 12-917-21 Table 2-2a).
    K_z = 2 G L / (1 - nu) (0.73 + 1.54 chi^0.75), L and B the half-sides (L >= B), chi = A_b / (4 L^2) = B / L.
    A check on the paper's eq. 19, which takes the soil as a column of depth H under the footprint: the report
    compares the two, it does not run this one.
    """
    if min(shear_modulus, length, width) <= 0 or not 0 <= poisson_ratio < 0.5:
        raise ConfigError("half_space_stiffness", "G, the footing's length and width must be > 0 and nu in [0, 0.5)")
    half_long, half_short = max(length, width) / 2.0, min(length, width) / 2.0
    chi = half_short / half_long
    return 2.0 * shear_modulus * half_long / (1.0 - poisson_ratio) * (0.73 + 1.54 * chi ** 0.75)


def half_space_strip_stiffness(shear_modulus: float, poisson_ratio: float) -> float:
    """Static vertical stiffness [N/m per metre of length] of a long rigid strip on an elastic half-space.

    0.73 G / (1 - nu) (Gazetas 1991, Table 1, strip): an approximation, since a strip's exact static settlement
    under a finite load grows without bound; the plane model's per-metre blocks are compared with it.
    """
    if shear_modulus <= 0 or not 0 <= poisson_ratio < 0.5:
        raise ConfigError("half_space_strip_stiffness", "G must be > 0 and nu in [0, 0.5)")
    return 0.73 * shear_modulus / (1.0 - poisson_ratio)


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
    block : rockfrag.blocks.Block
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


def _from_constrained(name, constrained_mpa, nu, density, description, friction, vs30):
    shear = constrained_mpa * 1e6 * (1 - 2 * nu) / (2 * (1 - nu))
    return SoilClass(name, shear, nu, density, 0.05, description, *friction, vs30=vs30)


def _navfac(static: float) -> tuple[float, float]:
    """(mu_s, mu_k) of concrete on a soil from its NAVFAC DM-7.02 friction factor (``FRICTION_SOURCES``)."""
    return static, round(KINETIC_OVER_STATIC * static, 2)


SITE_CLASS_OF_SOIL = {"clay": "E", "sand": "D", "gravel": "C", "rock": "B"}
"""The site class each shipped soil stands for (soft clay E, sand D stiff soil, gravel C very dense soil, rock B; the
names of ASCE 7-16 Table 20.3-1). Its site's Vs30 is the class's ``SITE_CLASS_VS30``. Steel is a deck on a
structure: its site is the ground below, which the study states (``[hazard] vs30 = { steel = ... }``); without it,
the hazard curve's own reference site. The bed's own shear-wave velocity sqrt(G/rho) (clay 144, sand 205, gravel
387, rock 632 m/s) is not the site's Vs30: a 1-2 m bed does not make the top 30 m."""

# Paper Table 1 (G_max, nu, rho); clay from the text (E_d = 130 MPa, nu = 0.3 assumed). Friction: FRICTION_SOURCES.
# Site Vs30: SITE_CLASS_OF_SOIL.
SOILS = {
    "clay": _from_constrained("clay", 130.0, 0.3, 1800.0, "soft clay, E_d = 130 MPa (paper Figs. 9-11)",
                              _navfac(0.35), SITE_CLASS_VS30["E"]),
    "sand": SoilClass("sand", 80e6, 0.3, 1900.0, 0.05, "sand, G = 80 MPa (paper Table 1)", *_navfac(0.45),
                      vs30=SITE_CLASS_VS30["D"]),
    "gravel": SoilClass("gravel", 300e6, 0.3, 2000.0, 0.05, "gravel, G = 300 MPa (paper Table 1)", *_navfac(0.55),
                        vs30=SITE_CLASS_VS30["C"]),
    "rock": SoilClass("rock", 1000e6, 0.3, 2500.0, 0.05, "rock, G = 1000 MPa (paper Table 1)", *_navfac(0.70),
                      vs30=SITE_CLASS_VS30["B"]),
    "steel": SoilClass("steel", 80e9, 0.3, 7800.0, 0.05, "steel base, G = 80 GPa (paper Table 1)", 0.50, 0.40),
}
