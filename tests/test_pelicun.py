"""Round trip through pelicun: every component of our fragility_pelicun.csv loads and computes with pelicun's own
API (Assessment -> demand.load_sample -> asset.load_cmp_model -> damage.load_model_parameters -> damage.calculate),
one at a time and all together, and its P(DS >= k) matches our curves within 0.01 at every demand level.

pelicun 3.10 pins scipy<1.16 and pandas<3, so it runs in its own environment (.venv-pelicun, from
tests/consumers/pelicun.txt, built by `make consumers`): the CSV and the demand sample are written here, in the
main environment, and tests/consumers/pelicun_damage.py computes the damage states with that environment's
Python. `make test` requires the environment; elsewhere those tests are skipped when it is not built.

The expected P(DS >= k) is the documented way each row is written (pipeline/exchange.py): a lognormal, a step at
the median (beta = 0), a step at the lowest level studied (below-range), the records' fractions up to the credible
cap held above it (censored-at-cap, above-range; pelicun: their running maximum), or never (not reached),
evaluated here from
the dataset with scipy and numpy. pelicun samples the capacities of a component's limit states perfectly
correlated and reports the most severe state exceeded, so P(DS >= k) is the largest of our curves k..n (the
curves may cross in a tail outside the data). The demand is held at each level over all realizations, so
pelicun's Latin hypercube capacities give the probability to within one over the sample size: the 0.01
tolerance is not Monte-Carlo noise.
"""

from __future__ import annotations

import re
import subprocess

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from scipy.stats import norm

from rockfrag.exchange import pelicun_id, pelicun_table, state_families, write_exchange_files
from rockfrag.models.variants import RECOMMENDED
from tests.helpers import CONSUMERS, ROOT, consumer_python

DEMAND_LEVELS = np.geomspace(0.03, 8.0, 10)
"""PGA [g] of the demand sample: below, across and above the studied ranges, on no step of the test rows."""

N_REALIZATIONS = 200
"""Realizations per demand level: pelicun's Latin hypercube capacities resolve P to 1/200."""

TOLERANCE = 0.01

STATES = ["uplift", "rocking-0.2", "rocking-0.5", "overturning"]
NAN = (np.nan, np.nan)
ROWS = {  # (block, model): (median [g], beta, status) per damage state, every way a row can be written
    ("b-1", "ssi"): [(0.2, 0.0, "deterministic-threshold"), (0.4, 0.35, "fitted"), (0.6, 0.4, "fitted"),
                     (*NAN, "censored-at-cap")],
    ("b-1", RECOMMENDED): [(*NAN, "below-range"), (0.3, 0.5, "fitted"), (0.5, 0.45, "fitted"),
                                 (0.8, 0.5, "fitted")],
    ("b-1", "winkler"): [(0.1, 0.3, "fitted"), (0.45, 0.0, "separated"), (*NAN, "above-range"),
                         (*NAN, "not-reached")],
    ("stocky", "ssi"): [(5.0, 0.0, "deterministic-threshold"), (*NAN, "censored-at-cap"), (*NAN, "censored-at-cap"),
                        (*NAN, "not-reached")],
    ("stocky", RECOMMENDED): [(*NAN, "not-reached")] * 4,
    ("stocky", "winkler"): [(2.5, 0.3, "extrapolated"), (*NAN, "not-reached"), (*NAN, "not-reached"),
                            (3.5, 0.35, "extrapolated")],  # states that do not nest (a study's own states could)
}
STUDIED = {"b-1": (0.05, 3.0), "stocky": (0.1, 4.0)}  # studied range of each block [g], the top at the credible cap
LEVELS = {block: np.append(np.geomspace(low, high, 8), 1.3 * high) for block, (low, high) in STUDIED.items()}
"""The intensity levels of each block [g]: 8 up to the credible cap, one above it (not credible: never written)."""
FRACTIONS = ("censored-at-cap", "above-range")
"""The statuses of rows without a median that records reached: written as the records' fractions."""
CENSORED = {  # the records' fraction at each level of those rows (the same on both soils)
    ("b-1", "ssi", "overturning"): [0, 0, 0, 0, 0.05, 0.1, 0.1, 0.2, 0.95],  # a flat stretch: pelicun must rise
    ("stocky", "ssi", "rocking-0.2"): [0.1, 0.1, 0.2, 0.35, 0.3, 0.4, 0.45, 0.4, 0.9],  # reached at the lowest
    # level, falling twice (at the cap too: pelicun's rising curve keeps 0.45 there)
    ("stocky", "ssi", "rocking-0.5"): [0, 0, 0, 0, 0, 0, 0.05, 0.1, 0.9],
    ("b-1", "winkler", "rocking-0.5"): [0, 0, 0, 0, 0, 0, 0, 0.05, 0.6],  # above-range: only at the highest level
}
SOIL_FACTOR = {"sand": 1.0, "rock": 1.2}  # rock: the fitted medians 20% higher


