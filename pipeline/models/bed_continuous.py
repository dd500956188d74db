"""rockfrag.models.bed_continuous - the continuous Kelvin-Voigt bed, a contact law of ``winkler``.

Input : the state x = [theta, theta_dot, y, y_dot] and a parameter record (b, omega = sqrt(K/m), xi).
Output: the hooks of a bed contact law (rockfrag.models.contact): ``NAME``, ``force``,
        ``indicator``, ``indicators`` and ``full_contact``; all per unit mass.

The bed's stiffness K and dashpot C = 2 xi sqrt(K m) are spread uniformly over the footprint width 2b.
A base point s in [-b, b] is in the ground by delta(s) = y + s sin(theta) and carries the pressure
q(s) = max(0, k delta + c delta') while delta > 0 (k = K/2b, c = C/2b): the bed never pulls. q is
linear in s, so the force and its moment are integrated exactly over the loaded length.
"""

from __future__ import annotations

import math

from rockfrag.models.jit import kernel

NAME = "continuous"  # selects this law: simulate(..., bed="continuous"), [solver] bed


@kernel
def _clip(low, high, c0, c1):
    """Restrict [low, high] to where c0 + c1 s > 0."""
    if c1 > 0.0:
        low = max(low, -c0 / c1)
    elif c1 < 0.0:
        high = min(high, -c0 / c1)
    elif c0 <= 0.0:
        high = low
    return low, high


@kernel
def force(x, params, sin_t, cos_t):
    """Vertical force F [m/s^2] and its moment M [m^2/s^2] about the base centre, per unit mass.

    sin_t, cos_t : sin(theta), cos(theta) of the state x (the caller has them).
    """
    b = params["b"]
    omega = params["omega"]
    stiffness = omega * omega             # K/m
    damping = 2.0 * params["xi"] * omega  # C/m
    stiffness_per_length = stiffness / (2.0 * b)
    damping_per_length = damping / (2.0 * b)
    # q(s) = pressure_centre + pressure_slope s on the interval where both delta(s) > 0 and q(s) > 0
    pressure_centre = stiffness_per_length * x[2] + damping_per_length * x[3]
    pressure_slope = stiffness_per_length * sin_t + damping_per_length * cos_t * x[1]
    low, high = _clip(-b, b, x[2], sin_t)
    low, high = _clip(low, high, pressure_centre, pressure_slope)
    if high <= low:
        return 0.0, 0.0
    length = high - low                                  # int ds
    first = (high * high - low * low) / 2.0              # int s ds
    second = (high * high * high - low * low * low) / 3.0  # int s^2 ds
    return (max(pressure_centre * length + pressure_slope * first, 0.0),
            pressure_centre * first + pressure_slope * second)


@kernel
def indicator(index, x, params):
    """Contact indicator ``index`` (its sign changes where the contact changes).

    0, 1: penetration of the -b and +b corner [m]; 2, 3: the pressure law k delta + c delta' at the
    -b and +b corner per unit stiffness [m], where the corner's pressure switches on or off.
    """
    side = -1.0 if index % 2 == 0 else 1.0
    s = side * params["b"]
    delta = x[2] + s * math.sin(x[0])
    if index < 2:
        return delta
    omega = params["omega"]
    return delta + 2.0 * params["xi"] / omega * (x[3] + s * math.cos(x[0]) * x[1])


@kernel
def indicators(x, params, out):
    """All four ``indicator`` values into out (4,), with one sin and one cos."""
    b = params["b"]
    sin_t = math.sin(x[0])
    rate = 2.0 * params["xi"] / params["omega"] * b * math.cos(x[0]) * x[1]
    base_rate = 2.0 * params["xi"] / params["omega"] * x[3]
    out[0] = x[2] - b * sin_t
    out[1] = x[2] + b * sin_t
    out[2] = out[0] + base_rate - rate
    out[3] = out[1] + base_rate + rate


@kernel
def full_contact(x, params, sin_t):
    """The bed while the whole base is in the ground, per unit mass: (rocking stiffness, elastic energy).

    The small-tilt rocking stiffness about the base centre is K b^2 / 3m [m^2/s^2]; the elastic energy
    [m^2/s^2] is int_{-b}^{b} 1/2 (K/2b) (y + s sin)^2 ds / m = K/2m (y^2 + b^2 sin^2 / 3).
    """
    stiffness = params["omega"] * params["omega"]  # K/m
    b = params["b"]
    return (stiffness * b * b * (1.0 / 3.0),
            0.5 * stiffness * (x[2] * x[2] + b * b * sin_t * sin_t / 3.0))
