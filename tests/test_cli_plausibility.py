"""The command line and the plausibility checks: ``--force`` warns once per value (the study is loaded once per
command), and ``rockfrag study`` takes ``--force`` as run and fragility do."""

from __future__ import annotations

import pytest

from rockfrag.cli import main

BLOCK = '[blocks.cab]\nb = 0.3\nh = 1.0\nmass = 300\nE_b = 200\n'
STUDY = 'soils = ["clay"]\n' + BLOCK
"""A cabinet with E_b = 200 (GPa meant): three implausible values (E_b, settlement, bed frequency)."""


@pytest.mark.parametrize("command, force", [
    ("run", ["--force"]),
    ("run", []),  # [checks] plausibility = "warn" in the file
    ("records", ["--force"]),
    ("applicability", ["--force"]),
])
def test_each_plausibility_warning_is_printed_once(tmp_path, monkeypatch, capsys, command, force):
    monkeypatch.chdir(tmp_path)
    study = tmp_path / "eb.toml"
    study.write_text(STUDY if force else 'soils = ["clay"]\n[checks]\nplausibility = "warn"\n' + BLOCK)
    # no such record set: the command stops after loading the study, before any run
    assert main([command, str(study), *force, "--set", "no-such-set"]) == 2
    error = capsys.readouterr().err
    assert error.count("E_b = 200 Pa is below 1 MPa") == 1, error
    assert error.count("rockfrag: warning:") == 3, error


def test_study_takes_force(tmp_path, capsys):
    study = tmp_path / "eb.toml"
    study.write_text(STUDY)
    assert main(["study", str(study)]) == 2
    assert "--force" in capsys.readouterr().err
    assert main(["study", str(study), "--force"]) == 0
    captured = capsys.readouterr()
    assert "is valid" in captured.out and captured.err.count("E_b = 200 Pa is below 1 MPa") == 1
