"""Fuzzing the plausibility checks (issue 21 item 1): Hypothesis-made plausible blocks and soils pass;
the same inputs with one unit slip (a modulus in GPa/MPa written as Pa, a mass in t or g written as kg,
a footprint in cm^2 or mm^2, a soil depth in mm) are refused with one line naming the slipped field.

Plausible by construction: half-width b 0.1-3 m, h/b 0.5-5, out-of-plane depth 0.2-3 x 2b, mass per
bounding volume 10-3000 kg/m^3, E_b 1-300 GPa, soil depth 1-5 m, G_s 30 MPa-100 GPa. Then the static
settlement 2 rho g h H (1/G_s + 1/E_b) stays under 5% of min(b, h), and every slip below crosses its
check's limit by construction (e.g. mass / 1000 gives at most 3 kg/m^3 < 5), so a pass is no fluke.
"""

from __future__ import annotations

import warnings

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rockfrag.blocks import Block
from rockfrag.errors import ConfigError
from rockfrag.plausibility import PlausibilityWarning, check_study
from rockfrag.soils import SoilClass
from tests.fuzz.test_fuzz_inputs import FUZZ

EXAMPLES = 150


@st.composite
def plausible_case(draw) -> tuple[dict, dict]:
    """(Block keywords, SoilClass keywords) of a block and soil that are plausible by construction."""
    b = draw(st.floats(0.1, 3.0))
    h = b * draw(st.floats(0.5, 5.0))
    depth = 2.0 * b * draw(st.floats(0.2, 3.0))
    area = 2.0 * b * depth
    density = draw(st.floats(10.0, 3000.0))
    block = {"name": "fuzzed", "b": b, "h": h, "mass": density * area * 2.0 * h, "footprint_area": area,
             "E_b": draw(st.floats(1e9, 3e11)), "soil_depth": draw(st.floats(1.0, 5.0))}
    soil = {"name": "fuzzsoil", "shear_modulus": draw(st.floats(3e7, 1e11)),
            "poisson_ratio": draw(st.floats(0.1, 0.45)), "density": draw(st.floats(1500.0, 2600.0))}
    return block, soil


SLIPS = {  # name: (object changed, key, factor, field blamed)
    "E_b in GPa": ("block", "E_b", 1e-9, "blocks.fuzzed.E_b"),
    "E_b in MPa": ("block", "E_b", 1e-6, "blocks.fuzzed.E_b"),
    "mass in t": ("block", "mass", 1e-3, "blocks.fuzzed.mass"),
    "mass in g": ("block", "mass", 1e3, "blocks.fuzzed.mass"),
    "footprint in cm^2": ("block", "footprint_area", 1e4, "blocks.fuzzed.footprint_area"),
    "footprint in mm^2": ("block", "footprint_area", 1e6, "blocks.fuzzed.footprint_area"),
    "soil depth in mm": ("block", "soil_depth", 1e3, "blocks.fuzzed.soil_depth"),
    "G_s in MPa": ("soil", "shear_modulus", 1e-6, "soils_custom.fuzzsoil.shear_modulus"),
    "G_s in GPa": ("soil", "shear_modulus", 1e-9, "soils_custom.fuzzsoil.shear_modulus"),
}


def _build(block: dict, soil: dict) -> tuple[list[Block], list[SoilClass]]:
    """One block and one soil, as ``check_study`` takes them."""
    return [Block(**block)], [SoilClass(**soil)]


@settings(FUZZ, max_examples=EXAMPLES)
@given(case=plausible_case())
def test_fuzz_plausible_blocks_and_soils_pass(case):
    blocks, soils = _build(*case)
    assert check_study(blocks, soils, source="fuzz.toml") == []


@settings(FUZZ, max_examples=EXAMPLES)
@given(case=plausible_case(), slip=st.sampled_from(sorted(SLIPS)))
def test_fuzz_a_unit_slip_is_one_line_naming_its_field(case, slip):
    block, soil = case
    target, key, factor, field = SLIPS[slip]
    changed = block if target == "block" else soil
    changed[key] = changed[key] * factor
    with pytest.raises(ConfigError) as caught:
        check_study(*_build(block, soil), source="fuzz.toml")
    message = str(caught.value)
    assert caught.value.field == field, (slip, message)
    assert "\n" not in message and message.startswith(f"fuzz.toml: {field}: ")
    assert f"{key} = {changed[key]:g}" in message, (slip, message)
    assert "did you mean" in message, (slip, message)


@settings(FUZZ, max_examples=EXAMPLES // 3)
@given(case=plausible_case(), slip=st.sampled_from(sorted(SLIPS)))
def test_fuzz_the_expert_override_warns_instead(case, slip):
    block, soil = case
    target, key, factor, field = SLIPS[slip]
    (block if target == "block" else soil)[key] *= factor
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        messages = check_study(*_build(block, soil), on_implausible="warn")
    assert messages and len(caught) == len(messages)
    assert all(issubclass(w.category, PlausibilityWarning) for w in caught)
    assert str(caught[0].message).startswith(f"{field}: ")
