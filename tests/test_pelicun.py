"""Round trip through pelicun: our fragility_pelicun.csv loads with pelicun's own API (Assessment ->
demand.load_sample -> asset.load_cmp_model -> damage.load_model_parameters -> damage.calculate), and
P(DS >= k) over a demand sample agrees with our lognormals within Monte-Carlo noise.

pelicun 3.10 pins scipy<1.16 and pandas<3, so it runs in its own environment (.venv-pelicun, from
tests/consumers/pelicun.txt, built by `make consumers`): the CSV and the demand sample are written here, in the
main environment, and tests/consumers/pelicun_damage.py computes the damage states with that environment's
Python. `make test` requires the environment; elsewhere the test is skipped when it is not built."""

from __future__ import annotations

import subprocess

import numpy as np
import pandas as pd
import pytest
from scipy.stats import norm

from pipeline.fragility import fragility_dataset, lognormal_cdf, pelicun_table
from tests.helpers import CONSUMERS, consumer_python
from tests.test_fragility import synthetic_cube

N_DEMANDS = 20000


@pytest.fixture(scope="module")
def round_trip(tmp_path_factory):
    python = consumer_python("pelicun")
    folder = tmp_path_factory.mktemp("pelicun")
    fragility = fragility_dataset(synthetic_cube(n_records=200), n_bootstrap=0)
    pelicun_table(fragility).to_csv(folder / "fragility_pelicun.csv", index=False)
    rng = np.random.default_rng(0)
    pga = np.exp(rng.uniform(np.log(0.05), np.log(3.0), N_DEMANDS))
    demand = pd.DataFrame({"1-PGA-1-1": pga})
    with open(folder / "demand.csv", "w") as handle:  # pelicun's sample layout: a Units row under the header
        handle.write(",1-PGA-1-1\nUnits,g\n")
        demand.to_csv(handle, header=False)
    result = subprocess.run([str(python), str(CONSUMERS / "pelicun_damage.py"), str(folder)], capture_output=True,
                            text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    damage_state = np.load(folder / "damage_state.npy")
    assert damage_state.shape == (N_DEMANDS,)
    return fragility.isel(soil=0, block=0, model=0), pga, damage_state


def test_pelicun_damage_states_match_our_lognormals(round_trip):
    cell, pga, damage_state = round_trip
    for k, state in enumerate(cell.damage_state.values, start=1):
        median, beta = float(cell["median"].sel(damage_state=state)), float(cell.beta.sel(damage_state=state))
        expected = lognormal_cdf(pga, median, beta).mean()
        observed = np.mean(damage_state >= k)
        noise = np.sqrt(expected * (1 - expected) / pga.size)
        assert observed == pytest.approx(expected, abs=4 * noise + 1e-3), state


def test_directional_demand_is_not_scaled_by_pelicun(round_trip):
    """With Demand-Directional = 0 pelicun would multiply PGA by 1.2: P(DS) some points too high."""
    cell, pga, damage_state = round_trip
    median = float(cell["median"].sel(damage_state="overturning"))
    beta = float(cell.beta.sel(damage_state="overturning"))
    scaled = norm.cdf(np.log(1.2 * pga / median) / beta).mean()
    unscaled = norm.cdf(np.log(pga / median) / beta).mean()
    observed = np.mean(damage_state >= 4)
    assert abs(observed - unscaled) < abs(observed - scaled) / 4
