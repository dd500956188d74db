"""rockfrag.models.options - the solver options and the kernel's parameter record of one case.

Input : ``SolverOptions`` fields (validated once), a model, a ``Block``, the interface stiffness k [N/m]
        and the damping ratio xi [-].
Output: ``SolverOptions`` and its schema ``SOLVER_OPTIONS``; ``FOUNDATION`` (k and xi);
        ``case_record``, the parameter record (``fields.PARAMS_DTYPE``) and static initial state of one
        case with an explicit xi; ``pivot_restitution``, a ``restitution`` option as a number for a block;
        ``friction_coefficients``, a ``friction`` option as (mu_s, mu_k).

``rockfrag.models.parameter_record`` is ``case_record`` plus the calibration of a restitution target for
bed models (rockfrag.models.restitution), which runs ``case_record`` itself: this module is below both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rockfrag.blocks import Block
from rockfrag.errors import ConfigError, SolverError
from rockfrag.models import fields
from rockfrag.models.base import RockingModel
from rockfrag.models.bed_hunt_crossley import NAME as HUNT_CROSSLEY
from rockfrag.models.contact import BED_LAWS
from rockfrag.soils import MAX_KINETIC_FRICTION
from rockfrag.units import STANDARD_GRAVITY
from rockfrag.validation import Checked, Nullable, Number, Table, Text, shown

SWITCH_RULES = {"consistent": fields.SWITCH_CONSISTENT, "continuous": fields.SWITCH_CONTINUOUS}
BED_TYPES = BED_LAWS  # the winkler bed's contact laws, registered in rockfrag.models.contact

DEFAULT_RTOL = 1e-6  # relative error per step; peak angles agree with scipy at 1e-10 to ~1e-6
DEFAULT_ATOL = 1e-7  # absolute error per step, as a fraction of alpha, alpha*p, y_static, y_static*omega
DEFAULT_XI = 0.05
DEFAULT_ZENO_FRACTION = 1e-6  # excursions below this fraction of alpha end the rocking
MAX_EVENTS = 200_000

HOUSNER = "housner"  # restitution = "housner": Housner's r = 1 - 1.5 sin^2(alpha) of the block
RIGID_BASE_MAX_KINETIC_FRICTION = MAX_KINETIC_FRICTION
"""Largest kinetic friction coefficient of a rigid base (rockfrag.soils.MAX_KINETIC_FRICTION, 4/3). A bed has no
such limit."""
FRICTION_RANGE = "a number mu > 0 or a pair [mu_s, mu_k] with mu_s >= mu_k > 0 (static, kinetic)"
MAX_XI = {HUNT_CROSSLEY: 10.0}
"""Largest damping ratio xi of a bed law whose xi may reach 1 or more (default: xi < 1). Hunt-Crossley's
xi sets its damping at rest only (an overdamped vertical mode at rest is still a bed); its impacts need up
to a few on soft beds (rockfrag.models.restitution)."""


def _restitution_option(value, field: str, source: str | None):
    """A ``restitution`` option: a number from 0 to 1, or "housner" (Housner's value of each block)."""
    if isinstance(value, str):
        if value != HOUSNER:
            raise ConfigError(field, f"{value!r} unknown; must be a number from 0.0 to 1.0 or {HOUSNER!r}", source)
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(field, f"{shown(value)}; must be a number from 0.0 to 1.0 or {HOUSNER!r}", source)
    return Number(0.0, 1.0).check(value, field, source)


def _friction_option(value, field: str, source: str | None):
    """A ``friction`` option: one coefficient mu > 0 (static = kinetic) or a pair (mu_s, mu_k), mu_s >= mu_k > 0."""
    pair = (value, value) if isinstance(value, (int, float)) and not isinstance(value, bool) else value
    if not isinstance(pair, (tuple, list)) or len(pair) != 2:
        raise ConfigError(field, f"{shown(value)}; must be {FRICTION_RANGE}", source)
    for number in pair:
        if isinstance(number, bool) or not isinstance(number, (int, float)) or not math.isfinite(number) \
                or number <= 0:
            raise ConfigError(field, f"{value!r} out of range; must be {FRICTION_RANGE}", source)
    if pair[1] > pair[0]:
        raise ConfigError(field, f"{value!r} out of range: the kinetic coefficient {pair[1]:g} exceeds the "
                                 f"static one {pair[0]:g}; must be {FRICTION_RANGE}", source)
    return value


def friction_coefficients(friction) -> tuple[float, float]:
    """(mu_s, mu_k) [-] of a checked ``friction`` option; (0, 0) for None (the tied base).

    Parameters
    ----------
    friction : float or (float, float) or None
        One coefficient (static = kinetic) or the pair (static, kinetic).

    Returns
    -------
    tuple of float
        The static and kinetic coefficients.
    """
    if friction is None:
        return 0.0, 0.0
    if isinstance(friction, (int, float)):
        return float(friction), float(friction)
    return float(friction[0]), float(friction[1])


@dataclass(frozen=True)
class SolverOptions:
    """Settings shared by every case of a call (validated once).

    ``restitution``: pivot models, the impact coefficient (None: the model's default); bed models
    (winkler), the target of the calibrated bed dissipation (rockfrag.models.restitution; None: xi is
    given). A number, or "housner" for Housner's value 1 - 1.5 sin^2(alpha) of each block.
    ``friction``: Coulomb friction at the base of a model that ``slides`` (housner, winkler): one
    coefficient (static = kinetic) or (mu_s, mu_k); None ties the base horizontally (no sliding).
    """

    switch: str = "consistent"               # ssi pivot-switch rule: consistent | continuous
    bed: str = "continuous"                  # winkler bed: a law of rockfrag.models.contact
    restitution: float | str | None = None   # see the class docstring
    g: float = STANDARD_GRAVITY
    overturn_angle: float = math.pi / 2
    rtol: float = DEFAULT_RTOL
    atol: float = DEFAULT_ATOL
    friction: float | tuple[float, float] | None = None  # see the class docstring

    def __post_init__(self):
        check(SOLVER_OPTIONS, vars(self))


SOLVER_OPTIONS = Table({
    "switch": Text(tuple(SWITCH_RULES)),
    "bed": Text(tuple(BED_TYPES)),
    "restitution": Nullable(Checked(_restitution_option, f"a number from 0.0 to 1.0 or {HOUSNER!r}")),
    "g": Number(0.0, low_open=True, unit="m/s^2"),
    "overturn_angle": Number(0.0, math.pi / 2, low_open=True, unit="rad"),
    "rtol": Number(0.0, 1.0, low_open=True, high_open=True),
    "atol": Number(0.0, 1.0, low_open=True, high_open=True),
    "friction": Nullable(Checked(_friction_option, FRICTION_RANGE)),
})
"""The schema of ``SolverOptions`` (rockfrag.validation)."""
FOUNDATION = Table({"k": Number(0.0, low_open=True, unit="N/m"), "xi": Number(0.0, 1.0, high_open=True)})
"""The schema of a foundation's interface stiffness k and damping ratio xi (a law in ``MAX_XI``: xi up to that)."""


def check(schema: Table, values: dict) -> None:
    """Check solver arguments against ``schema``: a value out of range is a ``SolverError`` naming it."""
    try:
        schema.check(values, "", None)
    except ConfigError as error:
        raise SolverError(str(error)) from None


def pivot_restitution(model: RockingModel, block: Block, restitution: float | str | None) -> float:
    """The impact coefficient of a pivot model for ``block``.

    The option as a number ("housner": Housner's 1 - 1.5 sin^2(alpha)), or the model's default when None.
    """
    if restitution is None:
        return model.default_restitution(block)
    if restitution == HOUSNER:
        return block.housner_restitution()
    return float(restitution)


def case_record(model: RockingModel, block: Block, k=None, xi=None, options: SolverOptions = SolverOptions()):
    """The kernel's parameter record and initial state [theta, theta', y, y', u, u'] (static) for one case.

    The damping ratio xi is explicit (None: ``DEFAULT_XI``); a bed model's ``restitution`` option is not read
    here (rockfrag.models.parameter_record calibrates xi to it first).
    """
    params = fields.new_params(1)[0]
    mu_s, mu_k = friction_coefficients(options.friction)
    if options.friction is not None and not model.slides:
        raise SolverError(f"friction: model {model.name!r} has a tied base (no sliding); friction applies to "
                          "the models that slide (housner, winkler)")
    if model.is_rigid_base and mu_k > RIGID_BASE_MAX_KINETIC_FRICTION:
        raise SolverError(f"friction: the kinetic coefficient {mu_k:g} is out of range for the rigid base of "
                          f"{model.name!r}; must be > 0 and <= 4/3 (above it a block rocking on a sliding corner "
                          "can have no motion at all: Painleve's paradox)")
    omega = 0.0
    xi_value = 0.0
    y0 = 0.0
    if model.needs_foundation:
        if k is None:
            raise SolverError(f"model {model.name!r} needs the interface stiffness k [N/m]")
        xi_value = DEFAULT_XI if xi is None else xi
        schema = FOUNDATION
        if model.uses_bed and options.bed in MAX_XI:
            schema = Table({**FOUNDATION.fields, "xi": Number(0.0, MAX_XI[options.bed])})
        check(schema, {"k": k, "xi": xi_value})
        omega = math.sqrt(k / block.mass)
        y0 = options.g / omega**2  # static equilibrium: never drop the block onto an unloaded bed
    if model.uses_bed:
        restitution = model.default_restitution(block)  # no impact rule: the option is the calibration target
    else:
        restitution = pivot_restitution(model, block, options.restitution)
    params["R"] = block.R
    params["alpha"] = block.alpha
    params["b"] = block.b
    params["h"] = block.h
    params["g"] = options.g
    params["kappa"] = model.kappa
    params["omega"] = omega
    params["xi"] = xi_value
    params["restitution"] = restitution
    params["switch"] = SWITCH_RULES[options.switch]
    params["bed"] = BED_TYPES[options.bed]
    params["overturn"] = options.overturn_angle
    params["rtol"] = options.rtol
    params["atol"] = options.atol
    params["zeno"] = DEFAULT_ZENO_FRACTION * block.alpha
    params["max_events"] = MAX_EVENTS
    params["mu_s"] = mu_s
    params["mu_k"] = mu_k
    state = np.zeros(fields.STATE_SIZE)
    state[2] = y0
    return params, state
