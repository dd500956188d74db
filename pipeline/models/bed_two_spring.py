"""rockfrag.models.bed_two_spring - two Kelvin-Voigt corner springs, a contact law of ``winkler``.

Input : the state x = [theta, theta_dot, y, y_dot] and a parameter record (b, omega = sqrt(K/m), xi).
Output: the hooks of a bed contact law (rockfrag.models.contact): ``NAME``, ``force``,
        ``indicator``, ``indicators`` and ``full_contact``; all per unit mass.

The classic model of Psycharis & Jennings (1983) and Chopra & Yim (1985): K/2 and C/2 at each corner
s = -b, +b, each pushing with max(0, (K/2) delta + (C/2) delta') while its corner is in the ground
(delta = y + s sin(theta) > 0). Contact changes at the corners where the continuous bed's do, so the
indicators are the continuous bed's.
"""

from __future__ import annotations

from rockfrag.models.bed_continuous import indicator, indicators  # noqa: F401  (the same Kelvin-Voigt corners)
from rockfrag.models.jit import kernel

NAME = "two-spring"  # selects this law: simulate(..., bed="two-spring"), [solver] bed


@kernel
def force(x, params, sin_t, cos_t):
    """Vertical force F [m/s^2] and its moment M [m^2/s^2] about the base centre, per unit mass.

    sin_t, cos_t : sin(theta), cos(theta) of the state x (the caller has them).
    """
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
def full_contact(x, params, sin_t):
    """The springs while both corners are in the ground, per unit mass: (rocking stiffness, elastic energy).

    The small-tilt rocking stiffness about the base centre is K b^2 / m [m^2/s^2]; the elastic energy
    [m^2/s^2] is K/4m ((y - b sin)^2 + (y + b sin)^2) = K/2m (y^2 + b^2 sin^2).
    """
    stiffness = params["omega"] * params["omega"]  # K/m
    b = params["b"]
    return stiffness * b * b, 0.5 * stiffness * (x[2] * x[2] + b * b * sin_t * sin_t)
