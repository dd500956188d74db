"""Hazard from regional runs: ``[hazard] site = [lon, lat]`` picks the nearest site of a multi-site OpenQuake
export or USGS file; the great-circle distance is checked against an independent formula; a multi-site file
without a site is one error naming the fix; a far site warns; the site travels with the risk's attributes."""

from __future__ import annotations

import math
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr

from rockfrag import errors
from rockfrag.cli import main
from rockfrag.config import load_study
from rockfrag.errors import ConfigError
from rockfrag.hazard import (
    EARTH_RADIUS_KM,
    HazardSiteWarning,
    great_circle_km,
    load_hazard,
    study_hazard,
)
from rockfrag.risk import risk_dataset

DATA = Path(__file__).parent / "data"
REGIONAL = DATA / "openquake_hazard_curve-rlz-000-PGA_6sites.csv"
"""Six sites (lon -122.50, -122.39, -122.27 x lat 38.10, 38.20, in that row order), site i with
H_i(s) = K0[i] s^-2.5 [1/yr]; site 0's last level has a zero probability (as in real exports)."""
K0 = 1e-4 * (1 + 0.4 * np.arange(6))
SITES = [(lon, lat) for lat in (38.10, 38.20) for lon in (-122.50, -122.39, -122.27)]
USGS_TWO = DATA / "usgs_hazard_SA1P0_2sites.json"
"""The single-site USGS response at (-118.25, 34.05) and a copy at (-117.0, 34.5) with doubled frequencies."""


def vector_distance_km(lon1, lat1, lon2, lat2):
    """Great-circle distance from the angle between unit vectors (atan2 of |a x b| and a.b): not the haversine."""
    def unit(lon, lat):
        lon, lat = math.radians(lon), math.radians(lat)
        return np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])

    a, b = unit(lon1, lat1), unit(lon2, lat2)
    return EARTH_RADIUS_KM * math.atan2(np.linalg.norm(np.cross(a, b)), float(a @ b))


