"""Study engine: configuration errors, the cube's schema and values, executors, resume."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import tomllib
import warnings

import numpy as np
import pytest
import xarray as xr

from rockfrag.config import load_study, study_from_dict
from rockfrag.errors import ConfigError
from rockfrag.measures import MEASURES, spectral_acceleration
from rockfrag.models import simulate
from rockfrag.models.variants import sample_models
from rockfrag.processing import process_record
from rockfrag.records import load_records
from rockfrag.soils import SOILS, soil_block_stiffness
from rockfrag.study import run_study
from tests.helpers import SMALL_STUDY

SMALL = SMALL_STUDY  # tests/helpers.py: the same study runs the session pipeline (conftest small_pipeline)


@pytest.fixture(scope="module")
def small_study(tmp_path_factory):
    path = tmp_path_factory.mktemp("study") / "small.toml"
    path.write_text(SMALL)
    return path


@pytest.fixture(scope="module")
def small_cube(small_study, tmp_path_factory):
    output = tmp_path_factory.mktemp("serial")
    dataset, stats = run_study(load_study(small_study), output=output, workers=1, progress=False, log=lambda m: None)
    return output, dataset, stats


@pytest.mark.parametrize("text, field", [
    ('[intensity]\nmeasure = "arias"\n', "intensity.measure"),
    ('[intensity]\nlevels = { start = 1.0, stop = 0.5, count = 4 }\n', "intensity.levels"),
    ('[intensity]\nlevels = [0.1, 0.05]\n', "intensity.levels"),
    ('[intensity]\nperiod = -1.0\n', "intensity.period"),
    ('soils = ["mud"]\n', "soils"),
    ('models = ["newmark"]\n', "models"),
    ('[solver]\nswitch = "sticky"\n', "solver.switch"),
    ('[solver]\noverturn_angle = 2.0\n', "solver.overturn_angle"),
    ('[blocks.bad]\nb = -1.0\nh = 2.0\n', "blocks.bad.b"),
    ('[blocks.bad]\nb = 1.0\nh = 2.0\nR = 3.0\nalpha = 0.3\n', "blocks.bad"),
    ('[blocks.bad]\nb = 1.0\nh = 2.0\ncolour = "red"\n', "blocks.bad.colour"),
    ('[intensity]\nlevels = [0.1]\nsoils = ["sand"]\n', "intensity.soils"),
])
def test_invalid_study_names_field_and_file(tmp_path, text, field):
    path = tmp_path / "study.toml"
    path.write_text(text)
    with pytest.raises(ConfigError) as caught:
        load_study(path)
    assert caught.value.field == field, str(caught.value)
    assert str(path) in str(caught.value)


def test_default_study_matches_the_issue():
    config = load_study()
    assert len(config.levels) == 14 and config.measure == "pga" and config.component == "rotd50"
    # the grid runs from half the uplift intensity up to the credible cap, 3 g PGA (re-spaced per block)
    assert config.level_range == (0.5, 100.0, 14, "log") and config.credible_max == 3.0
    assert config.credible_measure == "pga" and not config.beyond_credible
    assert config.friction == "recommended"  # the recommended (bed) model's sliding is always computed
    assert [s.name for s in config.soils] == ["clay", "sand", "gravel", "rock", "steel"]
    assert config.models == ("housner", "ssi", *sample_models())  # the recommended model and its sample
    assert config.restitution == "recommended" and len(config.blocks) == 3
    paper = config.blocks[0]
    assert paper.R == 9.39 and paper.alpha == 0.44
    # levels are multiples of each block's uplift intensity: from below uplift to far above it
    assert config.relative_levels and config.levels[0] < 1.0 < 10.0 < config.levels[-1]


def test_cube_schema_is_cf_labelled(small_cube):
    output, _, _ = small_cube
    cube = xr.open_dataset(output / "cube.nc")
    assert cube.attrs["Conventions"] == "CF-1.12"
    for key in ("rockfrag_version", "study_config", "config_hash", "record_checksums", "processing"):
        assert cube.attrs[key]
    sizes = {dim: size for dim, size in cube.sizes.items() if dim != "step_level"}  # the steps' runs (rockfrag.steps)
    assert sizes == {"record": 2, "im_level": 4, "soil": 2, "block": 3, "model": 2}
    for name, variable in cube.data_vars.items():
        assert "units" in variable.attrs and "long_name" in variable.attrs, name
    assert cube.outcome.attrs["flag_meanings"].split() == ["no_uplift", "rocking", "overturned", "solver_failed",
                                                            "free_flight"]
    assert cube.im_level.attrs["units"] == "9.80665 m s-2"  # g, as UDUNITS reads it (not grams)


def test_cube_values_match_direct_solver_calls(small_cube):
    _, cube, _ = small_cube
    config = load_study(None, {"study": {"record_sets": ["bolu"]}})
    records, _ = load_records("bolu")
    record, partner = process_record(records[1]), process_record(records[0])
    # Bolu's two components are one pair: scaled together to a RotD50 PGA of 0.6 g
    scale = 0.6 * 9.80665 / MEASURES["pga"].rotd(record.acceleration, partner.acceleration, record.dt)
    cell = cube.sel(record="DUZCE/BOL090", im_level=0.6, block="slender-cabinet")
    assert cell.scale_factor.item() == pytest.approx(scale, rel=1e-12)
    scale = cell.scale_factor.item()  # the study's own float, for bit-equal runs
    block = cube.block.values.tolist().index("slender-cabinet")
    blocks = study_from_dict(tomllib.loads(SMALL)).blocks
    t_end = (record.acceleration.size - 1) * record.dt + 10.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        housner = simulate("housner", record.acceleration * scale, record.dt, blocks[block], t_end=t_end)
        soil = config.soils[3]  # rock
        ssi = simulate("ssi", record.acceleration * scale, record.dt, blocks[block],
                       k=soil_block_stiffness(soil, blocks[block]), xi=soil.damping_ratio, t_end=t_end)
    # Housner does not depend on the soil: the same value on every soil
    np.testing.assert_array_equal(cell.peak_angle.sel(model="housner").values, housner.peak_angle)
    assert cell.peak_angle.sel(model="ssi", soil="rock").item() == pytest.approx(ssi.peak_angle, rel=1e-12)
    assert cell.n_impacts.sel(model="ssi", soil="rock").item() == ssi.n_impacts
    assert cell.peak_angle_ratio.sel(model="housner", soil="sand").item() == pytest.approx(
        housner.peak_angle / blocks[block].alpha)
    assert np.isnan(cell.peak_settlement.sel(model="housner")).all()


def test_outcomes_are_ordered_with_intensity(small_cube):
    """Below g tan(alpha) nothing uplifts; the lowest level is below every block's threshold."""
    _, cube, _ = small_cube
    lowest = cube.outcome.isel(im_level=0)
    assert (lowest == 0).all()
    uplift_g = cube.block_uplift_acceleration  # [g]
    housner = cube.sel(model="housner")
    below = housner.outcome.where(cube.im_level < uplift_g)
    assert ((below == 0) | below.isnull()).all()


