"""pipeline.models.kernels - the compiled hot loop shared by every rocking model.

Input : plain float64 arrays and scalars only (ground acceleration samples [m/s^2], dt [s],
        a parameter vector, initial state); no Python objects cross this line.
Output: a summary vector (status, peak angle, impacts, ...) and, when asked, the rotation and
        settlement histories at the record's sample times.

One adaptive Dormand-Prince 5(4) integrator (Hairer, Norsett & Wanner, table 5.2) steps the state
x = [theta, theta_dot, y, y_dot]. Steps never cross a sample of the ground motion (which is linear
between samples), so every step sees a smooth right-hand side. Events (impact theta = 0, uplift,
overturning) are located on a cubic Hermite interpolant and the step is then redone exactly to the
event time, after which integration restarts cleanly. Set PIPELINE_NO_NUMBA=1 to run as plain
Python (debugging, coverage).
"""

from __future__ import annotations

import math
import os

import numpy as np

if os.environ.get("PIPELINE_NO_NUMBA", "") not in ("", "0"):
    def njit(*args, **kwargs):
        if args and callable(args[0]):
            return args[0]
        return lambda function: function
else:
    from numba import njit

# model codes
HOUSNER = 0
SSI = 1

# switch rules at theta = 0 for SSI
SWITCH_CONSISTENT = 0
SWITCH_CONTINUOUS = 1

# phases
REST = 0
ROCKING = 1

# status codes (also RockingResult.status)
STATUS_NO_UPLIFT = 0
STATUS_ROCKING = 1
STATUS_OVERTURNED = 2
STATUS_FAILED = 3

# parameter vector layout
P_R, P_ALPHA, P_G, P_KAPPA, P_OMEGA, P_XI, P_RESTITUTION, P_SWITCH, P_OVERTURN, P_RTOL, \
    P_ATOL, P_ZENO, P_MAX_EVENTS = range(13)
N_PARAMS = 13

# summary vector layout
S_STATUS, S_PEAK, S_TIME_OF_PEAK, S_N_IMPACTS, S_UPLIFTED, S_PEAK_Y, S_MIN_SUPPORT, S_T_END, \
    S_N_STEPS, S_TIME_OF_UPLIFT, S_TIME_OF_OVERTURN = range(11)
N_SUMMARY = 11

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


@njit(cache=True)
def _ground_in_segment(a_start, a_slope, t_start, t):
    """Ground acceleration [m/s^2] at t inside a sample interval (linear between samples)."""
    return a_start + a_slope * (t - t_start)


@njit(cache=True)
def rhs(model, phase, sigma, x, accel, params, out):
    """dx/dt for state x = [theta, theta_dot, y, y_dot] given ground acceleration ``accel``."""
    radius = params[P_R]
    g = params[P_G]
    if phase == REST:
        out[0] = 0.0
        out[1] = 0.0
        if model == SSI:
            omega = params[P_OMEGA]
            out[2] = x[3]
            out[3] = g - omega * omega * x[2] - 2.0 * params[P_XI] * omega * x[3]
        else:
            out[2] = 0.0
            out[3] = 0.0
        return
    angle = sigma * params[P_ALPHA] - x[0]  # A = sigma*alpha - theta
    sin_a = math.sin(angle)
    cos_a = math.cos(angle)
    kappa = params[P_KAPPA]
    out[0] = x[1]
    if model == HOUSNER:
        # theta'' = -p^2 [sin A + (ag/g) cos A], p^2 = kappa g / R with kappa = 3/4
        out[1] = -kappa * (g * sin_a + accel * cos_a) / radius
        out[2] = 0.0
        out[3] = 0.0
    else:
        omega = params[P_OMEGA]
        # From the Lagrangian (see models/ssi.py):
        #   theta'' = (kappa/R) (sin A * y'' - g sin A - ag cos A)
        #   y''     = g - w^2 y - 2 xi w y' - R cos A theta'^2 + R sin A theta''
        free = g - omega * omega * x[2] - 2.0 * params[P_XI] * omega * x[3] - radius * cos_a * x[1] * x[1]
        moment = -g * sin_a - accel * cos_a
        y_acc = (free + kappa * sin_a * moment) / (1.0 - kappa * sin_a * sin_a)
        out[1] = kappa / radius * (sin_a * y_acc + moment)
        out[2] = x[3]
        out[3] = y_acc


