"""pipeline.models.ssi - the 2-DOF SSI-rocking model, derived from the paper's Lagrangian.

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
Pivot switch at theta = 0: ``consistent`` keeps theta' and the centre-of-mass velocity continuous,
so y' jumps by 2 R sin(alpha) |theta'| (energy conserved at the switch; with xi > 0 and k -> inf
Housner's restitution emerges); ``continuous`` keeps theta' and y' (what ODE45 on the paper's
equations does; tends to Housner with r = 1).
"""

from pipeline.models import kernels
from pipeline.models.base import RockingModel

MODEL = RockingModel(
    name="ssi", kernel_code=kernels.SSI, kappa=0.75, needs_foundation=True,
    default_restitution=lambda block: 1.0,
    description="2-DOF rocking on a vertical spring-dashpot, derived from the Lagrangian")

PAPER_MODEL = RockingModel(
    name="ssi-paper", kernel_code=kernels.SSI, kappa=3.0 / 7.0, needs_foundation=True,
    default_restitution=lambda block: 1.0,
    description="the paper's printed eqs. 15-16 (3/7 factors; typos fixed); does not tend to Housner")
