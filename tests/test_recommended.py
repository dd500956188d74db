"""The recommended model and its designed sample: the members' parameters, their calibration in a study, and
the model uncertainty of the recommended curve (rockfrag.models.variants, rockfrag.study, rockfrag.cube,
rockfrag.fragility.with_recommended).

The parameter spread is checked against a Monte Carlo of what it claims to be (ln median uniform over each
parameter's range between its ends' medians, the parameters independent), not against its own formula."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from rockfrag.blocks import Block
from rockfrag.config import load_study
from rockfrag.cube import OUTCOME_NO_UPLIFT, OUTCOME_OVERTURNED, OUTCOME_ROCKING, member_cube, members_apart
from rockfrag.errors import ConfigError, SolverError
from rockfrag.fragility import FORM_RATINGS, RECOMMENDED, fragility_dataset, fragility_table
from rockfrag.models import get_model, model_label
from rockfrag.models.restitution import admissible_xi, free_rocking_restitution, stability, tolerance
from rockfrag.models.variants import (
    DEFAULT_DESIGN,
    MEMBERS,
    RESTITUTION_CAP,
    calibrate_models,
    member_friction,
    member_restitution,
    member_stiffness,
    sample_models,
    split_variant,
)
from rockfrag.soils import SOILS
from rockfrag.study import cells_for_record, restitution_key

CABINET = Block(name="cabinet", b=0.3, h=1.5, mass=2000.0, E_b=200e9, footprint_area=0.48, soil_depth=1.0)
PAPER = Block(name="paper", R=9.39, alpha=0.44, mass=326197.0, E_b=210e9, footprint_area=8.0, soil_depth=2.0)


# ---------------------------------------------------------------- names and parameters

def test_member_names_resolve_to_the_bed_model():
    assert sample_models() == ["recommended", "recommended-restitution_low", "recommended-restitution_high",
                               "recommended-friction_low", "recommended-friction_high",
                               "recommended-stiffness_low", "recommended-stiffness_high"]
    assert split_variant("recommended") == ("winkler", "centre")
    assert split_variant("recommended-friction_high") == ("winkler", "friction_high")
    assert split_variant("ssi-paper") == ("ssi-paper", None) and split_variant("winkler-low") == ("winkler-low", None)
    assert get_model("recommended-stiffness_low") is get_model("winkler")
    assert model_label("recommended-friction_low").endswith("friction at the low end")
    with pytest.raises(SolverError, match="unknown model"):
        get_model("winkler-low")


def test_restitution_ends_are_multiples_of_housner_capped_below_one_and_only_its_members_move_it():
    slender = Block(name="slender", R=2.0, alpha=0.1, mass=1000.0)
    housner = slender.housner_restitution()  # 0.985: 1.05 x would gain energy, so the cap holds
    assert member_restitution(slender, DEFAULT_DESIGN, "restitution_low") == pytest.approx(housner)
    assert member_restitution(slender, DEFAULT_DESIGN, "restitution_high") == RESTITUTION_CAP
    middle = 0.5 * (housner + RESTITUTION_CAP)
    for member in ("centre", "friction_low", "friction_high", "stiffness_low", "stiffness_high"):
        assert member_restitution(slender, DEFAULT_DESIGN, member) == pytest.approx(middle)
    assert member_restitution(PAPER, DEFAULT_DESIGN, "restitution_high") == pytest.approx(
        1.05 * (1 - 1.5 * math.sin(0.44) ** 2))


def test_friction_and_stiffness_members_scale_the_soils_values():
    clay = SOILS["clay"]  # NAVFAC 0.35, kinetic 0.30
    assert member_friction(clay.friction, DEFAULT_DESIGN, "friction_high") == pytest.approx((0.42, 0.36))
    assert member_friction(clay.friction, DEFAULT_DESIGN, "friction_low") == pytest.approx((0.35 / 1.2, 0.30 / 1.2))
    assert member_friction(clay.friction, DEFAULT_DESIGN, "stiffness_low") == clay.friction
    # eq. 19 by hand with G halved and doubled: K = A / d / (1 / G + 1 / E_b)
    for member, g in (("stiffness_low", clay.shear_modulus / 2), ("stiffness_high", clay.shear_modulus * 2),
                      ("centre", clay.shear_modulus), ("restitution_high", clay.shear_modulus)):
        expected = CABINET.footprint_area / CABINET.soil_depth / (1 / g + 1 / CABINET.E_b)
        assert member_stiffness(clay, CABINET, DEFAULT_DESIGN, member) == pytest.approx(expected, rel=1e-12)


def test_the_default_study_runs_the_sample_and_the_old_band_keys_name_the_new_ones(tmp_path):
    default = load_study()
    assert default.restitution == "recommended" and default.bed == "two-spring"
    assert [m for m in default.models if split_variant(m)[1]] == sample_models()
    assert default.design == DEFAULT_DESIGN and default.model_quality == "fair"
    study = tmp_path / "study.toml"
    study.write_text('models = ["housner", "winkler"]\n[solver]\nrestitution = ""\n')
    assert load_study(study).models == ("housner", "winkler")
    study.write_text('[solver]\nrestitution = 1.2\n')
    with pytest.raises(ConfigError, match=r"solver\.restitution.*< 1"):
        load_study(study)
    study.write_text('[solver]\nrestitution = "band"\n')
    with pytest.raises(ConfigError, match=r"solver\.restitution.*'recommended'.*\[uncertainty\]"):
        load_study(study)
    study.write_text('[solver]\nrestitution_band = [1.0, 1.05]\n')
    with pytest.raises(ConfigError, match=r"solver\.restitution_band.*\[uncertainty\] restitution_range"):
        load_study(study)
    study.write_text('models = ["housner", "winkler-centre"]\n')
    with pytest.raises(ConfigError, match=r"models.*'winkler-centre'.*restitution = 'recommended'"):
        load_study(study)
    study.write_text('[uncertainty]\nrestitution_range = [1.05, 1.0]\n')
    with pytest.raises(ConfigError, match=r"uncertainty\.restitution_range"):
        load_study(study)
    study.write_text('[uncertainty]\nmodel_quality = "excellent"\n')
    with pytest.raises(ConfigError, match=r"uncertainty\.model_quality"):
        load_study(study)


# ---------------------------------------------------------------- calibration of the members

def _stiffness(block, soils, models=None):
    """K [N/m] of each (soil, block, model) as the study runs it: the stiffness members' own (eq. 19)."""
    models = models or sample_models()
    return np.array([[[member_stiffness(SOILS[s], block, DEFAULT_DESIGN, split_variant(m)[1] or "centre")
                       for m in models]] for s in soils])


