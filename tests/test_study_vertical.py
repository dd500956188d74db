"""Studies with the vertical component (issue 22, item 3): ``[study] vertical = true``.

A small study from the shipped records (the South Napa station CE.68150, whose two horizontals share one
vertical, plus DUZCE/BOL090, which has none): it runs, the cube flags the vertical, the record without one
is skipped with its reason, the runs scale the vertical with the horizontal, the comparison cube holds the
same records without it, and the report plans its pages. A horizontal-only study is unchanged: verticals
are left out of it, and its summaries are bit for bit those of the solver without ``ag_vertical``. Free
flight is censored in the fragility counts and stops the capacity refinement.
"""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

from rockfrag.config import load_study
from rockfrag.cube import COMPARISON_CUBE, OUTCOME_FAILED, OUTCOME_FREE_FLIGHT, OUTCOME_OVERTURNED, OUTCOME_ROCKING
from rockfrag.damage_states import DamageState
from rockfrag.errors import ConfigError
from rockfrag.fragility import exceedance, fragility_dataset
from rockfrag.measures import MEASURES
from rockfrag.models import simulate_batch
from rockfrag.models.base import Outcome
from rockfrag.models.fields import SUMMARY_FIELDS
from rockfrag.processing import load_recipe
from rockfrag.soils import soil_block_stiffness
from rockfrag.study import cell_capacity, cells_for_record, run_study, solver_options, study_records, vertical_key

from .physics.reference import free_flight_time

NAPA = ["SOUTHNAPA/CE.68150.HNN", "SOUTHNAPA/CE.68150.HNE"]
NAPA_Z = "SOUTHNAPA/CE.68150.HNZ"

VERTICAL_STUDY = f"""
soils = ["rock"]
models = ["housner", "winkler"]
blocks = ["slender-cabinet"]
[study]
name = "vertical-small"
record_sets = ["{NAPA[0]}", "{NAPA[1]}", "{NAPA_Z}", "DUZCE/BOL090"]
vertical = true
[intensity]
# 0.8, 2 and 12 times the cabinet's uplift PGA: no uplift, overturning, and free flight of Housner at the top
levels = {{ values = [0.8, 2.0, 12.0], relative_to = "uplift" }}
[solver]
restitution = ""  # the bed at each soil's xi, as the direct solver calls below run it
bed = "continuous"
friction = "none"  # tied, as the direct solver calls below run it (the default slides every winkler cell)
"""

HORIZONTAL_STUDY = """
soils = ["rock"]
models = ["housner", "winkler"]
blocks = ["slender-cabinet"]
[study]
name = "far-field-small"
record_sets = ["bolu"]
[intensity]
levels = { values = [0.8, 2.0, 6.0], relative_to = "uplift" }
[solver]
restitution = ""  # the bed at each soil's xi, as the direct solver calls below run it
bed = "continuous"
friction = "none"  # tied, as the direct solver calls below run it (the default slides every winkler cell)
"""

QUIET = {"workers": 1, "progress": False, "log": lambda message: None}


def _study(tmp_path_factory, name, text):
    path = tmp_path_factory.mktemp(name) / f"{name}.toml"
    path.write_text(text)
    return load_study(path)


@pytest.fixture(scope="module")
def vertical_run(tmp_path_factory):
    config = _study(tmp_path_factory, "vertical", VERTICAL_STUDY)
    output = tmp_path_factory.mktemp("vertical-out")
    warnings = []
    dataset, stats = run_study(config, output=output, warn=warnings.append, **QUIET)
    return config, output, dataset, stats, warnings


@pytest.fixture(scope="module")
def loaded(vertical_run):
    return study_records(vertical_run[0], log=lambda message: None)


def test_the_study_file_takes_vertical_as_a_flag(tmp_path):
    assert load_study().vertical is False
    path = tmp_path / "bad.toml"
    path.write_text('[study]\nvertical = "yes"\n')
    with pytest.raises(ConfigError, match="study.vertical") as error:
        load_study(path)
    assert "true or false" in str(error.value)


