"""Round trip through OpenQuake: our fragility_openquake.xml reads with OpenQuake's own NRML reader (the engine's
``nrml.to_python`` with risklib's fragility-model reader), every function with our medians and betas, the
study's IMT and our curves wherever OpenQuake evaluates them; and risklib's classical damage on a hazard curve
gives our probability of each damage state in the design life (pipeline/risk.py).

OpenQuake's engine declares a server and GIS stack (Django, GDAL) that its NRML reader does not import, so it
runs in its own environment (.venv-openquake, from tests/consumers/openquake.no-deps.txt and openquake.txt,
built by `make consumers`): the file is written here, in the main environment, and
tests/consumers/openquake_fragility.py reads it with that environment's Python. `make test` requires the
environment; elsewhere these tests are skipped when it is not built. Importing OpenQuake's reader takes about
8 s of CPU (it imports every ground-motion model), so the tests are `slow` and share one consumer run, which also
reads the file of the session's small pipeline run.
"""

from __future__ import annotations

import json
import subprocess
import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest
import xarray as xr
from scipy.stats import norm

from rockfrag.errors import ConfigError
from rockfrag.exchange import (
    DISCRETE_ERROR,
    OPENQUAKE_FILE,
    WrittenState,
    discrete_curves,
    openquake_imt,
    openquake_limit_state,
    pelicun_id,
    state_families,
    write_exchange_files,
)
from rockfrag.hazard import HazardCurve
from rockfrag.models.variants import RECOMMENDED
from rockfrag.risk import annual_frequency, probability_in_life
from tests.helpers import CONSUMERS, consumer_python
from tests.test_pelicun import FRACTIONS, censored_curve, exchange_dataset, our_curves, readme_example
from tests.test_pelicun import LEVELS as LEVELS_OF

LEVELS = np.geomspace(0.001, 100.0, 61)
"""PGA [g] at which OpenQuake evaluates every function: far below and above every studied range."""

DESIGN_LIFE = 50.0
HAZARD_IMLS = np.geomspace(0.001, 200.0, 600)
HAZARD_RATES = 1e-4 * HAZARD_IMLS ** -2.5
"""The example site's power-law hazard (pipeline/hazard_example.csv: 1e-4 /yr at 1 g, slope 2.5) on a dense grid
that reaches far beyond every curve: risklib sums occurrences between the hazard's levels only (it drops the rate
above the highest), our integral continues the power law."""


