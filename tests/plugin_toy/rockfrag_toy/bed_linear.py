"""rockfrag_toy.bed_linear - a contact law from outside rockfrag: the two Kelvin-Voigt corner springs again.

Input : the state x = [theta, theta_dot, y, y_dot] and rockfrag's parameter record (b, omega = sqrt(K/m), xi).
Output: the hooks of a rockfrag contact law (``NAME``, ``force``, ``indicator``, ``indicators``,
        ``full_contact``; rockfrag.models.contact), registered by the entry point ``toy-two-spring``.

The same arithmetic as rockfrag's own ``two-spring`` law (K/2 and C/2 at each corner, Psycharis & Jennings 1983),
written out here rather than imported: a run with ``bed="toy-two-spring"`` must equal a run with
``bed="two-spring"`` bit for bit, which shows that a law from a plugin is called as a shipped one is.
"""

from __future__ import annotations

import math

from rockfrag.models.jit import kernel

NAME = "toy-two-spring"


@kernel
def force(x, params, sin_t, cos_t):
    """Vertical force F [m/s^2] and its moment M [m^2/s^2] about the base centre, per unit mass."""
    b = params["b"]
    omega = params["omega"]
    stiffness = omega * omega             # K/m
    damping = 2.0 * params["xi"] * omega  # C/m
    total = 0.0
    moment = 0.0
    for side in (-1.0, 1.0):
        s = side * b
        delta = x[2] + s * sin_t
        if delta > 0.0:
            corner = 0.5 * (stiffness * delta + damping * (x[3] + s * cos_t * x[1]))
            if corner > 0.0:
                total += corner
                moment += s * corner
    return total, moment


@kernel
def indicator(index, x, params):
    """0, 1: penetration of the -b and +b corner [m]; 2, 3: the corner's k delta + c delta' per unit stiffness."""
    side = -1.0 if index % 2 == 0 else 1.0
    s = side * params["b"]
    delta = x[2] + s * math.sin(x[0])
    if index < 2:
        return delta
    omega = params["omega"]
    return delta + 2.0 * params["xi"] / omega * (x[3] + s * math.cos(x[0]) * x[1])


@kernel
def indicators(x, params, out):
    """All four ``indicator`` values into out (4,)."""
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
    """(K b^2 / m, K/2m (y^2 + b^2 sin^2)): rocking stiffness and elastic energy, both corners down."""
    stiffness = params["omega"] * params["omega"]
    b = params["b"]
    return stiffness * b * b, 0.5 * stiffness * (x[2] * x[2] + b * b * sin_t * sin_t)