def test_a_vertical_study_runs_and_the_cube_flags_the_vertical(vertical_run):
    _, output, cube, _, _ = vertical_run
    assert list(cube.record.values) == NAPA
    assert cube.attrs["vertical"] == "applied" and cube.attrs["vertical_comparison"] == COMPARISON_CUBE
    assert cube.vertical_applied.dtype == np.int8 and cube.vertical_applied.values.tolist() == [1, 1]
    assert cube.vertical_applied.attrs["flag_meanings"] == "horizontal_only with_vertical"
    assert cube.record_vertical.values.tolist() == [NAPA_Z, NAPA_Z]
    assert cube.record_vertical_pga.attrs["units"] == cube.record_pga.attrs["units"] == "9.80665 m s-2"
    on_disk = xr.open_dataset(output / "cube.nc")
    assert on_disk.vertical_applied.values.tolist() == [1, 1] and "time_of_free_flight" in on_disk
    assert on_disk.time_of_free_flight.attrs["units"] == "s"
    outcomes = set(np.unique(cube.outcome.values).tolist())
    assert {int(Outcome.NO_UPLIFT), OUTCOME_OVERTURNED, OUTCOME_FREE_FLIGHT} <= outcomes
    housner = cube.sel(model="housner", soil="rock", block="slender-cabinet")
    flew = housner.outcome.values == OUTCOME_FREE_FLIGHT
    assert np.all(np.isfinite(housner.time_of_free_flight.values[flew]))  # when it flew, for every flight
    assert np.all(flew[:, -1]) and not flew[:, :-1].any()  # only at 12 x uplift


def test_the_vertical_pga_is_the_processed_vertical_s(vertical_run, loaded):
    cube = vertical_run[2]
    g = MEASURES["pga"].display_factor
    assert loaded.records[0].id == NAPA[0] and loaded.verticals[0].id == NAPA_Z
    assert float(cube.record_vertical_pga[0]) == pytest.approx(np.max(np.abs(loaded.verticals[0].acceleration)) / g,
                                                               rel=1e-12)
    ratio = cube.record_vertical_pga.values / cube.record_pga.values
    assert np.all((ratio > 0.5) & (ratio < 0.7))  # CE.68150: V/H of PGA 0.58 and 0.63


def test_a_record_without_a_vertical_is_skipped_with_its_reason(vertical_run):
    _, _, cube, stats, warnings = vertical_run
    assert "DUZCE/BOL090" not in cube.record.values
    [failure] = stats["failures"]
    assert "BOL090.AT2" in failure and "DUZCE/BOL090" in failure and "no vertical component" in failure
    assert "vertical = true" in failure
    assert any("skipped" in w and "DUZCE/BOL090" in w for w in warnings)


def test_each_horizontal_and_its_vertical_share_start_step_and_length(loaded):
    assert [r.id for r in loaded.records] == NAPA and [v.id for v in loaded.verticals] == [NAPA_Z, NAPA_Z]
    for record, vertical in zip(loaded.records, loaded.verticals):
        assert vertical.is_vertical and not record.is_vertical
        assert record.trace.stats.starttime == vertical.trace.stats.starttime
        assert record.dt == vertical.dt and record.trace.stats.npts == vertical.trace.stats.npts
        steps = [line for line in vertical.trace.stats.processing if "rockfrag" in line and "asdf" not in line]
        assert steps == [line for line in record.trace.stats.processing if "rockfrag" in line
                         and "asdf" not in line]  # processed alike


