"""Every soil has a site class and its site's hazard: the Vs30 keys, a curve per soil or amplified from one site,
the horizontal component each source states, a value that is not a number named by line and column, and each soil's
risk recomputed by hand from fragility.nc."""

from __future__ import annotations

import json
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from rockfrag.config import load_study
from rockfrag.errors import ConfigError
from rockfrag.hazard import COMPONENTS, load_hazard
from rockfrag.risk import risk_dataset
from rockfrag.site_amplification import SiteAmplificationWarning
from rockfrag.site_hazard import site_hazard_dataset, study_site_hazards
from rockfrag.soils import SITE_CLASS_VS30, SOILS, site_class

DATA = Path(__file__).parent / "data"
K0, K = 1e-4, 2.5  # the shipped example: H(s) = 1e-4 s^-2.5 [1/yr], PGA [g]


def curve_file(path: Path, scale: float = 1.0, extra: str = "") -> Path:
    """A rockfrag CSV of scale x the shipped power law (PGA)."""
    s = np.geomspace(0.01, 3.0, 25)
    rows = "\n".join(f"{a:.6g},{b:.9g}" for a, b in zip(s, scale * K0 * s**-K))
    path.write_text(f"# measure = pga\n{extra}intensity,frequency\n{rows}\n")
    return path


def study_file(tmp_path: Path, text: str, soils: str = '["sand", "rock"]') -> Path:
    path = tmp_path / "study.toml"
    path.write_text(f"soils = {soils}\n{text}")
    return path


# ------------------------------------------------------------------ site classes and Vs30

def test_the_shipped_soils_stand_for_site_classes():
    assert {name: (soil.site_class, soil.vs30) for name, soil in SOILS.items()} == {
        "clay": ("E", 150.0), "sand": ("D", 260.0), "gravel": ("C", 530.0), "rock": ("B", 1080.0),
        "steel": ("", None)}
    for name, vs30 in SITE_CLASS_VS30.items():
        assert site_class(vs30) == name  # each class's representative Vs30 lies in it
    assert [site_class(v) for v in (180.0, 180.1, 360.0, 760.0, 760.1, 1500.0, 1500.1)] == \
        ["E", "D", "D", "C", "B", "B", "A"]


def test_eurocode_8_ground_types_follow_en_1998_1_table_3_1():
    """EN 1998-1:2004 Table 3.1 by Vs30 [m/s]: A > 800, B 360-800, C 180-360, D < 180 (a bound: the softer type)."""
    from rockfrag.soils import ec8_ground_type

    assert [ec8_ground_type(v) for v in (100.0, 180.0, 180.1, 360.0, 360.1, 800.0, 800.1, 3000.0)] == \
        ["D", "D", "C", "C", "B", "B", "A", "A"]
    assert {name: ec8_ground_type(soil.vs30) for name, soil in SOILS.items()} == {
        "clay": "D", "sand": "C", "gravel": "B", "rock": "A", "steel": ""}


def test_the_user_states_a_sites_vs30(tmp_path):
    path = study_file(tmp_path, '[hazard]\nvs30 = { steel = 400.0, sand = 200.0 }\n'
                      '[soils_custom.loam]\nshear_modulus = 50e6\nvs30 = 300.0\n', '["sand", "steel", "loam"]')
    soils = {soil.name: soil for soil in load_study(path).soils}
    assert (soils["steel"].vs30, soils["steel"].site_class) == (400.0, "C")
    assert (soils["sand"].vs30, soils["loam"].vs30, soils["loam"].site_class) == (200.0, 300.0, "D")
    assert soils["sand"].shear_modulus == SOILS["sand"].shear_modulus  # the bed is not the site


