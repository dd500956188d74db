"""An independent scipy reference for the `winkler` model WITH Coulomb friction at the base (a rigid block on a
tensionless viscoelastic Winkler bed that may slide), written from the README's spec ("Sliding: Coulomb
friction at the base", the bed bullet, and the tied Winkler bed above it), not from the compiled kernel.

Input : ground acceleration ag [m/s^2] sampled at dt [s] (linear between samples, zero after the record),
        block half-width b and half-height h [m], mass [kg], total bed stiffness K [N/m], damping ratio xi [-]
        of the vertical mode, static and kinetic friction coefficients mu_s >= mu_k > 0 [-], bed
        "two-spring" or "continuous", end time [s].
Output: ``reference_winkler_sliding`` returns a dict: t [s], theta [rad], y [m] (settlement of the base
        centre, positive down), u [m] (slip of the base centre relative to the ground) and u_dot [m/s] on the
        sample grid; peak_angle [rad], peak_slip and residual_slip [m] (largest and final |u|), n_impacts (a
        lifted corner landing), n_flights, overturned, and the time [s] in each mode: time_at_rest (stuck,
        both corners in the ground), time_rocking (stuck, one corner out), time_sliding (sliding, both in),
        time_slide_rocking (sliding, one out), time_in_flight (both corners out).

The spec, as used here (per unit mass; theta > 0 turns the top towards +x and presses the +b corner in):

* Degrees of freedom theta, the settlement y of the base centre and its horizontal slip u relative to the
  ground. The centre of mass is at (u + h sin(theta), -y + h cos(theta)) in the ground's frame, which
  accelerates by ag, so the block feels -ag horizontally and g downwards; j_c = (b^2 + h^2) / 3.
* The bed gives a vertical force F and a moment M about the base centre (``winkler_reference.bed_force``,
  written independently of the kernel); friction H (towards +x on the block) acts at the base centre's level.
  Newton-Euler: j_c theta'' = h sin(theta) F - cos(theta) M - h cos(theta) H (torque about the centre of mass),
  y'' = g - F - h sin(theta) theta'' - h cos(theta) theta'^2, u'' = H - ag - h cos(theta) theta'' +
  h sin(theta) theta'^2.
* Stuck (u' = 0, u'' = 0): the three equations give theta'', y'' and the friction needed, H; it stays stuck
  while |H| <= mu_s F. Where mu_s F - |H| crosses zero (an event) it slides in d = -sign(H).
* Sliding in d = sign(u'): H = -mu_k F d, explicit. Where u' reaches zero (an event) it sticks if the stuck
  solution has |H| <= mu_s F, else it slides back, d = -sign(H).
* In flight F = 0 and so H = 0: the block moves freely (the sliding equations with F = 0 do exactly that).

How: scipy solve_ivp (DOP853, rtol 1e-10) one sample interval at a time, with terminal events at every
corner entering or leaving the ground and every corner pressure reaching zero (the kinks of F and M, as in
``winkler_reference``) and at every stick-slip change, so each is a step boundary. Slow: tests only.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from .reference import bounded_first_step, carried_step
from .winkler_reference import bed_force

G = 9.80665
MODE_NAMES = ("time_at_rest", "time_rocking", "time_sliding", "time_slide_rocking", "time_in_flight")


class SlidingBlock:
    """Geometry, bed and friction of one case, and the Newton-Euler equations of the spec (per unit mass)."""

    def __init__(self, b, h, mass, K, C, mu_s, mu_k, bed, g=G):
        self.b, self.h, self.mass, self.K, self.C = b, h, mass, K, C
        self.mu_s, self.mu_k, self.bed, self.g = mu_s, mu_k, bed, g
        self.j_c = (b * b + h * h) / 3.0

    def bed_load(self, x):
        """Bed force F and moment M per unit mass at the state x = (theta, theta', y, y', u, u')."""
        force, moment = bed_force(x[0], x[1], x[2], x[3], self.b, self.K, self.C, self.bed)
        return force / self.mass, moment / self.mass

    def stuck(self, x, ag):
        """(theta'', y'', H, F) with the base stuck: u'' = 0 in the horizontal equation gives H in terms of
        theta'', which the moment equation then fixes."""
        theta, rate = x[0], x[1]
        sin_t, cos_t = math.sin(theta), math.cos(theta)
        force, moment = self.bed_load(x)
        h = self.h
        # H = ag + h cos theta''  - h sin theta'^2  into  j_c theta'' = h sin F - cos M - h cos H
        theta_dd = (h * sin_t * force - cos_t * moment - h * cos_t * (ag - h * sin_t * rate * rate)) \
            / (self.j_c + h * h * cos_t * cos_t)
        friction = ag + h * cos_t * theta_dd - h * sin_t * rate * rate
        y_dd = self.g - force - h * sin_t * theta_dd - h * cos_t * rate * rate
        return theta_dd, y_dd, friction, force

    def sliding(self, x, ag, direction):
        """(theta'', y'', u'', H, F) sliding in ``direction`` (+1, -1): H = -mu_k F direction."""
        theta, rate = x[0], x[1]
        sin_t, cos_t = math.sin(theta), math.cos(theta)
        force, moment = self.bed_load(x)
        h = self.h
        friction = -self.mu_k * force * direction
        theta_dd = (h * sin_t * force - cos_t * moment - h * cos_t * friction) / self.j_c
        y_dd = self.g - force - h * sin_t * theta_dd - h * cos_t * rate * rate
        u_dd = friction - ag - h * cos_t * theta_dd + h * sin_t * rate * rate
        return theta_dd, y_dd, u_dd, friction, force

    def after_stop(self, x, ag):
        """Mode once the slip rate is zero: 0 (stuck) if the friction can hold, else the direction it slides."""
        _, _, friction, force = self.stuck(x, ag)
        if abs(friction) <= self.mu_s * force:
            return 0
        return -1 if friction > 0 else 1


def reference_winkler_sliding(ag, dt, b, h, mass, K, xi, mu_s, mu_k, bed="two-spring", t_end=None, g=G,
                              rtol=1e-10, max_events=200_000):
    """Response of the block on the bed with Coulomb friction to ag (see the module docstring)."""
    if not mu_s >= mu_k > 0:
        raise ValueError(f"friction ({mu_s}, {mu_k}): need mu_s >= mu_k > 0")
    ag = np.asarray(ag, dtype=float)
    record_end = (ag.size - 1) * dt
    t_end = record_end + 5.0 if t_end is None else t_end
    n = int(round(t_end / dt)) + 1
    ground = np.zeros(n + 1)
    ground[:min(n, ag.size)] = ag[:n]
    ground = ground.tolist()
    C = 2.0 * xi * math.sqrt(K * mass)
    block = SlidingBlock(b, h, mass, K, C, mu_s, mu_k, bed, g)
    y_static = mass * g / K
    omega_v = math.sqrt(K / mass)
    alpha = math.atan2(b, h)
    p = math.sqrt(0.75 * g / math.hypot(b, h))
    atol = 1e-2 * rtol * np.array([alpha, alpha * p, y_static, y_static * omega_v, b, b * p])
    damping_time = C / K  # p(s) / k = delta + (C/K) delta' has the sign of the corner's pressure

    def corner(s):
        return lambda t, x: x[2] + s * math.sin(x[0])

    def corner_pressure(s):
        return lambda t, x: x[2] + s * math.sin(x[0]) + damping_time * (x[3] + s * math.cos(x[0]) * x[1])

    contact_events = [corner(-b), corner(b)]
    if C > 0:
        contact_events += [corner_pressure(-b), corner_pressure(b)]

    def overturn(t, x):
        return abs(x[0]) - math.pi / 2
    overturn.terminal = True

    def turning(t, x):  # extrema of theta
        return x[1]

    state = np.array([0.0, 0.0, y_static, 0.0, 0.0, 0.0])
    next_direction = [-1.0 if e(0.0, state) > 0 else 1.0 for e in contact_events]
    direction = block.after_stop(state, ground[0])  # stuck unless the first sample already exceeds mu_s g
    history = np.full((n, 4), np.nan)
    history[0] = state[[0, 2, 4, 5]]
    peak_angle = peak_slip = 0.0
    mode_time = dict.fromkeys(MODE_NAMES, 0.0)
    n_impacts = n_flights = n_events = 0
    overturned = False

    step = None  # solve_ivp's first step in the next interval (reference.carried_step)
    for i in range(n - 1):
        t, t_next = i * dt, (i + 1) * dt
        a0, slope = ground[i], (ground[i + 1] - ground[i]) / dt
        while t < t_next - 1e-14 * max(1.0, t_next):
            n_events += 1
            if n_events > max_events:
                raise RuntimeError(f"reference: more than {max_events} steps and events by t = {t}")

            def rhs(tt, x, d=direction):
                a = a0 + slope * (tt - i * dt)
                if d == 0:
                    theta_dd, y_dd, _, _ = block.stuck(x, a)
                    return [x[1], theta_dd, x[3], y_dd, 0.0, 0.0]
                theta_dd, y_dd, u_dd, _, _ = block.sliding(x, a, d)
                return [x[1], theta_dd, x[3], y_dd, x[5], u_dd]

            if direction == 0:
                def friction_event(tt, x):  # the friction the stuck base needs reaches mu_s F
                    _, _, friction, force = block.stuck(x, a0 + slope * (tt - i * dt))
                    return mu_s * force - abs(friction)
            else:
                def friction_event(tt, x, d=direction):  # the slip rate reaches zero
                    return d * x[5]
            friction_event.terminal, friction_event.direction = True, -1
            events = []
            for event, crossing in zip(contact_events, next_direction):
                wrapped = (lambda e: lambda tt, x: e(tt, x))(event)
                wrapped.terminal, wrapped.direction = True, crossing
                events.append(wrapped)
            solution = solve_ivp(rhs, (t, t_next), state, method="DOP853", rtol=rtol, atol=atol,
                                 events=events + [friction_event, overturn, turning],
                                 first_step=bounded_first_step(step, t_next - t))
            step = carried_step(solution)
            if solution.status < 0:
                raise RuntimeError(f"solve_ivp failed at t = {t}: {solution.message}")
            t_stop = float(solution.t[-1])
            # the mode of this segment: the contact state and the stick-slip state are constant within it
            out = sum(1 for k in (0, 1) if next_direction[k] > 0)  # corners out of the ground
            key = "time_in_flight" if out == 2 else (
                ("time_at_rest", "time_rocking") if direction == 0 else ("time_sliding", "time_slide_rocking"))[out]
            mode_time[key] += t_stop - t
            peak_angle = max(peak_angle, float(np.max(np.abs(solution.y[0]))))
            for found in solution.y_events[-1]:
                peak_angle = max(peak_angle, abs(float(found[0])))
            peak_slip = max(peak_slip, float(np.max(np.abs(solution.y[4]))))
            state = solution.y[:, -1].copy()
            t = t_stop
            if len(solution.t_events[-2]):
                overturned = True
                break
            for k, found in enumerate(solution.t_events[:len(events)]):
                if not len(found):
                    continue
                crossing = next_direction[k]
                next_direction[k] = -crossing
                if k >= 2:
                    continue  # a corner's pressure reaching zero: a kink of F, nothing to count
                if crossing > 0:  # a lifted corner landed
                    n_impacts += 1
                elif next_direction[1 - k] > 0:  # a corner left the ground while the other was out
                    n_flights += 1
            if len(solution.t_events[len(events)]):
                if direction == 0:  # stuck -> sliding against the friction it needed
                    _, _, friction, _ = block.stuck(state, a0 + slope * (t - i * dt))
                    direction = -1 if friction > 0 else 1
                else:  # stopped: sticks, or slides back
                    state[5] = 0.0
                    direction = block.after_stop(state, a0 + slope * (t - i * dt))
            if solution.status == 0:
                t = t_next
        if overturned:
            break
        history[i + 1] = state[[0, 2, 4, 5]]
    return {"t": np.arange(n) * dt, "theta": history[:, 0], "y": history[:, 1], "u": history[:, 2],
            "u_dot": history[:, 3], "peak_angle": math.pi / 2 if overturned else peak_angle,
            "peak_slip": peak_slip, "residual_slip": abs(float(state[4])), "n_impacts": n_impacts,
            "n_flights": n_flights, "overturned": overturned, **mode_time}
