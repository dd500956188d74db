"""Credible intensities (issue 32 item 4): the cap, the level grid below it, censored fits, the capped risk."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy.integrate import quad
from scipy.stats import norm

from rockfrag.config import load_study
from rockfrag.damage_states import DAMAGE_STATES
from rockfrag.fragility import capped_frequency, clopper_pearson, fit_cell, fragility_dataset
from rockfrag.hazard import HazardCurve
from rockfrag.ida import capacity_from_stripes
from rockfrag.study import DEFAULT_CREDIBLE_REASON, credible_cap, level_intensities, run_study, uplift_intensity
from rockfrag.units import STANDARD_GRAVITY as G

POWER_LAW = HazardCurve(np.geomspace(0.01, 10.0, 40), 1e-4 * np.geomspace(0.01, 10.0, 40) ** -2.5, "pga", None,
                        "power law k0 = 1e-4, k = 2.5")
"""lambda(s) = 1e-4 s^-2.5 [1/yr], s [g]: exactly log-log linear, so its interpolation is exact."""


def _records(n=6, seed=1):
    rng = np.random.default_rng(seed)
    pga = rng.uniform(0.2, 0.8, n) * G
    return pga[:, None] * rng.uniform(0.8, 1.2, (n, 1)), pga  # a RotD50-like intensity, the components' PGA


def test_the_default_cap_is_3_g_pga_with_its_reason():
    config = load_study()
    record_im, record_pga = _records()
    cap, reason = credible_cap(config, np.repeat(record_im, 3, axis=1), record_pga)
    np.testing.assert_allclose(cap, 3.0 * G)
    assert reason == DEFAULT_CREDIBLE_REASON and "2.7 g" in reason


def test_a_site_hazard_above_the_cap_at_its_frequency_raises_it():
    config = load_study()
    record_im, record_pga = _records()
    strong = HazardCurve(POWER_LAW.intensity, POWER_LAW.annual_frequency * 100.0, "pga", None, "strong site")
    cap, reason = credible_cap(config, np.repeat(record_im, 3, axis=1), record_pga, strong)
    expected = (1e-5 / 1e-2) ** (-1 / 2.5)  # 1e-2 s^-2.5 = 1e-5: s = 15.8 g
    np.testing.assert_allclose(cap, expected * G, rtol=1e-9)
    assert "site hazard" in reason and "1e-05/yr" in reason
    cap, _ = credible_cap(config, np.repeat(record_im, 3, axis=1), record_pga, POWER_LAW)  # 2.5 g < 3 g: no change
    np.testing.assert_allclose(cap, 3.0 * G)


def test_another_measure_gets_the_records_equivalent(tmp_path):
    study = tmp_path / "pgv.toml"
    study.write_text('[intensity]\nmeasure = "pgv"\nlevels = { start = 0.05, stop = 5.0, count = 6 }\n')
    config = load_study(study)
    pgv = np.array([0.3, 0.5, 0.4, 0.9])
    pga = np.array([3.0, 4.0, 5.0, 6.0])
    cap, reason = credible_cap(config, np.repeat(pgv[:, None], 3, axis=1), pga)
    np.testing.assert_allclose(cap, np.median(pgv / pga) * 3.0 * G)
    assert "median of PGV/PGA" in reason
    intensity = level_intensities(config, np.repeat(pgv[:, None], 3, axis=1), pga, cap)
    assert intensity.shape == (3, 6) and np.allclose(intensity[:, 0], 0.05) and np.allclose(intensity[:, -1], cap)


def test_the_grid_spans_from_below_uplift_to_the_cap_re_spaced_per_block():
    config = load_study()
    record_im, record_pga = _records()
    record_im = np.repeat(record_im, len(config.blocks), axis=1)
    cap = np.full(len(config.blocks), 3.0 * G)
    intensity = level_intensities(config, record_im, record_pga, cap)
    uplift = uplift_intensity(config, record_im, record_pga)
    assert intensity.shape == (len(config.blocks), 14)
    # half the first motion: the uplift, or the sliding onset mu_s g on the lowest-friction soil where mu_s < b/h
    lowest = min(soil.friction_static for soil in config.soils)
    onset = {"paper": min(1.0, lowest / np.tan(0.44)), "slender-cabinet": 1.0, "squat-machinery": lowest / 0.75}
    assert lowest == 0.35 and [b.name for b in config.blocks] == list(onset)  # clay, NAVFAC DM-7.02's upper end
    np.testing.assert_allclose(intensity[:, 0], 0.5 * uplift * np.array(list(onset.values())), rtol=2e-3)
    np.testing.assert_allclose(intensity[:, -1], cap)  # the top level is the cap: none above it
    ratios = intensity[:, 1:] / intensity[:, :-1]
    np.testing.assert_allclose(ratios, ratios[:, :1] * np.ones_like(ratios))  # geometric within each block
    assert np.all(ratios < 1.32)  # at least as fine as the old 32% spacing
    beyond = level_intensities(config.__class__(**{**config.__dict__, "beyond_credible": True}), record_im,
                               record_pga, cap)
    np.testing.assert_allclose(beyond, uplift[:, None] * np.geomspace(0.5, 100.0, 14)[None, :])


def test_a_block_that_slides_first_starts_below_its_sliding_onset_and_a_tied_study_at_its_uplift():
    """Cold read 7: the squat skid (b/h 0.75) slides on every soil from about mu_s g = 0.35 g, but its levels
    started at half its uplift, 0.37 g, so its 475-year values on four soils were the fitted curve carried below the
    lowest level. Its grid now starts at half its sliding onset; with every base tied nothing slides first."""
    config = load_study()
    record_im, record_pga = _records()
    record_im = np.repeat(record_im, len(config.blocks), axis=1)
    cap = np.full(len(config.blocks), 3.0 * G)
    squat = [b.name for b in config.blocks].index("squat-machinery")
    onset_g = 0.35 * np.median(record_im[:, squat] / record_pga)  # clay's mu_s g, in the pair's RotD50
    assert level_intensities(config, record_im, record_pga, cap)[squat, 0] / G <= 0.5 * onset_g * (1 + 1e-9)
    tied = config.__class__(**{**config.__dict__, "friction": "none"})
    np.testing.assert_allclose(level_intensities(tied, record_im, record_pga, cap)[:, 0],
                               0.5 * uplift_intensity(config, record_im, record_pga))


def test_the_capacity_hunt_stops_at_the_cap():
    runs = []

    def overturns(scale):
        runs.append(scale)
        return scale >= 5.0

    # stripes 1, 2 survive; the cap is at 3: the hunt tries 3 and stops, censored there
    capacity, lower, upper, extra = capacity_from_stripes([1.0, 2.0], [False, False], overturns, limit=3.0)
    assert np.isnan(capacity) and lower == 3.0 and np.isnan(upper) and max(runs) == 3.0
    runs.clear()  # the top stripe at the cap: no run at all
    capacity, lower, _, extra = capacity_from_stripes([1.0, 3.0], [False, False], overturns, limit=3.0)
    assert np.isnan(capacity) and lower == 3.0 and extra == 0 and not runs
    capacity, *_ = capacity_from_stripes([1.0, 2.0], [False, False], overturns, limit=np.inf)
    assert 4.9 < capacity < 5.1  # without a cap it hunts on to the capacity


def test_a_median_above_the_cap_is_censored_and_never_printed():
    levels = np.geomspace(0.2, 3.0, 8)
    total = np.full((1, 8), 20.0)
    # a curve with median 5 g and beta 0.5: few records reach the state below 3 g
    exceed = np.round(total * norm.cdf(np.log(levels / 5.0) / 0.5))
    rows, _ = fit_cell(levels, exceed, total, [DAMAGE_STATES["overturning"]], cap=3.0, unit="g")
    assert rows[0].status == "censored-at-cap" and np.isnan(rows[0].median)
    assert "5" not in rows[0].warnings[0].split("cap")[0]  # the warning names the cap, not the median
    uncapped, _ = fit_cell(levels, exceed, total, [DAMAGE_STATES["overturning"]], unit="g")
    assert uncapped[0].median > 3.0  # the same counts without a cap: an extrapolated median


def test_clopper_pearson_bounds():
    low, high = clopper_pearson([0, 20, 7], [20, 20, 20], 0.90)
    assert low[0] == 0 and high[0] == pytest.approx(1 - 0.05 ** (1 / 20))  # 0 of n: closed form
    assert high[1] == 1 and low[1] == pytest.approx(0.05 ** (1 / 20))
    assert low[2] < 7 / 20 < high[2]


@pytest.mark.parametrize("median, beta, cap", [(1.0, 0.5, 3.0), (2.5, 0.6, 3.0), (0.4, 0.3, 2.0)])
def test_the_risk_stops_at_the_cap_and_adds_its_exceedance(median, beta, cap):
    """lambda = integral_0^cap P(im) |d lambda(im)| + lambda(cap), checked by quadrature on the power law."""
    density = lambda s: 2.5e-4 * s ** -3.5  # noqa: E731  -d lambda/ds of 1e-4 s^-2.5
    below, _ = quad(lambda s: norm.cdf(np.log(s / median) / beta) * density(s), 1e-3, cap, limit=200)
    expected = below + 1e-4 * cap ** -2.5
    assert capped_frequency(median, beta, POWER_LAW, cap) == pytest.approx(expected, rel=2e-4)
    whole, _ = quad(lambda s: norm.cdf(np.log(s / median) / beta) * density(s), 1e-3, 1e3, limit=400)
    assert capped_frequency(median, beta, POWER_LAW, cap) >= whole  # an upper bound


def test_a_step_below_the_cap_keeps_its_frequency():
    """A step at m < cap reaches the state at every intensity above m: lambda(m), the cap's exceedance within it."""
    assert capped_frequency(1.0, 0.0, POWER_LAW, 3.0) == pytest.approx(1e-4, rel=1e-9)