@njit(cache=True)
def _dopri_step(model, phase, sigma, t, x, f0, h, a_start, a_slope, t_seg, params,
                k2, k3, k4, k5, k6, k7, tmp, x_new, err):
    """One Dormand-Prince step from (t, x) with f0 = f(t, x); fills x_new, k7 = f(t+h, x_new), err."""
    n = 4
    for i in range(n):
        tmp[i] = x[i] + h * A21 * f0[i]
    rhs(model, phase, sigma, tmp, _ground_in_segment(a_start, a_slope, t_seg, t + C2 * h), params, k2)
    for i in range(n):
        tmp[i] = x[i] + h * (A31 * f0[i] + A32 * k2[i])
    rhs(model, phase, sigma, tmp, _ground_in_segment(a_start, a_slope, t_seg, t + C3 * h), params, k3)
    for i in range(n):
        tmp[i] = x[i] + h * (A41 * f0[i] + A42 * k2[i] + A43 * k3[i])
    rhs(model, phase, sigma, tmp, _ground_in_segment(a_start, a_slope, t_seg, t + C4 * h), params, k4)
    for i in range(n):
        tmp[i] = x[i] + h * (A51 * f0[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
    rhs(model, phase, sigma, tmp, _ground_in_segment(a_start, a_slope, t_seg, t + C5 * h), params, k5)
    for i in range(n):
        tmp[i] = x[i] + h * (A61 * f0[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i])
    rhs(model, phase, sigma, tmp, _ground_in_segment(a_start, a_slope, t_seg, t + h), params, k6)
    for i in range(n):
        x_new[i] = x[i] + h * (B1 * f0[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i])
    rhs(model, phase, sigma, x_new, _ground_in_segment(a_start, a_slope, t_seg, t + h), params, k7)
    for i in range(n):
        err[i] = h * (E1 * f0[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])


@njit(cache=True)
def _hermite(x0, f0, x1, f1, h, s, i):
    """Cubic Hermite interpolant of component i at fraction s of a step of length h."""
    h00 = 2 * s**3 - 3 * s**2 + 1
    h10 = s**3 - 2 * s**2 + s
    h01 = -2 * s**3 + 3 * s**2
    h11 = s**3 - s**2
    return h00 * x0[i] + h10 * h * f0[i] + h01 * x1[i] + h11 * h * f1[i]


@njit(cache=True)
def _hermite_derivative(x0, f0, x1, f1, h, s, i):
    d00 = (6 * s**2 - 6 * s) / h
    d10 = 3 * s**2 - 4 * s + 1
    d01 = (-6 * s**2 + 6 * s) / h
    d11 = 3 * s**2 - 2 * s
    return d00 * x0[i] + d10 * f0[i] + d01 * x1[i] + d11 * f1[i]


@njit(cache=True)
def _support(model, params, x):
    """Vertical support force per unit mass [m/s^2] (SSI); g for Housner."""
    if model == SSI:
        omega = params[P_OMEGA]
        return omega * omega * x[2] + 2.0 * params[P_XI] * omega * x[3]
    return params[P_G]


@njit(cache=True)
def _event_value(kind, model, sigma, params, x0, f0, x1, f1, h, s, a_start, a_slope, t_seg, t0):
    """Event functions on the interpolant: 0 impact (sigma*theta), 1 overturn, 2 uplift."""
    if kind == 0:
        return sigma * _hermite(x0, f0, x1, f1, h, s, 0)
    if kind == 1:
        return abs(_hermite(x0, f0, x1, f1, h, s, 0)) - params[P_OVERTURN]
    # uplift: |ag| - tan(alpha) * support force per mass
    state = np.empty(4)
    for i in range(4):
        state[i] = _hermite(x0, f0, x1, f1, h, s, i)
    accel = _ground_in_segment(a_start, a_slope, t_seg, t0 + s * h)
    return abs(accel) - math.tan(params[P_ALPHA]) * _support(model, params, state)


@njit(cache=True)
def _locate(kind, model, sigma, params, x0, f0, x1, f1, h, a_start, a_slope, t_seg, t0):
    """Fraction s in (0, 1] of the step where the event function changes sign (Illinois method)."""
    s_low, s_high = 0.0, 1.0
    v_low = _event_value(kind, model, sigma, params, x0, f0, x1, f1, h, s_low, a_start, a_slope, t_seg, t0)
    v_high = _event_value(kind, model, sigma, params, x0, f0, x1, f1, h, s_high, a_start, a_slope, t_seg, t0)
    side = 0
    for _ in range(100):
        if v_high == v_low:
            break
        s_mid = (s_low * v_high - s_high * v_low) / (v_high - v_low)
        if not (s_low < s_mid < s_high):
            s_mid = 0.5 * (s_low + s_high)
        v_mid = _event_value(kind, model, sigma, params, x0, f0, x1, f1, h, s_mid, a_start, a_slope, t_seg, t0)
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
        if (s_high - s_low) * h < 1e-13:
            break
    return s_high


@njit(cache=True)
def simulate_kernel(model, ag, dt, n_tail, params, theta0, thetadot0, y0, ydot0,
                    history, impact_times, summary):
    """Integrate one rocking response.

    Parameters
    ----------
    model : int
        HOUSNER or SSI (SSI variants differ by params[P_KAPPA]).
    ag : ndarray, shape (n,)
        Ground acceleration [m/s^2] at t = k dt.
    n_tail : int
        Samples of free vibration after the record (zero ground acceleration).
    params : ndarray, shape (N_PARAMS,)
    history : ndarray, shape (n + n_tail, 4) or (0, 4)
        Filled with [theta, theta_dot, y, y_dot] at the sample times (NaN after overturning).
    impact_times : ndarray, shape (capacity,)
        Filled with the first ``capacity`` impact times [s].
    summary : ndarray, shape (N_SUMMARY,)
        Filled with the results (see S_* indices).
    """
    n_samples = ag.size + n_tail
    record_history = history.shape[0] > 0
    alpha = params[P_ALPHA]
    radius = params[P_R]
    g = params[P_G]
    p2 = 0.75 * g / radius
    zeno_speed = math.sqrt(2.0 * p2 * math.sin(alpha) * params[P_ZENO])
    rtol = params[P_RTOL]
    atol = params[P_ATOL]
    omega = params[P_OMEGA]
    y_static = g / (omega * omega) if model == SSI else 0.0
    scale = np.empty(4)
    scale[0] = alpha
    scale[1] = alpha * math.sqrt(p2)
    scale[2] = max(y_static, 1e-9)
    scale[3] = max(y_static * omega, 1e-9)

    x = np.empty(4)
    x[0] = theta0
    x[1] = thetadot0
    x[2] = y0
    x[3] = ydot0
    f0 = np.empty(4)
    k2 = np.empty(4)
    k3 = np.empty(4)
    k4 = np.empty(4)
    k5 = np.empty(4)
    k6 = np.empty(4)
    k7 = np.empty(4)
    tmp = np.empty(4)
    x_new = np.empty(4)
    err = np.empty(4)

    phase = REST
    sigma = 0.0
    if theta0 != 0.0 or thetadot0 != 0.0:
        phase = ROCKING
        sigma = 1.0 if (theta0 > 0.0 or (theta0 == 0.0 and thetadot0 > 0.0)) else -1.0

    status = STATUS_NO_UPLIFT if phase == REST else STATUS_ROCKING
    peak = abs(theta0)
    time_of_peak = 0.0
    n_impacts = 0
    uplifted = phase == ROCKING
    time_of_uplift = 0.0 if uplifted else -1.0
    time_of_overturn = -1.0
    peak_y = y0
    min_support = _support(model, params, x)
    n_steps = 0
    n_events = 0
    max_events = params[P_MAX_EVENTS]

    if record_history:
        for i in range(4):
            history[0, i] = x[i]

    t = 0.0
    h = dt * 0.25
    segment = 0
    failed = False
    start_now = False
    while segment < n_samples - 1 and not failed:
        t_seg = segment * dt
        t_seg_end = (segment + 1) * dt
        # linear between samples; after the last sample it ramps to zero within one step
        a_start = ag[segment] if segment < ag.size else 0.0
        a_next = ag[segment + 1] if segment + 1 < ag.size else 0.0
        a_slope = (a_next - a_start) / dt
        while t < t_seg_end - 1e-12 * dt:
            if phase == REST:
                # start rocking at once if the uplift condition holds (or an uplift was just located)
                accel = _ground_in_segment(a_start, a_slope, t_seg, t)
                if start_now or abs(accel) > math.tan(alpha) * _support(model, params, x):
                    start_now = False
                    phase = ROCKING
                    sigma = -1.0 if accel > 0 else 1.0
                    x[0] = 0.0
                    x[1] = 0.0
                    if not uplifted:
                        uplifted = True
                        time_of_uplift = t
                    if status == STATUS_NO_UPLIFT:
                        status = STATUS_ROCKING
                    n_events += 1
                    if n_events > max_events:
                        failed = True
                        break
                    continue
                at_rest = model == HOUSNER or (abs(x[2] - y_static) <= 1e-12 * scale[2] + 1e-15
                                               and abs(x[3]) <= 1e-12 * scale[3])
                if at_rest:
                    # Closed form: the state is constant; find where |ag| first beats the threshold.
                    threshold = math.tan(alpha) * _support(model, params, x)
                    a_end = _ground_in_segment(a_start, a_slope, t_seg, t_seg_end)
                    if abs(a_end) > threshold:
                        target = threshold if a_end > 0 else -threshold
                        t_cross = t_seg_end
                        if a_slope != 0.0:
                            t_cross = t_seg + (target - a_start) / a_slope
                        t = min(max(t_cross, t), t_seg_end)
                        if t >= t_seg_end - 1e-12 * dt:
                            t = t_seg_end  # starts at the top of the next segment
                            break
                        start_now = True
                        continue
                    t = t_seg_end
                    break
            # one adaptive step, never past the end of the sample interval
            h = min(h, t_seg_end - t)
            rhs(model, phase, sigma, x, _ground_in_segment(a_start, a_slope, t_seg, t), params, f0)
            while True:
                _dopri_step(model, phase, sigma, t, x, f0, h, a_start, a_slope, t_seg, params,
                            k2, k3, k4, k5, k6, k7, tmp, x_new, err)
                error_norm = 0.0
                for i in range(4):
                    tolerance = atol * scale[i] + rtol * max(abs(x[i]), abs(x_new[i]))
                    error_norm += (err[i] / tolerance) ** 2
                error_norm = math.sqrt(error_norm / 4.0)
                if h < 1e-14:
                    break
                if (error_norm <= 1.0 and phase == ROCKING and x[0] == 0.0 and sigma * x[1] > 0.0
                        and sigma * x_new[0] <= 0.0):
                    # a whole excursion after an impact fits inside this step: shorten the step so
                    # that the next impact is seen (this is how Zeno cascades are followed)
                    h = h * 0.25
                    continue
                if error_norm <= 1.0:
                    break
                h = h * max(0.2, 0.9 * error_norm ** -0.2)
            n_steps += 1
            if n_steps > 50_000_000:
                failed = True
                break
            # events inside the accepted step (earliest wins)
            event_kind = -1
            event_s = 2.0
            if phase == ROCKING:
                if sigma * x[0] > 0.0 and sigma * x_new[0] <= 0.0:
                    s_hit = _locate(0, model, sigma, params, x, f0, x_new, k7, h, a_start, a_slope, t_seg, t)
                    event_kind, event_s = 0, s_hit
                if abs(x_new[0]) >= params[P_OVERTURN]:
                    s_hit = _locate(1, model, sigma, params, x, f0, x_new, k7, h, a_start, a_slope, t_seg, t)
                    if s_hit < event_s:
                        event_kind, event_s = 1, s_hit
                if event_kind == -1 and sigma * x[0] == 0.0 and sigma * x_new[0] < 0.0:
                    event_kind, event_s = 3, 1.0  # a start that does not lift: back to rest
            else:
                v_start = _event_value(2, model, sigma, params, x, f0, x_new, k7, h, 0.0, a_start, a_slope, t_seg, t)
                v_end = _event_value(2, model, sigma, params, x, f0, x_new, k7, h, 1.0, a_start, a_slope, t_seg, t)
                if v_start <= 0.0 and v_end > 0.0:
                    event_kind = 2
                    event_s = _locate(2, model, sigma, params, x, f0, x_new, k7, h, a_start, a_slope, t_seg, t)
            if event_kind >= 0 and event_kind != 3 and event_s < 1.0:
                # redo the step exactly to the event time
                h_event = event_s * h
                _dopri_step(model, phase, sigma, t, x, f0, h_event, a_start, a_slope, t_seg, params,
                            k2, k3, k4, k5, k6, k7, tmp, x_new, err)
                h_taken = h_event
            else:
                h_taken = h
            # peak angle inside the step: theta' changes sign -> extremum of the interpolant
            if phase == ROCKING:
                if x[1] * k7[0] < 0.0 or x[1] * x_new[1] < 0.0:
                    s_low, s_high = 0.0, 1.0
                    d_low = _hermite_derivative(x, f0, x_new, k7, h_taken, s_low, 0)
                    for _ in range(60):
                        s_mid = 0.5 * (s_low + s_high)
                        d_mid = _hermite_derivative(x, f0, x_new, k7, h_taken, s_mid, 0)
                        if (d_mid > 0) == (d_low > 0):
                            s_low, d_low = s_mid, d_mid
                        else:
                            s_high = s_mid
                    theta_mid = abs(_hermite(x, f0, x_new, k7, h_taken, 0.5 * (s_low + s_high), 0))
                    if theta_mid > peak and theta_mid <= params[P_OVERTURN]:
                        peak = theta_mid
                        time_of_peak = t + 0.5 * (s_low + s_high) * h_taken
                if abs(x_new[0]) > peak:
                    peak = min(abs(x_new[0]), params[P_OVERTURN])
                    time_of_peak = t + h_taken
            t = t + h_taken
            for i in range(4):
                x[i] = x_new[i]
            if model == SSI and phase == REST and abs(x[2] - y_static) < 1e-7 * y_static \
                    and abs(x[3]) < 1e-7 * y_static * omega:
                # the free vertical vibration has died out: snap to the static equilibrium so that
                # the closed-form rest phase takes over (the support force changes by < 1e-7 g)
                x[2] = y_static
                x[3] = 0.0
            if model == SSI:
                support = _support(model, params, x)
                if support < min_support:
                    min_support = support
                if x[2] > peak_y:
                    peak_y = x[2]
            # step-size proposal for the next step
            if error_norm > 0.0:
                h = h * min(5.0, max(0.2, 0.9 * error_norm ** -0.2))
            else:
                h = h * 5.0
            if event_kind == 1:
                status = STATUS_OVERTURNED
                time_of_overturn = t
                peak = params[P_OVERTURN]
                time_of_peak = t
                break
            if event_kind == 3:
                phase = REST
                x[0] = 0.0
                x[1] = 0.0
                sigma = 0.0
            elif event_kind == 0:
                n_impacts += 1
                if n_impacts <= impact_times.size:
                    impact_times[n_impacts - 1] = t
                x[0] = 0.0
                if model == HOUSNER:
                    x[1] = x[1] * params[P_RESTITUTION]
                else:
                    if params[P_SWITCH] == SWITCH_CONSISTENT:
                        # theta_dot and the centre-of-mass velocity stay continuous:
                        # y_dot jumps by 2 R sin(alpha) |theta_dot|
                        x[3] = x[3] + 2.0 * radius * math.sin(alpha) * abs(x[1])
                    x[1] = x[1] * params[P_RESTITUTION]
                sigma = -sigma
                if abs(x[1]) < zeno_speed:
                    # the next excursion would be below the Zeno angle: the block comes to rest
                    phase = REST
                    x[1] = 0.0
                    sigma = 0.0
                n_events += 1
            elif event_kind == 2:
                start_now = True  # uplift located: the top of the loop starts rocking here
            if n_events > max_events:
                failed = True
                break
        if status == STATUS_OVERTURNED or failed:
            break
        t = t_seg_end
        segment += 1
        if record_history:
            for i in range(4):
                history[segment, i] = x[i]

    if record_history and (status == STATUS_OVERTURNED or failed):
        for k in range(segment + 1, n_samples):
            for i in range(4):
                history[k, i] = np.nan
    if failed:
        status = STATUS_FAILED
    summary[S_STATUS] = status
    summary[S_PEAK] = peak
    summary[S_TIME_OF_PEAK] = time_of_peak
    summary[S_N_IMPACTS] = n_impacts
    summary[S_UPLIFTED] = 1.0 if uplifted else 0.0
    summary[S_PEAK_Y] = peak_y
    summary[S_MIN_SUPPORT] = min_support
    summary[S_T_END] = t
    summary[S_N_STEPS] = n_steps
    summary[S_TIME_OF_UPLIFT] = time_of_uplift
    summary[S_TIME_OF_OVERTURN] = time_of_overturn


@njit(cache=True)
def batch_kernel(model, ag, dt, n_tail, scales, params_table, y0s, summaries):
    """Run one record scaled by each factor in ``scales`` for each parameter row.

    ag : (n,) [m/s^2]; scales : (n_scale,); params_table : (n_param, N_PARAMS); y0s : (n_param,)
    initial settlements [m]; summaries : (n_param, n_scale, N_SUMMARY), filled.
    """
    empty = np.empty((0, 4))
    impacts = np.empty(0)
    scaled = np.empty(ag.size)
    for j in range(scales.size):
        for i in range(ag.size):
            scaled[i] = ag[i] * scales[j]
        for row in range(params_table.shape[0]):
            simulate_kernel(model, scaled, dt, n_tail, params_table[row], 0.0, 0.0, y0s[row], 0.0,
                            empty, impacts, summaries[row, j])


@njit(cache=True)
def history_batch_kernel(model, ag, dt, n_tail, params_table, y0s, histories, summaries):
    """Run one ground motion for each parameter row, keeping the histories.

    params_table : (n_case, N_PARAMS); y0s : (n_case,); histories : (n_case, n + n_tail, 4) and
    summaries : (n_case, N_SUMMARY), filled.
    """
    impacts = np.empty(0)
    for row in range(params_table.shape[0]):
        simulate_kernel(model, ag, dt, n_tail, params_table[row], 0.0, 0.0, y0s[row], 0.0,
                        histories[row], impacts, summaries[row])
