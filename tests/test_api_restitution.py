"""``simulate("winkler", ..., restitution=r)`` calibrates the bed's damping by the study's rule (issue 33 item 3).

The issue's trial found the API and the study calibrating one target (``restitution=0.871``, a continuous clay bed)
to different damping ratios. The check runs that study (``[solver] restitution = 0.871``, ``bed = "continuous"``, the
plain ``winkler`` model on clay) and calls ``simulate`` with the cube's stiffness, the soil's friction, the same target
and each run's scale factor: the calibrated xi and every summary must be the same floats. A target reached only at
xi where free rocking is not reproducible (the issue's case) is refused by both, for the same reason.
"""

from __future__ import annotations

import pytest

from rockfrag.errors import SolverError
from rockfrag.models import simulate
from rockfrag.models.restitution import admissible_xi
from rockfrag.soils import SOILS
from tests.helpers import run_study_file

TARGET = 0.871
STUDY = f"""
soils = ["clay"]
models = ["winkler"]
[study]
name = "api-restitution"
record_sets = ["bolu"]
[intensity]
levels = [0.8]
[solver]
bed = "continuous"
restitution = {TARGET}
[blocks.paper]
R = 9.39
alpha = 0.44
mass = 326197.0
E_b = 210e9
footprint_area = 8.0
soil_depth = 2.0
"""
COMPARED = ("peak_angle", "peak_uplift", "peak_slip", "residual_slip", "n_impacts", "time_of_peak",
            "peak_settlement", "peak_friction_demand")


@pytest.fixture(scope="module")
def study_run(tmp_path_factory):
    config, records, cube = run_study_file(tmp_path_factory.mktemp("api-restitution"), STUDY)
    return config, records, cube.sel(soil="clay", model="winkler").isel(block=0)


def test_restitution_calibrates_as_the_study_does(study_run):
    config, records, cube = study_run
    block = config.blocks[0]
    k = float(cube.interface_stiffness)
    assert float(cube.damping_ratio_calibrated) >= admissible_xi(block, k, "continuous").smallest
    compared = 0
    for r, record in enumerate(records):
        for level in range(cube.sizes["im_level"]):
            cell = cube.isel(record=r, im_level=level)
            result = simulate("winkler", record.acceleration, record.dt, block, k=k, bed="continuous",
                              restitution=TARGET, friction=SOILS["clay"].friction,
                              scale=float(cell.scale_factor))
            assert result.extra["xi"] == float(cube.damping_ratio_calibrated)
            for name in COMPARED:
                assert getattr(result, name) == pytest.approx(float(cell[name]), rel=0, abs=0, nan_ok=True), \
                    (r, level, name)
            compared += 1
    assert compared == len(records) * cube.sizes["im_level"] > 0


def test_an_unreachable_target_is_refused_by_both(study_run, tmp_path, capsys):
    from rockfrag.cli import main

    config, records, cube = study_run
    block, k = config.blocks[0], float(cube.interface_stiffness)
    beyond = admissible_xi(block, k, "continuous").reachable[1] + 0.02
    # reached only below the admissible xi (the case): the API once calibrated it there
    with pytest.raises(SolverError, match="not reproducible") as refused:
        simulate("winkler", records[0].acceleration, records[0].dt, block, k=k, bed="continuous",
                 restitution=beyond, friction=SOILS["clay"].friction)
    (tmp_path / "study.toml").write_text(STUDY.replace(f"restitution = {TARGET}", f"restitution = {beyond}"))
    assert main(["run", str(tmp_path / "study.toml"), "--output", str(tmp_path / "out"), "--no-progress",
                 "--serial"]) != 0
    assert not (tmp_path / "out" / "cube.nc").exists()
    # the same rule refuses the same target with the same reason (the study adds the cell it was calibrating)
    assert str(refused.value) in capsys.readouterr().err