def test_a_censored_row_integrates_the_records_below_the_cap():
    levels, fractions = np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.1, 0.2])
    expected = 0.1 * (1e-4 * 2.0 ** -2.5 - 1e-4 * 3.0 ** -2.5) + 1e-4 * 3.0 ** -2.5
    assert capped_frequency(np.nan, np.nan, POWER_LAW, 3.0, levels, fractions) == pytest.approx(expected, rel=1e-9)


STUDY = """
soils = ["rock"]
models = ["housner"]
[study]
name = "cap"
record_sets = ["bolu"]
[intensity]
levels = { start = 0.5, stop = 100.0, count = 6, relative_to = "uplift" }
credible_max = 1.5
credible_reason = "the test's cap"
credible_frequency = 0.0  # the shipped example hazard would raise it to its 1e-5/yr PGA, 2.5 g
[solver]
friction = "none"
[blocks.paper]
R = 9.39
alpha = 0.44
mass = 326197.0
"""


def test_a_study_runs_and_fits_nothing_above_the_cap(tmp_path):
    (tmp_path / "s.toml").write_text(STUDY)
    lines = []
    cube, _ = run_study(load_study(tmp_path / "s.toml"), output=tmp_path / "out", workers=1, progress=False,
                        log=lines.append, warn=lambda *_: None)
    written = xr.open_dataset(tmp_path / "out" / "cube.nc")
    assert written.attrs["credible_intensity_max"] == pytest.approx(1.5)
    assert written.attrs["credible_intensity_reason"] == "the test's cap"
    assert float(written.intensity.max()) == pytest.approx(1.5) and bool(written.credible_level.all())
    assert any("at most 1.5 g (the test's cap)" in line for line in lines)
    upper = written.capacity_scale_upper * written.record_im  # every overturning found lies at or below the cap
    assert not (upper > 1.5 * (1 + 1e-9)).any()
    standing = np.isnan(written.capacity_scale_factor)  # the portal stands at 1.5 g: censored at the cap
    assert bool(standing.any())
    np.testing.assert_allclose((written.capacity_scale_lower * written.record_im).where(standing).values[
        standing.values], 1.5, rtol=1e-9)
    fits = fragility_dataset(cube, n_bootstrap=0)
    assert fits.attrs["credible_intensity_max"] == pytest.approx(1.5)
    finite = np.isfinite(fits["median"].values)
    assert np.all(fits["median"].values[finite] <= 1.5 * (1 + 1e-9))
    assert np.all(fits.capacity_median.values[np.isfinite(fits.capacity_median.values)] <= 1.5 * (1 + 1e-9))
    overturning = fits.sel(damage_state="overturning", model="housner").isel(soil=0, block=0)
    assert str(overturning.status.values) in ("censored-at-cap", "not-reached", "fitted")
    assert np.isfinite(float(overturning.probability_at_cap))