@pytest.mark.slow
def test_dask_local_cluster_gives_the_identical_cube(small_study, small_cube, tmp_path):
    _, serial, _ = small_cube
    distributed, stats = run_study(load_study(small_study), output=tmp_path, dask_workers=2, progress=False,
                                   log=lambda m: None)
    assert stats["runs_computed"] > 0
    xr.testing.assert_identical(serial.drop_attrs(), distributed.drop_attrs())


def test_resume_reuses_checkpoints_and_changed_soil_touches_only_its_cells(small_study, small_cube, tmp_path):
    output, cube, stats = small_cube
    assert stats["cells_reused"] == 0
    again, stats_again = run_study(load_study(small_study), output=output, workers=1, progress=False,
                                   log=lambda m: None)
    assert stats_again["runs_computed"] == 0 and stats_again["cells_reused"] == stats["cells"]
    xr.testing.assert_identical(cube, again)
    rock = SOILS["rock"]  # the same friction: the skid's sliding Housner cell on rock depends on nothing else
    friction = {"friction_static": rock.friction_static, "friction_kinetic": rock.friction_kinetic}
    changed = load_study(small_study, {"soils_custom": {"rock": {"shear_modulus": 2e9, **friction}}})
    _, stats_changed = run_study(changed, output=output, workers=1, progress=False, log=lambda m: None)
    # one soil x 3 blocks x 2 records of SSI cells; Housner cells and the other soil are reused
    assert stats_changed["runs_computed"] == 3 * 2 * 4


