"""Sliding in the study: which cells run with friction (``[solver] friction``, rockfrag.study.cell_friction),
their checkpoint keys, the cube's slip variables and the slip damage states' rows.

The small study: the squat skid (b/h = 0.75) on a slick soil (mu_s 0.3: it slides) and on a grippy one (mu_s 1.0
> b/h: tied under "where-it-matters"), housner, winkler and ssi, Bolu's two components at three PGA levels.
"""

from __future__ import annotations

import numpy as np
import pytest

from rockfrag.blocks import Block
from rockfrag.config import load_study
from rockfrag.damage_states import DAMAGE_STATES
from rockfrag.errors import ConfigError
from rockfrag.fragility import fragility_dataset
from rockfrag.models import simulate_batch
from rockfrag.models.options import RIGID_BASE_MAX_KINETIC_FRICTION
from rockfrag.processing import load_recipe
from rockfrag.soils import MAX_KINETIC_FRICTION, SOILS
from rockfrag.study import cell_friction, cells_for_record, run_study, solver_options, study_records

STUDY = """
soils = ["slick", "grippy"]
models = ["housner", "winkler", "ssi"]
[study]
name = "sliding"
record_sets = ["bolu"]
[intensity]
levels = [0.2, 0.5, 0.9]
capacity_resolution = 0.0
component = "single"  # each component its own PGA: a tied rigid base lifts at exactly g tan(alpha)
[solver]
bed = "two-spring"
restitution = ""
friction = "{mode}"
[soils_custom.slick]
shear_modulus = 300e6
friction_static = 0.3
friction_kinetic = 0.25
[soils_custom.grippy]
shear_modulus = 300e6
friction_static = 1.0
friction_kinetic = 0.9
[blocks.squat-machinery]
b = 1.5
h = 2.0
mass = 30000.0
E_b = 30e9
footprint_area = 6.0
soil_depth = 1.5
"""


def _study(tmp_path, mode):
    path = tmp_path / f"{mode}.toml"
    path.write_text(STUDY.replace("{mode}", mode))
    return load_study(path, overrides={"study": {"output": str(tmp_path / mode)}})


@pytest.fixture(scope="module")
def cubes(tmp_path_factory):
    """The study's cube with friction "where-it-matters" and with "none" (each ~3 s once compiled)."""
    folder = tmp_path_factory.mktemp("sliding")
    out = {}
    for mode in ("where-it-matters", "none"):
        config = _study(folder, mode)
        out[mode] = (config, run_study(config, progress=False, log=lambda *_: None, warn=lambda *_: None)[0])
    return out


def test_a_cell_slides_where_the_soils_static_friction_is_below_b_over_h():
    squat = Block(name="squat", b=1.5, h=2.0, mass=3e4)   # b/h = 0.75
    slender = Block(name="slender", b=0.3, h=1.5, mass=2e3)  # b/h = 0.2
    rock, clay = SOILS["rock"], SOILS["clay"]  # mu_s 0.70 and 0.35
    assert cell_friction(squat, rock, "housner", "where-it-matters") == rock.friction
    assert cell_friction(squat, clay, "recommended", "where-it-matters") == clay.friction
    assert cell_friction(slender, clay, "housner", "where-it-matters") is None
    assert cell_friction(slender, clay, "winkler", "all") == clay.friction
    assert cell_friction(squat, clay, "ssi", "all") is None  # the paper's model is always tied
    assert cell_friction(squat, clay, "housner", "none") is None


def test_shipped_soils_friction_and_the_kinetic_limit():
    # NAVFAC DM-7.02 Table 1 (concrete on soil and rock), kinetic 0.85 x static; steel on steel 0.5 / 0.4
    assert {name: soil.friction_static for name, soil in SOILS.items()} == \
        {"clay": 0.35, "sand": 0.45, "gravel": 0.55, "rock": 0.70, "steel": 0.50}
    assert all(0 < s.friction_kinetic <= s.friction_static for s in SOILS.values())
    assert MAX_KINETIC_FRICTION == RIGID_BASE_MAX_KINETIC_FRICTION


