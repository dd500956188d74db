"""rockfrag.models.fields - the named fields that cross the compiled-kernel boundary.

Input : nothing (definitions). Output: ``PARAMS_DTYPE`` (what a kernel is told about one case),
``SUMMARY_FIELDS``/``SUMMARY_DTYPE`` (what it reports about one run), the layout of the state, the
model codes and the event kinds. (The codes of the bed contact laws are registered with the laws, in
rockfrag.models.contact.) Both records are NumPy structured dtypes: numba reads and writes their fields by name
(``params["alpha"]``, ``summary["peak_angle"]``), so no slot index leaks out of the kernels, and the
cube's variables are generated from ``SUMMARY_FIELDS`` (rockfrag.cube).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# The state every kernel integrates: x = [theta, theta_dot, y, y_dot, u, u_dot] (rotation [rad] and its
# rate [rad/s], settlement of the pivot or base centre [m, positive down] and its rate [m/s], horizontal
# slip of the base relative to the ground [m] and its rate [m/s]). A tied base (no friction) keeps u = 0
# and measures its step error over the first TIED_STATE_SIZE components only, so its numbers do not
# depend on the slip components. The slip u is that of the contact corner as if the block were flat on
# it (rigid base: the pivot's position minus sigma b) or of the base centre (bed models).
STATE_SIZE = 6
TIED_STATE_SIZE = 4
SLIP = 4       # index of u in the state
SLIP_RATE = 5  # index of u_dot

# Kernel codes: which right-hand side and which time loop a model uses (rockfrag.models.kernels
# dispatches on them; a model states its code in its ``RockingModel``).
HOUSNER = 0   # rigid base, pivot rocking with a restitution rule
SSI = 1       # one vertical spring-dashpot under the active pivot (the paper's model)
WINKLER = 2   # tensionless bed of vertical contact (rockfrag.models.contact: the bed's contact law)

# Pivot-switch rules of the SSI model at theta = 0.
SWITCH_CONSISTENT = 0
SWITCH_CONTINUOUS = 1

# Event kinds located inside a step.
EVENT_NONE = -1
EVENT_IMPACT = 0        # theta crosses 0 (pivot switch for pivot models; counted for winkler)
EVENT_OVERTURN = 1      # |theta| reaches the overturning angle
EVENT_UPLIFT = 2        # rest -> rocking (pivot models)
EVENT_SETTLE = 3        # a start that does not lift: back to rest (pivot models)
EVENT_CONTACT = 4       # a bed contact point opens or closes (winkler)
EVENT_SLIP_START = 5    # a stuck base needs more friction than mu_s N (friction models)
EVENT_SLIP_STOP = 6     # the slip rate of a sliding base reaches zero (friction models)

# Contact modes of a run with friction (the summaries' time_* fields): the base stuck and flat (or in full
# contact with a bed), sliding flat, rocking on a stuck corner, rocking on a sliding corner, all in the air.
MODE_REST = 0
MODE_SLIDE = 1
MODE_ROCK = 2
MODE_SLIDE_ROCK = 3
MODE_FLIGHT = 4
MODE_NAMES = ("rest", "slide", "rock", "slide_rock", "flight")

PARAMS_DTYPE = np.dtype([
    ("R", "f8"),            # semi-diagonal [m]
    ("alpha", "f8"),        # slenderness [rad]
    ("b", "f8"),            # half-width [m]
    ("h", "f8"),            # half-height [m]
    ("g", "f8"),            # gravity [m/s^2]
    ("kappa", "f8"),        # m R^2 / I_O of the pivot equation [-]; p^2 = kappa g / R
    ("omega", "f8"),        # sqrt(K/m) of the foundation [rad/s]; 0 for a rigid base
    ("xi", "f8"),           # damping ratio of the vertical foundation mode [-]
    ("restitution", "f8"),  # factor on theta' at each impact (pivot models)
    ("switch", "f8"),       # SWITCH_* (SSI)
    ("bed", "f8"),          # code of the bed's contact law (winkler; rockfrag.models.contact.BED_LAWS)
    ("bed_hooks", "f8"),    # a plugin law's compiled hooks in this process (rockfrag.models.contact.attach_hooks)
    ("overturn", "f8"),     # |theta| of overturning [rad]
    ("rtol", "f8"),         # relative error per step [-]
    ("atol", "f8"),         # absolute error per step as a fraction of each state's scale [-]
    ("zeno", "f8"),         # excursions below this angle end the rocking [rad] (pivot models)
    ("max_events", "f8"),   # chatter guard
    ("mu_s", "f8"),         # static friction coefficient of the base [-]; 0: the base is tied (no sliding)
    ("mu_k", "f8"),         # kinetic friction coefficient [-], 0 < mu_k <= mu_s (0 when tied)
])


@dataclass(frozen=True)
class SummaryField:
    """One summary field: its name, CF units and long name (the numba record and the cube's metadata)."""

    name: str
    units: str
    long_name: str
    per_mass: bool = False  # stored per unit mass in the kernel; the cube multiplies by the mass


MODE_TIMES = {
    "time_at_rest": "time with the base stuck and wholly on the ground",
    "time_sliding": "time with the base sliding and wholly on the ground",
    "time_rocking": "time rocking (part of the base lifted) on a stuck contact",
    "time_slide_rocking": "time rocking (part of the base lifted) on a sliding contact",
    "time_in_flight": "time with the whole base off the ground",
}
"""Summary field and long name of the time in each contact mode [s], in the order of the MODE_* codes."""

SUMMARY_FIELDS = (
    SummaryField("status", "1", "outcome of the run (rockfrag.models.base.Outcome)"),
    SummaryField("peak_angle", "rad", "peak absolute rocking angle"),
    SummaryField("time_of_peak", "s", "time of the peak rocking angle"),
    SummaryField("n_impacts", "1", "number of impacts (pivot switches; winkler: a lifted corner landing)"),
    SummaryField("uplifted", "1", "1 if some point of the base left the ground"),
    SummaryField("peak_settlement", "m",
                 "peak settlement of the active pivot (ssi) or of the base centre (winkler)"),
    SummaryField("min_support_force", "N",
                 "minimum vertical foundation force (negative: the foundation pulled on the block)",
                 per_mass=True),
    SummaryField("time_of_tension", "s", "first time the paper's spring pulled on the block (NaN: never)"),
    SummaryField("t_end", "s", "time reached by the integration"),
    SummaryField("n_steps", "1", "accepted integration steps"),
    SummaryField("time_of_uplift", "s", "time of first uplift (NaN: never uplifted)"),
    SummaryField("time_of_overturn", "s", "time of overturning (NaN: did not overturn)"),
    SummaryField("n_flights", "1", "times the whole base left the ground"),
    SummaryField("airborne_time", "s", "total time with the whole base off the ground"),
    SummaryField("peak_corner_uplift", "m", "peak height of a base corner above the ground"),
    SummaryField("peak_friction_demand", "1",
                 "peak |H|/N, the base friction coefficient needed to prevent sliding (while N >= 0.1 m g)"),
    SummaryField("time_of_free_flight", "s",
                 "first time g + a_v fell below zero, the ground falling faster than gravity (pivot models stop "
                 "there: outcome free_flight; NaN: never)"),
    SummaryField("peak_slip", "m", "peak absolute horizontal slip of the base relative to the ground (0: tied base)"),
    SummaryField("residual_slip", "m", "absolute horizontal slip of the base at the end of the run"),
    *(SummaryField(name, "s", long_name) for name, long_name in MODE_TIMES.items()),
)
MODE_TIME_FIELDS = tuple(MODE_TIMES)
"""The summary field of each contact mode, in the order of the MODE_* codes."""
FIELDS_BY_NAME = {field.name: field for field in SUMMARY_FIELDS}

SUMMARY_DTYPE = np.dtype([(field.name, "f8") for field in SUMMARY_FIELDS])


def new_params(shape=()) -> np.ndarray:
    """A zeroed parameter record (or array of records)."""
    return np.zeros(shape, dtype=PARAMS_DTYPE)


def new_summaries(shape=()) -> np.ndarray:
    """Summary records filled with NaN (a cell never computed reads as NaN)."""
    out = np.empty(shape, dtype=SUMMARY_DTYPE)
    for name in SUMMARY_DTYPE.names:
        out[name] = np.nan
    return out
