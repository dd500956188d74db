"""Calibration (paper eq. 17): the global search recovers off-grid (k, xi) with and without noise,
references are read in the units their headers state (or refused with one line), and the CLI writes
its outputs and refuses nonsense with exit code 2."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pandas as pd
import pytest

from rockfrag.blocks import PAPER_BLOCK, Block
from rockfrag.calibrate import calibrate, check_reference, correlation, load_reference
from rockfrag.cli import main
from rockfrag.errors import ConfigError, PipelineError, RecordError
from rockfrag.models import simulate
from rockfrag.processing import process_record
from rockfrag.records import load_records

SEGMENT = slice(800, 2000)  # Bolu 090, 8-20 s: the strong motion, where the paper block rocks many cycles
SCALE = 2.0  # peak angle ~7 % of alpha, 30-90 impacts, no overturning for k in 1e8-9e8 N/m


@pytest.fixture(scope="module")
def bolu():
    records, _ = load_records("DUZCE/BOL090")
    record = process_record(records[0])
    return record.acceleration, record.dt


@pytest.fixture(scope="module")
def strong_segment(bolu):
    ag, dt = bolu
    return ag[SEGMENT] * SCALE, dt


def model_reference(model, ag, dt, k, xi, noise=0.0, seed=2026):
    """A reference made by the model: resampled onto a finer, different time base (as an FE model would
    give) plus Gaussian noise of ``noise`` times the peak |rotation|."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = simulate(model, ag, dt, PAPER_BLOCK, k=k, xi=xi, t_end=(ag.size - 1) * dt)
    ref_time = np.arange(0.0, result.t[-1], 0.005)
    ref_rotation = np.interp(ref_time, result.t, result.theta)
    rng = np.random.default_rng(seed)
    return ref_time, ref_rotation + rng.normal(0.0, noise * np.max(np.abs(ref_rotation)), ref_time.size)


def test_correlation_is_pearson():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=200), rng.normal(size=200)
    assert correlation(a, b) == pytest.approx(np.corrcoef(a, b)[0, 1], rel=1e-12)
    assert correlation(a, 3 * a + 1) == pytest.approx(1.0)


@pytest.mark.slow
@pytest.mark.parametrize("k_true, xi_true, noise", [
    (4.6e8, 0.027, 0.0),  # the case: between grid points 4.33e8 and 4.74e8, and 0.02 and 0.03
    (4.6e8, 0.027, 0.05),
    (1.27e8, 0.0193, 0.05),  # a soft foundation, light damping
])
def test_recovers_off_grid_stiffness_and_damping(strong_segment, k_true, xi_true, noise):
    ag, dt = strong_segment
    ref_time, ref_rotation = model_reference("ssi", ag, dt, k_true, xi_true, noise)
    # default grid; the search alone (its intervals are tested in tests/test_calibrate_intervals.py)
    result = calibrate(ref_time, ref_rotation, ag, dt, PAPER_BLOCK, soil_shear_modulus=80e6, confidence=None)
    grid_k = np.geomspace(1e8, 9e8, 25)
    assert np.min(np.abs(grid_k / k_true - 1)) > 0.03  # the truth is not a grid point
    assert result.k == pytest.approx(k_true, rel=0.03)
    assert result.xi == pytest.approx(xi_true, abs=0.005)
    # the refinement moves: strictly better than the best grid point, and off it
    assert result.correlation > result.correlation_grid + 1e-3
    assert (result.k, result.xi) != (result.k_grid, result.xi_grid)
    assert result.correlation > (0.99 if noise == 0 else 0.95)
    assert abs(result.peak_error) < 0.1
    assert result.area_over_depth == pytest.approx(result.k * (1 / 80e6 + 1 / PAPER_BLOCK.E_b))  # eq. 19


@pytest.mark.slow
@pytest.mark.parametrize("model", ["ssi-paper", "winkler"])
def test_calibrates_any_model_with_a_foundation(strong_segment, model):
    ag, dt = strong_segment
    ref_time, ref_rotation = model_reference(model, ag, dt, 3.1e8, 0.035)
    result = calibrate(ref_time, ref_rotation, ag, dt, PAPER_BLOCK, model=model, confidence=None)  # the search
    assert result.model == model
    assert result.k == pytest.approx(3.1e8, rel=0.03) and result.xi == pytest.approx(0.035, abs=0.005)
    with pytest.raises(ConfigError, match="housner.*no foundation"):
        calibrate(ref_time, ref_rotation, ag, dt, PAPER_BLOCK, model="housner")


def test_solver_keywords_reach_the_model(strong_segment):
    ag, dt = strong_segment
    ref_time, ref_rotation = model_reference("winkler", ag[:600], dt, 3.1e8, 0.035)
    beds = [calibrate(ref_time, ref_rotation, ag[:600], dt, PAPER_BLOCK, model="winkler", bed=bed, n_k=3, n_xi=2,
                      local=False).surface for bed in ("continuous", "two-spring")]
    assert beds[0] != beds[1]
    with pytest.raises(PipelineError, match="bed"):
        calibrate(ref_time, ref_rotation, ag[:600], dt, PAPER_BLOCK, model="winkler", bed="sponge", n_k=2, n_xi=2,
                  local=False)


