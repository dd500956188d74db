"""rockfrag.models.ssi - the 2-DOF SSI-rocking model, derived from the paper's Lagrangian.

Input : block (R, alpha, m), interface stiffness k [N/m] and damping ratio xi [-].
Output: registered models ``ssi`` (derived here) and ``ssi-paper`` (the printed eqs. 15-16).

Coordinates: rocking angle theta and the settlement y of the active pivot (positive down, as the
potential energy eq. 9 implies). With A = sigma alpha - theta and I_O = 4/3 m R^2 the inertia about
the corner, the exact kinetic energy is

    T = 1/2 I_O theta'^2 - m R sin(A) theta' y' + 1/2 m y'^2,
    V = 1/2 k y^2 + m g (R cos A - y),

with the dashpot -c y' and the ground-inertia moment -m ag R cos A as generalised forces.
Euler-Lagrange gives (tests/physics/test_equations_of_motion.py checks this with sympy):

    I_O theta'' - m R sin(A) y'' + m g R sin(A) = -m ag R cos(A)
    m y'' - m R sin(A) theta'' + m R cos(A) theta'^2 + k y - m g = -c y'

so, with kappa = m R^2 / I_O = 3/4, omega^2 = k/m and 2 xi omega = c/m:

    y''     = [g - w^2 y - 2 xi w y' - R cos(A) theta'^2 + kappa sin(A) (-g sin A - ag cos A)]
              / (1 - kappa sin^2 A)
    theta'' = (kappa / R) [sin(A) y'' - g sin(A) - ag cos(A)]

As k -> infinity, y'' -> 0 and theta'' -> -(3g/4R)[sin A + (ag/g) cos A]: Housner's eq. 1.
The printed eqs. 12-16 use I = 4/3 m R^2 inside (I + m R^2), i.e. kappa = 3/7 (double-counted
inertia); the ``ssi-paper`` variant keeps that, with the sign of eq. 15's gravity term and eq. 16's
multiplication fixed in the minimal way. It does not converge to Housner.

Rest phase: theta = theta' = 0 and only the vertical spring-dashpot moves. Rocking about sigma
starts when |ag| > tan(alpha) (w^2 y + 2 xi w y'), which is g tan(alpha) at static equilibrium.

With a vertical ground acceleration a_v (up positive), the base moves vertically too: in its frame
the gravity term m g (R cos A - y) of V becomes m (g + a_v(t)) (R cos A - y) while the spring and
dashpot act on the relative settlement y, so g is g + a_v(t) in both equations above and in the rest
phase (test_equations_of_motion.py derives this with sympy); the uplift condition reads the spring's
force, which the vertical motion moves.

Pivot switch at theta = 0: ``consistent`` keeps theta' and the centre-of-mass velocity continuous,
so y' jumps by 2 R sin(alpha) |theta'| (energy conserved at the switch; with xi > 0 and k -> inf
Housner's restitution emerges); ``continuous`` keeps theta' and y' (what ODE45 on the paper's
equations does; tends to Housner with r = 1).
"""

import math

from rockfrag.models.base import RockingModel
from rockfrag.models.fields import SSI
from rockfrag.models.jit import kernel

PAPER_TITLE = "A Simplified Mechanical Model for Rocking Structures on Compliant Foundations"
PAPER_CITATION = (f"{PAPER_TITLE}. Article; preprint at Preprints.org, 2026, doi:10.20944/preprints202603.1401.v1. "
                  "The copy the project holds (shared/seed/rocking-ssi-paper.txt) names no authors, journal, volume "
                  "or pages, so none are given here; the DOI is that of the preprint of the same title and abstract.")
"""The seed paper as far as its copy and the preprint's DOI state it: cited in full wherever a page or a file
names it (the report, cube.nc's ``references``)."""



@kernel
def ssi_rest_rhs(x, gravity, params, out):
    """Both corners down: only the vertical spring-dashpot moves (gravity: g + a_v [m/s^2])."""
    omega = params["omega"]
    out[0] = 0.0
    out[1] = 0.0
    out[2] = x[3]
    out[3] = gravity - omega * omega * x[2] - 2.0 * params["xi"] * omega * x[3]


@kernel
def ssi_rhs(sigma, x, accel, gravity, params, out):
    """dx/dt while rocking on pivot sigma (the equations in the module docstring).

    accel: horizontal ground acceleration [m/s^2]; gravity: g + a_v, the effective gravity [m/s^2].
    """
    radius = params["R"]
    g = gravity
    omega = params["omega"]
    kappa = params["kappa"]
    angle = sigma * params["alpha"] - x[0]  # A = sigma*alpha - theta
    sin_a = math.sin(angle)
    cos_a = math.cos(angle)
    free = g - omega * omega * x[2] - 2.0 * params["xi"] * omega * x[3] - radius * cos_a * x[1] * x[1]
    moment = -g * sin_a - accel * cos_a
    y_acc = (free + kappa * sin_a * moment) / (1.0 - kappa * sin_a * sin_a)
    out[0] = x[1]
    out[1] = kappa / radius * (sin_a * y_acc + moment)
    out[2] = x[3]
    out[3] = y_acc


@kernel
def ssi_support(x, params):
    """Force of the spring-dashpot on the block per unit mass [m/s^2] (negative: it pulls).

    The vertical ground motion reaches it through the state.
    """
    omega = params["omega"]
    return omega * omega * x[2] + 2.0 * params["xi"] * omega * x[3]


@kernel
def ssi_pivot_switch(x, params):
    """``consistent`` switch: theta' and the centre-of-mass velocity stay continuous, so y' jumps."""
    x[3] = x[3] + 2.0 * params["R"] * math.sin(params["alpha"]) * abs(x[1])


MODEL = RockingModel(
    name="ssi", kernel_code=SSI, kappa=0.75, needs_foundation=True, uses_switch=True,
    uses_restitution=True, uplift_is_rigid_threshold=True, can_pull=True,
    default_restitution=lambda block: 1.0,
    label="SSI, paper's model (spring can pull)",
    description="the paper's 2-DOF model: one vertical spring-dashpot under the active pivot, derived from "
                "the Lagrangian; the spring can pull on the block")

PAPER_MODEL = RockingModel(
    name="ssi-paper", kernel_code=SSI, kappa=3.0 / 7.0, needs_foundation=True, uses_switch=True,
    uses_restitution=True, uplift_is_rigid_threshold=True, can_pull=True,
    default_restitution=lambda block: 1.0,
    label="SSI, paper's printed equations",
    description="the paper's printed eqs. 15-16 (3/7 factors; typos fixed); does not tend to Housner")
