"""rockfrag_toy.bed_hertz - a contact law from outside rockfrag, physically different: stiffening corner springs.

Input : the state x = [theta, theta_dot, y, y_dot] and rockfrag's parameter record (b, omega = sqrt(K/m), xi).
Output: the hooks of a rockfrag contact law, registered by the entry point ``toy-hertz``.

Each corner pushes with (K/2) delta^(3/2) / sqrt(b) + (C/2) delta' while it is in the ground (never pulling), the
power law of a Hertzian contact: the stiffer the deeper. At rest on both corners the weight balances
K y^(3/2) / sqrt(b) = m g, so the block settles at y* = (g sqrt(b) / omega^2)^(2/3), not at the linear bed's
g / omega^2: the closed form tests/test_plugins.py checks a run against.
"""

from __future__ import annotations

import math

from rockfrag.models.jit import kernel

NAME = "toy-hertz"


@kernel
def _spring(delta, b):
    """delta^(3/2) / sqrt(b) [m] of a corner in the ground (0 out of it)."""
    return delta * math.sqrt(delta / b) if delta > 0.0 else 0.0


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
            corner = 0.5 * (stiffness * _spring(delta, b) + damping * (x[3] + s * cos_t * x[1]))
            if corner > 0.0:
                total += corner
                moment += s * corner
    return total, moment


@kernel
def indicator(index, x, params):
    """0, 1: penetration of the -b and +b corner [m]; 2, 3: the corner's force per unit stiffness [m]."""
    side = -1.0 if index % 2 == 0 else 1.0
    b = params["b"]
    delta = x[2] + side * b * math.sin(x[0])
    if index < 2:
        return delta
    rate = x[3] + side * b * math.cos(x[0]) * x[1]
    return _spring(delta, b) + 2.0 * params["xi"] / params["omega"] * rate if delta > 0.0 else delta


@kernel
def indicators(x, params, out):
    """All four ``indicator`` values into out (4,)."""
    for index in range(4):
        out[index] = indicator(index, x, params)


@kernel
def full_contact(x, params, sin_t):
    """(K_r/m, V/m) [m^2/s^2] with both corners down: rocking stiffness and elastic energy.

    The rocking stiffness is 2 (3/4)(K/m) sqrt(y/b) b^2 (each corner's spring differentiated at delta = y); the
    energy is the sum over the corners of (K/m)/5 delta^(5/2) / sqrt(b).
    """
    stiffness = params["omega"] * params["omega"]
    b = params["b"]
    y = max(x[2], 0.0)
    energy = 0.0
    for side in (-1.0, 1.0):
        delta = max(x[2] + side * b * sin_t, 0.0)
        energy += 0.2 * stiffness * delta * _spring(delta, b)
    return 1.5 * stiffness * b * b * math.sqrt(y / b), energy