def test_reachable_band_targets_are_hit_by_free_rocking_within_the_tolerance():
    stiffness = _stiffness(PAPER, ["clay", "rock"])  # centre, restitution low, restitution high
    calibration = calibrate_models([PAPER], ["clay", "rock"], stiffness[..., :3], sample_models()[:3],
                                   "recommended", DEFAULT_DESIGN, "two-spring")
    assert not calibration.moved[0].any()  # on clay the paper block's bed reaches the whole range ...
    assert calibration.moved[1].tolist() == [[True, False, True]]  # ... on rock only Housner's value
    for s in range(2):
        for v in range(3):
            measured = free_rocking_restitution(PAPER, float(stiffness[s, 0, v]), "two-spring",
                                                float(calibration.xi[s, 0, v]))
            target = calibration.target[s, 0, v]
            assert abs(measured - target) <= tolerance(target)
            # at an admissible xi: the smallest, on clay, is above the 0.15 the study used to impose (r spreads 2.4 %
            # between launches 0.5 and 0.6 alpha at 0.158), and each variant's xi passes the checks itself
            assert calibration.xi[s, 0, v] >= calibration.smallest_xi[s, 0]
            assert stability(PAPER, float(stiffness[s, 0, v]), "two-spring",
                             float(calibration.xi[s, 0, v])).admissible
    assert calibration.smallest_xi[0, 0] > 0.15 and not stability(PAPER, float(stiffness[0, 0, 0]), "two-spring",
                                                                    0.158).admissible


