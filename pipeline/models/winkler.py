"""rockfrag.models.winkler - a rigid block on a tensionless viscoelastic Winkler bed.

Input : block (b, h, m), the bed's total vertical stiffness K [N/m] (eq. 19, as for ``ssi``), its
        damping ratio xi [-] relative to the vertical mode (total dashpot C = 2 xi sqrt(K m)) and the
        bed's contact law, a registered law of rockfrag.models.contact: ``continuous`` (K spread
        uniformly over the footprint width 2b, bed_continuous.py), ``two-spring`` (K/2 and C/2 at
        each corner, the classic Psycharis & Jennings 1983 / Chopra & Yim 1985 model, bed_two_spring.py)
        or ``hunt-crossley`` (the continuous springs with Hunt-Crossley damping, bed_hunt_crossley.py).
Output: registered model ``winkler`` and its compiled physics: ``bed_force``, ``accelerations``,
        ``winkler_rhs``, ``winkler_slip_rhs``, ``stick_forces``, ``settled_beyond_reach``, ``friction_demand``.

Why: the paper's model puts one linear spring-dashpot under the active pivot, and that spring pulls
the block down whenever it rebounds, which real ground cannot do. Here every point of the base
carries pressure = max(0, k delta + c delta') while it is in the ground (delta > 0) and nothing
otherwise: the contact opens by itself, the block tilts elastically before it uplifts, it can leave
the ground entirely (flight), and impacts dissipate through the bed's damping - no impact rule (a
restitution can instead be the target to which rockfrag.models.restitution calibrates xi).

Coordinates: theta (> 0 tilts towards +x: the +b corner presses in) and y, the settlement of the
base centre (positive down; static y = m g / K). No sliding: the base centre follows the ground
horizontally (unless friction is given, below). When the block rocks on a corner that corner therefore
slips by b (1 - cos theta), a second-order effect; ``friction_demand`` reports |H|/N, the friction
coefficient needed to hold the base, so a user sees where the no-sliding assumption is strained.

Base point s in [-b, b]: penetration delta(s) = y + s sin(theta), rate y' + s cos(theta) theta'.
With j = J/m = (b^2 + 4 h^2)/3 (inertia about the base centre over m), F and M the bed's vertical
force and its moment about the base centre (per unit mass), the Lagrangian

    T = m/2 [(xg' + h cos(th) th')^2 + (y' + h sin(th) th')^2] + I_c th'^2 / 2,
    V = m g (h cos(th) - y) + bed energy,   Q_y = -F m,  Q_th = -cos(th) M m

gives (tests/physics/test_winkler*.py checks this with sympy)

    j th'' + h sin(th) y'' = g h sin(th) - h cos(th) ag - cos(th) M
    h sin(th) th'' + y''   = g - F - h cos(th) th'^2.

With Coulomb friction (``params["mu_s"] > 0``, static mu_s >= kinetic mu_k) the base centre may slide by u
relative to the ground. The friction is the horizontal force H of the bed, bounded by the bed's normal
force: |H| <= mu_s F while the base is stuck (u' = 0: the equations above, H = ag + h cos(th) th'' -
h sin(th) th'^2, ``stick_forces``), H = eta F with eta = -mu_k sign(u') while it slides. Like the tied
base, the friction acts at the base centre's level and the slip is the base centre's: a contact point
s of the base moves by u - s sin(th) th' horizontally, which differs from u' by the same second-order
term the tied model neglects. In flight F = 0, so H = 0 and the block moves freely. Sliding, the
Newton-Euler equations per unit mass with j_c = (b^2 + h^2)/3 are explicit (``winkler_slip_rhs``):

    j_c th'' = h sin(th) F - cos(th) M - h cos(th) H,
    y''      = g - F - h sin(th) th'' - h cos(th) th'^2,
    u''      = H - ag - h cos(th) th'' + h sin(th) th'^2.

u'' grows with eta (d u''/d eta = F (1 + h cos(th) (h cos(th) + e sin(th)) / j_c) > 0 for any eccentricity
|e| <= b), so the slip after a stop is always the one opposite to the stuck force: no Painleve paradox.
"""

from __future__ import annotations

import math

from rockfrag.models.base import RockingModel
from rockfrag.models.contact import FIRST_PLUGIN, bed_force_at, bed_full_contact
from rockfrag.models.fields import WINKLER
from rockfrag.models.jit import kernel


@kernel
def bed_force(x, params):
    """Vertical force F and its moment M about the base centre, both per unit mass, for state x.

    F [m/s^2] pushes the block up; M [m^2/s^2] is int q(s) s ds (positive when the +b side carries more).
    The bed's contact law (``params["bed"]``, rockfrag.models.contact) gives them.
    """
    return bed_force_at(x, params, math.sin(x[0]), math.cos(x[0]))


@kernel
def accelerations(theta, theta_dot, y, y_dot, ag, force, moment, h, j, g):
    """(theta'', y'') from the two equations of motion (module docstring); force, moment per mass."""
    return accelerations_at(math.sin(theta), math.cos(theta), theta_dot, ag, force, moment, h, j, g)


