"""``rockfrag study``: a study file checked without running anything, and ``--keys``, every key documented."""

import re
import tomllib
from importlib.resources import files

import pytest

from rockfrag.cli import main
from rockfrag.config import SCHEMA, load_study, study_keys
from rockfrag.errors import ConfigError
from rockfrag.validation import schema_keys


def _leaf_keys(table: dict, prefix: str = "") -> set[str]:
    """The dotted leaf keys of a TOML table, block and soil names replaced by NAME."""
    keys = set()
    for key, value in table.items():
        dotted = f"{prefix}.{key}" if prefix else key
        if prefix in ("blocks", "soils_custom", "blocks_custom", "damage_states"):
            dotted = f"{prefix}.NAME"
        if isinstance(value, dict) and key not in ("levels", "max_probability_in_life", "block_names"):  # one key each
            keys |= _leaf_keys(value, dotted)
        else:
            keys.add(dotted)
    return keys


def test_keys_lists_every_key_of_the_shipped_study_with_what_it_must_be(capsys):
    assert main(["study", "--keys"]) == 0
    printed = capsys.readouterr().out
    listed = {line.split()[0] for line in printed.splitlines()[1:-1]}
    shipped = _leaf_keys(tomllib.loads(files("rockfrag").joinpath("defaults.toml").read_text()))
    assert shipped <= listed, f"keys of defaults.toml missing from --keys: {sorted(shipped - listed)}"
    assert listed == {key for key, _ in schema_keys(SCHEMA)}
    line = next(line for line in printed.splitlines() if line.startswith("hazard.design_life "))
    assert "50.0" in line and "[years]" in line  # its value, its range with the unit


def test_keys_show_the_studys_own_values_and_units(tmp_path):
    study = tmp_path / "s.toml"
    study.write_text('soils = ["clay"]\n[intensity]\ndamping = 0.03\n')
    rows = {key: (value, allowed) for key, value, _, allowed, _ in study_keys(load_study(study))}
    assert rows["soils"][0] == '["clay"]' and rows["intensity.damping"][0] == "0.03"
    assert rows["blocks.NAME.mass"][1].endswith("[kg]") and rows["blocks.NAME.E_b"][1].endswith("[Pa]")


def test_keys_show_the_block_ranges_block_checks(tmp_path):
    rows = {key: allowed for key, _, _, allowed, _ in study_keys()}
    for table in ("blocks", "blocks_custom"):
        assert rows[f"{table}.NAME.b"] == "a number > 0.0 and <= 10000.0 [m]"
        assert rows[f"{table}.NAME.mass"] == "a number > 0.0 and <= 1e+10 [kg]"
    study = tmp_path / "s.toml"
    study.write_text("[blocks.cab]\nb = -0.5\nh = 1.0\n")
    expected = r"blocks\.cab\.b: -0\.5 out of range; must be " + re.escape(rows["blocks.NAME.b"])
    with pytest.raises(ConfigError, match=expected):
        load_study(study)


def test_keys_show_the_shipped_default_beside_the_value_and_whole_notes(tmp_path, capsys):
    study = tmp_path / "s.toml"
    study.write_text("[intensity]\ndamping = 0.03\n")
    rows = {key: (value, default, note) for key, value, default, _, note in study_keys(load_study(study))}
    assert rows["intensity.damping"][:2] == ("0.03", "0.05")
    assert rows["checks.plausibility"][2].endswith("(rockfrag --force does the same)")  # its second line
    assert rows["applicability.run"][2].endswith("`--no-applicability` override both")  # its third line
    assert main(["study", str(study), "--keys"]) == 0
    line = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("intensity.damping "))
    assert "0.03 | 0.05 |" in line


def test_study_checks_a_file_and_writes_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    study = tmp_path / "s.toml"
    study.write_text('soils = ["clay"]\n')
    assert main(["study", str(study)]) == 0
    assert "is valid" in capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]  # no output folder, no lock
    study.write_text('[intensity]\ndampnig = 0.03\n')
    assert main(["study", str(study)]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "dampnig" in error and "did you mean 'damping'" in error


def test_study_checks_that_the_record_selection_exists(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    study = tmp_path / "s.toml"
    for selection, fragments in (("far-feild", ["'far-feild' not found", "did you mean 'far-field'?"]),
                                 ("PEER/NO_SUCH_RECORD", ["'PEER/NO_SUCH_RECORD' not found"]),
                                 ("mine/cabinet.csv", ["'mine/cabinet.csv' not found"])):
        study.write_text(f'[study]\nrecord_sets = ["{selection}"]\n')
        assert main(["study", str(study)]) == 2
        error = capsys.readouterr().err
        assert error.count("\n") == 1 and "study.record_sets" in error, error
        assert all(fragment in error for fragment in fragments), error
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "cabinet.csv").write_text("0.0\n")
    assert main(["study", str(study)]) == 0
    assert "found; the records themselves are read by rockfrag records" in capsys.readouterr().out
    study.write_text('[study]\nrecord_sets = ["far-field", "PEER/elCentro"]\n')
    assert main(["study", str(study)]) == 0