def test_a_range_end_the_bed_cannot_reach_runs_at_the_nearest_reachable_r_and_says_so():
    stiffness = _stiffness(CABINET, ["steel"])[..., :3]
    calibration = calibrate_models([CABINET], ["steel"], stiffness, sample_models()[:3], "recommended",
                                   DEFAULT_DESIGN, "two-spring")
    low, high = calibration.reachable[0, 0]
    assert calibration.requested[0, 0, 2] == pytest.approx(1.05 * CABINET.housner_restitution())
    assert calibration.requested[0, 0, 2] > high  # a stiff two-spring bed stays near Housner's value
    assert high == pytest.approx(CABINET.housner_restitution(), abs=0.005)
    assert calibration.target[0, 0, 2] == pytest.approx(high)
    assert calibration.moved[0, 0].tolist() == [True, False, True]  # centre and high end moved, Housner's r hit
    # not the bouncing regime: the smallest admissible xi of this bed, below which r moves with the launch
    assert calibration.xi.min() >= calibration.smallest_xi[0, 0] == admissible_xi(CABINET, float(stiffness[0, 0, 0]),
                                                                                  "two-spring").smallest
    # the bed really rocks at the target it says it runs at
    target = calibration.target[0, 0, 2]
    measured = free_rocking_restitution(CABINET, float(stiffness[0, 0, 2]), "two-spring",
                                        float(calibration.xi[0, 0, 2]))
    assert abs(measured - target) <= tolerance(target)


def test_a_squat_block_whose_restitution_the_measure_cannot_resolve_runs_at_its_smallest_admissible_xi():
    skid = Block(name="skid", b=1.5, h=2.0, mass=30000.0, E_b=30e9, footprint_area=6.0, soil_depth=1.5)
    stiffness = _stiffness(skid, ["clay"])[..., :3]
    calibration = calibrate_models([skid], ["clay"], stiffness, sample_models()[:3], "recommended", DEFAULT_DESIGN,
                                   "two-spring")
    assert np.isnan(calibration.target).all() and calibration.moved.all()
    smallest = admissible_xi(skid, float(stiffness[0, 0, 0]), "two-spring").smallest
    assert np.all(calibration.xi == smallest) and calibration.smallest_xi[0, 0] == smallest
    assert len(calibration.notes) == 3 and all("dies below the measure's resolution" in n for n in calibration.notes)
    # at that xi the free rocking really decays below the measure's floor: fewer than two peaks above 0.1 alpha
    for fraction in (0.5, 0.6, 0.7):
        assert np.isnan(free_rocking_restitution(skid, float(stiffness[0, 0, 0]), "two-spring", smallest,
                                                 fraction=fraction))


def test_a_single_target_the_bed_cannot_reach_is_an_error_naming_block_and_soil():
    stiffness = _stiffness(CABINET, ["steel"], ["winkler"])
    with pytest.raises(SolverError, match=r"block 'cabinet' on soil 'steel'.*reach"):
        calibrate_models([CABINET], ["steel"], stiffness, ["winkler"], 0.99, DEFAULT_DESIGN, "two-spring")


def test_checkpoint_keys_tell_the_members_and_the_design_apart():
    config = load_study(overrides={"soils": ["clay"], "blocks": ["slender-cabinet"]})
    assert restitution_key(config, "housner") == {}
    record = type("R", (), {"metadata": {"sha256": "x"}, "id": "x"})()
    recipe = type("P", (), {"as_dict": lambda self: {}})()
    keys = {c.model: c.key for c in cells_for_record(record, config, recipe)}
    assert len({keys[m] for m in sample_models()}) == len(MEMBERS)
    wider = load_study(overrides={"soils": ["clay"], "blocks": ["slender-cabinet"],
                                  "uncertainty": {"stiffness_factor": 1.5}})
    wider_keys = {c.model: c.key for c in cells_for_record(record, wider, recipe)}
    assert wider_keys["housner"] == keys["housner"]
    assert wider_keys["recommended-stiffness_high"] != keys["recommended-stiffness_high"]


# ---------------------------------------------------------------- the recommended curve and its model uncertainty

CENTRE = 0.9
MEMBER_MEDIANS = {"restitution_low": 0.5, "restitution_high": 1.6, "friction_low": 0.7, "friction_high": 1.2,
                  "stiffness_low": 0.9, "stiffness_high": 0.9}  # overturning medians [g]; stiffness moves nothing
BETA_RTR = 0.35