@kernel
def accelerations_at(sin_t, cos_t, theta_dot, ag, force, moment, h, j, g):
    """``accelerations`` with sin(theta) and cos(theta) already known."""
    vertical = g - force - h * cos_t * theta_dot * theta_dot
    rotational = g * h * sin_t - h * cos_t * ag - cos_t * moment
    determinant = j - h * h * sin_t * sin_t
    theta_acc = (rotational - h * sin_t * vertical) / determinant
    y_acc = (j * vertical - h * sin_t * rotational) / determinant
    return theta_acc, y_acc


@kernel
def winkler_rhs(x, accel, gravity, params, out):
    """dx/dt for x = [theta, theta', y, y']; accel: horizontal ground acceleration, gravity: g + a_v [m/s^2]."""
    h = params["h"]
    b = params["b"]
    sin_t = math.sin(x[0])
    cos_t = math.cos(x[0])
    force, moment = bed_force_at(x, params, sin_t, cos_t)
    theta_acc, y_acc = accelerations_at(sin_t, cos_t, x[1], accel, force, moment, h,
                                        (b * b + 4.0 * h * h) / 3.0, gravity)
    out[0] = x[1]
    out[1] = theta_acc
    out[2] = x[3]
    out[3] = y_acc


@kernel
def winkler_slip_rhs(slip, x, accel, gravity, params, out):
    """dx/dt while the base slides in direction ``slip`` (+1, -1): the friction is -mu_k slip F (docstring)."""
    h = params["h"]
    b = params["b"]
    sin_t = math.sin(x[0])
    cos_t = math.cos(x[0])
    force, moment = bed_force_at(x, params, sin_t, cos_t)
    horizontal = -params["mu_k"] * slip * force
    rate2 = x[1] * x[1]
    theta_acc = (h * sin_t * force - cos_t * moment - h * cos_t * horizontal) / ((b * b + h * h) / 3.0)
    out[0] = x[1]
    out[1] = theta_acc
    out[2] = x[3]
    out[3] = gravity - force - h * sin_t * theta_acc - h * cos_t * rate2
    out[4] = x[5]
    out[5] = horizontal - accel - h * cos_t * theta_acc + h * sin_t * rate2


@kernel
def stick_forces(x, accel, gravity, params):
    """(H, F) per unit mass [m/s^2]: the horizontal force a stuck base needs and the bed's normal force."""
    h = params["h"]
    b = params["b"]
    sin_t = math.sin(x[0])
    cos_t = math.cos(x[0])
    force, moment = bed_force_at(x, params, sin_t, cos_t)
    theta_acc, _ = accelerations_at(sin_t, cos_t, x[1], accel, force, moment, h, (b * b + 4.0 * h * h) / 3.0,
                                    gravity)
    return accel + h * cos_t * theta_acc - h * sin_t * x[1] * x[1], force


@kernel
def settled_beyond_reach(x, params, peak_angle):
    """True when the settled block can no longer reach its recorded peak angle nor lift a corner.

    That is, with the ground at rest and the base in full contact, its energy above the settled state is
    below a quarter of the elastic energy of either (small-tilt stiffness of the bed, K_r - m g h). The
    bed only dissipates, so the rest of the response cannot change the peak angle, uplift or flights; the
    batch kernels (which keep no history) stop there.
    """
    if params["bed"] >= FIRST_PLUGIN:
        return False  # the settled state below is a linear bed's: a plugin's law runs to the end of the record
    b = params["b"]
    h = params["h"]
    g = params["g"]
    omega = params["omega"]
    stiffness = omega * omega  # K/m
    sin_t = math.sin(x[0])
    rocking_stiffness, bed = bed_full_contact(x, params, sin_t)  # the caller checks: the whole base is down
    tilt_stiffness = rocking_stiffness - g * h
    if tilt_stiffness <= 0.0:
        return False  # the bed cannot even hold the block upright elastically
    y_static = g / stiffness
    cos_t = math.cos(x[0])
    j = (b * b + 4.0 * h * h) / 3.0
    kinetic = 0.5 * ((h * cos_t * x[1]) ** 2 + (x[3] + h * sin_t * x[1]) ** 2 + (j - h * h) * x[1] * x[1])
    excess = kinetic + g * (h * cos_t - x[2]) + bed - (g * (h - y_static) + 0.5 * stiffness * y_static * y_static)
    lift_angle = y_static / b  # a corner lifts at about this tilt (settled base)
    reach = 0.25 * 0.5 * tilt_stiffness * min(peak_angle, lift_angle) ** 2
    return excess < reach


@kernel
def friction_demand(x, dx, accel, force, params):
    """|H| / N: friction coefficient needed to hold the base centre against sliding.

    H/m = ag + d^2/dt^2 (h sin theta) = ag + h cos(theta) theta'' - h sin(theta) theta'^2; N/m = force.
    """
    h = params["h"]
    horizontal = accel + h * math.cos(x[0]) * dx[1] - h * math.sin(x[0]) * x[1] * x[1]
    return abs(horizontal) / force


MODEL = RockingModel(
    name="winkler", kernel_code=WINKLER, kappa=0.75, needs_foundation=True, uses_bed=True,
    uplift_is_rigid_threshold=False, slides=True,
    default_restitution=lambda block: 1.0,
    label="Winkler bed, tensionless",
    description="rigid block on a tensionless viscoelastic Winkler bed (continuous, two springs or "
                "Hunt-Crossley); the bed never pulls, impacts dissipate through its damping")