@pytest.mark.slow
def test_killed_run_resumes_without_recomputing(small_study, tmp_path):
    """kill -9 during a run, run again: finished cells are not recomputed, the cube is identical."""
    study = tmp_path / "study.toml"
    ten = ["NORTHR/MUL009", "NORTHR/MUL279", "DUZCE/BOL000", "DUZCE/BOL090", "KOBE/NIS000", "KOBE/NIS090",
           "LANDERS/YER270", "LANDERS/YER360", "CAPEMEND/RIO270", "CAPEMEND/RIO360"]  # 90 cells: killed at 20
    study.write_text(SMALL.replace('record_sets = ["bolu"]', f"record_sets = {ten}".replace("'", '"'))
                     .replace("levels = [0.1, 0.3, 0.6, 1.0]",  # one checkpoint file per cell
                              "levels = [0.6]\ncapacity_resolution = 0.0"))
    output = tmp_path / "out"
    command = [sys.executable, "-m", "rockfrag", "run", str(study), "--output", str(output), "--no-progress",
               "--serial"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    checkpoints = output / ".checkpoints"
    deadline = time.time() + 120
    while time.time() < deadline and len(list(checkpoints.glob("*.ckpt"))) < 20:
        time.sleep(0.05)
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    finished = {p: p.stat().st_mtime_ns for p in checkpoints.glob("*.ckpt")}
    assert finished and not (output / "cube.nc").exists()
    result = subprocess.run(command, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert f"{len(finished)} of" in result.stdout or f"{len(finished)} of" in result.stderr
    for path, mtime in finished.items():
        assert path.stat().st_mtime_ns == mtime, "a finished cell was recomputed"
    assert not list(output.glob(".*.part")) and not list(checkpoints.glob(".*.part"))
    fresh, _ = run_study(load_study(study), output=tmp_path / "fresh", workers=1, progress=False,
                         log=lambda message: None, warn=lambda message: None)  # the same study, never killed
    xr.testing.assert_identical(xr.open_dataset(output / "cube.nc").drop_attrs(), fresh.drop_attrs())


def test_sa_scaling_reaches_the_requested_spectral_acceleration(tmp_path):
    study = tmp_path / "sa.toml"
    study.write_text(SMALL.replace("[intensity]", '[intensity]\nmeasure = "sa"\nperiod = 0.5')
                     .replace('models = ["housner", "ssi"]', 'models = ["housner"]'))
    config = load_study(study)
    cube, _ = run_study(config, output=tmp_path / "out", workers=1, progress=False, log=lambda m: None)
    first, second = (process_record(record) for record in load_records("bolu")[0])
    assert cube.attrs["intensity_component"] == "RotD50"
    assert list(cube.record_partner.values) == [second.id, first.id]
    scales = cube.scale_factor.isel(block=0).values  # absolute levels: any block
    np.testing.assert_array_equal(scales[0], scales[1])  # one factor for both components of the pair
    for level, scale in zip(cube.im_level.values * 9.80665, scales[0]):
        # Sa is linear in the scale factor: the scaled pair has exactly the requested RotD50 Sa(0.5 s)...
        rotd50 = MEASURES["sa"].rotd(first.acceleration * scale, second.acceleration * scale, first.dt,
                                     period=0.5)
        assert rotd50 == pytest.approx(level, rel=1e-9)
        # ...checked by rotating the ground motion itself (not the responses) at the median angles
        peaks = [spectral_acceleration(np.cos(np.radians(t)) * first.acceleration * scale
                                       + np.sin(np.radians(t)) * second.acceleration * scale, first.dt, 0.5)
                 for t in range(180)]
        assert np.median(peaks) == pytest.approx(level, rel=1e-9)
    own = cube.record_component_im.isel(block=0).values
    assert not np.allclose(own, cube.record_im.isel(block=0).values)  # each component's own Sa differs
    assert cube.im_level.attrs["units"] == "9.80665 m s-2" and "Sa(0.5 s" in cube.im_level.attrs["long_name"]
