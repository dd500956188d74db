"""pipeline.models.kernels - the compiled time loops shared by every rocking model.

Input : plain float64 arrays, a parameter record (``fields.PARAMS_DTYPE``) and an initial state;
        no Python objects cross this line.
Output: a summary record (``fields.SUMMARY_DTYPE``: outcome, peak angle, impacts, ...) and, when
        asked, the histories [theta, theta_dot, y, y_dot] at the record's sample times.

One adaptive Dormand-Prince 5(4) integrator (Hairer, Norsett & Wanner, table 5.2) steps the state
x = [theta, theta_dot, y, y_dot]. Steps never cross a sample of the ground motion (which is linear
between samples), so every step sees a smooth right-hand side. Events (impact, uplift, contact
changes, overturning) are located on a cubic Hermite interpolant and the step is redone exactly to
the event time, after which integration restarts cleanly.

Two time loops:
- ``pivot_loop`` (housner, ssi, ssi-paper): the block rests until the uplift condition, rocks on one
  corner, and at theta = 0 an impact rule switches the pivot.
- ``bed_loop`` (winkler): no rest phase and no impact rule; the block tilts on its bed from the first
  sample and the bed's contact law (pipeline.models.winkler) decides everything.

The physics of each model sits in its own module (housner.py, ssi.py, winkler.py) as small compiled
functions; ``rhs`` dispatches on the kernel code. Set PIPELINE_NO_NUMBA=1 to run as plain Python.
"""

from __future__ import annotations

import math

import numpy as np

from pipeline.models.base import Outcome
from pipeline.models.fields import (EVENT_CONTACT, EVENT_IMPACT, EVENT_NONE, EVENT_OVERTURN, EVENT_SETTLE,
                                    EVENT_UPLIFT, HOUSNER, SWITCH_CONSISTENT, WINKLER)
from pipeline.models.housner import housner_rhs
from pipeline.models.jit import njit
from pipeline.models.ssi import ssi_pivot_switch, ssi_rest_rhs, ssi_rhs, ssi_support
from pipeline.models.winkler import (N_CONTACT_INDICATORS, bed_force, contact_indicator, contact_indicators,
                                     friction_demand, settled_beyond_reach, winkler_rhs)

# phases of the pivot loop
REST = 0
ROCKING = 1

NO_UPLIFT = int(Outcome.NO_UPLIFT)
ROCKING_OUTCOME = int(Outcome.ROCKING)
OVERTURNED = int(Outcome.OVERTURNED)
FAILED = int(Outcome.FAILED)

# Step control (scipy's rk.py names): the step grows by at most MAX_FACTOR, shrinks by at least
# MIN_FACTOR, with a SAFETY margin on the optimal order-5 proposal.
SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 5.0
ERROR_EXPONENT = -0.2
MIN_STEP = 1e-14                # [s] below this a step is accepted whatever its error
SEGMENT_END_FRACTION = 1e-12    # of dt: "at the end of the sample interval"
EVENT_TIME_RESOLUTION = 1e-13   # [s] event location stops here
EVENT_VALUE_FRACTION = 1e-12    # ... or when the event function is this fraction of its bracket values
EVENT_REFINEMENTS = 12          # real steps spent sharpening one event time at most
STATE_SCALE_FLOOR = 1e-9        # scales of y, y_dot for a rigid base (no foundation)
AT_REST_FRACTION = 1e-12        # SSI: vertical vibration this small counts as static (closed-form rest)
SNAP_TO_STATIC_FRACTION = 1e-4  # SSI: leftover vertical vibration below this is snapped to statics
ZENO_STEP_SHRINK = 0.25         # a whole excursion inside one step: retry with this fraction
MAX_STEPS = 50_000_000          # runaway guard
FRICTION_MIN_SUPPORT = 0.1      # friction demand |H|/N is read only while N >= this fraction of m g
TINY_INDICATOR = 1e-300         # a contact indicator that ended exactly on zero, booked on its far side

# rows of the work array (``workspace``): the Dormand-Prince stages k2..k7 (row 5 is f(t + h, x_new),
# which the dense output and the next step reuse), then the interpolated state of the event functions
ROW_F1 = 5
ROW_EVENT = 6
WORK_ROWS = 7

# Dormand-Prince 5(4) tableau
C2, C3, C4, C5 = 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0
A21 = 1.0 / 5.0
A31, A32 = 3.0 / 40.0, 9.0 / 40.0
A41, A42, A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
A51, A52, A53, A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
A61, A62, A63, A64, A65 = 9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0
B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0
E1, E3, E4, E5, E6, E7 = (71.0 / 57600.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0,
                          22.0 / 525.0, -1.0 / 40.0)


# ---------------------------------------------------------------------------------------------
# right-hand side and the Dormand-Prince step
# ---------------------------------------------------------------------------------------------