def test_friction_settings_are_checked(tmp_path):
    path = tmp_path / "old.toml"
    path.write_text('[report]\nfriction_coefficient = 0.5\n')
    with pytest.raises(ConfigError, match="report.friction_coefficient.*friction_static"):
        load_study(path)
    path.write_text('soils = ["odd"]\n[soils_custom.odd]\nshear_modulus = 1e8\nfriction_static = 0.3\n'
                    'friction_kinetic = 0.4\n')
    with pytest.raises(ConfigError, match="soils_custom.odd.friction_kinetic"):
        load_study(path)
    path.write_text('[solver]\nfriction = "some"\n')
    with pytest.raises(ConfigError, match="solver.friction"):
        load_study(path)


def test_checkpoint_keys_carry_the_friction_and_tied_keys_stay(tmp_path):
    sliding, tied = _study(tmp_path, "where-it-matters"), _study(tmp_path, "none")
    loaded = study_records(tied, log=lambda *_: None)
    record = loaded.records[0]
    recipe = load_recipe(None)
    cells = {(c.model, c.soil_index): c for c in cells_for_record(record, sliding, recipe)}
    plain = {(c.model, c.soil_index): c for c in cells_for_record(record, tied, recipe)}
    # slick (0): housner and winkler slide, new keys; grippy (1) and ssi: tied, the keys of friction = "none"
    assert cells[("housner", 0)].friction == (0.3, 0.25) and cells[("housner", 1)].friction is None
    assert cells[("housner", 0)].key != plain[("housner", None)].key
    assert cells[("housner", 1)].key == plain[("housner", None)].key
    assert cells[("winkler", 0)].key != plain[("winkler", 0)].key
    assert cells[("winkler", 1)].key == plain[("winkler", 1)].key
    assert cells[("ssi", 0)].key == plain[("ssi", 0)].key


def test_the_cube_has_slip_where_a_cell_slides_and_nan_where_tied(cubes):
    config, cube = cubes["where-it-matters"]
    slides = cube.friction_static.sel(block="squat-machinery")
    assert float(slides.sel(soil="slick", model="housner")) == 0.3
    assert float(cube.friction_kinetic.sel(soil="slick", model="winkler", block="squat-machinery")) == 0.25
    assert np.isnan(slides.sel(soil="grippy")).all() and np.isnan(slides.sel(model="ssi")).all()
    slip = cube.peak_slip.sel(block="squat-machinery")
    for model in ("housner", "winkler"):
        on_slick = slip.sel(soil="slick", model=model)
        assert np.isfinite(on_slick).all()
        # 0.9 g against mu_k g = 0.25 g: the skid slides (Newmark: centimetres at least); 0.2 g < mu_s g: it stays
        assert float(on_slick.isel(im_level=-1).min()) > 0.01
        assert float(on_slick.isel(im_level=0).max()) < 1e-6
        assert np.isnan(slip.sel(soil="grippy", model=model)).all()
    assert np.isnan(slip.sel(model="ssi")).all()
    times = sum(cube[name] for name in ("time_at_rest", "time_sliding", "time_rocking", "time_slide_rocking",
                                        "time_in_flight")).sel(soil="slick", model="housner")
    assert float(cube.time_sliding.sel(soil="slick", model="housner").isel(im_level=-1).min()) > 0
    assert np.isfinite(times).all() and float(times.min()) > 0
    assert cube.peak_slip.attrs["units"] == "m" and cube.attrs["friction"] == "where-it-matters"


def test_friction_none_gives_the_tied_numbers(cubes):
    """"none" reproduces a tied solver run, and the tied cells of "where-it-matters" are the same runs."""
    config, cube = cubes["none"]
    _, sliding = cubes["where-it-matters"]
    assert np.isnan(cube.friction_static).all() and np.isnan(cube.peak_slip).all()
    loaded = study_records(config, log=lambda *_: None)
    record = loaded.records[0]
    block = config.blocks[0]
    scales = cube.scale_factor.sel(record=record.id, block=block.name).values
    direct = simulate_batch("housner", record.acceleration, record.dt, scales, [(block, None, None)],
                            t_end=(record.acceleration.size - 1) * record.dt + config.tail,
                            **solver_options(config))[0]
    for soil in ("slick", "grippy"):
        tied = cube.peak_angle.sel(record=record.id, soil=soil, model="housner", block=block.name)
        np.testing.assert_array_equal(tied.values, direct["peak_angle"])
    for name in ("peak_angle", "outcome", "peak_settlement"):
        np.testing.assert_array_equal(cube[name].sel(soil="grippy").values, sliding[name].sel(soil="grippy").values)
        np.testing.assert_array_equal(cube[name].sel(model="ssi").values, sliding[name].sel(model="ssi").values)
    # the sliding housner runs on the slick soil differ from the tied ones
    assert not np.array_equal(cube.peak_angle.sel(soil="slick", model="housner").values,
                              sliding.peak_angle.sel(soil="slick", model="housner").values)


