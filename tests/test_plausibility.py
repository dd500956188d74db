"""Physical plausibility of blocks, soils and foundations (issue 21 item 1): each unit slip is one line
naming the value with its unit, the consequence and the likely slip; the shipped studies pass."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest

from rockfrag.blocks import Block
from rockfrag.config import load_study
from rockfrag.errors import ConfigError
from rockfrag.plausibility import (
    CHECKS,
    MIN_FREQUENCY_RATIO,
    OVERRIDE_HINT,
    PlausibilityWarning,
    check_study,
    frequency_ratio,
    implausibilities,
    settlement,
)
from rockfrag.soils import SOILS, Foundation, SoilClass, foundation
from rockfrag.units import STANDARD_GRAVITY

ROOT = Path(__file__).resolve().parents[1]
CABINET = {"b": 0.3, "h": 1.5, "mass": 2000.0, "E_b": 200e9, "footprint_area": 0.48, "soil_depth": 1.0}
"""The user's cabinet of the issue: 0.6 m x 3 m, 0.8 m deep, 2 t, steel (1389 kg/m^3 overall)."""


def _study(tmp_path, block=None, soil=None, soils=("clay", "rock")) -> Path:
    """A study file with one [blocks.cabinet] (CABINET updated by ``block``) and, optionally, a custom soil."""
    keys = {**CABINET, **(block or {})}
    names = list(soils) + (["loam"] if soil else [])
    text = f"soils = {names!r}\n".replace("'", '"')
    text += "[blocks.cabinet]\n" + "".join(f"{key} = {value!r}\n" for key, value in keys.items())
    if soil:
        text += "[soils_custom.loam]\n" + "".join(f"{key} = {value!r}\n" for key, value in soil.items())
    path = tmp_path / "cabinet.toml"
    path.write_text(text)
    return path


def _cabinet(**changes) -> Block:
    return Block(name="cabinet", **{**CABINET, **changes})


def _refused(path) -> ConfigError:
    """The error of loading the study and checking its plausibility (what ``load_study`` will do)."""
    with pytest.raises(ConfigError) as caught:
        config = load_study(path)
        check_study(config.blocks, config.soils, source=str(path))
    return caught.value


@pytest.mark.parametrize("block, soil, field, fragments", [
    ({"E_b": 200.0}, None, "blocks.cabinet.E_b",
     ["E_b = 200 Pa is below 1 MPa", "static settlement 204 m on clay", "did you mean 200 GPa?"]),
    ({"E_b": 200000.0}, None, "blocks.cabinet.E_b", ["E_b = 200000 Pa", "did you mean 200000 MPa?"]),
    ({"mass": 0.8}, None, "blocks.cabinet.mass",
     ["mass = 0.8 kg", "0.556 kg/m^3, below 5 kg/m^3", "slow runs", "did you mean 0.8 t = 800 kg?"]),
    ({"mass": 2.0e6}, None, "blocks.cabinet.mass",
     ["1.39e+06 kg/m^3, above steel's 7850 kg/m^3", "did you mean 2e+06 g = 2000 kg?"]),
    ({"footprint_area": 4800.0}, None, "blocks.cabinet.footprint_area",
     ["footprint_area = 4800 m^2", "8e+03 m deep", "did you mean 4800 cm^2 = 0.48 m^2?"]),
    ({"footprint_area": 800000.0}, None, "blocks.cabinet.footprint_area",
     ["footprint_area = 800000 m^2", "did you mean 800000 mm^2 = 0.8 m^2?"]),
    ({"b": 500.0, "h": 1000.0}, None, "blocks.cabinet",
     ["b = 500 m and half-height h = 1000 m", "1000 m wide and 2000 m tall", "did you mean mm (b = 0.5 m, h = 1 m)?"]),
    ({"b": 30.0, "h": 150.0}, None, "blocks.cabinet", ["did you mean cm (b = 0.3 m, h = 1.5 m)?"]),
    ({"soil_depth": 1000.0}, None, "blocks.cabinet.soil_depth",
     ["soil_depth = 1000 m", "static settlement 1.1 m on clay", "did you mean 1000 mm = 1 m?"]),
    ({}, {"shear_modulus": 50.0}, "soils_custom.loam.shear_modulus",
     ["shear_modulus = 50 Pa is below 1 MPa", "static settlement 817 m", "did you mean 50 MPa?"]),
    ({}, {"shear_modulus": 0.08}, "soils_custom.loam.shear_modulus", ["did you mean 0.08 GPa?"]),
    ({}, {"shear_modulus": 50000.0}, "soils_custom.loam.shear_modulus", ["did you mean 50000 kPa?"]),
])
def test_a_unit_slip_is_one_line_naming_value_consequence_and_slip(tmp_path, block, soil, field, fragments):
    path = _study(tmp_path, block, soil)
    error = _refused(path)
    assert error.field == field and error.source == str(path)
    message = str(error)
    assert "\n" not in message and message.startswith(f"{path}: {field}: ")
    for fragment in fragments:
        assert fragment in message, (fragment, message)
    assert message.endswith(OVERRIDE_HINT)


def test_r_beside_b_and_h_is_refused_when_the_study_loads(tmp_path):
    path = _study(tmp_path, {"R": 2.0})
    with pytest.raises(ConfigError) as caught:
        load_study(path)  # Block refuses it: no plausibility call needed
    assert caught.value.field == "blocks.cabinet" and caught.value.source == str(path)
    assert "R = 2 m would be ignored" in str(caught.value) and "\n" not in str(caught.value)


