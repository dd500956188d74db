"""Calibration on chaotic references (issue 34 item 1): the window the data identify decides, the intervals cover
the truth where the whole record's likelihood is a needle field, a reference is called "not identifiable" with
the range of the fits that explain it when it is, and "almost no noise" is said only when it is true.

The coverage over 120 references (k 1e8-1e9 N/m, xi 0.01-0.07, noise 0-10 % white and AR(1), five records) is
benchmarks/calibration_coverage.py and its table is in docs/theory/calibration.md; the cases here are a few of that
kind, plus the decision's parts on inputs whose answer is known.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from rockfrag.blocks import PAPER_BLOCK
from rockfrag.calibrate import (
    NOISE_FLOOR,
    NOT_IDENTIFIABLE,
    CalibrationResult,
    _explained,
    _interval_fields,
    _irregularity,
    _Scan,
    _spans_search_range,
    _Window,
    autocorrelation_time,
    calibrate,
)
from rockfrag.models import simulate
from rockfrag.processing import process_record
from rockfrag.records import load_records

THRESHOLD = 2.706  # chi^2_1 at 90 %


# ---------------------------------------------------------------- the parts, on inputs with a known answer


def test_a_quadratic_profile_is_regular_and_jagged_or_split_ones_are_not():
    offsets = np.linspace(-2.5, 2.5, 11)
    assert _irregularity(THRESHOLD * (offsets / 1.0) ** 2, THRESHOLD) is None
    jagged = THRESHOLD * offsets**2
    jagged[9] = jagged[8] - 2.0  # falls back by 2 on its way out, inside the region's neighbourhood
    assert "jagged" in _irregularity(jagged, THRESHOLD)
    split = THRESHOLD * offsets**2
    split[9] = 0.5 * THRESHOLD  # a second basin inside the threshold, beyond the first crossing
    assert "comes back" in _irregularity(split, THRESHOLD)
    wide = np.linspace(-4.0, 4.0, 17)
    far = THRESHOLD * wide**2
    far[16] = far[15] - 5.0  # a dip far beyond four thresholds (at 33) does not move the interval
    assert _irregularity(far, THRESHOLD) is None


def test_a_window_is_accepted_while_its_fit_leaves_only_the_noise():
    rng = np.random.default_rng(0)
    sigma, n0, n1 = 0.01, 400, 600
    base = _Window(n0, 4.0, np.zeros(2), float(np.sum(rng.normal(0, sigma, n0) ** 2)), 1.0, np.zeros(n0))
    explained = float(np.sum(rng.normal(0, sigma, n1) ** 2))
    window = _Window(n1, 6.0, np.zeros(2), explained, 1.0, np.zeros(n1))
    assert _explained(base, base, window) == (True, "")
    # the same window whose last 100 samples the fit misses by twice the noise: refused, with the numbers
    missed = explained + 100 * (2 * sigma) ** 2
    accepted, reason = _explained(base, base, _Window(n1, 6.0, np.zeros(2), missed, 1.0, np.zeros(n1)))
    assert not accepted and "times the noise variance unexplained" in reason


def test_almost_no_noise_is_said_only_below_the_floor():
    class Search:
        @staticmethod
        def physical(point):
            return 1e8 * 9 ** point[0], 0.01 + 0.06 * point[1]

    def fields(noise):
        decision = {"notes": [], "noise_rms": noise, "autocorrelation_time": 1.0, "identifiable": True, "end": 12.0,
                    "windows": [], "range_points": np.array([[0.5, 0.5]]), "k_low": 2.9e8, "k_high": 3.1e8,
                    "xi_low": 0.03, "xi_high": 0.04}
        return _interval_fields(Search, decision, False, 0.9, peak=0.0174)

    quiet = fields(0.5 * NOISE_FLOOR * 0.0174)
    assert any("almost no noise" in note for note in quiet["interval_notes"])
    for noise in (0.01 * 0.0174, 8.4e-4):  # 1 % of the peak, and the issue's case (5 % of a 0.0174 rad peak)
        assert not any("almost no noise" in note for note in fields(noise)["interval_notes"])


def test_not_identifiable_is_printed_with_the_range():
    result = CalibrationResult(
        k_grid=4e8, xi_grid=0.03, correlation_grid=0.9, k=4.1e8, xi=0.031, correlation=0.97, rms_error=1e-3,
        peak_error=0.0, peak_reference=0.02, peak_model=0.02, area_over_depth=None, soil_shear_modulus=None,
        block_modulus=PAPER_BLOCK.E_b, confidence=0.9, k_low=2e8, k_high=8e8, xi_low=0.01, xi_high=0.07,
        interval_method=f"{NOT_IDENTIFIABLE}: the range of fits that explain it equally", noise_rms=1e-3,
        autocorrelation_time=1.0, identifiable=False, decisive_window=None,
        windows=[{"end": 12.0, "k": 4e8, "xi": 0.03, "accepted": True, "regular": False, "reason": "jagged"},
                 {"end": 30.0, "k": 4e8, "xi": 0.03, "accepted": False, "regular": None, "reason": "misses"}])
    lines = result.interval_lines()
    assert lines[0].startswith(f"{NOT_IDENTIFIABLE} (90%): the fits that explain it equally span k 2e+08 to 8e+08")
    assert lines[1].startswith("  no window decided")


def test_a_range_that_spans_the_search_box_is_found_in_either_parameter():
    class Search:  # k 1e8-9e8 N/m log-spaced, xi 0.01-0.07 in the unit box
        log_k = (math.log(1e8), math.log(9e8))
        xi_range = (0.01, 0.07)

    def decision(points, **bounds):
        return {"range_points": np.array(points, float), **bounds}

    inside = decision([[0.4, 0.5]], k_low=2e8, k_high=4e8, xi_low=0.02, xi_high=0.05)
    assert _spans_search_range(Search, inside, (0, 1)) == []
    # the profile bounds xi inside, but basins at both edges of the xi range explain the window as well
    basins = decision([[0.4, 0.5], [0.45, 0.0], [0.42, 1.0]], k_low=2e8, k_high=4e8, xi_low=0.02, xi_high=0.05)
    assert _spans_search_range(Search, basins, (0, 1)) == ["xi"]
    whole_k = decision([[0.4, 0.5]], k_low=1e8, k_high=9e8, xi_low=0.02, xi_high=0.05)
    assert _spans_search_range(Search, whole_k, (0, 1)) == ["k"]
    assert _spans_search_range(Search, basins, (0,)) == []  # a fixed xi is no interval


def test_a_scan_region_reaches_one_scan_step_beyond_its_outermost_points():
    grid = np.array([(u, v) for u in np.linspace(0, 1, 121) for v in np.linspace(0, 1, 21)])
    rss = np.full(len(grid), 10.0)
    chosen = [int(np.argmin(np.abs(grid - point).sum(axis=1))) for point in ((0.5, 0.5), (0.525, 0.55))]
    rss[chosen] = 1.0
    scan = _Scan(np.zeros((0, 2)), np.zeros(0), grid, rss)
    region = scan.region(best=1.0, variance=1.0, level=2.0)
    # the two grid points inside, and the corners of their box moved out by one step (1/120 in u, 1/20 in v)
    assert region.min(axis=0) == pytest.approx([0.5 - 1 / 120, 0.5 - 1 / 20])
    assert region.max(axis=0) == pytest.approx([0.525 + 1 / 120, 0.55 + 1 / 20])
    assert scan.region(best=1.0, variance=1.0, level=-1.0).size == 0


def test_the_autocorrelation_time_of_ar1_noise_is_not_cut_short_on_a_short_window():
    # 600 samples of AR(1) noise, phi 0.8 (tau 9): the sum of rho_k cut at its sampling noise (2/sqrt(n)) leaves out
    # the tail, 8.0 in the median; the AR(1) value keeps it. White noise stays at 1.
    phi, rng = 0.8, np.random.default_rng(3)
    taus = []
    for _ in range(100):
        shocks = rng.normal(0.0, math.sqrt(1 - phi**2), 600)
        series = np.empty(600)
        series[0] = rng.normal()
        for i in range(1, 600):
            series[i] = phi * series[i - 1] + shocks[i]
        taus.append(autocorrelation_time(series))
    assert np.median(taus) == pytest.approx((1 + phi) / (1 - phi), rel=0.05)
    assert np.median([autocorrelation_time(rng.normal(size=600)) for _ in range(100)]) < 1.15


# ---------------------------------------------------------------- whole calibrations of chaotic references


@pytest.fixture(scope="module")
def bolu_15():
    """Bolu 090 x 1.5, as studies/calibration-reference.csv: the paper block rocks from 11 s, chaotically."""
    records, _ = load_records("DUZCE/BOL090")
    record = process_record(records[0])
    return record.acceleration * 1.5, record.dt


DURATION = 18.0  # s: 7 s of rocking, past the chaotic horizon (13-16 s); the tail beyond costs time, not insight


def reference(ag, dt, k, xi, noise, seed):
    """The ssi model's rotation every 0.02 s for ``DURATION``, plus white noise of ``noise`` times its peak."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = simulate("ssi", ag, dt, PAPER_BLOCK, k=k, xi=xi, t_end=DURATION)
    time, theta = result.t[::2], result.theta[::2]
    rng = np.random.default_rng(seed)
    return time, theta + rng.normal(0.0, noise * np.max(np.abs(theta)), theta.size)


