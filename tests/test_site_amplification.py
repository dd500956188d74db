"""The NGA-West2 site term (BSSA14) against its published coefficients and against OpenQuake's own BSSA14; the
factor of 1 at the reference site; the convolution of a hazard curve with a lognormal factor against its closed
form (Bazzurro & Cornell 2004)."""

from __future__ import annotations

import json
import math
import subprocess
import warnings

import numpy as np
import pytest
from scipy.optimize import brentq

from rockfrag.site_amplification import (
    REFERENCE_VS30,
    ROCK_PGA_LIMIT,
    SiteAmplificationWarning,
    amplification,
    clip_vs30,
    coefficients,
    convolve_hazard,
    rock_median,
    site_term,
    site_term_vs30_slope,
)
from tests.helpers import CONSUMERS, consumer_python

# BSSA14's site coefficients as printed in its coefficient table (Boore et al. 2014, Earthquake Spectra 30(3),
# electronic supplement; the same rows in OpenQuake's boore_2014.py): c, Vc [m/s], f4, f5 [s/m]. f3 = 0.1 g,
# Vref = 760 m/s at every period.
PRINTED = {
    "pga": (-0.600000, 1500.000000, -0.150000, -0.007010),
    "pgv": (-0.840000, 1300.000000, -0.100000, -0.008440),
    0.2: (-0.687620, 1392.610000, -0.246580, -0.006140),
    0.32: (-0.861750, 1297.650000, -0.213180, -0.006800),
    0.34: (-0.877260, 1287.500000, -0.208160, -0.006890),
    1.0: (-1.050000, 1109.950000, -0.105210, -0.008440),
    3.0: (-1.011200, 922.430000, -0.013577, -0.001830),
}
VS30S = (150.0, 220.0, 300.0, 450.0, 620.0, 900.0, 1300.0)
ROCK_PGAS = (0.02, 0.25, 0.9)


def by_hand(c, vc, f4, f5, vs30, rock_pga):
    """ln F = c ln(min(V, Vc)/760) + f2 ln((PGAr + 0.1)/0.1), f2 = f4 (e^{f5 (min(V, 760) - 360)} - e^{400 f5})."""
    linear = c * math.log(min(vs30, vc) / 760.0)
    f2 = f4 * (math.exp(f5 * (min(vs30, 760.0) - 360.0)) - math.exp(f5 * 400.0))
    return linear + f2 * math.log((rock_pga + 0.1) / 0.1)


@pytest.mark.parametrize("imt", ["pga", "pgv", 0.2, 1.0, 3.0])
def test_the_site_term_is_the_published_one(imt):
    """21 points per measure: 7 Vs30 from 150 to 1300 m/s, rock PGAs 0.02-0.9 g."""
    for vs30 in VS30S:
        for rock_pga in ROCK_PGAS:
            assert site_term(coefficients(imt), vs30, rock_pga) == pytest.approx(
                by_hand(*PRINTED[imt], vs30, rock_pga), abs=1e-12)


def test_between_two_periods_the_coefficients_are_interpolated_in_log_period():
    weight = math.log(0.33 / 0.32) / math.log(0.34 / 0.32)  # 0.33 s lies between the tabulated 0.32 and 0.34 s
    mixed = [a + weight * (b - a) for a, b in zip(PRINTED[0.32], PRINTED[0.34])]
    for vs30 in VS30S:
        for rock_pga in ROCK_PGAS:
            assert site_term(coefficients(0.33), vs30, rock_pga) == pytest.approx(by_hand(*mixed, vs30, rock_pga),
                                                                                 abs=1e-12)
    with pytest.raises(ValueError, match="outside BSSA14's 0.01-10 s"):
        coefficients(12.0)


