"""pipeline.models.base - the model contract and the result object.

Input : nothing (definitions). Output: ``RockingModel`` (what a model registers), ``RockingResult``
(what ``simulate`` returns) and ``Status``.

Contract for a new model (one module, one ``register`` call):
1. It names a compiled kernel code (``kernels.HOUSNER`` or ``kernels.SSI``) and the inertia factor
   kappa of its rotational equation; the kernel owns the time loop, events and status.
2. ``needs_foundation`` says whether k [N/m] and xi [-] are required.
3. ``default_restitution(block)`` gives the velocity factor applied at each impact.
4. A result with status OVERTURNED is an outcome, not an error.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Callable

import numpy as np


class Status(enum.IntEnum):
    NO_UPLIFT = 0
    ROCKING = 1
    OVERTURNED = 2
    FAILED = 3


MESSAGES = {
    Status.NO_UPLIFT: "the block never uplifted",
    Status.ROCKING: "the block rocked and did not overturn",
    Status.OVERTURNED: "the block overturned (|theta| reached the overturning angle)",
    Status.FAILED: "integration stopped: too many events or steps (chatter or bad parameters)",
}


@dataclass(frozen=True)
class RockingModel:
    name: str
    kernel_code: int
    kappa: float  # theta'' = (kappa/R)(...): 3/4 from I_O = 4/3 m R^2
    needs_foundation: bool
    default_restitution: Callable
    description: str


@dataclass
class RockingResult:
    """Response of one block to one ground motion (SI units).

    Attributes
    ----------
    t : ndarray (n,) [s]; theta, theta_dot : ndarray (n,) [rad], [rad/s], NaN after overturning.
    y, y_dot : ndarray (n,) [m], [m/s] pivot settlement and its rate (SSI; zeros for Housner).
    peak_angle [rad], peak_angle_ratio = peak_angle / alpha [-], time_of_peak [s],
    uplifted, overturned (bool), n_impacts, impact_times [s], time_of_uplift [s] (NaN if none),
    peak_settlement [m] (SSI), min_support_force [N] (SSI; negative = tension, warned),
    status (Status) and message.
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
    status: Status
    message: str
    n_steps: int = 0
    extra: dict = field(default_factory=dict)

    @property
    def success(self) -> bool:
        return self.status != Status.FAILED
