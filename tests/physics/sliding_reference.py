"""An independent scipy reference for a rigid block with Coulomb friction on a rigid base (``housner`` with
``friction``), written from the spec below and not from the compiled kernel.

Spec (the contact law with friction):

* A rigid rectangular block, half-width b, half-height h, mass m, I_c = m (b^2 + h^2) / 3 about its centre of
  mass c. The ground accelerates horizontally by ag(t) (linear between samples, zero after them); in its frame
  the block feels gravity g downwards and the inertial force -m ag. Tilt theta > 0 turns the block clockwise
  (its top towards +x); the state is (theta, theta', x_c, x_c'), x_c the horizontal position of c relative to
  the ground (0 at the start, flat).
* Contact is at the base corners only, with a normal force V >= 0 and a friction force H (towards +x on the
  block). Flat, the whole base is down. Modes: flat stuck, flat sliding in direction d (+1, -1), rocking on
  corner sigma (+1: the +b corner) stuck, rocking on corner sigma sliding in direction d.
* In every mode the unknowns (x_c'', z_c'', theta'', H, V) solve five linear equations: m x_c'' = H - m ag,
  m z_c'' = V - m g, I_c theta'' = (torque of (H, V) at the contact point about c, clockwise), the contact
  point's vertical acceleration is zero, and either its horizontal acceleration is zero (stuck) or
  H = -mu_k d V (sliding in direction d). The friction needs |H| <= mu_s V to stay stuck.
* Flat and stuck the block starts to move when it cannot stay: rocking on the corner sigma = -sign(ag) if
  the rocking solution tips it (sigma theta'' > 0) and |H| <= mu_s V; else rocking on that corner while it
  slides (d = -sign(H) of the stuck solution) if that tips it; else sliding flat (d = -sign(ag)) if
  |ag| > mu_s g; a block sliding flat tips onto its leading corner (sigma = d) if rocking on it while sliding
  tips it.
* A stuck contact starts to slide when |H| = mu_s V is crossed, in the direction d = -sign(H); a sliding
  contact whose velocity reaches zero sticks if the stuck solution has |H| <= mu_s V, else slides on with
  d = -sign(H).
* At theta = 0 the other corner lands plastically (its vertical velocity becomes zero) with an impulse
  (P_x, P_z) from the ground, from the momentum and angular-momentum balance (five linear equations, as above).
  Which landing happens is the Coulomb condition on the impulses (Shenton & Jones 1991's mode criteria, applied
  to a landing):
  1. the new corner stops and the old one lifts, if that needs a compressive P_z > 0 with |P_x| <= mu_s P_z and
     leaves the block turning onto the new corner (this keeps the angular momentum about the new corner:
     Housner's r when nothing slid);
  2. else the new corner slides, P_x = -mu_k d P_z, d the direction of its slip (the corner's horizontal
     velocity before the landing; if it was zero, the direction opposite to the sticking impulse);
  3. if the rotation rate that leaves would turn the block back onto the old corner (into the ground), both
     corners land: a flat plastic landing (theta' and the centre's vertical velocity stop, impulses at both
     corners), sticking if the total |P_x| <= mu_s P_z and both normal impulses are >= 0, else sliding with
     P_x = -mu_k d P_z against the centre's horizontal velocity d.
  If a kinetic landing's slip would reverse, it halts within the impact (Routh's construction: the slide ends where
  the corner's horizontal velocity is zero) and the rest of the landing sticks if that needs |P_x| <= mu_s P_z, else
  slides back.
  The block then rocks on the new corner, or, if its rotation rate is too small to lift it by
  ``ZENO_FRACTION`` alpha on a fixed corner (rate^2 < 2 p^2 sin(alpha) ZENO_FRACTION alpha, p^2 = 3 g / 4R: the
  README's rule for ending Zeno chatter), lies flat.
* Overturning at |theta| = pi/2 ends the run. The slip u is the contact corner's horizontal position minus
  sigma b (flat: the base centre's).
* Energy, per unit mass in the ground's frame: E = |v_c|^2 / 2 + j theta'^2 / 2 + g z_c changes by the work of the
  inertial force, -ag x_c', minus the friction's dissipation, -H v_p (v_p the contact point's horizontal velocity),
  minus the losses at the landings (and at the Zeno rule, which lays a slow block flat); the reference integrates
  the first two with the state and books the others, so that the balance can be checked.

How: scipy solve_ivp (DOP853, rtol 1e-10) one sample interval at a time, with terminal events at every mode
change, and the linear equations solved with numpy in every right-hand side. Slow: tests only.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from .reference import bounded_first_step, carried_step

G = 9.80665
ZENO_FRACTION = 1e-6  # of alpha: a smaller excursion after an impact lays the block flat


class Block:
    """The block's geometry and friction (SI)."""

    def __init__(self, b, h, mu_s, mu_k, g=G):
        self.b, self.h, self.mu_s, self.mu_k, self.g = b, h, mu_s, mu_k, g
        self.j = (b * b + h * h) / 3.0  # I_c / m
        self.housner_r = 1.0 - 1.5 * b * b / (b * b + h * h)  # Housner's r = 1 - 1.5 sin^2(alpha)
        radius, alpha = math.hypot(b, h), math.atan2(b, h)
        self.zeno_rate = math.sqrt(2 * (0.75 * g / radius) * math.sin(alpha) * ZENO_FRACTION * alpha)

    def arm(self, sigma, theta):
        """Contact corner sigma relative to the centre of mass: (dx, dz)."""
        s, c = math.sin(theta), math.cos(theta)
        return sigma * self.b * c - self.h * s, -sigma * self.b * s - self.h * c

    def solve(self, sigma, d, theta, rate, ag):
        """(x_c'', z_c'', theta'', H, V) per unit mass rocking on corner sigma, stuck (d = 0) or sliding in d."""
        dx, dz = self.arm(sigma, theta)
        a = np.zeros((5, 5))
        rhs = np.zeros(5)
        a[0, 0], a[0, 3], rhs[0] = 1.0, -1.0, -ag          # x_c'' - H = -ag
        a[1, 1], a[1, 4], rhs[1] = 1.0, -1.0, -self.g      # z_c'' - V = -g
        a[2, 2], a[2, 3], a[2, 4] = self.j, -dz, dx        # j theta'' = dz H - dx V (clockwise torque)
        # contact point: r_p = r_c + d(theta), d' = theta' (dz, -dx), d'' = theta'' (dz, -dx) - theta'^2 (dx, dz)
        a[3, 1], a[3, 2], rhs[3] = 1.0, -dx, dz * rate * rate  # z_p'' = 0
        if d == 0:
            a[4, 0], a[4, 2], rhs[4] = 1.0, dz, dx * rate * rate  # x_p'' = 0
        else:
            a[4, 3], a[4, 4] = 1.0, self.mu_k * d                 # H = -mu_k d V
        return np.linalg.solve(a, rhs)


