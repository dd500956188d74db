"""Study-file validation: every bad input is one line naming the file and the user's field, exit status 2,
before anything runs; the blocks selector picks the blocks that run."""

from __future__ import annotations

import pytest

from rockfrag.cli import main
from rockfrag.config import load_study
from rockfrag.errors import ConfigError

BLOCK = "b = 0.5\nh = 2.0\nmass = 1000.0\n"

BAD_STUDIES = [
    # (study text, field the message must name, words it must contain)
    ('[soils_custom.loam]\nshear_modulus = 5e7\npoison_ratio = 0.3\n', "soils_custom.loam.poison_ratio",
     "did you mean 'poisson_ratio'"),
    ('[soils_custom.loam]\nshear_modulus = 5e7\ndamping_raito = 0.2\n', "soils_custom.loam.damping_raito",
     "damping_ratio"),
    ('[damage_states.tilt]\nedp = "peak_angle_ratio"\ntreshold = 0.8\n', "damage_states.tilt.treshold",
     "allowed: description, edp, threshold"),
    ('[damage_states.tilt]\nedp = "peak_tilt"\nthreshold = 0.8\n', "damage_states.tilt.edp", "peak_angle_ratio"),
    ('[damage_states.tilt]\nedp = "peak_angle_ratio"\nthreshold = -1\n', "damage_states.tilt.threshold", "> 0"),
    ('blocks.x = 5\n', "blocks.x", "must be a table"),
    ('[intensity]\nmeasure = ["pga"]\n', "intensity.measure", "must be a string"),
    ('[intensity]\nmeasure = "arias"\n', "intensity.measure", "allowed: 'pga'"),
    ('soils = [["sand"]]\n', "soils[0]", "must be a name"),
    ('soils = ["sand", "loam"]\n', "soils", "unknown soil 'loam'"),
    ('[study]\noutput = 5\n', "study.output", "must be a string"),
    ('output = 5\n', "output", "unknown key"),
    ('[study]\nrecord_sets = 5\n', "study.record_sets", "must be a list of names"),
    ('[study]\nrecord_sets = ["far-field", ""]\n', "study.record_sets[1]", "empty name"),
    ('[soils_custom.loam]\nshear_modulus = 5e7\npoisson_ratio = "0.3"\n', "soils_custom.loam.poisson_ratio",
     "must be a number"),
    ('[soils_custom.loam]\nshear_modulus = 0\n', "soils_custom.loam.shear_modulus", "must be a number > 0"),
    ('[soils_custom.loam]\npoisson_ratio = 0.3\n', "soils_custom.loam.shear_modulus", "missing"),
    ('models = "housner"\n', "models", "must be a list of names"),
    ('models = ["housner", "rigid"]\n', "models", "unknown model 'rigid'"),
    ('[intensity]\nlevels = { start = 0.1, stop = 1.0, count = true }\n', "intensity.levels.count",
     "true is a boolean"),
    ('[intensity]\nlevels = { start = -0.1, stop = 1.0, count = 5 }\n', "intensity.levels.start",
     "must be a number > 0"),
    ('[intensity]\nlevels = [0.1, -0.2]\n', "intensity.levels[1]", "must be a number > 0"),
    ('[intensity]\nlevels = { start = 0.1, stop = 1.0, step = 5 }\n', "intensity.levels.step", "allowed: count"),
    ('[intensity]\nlevels = { start = 0.1, stop = 1.0, relative_to = "overturn" }\n', "intensity.levels.relative_to",
     "'uplift'"),
    ('[intensity]\nlevels = [0.1]\nsoils = ["sand"]\n', "intensity.soils", "before the first [table]"),
    ('[solver]\nbed = "springs"\n', "solver.bed", "'two-spring'"),
    ('[solver]\novertun_angle = 1.0\n', "solver.overtun_angle", "did you mean 'overturn_angle'"),
    ('[fragility]\nbootstrap = 10.5\n', "fragility.bootstrap", "whole number"),
    ('[hazard]\nfile = "no-such-hazard.csv"\n', "hazard.file", "not found"),
    ('[blocks.bad]\nb = -1.0\nh = 2.0\n', "blocks.bad.b", "out of range"),
    ('[blocks_custom.bad]\nR = 1.0\nalpha = 2.0\n', "blocks_custom.bad.alpha", "out of range"),
    ('[blocks.bad]\nb = 1.0\nh = "2"\n', "blocks.bad.h", "must be a number"),
    ('blocks = ["paper", "transformer"]\n', "blocks", "unknown block 'transformer'"),
    ('blocks = ["paper", "paper"]\n', "blocks", "named twice"),
    ('[applicability]\ng_range = [1e9, 1e7]\n', "applicability.g_range", "G_min < G_max"),
    ('[applicability]\nn_g = 0\n', "applicability.n_g", "whole number >= 2"),
    ('[applicability]\ntolerance = -0.1\n', "applicability.tolerance", "> 0"),
    ('study = "x"\n', "study", "must be a table"),
    ('[damage_states.rocking-0.8]\nedp = "peak_angle_ratio"\n', "damage_states.rocking-0.8",
     '[damage_states."rocking-0.8"]'),
    ('[study]\nname = "x"\nnaem = "y"\n', "study.naem", "did you mean 'name'"),
]


