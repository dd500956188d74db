"""Steps where the physics puts them (issue 34 item 3): where each step row lies and how it was placed."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from rockfrag import study as study_module
from rockfrag.blocks import Block
from rockfrag.config import load_study
from rockfrag.damage_states import DAMAGE_STATES, uplift_lift
from rockfrag.fragility import (
    exact_uplift_thresholds,
    fit_cell,
    fragility_dataset,
    fragility_stage,
    with_recommended,
)
from rockfrag.ida import ida_stage
from rockfrag.measures import MEASURES, pga
from rockfrag.models import simulate_batch
from rockfrag.models.base import Outcome
from rockfrag.models.variants import MEMBERS, RECOMMENDED, member_model
from rockfrag.processing import process_record
from rockfrag.records import load_records
from rockfrag.records.components import pair_window
from rockfrag.soils import SOILS, soil_block_stiffness
from rockfrag.steps import bisection_intensity
from rockfrag.study import run_study

UPLIFT, ROCKING = DAMAGE_STATES["uplift"], DAMAGE_STATES["rocking-0.2"]
LEVELS = np.array([0.1, 0.2, 0.4, 0.8])


def test_a_rigid_base_under_its_own_pga_steps_at_g_tan_alpha():
    exceed = np.array([[0, 0, 10, 10]], float)
    total = np.full((1, 4), 10.0)
    rows, _ = fit_cell(LEVELS, exceed, total, [UPLIFT], threshold=0.3, unit="g")
    assert rows[0].median == 0.3 and rows[0].beta == 0 and rows[0].status == "deterministic-threshold"
    assert rows[0].step_method.startswith("exact: g tan(alpha)")


def test_a_separated_state_steps_at_the_geometric_middle_of_its_bracket():
    exceed = np.array([[0, 0, 10, 10]], float)  # none at 0.2 g, all at 0.4 g
    rows, _ = fit_cell(LEVELS, exceed, np.full((1, 4), 10.0), [ROCKING], unit="g")
    assert rows[0].status == "separated" and rows[0].beta == 0
    assert rows[0].median == pytest.approx(np.sqrt(0.2 * 0.4))
    assert "geometric middle of the bracket 0.2-0.4 g" in rows[0].step_method


def test_a_quasi_separated_state_steps_at_its_mixed_level_and_a_curve_has_no_step():
    rows, _ = fit_cell(LEVELS, np.array([[0, 4, 10, 10]], float), np.full((1, 4), 10.0), [ROCKING], unit="g")
    assert rows[0].median == pytest.approx(0.2) and "the one level where some records" in rows[0].step_method
    rows, _ = fit_cell(LEVELS, np.array([[1, 4, 7, 9]], float), np.full((1, 4), 10.0), [ROCKING], unit="g")
    assert rows[0].beta > 0 and rows[0].step_method == ""


def test_a_step_at_the_lowest_level_below_half_is_inside_the_range_not_above_it():
    # the tiny study's uplift row (a winkler bed, 4 records): 1 of 4 uplifted at the lowest level, all 4 from the next
    # on. The median lies between the two lowest levels; it was reported 'above-range' ("reached only at the highest
    # level by 4 of 4 records; the median lies above 3 g") with no median
    levels = np.array([0.101, 0.2, 0.393, 0.774, 1.524, 3.0])
    exceed, total = np.array([[1, 4, 4, 4, 4, 4]], float), np.full((1, 6), 4.0)
    rows, _ = fit_cell(levels, exceed, total, [UPLIFT], unit="g", cap=3.0)
    assert rows[0].status == "separated" and rows[0].beta == 0
    assert levels[0] <= rows[0].median < levels[1]
    assert "the one level where some records" in rows[0].step_method
    assert not any("above" in warning for warning in rows[0].warnings)
    # half or more at the lowest level: the median lies below it; at most half at the highest: above it
    below, _ = fit_cell(levels, np.array([[2, 4, 4, 4, 4, 4]], float), total, [UPLIFT], unit="g")
    above, _ = fit_cell(levels, np.array([[0, 0, 0, 0, 0, 2]], float), total, [ROCKING], unit="g")
    assert below[0].status == "below-range" and above[0].status == "above-range"


# ---------------------------------------------------------------- a rigid base under RotD50 pair scaling

PAPER = Block(name="paper", R=9.39, alpha=0.44, mass=5.0e5)


@pytest.fixture(scope="module")
def bolu_pair():
    """DUZCE BOL000 and BOL090, processed, with each component's exact uplift intensity under RotD50 scaling."""
    first, second = (process_record(record) for record in load_records("bolu")[0])
    window = pair_window(first, second)
    rotd50 = MEASURES["pga"].rotd(first.acceleration[window[0]], second.acceleration[window[1]], first.dt)
    # a component lifts when its own scaled PGA exceeds g tan(alpha): at the level g tan(alpha) RotD50 / PGA
    thresholds = np.array([PAPER.uplift_acceleration() * rotd50 / pga(r.acceleration) for r in (first, second)])
    return (first, second), rotd50, thresholds


