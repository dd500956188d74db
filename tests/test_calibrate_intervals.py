"""Calibration intervals (profile likelihood): on noisy synthetic references over many seeds, the 90 % intervals
of k and xi contain the truth about 90 % of the time (and the 50 % intervals about half), a too-narrow
interval is caught by the same check, calibrate() carries the intervals to its result, printout, JSON and
figures, and the residual autocorrelation time has its closed form."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from scipy.stats import binom, chi2

from rockfrag.blocks import PAPER_BLOCK
from rockfrag.calibrate import autocorrelation_time, calibrate, fit_intervals, write_outputs
from rockfrag.models import simulate
from rockfrag.processing import process_record
from rockfrag.records import load_records

pytestmark = pytest.mark.xdist_group("calibration-intervals")  # one worker computes the 40 seeds' intervals once

SEGMENT = slice(800, 1400)  # Bolu 090, 8-14 s, x 2: the paper block rocks through four half-cycles, no overturning
SCALE = 2.0
K_TRUE, XI_TRUE = 4.6e8, 0.027  # off the default grid (as in tests/test_calibrate.py)
NOISE = 0.05  # Gaussian, of the peak |rotation|
SEEDS = 40
BAND = 0.99
"""Accept a count of covering intervals inside the central 99 % of Binomial(SEEDS, nominal): for 40 seeds at
90 %, 30 to 40 (a 90 % method fails this with probability 0.0015); at 50 %, 12 to 28."""


def binomial_band(n: int, p: float, level: float = BAND) -> tuple[int, int]:
    """The central ``level`` acceptance region [low, high] of Binomial(n, p) (each tail at most (1 - level)/2)."""
    tail = (1.0 - level) / 2.0
    distribution = binom(n, p)
    low = max(k for k in range(n + 1) if distribution.cdf(k - 1) <= tail)
    high = min(k for k in range(n + 1) if distribution.sf(k) <= tail)
    return low, high


@pytest.fixture(scope="module")
def segment():
    records, _ = load_records("DUZCE/BOL090")
    record = process_record(records[0])
    return record.acceleration[SEGMENT] * SCALE, record.dt


@pytest.fixture(scope="module")
def clean(segment):
    """The model's own response at the truth, on a finer time base than the record's (as an FE export would be)."""
    ag, dt = segment
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = simulate("ssi", ag, dt, PAPER_BLOCK, k=K_TRUE, xi=XI_TRUE, t_end=(ag.size - 1) * dt)
    ref_time = np.arange(0.0, result.t[-1], 0.005)
    return ref_time, np.interp(ref_time, result.t, result.theta)


def noisy(clean, seed):
    ref_time, rotation = clean
    rng = np.random.default_rng(seed)
    return ref_time, rotation + rng.normal(0.0, NOISE * np.max(np.abs(rotation)), rotation.size)


@pytest.fixture(scope="module")
def seeded_intervals(segment, clean):
    """The 90 % intervals of SEEDS noisy references. Each starts from a point off the truth (+0.2 % in k,
    -0.0002 in xi, a few interval widths; the search's optimum in practice): the intervals first move to the
    maximum-likelihood point, so they do not know the truth. The search itself (3 s a seed) is tested in
    tests/test_calibrate.py; ``test_calibrate_reports_the_intervals`` checks one seed end to end."""
    ag, dt = segment
    return [fit_intervals(*noisy(clean, seed), ag, dt, PAPER_BLOCK, K_TRUE * 1.002, XI_TRUE - 0.0002)
            for seed in range(SEEDS)]


def interval_at(values, deviance, threshold):
    """The interval where a profile stays below ``threshold``: linear interpolation on each side of its minimum
    (the test's own reading of the returned profile)."""
    values, deviance = np.asarray(values), np.asarray(deviance)
    centre = int(np.argmin(deviance))
    left, right = deviance[:centre + 1][::-1], deviance[centre:]
    assert left.max() >= threshold and right.max() >= threshold, "the profile does not reach the threshold"
    root, left, right = np.sqrt(threshold), np.sqrt(np.maximum(left, 0.0)), np.sqrt(np.maximum(right, 0.0))
    i = int(np.argmax(left >= root))  # in the root deviance, linear in the parameter for a quadratic profile
    low = np.interp(root, [left[i - 1], left[i]], [values[centre - i + 1], values[centre - i]])
    j = int(np.argmax(right >= root))
    high = np.interp(root, [right[j - 1], right[j]], [values[centre + j - 1], values[centre + j]])
    return low, high


def covering(results, confidence, shrink=1.0):
    """How many of the profiles' intervals at ``confidence`` contain the truth, for k and for xi; ``shrink``
    divides the threshold (shrink = 4: intervals half as wide, as if the noise were counted four times)."""
    threshold = chi2.ppf(confidence, 1) / shrink
    hits = {"k": 0, "xi": 0}
    for result in results:
        for name, truth in (("k", K_TRUE), ("xi", XI_TRUE)):
            low, high = interval_at(result[f"profile_{name}"], result[f"profile_{name}_deviance"], threshold)
            hits[name] += bool(low <= truth <= high)
    return hits


@pytest.mark.slow  # 8-9 s on a busy machine: 40 seeds x ~250 simulations of a 6 s record (about 0.2 s a seed)
def test_90_percent_intervals_cover_the_truth_about_90_percent_of_the_time(seeded_intervals, clean):
    low, high = binomial_band(SEEDS, 0.90)
    assert (low, high) == (30, 40)
    k_hits = sum(r["k_low"] <= K_TRUE <= r["k_high"] for r in seeded_intervals)
    xi_hits = sum(r["xi_low"] <= XI_TRUE <= r["xi_high"] for r in seeded_intervals)
    assert low <= k_hits <= high and low <= xi_hits <= high, (k_hits, xi_hits)
    # the returned profiles, read by the test's own interpolation, give the same intervals
    assert covering(seeded_intervals, 0.90) == {"k": k_hits, "xi": xi_hits}
    for result in seeded_intervals:
        # bounded on both sides, white residuals; the start, off the truth on purpose, may lie outside the region
        assert all(note.startswith("the fit lies outside") for note in result["notes"]), result["notes"]
        assert result["autocorrelation_time"] < 1.3
        assert result["noise_rms"] == pytest.approx(NOISE * np.max(np.abs(clean[1])), rel=0.08)  # the added noise
    # the same profiles at 50 %: the deviance's scale is right in the middle too, not only at the 90 % point
    low50, high50 = binomial_band(SEEDS, 0.50)
    hits50 = covering(seeded_intervals, 0.50)
    assert low50 <= hits50["k"] <= high50 and low50 <= hits50["xi"] <= high50, hits50


@pytest.mark.slow  # shares the fixture of the test above (no simulations of its own)
def test_the_coverage_check_catches_a_too_narrow_interval(seeded_intervals):
    """Intervals half as wide (the noise counted four times: threshold / 4, true coverage P(chi2_1 < 0.68) =
    59 %) fall below the band: the check above can fail."""
    low, _ = binomial_band(SEEDS, 0.90)
    narrow = covering(seeded_intervals, 0.90, shrink=4.0)
    assert narrow["k"] < low and narrow["xi"] < low, narrow
    # and the intervals that pass are not merely wide: they are about 2 x 1.645 sd of the scatter of the
    # maximum-likelihood points across seeds (the profiles' minima)
    k_best = np.array([r["profile_k"][int(np.argmin(r["profile_k_deviance"]))] for r in seeded_intervals])
    widths = np.array([r["k_high"] - r["k_low"] for r in seeded_intervals])
    assert np.median(widths) == pytest.approx(2 * 1.645 * np.std(k_best), rel=0.3)


@pytest.mark.slow  # ~4-6 s: one full search and its intervals, then the outputs
def test_calibrate_reports_the_intervals(segment, clean, tmp_path):
    ag, dt = segment
    ref_time, rotation = noisy(clean, 1)
    result = calibrate(ref_time, rotation, ag, dt, PAPER_BLOCK)
    assert result.confidence == 0.9 and result.interval_method == "profile likelihood on the decisive window"
    # 6 s of rocking is not chaotic at 5 % noise: the whole reference is explained and its likelihood regular
    assert result.identifiable and result.decisive_window == ref_time[-1]
    assert all(window["accepted"] for window in result.windows) and result.windows[-1]["regular"]
    assert result.k_low < result.k < result.k_high and result.xi_low < result.xi < result.xi_high
    # no other basin, no widening, white residuals: only the union with the next shorter regular window
    assert len(result.interval_notes) == 1 and result.interval_notes[0].startswith("the intervals are the union")
    assert result.k_low <= K_TRUE <= result.k_high and result.xi_low <= XI_TRUE <= result.xi_high  # seed 1 covers
    # the windows' fits, the profiles, one scan of the decisive window over the whole range (121 x 21) and the
    # bootstrap (40 replicates)
    assert 3000 < result.interval_simulations < 15000 and result.interval_simulations < result.n_simulations
    alone = fit_intervals(ref_time, rotation, ag, dt, PAPER_BLOCK, result.k, result.xi)
    # the decisive window's own intervals, from calibrate's own estimate, lie inside the union, which reaches back
    # to the first shorter regular window whose interval is twice as wide (here 2.4 times the decisive one's)
    assert result.k_low <= alone["k_low"] * (1 + 1e-4) and alone["k_high"] * (1 - 1e-4) <= result.k_high
    assert result.xi_low <= alone["xi_low"] + 1e-6 and alone["xi_high"] - 1e-6 <= result.xi_high
    assert 2.0 * (alone["k_high"] - alone["k_low"]) < result.k_high - result.k_low < 4.0 * (alone["k_high"] -
                                                                                           alone["k_low"])
    lines = result.interval_lines()
    assert lines[0].startswith(f"90% confidence (profile likelihood on the decisive window): k {result.k_low:.5g} to "
                               f"{result.k_high:.5g} N/m")
    assert lines[1].startswith(f"  decided by the window 0-{ref_time[-1]:.2f} s of 0-{ref_time[-1]:.2f} s")
    files = write_outputs(result, ref_time, rotation, ag, dt, PAPER_BLOCK, tmp_path)
    summary = json.loads((tmp_path / "calibration.json").read_text())
    assert summary["k_low"] == result.k_low and summary["xi_high"] == result.xi_high
    assert summary["units"]["k_low"] == "N/m" and "profile_k" not in summary
    assert tmp_path / "calibration-profile.png" in files and (tmp_path / "calibration-profile.png").stat().st_size
    wider = fit_intervals(ref_time, rotation, ag, dt, PAPER_BLOCK, result.k, result.xi, confidence=0.99)
    assert wider["k_low"] < alone["k_low"] and wider["k_high"] > alone["k_high"]  # a higher level, a wider interval


def test_coloured_noise_widens_the_intervals_by_the_square_root_of_its_autocorrelation_time(segment, clean):
    """AR(1) noise (phi = 0.8, tau = 9) of the same variance as white noise: the intervals are about 3 times as
    wide, and the note says why."""
    ag, dt = segment
    ref_time, rotation = clean
    sigma = NOISE * np.max(np.abs(rotation))
    rng = np.random.default_rng(11)
    white = rng.normal(0.0, sigma, rotation.size)
    phi, shocks = 0.8, rng.normal(0.0, sigma * np.sqrt(1 - 0.8**2), rotation.size)
    coloured = np.empty_like(shocks)
    coloured[0] = rng.normal(0.0, sigma)
    for i in range(1, coloured.size):
        coloured[i] = phi * coloured[i - 1] + shocks[i]
    results = [fit_intervals(ref_time, rotation + noise, ag, dt, PAPER_BLOCK, K_TRUE, XI_TRUE)
               for noise in (white, coloured)]
    assert results[0]["autocorrelation_time"] < 1.3
    assert results[1]["autocorrelation_time"] == pytest.approx((1 + phi) / (1 - phi), rel=0.3)
    ratio = [(results[1][f"{name}_high"] - results[1][f"{name}_low"]) / (results[0][f"{name}_high"]
                                                                          - results[0][f"{name}_low"])
             for name in ("k", "xi")]
    assert ratio == pytest.approx([3.0, 3.0], rel=0.3)
    assert any("correlated over" in note for note in results[1]["notes"])


def test_autocorrelation_time_of_white_and_ar1_noise():
    rng = np.random.default_rng(3)
    assert autocorrelation_time(rng.normal(size=20000)) == pytest.approx(1.0, abs=0.05)
    phi = 0.8  # AR(1): tau = (1 + phi) / (1 - phi) = 9
    shocks = rng.normal(size=200000)
    series = np.empty_like(shocks)
    series[0] = shocks[0]
    for i in range(1, series.size):
        series[i] = phi * series[i - 1] + shocks[i]
    assert autocorrelation_time(series) == pytest.approx((1 + phi) / (1 - phi), rel=0.1)


def test_a_confidence_outside_zero_one_is_refused(segment, clean):
    from rockfrag.errors import ConfigError

    ag, dt = segment
    for confidence in (0.0, 1.0, 1.5):
        with pytest.raises(ConfigError, match="confidence"):
            calibrate(*clean, ag, dt, PAPER_BLOCK, confidence=confidence)


def test_cli_prints_the_intervals_and_passes_the_confidence(tmp_path, capsys, monkeypatch):
    """rockfrag calibrate --confidence reaches calibrate(), and its printout and calibration.json carry the intervals
    (the search itself replaced: its intervals are the tests above)."""
    import rockfrag.calibrate as calibration
    from rockfrag.calibrate import CalibrationResult
    from rockfrag.cli import main

    asked = {}

    def fake(*args, **kwargs):
        asked.update(kwargs)
        return CalibrationResult(
            k_grid=4.33e8, xi_grid=0.03, correlation_grid=0.9, k=4.6e8, xi=0.027, correlation=0.99, rms_error=1e-3,
            peak_error=0.01, peak_reference=0.03, peak_model=0.0303, area_over_depth=None, soil_shear_modulus=None,
            block_modulus=PAPER_BLOCK.E_b, surface_k=[1e8, 9e8], surface_xi=[0.01, 0.07],
            surface=[[0.5, 0.6], [0.7, 0.8]],
            confidence=kwargs["confidence"], k_low=4.5e8, k_high=4.7e8, xi_low=0.026, xi_high=0.028,
            interval_method="profile likelihood", noise_rms=1e-3, autocorrelation_time=1.0, interval_simulations=450,
            profile_k=[4.4e8, 4.6e8, 4.8e8], profile_k_deviance=[5.0, 0.0, 5.0], profile_xi=[0.025, 0.027, 0.029],
            profile_xi_deviance=[5.0, 0.0, 5.0])

    monkeypatch.setattr(calibration, "calibrate", fake)
    reference = tmp_path / "ref.csv"
    seconds = np.arange(0.0, 10.0, 0.01)
    reference.write_text("time [s],theta [rad]\n" + "\n".join(f"{t:.2f},{0.01 * np.sin(t):.6f}" for t in seconds))
    status = main(["calibrate", str(reference), "--record", "DUZCE/BOL090", "--confidence", "0.8",
                   "--output", str(tmp_path / "out")])
    printed = capsys.readouterr().out
    assert status == 0 and asked["confidence"] == 0.8
    assert ("80% confidence (profile likelihood): k 4.5e+08 to 4.7e+08 N/m (-2.17% / +2.17%), xi 0.02600 to 0.02800"
            in printed)
    summary = json.loads((tmp_path / "out" / "calibration.json").read_text())
    assert (summary["confidence"], summary["k_low"], summary["xi_high"]) == (0.8, 4.5e8, 0.028)
    assert (tmp_path / "out" / "calibration-profile.png").stat().st_size > 0
    with pytest.raises(SystemExit) as stop:  # a usage error, one line
        main(["calibrate", str(reference), "--record", "DUZCE/BOL090", "--confidence", "1.5"])
    assert stop.value.code == 2 and "--confidence: 1.5 must be > 0 and < 1" in capsys.readouterr().err