def test_scaling_keeps_the_ratio_of_vertical_to_horizontal(vertical_run, loaded):
    """The vertical is scaled by the record's factor: each run flies first where scale x a_v(t) < -g."""
    config, _, cube, _, _ = vertical_run
    block, soil = config.blocks[0], config.soils[0]
    cases = [(block, soil_block_stiffness(soil, block), soil.damping_ratio)]
    flights = 0
    for r, (record, vertical) in enumerate(zip(loaded.records, loaded.verticals)):
        scales = cube.scale_factor.values[r, :, 0]
        t_end = (record.acceleration.size - 1) * record.dt + config.tail
        for model in config.models:
            runs = simulate_batch(model, record.acceleration, record.dt, scales, cases,
                                  ag_vertical=vertical.acceleration, t_end=t_end, **solver_options(config))[0]
            picked = cube.isel(record=r).sel(model=model, soil=soil.name, block=block.name)
            np.testing.assert_array_equal(picked.outcome.values, runs["status"].astype(np.int8))
            np.testing.assert_array_equal(picked.peak_angle.values, runs["peak_angle"])
            for j, scale in enumerate(scales):
                expected = free_flight_time(scale * vertical.acceleration, record.dt)  # independent of the solver
                if math.isinf(expected):
                    assert math.isnan(float(picked.time_of_free_flight[j]))
                else:
                    flights += 1
                    assert float(picked.time_of_free_flight[j]) == pytest.approx(expected, abs=1e-9)
    assert flights >= 2  # the top level throws the cabinet off the ground under both records


def test_the_comparison_cube_holds_the_same_runs_without_the_vertical(vertical_run, loaded):
    config, output, cube, stats, _ = vertical_run
    comparison = xr.open_dataset(output / COMPARISON_CUBE)
    assert stats["comparison"] == output / COMPARISON_CUBE
    assert comparison.attrs["vertical"] == "not applied" and comparison.vertical_applied.values.tolist() == [0, 0]
    assert comparison.attrs["config_hash"] == cube.attrs["config_hash"]
    assert list(comparison.record.values) == list(cube.record.values)
    np.testing.assert_array_equal(comparison.scale_factor.values, cube.scale_factor.values)
    np.testing.assert_array_equal(comparison.record_pga.values, cube.record_pga.values)
    assert not (comparison.outcome == OUTCOME_FREE_FLIGHT).any()
    assert comparison.time_of_free_flight.isnull().all()
    block, soil = config.blocks[0], config.soils[0]
    record = loaded.records[0]
    scales = comparison.scale_factor.values[0, :, 0]
    t_end = (record.acceleration.size - 1) * record.dt + config.tail
    plain = simulate_batch("winkler", record.acceleration, record.dt, scales,
                           [(block, soil_block_stiffness(soil, block), soil.damping_ratio)], t_end=t_end,
                           **solver_options(config))[0]
    np.testing.assert_array_equal(comparison.peak_angle.sel(model="winkler").values[0, :, 0, 0], plain["peak_angle"])
    assert not np.array_equal(cube.peak_angle.sel(model="winkler").values[0, :, 0, 0], plain["peak_angle"])


def test_checkpoint_keys_say_whether_and_which_vertical_was_applied(vertical_run, loaded):
    config, output, cube, stats, _ = vertical_run
    record, vertical = loaded.records[0], loaded.verticals[0]
    scales = cube.scale_factor.values[0]
    recipe = load_recipe(None)
    keys = {variant: {c.key for c in cells_for_record(record, config, recipe, scales, vertical)}
            for variant, vertical in (("with", vertical_key(record, vertical, True)),
                                      ("without", vertical_key(record, vertical, False)),
                                      ("horizontal study", None))}
    assert len(set.union(*keys.values())) == 3 * len(keys["with"])  # all distinct
    stored = {path.stem for path in (output / ".checkpoints").glob("*.ckpt")}
    assert keys["with"] <= stored and keys["without"] <= stored and not keys["horizontal study"] & stored
    assert vertical_key(record, vertical, True)["component"] == vertical.metadata["sha256"]
    assert vertical_key(record, vertical, False)["component"] is None
    again, second = run_study(config, output=output, **QUIET)
    assert second["runs_computed"] == 0 and second["cells_reused"] == second["cells"] == stats["cells"]
    np.testing.assert_array_equal(again.peak_angle.values, cube.peak_angle.values)