def exchange_dataset() -> xr.Dataset:
    """A fragility dataset with a row of every kind: lognormal, step, below-range, above-range, censored at the
    credible cap (beside a step and lognormals, and beside a step and a state not reached), not reached (as the
    first state, after others, between others, and in every state of a cell). The model "recommended" is not
    first in the model coordinate; ``beta_model`` is there (the files carry it in comments only)."""
    soils, blocks, models = list(SOIL_FACTOR), list(STUDIED), ["ssi", RECOMMENDED, "winkler"]
    shape = (len(soils), len(blocks), len(models), len(STATES))
    median, beta = np.full(shape, np.nan), np.full(shape, np.nan)
    status = np.full(shape, "", dtype=object)
    for (s, soil), (b, block), (m, model) in ((a, c, d) for a in enumerate(soils) for c in enumerate(blocks)
                                              for d in enumerate(models)):
        for k, (row_median, row_beta, row_status) in enumerate(ROWS[block, model]):
            factor = SOIL_FACTOR[soil] if row_beta > 0 else 1.0  # steps (g tan alpha) do not depend on the soil
            median[s, b, m, k], beta[s, b, m, k], status[s, b, m, k] = row_median * factor, row_beta, row_status
    dims = ("soil", "block", "model", "damage_state")
    fraction = np.full((LEVELS[blocks[0]].size, *shape), np.nan)
    for (block, model, state), fractions in CENSORED.items():
        fraction[:, :, blocks.index(block), models.index(model), STATES.index(state)] = np.array(fractions)[:, None]
    at_cap = fraction[-2]  # the highest level at or below the cap
    g = {"units": "9.80665 m s-2"}
    return xr.Dataset(
        {"median": (dims, median, g), "beta": (dims, beta), "status": (dims, status.astype(str)),
         "beta_model": (dims, np.where(beta > 0, 0.2, np.nan)),
         "studied_im_min": ("block", [STUDIED[b][0] for b in blocks], g),
         "studied_im_max": ("block", [STUDIED[b][1] for b in blocks], g),
         "credible_max": ("block", [STUDIED[b][1] for b in blocks], g),
         "intensity": (("block", "im_level"), [LEVELS[b] for b in blocks], g),
         "empirical_fraction": (("im_level", *dims), fraction),
         "probability_at_cap": (dims, at_cap),
         "probability_at_cap_low": (dims, np.clip(at_cap - 0.1, 0, 1),
                                    {"long_name": "lower 90% Clopper-Pearson bound of probability_at_cap"}),
         "probability_at_cap_high": (dims, np.clip(at_cap + 0.1, 0, 1))},
        coords={"soil": soils, "block": blocks, "model": models, "damage_state": STATES},
        attrs={"intensity_measure": "pga", "intensity_unit": "9.80665 m s-2", "intensity_unit_label": "g"})


def censored_curve(cell: xr.Dataset, state: str, demand: np.ndarray, rising: bool = False) -> np.ndarray:
    """P(state | demand) of a row censored at the credible cap as the files write it: the records' fractions at
    the levels up to the cap, linear between them, 0 below the lowest level and the fraction at the cap above it
    (``rising``: their running maximum, pelicun's curve)."""
    levels = cell.intensity.values
    keep = levels <= float(cell.credible_max) * (1 + 1e-9)
    fractions = cell.empirical_fraction.sel(damage_state=state).values[keep]
    if rising:
        fractions = np.maximum.accumulate(fractions)
    return np.where(demand < levels[0], 0.0, np.interp(demand, levels[keep], fractions))


