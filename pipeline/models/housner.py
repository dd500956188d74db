"""rockfrag.models.housner - Housner's rigid-base rocking block (paper eqs. 1-6).

Input : block (R, alpha), ground acceleration. Output: registered model ``housner`` and its
compiled physics: ``housner_rhs`` (rocking), ``housner_rest_rhs`` and ``housner_support``.

theta'' = -p^2 [sin(sigma alpha - theta) + (ag/g) cos(sigma alpha - theta)], p^2 = 3g/(4R), sigma
the active pivot. At rest until |ag| > g tan(alpha); at each impact (theta = 0) theta' <- r theta'
with r = 1 - 1.5 sin^2(alpha) by default (angular momentum about the new corner), pivot switches.

With a vertical ground acceleration a_v (up positive) g is g + a_v(t) throughout, in the ground's
frame: theta'' = -(3/4R) [(g + a_v) sin A + ag cos A] (from the Lagrangian with the base moving
vertically, tests/physics/test_equations_of_motion.py) and uplift at |ag| > (g + a_v) tan(alpha).

With Coulomb friction at the base (``params["mu_s"] > 0``; static mu_s >= kinetic mu_k) the base may slide:
u is the slip of the contact corner relative to the ground, counted as if the block were flat on it
(the pivot's position minus sigma b, so u is continuous through a pivot switch). Per unit mass, with the
centre of mass at (X, Z) = (-sigma b cos(theta) + h sin(theta), sigma b sin(theta) + h cos(theta)) from
the pivot, j_c = I_c / m = R^2 (1/kappa - 1), the pivot's horizontal force H and vertical force V obey
(Newton-Euler; Shenton & Jones 1991)

    u'' + Z theta'' - X theta'^2 = H - ag,    -X theta'' - Z theta'^2 = V - g,    j_c theta'' = X V - Z H.

Rocking on a stuck pivot (u'' = 0) gives Housner's equation, and H, V (``rock_forces``) must satisfy
|H| <= mu_s V. Slide-rock: H = eta V, eta = -mu_k sign(u') (``housner_slide_rock_rhs``); a flat slide:
theta = 0, V = g, u'' = -ag - mu_k g sign(u') (``housner_slide_rhs``). A slide-rock motion always
exists for mu_k <= 4/3 (its inertia term j_c + X (X - Z eta) >= R^2 (5/6 - sqrt(1 + mu_k^2)/2) > 0;
above that Painleve's paradox can occur), which the option's range ensures. Where V would be negative
the pivot is kept, as in the tied model, but carries no friction. The impact rule with friction
(``friction_impact``): the new corner lands plastically (Housner's assumption); if the impulse it
needs stays within mu_s of the normal impulse it sticks and theta' <- r theta' + h u'/(j_c + R^2)
(angular momentum about the new corner; r's value for u' = 0), otherwise it slides with the kinetic
impulse ratio.
"""

import math

from rockfrag.models.base import RockingModel
from rockfrag.models.fields import HOUSNER
from rockfrag.models.jit import kernel


@kernel
def housner_rhs(sigma, x, accel, gravity, params, out):
    """dx/dt while rocking on pivot sigma: theta'' = -(kappa/R)(g sin A + ag cos A), A = sigma alpha - theta.

    accel: horizontal ground acceleration [m/s^2]; gravity: g + a_v, the effective gravity [m/s^2].
    """
    angle = sigma * params["alpha"] - x[0]
    out[0] = x[1]
    out[1] = -params["kappa"] * (gravity * math.sin(angle) + accel * math.cos(angle)) / params["R"]
    out[2] = 0.0
    out[3] = 0.0


@kernel
def housner_rest_rhs(out):
    """dx/dt at rest on a rigid base: nothing moves."""
    for i in range(out.size):
        out[i] = 0.0


@kernel
def housner_support(gravity):
    """Vertical force of the rigid base on the block at rest per unit mass [m/s^2].

    It is the effective gravity g + a_v, whatever the state.
    """
    return gravity


@kernel
def pivot_arm(sigma, theta, params):
    """(X, Z) [m]: the centre of mass relative to pivot sigma (horizontal, vertical), at tilt theta."""
    b = params["b"]
    h = params["h"]
    sin_t = math.sin(theta)
    cos_t = math.cos(theta)
    return -sigma * b * cos_t + h * sin_t, sigma * b * sin_t + h * cos_t


@kernel
def central_inertia(params):
    """I_c / m [m^2], the block's moment of inertia about its centre of mass per unit mass."""
    return params["R"] * params["R"] * (1.0 / params["kappa"] - 1.0)


