"""`rockfrag fragility` ends with the answer (issue 21, item 5) and runs the applicability sweep only for the
default study or when asked (item 4); the shipped example study and calibration reference load (item 3)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from rockfrag import applicability as applicability_module
from rockfrag.answer import answer_model, answer_rows, answer_table, display_scale
from rockfrag.calibrate import check_reference, load_reference
from rockfrag.cli import _study_config, build_parser, main, run_applicability
from rockfrag.config import load_study
from rockfrag.errors import ConfigError
from rockfrag.records import load_records
from rockfrag.units import STANDARD_GRAVITY

ROOT = Path(__file__).resolve().parents[1]
TINY = """
soils = ["sand"]  # one soil: the report draws its by-model page on a grid (it once crashed here)
models = ["housner", "winkler"]
[study]
name = "tiny-answer"
record_sets = ["bolu"]
[intensity]
levels = { values = [0.5, 1.5, 3.0, 6.0], relative_to = "uplift" }
[solver]
tail = 2.0
[fragility]
bootstrap = 5
[blocks.cabinet]
b = 0.3
h = 1.5
mass = 2000.0
E_b = 200e9
footprint_area = 0.48
soil_depth = 1.0
"""


# ---------------------------------------------------------------- which runs the sweep

def _decide(tmp_path, study_text, *flags):
    words = ["fragility"]
    if study_text is not None:
        study = tmp_path / "study.toml"
        study.write_text(study_text)
        words.append(str(study))
    args = build_parser().parse_args([*words, *flags])
    config, _ = _study_config(args)
    return run_applicability(args, config)


@pytest.mark.parametrize("study_text, flags, runs", [
    (None, [], True),                                               # the default study: as before
    (None, ["--no-applicability"], False),
    ('[study]\nname = "mine"\n', [], False),                        # a user's study pays only for what it asks
    ('[study]\nname = "mine"\n', ["--applicability"], True),
    ("[applicability]\nrun = true\n", [], True),                    # the study asks for it
    ("[applicability]\nrun = true\n", ["--no-applicability"], False),  # the command line overrides the file
    ("[applicability]\nrun = false\n", ["--applicability"], True),
    ("[applicability]\nrun = true\n", ["--skip-applicability"], False),  # the old spelling still works
])
def test_the_sweep_runs_for_the_default_study_or_when_asked(tmp_path, study_text, flags, runs):
    assert _decide(tmp_path, study_text, *flags) is runs


def test_run_must_be_a_boolean(tmp_path):
    with pytest.raises(ConfigError, match=r"applicability\.run.*'yes'.*true or false"):
        _decide(tmp_path, '[applicability]\nrun = "yes"\n')


# ---------------------------------------------------------------- the table, from a hand-made fragility.nc

def _fragility(units="g", probability=(0.01, 0.2), hazard="my_site.csv", models=("housner", "winkler", "ssi")):
    """A fragility dataset with the layout of fragility.nc: overturning rows of two soils, one block."""
    soils, states = ["clay", "rock"], ["uplift", "overturning"]
    shape = (len(soils), 1, len(models), len(states))
    median = np.full(shape, 0.2)
    median[:, 0, models.index("winkler"), 1] = [0.5, np.nan]  # rock: no record overturned
    status = np.full(shape, "fitted", dtype=object)
    status[1, 0, models.index("winkler"), 1] = "not-reached"
    risk = np.full(shape, np.nan)
    risk[:, 0, models.index("winkler"), 1] = probability
    dims = ("soil", "block", "model", "damage_state")
    interval = {"long_name": "90% two-sided interval: lower bootstrap bound of the median", "units": units}
    dataset = xr.Dataset({
        "median": (dims, median, {"units": units}),
        "median_low": (dims, median * 0.8, interval),
        "median_high": (dims, median * 1.25, interval),
        "beta": (dims, np.full(shape, 0.4)),
        "status": (dims, status.astype(str)),
        "probability_in_life": (dims, risk),
        "studied_im_min": (("block",), [0.1], {"units": units}),
        "studied_im_max": (("block",), [2.0], {"units": units}),
        "n_records": ((), 10),
    }, coords={"soil": soils, "block": ["cabinet"], "model": list(models), "damage_state": states})
    dataset.attrs = {"intensity_measure": "pga", "intensity_unit": units, "design_life_years": 50.0,
                     "hazard_source": hazard}
    return dataset


def test_the_answer_is_the_winkler_overturning_row_per_block_and_soil():
    fragility = _fragility()
    assert answer_model(fragility) == "winkler"
    assert answer_model(fragility.sel(model=["housner", "ssi"])) == "ssi"
    text = answer_table(fragility, outputs=["out/report.pdf", "out/fragility.csv"])
    lines = text.splitlines()
    assert "model winkler" in lines[0] and "10 records" in lines[0] and "PGA in g" in lines[0]
    header = lines[1].split()
    assert header[:5] == ["block", "soil", "median", "PGA", "[g]"] and "P(50" in lines[1]
    clay, rock = lines[2].split(), lines[3].split()
    assert clay[:5] == ["cabinet", "clay", "0.5", "0.4-0.625", "0.4"] and clay[5] == "0.01"
    assert rock[:4] == ["cabinet", "rock", ">", "2"] and "no record overturned" in lines[3]
    assert "my_site.csv" in text and "example" not in text
    assert lines[-1] == "Results: out/report.pdf, out/fragility.csv"


def test_without_a_hazard_curve_there_is_no_probability_column():
    text = answer_table(_fragility(probability=(np.nan, np.nan), hazard="none"))
    assert "P(" not in text and "hazard" not in text


def test_the_shipped_example_hazard_is_labelled_as_such():
    text = answer_table(_fragility(hazard="pipeline/hazard_example.csv (example, not site-specific)"))
    assert "P(50 yr, example hazard)" in text and "set your site's as [hazard] file" in text


@pytest.mark.parametrize("units, factor", [("g", 1.0), ("m s-2", 1 / STANDARD_GRAVITY), ("m/s^2", 1 / STANDARD_GRAVITY),
                                           ("9.80665 m s-2", 1.0)])
def test_accelerations_are_shown_in_g_whatever_the_file_states(units, factor):
    assert display_scale(units) == (pytest.approx(factor), "g")
    fragility = _fragility(units=units)
    fragility["median"] = fragility["median"] / factor if factor != 1.0 else fragility["median"]
    row = answer_rows(fragility)[0]
    assert row["median"] == pytest.approx(0.5)


def test_other_measures_keep_their_unit():
    assert display_scale("m/s") == (1.0, "m/s")
    assert display_scale("") == (1.0, "-")


# ---------------------------------------------------------------- the command, end to end on a tiny study

@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("answer")
    study = folder / "study.toml"
    study.write_text(TINY)
    return study, folder / "out"


def _run(study, output, capsys, monkeypatch, *flags):
    calls = []
    monkeypatch.setattr(applicability_module, "applicability_stage",
                        lambda *args, **kwargs: calls.append(kwargs) or xr.Dataset())
    status = main(["fragility", str(study), "--output", str(output), "--no-progress", "--serial", *flags])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    return captured, calls


def _planned_not_rendered(planned: list, workers_seen: list):
    """Stands in for ``report_stage``: plans the report from what the run hands it (every text page's HTML) and
    builds every figure page's figure, without rendering report.pdf and the PNGs (the small pipeline's run and the
    README's example render theirs, about 10 s of CPU here). The planned pages are appended to ``planned``, the
    ``workers`` it was given to ``workers_seen``."""
    import matplotlib.pyplot as plt

    from rockfrag.report import build_plan, report_results

    def stage(config, cube, ida, fragility, risk, output, runtime_s=float("nan"), applicability=None,
              progress=True, workers=None, run=None):
        workers_seen.append(workers)
        pages = build_plan(report_results(config, cube, ida, fragility, risk, output, runtime_s, applicability, run))
        for page in pages:
            plt.close(page.draw())
        planned.extend(pages)
        return Path(output) / "report.pdf", []

    return stage


def test_fragility_ends_with_the_answer_and_skips_the_sweep_of_a_study_file(tiny_run, capsys, monkeypatch):
    """On a study with one soil, whose by-model page is laid out on a grid (drawing it once crashed)."""
    study, output = tiny_run
    planned, workers = [], []
    monkeypatch.setattr("rockfrag.report.report_stage", _planned_not_rendered(planned, workers))
    captured, calls = _run(study, output, capsys, monkeypatch)
    assert not calls and "good enough; minutes) was not run" in captured.err and "--applicability" in captured.err
    assert workers == [1]  # --serial: the report's figures are drawn in this process too, no forked worker
    answer = captured.out[captured.out.index("Overturning, model recommended"):].splitlines()
    table = pd.read_csv(output / "fragility.csv")
    row = table[(table.model == "recommended") & (table.damage_state == "overturning") & (table.soil == "sand")]
    cells = answer[2].split()
    assert cells[:2] == ["cabinet", "sand"]
    if row.status.iloc[0] in ("fitted", "extrapolated", "separated"):  # a number, as fragility.csv has it
        assert cells[2] == f"{row['median'].iloc[0]:.3g}"
    results_line = f"Results: {output / 'report.pdf'}, {output / 'fragility.csv'}, {output / 'fragility.nc'}"
    assert results_line in answer  # the answer table ends with it; the verdict per asset and soil follows
    verdicts = answer[answer.index(results_line) + 1:]
    assert verdicts[0] == "" and verdicts[1].startswith("Verdict per asset and soil")
    assert any(line.split()[:2] == ["cabinet", "sand"] for line in verdicts)
    assert any(page.name.startswith("fragility-models") for page in planned)
    html = "".join(page.html for page in planned if page.html is not None)
    read_from = html.split("result files read")[1].split("</tr>")[0]  # the provenance table's row
    assert "fragility.nc" in read_from and "applicability.nc" not in read_from  # the sweep did not run


def test_quiet_hides_the_answer_and_the_flag_runs_the_sweep(tiny_run, capsys, monkeypatch):
    study, output = tiny_run
    # the flags are what is tested here: the report (planned by the test above) is not made again
    monkeypatch.setattr("rockfrag.report.report_stage", lambda *args, **kwargs: (output / "report.pdf", []))
    captured, calls = _run(study, output, capsys, monkeypatch, "--quiet", "--applicability")
    assert len(calls) == 1 and "Overturning" not in captured.out and "was not run" not in captured.err


# ---------------------------------------------------------------- the shipped examples

def test_the_example_study_is_one_user_block_two_soils_ten_records():
    study = load_study(ROOT / "studies" / "example.toml")
    assert [b.name for b in study.blocks] == ["cabinet"] and len(study.soils) == 2
    assert len(study.record_sets) == 10 and "recommended" in study.models  # the recommended model and its sample
    assert str(study.output) == "reports-example"


def test_the_sample_reference_belongs_to_its_record():
    reference = load_reference(ROOT / "studies" / "calibration-reference.csv")
    assert (reference.time_unit, reference.angle_unit) == ("s", "rad")
    records, _ = load_records(["DUZCE/BOL090"])
    record = records[0]
    check_reference(reference.time, reference.rotation, (len(record.acceleration) - 1) * record.dt, record.dt)
    assert 0.005 < np.max(np.abs(reference.rotation)) < 0.1  # it rocks, far from overturning
