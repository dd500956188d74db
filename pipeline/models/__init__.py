"""pipeline.models - stage 5: rocking solvers (Housner, the paper's SSI model, the Winkler bed).

Input : a model name, ground acceleration [m/s^2] sampled at dt [s] (optionally a vertical one,
        ``ag_vertical``, same sampling, up positive), a ``Block`` and, for models with a foundation,
        the interface stiffness k [N/m] and damping ratio xi [-] (winkler: or a target restitution that
        calibrates xi, pipeline.models.restitution).
Output: a ``RockingResult`` (histories, peak angle, impacts, overturning, foundation checks), or for
        many scale factors and cases at once summary records (``fields.SUMMARY_DTYPE``) from
        ``simulate_batch`` and ``simulate_histories``.

Models are a registry: ``MODELS[name]``; a new model is one module and one ``register`` call (the
contract is in pipeline/models/base.py). Callers ask the model object what it needs
(``needs_foundation``, ``is_rigid_base``, ``uses_bed`` ...) instead of comparing names.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np

from pipeline.blocks import Block
from pipeline.errors import SolverError
from pipeline.models import fields, kernels
from pipeline.models.base import MESSAGES, Outcome, RockingModel, RockingResult
from pipeline.models.contact import LAWS
from pipeline.models.fields import SUMMARY_DTYPE, SUMMARY_FIELDS, new_summaries
from pipeline.models.options import (  # noqa: F401  (the API)
    BED_TYPES,
    DEFAULT_ATOL,
    DEFAULT_RTOL,
    DEFAULT_XI,
    DEFAULT_ZENO_FRACTION,
    FOUNDATION,
    MAX_EVENTS,
    SOLVER_OPTIONS,
    SWITCH_RULES,
    SolverOptions,
    case_record,
)
from pipeline.models.restitution import calibrate_dissipation, calibrated_law, radiation_damping
from pipeline.units import STANDARD_GRAVITY

MODELS: dict[str, RockingModel] = {}

DEFAULT_TAIL = 10.0  # s of free vibration after the record
IMPACT_CAPACITY = 10_000


def register(model: RockingModel) -> None:
    MODELS[model.name] = model


def get_model(name: str) -> RockingModel:
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        raise SolverError(f"unknown model {name!r}; valid models are: {', '.join(MODELS)}") from None


def parameter_record(model: RockingModel, block: Block, k=None, xi=None, options=SolverOptions()):
    """The kernel's parameter record and initial state [theta, theta', y, y'] (static) for one case.

    A bed model (winkler) given ``options.restitution`` calibrates its bed's dissipation to that target
    (``restitution.calibrate_dissipation``, cached per block, stiffness, bed and target): xi is then an
    output, and the bed ``continuous`` takes its Hunt-Crossley damping (``restitution.calibrated_law``).
    """
    if model.uses_bed and options.restitution is not None:
        if xi is not None:
            raise SolverError(f"model {model.name!r}: give xi or restitution, not both (a restitution target "
                              f"calibrates xi; restitution = {options.restitution!r}, xi = {xi!r})")
        if k is None:
            raise SolverError(f"model {model.name!r} needs the interface stiffness k [N/m]")
        xi = calibrate_dissipation(block, k, options.bed, options.restitution, g=options.g)
        options = replace(options, bed=calibrated_law(options.bed), restitution=None)
    return case_record(model, block, k, xi, options)


def parameter_table(model: RockingModel, cases, options: SolverOptions):
    """Parameter records (n_case,) and initial states (n_case, STATE_SIZE) for (block, k, xi) cases."""
    if len(cases) == 0:
        raise SolverError("no (block, k, xi) case given")
    table = fields.new_params(len(cases))
    states = np.empty((len(cases), fields.STATE_SIZE))
    for row, (block, k, xi) in enumerate(cases):
        table[row], states[row] = parameter_record(model, block, k, xi, options)
    return table, states


def _ground(ag, dt):
    ag = np.ascontiguousarray(ag, dtype=np.float64)
    if ag.ndim != 1 or ag.size < 2:
        raise SolverError("ag must be a 1-D array of at least 2 samples [m/s^2]")
    if not np.all(np.isfinite(ag)):
        raise SolverError("ag contains NaN or infinite values")
    if not (dt > 0 and math.isfinite(dt)):
        raise SolverError(f"dt = {dt} [s]; must be > 0")
    return ag


def _vertical(ag_vertical, ag):
    """The vertical ground acceleration, sampled as ag (checked), or None."""
    if ag_vertical is None:
        return None
    ag_vertical = np.ascontiguousarray(ag_vertical, dtype=np.float64)
    if ag_vertical.shape != ag.shape:
        raise SolverError(f"ag_vertical has shape {ag_vertical.shape}; it must be sampled as ag, shape {ag.shape} "
                          "[m/s^2]")
    if not np.all(np.isfinite(ag_vertical)):
        raise SolverError("ag_vertical contains NaN or infinite values")
    return ag_vertical


def _time_window(ag, dt, t_end):
    """(ground motion cut to t_end, number of tail samples): the record plus DEFAULT_TAIL by default."""
    if t_end is None:
        t_end = (ag.size - 1) * dt + DEFAULT_TAIL
    if not (t_end >= 0 and math.isfinite(t_end)):
        raise SolverError(f"t_end = {t_end} [s]; must be >= 0")
    n_total = max(2, int(round(t_end / dt)) + 1)
    if n_total < ag.size:
        ag = ag[:n_total]
    return ag, max(0, n_total - ag.size)


def _motion(ag, dt, t_end, ag_vertical):
    """(samples, number of tail samples): the components checked, cut to t_end and stacked as the kernels
    take them, (1, n) or with the vertical (2, n) (rows ``kernels.HORIZONTAL``, ``kernels.VERTICAL``)."""
    ag = _ground(ag, dt)
    vertical = _vertical(ag_vertical, ag)
    ag, n_tail = _time_window(ag, dt, t_end)
    samples = np.empty((1 if vertical is None else 2, ag.size))
    samples[kernels.HORIZONTAL] = ag
    if vertical is not None:
        samples[kernels.VERTICAL] = vertical[:ag.size]
    return samples, n_tail


def simulate(model, ag, dt, block, *, ag_vertical=None, k=None, xi=None, theta0=0.0, thetadot0=0.0, t_end=None,
             **options) -> RockingResult:
    """Rocking response of ``block`` to ground acceleration ``ag`` [m/s^2] sampled at ``dt`` [s].

    Parameters
    ----------
    model : str
        ``housner``, ``ssi`` (the paper's model), ``ssi-paper`` (its printed equations) or ``winkler``
        (tensionless bed); see ``MODELS``.
    ag_vertical : array_like, optional
        Vertical ground acceleration [m/s^2, up positive], sampled as ``ag``: gravity becomes
        g + ag_vertical(t) in the ground's frame. Where g + ag_vertical < 0 the block is in free flight:
        the pivot models (housner, ssi) stop there with ``Outcome.FREE_FLIGHT``; winkler flies on.
        None (default) and zeros give the same numbers.
    k, xi : float
        Interface stiffness [N/m] (winkler: the bed's total vertical stiffness K) and damping ratio
        [-] (xi defaults to 0.05; winkler: c_total = 2 xi sqrt(K m); hunt-crossley: the same damping at
        rest). winkler with ``restitution``: xi is calibrated (give none), ``result.extra["xi"]``.
    theta0, thetadot0 : float
        Initial rotation [rad] and rate [rad/s] (free rocking).
    t_end : float, optional
        End time [s]; zero ground motion after the record. Default: record + 10 s.
    **options
        ``SolverOptions`` fields: ``switch`` (ssi: consistent | continuous), ``bed`` (winkler:
        continuous | two-spring | hunt-crossley), ``restitution`` (pivot models: the impact
        coefficient, Housner default 1 - 1.5 sin^2 alpha; winkler: the target effective restitution
        < 1 of free rocking to which the bed's damping is calibrated, the continuous bed with
        Hunt-Crossley damping; "housner" is 1 - 1.5 sin^2 alpha), ``g``, ``overturn_angle`` [rad]
        (default pi/2, terminal), ``rtol``, ``atol``.
    """
    spec = get_model(model)
    settings = SolverOptions(**options)
    samples, n_tail = _motion(ag, dt, t_end, ag_vertical)
    table, states = parameter_table(spec, [(block, k, xi)], settings)
    state = states[0]
    state[0], state[1] = float(theta0), float(thetadot0)
    history = np.empty((samples.shape[1] + n_tail, fields.STATE_SIZE))
    impacts = np.empty(IMPACT_CAPACITY)
    summaries = new_summaries(1)
    kernels.single_kernel(spec.kernel_code, samples, float(dt), n_tail, table, state, history, impacts, summaries)
    return _result(spec, block, dt, summaries[0], history, impacts, table[0])


def _result(spec, block, dt, summary, history, impacts, params):
    status = Outcome(int(summary["status"]))
    n_impacts = int(summary["n_impacts"])
    min_support = float(summary["min_support_force"]) * block.mass
    message = MESSAGES[status]
    if spec.can_pull and min_support < 0:
        message += f"; the foundation spring went into tension (min support force {min_support:.3g} N)"
        warnings.warn(f"{spec.name}: foundation spring in tension from t = {float(summary['time_of_tension']):.3f} s "
                      f"(min support force {min_support:.3g} N = "
                      f"{min_support / (block.mass * STANDARD_GRAVITY):.2g} W): "
                      "real ground cannot pull; results past that moment are not physical "
                      "(the 'winkler' model has a tensionless bed)", stacklevel=3)
    return RockingResult(
        model=spec.name, t=np.arange(history.shape[0]) * dt, theta=history[:, 0].copy(),
        theta_dot=history[:, 1].copy(), y=history[:, 2].copy(), y_dot=history[:, 3].copy(),
        peak_angle=float(summary["peak_angle"]),
        peak_angle_ratio=float(summary["peak_angle"] / block.alpha),
        time_of_peak=float(summary["time_of_peak"]),
        uplifted=bool(summary["uplifted"]), overturned=status == Outcome.OVERTURNED,
        n_impacts=n_impacts, impact_times=impacts[:min(n_impacts, impacts.size)].copy(),
        time_of_uplift=float(summary["time_of_uplift"]),
        peak_settlement=float(summary["peak_settlement"]) if spec.needs_foundation else 0.0,
        min_support_force=min_support,
        time_of_tension=float(summary["time_of_tension"]),
        n_flights=int(summary["n_flights"]), airborne_time=float(summary["airborne_time"]),
        peak_uplift=float(summary["peak_corner_uplift"]),
        peak_friction_demand=float(summary["peak_friction_demand"]),
        time_of_free_flight=float(summary["time_of_free_flight"]),
        status=status, message=message, n_steps=int(summary["n_steps"]), extra=_case_extra(spec, params))


def _case_extra(spec, params) -> dict:
    """``RockingResult.extra`` of a bed model: its damping ratio xi [-] and contact law; empty otherwise.

    With a restitution target these are the calibrated xi and law (``hunt-crossley`` for a continuous bed).
    """
    if not spec.uses_bed:
        return {}
    return {"xi": float(params["xi"]), "bed": LAWS[int(params["bed"])].NAME}


def simulate_batch(model, ag, dt, scales, blocks_and_foundations, *, ag_vertical=None, t_end=None,
                   **options) -> np.ndarray:
    """Run one record at many scale factors for many (block, k, xi) cases in one compiled call.

    Parameters
    ----------
    scales : array_like, shape (n_scale,)
        Factors applied to ``ag`` (and to ``ag_vertical``: the ratio of vertical to horizontal stays).
    blocks_and_foundations : list of (Block, k, xi)
        k and xi are ignored (may be None) for rigid-base models.
    ag_vertical : array_like, optional
        Vertical ground acceleration [m/s^2, up positive], sampled as ``ag`` (see ``simulate``).
    **options
        ``SolverOptions`` fields (see ``simulate``).

    Returns
    -------
    ndarray of ``fields.SUMMARY_DTYPE`` records, shape (n_case, n_scale)
        ``summaries["peak_angle"]`` etc.; ``status`` holds ``Outcome`` codes.
    """
    spec = get_model(model)
    samples, n_tail = _motion(ag, dt, t_end, ag_vertical)
    table, states = parameter_table(spec, blocks_and_foundations, SolverOptions(**options))
    scales = np.ascontiguousarray(scales, dtype=np.float64)
    summaries = new_summaries((len(table), scales.size))
    kernels.batch_kernel(spec.kernel_code, samples, float(dt), n_tail, scales, table, states, summaries)
    return summaries


def simulate_histories(model, ag, dt, cases, *, ag_vertical=None, t_end=None, **options):
    """Rotation histories of one ground motion (``ag`` and the optional ``ag_vertical``, as in ``simulate``)
    for many (block, k, xi) cases in one compiled call.

    Returns
    -------
    t : ndarray (n,) [s]; theta : ndarray (n_case, n) [rad] (NaN after overturning or free flight);
    y : ndarray (n_case, n) [m]; summaries : ``SUMMARY_DTYPE`` records (n_case,).
    """
    spec = get_model(model)
    samples, n_tail = _motion(ag, dt, t_end, ag_vertical)
    table, states = parameter_table(spec, cases, SolverOptions(**options))
    n_total = samples.shape[1] + n_tail
    histories = np.empty((len(table), n_total, fields.STATE_SIZE))
    summaries = new_summaries(len(table))
    kernels.history_batch_kernel(spec.kernel_code, samples, float(dt), n_tail, table, states, histories, summaries)
    return np.arange(n_total) * dt, histories[:, :, 0], histories[:, :, 2], summaries


from pipeline.models import housner as _housner  # noqa: E402  (registration at import)
from pipeline.models import ssi as _ssi  # noqa: E402
from pipeline.models import winkler as _winkler  # noqa: E402

register(_housner.MODEL)
register(_ssi.MODEL)
register(_ssi.PAPER_MODEL)
register(_winkler.MODEL)

__all__ = ["BED_TYPES", "MODELS", "Outcome", "RockingResult", "SUMMARY_DTYPE", "SUMMARY_FIELDS", "SWITCH_RULES",
           "SolverOptions", "calibrate_dissipation", "get_model", "radiation_damping", "register", "simulate",
           "simulate_batch", "simulate_histories"]
