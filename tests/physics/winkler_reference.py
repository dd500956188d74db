"""An independent scipy reference for the `winkler` model (rigid block on a tensionless viscoelastic
Winkler bed), written from /work/helpers/WINKLER-SPEC.md and not from the compiled kernel.

Input : ground acceleration ag [m/s^2] sampled at dt [s] (linear between samples, zero after the
        record), block half-width b and half-height h [m], mass [kg], total bed stiffness K [N/m],
        damping ratio xi [-] of the vertical mode, bed "continuous", "two-spring" or "hunt-crossley", end time [s],
        optional initial tilt theta0 [rad], rate thetadot0 [rad/s] and settlement y0 [m] (default m g / K).
Output: ``reference_winkler`` returns a dict: t [s], theta [rad], theta_dot [rad/s], y [m] (settlement of
        the base centre, positive down), y_dot [m/s] on the sample grid; peak_angle [rad], uplifted,
        time_of_uplift [s] (NaN if none), n_flights, airborne_time [s], peak_uplift [m], overturned.

How: scipy solve_ivp (DOP853, rtol 1e-10) from one kink of the piecewise-linear ground motion to the
next (each sample of a record; a zero tail or a free vibration in one piece, its samples from the dense
output), so the kinks are step boundaries; terminal events at every change of the contact law (a corner
entering or leaving the ground, a corner's pressure reaching zero) so the kinks and jumps of the bed
force are step boundaries too, and the step that found such an event is solved again up to it. Slow:
tests and benchmarks only.

The "hunt-crossley" bed (issue 18), from its formula: the continuous bed's springs k = K/2b with the
damping of Hunt & Crossley (1975) in the linear-spring form of Marhefka & Orin (1999), pressure
q(s) = max(0, k delta (1 + c delta')) while delta > 0, c = lambda/K = 2 xi omega / g (the damping of the
settled bed equals the Kelvin-Voigt bed's C = 2 xi sqrt(K m)); integrated by two-point Gauss-Legendre
quadrature (exact: q is quadratic in s) over the interval where delta > 0 and 1 + c delta' > 0; events
where a corner's 1 + c delta' crosses zero.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from .reference import bounded_first_step, carried_step

G = 9.80665
# The longest step [samples]: a longer one that ran past a landing would try a deep penetration of a stiff bed
# (an overflow, then rejected); with ten, none does in the tests' cases, at a third of the run time of one.
MAX_STEP_SAMPLES = 10


def _positive_part(lower, upper, offset, slope):
    """Clip [lower, upper] to where offset + slope * s > 0 (the set is an interval)."""
    if slope > 0.0:
        lower = max(lower, -offset / slope)
    elif slope < 0.0:
        upper = min(upper, -offset / slope)
    elif offset <= 0.0:
        upper = lower
    return lower, upper


def bed_force(theta, theta_dot, y, y_dot, b, K, C, bed):
    """Resultant vertical force F [N] (upward on the block) and moment M [N m] of the bed about the
    base centre (spec: Q_theta = -cos(theta) M)."""
    sin_t, cos_t = math.sin(theta), math.cos(theta)
    if bed == "two-spring":
        force = moment = 0.0
        for s in (-b, b):
            penetration = y + s * sin_t
            if penetration <= 0.0:
                continue
            spring = 0.5 * K * penetration + 0.5 * C * (y_dot + s * cos_t * theta_dot)
            if spring > 0.0:
                force += spring
                moment += s * spring
        return force, moment
    if bed == "hunt-crossley":
        return hunt_crossley_force(sin_t, cos_t, theta_dot, y, y_dot, b, K, C)
    if bed != "continuous":
        raise ValueError(f"bed {bed!r}")
    k_l, c_l = K / (2.0 * b), C / (2.0 * b)
    lower, upper = _positive_part(-b, b, y, sin_t)  # in the ground
    p0 = k_l * y + c_l * y_dot
    p1 = k_l * sin_t + c_l * cos_t * theta_dot
    lower, upper = _positive_part(lower, upper, p0, p1)  # pressing, not pulling
    if upper <= lower:
        return 0.0, 0.0
    d1, d2, d3 = upper - lower, (upper**2 - lower**2) / 2.0, (upper**3 - lower**3) / 3.0
    return p0 * d1 + p1 * d2, p0 * d2 + p1 * d3


def hunt_crossley_force(sin_t, cos_t, theta_dot, y, y_dot, b, K, lam):
    """Force [N] and moment [N m] about the base centre of q(s) = max(0, (K/2b) delta (1 + (lam/K) delta')),
    delta = y + s sin(theta) > 0, delta' = y' + s cos(theta) theta'. On the interval where both factors are
    positive q is quadratic in s and q s cubic, so two-point Gauss-Legendre quadrature is exact."""
    c = lam / K
    lower, upper = _positive_part(-b, b, y, sin_t)
    lower, upper = _positive_part(lower, upper, 1.0 + c * y_dot, c * cos_t * theta_dot)
    if upper <= lower:
        return 0.0, 0.0
    middle, half = 0.5 * (upper + lower), 0.5 * (upper - lower)
    force = moment = 0.0
    for s in (middle - half / math.sqrt(3.0), middle + half / math.sqrt(3.0)):
        q = K / (2.0 * b) * (y + s * sin_t) * (1.0 + c * (y_dot + s * cos_t * theta_dot))
        force += half * q
        moment += half * q * s
    return max(force, 0.0), moment


def accelerations(theta, theta_dot, y, ag, force_over_m, moment_over_m, h, j, g=G):
    """theta'' and y'' from the spec's 2x2 system (determinant j - h^2 sin^2 theta)."""
    sin_t, cos_t = math.sin(theta), math.cos(theta)
    det = j - h * h * sin_t * sin_t
    rotation_rhs = g * h * sin_t - h * cos_t * ag - cos_t * moment_over_m
    vertical_rhs = g - force_over_m - h * cos_t * theta_dot**2
    theta_dd = (rotation_rhs - h * sin_t * vertical_rhs) / det
    y_dd = (j * vertical_rhs - h * sin_t * rotation_rhs) / det
    return theta_dd, y_dd


def energy(theta, theta_dot, y, y_dot, b, h, mass, K, bed, g=G):
    """Kinetic + gravity + elastic energy [J] of the spec (arrays accepted)."""
    theta, theta_dot, y, y_dot = (np.asarray(v, dtype=float) for v in (theta, theta_dot, y, y_dot))
    sin_t, cos_t = np.sin(theta), np.cos(theta)
    inertia_c = mass * (b * b + h * h) / 3.0
    kinetic = 0.5 * mass * ((h * cos_t * theta_dot) ** 2 + (y_dot + h * sin_t * theta_dot) ** 2) \
        + 0.5 * inertia_c * theta_dot**2
    gravity = mass * g * (h * cos_t - y)
    if bed == "two-spring":
        elastic = sum(0.25 * K * np.maximum(0.0, y + s * sin_t) ** 2 for s in (-b, b))
    else:
        # int over delta > 0 of 1/2 k_l delta^2 ds, delta = y + s sin theta linear in s
        k_l = K / (2.0 * b)
        elastic = np.zeros_like(theta)
        for i in np.ndindex(theta.shape):
            lower, upper = _positive_part(-b, b, float(y[i]), float(sin_t[i]))
            if upper > lower:
                a, c = float(y[i]), float(sin_t[i])
                primitive = (lambda s: (a + c * s) ** 3 / (3 * c)) if c != 0 else (lambda s: a * a * s)
                elastic[i] = 0.5 * k_l * (primitive(upper) - primitive(lower))
    return kinetic + gravity + elastic


def linear_pieces(*samples) -> list[int]:
    """Sample indices where a piecewise-linear input (samples linear in between) has a kink, with the first
    and last: between two of them every input is one straight line, so the reference integrates that piece in
    one solve_ivp call (a record's zero tail, a free vibration from rest) instead of one call per sample."""
    kinks = set()
    for values in samples:
        values = np.asarray(values, dtype=float)
        kinks.update((np.flatnonzero(np.diff(values, 2) != 0.0) + 1).tolist())
    last = len(samples[0]) - 1
    return [0] + sorted(k for k in kinks if 0 < k < last) + [last]


def _joined(before, after, split):
    """A dense output that is ``before`` up to ``split`` [s] and ``after`` from there (None if ``before`` is)."""
    if before is None:
        return None
    return lambda times: np.where(times <= split, before(times), after(times))


def reference_winkler(ag, dt, b, h, mass, K, xi, bed="continuous", t_end=None, g=G, theta0=0.0,
                      thetadot0=0.0, y0=None, rtol=1e-10, overturn_angle=math.pi / 2, law=None, ag_vertical=None):
    """Response of the block on the bed to ag (see the module docstring for inputs and outputs).

    ``law`` replaces ``bed_force`` (same signature) to study other contact laws, e.g. a dashpot that
    keeps acting out of the ground as in an OpenSees Parallel(ENT, Viscous) spring.
    ``ag_vertical`` [m/s^2, up positive, sampled as ag]: gravity is g + a_v(t) in the ground's frame.
    """
    law = bed_force if law is None else law
    ag = np.asarray(ag, dtype=float)
    record_end = (ag.size - 1) * dt
    t_end = record_end + 5.0 if t_end is None else t_end
    n = int(round(t_end / dt)) + 1
    ground = np.zeros(n + 1)
    ground[:min(n, ag.size)] = ag[:n]
    ground = ground.tolist()
    vertical = np.zeros(n + 1)  # a_v, linear between samples like ag
    if ag_vertical is not None:
        vertical[:min(n, ag.size)] = np.asarray(ag_vertical, dtype=float)[:n]
    vertical = vertical.tolist()
    C = 2.0 * xi * math.sqrt(K * mass)  # the dashpot; for "hunt-crossley" its lambda = K c, c = 2 xi omega_v / g
    j = (b * b + 4.0 * h * h) / 3.0
    y_static = mass * g / K
    omega_v = math.sqrt(K / mass)
    if bed == "hunt-crossley":
        C = K * 2.0 * xi * omega_v / g
    alpha = math.atan2(b, h)
    p = math.sqrt(0.75 * g / math.hypot(b, h))
    atol = 1e-2 * rtol * np.array([alpha, alpha * p, y_static, y_static * omega_v])
    damping_time = C / K  # p(s) / k = delta + (C/K) delta_dot has the sign of the pressure (hunt-crossley: c)

    def rhs_factory(i):
        t_i, a0, slope = i * dt, ground[i], (ground[i + 1] - ground[i]) / dt
        v0, v_slope = vertical[i], (vertical[i + 1] - vertical[i]) / dt

        def rhs(t, x):
            theta, theta_dot, y, y_dot = x
            force, moment = law(theta, theta_dot, y, y_dot, b, K, C, bed)
            theta_dd, y_dd = accelerations(theta, theta_dot, y, a0 + slope * (t - t_i), force / mass,
                                           moment / mass, h, j, g + v0 + v_slope * (t - t_i))
            return [theta_dot, theta_dd, y_dot, y_dd]
        return rhs

    def corner(s):
        return lambda t, x: x[2] + s * math.sin(x[0])

    def corner_pressure(s):
        if bed == "hunt-crossley":  # where 1 + c delta' at the corner crosses zero (times y_static: metres)
            return lambda t, x: y_static * (1.0 + damping_time * (x[3] + s * math.cos(x[0]) * x[1]))
        return lambda t, x: x[2] + s * math.sin(x[0]) + damping_time * (x[3] + s * math.cos(x[0]) * x[1])

    def corner_rate(s):
        return lambda t, x: x[3] + s * math.cos(x[0]) * x[1]

    contact_events = [corner(-b), corner(b)]
    if C > 0:
        contact_events += [corner_pressure(-b), corner_pressure(b)]

    def overturn(t, x):
        return abs(x[0]) - overturn_angle
    overturn.terminal = True

    def peak(t, x):
        return x[1]
    watch_events = [peak, corner_rate(-b), corner_rate(b)]  # extrema of theta and of each corner's height

    state = np.array([theta0, thetadot0, y_static if y0 is None else y0, 0.0])
    next_direction = [-1.0 if e(0.0, state) > 0 else 1.0 for e in contact_events]
    history = np.full((n, 4), np.nan)
    history[0] = state
    peak_angle = abs(theta0)
    peak_uplift = max(0.0, -state[2] + b * abs(math.sin(state[0])))
    time_of_uplift = 0.0 if peak_uplift > 0 else math.nan
    n_flights, airborne_time, flight_start = 0, 0.0, None
    overturned = False

    def track(states):
        nonlocal peak_angle, peak_uplift
        peak_angle = max(peak_angle, float(np.max(np.abs(states[0]))))
        peak_uplift = max(peak_uplift, float(np.max(-states[2] + b * np.abs(np.sin(states[0])))))

    step = None  # solve_ivp's first step in the next piece (reference.carried_step)
    knots = linear_pieces(ground[:n], vertical[:n])
    for i, stop in zip(knots[:-1], knots[1:]):
        t, t_next = i * dt, stop * dt
        rhs = rhs_factory(i)
        inside = stop - i > 1  # samples inside the piece: their states come from the dense output
        while t < t_next - 1e-14 * max(1.0, t_next):
            events = []
            for event, direction in zip(contact_events, next_direction):
                wrapped = (lambda e: lambda tt, x: e(tt, x))(event)
                wrapped.terminal, wrapped.direction = True, direction
                events.append(wrapped)
            solution = solve_ivp(rhs, (t, t_next), state, method="DOP853", rtol=rtol, atol=atol,
                                 events=events + [overturn] + watch_events, dense_output=inside,
                                 max_step=MAX_STEP_SAMPLES * dt, first_step=bounded_first_step(step, t_next - t))
            step = carried_step(solution)
            if solution.status < 0:
                raise RuntimeError(f"solve_ivp failed at t = {t}: {solution.message}")
            dense = solution.sol
            if solution.status == 1:
                # The step that found the event ran past it, and its later stages saw the bed force change there
                # (a kink or a jump): its dense output, which gives the state at the event, is then less accurate
                # than the tolerance, however small the step's error estimate. That step is solved again up to
                # the event, so that every stage sees one contact law.
                redo = solve_ivp(rhs, (solution.t[-2], solution.t[-1]), solution.y[:, -2], method="DOP853",
                                 rtol=rtol, atol=atol, dense_output=inside,
                                 first_step=solution.t[-1] - solution.t[-2])  # shorter than the step taken
                solution.y[:, -1] = redo.y[:, -1]
                dense = _joined(solution.sol, redo.sol, solution.t[-2])
            if inside:
                samples = np.arange(i + 1, stop)
                samples = samples[(samples * dt > t) & (samples * dt <= solution.t[-1])]
                if samples.size:
                    history[samples] = dense(samples * dt).T
            track(solution.y)
            for found in solution.y_events[len(events) + 1:]:
                if len(found):
                    track(np.asarray(found).T)
            state = solution.y[:, -1].copy()
            t = float(solution.t[-1])
            if len(solution.t_events[len(events)]):
                overturned = True
                break
            for k, found in enumerate(solution.t_events[:len(events)]):
                if not len(found):
                    continue
                crossing = next_direction[k]
                next_direction[k] = -crossing
                if k >= 2:
                    continue  # a pressure zero: a kink, nothing to count
                if crossing < 0:  # a corner left the ground
                    if math.isnan(time_of_uplift):
                        time_of_uplift = t
                    if flight_start is None and next_direction[1 - k] > 0:  # the other corner is out too
                        n_flights += 1
                        flight_start = t
                elif flight_start is not None:  # a corner landed
                    airborne_time += t - flight_start
                    flight_start = None
            if solution.status == 0:
                t = t_next
        if overturned:
            break
        history[stop] = state
    if flight_start is not None:
        airborne_time += (n - 1) * dt - flight_start
    return {"t": np.arange(n) * dt, "theta": history[:, 0], "theta_dot": history[:, 1], "y": history[:, 2],
            "y_dot": history[:, 3], "peak_angle": overturn_angle if overturned else peak_angle,
            "uplifted": not math.isnan(time_of_uplift), "time_of_uplift": time_of_uplift,
            "n_flights": n_flights, "airborne_time": airborne_time, "peak_uplift": peak_uplift,
            "overturned": overturned}


def dashpot_always_force(theta, theta_dot, y, y_dot, b, K, C, bed="two-spring"):
    """Two-spring law as OpenSees builds it: Parallel(ENT spring K/2, Viscous dashpot C/2) at each corner.
    The spring carries compression only; the dashpot acts at all times, so it pulls on a lifting corner."""
    force = moment = 0.0
    for s in (-b, b):
        f = 0.5 * K * max(0.0, y + s * math.sin(theta)) + 0.5 * C * (y_dot + s * math.cos(theta) * theta_dot)
        force += f
        moment += s * f
    return force, moment


def rocking_peaks(theta):
    """Peak |theta| [rad] of each excursion (between sign changes) of a rotation history."""
    theta = np.asarray(theta, dtype=float)
    theta = theta[np.isfinite(theta)]
    sign = np.sign(theta)
    changes = np.flatnonzero(sign[1:] * sign[:-1] < 0) + 1
    pieces = np.split(np.abs(theta), changes)
    return np.array([piece.max() for piece in pieces if piece.size])


def effective_restitution(peaks, alpha):
    """Per-impact velocity ratio from successive rocking peaks, as Housner's r: the rigid block that
    peaks at theta_k hits the ground with theta'^2 proportional to cos(alpha - theta_k) - cos(alpha)."""
    peaks = np.asarray(peaks, dtype=float)
    drop = np.cos(alpha - peaks) - math.cos(alpha)
    return np.sqrt(drop[1:] / drop[:-1])


def product_response(ag, dt, b, h, mass, K, xi, bed="continuous", t_end=None, g=G, theta0=0.0,
                     thetadot0=0.0):
    """The product's ``simulate("winkler", ...)`` in the reference's dict form (for side-by-side tests)."""
    from rockfrag.blocks import Block
    from rockfrag.models import simulate

    block = Block(name="winkler-test", b=b, h=h, mass=mass)
    result = simulate("winkler", ag, dt, block, k=K, xi=xi, bed=bed, t_end=t_end, theta0=theta0,
                      thetadot0=thetadot0, g=g)
    response = {name: getattr(result, name) for name in (
        "t", "theta", "theta_dot", "y", "y_dot", "peak_angle", "uplifted", "time_of_uplift", "n_flights",
        "airborne_time", "peak_uplift", "overturned", "min_support_force")}
    response["result"] = result
    return response


def solve(solver, *args, **kwargs):
    """Run the case through ``reference_winkler`` (solver "reference") or the product ("product")."""
    if solver == "reference":
        return reference_winkler(*args, **kwargs)
    return product_response(*args, **kwargs)