@pytest.mark.slow  # one calibration of an 18 s reference
def test_the_issues_case_is_decided_by_a_window_the_data_identify_and_covers(bolu_15):
    """The issue's last case: 7.3e8 N/m, xi 0.018, 5 % white noise. The whole record's likelihood is a needle
    field (the search's optimum over it is off the truth and its old interval excluded it); the decisive window
    ends before the chaotic tail, its intervals contain the truth, and the printout says which window decided."""
    ag, dt = bolu_15
    time, rotation = reference(ag, dt, 7.3e8, 0.018, 0.05, seed=5)
    result = calibrate(time, rotation, ag, dt, PAPER_BLOCK)
    assert result.identifiable
    assert 11.0 < result.decisive_window < DURATION - 1.0  # rocking starts at 11 s; the tail is not explained
    assert not result.windows[-1]["accepted"] or result.windows[-1]["regular"] is False
    assert result.k_low <= 7.3e8 <= result.k_high and result.xi_low <= 0.018 <= result.xi_high
    assert result.k_high / result.k_low < 1.2 and result.xi_high - result.xi_low < 0.03  # not the search range
    lines = result.interval_lines()
    assert lines[1].startswith(f"  decided by the window 0-{result.decisive_window:.2f} s of 0-{DURATION:.2f} s")
    assert result.noise_rms / result.peak_reference == pytest.approx(0.05, rel=0.15)
    assert not any("almost no noise" in note for note in result.interval_notes)


@pytest.mark.slow  # one calibration: 5-15 s
def test_a_reference_the_model_cannot_produce_is_not_identifiable_or_wide(bolu_15):
    """ssi-paper's rotation (another model) fitted by ssi with 1 % noise: no (k, xi) explains it at its noise level
    for long, so the intervals either say "not identifiable" or span more than the noise alone would give."""
    ag, dt = bolu_15
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        other = simulate("ssi-paper", ag, dt, PAPER_BLOCK, k=3.1e8, xi=0.035, t_end=DURATION)
    rng = np.random.default_rng(3)
    time, theta = other.t[::2], other.theta[::2]
    rotation = theta + rng.normal(0.0, 0.01 * np.max(np.abs(theta)), theta.size)
    result = calibrate(time, rotation, ag, dt, PAPER_BLOCK)
    accepted = [w for w in result.windows if w["accepted"]]
    assert len(accepted) < len(result.windows)  # the model error shows: some window is not explained
    assert result.identifiable is False or result.k_high / result.k_low > 1.01
    assert math.isfinite(result.k_low) and result.k_low <= result.k <= result.k_high
