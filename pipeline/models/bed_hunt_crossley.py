"""rockfrag.models.bed_hunt_crossley - the continuous bed with Hunt-Crossley damping, a contact law of ``winkler``.

Input : the state x = [theta, theta_dot, y, y_dot] and a parameter record (b, g, omega = sqrt(K/m), xi).
Output: the hooks of a bed contact law (rockfrag.models.contact): ``NAME``, ``force``,
        ``indicator``, ``indicators`` and ``full_contact``; all per unit mass.

The continuous bed's springs (K spread uniformly over the footprint width 2b, k = K/2b, as in
bed_continuous.py) with the dissipation of Hunt & Crossley (1975) in its linear-spring form
(Marhefka & Orin 1999, F = k x + lambda x x'): a base point s in [-b, b] in the ground by
delta(s) = y + s sin(theta) > 0 carries the pressure

    q(s) = max(0, k delta (1 + c delta')),   delta' = y' + s cos(theta) theta'.

The damping k c delta delta' grows with the penetration, so it vanishes where a point touches down or
lifts off: a landing corner meets no dashpot jump, and the clip at zero (where 1 + c delta' < 0, a
point leaving the ground faster than 1/c) keeps the bed from pulling. The power k c delta delta'^2 of
the damping, and k delta |delta'| where the clip acts, are never negative: the law only dissipates.

c [s/m] is set by the damping ratio xi of the vertical mode at rest, as for the Kelvin-Voigt beds:
about the settled state delta = y_static = g / omega^2 the linearised damping force is
K y_static c y' = C y' with C = 2 xi sqrt(K m), so c = 2 xi omega / g. The bed at rest damps its
vertical vibration as the Kelvin-Voigt bed of the same xi; its impacts lose more, because the damping
is weighted by the penetration and so acts nearer the landing corner (rockfrag.models.restitution
calibrates xi to a target restitution; docs/theory/bed.md gives the range it reaches). q(s) is a product of
two linear functions of s, so the force and its moment are integrated exactly over the loaded length
(where both factors are positive).
"""

from __future__ import annotations

import math

from rockfrag.models.bed_continuous import (
    _clip,
    full_contact,  # noqa: F401  (the same springs: same elastic energy)
)
from rockfrag.models.jit import kernel

NAME = "hunt-crossley"  # selects this law: simulate(..., bed="hunt-crossley"), [solver] bed


@kernel
def damping_factor(params):
    """Hunt-Crossley c = lambda / k [s/m] of the bed: 2 xi omega / g (the vertical damping ratio xi at rest)."""
    return 2.0 * params["xi"] * params["omega"] / params["g"]


@kernel
def force(x, params, sin_t, cos_t):
    """Vertical force F [m/s^2] and its moment M [m^2/s^2] about the base centre, per unit mass.

    sin_t, cos_t : sin(theta), cos(theta) of the state x (the caller has them).
    """
    b = params["b"]
    omega = params["omega"]
    c = damping_factor(params)
    stiffness_per_length = omega * omega / (2.0 * b)  # k/m
    # delta(s) = depth_centre + depth_slope s; 1 + c delta'(s) = factor_centre + factor_slope s
    depth_centre = x[2]
    depth_slope = sin_t
    factor_centre = 1.0 + c * x[3]
    factor_slope = c * cos_t * x[1]
    low, high = _clip(-b, b, depth_centre, depth_slope)
    low, high = _clip(low, high, factor_centre, factor_slope)
    if high <= low:
        return 0.0, 0.0
    # q(s) / (k/m) = q0 + q1 s + q2 s^2 on [low, high]
    q0 = depth_centre * factor_centre
    q1 = depth_centre * factor_slope + depth_slope * factor_centre
    q2 = depth_slope * factor_slope
    low2, high2 = low * low, high * high
    i0 = high - low                          # int ds
    i1 = (high2 - low2) / 2.0                # int s ds
    i2 = (high2 * high - low2 * low) / 3.0   # int s^2 ds
    i3 = (high2 * high2 - low2 * low2) / 4.0  # int s^3 ds
    return (max(stiffness_per_length * (q0 * i0 + q1 * i1 + q2 * i2), 0.0),
            stiffness_per_length * (q0 * i1 + q1 * i2 + q2 * i3))


@kernel
def indicator(index, x, params):
    """Contact indicator ``index`` (its sign changes where the contact changes).

    0, 1: penetration of the -b and +b corner [m]; 2, 3: y_static (1 + c delta') at the -b and +b
    corner [m], whose zero is where the corner's pressure switches off or on while it is in the ground.
    """
    side = -1.0 if index % 2 == 0 else 1.0
    s = side * params["b"]
    if index < 2:
        return x[2] + s * math.sin(x[0])
    omega = params["omega"]
    y_static = params["g"] / (omega * omega)
    return y_static * (1.0 + damping_factor(params) * (x[3] + s * math.cos(x[0]) * x[1]))


@kernel
def indicators(x, params, out):
    """All four ``indicator`` values into out (4,), with one sin and one cos."""
    b = params["b"]
    sin_t = math.sin(x[0])
    omega = params["omega"]
    y_static = params["g"] / (omega * omega)
    c = damping_factor(params)
    rate = b * math.cos(x[0]) * x[1]
    out[0] = x[2] - b * sin_t
    out[1] = x[2] + b * sin_t
    out[2] = y_static * (1.0 + c * (x[3] - rate))
    out[3] = y_static * (1.0 + c * (x[3] + rate))
