"""Hazard curves state their intensity measure and are checked against the study's; OpenQuake and USGS
exports are read as they come; the risk integral against its closed form."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from rockfrag.config import load_study
from rockfrag.errors import ConfigError
from rockfrag.hazard import _measure_from_imt, hazard_frequency, load_hazard, study_hazard
from rockfrag.risk import annual_frequency, probability_in_life

DATA = Path(__file__).parent / "data"


def power_law(s):
    return 1e-4 * np.asarray(s) ** -2.5


def test_risk_integral_matches_power_law_closed_form():
    """H(s) = k0 s^-k and a lognormal fragility: lambda = k0 median^-k exp(k^2 beta^2 / 2)."""
    hazard = load_hazard()  # the shipped example: k0 = 1e-4, k = 2.5, PGA
    assert hazard.measure == "pga"
    for median, beta in ((0.3, 0.3), (0.62, 0.41), (1.5, 0.6)):
        expected = 1e-4 * median**-2.5 * np.exp(0.5 * 2.5**2 * beta**2)
        assert annual_frequency(median, beta, hazard) == pytest.approx(expected, rel=1e-3)
    assert probability_in_life(1e-3, 50) == pytest.approx(1 - np.exp(-0.05))


def test_a_step_fragility_has_the_hazard_frequency_at_its_threshold():
    hazard = load_hazard()
    assert annual_frequency(0.75, 0.0, hazard) == pytest.approx(power_law(0.75), rel=1e-5)  # table: 7 digits
    assert np.isnan(annual_frequency(np.nan, np.nan, hazard))


def test_openquake_export_is_converted_from_poe_in_the_investigation_time():
    hazard = load_hazard(DATA / "openquake_hazard_curve-mean-PGA.csv", "pga")
    assert hazard.notes["investigation_time_years"] == 50.0
    # lambda = -ln(1 - poe) / T recovers the power law the file was written from (6 digits in the file)
    np.testing.assert_allclose(hazard.annual_frequency, power_law(hazard.intensity), rtol=2e-5)
    assert hazard_frequency(hazard, 0.3) == pytest.approx(power_law(0.3), rel=1e-4)


def test_usgs_json_gives_the_total_curve_for_its_imt():
    hazard = load_hazard(DATA / "usgs_hazard_SA1P0.json", "sa", 1.0)
    assert hazard.measure == "sa" and hazard.period == 1.0
    np.testing.assert_allclose(hazard.annual_frequency, power_law(hazard.intensity), rtol=1e-12)


@pytest.mark.parametrize("path, measure, period, message", [
    ("openquake_hazard_curve-mean-PGA.csv", "sa", 1.0, "curve is for PGA but the study's intensity measure is Sa"),
    ("usgs_hazard_SA1P0.json", "pga", None, "curve is for Sa\\(1 s\\) but the study's intensity measure is PGA"),
    ("usgs_hazard_SA1P0.json", "sa", 0.5, "Sa\\(1 s\\) but the study uses Sa\\(0.5 s\\)"),
    ("usgs_hazard_SA1P0.json", "pgv", None, "give a hazard curve for PGV"),
])
def test_a_hazard_for_another_measure_is_a_config_error(path, measure, period, message):
    with pytest.raises(ConfigError, match=message) as error:
        load_hazard(DATA / path, measure, period)
    assert path in str(error.value) and "hazard.file" in str(error.value)


def test_the_shipped_example_is_for_pga_only():
    with pytest.raises(ConfigError, match="PGA only"):
        load_hazard(None, "sa", 1.0)
    study = SimpleNamespace(hazard_file="", measure="sa", period=1.0)
    assert study_hazard(study) is None  # no hazard for an Sa study without a file: risk not computed
    assert study_hazard(SimpleNamespace(hazard_file="", measure="pga", period=1.0)).measure == "pga"


def test_a_csv_without_its_measure_is_refused(tmp_path):
    path = tmp_path / "hazard.csv"
    path.write_text("intensity,annual_frequency\n0.1,1e-2\n0.2,2e-3\n")
    with pytest.raises(ConfigError, match="does not state its intensity measure"):
        load_hazard(path, "pga")
    path.write_text("# measure = sa\nintensity,annual_frequency\n0.1,1e-2\n0.2,2e-3\n")
    with pytest.raises(ConfigError, match="must state its period"):
        load_hazard(path, "sa", 1.0)


def test_bad_hazard_file_is_named(tmp_path):
    path = tmp_path / "hazard.csv"
    path.write_text("# measure = pga\nintensity,freq\n0.1,1e-3\n0.2,2e-3\n")
    with pytest.raises(ConfigError, match="decrease") as error:
        load_hazard(path, "pga")
    assert str(path) in str(error.value)
    with pytest.raises(ConfigError, match="not found"):
        load_hazard(tmp_path / "missing.csv", "pga")
    many = tmp_path / "two_sites.csv"
    lines = (DATA / "openquake_hazard_curve-mean-PGA.csv").read_text().splitlines()
    many.write_text("\n".join([*lines, lines[-1]]) + "\n")
    with pytest.raises(ConfigError, match="2 sites"):
        load_hazard(many, "pga")


def test_the_study_file_is_refused_before_any_run_when_its_hazard_is_for_another_measure(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(f'[hazard]\nfile = "{DATA / "usgs_hazard_SA1P0.json"}"\n')
    with pytest.raises(ConfigError, match="hazard.file.*Sa\\(1 s\\).*PGA"):
        load_study(study)
    study.write_text(f'[intensity]\nmeasure = "sa"\nperiod = 1.0\n'
                     f'[hazard]\nfile = "{DATA / "usgs_hazard_SA1P0.json"}"\n')
    assert load_study(study).measure == "sa"


@pytest.mark.parametrize("imt, expected", [
    ("PGA", ("pga", None, 1.0)), ("pgv", ("pgv", None, 0.01)),  # OpenQuake and USGS give PGV in cm/s
    ("SA(0.2)", ("sa", 0.2, 1.0)), ("SA0P2", ("sa", 0.2, 1.0)), ("SA1P0", ("sa", 1.0, 1.0)),
])
def test_openquake_and_usgs_imts_are_read_by_the_measure_registry(imt, expected):
    assert _measure_from_imt(imt, "here") == expected


def test_an_imt_no_measure_registers_is_refused_with_the_registered_ones():
    with pytest.raises(ConfigError, match=r"'PGD' not supported; allowed PGA, PGV, SA\(T\)"):
        _measure_from_imt("PGD", "here")