def test_slip_damage_states_are_fitted_where_cells_slide_and_not_applicable_where_tied(cubes):
    _, cube = cubes["where-it-matters"]
    states = list(DAMAGE_STATES.values())
    assert [s.name for s in states][:3] == ["uplift", "slip-0.05", "slip-0.30"] and states[-1].name == "overturning"
    fits = fragility_dataset(cube, states, n_bootstrap=0)
    status = fits.status.sel(block="squat-machinery")
    for model in ("housner", "winkler"):
        assert str(status.sel(soil="grippy", model=model, damage_state="slip-0.05").values) == "not-applicable"
        assert np.isnan(fits["median"].sel(soil="grippy", model=model, damage_state="slip-0.05",
                                           block="squat-machinery"))
        assert str(status.sel(soil="slick", model=model, damage_state="slip-0.05").values) != "not-applicable"
    assert (status.sel(model="ssi", damage_state=["slip-0.05", "slip-0.30"]) == "not-applicable").all()
    # the fraction of records beyond 5 cm is the cube's own count
    fraction = fits.empirical_fraction.sel(soil="slick", model="housner", block="squat-machinery",
                                           damage_state="slip-0.05")
    counted = ((cube.peak_slip >= 0.05) | (cube.outcome == 2)).sel(soil="slick", model="housner",
                                                                   block="squat-machinery").mean("record")
    np.testing.assert_allclose(fraction.values, counted.values)


def test_showcase_runs_each_case_as_the_study_runs_its_cell():
    """The showcase's histories take the study's base friction: a rigid base that slides on some soil is drawn per
    soil (not once, tied), and a bed model slides where its cell does."""
    from rockfrag.showcase import response_cases

    config = load_study()
    paper = next(b for b in config.blocks if b.name == "paper")  # tan(alpha) = 0.47: slides on clay and sand
    cases = response_cases(config, paper)
    assert not [name for name, _, _ in cases if name.startswith("recommended-")]  # the central member draws the model
    for model in [m for m in config.models if not m.startswith("recommended-")]:
        of_model = [(soil, friction) for name, soil, friction in cases if name == model]
        if model == "ssi":
            assert [friction for _, friction in of_model] == [None] * len(config.soils)  # tied, as the paper has it
            continue
        assert [soil.name for soil, _ in of_model] == [soil.name for soil in config.soils]
        for soil, friction in of_model:
            assert friction == cell_friction(paper, soil, model, config.friction)
        assert any(friction is not None for _, friction in of_model)
    cabinet = next(b for b in config.blocks if b.name == "slender-cabinet")  # b/h = 0.2: never slides
    assert [(soil, friction) for name, soil, friction in response_cases(config, cabinet)
            if name == "housner"] == [(None, None)]


def test_uplift_of_a_rigid_base_is_the_exact_step_only_where_the_base_is_tied(cubes):
    """g tan(alpha) is Housner's uplift on a tied base; a base that slides first need not lift there, so its uplift
    is fitted from its runs (the report drew the exact step through runs that never lifted)."""
    _, cube = cubes["where-it-matters"]
    uplift = [s for s in DAMAGE_STATES.values() if s.edp == "uplifted"]
    fits = fragility_dataset(cube, uplift, n_bootstrap=0)
    cell = dict(block="squat-machinery", model="housner", damage_state=uplift[0].name)
    assert str(fits.fit_method.sel(soil="grippy", **cell).values) == "exact-g-tan-alpha"
    assert str(fits.fit_method.sel(soil="slick", **cell).values) != "exact-g-tan-alpha"
    assert "disagree with the exact" not in str(fits.fit_warning.sel(soil="slick", **cell).values)