@kernel
def rock_forces(sigma, theta, theta_dot, accel, gravity, params):
    """(H, V) per unit mass [m/s^2]: the pivot's horizontal and vertical force while rocking on stuck pivot sigma.

    H pushes the block towards +x; theta'' is Housner's. accel: ag; gravity: g + a_v [m/s^2].
    """
    arm_x, arm_z = pivot_arm(sigma, theta, params)
    radius = params["R"]
    theta_acc = params["kappa"] * (arm_x * gravity - arm_z * accel) / (radius * radius)
    rate2 = theta_dot * theta_dot
    return accel + arm_z * theta_acc - arm_x * rate2, gravity - arm_x * theta_acc - arm_z * rate2


@kernel
def slide_rock_accelerations(sigma, slip, theta, theta_dot, gravity, params):
    """(theta'', V, eta) rocking on pivot sigma that slides in direction ``slip`` (+1, -1); V per unit mass.

    eta = -mu_k slip is the friction ratio H / V; it is 0 where V would be negative (no normal force).
    """
    arm_x, arm_z = pivot_arm(sigma, theta, params)
    inertia = central_inertia(params)
    rate2 = theta_dot * theta_dot
    eta = -params["mu_k"] * slip
    lever = arm_x - arm_z * eta
    theta_acc = lever * (gravity - arm_z * rate2) / (inertia + arm_x * lever)
    normal = gravity - arm_x * theta_acc - arm_z * rate2
    if normal < 0.0:
        eta = 0.0
        theta_acc = arm_x * (gravity - arm_z * rate2) / (inertia + arm_x * arm_x)
        normal = gravity - arm_x * theta_acc - arm_z * rate2
    return theta_acc, normal, eta


@kernel
def housner_slide_rock_rhs(sigma, slip, x, accel, gravity, params, out):
    """dx/dt rocking on pivot sigma while it slides in direction ``slip``: the pivot's friction is eta V."""
    theta_acc, normal, eta = slide_rock_accelerations(sigma, slip, x[0], x[1], gravity, params)
    arm_x, arm_z = pivot_arm(sigma, x[0], params)
    out[0] = x[1]
    out[1] = theta_acc
    out[2] = 0.0
    out[3] = 0.0
    out[4] = x[5]
    out[5] = eta * normal - accel - (arm_z * theta_acc - arm_x * x[1] * x[1])


@kernel
def housner_slide_rhs(slip, x, accel, gravity, params, out):
    """dx/dt sliding flat in direction ``slip``: u'' = -ag - mu_k (g + a_v) slip."""
    for i in range(4):
        out[i] = 0.0
    out[4] = x[5]
    out[5] = -accel - params["mu_k"] * slip * gravity


@kernel
def friction_impact(sigma, x, params):
    """Impact at theta = 0 onto the corner -sigma with friction: new theta' (x[1]) and slip rate (x[5]).

    The new corner lands plastically and the old one lifts (Housner). Impulses (per unit mass) from
    v_cm+ - v_cm- = (P_x, P_z) and j_c (theta'+ - theta'-) = sigma b P_z - h P_x (module docstring). Sticking
    (new corner stops): theta'+ = r theta'- + h u'- / (j_c + R^2), kept if |P_x| <= mu_s P_z; otherwise the
    corner slides with P_x = eta P_z, eta = -mu_k (direction of slip).
    """
    b = params["b"]
    h = params["h"]
    inertia = central_inertia(params)
    radius = params["R"]
    rate = x[1]
    slip_rate = x[5]
    stuck_rate = params["restitution"] * rate + h * slip_rate / (inertia + radius * radius)
    normal = -sigma * b * (stuck_rate + rate)
    horizontal = h * (stuck_rate - rate) - slip_rate
    if normal <= 0.0 or abs(horizontal) <= params["mu_s"] * normal:
        x[1] = stuck_rate
        x[5] = 0.0
        return
    direction = -1.0 if horizontal > 0.0 else 1.0  # the impulse needed opposes the corner's motion
    eta = -params["mu_k"] * direction
    new_rate = rate * (inertia - b * b + sigma * h * eta * b) / (inertia + b * b - sigma * h * eta * b)
    normal = -sigma * b * (new_rate + rate)
    new_slip_rate = slip_rate + h * (rate - new_rate) + eta * normal
    if new_slip_rate * direction < 0.0:
        new_slip_rate = 0.0  # the slip stops within the impact
    x[1] = new_rate
    x[5] = new_slip_rate


MODEL = RockingModel(
    name="housner", kernel_code=HOUSNER, kappa=0.75, needs_foundation=False, is_rigid_base=True,
    uses_restitution=True, uplift_is_rigid_threshold=True,
    default_restitution=lambda block: block.housner_restitution(),
    slides=True,
    label="Housner (rigid base)",
    description="rigid base (Housner 1963); impacts dissipate with r = 1 - 1.5 sin^2(alpha)")
