"""Coulomb friction at the base (``friction=``) against closed forms and a 1-DOF stick-slip integration.

* Newmark's rigid-plastic sliding block: a block too squat to rock (b/h >> mu) under a rectangular pulse of
  amplitude A and duration t_d slides (A - mu_k g) t_d^2 / 2 + ((A - mu_k g) t_d)^2 / (2 mu_k g) and stops at
  t = A t_d / (mu_k g); on the rigid base (housner) and on a stiff tensionless bed (winkler, both beds).
* A one-cycle sine pulse has no closed form: a 1-DOF stick-slip integration (scipy solve_ivp, events at
  every slip stop and every start, the same piecewise-linear ground motion) is the reference.
* Below mu_s g nothing slides; a block whose mu_s is below b/h never rocks (Shenton 1996: mu > b/h is
  necessary for rocking from rest); the initial mode under a suddenly applied acceleration follows
  Shenton's criteria, computed here from the Newton-Euler equations of a block starting to rock.
* Large mu reproduces the tied base where the block never flies.
* Bad friction values are one SolverError naming ``friction`` and its range.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rockfrag.blocks import Block
from rockfrag.errors import SolverError
from rockfrag.models import simulate

G = 9.80665
SQUAT = Block(name="squat", R=math.hypot(1.0, 0.5), alpha=math.atan2(1.0, 0.5), mass=1000.0)  # b/h = 2
SLENDER = Block(name="slender", R=math.hypot(0.25, 1.0), alpha=math.atan2(0.25, 1.0), mass=1000.0)  # b/h = 1/4


def newmark_slip(amplitude, duration, mu_k, g=G):
    """Newmark's (1965) slip [m] of a rigid-plastic block under a rectangular pulse (A > mu_k g)."""
    excess = amplitude - mu_k * g
    return excess * duration**2 / 2 + (excess * duration) ** 2 / (2 * mu_k * g)


def rectangular_pulse(amplitude, duration, dt):
    """Samples of a pulse A on [0, t_d], then 0; the kernels interpolate linearly, so the last interval is a
    ramp from A to 0 whose impulse is that of a rectangle of duration t_d + dt/2 (second order in dt)."""
    n = int(round(duration / dt))
    ag = np.zeros(n + 2)
    ag[:n + 1] = amplitude
    return ag, n * dt + dt / 2


def bed_stiffness(block, omega_over_p):
    return block.mass * (omega_over_p * block.p()) ** 2


@pytest.mark.parametrize("friction", [0.3, (0.3, 0.25), (0.5, 0.2)])
@pytest.mark.parametrize("amplitude_g", [0.6, 1.0])
def test_rectangular_pulse_rigid_base_matches_newmark(friction, amplitude_g):
    mu_k = friction if isinstance(friction, float) else friction[1]
    amplitude = amplitude_g * G
    ag, duration = rectangular_pulse(amplitude, 0.5, 1e-4)
    result = simulate("housner", ag, 1e-4, SQUAT, friction=friction, t_end=3.0)
    assert result.peak_slip == pytest.approx(newmark_slip(amplitude, duration, mu_k), rel=1e-7)
    assert result.residual_slip == result.peak_slip  # the tail is long enough: the slip stopped
    assert result.peak_angle == 0.0 and not result.uplifted
    # it slides away from the ground's acceleration, and for exactly the time to stop
    assert np.nanmin(result.u) == pytest.approx(-result.peak_slip, rel=1e-12)
    assert result.mode_times["slide"] == pytest.approx(amplitude * duration / (mu_k * G), abs=2e-4)
    assert result.mode_times["rock"] == result.mode_times["slide_rock"] == result.mode_times["flight"] == 0.0


@pytest.mark.parametrize("bed", ["two-spring", "continuous"])
def test_rectangular_pulse_stiff_bed_matches_newmark(bed):
    """On a stiff bed (omega_v/p = 300) the squat block does not lift and slides as Newmark's block."""
    amplitude = 0.6 * G
    ag, duration = rectangular_pulse(amplitude, 0.5, 1e-4)
    result = simulate("winkler", ag, 1e-4, SQUAT, k=bed_stiffness(SQUAT, 300), bed=bed, friction=0.3, t_end=2.0)
    assert result.peak_slip == pytest.approx(newmark_slip(amplitude, duration, 0.3), rel=1e-4)  # measured 2-5e-6
    assert result.residual_slip == pytest.approx(result.peak_slip, rel=1e-9)
    assert not result.uplifted and result.mode_times["flight"] == 0.0


def sine_pulse(amplitude, period, dt, total):
    t = np.arange(int(round(total / dt)) + 1) * dt
    return np.where(t <= period, amplitude * np.sin(2 * np.pi * t / period), 0.0)


