"""Where a study's files are: inputs relative to the study file's folder, outputs relative to the working folder,
the shipped records found by the catalogue lookup; and the study refuses a soil damping ratio it would ignore."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rockfrag.cli import main
from rockfrag.config import load_study
from rockfrag.errors import ConfigError
from rockfrag.records import RECORDS_DIR, load_records
from rockfrag.records.manifest import shipped_records_dir

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "records" / "fema_p695" / "farfield" / "DUZCE" / "BOL090.AT2"

STUDY = """
soils = ["rock"]
models = ["housner"]
[study]
record_sets = ["DUZCE/BOL000", "mine", "extra/BOL090.AT2"]
processing = "recipe.toml"
output = "results"
[hazard]
file = "site/hazard.csv"
[intensity]
levels = [0.1, 0.3]
[blocks.cabinet]
b = 0.3
h = 1.1
mass = 400.0
"""


def _study_folder(folder: Path) -> Path:
    """A user's study folder: the study, a folder and a file of records, a recipe and a hazard curve."""
    (folder / "mine").mkdir(parents=True)
    shutil.copy(RECORD.with_name("BOL000.AT2"), folder / "mine" / "bolu-copy.AT2")
    (folder / "extra").mkdir()
    shutil.copy(RECORD, folder / "extra" / "BOL090.AT2")
    shutil.copy(ROOT / "pipeline" / "processing.toml", folder / "recipe.toml")
    (folder / "site").mkdir()
    shutil.copy(ROOT / "pipeline" / "hazard_example.csv", folder / "site" / "hazard.csv")
    (folder / "study.toml").write_text(STUDY)
    return folder / "study.toml"


def test_inputs_resolve_from_the_study_folder_from_any_working_folder(tmp_path, monkeypatch):
    study = _study_folder(tmp_path / "copied" / "elsewhere")
    elsewhere = tmp_path / "work"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    config = load_study(study)
    folder = study.parent
    assert config.record_sets == ("DUZCE/BOL000", str(folder / "mine"), str(folder / "extra" / "BOL090.AT2"))
    assert config.processing == str(folder / "recipe.toml")
    assert config.hazard_file == str(folder / "site" / "hazard.csv")
    assert config.output == Path("results")  # an output: relative to the working folder, as --output
    records, failures = load_records(list(config.record_sets))
    assert [r.id for r in records] == ["DUZCE/BOL000", "BOL090"] and len(failures) == 1  # the copy: a duplicate
    assert "same content as record DUZCE/BOL000" in str(failures[0])


def test_a_study_in_the_working_folder_keeps_its_relative_paths_short(tmp_path, monkeypatch):
    study = _study_folder(tmp_path)
    monkeypatch.chdir(tmp_path)
    config = load_study(study.resolve())  # an absolute study path, as a script would give it
    assert config.record_sets == ("DUZCE/BOL000", "mine", "extra/BOL090.AT2")
    assert config.processing == "recipe.toml" and config.hazard_file == "site/hazard.csv"


def test_command_line_paths_stay_relative_to_the_working_folder(tmp_path, monkeypatch, capsys):
    study = _study_folder(tmp_path / "project")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "here").mkdir()
    shutil.copy(RECORD, tmp_path / "here" / "mine.AT2")
    assert main(["study", str(study), "--set", "here"]) == 0, capsys.readouterr().err
    assert main(["study", str(study), "--set", "mine"]) == 2  # the study's folder 'mine' is not the command's
    error = capsys.readouterr().err
    assert "command line: --set: 'mine' not found" in error and error.count("\n") == 1


def test_a_missing_input_is_named_where_it_was_looked_for(tmp_path, monkeypatch, capsys):
    folder = tmp_path / "project"
    folder.mkdir()
    (folder / "study.toml").write_text('[hazard]\nfile = "no-such.csv"\n')
    monkeypatch.chdir(tmp_path)
    assert main(["study", "project/study.toml"]) == 2
    error = capsys.readouterr().err
    assert "project/study.toml: hazard.file: " in error and "project/no-such.csv" in error


def test_a_misspelt_record_set_still_gets_its_did_you_mean(tmp_path, monkeypatch, capsys):
    folder = tmp_path / "project"
    folder.mkdir()
    (folder / "study.toml").write_text('[study]\nrecord_sets = ["far-feild"]\n')
    monkeypatch.chdir(tmp_path)
    assert main(["study", "project/study.toml"]) == 2
    assert "did you mean 'far-field'?" in capsys.readouterr().err


def test_the_readme_example_writes_where_the_readme_says(monkeypatch):
    monkeypatch.chdir(ROOT)
    assert load_study("studies/example.toml").output == Path("reports-example")


def test_the_shipped_records_are_found_in_a_clone_and_through_the_environment(tmp_path, monkeypatch):
    monkeypatch.delenv("ROCKFRAG_RECORDS", raising=False)
    assert shipped_records_dir() == ROOT / "records" == RECORDS_DIR
    monkeypatch.setenv("ROCKFRAG_RECORDS", str(tmp_path))
    assert shipped_records_dir() == tmp_path
    with pytest.raises(Exception, match="record catalogue not found; set \\$ROCKFRAG_RECORDS"):
        load_records("bolu", records_dir=shipped_records_dir())


# ---------------------------------------------------------------- a damping ratio the bed would ignore

LOAM = '[soils_custom.loam]\nshear_modulus = 5e7\ndamping_ratio = 0.20\n'


@pytest.mark.parametrize("restitution, shown", [("0.93", "0.93"), ('"recommended"', "'recommended'"),
                                                ('"housner"', "'housner'")])
def test_an_explicit_damping_ratio_with_a_restitution_target_is_refused(tmp_path, restitution, shown):
    study = tmp_path / "s.toml"
    study.write_text(f'soils = ["loam"]\nmodels = ["housner", "winkler"]\n[solver]\nrestitution = {restitution}\n'
                     + LOAM)
    with pytest.raises(ConfigError) as caught:
        load_study(study)
    message = str(caught.value)
    assert "soils_custom.loam.damping_ratio" in message and f"restitution = {shown}" in message
    assert 'restitution = ""' in message and str(study) in message


def test_the_default_recommended_model_refuses_it_too_through_the_command(tmp_path, capsys):
    study = tmp_path / "s.toml"
    study.write_text('soils = ["loam"]\n' + LOAM)  # the shipped [solver] restitution is "recommended"
    assert main(["study", str(study)]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "soils_custom.loam.damping_ratio: 0.2 together with" in error


@pytest.mark.parametrize("text", [
    'soils = ["loam"]\nmodels = ["housner", "winkler"]\n[solver]\nrestitution = ""\n' + LOAM,  # the bed uses it
    'soils = ["loam"]\nmodels = ["housner", "ssi"]\n' + LOAM,  # no bed model: ssi runs at the soil's ratio
    'soils = ["loam", "sand"]\nmodels = ["winkler"]\n[soils_custom.loam]\nshear_modulus = 5e7\n',  # not explicit
])
def test_a_damping_ratio_that_is_used_is_accepted(tmp_path, text):
    study = tmp_path / "s.toml"
    study.write_text(text)
    config = load_study(study)
    assert [soil.name for soil in config.soils][0] == "loam"


def test_a_hazard_file_per_soil_resolves_from_the_study_folder_too(tmp_path, monkeypatch):
    study = _study_folder(tmp_path / "project")
    study.write_text(STUDY.replace('file = "site/hazard.csv"', 'file = { rock = "site/hazard.csv" }'))
    monkeypatch.chdir(tmp_path)
    assert load_study(study).hazard_file == {"rock": str(Path("project") / "site" / "hazard.csv")}
