"""Coverage of the calibration intervals over several truths and noises (issue 34 item 1), in little.

The full measurement (120 references over k 1e8-1e9 N/m, xi 0.01-0.07, noise 0-10 % white and AR(1), five
records) is benchmarks/calibration_coverage.py and its table is in docs/theory/calibration.md. Here five seeded
references of the issue's kind (Bolu 090 x 1.5, the paper block, 18 s: rocking from 11 s, chaotic from 13-16 s)
at truths spread over the search range and noises of 1-5 %, white and AR(1), are calibrated as
``rockfrag calibrate`` calibrates them. With a true coverage of 90 %, at least 4 of 5 intervals contain the truth
with probability 0.92; intervals a quarter as wide around the same estimates fail the same check, so the test
can fail when the intervals stop covering. Three more at 5 % AR(1) noise check the rule that an interval is never
the whole search range at noise <= 5 %, and fail when the fallback to a longer window is switched off.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from rockfrag.blocks import PAPER_BLOCK
from rockfrag.calibrate import calibrate
from rockfrag.models import simulate
from rockfrag.processing import process_record
from rockfrag.records import load_records

pytestmark = pytest.mark.xdist_group("calibration-coverage")  # one worker runs the five calibrations once

DURATION = 18.0  # s
K_RANGE, XI_RANGE = (1e8, 1e9), (0.01, 0.07)
PHI = 0.8  # AR(1) noise: lag-1 correlation per 0.02 s sample
CASES = (  # (k [N/m], xi [-], noise of the peak, kind, seed): truths spread over the range, off every grid
    (1.5e8, 0.030, 0.02, "white", 1),
    (4.0e8, 0.050, 0.05, "white", 2),
    (6.0e8, 0.012, 0.05, "ar1", 3),
    (2.5e8, 0.020, 0.01, "ar1", 4),
    (8.6e8, 0.062, 0.01, "white", 5),
)
MIN_COVERED = 4  # of 5: P(at least 4 | coverage 0.9) = 0.92


def noisy_reference(ag, dt, k, xi, noise, kind, seed):
    """The ssi model's rotation every 0.02 s for ``DURATION`` plus white or AR(1) noise of ``noise`` x its peak."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = simulate("ssi", ag, dt, PAPER_BLOCK, k=k, xi=xi, t_end=DURATION)
    every = int(round(0.02 / dt))
    time, theta = result.t[::every], result.theta[::every]
    rng = np.random.default_rng(seed)
    sigma = noise * float(np.max(np.abs(theta)))
    if kind == "white":
        return time, theta + rng.normal(0.0, sigma, theta.size)
    shocks = rng.normal(0.0, sigma * math.sqrt(1.0 - PHI**2), theta.size)
    series = np.empty_like(shocks)
    series[0] = rng.normal(0.0, sigma)
    for i in range(1, series.size):
        series[i] = PHI * series[i - 1] + shocks[i]
    return time, theta + series


@pytest.fixture(scope="module")
def calibrated():
    """(case, CalibrationResult) of every case."""
    records, _ = load_records("DUZCE/BOL090")
    record = process_record(records[0])
    ag, dt = record.acceleration * 1.5, record.dt
    results = []
    for k, xi, noise, kind, seed in CASES:
        time, rotation = noisy_reference(ag, dt, k, xi, noise, kind, seed)
        results.append(((k, xi), calibrate(time, rotation, ag, dt, PAPER_BLOCK, k_range=K_RANGE, xi_range=XI_RANGE)))
    return results


def covered(results, shrink=1.0):
    """How many intervals of k and of xi contain the truth, each interval's sides multiplied by ``shrink``."""
    count_k = count_xi = 0
    for (k, xi), result in results:
        low_k = result.k * (result.k_low / result.k) ** shrink  # k's sides shrink in log k
        high_k = result.k * (result.k_high / result.k) ** shrink
        low_xi = result.xi + shrink * (result.xi_low - result.xi)
        high_xi = result.xi + shrink * (result.xi_high - result.xi)
        count_k += low_k <= k <= high_k
        count_xi += low_xi <= xi <= high_xi
    return count_k, count_xi


@pytest.mark.slow  # five calibrations of 18 s references: 20-60 s on the shared 2-core machine
def test_the_intervals_cover_truths_spread_over_the_range_without_being_the_range(calibrated):
    count_k, count_xi = covered(calibrated)
    assert count_k >= MIN_COVERED and count_xi >= MIN_COVERED, (count_k, count_xi)
    for (k, xi), result in calibrated:
        # covering must not come from width: never the search range at noise <= 5 %, and informative
        assert not (result.k_low <= K_RANGE[0] * 1.0001 and result.k_high >= K_RANGE[1] * 0.9999)
        assert not (result.xi_low <= XI_RANGE[0] + 1e-9 and result.xi_high >= XI_RANGE[1] - 1e-9)
    widths = [result.k_high / result.k_low - 1.0 for _, result in calibrated]
    assert np.median(widths) < 0.1  # the median 90 % interval of k is narrower than 10 %


@pytest.mark.slow  # shares the fixture above (no simulations of its own)
def test_the_check_fails_on_intervals_a_quarter_as_wide(calibrated):
    count_k, count_xi = covered(calibrated, shrink=0.25)
    assert count_k < MIN_COVERED or count_xi < MIN_COVERED, (count_k, count_xi)


# 5 % AR(1) noise on Bolu 090 x 1.5 (the benchmark's cases 108 and 118, here on 18 s): the regular window ends
# about 1.5 s into the rocking and its other basins explain it as well, so its range of xi alone is the whole
# search range (measured with the fallback to a longer window switched off: xi 0.01-0.07 on all three).
WHOLE_RANGE_CASES = ((7.178e8, 0.0479, 1), (8.525e8, 0.0663, 2), (7.178e8, 0.0479, 2))  # (k, xi, seed)


def calibrate_coloured(case, **kwargs):
    records, _ = load_records("DUZCE/BOL090")
    record = process_record(records[0])
    ag, dt = record.acceleration * 1.5, record.dt
    k, xi, seed = case
    time, rotation = noisy_reference(ag, dt, k, xi, 0.05, "ar1", seed)
    return calibrate(time, rotation, ag, dt, PAPER_BLOCK, k_range=K_RANGE, xi_range=XI_RANGE, **kwargs)


def whole_range(result):
    return (result.k_low <= K_RANGE[0] * 1.0001 and result.k_high >= K_RANGE[1] * 0.9999) or (
        result.xi_low <= XI_RANGE[0] + 1e-9 and result.xi_high >= XI_RANGE[1] - 1e-9)


@pytest.mark.slow  # three calibrations of 18 s references: about 17 s of CPU
def test_at_5_percent_noise_the_intervals_are_never_the_whole_search_range():
    for k, xi, seed in WHOLE_RANGE_CASES:
        result = calibrate_coloured((k, xi, seed))
        assert not whole_range(result), (k, xi, seed, result.interval_lines())
        assert result.k_low <= k <= result.k_high and result.xi_low <= xi <= result.xi_high, result.interval_lines()


def test_the_whole_range_check_fails_without_the_longer_window(monkeypatch):
    import rockfrag.calibrate

    monkeypatch.setattr(rockfrag.calibrate, "_spans_search_range", lambda *args: [])
    assert whole_range(calibrate_coloured(WHOLE_RANGE_CASES[2]))  # about 2 s of CPU