def our_curves(cell: xr.Dataset, demand: np.ndarray, rising: bool = False) -> np.ndarray:
    """P(state k | demand) of one cell as the exchange files write it (pipeline/exchange.py): (k, demand);
    ``rising``: a censored row as pelicun's rising curve."""
    curves = []
    for state in cell.damage_state.values:
        median, beta = float(cell["median"].sel(damage_state=state)), float(cell.beta.sel(damage_state=state))
        status = str(cell.status.sel(damage_state=state).values)
        if np.isfinite(median) and beta > 0:
            curves.append(norm.cdf(np.log(demand / median) / beta))
        elif np.isfinite(median):
            curves.append((demand >= median).astype(float))
        elif status == "below-range":
            curves.append((demand >= float(cell.studied_im_min)).astype(float))
        elif status in FRACTIONS:
            curves.append(censored_curve(cell, state, demand, rising))
        else:
            curves.append(np.zeros_like(demand))
    return np.array(curves)


def pelicun_expected(cell: xr.Dataset, demand: np.ndarray) -> np.ndarray:
    """P(DS >= k | demand) in pelicun: the most severe state exceeded, capacities perfectly correlated: (demand, k)."""
    curves = our_curves(cell, demand, rising=True)
    return np.maximum.accumulate(curves[::-1], axis=0)[::-1].T


def readme_example(command: str) -> str:
    """The Python of the documented example run by ``command`` (a shell block ``COMMAND - <<'EOF' ... EOF``) in
    docs/guide/exchange.md, the page that holds the README's former exchange-file section."""
    page = (ROOT / "docs" / "guide" / "exchange.md").read_text(encoding="utf-8")
    found = re.findall(rf"^{re.escape(command)} - <<'EOF'\n(.*?)^EOF$", page, flags=re.MULTILINE | re.DOTALL)
    assert len(found) == 1, f"docs/guide/exchange.md has {len(found)} examples run by {command}"
    return found[0]


