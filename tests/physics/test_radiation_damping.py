"""Radiation damping on request (issue 18): ``radiation_damping(block, soil)`` is Lysmer's analog, a dashpot
rho V_La per unit footprint area, V_La = 3.4 V_s / (pi (1 - nu)), over the eq. 19 stiffness, as the damping
ratio of the vertical mode; a value of 1 or more is refused with a line naming the soil and the block."""

from __future__ import annotations

import math

import pytest

from rockfrag.blocks import Block
from rockfrag.config import load_study
from rockfrag.errors import SolverError
from rockfrag.models import radiation_damping
from rockfrag.soils import SOILS, SoilClass


def test_the_formula_by_hand():
    soil = SoilClass("loam", shear_modulus=50e6, poisson_ratio=0.25, density=1600.0)
    block = Block(name="hand", b=0.5, h=1.0, mass=4000.0, E_b=30e9, footprint_area=1.2, soil_depth=1.5)
    stiffness = (1.2 / 1.5) / (1 / 50e6 + 1 / 30e9)
    lysmer = 3.4 * math.sqrt(50e6 / 1600.0) / (math.pi * 0.75)
    assert radiation_damping(block, soil) == pytest.approx(1600.0 * lysmer * 1.2 / (2 * math.sqrt(stiffness * 4000.0)),
                                                           rel=1e-12)


def test_default_blocks_on_clay_to_rock():
    """Issue 18's numbers: about 0.23-0.27 for the paper block, 0.5-0.7 for the cabinet and the skid (its footprint
    then 3 m x 2 m). The skid is square in plan since cold read 5 (3 m x 3 m): the dashpot grows with the area and
    the stiffness k with it too, so the ratio grows as the square root of the area, by sqrt(9/6)."""
    import dataclasses

    blocks = {block.name: block for block in load_study().blocks}
    skid = blocks["squat-machinery"]
    blocks["skid-issue-18"] = dataclasses.replace(skid, footprint_area=6.0)
    expected = {"paper": (0.22, 0.28), "slender-cabinet": (0.5, 0.7), "skid-issue-18": (0.5, 0.7)}
    for name, (low, high) in expected.items():
        for soil in ("clay", "sand", "gravel", "rock"):
            assert low <= radiation_damping(blocks[name], SOILS[soil]) <= high, (name, soil)
    for soil in ("clay", "sand", "gravel", "rock"):
        assert radiation_damping(skid, SOILS[soil]) == pytest.approx(
            radiation_damping(blocks["skid-issue-18"], SOILS[soil]) * math.sqrt(9.0 / 6.0), rel=1e-12)


def test_steel_is_not_a_half_space():
    cabinet = next(block for block in load_study().blocks if block.name == "slender-cabinet")
    with pytest.raises(SolverError, match="block 'slender-cabinet' on soil 'steel': xi = 1.2"):
        radiation_damping(cabinet, SOILS["steel"])