def test_the_rock_median_is_bssa14s():
    """PGA at M 7, Rjb 10 km, Vs30 760 m/s from the printed e0, e4-e6, Mh, c1-c3, h (unspecified mechanism)."""
    e0, e6, mh, c1, c2, c3, h = 0.4473, -0.1662, 5.5, -1.134, 0.1917, -0.008088, 4.5
    r = math.hypot(10.0, h)
    expected = math.exp(e0 + e6 * (7.0 - mh) + (c1 + c2 * (7.0 - 4.5)) * math.log(r) + c3 * (r - 1.0))
    assert rock_median(coefficients("pga"), 7.0, 10.0) == pytest.approx(expected, rel=1e-12)


MEASURES = [("pga", (), 1.0), ("pgv", (), 1.0), ("sa", (1.0,), 1.0), ("sa", (0.33,), 1.0),
            ("avgsa", (0.2, 0.33, 1.0, 3.0), 1.0), ("pga_ratio", (), 0.47), ("pgv_ratio", (), 0.21)]
"""(measure, its Sa periods [s], its unit in g or m/s): pga_ratio's tan(alpha), pgv_ratio's g tan(alpha)/p [m/s]."""


@pytest.mark.parametrize("measure, periods, to_base", MEASURES)
def test_the_reference_site_gives_a_factor_of_exactly_one(measure, periods, to_base):
    x = np.geomspace(1e-3, 20.0, 50)
    median, _ = amplification(measure, REFERENCE_VS30, periods=periods, to_base=to_base)(x)
    assert np.all(median == 0.0)
    median, _ = amplification(measure, 1080.0, 1080.0, periods=periods, to_base=to_base)(x)  # any reference
    assert np.all(median == 0.0)


@pytest.mark.parametrize("measure, periods, to_base", MEASURES)
def test_block_normalised_and_averaged_measures_take_their_base_measures_factor(measure, periods, to_base):
    """pga_ratio's AF is PGA's at PGA = x tan(alpha); AvgSa's the geometric mean of its periods' Sa factors."""
    x = np.geomspace(0.01, 3.0, 9)
    site = amplification(measure, 260.0, periods=periods, to_base=to_base)
    median, _ = site(x)
    rock_pga = np.minimum(site.rock_pga(x), ROCK_PGA_LIMIT)
    terms = [coefficients(t) for t in periods] if periods else [coefficients(measure.split("_")[0])]
    expected = np.mean([site_term(co, 260.0, rock_pga) for co in terms], axis=0)
    np.testing.assert_allclose(median, expected, rtol=0, atol=1e-12)
    if measure == "pga_ratio":
        np.testing.assert_allclose(site.rock_pga(x), x * to_base, rtol=1e-12)


def test_the_factor_falls_with_vs30_and_with_the_rock_motion():
    """Softer sites amplify more at small motion; below 760 m/s the factor falls as the rock PGA grows (f2 < 0
    up to 3 s), yet the site's motion x AF(x) still grows with the rock's."""
    for imt in ("pga", "pgv", 0.2, 1.0, 3.0):
        co = coefficients(imt)
        small = [float(site_term(co, v, 0.001)) for v in VS30S]
        assert small == sorted(small, reverse=True)
        rock = np.geomspace(0.001, 3.0, 200)
        for vs30 in (150.0, 260.0, 530.0):
            factor = site_term(co, vs30, rock)
            assert np.all(np.diff(factor) <= 0)
            assert np.all(np.diff(np.log(rock) + factor) > 0)
        assert np.all(site_term(co, 1080.0, rock) == site_term(co, 1080.0, 0.0))  # linear above 760 m/s


def test_the_vs30_slope_is_the_derivative_of_the_site_term():
    co = coefficients(0.2)
    for vs30 in (160.0, 300.0, 700.0, 1000.0):
        for rock_pga in ROCK_PGAS:
            step = 1e-6
            numeric = (site_term(co, vs30 * math.exp(step), rock_pga) - site_term(co, vs30 * math.exp(-step),
                                                                                     rock_pga)) / (2 * step)
            assert site_term_vs30_slope(co, vs30, rock_pga) == pytest.approx(float(numeric), rel=1e-6)