def _run_study_command(path, tmp_path, capsys):
    status = main(["run", str(path), "--output", str(tmp_path / "out"), "--no-progress"])
    error_lines = capsys.readouterr().err.strip().splitlines()
    return status, error_lines


@pytest.mark.parametrize("text, field, words", BAD_STUDIES, ids=[row[1] for row in BAD_STUDIES])
def test_bad_study_is_one_line_with_file_and_field(tmp_path, capsys, text, field, words):
    path = tmp_path / "study.toml"
    path.write_text(text)
    status, lines = _run_study_command(path, tmp_path, capsys)
    assert status == 2
    assert len(lines) == 1, lines
    assert f"{path}: {field}: " in lines[0]
    assert words in lines[0]
    assert not (tmp_path / "out" / "cube.nc").exists()


def test_hazard_with_a_text_cell_is_reported_before_the_run(tmp_path, capsys):
    hazard = tmp_path / "hazard.csv"
    hazard.write_text("pga,frequency\n0.1,0.01\n0.5,abc\n")
    path = tmp_path / "study.toml"
    path.write_text(f'[hazard]\nfile = "{hazard}"\n')
    status, lines = _run_study_command(path, tmp_path, capsys)
    assert status == 2 and len(lines) == 1
    assert f"{path}: hazard.file: {hazard}: line 3, column 2 (frequency): 'abc' is not a number" in lines[0]


def test_binary_study_file(tmp_path, capsys):
    path = tmp_path / "study.toml"
    path.write_bytes(bytes(range(256)) * 4)
    status, lines = _run_study_command(path, tmp_path, capsys)
    assert status == 2 and len(lines) == 1
    assert str(path) in lines[0] and "binary" in lines[0]


def test_study_path_that_is_a_folder(tmp_path, capsys):
    folder = tmp_path / "studies"
    folder.mkdir()
    status, lines = _run_study_command(folder, tmp_path, capsys)
    assert status == 2 and len(lines) == 1
    assert str(folder) in lines[0] and "is a folder" in lines[0]


def test_invalid_toml_names_the_file(tmp_path, capsys):
    path = tmp_path / "study.toml"
    path.write_text("soils = [\n")
    status, lines = _run_study_command(path, tmp_path, capsys)
    assert status == 2 and len(lines) == 1 and str(path) in lines[0] and "not valid TOML" in lines[0]


def test_error_comes_from_the_command_line_override(capsys, tmp_path):
    with pytest.raises(SystemExit) as stopped:
        main(["run", "--set", "", "--output", str(tmp_path)])
    assert stopped.value.code == 2


# ---------------------------------------------------------------- what runs

def _study(tmp_path, text):
    path = tmp_path / "study.toml"
    path.write_text(text)
    return load_study(path)


def test_default_study_runs_the_three_presets():
    assert [b.name for b in load_study().blocks] == ["paper", "slender-cabinet", "squat-machinery"]


def test_a_user_file_without_blocks_keeps_the_presets(tmp_path):
    config = _study(tmp_path, 'soils = ["rock"]\n')
    assert [b.name for b in config.blocks] == ["paper", "slender-cabinet", "squat-machinery"]


def test_user_blocks_replace_the_presets(tmp_path):
    config = _study(tmp_path, f"[blocks.transformer]\n{BLOCK}")
    assert [b.name for b in config.blocks] == ["transformer"]
    assert config.blocks[0].b == 0.5 and config.blocks[0].h == 2.0


def test_user_custom_blocks_without_selector_run_alone(tmp_path):
    config = _study(tmp_path, f"[blocks_custom.transformer]\n{BLOCK}")
    assert [b.name for b in config.blocks] == ["transformer"]


def test_selector_mixes_presets_and_custom_blocks_in_its_order(tmp_path):
    config = _study(tmp_path, f'blocks = ["transformer", "paper"]\n[blocks_custom.transformer]\n{BLOCK}')
    assert [b.name for b in config.blocks] == ["transformer", "paper"]
    assert config.blocks[1].R == 9.39


def test_new_keys_reach_the_config(tmp_path):
    config = _study(tmp_path, '[solver]\nbed = "continuous"\n[study]\nunits = "gal"\ndt = 0.005\n'
                              '[applicability]\nn_g = 5\nlevels = [2.0]\n'
                              '[intensity]\nlevels = { start = 0.5, stop = 6, count = 30, relative_to = "uplift" }\n')
    assert config.bed == "continuous" and config.record_units == "gal" and config.record_dt == 0.005
    assert config.applicability.n_g == 5 and config.applicability.levels == (2.0,)
    assert config.applicability.tolerance == 0.10  # the default where the table is silent
    assert config.levels_relative_to == "uplift" and len(config.levels) == 30
    assert load_study().bed == "two-spring"


def test_custom_damage_state_is_accepted(tmp_path):
    config = _study(tmp_path, '[damage_states."rocking-0.8"]\nedp = "peak_angle_ratio"\nthreshold = 0.8\n')
    assert config.raw["damage_states"]["rocking-0.8"]["threshold"] == 0.8


def test_override_from_the_command_line_is_validated():
    with pytest.raises(ConfigError) as caught:
        load_study(None, {"study": {"record_sets": [""]}})
    assert caught.value.source == "command line" and caught.value.field == "study.record_sets[0]"