def test_the_report_plans_the_vertical_pages(vertical_run):
    from rockfrag.damage_states import damage_states_from_config
    from rockfrag.ida import ida_dataset
    from rockfrag.report import plan
    from rockfrag.report.sections import Results, limitations_items
    from rockfrag.report.vertical import open_comparison, vertical_effect, vertical_items, vertical_page

    config, output, cube, _, _ = vertical_run
    comparison = open_comparison(cube, output)
    assert comparison is not None and open_comparison(comparison, output) is None  # only beside its own cube
    effect = vertical_effect(cube, comparison, damage_states_from_config(config.raw))
    ida = ida_dataset(cube)
    fragility = fragility_dataset(cube, damage_states_from_config(config.raw), ida=ida, n_bootstrap=0)
    results = Results(config, cube, ida, fragility, output, vertical=effect)
    names = [page.name for page in plan(results)]
    assert "vertical" in names and "vertical-slender-cabinet" in names
    np.testing.assert_array_equal(effect.fits[True]["median"].values, fragility["median"].values)
    text = " ".join(item.text + " ".join(map(str, item.rows)) for item in vertical_items(effect))
    assert "with / without" in text and "slender-cabinet" in text and "free flight" in text.lower()
    limitations = " ".join(item.text for item in limitations_items(results))
    assert "Free flight (vertical component)" in limitations and "runs" in limitations
    figure = vertical_page(effect, "slender-cabinet", "caption")
    try:
        assert len(figure.axes) == 2
    finally:
        plt.close(figure)


def test_a_horizontal_study_leaves_verticals_out(tmp_path):
    study = tmp_path / "h.toml"
    study.write_text(f'[study]\nrecord_sets = ["{NAPA[0]}", "{NAPA_Z}"]\n')
    lines = []
    loaded = study_records(load_study(study), log=lines.append)
    assert [r.id for r in loaded.records] == [NAPA[0]] and loaded.failures == [] and loaded.verticals is None
    assert len(lines) == 1 and "left out" in lines[0] and NAPA_Z in lines[0]


@pytest.fixture(scope="module")
def horizontal_run(tmp_path_factory):
    config = _study(tmp_path_factory, "horizontal", HORIZONTAL_STUDY)
    output = tmp_path_factory.mktemp("horizontal-out")
    dataset, stats = run_study(config, output=output, **QUIET)
    return config, output, dataset, stats


def test_vertical_false_gives_the_far_field_cube_as_before(horizontal_run):
    """Summaries bit for bit those of the solver called without ag_vertical; the keys as before."""
    config, output, cube, _ = horizontal_run
    assert not (output / COMPARISON_CUBE).exists() and cube.attrs["vertical"] == "not applied"
    assert cube.vertical_applied.values.tolist() == [0, 0] and cube.record_vertical_pga.isnull().all()
    assert cube.time_of_free_flight.isnull().all()
    loaded = study_records(config, log=lambda message: None)
    block, soil = config.blocks[0], config.soils[0]
    stored = {path.stem for path in (output / ".checkpoints").glob("*.ckpt")}
    for r, record in enumerate(loaded.records):
        scales = cube.scale_factor.values[r, :, 0]
        t_end = (record.acceleration.size - 1) * record.dt + config.tail
        assert {c.key for c in cells_for_record(record, config, load_recipe(None), cube.scale_factor.values[r])} \
            <= stored  # no vertical entry in the keys: the checkpoints of earlier runs still count
        for model in config.models:
            old = simulate_batch(model, record.acceleration, record.dt, scales,
                                 [(block, soil_block_stiffness(soil, block), soil.damping_ratio)], t_end=t_end,
                                 **solver_options(config))[0]
            picked = cube.isel(record=r).sel(model=model, soil=soil.name, block=block.name)
            np.testing.assert_array_equal(picked.outcome.values, old["status"].astype(np.int8))
            for name, field in (("peak_angle", "peak_angle"), ("time_of_peak", "time_of_peak"),
                                ("n_impacts", "n_impacts"), ("time_of_uplift", "time_of_uplift"),
                                ("peak_uplift", "peak_corner_uplift")):
                np.testing.assert_array_equal(picked[name].values, old[field])
    assert {f.name for f in SUMMARY_FIELDS} >= {"time_of_free_flight"}