@pytest.mark.slow
def test_housner_reference_is_fitted_with_a_very_stiff_foundation(bolu):
    ag, dt = bolu
    ag = ag[:3000]
    block = Block(name="small", R=2.0, alpha=0.25, mass=5000.0)
    reference = simulate("housner", ag * 0.8, dt, block, restitution=block.housner_restitution(), t_end=35.0)
    result = calibrate(reference.t, reference.theta, ag * 0.8, dt, block, k_range=(1e6, 1e11), n_k=11,
                       xi_range=(0.05, 0.05), n_xi=1, local=False)
    omega_over_p = np.sqrt(result.k / block.mass) / block.p()
    assert omega_over_p > 100  # the best match is a practically rigid base
    assert result.correlation > 0.97


def test_bad_search_settings_are_refused(strong_segment):
    ag, dt = strong_segment
    ref_time, ref_rotation = np.arange(0, 10, 0.01), np.sin(np.arange(0, 10, 0.01))
    for settings, field in (({"n_k": 0}, "n_k"), ({"n_xi": 0}, "n_xi"), ({"k_range": (9e8, 1e8)}, "k_range"),
                            ({"xi_range": (0.05, 0.01)}, "xi_range")):
        with pytest.raises(ConfigError, match=field):
            calibrate(ref_time, ref_rotation, ag, dt, PAPER_BLOCK, **settings)
    with pytest.raises(ConfigError, match="constant"):
        calibrate(ref_time, np.zeros_like(ref_time), ag, dt, PAPER_BLOCK)


# ------------------------------------------------------------------------------------ reading


def write_table(path, header, rows, comment=None):
    lines = ([comment] if comment else []) + [",".join(header)] + [",".join(map(str, row)) for row in rows]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("time_header, time_factor", [
    ("time [s]", 1.0), ("t (sec)", 1.0), ("time_seconds", 1.0), ("time [ms]", 1e-3), ("time_ms", 1e-3),
    ("time [min]", 60.0), ("time [us]", 1e-6), ("time [\u00b5s]", 1e-6), ("time", 1.0)])
@pytest.mark.parametrize("angle_header, angle_factor", [
    ("theta [rad]", 1.0), ("theta [radians]", 1.0), ("rotation_mrad", 1e-3), ("theta [deg]", math.pi / 180),
    ("theta [degrees]", math.pi / 180), ("theta (Degree)", math.pi / 180), ("theta", 1.0)])
def test_reference_units_from_headers(tmp_path, time_header, time_factor, angle_header, angle_factor):
    path = write_table(tmp_path / "ref.csv", [time_header, angle_header], [(i * 2, i * 0.5) for i in range(12)])
    reference = load_reference(path)
    assert reference.time[3] == pytest.approx(6 * time_factor)
    assert reference.rotation[3] == pytest.approx(1.5 * angle_factor)
    described = reference.describe_units()
    assert ("assumed" in described) == (time_header == "time" or angle_header == "theta")


def test_flags_override_headers_and_unknown_units_are_refused(tmp_path):
    path = write_table(tmp_path / "ref.csv", ["time [ms]", "theta [deg]"], [(i * 10, i) for i in range(12)])
    reference = load_reference(path, time_unit="s", angle_unit="mrad")
    assert reference.time[1] == pytest.approx(10.0) and reference.rotation[1] == pytest.approx(1e-3)
    assert "from the command line" in reference.describe_units()
    with pytest.raises(ConfigError, match="time_unit.*'hours'.*allowed"):
        load_reference(path, time_unit="hours")
    bad = write_table(tmp_path / "bad.csv", ["time [fortnights]", "theta"], [(i, i) for i in range(12)])
    with pytest.raises(ConfigError, match=r"bad\.csv: column 'time \[fortnights\]': time unit 'fortnights'"):
        load_reference(bad)


def test_a_text_cell_is_an_error_naming_its_line(tmp_path):
    rows = [(i * 0.01, i * 0.001, 7) for i in range(12)]
    rows[5] = (0.05, "n/a", 7)
    path = write_table(tmp_path / "ref.csv", ["time [s]", "theta [rad]", "other"], rows, comment="# LS-DYNA export")
    with pytest.raises(RecordError, match=r"ref\.csv, line 8: column 'theta \[rad\]': 'n/a' is not a number"):
        load_reference(path)


def test_headerless_table_and_short_or_unordered_tables(tmp_path):
    path = tmp_path / "plain.txt"
    path.write_text("\n".join(f"{i * 0.01} {i * 1e-3}" for i in range(12)) + "\n")
    reference = load_reference(path)
    assert reference.time.size == 12 and reference.rotation[2] == pytest.approx(2e-3)
    with pytest.raises(PipelineError, match="at least 10 rows"):
        load_reference(write_table(tmp_path / "short.csv", ["t", "theta"], [(0, 0)]))
    rows = [(i * 0.01, 0.0) for i in range(12)]
    rows[4] = (0.01, 0.0)
    with pytest.raises(RecordError, match="line 6: time must increase"):
        load_reference(write_table(tmp_path / "order.csv", ["t", "theta"], rows))