@pytest.mark.parametrize("text, field, words", [
    ("[hazard]\nvs30 = { stel = 400.0 }\n", "hazard.vs30.stel", "not a soil of the study (did you mean 'steel'?)"),
    ("[hazard]\nvs30 = { steel = -5.0 }\n", "hazard.vs30.steel", "-5 out of range; must be a number > 0.0"),
    ("[hazard]\nvs30 = 300.0\n", "hazard.vs30", "must be a table"),
    ("[hazard]\nvs30_sigma = 3.0\n", "hazard.vs30_sigma", "3 out of range"),
    ("[hazard]\nreference_vs30 = 0.0\n", "hazard.reference_vs30", "0 out of range"),
    ("[soils_custom.loam]\nshear_modulus = 5e7\nvs30 = true\n", "soils_custom.loam.vs30", "true is a boolean"),
    ('[hazard]\nfile = { sandy = "x.csv" }\n', "hazard.file.sandy", "neither a soil of the study nor a site class"),
    ("[hazard]\nfile = {}\n", "hazard.file", "empty table"),
    ('[hazard]\nfile = { sand = 3 }\n', "hazard.file.sand", "must be a string"),
])
def test_bad_site_keys_name_the_field(tmp_path, text, field, words):
    with pytest.raises(ConfigError) as error:
        load_study(study_file(tmp_path, text, '["sand", "steel", "loam"]' if "loam" in text else '["sand", "steel"]'))
    assert error.value.field == field and words in error.value.reason
    assert error.value.source == str(tmp_path / "study.toml")