def sample_cube(seed=5, n_records=400, medians=None):
    """Outcomes of the central member, its six members and housner from known lognormal overturning capacities."""
    medians = {"housner": 1.1, RECOMMENDED: CENTRE,
               **{f"{RECOMMENDED}-{m}": v for m, v in (medians or MEMBER_MEDIANS).items()}}
    rng = np.random.default_rng(seed)
    levels = np.geomspace(0.1, 6.0, 36)
    z = rng.normal(size=n_records)
    outcomes, ratios = [], []
    for median in medians.values():
        capacity = median * np.exp(BETA_RTR * z)
        over = levels[None, :] >= capacity[:, None]
        outcomes.append(np.where(over, OUTCOME_OVERTURNED, np.where(levels[None, :] > 0.2, OUTCOME_ROCKING,
                                                                    OUTCOME_NO_UPLIFT)))
        ratios.append(np.where(over, 2.0, np.where(levels[None, :] >= 0.6 * capacity[:, None], 0.7, 0.05)))
    dims = ("record", "im_level", "soil", "block", "model")
    stack = lambda arrays: np.stack(arrays, axis=-1)[:, :, None, None, :]  # noqa: E731
    coords = {"record": np.arange(n_records).astype(str), "im_level": ("im_level", levels, {"units": "g"}),
              "soil": ["sand"], "block": ["b-1"], "model": list(medians),
              "block_alpha": ("block", [np.arctan(0.2)])}
    return members_apart(xr.Dataset({"peak_angle_ratio": (dims, stack(ratios)),
                                     "outcome": (dims, stack(outcomes).astype(np.int8))},
                                    coords=coords, attrs={"intensity_measure": "pga"}))


@pytest.fixture(scope="module")
def sample_fit():
    return fragility_dataset(sample_cube(), n_bootstrap=0)


def overturning(fit, model=RECOMMENDED):
    return fit.sel(model=model, soil="sand", block="b-1", damage_state="overturning")


def test_the_cube_keeps_the_members_apart_and_gives_them_back():
    cube = sample_cube(n_records=20)
    assert list(cube.model.values) == ["housner", RECOMMENDED]
    assert list(cube.member.values) == list(MEMBER_MEDIANS)
    assert cube.member_outcome.attrs["long_name"].startswith("sample member")
    members = member_cube(cube)
    assert list(members.model.values) == [f"{RECOMMENDED}-{m}" for m in MEMBER_MEDIANS]
    assert np.array_equal(members.outcome.sel(model="recommended-friction_low").values,
                          cube.member_outcome.sel(member="friction_low").values)
    assert member_cube(cube.drop_dims("member")) is None


def test_the_recommended_row_is_the_central_fit_with_the_beta_split(sample_fit):
    row = overturning(sample_fit)
    assert list(sample_fit.model.values) == ["housner", RECOMMENDED]
    assert float(row["median"]) == pytest.approx(CENTRE, rel=0.05)
    assert float(row.beta_record_to_record) == pytest.approx(BETA_RTR, rel=0.1)
    assert float(row.beta_form) == FORM_RATINGS["fair"] == 0.35
    assert float(row.beta) ** 2 == pytest.approx(float(row.beta_record_to_record) ** 2 + float(row.beta_model) ** 2)
    reference = sample_fit.sel(model="housner")
    assert np.all(reference.beta_model.fillna(0) == 0) and np.all(reference.beta_form.fillna(0) == 0)
    assert np.allclose(reference.beta_record_to_record, reference.beta, equal_nan=True)


def test_beta_parameters_is_the_spread_of_a_median_uniform_in_log_over_each_range(sample_fit):
    """Monte Carlo of the claim: ln m = sum over parameters of independent uniforms between its ends' medians."""
    fitted = sample_fit.member_median.sel(soil="sand", block="b-1", damage_state="overturning")
    rng = np.random.default_rng(11)
    n = 400_000
    log_median = sum(rng.uniform(math.log(float(fitted.sel(member=f"{p}_low"))),
                                 math.log(float(fitted.sel(member=f"{p}_high"))), n)
                     for p in ("restitution", "friction", "stiffness"))
    row = overturning(sample_fit)
    assert float(row.beta_parameters) == pytest.approx(np.std(log_median), rel=0.02)
    sensitivity = sample_fit.median_sensitivity.sel(soil="sand", block="b-1", damage_state="overturning")
    assert float(sensitivity.sel(parameter="stiffness")) == pytest.approx(0, abs=0.02)
    assert sample_fit.sensitivity_leading_parameter.sel(soil="sand", block="b-1",
                                                        damage_state="overturning").item() == "restitution"


