"""An independent reference solver built on scipy's solve_ivp (DOP853, tight tolerances, events).

It re-implements the equations of motion from scratch (Housner eq. 1; the SSI equations derived in
pipeline/models/ssi.py) with scipy's own event location, so that the compiled kernel can be checked
against it. Slow: for tests and benchmarks only.

A vertical ground acceleration a_v(t) (up positive, linear between samples like ag) replaces G by
G + a_v(t) wherever gravity acts on the block (the ground's frame); the spring acts on the relative
settlement and does not see it. The rest phase is then a root search (brentq) of
|ag| - tan(alpha) (G + a_v) on every sample interval, and the run ends where G + a_v first falls
below zero (``free_flight_time``): the pivot models have no flight phase.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

G = 9.80665


def free_flight_time(ag_vertical, dt, g=G):
    """First time [s] at which g + a_v(t) < 0 (a_v linear between samples, zero after them); inf if never."""
    if ag_vertical is None:
        return math.inf
    gravity = g + np.append(np.asarray(ag_vertical, dtype=float), 0.0)
    below = np.flatnonzero(gravity < 0.0)
    if not below.size:
        return math.inf
    i = int(below[0])
    if i == 0:
        return 0.0
    return brentq(lambda t: gravity[i - 1] + (gravity[i] - gravity[i - 1]) * (t - (i - 1) * dt) / dt,
                  (i - 1) * dt, i * dt, xtol=1e-15, rtol=4 * np.finfo(float).eps)


def carried_step(piece) -> float | None:
    """The first step [s] for the interval after ``piece`` (a solve_ivp result): the longest step it took, if it
    ran to its end. solve_ivp would otherwise estimate one at every interval (two more right-hand sides and often
    a smaller step; the step controller still rejects a step that is too long). None after a terminal event:
    there the right-hand side or the state jumps, and solve_ivp estimates the step afresh."""
    return float(np.max(np.diff(piece.t))) if piece.status == 0 and piece.t.size > 1 else None


def bounded_first_step(carried: float | None, room: float) -> float | None:
    """solve_ivp's ``first_step`` for an interval of length ``room`` [s]: the carried step (``carried_step``) if it
    fits, else ``room``; None (solve_ivp estimates one) when nothing was carried."""
    return None if carried is None else min(carried, room)


def solve_by_interval(fun, t_start, t_stop, state, dt, events, args=(), first_step=None, **tolerances):
    """solve_ivp(DOP853) from ``t_start`` to ``t_stop``, one sample interval of the ground motion at a time.

    The ground motion is linear inside each interval [i dt, (i + 1) dt] and has a kink at each sample, so
    the integrator restarts there instead of stepping across the kinks (where most of its steps were
    rejected). Stops at the first terminal event like solve_ivp; returns an object with solve_ivp's ``t``,
    ``y`` (every interval's points, concatenated), ``t_events`` and ``y_events``. ``first_step`` [s] bounds the
    first step: an excursion starts on its event surface (theta = 0), so a first step that crossed the whole
    excursion would find its end at the start.
    """
    events = tuple(events)
    ts, ys = [np.array([t_start])], [np.asarray(state, dtype=float).reshape(-1, 1)]
    t_events = [[] for _ in events]
    y_events = [[] for _ in events]
    t, y = t_start, np.asarray(state, dtype=float)
    step = first_step
    while t < t_stop:
        knot = (math.floor(t / dt + 1e-9) + 1) * dt
        t_next = min(knot, t_stop)
        if t_next - t <= 1e-12 * max(1.0, t):
            t = t_next
            continue
        piece = solve_ivp(fun, (t, t_next), y, method="DOP853", events=events, args=args,
                          first_step=bounded_first_step(step, t_next - t),
                          **tolerances)
        step = carried_step(piece)
        ts.append(piece.t[1:])
        ys.append(piece.y[:, 1:])
        for k in range(len(events)):
            t_events[k].extend(piece.t_events[k])
            y_events[k].extend(piece.y_events[k])
        t, y = float(piece.t[-1]), piece.y[:, -1]
        if piece.status == 1:  # a terminal event
            break
    return SimpleNamespace(t=np.concatenate(ts), y=np.concatenate(ys, axis=1),
                           t_events=[np.array(v) for v in t_events],
                           y_events=[np.array(v).reshape(-1, y.size) for v in y_events])


def reference_response(model, ag, dt, block, k=None, xi=0.05, restitution=None, switch="consistent",
                       t_end=None, rtol=1e-10, atol=1e-12, ag_vertical=None):
    """Peak |theta| [rad], impact times [s] and whether the block overturned, up to t_end or to the free
    flight (``free_flight_time``) when ``ag_vertical`` [m/s^2, up positive, sampled as ag] takes gravity
    below zero."""
    radius, alpha, m = block.R, block.alpha, block.mass
    p2 = 0.75 * G / radius
    omega = math.sqrt(k / m) if k else 0.0
    if restitution is None:
        restitution = block.housner_restitution() if model == "housner" else 1.0
    times = np.arange(ag.size) * dt
    t_end = times[-1] + 5.0 if t_end is None else t_end
    t_end = min(t_end, free_flight_time(ag_vertical, dt))
    vertical_samples = np.zeros(ag.size) if ag_vertical is None else np.asarray(ag_vertical, dtype=float)
    vertical_end = (np.flatnonzero(vertical_samples)[-1] + 1) * dt if np.any(vertical_samples) else -1.0

    # the ground motion is piecewise linear through the samples and returns to zero one step after the last;
    # the padded arrays are built once (building them in every call made the reference O(samples) per call)
    knots = np.append(times, times[-1] + dt)
    ground_knots, vertical_knots = np.append(ag, 0.0), np.append(vertical_samples, 0.0)

    def ground(t):
        return float(np.interp(t, knots, ground_knots, right=0.0))

    def gravity(t):
        """G + a_v(t) [m/s^2]."""
        return G + float(np.interp(t, knots, vertical_knots, right=0.0))

    def rocking(t, x, sigma):
        a = ground(t)
        g = gravity(t)
        angle = sigma * alpha - x[0]
        if model == "housner":
            return [x[1], -0.75 / radius * (g * math.sin(angle) + a * math.cos(angle)), 0.0, 0.0]
        free = g - omega**2 * x[2] - 2 * xi * omega * x[3] - radius * math.cos(angle) * x[1] ** 2
        moment = -g * math.sin(angle) - a * math.cos(angle)
        y_acc = (free + 0.75 * math.sin(angle) * moment) / (1 - 0.75 * math.sin(angle) ** 2)
        return [x[1], 0.75 / radius * (math.sin(angle) * y_acc + moment), x[3], y_acc]

    def support(t, x):
        return gravity(t) if model == "housner" else omega**2 * x[2] + 2 * xi * omega * x[3]

    state = np.array([0.0, 0.0, G / omega**2 if omega else 0.0, 0.0])
    t = 0.0
    peak, impacts, overturned = 0.0, [], False
    zeno_speed = math.sqrt(2 * p2 * math.sin(alpha) * 1e-6 * alpha)
    y_static = G / omega**2 if omega else 0.0

    def vertical(time, x):
        return [0.0, 0.0, x[3], gravity(time) - omega**2 * x[2] - 2 * xi * omega * x[3]]

    def uplift(time, x):
        return abs(ground(time)) - math.tan(alpha) * support(time, x)
    uplift.terminal = True
    uplift.direction = 1

    while t < t_end - 1e-12:
        start = None
        if model != "housner" and (abs(state[2] - y_static) > 1e-9 * y_static or abs(state[3]) > 1e-9 * y_static * omega
                                   or t < vertical_end):
            # rest with a vertical vibration left over, or forced by the ground: integrate it until the uplift
            # condition holds
            if uplift(t, state) > 0:
                start = (t, -math.copysign(1.0, ground(t)))
            else:
                solution = solve_by_interval(vertical, t, t_end, state, dt, (uplift,), rtol=rtol, atol=atol * y_static)
                state = solution.y[:, -1].copy()
                t = solution.t[-1]
                if not solution.t_events[0].size:
                    break
                start = (t, -math.copysign(1.0, ground(t)))
        else:
            # rest at static equilibrium: the support force is m (G + a_v); scan the sample intervals of the
            # piecewise-linear ground motion for the first t where |ag| > tan(alpha) (G + a_v)
            def excess(time):
                return abs(ground(time)) - math.tan(alpha) * gravity(time)
            k0 = int(math.floor(t / dt + 1e-9))
            for i in range(k0, int(math.ceil(t_end / dt - 1e-9))):
                t0, t1 = max(t, i * dt), min((i + 1) * dt, t_end)
                if excess(t1) > 0:
                    s = t0 if excess(t0) > 0 else brentq(excess, t0, t1, xtol=1e-15, rtol=4 * np.finfo(float).eps)
                    start = (max(s, t), -math.copysign(1.0, ground(s if excess(t0) > 0 else t1)))
                    break
        if start is None:
            break
        t, sigma = start
        state[0] = state[1] = 0.0
        while True:
            def impact(time, x, s):
                return x[0]
            impact.terminal = True
            impact.direction = -sigma

            def overturn(time, x, s):
                return abs(x[0]) - math.pi / 2
            overturn.terminal = True

            def extremum(time, x, s):
                return x[1]

            solution = solve_by_interval(rocking, t, t_end, state, dt, (impact, overturn, extremum), args=(sigma,),
                                         first_step=1e-6 * dt, rtol=rtol, atol=atol)
            for x_ext in solution.y_events[2]:
                peak = max(peak, abs(x_ext[0]))
            peak = max(peak, float(np.max(np.abs(solution.y[0]))))
            started_at = t
            state = solution.y[:, -1].copy()
            t = solution.t[-1]
            if solution.t_events[0].size and t - started_at < 1e-12:
                # an excursion of zero length (a start that does not lift): back to rest
                state[0] = state[1] = 0.0
                t = min(t + 1e-9, t_end)
                break
            if solution.t_events[1].size:
                return math.pi / 2, np.array(impacts), True
            if not solution.t_events[0].size:
                return peak, np.array(impacts), overturned
            impacts.append(t)
            state[0] = 0.0
            if model != "housner" and switch == "consistent":
                state[3] += 2 * radius * math.sin(alpha) * abs(state[1])
            state[1] *= restitution
            sigma = -sigma
            if abs(state[1]) < zeno_speed:
                state[1] = 0.0
                break
    return peak, np.array(impacts), overturned
