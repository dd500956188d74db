"""rockfrag.models.contact - the registry of the bed contact laws: the one place a new law is added.

Input : a law's option name (``SolverOptions.bed``) on the Python side; in the kernels, the law code
        in the parameter record (``params["bed"]``) and the state x = [theta, theta_dot, y, y_dot].
Output: ``LAWS`` (law code -> module), ``BED_LAWS`` (option name -> law code) and the compiled
        dispatchers that the bed model and its time loop call: ``bed_force_at``, ``contact_indicator``,
        ``contact_indicators`` and ``bed_full_contact``.

A contact law says how the ground pushes on the base of the block. Each law is one module with its
option name ``NAME`` and the same four compiled hooks (all per unit mass; bed_continuous.py is the
worked example):

    force(x, params, sin_t, cos_t) -> (F, M)   vertical force [m/s^2], its moment about the base centre
                                                [m^2/s^2]; the hot call (every right-hand side)
    indicator(index, x, params) -> value       contact indicator ``index``: its sign changes where the
                                                contact changes (located as an event)
    indicators(x, params, out)                  all N_CONTACT_INDICATORS at once (at every step's end)
    full_contact(x, params, sin_t)              (K_r/m, V/m): small-tilt rocking stiffness about the
        -> (stiffness, energy)                  base centre and elastic energy, whole base in the ground

Indicators 0 and 1 are the penetrations of the -b and +b corners [m] (the time loop reads them for
uplift, impacts and flights); 2 and 3 are the law's own, e.g. where a corner's force switches on or off.

Registering a law is one import, one code, one entry in ``LAWS`` and one branch in each dispatcher
below, all in this file; tests/physics/test_contact_registry.py checks that every registered law
reaches its own hooks through every dispatcher. numba cannot cache a kernel that receives functions
as arguments, so the dispatch is an if/elif on the integer law code, written out here once.
"""

from __future__ import annotations

from rockfrag.models import bed_continuous, bed_hunt_crossley, bed_two_spring
from rockfrag.models.jit import kernel

# contact indicators every law reports (see the module docstring)
N_CONTACT_INDICATORS = 4

# ---- the registration: one code per law, and its module (which names it and holds its hooks) ----
CONTINUOUS = 0  # Kelvin-Voigt bed spread over the footprint width
TWO_SPRING = 1  # Kelvin-Voigt springs at the two corners
HUNT_CROSSLEY = 2  # the continuous bed's springs with Hunt-Crossley damping (vanishing with the penetration)

LAWS = {CONTINUOUS: bed_continuous, TWO_SPRING: bed_two_spring, HUNT_CROSSLEY: bed_hunt_crossley}
BED_LAWS = {law.NAME: code for code, law in LAWS.items()}  # option name (SolverOptions.bed) -> law code

UNREGISTERED = "bed contact law code not registered in rockfrag.models.contact"


# ---- the dispatchers: one branch per registered law ---------------------------------------------

@kernel
def bed_force_at(x, params, sin_t, cos_t):
    """The law's ``force``: (F [m/s^2], M [m^2/s^2]) of the bed on the block, per unit mass."""
    law = params["bed"]
    if law == CONTINUOUS:
        return bed_continuous.force(x, params, sin_t, cos_t)
    if law == TWO_SPRING:
        return bed_two_spring.force(x, params, sin_t, cos_t)
    if law == HUNT_CROSSLEY:
        return bed_hunt_crossley.force(x, params, sin_t, cos_t)
    raise ValueError(UNREGISTERED)


@kernel
def contact_indicator(index, x, params):
    """The law's ``indicator``: contact indicator ``index`` at state x."""
    law = params["bed"]
    if law == CONTINUOUS:
        return bed_continuous.indicator(index, x, params)
    if law == TWO_SPRING:
        return bed_two_spring.indicator(index, x, params)
    if law == HUNT_CROSSLEY:
        return bed_hunt_crossley.indicator(index, x, params)
    raise ValueError(UNREGISTERED)


@kernel
def contact_indicators(x, params, out):
    """The law's ``indicators``: all N_CONTACT_INDICATORS values into out."""
    law = params["bed"]
    if law == CONTINUOUS:
        bed_continuous.indicators(x, params, out)
    elif law == TWO_SPRING:
        bed_two_spring.indicators(x, params, out)
    elif law == HUNT_CROSSLEY:
        bed_hunt_crossley.indicators(x, params, out)
    else:
        raise ValueError(UNREGISTERED)


@kernel
def bed_full_contact(x, params, sin_t):
    """The law's ``full_contact``: (rocking stiffness K_r/m, elastic energy V/m) [m^2/s^2], whole base down."""
    law = params["bed"]
    if law == CONTINUOUS:
        return bed_continuous.full_contact(x, params, sin_t)
    if law == TWO_SPRING:
        return bed_two_spring.full_contact(x, params, sin_t)
    if law == HUNT_CROSSLEY:
        return bed_hunt_crossley.full_contact(x, params, sin_t)
    raise ValueError(UNREGISTERED)