# ---------------------------------------------------------------- free flight in the fits and capacities

def _cube(outcomes, ratios):
    """A cube of one soil, block and model: outcomes and peak_angle_ratio over (record, level)."""
    outcomes = np.asarray(outcomes, np.int8)[:, :, None, None, None]
    ratios = np.asarray(ratios, float)[:, :, None, None, None]
    dims = ("record", "im_level", "soil", "block", "model")
    return xr.Dataset({"outcome": (dims, outcomes), "peak_angle_ratio": (dims, ratios)},
                      coords={"im_level": np.arange(outcomes.shape[1]) + 1.0, "soil": ["rock"], "block": ["b"],
                              "model": ["housner"]})


def test_free_flight_is_uplifted_and_censored_for_overturning_and_unreached_angle_states():
    no, rock, over, failed, fly = int(Outcome.NO_UPLIFT), OUTCOME_ROCKING, OUTCOME_OVERTURNED, OUTCOME_FAILED, \
        OUTCOME_FREE_FLIGHT
    cube = _cube([[no, rock, fly, fly],      # flew before overturning
                  [no, over, fly, rock],     # overturned, then flew: overturned from its first overturning on
                  [rock, fly, failed, fly]],  # the angle before the stop already beyond 0.5
                 [[0.0, 0.3, 0.1, 0.7],
                  [0.0, 9.0, 0.2, 0.4],
                  [0.1, 0.6, 0.0, 0.2]])

    def values(state):
        return exceedance(cube, state).values[:, :, 0, 0, 0]

    nan = np.nan
    np.testing.assert_array_equal(values(DamageState("uplift", "uplifted", 1.0, "")),
                                  [[0, 1, 1, 1], [0, 1, 1, 1], [1, 1, nan, 1]])
    np.testing.assert_array_equal(values(DamageState("overturning", "overturned", 1.0, "")),
                                  [[0, 0, nan, nan], [0, 1, 1, 1], [0, nan, nan, nan]])
    np.testing.assert_array_equal(values(DamageState("rocking-0.5", "peak_angle_ratio", 0.5, "")),
                                  [[0, 0, nan, 1], [0, 1, 1, 1], [0, 1, nan, nan]])  # 0.7 before the stop: reached


def test_without_free_flight_exceedance_is_unchanged():
    no, rock, over, failed = int(Outcome.NO_UPLIFT), OUTCOME_ROCKING, OUTCOME_OVERTURNED, OUTCOME_FAILED
    cube = _cube([[no, rock, over, rock], [rock, failed, rock, over]], [[0, 0.3, 9, 0.6], [0.2, 0, 0.7, 9]])
    for state, expected in ((DamageState("u", "uplifted", 1.0, ""), [[0, 1, 1, 1], [1, np.nan, 1, 1]]),
                            (DamageState("o", "overturned", 1.0, ""), [[0, 0, 1, 1], [0, np.nan, 0, 1]]),
                            (DamageState("r", "peak_angle_ratio", 0.5, ""), [[0, 0, 1, 1], [0, np.nan, 1, 1]])):
        np.testing.assert_array_equal(exceedance(cube, state).values[:, :, 0, 0, 0], expected)


def _fake_solver(rule):
    """simulate_batch that answers each single scale with ``rule(scale)`` -> Outcome, and counts its calls."""
    calls = []

    def fake(model, acceleration, dt, scales, cases, **options):
        calls.append(float(scales[0]))
        out = np.zeros((1, 1), dtype=[("status", "f8")])
        out[0, 0]["status"] = float(rule(float(scales[0])))
        return out

    return fake, calls


