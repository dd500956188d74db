"""Did-you-mean for every name a user types: models, soils, blocks, measures, damage-state EDPs (study
files), ``rockfrag calibrate --block/--soil/--model``, ``get_model``, one helper for all of them."""

import pytest

from rockfrag.cli import main
from rockfrag.config import load_study
from rockfrag.errors import ConfigError, SolverError
from rockfrag.models import get_model
from rockfrag.validation import did_you_mean


def test_did_you_mean_suggests_the_closest_name_or_nothing():
    assert did_you_mean("winklr", ["housner", "ssi", "winkler"]) == " (did you mean 'winkler'?)"
    assert did_you_mean("snad", ("sand", "rock")) == " (did you mean 'sand'?)"
    assert did_you_mean("concrete", ["sand", "rock"]) == ""
    assert did_you_mean(3, ["sand"]) == ""  # not a string: nothing to suggest, no crash


@pytest.mark.parametrize("study, field, word, suggestion", [
    ('models = ["winklr"]\n', "models", "winklr", "winkler"),
    ('soils = ["snad"]\n', "soils", "snad", "sand"),
    ('blocks = ["papr"]\n', "blocks", "papr", "paper"),
    ('[intensity]\nmeasure = "pgv2"\n', "intensity.measure", "pgv2", "pgv"),
    ('[damage_states.tilt]\nedp = "peak_angel"\nthreshold = 0.5\n', "damage_states.tilt.edp", "peak_angel",
     "peak_angle"),
])
def test_study_names_get_a_did_you_mean(tmp_path, study, field, word, suggestion):
    path = tmp_path / "s.toml"
    path.write_text(study)
    with pytest.raises(ConfigError) as caught:
        load_study(path)
    message = str(caught.value)
    assert field in message and repr(word) in message and f"did you mean {suggestion!r}" in message


def test_get_model_suggests_the_closest_model():
    with pytest.raises(SolverError, match=r"unknown model 'winklr' \(did you mean 'winkler'\?\)"):
        get_model("winklr")


@pytest.mark.parametrize("options, suggestion", [
    (["--block", "papr"], "paper"),
    (["--soil", "snad"], "sand"),
    (["--model", "winklr"], "winkler"),
])
def test_calibrate_options_get_a_did_you_mean_before_any_file_is_read(tmp_path, capsys, options, suggestion):
    # the reference file does not exist: the names are checked before it is read
    argv = ["calibrate", str(tmp_path / "missing.csv"), "--record", "RSN0001", "--output", str(tmp_path / "out"),
            *options]
    assert main(argv) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and f"did you mean {suggestion!r}" in error