def stick_slip_reference(ag, dt, mu_s, mu_k, t_end, g=G):
    """1-DOF Coulomb block on the ground (independent of the kernels): (peak |u|, final u, sliding time).

    u'' = -ag(t) - mu_k g s while it slides in direction s; stuck while |ag| <= mu_s g. ag is linear between
    samples (zero after them). solve_ivp (DOP853, rtol 1e-12) per sample interval, with terminal events at the
    slip stop (u' = 0) and at the start (|ag| = mu_s g).
    """
    def acceleration(t):
        i = min(int(t // dt), ag.size - 1)
        a0 = ag[i]
        a1 = ag[i + 1] if i + 1 < ag.size else 0.0
        return a0 + (a1 - a0) * (t - i * dt) / dt if i + 1 < ag.size else 0.0

    u = v = 0.0
    direction = 0.0
    peak = slide_time = 0.0
    t = 0.0
    while t < t_end - 1e-12:
        t_next = min((math.floor(t / dt + 1e-9) + 1) * dt, t_end)
        if direction == 0.0:
            start = solve_ivp(lambda s, y: [0.0], (t, t_next), [0.0], events=_start_event(acceleration, mu_s * g),
                              rtol=1e-12, atol=1e-14)
            if abs(acceleration(t)) > mu_s * g:
                direction = -math.copysign(1.0, acceleration(t))
                continue
            if start.t_events[0].size:
                t = start.t_events[0][0] + 1e-13
                direction = -math.copysign(1.0, acceleration(t))
                continue
            t = t_next
            continue
        s = direction

        def rhs(time, y):
            return [y[1], -acceleration(time) - mu_k * g * s]

        def stop(time, y):
            return y[1]
        stop.terminal = True
        stop.direction = -s
        solution = solve_ivp(rhs, (t, t_next), [u, v], method="DOP853", events=stop, rtol=1e-12, atol=1e-14)
        u, v = solution.y[0, -1], solution.y[1, -1]
        slide_time += solution.t[-1] - t
        peak = max(peak, abs(u))
        t = solution.t[-1]
        if solution.status == 1:  # stopped
            v = 0.0
            a = acceleration(t)
            direction = 0.0 if abs(a) <= mu_s * g else -math.copysign(1.0, a)
    return peak, u, slide_time


def _start_event(acceleration, limit):
    def event(t, y):
        return abs(acceleration(t)) - limit
    event.terminal = True
    event.direction = 1
    return event


@pytest.mark.parametrize("friction", [(0.3, 0.3), (0.4, 0.3)])
@pytest.mark.parametrize("amplitude_g", [0.5, 1.2])
def test_sine_pulse_matches_stick_slip_reference(friction, amplitude_g):
    """One cycle of a sine (two slides, opposite ways, when A >> mu g) on the rigid base."""
    dt = 1e-3
    ag = sine_pulse(amplitude_g * G, 0.5, dt, 1.0)
    result = simulate("housner", ag, dt, SQUAT, friction=friction, t_end=2.5)
    peak, final, slide_time = stick_slip_reference(ag, dt, friction[0], friction[1], 2.5)
    assert result.peak_slip == pytest.approx(peak, rel=1e-7)
    assert result.residual_slip == pytest.approx(abs(final), rel=1e-7, abs=1e-12)
    assert result.mode_times["slide"] == pytest.approx(slide_time, abs=1e-6)


def test_sine_pulse_on_a_stiff_bed_matches_the_reference():
    dt = 1e-3
    ag = sine_pulse(1.2 * G, 0.5, dt, 1.0)
    peak, final, _ = stick_slip_reference(ag, dt, 0.4, 0.3, 2.5)
    for bed in ("two-spring", "continuous"):
        result = simulate("winkler", ag, dt, SQUAT, k=bed_stiffness(SQUAT, 300), bed=bed, friction=(0.4, 0.3),
                          t_end=2.5)
        assert result.peak_slip == pytest.approx(peak, rel=1e-3)
        assert result.residual_slip == pytest.approx(abs(final), rel=1e-3)


def test_nothing_slides_below_mu_g_on_the_rigid_base():
    ag = np.full(2001, 0.999 * 0.3 * G)
    result = simulate("housner", ag, 1e-3, SQUAT, friction=0.3, t_end=3.0)
    assert result.peak_slip == 0.0 and result.mode_times["slide"] == 0.0 and result.peak_angle == 0.0
    assert result.mode_times["rest"] == pytest.approx(3.0, abs=1e-9)
    above = simulate("housner", np.full(2001, 1.001 * 0.3 * G), 1e-3, SQUAT, friction=0.3, t_end=3.0)
    assert above.peak_slip > 0.0 and above.mode_times["slide"] > 0.0


def test_nothing_slides_below_mu_g_on_a_stiff_bed():
    """A slow ramp (quasi-static: no overshoot of the bed's vibration) to just below mu g."""
    dt = 1e-3
    t = np.arange(3001) * dt
    ag = 0.98 * 0.3 * G * np.minimum(t / 2.0, 1.0)
    for bed in ("two-spring", "continuous"):
        result = simulate("winkler", ag, dt, SQUAT, k=bed_stiffness(SQUAT, 300), bed=bed, friction=0.3, t_end=3.0)
        assert result.peak_slip == 0.0 and result.mode_times["slide"] == 0.0, bed
        above = simulate("winkler", ag / 0.98 * 1.02, dt, SQUAT, k=bed_stiffness(SQUAT, 300), bed=bed,
                         friction=0.3, t_end=3.0)
        assert above.peak_slip > 1e-3, bed


def rocking_start_ratio(block, a, g=G):
    """|H| / V at the start of rocking from rest under a suddenly applied |ag| = a > g tan(alpha).

    Newton-Euler about the corner (I_O = 4/3 m R^2): theta'' = 3 (a h - g b) / (4 R^2); the centre of mass
    accelerates by h theta'' against the ground's acceleration and b theta'' upwards, so the corner's
    forces are H = m (a - h theta''), V = m (g + b theta'') (Shenton 1996's mu_crit(a)).
    """
    b, h = block.b, block.h
    theta_acc = 3 * (a * h - g * b) / (4 * (b * b + h * h))
    return (a - h * theta_acc) / (g + b * theta_acc)


def expected_start(block, a, mu_s, mu_k, g=G):
    """Shenton's initiation criteria for a block at rest under a sudden a: the first mode."""
    tan_alpha = block.b / block.h
    if a > tan_alpha * g and mu_s >= tan_alpha:
        if rocking_start_ratio(block, a) <= mu_s:
            return "rock"
        return "slide_rock" if mu_k > tan_alpha else "slide"
    if a > mu_s * g:
        return "slide"
    return "rest"


def test_rocking_start_ratio_is_b_over_h_at_the_threshold_and_grows():
    tan_alpha = SLENDER.b / SLENDER.h
    assert rocking_start_ratio(SLENDER, tan_alpha * G) == pytest.approx(tan_alpha, rel=1e-12)
    ratios = [rocking_start_ratio(SLENDER, f * G) for f in (0.3, 0.5, 1.0, 3.0, 100.0)]
    assert all(np.diff(ratios) > 0)
    b, h = SLENDER.b, SLENDER.h
    assert ratios[-1] < (4 * b * b + h * h) / (3 * b * h)  # its limit for a -> infinity


@pytest.mark.parametrize("friction", [(0.2, 0.2), (0.3, 0.3), (0.3, 0.2), (0.6, 0.5)])
@pytest.mark.parametrize("a_g", [0.22, 0.28, 0.5, 1.0, 2.0, 10.0])
def test_initial_mode_follows_shenton(friction, a_g):
    """The mode of the first 2 ms under a step acceleration a (slender block, b/h = 1/4)."""
    dt = 1e-4
    expected = expected_start(SLENDER, a_g * G, *friction)
    result = simulate("housner", np.full(30, a_g * G), dt, SLENDER, friction=friction, t_end=20 * dt)
    modes = result.mode_times
    assert max(modes, key=modes.get) == expected, (modes, expected)
    assert modes[expected] == pytest.approx(20 * dt, rel=1e-6)


def test_no_rocking_when_mu_is_below_b_over_h():
    """mu_s < b/h: whatever the shaking, the block slides and never rocks (Shenton 1996)."""
    rng = np.random.default_rng(7)
    ag = np.convolve(rng.standard_normal(4000), np.ones(20) / 20, mode="same")
    ag *= 3.0 * G / np.max(np.abs(ag))
    result = simulate("housner", ag, 0.005, SLENDER, friction=(0.24, 0.2), t_end=25.0)
    assert result.peak_angle == 0.0 and not result.uplifted and result.peak_slip > 0.1
    assert result.mode_times["rock"] == result.mode_times["slide_rock"] == 0.0
    rocking = simulate("housner", ag, 0.005, SLENDER, friction=(0.26, 0.2), t_end=25.0)
    assert rocking.uplifted


def test_friction_errors_name_the_field_and_range():
    ag = np.zeros(10)
    for bad in (-0.1, 0.0, (0.3, 0.5), (0.5,), "high", (0.5, float("nan")), True):
        with pytest.raises(SolverError, match=r"friction.*mu_s >= mu_k > 0"):
            simulate("housner", ag, 0.01, SQUAT, friction=bad)
    with pytest.raises(SolverError, match=r"friction: model 'ssi' has a tied base"):
        simulate("ssi", ag, 0.01, SQUAT, k=1e8, friction=0.5)
    with pytest.raises(SolverError, match=r"friction: the kinetic coefficient 2 .* <= 4/3"):
        simulate("housner", ag, 0.01, SQUAT, friction=2.0)
    assert simulate("winkler", ag, 0.01, SQUAT, k=1e8, friction=2.0).peak_slip == 0.0  # a bed has no such limit
