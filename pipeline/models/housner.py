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
the pivot is kept, as in the tied model, but carries no friction.

The landing with friction (``friction_impact``): at theta = 0 the corner -sigma lands and the old pivot sigma
lifts. Per unit mass, with the new corner at (-sigma b, -h) from the centre of mass c, c's velocity
(u' + h theta', sigma b theta') before the landing and (u'+ + h theta'+, -sigma b theta'+) after it (rocking
on the new corner, which lands plastically: Housner 1963), the ground's impulse (P_x, P_z) on the new corner
obeys (Shenton & Jones 1991's Newton-Euler equations integrated over the impact)

    linear momentum:           u'+ + h theta'+ - (u' + h theta') = P_x,    -sigma b (theta'+ + theta') = P_z,
    angular momentum about c:  j_c (theta'+ - theta') = sigma b P_z - h P_x;

eliminating P, the angular momentum about the new corner is kept:
(j_c + R^2) theta'+ + h u'+ = (j_c + h^2 - b^2) theta' + h u'. In the corner's velocities (v_t, v_n) = (u',
2 sigma b theta') the impulse acts through W_tt = 1 + h^2/j_c, W_tn = -sigma b h/j_c, W_nn = 1 + b^2/j_c:
dv_t = W_tt dP_x + W_tn dP_z, dv_n = W_tn dP_x + W_nn dP_z. The landing's mode is chosen by Coulomb's law on
the impulses, as Shenton & Jones (1991) and Shenton (1996) choose the contact mode from the forces (rocking with
sliding under pulses: Zhang & Makris 2001):

1. Stick (u'+ = 0): theta'+ = r theta' + h u' / (j_c + R^2), r = (j_c + h^2 - b^2)/(j_c + R^2) =
   1 - 1.5 sin^2(alpha) (Housner's; the ``restitution`` option replaces it). Kept only if the normal impulse is
   compressive, P_z > 0, |P_x| <= mu_s P_z, and the block goes on turning onto the new corner (sigma theta'+ <= 0).
   (Before issue 32 the stick was kept whatever the sign of P_z: in fast slide-rock a landing of the trailing
   corner then needed a ground that pulls, and it cancelled the slip rate in one impact.)
2. Else a kinetic sliding impact: P_x = eta P_z, eta = -mu_k s, s the direction of the slip (that of u', or
   where u' = 0 the one in which the stuck corner would slip, against its P_x), until v_n = 0:
   theta'+ = theta' (j_c - b^2 + sigma eta h b)/(j_c + b^2 - sigma eta h b) (denominator >= (2b - h)^2/3 > 0
   for mu_k <= 4/3: P_z > 0 always), u'+ = u' + h (theta' - theta'+) + eta P_z.
   If the slip would change sign, it halts within the impact (Routh's construction, Wang & Mason 1992): at
   P_z0 = -u'/(W_tt eta + W_tn) the corner stops, and the rest of the impact (to v_n = 0) sticks along the
   ratio rho = sigma b h/(j_c + h^2) if |rho| <= mu_s (the plastic stick, Housner's r), else slides back with
   -eta. With Housner's r this happens only where |rho| > mu_s (which needs mu_s < b/h: a block that cannot
   rock from rest); with a smaller ``restitution`` also where its stick was refused.
3. If that landing turns the block back (sigma theta'+ > 0: the old corner would go into the ground), both
   corners land: a plastic flat landing, theta'+ = 0, P_z = -sigma b theta' shared by the corners. The base
   stops if |u' + h theta'| <= mu_s P_z and both corners' normal impulses are >= 0 (per unit mass, 2 b P_new =
   (b^2 + j_c) w - sigma h D and 2 b P_old = (b^2 - j_c) w + sigma h D, w = -sigma theta', D = u' + h theta'),
   else u'+ = D - mu_k P_z sign(D). A kinetic landing of the trailing corner turns back where
   1 - 2 (b/h)^2 - 3 mu_k b/h < 0, e.g. the paper's block (b/h 0.47) on steel (mu_k 0.40).

Every landing this rule keeps has compressive normal impulses, friction within the cone (sticking) or at mu_k
(sliding) and loses energy wherever mu_s >= b/h and the restitution is at most Housner's: checked on 1,600 random
blocks and frictions (b/h 0.1-1.3, mu_k up to 4/3), 300 landings each, with restitutions 0.6, 0.8, 1 and 1.05 r
(a restitution above Housner's gains energy in some sticking landings with slip: 3.5% of the landings at 1.05 r).
tests/physics/test_slide_rock_landings.py checks the rule against the scipy reference on a grid of states. Where
mu_s < b/h (a block that rocks only from an initial tilt) a few landings have no consistent mode among these and
take the one the rule reaches.
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
def flat_landing(sigma, x, params):
    """Both corners land (a plastic flat landing from pivot sigma at theta = 0): theta' (x[1]) <- 0, new slip rate.

    The centre's vertical velocity sigma b theta' stops (normal impulse P_z = -sigma b theta' > 0 per unit mass);
    the base stops if the horizontal impulse that needs, |u' + h theta'|, is within mu_s P_z and leaves both corners'
    normal impulses >= 0, else slides on with the kinetic impulse mu_k P_z against it (module docstring, case 3).
    """
    b = params["b"]
    spin = -sigma * x[1]  # > 0
    normal = b * spin
    drift = x[5] + params["h"] * x[1]  # the centre's horizontal velocity: the base's after a flat landing
    # a stuck base (horizontal impulse -drift) needs both corners to push: 2 b P_new, 2 b P_old >= 0
    moment = sigma * params["h"] * drift
    inertia = central_inertia(params)
    pushes = (b * b + inertia) * spin - moment >= 0.0 and (b * b - inertia) * spin + moment >= 0.0
    if abs(drift) <= params["mu_s"] * normal and pushes:
        x[5] = 0.0
    else:
        x[5] = drift - math.copysign(params["mu_k"] * normal, drift)
    x[1] = 0.0


@kernel
def impulse_segment(sigma, rate, tangential, normal, eta, to_halt, params):
    """Part of a landing on corner -sigma at the impulse ratio P_x / P_z = eta: (theta', v_t, v_n) at its end.

    From theta' = rate and the new corner's velocities v_t = ``tangential`` (its slip rate) and v_n = ``normal``
    [m/s] until v_n = 0 (the end of the plastic landing) or, ``to_halt``, until v_t = 0 (module docstring).
    """
    b = params["b"]
    h = params["h"]
    inertia = central_inertia(params)
    coupling = -sigma * b * h / inertia  # W_tn
    tangential_slope = eta * (1.0 + h * h / inertia) + coupling  # dv_t / dP_z
    normal_slope = eta * coupling + 1.0 + b * b / inertia  # dv_n / dP_z
    impulse = -tangential / tangential_slope if to_halt else -normal / normal_slope
    return (rate + (sigma * b - h * eta) * impulse / inertia, tangential + tangential_slope * impulse,
            normal + normal_slope * impulse)


@kernel
def friction_impact(sigma, x, params):
    """Impact at theta = 0 onto the corner -sigma with friction: new theta' (x[1]) and slip rate (x[5]).

    Returns True when the block lands flat (both corners down, theta' = 0). The rule, its impulse equations and
    their sources are in the module docstring: the new corner sticks if the impulse that needs is compressive and
    within mu_s; else it slides with the kinetic impulse against its slip (halting within the impact if that stops
    it); a landing that would turn the block back onto the old corner lands it flat.
    """
    b = params["b"]
    h = params["h"]
    inertia = central_inertia(params)
    radius = params["R"]
    rate = x[1]
    slip_rate = x[5]
    new_rate = params["restitution"] * rate + h * slip_rate / (inertia + radius * radius)
    new_slip_rate = 0.0
    normal = -sigma * b * (new_rate + rate)
    horizontal = h * (new_rate - rate) - slip_rate
    if not (normal > 0.0 and abs(horizontal) <= params["mu_s"] * normal and sigma * new_rate <= 0.0):
        if slip_rate != 0.0:
            direction = 1.0 if slip_rate > 0.0 else -1.0
        else:
            direction = -1.0 if horizontal > 0.0 else 1.0  # where the stuck corner would slip: against its impulse
        eta = -params["mu_k"] * direction
        approach = 2.0 * sigma * b * rate  # the new corner's vertical velocity before the landing
        new_rate, new_slip_rate, _ = impulse_segment(sigma, rate, slip_rate, approach, eta, False, params)
        if new_slip_rate * direction < 0.0:  # the slip halts within the impact (Routh): stick or slide back
            halted_rate, _, halted_normal = impulse_segment(sigma, rate, slip_rate, approach, eta, True, params)
            rho = sigma * b * h / (inertia + h * h)
            stuck = abs(rho) <= params["mu_s"]
            new_rate, new_slip_rate, _ = impulse_segment(sigma, halted_rate, 0.0, halted_normal,
                                                         rho if stuck else -eta, False, params)
            if stuck:
                new_slip_rate = 0.0  # (it is, to rounding)
    if sigma * new_rate > 0.0:
        flat_landing(sigma, x, params)
        return True
    x[1] = new_rate
    x[5] = new_slip_rate
    return False


MODEL = RockingModel(
    name="housner", kernel_code=HOUSNER, kappa=0.75, needs_foundation=False, is_rigid_base=True,
    uses_restitution=True, uplift_is_rigid_threshold=True,
    default_restitution=lambda block: block.housner_restitution(),
    slides=True,
    label="Housner (rigid base)",
    description="rigid base (Housner 1963); impacts dissipate with r = 1 - 1.5 sin^2(alpha)")
