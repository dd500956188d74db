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
