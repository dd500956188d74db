"""Per-block intensity levels: multiples of each block's uplift intensity, the cube's coordinates."""

from __future__ import annotations

import numpy as np
import pytest

from rockfrag.config import load_study
from rockfrag.cube import OUTCOME_NO_UPLIFT
from rockfrag.errors import ConfigError
from rockfrag.models import simulate
from rockfrag.processing import process_record
from rockfrag.records import load_records
from rockfrag.study import run_study, uplift_intensity
from rockfrag.units import STANDARD_GRAVITY as G

RELATIVE = """
soils = ["rock"]
models = ["housner"]
[study]
name = "levels"
record_sets = ["bolu"]
[intensity]
levels = { values = [0.9, 1.5, 3.0, 6.0], relative_to = "uplift" }
capacity_resolution = 0.02
component = "single"  # each component its own PGA: Housner lifts at exactly g tan(alpha) of it
[solver]
friction = "none"  # Housner's rigid-base uplift threshold: the squat skid would slide on rock (mu_s 0.7 < b/h 0.75)
"""


@pytest.fixture(scope="module")
def relative_cube(tmp_path_factory):
    folder = tmp_path_factory.mktemp("levels")
    (folder / "study.toml").write_text(RELATIVE)
    config = load_study(folder / "study.toml")
    cube, stats = run_study(config, output=folder / "out", workers=1, progress=False, log=lambda m: None)
    return config, cube, stats


def test_levels_are_multiples_of_each_blocks_uplift_acceleration(relative_cube):
    config, cube, _ = relative_cube
    assert cube.im_level.attrs["units"] == "1" and list(cube.im_level.values) == [0.9, 1.5, 3.0, 6.0]
    assert cube.intensity.dims == ("block", "im_level") and cube.intensity.attrs["units"] == "9.80665 m s-2"
    for block in config.blocks:
        tan_alpha = np.tan(block.alpha)
        np.testing.assert_allclose(cube.intensity.sel(block=block.name).values,
                                   tan_alpha * np.array([0.9, 1.5, 3.0, 6.0]), rtol=1e-12)
    assert cube.scale_factor.dims == ("record", "im_level", "block")
    # scaled record PGA = level intensity, per block
    np.testing.assert_allclose((cube.scale_factor * cube.record_im).transpose("block", "im_level", "record"),
                               cube.intensity.broadcast_like(cube.record_im).transpose(
                                   "block", "im_level", "record"), rtol=1e-12)


def test_every_block_stays_put_below_uplift_and_rocks_above(relative_cube):
    """Housner under PGA scaling: no uplift at 0.9 g tan(alpha), uplift at 1.5 g tan(alpha), for
    three blocks whose thresholds differ by a factor 3.75: only per-block levels put both sides of
    every threshold in one study."""
    _, cube, _ = relative_cube
    outcome = cube.outcome.sel(model="housner")
    assert (outcome.sel(im_level=0.9) == OUTCOME_NO_UPLIFT).all()
    assert (outcome.sel(im_level=1.5) > OUTCOME_NO_UPLIFT).all()


def test_adaptive_capacities_bracket_overturning_by_direct_runs(relative_cube):
    config, cube, stats = relative_cube
    loaded, _ = load_records(["DUZCE/BOL090"])
    record = process_record(loaded[0])
    block = next(b for b in config.blocks if b.name == "slender-cabinet")
    cell = cube.sel(record=record.id, block=block.name, model="housner").isel(soil=0)
    lower, upper = float(cell.capacity_scale_lower), float(cell.capacity_scale_upper)
    assert upper - lower <= 0.02 * upper
    assert not simulate("housner", lower * record.acceleration, record.dt, block).overturned
    assert simulate("housner", upper * record.acceleration, record.dt, block).overturned
    assert stats["uniform_runs"] > stats["grid_runs"] + stats["capacity_runs"]
    assert cube.attrs["runs_saved_fraction"] == pytest.approx(stats["runs_saved_fraction"])


def test_absolute_levels_give_every_block_the_same_intensities(tmp_path):
    study = tmp_path / "abs.toml"
    study.write_text(RELATIVE.replace('{ values = [0.9, 1.5, 3.0, 6.0], relative_to = "uplift" }', "[0.1, 0.2]")
                     .replace("capacity_resolution = 0.02", "capacity_resolution = 0.0")
                     .replace('record_sets = ["bolu"]', 'record_sets = ["DUZCE/BOL090"]'))
    config = load_study(study)
    cube, _ = run_study(config, output=tmp_path / "out", workers=1, progress=False, log=lambda m: None)
    assert cube.im_level.attrs["units"] == "9.80665 m s-2" and "capacity_scale_factor" not in cube
    np.testing.assert_allclose(cube.intensity.values, [[0.1, 0.2]] * len(config.blocks))
    assert cube.record_pga.attrs["units"] == cube.intensity.attrs["units"]  # one unit for every acceleration


def test_uplift_intensity_of_other_measures_is_the_record_median_at_uplift_pga():
    config = load_study(overrides={"intensity": {"measure": "pgv", "levels": {
        "start": 0.5, "stop": 5.0, "count": 3, "relative_to": "uplift"}}})
    record_pga = np.array([2.0, 4.0, 5.0])
    record_pgv = np.array([0.2, 0.2, 1.0])  # PGV/PGA = 0.1, 0.05, 0.2 -> median 0.1 s
    record_im = np.repeat(record_pgv[:, None], len(config.blocks), axis=1)
    expected = [0.1 * G * np.tan(b.alpha) for b in config.blocks]
    np.testing.assert_allclose(uplift_intensity(config, record_im, record_pga), expected, rtol=1e-12)


@pytest.mark.parametrize("levels, field", [
    ('{ start = 0.5, stop = 5.0, count = 4, relative_to = "pga" }', "intensity.levels.relative_to"),
    ('{ start = 0.5, stop = 5.0, count = 4, relative = "uplift" }', "intensity.levels.relative"),
])
def test_bad_relative_levels_name_the_field(tmp_path, levels, field):
    study = tmp_path / "bad.toml"
    study.write_text(f"[intensity]\nlevels = {levels}\n")
    with pytest.raises(ConfigError) as caught:
        load_study(study)
    assert caught.value.field == field and str(study) in str(caught.value)


def test_capacity_resolution_out_of_range_names_the_field(tmp_path):
    study = tmp_path / "bad.toml"
    study.write_text("[intensity]\ncapacity_resolution = 0.9\n")
    with pytest.raises(ConfigError) as caught:
        load_study(study)
    assert caught.value.field == "intensity.capacity_resolution"


def test_default_study_levels_span_uplift_to_far_above_it():
    """The default levels run from half to 50 x each block's uplift PGA (the paper block overturns
    at 15-25 x; README, IDA section, has the fraction overturned at the top per block)."""
    config = load_study()
    assert config.relative_levels and config.levels[0] < 1.0 and config.levels[-1] >= 40.0