def _capacity(monkeypatch, stripes, statuses, rule, resolution=0.02):
    fake, calls = _fake_solver(rule)
    monkeypatch.setattr("rockfrag.study.simulate_batch", fake)
    summary = np.zeros(len(stripes), dtype=[("status", "f8")])
    summary["status"] = [float(s) for s in statuses]
    job = ("key", "housner", None, None, None, None)  # (key, model, block, k, xi, friction): tied
    return cell_capacity(np.zeros(3), 0.01, np.asarray(stripes, float), summary, job, {}, 1.0, resolution), calls


def test_capacity_refinement_without_free_flight_is_the_plain_bisection(monkeypatch):
    rock, over = Outcome.ROCKING, Outcome.OVERTURNED
    result, calls = _capacity(monkeypatch, [1.0, 2.0, 4.0], [rock, over, over], lambda s: over if s >= 1.5 else rock)
    assert result[1] < 1.5 <= result[2] and (result[2] - result[1]) <= 0.02 * result[2]
    assert result[3] == len(calls) and all(1.0 < s < 2.0 for s in calls)


def test_capacity_below_the_first_free_flight_stripe_is_refined_as_usual(monkeypatch):
    rock, over, fly = Outcome.ROCKING, Outcome.OVERTURNED, Outcome.FREE_FLIGHT
    result, calls = _capacity(monkeypatch, [1.0, 2.0, 4.0], [rock, over, fly],
                              lambda s: fly if s >= 3.0 else over if s >= 1.5 else rock)
    assert result[1] < 1.5 <= result[2] and result[3] == len(calls) > 0


def test_no_overturning_below_free_flight_is_censored_at_the_last_survival(monkeypatch):
    rock, over, fly = Outcome.ROCKING, Outcome.OVERTURNED, Outcome.FREE_FLIGHT
    result, calls = _capacity(monkeypatch, [1.0, 2.0, 4.0], [rock, fly, over], lambda s: pytest.fail("no run"))
    assert math.isnan(result[0]) and result[1] == 1.0 and math.isnan(result[2]) and result[3] == 0 and not calls
    result, _ = _capacity(monkeypatch, [1.0, 2.0], [fly, fly], lambda s: pytest.fail("no run"))
    assert np.isnan(result[:3]).all() and result[3] == 0


def test_a_refining_run_in_free_flight_stops_with_the_bracket_so_far(monkeypatch):
    rock, over, fly = Outcome.ROCKING, Outcome.OVERTURNED, Outcome.FREE_FLIGHT
    # bisection of (1, 4): 2.5 survives, 3.25 flies -> the bracket stays (2.5, 4)
    result, calls = _capacity(monkeypatch, [1.0, 4.0], [rock, over],
                              lambda s: over if s >= 3.9 else fly if s >= 3.0 else rock)
    assert calls == [2.5, 3.25]
    np.testing.assert_array_equal(result, [3.25, 2.5, 4.0, 2.0])
    # a hunt above the stripes that meets free flight: no capacity, censored at the highest survival
    result, calls = _capacity(monkeypatch, [1.0, 2.0], [rock, rock], lambda s: fly if s >= 2.5 else rock)
    assert math.isnan(result[0]) and math.isnan(result[2]) and result[1] == max(s for s in [2.0, *calls] if s < 2.5)


def test_a_free_flight_is_neither_a_resurrection_nor_counted_in_the_outcome_classes():
    from rockfrag.cube import OUTCOME_FREE_FLIGHT, OUTCOME_NO_UPLIFT, OUTCOME_OVERTURNED, OUTCOME_ROCKING
    from rockfrag.ida import resurrected

    flown = np.array([[OUTCOME_ROCKING, OUTCOME_OVERTURNED, OUTCOME_FREE_FLIGHT]])
    survived = np.array([[OUTCOME_ROCKING, OUTCOME_OVERTURNED, OUTCOME_ROCKING]])
    assert resurrected(flown).tolist() == [0] and resurrected(survived).tolist() == [1]
    assert OUTCOME_NO_UPLIFT != OUTCOME_FREE_FLIGHT