@pytest.mark.parametrize("model", ["housner", "ssi"])
def test_each_component_lifts_at_its_own_exact_threshold_under_pair_scaling(bolu_pair, model):
    (first, second), rotd50, thresholds = bolu_pair
    assert abs(np.log(thresholds[0] / thresholds[1])) > 0.02  # two distinct thresholds: not one step
    k = soil_block_stiffness(SOILS["steel"], PAPER)
    for record, threshold in zip((first, second), thresholds):
        scales = threshold / rotd50 * np.array([1 - 1e-6, 1 + 1e-6])  # the pair's scale factor just below/above
        status = simulate_batch(model, record.acceleration, record.dt, scales, [(PAPER, k, 0.05)])[0]["status"]
        assert list(status.astype(int)) == [int(Outcome.NO_UPLIFT), int(Outcome.ROCKING)]


def test_the_rigid_uplift_row_under_pair_scaling_is_the_fit_of_the_exact_thresholds(bolu_pair, tmp_path):
    _, _, thresholds = bolu_pair
    low, high = np.sort(thresholds) / 9.80665
    levels = [0.8 * low, np.sqrt(low * high), 1.25 * high]  # the middle level lifts one component, not the other
    (tmp_path / "study.toml").write_text(f"""
soils = ["steel"]
models = ["housner", "ssi"]
[study]
name = "pair-uplift"
record_sets = ["bolu"]
[intensity]
levels = [{", ".join(f"{v:.6f}" for v in levels)}]
capacity_resolution = 0.0
[solver]
friction = "none"
[blocks.paper]
R = 9.39
alpha = 0.44
mass = 5.0e5
""")
    cube, _ = run_study(load_study(tmp_path / "study.toml"), output=tmp_path / "out", workers=1, progress=False,
                        log=lambda *_: None, warn=lambda *_: None)
    fits = fragility_dataset(cube, [UPLIFT], n_bootstrap=20, seed=1).sel(damage_state="uplift")
    for model in ("housner", "ssi"):
        row = fits.sel(model=model).isel(soil=0, block=0)
        assert row.fit_method.item() == "exact-thresholds" and row.status.item() == "fitted"
        assert row["median"].item() == pytest.approx(np.sqrt(low * high), rel=1e-9)  # MLE: the geometric mean
        assert row.beta.item() == pytest.approx(np.log(high / low) / 2, rel=1e-9)  # the divisor-n spread of ln
        assert np.isnan(row.step_position.item()) and row.step_method.item() == ""
        assert "disagree" not in row.fit_warning.item()  # the stripes counted what the thresholds say: 0, 1, 2
        np.testing.assert_array_equal(row.empirical_fraction.values, [0.0, 0.5, 1.0])
        assert row.median_low.item() <= row["median"].item() <= row.median_high.item()


# ---------------------------------------------------------------- steps bisected by runs between the levels

def _study(tmp_path, body, name="steps"):
    (tmp_path / f"{name}.toml").write_text(body)
    return load_study(tmp_path / f"{name}.toml")


RIGID_STUDY = """
soils = ["rock"]
models = ["housner"]
[study]
name = "rigid-step"
record_sets = ["bolu"]
[intensity]
measure = "pga_ratio"
component = "single"
levels = [0.45, 1.9]
credible_max = 2.0
credible_measure = "pga_ratio"
capacity_resolution = 0.02
[solver]
friction = "none"
[blocks.slender-cabinet]
b = 0.3
h = 1.5
mass = 2000.0
"""


@pytest.fixture(scope="module")
def rigid_step(tmp_path_factory):
    """The rigid step study, run once, with the step runs the solver computed (keys of ``compute_cells`` jobs)."""
    folder = tmp_path_factory.mktemp("rigid-step")
    config = _study(folder, RIGID_STUDY)
    computed = []
    original = study_module.compute_cells

    def counting(acceleration, dt, scales, jobs, *args):
        computed.extend(job[0] for job in jobs if "-step-" in job[0])
        return original(acceleration, dt, scales, jobs, *args)

    study_module.compute_cells = counting
    try:
        cube, stats = run_study(config, output=folder / "out", workers=1, progress=False, log=lambda *_: None,
                                warn=lambda *_: None)
        first = list(computed)
        computed.clear()
        again, _ = run_study(config, output=folder / "out", workers=1, progress=False, log=lambda *_: None,
                             warn=lambda *_: None)
    finally:
        study_module.compute_cells = original
    return config, folder, cube, stats, first, again, list(computed)