def run_openquake(*folders, example: str | None = None) -> tuple[list[dict], str]:
    """Run the consumer script on each folder's fragility_openquake.xml (one OpenQuake import, about 8 s of CPU)
    and then the Python ``example`` in the first folder's parent: what OpenQuake read and computed, per folder,
    and what the process printed."""
    python = consumer_python("openquake")
    poes = -np.expm1(-HAZARD_RATES * DESIGN_LIFE)  # an OpenQuake hazard curve: P(exceedance in the time)
    query = {"levels": LEVELS.tolist(), "hazard": {"imls": HAZARD_IMLS.tolist(), "poes": poes.tolist(),
                                                   "investigation_time": DESIGN_LIFE,
                                                   "risk_investigation_time": DESIGN_LIFE}}
    for folder in folders:
        (folder / "query.json").write_text(json.dumps(query))
    options = []
    if example is not None:
        (folders[0].parent / "example.py").write_text(example)
        options = ["--example", str(folders[0].parent / "example.py")]
    result = subprocess.run([str(python), str(CONSUMERS / "openquake_fragility.py"), *map(str, folders), *options],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    return [json.loads((folder / "openquake.json").read_text()) for folder in folders], result.stdout


def near_a_step(cell: xr.Dataset, levels: np.ndarray) -> np.ndarray:
    """Levels within 2% of a step of the cell (written as a lognormal with beta 0.001 in OpenQuake's continuous
    format, a rise over 0.1% in its discrete one), or of a censored row's rise at the lowest level."""
    steps = [float(m) for m, b in zip(cell["median"].values, cell.beta.values) if np.isfinite(m) and b == 0]
    steps += [float(cell.studied_im_min)] if {"below-range", *FRACTIONS} & set(cell.status.values) else []
    return np.array([any(abs(np.log(level / step)) < 0.02 for step in steps) for level in levels], bool)


def check_functions(dataset: xr.Dataset, read: dict) -> None:
    """Every cell has its function, with our limit states, IMT, medians, betas and curves (the rocking states:
    a sliding cell's slip states are a file of their own); a cell with a row of records' fractions (censored at
    the credible cap, or above-range: ``FRACTIONS``) is a discrete function: OpenQuake gives the records'
    fraction at the cap there and above it (held), and the other rows within the discrete format's
    DISCRETE_ERROR of our curves (the lognormals), or to the 8 digits the file writes."""
    dataset = dataset.sel(damage_state=state_families(dataset)[""])
    assert read["limitStates"] == [openquake_limit_state(s) for s in dataset.damage_state.values]
    cells = {pelicun_id(b, s, m): (s, b, m) for s in dataset.soil.values for b in dataset.block.values
             for m in dataset.model.values}
    ids = [function["id"] for function in read["functions"]]
    assert sorted(ids) == sorted(cells)  # one function per block x soil x model
    models = [cells[i][2] for i in ids]
    first = models.count(RECOMMENDED)
    assert models[:first] == [RECOMMENDED] * first  # the recommended rows come first
    for function in read["functions"]:
        soil, block, model = cells[function["id"]]
        cell = dataset.sel(soil=soil, block=block, model=model)
        censored = np.isin(cell.status.values, FRACTIONS)
        assert function["imt"] == "PGA"
        if censored.any():
            assert function["format"] == "discrete"
            check_discrete(cell, function)
            continue
        assert function["format"] == "continuous"
        assert function["minIML"] <= float(cell.studied_im_min) and function["maxIML"] >= float(cell.studied_im_max)
        mean, stddev = np.array(function["mean"]), np.array(function["stddev"])
        beta = np.sqrt(np.log1p((stddev / mean) ** 2))  # OpenQuake's mean and stddev of the intensity -> lognormal
        median = mean / np.sqrt(1 + (stddev / mean) ** 2)
        fitted = np.isfinite(cell["median"].values) & (cell.beta.values > 0)
        np.testing.assert_allclose(median[fitted], cell["median"].values[fitted], rtol=1e-8)
        np.testing.assert_allclose(beta[fitted], cell.beta.values[fitted], rtol=1e-8)
        away = ~near_a_step(cell, LEVELS)
        np.testing.assert_allclose(np.array(function["poes"])[:, away], our_curves(cell, LEVELS)[:, away], atol=1e-6,
                                   err_msg=function["id"])


def check_discrete(cell: xr.Dataset, function: dict) -> None:
    """A discrete function (a cell with a censored row) as OpenQuake evaluates it: the censored rows' fraction at
    the cap equals probability_at_cap there and at 10 and 100 times the cap (held above it); every row is our
    curve at the 61 levels (away from the steps), the lognormals within DISCRETE_ERROR, the rest to 1e-7."""
    poes = np.array(function["poes"])
    away = ~near_a_step(cell, LEVELS)
    curves = our_curves(cell, LEVELS)
    lognormal = np.isfinite(cell["median"].values) & (cell.beta.values > 0)
    error = np.abs(poes[:, away] - curves[:, away])
    assert error[lognormal].max(initial=0) <= DISCRETE_ERROR, function["id"]
    assert error[~lognormal].max(initial=0) <= 1e-7, function["id"]  # the file: 8 significant digits
    cap = float(cell.studied_im_max)
    imls = np.array(function["imls"])
    for k in np.flatnonzero(np.isin(cell.status.values, FRACTIONS)):
        at_cap = float(cell.probability_at_cap.values[k])
        assert np.isfinite(at_cap)
        table = np.array(function["table"])[k]
        assert table[np.argmin(np.abs(imls - cap))] == pytest.approx(at_cap, abs=1e-8)  # the cap is an IML
        assert poes[k][LEVELS > 1.01 * cap] == pytest.approx(at_cap, abs=1e-8), function["id"]


@pytest.fixture(scope="module")
def round_trip(tmp_path_factory, small_pipeline):
    """What OpenQuake reads from our file for the test dataset (every kind of row) and from the file
    ``rockfrag fragility`` wrote for the session's small study: one consumer run for both."""
    synthetic = tmp_path_factory.mktemp("openquake") / "reports-example"  # where the README's example reads
    study = tmp_path_factory.mktemp("openquake-study")
    dataset = exchange_dataset()
    assert synthetic / OPENQUAKE_FILE in write_exchange_files(dataset, synthetic)
    (study / OPENQUAKE_FILE).write_bytes((small_pipeline.output / OPENQUAKE_FILE).read_bytes())
    example = readme_example("NUMBA_DISABLE_JIT=1 .venv-openquake/bin/python")
    (read, read_study), printed = run_openquake(synthetic, study, example=example)
    return dataset, read, xr.open_dataset(small_pipeline.output / "fragility.nc"), read_study, printed


@pytest.mark.slow
def test_every_function_reads_with_our_medians_betas_and_curves(round_trip):
    dataset, read, _, _, _ = round_trip
    assert (read["id"], read["lossCategory"]) == ("rockfrag", "structural")
    check_functions(dataset, read)


def censored_in_life(cell: xr.Dataset, state: str) -> float:
    """P(reaching a censored row's state in the design life) on the test hazard, the row's curve as written
    (``our_curves``: the records' fractions up to the cap, held above it) integrated over the power law by the
    midpoint rule on 20,000 intensities from 0.001 to 1000 g."""
    edges = np.geomspace(0.001, 1000.0, 20001)
    rates = 1e-4 * edges ** -2.5
    middle = np.sqrt(edges[:-1] * edges[1:])
    frequency = float(np.sum(censored_curve(cell, state, middle) * -np.diff(rates)))
    return float(probability_in_life(frequency, DESIGN_LIFE))


@pytest.mark.slow
def test_risklib_classical_damage_gives_our_probability_in_the_design_life(round_trip):
    """On the same hazard curve, every lognormal row within 0.1% of pipeline/risk.py (measured: 0.04% in a
    continuous function, 0.056% sampled in a discrete one), every row censored at the cap within 0.1% of its
    written curve integrated here (``censored_in_life``; measured 0.05%), and every step within the hazard's
    resolution: risklib sums the occurrences at the hazard's levels, so it places a step (and a censored row's
    rise at the lowest level) at one of the two levels around it, whose rates differ by 5% on this grid
    (measured: 1.6%, 2.5% for a step in a discrete function, 2.0% for the censored row)."""
    dataset, read, _, _, _ = round_trip
    hazard = HazardCurve(HAZARD_IMLS, HAZARD_RATES, "pga", None, "test power law")
    compared = censored = 0
    for function in read["functions"]:
        soil, block, model = (part for part in function["id"].split(".")[1:])
        cell = next(dataset.sel(soil=s, block=b, model=m) for s in dataset.soil.values for b in dataset.block.values
                    for m in dataset.model.values if pelicun_id(b, s, m) == function["id"])
        for k, state in enumerate(cell.damage_state.values):
            median, beta = float(cell["median"].sel(damage_state=state)), float(cell.beta.sel(damage_state=state))
            step = HAZARD_RATES[0] / HAZARD_RATES[1] - 1
            if str(cell.status.sel(damage_state=state).values) in FRACTIONS:
                ours = censored_in_life(cell, state)
                rises_at_lowest = cell.empirical_fraction.sel(damage_state=state).values[0] > 0
                tolerance = step if rises_at_lowest else 0.001
                censored += 1
            elif not np.isfinite(median):
                continue
            else:
                ours = float(probability_in_life(annual_frequency(median, beta, hazard), DESIGN_LIFE))
                tolerance = 0.001 if beta > 0 else step
            assert function["in_life"][k] == pytest.approx(ours, rel=tolerance), (function["id"], state)
            compared += 1
    assert compared >= 20 and censored == 8


@pytest.mark.slow
def test_a_studys_file_reads_in_openquake(round_trip):
    """Every function of the file ``rockfrag fragility`` wrote for the small study."""
    _, _, dataset, read, _ = round_trip
    check_functions(dataset, read)


@pytest.mark.slow
def test_the_readme_example_runs_as_printed(round_trip):
    """The README's OpenQuake example, on the file of the test dataset: the limit states, then every function."""
    _, read, _, _, printed = round_trip
    lines = printed.splitlines()
    assert lines[0] == "structural ['uplift', 'rocking-0_2', 'rocking-0_5', 'overturning']"
    assert [line.split()[0] for line in lines[1:]] == [function["id"] for function in read["functions"]]


# ---------------------------------------------------------------- the writer alone (no OpenQuake needed)

@pytest.mark.parametrize("measure, period, imt", [
    ("pga", None, "PGA"), ("pga", 1.0, "PGA"), ("sa", 1.0, "SA(1.0)"), ("sa", 0.3, "SA(0.3)"), ("sa", 2, "SA(2.0)"),
    ("sa", None, None), ("pgv", None, "PGV"), ("avgsa", 1.0, None), ("pga_ratio", None, None),
])
def test_the_imt_comes_from_the_measure_registry(measure, period, imt):
    assert openquake_imt(measure, period) == imt


def test_pgv_is_written_in_centimetres_per_second(tmp_path):
    """OpenQuake's PGV is in cm/s: a median of 0.3 m/s is written as 30 (the mean and stddev of a lognormal)."""
    dataset = exchange_dataset().assign_attrs(intensity_measure="pgv", intensity_unit="m s-1",
                                              intensity_unit_label="m/s")
    write_exchange_files(dataset, tmp_path)
    namespace = {"nrml": "http://openquake.org/xmlns/nrml/0.5"}
    root = ElementTree.parse(tmp_path / OPENQUAKE_FILE).getroot()
    function = root.find(".//nrml:fragilityFunction[@id='ROCK.b_1.sand.recommended']", namespace)
    assert function.find("nrml:imls", namespace).get("imt") == "PGV"
    params = function.findall("nrml:params", namespace)[1]  # rocking-0.2: median 0.3 m/s, beta 0.5
    mean, stddev = float(params.get("mean")), float(params.get("stddev"))
    assert mean / np.sqrt(1 + (stddev / mean) ** 2) == pytest.approx(30.0, rel=1e-9)


def test_no_file_for_a_measure_the_consumers_do_not_have(tmp_path):
    from rockfrag.exchange import ExchangeWarning

    (tmp_path / OPENQUAKE_FILE).write_text("an older run's file")
    (tmp_path / "fragility_pelicun.csv").write_text("an older run's file")
    with pytest.warns(ExchangeWarning, match="pelicun has no demand type for the measure 'avgsa'"):
        written = write_exchange_files(exchange_dataset().assign_attrs(intensity_measure="avgsa"), tmp_path, 1.0)
    assert written == [] and not (tmp_path / OPENQUAKE_FILE).exists()
    assert not (tmp_path / "fragility_pelicun.csv").exists()


def test_damage_states_that_clash_as_openquake_limit_states_are_refused(tmp_path):
    dataset = exchange_dataset().assign_coords(damage_state=["uplift", "rocking-0.2", "rocking-0_2", "overturning"])
    with pytest.raises(ConfigError, match="rocking-0_2"):
        write_exchange_files(dataset, tmp_path)


def test_ids_that_clash_are_refused_and_the_comments_carry_the_dispersion_parts(tmp_path):
    """'b-1' and 'b_1' give the same component ID: a ConfigError names both. beta_model is in the comments only."""
    with pytest.raises(ConfigError, match="same component ID ROCK.b_1.sand.recommended"):
        write_exchange_files(exchange_dataset().assign_coords(block=["b-1", "b_1"]), tmp_path)
    write_exchange_files(exchange_dataset(), tmp_path)
    text = (tmp_path / OPENQUAKE_FILE).read_text()
    start = text.index("<!-- ROCK.b_1.sand.recommended")
    comment = text[start:text.index("-->", start)]
    assert "studied range 0.05-3 g" in comment and "beta is the total; beta_model 0.2" in comment
    params = ElementTree.parse(tmp_path / OPENQUAKE_FILE).getroot().iter("{http://openquake.org/xmlns/nrml/0.5}params")
    assert {tuple(sorted(element.attrib)) for element in params} == {("ls", "mean", "stddev")}


NRML = {"nrml": "http://openquake.org/xmlns/nrml/0.5"}


def test_a_row_censored_at_the_cap_is_the_records_fractions_held_above_the_cap(tmp_path):
    """The writer alone (no OpenQuake): a cell with a censored row is a discrete function whose IMLs rise, are
    distinct and include the cap; a censored row is the records' fractions at the levels up to the cap (never
    the level above it), probability_at_cap at the cap and at the last IML (what OpenQuake holds above it); its
    comment says what it is, never "not reached"; every lognormal row of it is within DISCRETE_ERROR of its
    curve between the IMLs (linear interpolation, as OpenQuake's FragilityFunctionDiscrete)."""
    dataset = exchange_dataset()
    write_exchange_files(dataset, tmp_path)
    text = (tmp_path / OPENQUAKE_FILE).read_text()
    root = ElementTree.parse(tmp_path / OPENQUAKE_FILE).getroot()
    cells = {pelicun_id(b, s, m): dataset.sel(soil=s, block=b, model=m) for s in dataset.soil.values
             for b in dataset.block.values for m in dataset.model.values}
    discrete = 0
    for function in root.iterfind(".//nrml:fragilityFunction", NRML):
        cell = cells[function.get("id")]
        if not np.isin(cell.status.values, FRACTIONS).any():
            assert function.get("format") == "continuous"
            continue
        discrete += 1
        assert function.get("format") == "discrete"
        imls = np.array(function.find("nrml:imls", NRML).text.split(), float)
        assert (np.diff(imls) > 0).all()
        cap = float(cell.studied_im_max)
        assert cap in imls
        dense = np.geomspace(imls[0], imls[-1], 20001)
        for state, poes in zip(cell.damage_state.values, function.iterfind("nrml:poes", NRML)):
            poes = np.array(poes.text.split(), float)
            row = cell.sel(damage_state=state)
            if str(row.status.values) in FRACTIONS:
                at_cap = float(row.probability_at_cap)
                assert poes[imls == cap][0] == pytest.approx(at_cap, abs=1e-8) and poes[-1] == pytest.approx(at_cap)
                levels = LEVELS_OF[str(cell.block.values)]
                credible = levels <= cap
                np.testing.assert_allclose(np.interp(levels[credible], imls, poes),
                                           row.empirical_fraction.values[credible], atol=1e-8)
                assert not np.isclose(poes, row.empirical_fraction.values[-1]).any()  # the level above the cap
                start = text.index(f"<!-- {function.get('id')}")
                note = text[start:text.index("-->", start)].split(f"; {state}:")[1]
                for later in cell.damage_state.values:
                    note = note.split(f"; {later}:")[0]
                assert "not reached" not in note and "never reached" not in note
                assert f"reached by {100 * at_cap:.0f} % of the records at {cap:.4g} g" in note, note
            elif np.isfinite(float(row["median"])) and float(row.beta) > 0:
                exact = norm.cdf(np.log(dense / float(row["median"])) / float(row.beta))
                assert np.abs(np.interp(dense, imls, poes) - exact).max() <= DISCRETE_ERROR
    assert discrete == 6


@pytest.mark.parametrize("beta", [0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.8, 1.0, 1.5, 2.0])
def test_a_lognormal_on_the_discrete_grid_is_within_the_stated_error(beta):
    """DISCRETE_ERROR holds over the dispersions a fit gives: OpenQuake's linear interpolation between the IMLs
    ``discrete_curves`` samples a lognormal at, against the lognormal, at 2e5 intensities."""
    imls, poes = discrete_curves([WrittenState("lognormal", 0.7, beta)], {}, (0.1, 3.0))
    dense = np.geomspace(imls[0], imls[-1], 200001)
    error = np.abs(np.interp(dense, imls, poes[0]) - norm.cdf(np.log(dense / 0.7) / beta)).max()
    assert error <= DISCRETE_ERROR
    assert poes[0, 0] < 1e-8 and poes[0, -1] > 1 - 1e-8  # 6 beta either side: held at 0 and 1 beyond