def test_a_vs30_outside_the_data_is_clipped_with_a_warning():
    with pytest.warns(SiteAmplificationWarning, match="Vs30 120 m/s is below .*150-1500 m/s.*as at 150 m/s"):
        assert clip_vs30(120.0, "soil peat") == 150.0
    with pytest.warns(SiteAmplificationWarning, match="soil granite: Vs30 2000 m/s is above"):
        assert clip_vs30(2000.0, "soil granite") == 1500.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert clip_vs30(150.0, "soil clay") == 150.0


def test_the_rock_pga_above_the_limit_holds_the_factor():
    site = amplification("pga", 150.0)
    median, _ = site(np.array([ROCK_PGA_LIMIT, 2 * ROCK_PGA_LIMIT, 5 * ROCK_PGA_LIMIT]))
    assert median[1] == median[0] and median[2] == median[0]


def test_another_reference_site_takes_its_own_site_term_out_first():
    """A curve for a 1080 m/s site: its rock PGA on 760 m/s rock is x / AF_1080, and the factor is the ratio."""
    site = amplification("pga", 260.0, 1080.0)
    co = coefficients("pga")
    for x in (0.05, 0.4, 0.9):  # 0.9 g on the 1080 m/s site is 1.11 g on 760 m/s rock: the term held at 1 g
        rock = brentq(lambda p: math.log(p) + by_hand(*PRINTED["pga"], 1080.0, p) - math.log(x), 1e-6, 50.0,
                      xtol=1e-14)
        assert float(site.rock_pga(x)) == pytest.approx(rock, rel=1e-9)
        held = min(rock, ROCK_PGA_LIMIT)
        expected = by_hand(*PRINTED["pga"], 260.0, held) - by_hand(*PRINTED["pga"], 1080.0, held)
        assert float(site(x)[0]) == pytest.approx(expected, abs=1e-9)
    assert co.Vc == PRINTED["pga"][1]


# ------------------------------------------------------------------ the convolution

K0, K = 1e-4, 2.5


def power_law(x):
    return K0 * np.asarray(x, float) ** -K


def test_a_power_law_through_a_lognormal_factor_has_its_closed_form():
    """lambda_site(z) = k0 (z / A)^-k exp(k^2 sigma^2 / 2) for a constant median factor A and spread sigma."""
    rock = np.exp(np.arange(np.log(1e-5), np.log(1e3), 0.01))
    z = np.geomspace(0.01, 5.0, 40)
    for factor, sigma in ((1.7, 0.3), (0.6, 0.12), (2.4, 0.0)):
        site = convolve_hazard(rock, power_law(rock), np.full(rock.shape, math.log(factor)), sigma, z)
        np.testing.assert_allclose(site, K0 * (z / factor) ** -K * math.exp(0.5 * K**2 * sigma**2), rtol=2e-4)


def test_a_rock_site_amplifies_the_power_law_in_closed_form():
    """Above 760 m/s the site term is linear: a constant factor (1080/760)^c and spread |c| sigma_lnVs30."""
    from rockfrag.hazard import HazardCurve
    from rockfrag.site_hazard import amplified_curve

    reference = HazardCurve(np.geomspace(0.01, 3.0, 30), power_law(np.geomspace(0.01, 3.0, 30)), "pga", None, "law")
    z = np.geomspace(0.01, 3.0, 25)
    site = amplification("pga", 1080.0, vs30_sigma=0.2)
    factor, sigma = (1080.0 / 760.0) ** PRINTED["pga"][0], abs(PRINTED["pga"][0]) * 0.2
    expected = K0 * (z / factor) ** -K * math.exp(0.5 * K**2 * sigma**2)
    np.testing.assert_allclose(amplified_curve(reference, site, z), expected, rtol=2e-4)


def test_without_spread_the_site_curve_is_the_rock_curve_at_the_rock_motion_behind_it():
    """sigma = 0: lambda_site(z) = lambda_ref(x) where x AF(x) = z (solved independently, nonlinear clay site)."""
    from rockfrag.hazard import HazardCurve
    from rockfrag.site_hazard import amplified_curve

    reference = HazardCurve(np.geomspace(0.01, 3.0, 30), power_law(np.geomspace(0.01, 3.0, 30)), "pga", None, "law")
    site = amplification("pga", 150.0, vs30_sigma=0.0)
    z = np.geomspace(0.02, 2.0, 15)
    rock = [brentq(lambda x, target=target: math.log(x) + by_hand(*PRINTED["pga"], 150.0, min(x, ROCK_PGA_LIMIT))
                   - math.log(target), 1e-6, 1e3, xtol=1e-14) for target in z]
    np.testing.assert_allclose(amplified_curve(reference, site, z), power_law(rock), rtol=2e-4)


