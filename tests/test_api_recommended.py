"""``simulate("recommended", ...)`` reproduces the study's central recommended run bit for bit (issue 33 item 3).

The study (``rockfrag run``) and the API share one definition of that run (``variants.sample_member``): the bed's
stiffness from the soil (eq. 19), its damping calibrated to the middle of the restitution range, the soil's friction.
The check runs a one-block study on a sliding sand bed and on a stiff steel deck, and calls ``simulate`` with each
record's processed acceleration and its scale factor from ``cube.nc``: every summary must be the same float.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from rockfrag.errors import SolverError
from rockfrag.models import simulate
from rockfrag.models.restitution import calibrate_dissipation
from rockfrag.models.variants import DEFAULT_DESIGN, RECOMMENDED_BED, central_member, member_restitution
from rockfrag.soils import SOILS, soil_block_stiffness
from tests.helpers import run_study_file

STUDY = """
soils = ["sand", "steel"]
models = ["winkler"]
[study]
name = "api"
record_sets = ["bolu"]
[intensity]
levels = [0.6, 1.0]
[blocks.paper]
R = 9.39
alpha = 0.44
mass = 326197.0
E_b = 210e9
footprint_area = 8.0
soil_depth = 2.0
[blocks.slender-cabinet]
b = 0.3
h = 1.5
mass = 2000.0
E_b = 200e9
footprint_area = 0.48
soil_depth = 1.0
[blocks.squat-machinery]
b = 1.5
h = 2.0
mass = 30000.0
"""
COMPARED = ("peak_angle", "peak_uplift", "peak_slip", "residual_slip", "n_impacts", "time_of_peak",
            "peak_settlement", "peak_friction_demand")


@pytest.fixture(scope="module")
def study_run(tmp_path_factory):
    config, records, cube = run_study_file(tmp_path_factory.mktemp("api-recommended"), STUDY)
    return config, records, cube


def test_recommended_reproduces_the_cube_bit_for_bit(study_run):
    config, records, cube = study_run
    cells = list(itertools.product(range(len(config.blocks)), ("sand", "steel"), range(len(records)),
                                   range(cube.sizes["im_level"])))
    for b, soil, r, level in cells:  # the paper's block, the slender cabinet and the squat skid
        block, record = config.blocks[b], records[r]
        scale = float(cube.scale_factor.isel(record=r, im_level=level, block=b))
        # the way: the processed record times the cube's scale factor; and scale=
        scaled = simulate("recommended", record.acceleration * scale, record.dt, block, soil=SOILS[soil])
        result = simulate("recommended", record.acceleration, record.dt, block, soil=soil, scale=scale)
        cell = cube.sel(soil=soil, model="recommended").isel(record=r, im_level=level, block=b)
        for name in COMPARED:
            for run in (scaled, result):
                assert getattr(run, name) == pytest.approx(float(cell[name]), rel=0, abs=0, nan_ok=True), \
                    (block.name, soil, r, level, name)
    assert len(cells) == 3 * 2 * len(records) * cube.sizes["im_level"]
    # the sand bed slides: the comparison covers the slip
    assert float(cube.peak_slip.sel(soil="sand", model="recommended").max()) > 0


def test_the_calibration_is_the_studys(study_run):
    config, _, cube = study_run
    for (b, block), soil in itertools.product(enumerate(config.blocks), ("sand", "steel")):
        member = central_member(block, SOILS[soil])
        cell = cube.sel(soil=soil, model="recommended").isel(block=b)
        assert member.xi == float(cell.damping_ratio_calibrated)
        assert member.k == float(cell.interface_stiffness)
        assert member.friction == (float(cell.friction_static), float(cell.friction_kinetic))


def test_a_target_in_reach_is_the_plain_calibration():
    """Independent of the sample's bookkeeping: where the centre is reachable, its xi is calibrate_dissipation's."""
    block = load_study_blocks()[0]
    k = soil_block_stiffness(SOILS["sand"], block)
    member = central_member(block, SOILS["sand"])
    expected = calibrate_dissipation(block, k, RECOMMENDED_BED, member_restitution(block, DEFAULT_DESIGN, "centre"))
    assert member.xi == expected.xi


def load_study_blocks():
    import tomllib

    from rockfrag.config import study_from_dict

    return study_from_dict(tomllib.loads(STUDY)).blocks


def test_winkler_without_damping_runs_the_recommended_bed():
    """The README calls the continuous bed at xi = 5% under-dissipating: it is no longer simulate's default."""
    block = load_study_blocks()[0]
    k = soil_block_stiffness(SOILS["sand"], block)
    t = np.arange(0, 4, 0.005)
    ag = 4.0 * np.sin(2 * np.pi * 1.5 * t)
    default = simulate("winkler", ag, 0.005, block, k=k)
    member = central_member(block, SOILS["sand"])
    assert default.extra == {"xi": member.xi, "bed": member.bed}
    old = simulate("winkler", ag, 0.005, block, k=k, xi=0.05, bed="continuous")
    assert old.extra["xi"] != default.extra["xi"]


@pytest.mark.parametrize("name", ["recommended", "recommended-restitution_low", "recommended-friction_high",
                                  "recommended-stiffness_low"])
def test_every_cube_name_runs_on_a_soil(name):
    block = load_study_blocks()[0]
    t = np.arange(0, 2, 0.01)
    result = simulate(name, np.sin(t), 0.01, block, soil="sand")
    assert result.extra["bed"] == "two-spring"
    with pytest.raises(SolverError, match="needs soil="):
        simulate(name, np.sin(t), 0.01, block)
    with pytest.raises(SolverError, match="takes no k, xi"):
        simulate(name, np.sin(t), 0.01, block, soil="sand", k=1e9, xi=0.1)


def test_unknown_names_are_refused_with_the_list():
    block = load_study_blocks()[0]
    with pytest.raises(SolverError, match="valid models are: housner, ssi"):
        simulate("winkler-middle", np.zeros(3), 0.01, block, soil="sand")
    with pytest.raises(SolverError, match="gave way to the designed sample.*'recommended'"):
        simulate("winkler-centre", np.zeros(3), 0.01, block, soil="sand")
    with pytest.raises(SolverError, match="shipped soils: clay, sand"):
        simulate("recommended", np.zeros(3), 0.01, block, soil="loam")
    with pytest.raises(SolverError, match="takes k"):
        simulate("housner", np.zeros(3), 0.01, block, soil="sand")
