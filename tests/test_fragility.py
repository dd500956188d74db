"""Fragility fits recover known lognormals; censoring; non-crossing; pelicun columns; risk closed form."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy.stats import norm

from pipeline.cube import OUTCOME_NO_UPLIFT, OUTCOME_OVERTURNED, OUTCOME_ROCKING
from pipeline.fragility import (DAMAGE_STATES, curves_cross, damage_states_from_config, fit_binomial,
                                fit_censored_capacities, fragility_dataset, pelicun_table)
from pipeline.risk import annual_frequency, load_hazard, probability_in_life


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


def synthetic_cube(seed=3, n_records=300):
    """Outcomes drawn from known lognormal capacities: rocking-0.2 at 0.4 g, rocking-0.5 at 0.6 g,
    overturning at 0.9 g (common beta 0.4); uplift at 0.2 g for every record."""
    rng = np.random.default_rng(seed)
    levels = np.geomspace(0.05, 3.0, 25)
    z = rng.normal(size=n_records)  # one capacity factor per record keeps the states ordered
    cap02, cap05, cap_over = (m * np.exp(0.4 * z) for m in (0.4, 0.6, 0.9))
    im = levels[None, :]
    ratio = np.where(im >= cap05[:, None], 0.7, np.where(im >= cap02[:, None], 0.3, 0.05))
    outcome = np.where(im >= cap_over[:, None], OUTCOME_OVERTURNED, np.where(im >= 0.2, OUTCOME_ROCKING,
                                                                              OUTCOME_NO_UPLIFT))
    dims = ("record", "im_level", "soil", "block", "model")
    expand = (slice(None), slice(None), None, None, None)
    return xr.Dataset({"peak_angle_ratio": (dims, ratio[expand]), "outcome": (dims, outcome.astype(np.int8)[expand])},
                      coords={"record": np.arange(n_records).astype(str),
                              "im_level": ("im_level", levels, {"units": "g"}),
                              "soil": ["sand"], "block": ["b"], "model": ["ssi"]},
                      attrs={"intensity_measure": "pga"})


def test_cube_fit_recovers_medians_and_orders_states():
    fragility = fragility_dataset(synthetic_cube(), n_bootstrap=20, seed=1)
    cell = fragility.isel(soil=0, block=0, model=0)
    medians = cell["median"].to_series()
    levels = fragility.im_level.values
    below, above = levels[levels < 0.2].max(), levels[levels >= 0.2].min()
    assert below <= medians["uplift"] <= above  # a step between the two levels around 0.2 g
    assert cell.fit_method.sel(damage_state="uplift").item() == "deterministic-threshold"
    assert medians["rocking-0.2"] == pytest.approx(0.4, rel=0.08)
    assert medians["rocking-0.5"] == pytest.approx(0.6, rel=0.08)
    assert medians["overturning"] == pytest.approx(0.9, rel=0.08)
    assert cell["beta"].sel(damage_state="overturning").item() == pytest.approx(0.4, rel=0.15)
    low, high = cell.median_low.sel(damage_state="overturning").item(), cell.median_high.sel(damage_state="overturning").item()
    assert low < medians["overturning"] < high
    ordered = [(medians[s], cell["beta"].sel(damage_state=s).item()) for s in ("rocking-0.2", "rocking-0.5", "overturning")]
    assert not curves_cross(np.geomspace(0.05, 3.0, 400), ordered)
    probabilities = cell.outcome_probability.sum("outcome_class").values
    np.testing.assert_allclose(probabilities, 1.0)


def test_bootstrap_is_seeded():
    a = fragility_dataset(synthetic_cube(), n_bootstrap=10, seed=5)
    b = fragility_dataset(synthetic_cube(), n_bootstrap=10, seed=5)
    xr.testing.assert_identical(a, b)


def test_crossing_curves_are_refitted_with_shared_beta():
    levels = np.geomspace(0.1, 3, 20)
    fits = [(0.5, 0.2), (0.7, 0.8)]  # a wide curve for the more severe state crosses
    assert curves_cross(levels, fits)
    assert not curves_cross(levels, [(0.5, 0.4), (0.7, 0.4)])


def test_user_damage_state(tmp_path):
    states = damage_states_from_config({"damage_states": {"rocking-0.8": {"edp": "peak_angle_ratio",
                                                                          "threshold": 0.8}}})
    assert [s.name for s in states] == ["uplift", "rocking-0.2", "rocking-0.5", "rocking-0.8", "overturning"]
    assert "rocking-0.8" not in DAMAGE_STATES  # the registry itself is not changed by a study


def test_pelicun_table_follows_its_column_conventions():
    fragility = fragility_dataset(synthetic_cube(), n_bootstrap=0)
    table = pelicun_table(fragility)
    assert list(table.columns[:6]) == ["ID", "Incomplete", "Demand-Type", "Demand-Unit", "Demand-Offset",
                                       "Demand-Directional"]
    for level in range(1, 5):
        assert {f"LS{level}-Family", f"LS{level}-Theta_0", f"LS{level}-Theta_1",
                f"LS{level}-DamageStateWeights"} <= set(table.columns)
    row = table.iloc[0]
    assert row["ID"] == "ROCK.b.sand.ssi" and row["Demand-Type"] == "Peak Ground Acceleration"
    assert row["Demand-Unit"] == "g" and row["LS1-Family"] == "lognormal"
    thetas = [row[f"LS{i}-Theta_0"] for i in range(1, 5)]
    assert thetas == sorted(thetas)  # limit states in increasing severity


def test_risk_integral_matches_power_law_closed_form():
    """H(s) = k0 s^-k and a lognormal fragility: lambda = k0 median^-k exp(k^2 beta^2 / 2)."""
    hazard = load_hazard()  # the shipped example: k0 = 1e-4, k = 2.5
    for median, beta in ((0.3, 0.3), (0.62, 0.41), (1.5, 0.6)):
        expected = 1e-4 * median**-2.5 * np.exp(0.5 * 2.5**2 * beta**2)
        assert annual_frequency(median, beta, hazard) == pytest.approx(expected, rel=1e-3)
    assert probability_in_life(1e-3, 50) == pytest.approx(1 - np.exp(-0.05))


def test_bad_hazard_file_is_named(tmp_path):
    from pipeline.errors import ConfigError

    path = tmp_path / "hazard.csv"
    path.write_text("intensity,freq\n0.1,1e-3\n0.2,2e-3\n")
    with pytest.raises(ConfigError, match="decrease"):
        load_hazard(path)