@njit(cache=True)
def sample(ag, index):
    """Ground acceleration sample [m/s^2]; zero after the record (the tail of free vibration)."""
    return ag[index] if index < ag.size else 0.0


@njit(cache=True)
def ground(motion, t):
    """Ground acceleration [m/s^2] at time t: linear between the samples of motion = (ag, dt)."""
    ag, dt = motion
    u = t / dt
    index = int(math.floor(u))
    if index < 0:
        return ag[0]
    a0 = sample(ag, index)
    return a0 + (sample(ag, index + 1) - a0) * (u - index)


@njit(cache=True)
def rhs(code, phase, sigma, x, accel, params, out):
    """dx/dt for state x = [theta, theta_dot, y, y_dot] given ground acceleration ``accel``."""
    if code == WINKLER:
        winkler_rhs(x, accel, params, out)
    elif phase == REST:
        if code == HOUSNER:
            for i in range(4):
                out[i] = 0.0
        else:
            ssi_rest_rhs(x, params, out)
    elif code == HOUSNER:
        housner_rhs(sigma, x, accel, params, out)
    else:
        ssi_rhs(sigma, x, accel, params, out)


@njit(cache=True)
def dopri_step(code, phase, sigma, t, x, f0, h, motion, params, k, x_new, err):
    """One Dormand-Prince step from (t, x), f0 = f(t, x); fills x_new, k[5] = f(t+h, x_new), err.

    k : (WORK_ROWS, 4) work array: the stages k2..k7 in rows 0-5.
    """
    k2, k3, k4, k5, k6, k7 = k[0], k[1], k[2], k[3], k[4], k[5]
    tmp = err  # err is written last: use it as the stage buffer meanwhile
    for i in range(4):
        tmp[i] = x[i] + h * A21 * f0[i]
    rhs(code, phase, sigma, tmp, ground(motion, t + C2 * h), params, k2)
    for i in range(4):
        tmp[i] = x[i] + h * (A31 * f0[i] + A32 * k2[i])
    rhs(code, phase, sigma, tmp, ground(motion, t + C3 * h), params, k3)
    for i in range(4):
        tmp[i] = x[i] + h * (A41 * f0[i] + A42 * k2[i] + A43 * k3[i])
    rhs(code, phase, sigma, tmp, ground(motion, t + C4 * h), params, k4)
    for i in range(4):
        tmp[i] = x[i] + h * (A51 * f0[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
    rhs(code, phase, sigma, tmp, ground(motion, t + C5 * h), params, k5)
    for i in range(4):
        tmp[i] = x[i] + h * (A61 * f0[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i])
    rhs(code, phase, sigma, tmp, ground(motion, t + h), params, k6)
    for i in range(4):
        x_new[i] = x[i] + h * (B1 * f0[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i])
    rhs(code, phase, sigma, x_new, ground(motion, t + h), params, k7)
    for i in range(4):
        err[i] = h * (E1 * f0[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])


@njit(cache=True)
def error_norm(x, x_new, err, scale, rtol, atol):
    """RMS of the local error over the mixed absolute/relative tolerance (accept when <= 1)."""
    total = 0.0
    for i in range(4):
        tolerance = atol * scale[i] + rtol * max(abs(x[i]), abs(x_new[i]))
        total += (err[i] / tolerance) ** 2
    return math.sqrt(total / 4.0)


@njit(cache=True)
def next_step(h, norm):
    """Step-size proposal after an accepted step."""
    if norm > 0.0:
        return h * min(MAX_FACTOR, max(MIN_FACTOR, SAFETY * norm ** ERROR_EXPONENT))
    return h * MAX_FACTOR


@njit(cache=True)
def adaptive_step(code, phase, sigma, t, x, f0, h, motion, params, scale, k, x_new, err, zeno_guard):
    """Take one accepted step of at most h; returns (h_taken, error norm).

    zeno_guard: the step starts at an impact (theta = 0, moving off): a step that would contain a
    whole excursion is shortened so that the next impact is seen (Zeno cascades are followed).
    """
    rtol = params["rtol"]
    atol = params["atol"]
    while True:
        dopri_step(code, phase, sigma, t, x, f0, h, motion, params, k, x_new, err)
        norm = error_norm(x, x_new, err, scale, rtol, atol)
        if h < MIN_STEP:
            return h, norm
        if norm <= 1.0 and zeno_guard and sigma * x_new[0] <= 0.0:
            h = h * ZENO_STEP_SHRINK
            continue
        if norm <= 1.0:
            return h, norm
        h = h * max(MIN_FACTOR, SAFETY * norm ** ERROR_EXPONENT)


@njit(cache=True)
def workspace():
    """Work arrays of one response: (k, f0, x_new, err, scale); the loops never allocate after this."""
    return np.empty((WORK_ROWS, 4)), np.empty(4), np.empty(4), np.empty(4), np.empty(4)


# ---------------------------------------------------------------------------------------------
# dense output and event location
# ---------------------------------------------------------------------------------------------

@njit(cache=True)
def hermite(x0, f0, x1, f1, h, s, i):
    """Cubic Hermite interpolant of component i at fraction s of a step of length h."""
    h00 = 2 * s**3 - 3 * s**2 + 1
    h10 = s**3 - 2 * s**2 + s
    h01 = -2 * s**3 + 3 * s**2
    h11 = s**3 - s**2
    return h00 * x0[i] + h10 * h * f0[i] + h01 * x1[i] + h11 * h * f1[i]


@njit(cache=True)
def hermite_derivative(x0, f0, x1, f1, h, s, i):
    d00 = (6 * s**2 - 6 * s) / h
    d10 = 3 * s**2 - 4 * s + 1
    d01 = (-6 * s**2 + 6 * s) / h
    d11 = 3 * s**2 - 2 * s
    return d00 * x0[i] + d10 * f0[i] + d01 * x1[i] + d11 * f1[i]


@njit(cache=True)
def support(code, params, x):
    """Vertical support force per unit mass [m/s^2] of the pivot models (g for a rigid base)."""
    if code == HOUSNER:
        return params["g"]
    return ssi_support(x, params)


@njit(cache=True)
def event_value(kind, index, code, sigma, params, x0, f0, x1, f1, h, s, motion, t0, state):
    """The event function of ``kind`` on the step's interpolant at fraction s (sign change = event).

    state : (4,) scratch array (the interpolated state; passed in so the hot event loops never allocate).
    """
    if kind == EVENT_IMPACT:
        return sigma * hermite(x0, f0, x1, f1, h, s, 0)
    if kind == EVENT_OVERTURN:
        return abs(hermite(x0, f0, x1, f1, h, s, 0)) - params["overturn"]
    for i in range(4):
        state[i] = hermite(x0, f0, x1, f1, h, s, i)
    if kind == EVENT_CONTACT:
        return contact_indicator(index, state, params)
    # uplift of a pivot model: |ag| - tan(alpha) * support force per mass
    accel = ground(motion, t0 + s * h)
    return abs(accel) - math.tan(params["alpha"]) * support(code, params, state)


@njit(cache=True)
def locate(kind, index, code, sigma, params, x0, f0, x1, f1, h, motion, t0, state):
    """Fraction s in (0, 1] of the step where the event function changes sign (Illinois method)."""
    s_low, s_high = 0.0, 1.0
    v_low = event_value(kind, index, code, sigma, params, x0, f0, x1, f1, h, s_low, motion, t0, state)
    v_high = event_value(kind, index, code, sigma, params, x0, f0, x1, f1, h, s_high, motion, t0, state)
    side = 0
    for _ in range(100):
        if v_high == v_low:
            break
        s_mid = (s_low * v_high - s_high * v_low) / (v_high - v_low)
        if not (s_low < s_mid < s_high):
            s_mid = 0.5 * (s_low + s_high)
        v_mid = event_value(kind, index, code, sigma, params, x0, f0, x1, f1, h, s_mid, motion, t0, state)
        if (v_mid > 0) == (v_high > 0):
            s_high, v_high = s_mid, v_mid
            if side == 1:
                v_low *= 0.5
            side = 1
        else:
            s_low, v_low = s_mid, v_mid
            if side == -1:
                v_high *= 0.5
            side = -1
        if (s_high - s_low) * h < EVENT_TIME_RESOLUTION:
            break
    return s_high


@njit(cache=True)
def refine_event(kind, index, code, phase, sigma, t, x, f0, h, s_guess, motion, params, k, x_new, err, state):
    """Take the step to the event found on the interpolant, then sharpen the event time on the real
    solution (Illinois method on the step length: the cubic interpolant alone is only 4th-order
    accurate, which long steps would feel). On entry x_new, k[5] hold the full step; on return they hold
    the step to the event (on its far side or at it). Returns the step length taken."""
    f1 = k[ROW_F1]
    g_low = event_value(kind, index, code, sigma, params, x, f0, x, f0, h, 0.0, motion, t, state)
    g_high = event_value(kind, index, code, sigma, params, x, f0, x_new, f1, h, 1.0, motion, t, state)
    h_low, h_high = 0.0, h
    tolerance = EVENT_VALUE_FRACTION * max(abs(g_low), abs(g_high))
    h_event = s_guess * h
    side = 0
    for _ in range(EVENT_REFINEMENTS):
        dopri_step(code, phase, sigma, t, x, f0, h_event, motion, params, k, x_new, err)
        g_event = event_value(kind, index, code, sigma, params, x, f0, x_new, f1, h_event, 1.0, motion, t, state)
        if (g_event > 0.0) == (g_high > 0.0):
            h_high, g_high = h_event, g_event
            if side == 1:
                g_low *= 0.5
            side = 1
            if abs(g_event) <= tolerance or h_high - h_low < EVENT_TIME_RESOLUTION:
                return h_event
        else:
            h_low, g_low = h_event, g_event
            if side == -1:
                g_high *= 0.5
            side = -1
            if h_high - h_low < EVENT_TIME_RESOLUTION:
                break
        if g_high == g_low:
            break
        h_event = (h_low * g_high - h_high * g_low) / (g_high - g_low)
        if not (h_low < h_event < h_high):
            h_event = 0.5 * (h_low + h_high)
    # end on the far side of the event
    dopri_step(code, phase, sigma, t, x, f0, h_high, motion, params, k, x_new, err)
    return h_high


@njit(cache=True)
def track_peak(x0, f0, x1, f1, h, t, summary, overturn):
    """Update the peak |theta| with the extremum inside the step (theta' changes sign) and its end."""
    if x0[1] * f1[0] < 0.0 or x0[1] * x1[1] < 0.0:
        s_low, s_high = 0.0, 1.0
        d_low = hermite_derivative(x0, f0, x1, f1, h, s_low, 0)
        for _ in range(60):
            s_mid = 0.5 * (s_low + s_high)
            d_mid = hermite_derivative(x0, f0, x1, f1, h, s_mid, 0)
            if (d_mid > 0) == (d_low > 0):
                s_low, d_low = s_mid, d_mid
            else:
                s_high = s_mid
        theta_mid = abs(hermite(x0, f0, x1, f1, h, 0.5 * (s_low + s_high), 0))
        if theta_mid > summary["peak_angle"] and theta_mid <= overturn:
            summary["peak_angle"] = theta_mid
            summary["time_of_peak"] = t + 0.5 * (s_low + s_high) * h
    if abs(x1[0]) > summary["peak_angle"]:
        summary["peak_angle"] = min(abs(x1[0]), overturn)
        summary["time_of_peak"] = t + h


@njit(cache=True)
def state_scales(code, params, y_static, scale):
    """Absolute-error scales of [theta, theta_dot, y, y_dot]: alpha, alpha p, static settlement, ..."""
    p2 = params["kappa"] * params["g"] / params["R"]  # p^2 of the model's own pivot equation
    scale[0] = params["alpha"]
    scale[1] = params["alpha"] * math.sqrt(p2)
    scale[2] = max(y_static, STATE_SCALE_FLOOR)
    scale[3] = max(y_static * params["omega"], STATE_SCALE_FLOOR)
    return p2


@njit(cache=True)
def interval_of(t, dt):
    """Index of the sample interval that starts at or just before t (t within 1e-9 dt of a sample: that one)."""
    return int(math.floor(t / dt + 1e-9))


@njit(cache=True)
def write_rows(history, next_row, dt, t0, h, x0, f0, x1, f1):
    """History rows at the sample times in (t0, t0 + h], from the step's interpolant; returns the next row."""
    if history.shape[0] == 0:
        return next_row
    t1 = t0 + h
    while next_row < history.shape[0] and next_row * dt <= t1 + SEGMENT_END_FRACTION * dt:
        s = min(max((next_row * dt - t0) / h, 0.0), 1.0) if h > 0.0 else 1.0
        for i in range(4):
            history[next_row, i] = hermite(x0, f0, x1, f1, h, s, i)
        next_row += 1
    return next_row


@njit(cache=True)
def hold_rows(history, next_row, dt, t1, x):
    """History rows up to time t1 while the state is constant (rest)."""
    if history.shape[0] == 0:
        return next_row
    while next_row < history.shape[0] and next_row * dt <= t1 + SEGMENT_END_FRACTION * dt:
        for i in range(4):
            history[next_row, i] = x[i]
        next_row += 1
    return next_row


@njit(cache=True)
def finish(history, next_row, summary, status, t):
    """Blank the history after overturning or failure and write the outcome."""
    if history.shape[0] > 0 and (status == OVERTURNED or status == FAILED):
        for row in range(next_row, history.shape[0]):
            for i in range(4):
                history[row, i] = np.nan
    summary["status"] = status
    summary["t_end"] = t


@njit(cache=True)
def book_overturn(summary, params, t):
    """The block reached the overturning angle at time t."""
    summary["time_of_overturn"] = t
    summary["peak_angle"] = params["overturn"]
    summary["time_of_peak"] = t


@njit(cache=True)
def start_summary(summary, x, min_support):
    summary["peak_angle"] = abs(x[0])
    summary["time_of_peak"] = 0.0
    summary["n_impacts"] = 0.0
    summary["uplifted"] = 0.0
    summary["peak_settlement"] = x[2]
    summary["min_support_force"] = min_support
    summary["time_of_tension"] = np.nan
    summary["n_steps"] = 0.0
    summary["time_of_uplift"] = np.nan
    summary["time_of_overturn"] = np.nan
    summary["n_flights"] = 0.0
    summary["airborne_time"] = 0.0
    summary["peak_corner_uplift"] = 0.0
    summary["peak_friction_demand"] = 0.0


# ---------------------------------------------------------------------------------------------
# pivot models: housner, ssi, ssi-paper
# ---------------------------------------------------------------------------------------------

@njit(cache=True)
def rest_until_uplift(motion, t, t_seg_end, threshold):
    """Closed-form rest phase inside one sample interval: the state is constant; find where |ag| first
    beats the threshold. Returns (t_new, start_now); t_new = t_seg_end when it is not reached."""
    ag, dt = motion
    a_end = ground(motion, t_seg_end)
    if abs(a_end) <= threshold:
        return t_seg_end, False
    index = interval_of(t, dt)
    a_start = sample(ag, index)
    slope = (sample(ag, index + 1) - a_start) / dt
    target = threshold if a_end > 0 else -threshold
    t_cross = t_seg_end
    if slope != 0.0:
        t_cross = index * dt + (target - a_start) / slope
    return min(max(t_cross, t), t_seg_end), True


@njit(cache=True)
def pivot_event(code, phase, sigma, params, x, f0, x_new, k7, h, motion, t, state):
    """The earliest event inside an accepted step of a pivot model: (kind, fraction s)."""
    kind = EVENT_NONE
    s_event = 2.0
    if phase == ROCKING:
        if sigma * x[0] > 0.0 and sigma * x_new[0] <= 0.0:
            kind = EVENT_IMPACT
            s_event = locate(EVENT_IMPACT, 0, code, sigma, params, x, f0, x_new, k7, h, motion, t, state)
        if abs(x_new[0]) >= params["overturn"]:
            s_hit = locate(EVENT_OVERTURN, 0, code, sigma, params, x, f0, x_new, k7, h, motion, t, state)
            if s_hit < s_event:
                kind, s_event = EVENT_OVERTURN, s_hit
        if kind == EVENT_NONE and sigma * x[0] == 0.0 and sigma * x_new[0] < 0.0:
            kind, s_event = EVENT_SETTLE, 1.0
    else:
        v_start = event_value(EVENT_UPLIFT, 0, code, sigma, params, x, f0, x_new, k7, h, 0.0, motion, t, state)
        v_end = event_value(EVENT_UPLIFT, 0, code, sigma, params, x, f0, x_new, k7, h, 1.0, motion, t, state)
        if v_start <= 0.0 and v_end > 0.0:
            kind = EVENT_UPLIFT
            s_event = locate(EVENT_UPLIFT, 0, code, sigma, params, x, f0, x_new, k7, h, motion, t, state)
    return kind, s_event


@njit(cache=True)
def pivot_impact(code, params, x, sigma, zeno_speed, t, impact_times, summary):
    """Impact at theta = 0: restitution, pivot switch; returns (phase, sigma) after it."""
    summary["n_impacts"] += 1.0
    n = int(summary["n_impacts"])
    if n <= impact_times.size:
        impact_times[n - 1] = t
    x[0] = 0.0
    if code != HOUSNER and params["switch"] == SWITCH_CONSISTENT:
        ssi_pivot_switch(x, params)
    x[1] = x[1] * params["restitution"]
    if abs(x[1]) < zeno_speed:
        # the next excursion would be below the Zeno angle: the block comes to rest
        x[1] = 0.0
        return REST, 0.0
    return ROCKING, -sigma


@njit(cache=True)
def pivot_loop(code, ag, dt, n_tail, params, x, history, impact_times, summary):
    """Integrate one response of a pivot model from state x (see the module docstring).

    At rest the state is constant (closed form) or only the SSI vertical vibration moves; steps never
    cross a sample of the ground motion.
    """
    motion = (ag, dt)
    t_final = (ag.size + n_tail - 1) * dt
    alpha = params["alpha"]
    tan_alpha = math.tan(alpha)
    omega = params["omega"]
    y_static = params["g"] / (omega * omega) if code != HOUSNER else 0.0
    k, f0, x_new, err, scale = workspace()
    p2 = state_scales(code, params, y_static, scale)
    zeno_speed = math.sqrt(2.0 * p2 * math.sin(alpha) * params["zeno"])
    k7 = k[ROW_F1]
    state = k[ROW_EVENT]
    f0_current = False  # f0 = f(t, x) is known (first same as last: k7 of the step just taken)

    phase = REST
    sigma = 0.0
    if x[0] != 0.0 or x[1] != 0.0:
        phase = ROCKING
        sigma = 1.0 if (x[0] > 0.0 or (x[0] == 0.0 and x[1] > 0.0)) else -1.0
    status = NO_UPLIFT if phase == REST else ROCKING_OUTCOME
    start_summary(summary, x, support(code, params, x))
    if phase == ROCKING:
        summary["uplifted"] = 1.0
        summary["time_of_uplift"] = 0.0
    n_events = 0
    max_events = params["max_events"]
    next_row = hold_rows(history, 0, dt, 0.0, x)

    t = 0.0
    h = dt * 0.25
    failed = False
    start_now = False
    while t < t_final - SEGMENT_END_FRACTION * dt:
        # Steps end on every sample: a kink of the piecewise-linear ground motion inside a step fools the
        # embedded error estimate (measured: 5% peak-angle errors on real records when steps spanned samples).
        t_seg_end = (interval_of(t, dt) + 1) * dt
        if phase == REST:
            accel = ground(motion, t)
            if start_now or abs(accel) > tan_alpha * support(code, params, x):
                # start rocking towards the side the inertia force pushes
                start_now = False
                phase = ROCKING
                sigma = -1.0 if accel > 0 else 1.0
                x[0] = 0.0
                x[1] = 0.0
                f0_current = False
                if summary["uplifted"] == 0.0:
                    summary["uplifted"] = 1.0
                    summary["time_of_uplift"] = t
                if status == NO_UPLIFT:
                    status = ROCKING_OUTCOME
                n_events += 1
                if n_events > max_events:
                    failed = True
                    break
                continue
            at_rest = code == HOUSNER or (abs(x[2] - y_static) <= AT_REST_FRACTION * scale[2] + 1e-15
                                          and abs(x[3]) <= AT_REST_FRACTION * scale[3])
            if at_rest:
                t, start_now = rest_until_uplift(motion, t, t_seg_end, tan_alpha * support(code, params, x))
                if t >= t_seg_end - SEGMENT_END_FRACTION * dt:
                    t = t_seg_end  # (a crossing at the very end starts at the next interval's top)
                    start_now = False
                next_row = hold_rows(history, next_row, dt, t, x)
                f0_current = False
                continue
        h = min(h, t_seg_end - t)
        if not f0_current:
            rhs(code, phase, sigma, x, ground(motion, t), params, f0)
        zeno_guard = phase == ROCKING and x[0] == 0.0 and sigma * x[1] > 0.0
        h, norm = adaptive_step(code, phase, sigma, t, x, f0, h, motion, params, scale, k, x_new, err, zeno_guard)
        summary["n_steps"] += 1.0
        if summary["n_steps"] > MAX_STEPS:
            failed = True
            break
        kind, s_event = pivot_event(code, phase, sigma, params, x, f0, x_new, k7, h, motion, t, state)
        h_taken = h
        if kind != EVENT_NONE and kind != EVENT_SETTLE and s_event < 1.0:
            h_taken = refine_event(kind, 0, code, phase, sigma, t, x, f0, h, s_event, motion, params, k, x_new, err,
                                   state)
        if phase == ROCKING:
            track_peak(x, f0, x_new, k7, h_taken, t, summary, params["overturn"])
        if kind != EVENT_OVERTURN:
            next_row = write_rows(history, next_row, dt, t, h_taken, x, f0, x_new, k7)
        t = t + h_taken
        for i in range(4):
            x[i] = x_new[i]
            f0[i] = k7[i]
        f0_current = True
        if code != HOUSNER:
            if phase == REST and abs(x[2] - y_static) < SNAP_TO_STATIC_FRACTION * y_static \
                    and abs(x[3]) < SNAP_TO_STATIC_FRACTION * y_static * omega:
                # the free vertical vibration has died out: snap to the static equilibrium so that
                # the closed-form rest phase takes over (the support force changes by < 1e-4 g)
                x[2] = y_static
                x[3] = 0.0
                f0_current = False
            force = ssi_support(x, params)
            if force < summary["min_support_force"]:
                summary["min_support_force"] = force
            if force < 0.0 and math.isnan(summary["time_of_tension"]):
                summary["time_of_tension"] = t
            if x[2] > summary["peak_settlement"]:
                summary["peak_settlement"] = x[2]
        h = next_step(h, norm)
        if kind == EVENT_OVERTURN:
            status = OVERTURNED
            book_overturn(summary, params, t)
            break
        if kind == EVENT_SETTLE:
            phase = REST
            x[0] = 0.0
            x[1] = 0.0
            sigma = 0.0
            f0_current = False
        elif kind == EVENT_IMPACT:
            phase, sigma = pivot_impact(code, params, x, sigma, zeno_speed, t, impact_times, summary)
            f0_current = False
            n_events += 1
        elif kind == EVENT_UPLIFT:
            start_now = True  # uplift located: the top of the loop starts rocking here
        if n_events > max_events:
            failed = True
            break
    if not (failed or status == OVERTURNED):
        next_row = hold_rows(history, next_row, dt, t_final, x)
    # the lifted corner of a block rocking on the other one is 2 b sin(theta) above it
    summary["peak_corner_uplift"] = 2.0 * params["b"] * math.sin(min(summary["peak_angle"], 0.5 * math.pi))
    finish(history, next_row, summary, FAILED if failed else status, t)


# ---------------------------------------------------------------------------------------------
# bed models: winkler
# ---------------------------------------------------------------------------------------------

@njit(cache=True)
def bed_event(params, x, f0, x_new, k7, h, motion, t, before, after, min_fraction, state):
    """Earliest contact change or overturning inside the step: (kind, indicator index, fraction s).

    before, after: the contact indicators at the step's ends (``winkler.contact_indicators``).
    """
    kind = EVENT_NONE
    index = 0
    s_event = 2.0
    for i in range(N_CONTACT_INDICATORS):
        if (before[i] > 0.0) != (after[i] > 0.0):
            s_hit = locate(EVENT_CONTACT, i, WINKLER, 0.0, params, x, f0, x_new, k7, h, motion, t, state)
            if s_hit < s_event and s_hit > min_fraction:
                kind, index, s_event = EVENT_CONTACT, i, s_hit
    if abs(x_new[0]) >= params["overturn"]:
        s_hit = locate(EVENT_OVERTURN, 0, WINKLER, 0.0, params, x, f0, x_new, k7, h, motion, t, state)
        if s_hit < s_event:
            kind, index, s_event = EVENT_OVERTURN, 0, s_hit
    return kind, index, s_event


@njit(cache=True)
def bed_bookkeeping(params, x1, h, t_end, accel, f1, before, after, event_at_end, summary, impact_times):
    """Uplift, flights, touch-downs, corner uplift, support and friction demand after a step.

    before, after: contact indicators at the step's ends; indicators 0, 1 are the corners' penetrations;
    event_at_end: the step ends on a located contact change (a take-off or landing exactly there).
    """
    lift_minus = -after[0]
    lift_plus = -after[1]
    if summary["uplifted"] == 0.0 and (lift_minus > 0.0 or lift_plus > 0.0):
        summary["uplifted"] = 1.0
        summary["time_of_uplift"] = t_end
    highest = max(lift_minus, lift_plus)
    if highest > summary["peak_corner_uplift"]:
        summary["peak_corner_uplift"] = highest
    # a corner coming back into the ground is an impact
    if (before[0] < 0.0 and after[0] >= 0.0) or (before[1] < 0.0 and after[1] >= 0.0):
        summary["n_impacts"] += 1.0
        n = int(summary["n_impacts"])
        if n <= impact_times.size:
            impact_times[n - 1] = t_end
    flying_before = before[0] < 0.0 and before[1] < 0.0
    flying = after[0] < 0.0 and after[1] < 0.0
    if flying and not flying_before:
        summary["n_flights"] += 1.0
    if flying and flying_before:
        summary["airborne_time"] += h
    elif flying_before and event_at_end:
        summary["airborne_time"] += h  # landed at the step's end
    elif (flying or flying_before) and not event_at_end:
        summary["airborne_time"] += 0.5 * h  # a transition not located inside this step
    force, _ = bed_force(x1, params)
    if force < summary["min_support_force"]:
        summary["min_support_force"] = force
    if x1[2] > summary["peak_settlement"]:
        summary["peak_settlement"] = x1[2]
    if force >= FRICTION_MIN_SUPPORT * params["g"]:
        demand = friction_demand(x1, f1, accel, force, params)
        if demand > summary["peak_friction_demand"]:
            summary["peak_friction_demand"] = demand


@njit(cache=True)
def bed_loop(code, ag, dt, n_tail, params, x, history, impact_times, summary):
    """Integrate one response of a bed model from state x; no rest phase, no impact rule."""
    motion = (ag, dt)
    t_final = (ag.size + n_tail - 1) * dt
    omega = params["omega"]
    y_static = params["g"] / (omega * omega)
    k, f0, x_new, err, scale = workspace()
    state_scales(code, params, y_static, scale)
    before = np.empty(N_CONTACT_INDICATORS)
    after = np.empty(N_CONTACT_INDICATORS)
    k7 = k[ROW_F1]
    state = k[ROW_EVENT]
    force, _ = bed_force(x, params)
    start_summary(summary, x, force)
    contact_indicators(x, params, before)
    if before[0] < 0.0 or before[1] < 0.0:
        summary["uplifted"] = 1.0
        summary["time_of_uplift"] = 0.0
    next_row = hold_rows(history, 0, dt, 0.0, x)
    t = 0.0
    h = dt * 0.25
    failed = False
    overturned = False
    rhs(code, ROCKING, 0.0, x, ground(motion, t), params, f0)
    while t < t_final - SEGMENT_END_FRACTION * dt:
        h = min(h, (interval_of(t, dt) + 1) * dt - t)  # steps end on every sample (see pivot_loop)
        h, norm = adaptive_step(code, ROCKING, 0.0, t, x, f0, h, motion, params, scale, k, x_new, err, False)
        summary["n_steps"] += 1.0
        if summary["n_steps"] > MAX_STEPS:
            failed = True
            break
        contact_indicators(x_new, params, after)
        # an event at the very start of the step is the one just located: ignore it
        kind, index, s_event = bed_event(params, x, f0, x_new, k7, h, motion, t, before, after,
                                         EVENT_TIME_RESOLUTION / h, state)
        h_taken = h
        event_at_end = False
        if kind != EVENT_NONE and s_event < 1.0:
            h_taken = refine_event(kind, index, code, ROCKING, 0.0, t, x, f0, h, s_event, motion, params, k, x_new,
                                   err, state)
            far_side = after[index]
            contact_indicators(x_new, params, after)
            if kind == EVENT_CONTACT and ((after[index] > 0.0) != (far_side > 0.0) or after[index] == 0.0):
                # the step ends exactly on the contact change: book it as crossed
                after[index] = math.copysign(TINY_INDICATOR, far_side)
            event_at_end = kind == EVENT_CONTACT
        track_peak(x, f0, x_new, k7, h_taken, t, summary, params["overturn"])
        if kind != EVENT_OVERTURN:
            next_row = write_rows(history, next_row, dt, t, h_taken, x, f0, x_new, k7)
        for i in range(4):
            x[i] = x_new[i]
            f0[i] = k7[i]  # first same as last: the bed's force law is continuous, so is f
        t = t + h_taken
        bed_bookkeeping(params, x, h_taken, t, ground(motion, t), k7, before, after, event_at_end, summary,
                        impact_times)
        for i in range(N_CONTACT_INDICATORS):
            before[i] = after[i]
        h = next_step(h, norm)
        if (history.shape[0] == 0 and t > ag.size * dt and after[0] > 0.0 and after[1] > 0.0
                and settled_beyond_reach(x, params, summary["peak_angle"])):
            break  # the ground is at rest and the block can no longer reach its peak or lift (no history kept)
        if kind == EVENT_OVERTURN:
            overturned = True
            book_overturn(summary, params, t)
            break
    status = NO_UPLIFT
    if summary["uplifted"] > 0.0:
        status = ROCKING_OUTCOME
    if overturned:
        status = OVERTURNED
    finish(history, next_row, summary, FAILED if failed else status, t)


# ---------------------------------------------------------------------------------------------
# entry points (plain arrays in, records out)
# ---------------------------------------------------------------------------------------------

@njit(cache=True)
def simulate_kernel(code, ag, dt, n_tail, params, x0, history, impact_times, summary):
    """Integrate one response.

    Parameters
    ----------
    code : int
        Kernel code (fields.HOUSNER, SSI or WINKLER).
    ag : ndarray (n,)
        Ground acceleration [m/s^2] at t = k dt.
    n_tail : int
        Samples of free vibration after the record (zero ground acceleration).
    params : PARAMS_DTYPE record
    x0 : ndarray (4,)
        Initial [theta, theta_dot, y, y_dot]; overwritten with the final state.
    history : ndarray (n + n_tail, 4) or (0, 4)
        Filled with the state at the sample times (NaN after overturning).
    impact_times : ndarray (capacity,)
        Filled with the first ``capacity`` impact times [s].
    summary : SUMMARY_DTYPE record, filled.
    """
    if code == WINKLER:
        bed_loop(code, ag, dt, n_tail, params, x0, history, impact_times, summary)
    else:
        pivot_loop(code, ag, dt, n_tail, params, x0, history, impact_times, summary)


@njit(cache=True)
def single_kernel(code, ag, dt, n_tail, params_table, x0, history, impact_times, summaries):
    """``simulate_kernel`` for params_table[0] into summaries[0] (records cross from Python as arrays)."""
    simulate_kernel(code, ag, dt, n_tail, params_table[0], x0, history, impact_times, summaries[0])


@njit(cache=True)
def batch_kernel(code, ag, dt, n_tail, scales, params_table, initial_states, summaries):
    """One record at each factor in ``scales`` for each parameter row (no histories).

    scales (n_scale,); params_table (n_case,) records; initial_states (n_case, 4);
    summaries (n_case, n_scale) records, filled.
    """
    empty = np.empty((0, 4))
    impacts = np.empty(0)
    scaled = np.empty(ag.size)
    x = np.empty(4)
    for j in range(scales.size):
        for i in range(ag.size):
            scaled[i] = ag[i] * scales[j]
        for row in range(params_table.shape[0]):
            for i in range(4):
                x[i] = initial_states[row, i]
            simulate_kernel(code, scaled, dt, n_tail, params_table[row], x, empty, impacts, summaries[row, j])


@njit(cache=True)
def history_batch_kernel(code, ag, dt, n_tail, params_table, initial_states, histories, summaries):
    """One ground motion for each parameter row, keeping the histories (n_case, n + n_tail, 4)."""
    impacts = np.empty(0)
    x = np.empty(4)
    for row in range(params_table.shape[0]):
        for i in range(4):
            x[i] = initial_states[row, i]
        simulate_kernel(code, ag, dt, n_tail, params_table[row], x, histories[row], impacts, summaries[row])
