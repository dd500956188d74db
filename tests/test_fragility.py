"""Fragility fits against data with known answers: binomial MLE (vectorised, checked against scipy),
censoring, separation, small samples, shared beta, the exact uplift step, extrapolation flags, the
non-crossing rule, bootstrap bounds, both cube layouts, and the pelicun export's conventions."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr
from scipy import optimize, stats
from scipy.optimize import minimize
from scipy.special import log_ndtr
from scipy.stats import norm

from rockfrag.cube import OUTCOME_NO_UPLIFT, OUTCOME_OVERTURNED, OUTCOME_ROCKING
from rockfrag.damage_states import DAMAGE_STATES, damage_states_from_config, families_of, state_family
from rockfrag.fragility import (
    STATUS,
    curves_cross,
    fit_binomial,
    fit_cell,
    fit_censored_capacities,
    fit_independent,
    fit_shared_beta,
    fragility_dataset,
    fragility_table,
    intensity_levels,
    pelicun_id,
    pelicun_table,
    separation,
)
from rockfrag.ida import ida_dataset
from rockfrag.outputs import write_dataset
from rockfrag.units import STANDARD_GRAVITY

UPLIFT_G = 0.2  # g tan(alpha) of the synthetic block [g]


def scipy_fit(levels, exceed, total):
    """Independent reference: Nelder-Mead on the binomial log-likelihood in (ln median, ln beta)."""
    def negative(p):
        z = (np.log(levels) - p[0]) / np.exp(p[1])
        return -np.sum(exceed * log_ndtr(z) + (total - exceed) * log_ndtr(-z))
    result = minimize(negative, [np.log(np.median(levels)), np.log(0.5)], method="Nelder-Mead",
                      options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 20000})
    return np.exp(result.x)


def test_binomial_mle_recovers_known_lognormal():
    rng = np.random.default_rng(42)
    median, beta = 0.6, 0.45
    levels = np.geomspace(0.1, 3.0, 30)
    n = 400
    exceed = rng.binomial(n, norm.cdf(np.log(levels / median) / beta))
    fitted_median, fitted_beta = fit_binomial(levels, exceed, np.full(levels.size, n))
    # standard errors at this sample size are about 1% (median) and 3% (beta)
    assert fitted_median == pytest.approx(median, rel=0.04)
    assert fitted_beta == pytest.approx(beta, rel=0.10)


def test_vectorised_fisher_scoring_equals_a_scipy_refit():
    rng = np.random.default_rng(5)
    levels = np.geomspace(0.05, 3.0, 12)
    exceed = rng.binomial(15, norm.cdf(np.log(levels / 0.7) / 0.5), size=(8, levels.size)).astype(float)
    total = np.full_like(exceed, 15.0)
    total[:, 3] = 0  # a level without valid runs is ignored
    exceed[:, 3] = 0
    medians, betas = fit_independent(levels, exceed, total)
    for i in range(8):
        if betas[i] == 0 or not np.isfinite(betas[i]):
            continue
        reference = scipy_fit(levels, exceed[i], total[i])
        np.testing.assert_allclose([medians[i], betas[i]], reference, rtol=1e-5)


def test_censored_capacity_fit_recovers_known_lognormal():
    rng = np.random.default_rng(7)
    median, beta, censor = 1.0, 0.5, 1.5
    capacities = np.exp(rng.normal(np.log(median), beta, 3000))
    observed = np.where(capacities <= censor, capacities, np.nan)  # about 21% censored
    assert 0.15 < np.isnan(observed).mean() < 0.3
    fitted_median, fitted_beta = fit_censored_capacities(observed, censor)
    assert fitted_median == pytest.approx(median, rel=0.04)
    assert fitted_beta == pytest.approx(beta, rel=0.06)
    # ignoring the censoring would bias the median low: the censored fit must do better
    naive = np.exp(np.nanmean(np.log(observed)))
    assert abs(naive - median) > 2 * abs(fitted_median - median)


def test_unidentifiable_data_gives_nan():
    levels = np.array([0.1, 0.2, 0.3])
    assert np.isnan(fit_binomial(levels, [0, 0, 0], [10, 10, 10])[0])
    assert np.isnan(fit_binomial(levels, [10, 10, 10], [10, 10, 10])[0])


def test_separated_data_are_a_step_between_the_bracketing_levels_not_a_small_beta():
    levels = np.array([0.1, 0.2, 0.4, 0.8])
    median, beta = fit_binomial(levels, [0, 0, 4, 4], [4, 4, 4, 4])
    assert beta == 0.0 and median == pytest.approx(np.sqrt(0.2 * 0.4))
    # quasi-complete separation: one mixed level, zeros below, all above -> the step sits at it
    median, beta = fit_binomial(levels, [0, 1, 4, 4], [4, 4, 4, 4])
    assert beta == 0.0 and median == pytest.approx(0.2)
    # two mixed levels: an ordinary MLE with beta > 0
    assert separation(np.array([0, 1, 3, 4.0]), np.full(4, 4.0))[0] == np.False_
    assert fit_binomial(levels, [0, 1, 3, 4], [4, 4, 4, 4])[1] > 0.05
    # a step at the highest (or lowest) level with the median beyond it (at most half the records in the state at
    # the highest, at least half at the lowest) only says the median lies outside the range: no estimate
    assert np.isnan(fit_binomial(levels, [0, 0, 0, 1], [4, 4, 4, 4])[0])
    assert np.isnan(fit_binomial(levels, [3, 4, 4, 4], [4, 4, 4, 4])[0])
    assert np.isnan(fit_binomial(levels, [0, 0, 0, 2], [4, 4, 4, 4])[0])
    assert np.isnan(fit_binomial(levels, [2, 4, 4, 4], [4, 4, 4, 4])[0])
    assert np.isnan(fit_binomial(levels[:1], [1], [4])[0])  # one level: nothing brackets the median
    # ...but a mixed edge level on the median's near side brackets it inside the range: the step sits at that level,
    # as it does at an interior mixed level (1 of 4 at the lowest, 4 of 4 above; 3 of 4 at the highest, none below)
    assert fit_binomial(levels, [1, 4, 4, 4], [4, 4, 4, 4]) == (pytest.approx(0.1), 0.0)
    assert fit_binomial(levels, [0, 0, 0, 3], [4, 4, 4, 4]) == (pytest.approx(0.8), 0.0)
    # the same through the vectorised fit (a stack of data sets, as the bootstrap fits them)
    stack = np.array([[1, 4, 4, 4], [3, 4, 4, 4], [0, 0, 0, 3.0]])
    medians, _ = fit_independent(levels, stack, np.full((3, 4), 4.0))
    np.testing.assert_array_equal(np.isnan(medians), [False, True, False])
    np.testing.assert_allclose(medians[[0, 2]], [0.1, 0.8])


def test_shared_beta_fit_recovers_known_medians_and_common_beta():
    rng = np.random.default_rng(11)
    levels = np.geomspace(0.1, 4.0, 25)
    truth = np.array([0.4, 0.7, 1.2])
    exceed = np.stack([rng.binomial(300, norm.cdf(np.log(levels / m) / 0.35)) for m in truth]).astype(float)
    medians, beta = fit_shared_beta(levels, exceed, np.full_like(exceed, 300.0))
    np.testing.assert_allclose(medians, truth, rtol=0.04)
    assert beta == pytest.approx(0.35, rel=0.08)


def synthetic_cube(seed=3, n_records=300, levels=None, rocking_beta=0.4, alpha_known=True, model="ssi"):
    """Outcomes drawn from known lognormal capacities: rocking-0.2 at 0.4 g, rocking-0.5 at 0.6 g,
    overturning at 0.9 g (common beta 0.4); every record uplifts above UPLIFT_G = g tan(alpha)."""
    rng = np.random.default_rng(seed)
    levels = np.geomspace(0.05, 3.0, 25) if levels is None else np.asarray(levels)
    z = rng.normal(size=n_records)  # one capacity factor per record keeps the states ordered
    cap02, cap05, cap_over = (m * np.exp(rocking_beta * z) for m in (0.4, 0.6, 0.9))
    im = levels[None, :]
    ratio = np.where(im >= cap05[:, None], 0.7, np.where(im >= cap02[:, None], 0.3, 0.05))
    outcome = np.where(im >= cap_over[:, None], OUTCOME_OVERTURNED,
                       np.where(im > UPLIFT_G, OUTCOME_ROCKING, OUTCOME_NO_UPLIFT))
    dims = ("record", "im_level", "soil", "block", "model")
    expand = (slice(None), slice(None), None, None, None)
    coords = {"record": np.arange(n_records).astype(str), "im_level": ("im_level", levels, {"units": "g"}),
              "soil": ["sand"], "block": ["b-1"], "model": [model]}
    if alpha_known:
        coords["block_alpha"] = ("block", [np.arctan(UPLIFT_G)])
    return xr.Dataset({"peak_angle_ratio": (dims, ratio[expand]),
                       "outcome": (dims, outcome.astype(np.int8)[expand])},
                      coords=coords, attrs={"intensity_measure": "pga"})


@pytest.fixture(scope="module")
def fitted():
    return fragility_dataset(synthetic_cube(), n_bootstrap=40, seed=1)


def test_cube_fit_recovers_medians_and_uplift_is_the_exact_step(fitted):
    cell = fitted.isel(soil=0, block=0, model=0)
    medians = cell["median"].to_series()
    assert medians["uplift"] == pytest.approx(UPLIFT_G, rel=1e-12)  # g tan(alpha), not between two levels
    assert cell.beta.sel(damage_state="uplift").item() == 0.0
    assert cell.status.sel(damage_state="uplift").item() == "deterministic-threshold"
    assert medians["rocking-0.2"] == pytest.approx(0.4, rel=0.08)
    assert medians["rocking-0.5"] == pytest.approx(0.6, rel=0.08)
    assert medians["overturning"] == pytest.approx(0.9, rel=0.08)
    assert cell["beta"].sel(damage_state="overturning").item() == pytest.approx(0.4, rel=0.15)
    assert set(cell.status.values) <= set(STATUS)
    assert not cell.extrapolated.values.any()
    ordered = [(medians[s], cell["beta"].sel(damage_state=s).item())
               for s in ("rocking-0.2", "rocking-0.5", "overturning")]
    assert not curves_cross(np.geomspace(0.05, 3.0, 400), ordered)
    np.testing.assert_allclose(cell.outcome_probability.sum("outcome_class").values, 1.0)


def test_runs_that_contradict_the_exact_uplift_step_are_reported():
    cube = synthetic_cube(n_records=40)
    outcome = cube.outcome.values
    below = np.flatnonzero(cube.im_level.values < UPLIFT_G)[-1]
    outcome[:5, below] = OUTCOME_ROCKING  # five records "uplift" below g tan(alpha)
    row = fragility_dataset(cube, n_bootstrap=0).isel(soil=0, block=0, model=0).sel(damage_state="uplift")
    assert row.status.item() == "deterministic-threshold"
    assert "disagree with the exact g tan(alpha) step" in row.fit_warning.item()


def test_bootstrap_bounds_contain_the_point_estimate(fitted):
    fitted_rows = fitted.status.isin(["fitted", "extrapolated"])
    for name, low, high in (("median", "median_low", "median_high"), ("beta", "beta_low", "beta_high")):
        point, lower, upper = (fitted[v].where(fitted_rows).values.ravel() for v in (name, low, high))
        keep = np.isfinite(point)
        assert keep.sum() >= 3
        assert np.all(lower[keep] <= point[keep]) and np.all(point[keep] <= upper[keep]), name
        assert np.all(upper[keep] > lower[keep])


def test_shared_beta_rows_bootstrap_the_shared_fit_and_report_its_cost():
    # a noisy small sample whose independent fits cross inside the data range
    rng = np.random.default_rng(0)
    levels = np.geomspace(0.2, 2.0, 10)
    n = 60
    cube = synthetic_cube(seed=9, n_records=n, levels=levels)
    ratio = cube.peak_angle_ratio.values
    # rocking-0.5 becomes a much wider curve than rocking-0.2: independent fits cross at high levels
    wide = np.exp(rng.normal(np.log(0.65), 1.2, n))[:, None]
    ratio[..., 0, 0, 0] = np.where(levels[None, :] >= wide, 0.7, np.minimum(ratio[..., 0, 0, 0], 0.3))
    ratio[..., 0, 0, 0] = np.where(ratio[..., 0, 0, 0] >= 0.5, ratio[..., 0, 0, 0],
                                   np.where(levels[None, :] >= 0.4 * np.exp(0.1 * rng.normal(size=(n, 1))), 0.3, 0.05))
    fragility = fragility_dataset(cube, n_bootstrap=60, seed=2)
    cell = fragility.isel(soil=0, block=0, model=0)
    shared = cell.fit_method.values == "mle-binomial-shared-beta"
    assert shared.sum() >= 2
    betas = cell.beta.values[shared]
    assert np.allclose(betas, betas[0])  # one beta
    cost = cell.noncrossing_deviance_cost.values[shared]
    assert np.all(cost >= -1e-6) and cost.sum() > 0  # the constraint costs deviance, reported
    assert np.all(cell.beta_low.values[shared] <= betas) and np.all(betas <= cell.beta_high.values[shared])
    assert np.all(cell.median_low.values[shared] <= cell["median"].values[shared])
    assert np.all(cell["median"].values[shared] <= cell.median_high.values[shared])


def test_tail_overlap_below_the_first_exceedance_does_not_trigger_the_shared_fit():
    levels = np.geomspace(0.05, 3.0, 30)
    # rocking-0.5 has a much wider beta: far below its first exceedance its tail exceeds rocking-0.2's
    n = 400
    rng = np.random.default_rng(1)
    e02 = rng.binomial(n, norm.cdf(np.log(levels / 0.4) / 0.15))
    e05 = np.where(levels >= 0.45, rng.binomial(n, norm.cdf(np.log(levels / 0.9) / 0.3)), 0)
    states = [DAMAGE_STATES["rocking-0.2"], DAMAGE_STATES["rocking-0.5"]]
    exceed = np.stack([e02, e05]).astype(float)
    rows, groups = fit_cell(levels, exceed, np.full_like(exceed, n), states)
    assert [row.method for row in rows] == ["mle-binomial", "mle-binomial"]
    assert all(len(g) == 1 for g in groups)


def test_extrapolated_and_not_reached_rows_are_flagged_everywhere(tmp_path):
    levels = np.geomspace(0.05, 0.55, 12)  # overturning (0.9 g) far above the highest level
    fragility = fragility_dataset(synthetic_cube(levels=levels, n_records=200), n_bootstrap=5)
    cell = fragility.isel(soil=0, block=0, model=0)
    status = cell.status.to_series()
    if status["overturning"] != "not-reached":
        assert status["overturning"] == "extrapolated" and cell.extrapolated.sel(damage_state="overturning") == 1
    medians = cell["median"].where(cell.status == "fitted").values
    assert np.all((medians[np.isfinite(medians)] >= levels[0]) & (medians[np.isfinite(medians)] <= levels[-1]))
    # beyond the data: no record reaches a state above the range
    high = fragility_dataset(synthetic_cube(levels=np.geomspace(0.05, 0.3, 8), n_records=50), n_bootstrap=0)
    row = high.isel(soil=0, block=0, model=0).sel(damage_state="overturning")
    assert row.status.item() in ("not-reached", "above-range") and np.isnan(row["median"].item())
    assert "not reached" in row.fit_warning.item() or "above" in row.fit_warning.item()
    table = fragility_table(fragility)
    assert {"status", "extrapolated", "im_lowest", "im_highest", "fit_warning"} <= set(table.columns)
    assert table.im_highest.iloc[0] == pytest.approx(levels[-1])
    path = tmp_path / "f.nc"
    write_dataset(fragility, path)
    with xr.open_dataset(path) as back:
        assert back.extrapolated.attrs["units"] == "1" and back.studied_im_max.attrs["units"] == "9.80665 m s-2"
        assert all("long_name" in back[v].attrs for v in back.data_vars)


def test_small_samples_warn_visibly():
    fragility = fragility_dataset(synthetic_cube(n_records=6), n_bootstrap=5)
    warnings = json.loads(fragility.attrs["fit_warnings"])
    assert any("fewer than 10" in line for line in warnings)
    fitted_rows = fragility.fit_warning.where(np.isfinite(fragility["median"]) & (fragility.beta > 0), "")
    assert all("fewer than 10" in w for w in fitted_rows.values.ravel() if w)
    assert not np.any((fragility.beta.values > 0) & (fragility.beta.values < 0.02))  # never a silent beta floor


def test_a_model_whose_uplift_is_not_the_rigid_threshold_is_fitted():
    fragility = fragility_dataset(synthetic_cube(model="winkler"), n_bootstrap=0)
    row = fragility.isel(soil=0, block=0, model=0).sel(damage_state="uplift")
    assert row.status.item() != "deterministic-threshold"
    assert row.fit_method.item() in ("step-between-levels", "mle-binomial")


def test_per_block_intensity_layout_gives_the_same_fits():
    single = synthetic_cube(n_records=120)
    levels = single.im_level.values
    per_block = single.assign_coords(im_level=np.arange(levels.size) + 1.0)
    per_block = per_block.assign_coords(intensity=(("block", "im_level"), levels[None, :], {"units": "g"}))
    intensity, unit = intensity_levels(per_block)
    np.testing.assert_allclose(intensity[0], levels)
    assert unit == "9.80665 m s-2"  # an older file's "g" comes back as UDUNITS reads it
    a = fragility_dataset(single, n_bootstrap=10, seed=3)
    b = fragility_dataset(per_block, n_bootstrap=10, seed=3)
    np.testing.assert_allclose(a["median"].values, b["median"].values)
    np.testing.assert_allclose(a.median_high.values, b.median_high.values)


def test_si_intensity_coordinate_is_read_in_display_units():
    cube = synthetic_cube(n_records=20).assign_coords(im_level=np.arange(25.0))
    si = np.geomspace(0.05, 3.0, 25)[None, :] * STANDARD_GRAVITY
    cube = cube.assign_coords(im_level_si=(("block", "im_level"), si, {"units": "m/s^2"}),
                              im_level=("im_level", np.arange(25.0), {"units": "1"}))
    intensity, unit = intensity_levels(cube)
    np.testing.assert_allclose(intensity[0], np.geomspace(0.05, 3.0, 25))
    assert unit == "9.80665 m s-2"


def test_bootstrap_is_seeded():
    a = fragility_dataset(synthetic_cube(), n_bootstrap=10, seed=5)
    b = fragility_dataset(synthetic_cube(), n_bootstrap=10, seed=5)
    xr.testing.assert_identical(a, b)


def test_curves_cross_ignores_differences_below_tolerance():
    levels = np.geomspace(0.1, 3, 20)
    assert curves_cross(levels, [(0.5, 0.2), (0.7, 0.8)])  # a wide curve for the more severe state crosses
    assert not curves_cross(levels, [(0.5, 0.4), (0.7, 0.4)])


def test_user_damage_state():
    states = damage_states_from_config({"damage_states": {"rocking-0.8": {"edp": "peak_angle_ratio",
                                                                          "threshold": 0.8}}})
    names = [s.name for s in states]
    assert set(names) == {*DAMAGE_STATES, "rocking-0.8"}  # every registered state (an installed plugin's too)
    assert names.index("rocking-0.5") < names.index("rocking-0.8") < names.index("overturning") == len(names) - 1
    assert names[0] == "uplift"
    assert "rocking-0.8" not in DAMAGE_STATES  # the registry itself is not changed by a study


def test_pelicun_table_follows_its_conventions(fitted):
    table = pelicun_table(fitted)
    assert list(table.columns[:6]) == ["ID", "Incomplete", "Demand-Type", "Demand-Unit", "Demand-Offset",
                                       "Demand-Directional"]
    row = table.iloc[0]
    # pelicun splits IDs on '-': none inside our segments
    assert row["ID"] == "ROCK.b_1.sand.ssi" and "-" not in row["ID"]
    assert pelicun_id("slender-cabinet", "clay", "ssi-paper") == "ROCK.slender_cabinet.clay.ssi_paper"
    assert row["Demand-Type"] == "Peak Ground Acceleration" and row["Demand-Unit"] == "g"
    assert row["Demand-Directional"] == 1  # our demand is the scaled component: no 1.2 factor
    assert row["LS1-Family"] == "deterministic" and row["LS1-Theta_0"] == pytest.approx(UPLIFT_G)
    assert row["LS2-Family"] == "lognormal"
    thetas = [row[f"LS{i}-Theta_0"] for i in range(1, 5)]
    assert thetas == sorted(thetas)  # limit states in increasing severity
    assert "studied range 0.05-3 g" in row["Comment"] and "LS1 uplift: deterministic-threshold" in row["Comment"]


@pytest.mark.parametrize("measure, period, demand", [
    ("pga", 1.0, ("Peak Ground Acceleration", "g")), ("pgv", None, ("Peak Ground Velocity", "mps")),
    ("sa", 0.5, ("Spectral Acceleration|0.5", "g")), ("sa", None, ("Spectral Acceleration", "g")),
])
def test_pelicun_demand_comes_from_the_measure_registry(fitted, measure, period, demand):
    dataset = fitted.assign_attrs(intensity_measure=measure)
    row = pelicun_table(dataset, period).iloc[0]
    assert (row["Demand-Type"], row["Demand-Unit"]) == demand


@pytest.mark.parametrize("measure", ["avgsa", "cav", "no-such-measure"])
def test_pelicun_leaves_out_the_rows_of_a_measure_it_has_no_demand_for(fitted, measure):
    from rockfrag.exchange import ExchangeWarning

    with pytest.warns(ExchangeWarning) as caught:  # pelicun 3.10 refuses an empty Demand-Type: no row at all
        table = pelicun_table(fitted.assign_attrs(intensity_measure=measure), 1.0)
    assert table.empty and len(caught) == 1
    message = str(caught[0].message)
    assert "\n" not in message and repr(measure) in message and "left out" in message


# ---------------------------------------------------------------- overturning: first-overturn convention

def capacity_cube(outcomes, capacities, levels, lower=None, record_im=0.5):
    """One soil, block and model: outcomes (record, level) over the block's ``levels`` [g] and the refined
    capacities [g] (NaN: never overturned, survived up to ``lower``) as the study writes them (scale factors x
    the record's PGA, ``units`` as UDUNITS reads them)."""
    outcomes = np.asarray(outcomes, np.int8)
    n_record, n_level = outcomes.shape
    capacities = np.asarray(capacities, float)
    lower = np.where(np.isfinite(capacities), 0.98 * capacities, np.nan) if lower is None else np.asarray(lower)
    g = "9.80665 m s-2"
    dims = ("record", "im_level", "soil", "block", "model")
    ratio = np.where(outcomes == OUTCOME_ROCKING, 0.6, 0.0)
    per_cell = (slice(None), None, None, None)
    return xr.Dataset(
        {"outcome": (dims, outcomes[:, :, None, None, None]),
         "peak_angle_ratio": (dims, ratio[:, :, None, None, None]),
         "capacity_scale_factor": (("record", "soil", "block", "model"), (capacities / record_im)[per_cell]),
         "capacity_scale_lower": (("record", "soil", "block", "model"), (lower / record_im)[per_cell]),
         "capacity_scale_upper": (("record", "soil", "block", "model"), (1.02 * capacities / record_im)[per_cell]),
         "capacity_runs": (("record", "soil", "block", "model"), np.full((n_record, 1, 1, 1), 5.0))},
        coords={"record": [f"r{i}" for i in range(n_record)],
                "im_level": ("im_level", np.arange(1.0, n_level + 1), {"units": "1"}),
                "soil": ["clay"], "block": ["cabinet"], "model": ["winkler"],
                "intensity": (("block", "im_level"), np.asarray(levels, float)[None, :], {"units": g}),
                "record_im": (("record", "block"), np.full((n_record, 1), record_im), {"units": g}),
                "block_uplift_acceleration": ("block", [0.2], {"units": g})},
        attrs={"intensity_measure": "pga", "capacity_resolution": 0.02})


N, R, OT = OUTCOME_NO_UPLIFT, OUTCOME_ROCKING, OUTCOME_OVERTURNED
RESURRECTING_LEVELS = [0.3, 0.48, 0.6, 0.9, 1.2, 1.5]
# first overturning stripes 0.48, 0.90 and 0.48 g (the three records); r0 and r1 survive higher levels
RESURRECTING = [[R, OT, R, R, R, OT], [R, R, R, OT, R, OT], [R, OT, R, OT, OT, OT]]
REFINED = [0.45, 0.70, 0.40]  # each inside its first overturning gap


def test_resurrection_is_reported_not_fitted_into_a_median_above_every_capacity(tmp_path):
    cube = capacity_cube(RESURRECTING, REFINED, RESURRECTING_LEVELS)
    ida = ida_dataset(cube)
    np.testing.assert_allclose(ida.capacity.values.ravel(), REFINED)
    assert np.all(ida.capacity.values <= ida.first_overturn_im.values)  # refined inside the first gap
    assert ida.resurrected.values.ravel().tolist() == [1, 1, 1]
    fragility = fragility_dataset(cube, ida=ida, n_bootstrap=20)
    row = fragility.isel(soil=0, block=0, model=0).sel(damage_state="overturning")
    assert row["median"].item() <= max(REFINED)
    assert row.capacity_median.item() <= max(REFINED)
    # the test can fail: the raw stripe counts (2, 0, 2, 1, 3 of 3 from 0.48 g) put the median above them all
    raw = (np.asarray(RESURRECTING) == OT).sum(0)
    assert fit_binomial(np.asarray(RESURRECTING_LEVELS), raw, np.full(raw.size, 3))[0] > max(REFINED)
    # a record counts as overturned from its first overturning level on, for every damage state
    fraction = fragility.empirical_fraction.isel(soil=0, block=0, model=0)
    np.testing.assert_allclose(fraction.sel(damage_state="overturning").values, [0, 2 / 3, 2 / 3, 1, 1, 1])
    assert (fraction.sel(damage_state="rocking-0.5") >= fraction.sel(damage_state="overturning")).all()
    overturned = fragility.outcome_probability.sel(outcome_class="overturned").isel(soil=0, block=0, model=0)
    np.testing.assert_allclose(overturned.values, [0, 2 / 3, 2 / 3, 1, 1, 1])
    # reported: a count per cell, a warning on the row and for the console, and the convention
    assert int(fragility.n_resurrected.item()) == 3
    assert "3 of 3 records survived a level above their first overturning" in row.fit_warning.item()
    assert any("overturned at one level but not at a higher one" in line
               for line in json.loads(fragility.attrs["fit_warnings"]))
    assert "first overturning" in fragility.attrs["overturning_convention"]
    table = fragility_table(fragility)
    assert (table.n_resurrected == 3).all() and (table.im_units == "g").all()


def test_capacity_fit_is_the_lognormal_mle_of_the_refined_capacities():
    """Complete capacities: the closed-form MLE on ln c (mean, standard deviation with divisor n)."""
    cube = capacity_cube(RESURRECTING, REFINED, RESURRECTING_LEVELS)
    fragility = fragility_dataset(cube, ida=ida_dataset(cube), n_bootstrap=0)
    row = fragility.isel(soil=0, block=0, model=0).sel(damage_state="overturning")
    logs = np.log(REFINED)
    assert row.capacity_median.item() == pytest.approx(np.exp(logs.mean()), rel=1e-6)
    assert row.capacity_beta.item() == pytest.approx(logs.std(ddof=0), rel=1e-6)
    assert row.capacity_median.attrs["units"] == "9.80665 m s-2"


def test_censored_capacity_fit_matches_an_independent_scipy_refit():
    """Two of eight records never overturn: right-censored at the highest intensity each survived."""
    levels = [0.2, 0.4, 0.8, 1.6]
    capacities = np.array([0.35, 0.5, 0.62, 0.75, 1.1, 1.45, np.nan, np.nan])
    lower = np.where(np.isfinite(capacities), 0.98 * capacities, [0, 0, 0, 0, 0, 0, 2.1, 2.6])
    first = [np.searchsorted(levels, c) if np.isfinite(c) else len(levels) for c in capacities]
    outcomes = [[OT if j >= f else R for j in range(len(levels))] for f in first]
    cube = capacity_cube(outcomes, capacities, levels, lower=lower)
    ida = ida_dataset(cube)
    fragility = fragility_dataset(cube, ida=ida, n_bootstrap=0)
    row = fragility.isel(soil=0, block=0, model=0).sel(damage_state="overturning")
    refined = ida.capacity.values.ravel()
    survived = ida.capacity_lower.values.ravel()
    data = stats.CensoredData(uncensored=refined[np.isfinite(refined)], right=survived[~np.isfinite(refined)])

    def tight(func, x0, args=(), disp=0):
        return optimize.fmin(func, x0, args=args, xtol=1e-13, ftol=1e-15, maxiter=100000, maxfun=100000, disp=0)

    beta, _, median = stats.lognorm.fit(data, floc=0, optimizer=tight)
    assert row.capacity_median.item() == pytest.approx(median, rel=1e-6)
    assert row.capacity_beta.item() == pytest.approx(beta, rel=1e-6)
    assert row.capacity_median.item() > np.exp(np.nanmean(np.log(capacities)))  # censoring raises the median


def test_families_nest_by_edp_in_one_rule():
    """Slip states are one family, every other EDP (uplift, angles, overturning) the rocking one, in given order."""
    edps = ["uplifted", "peak_slip", "peak_slip", "peak_angle_ratio", "overturned"]
    assert families_of(edps) == {"rocking": [0, 3, 4], "slip": [1, 2]}
    assert families_of(["uplifted", "overturned"]) == {"rocking": [0, 1]}
    assert {state_family(s) for s in DAMAGE_STATES.values() if s.edp == "peak_slip"} == {"slip"}