def test_the_rating_replaces_the_sampled_spread_and_is_not_added_to_it(sample_fit):
    """beta_model = max(beta_form, beta_parameters): 0.35 (fair) is below this sample's ~0.37, 0.50 (poor) above."""
    row = overturning(sample_fit)
    assert float(row.beta_parameters) > FORM_RATINGS["fair"]
    assert float(row.beta_model) == float(row.beta_parameters)
    poor = overturning(fragility_dataset(sample_cube(), n_bootstrap=0, quality="poor"))
    assert float(poor.beta_model) == FORM_RATINGS["poor"] > float(poor.beta_parameters)
    narrow = {m: CENTRE * (1.05 if m.endswith("high") else 0.95) for m in MEMBER_MEDIANS}
    small = overturning(fragility_dataset(sample_cube(medians=narrow), n_bootstrap=0))
    assert float(small.beta_parameters) < 0.1 and float(small.beta_model) == FORM_RATINGS["fair"]
    assert float(small.beta) == pytest.approx(math.hypot(float(small.beta_record_to_record), 0.35))


def test_the_table_carries_the_split(sample_fit):
    table = fragility_table(sample_fit)
    assert {"beta_record_to_record", "beta_parameters", "beta_form", "beta_model"} <= set(table.columns)


def test_a_member_that_never_reaches_the_state_leaves_its_spread_to_the_other_end():
    cube = sample_cube(n_records=200)
    outcome = cube.member_outcome.values.copy()
    high = list(cube.member.values).index("restitution_high")
    outcome[..., high] = np.where(outcome[..., high] == OUTCOME_OVERTURNED, OUTCOME_ROCKING, outcome[..., high])
    cube["member_outcome"] = (cube.member_outcome.dims, outcome)
    fit = fragility_dataset(cube, n_bootstrap=0)
    row = overturning(fit)
    low = float(fit.member_median.sel(member="restitution_low", damage_state="overturning").squeeze())
    highest = float(fit.studied_im_max.squeeze())
    expected = max(2 * abs(math.log(low / float(row["median"]))), abs(math.log(highest / low))) / (2 * math.sqrt(3))
    sensitivity = fit.median_sensitivity.sel(parameter="restitution", damage_state="overturning").squeeze()
    assert float(sensitivity) == pytest.approx(expected)


def test_a_missing_end_bounds_the_spread_from_below_by_the_highest_intensity():
    """Cold read 9, user B4: an end with no median below the highest intensity studied has its median beyond it, so
    the range is at least from the other end to that intensity. The user study's sand overturning: friction's high
    end 1.873 g, centre 1.995 g, low end none by 3.00 g: at least ln(3.00 / 1.873) / (2 sqrt 3) = 0.136, where twice
    the high end's distance to the centre gave 0.036. Where twice the distance is larger it stays (the default's
    squat block on sand: 1.088 g against 2.877 g, 0.561)."""
    from rockfrag.fragility import parameter_spread

    nan = np.nan
    assert float(parameter_spread(np.array(nan), np.array(1.995), np.array(1.873), 3.0)) == pytest.approx(
        math.log(3.0 / 1.873) / (2 * math.sqrt(3)), rel=1e-12)
    assert math.log(3.0 / 1.873) / (2 * math.sqrt(3)) == pytest.approx(0.136, abs=0.001)
    assert float(parameter_spread(np.array(nan), np.array(2.877), np.array(1.088), 3.0)) == pytest.approx(
        0.561, abs=0.001)
    assert float(parameter_spread(np.array(1.2), np.array(1.5), np.array(nan))) == pytest.approx(
        2 * math.log(1.5 / 1.2) / (2 * math.sqrt(3)))  # no highest given: the old rule
    assert np.isnan(parameter_spread(np.array(nan), np.array(1.5), np.array(nan), 3.0))