def test_reference_numbers_are_read_as_written(tmp_path):
    """Every digit counts (pandas.to_numeric, the reader before, dropped those past the 16th)."""
    cell = "0.00019800515671750674"
    path = write_table(tmp_path / "ref.csv", ["time [s]", "theta [rad]"], [(i * 0.01, cell) for i in range(12)])
    assert load_reference(path).rotation[0] == float(cell)


def test_references_that_cannot_belong_to_the_record_are_refused():
    dt, duration = 0.01, 12.0
    seconds = np.arange(0, 12, 0.005)
    wave = 0.01 * np.sin(seconds)
    check_reference(seconds, wave, duration, dt)  # fine
    with pytest.raises(ConfigError, match=r"ends at 1\.2e\+07 s.*check the unit"):  # microseconds read as s
        check_reference(seconds * 1e6, wave, duration, dt)
    with pytest.raises(ConfigError, match="lasts 1.2e-05 s"):  # seconds read as microseconds
        check_reference(seconds * 1e-6, wave, duration, dt, time_unit="us")
    with pytest.raises(ConfigError, match="constant"):
        check_reference(seconds, np.zeros_like(seconds), duration, dt)
    with pytest.raises(ConfigError, match="exceeds pi"):  # degrees read as radians
        check_reference(seconds, np.degrees(wave) * 100, duration, dt)


# ------------------------------------------------------------------------------------ CLI


@pytest.fixture(scope="module")
def bolu_reference_file(tmp_path_factory, bolu):
    ag, dt = bolu
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reference = simulate("ssi", ag * 1.5, dt, PAPER_BLOCK, k=3e8, xi=0.05, t_end=40.0)
    path = tmp_path_factory.mktemp("calibration") / "ref.csv"
    pd.DataFrame({"time [ms]": reference.t * 1000, "theta [degrees]": np.degrees(reference.theta)}).to_csv(
        path, index=False)
    return path


def test_cli_calibrate_writes_summary_and_figures_and_prints_units(tmp_path, bolu_reference_file, capsys):
    status = main(["calibrate", str(bolu_reference_file), "--record", "DUZCE/BOL090", "--scale", "1.5", "--soil",
                   "sand", "--n-k", "5", "--n-xi", "3", "--grid-only", "--output", str(tmp_path / "out")])
    assert status == 0
    printed = capsys.readouterr().out
    assert "'time [ms]' in ms (from the header)" in printed and "'theta [degrees]' in degrees" in printed
    for name in ("calibration.json", "calibration.csv", "calibration-fit.png", "calibration-surface.png"):
        assert (tmp_path / "out" / name).stat().st_size > 0


@pytest.mark.parametrize("bed_arguments, study_bed, bed", [
    ([], "continuous", "continuous"),                      # the study's [solver] bed
    ([], "two-spring", "two-spring"),
    (["--bed", "two-spring"], "continuous", "two-spring"),  # --bed overrides it
])
def test_cli_calibrates_winkler_on_the_chosen_bed(tmp_path, bolu_reference_file, capsys, bed_arguments, study_bed,
                                                  bed):
    study = tmp_path / "study.toml"
    study.write_text(f'[solver]\nbed = "{study_bed}"\n')
    status = main(["calibrate", str(bolu_reference_file), "--record", "DUZCE/BOL090", "--scale", "1.5",
                   "--model", "winkler", *bed_arguments, "--n-k", "3", "--n-xi", "2", "--grid-only",
                   "--study", str(study), "--output", str(tmp_path / "out")])
    assert status == 0
    assert f"bed           : {bed}" in capsys.readouterr().out
    summary = json.loads((tmp_path / "out" / "calibration.json").read_text())
    assert summary["model"] == "winkler" and summary["bed"] == bed


@pytest.mark.parametrize("problem, arguments, message", [  # --n-k 0: the parser's, tests/test_cli_vocabulary.py
    ("zero", [], "constant"),
    ("microseconds", ["--time-unit", "us"], "lasts"),
    ("model", ["--model", "housner"], "no foundation"),
    ("bed for a model without one", ["--bed", "two-spring"], "model 'ssi' has no bed"),
    ("unknown bed", ["--model", "winkler", "--bed", "sponge"], "--bed 'sponge' unknown; valid: continuous, two-spring"),
])
def test_cli_calibrate_refuses_nonsense_with_one_line(tmp_path, bolu_reference_file, capsys, problem, arguments,
                                                      message):
    reference = bolu_reference_file
    if problem == "zero":
        reference = write_table(tmp_path / "zero.csv", ["time [s]", "theta [rad]"], [(i * 0.01, 0) for i in range(50)])
    status = main(["calibrate", str(reference), "--record", "DUZCE/BOL090", "--output", str(tmp_path), *arguments])
    error = capsys.readouterr().err.strip()
    assert status == 2
    assert message in error and len(error.splitlines()) == 1