# ------------------------------------------------------------------ OpenQuake's BSSA14

SCENARIOS = ((5.5, 30.0), (6.5, 10.0), (7.5, 2.0))
OQ_VS30S = (150.0, 200.0, 260.0, 360.0, 530.0, 760.0, 1080.0, 1400.0)
OQ_IMTS = {"PGA": "pga", "PGV": "pgv", "SA(0.2)": 0.2, "SA(0.33)": 0.33, "SA(1.0)": 1.0, "SA(3.0)": 3.0}


@pytest.fixture(scope="module")
def openquake_means(tmp_path_factory):
    """ln medians of OpenQuake's BooreEtAl2014 per IMT, scenario and Vs30 (tests/consumers/openquake_site_term.py)."""
    python = consumer_python("openquake")
    folder = tmp_path_factory.mktemp("openquake_bssa14")
    cases = [[m, r, v] for m, r in SCENARIOS for v in OQ_VS30S]
    (folder / "query.json").write_text(json.dumps({"imts": list(OQ_IMTS), "cases": cases}))
    subprocess.run([str(python), str(CONSUMERS / "openquake_site_term.py"), str(folder / "query.json"),
                    str(folder / "out.json")], check=True, capture_output=True, timeout=600)
    values = np.array(json.loads((folder / "out.json").read_text())["ln_mean"])
    return {imt: values[i].reshape(len(SCENARIOS), len(OQ_VS30S)) for i, imt in enumerate(OQ_IMTS)}


def test_the_rock_medians_and_site_terms_are_openquakes(openquake_means):
    """24 points per measure (3 scenarios x 8 Vs30): medians on 760 m/s rock and ln Y(Vs30) - ln Y(760)."""
    reference = OQ_VS30S.index(760.0)
    for imt, key in OQ_IMTS.items():
        co = coefficients(key)
        for s, (magnitude, distance) in enumerate(SCENARIOS):
            rock_pga = math.exp(openquake_means["PGA"][s, reference])
            assert math.log(rock_median(co, magnitude, distance)) == pytest.approx(
                openquake_means[imt][s, reference], abs=1e-7)
            for v, vs30 in enumerate(OQ_VS30S):
                assert float(site_term(co, vs30, rock_pga)) == pytest.approx(
                    openquake_means[imt][s, v] - openquake_means[imt][s, reference], abs=1e-7)


@pytest.mark.parametrize("measure, periods, to_base", MEASURES)
def test_each_measures_amplification_is_openquakes_at_the_scenario(openquake_means, measure, periods, to_base):
    """At the scenario the factor's rock PGA is the scenario's: the whole chain (rock PGA from the measure's ratio
    to PGA, the factor) against OpenQuake's ln Y(Vs30) - ln Y(760), AvgSa's as the mean over its periods."""
    reference = OQ_VS30S.index(760.0)
    by_key = {key: imt for imt, key in OQ_IMTS.items()}
    names = [by_key[t] for t in periods] or [by_key[measure.split("_")[0]]]
    for s, scenario in enumerate(SCENARIOS):
        rock = np.mean([openquake_means[n][s, reference] for n in names])
        x = math.exp(rock) * (0.01 if measure.startswith("pgv") else 1.0) / to_base
        for v, vs30 in enumerate(OQ_VS30S):
            site = amplification(measure, vs30, periods=periods, to_base=to_base, scenario=scenario)
            expected = np.mean([openquake_means[n][s, v] - openquake_means[n][s, reference] for n in names])
            assert float(site(x)[0]) == pytest.approx(expected, abs=1e-7)
