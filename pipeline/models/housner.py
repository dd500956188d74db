"""pipeline.models.housner - Housner's rigid-base rocking block (paper eqs. 1-6).

Input : block (R, alpha), ground acceleration. Output: registered model ``housner`` and its
compiled physics: ``housner_rhs`` (rocking), ``housner_rest_rhs`` and ``housner_support``.

theta'' = -p^2 [sin(sigma alpha - theta) + (ag/g) cos(sigma alpha - theta)], p^2 = 3g/(4R), sigma
the active pivot. At rest until |ag| > g tan(alpha); at each impact (theta = 0) theta' <- r theta'
with r = 1 - 1.5 sin^2(alpha) by default (angular momentum about the new corner), pivot switches.

With a vertical ground acceleration a_v (up positive) g is g + a_v(t) throughout, in the ground's
frame: theta'' = -(3/4R) [(g + a_v) sin A + ag cos A] (from the Lagrangian with the base moving
vertically, tests/physics/test_equations_of_motion.py) and uplift at |ag| > (g + a_v) tan(alpha).
"""

import math

from pipeline.models.base import RockingModel
from pipeline.models.fields import HOUSNER
from pipeline.models.jit import njit


@njit(cache=True)
def housner_rhs(sigma, x, accel, gravity, params, out):
    """dx/dt while rocking on pivot sigma: theta'' = -(kappa/R)(g sin A + ag cos A), A = sigma alpha - theta.

    accel: horizontal ground acceleration [m/s^2]; gravity: g + a_v, the effective gravity [m/s^2].
    """
    angle = sigma * params["alpha"] - x[0]
    out[0] = x[1]
    out[1] = -params["kappa"] * (gravity * math.sin(angle) + accel * math.cos(angle)) / params["R"]
    out[2] = 0.0
    out[3] = 0.0


@njit(cache=True)
def housner_rest_rhs(out):
    """dx/dt at rest on a rigid base: nothing moves."""
    for i in range(out.size):
        out[i] = 0.0


@njit(cache=True)
def housner_support(gravity):
    """Vertical force of the rigid base on the block at rest per unit mass [m/s^2].

    It is the effective gravity g + a_v, whatever the state.
    """
    return gravity


MODEL = RockingModel(
    name="housner", kernel_code=HOUSNER, kappa=0.75, needs_foundation=False, is_rigid_base=True,
    uses_restitution=True, uplift_is_rigid_threshold=True,
    default_restitution=lambda block: block.housner_restitution(),
    label="Housner (rigid base)",
    description="rigid base (Housner 1963); impacts dissipate with r = 1 - 1.5 sin^2(alpha)")
