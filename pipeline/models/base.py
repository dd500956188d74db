"""rockfrag.models.base - the model contract, the outcome enum and the result object.

Input : nothing (definitions). Output: ``RockingModel`` (what a model registers), ``Outcome`` (the one
spelling of a run's outcome, used by the kernels, the cube's flag variable, IDA and fragility) and
``RockingResult`` (what ``simulate`` returns).

The contract for a model (as scipy's ``integrate/_ivp/base.py`` states its own), one module and one
``register`` call:

1. The module defines its physics as small compiled functions of plain arrays and a
   ``fields.PARAMS_DTYPE`` record, and names its kernel code (``fields.HOUSNER``, ``SSI``,
   ``WINKLER``); the kernels dispatch on that code, each model by name, never by exclusion
   (``kernels.rhs``, ``support``, ``static_settlement``, ...: a new kernel code is one branch in each).
2. Pivot models (``kernel_code`` HOUSNER or SSI) rest until the uplift condition, rock on one corner
   and switch pivot at theta = 0 through an impact rule; bed models (WINKLER) have no rest phase and
   no impact rule: their contact law does everything. A new contact law of the bed is one module and
   one registration in ``rockfrag.models.contact``, not a new model.
3. ``needs_foundation``: the model needs the interface stiffness k [N/m] and damping ratio xi [-];
   ``is_rigid_base``: its result does not depend on the soil (computed once per block).
4. ``uses_restitution``, ``uses_switch``, ``uses_bed``, ``slides``: which solver options apply
   (``slides``: the ``friction`` option, Coulomb friction at the base); a caller asks these instead of
   comparing model names.
5. ``uplift_is_rigid_threshold``: uplift happens exactly when |ag| = g tan(alpha) (at rest), so under
   PGA scaling the uplift fragility is a known step.
6. ``can_pull``: the foundation force can become negative (the paper's spring); the kernel reports
   ``min_support_force`` and ``time_of_tension`` so that runs past that moment can be flagged.
7. A run that overturns is an outcome (``Outcome.OVERTURNED``), not an error; ``Outcome.FAILED``
   means the integration stopped (step or event guard).
8. The ground may move vertically (``ag_vertical``, up positive): in the ground's frame gravity becomes
   g + a_v(t) wherever it acts on the block's mass (the model's right-hand sides and support force take
   that effective gravity; springs and dashpots act on relative motion and do not see it). Where
   g + a_v(t) < 0 the ground falls faster than gravity and the block is in free flight: pivot models
   have no flight phase and stop there with ``Outcome.FREE_FLIGHT``; bed models fly on.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Callable

import numpy as np


class Outcome(enum.IntEnum):
    """Outcome of one run, stored as a number in the summaries' ``status`` field and the cube."""

    NO_UPLIFT = 0
    ROCKING = 1
    OVERTURNED = 2
    FAILED = 3
    FREE_FLIGHT = 4  # g + a_v(t) < 0 under a pivot model: the run stops there (no flight phase)

    @property
    def flag_meaning(self) -> str:
        """The outcome's CF ``flag_meanings`` word (``no_uplift``, ``rocking``, ...)."""
        return {0: "no_uplift", 1: "rocking", 2: "overturned", 3: "solver_failed", 4: "free_flight"}[int(self)]


MESSAGES = {
    Outcome.NO_UPLIFT: "the block never uplifted",
    Outcome.ROCKING: "the block rocked and did not overturn",
    Outcome.OVERTURNED: "the block overturned (|theta| reached the overturning angle)",
    Outcome.FAILED: "integration stopped: too many events or steps (chatter or bad parameters)",
    Outcome.FREE_FLIGHT: "the ground fell faster than gravity (g + a_v < 0): the block left it in free flight, "
                         "which a pivot model does not follow; the run stops there",
}


@dataclass(frozen=True)
class RockingModel:
    """A registered rocking model: what a caller asks of it instead of comparing names.

    ``kernel_code`` dispatches the model in the compiled kernels (``fields.HOUSNER`` ...);
    ``default_restitution(block)`` gives the impact coefficient [-] when no ``restitution`` option is set;
    the flags say which inputs it reads (a foundation's k and xi, restitution, switch rule, bed law) and
    which checks apply (``can_pull``: its foundation spring can go into tension); ``slides``: it takes Coulomb
    friction at its base (the ``friction`` option; without it the base is tied horizontally).
    """

    name: str
    kernel_code: int
    kappa: float  # m R^2 / I_O of the pivot equation: 3/4 from I_O = 4/3 m R^2; p^2 = kappa g / R
    needs_foundation: bool
    default_restitution: Callable
    description: str
    label: str = ""
    is_rigid_base: bool = False
    uses_restitution: bool = False
    uses_switch: bool = False
    uses_bed: bool = False
    uplift_is_rigid_threshold: bool = True
    can_pull: bool = False
    slides: bool = False


@dataclass
class RockingResult:
    """Response of one block to one ground motion (SI units).

    Attributes
    ----------
    t : ndarray (n,) [s]; theta, theta_dot : ndarray (n,) [rad], [rad/s], NaN after overturning.
    y, y_dot : ndarray (n,) [m], [m/s] settlement (positive down) of the active pivot (ssi) or of the
        base centre (winkler); zeros for Housner.
    peak_angle [rad], peak_angle_ratio = peak_angle / alpha [-], time_of_peak [s],
    uplifted, overturned (bool), n_impacts, impact_times [s], time_of_uplift [s] (NaN if none),
    peak_settlement [m], min_support_force [N] (negative: the foundation pulled, ssi only),
    time_of_tension [s] (first time it pulled; NaN if never), n_flights, airborne_time [s],
    peak_uplift [m] (highest corner above the ground), peak_friction_demand [-] (winkler),
    time_of_free_flight [s] (first time g + a_v < 0; NaN if never), status (Outcome) and message.
    u, u_dot : ndarray (n,) [m], [m/s] horizontal slip of the base relative to the ground (zeros for a tied
        base; rigid base: of the contact corner as if flat on it, bed: of the base centre), NaN as theta.
    peak_slip, residual_slip [m]: peak and final absolute slip; mode_times [s]: the time spent in each
    contact mode, {"rest", "slide", "rock", "slide_rock", "flight"} (fields.MODE_NAMES).
    """

    model: str
    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    y: np.ndarray
    y_dot: np.ndarray
    peak_angle: float
    peak_angle_ratio: float
    time_of_peak: float
    uplifted: bool
    overturned: bool
    n_impacts: int
    impact_times: np.ndarray
    time_of_uplift: float
    peak_settlement: float
    min_support_force: float
    status: Outcome
    message: str
    n_steps: int = 0
    time_of_tension: float = float("nan")
    n_flights: int = 0
    airborne_time: float = 0.0
    peak_uplift: float = 0.0
    peak_friction_demand: float = 0.0
    time_of_free_flight: float = float("nan")
    u: np.ndarray = field(default_factory=lambda: np.zeros(0))
    u_dot: np.ndarray = field(default_factory=lambda: np.zeros(0))
    peak_slip: float = 0.0
    residual_slip: float = 0.0
    mode_times: dict = field(default_factory=dict)
    extra: dict = field(default_factory=dict)

    @property
    def success(self) -> bool:
        """False when the integration stopped on its guards (``Outcome.FAILED``)."""
        return self.status != Outcome.FAILED