def run_pelicun(folder, alone: bool = False, example: str | None = None) -> tuple[dict[str, np.ndarray], str]:
    """Write the demand sample into ``folder`` (beside fragility_pelicun.csv) and run the consumer script: every
    component in one assessment (``together``) and, if ``alone``, each in its own (``alone``); then, in the
    same process, the Python ``example`` in ``folder``'s parent. The results and what the process printed."""
    python = consumer_python("pelicun")
    columns = [f"1-PGA-1-{d}" for d in range(1, DEMAND_LEVELS.size + 1)]  # event-type-location-direction
    with open(folder / "demand.csv", "w") as handle:  # pelicun's sample layout: a Units row under the header
        handle.write("," + ",".join(columns) + "\nUnits," + ",".join(["g"] * len(columns)) + "\n")
        pd.DataFrame(np.tile(DEMAND_LEVELS, (N_REALIZATIONS, 1))).to_csv(handle, header=False)
    options = ["--alone"] * alone
    if example is not None:
        (folder.parent / "example.py").write_text(example)
        options += ["--example", str(folder.parent / "example.py")]
    result = subprocess.run([str(python), str(CONSUMERS / "pelicun_damage.py"), str(folder), *options],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    with np.load(folder / "exceedance.npz") as data:
        return {name: data[name] for name in data.files}, result.stdout


def check_against_our_curves(dataset: xr.Dataset, table: pd.DataFrame, computed: dict[str, np.ndarray]) -> None:
    families = state_families(dataset)  # rocking states, and a sliding cell's slip states as ID.SLIP
    cells = {pelicun_id(b, s, m) + suffix: (s, b, m, states) for s in dataset.soil.values
             for b in dataset.block.values for m in dataset.model.values for suffix, states in families.items()}
    for way in computed:
        assert computed[way].shape == (len(table), DEMAND_LEVELS.size, max(map(len, families.values())))
        for index, component in enumerate(table.ID):
            soil, block, model, states = cells[component]
            expected = pelicun_expected(dataset.sel(soil=soil, block=block, model=model, damage_state=states),
                                        DEMAND_LEVELS)
            error = np.abs(computed[way][index][:, :len(states)] - expected)
            assert error.max() <= TOLERANCE, (way, component, error.max(), computed[way][index], expected)


def written(folder) -> tuple[xr.Dataset, pd.DataFrame]:
    dataset = exchange_dataset()
    write_exchange_files(dataset, folder)
    return dataset, pd.read_csv(folder / "fragility_pelicun.csv")


ROUND_TRIP = pytest.mark.xdist_group("pelicun-round-trip")
"""The tests of ``round_trip`` share one xdist worker, so that pelicun runs once (not once per worker)."""


@pytest.fixture(scope="module")
def round_trip(tmp_path_factory):
    """pelicun on the test dataset's file, written where the README's example reads it: every component in one
    assessment and each in its own (one pelicun process: its start-up is most of the cost), then the example."""
    folder = tmp_path_factory.mktemp("pelicun") / "reports-example"
    dataset, table = written(folder)
    computed, printed = run_pelicun(folder, alone=True, example=readme_example(".venv-pelicun/bin/python"))
    return dataset, table, computed, printed


def test_every_row_is_written_as_documented():
    """The table itself (no pelicun needed): each kind of row in pelicun's terms."""
    table = pelicun_table(exchange_dataset()).set_index("ID")
    assert (table.Incomplete == 0).all()  # every component computes: none is skipped by pelicun
    models = [component.rsplit(".", 1)[1] for component in table.index]
    assert models[:4] == [RECOMMENDED] * 4 and RECOMMENDED not in models[4:]  # recommended first
    below = table.loc["ROCK.b_1.sand.recommended"]
    assert (below["LS1-Family"], below["LS1-Theta_0"]) == ("deterministic", 0.05)  # reached from the lowest level
    assert below["LS2-Family"] == "lognormal" and below["LS2-Theta_1"] == 0.5  # beta is the total, not beta_model
    assert "beta_model 0.2" in below["Comment"] and "below-range" in below["Comment"]
    nothing = table.loc["ROCK.stocky.sand.recommended"]
    assert (nothing["LS1-Family"], nothing["LS1-Theta_0"]) == ("deterministic", np.inf)  # pelicun needs LS1
    assert all(pd.isna(nothing[f"LS{k}-Theta_0"]) and not nothing[f"LS{k}-Family"] for k in (2, 3, 4))
    trailing = table.loc["ROCK.b_1.rock.winkler"]
    assert trailing["LS2-Family"] == "deterministic" and trailing["LS2-Theta_0"] == 0.45  # separated: the step
    assert trailing["LS3-Family"] == "multilinear_CDF"  # above-range: the records' fractions
    assert "LS3 rocking-0.5: above-range, median above the levels studied (reached only at the highest): reached " \
           "by 5 % of the records at 3 g" in trailing["Comment"]
    assert pd.isna(trailing["LS4-Theta_0"]) and "LS4 overturning: not-reached, left out" in trailing["Comment"]
    middle = table.loc["ROCK.stocky.sand.winkler"]  # a state left out before a written one would renumber pelicun's
    assert [middle[f"LS{k}-Theta_0"] for k in (2, 3)] == [np.inf, np.inf]  # damage states: never reached instead


def multilinear(theta_0: str) -> tuple[np.ndarray, np.ndarray]:
    """The points of a ``multilinear_CDF`` Theta_0 ("x1,...,xn|y1,...,yn") as pelicun splits them."""
    xs, ys = theta_0.split("|")
    return np.array(xs.split(","), float), np.array(ys.split(","), float)


def test_a_row_censored_at_the_cap_is_written_as_what_the_records_did():
    """A censored row is a multilinear_CDF that pelicun accepts (y from 0 to 1, x and y strictly rising by more
    than its 1e-8, 1 at the capacity inf), through the records' fractions at the credible levels and never the
    one above the cap; its value at the cap is probability_at_cap (the running maximum where the fractions fall
    there); its comment says what it is, never "not reached"."""
    dataset = exchange_dataset()
    table = pelicun_table(dataset).set_index("ID")
    checked = 0
    for soil in dataset.soil.values:
        for block, model, state in CENSORED:
            cell = dataset.sel(soil=soil, block=block, model=model)
            row = table.loc[pelicun_id(block, soil, model)]
            k = STATES.index(state) + 1
            assert row[f"LS{k}-Family"] == "multilinear_CDF"
            x, y = multilinear(row[f"LS{k}-Theta_0"])
            assert y[0] == 0 and y[-1] == 1 and x[-1] == np.inf and pd.isna(row[f"LS{k}-Theta_1"])
            assert (np.diff(x) > 1e-8).all() and (np.diff(y) > 1e-8).all()
            # what pelicun's rewrite with 6 significant digits keeps strictly rising too
            assert all((np.diff([float(f"{v:g}") for v in values]) > 0).all() for values in (x, y))
            cap = float(cell.studied_im_max)
            fractions = np.array(CENSORED[block, model, state][:-1])
            at_cap = float(cell.probability_at_cap.sel(damage_state=state))
            assert at_cap == fractions[-1]
            value = np.interp(cap, x, y)
            assert value == pytest.approx(np.maximum.accumulate(fractions)[-1], abs=2e-4)
            if fractions[-1] == fractions.max():
                assert value == pytest.approx(at_cap, abs=2e-4)  # 0.2 and 0.1 here: the file's value at the cap
            assert np.interp(100 * cap, x, y) == value  # held above the cap (the rest at the capacity inf)
            levels = LEVELS[block][:-1]
            np.testing.assert_allclose(np.interp(levels, x, y), np.maximum.accumulate(fractions), atol=2e-4)
            note = row["Comment"].split(f"LS{k} {state}:")[1].split("; LS")[0]
            assert "not reached" not in note and "never reached" not in note
            assert f"reached by {100 * at_cap:.0f} % of the records at {cap:.4g} g" in note, note
            checked += 1
    assert checked == 8
    falling = table.loc["ROCK.stocky.sand.ssi", "Comment"]
    assert "pelicun's curve must rise: it keeps the earlier 45 % there" in falling


@ROUND_TRIP
def test_every_component_loads_and_matches_our_curves_together(round_trip):
    dataset, table, computed, _ = round_trip
    assert len(table) == dataset.soil.size * dataset.block.size * dataset.model.size
    check_against_our_curves(dataset, table, {"together": computed["together"]})


@ROUND_TRIP
@pytest.mark.slow
def test_every_component_loads_and_matches_our_curves_alone(round_trip):
    """One assessment per component (a file of one row must load too)."""
    dataset, table, computed, _ = round_trip
    assert set(computed) == {"alone", "together"}
    check_against_our_curves(dataset, table, {"alone": computed["alone"]})


@ROUND_TRIP
def test_the_tolerance_would_catch_pelicuns_directional_factor(round_trip):
    """With Demand-Directional = 0 pelicun would multiply PGA by 1.2; the comparison above would fail."""
    dataset, table, computed, _ = round_trip
    cell = dataset.sel(soil="sand", block="b-1", model="ssi")
    shift = np.abs(pelicun_expected(cell, 1.2 * DEMAND_LEVELS) - pelicun_expected(cell, DEMAND_LEVELS)).max()
    assert shift > 5 * TOLERANCE
    index = list(table.ID).index("ROCK.b_1.sand.ssi")
    assert np.abs(computed["together"][index] - pelicun_expected(cell, DEMAND_LEVELS)).max() < TOLERANCE


@ROUND_TRIP
def test_the_readme_example_runs_as_printed(round_trip):
    """The README's pelicun example, on the file of the test dataset: a damage-state table of every component."""
    _, table, _, printed = round_trip
    assert printed.splitlines()[0].split() == ["ds", "0", "1", "2", "3", "4"]
    assert all(component in printed for component in table.ID)


@pytest.mark.slow
def test_a_studys_file_loads_and_matches_in_pelicun(small_pipeline, tmp_path):
    """The file ``rockfrag fragility`` wrote for the small study: every component, in one assessment (the
    session's pipeline run; about 4 s for pelicun once it has run)."""
    dataset = xr.open_dataset(small_pipeline.output / "fragility.nc")
    table = pd.read_csv(small_pipeline.output / "fragility_pelicun.csv")
    (tmp_path / "fragility_pelicun.csv").write_bytes((small_pipeline.output / "fragility_pelicun.csv").read_bytes())
    check_against_our_curves(dataset, table, run_pelicun(tmp_path)[0])
