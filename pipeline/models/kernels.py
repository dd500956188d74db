"""rockfrag.models.kernels - the compiled time loops shared by every rocking model.

Input : plain float64 arrays, a parameter record (``fields.PARAMS_DTYPE``) and an initial state;
        no Python objects cross this line.
Output: a summary record (``fields.SUMMARY_DTYPE``: outcome, peak angle, impacts, ...) and, when
        asked, the histories [theta, theta_dot, y, y_dot] at the record's sample times.

One adaptive Dormand-Prince 5(4) integrator (Hairer, Norsett & Wanner, table 5.2) steps the state
x = [theta, theta_dot, y, y_dot]. Steps never cross a sample of the ground motion (which is linear
between samples), so every step sees a smooth right-hand side. Events (impact, uplift, contact
changes, overturning) are located on a cubic Hermite interpolant and the step is redone exactly to
the event time, after which integration restarts cleanly.

Four small records travel between the functions, as scipy's rk.py passes one state and its
``DenseOutput`` carries one step:
- ``GroundMotion`` (the components' samples, dt): the input; ``ground`` and ``vertical`` are the one
  place it is read. The vertical acts as a change of gravity, g + a_v(t), in the ground's frame
  (``effective_gravity``); a motion without a vertical row gives the same numbers as before, bit for bit.
- ``System`` (model code, phase, active pivot, parameters, ground motion): the right-hand side
  f(t, x), evaluated by ``derivatives``.
- ``Step`` (t, h, x0, f0, x1, f1): one step and its dense output, read by event location, peak
  tracking and the history rows.
- ``Workspace``: the work arrays of one response (Runge-Kutta stages, error, scales, contact indicators), allocated
  once per response by the entry point (``simulate_kernel``): the loops and their helpers are ``jit.kernel``s.

Two time loops:
- ``pivot_loop`` (housner, ssi, ssi-paper): the block rests until the uplift condition, rocks on one
  corner, and at theta = 0 an impact rule switches the pivot. Where g + a_v(t) < 0 the ground falls
  faster than gravity: these models have no flight phase, so the run stops there (``Outcome.FREE_FLIGHT``).
- ``bed_loop`` (winkler): no rest phase and no impact rule; the block tilts on its bed from the first
  sample and the bed's contact law (registered in rockfrag.models.contact) decides everything.

The physics of each model sits in its own module (housner.py, ssi.py, winkler.py and the bed laws) as
small compiled functions. What differs between models is dispatched on the model's kernel code
(``rhs``, ``support``, ``static_settlement``, ``vertical_at_rest``, ``pivot_impact``); what differs
between beds, on the law code (rockfrag.models.contact). Set ROCKFRAG_NO_NUMBA=1 to run as plain Python.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from rockfrag.models.base import Outcome
from rockfrag.models.contact import N_CONTACT_INDICATORS, attach_hooks, contact_indicator, contact_indicators
from rockfrag.models.fields import (
    EVENT_CONTACT,
    EVENT_IMPACT,
    EVENT_NONE,
    EVENT_OVERTURN,
    EVENT_SETTLE,
    EVENT_SLIP_START,
    EVENT_SLIP_STOP,
    EVENT_UPLIFT,
    HOUSNER,
    MODE_FLIGHT,
    MODE_REST,
    MODE_ROCK,
    MODE_SLIDE,
    MODE_SLIDE_ROCK,
    SLIP,
    SLIP_RATE,
    SSI,
    STATE_SIZE,
    SWITCH_CONSISTENT,
    TIED_STATE_SIZE,
    WINKLER,
    new_summaries,
)
from rockfrag.models.housner import (
    friction_impact,
    housner_rest_rhs,
    housner_rhs,
    housner_slide_rhs,
    housner_slide_rock_rhs,
    housner_support,
    rock_forces,
    slide_rock_accelerations,
)
from rockfrag.models.jit import kernel, njit
from rockfrag.models.ssi import ssi_pivot_switch, ssi_rest_rhs, ssi_rhs, ssi_support
from rockfrag.models.winkler import (
    bed_force,
    friction_demand,
    settled_beyond_reach,
    stick_forces,
    winkler_rhs,
    winkler_slip_rhs,
)

# phases of the pivot loop (bed models are always ROCKING)
REST = 0
ROCKING = 1

NO_UPLIFT = int(Outcome.NO_UPLIFT)
ROCKING_OUTCOME = int(Outcome.ROCKING)
OVERTURNED = int(Outcome.OVERTURNED)
FAILED = int(Outcome.FAILED)
FREE_FLIGHT = int(Outcome.FREE_FLIGHT)

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
SLIP_STOP_FRACTION = 1e-12      # of the slip rate's scale: a slide ending a step this slow has stopped there
UNKNOWN_CODE = "model kernel code not handled by rockfrag.models.kernels"

# rows of the ground motion's samples (``GroundMotion.samples``, what the entry points take)
HORIZONTAL = 0  # ag [m/s^2]
VERTICAL = 1    # a_v [m/s^2, up positive]; optional: a (1, n) motion has no vertical component

# The Dormand-Prince stages k2..k7 are the rows of ``Workspace.stages``; the last one is f(t + h, x_new),
# which the dense output and the next step reuse (first same as last).
N_STAGES = 6
END_STAGE = 5

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
# the records that travel between the functions
# ---------------------------------------------------------------------------------------------

class GroundMotion(NamedTuple):
    """The ground's acceleration: linear between samples, zero after the last one (the free tail).

    The horizontal component is read by ``ground``, the vertical one by ``vertical``; ``derivatives``
    hands both to the right-hand sides (the vertical as the effective gravity g + a_v). The components
    are the rows of one array (one array, not two, travels with every ``System``: measured 15% of an
    ssi batch's time for a second array).
    """

    samples: np.ndarray     # (1 or 2, n) [m/s^2] at t = i dt: rows HORIZONTAL and, if given, VERTICAL
    dt: float               # sampling step [s]


class System(NamedTuple):
    """The right-hand side f(t, x) being integrated (scipy's ``fun``), with what it depends on."""

    code: int               # the model's kernel code (fields.HOUSNER, SSI, WINKLER)
    phase: int              # REST or ROCKING (bed models: always ROCKING)
    sigma: float            # active pivot, +1 or -1 while rocking; 0 at rest and for bed models
    slip: float             # direction of the base's slip, +1 or -1 while it slides; 0 stuck or tied
    params: np.void         # the case's ``fields.PARAMS_DTYPE`` record
    motion: GroundMotion


class Step(NamedTuple):
    """One step from (t, x0, f0) to (t + h, x1, f1), f = dx/dt, and its cubic Hermite dense output."""

    t: float                # start [s]
    h: float                # length [s]
    x0: np.ndarray          # (STATE_SIZE,) state at t
    f0: np.ndarray          # (STATE_SIZE,) its derivative
    x1: np.ndarray          # (STATE_SIZE,) state at t + h
    f1: np.ndarray          # (STATE_SIZE,) its derivative


class Workspace(NamedTuple):
    """The work arrays of one response; the loops never allocate after ``workspace()``."""

    stages: np.ndarray        # (N_STAGES, STATE_SIZE) Dormand-Prince stages k2..k7; k7 = f(t + h, x_new)
    f0: np.ndarray            # (STATE_SIZE,) f(t, x) at the start of the step
    x_new: np.ndarray         # (STATE_SIZE,) state at the end of the step
    error: np.ndarray         # (STATE_SIZE,) local error estimate of the step
    scale: np.ndarray         # (STATE_SIZE,) absolute-error scale of each state component
    interpolated: np.ndarray  # (STATE_SIZE,) interpolated state of the event functions
    before: np.ndarray        # (N_CONTACT_INDICATORS,) a bed's contact indicators at the step's start
    after: np.ndarray         # (N_CONTACT_INDICATORS,) ... and at its end


@njit(cache=True)
def workspace():
    """The work arrays of one response (allocated by the entry point: the loops are kernels, which cannot)."""
    return Workspace(np.empty((N_STAGES, STATE_SIZE)), np.empty(STATE_SIZE), np.empty(STATE_SIZE),
                     np.empty(STATE_SIZE), np.empty(STATE_SIZE), np.empty(STATE_SIZE),
                     np.empty(N_CONTACT_INDICATORS), np.empty(N_CONTACT_INDICATORS))


# ---------------------------------------------------------------------------------------------
# ground motion, right-hand side and the Dormand-Prince step
# ---------------------------------------------------------------------------------------------

@kernel
def sample(samples, row, index):
    """Ground acceleration sample [m/s^2] of component ``row``.

    Zero after the record (the tail of free vibration) and for a component the motion does not have.
    """
    return samples[row, index] if index < samples.shape[1] and row < samples.shape[0] else 0.0


@kernel
def interpolate(motion, row, t):
    """Ground acceleration [m/s^2] of component ``row`` at time t [s]: linear between samples."""
    samples = motion.samples
    position = t / motion.dt  # in samples
    index = int(math.floor(position))
    if index < 0:
        return samples[row, 0]
    a0 = sample(samples, row, index)
    return a0 + (sample(samples, row, index + 1) - a0) * (position - index)


@kernel
def ground(motion, t):
    """Horizontal ground acceleration [m/s^2] at time t [s] (linear between samples)."""
    return interpolate(motion, HORIZONTAL, t)


@kernel
def vertical(motion, t):
    """Vertical ground acceleration a_v [m/s^2, up positive] at time t [s]; 0 without a vertical component."""
    if motion.samples.shape[0] <= VERTICAL:
        return 0.0
    return interpolate(motion, VERTICAL, t)


@kernel
def effective_gravity(params, motion, t):
    """Effective gravity g + a_v(t) [m/s^2]: gravity in the frame of the vertically accelerating ground."""
    return params["g"] + vertical(motion, t)


@kernel
def vertical_quiet(motion, t):
    """True when the vertical ground acceleration is zero over the whole sample interval of t."""
    samples = motion.samples
    index = interval_of(t, motion.dt)
    return sample(samples, VERTICAL, index) == 0.0 and sample(samples, VERTICAL, index + 1) == 0.0


@kernel
def free_flight_time(motion, g):
    """First time [s] at which g + a_v(t) falls below zero; inf if never.

    The ground then falls faster than gravity, so the block leaves it. a_v is linear between samples, so
    the crossing is exact.
    """
    samples = motion.samples
    if samples.shape[0] <= VERTICAL:
        return math.inf
    for i in range(samples.shape[1]):
        if g + samples[VERTICAL, i] < 0.0:
            if i == 0:
                return 0.0
            before = g + samples[VERTICAL, i - 1]
            return (i - 1) * motion.dt + motion.dt * before / (before - (g + samples[VERTICAL, i]))
    return math.inf


@kernel
def rhs(code, phase, sigma, x, accel, gravity, params, out, slip=0.0):
    """dx/dt into out for state x = [theta, theta_dot, y, y_dot, u, u_dot], by the model's kernel code.

    ``accel`` is the horizontal ground acceleration and ``gravity`` the effective gravity g + a_v [m/s^2];
    the pivot models also read the phase and the active pivot sigma; ``slip`` is the direction in which the
    base slides (0: stuck or tied, whose right-hand sides fill the first TIED_STATE_SIZE components: the slip's
    rates are zero; out may then be that short).
    """
    if slip == 0.0:
        for i in range(TIED_STATE_SIZE, out.size):
            out[i] = 0.0
    if code == HOUSNER:
        if phase == REST:
            if slip == 0.0:
                housner_rest_rhs(out)
            else:
                housner_slide_rhs(slip, x, accel, gravity, params, out)
        elif slip == 0.0:
            housner_rhs(sigma, x, accel, gravity, params, out)
        else:
            housner_slide_rock_rhs(sigma, slip, x, accel, gravity, params, out)
    elif code == SSI:
        if phase == REST:
            ssi_rest_rhs(x, gravity, params, out)
        else:
            ssi_rhs(sigma, x, accel, gravity, params, out)
    elif code == WINKLER:
        if slip == 0.0:
            winkler_rhs(x, accel, gravity, params, out)
        else:
            winkler_slip_rhs(slip, x, accel, gravity, params, out)
    else:
        raise ValueError(UNKNOWN_CODE)


@kernel
def derivatives(system, t, x, out):
    """f(t, x) of ``system`` into out: the one place where the ground motion enters the right-hand side.

    The horizontal enters as a ground acceleration, the vertical as the effective gravity g + a_v(t).
    """
    motion = system.motion
    rhs(system.code, system.phase, system.sigma, x, ground(motion, t), effective_gravity(system.params, motion, t),
        system.params, out, system.slip)


@kernel
def dopri_step(system, t, x, h, work):
    """One Dormand-Prince step of length h from (t, x), with ``work.f0`` = f(t, x).

    Fills ``work.x_new``, ``work.error`` and the stages, whose last row is f(t + h, x_new).

    k2..k7 are the stages in the notation of Hairer, Norsett & Wanner (table 5.2).
    """
    f0 = work.f0
    x_new = work.x_new
    k2, k3, k4, k5, k6, k7 = (work.stages[0], work.stages[1], work.stages[2], work.stages[3], work.stages[4],
                              work.stages[5])
    stage_state = work.error  # the error is written last: the stage states use its array meanwhile
    for i in range(STATE_SIZE):
        stage_state[i] = x[i] + h * A21 * f0[i]
    derivatives(system, t + C2 * h, stage_state, k2)
    for i in range(STATE_SIZE):
        stage_state[i] = x[i] + h * (A31 * f0[i] + A32 * k2[i])
    derivatives(system, t + C3 * h, stage_state, k3)
    for i in range(STATE_SIZE):
        stage_state[i] = x[i] + h * (A41 * f0[i] + A42 * k2[i] + A43 * k3[i])
    derivatives(system, t + C4 * h, stage_state, k4)
    for i in range(STATE_SIZE):
        stage_state[i] = x[i] + h * (A51 * f0[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
    derivatives(system, t + C5 * h, stage_state, k5)
    for i in range(STATE_SIZE):
        stage_state[i] = x[i] + h * (A61 * f0[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i])
    derivatives(system, t + h, stage_state, k6)
    for i in range(STATE_SIZE):
        x_new[i] = x[i] + h * (B1 * f0[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i])
    derivatives(system, t + h, x_new, k7)
    error = work.error
    for i in range(STATE_SIZE):
        error[i] = h * (E1 * f0[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])


@kernel
def error_norm(x, x_new, error, scale, rtol, atol, count):
    """RMS of the local error over the mixed absolute/relative tolerance (accept when <= 1).

    count: the number of state components the mean is over (``integrated_size``); the others are zero.
    """
    total = 0.0
    for i in range(STATE_SIZE):
        tolerance = atol * scale[i] + rtol * max(abs(x[i]), abs(x_new[i]))
        total += (error[i] / tolerance) ** 2
    return math.sqrt(total / count)


@kernel
def integrated_size(system):
    """State components the error norm is over: all while the base slides; else the slip is constant, not counted.

    (Its zero error adds exactly 0 to the norm, so a tied run steps as before the slip was added, and a stuck
    base with friction steps as the tied one.)
    """
    return STATE_SIZE if system.slip != 0.0 else TIED_STATE_SIZE


@kernel
def next_step(h, norm):
    """Step-size proposal after an accepted step."""
    if norm > 0.0:
        return h * min(MAX_FACTOR, max(MIN_FACTOR, SAFETY * norm ** ERROR_EXPONENT))
    return h * MAX_FACTOR


@kernel
def adaptive_step(system, t, x, h, work, zeno_guard):
    """Take one accepted step of at most h from (t, x) into ``work``; returns (h_taken, error norm).

    zeno_guard: the step starts at an impact (theta = 0, moving off): a step that would contain a
    whole excursion is shortened so that the next impact is seen (Zeno cascades are followed).
    """
    rtol = system.params["rtol"]
    atol = system.params["atol"]
    count = integrated_size(system)
    while True:
        dopri_step(system, t, x, h, work)
        norm = error_norm(x, work.x_new, work.error, work.scale, rtol, atol, count)
        if h < MIN_STEP:
            return h, norm
        if norm <= 1.0 and zeno_guard and system.sigma * work.x_new[0] <= 0.0:
            h = h * ZENO_STEP_SHRINK
            continue
        if norm <= 1.0:
            return h, norm
        h = h * max(MIN_FACTOR, SAFETY * norm ** ERROR_EXPONENT)


# ---------------------------------------------------------------------------------------------
# dense output and event location
# ---------------------------------------------------------------------------------------------

@kernel
def hermite(step, s, i):
    """Cubic Hermite interpolant of state component i at fraction s in [0, 1] of ``step``."""
    h00 = 2 * s**3 - 3 * s**2 + 1
    h10 = s**3 - 2 * s**2 + s
    h01 = -2 * s**3 + 3 * s**2
    h11 = s**3 - s**2
    h = step.h
    return h00 * step.x0[i] + h10 * h * step.f0[i] + h01 * step.x1[i] + h11 * h * step.f1[i]


@kernel
def hermite_derivative(step, s, i):
    """Time derivative of ``hermite`` at fraction s."""
    h = step.h
    d00 = (6 * s**2 - 6 * s) / h
    d10 = 3 * s**2 - 4 * s + 1
    d01 = (-6 * s**2 + 6 * s) / h
    d11 = 3 * s**2 - 2 * s
    return d00 * step.x0[i] + d10 * step.f0[i] + d01 * step.x1[i] + d11 * step.f1[i]


@kernel
def support(code, params, x, gravity):
    """Vertical support force per unit mass [m/s^2] of a pivot model at rest, by its kernel code.

    At state x under the effective gravity ``gravity`` = g + a_v [m/s^2].
    """
    if code == HOUSNER:
        return housner_support(gravity)
    if code == SSI:
        return ssi_support(x, params)
    raise ValueError(UNKNOWN_CODE)


@kernel
def event_value(kind, index, system, step, s, interpolated):
    """The event function of ``kind`` (and contact indicator ``index``) on the step's interpolant at fraction s.

    A sign change is the event.

    interpolated : (STATE_SIZE,) scratch for the interpolated state (the event loops never allocate).
    """
    params = system.params
    if kind == EVENT_IMPACT:
        return system.sigma * hermite(step, s, 0)
    if kind == EVENT_OVERTURN:
        return abs(hermite(step, s, 0)) - params["overturn"]
    if kind == EVENT_SLIP_STOP:
        return system.slip * hermite(step, s, SLIP_RATE)
    for i in range(STATE_SIZE):
        interpolated[i] = hermite(step, s, i)
    if kind == EVENT_CONTACT:
        return contact_indicator(index, interpolated, params)
    if kind == EVENT_SLIP_START:
        margin, _ = stick_margin(system, interpolated, step.t + s * step.h)
        return margin
    # uplift of a pivot model: |ag| - tan(alpha) * support force per mass
    t = step.t + s * step.h
    accel = ground(system.motion, t)
    gravity = effective_gravity(params, system.motion, t)
    return abs(accel) - math.tan(params["alpha"]) * support(system.code, params, interpolated, gravity)


@kernel
def locate(kind, index, system, step, interpolated):
    """Fraction s in (0, 1] of the step where the event function changes sign (Illinois method)."""
    s_low, s_high = 0.0, 1.0
    v_low = event_value(kind, index, system, step, s_low, interpolated)
    v_high = event_value(kind, index, system, step, s_high, interpolated)
    side = 0
    for _ in range(100):
        if v_high == v_low:
            break
        s_mid = (s_low * v_high - s_high * v_low) / (v_high - v_low)
        if not (s_low < s_mid < s_high):
            s_mid = 0.5 * (s_low + s_high)
        v_mid = event_value(kind, index, system, step, s_mid, interpolated)
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
        if (s_high - s_low) * step.h < EVENT_TIME_RESOLUTION:
            break
    return s_high


@kernel
def refine_event(kind, index, system, step, s_guess, work):
    """Take the step to the event found on the interpolant, then sharpen the event time on the real solution.

    Illinois method on the step length: the cubic interpolant alone is only 4th-order accurate, which
    long steps would feel.

    On entry ``step`` is the full step, whose x1, f1 are ``work.x_new`` and the last stage; on return
    these hold the step to the event (on its far side or at it). Returns that step's length.
    """
    t, x, f0, h = step.t, step.x0, step.f0, step.h
    interpolated = work.interpolated
    v_low = event_value(kind, index, system, Step(t, h, x, f0, x, f0), 0.0, interpolated)
    v_high = event_value(kind, index, system, step, 1.0, interpolated)
    h_low, h_high = 0.0, h
    tolerance = EVENT_VALUE_FRACTION * max(abs(v_low), abs(v_high))
    h_event = s_guess * h
    side = 0
    for _ in range(EVENT_REFINEMENTS):
        dopri_step(system, t, x, h_event, work)
        v_event = event_value(kind, index, system, Step(t, h_event, x, f0, step.x1, step.f1), 1.0, interpolated)
        if (v_event > 0.0) == (v_high > 0.0):
            h_high, v_high = h_event, v_event
            if side == 1:
                v_low *= 0.5
            side = 1
            if abs(v_event) <= tolerance or h_high - h_low < EVENT_TIME_RESOLUTION:
                return h_event
        else:
            h_low, v_low = h_event, v_event
            if side == -1:
                v_high *= 0.5
            side = -1
            if h_high - h_low < EVENT_TIME_RESOLUTION:
                break
        if v_high == v_low:
            break
        h_event = (h_low * v_high - h_high * v_low) / (v_high - v_low)
        if not (h_low < h_event < h_high):
            h_event = 0.5 * (h_low + h_high)
    # end on the far side of the event
    dopri_step(system, t, x, h_high, work)
    return h_high


@kernel
def track_peak(step, summary, overturn):
    """Update the peak |theta| with the extremum inside the step (theta' changes sign) and its end."""
    x0, x1 = step.x0, step.x1
    if x0[1] * step.f1[0] < 0.0 or x0[1] * x1[1] < 0.0:
        s_low, s_high = 0.0, 1.0
        rate_low = hermite_derivative(step, s_low, 0)
        for _ in range(60):
            s_mid = 0.5 * (s_low + s_high)
            rate_mid = hermite_derivative(step, s_mid, 0)
            if (rate_mid > 0) == (rate_low > 0):
                s_low, rate_low = s_mid, rate_mid
            else:
                s_high = s_mid
        theta_mid = abs(hermite(step, 0.5 * (s_low + s_high), 0))
        if theta_mid > summary["peak_angle"] and theta_mid <= overturn:
            summary["peak_angle"] = theta_mid
            summary["time_of_peak"] = step.t + 0.5 * (s_low + s_high) * step.h
    if abs(x1[0]) > summary["peak_angle"]:
        summary["peak_angle"] = min(abs(x1[0]), overturn)
        summary["time_of_peak"] = step.t + step.h


# ---------------------------------------------------------------------------------------------
# shared bookkeeping
# ---------------------------------------------------------------------------------------------

@kernel
def static_settlement(code, params):
    """Settlement of the foundation under the block's weight [m], by the model's kernel code."""
    if code == HOUSNER:
        return 0.0  # rigid base
    if code == SSI or code == WINKLER:
        omega = params["omega"]
        return params["g"] / (omega * omega)
    raise ValueError(UNKNOWN_CODE)


@kernel
def state_scales(params, y_static, scale):
    """Absolute-error scales of [theta, theta_dot, y, y_dot] into ``scale``; returns p^2 [1/s^2].

    The scales are alpha, alpha p, the static settlement and its rate (floored for a rigid base), alpha R
    and alpha R p for the slip; p^2 is that of the model's own pivot equation.
    """
    p_squared = params["kappa"] * params["g"] / params["R"]
    scale[0] = params["alpha"]
    scale[1] = params["alpha"] * math.sqrt(p_squared)
    scale[2] = max(y_static, STATE_SCALE_FLOOR)
    scale[3] = max(y_static * params["omega"], STATE_SCALE_FLOOR)
    scale[SLIP] = params["alpha"] * params["R"]  # the slip: the top's sway at theta = alpha, about b
    scale[SLIP_RATE] = scale[SLIP] * math.sqrt(p_squared)
    return p_squared


@kernel
def interval_of(t, dt):
    """Index of the sample interval that starts at or just before t (t within 1e-9 dt of a sample: that one)."""
    return int(math.floor(t / dt + 1e-9))


@kernel
def write_rows(history, next_row, dt, step):
    """History rows at the sample times in (t, t + h] of ``step``, from its interpolant; returns the next row."""
    if history.shape[0] == 0:
        return next_row
    t0, h = step.t, step.h
    t1 = t0 + h
    while next_row < history.shape[0] and next_row * dt <= t1 + SEGMENT_END_FRACTION * dt:
        s = min(max((next_row * dt - t0) / h, 0.0), 1.0) if h > 0.0 else 1.0
        for i in range(STATE_SIZE):
            history[next_row, i] = hermite(step, s, i)
        next_row += 1
    return next_row


@kernel
def hold_rows(history, next_row, dt, t1, x):
    """History rows up to time t1 while the state is constant (rest)."""
    if history.shape[0] == 0:
        return next_row
    while next_row < history.shape[0] and next_row * dt <= t1 + SEGMENT_END_FRACTION * dt:
        for i in range(STATE_SIZE):
            history[next_row, i] = x[i]
        next_row += 1
    return next_row


@kernel
def finish(history, next_row, summary, status, t):
    """Blank the history after overturning, failure or free flight and write the outcome."""
    if history.shape[0] > 0 and (status == OVERTURNED or status == FAILED or status == FREE_FLIGHT):
        for row in range(next_row, history.shape[0]):
            for i in range(STATE_SIZE):
                history[row, i] = np.nan
    summary["status"] = status
    summary["t_end"] = t


@kernel
def book_overturn(summary, params, t):
    """The block reached the overturning angle at time t."""
    summary["time_of_overturn"] = t
    summary["peak_angle"] = params["overturn"]
    summary["time_of_peak"] = t


@kernel
def book_impact(summary, impact_times, t):
    """Count an impact at time t and keep its time while there is room."""
    summary["n_impacts"] += 1.0
    count = int(summary["n_impacts"])
    if count <= impact_times.size:
        impact_times[count - 1] = t


@kernel
def start_summary(summary, x, min_support, t_free_flight):
    """Initial values of every summary field for a run starting at state x.

    t_free_flight [s] is the first time g + a_v < 0 (inf: never).
    """
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
    summary["time_of_free_flight"] = t_free_flight if t_free_flight < math.inf else np.nan
    summary["peak_slip"] = abs(x[SLIP])
    summary["residual_slip"] = abs(x[SLIP])
    summary["time_at_rest"] = 0.0
    summary["time_sliding"] = 0.0
    summary["time_rocking"] = 0.0
    summary["time_slide_rocking"] = 0.0
    summary["time_in_flight"] = 0.0


# ---------------------------------------------------------------------------------------------
# friction at the base (housner, winkler): stick-slip, mode selection, bookkeeping
# ---------------------------------------------------------------------------------------------

@kernel
def stick_margin(system, x, t):
    """(mu_s N - |H|, H) per unit mass [m/s^2] of the base held stuck at state x, time t.

    H is the horizontal force the stuck base needs (towards +x) and N the normal force: the rigid base's
    pivot force (``housner.rock_forces``) or g + a_v flat on it; the bed's (``winkler.stick_forces``). A
    negative margin: the base cannot stay stuck.
    """
    params = system.params
    accel = ground(system.motion, t)
    gravity = effective_gravity(params, system.motion, t)
    if system.code == WINKLER:
        horizontal, normal = stick_forces(x, accel, gravity, params)
    elif system.phase == ROCKING:
        horizontal, normal = rock_forces(system.sigma, x[0], x[1], accel, gravity, params)
    else:
        horizontal, normal = accel, gravity
    return params["mu_s"] * normal - abs(horizontal), horizontal


@kernel
def slip_direction(horizontal):
    """Direction of the slip that starts where a stuck base would need the force ``horizontal`` (opposite)."""
    return -1.0 if horizontal > 0.0 else 1.0


@kernel
def slip_event(system, step, min_fraction, interpolated, known_start):
    """The friction event inside the step: (kind, fraction s, event function at the step's end).

    kind is EVENT_NONE and s = 2 if there is none. A stuck base whose margin (``stick_margin``) turns negative
    starts to slide (EVENT_SLIP_START); a sliding one whose slip rate reaches zero stops (EVENT_SLIP_STOP). Events
    below min_fraction are ignored. known_start: the event function at the step's start when the caller has it
    (the previous step's end value, same system and state: the interpolant is exact at both ends), else NaN. A
    stuck base's margin costs a contact-force evaluation, so this saves one of the two per step.
    """
    kind = EVENT_SLIP_START if system.slip == 0.0 else EVENT_SLIP_STOP
    v_start = event_value(kind, 0, system, step, 0.0, interpolated) if math.isnan(known_start) else known_start
    v_end = event_value(kind, 0, system, step, 1.0, interpolated)
    crossed = v_end < 0.0 if kind == EVENT_SLIP_START else v_end <= 0.0
    if crossed and v_start >= 0.0:
        s_hit = locate(kind, 0, system, step, interpolated)
        if s_hit > min_fraction:
            return kind, s_hit, v_end
    return EVENT_NONE, 2.0, v_end


@kernel
def stopped_at_end(system, x, scale):
    """True when a sliding base ends a step with its slip rate at zero (or past it): the stop is there.

    (A stop at a step's very end is not located inside the next one, whose start it would be.)
    """
    return system.slip != 0.0 and system.slip * x[SLIP_RATE] <= SLIP_STOP_FRACTION * scale[SLIP_RATE]


@kernel
def book_mode_time(summary, mode, duration):
    """Add ``duration`` [s] to the time spent in contact ``mode`` (fields.MODE_*)."""
    if mode == MODE_REST:
        summary["time_at_rest"] += duration
    elif mode == MODE_SLIDE:
        summary["time_sliding"] += duration
    elif mode == MODE_ROCK:
        summary["time_rocking"] += duration
    elif mode == MODE_SLIDE_ROCK:
        summary["time_slide_rocking"] += duration
    else:
        summary["time_in_flight"] += duration


@kernel
def pivot_mode(system):
    """Contact mode (fields.MODE_*) of a pivot model's system: flat or rocking, stuck or sliding."""
    if system.phase == REST:
        return MODE_REST if system.slip == 0.0 else MODE_SLIDE
    return MODE_ROCK if system.slip == 0.0 else MODE_SLIDE_ROCK


@kernel
def bed_mode(system, indicators):
    """Contact mode of a bed model from its corners' penetrations (indicators 0, 1) and its slip."""
    lifted = int(indicators[0] < 0.0) + int(indicators[1] < 0.0)
    if lifted == 2:
        return MODE_FLIGHT
    if lifted == 1:
        return MODE_ROCK if system.slip == 0.0 else MODE_SLIDE_ROCK
    return MODE_REST if system.slip == 0.0 else MODE_SLIDE


@kernel
def book_slip(summary, x):
    """Peak and current absolute slip [m] after a step (the slip's extrema are at its stops: step ends)."""
    slip = abs(x[SLIP])
    if slip > summary["peak_slip"]:
        summary["peak_slip"] = slip
    summary["residual_slip"] = slip


@kernel
def flat_slide_mode(params, slip):
    """(phase, sigma, slip) of a rigid base sliding flat in direction ``slip``.

    The kinetic friction tips the block onto its leading corner when mu_k > tan(alpha) (Shenton 1996): it then
    slide-rocks on that corner.
    """
    if params["mu_k"] > math.tan(params["alpha"]):
        return ROCKING, slip, slip
    return REST, 0.0, slip


@kernel
def rest_mode(system, x, t, crossed):
    """(phase, sigma, slip) of a rigid base with friction, flat and not sliding (u' = 0) at time t.

    Shenton's (1996) initiation criteria: it rocks if |ag| > tan(alpha) (g + a_v) and the pivot's friction
    need stays within mu_s; slide-rocks if the pivot cannot hold but a sliding pivot still tips the block
    (mu_k > tan(alpha)); slides flat if it cannot rock but |ag| > mu_s (g + a_v); rests otherwise.
    ``crossed``: the lower of the two thresholds was just located (it counts as exceeded).
    """
    params = system.params
    accel = ground(system.motion, t)
    gravity = effective_gravity(params, system.motion, t)
    tan_alpha = math.tan(params["alpha"])
    mu_s = params["mu_s"]
    tipping = abs(accel) > tan_alpha * gravity or (crossed and tan_alpha <= mu_s)
    sliding = abs(accel) > mu_s * gravity or (crossed and mu_s < tan_alpha)
    if tipping:
        sigma = -1.0 if accel > 0.0 else 1.0
        horizontal, normal = rock_forces(sigma, 0.0, 0.0, accel, gravity, params)
        if abs(horizontal) <= mu_s * normal:
            return ROCKING, sigma, 0.0
        slip = slip_direction(horizontal)
        theta_acc, _, _ = slide_rock_accelerations(sigma, slip, 0.0, 0.0, gravity, params)
        if sigma * theta_acc > 0.0:
            return ROCKING, sigma, slip
        return flat_slide_mode(params, slip_direction(accel))
    if sliding:
        return flat_slide_mode(params, slip_direction(accel))
    return REST, 0.0, 0.0


@kernel
def stuck_slip(system, x, t):
    """Slip direction of a base whose slip rate is zero at time t: 0 if it can stay stuck."""
    stuck = System(system.code, system.phase, system.sigma, 0.0, system.params, system.motion)
    margin, horizontal = stick_margin(stuck, x, t)
    return 0.0 if margin >= 0.0 else slip_direction(horizontal)


@kernel
def friction_pivot_impact(system, x, zeno_speed, t, impact_times, summary):
    """Impact at theta = 0 of a rigid base with friction (``housner.friction_impact``); (phase, sigma, slip) after.

    The block rocks on the other corner (sliding if its slip rate is not zero, else stuck if the friction
    holds), or lies flat, sliding or at rest: where it landed on both corners, or where the next excursion would be
    below the Zeno angle.
    """
    book_impact(summary, impact_times, t)
    x[0] = 0.0
    flat = friction_impact(system.sigma, x, system.params)
    slip = 0.0 if x[SLIP_RATE] == 0.0 else (1.0 if x[SLIP_RATE] > 0.0 else -1.0)
    if flat or abs(x[1]) < zeno_speed:
        x[1] = 0.0
        if slip == 0.0:
            return REST, 0.0, 0.0
        return flat_slide_mode(system.params, slip)
    sigma = -system.sigma
    if slip == 0.0:
        slip = stuck_slip(System(system.code, ROCKING, sigma, 0.0, system.params, system.motion), x, t)
    return ROCKING, sigma, slip


# ---------------------------------------------------------------------------------------------
# pivot models: housner, ssi, ssi-paper
# ---------------------------------------------------------------------------------------------

@kernel
def start_threshold(params):
    """The coefficient c [-] with which a pivot model at rest starts to move when |ag| > c * support.

    tan(alpha), or with friction the lower of tan(alpha) (rocking) and mu_s (sliding).
    """
    tan_alpha = math.tan(params["alpha"])
    if params["mu_s"] > 0.0:
        return min(tan_alpha, params["mu_s"])
    return tan_alpha


@kernel
def rest_until_uplift(system, x, t, t_sample_end):
    """Closed-form rest phase inside one sample interval; returns (t_new, start_now).

    The state x is constant; find where |ag| first beats the threshold c * support, c = tan(alpha) or with
    friction min(tan(alpha), mu_s) (``start_threshold``); t_new = t_sample_end when it is not reached.

    Both ag and the threshold are linear in time inside the interval (the rigid base's support force is
    g + a_v; a settled spring's is constant), and |ag| is below the threshold at t, so the crossing is on
    the side of ag at the interval's end, where |ag| - threshold is linear: one division finds it.
    """
    motion, params, code = system.motion, system.params, system.code
    samples, dt = motion.samples, motion.dt
    tan_alpha = start_threshold(params)
    a_end = ground(motion, t_sample_end)
    threshold_end = tan_alpha * support(code, params, x, effective_gravity(params, motion, t_sample_end))
    if abs(a_end) <= threshold_end:
        return t_sample_end, False
    index = interval_of(t, dt)
    t_start = index * dt
    a_start = sample(samples, HORIZONTAL, index)
    slope = (sample(samples, HORIZONTAL, index + 1) - a_start) / dt
    threshold_start = tan_alpha * support(code, params, x, params["g"] + sample(samples, VERTICAL, index))
    span = t_sample_end - t_start
    threshold_slope = (threshold_end - threshold_start) / span if span > 0.0 else 0.0
    side = 1.0 if a_end > 0 else -1.0
    # a_start + slope s = side (threshold_start + threshold_slope s), s the time since t_start
    rate = slope - side * threshold_slope
    t_cross = t_sample_end
    if rate != 0.0:
        t_cross = t_start + (side * threshold_start - a_start) / rate
    return min(max(t_cross, t), t_sample_end), True


@kernel
def vertical_at_rest(code, x, y_static, scale, quiet):
    """True when a pivot model at rest has no vertical vibration left.

    Its rest phase is then the closed form (``rest_until_uplift``): always on a rigid base; for ssi below
    AT_REST_FRACTION and while the vertical ground motion is ``quiet`` (zero over the sample interval:
    nothing forces the spring).
    """
    if code == HOUSNER:
        return True
    if code == SSI:
        return quiet and (abs(x[2] - y_static) <= AT_REST_FRACTION * scale[2] + 1e-15
                and abs(x[3]) <= AT_REST_FRACTION * scale[3])
    raise ValueError(UNKNOWN_CODE)


@kernel
def pivot_event(system, step, interpolated):
    """The earliest event inside an accepted step of a pivot model: (kind, fraction s)."""
    params = system.params
    sigma = system.sigma
    x, x_new = step.x0, step.x1
    kind = EVENT_NONE
    s_event = 2.0
    if system.phase == ROCKING:
        if sigma * x[0] > 0.0 and sigma * x_new[0] <= 0.0:
            kind = EVENT_IMPACT
            s_event = locate(EVENT_IMPACT, 0, system, step, interpolated)
        if abs(x_new[0]) >= params["overturn"]:
            s_hit = locate(EVENT_OVERTURN, 0, system, step, interpolated)
            if s_hit < s_event:
                kind, s_event = EVENT_OVERTURN, s_hit
        if kind == EVENT_NONE and sigma * x[0] == 0.0 and sigma * x_new[0] < 0.0:
            kind, s_event = EVENT_SETTLE, 1.0
    else:
        v_start = event_value(EVENT_UPLIFT, 0, system, step, 0.0, interpolated)
        v_end = event_value(EVENT_UPLIFT, 0, system, step, 1.0, interpolated)
        if v_start <= 0.0 and v_end > 0.0:
            kind = EVENT_UPLIFT
            s_event = locate(EVENT_UPLIFT, 0, system, step, interpolated)
    return kind, s_event


@kernel
def pivot_impact(system, x, zeno_speed, t, impact_times, summary):
    """Impact at theta = 0: restitution and pivot switch by the model's rule; returns (phase, sigma) after it.

    The block rocks on the other pivot after it, or rests when the next excursion would be below the Zeno
    angle.
    """
    params = system.params
    book_impact(summary, impact_times, t)
    x[0] = 0.0
    if system.code == SSI and params["switch"] == SWITCH_CONSISTENT:
        ssi_pivot_switch(x, params)
    x[1] = x[1] * params["restitution"]
    if abs(x[1]) < zeno_speed:
        x[1] = 0.0
        return REST, 0.0
    return ROCKING, -system.sigma


@kernel
def ssi_bookkeeping(system, x, y_static, t, summary):
    """After a step of the ssi model: book the support force, tension and settlement.

    At rest, snap a died-out vertical vibration to the static equilibrium. Returns True when it snapped
    (f(t, x) changed).
    """
    params = system.params
    snapped = False
    if system.phase == REST and vertical_quiet(system.motion, t) \
            and abs(x[2] - y_static) < SNAP_TO_STATIC_FRACTION * y_static \
            and abs(x[3]) < SNAP_TO_STATIC_FRACTION * y_static * params["omega"]:
        # the free vertical vibration has died out: snap to the static equilibrium so that
        # the closed-form rest phase takes over (the support force changes by < 1e-4 g)
        x[2] = y_static
        x[3] = 0.0
        snapped = True
    force = ssi_support(x, params)
    if force < summary["min_support_force"]:
        summary["min_support_force"] = force
    if force < 0.0 and math.isnan(summary["time_of_tension"]):
        summary["time_of_tension"] = t
    if x[2] > summary["peak_settlement"]:
        summary["peak_settlement"] = x[2]
    return snapped


@kernel
def pivot_loop(code, samples, dt, n_tail, params, x, history, impact_times, summary, work):
    """Integrate one response of a pivot model from state x, in the work arrays ``work`` (see the module docstring).

    At rest the state is constant (closed form) or only the SSI vertical vibration moves; steps never
    cross a sample of the ground motion. The run stops where g + a_v first falls below zero (free flight).
    With friction (housner, ``params["mu_s"] > 0``) the base may also slide: flat (the rest phase with a
    slip direction) or on its pivot, with stick-slip events (``slip_event``) and Shenton's mode selection
    (``rest_mode``) wherever the base is flat and stuck.
    """
    motion = GroundMotion(samples, dt)
    t_final = (samples.shape[1] + n_tail - 1) * dt
    t_free_flight = free_flight_time(motion, params["g"])
    t_stop = min(t_final, t_free_flight)  # the end of the run
    alpha = params["alpha"]
    threshold = start_threshold(params)
    friction = params["mu_s"] > 0.0
    y_static = static_settlement(code, params)
    p_squared = state_scales(params, y_static, work.scale)
    zeno_speed = math.sqrt(2.0 * p_squared * math.sin(alpha) * params["zeno"])
    f0, x_new, f1 = work.f0, work.x_new, work.stages[END_STAGE]
    f0_current = False  # f0 = f(t, x) is known (first same as last: f1 of the step just taken)

    phase = REST
    sigma = 0.0
    if x[0] != 0.0 or x[1] != 0.0:
        phase = ROCKING
        sigma = 1.0 if (x[0] > 0.0 or (x[0] == 0.0 and x[1] > 0.0)) else -1.0
    system = System(code, phase, sigma, 0.0, params, motion)
    if friction and phase == ROCKING:
        system = System(code, phase, sigma, stuck_slip(system, x, 0.0), params, motion)
    status = NO_UPLIFT if phase == REST else ROCKING_OUTCOME
    start_summary(summary, x, support(code, params, x, effective_gravity(params, motion, 0.0)), t_free_flight)
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
    while t < t_stop - SEGMENT_END_FRACTION * dt:
        # Steps end on every sample: a kink of the piecewise-linear ground motion inside a step fools the
        # embedded error estimate (measured: 5% peak-angle errors on real records when steps spanned samples).
        t_sample_end = min((interval_of(t, dt) + 1) * dt, t_stop)
        if system.phase == REST and system.slip == 0.0:
            accel = ground(motion, t)
            gravity = effective_gravity(params, motion, t)
            if start_now or abs(accel) > threshold * support(code, params, x, gravity):
                if friction:
                    phase, sigma, slip = rest_mode(system, x, t, start_now)
                else:  # start rocking towards the side the inertia force pushes
                    phase, sigma, slip = ROCKING, -1.0 if accel > 0 else 1.0, 0.0
                start_now = False
                system = System(code, phase, sigma, slip, params, motion)
                f0_current = False
                if phase == ROCKING:
                    x[0] = 0.0
                    x[1] = 0.0
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
            if vertical_at_rest(code, x, y_static, work.scale, vertical_quiet(motion, t)):
                t_rest = t
                t, start_now = rest_until_uplift(system, x, t, t_sample_end)
                if t >= t_sample_end - SEGMENT_END_FRACTION * dt:
                    t = t_sample_end  # (a crossing at the very end starts at the next interval's top)
                    start_now = False
                book_mode_time(summary, MODE_REST, t - t_rest)
                next_row = hold_rows(history, next_row, dt, t, x)
                f0_current = False
                continue
        h = min(h, t_sample_end - t)
        if not f0_current:
            derivatives(system, t, x, f0)
        zeno_guard = system.phase == ROCKING and x[0] == 0.0 and system.sigma * x[1] > 0.0
        h, norm = adaptive_step(system, t, x, h, work, zeno_guard)
        summary["n_steps"] += 1.0
        if summary["n_steps"] > MAX_STEPS:
            failed = True
            break
        step = Step(t, h, x, f0, x_new, f1)
        if friction:
            kind, s_event = EVENT_NONE, 2.0
            if system.phase == ROCKING:  # (sliding flat, only the slip can change: the friction ratio is fixed)
                kind, s_event = pivot_event(system, step, work.interpolated)
            slip_kind, s_slip, _ = slip_event(system, step, 0.0, work.interpolated, math.nan)
            if slip_kind != EVENT_NONE and s_slip < s_event:
                kind, s_event = slip_kind, s_slip
        else:
            kind, s_event = pivot_event(system, step, work.interpolated)
        if kind != EVENT_NONE and kind != EVENT_SETTLE and s_event < 1.0:
            step = Step(t, refine_event(kind, 0, system, step, s_event, work), x, f0, x_new, f1)
        if system.phase == ROCKING:
            track_peak(step, summary, params["overturn"])
        if kind != EVENT_OVERTURN:
            next_row = write_rows(history, next_row, dt, step)
        book_mode_time(summary, pivot_mode(system), step.h)
        t = t + step.h
        for i in range(STATE_SIZE):
            x[i] = x_new[i]
            f0[i] = f1[i]
        f0_current = True
        if friction:
            book_slip(summary, x)
            if kind == EVENT_NONE and stopped_at_end(system, x, work.scale):
                kind = EVENT_SLIP_STOP
        if code == SSI and ssi_bookkeeping(system, x, y_static, t, summary):
            f0_current = False
        h = next_step(h, norm)
        if kind == EVENT_OVERTURN:
            status = OVERTURNED
            book_overturn(summary, params, t)
            break
        if kind == EVENT_SETTLE:
            x[0] = 0.0
            x[1] = 0.0
            system = System(code, REST, 0.0, 0.0, params, motion)
            if friction and x[SLIP_RATE] != 0.0:
                phase, sigma, slip = flat_slide_mode(params, 1.0 if x[SLIP_RATE] > 0.0 else -1.0)
                system = System(code, phase, sigma, slip, params, motion)
            f0_current = False
        elif kind == EVENT_IMPACT:
            if friction:
                phase, sigma, slip = friction_pivot_impact(system, x, zeno_speed, t, impact_times, summary)
            else:
                phase, sigma = pivot_impact(system, x, zeno_speed, t, impact_times, summary)
                slip = 0.0
            system = System(code, phase, sigma, slip, params, motion)
            f0_current = False
            n_events += 1
        elif kind == EVENT_UPLIFT:
            start_now = True  # uplift located: the top of the loop starts rocking here
        elif kind == EVENT_SLIP_START:
            _, horizontal = stick_margin(system, x, t)
            system = System(code, system.phase, system.sigma, slip_direction(horizontal), params, motion)
            f0_current = False
            n_events += 1
        elif kind == EVENT_SLIP_STOP:
            x[SLIP_RATE] = 0.0
            if system.phase == ROCKING:
                system = System(code, ROCKING, system.sigma, stuck_slip(system, x, t), params, motion)
            else:
                phase, sigma, slip = rest_mode(System(code, REST, 0.0, 0.0, params, motion), x, t, False)
                system = System(code, phase, sigma, slip, params, motion)
                if phase == ROCKING:
                    if summary["uplifted"] == 0.0:
                        summary["uplifted"] = 1.0
                        summary["time_of_uplift"] = t
                    if status == NO_UPLIFT:
                        status = ROCKING_OUTCOME
            f0_current = False
            n_events += 1
        if n_events > max_events:
            failed = True
            break
    if not (failed or status == OVERTURNED):
        if t_stop < t_final:
            status = FREE_FLIGHT  # the history ends here: the state after lift-off is not followed
        else:
            next_row = hold_rows(history, next_row, dt, t_final, x)
    # the lifted corner of a block rocking on the other one is 2 b sin(theta) above it
    summary["peak_corner_uplift"] = 2.0 * params["b"] * math.sin(min(summary["peak_angle"], 0.5 * math.pi))
    finish(history, next_row, summary, FAILED if failed else status, t)


# ---------------------------------------------------------------------------------------------
# bed models: winkler (the bed's contact law: rockfrag.models.contact)
# ---------------------------------------------------------------------------------------------

@kernel
def bed_event(system, step, before, after, min_fraction, interpolated):
    """Earliest contact change or overturning inside the step: (kind, indicator index, fraction s).

    before, after: the contact indicators at the step's ends (``contact.contact_indicators``); an event
    at a fraction below min_fraction is the one just located and is ignored.
    """
    kind = EVENT_NONE
    index = 0
    s_event = 2.0
    for i in range(N_CONTACT_INDICATORS):
        if (before[i] > 0.0) != (after[i] > 0.0):
            s_hit = locate(EVENT_CONTACT, i, system, step, interpolated)
            if s_hit < s_event and s_hit > min_fraction:
                kind, index, s_event = EVENT_CONTACT, i, s_hit
    if abs(step.x1[0]) >= system.params["overturn"]:
        s_hit = locate(EVENT_OVERTURN, 0, system, step, interpolated)
        if s_hit < s_event:
            kind, index, s_event = EVENT_OVERTURN, 0, s_hit
    return kind, index, s_event


@kernel
def bed_bookkeeping(system, step, before, after, event_at_end, summary, impact_times):
    """Uplift, flights, touch-downs, corner uplift, support and friction demand after ``step``.

    before, after: contact indicators at the step's ends; indicators 0, 1 are the corners' penetrations;
    event_at_end: the step ends on a located contact change (a take-off or landing exactly there).
    """
    params = system.params
    x1 = step.x1
    h = step.h
    t_end = step.t + step.h
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
        book_impact(summary, impact_times, t_end)
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
        demand = friction_demand(x1, step.f1, ground(system.motion, t_end), force, params)
        if demand > summary["peak_friction_demand"]:
            summary["peak_friction_demand"] = demand


@kernel
def bed_loop(code, samples, dt, n_tail, params, x, history, impact_times, summary, work):
    """Integrate one response of a bed model from state x, in the work arrays ``work`` (``workspace()``).

    No rest phase, no impact rule (the block flies where g + a_v < 0 as anywhere else: its bed lets go).
    With friction (``params["mu_s"] > 0``) the base centre sticks or slides, with stick-slip events
    (``slip_event``); a slip that stops sticks if the friction can hold it (``stuck_slip``).
    """
    motion = GroundMotion(samples, dt)
    friction = params["mu_s"] > 0.0
    system = System(code, ROCKING, 0.0, 0.0, params, motion)
    if friction:
        system = System(code, ROCKING, 0.0, stuck_slip(system, x, 0.0), params, motion)
    t_final = (samples.shape[1] + n_tail - 1) * dt
    state_scales(params, static_settlement(code, params), work.scale)
    f0, x_new, f1 = work.f0, work.x_new, work.stages[END_STAGE]
    before, after = work.before, work.after
    force, _ = bed_force(x, params)
    start_summary(summary, x, force, free_flight_time(motion, params["g"]))
    contact_indicators(x, params, before)
    if before[0] < 0.0 or before[1] < 0.0:
        summary["uplifted"] = 1.0
        summary["time_of_uplift"] = 0.0
    next_row = hold_rows(history, 0, dt, 0.0, x)
    t = 0.0
    h = dt * 0.25
    failed = False
    overturned = False
    n_events = 0
    margin_at_start = math.nan  # a stuck base's stick margin at (t, x), when the step before computed it
    derivatives(system, t, x, f0)
    while t < t_final - SEGMENT_END_FRACTION * dt:
        h = min(h, (interval_of(t, dt) + 1) * dt - t)  # steps end on every sample (see pivot_loop)
        h, norm = adaptive_step(system, t, x, h, work, False)
        summary["n_steps"] += 1.0
        if summary["n_steps"] > MAX_STEPS:
            failed = True
            break
        contact_indicators(x_new, params, after)
        step = Step(t, h, x, f0, x_new, f1)
        # an event at the very start of the step is the one just located: ignore it
        kind, index, s_event = bed_event(system, step, before, after, EVENT_TIME_RESOLUTION / h, work.interpolated)
        margin_at_end = math.nan
        if friction:
            slip_kind, s_slip, margin_at_end = slip_event(system, step, EVENT_TIME_RESOLUTION / h, work.interpolated,
                                                          margin_at_start)
            if slip_kind != EVENT_NONE and s_slip < s_event:
                kind, index, s_event = slip_kind, 0, s_slip
        event_at_end = False
        refined = kind != EVENT_NONE and s_event < 1.0
        if refined:
            step = Step(t, refine_event(kind, index, system, step, s_event, work), x, f0, x_new, f1)
            far_side = after[index]
            contact_indicators(x_new, params, after)
            if kind == EVENT_CONTACT and ((after[index] > 0.0) != (far_side > 0.0) or after[index] == 0.0):
                # the step ends exactly on the contact change: book it as crossed
                after[index] = math.copysign(TINY_INDICATOR, far_side)
            event_at_end = kind == EVENT_CONTACT
        track_peak(step, summary, params["overturn"])
        if kind != EVENT_OVERTURN:
            next_row = write_rows(history, next_row, dt, step)
        for i in range(STATE_SIZE):
            x[i] = x_new[i]
            f0[i] = f1[i]  # first same as last: the bed's force law is continuous, so is f
        # the step's mode is the one it started in: a step that ends on a contact change still belongs to the
        # mode before it (booking it after made a lift-off's mode gain the step, a landing's lose it)
        book_mode_time(summary, bed_mode(system, before), step.h)
        t = t + step.h
        bed_bookkeeping(system, step, before, after, event_at_end, summary, impact_times)
        for i in range(N_CONTACT_INDICATORS):
            before[i] = after[i]
        h = next_step(h, norm)
        if friction:
            book_slip(summary, x)
            if kind == EVENT_NONE and stopped_at_end(system, x, work.scale):
                kind = EVENT_SLIP_STOP
            if kind == EVENT_SLIP_START or kind == EVENT_SLIP_STOP:
                if kind == EVENT_SLIP_STOP:
                    x[SLIP_RATE] = 0.0
                    slip = stuck_slip(system, x, t)
                else:
                    _, horizontal = stick_margin(system, x, t)
                    slip = slip_direction(horizontal)
                system = System(code, ROCKING, 0.0, slip, params, motion)
                derivatives(system, t, x, f0)  # the friction changed: f jumps
                n_events += 1
                if n_events > params["max_events"]:
                    failed = True
                    break
            # the next step starts where this one ended, stuck as it was: its margin there is known (unless the
            # step was cut at an event, whose far side was not where the margin was evaluated)
            stuck_on = system.slip == 0.0 and not refined and kind != EVENT_SLIP_START and kind != EVENT_SLIP_STOP
            margin_at_start = margin_at_end if stuck_on else math.nan
        if (history.shape[0] == 0 and t > samples.shape[1] * dt and after[0] > 0.0 and after[1] > 0.0
                and system.slip == 0.0 and settled_beyond_reach(x, params, summary["peak_angle"])):
            # the ground is at rest and the block can no longer reach its peak, lift or slide (no history kept)
            book_mode_time(summary, MODE_REST, t_final - t)
            break
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
def simulate_kernel(code, samples, dt, n_tail, params, x0, history, impact_times, summary):
    """Integrate one response.

    Parameters
    ----------
    code : int
        Kernel code (fields.HOUSNER, SSI or WINKLER).
    samples : ndarray (1 or 2, n)
        Ground acceleration [m/s^2] at t = i dt: row HORIZONTAL, and row VERTICAL (up positive) if the
        ground also moves vertically.
    dt : float
        Sampling step [s].
    n_tail : int
        Samples of free vibration after the record (zero ground acceleration).
    params : PARAMS_DTYPE record
    x0 : ndarray (STATE_SIZE,)
        Initial [theta, theta_dot, y, y_dot]; overwritten with the final state.
    history : ndarray (n + n_tail, STATE_SIZE) or (0, STATE_SIZE)
        Filled with the state at the sample times (NaN after overturning).
    impact_times : ndarray (capacity,)
        Filled with the first ``capacity`` impact times [s].
    summary : SUMMARY_DTYPE record, filled.
    """
    work = workspace()
    if code == WINKLER:
        bed_loop(code, samples, dt, n_tail, params, x0, history, impact_times, summary, work)
    elif code == HOUSNER or code == SSI:
        pivot_loop(code, samples, dt, n_tail, params, x0, history, impact_times, summary, work)
    else:
        raise ValueError(UNKNOWN_CODE)


@njit(cache=True)
def run_kernel(code, samples, dt, n_tail, scales, params_table, initial_states, histories, impact_times, summaries):
    """Run each parameter row at each factor in ``scales``.

    The one compiled entry point: ``simulate``, ``simulate_batch`` and ``simulate_histories`` all call it (an
    entry point is compiled with the whole integrator inside it, about 1.5 s each in a fresh clone).
    Every component (the vertical too) is scaled by the same factor.

    scales (n_scale,); params_table (n_case,) records; initial_states (n_case, STATE_SIZE), left unchanged;
    histories (n_case, n + n_tail, STATE_SIZE) filled with each row's states, or (n_case, 0, STATE_SIZE) to keep
    none (with histories, one factor only: a second would write over the first); impact_times (n_case, capacity)
    filled, or (n_case, 0); summaries (n_case, n_scale) records, filled.
    """
    if histories.shape[1] > 0 and scales.size > 1:
        raise ValueError("run_kernel: histories are kept for one scale factor only")
    scaled = np.empty(samples.shape)
    x = np.empty(STATE_SIZE)
    for j in range(scales.size):
        for component in range(samples.shape[0]):
            for i in range(samples.shape[1]):
                scaled[component, i] = samples[component, i] * scales[j]
        for row in range(params_table.shape[0]):
            for i in range(STATE_SIZE):
                x[i] = initial_states[row, i]
            simulate_kernel(code, scaled, dt, n_tail, params_table[row], x, histories[row], impact_times[row],
                            summaries[row, j])


def run_cases(code, samples, dt, n_tail, params_table, initial_states, scales=None, histories=None,
              impact_times=None) -> np.ndarray:
    """``run_kernel`` from Python: the summaries, (n_case, n_scale) records.

    ``scales`` None runs the ground motion as given (one factor, 1). ``histories`` and ``impact_times`` None keep
    none: the kernel is handed empty arrays of the same types, so that one compiled signature serves every call.
    """
    n_case = params_table.shape[0]
    scales = np.ones(1) if scales is None else scales
    histories = np.empty((n_case, 0, STATE_SIZE)) if histories is None else histories
    impact_times = np.empty((n_case, 0)) if impact_times is None else impact_times
    summaries = new_summaries((n_case, scales.size))
    attach_hooks(params_table)  # a plugin contact law's hooks, compiled in this process (rockfrag.models.contact)
    run_kernel(code, samples, float(dt), n_tail, scales, params_table, initial_states, histories, impact_times,
               summaries)
    return summaries
