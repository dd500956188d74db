"""A routine study's lines say what happened in plain words (issue 33 item 5; docs/warnings.md lists them).

One small study (one slender block on rock, housner, two single components of different stations, levels up to
overturning) runs through the CLI (``rockfrag run``); its terminal lines are read back: no jargon of the fit's
internals, an intensity line that does not announce "0 pairs" when nothing was paired, and a capacity line whose
counts and saving agree with the cube's own bookkeeping.
"""

from __future__ import annotations

import contextlib
import io
import re

import pytest
import xarray as xr

STUDY = """
soils = ["rock"]
models = ["housner"]
[study]
name = "messages"
record_sets = ["DUZCE/BOL000", "KOBE/NIS000"]
[intensity]
levels = { start = 0.5, stop = 8.0, count = 4, spacing = "log", relative_to = "uplift" }
[blocks.cabinet]
b = 0.3
h = 1.1
mass = 400.0
"""
JARGON = ("resurrect", "perfectly separated", "0 refining runs", "0 stripe runs", "0 pairs")


@pytest.fixture(scope="module")
def study_lines(tmp_path_factory):
    from rockfrag.cli import main

    folder = tmp_path_factory.mktemp("messages")
    (folder / "study.toml").write_text(STUDY)
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        assert main(["run", str(folder / "study.toml"), "--output", str(folder / "out"), "--no-progress",
                     "--serial"]) == 0
    with xr.open_dataset(folder / "out" / "cube.nc") as cube:
        attrs = dict(cube.attrs)
    return (out.getvalue() + err.getvalue()).splitlines(), attrs


def test_no_jargon_and_no_empty_counts(study_lines):
    lines, _ = study_lines
    for line in lines:
        assert not any(word in line for word in JARGON), line
    intensity = [line for line in lines if line.startswith("intensity:")]
    assert intensity == ["intensity: 2 without a partner scaled by their own component: DUZCE/BOL000, KOBE/NIS000"]


def test_the_capacity_line_counts_what_the_cube_counts(study_lines):
    lines, attrs = study_lines
    found = [re.fullmatch(r"overturning intensities refined to 2%: (\d+) extra runs beside the (\d+) runs at the "
                          r"levels \(levels as fine would need (\d+) runs: the refinement saves (\d+)% of them\)", line)
             for line in lines if line.startswith("overturning intensities")]
    assert len(found) == 1 and found[0], lines
    extra, grid, uniform, saved = map(int, found[0].groups())
    assert grid == 2 * 4  # records x levels of the one cell
    assert extra > 0
    assert uniform > grid + extra  # the saving is real
    assert saved == round(100 * (1 - (grid + extra) / uniform))
    assert (extra, grid, uniform) == (attrs["capacity_runs"], attrs["grid_runs"], attrs["uniform_runs"])


def test_restitution_lines_are_one_per_block_and_name_every_moved_run():
    """The default study's calibration lines: at most two per block (one per kind), naming exactly the (soil,
    member) runs the calibration moved or found unmeasurable (19 near-identical lines before)."""
    import numpy as np

    from rockfrag import study
    from rockfrag.config import load_study

    config = load_study()
    calibration = study.bed_calibration(config, study.model_stiffness(config))
    lines = study.calibration_lines(config, calibration)
    names = [study._member_name(model) for model in calibration.variants]
    for b, block in enumerate(config.blocks):
        own = [line for line in lines if line.startswith(f"rockfrag: block {block.name}:")]
        assert len(own) <= 2
        for finite, marker in ((True, "cannot reach"), (False, "loses more")):
            expected = {}
            for s, soil in enumerate(config.soils):
                for v, name in enumerate(names):
                    if calibration.moved[s, b, v] and np.isfinite(calibration.target[s, b, v]) == finite:
                        expected.setdefault(soil.name, set()).add(name)
            line = next((text for text in own if marker in text), None)
            assert (line is None) == (not expected), (block.name, marker)
            if line is not None:
                assert _soils_and_members(line, names) == expected, line
    assert len(lines) >= 2  # the default study's paper block and cabinet cannot reach the targets on stiff beds


def _soils_and_members(line: str, every: list) -> dict:
    """{soil: members} read back from a line's 'on clay, sand (a, b); rock (every member)' part."""
    named = {}
    groups = line.split(") on ", 1)[1].split("; those runs")[0].split("; it runs")[0]
    for group in groups.split("; "):
        soils, words = group.split(" (", 1)
        for soil in soils.split(", "):
            named[soil] = _members_named(words.rstrip(")"), every)
    return named


def _members_named(words: str, every: list) -> set:
    """The members a line's brackets name: 'every member', 'every member but a, b' or 'a, b'."""
    if words == "every member":
        return set(every)
    if words.startswith("every member but "):
        return set(every) - set(words.removeprefix("every member but ").split(", "))
    return set(words.split(", "))
