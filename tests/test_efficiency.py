"""Measure ranking: efficiency and sufficiency on synthetic capacities with a known answer."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

from rockfrag.efficiency import (
    capacities_in_measures,
    efficiency_from_capacities,
    efficiency_table,
    plot_efficiency,
    rank_ascending,
    write_efficiency,
)
from rockfrag.units import STANDARD_GRAVITY

N = 40
rng = np.random.default_rng(7)
MAGNITUDE = rng.uniform(6.0, 7.8, N)
DISTANCE = rng.uniform(5.0, 60.0, N)


def standardised(values):
    values = np.asarray(values, float)
    return (values - values.mean()) / values.std(ddof=1)


def synthetic(sigma_a=0.2, sigma_b=0.5):
    """Three measures on one block: 'tight' (dispersion 0.2, independent of M and R), 'loose'
    (dispersion 0.5) and 'magnitude' (dispersion 0.3, all of it explained by magnitude)."""
    noise = standardised(rng.standard_normal(N))
    noise = standardised(noise - np.polyfit(MAGNITUDE, noise, 1)[0] * MAGNITUDE)  # uncorrelated with M
    tight = np.exp(1.0 + sigma_a * noise)
    loose = np.exp(2.0 + sigma_b * noise[::-1])
    by_magnitude = np.exp(0.5 + 0.3 * standardised(MAGNITUDE))
    values = np.stack([tight, loose, by_magnitude], axis=-1)[:, None, None, None, :]
    return xr.DataArray(values, dims=("record", "soil", "block", "model", "measure"),
                        coords={"record": [f"r{i}" for i in range(N)], "soil": ["rock"], "block": ["b"],
                                "model": ["housner"], "measure": ["pga", "pgv", "sa"]})


def test_dispersion_and_rank_of_known_capacities():
    dataset = efficiency_from_capacities(synthetic(), {"magnitude": MAGNITUDE, "distance": DISTANCE})
    cell = dataset.isel(soil=0, block=0, model=0)
    np.testing.assert_allclose(cell.dispersion.values, [0.2, 0.5, 0.3], rtol=1e-12)
    assert list(cell.efficiency_rank.values) == [1.0, 3.0, 2.0]
    # the capacities are SI [m/s^2]; the file gives PGA medians in g and PGV ones in m/s
    assert cell.median_capacity_pga.item() == pytest.approx(np.exp(1.0) / STANDARD_GRAVITY, rel=1e-12)
    assert cell.median_capacity_pga.attrs["units"] == "9.80665 m s-2"
    assert cell.median_capacity_pgv.item() == pytest.approx(np.exp(2.0), rel=1e-12)
    assert cell.median_capacity_pgv.attrs["units"] == "m s-1"


def test_sufficiency_flags_the_measure_whose_residuals_follow_magnitude():
    dataset = efficiency_from_capacities(synthetic(), {"magnitude": MAGNITUDE, "distance": DISTANCE})
    cell = dataset.isel(soil=0, block=0, model=0)
    assert cell.p_magnitude.sel(measure="sa").item() < 1e-10
    assert cell.p_magnitude.sel(measure="pga").item() > 0.5  # built uncorrelated with magnitude
    assert np.isnan(cell.p_pulse_period.sel(measure="pga").item())  # not given: untested
    table = efficiency_table(dataset)
    assert list(table["measure"]) == ["pga", "sa", "pgv"]  # best first
    assert table.set_index("measure").loc["sa", "sufficient"] == "no"


def test_records_that_never_overturned_are_left_out():
    capacity = synthetic()
    capacity[:5, ..., 0] = np.nan
    dataset = efficiency_from_capacities(capacity, {"magnitude": MAGNITUDE})
    assert dataset.n_records.sel(measure="pga").item() == N - 5


def test_pooled_dispersion_rewards_a_measure_that_collapses_the_blocks():
    """Two blocks whose capacities differ by a factor 4 in 'pga' but coincide in 'pga_ratio'."""
    base = np.exp(0.3 * standardised(rng.standard_normal(N)))
    values = np.stack([np.stack([base, 4 * base], axis=-1), np.stack([base, base], axis=-1)], axis=-1)
    capacity = xr.DataArray(values[:, None, :, None, :], dims=("record", "soil", "block", "model", "measure"),
                            coords={"soil": ["rock"], "block": ["small", "large"], "model": ["housner"],
                                    "measure": ["pga", "pga_ratio"]})
    dataset = efficiency_from_capacities(capacity, {})
    within = dataset.dispersion.isel(soil=0, model=0)
    np.testing.assert_allclose(within.values, 0.3, rtol=1e-12)  # same within each block
    pooled = dataset.dispersion_pooled.isel(soil=0, model=0)
    assert pooled.sel(measure="pga_ratio").item() == pytest.approx(0.3, rel=0.02)
    assert pooled.sel(measure="pga").item() > 0.6


def test_capacity_is_the_scale_factor_times_the_records_measure():
    cube = xr.Dataset({"capacity_scale_factor": (("record", "soil", "block", "model"), [[[[2.0]]], [[[0.5]]]])},
                      coords={"record": ["a", "b"], "soil": ["rock"], "block": ["x"], "model": ["housner"]})
    values = xr.DataArray([[[3.0, 10.0]], [[4.0, 1.0]]], dims=("record", "block", "measure"),
                          coords={"record": ["a", "b"], "block": ["x"], "measure": ["pga", "pgv"]})
    capacity = capacities_in_measures(cube, values)
    np.testing.assert_allclose(capacity.sel(soil="rock", block="x", model="housner").values,
                               [[6.0, 20.0], [2.0, 0.5]])


def test_rank_leaves_missing_dispersions_unranked():
    np.testing.assert_array_equal(rank_ascending([0.4, np.nan, 0.1]), [2.0, np.nan, 1.0])
    np.testing.assert_array_equal(rank_ascending([0.3, 0.1, 0.3 * (1 + 1e-12), 0.5]), [2.0, 1.0, 2.0, 4.0])


def test_outputs_and_a4_figure(tmp_path):
    dataset = efficiency_from_capacities(synthetic(), {"magnitude": MAGNITUDE, "distance": DISTANCE})
    nc, csv = write_efficiency(dataset, tmp_path)
    reread = xr.open_dataset(nc)
    assert reread.dispersion.attrs["units"] == "1" and "long_name" in reread.p_distance.attrs
    assert csv.read_text().splitlines()[0].startswith("soil,block,model,measure")
    before = plt.get_fignums()  # another test in this process may have left one open: compare, not assume none
    figure = plot_efficiency(dataset)
    assert isinstance(figure, Figure) and plt.get_fignums() == before  # no pyplot state left behind
    np.testing.assert_allclose(figure.get_size_inches(), [8.27, 11.69])


def test_the_dispersion_band_is_the_chi_square_interval_and_covers_as_stated():
    """The whiskers of the efficiency page: for n = 5 the 90% band is s·sqrt(4/9.488) to s·sqrt(4/0.711) (chi-square
    table, 4 degrees of freedom, 5% and 95%), and over many samples of 5 normal values it holds the true sigma in
    90% of them (coverage, not the formula again)."""
    from rockfrag.efficiency import dispersion_interval

    low, high = dispersion_interval([0.27], [5])
    assert low[0] == pytest.approx(0.27 * np.sqrt(4 / 9.488), rel=1e-3)
    assert high[0] == pytest.approx(0.27 * np.sqrt(4 / 0.711), rel=1e-3)
    samples = np.random.default_rng(3).normal(0.0, 0.4, size=(20000, 5))
    low, high = dispersion_interval(samples.std(axis=1, ddof=1), np.full(20000, 5))
    assert np.mean((low <= 0.4) & (0.4 <= high)) == pytest.approx(0.90, abs=0.01)
    assert np.isnan(dispersion_interval([0.3], [1])[0][0])  # one record: no spread, no band


def test_cells_that_are_the_same_runs_are_one_independent_test():
    """Cold read 3 (default B2): the tied rigid base is the same runs on every soil, and efficiency.nc repeats its
    test in each soil's cell (the slender cabinet on five soils, the paper block on three). Counted once each: two
    tests, with the records behind each, not 'the 8 of 45 cells'."""
    from pathlib import Path

    from rockfrag.efficiency import independent_tests

    dataset = xr.load_dataset(Path(__file__).parent / "data" / "efficiency_default_study.nc")
    assert int(np.isfinite(dataset.dispersion.sel(measure="pga")).sum()) == 8  # the copies the file holds
    tests = independent_tests(dataset)
    assert [(t.block, t.model, t.soils, t.records) for t in tests] == [
        ("slender-cabinet", "housner", ("clay", "sand", "gravel", "rock", "steel"), 44),
        ("paper", "housner", ("gravel", "rock", "steel"), 5)]
    changed = dataset.copy(deep=True)
    changed["dispersion"].loc[dict(soil="rock", block="paper", model="housner", measure="pgv")] = 0.31
    assert [t.soils for t in independent_tests(changed) if t.block == "paper"] == [("gravel", "steel"), ("rock",)]