def reference_sliding(ag, dt, b, h, mu_s, mu_k, t_end, g=G, rtol=1e-10, atol=1e-13):
    """Rigid block on a rigid base with Coulomb friction: dict of peak_angle [rad], peak_slip [m], residual_slip
    [m], overturned, slide_rock_time [s], n_impacts, the landings by kind (``landings``: stick, slide, halt, flat), the
    smallest normal impulse of any landing corner [m/s] (``min_normal_impulse``), the largest |P_x|/P_z of a
    sticking landing (``max_stick_ratio``), the smallest energy loss of a landing [J/kg] (``min_landing_loss``), and
    the energy balance per unit mass [J/kg]: ``energy_start``, ``energy_end``, ``work_in`` (inertial force),
    ``friction_loss``, ``landing_loss`` (the landings', the Zeno rule's and the events' resets of the state to their
    surfaces); ``balance_error`` = energy_end -
    energy_start - (work_in - friction_loss - landing_loss)."""
    block = Block(b, h, mu_s, mu_k, g)
    n = ag.size

    def ground(t):
        i = int(math.floor(t / dt + 1e-9))
        if i + 1 >= n:
            return float(ag[-1]) * max(0.0, 1.0 - (t - (n - 1) * dt) / dt) if i < n else 0.0
        return ag[i] + (ag[i + 1] - ag[i]) * (t / dt - i)

    state = np.zeros(6)  # theta, theta', x_c, x_c', work of the inertial force, friction loss (per unit mass)
    mode = ("flat", 0, 0)  # (kind, sigma, d)
    peak_angle = peak_slip = slide_rock_time = landing_loss = 0.0
    impacts = 0
    overturned = False
    landings = {"stick": 0, "slide": 0, "halt": 0, "flat": 0}
    checks = {"min_normal_impulse": math.inf, "max_stick_ratio": 0.0, "min_landing_loss": math.inf}

    def slip_of(sigma, y):
        if sigma == 0:
            return y[2]
        dx, _ = block.arm(sigma, y[0])
        return y[2] + dx - sigma * b

    def pivot_velocity(sigma, y):
        _, dz = block.arm(sigma, y[0])
        return y[3] + dz * y[1]

    def energy(mode, y):
        """E per unit mass: the centre's height is -dz above the contact corner, its vertical velocity dx theta'."""
        kind, sigma, _ = mode
        if kind == "flat":
            return 0.5 * y[3] ** 2 + g * h
        dx, dz = block.arm(sigma, y[0])
        return 0.5 * (y[3] ** 2 + (dx * y[1]) ** 2) + 0.5 * block.j * y[1] ** 2 - g * dz

    def select_flat(t, y, d_slide):
        """Mode of a flat block not rotating; d_slide: its current slide direction (0: stuck)."""
        a = ground(t)
        if d_slide != 0:
            xa, za, ta, hh, vv = block.solve(d_slide, d_slide, 0.0, 0.0, a)
            return ("rock", d_slide, d_slide) if d_slide * ta > 0 else ("flat", 0, d_slide)
        if a != 0.0:
            sigma = -int(math.copysign(1, a))
            xa, za, ta, hh, vv = block.solve(sigma, 0, 0.0, 0.0, a)
            if sigma * ta > 0:
                if abs(hh) <= mu_s * vv:
                    return ("rock", sigma, 0)
                d = -int(math.copysign(1, hh))
                if sigma * block.solve(sigma, d, 0.0, 0.0, a)[2] > 0:
                    return ("rock", sigma, d)
                return select_flat(t, y, -int(math.copysign(1, a)))
            if abs(a) > mu_s * g:
                return select_flat(t, y, -int(math.copysign(1, a)))
        return ("flat", 0, 0)

    def rhs(t, y):
        kind, sigma, d = mode
        a = ground(t)
        if kind == "flat":
            if d == 0:
                return [0.0, 0.0, y[3], 0.0, -a * y[3], 0.0]
            friction = -mu_k * d * g
            return [0.0, 0.0, y[3], friction - a, -a * y[3], -friction * y[3]]
        xa, za, ta, hh, vv = block.solve(sigma, d, y[0], y[1], a)
        return [y[1], ta, y[3], xa, -a * y[3], -hh * pivot_velocity(sigma, y)]

    def events_for():
        kind, sigma, d = mode
        out = []
        if kind == "flat" and d == 0:
            def start(t, y):
                return min(mu_s, b / h) * g - abs(ground(t))
            start.terminal, start.direction = True, -1
            out.append(("start", start))
        if d != 0:
            def stop(t, y):
                return d * (pivot_velocity(sigma, y) if kind == "rock" else y[3])
            stop.terminal, stop.direction = True, -1
            out.append(("stop", stop))
        if kind == "rock":
            def impact(t, y):
                return sigma * y[0]
            impact.terminal, impact.direction = True, -1
            out.append(("impact", impact))

            def over(t, y):
                return abs(y[0]) - math.pi / 2
            over.terminal, over.direction = True, 1
            out.append(("overturn", over))
            if d == 0:
                def slip_start(t, y):
                    xa, za, ta, hh, vv = block.solve(sigma, 0, y[0], y[1], ground(t))
                    return mu_s * vv - abs(hh)
                slip_start.terminal, slip_start.direction = True, -1
                out.append(("slip", slip_start))

            def turn(t, y):
                return y[1]
            out.append(("peak", turn))
        return out

    t = 0.0
    mode = select_flat(0.0, state, 0)
    energy_start = energy(mode, state)
    guard = 0
    step = None  # solve_ivp's first step in the next interval (reference.carried_step)
    while t < t_end - 1e-12 and not overturned:
        guard += 1
        if guard > 500_000:
            raise RuntimeError("reference: too many mode changes")
        t_next = min((math.floor(t / dt + 1e-9) + 1) * dt, t_end)
        if mode == ("flat", 0, 0):
            a0, a1 = abs(ground(t)), abs(ground(t_next - 1e-15))
            if max(a0, a1) <= min(mu_s, b / h) * g:
                t, step = t_next, None
                continue
        named = events_for()
        solution = solve_ivp(rhs, (t, t_next), state, method="DOP853", rtol=rtol, atol=atol,
                             events=[e for _, e in named], dense_output=True,
                             first_step=bounded_first_step(step, t_next - t))
        step = carried_step(solution)
        kind, sigma, d = mode
        for (name, _), times in zip(named, solution.t_events):
            if name == "peak":
                for tp in times:
                    peak_angle = max(peak_angle, abs(solution.sol(tp)[0]))
        t_stop = solution.t[-1]
        if kind == "rock" and d != 0:
            slide_rock_time += t_stop - t
        state = solution.y[:, -1].copy()
        if kind == "rock":
            peak_angle = max(peak_angle, abs(state[0]))
        peak_slip = max(peak_slip, abs(slip_of(sigma, state)))
        t = t_stop
        if solution.status != 1:
            continue
        fired = [name for (name, _), times in zip(named, solution.t_events) if name != "peak" and times.size
                 and abs(times[-1] - t_stop) < 1e-12]
        event = fired[0] if fired else None
        before = energy(mode, state)
        if event == "overturn":
            overturned = True
        elif event == "start":
            mode = select_flat(t + 1e-13, state, 0)
            if mode[0] == "rock":
                state[0] = state[1] = 0.0
        elif event == "slip":
            xa, za, ta, hh, vv = block.solve(sigma, 0, state[0], state[1], ground(t))
            mode = ("rock", sigma, -int(math.copysign(1, hh)))
        elif event == "stop":
            if kind == "flat":
                state[3] = 0.0
                mode = select_flat(t, state, 0)
                if mode[0] == "rock":
                    state[0] = state[1] = 0.0
            else:
                _, dz = block.arm(sigma, state[0])
                state[3] = -dz * state[1]  # the corner stops
                xa, za, ta, hh, vv = block.solve(sigma, 0, state[0], state[1], ground(t))
                mode = ("rock", sigma, 0) if abs(hh) <= mu_s * vv else ("rock", sigma, -int(math.copysign(1, hh)))
        elif event == "impact":
            impacts += 1
            state[0] = 0.0
            at_landing = energy(mode, state)
            landing, state, mode = _impact(block, sigma, state)
            landings[landing["kind"]] += 1
            checks["min_normal_impulse"] = min(checks["min_normal_impulse"], *landing["normal"])
            if landing["kind"] == "stick":
                checks["max_stick_ratio"] = max(checks["max_stick_ratio"], landing["ratio"])
            checks["min_landing_loss"] = min(checks["min_landing_loss"], at_landing - landing["energy_after"])
            if mode[0] == "flat":
                mode = select_flat(t, state, mode[2])
            else:
                if mode[2] == 0:  # a stuck corner: can the friction hold it?
                    xa, za, ta, hh, vv = block.solve(mode[1], 0, 0.0, state[1], ground(t))
                    if abs(hh) > mu_s * vv:
                        mode = ("rock", mode[1], -int(math.copysign(1, hh)))
                # the first step must not hold the whole next excursion (its landing would be found at its start)
                turn = block.solve(mode[1], mode[2], 0.0, state[1], ground(t))[2]
                if turn * state[1] < 0:
                    step = 0.1 * abs(state[1] / turn)
        landing_loss += before - energy(mode, state)  # a landing's loss; the other events' resets are ~atol
    u_end = slip_of(mode[1] if mode[0] == "rock" else 0, state)
    energy_end = energy(mode, state)
    return {"peak_angle": peak_angle, "peak_slip": peak_slip, "residual_slip": abs(u_end),
            "overturned": overturned, "slide_rock_time": slide_rock_time, "n_impacts": impacts,
            "landings": landings, **checks, "energy_start": energy_start, "energy_end": energy_end,
            "work_in": state[4], "friction_loss": state[5], "landing_loss": landing_loss,
            "balance_error": energy_end - energy_start - (state[4] - state[5] - landing_loss)}


