"""Intensity measures against closed forms, published values and physical identities."""

from __future__ import annotations

import numpy as np
import pytest

from rockfrag.measures import (
    arias_intensity,
    cav,
    pga,
    pgv,
    response_spectrum,
    significant_duration,
    significant_window,
)
from rockfrag.units import STANDARD_GRAVITY


def test_sdof_step_response_matches_closed_form():
    """Suddenly applied constant a0: u(t) = -a0/w^2 [1 - e^{-zwt}(cos wd t + z/sqrt(1-z^2) sin wd t)]."""
    dt, a0, period, zeta = 0.01, 2.0, 0.7, 0.05
    acceleration = np.full(3000, a0)
    acceleration[0] = a0  # constant from t = 0 (exact for piecewise-linear input)
    omega = 2 * np.pi / period
    omega_d = omega * np.sqrt(1 - zeta**2)
    t = np.arange(acceleration.size) * dt
    u = -a0 / omega**2 * (1 - np.exp(-zeta * omega * t) * (np.cos(omega_d * t)
                                                           + zeta / np.sqrt(1 - zeta**2) * np.sin(omega_d * t)))
    spectrum = response_spectrum(acceleration, dt, [period], zeta)
    # the sampled peak of the exact solution bounds the discrete peak from below, within one step
    assert spectrum["sd"][0] == pytest.approx(np.max(np.abs(u)), rel=1e-9)


def test_sdof_harmonic_resonance_undamped_growth():
    """Undamped resonance a = A sin(wt): amplitude grows like A t/(2w) (closed form)."""
    period, amplitude, dt = 1.0, 1.0, 0.001
    omega = 2 * np.pi / period
    t = np.arange(0, 20.0, dt)
    u_exact = amplitude / (2 * omega**2) * (np.sin(omega * t) - omega * t * np.cos(omega * t))
    spectrum = response_spectrum(amplitude * np.sin(omega * t), dt, [period], 0.0)
    assert spectrum["sd"][0] == pytest.approx(np.max(np.abs(u_exact)), rel=1e-5)


def test_light_damping_identity_sa_equals_w2_sd(bolu_records):
    record = bolu_records["DUZCE/BOL090"]
    spectrum = response_spectrum(record.acceleration, record.dt, np.geomspace(0.05, 3, 20), damping=0.005)
    np.testing.assert_allclose(spectrum["sa"], spectrum["psa"], rtol=0.02)


def test_short_period_sa_tends_to_pga(bolu_records):
    record = bolu_records["DUZCE/BOL090"]
    spectrum = response_spectrum(record.acceleration, record.dt, [0.005], damping=0.05)
    assert spectrum["sa"][0] == pytest.approx(pga(record.acceleration), rel=0.01)


def test_bolu_published_values(bolu_records):
    """PEER NGA RSN 1602 Bolu 090: PGA 0.82 g, PGV about 62 cm/s."""
    record = bolu_records["DUZCE/BOL090"]
    assert pga(record.acceleration) / STANDARD_GRAVITY == pytest.approx(0.822, abs=0.001)
    assert pgv(record.acceleration, record.dt) == pytest.approx(0.62, abs=0.02)


def test_arias_cav_duration_of_a_sine():
    """a = A sin(2 pi t / T) over n whole cycles: Ia = pi A^2 D / (4 g), CAV = 2 A D / pi."""
    amplitude, period, dt = 3.0, 0.5, 1e-4
    t = np.arange(0, 10.0 + dt / 2, dt)
    a = amplitude * np.sin(2 * np.pi * t / period)
    assert arias_intensity(a, dt) == pytest.approx(np.pi * amplitude**2 * 10.0 / (4 * STANDARD_GRAVITY), rel=1e-6)
    assert cav(a, dt) == pytest.approx(2 * amplitude * 10.0 / np.pi, rel=1e-6)
    assert significant_duration(a, dt) == pytest.approx(9.0, abs=0.01)


def test_the_significant_window_is_the_d5_95_of_the_records_table():
    """One D5-95: the showcase's strong-motion window (significant_window) spans the records table's
    duration exactly; a burst of constant |a| from 2 s to 6 s opens at 2.2 s and closes at 5.8 s."""
    dt = 0.01
    a = np.where((np.arange(1000) * dt >= 2.0) & (np.arange(1000) * dt < 6.0), 1.5, 0.0)
    start, end = significant_window(a, dt)
    assert (start, end) == pytest.approx((2.2, 5.8), abs=dt)
    assert end - start == significant_duration(a, dt)  # the same numbers, not a second estimate
    silent = np.zeros(11)  # no energy: the whole record is the window, and the duration is 0
    assert significant_window(silent, dt) == (0.0, pytest.approx(0.1)) and significant_duration(silent, dt) == 0


def test_spectrum_rejects_bad_input():
    with pytest.raises(ValueError, match="damping"):
        response_spectrum(np.zeros(10), 0.01, [1.0], damping=1.5)
    with pytest.raises(ValueError, match="periods"):
        response_spectrum(np.zeros(10), 0.01, [0.0])