def test_a_step_the_levels_bracket_widely_is_bisected_to_the_resolution_of_its_known_threshold(rigid_step):
    # PGA/(g tan alpha), each component by its own: every record lifts above 1 exactly (not an exact row: the
    # measure is not PGA), the levels bracket it 0.45-1.9; the runs between them must place it within 1% of 1
    _, _, cube, stats, first, _, _ = rigid_step
    row = fragility_dataset(cube, [UPLIFT], n_bootstrap=0).sel(damage_state="uplift").isel(soil=0, block=0, model=0)
    assert row.status.item() == "separated" and row.beta.item() == 0
    assert row.step_position.item() == pytest.approx(1.0, abs=0.01)
    assert row.step_method.item().startswith("bisected to 2%: geometric middle of the bracket")
    assert "narrowed from the levels 0.45-1.9" in row.step_method.item()
    runs = cube.attrs["step_runs"]
    assert stats["step_runs"] == runs == len(first) and runs == 2 * np.isfinite(cube.step_intensity.values).sum()
    assert runs <= 2 * 7  # ln(1.9/0.45)/ln(1.02) = 73 stripes would do it; bisection takes log2 of that


def test_a_resumed_study_reuses_its_step_runs(rigid_step):
    _, _, cube, _, first, again, computed = rigid_step
    assert first and computed == []  # every step run came from its checkpoint
    xr.testing.assert_identical(cube.step_intensity, again.step_intensity)
    xr.testing.assert_identical(cube.step_outcome, again.step_outcome)
    assert again.attrs["step_runs"] == cube.attrs["step_runs"]  # requested again, none computed


def test_fragility_csv_says_where_each_step_lies_and_how_it_was_placed(rigid_step, tmp_path):
    config, folder, cube, _, _, _, _ = rigid_step
    fragility_stage(cube, ida_stage(cube, tmp_path), config, tmp_path, progress=False, log=lambda *_: None)
    table = pd.read_csv(tmp_path / "fragility.csv").set_index("damage_state")
    uplift = table.loc["uplift"]
    assert uplift.step_position == pytest.approx(1.0, abs=0.01) and uplift.beta == 0
    lower, upper = (float(v) for v in re.search(r"bracket ([0-9.]+)-([0-9.]+) ", uplift.step_method).groups())
    assert lower < 1.0 <= upper and upper - lower <= 0.02 * upper  # g tan(alpha) inside, at the resolution
    assert uplift.step_position == pytest.approx(np.sqrt(lower * upper), rel=1e-3)
    runs = int(re.search(r"by (\d+) runs at (\d+) intensities", uplift.step_method).group(1))
    assert runs == cube.attrs["step_runs"] and "narrowed from the levels 0.45-1.9" in uplift.step_method
    curves = table[table.beta > 0]
    assert curves.step_method.isna().all() and curves.step_position.isna().all()  # a curve has no step


BED_STUDY = """
soils = ["steel"]
models = ["winkler"]
[study]
name = "bed-step"
record_sets = ["DUZCE/BOL000"]
[intensity]
component = "single"
levels = [0.1, 0.3, 0.9]
credible_max = 1.0
capacity_resolution = 0.02
[solver]
friction = "none"
restitution = ""
[blocks.slender-cabinet]
b = 0.3
h = 1.5
mass = 2000.0
"""


def test_another_models_step_lands_on_a_threshold_a_fine_scan_finds(tmp_path):
    # one record: the tensionless bed's uplift (a corner 1 mm off the bed) is a step, bracketed by levels a factor 3
    # apart. A fine scan of scale factors (1% apart, the solver called directly) finds where the record passes from
    # below the lift to above it: near 0.27 g on steel, not quite monotonic (on, off and on again within 3%), so the
    # bisection must land within the resolution of one of those transitions (the levels' middle, 0.17 g, lies below
    # the scan, which starts where the record does not lift yet)
    config = _study(tmp_path, BED_STUDY)
    cube, _ = run_study(config, output=tmp_path / "out", workers=1, progress=False, log=lambda *_: None,
                        warn=lambda *_: None)
    row = fragility_dataset(cube, [UPLIFT], n_bootstrap=0).sel(damage_state="uplift").isel(soil=0, block=0, model=0)
    assert row.status.item() == "separated" and row.step_method.item().startswith("bisected to 2%")
    step = row.step_position.item()
    lower, upper = 0.1, 0.3
    assert lower < step < upper
    record = process_record(load_records(["DUZCE/BOL000"])[0][0])
    block = Block(name="cabinet", b=0.3, h=1.5, mass=2000.0)
    k, xi = float(cube.bed_stiffness.isel(soil=0, block=0, model=0)), SOILS["steel"].damping_ratio
    scan = np.geomspace(0.2, upper, int(np.log(upper / 0.2) / np.log(1.01)) + 1)
    summary = simulate_batch("winkler", record.acceleration, record.dt, scan / (pga(record.acceleration) / 9.80665),
                             [(block, k, xi)], bed="two-spring")[0]
    reached = (summary["peak_corner_uplift"] >= uplift_lift(block.b)) | (summary["status"] == int(Outcome.OVERTURNED))
    transitions = scan[1:][~reached[:-1] & reached[1:]]  # the first scanned intensity at which it lifts again
    assert transitions.size and not reached[0] and scan[0] < step
    assert np.min(np.abs(np.log(transitions / step))) <= np.log(1.03)  # the 2% resolution and the scan's 1%


