"""The command under failure (issue 13): a bad record is skipped with its one-line reason and the rest
run (exit 1), only bad records or a wrong option is a user error (one line, exit 2), a bug is one line
with a log file (exit 3), in-process and in a real process; record ids stay distinct when file names
clash."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest
import xarray as xr

from rockfrag import cli
from rockfrag.config import load_study
from rockfrag.records import load_records
from rockfrag.study import run_study
from tests.reliability_helpers import (
    QUIET,
    assert_one_line_error,
    error_lines,
    records_folder,
    small_study_text,
    tiny_run_argv,
    write_at2,
    write_tiny_study,
)

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def tiny_study(tmp_path_factory):
    """One short synthetic record, 2 levels, 2 soils, the 3 default blocks, Housner and SSI."""
    return write_tiny_study(tmp_path_factory.mktemp("tiny"))


# ---------------------------------------------------------------- bad records, one at a time

BAD_RECORDS = [  # (id, arguments of the bad file, words of its one-line reason)
    ("1 sample", {"values": [0.1]}, ["only 1 samples"]),
    ("2 samples", {"values": [0.1, -0.1]}, ["only 2 samples"]),
    ("DT 5 s", {"dt": 5.0}, ["DT = 5 s", "implausible"]),
    ("DT 1e-300", {"dt": 1e-300}, ["DT = 1e-300 s", "implausible"]),
    ("all zero", {"amplitude_g": 0.0}, ["all accelerations are zero"]),
    ("1e305 g", {"amplitude_g": 1e305}, ["implausible", "check the units"]),
    ("empty file", {"text": ""}, ["file is empty"]),
    ("binary file", {"bytes": b"\x00\x01\x02rockfrag\x00" * 10}, ["binary"]),
]


def _bad_folder(tmp_path, spec, good=True):
    spec = dict(spec)
    return records_folder(tmp_path, good=good, bad_text=spec.pop("text", None),
                          bad_bytes=spec.pop("bytes", None), bad=spec or None)


@pytest.mark.parametrize("command", ["records", "run"])
@pytest.mark.parametrize("name, spec, words", BAD_RECORDS, ids=[case[0] for case in BAD_RECORDS])
def test_bad_record_is_skipped_with_its_reason_and_the_rest_run(name, spec, words, command, tmp_path, capsys):
    folder = _bad_folder(tmp_path, spec)
    output = tmp_path / "out"
    if command == "records":
        argv = ["records", "--set", str(folder), "--output", str(output), "--no-progress"]
    else:
        study = tmp_path / "study.toml"
        study.write_text(small_study_text(folder, levels=[0.5], soils=["rock"]))
        argv = ["run", str(study), "--output", str(output), "--serial", "--no-progress"]
    status = cli.main(argv)
    captured = capsys.readouterr()
    assert status == cli.EXIT_PARTIAL, captured.err
    line = assert_one_line_error(captured.err, "skipped", "bad.AT2", *words)
    assert line.startswith("rockfrag: skipped")
    if command == "records":
        assert list(pd.read_csv(output / "records.csv")["id"]) == ["good"]
    else:
        assert list(xr.open_dataset(output / "cube.nc").record.values) == ["good"]


@pytest.mark.parametrize("name, spec, words", BAD_RECORDS, ids=[case[0] for case in BAD_RECORDS])
def test_only_bad_records_is_a_user_error(name, spec, words, tmp_path, capsys):
    folder = _bad_folder(tmp_path, spec, good=False)
    status = cli.main(["records", "--set", str(folder), "--output", str(tmp_path / "out"), "--no-progress"])
    captured = capsys.readouterr()
    assert status == cli.EXIT_USER_ERROR
    lines = error_lines(captured.err)
    assert "Traceback" not in captured.err and len(lines) == 2  # the skipped file, then "nothing to do"
    assert all(word in lines[0] for word in words) and "no record" in lines[1]


def test_same_file_names_in_two_folders_get_ids_from_their_paths(tmp_path, capsys):
    write_at2(tmp_path / "records" / "site-a" / "X.AT2", amplitude_g=0.2)
    write_at2(tmp_path / "records" / "site-b" / "X.AT2", amplitude_g=0.4)
    status = cli.main(["records", "--set", str(tmp_path / "records"), "--output", str(tmp_path / "out"),
                       "--no-progress"])
    assert status == 0, capsys.readouterr().err
    table = pd.read_csv(tmp_path / "out" / "records.csv")
    assert sorted(table["id"]) == ["site-a/X", "site-b/X"]
    pga = table.set_index("id")["raw_pga_g"]
    assert pga["site-b/X"] == pytest.approx(2 * pga["site-a/X"], rel=1e-6)  # each id has its own file


def test_same_content_twice_is_skipped_as_a_duplicate(tmp_path, capsys):
    write_at2(tmp_path / "records" / "one.AT2")
    write_at2(tmp_path / "records" / "two.AT2")
    status = cli.main(["records", "--set", str(tmp_path / "records"), "--output", str(tmp_path / "out"),
                       "--no-progress"])
    assert status == cli.EXIT_PARTIAL
    assert_one_line_error(capsys.readouterr().err, "two.AT2", "same content as record one", "duplicate")


def test_same_file_named_twice_is_read_once(tmp_path, capsys):
    path = write_at2(tmp_path / "records" / "one.AT2")
    relative = os.path.relpath(path)
    status = cli.main(["records", "--set", str(path), "--set", relative, "--output", str(tmp_path / "out"),
                       "--no-progress"])
    assert status == 0, capsys.readouterr().err
    assert len(pd.read_csv(tmp_path / "out" / "records.csv")) == 1


@pytest.mark.parametrize("npts", [3, 5, 9])
def test_short_record_that_processing_cannot_handle_is_skipped_not_a_traceback(npts, tmp_path, capsys):
    write_at2(tmp_path / "records" / "good.AT2")
    write_at2(tmp_path / "records" / "short.AT2", values=[0.1, -0.2, 0.15, -0.05, 0.02, 0.3, -0.1, 0.05, 0.01][:npts])
    status = cli.main(["records", "--set", str(tmp_path / "records"), "--output", str(tmp_path / "out"),
                       "--no-progress"])
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    if status == cli.EXIT_PARTIAL:  # skipped by processing, with the step that failed
        assert_one_line_error(captured.err, "short.AT2", "cannot be processed")
    else:
        assert status == 0 and len(pd.read_csv(tmp_path / "out" / "records.csv")) == 2


# ---------------------------------------------------------------- record ids when names clash

def test_user_file_id_never_takes_a_catalogue_id(tmp_path):
    write_at2(tmp_path / "mine" / "x" / "DUZCE" / "BOL090.AT2", amplitude_g=0.2)
    write_at2(tmp_path / "mine" / "y" / "BOL090.AT2", amplitude_g=0.3)
    records, failures = load_records(["DUZCE/BOL090", str(tmp_path / "mine")])
    ids = [r.id for r in records]
    assert not failures and len(set(ids)) == 3 and "DUZCE/BOL090" in ids
    assert records[0].metadata["file"].endswith("BOL090.AT2") and "x/DUZCE/BOL090" in ids and "y/BOL090" in ids


def test_cube_lists_every_record_checksum_when_names_clash(tmp_path):
    write_at2(tmp_path / "records" / "a" / "X.AT2", amplitude_g=0.2)
    write_at2(tmp_path / "records" / "b" / "X.AT2", amplitude_g=0.4)
    study = tmp_path / "study.toml"
    study.write_text(small_study_text(tmp_path / "records", levels=[0.5], soils=["rock"]))
    dataset, _ = run_study(load_study(study), output=tmp_path / "out", workers=1, **QUIET)
    assert sorted(dataset.record.values) == ["a/X", "b/X"]
    assert sorted(json.loads(dataset.attrs["record_checksums"])) == ["a/X", "b/X"]


# ---------------------------------------------------------------- user errors and internal errors

USER_ERRORS = [  # (id, argv builder, words of the one line); each must end with rc 2
    ("output is a file", lambda t: (t / "file").write_text("x") and
     ["records", "--set", "bolu", "--output", str(t / "file")], ["is a file"]),
    ("output below a file", lambda t: (t / "file").write_text("x") and
     ["records", "--set", "bolu", "--output", str(t / "file" / "sub")], ["cannot create the output folder"]),
    ("run output is a file", lambda t: (t / "file").write_text("x") and
     tiny_run_argv(t, "--output", str(t / "file")), ["is a file"]),
    ("--workers -1", lambda t: tiny_run_argv(t, "--output", str(t / "out"), "--workers", "-1"),
     ["--workers", "-1", ">= 1"]),
    ("--workers 0", lambda t: tiny_run_argv(t, "--output", str(t / "out"), "--workers", "0"),
     ["--workers", "0"]),
    ("--set ''", lambda t: ["records", "--set", "", "--output", str(t / "out")], ["--set", "empty"]),
    ("study is a folder", lambda t: ["run", str(t), "--output", str(t / "out")], []),
]


@pytest.mark.parametrize("name, build, words", USER_ERRORS, ids=[case[0] for case in USER_ERRORS])
def test_user_error_is_one_line_and_exit_2(name, build, words, tmp_path, capsys):
    argv = build(tmp_path)
    try:
        status = cli.main(argv)
    except SystemExit as stop:  # a usage error found by argparse
        status = stop.code
    captured = capsys.readouterr()
    assert status == cli.EXIT_USER_ERROR, captured.err
    assert_one_line_error(captured.err, "error:", *words)


def test_internal_error_is_one_line_with_a_log_and_exit_3(tmp_path, capsys, monkeypatch):
    def broken_stage(*args, **kwargs):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr("rockfrag.records_report.records_stage", broken_stage)
    output = tmp_path / "out"
    status = cli.main(["records", "--set", "bolu", "--output", str(output), "--no-progress"])
    captured = capsys.readouterr()
    assert status == cli.EXIT_INTERNAL_ERROR == 3
    line = assert_one_line_error(captured.err, "internal error in stage 'records'", "records bolu",
                                 "ZeroDivisionError: a bug")
    logs = list(output.glob("rockfrag-error-*.log"))
    assert len(logs) == 1 and str(logs[0]) in line
    assert "Traceback" in logs[0].read_text() and "broken_stage" in logs[0].read_text()


def test_internal_error_log_falls_back_to_the_temp_folder(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    (tmp_path / "file").write_text("x")
    args = cli.build_parser().parse_args(["records", "--output", str(tmp_path / "file" / "out")])
    assert cli._report_internal_error(args, RuntimeError("boom")) == 3
    line = assert_one_line_error(capsys.readouterr().err, "RuntimeError: boom")
    assert str(tmp_path / "tmp") in line and len(list((tmp_path / "tmp").glob("rockfrag-error-*.log"))) == 1


def test_help_documents_the_exit_codes(capsys):
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    text = capsys.readouterr().out
    for code in ("0 ", "1 ", "2 ", "3 "):
        assert f"\n  {code}" in text
    assert "internal error" in text
    documented = (ROOT / "docs" / "guide" / "command-line.md").read_text()  # the README's exit-status table moved here
    assert "| 3 |" in documented and "internal error" in documented


def test_internal_error_in_a_real_process(tmp_path):
    """A real process: one stderr line, rc 3, no traceback on the terminal."""
    code = textwrap.dedent(f"""
        import sys
        import rockfrag.records_report as stage
        def broken(*a, **k):
            raise KeyError("surprise")
        stage.records_stage = broken
        from rockfrag.cli import main
        sys.exit(main(["records", "--set", "bolu", "--output", {str(tmp_path)!r}, "--no-progress"]))
    """)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert result.returncode == 3
    assert_one_line_error(result.stderr, "internal error in stage 'records'", "KeyError")


def test_bad_records_in_a_real_process_exit_1(tmp_path):
    folder = _bad_folder(tmp_path, {"dt": 1e-300})
    result = subprocess.run([sys.executable, "-m", "rockfrag", "records", "--set", str(folder), "--output",
                             str(tmp_path / "out"), "--no-progress"], capture_output=True, text=True, cwd=ROOT)
    assert result.returncode == 1
    assert_one_line_error(result.stderr, "bad.AT2", "DT = 1e-300")


def test_internal_error_in_a_cell_names_the_record(tiny_study, tmp_path, capsys, monkeypatch):
    def broken_cells(*args, **kwargs):
        raise IndexError("kernel bug")

    monkeypatch.setattr("rockfrag.study.compute_cells", broken_cells)
    status = cli.main(["run", str(tiny_study), "--output", str(tmp_path / "out"), "--serial", "--no-progress"])
    assert status == cli.EXIT_INTERNAL_ERROR
    assert_one_line_error(capsys.readouterr().err, "stage 'run'", str(tiny_study), "(record pulse, block ",
                          "IndexError: kernel bug")
