"""Issue 13's list of ~30 probes, one row each: every one must end with one line on stderr and the
documented exit status (README, ``rockfrag --help``), never a traceback."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pytest

from rockfrag import cli
from rockfrag.checkpoints import SUFFIX
from tests.reliability_helpers import error_lines, small_study_text, write_at2


def run_cli(argv) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = cli.main([str(a) for a in argv])
        except SystemExit as exit_:
            status = exit_.code
    return status, out.getvalue(), err.getvalue()


@pytest.fixture
def place(tmp_path):
    """A folder with one good short record, a tiny study of it and a reference CSV."""
    write_at2(tmp_path / "records" / "good.AT2")
    study = tmp_path / "study.toml"
    study.write_text(small_study_text(tmp_path / "records", levels=[0.5], soils=["rock"])
                     .replace('["housner", "ssi"]', '["housner"]'))
    reference = tmp_path / "reference.csv"
    reference.write_text("time [s],theta [rad]\n" + "".join(f"{0.01 * i},{1e-4 * i}\n" for i in range(30)))
    return tmp_path


def study_with(place, text):
    path = place / "probe.toml"
    path.write_text((place / "study.toml").read_text() + text)
    return path


def replaced(place, old, new, extra=""):
    """The tiny study with one text replaced (and tables appended): a study file with one mistake."""
    text = (place / "study.toml").read_text()
    assert old in text
    path = place / "probe.toml"
    path.write_text(text.replace(old, new) + extra)
    return path


def bad_record(place, **kwargs):
    write_at2(place / "records" / "bad.AT2", **kwargs)
    return place / "records"


def corrupt_checkpoint(place):
    """Run once, then empty a checkpoint file: the rerun names it, recomputes it and exits 0."""
    assert run_cli(["run", place / "study.toml", "--output", place / "out", "--serial", "--no-progress"])[0] == 0
    victim = sorted((place / "out" / ".checkpoints").glob(f"*{SUFFIX}"))[0]
    victim.write_bytes(b"")
    return ["run", place / "study.toml", "--output", place / "out", "--serial", "--no-progress"]


def zero_reference(place):
    path = place / "zero.csv"
    path.write_text("time [s],theta [rad]\n" + "".join(f"{0.01 * i},0\n" for i in range(30)))
    return path


def text_cell_hazard(place):
    (place / "hazard.csv").write_text("pga_g,annual_frequency\n0.1,0.01\n0.5,abc\n1.0,0.0001\n")
    return study_with(place, f'[hazard]\nfile = "{place / "hazard.csv"}"\n')


RUN = ["--serial", "--no-progress"]
PROBES = [  # (id, argv builder, exit status, words in the one line, marks)
    # 1. damaged checkpoints
    ("empty checkpoint", corrupt_checkpoint, 0, ["damaged", "quarantine"], ()),
    # 2. mistakes that silently changed results (time [min]/[us] and theta [degrees] units: the
    #    calibration helper's tests check the converted values)
    ("typo under soils_custom", lambda p: ["run", replaced(
        p, 'soils = ["rock"]', 'soils = ["wet"]', "[soils_custom.wet]\nshear_modulus = 5e7\ndamping_raito = 0.2\n"),
        "--output", p / "o", *RUN], 2, ["damping_raito"], ()),
    ("typo under damage_states", lambda p: [
        "run", study_with(p, '[damage_states.x]\nedp = "overturned"\nthreshhold = 1\n'),
        "--output", p / "o", *RUN], 2, ["threshhold"], ()),
    ("calibrate text cell in theta", lambda p: [
        "calibrate", _write(p / "t.csv", "time [s],theta [rad],other\n" + "".join(
            f"{0.01 * i},{'x' if i == 5 else 1e-4 * i},{i}\n" for i in range(30))),
        "--record", p / "records" / "good.AT2",
        "--output", p / "o", "--grid-only", "--n-k", "2", "--n-xi", "2"], 2, ["theta"], ()),
    # 3. tracebacks with rc 1
    ("output is a file", lambda p: _write(p / "f", "x") and ["records", "--set", p / "records", "--output", p / "f"],
     2, ["is a file"], ()),
    ("output below a file", lambda p: _write(p / "f", "x") and
     ["run", p / "study.toml", "--output", p / "f" / "o", *RUN], 2, ["output folder"], ()),
    ("1-sample record", lambda p: ["records", "--set", bad_record(p, values=[0.1]), "--output", p / "o",
                                   "--no-progress"], 1, ["bad.AT2", "only 1 samples"], ()),
    ("2-sample record", lambda p: ["run", study_with(p, ""), "--output", p / "o", *RUN]
     if bad_record(p, values=[0.1, 0.2]) else None, 1, ["bad.AT2", "only 2 samples"], ()),
    ("DT 5 s", lambda p: ["run", p / "study.toml", "--output", p / "o", *RUN] if bad_record(p, dt=5.0) else None,
     1, ["bad.AT2", "DT = 5 s"], ()),
    ("DT 1e-300", lambda p: ["records", "--set", bad_record(p, dt=1e-300), "--output", p / "o", "--no-progress"], 1,
     ["bad.AT2", "DT = 1e-300"], ()),
    ("blocks.x = 5", lambda p: ["run", study_with(p, "[blocks]\nx = 5\n"), "--output", p / "o", *RUN], 2,
     ["blocks"], ()),
    ("measure list", lambda p: ["run", replaced(p, "[intensity]", '[intensity]\nmeasure = ["pga"]'),
                                "--output", p / "o", *RUN], 2, ["measure"], ()),
    ("soils nested list", lambda p: ["run", _write(p / "s.toml", (p / "study.toml").read_text().replace(
        'soils = ["rock"]', 'soils = [["rock"]]')), "--output", p / "o", *RUN], 2, ["soils"], ()),
    ("output = 5", lambda p: ["run", _write(p / "s.toml", (p / "study.toml").read_text().replace(
        'name = "tiny"', 'name = "tiny"\noutput = 5')), *RUN], 2, ["output"], ()),
    ("record_sets = 5", lambda p: ["run", _write(p / "s.toml", 'soils = ["rock"]\n[study]\nrecord_sets = 5\n'),
                                   "--output", p / "o", *RUN], 2, ["record_sets"], ()),
    ("poisson_ratio text", lambda p: ["run", replaced(p, 'soils = ["rock"]', 'soils = ["wet"]',
                                                      '[soils_custom.wet]\nshear_modulus = 5e7\npoisson_ratio = "a"\n'),
                                      "--output", p / "o", *RUN], 2, ["poisson_ratio"], ()),
    ("binary study", lambda p: ["run", _write_bytes(p / "b.toml", b"\x00\xff\xfe\x01"), "--output", p / "o", *RUN], 2,
     ["b.toml"], ()),
    ("study is a folder", lambda p: ["run", p / "records", "--output", p / "o", *RUN], 2, ["records"], ()),
    ("hazard CSV text cell", lambda p: ["run", text_cell_hazard(p), "--output", p / "o", *RUN], 2, ["hazard"],
     ()),
    ("calibrate all-zero reference", lambda p: ["calibrate", zero_reference(p), "--record", p / "records" / "good.AT2",
                                                "--output", p / "o", "--grid-only", "--n-k", "2", "--n-xi", "2"],
     2, ["zero.csv"], ()),
    ("calibrate --n-k 0", lambda p: ["calibrate", p / "reference.csv", "--record", p / "records" / "good.AT2",
                                     "--output", p / "o", "--grid-only", "--n-k", "0"], 2, ["n-k"], ()),
    ("applicability --n-g 0", lambda p: ["applicability", p / "study.toml", "--output", p / "o", "--n-g", "0",
                                         "--serial", "--no-progress"], 2, ["n-g"], ()),
    # 6. --workers -1
    ("--workers -1", lambda p: ["run", p / "study.toml", "--output", p / "o", "--workers", "-1", "--no-progress"], 2,
     ["--workers", "-1"], ()),
    # 7. inconsistent or unchecked records and values
    ("all-zero record in records", lambda p: ["records", "--set", bad_record(p, amplitude_g=0.0), "--output", p / "o",
                                              "--no-progress"], 1, ["bad.AT2", "zero"], ()),
    ("all-zero record in run", lambda p: ["run", p / "study.toml", "--output", p / "o", *RUN]
     if bad_record(p, amplitude_g=0.0) else None, 1, ["bad.AT2", "zero"], ()),
    ("1e305 g record", lambda p: ["records", "--set", bad_record(p, amplitude_g=1e305), "--output", p / "o",
                                  "--no-progress"], 1, ["bad.AT2", "implausible"], ()),
    ("empty AT2", lambda p: _write(p / "records" / "bad.AT2", "") and
     ["records", "--set", p / "records", "--output", p / "o", "--no-progress"], 1, ["bad.AT2", "empty"], ()),
    ("binary AT2", lambda p: _write_bytes(p / "records" / "bad.AT2", b"\x00\x01\x02" * 50) and
     ["records", "--set", p / "records", "--output", p / "o", "--no-progress"], 1, ["bad.AT2", "binary"], ()),
    ('models = "housner"', lambda p: ["run", _write(p / "s.toml", (p / "study.toml").read_text().replace(
        'models = ["housner"]', 'models = "housner"')), "--output", p / "o", *RUN], 2, ["models", "!'h'"], ()),
    ("shear_modulus = 0", lambda p: ["run", study_with(p, "[soils_custom.wet]\nshear_modulus = 0\n"), "--output",
                                     p / "o", *RUN], 2, ["shear_modulus", "> 0"], ()),
    ("count = true", lambda p: ["run", _write(p / "s.toml", (p / "study.toml").read_text().replace(
        "levels = [0.5]", "levels = { start = 0.1, stop = 1.0, count = true }")), "--output", p / "o", *RUN], 2,
     ["count"], ()),
    ("negative --levels", lambda p: ["applicability", p / "study.toml", "--output", p / "o", "--levels", "-1",
                                     "--serial", "--no-progress"], 2, ["levels"], ()),
    ("negative --tolerance", lambda p: ["applicability", p / "study.toml", "--output", p / "o", "--tolerance", "-0.1",
                                        "--serial", "--no-progress"], 2, ["tolerance"], ()),
    ("negative --soil-g", lambda p: ["calibrate", p / "reference.csv", "--record", p / "records" / "good.AT2",
                                     "--output", p / "o", "--soil-g", "-1", "--grid-only", "--n-k", "2", "--n-xi", "2"],
     2, ["soil-g"], ()),
    ('--set ""', lambda p: ["records", "--set", "", "--output", p / "o"], 2, ["--set", "empty"], ()),
    ("damage_states error before the cube", lambda p: ["run", study_with(
        p, '[damage_states.x]\nedp = "nonsense"\nthreshold = 1\n'), "--output", p / "o", *RUN], 2,
     ["damage_states.x.edp", "probe.toml"], ()),
]


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def _write_bytes(path: Path, data: bytes) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data)
    return path


@pytest.mark.parametrize("name, build, status, words",
                         [pytest.param(*row[:4], id=row[0], marks=row[4]) for row in PROBES])
def test_issue_probe_ends_in_one_line_and_its_exit_status(name, build, status, words, place):
    argv = build(place)
    got, _, stderr = run_cli(argv)
    lines = error_lines(stderr)
    assert "Traceback" not in stderr, stderr
    assert got == status, stderr
    assert len(lines) == 1, stderr
    for word in words:  # "!text": must not appear
        assert (word[1:] not in lines[0]) if word.startswith("!") else (word in lines[0]), (word, lines[0])
    if status == 2 and "cube" not in name:
        assert not (place / "o" / "cube.nc").exists()
