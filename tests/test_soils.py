"""Soil classes, the paper's Table 1, interface stiffness (eq. 19) and block geometry."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from rockfrag.blocks import Block
from rockfrag.errors import ConfigError
from rockfrag.soils import SOILS, SoilClass, interface_stiffness, soil_block_stiffness


@pytest.mark.parametrize("name, table_e_d", [("sand", 280e6), ("gravel", 1050e6), ("rock", 3500e6)])
def test_table1_dynamic_modulus_is_the_constrained_modulus(name, table_e_d):
    """Table 1's E_d equals 2G(1-nu)/(1-2nu) (eq. 7) for nu = 0.3, not Young's modulus 2G(1+nu)."""
    soil = SOILS[name]
    assert soil.constrained_modulus == pytest.approx(table_e_d, rel=1e-12)
    assert soil.youngs_modulus == pytest.approx(2.6 * soil.shear_modulus)


def test_clay_from_the_papers_e_d():
    assert SOILS["clay"].constrained_modulus == pytest.approx(130e6)
    assert SOILS["clay"].shear_modulus == pytest.approx(130e6 / 3.5)


def test_interface_stiffness_is_springs_in_series():
    area, depth = 8.0, 2.0
    k = interface_stiffness(80e6, 210e9, area, depth)
    assert 1 / k == pytest.approx(depth / area / 80e6 + depth / area / 210e9, rel=1e-12)
    assert interface_stiffness(80e6, 1e30, area, depth) == pytest.approx(area / depth * 80e6)
    assert interface_stiffness(1e30, 30e9, area, depth) == pytest.approx(area / depth * 30e9)
    with pytest.raises(ConfigError):
        interface_stiffness(0.0, 30e9, area, depth)


def test_soil_stiffness_grows_with_the_soil_and_the_block():
    block = Block(name="b", R=9.39, alpha=0.44, mass=3e5, E_b=30e9, footprint_area=8.0, soil_depth=2.0)
    values = [soil_block_stiffness(SOILS[n], block) for n in ("clay", "sand", "gravel", "rock", "steel")]
    assert values == sorted(values)
    stiffer = replace(block, E_b=210e9)
    assert soil_block_stiffness(SOILS["gravel"], stiffer) > soil_block_stiffness(SOILS["gravel"], block)


def test_block_geometry_both_ways():
    by_sides = Block(name="b", b=1.0, h=2.0, mass=1.0)
    assert by_sides.R == pytest.approx(math.sqrt(5)) and by_sides.alpha == pytest.approx(math.atan(0.5))
    by_angle = Block(name="a", R=by_sides.R, alpha=by_sides.alpha, mass=1.0)
    assert by_angle.b == pytest.approx(1.0) and by_angle.h == pytest.approx(2.0)
    assert by_sides.p() == pytest.approx(math.sqrt(3 * 9.80665 / (4 * by_sides.R)))
    assert by_sides.housner_restitution() == pytest.approx(1 - 1.5 * math.sin(by_sides.alpha) ** 2)
    assert by_sides.uplift_acceleration() == pytest.approx(9.80665 * 0.5)
    assert by_sides.footprint_area == pytest.approx(2.0)  # 2b wide, 1 m out of plane


@pytest.mark.parametrize("kwargs, field", [
    (dict(b=1.0), "block x"),
    (dict(b=1.0, h=2.0, R=5.0, alpha=0.1), "block x"),
    (dict(b=-1.0, h=2.0), "block x.b"),
    (dict(R=1.0, alpha=2.0), "block x.alpha"),
    (dict(b=1.0, h=2.0, mass=0.0), "block x.mass"),
])
def test_bad_blocks_name_the_field(kwargs, field):
    with pytest.raises(ConfigError) as caught:
        Block(name="x", **kwargs)
    assert caught.value.field == field


def test_bad_soil_is_refused():
    with pytest.raises(ConfigError, match="poisson"):
        SoilClass("mud", 1e6, 0.5, 1500.0)


def test_the_half_space_stiffness_is_gazetas_and_meets_the_rigid_disc():
    """Gazetas (1991) for a rigid rectangular surface footing: a square is within 1% of the rigid disc of the same
    area, 4 G R / (1 - nu) (Boussinesq's closed form); a 2:1 rectangle gives 2GL/(1 - nu) (0.73 + 1.54 0.5^0.75);
    the enclosure of the user study (1.2 m x 1.5 m on G 37.1 MPa, nu 0.3) 162 MN/m, as a cold reader computed."""
    from rockfrag.soils import half_space_stiffness

    shear, nu = 50e6, 0.3
    square = half_space_stiffness(shear, nu, 2.0, 2.0)
    radius = 2.0 / math.sqrt(math.pi)
    assert square == pytest.approx(4 * shear * radius / (1 - nu), rel=0.01)
    assert half_space_stiffness(shear, nu, 4.0, 2.0) == pytest.approx(
        2 * shear * 2.0 / (1 - nu) * (0.73 + 1.54 * 0.5 ** 0.75), rel=1e-12)
    assert half_space_stiffness(shear, nu, 2.0, 4.0) == half_space_stiffness(shear, nu, 4.0, 2.0)
    assert half_space_stiffness(37.142857e6, nu, 1.2, 1.5) / 1e6 == pytest.approx(162, abs=0.5)
    with pytest.raises(ConfigError):
        half_space_stiffness(shear, 0.5, 1.0, 1.0)


def test_the_bearing_check_is_prandtl_on_clay_and_vesic_on_sand():
    """Cold read 12, default A1: the paper's block presses 400 kPa; a clay carries it only with s_u >= 400 / 5.14 =
    78 kPa (Prandtl 1921, N_c = 2 + pi). On sand N_gamma(30 deg) = 22.4 (Vesic 1973's table), so a 1 m strip on
    ground of 1,900 kg/m3 bears 0.5 x 18.6 kN/m3 x 1 m x 22.4 = 209 kPa."""
    from types import SimpleNamespace

    from rockfrag.soils import SOILS, bearing_case, drained_bearing, undrained_bearing

    assert undrained_bearing(1.0) == pytest.approx(5.14, abs=0.005)
    assert drained_bearing(1900.0, 1.0) / (0.5 * 1900.0 * 9.80665) == pytest.approx(22.4, abs=0.05)
    paper = SimpleNamespace(mass=326197.0, footprint_area=8.0, b=4.0)
    clay = bearing_case(SOILS["clay"], paper)
    assert clay.kind == "clay" and clay.pressure / 1e3 == pytest.approx(399.9, abs=0.1)
    assert clay.needed_strength / 1e3 == pytest.approx(77.8, abs=0.1)
    sand = bearing_case(SOILS["sand"], paper)
    assert sand.kind == "granular" and sand.capacity == pytest.approx(drained_bearing(SOILS["sand"].density, 8.0))
    assert bearing_case(SOILS["rock"], paper).kind == "rock"
