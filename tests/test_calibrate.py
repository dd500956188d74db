"""Calibration (paper eq. 17): recover known k and xi; a Housner reference needs a stiff k."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest

from pipeline.blocks import PAPER_BLOCK, Block
from pipeline.calibrate import calibrate, correlation, load_reference
from pipeline.cli import main
from pipeline.errors import PipelineError
from pipeline.models import simulate
from pipeline.processing import process_record
from pipeline.records import load_records


@pytest.fixture(scope="module")
def bolu():
    records, _ = load_records("DUZCE/BOL090")
    record = process_record(records[0])
    return record.acceleration[:3000], record.dt  # first 30 s


def test_correlation_is_pearson():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=200), rng.normal(size=200)
    assert correlation(a, b) == pytest.approx(np.corrcoef(a, b)[0, 1], rel=1e-12)
    assert correlation(a, 3 * a + 1) == pytest.approx(1.0)


@pytest.mark.slow
def test_recovers_known_stiffness_and_damping_from_noisy_reference(bolu):
    ag, dt = bolu
    ag = ag * 1.5
    k_true, xi_true = 3.95e8, 0.03
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reference = simulate("ssi", ag, dt, PAPER_BLOCK, k=k_true, xi=xi_true, t_end=35.0)
    rng = np.random.default_rng(2026)
    ref_time = np.arange(0.0, 35.0, 0.005)  # a finer, different time base, as an FE model would give
    ref_rotation = np.interp(ref_time, reference.t, reference.theta)
    ref_rotation += rng.normal(0, 0.03 * np.max(np.abs(ref_rotation)), ref_time.size)
    result = calibrate(ref_time, ref_rotation, ag, dt, PAPER_BLOCK, k_range=(1e8, 9e8), xi_range=(0.01, 0.07),
                       n_k=25, n_xi=7, soil_shear_modulus=80e6)  # the default grid
    assert result.k == pytest.approx(k_true, rel=0.05)
    assert result.xi == pytest.approx(xi_true, abs=0.011)
    assert result.correlation > 0.95 and result.correlation >= result.correlation_grid - 1e-12
    assert abs(result.peak_error) < 0.1
    # eq. 19 solved for A/H
    assert result.area_over_depth == pytest.approx(result.k * (1 / 80e6 + 1 / PAPER_BLOCK.E_b))


@pytest.mark.slow
def test_housner_reference_is_fitted_with_a_very_stiff_foundation(bolu):
    ag, dt = bolu
    block = Block(name="small", R=2.0, alpha=0.25, mass=5000.0)
    reference = simulate("housner", ag * 0.8, dt, block, restitution=block.housner_restitution(), t_end=35.0)
    result = calibrate(reference.t, reference.theta, ag * 0.8, dt, block, k_range=(1e6, 1e11), n_k=11,
                       xi_range=(0.05, 0.05), n_xi=1, local=False)
    omega_over_p = np.sqrt(result.k / block.mass) / block.p()
    assert omega_over_p > 100  # the best match is a practically rigid base
    assert result.correlation > 0.97


def test_reference_units_from_headers_and_flags(tmp_path):
    path = tmp_path / "ref.csv"
    pd.DataFrame({"time [ms]": np.arange(20) * 10.0, "theta [deg]": np.linspace(0, 1, 20)}).to_csv(path, index=False)
    time, rotation = load_reference(path)
    assert time[1] == pytest.approx(0.01) and rotation[-1] == pytest.approx(np.pi / 180)
    time, rotation = load_reference(path, time_unit="s", angle_unit="rad")
    assert time[1] == pytest.approx(10.0)
    bad = tmp_path / "bad.csv"
    bad.write_text("t,theta\n0,0\n")
    with pytest.raises(PipelineError, match="at least 10 rows"):
        load_reference(bad)


@pytest.mark.slow
def test_cli_calibrate_writes_summary_and_figures(tmp_path, bolu):
    ag, dt = bolu
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full, _ = load_records("DUZCE/BOL090")
        record = process_record(full[0])
        reference = simulate("ssi", record.acceleration * 1.5, dt, PAPER_BLOCK, k=3e8, xi=0.05, t_end=40.0)
    path = tmp_path / "ref.csv"
    pd.DataFrame({"time_s": reference.t, "rotation_rad": reference.theta}).to_csv(path, index=False)
    status = main(["calibrate", str(path), "--record", "DUZCE/BOL090", "--scale", "1.5", "--soil", "sand",
                   "--n-k", "5", "--n-xi", "3", "--grid-only", "--output", str(tmp_path / "out")])
    assert status == 0
    for name in ("calibration.json", "calibration.csv", "calibration-fit.png", "calibration-surface.png"):
        assert (tmp_path / "out" / name).stat().st_size > 0