def test_a_vs30_outside_the_site_terms_data_is_warned_and_clipped(tmp_path):
    path = study_file(tmp_path, "[soils_custom.peat]\nshear_modulus = 5e6\nvs30 = 100.0\n", '["peat"]')
    with pytest.warns(SiteAmplificationWarning, match="soil peat: Vs30 100 m/s is below"):
        config = load_study(path)
    with pytest.warns(SiteAmplificationWarning):
        peat = study_site_hazards(config)["peat"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", SiteAmplificationWarning)  # 150 m/s: inside the data, no warning
        at_150 = study_site_hazards(load_study(study_file(
            tmp_path, "[soils_custom.peat]\nshear_modulus = 5e6\nvs30 = 100.0\n[hazard]\nvs30 = { peat = 150.0 }\n",
            '["peat"]')))["peat"]
    np.testing.assert_array_equal(peat.annual_frequency, at_150.annual_frequency)


# ------------------------------------------------------------------ a curve per soil, or amplified

def test_a_curve_per_soil_or_site_class_is_taken_as_it_is(tmp_path):
    sand, rock = curve_file(tmp_path / "sand.csv", 2.0), curve_file(tmp_path / "b.csv", 0.5)
    config = load_study(study_file(tmp_path, f'[hazard]\nfile = {{ sand = "{sand}", B = "{rock}" }}\n'))
    hazards = study_site_hazards(config)
    assert list(hazards) == ["sand", "rock"] and hazards.reference is None
    np.testing.assert_array_equal(hazards["sand"].annual_frequency, load_hazard(sand).annual_frequency)
    np.testing.assert_array_equal(hazards["rock"].annual_frequency, load_hazard(rock).annual_frequency)
    assert "file.B" in hazards.how["rock"]


@pytest.mark.parametrize("soils, files, words", [
    ('["sand", "rock"]', "sand", "no hazard curve for the soil rock: name it or its site class B"),
    ('["sand", "steel"]', "sand", "no hazard curve for the soil steel: its site is the reference site"),
])
def test_a_soil_without_a_curve_is_an_error(tmp_path, soils, files, words):
    curve = curve_file(tmp_path / "one.csv")
    with pytest.raises(ConfigError, match=words) as error:
        load_study(study_file(tmp_path, f'[hazard]\nfile = {{ {files} = "{curve}" }}\n', soils))
    assert error.value.field == "hazard.file"


def test_the_soils_curves_state_one_component(tmp_path):
    sand = curve_file(tmp_path / "sand.csv", extra="# component = RotD100\n")
    rock = curve_file(tmp_path / "rock.csv")
    with pytest.raises(ConfigError, match="different horizontal components \\(sand RotD100, rock RotD50\\)"):
        load_study(study_file(tmp_path, f'[hazard]\nfile = {{ sand = "{sand}", rock = "{rock}" }}\n'))


def test_one_curve_is_amplified_to_each_soils_site_and_the_reference_site_keeps_it(tmp_path):
    config = load_study(study_file(tmp_path, "[hazard]\nreference_vs30 = 260.0\n",
                                   '["clay", "sand", "rock", "steel"]'))
    hazards = study_site_hazards(config)
    reference = hazards.reference
    assert hazards["sand"] is reference and hazards["steel"] is reference  # Vs30 of the reference, and none
    low = 0.05  # small motion: the softer site shakes more, the stiffer less
    frequencies = {soil: float(np.interp(np.log(low), np.log(hazards[soil].intensity),
                                         np.log(hazards[soil].annual_frequency))) for soil in ("clay", "sand", "rock")}
    assert frequencies["clay"] > frequencies["sand"] > frequencies["rock"]
    for soil in ("clay", "rock"):
        assert np.all(np.diff(hazards[soil].annual_frequency) < 0)
        assert hazards[soil].component == "RotD50" and hazards[soil].notes["site_vs30_m_s"] == SOILS[soil].vs30


@pytest.mark.parametrize("study, words", [
    ("[intensity]\nmeasure = \"sa\"\nperiod = 12.0\n", "Sa period 12 s is outside BSSA14's 0.01-10 s; give a "
                                                        "hazard curve per soil"),
    ("[intensity]\nmeasure = \"pga_ratio\"\n[blocks.a]\nb = 0.3\nh = 1.5\nmass = 2000.0\nfootprint_area = 0.48\n"
     "[blocks.b]\nb = 1.0\nh = 1.5\nmass = 20000.0\nfootprint_area = 2.0\n", "the study's blocks differ"),
])
def test_a_measure_the_site_term_cannot_amplify_asks_for_a_curve_per_soil(tmp_path, study, words):
    measure, period = ("sa", 12.0) if "period" in study else ("pga_ratio", None)
    header = f"# measure = {measure}\n" + (f"# period = {period}\n" if period else "") + \
        ("# units = 1\n" if measure == "pga_ratio" else "")
    curve = tmp_path / "curve.csv"
    curve.write_text(header + "intensity,frequency\n0.1,1e-2\n1.0,1e-4\n")
    with pytest.raises(ConfigError, match=words) as error:
        load_study(study_file(tmp_path, f'{study}[hazard]\nfile = "{curve}"\n'))
    assert error.value.field == "hazard.file"


def test_the_dataset_holds_every_soils_curve_on_one_grid(tmp_path):
    config = load_study(study_file(tmp_path, "", '["clay", "rock", "steel"]'))
    hazards = study_site_hazards(config)
    dataset = site_hazard_dataset(hazards, config.soils, config.measure)
    assert dataset["site_hazard"].dims == ("soil", "hazard_intensity")
    assert dataset["site_hazard"].attrs["units"] == "yr-1"
    assert dataset["hazard_intensity"].attrs["units"] == "9.80665 m s-2"  # g, as every acceleration of the files
    assert dataset.attrs["hazard_component"] == "RotD50"
    assert list(dataset["site_class"].values) == ["E", "B", ""] and np.isnan(dataset["site_vs30"].values[2])
    grid = dataset["hazard_intensity"].values
    np.testing.assert_allclose(dataset["site_hazard"].sel(soil="steel"), K0 * grid**-K, rtol=1e-5)


# ------------------------------------------------------------------ components and non-numbers

def test_every_source_states_its_horizontal_component(tmp_path):
    assert load_hazard().component == "RotD50"  # the shipped example says so in its header
    assert load_hazard(curve_file(tmp_path / "plain.csv")).component == "RotD50"  # absent: RotD50
    assert "not stated" in load_hazard(tmp_path / "plain.csv").notes["component_basis"]
    assert load_hazard(curve_file(tmp_path / "gm.csv", extra="# component = geometric-mean\n")).component == \
        "geometric-mean"
    assert load_hazard(DATA / "openquake_hazard_curve-mean-PGA.csv").component == "RotD50"
    assert load_hazard(DATA / "usgs_hazard_SA1P0.json", "sa", 1.0).component == "RotD50"
    with pytest.raises(ConfigError, match="component 'RotD5O' unknown \\(did you mean 'RotD50'\\?\\); allowed "
                                          + ", ".join(COMPONENTS)):
        load_hazard(curve_file(tmp_path / "typo.csv", extra="# component = RotD5O\n"))


def test_the_risk_states_the_hazards_component(tmp_path):
    dims = ("soil", "block", "model", "damage_state")
    fragility = xr.Dataset({"median": (dims, np.full((1, 1, 1, 1), 0.5)), "beta": (dims, np.full((1, 1, 1, 1), 0.4))},
                           coords={"soil": ["sand"], "block": ["b"], "model": ["m"], "damage_state": ["overturning"]})
    hazard = load_hazard(curve_file(tmp_path / "c.csv", extra="# component = RotD100\n"))
    assert risk_dataset(fragility, hazard).attrs["hazard_component"] == "RotD100"
    assert risk_dataset(fragility, {"sand": hazard}).attrs["hazard_component"] == "RotD100"


@pytest.mark.parametrize("text, where", [
    ("# measure = pga\nintensity,frequency\n0.1,1e-2\n0.2,nan\n0.3,1e-4\n", "line 4, column 2 (frequency): 'nan'"),
    ("# measure = pga\n\nintensity,frequency\n0.1,1e-2\n,1e-3\n", "line 5, column 1 (intensity): an empty cell"),
    ("# measure = pga\nintensity,frequency\n0.1,1e-2\n0.2,inf\n", "line 4, column 2 (frequency): 'inf'"),
    ("# measure = pga\nintensity,frequency\n0.1,-\n", "line 3, column 2 (frequency): '-'"),
])
def test_a_value_that_is_not_a_number_names_the_line_and_column(tmp_path, text, where):
    path = tmp_path / "curve.csv"
    path.write_text(text)
    with pytest.raises(ConfigError, match=re.escape(f"{where} is not a number")) as error:
        load_hazard(path)
    assert error.value.source == str(path)


def test_a_nan_in_an_openquake_export_is_named_not_dropped(tmp_path):
    lines = (DATA / "openquake_hazard_curve-mean-PGA.csv").read_text().splitlines()
    cells = lines[2].split(",")
    cells[5] = "nan"
    lines[2] = ",".join(cells)
    path = tmp_path / "hazard_curve-mean-PGA.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ConfigError, match=r"line 3, column 6 \(poe-0.2000000\): 'nan' is not a number"):
        load_hazard(path)


@pytest.mark.parametrize("token", ["NaN", "null", '"0.1"', "Infinity"])
def test_a_non_number_in_a_usgs_response_names_its_line_and_column(tmp_path, token):
    text = (DATA / "usgs_hazard_SA1P0.json").read_text()
    document = json.loads(text)
    values = document["response"][0]["data"][0]["yvalues"]
    marker = json.dumps(values[2])
    at = text.index(marker, text.index('"yvalues"'))
    changed = text[:at] + token + text[at + len(marker):]
    line = changed.count("\n", 0, at) + 1
    column = at - changed.rfind("\n", 0, at)
    path = tmp_path / "usgs.json"
    path.write_text(changed)
    with pytest.raises(ConfigError, match=rf"line {line}, column {column} \(yvalues\[2\]\): .* is not a number"):
        load_hazard(path, "sa", 1.0)


# ------------------------------------------------------------------ each soil's risk, by hand

def by_hand_rate(median: float, beta: float, grid: np.ndarray, curve: np.ndarray, cap: float = math.inf) -> float:
    """lambda_DS [1/yr] of a lognormal (beta = 0: step) fragility on a tabulated curve, log-log between its points.

    beta > 0: the integral of lambda(z) dP(DS | z) (by parts), by the trapezoid rule over +-7 beta. With a credible
    ``cap`` (rockfrag.fragility.capped_risk) the integral stops there and every intensity above it counts as
    reaching the state: + lambda(cap) (1 - P(DS | cap)).
    """
    def frequency(z):
        return np.exp(np.interp(np.log(z), np.log(grid), np.log(curve)))

    if beta == 0:
        return float(frequency(min(median, cap)))
    z = np.geomspace(median * math.exp(-7 * beta), min(median * math.exp(7 * beta), cap), 20001)
    density = np.exp(-0.5 * (np.log(z / median) / beta) ** 2) / (beta * z * math.sqrt(2 * math.pi))
    above = 0.0 if not math.isfinite(cap) else \
        float(frequency(cap)) * (1 - 0.5 * math.erfc(-math.log(cap / median) / (beta * math.sqrt(2))))
    return float(np.trapezoid(frequency(z) * density, z)) + above


def rock_rate(median: float, beta: float) -> float:
    """The 1080 m/s rock site on the shipped power law: a linear site term, factor A = (1080/760)^-0.6 and spread
    |c| sigma_lnVs30 = 0.6 x 0.2; lambda_DS = k0 A^k exp(k^2 sigma^2 / 2) median^-k exp(k^2 beta^2 / 2)."""
    factor, sigma = (1080.0 / 760.0) ** -0.6, 0.6 * 0.2
    return K0 * factor**K * math.exp(0.5 * K**2 * sigma**2) * median**-K * math.exp(0.5 * K**2 * beta**2)


def test_each_soils_probability_is_recomputed_by_hand_from_fragility_nc(small_pipeline):
    """P(DS in 50 years) of every fitted row from its median, beta and its own soil's site_hazard in fragility.nc,
    and the rock site's also in closed form."""
    with xr.open_dataset(small_pipeline.output / "fragility.nc") as data:
        fragility = data.load()
    assert "component" in " ".join(fragility.attrs) and fragility.attrs["hazard_component"] == "RotD50"
    assert fragility["site_hazard"].dims == ("soil", "hazard_intensity")
    grid = fragility["hazard_intensity"].values
    rows = fragility[["median", "beta", "probability_in_life"]].to_dataframe().dropna().reset_index()
    assert len(rows) >= 10 and set(rows["soil"]) == {"sand", "rock"}
    for row in rows.itertuples():
        curve = fragility["site_hazard"].sel(soil=row.soil).values
        cap = float(fragility["credible_max"].sel(block=row.block))  # the risk stops at the credible cap
        rate = by_hand_rate(row.median, row.beta, grid, curve, cap)
        assert row.probability_in_life == pytest.approx(1 - math.exp(-rate * 50.0), rel=1e-3), row
        if row.soil == "rock":
            assert by_hand_rate(row.median, row.beta, grid, curve) == pytest.approx(rock_rate(row.median, row.beta),
                                                                                   rel=1e-3)
    same = rows.pivot_table(index=["block", "model", "damage_state"], columns="soil", values=["median", "beta"])
    pairs = rows.pivot_table(index=["block", "model", "damage_state"], columns="soil", values="probability_in_life")
    alike = (same["median"]["sand"] == same["median"]["rock"]) & (same["beta"]["sand"] == same["beta"]["rock"])
    assert alike.any() and (pairs["sand"][alike] != pairs["rock"][alike]).all()  # one fragility, two site hazards


def test_a_lognormal_rows_risk_uses_its_own_soils_curve():
    config = load_study(None, {"soils": ["clay", "rock"]})
    hazards = study_site_hazards(config)
    dims = ("soil", "block", "model", "damage_state")
    medians, betas = np.array([0.3, 0.8, 1.4]), np.array([0.25, 0.45, 0.6])
    fragility = xr.Dataset({"median": (dims, np.broadcast_to(medians, (2, 1, 1, 3)).copy()),
                            "beta": (dims, np.broadcast_to(betas, (2, 1, 1, 3)).copy())},
                           coords={"soil": ["clay", "rock"], "block": ["b"], "model": ["m"],
                                   "damage_state": ["a", "b", "c"]})
    risk = risk_dataset(fragility, hazards)
    for soil in ("clay", "rock"):
        curve = hazards[soil]
        for median, beta, state in zip(medians, betas, ("a", "b", "c")):
            got = float(risk["annual_frequency"].sel(soil=soil, damage_state=state).squeeze())
            assert got == pytest.approx(by_hand_rate(median, beta, curve.intensity, curve.annual_frequency), rel=1e-3)
            if soil == "rock":
                assert got == pytest.approx(rock_rate(median, beta), rel=1e-3)


def test_warnings_of_the_default_study_are_none_about_sites():
    with warnings.catch_warnings():
        warnings.simplefilter("error", SiteAmplificationWarning)
        study_site_hazards(load_study())