def test_the_distance_is_the_great_circle_distance():
    assert great_circle_km(0.0, 0.0, 0.0, 1.0) == pytest.approx(EARTH_RADIUS_KM * math.pi / 180, rel=1e-12)
    assert great_circle_km(10.0, 0.0, 190.0, 0.0) == pytest.approx(EARTH_RADIUS_KM * math.pi, rel=1e-12)
    assert great_circle_km(-179.9, 0.0, 179.9, 0.0) == pytest.approx(EARTH_RADIUS_KM * math.radians(0.2), rel=1e-9)
    rng = np.random.default_rng(7)
    for _ in range(50):
        lon1, lon2 = rng.uniform(-180, 360, 2)
        lat1, lat2 = rng.uniform(-90, 90, 2)
        assert great_circle_km(lon1, lat1, lon2, lat2) == pytest.approx(vector_distance_km(lon1, lat1, lon2, lat2),
                                                                        rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("site", [(-122.26, 38.21), (-122.49, 38.11), (-122.40, 38.16), (237.6, 38.0),
                                  (-122.33, 38.14)])
def test_a_regional_openquake_export_gives_the_nearest_sites_curve(site):
    hazard = load_hazard(REGIONAL, "pga", site=site)
    distances = [vector_distance_km(*site, *other) for other in SITES]
    expected = int(np.argmin(distances))
    assert hazard.site.index == expected and hazard.site.count == 6
    assert (hazard.site.longitude, hazard.site.latitude) == pytest.approx(SITES[expected])
    assert hazard.site.distance_km == pytest.approx(distances[expected], rel=1e-9)
    assert hazard.site.requested == pytest.approx(site)
    # the curve is that site's: lambda = -ln(1 - poe)/50 gives back its power law
    assert hazard.annual_frequency == pytest.approx(K0[expected] * hazard.intensity ** -2.5, rel=1e-4)
    assert hazard.intensity.size == (5 if expected == 0 else 6)  # site 0's zero probability is left out


def test_a_multi_site_file_without_a_site_names_the_fix(tmp_path):
    with pytest.raises(ConfigError, match=r"6 sites .*lon -122.5 to -122.27, lat 38.1 to 38.2.*\[hazard\] site = "
                                          r"\[lon, lat\]") as error:
        load_hazard(REGIONAL, "pga")
    assert error.value.field == "hazard.file" and str(REGIONAL) in str(error.value)
    study = tmp_path / "study.toml"
    study.write_text(f'[hazard]\nfile = "{REGIONAL}"\n')
    with pytest.raises(ConfigError, match="6 sites"):
        load_study(study)  # refused when the study is read, before any run
    with pytest.raises(ConfigError, match="2 sites.*site = \\[lon, lat\\]"):
        load_hazard(USGS_TWO, "sa", 1.0)


def test_a_site_is_refused_for_a_file_without_coordinates():
    with pytest.raises(ConfigError, match="states no site coordinates"):
        load_hazard(None, "pga", site=(10.0, 45.0))  # the shipped example, a rockfrag CSV


def test_usgs_responses_for_several_sites_and_one_site_with_its_distance():
    near_second = load_hazard(USGS_TWO, "sa", 1.0, site=(-117.1, 34.4))
    near_first = load_hazard(USGS_TWO, "sa", 1.0, site=(-118.2, 34.0))
    assert near_second.site.index == 1 and near_first.site.index == 0
    assert near_second.annual_frequency == pytest.approx(2 * near_first.annual_frequency)
    assert near_second.site.distance_km == pytest.approx(vector_distance_km(-117.1, 34.4, -117.0, 34.5), rel=1e-9)
    one = load_hazard(DATA / "usgs_hazard_SA1P0.json", "sa", 1.0, site=(-118.0, 34.05))
    assert one.site.count == 1
    assert one.site.distance_km == pytest.approx(vector_distance_km(-118.0, 34.05, -118.25, 34.05), rel=1e-9)
    single = load_hazard(DATA / "openquake_hazard_curve-mean-PGA.csv", "pga", site=(10.0, 45.5))
    assert single.site.distance_km == pytest.approx(EARTH_RADIUS_KM * math.radians(0.5), rel=1e-9)


def study(site):
    return SimpleNamespace(hazard_file=str(REGIONAL), measure="pga", period=1.0, hazard_site=site)


def test_a_far_site_is_warned_and_a_near_one_is_not():
    with pytest.warns(HazardSiteWarning, match=r"(\d+) km from the study's site \(more than 50 km\)") as caught:
        hazard = study_hazard(study((-121.0, 38.2)))
    distance = vector_distance_km(-121.0, 38.2, -122.27, 38.20)
    assert distance > 100 and f"{distance:.0f} km" in str(caught[0].message)
    assert hazard.site.index == 5
    with warnings.catch_warnings():
        warnings.simplefilter("error", HazardSiteWarning)
        assert study_hazard(study((-122.3, 38.2))).site.distance_km < 5
        assert study_hazard(SimpleNamespace(hazard_file="", measure="pga", period=1.0)).site is None  # no site key


@pytest.mark.parametrize("value, message", [
    ("[10.0]", r"\[10\.0\] is a list; must be \[lon, lat\]"),
    ('"10, 45"', "is a string; must be"),
    ("[360.0, 45.0]", r"hazard\.site\[0\] \(longitude\): 360 out of range; must be a number >= -180.0 and < 360.0"),
    ("[-180.5, 45.0]", r"\(longitude\): -180.5 out of range"),
    ("[10.0, 90.5]", r"hazard\.site\[1\] \(latitude\): 90.5 out of range; must be a number from -90.0 to 90.0"),
    ("[nan, 45.0]", r"\(longitude\): nan is a number; must be"),
    ("[10.0, inf]", r"\(latitude\): inf is a number"),
    ("[true, 45.0]", "true is a boolean"),
])
def test_the_study_key_is_two_finite_coordinates(tmp_path, value, message):
    path = tmp_path / "study.toml"
    path.write_text(f'[hazard]\nfile = "{REGIONAL}"\nsite = {value}\n')
    with pytest.raises(ConfigError, match=message) as error:
        load_study(path)
    assert error.value.source == str(path)


def test_the_study_key_reaches_the_risk_and_its_attributes(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(f'[hazard]\nfile = "{REGIONAL}"\nsite = [-122.25, 38.19]\n')
    config = load_study(path)
    assert config.hazard_site == (-122.25, 38.19)
    hazard = study_hazard(config)
    median, beta = 0.6, 0.4
    dims = ("soil", "block", "model", "damage_state")
    one = np.ones((1, 1, 1, 1))
    fragility = xr.Dataset({"median": (dims, median * one), "beta": (dims, beta * one)},
                           coords={"soil": ["sand"], "block": ["b"], "model": ["winkler"],
                                   "damage_state": ["overturning"]})
    risk = risk_dataset(fragility, hazard, 50.0)
    # lambda_DS of a lognormal fragility on a power-law hazard: K0 median^-k exp(k^2 beta^2 / 2) (Cornell et al.)
    closed_form = K0[5] * median ** -2.5 * math.exp(2.5**2 * beta**2 / 2)
    assert float(risk["annual_frequency"].squeeze()) == pytest.approx(closed_form, rel=2e-3)
    distance = vector_distance_km(-122.25, 38.19, -122.27, 38.20)
    assert risk.attrs["hazard_site_distance_km"] == pytest.approx(distance, rel=1e-9)
    assert (risk.attrs["hazard_site_longitude_deg"], risk.attrs["hazard_site_latitude_deg"]) == (-122.27, 38.2)
    assert (risk.attrs["study_site_longitude_deg"], risk.attrs["study_site_latitude_deg"]) == (-122.25, 38.19)
    source = risk.attrs["hazard_source"]
    assert f"site 6 of 6 (lon -122.27, lat 38.2), {distance:.1f} km from the study's site" in source
    written = tmp_path / "risk.nc"
    risk.to_netcdf(written)
    with xr.open_dataset(written) as reread:  # a consumer reads the site back from the netCDF attributes
        assert reread.attrs["hazard_site_distance_km"] == pytest.approx(distance, rel=1e-9)


def test_rockfrag_fragility_prints_the_site_and_warns_when_far(tmp_path, capsys, monkeypatch):
    import rockfrag.study

    def stop(*args, **kwargs):
        raise errors.PipelineError("stopped after the hazard (test)")

    monkeypatch.setattr(rockfrag.study, "study_records", stop)  # the run itself is not this test's business
    path = tmp_path / "study.toml"
    path.write_text(f'[hazard]\nfile = "{REGIONAL}"\nsite = [-121.0, 38.2]\n')
    with warnings.catch_warnings():
        warnings.simplefilter("always", HazardSiteWarning)
        main(["fragility", str(path), "--output", str(tmp_path / "out"), "--no-progress", "--serial"])
    captured = capsys.readouterr()
    distance = vector_distance_km(-121.0, 38.2, -122.27, 38.20)
    assert f"hazard: {REGIONAL}, site 6 of 6 (lon -122.27, lat 38.2), {distance:.1f} km" in captured.out
    assert "rockfrag: warning:" in captured.err and "more than 50 km" in captured.err