def test_the_model_uncertainty_widens_a_recommended_step_like_any_other_row():
    # a separated recommended row (beta_rtr = 0, a step at 0.5 g) and a fitted one (beta_rtr 0.3) beside it: both get
    # beta = sqrt(beta_rtr^2 + beta_model^2), the step keeps its position and record-to-record beta 0
    dims = ("soil", "block", "model", "damage_state")
    coords = {"soil": ["rock"], "block": ["b"], "model": ["housner", RECOMMENDED], "damage_state": ["step", "curve"]}
    median = np.array([[[[0.5, 0.8], [0.5, 0.8]]]])
    beta = np.array([[[[0.0, 0.3], [0.0, 0.3]]]])
    dataset = xr.Dataset({"median": (dims, median, {"units": "9.80665 m s-2"}), "beta": (dims, beta),
                          "fit_warning": (dims, np.full(median.shape, ""))}, coords=coords)
    roles = [m for m in MEMBERS if m != "centre"]
    spread = {"restitution": 1.6, "friction": 1.0, "stiffness": 1.1}  # m_high / m_low of each parameter
    ends = [0.5 * spread[r.split("_")[0]] ** (0.5 if r.endswith("high") else -0.5) for r in roles]
    member = np.array(ends)[:, None, None, None] * np.ones((1, 1, 1, 2))  # (member, soil, block, damage_state)
    members = xr.Dataset({"median": (("model", "soil", "block", "damage_state"), member)},
                         coords={"model": [member_model(r) for r in roles], "soil": ["rock"], "block": ["b"],
                                 "damage_state": ["step", "curve"]})
    out = with_recommended(dataset, members, "fair").sel(soil="rock", block="b")
    parameters = np.sqrt(sum((np.log(v) / (2 * np.sqrt(3))) ** 2 for v in spread.values()))
    model_beta = max(0.35, parameters)  # the rating replaces the sampled spread unless the spread is larger
    assert parameters == pytest.approx(0.138, abs=0.001) and model_beta == 0.35
    step, curve = (out.sel(model=RECOMMENDED, damage_state=s) for s in ("step", "curve"))
    assert step.beta_parameters.item() == pytest.approx(parameters, rel=1e-12)
    assert step.beta.item() == pytest.approx(model_beta, rel=1e-12) and step.beta_record_to_record.item() == 0
    assert curve.beta.item() == pytest.approx(np.hypot(0.3, model_beta), rel=1e-12)
    assert out.sel(model="housner", damage_state="step").beta.item() == 0  # a reference's step stays a step


def test_the_next_intensity_halves_the_bracket_or_its_wider_side_and_stops_at_the_resolution():
    levels, total = np.array([0.1, 0.2, 0.4, 0.8]), np.full(4, 10.0)
    assert bisection_intensity(levels, [0, 0, 10, 10], total, 0.02) == pytest.approx(np.sqrt(0.2 * 0.4))
    # one mixed intensity (0.25): the wider side, 0.25-0.4, is bisected next
    mixed = np.array([0.1, 0.2, 0.25, 0.4, 0.8])
    assert bisection_intensity(mixed, [0, 0, 3, 10, 10], np.full(5, 10.0), 0.02) == pytest.approx(np.sqrt(0.1))
    assert bisection_intensity([0.1, 0.2, 0.203, 0.8], [0, 0, 10, 10], total, 0.02) is None  # within 2%
    assert bisection_intensity(levels, [4, 10, 10, 10], total, 0.02) is None  # open at the lowest level


def test_a_record_run_with_its_vertical_has_no_exact_uplift_threshold(rigid_step):
    # it lifts where |a_h| > (g + a_v) tan(alpha): not at a known intensity, so its rows are fitted from the runs
    cube = rigid_step[2]  # scaled by each component's own PGA, as a PGA study
    cube = cube.assign(record_im=cube.record_pga.expand_dims(block=cube.block.values).transpose("record", "block"))
    cube = cube.assign_attrs(intensity_measure="pga")
    assert exact_uplift_thresholds(cube, "9.80665 m s-2") is not None
    with_vertical = cube.assign(vertical_applied=cube.vertical_applied.copy(data=np.ones(cube.sizes["record"],
                                                                                          np.int8)))
    assert exact_uplift_thresholds(with_vertical, "9.80665 m s-2") is None