def _impact(block, sigma, state, restitution=None):
    """The new corner -sigma lands (spec): (landing, state after, mode after).

    landing: kind ("stick", "slide", "halt", "flat"), the normal impulses of the corners that land (``normal``),
    |P_x|/P_z (``ratio``) and the energy per unit mass after the landing and the Zeno rule (``energy_after``).
    ``restitution`` r (None: the plastic landing, Housner's r_H) changes the sticking landing only: the part of the
    angular momentum about the new corner that the rotation brings, (j + h^2 - b^2) theta', is scaled by r / r_H
    (the kernel's ``restitution`` option)."""
    new = -sigma
    rate, xdot = state[1], state[3]
    dx_old, _ = block.arm(sigma, 0.0)
    zdot = dx_old * rate  # the old corner's vertical velocity was zero
    dx, dz = block.arm(new, 0.0)
    corner_before = xdot + dz * rate  # both corners' horizontal velocity at theta = 0

    def post(x0, z0, rate0, stick, d=0, halt=False, scaled=False):
        """From the centre's velocities (x0, z0) and rate0, the landing on the new corner alone: (x', z', theta',
        P_x, P_z) per unit mass. It ends when the corner's vertical velocity is zero, or (halt) its horizontal one;
        the corner sticks (both zero) or slides in direction d (P_x = -mu_k d P_z). ``scaled``: the whole landing
        sticks with the restitution's angular momentum."""
        a = np.zeros((5, 5))
        r = np.zeros(5)
        a[0, 0], a[0, 3], r[0] = 1.0, -1.0, x0
        a[1, 1], a[1, 4], r[1] = 1.0, -1.0, z0
        a[2, 2], a[2, 3], a[2, 4], r[2] = block.j, -dz, dx, block.j * rate0
        if scaled and restitution is not None:
            # the angular momentum about the new corner, j theta' - dz x' + dx z', with the rotation's part scaled
            momentum = block.j * rate - dz * xdot + dx * zdot
            rotation_part = momentum - block.h * corner_before
            a[2] = [-dz, dx, block.j, 0.0, 0.0]
            r[2] = momentum - (1.0 - restitution / block.housner_r) * rotation_part
        if halt:
            a[3, 0], a[3, 2] = 1.0, dz  # the corner's horizontal velocity x' + dz theta' = 0
        else:
            a[3, 1], a[3, 2] = 1.0, -dx  # its vertical velocity z' - dx theta' = 0
        if stick:
            a[4, 0], a[4, 2] = 1.0, dz  # and its horizontal velocity
        else:
            a[4, 3], a[4, 4] = 1.0, block.mu_k * d
        return np.linalg.solve(a, r)

    def flat():
        # both corners land: unknowns x', P_x, P_new, P_old (theta' and z' become zero)
        # x' - P_x = xdot; -(P_new + P_old) = zdot; j (0 - rate) = dz P_x - dx P_new - dx_old P_old (both at dz)
        a = np.zeros((4, 4))
        r = np.array([xdot, -zdot, -block.j * rate, 0.0])
        a[0, 0], a[0, 1] = 1.0, -1.0
        a[1, 2], a[1, 3] = 1.0, 1.0
        a[2, 1], a[2, 2], a[2, 3] = dz, -dx, -dx_old
        a[3, 0] = 1.0  # stuck: x' = 0
        x1, px, p_new, p_old = np.linalg.solve(a, r)
        d = 0
        if abs(px) > block.mu_s * (p_new + p_old) or min(p_new, p_old) < 0:
            d = int(math.copysign(1, xdot))
            a[3] = [0.0, 1.0, block.mu_k * d, block.mu_k * d]  # P_x = -mu_k d (P_new + P_old)
            x1, px, p_new, p_old = np.linalg.solve(a, r)
            if d * x1 <= 0:
                raise NotImplementedError("a flat landing whose slip reverses: outside the spec")
        state_after = np.array([0.0, 0.0, state[2], x1, state[4], state[5]])
        landing = {"kind": "flat", "normal": (p_new, p_old), "ratio": abs(px) / (p_new + p_old),
                   "energy_after": 0.5 * x1 * x1 + block.g * block.h}
        return landing, state_after, ("flat", 0, d)

    x1, z1, rate1, px, pz = post(xdot, zdot, rate, True, scaled=True)
    kind, d, normal = "stick", 0, (pz,)
    if not (pz > 0 and abs(px) <= block.mu_s * pz and new * rate1 >= 0):
        d = int(math.copysign(1, corner_before)) if corner_before != 0 else -int(math.copysign(1, px))
        x1, z1, rate1, px, pz = post(xdot, zdot, rate, False, d)
        kind, normal = "slide", (pz,)
        if d * (x1 + dz * rate1) < 0:  # the slip halts within the landing: the rest sticks, or slides back
            xh, zh, rate_h, px_h, pz_h = post(xdot, zdot, rate, False, d, halt=True)
            x1, z1, rate1, px, pz = post(xh, zh, rate_h, True)
            if not (pz > 0 and abs(px) <= block.mu_s * pz):
                d = -d
                x1, z1, rate1, px, pz = post(xh, zh, rate_h, False, d)
            else:
                d = 0
            kind, normal, px, pz = "halt", (pz_h, pz), px_h + px, pz_h + pz
    if new * rate1 < 0:  # it would turn back onto the old corner: both land
        return flat()
    corner_velocity = x1 + dz * rate1
    state = np.array([0.0, rate1, state[2], x1, state[4], state[5]])
    landing = {"kind": kind, "normal": normal, "ratio": abs(px) / pz}
    mode = ("rock", new, d)
    if abs(rate1) < block.zeno_rate:
        state[1] = 0.0
        state[3] = corner_velocity
        mode = ("flat", 0, 0 if d == 0 or corner_velocity == 0 else int(math.copysign(1, corner_velocity)))
        landing["energy_after"] = 0.5 * corner_velocity ** 2 + block.g * block.h
    else:
        landing["energy_after"] = (0.5 * (x1 * x1 + (dx * rate1) ** 2) + 0.5 * block.j * rate1 ** 2
                                   - block.g * block.arm(new, 0.0)[1])
    return landing, state, mode