@pytest.mark.parametrize("kwargs, fragment", [
    (dict(b=0.3, h=1.5, R=2.0), "R = 2 m would be ignored (the geometry comes from b and h)"),
    (dict(b=0.3, h=1.5, alpha=0.2), "alpha = 0.2 rad would be ignored"),
    (dict(R=2.0, alpha=0.2, b=0.3), "b = 0.3 m would be ignored (the geometry comes from R and alpha)"),
    (dict(b=0.3, R=2.0), "neither pair is complete"),
    (dict(b=0.3, h=1.5, R=2.0, alpha=0.2), "the two pairs disagree"),
])
def test_a_block_given_both_ways_is_refused(kwargs, fragment):
    with pytest.raises(ConfigError) as caught:
        Block(name="x", mass=100.0, **kwargs)
    assert caught.value.field == "block x" and fragment in str(caught.value)


def test_a_consistent_block_given_both_ways_is_accepted():
    block = Block(name="x", b=0.3, h=1.5, mass=2000.0)
    assert replace(block, E_b=30e9).R == block.R  # dataclasses.replace passes all four keys
    assert Block(name="y", b=0.3, h=1.5, R=block.R, alpha=block.alpha).alpha == block.alpha


def test_the_user_cabinet_as_written_is_plausible(tmp_path):
    config = load_study(_study(tmp_path))
    assert check_study(config.blocks, config.soils) == []


@pytest.mark.parametrize("study", [None, *sorted((ROOT / "studies").glob("*.toml"))], ids=str)
def test_shipped_studies_are_plausible(study):
    config = load_study(study)
    assert implausibilities(config.blocks, config.soils) == []
    assert implausibilities(config.blocks, SOILS.values()) == []  # every preset soil, too


def test_settlement_beyond_a_tenth_of_the_block_names_every_input():
    heavy = Block(name="safe", b=0.3, h=1.5, mass=7000.0, E_b=200e9, footprint_area=0.48, soil_depth=1.0)
    mud = SoilClass("mud", 2e6, 0.3, 1800.0)
    found = foundation(mud, heavy)
    assert found.settlement == pytest.approx(7000.0 * STANDARD_GRAVITY / found.stiffness)
    assert found.settlement > 0.1 * heavy.b  # 72 mm under a 0.6 m wide safe
    message = settlement(heavy, mud, found)
    for fragment in ("static settlement m g / k = 0.0715 m", "min(b, h) = 0.3 m", "mass = 7000 kg",
                     "shear_modulus = 2e+06 Pa", "soil_depth = 1 m"):
        assert fragment in message
    assert settlement(heavy, SOILS["clay"], foundation(SOILS["clay"], heavy)) is None


def test_frequency_ratio_is_omega_v_over_p():
    block = Block(name="x", b=0.3, h=1.5, mass=2000.0, footprint_area=0.48, soil_depth=1.0)
    found = foundation(SOILS["clay"], block)
    assert found.frequency_ratio == pytest.approx(math.sqrt(found.stiffness / block.mass) / block.p())
    # (omega_v/p)^2 = 4R / (3 m g / k): the ratio and the settlement are one fact seen twice
    assert found.frequency_ratio ** 2 == pytest.approx(4 * block.R / (3 * found.settlement))
    assert frequency_ratio(block, SOILS["clay"], found) is None
    slow = Foundation(stiffness=found.stiffness, settlement=found.settlement, vertical_frequency=2.0 * block.p(),
                      frequency_ratio=2.0)
    message = frequency_ratio(block, SOILS["clay"], slow)
    assert f"below {MIN_FREQUENCY_RATIO:g}" in message and "only 2 x Housner's p" in message


def test_an_expert_can_run_it_anyway_with_a_warning_per_value():
    soils = [SOILS["clay"], SOILS["rock"]]
    with pytest.warns(PlausibilityWarning) as caught:
        messages = check_study([_cabinet(E_b=200.0, mass=0.8)], soils, on_implausible="warn", source="my.toml")
    assert len(messages) == len(caught) >= 2
    assert any("did you mean 200 GPa?" in str(w.message) for w in caught)
    assert all(str(w.message).startswith("my.toml: blocks.cabinet") for w in caught)


def test_each_field_is_reported_once_and_the_error_counts_the_rest():
    blocks, soils = [_cabinet(E_b=200.0)], [SOILS["clay"], SOILS["sand"], SOILS["rock"]]
    found = implausibilities(blocks, soils)
    fields = [field for field, _ in found]
    assert fields[0] == "blocks.cabinet.E_b" and fields.count("blocks.cabinet.E_b") == 1
    with pytest.raises(ConfigError, match=rf"\(and {len(found) - 1} more implausible values\)"):
        check_study(blocks, soils)


def test_a_wrong_override_value_is_refused():
    with pytest.raises(ConfigError, match="'ignore'; must be one of 'error', 'warn'"):
        check_study([], [], on_implausible="ignore", source="my.toml")


def test_checks_are_registered_in_order_with_a_field_each():
    names = [check.name for check in CHECKS]
    assert names[:2] == ["block modulus", "soil modulus"] and names[-2:] == ["settlement", "frequency ratio"]
    assert all("{block}" in check.field or "{soil}" in check.field for check in CHECKS)


def test_lengths_in_mm_are_a_size_slip_not_a_mass_one():
    found = implausibilities([_cabinet(b=500.0, h=1000.0)], [SOILS["clay"]])
    assert [field for field, _ in found] == ["blocks.cabinet"], found
    assert "mass" not in found[0][1] and " t = " not in found[0][1]


def test_load_study_alone_refuses_a_unit_slip(tmp_path):
    path = _study(tmp_path, {"E_b": 200.0})
    with pytest.raises(ConfigError, match="did you mean 200 GPa"):
        load_study(path)
