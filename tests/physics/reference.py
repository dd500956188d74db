"""An independent reference solver built on scipy's solve_ivp (DOP853, tight tolerances, events).

It re-implements the equations of motion from scratch (Housner eq. 1; the SSI equations derived in
pipeline/models/ssi.py) with scipy's own event location, so that the compiled kernel can be checked
against it. Slow: for tests and benchmarks only.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

G = 9.80665


def reference_response(model, ag, dt, block, k=None, xi=0.05, restitution=None, switch="consistent",
                       t_end=None, rtol=1e-10, atol=1e-12):
    """Peak |theta| [rad], impact times [s] and whether the block overturned."""
    radius, alpha, m = block.R, block.alpha, block.mass
    p2 = 0.75 * G / radius
    omega = math.sqrt(k / m) if k else 0.0
    if restitution is None:
        restitution = block.housner_restitution() if model == "housner" else 1.0
    times = np.arange(ag.size) * dt
    t_end = times[-1] + 5.0 if t_end is None else t_end

    def ground(t):
        return float(np.interp(t, np.append(times, times[-1] + dt), np.append(ag, 0.0), right=0.0))

    def rocking(t, x, sigma):
        a = ground(t)
        angle = sigma * alpha - x[0]
        if model == "housner":
            return [x[1], -p2 * (math.sin(angle) + a / G * math.cos(angle)), 0.0, 0.0]
        free = G - omega**2 * x[2] - 2 * xi * omega * x[3] - radius * math.cos(angle) * x[1] ** 2
        moment = -G * math.sin(angle) - a * math.cos(angle)
        y_acc = (free + 0.75 * math.sin(angle) * moment) / (1 - 0.75 * math.sin(angle) ** 2)
        return [x[1], 0.75 / radius * (math.sin(angle) * y_acc + moment), x[3], y_acc]

    def support(x):
        return G if model == "housner" else omega**2 * x[2] + 2 * xi * omega * x[3]

    state = np.array([0.0, 0.0, G / omega**2 if omega else 0.0, 0.0])
    t = 0.0
    peak, impacts, overturned = 0.0, [], False
    zeno_speed = math.sqrt(2 * p2 * math.sin(alpha) * 1e-6 * alpha)
    y_static = G / omega**2 if omega else 0.0

    def vertical(time, x):
        return [0.0, 0.0, x[3], G - omega**2 * x[2] - 2 * xi * omega * x[3]]

    def uplift(time, x):
        return abs(ground(time)) - math.tan(alpha) * support(x)
    uplift.terminal = True
    uplift.direction = 1

    while t < t_end - 1e-12:
        start = None
        if model != "housner" and (abs(state[2] - y_static) > 1e-9 * y_static or abs(state[3]) > 1e-9 * y_static * omega):
            # rest with a vertical vibration left over: integrate it until the uplift condition holds
            if uplift(t, state) > 0:
                start = (t, -math.copysign(1.0, ground(t)))
            else:
                solution = solve_ivp(vertical, (t, t_end), state, method="DOP853", rtol=rtol, atol=atol * y_static,
                                     max_step=dt, events=uplift)
                state = solution.y[:, -1].copy()
                t = solution.t[-1]
                if not solution.t_events[0].size:
                    break
                start = (t, -math.copysign(1.0, ground(t)))
        else:
            # rest at static equilibrium: the support force is m g; scan the piecewise-linear ground motion
            threshold = math.tan(alpha) * G
            k0 = int(math.floor(t / dt + 1e-9))
            for i in range(k0, int(t_end / dt)):
                a0, a1 = ground(max(t, i * dt)), ground((i + 1) * dt)
                if abs(a1) > threshold:
                    target = math.copysign(threshold, a1)
                    s = max(t, i * dt) if abs(a0) > threshold else i * dt + (target - ground(i * dt)) / (
                        (ground((i + 1) * dt) - ground(i * dt)) / dt)
                    start = (max(s, t), -math.copysign(1.0, a1))
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

            solution = solve_ivp(rocking, (t, t_end), state, method="DOP853", rtol=rtol, atol=atol,
                                 max_step=dt, events=(impact, overturn, extremum), args=(sigma,))
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
