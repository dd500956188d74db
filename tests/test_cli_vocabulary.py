"""One CLI vocabulary: shared options defined once with the same defaults, checked values, one
applicability definition shared by `rockfrag applicability` and the fragility stage."""

from __future__ import annotations

import argparse

import pytest
import xarray as xr

from rockfrag.cli import _executor_options, _study_config, build_parser, main
from rockfrag.errors import PipelineError

RECORD_COMMANDS = ("records", "run", "fragility", "applicability", "study")
SHARED = ("--set", "--units", "--dt", "--processing", "--output", "--no-progress", "--force", "--wait")


def _subparsers():
    parser = build_parser()
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices


def _option(subparser, flag):
    return next((a for a in subparser._actions if flag in a.option_strings), None)


def test_shared_options_are_the_same_on_every_record_command():
    commands = _subparsers()
    for flag in SHARED:
        actions = {name: _option(commands[name], flag) for name in RECORD_COMMANDS}
        assert all(actions.values()), (flag, actions)
        reference = actions["records"]
        for name, action in actions.items():
            assert (action.default, action.help, action.type) == (reference.default, reference.help, reference.type), \
                (flag, name)


def test_every_command_takes_the_shared_options():
    """Calibrate names its one record with --record instead of --set; every other shared option is everywhere."""
    commands = _subparsers()
    assert set(commands) == {*RECORD_COMMANDS, "calibrate"}
    missing = [(name, flag) for name in commands for flag in SHARED
               if _option(commands[name], flag) is None and (name, flag) != ("calibrate", "--set")]
    assert not missing


def test_the_study_check_accepts_them_and_writes_nothing(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["study", "--no-progress", "--output", "elsewhere", "--set", "bolu", "--wait", "--force"]) == 0
    out = capsys.readouterr().out
    assert "record sets bolu" in out and "output elsewhere" in out
    assert list(tmp_path.iterdir()) == []  # no output folder, no lock file


def test_processing_and_output_on_every_command_that_processes_records():
    commands = _subparsers()
    for name in (*RECORD_COMMANDS, "calibrate"):
        for flag in ("--processing", "--units", "--dt", "--output"):
            assert _option(commands[name], flag) is not None, (name, flag)


def test_workers_on_every_command_that_computes():
    commands = _subparsers()
    for name in ("run", "fragility", "applicability"):
        assert _option(commands[name], "--workers") is not None, name
    for name in ("run", "fragility"):
        assert _option(commands[name], "--scheduler") is not None, name


@pytest.mark.parametrize("command", ["records", "run", "applicability"])
def test_defaults_come_from_the_study_everywhere(command, tmp_path):
    parser = build_parser()
    config, output = _study_config(parser.parse_args([command]))
    assert config.record_sets == ("far-field",) and str(output) == "reports"
    study = tmp_path / "study.toml"
    study.write_text(f'[study]\nrecord_sets = ["bolu"]\noutput = "{tmp_path / "mine"}"\nprocessing = ""\n')
    config, output = _study_config(parser.parse_args([command, str(study)]))
    assert config.record_sets == ("bolu",) and output == tmp_path / "mine"
    config, output = _study_config(parser.parse_args([command, str(study), "--set", "far-field", "--output", "x"]))
    assert config.record_sets == ("far-field",) and str(output) == "x"


@pytest.mark.parametrize("arguments", [
    ["run", "--workers", "0"],
    ["run", "--workers", "-1"],
    ["fragility", "--workers", "0"],
    ["applicability", "--workers", "-2"],
    ["records", "--set", ""],
    ["run", "--set", " "],
    ["applicability", "--levels", "1.5", "-2"],
    ["applicability", "--tolerance", "-0.1"],
    ["applicability", "--n-g", "0"],
    ["applicability", "--g-range", "0", "1e9"],
    ["calibrate", "ref.csv", "--record", "DUZCE/BOL090", "--soil-g", "-5e7"],
    ["calibrate", "ref.csv", "--record", "DUZCE/BOL090", "--n-k", "0"],
    ["calibrate", "ref.csv", "--record", "DUZCE/BOL090", "--xi-range", "0.01", "1.5"],
    ["records", "--dt", "0"],
])
def test_bad_option_values_stop_at_parse_time(arguments, capsys):
    with pytest.raises(SystemExit) as stopped:
        main(arguments)
    assert stopped.value.code == 2
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert "error: argument" in error


def test_workers_is_a_pool_size_and_scheduler_chooses_dask(monkeypatch):
    checked = []
    monkeypatch.setattr("rockfrag.executors.check_scheduler", checked.append)  # no cluster at tcp://h:8786
    parser = build_parser()
    assert _executor_options(parser.parse_args(["run", "--workers", "3"])) == {"workers": 3}
    assert _executor_options(parser.parse_args(["run", "--serial"])) == {"workers": 1}
    assert _executor_options(parser.parse_args(["run"])) == {"workers": None}
    assert _executor_options(parser.parse_args(["run", "--scheduler", "local", "--workers", "2"])) == \
        {"dask_workers": 2}
    assert _executor_options(parser.parse_args(["run", "--scheduler", "tcp://h:8786"])) == \
        {"scheduler": "tcp://h:8786"}
    assert checked == ["tcp://h:8786"]  # the address is checked before the run, whatever the run has left to do
    with pytest.raises(PipelineError):
        _executor_options(parser.parse_args(["run", "--scheduler", "tcp://h:8786", "--workers", "2"]))


SWEEP_STUDY = """
soils = ["rock"]
models = ["housner", "winkler"]
[study]
record_sets = ["DUZCE/BOL090"]
[applicability]
g_range = [1e8, 1e10]
n_g = 3
levels = [2.0]
block_moduli = [30e9]
[blocks.cabinet]
b = 0.3
h = 1.5
mass = 2000.0
"""


def test_applicability_command_and_fragility_stage_share_one_definition(tmp_path, capsys):
    from rockfrag.applicability import applicability_stage
    from rockfrag.config import load_study

    study = tmp_path / "study.toml"
    study.write_text(SWEEP_STUDY)
    output = tmp_path / "out"
    assert main(["applicability", str(study), "--output", str(output), "--workers", "1", "--no-progress"]) == 0
    written = xr.open_dataset(output / "applicability.nc").load()
    assert written.sizes == {"model": 1, "block": 1, "block_modulus": 1, "level": 1, "shear_modulus": 3}
    assert written.shear_modulus.values[[0, -1]].tolist() == [1e8, 1e10]

    messages = []
    again = applicability_stage(load_study(study), output, workers=1, progress=False, log=messages.append)
    assert any("reused" in m for m in messages), messages  # the fragility stage's parameters are the same
    xr.testing.assert_identical(again, written)

    assert main(["applicability", str(study), "--output", str(output), "--workers", "1", "--tolerance", "0.2",
                 "--no-progress"]) == 0
    changed = xr.open_dataset(output / "applicability.nc").load()
    assert changed.attrs["tolerance"] == 0.2 and changed.attrs["input_hash"] != written.attrs["input_hash"]
