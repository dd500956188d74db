"""pipeline.models - stage 5: rocking solvers (Housner and SSI-rocking).

Input : a model name, ground acceleration [m/s^2] sampled at dt [s], a ``Block`` and, for SSI,
        the interface stiffness k [N/m] and damping ratio xi [-].
Output: a ``RockingResult`` (histories, peak angle, impacts, overturning), or for many scale
        factors at once a summary array from ``simulate_batch``.

Models are a registry: ``MODELS[name]``; a new model is one module and one ``register`` call.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from pipeline.blocks import Block
from pipeline.errors import SolverError
from pipeline.models import kernels
from pipeline.models.base import MESSAGES, RockingModel, RockingResult, Status
from pipeline.units import STANDARD_GRAVITY

MODELS: dict[str, RockingModel] = {}

SWITCH_RULES = {"consistent": kernels.SWITCH_CONSISTENT, "continuous": kernels.SWITCH_CONTINUOUS}

DEFAULT_RTOL = 1e-6  # relative error per step; peak angles agree with scipy at 1e-10 to ~1e-6
DEFAULT_ATOL = 1e-7  # absolute error per step, as a fraction of alpha, alpha*p, y_static, y_static*omega
DEFAULT_ZENO_FRACTION = 1e-6  # excursions below this fraction of alpha end the rocking
DEFAULT_TAIL = 10.0  # s of free vibration after the record
MAX_EVENTS = 200_000
IMPACT_CAPACITY = 10_000


def register(model: RockingModel) -> None:
    MODELS[model.name] = model


def get_model(name: str) -> RockingModel:
    try:
        return MODELS[name]
    except KeyError:
        raise SolverError(f"unknown model {name!r}; valid models are: {', '.join(MODELS)}") from None


def parameter_vector(model: RockingModel, block: Block, *, k=None, xi=None, switch="consistent",
                     restitution=None, g=STANDARD_GRAVITY, overturn_angle=math.pi / 2,
                     rtol=DEFAULT_RTOL, atol=DEFAULT_ATOL) -> tuple[np.ndarray, float]:
    """Kernel parameter vector and the initial (static) settlement y0 [m]; validates the inputs."""
    if switch not in SWITCH_RULES:
        raise SolverError(f"switch {switch!r} unknown; valid: {', '.join(SWITCH_RULES)}")
    if not 0 < overturn_angle <= math.pi / 2:
        raise SolverError(f"overturn_angle {overturn_angle} [rad] out of range; allowed 0 < angle <= pi/2")
    if not g > 0:
        raise SolverError(f"g = {g} [m/s^2]; must be > 0")
    if restitution is None:
        restitution = model.default_restitution(block)
    if not 0 <= restitution <= 1:
        raise SolverError(f"restitution {restitution} out of range; allowed 0 to 1")
    omega = 0.0
    xi_value = 0.0
    y0 = 0.0
    if model.needs_foundation:
        if k is None:
            raise SolverError(f"model {model.name!r} needs the interface stiffness k [N/m]")
        if not (k > 0 and math.isfinite(k)):
            raise SolverError(f"k = {k} [N/m] out of range; allowed finite > 0")
        xi_value = 0.05 if xi is None else xi
        if not 0 <= xi_value < 1:
            raise SolverError(f"xi = {xi_value} out of range; allowed 0 <= xi < 1")
        omega = math.sqrt(k / block.mass)
        y0 = g / omega**2  # static equilibrium: never drop the block onto an unloaded spring
    params = np.zeros(kernels.N_PARAMS)
    params[kernels.P_R] = block.R
    params[kernels.P_ALPHA] = block.alpha
    params[kernels.P_G] = g
    params[kernels.P_KAPPA] = model.kappa
    params[kernels.P_OMEGA] = omega
    params[kernels.P_XI] = xi_value
    params[kernels.P_RESTITUTION] = restitution
    params[kernels.P_SWITCH] = SWITCH_RULES[switch]
    params[kernels.P_OVERTURN] = overturn_angle
    params[kernels.P_RTOL] = rtol
    params[kernels.P_ATOL] = atol
    params[kernels.P_ZENO] = DEFAULT_ZENO_FRACTION * block.alpha
    params[kernels.P_MAX_EVENTS] = MAX_EVENTS
    return params, y0


def _ground(ag, dt):
    ag = np.ascontiguousarray(ag, dtype=np.float64)
    if ag.ndim != 1 or ag.size < 2:
        raise SolverError("ag must be a 1-D array of at least 2 samples [m/s^2]")
    if not np.all(np.isfinite(ag)):
        raise SolverError("ag contains NaN or infinite values")
    if not (dt > 0 and math.isfinite(dt)):
        raise SolverError(f"dt = {dt} [s]; must be > 0")
    return ag


def simulate(model, ag, dt, block, *, k=None, xi=None, switch="consistent", restitution=None,
             theta0=0.0, thetadot0=0.0, t_end=None, g=STANDARD_GRAVITY, overturn_angle=math.pi / 2,
             rtol=DEFAULT_RTOL, atol=DEFAULT_ATOL) -> RockingResult:
    """Rocking response of ``block`` to ground acceleration ``ag`` [m/s^2] sampled at ``dt`` [s].

    Parameters
    ----------
    model : str
        ``housner``, ``ssi`` or ``ssi-paper`` (see ``MODELS``).
    k, xi : float
        Interface stiffness [N/m] and damping ratio [-] (SSI models; xi defaults to 0.05).
    switch : str
        SSI pivot-switch rule, ``consistent`` (default) or ``continuous``.
    restitution : float, optional
        Factor on theta' at each impact; Housner default 1 - 1.5 sin^2(alpha), SSI default 1.
    theta0, thetadot0 : float
        Initial rotation [rad] and rate [rad/s] (free rocking).
    t_end : float, optional
        End time [s]; zero ground motion after the record. Default: record + 10 s.
    overturn_angle : float
        |theta| at which the block has overturned [rad] (default pi/2, terminal).
    """
    spec = get_model(model)
    ag = _ground(ag, dt)
    params, y0 = parameter_vector(spec, block, k=k, xi=xi, switch=switch, restitution=restitution,
                                  g=g, overturn_angle=overturn_angle, rtol=rtol, atol=atol)
    record_end = (ag.size - 1) * dt
    if t_end is None:
        t_end = record_end + DEFAULT_TAIL
    if t_end < 0:
        raise SolverError(f"t_end = {t_end} [s]; must be >= 0")
    n_total = max(2, int(round(t_end / dt)) + 1)
    n_tail = max(0, n_total - ag.size)
    if n_total < ag.size:
        ag = ag[:n_total]
    history = np.empty((ag.size + n_tail, 4))
    impacts = np.empty(IMPACT_CAPACITY)
    summary = np.zeros(kernels.N_SUMMARY)
    kernels.simulate_kernel(spec.kernel_code, ag, float(dt), n_tail, params, float(theta0),
                            float(thetadot0), y0, 0.0, history, impacts, summary)
    return _result(spec, block, params, dt, summary, history, impacts)


def _result(spec, block, params, dt, summary, history, impacts):
    status = Status(int(summary[kernels.S_STATUS]))
    n_impacts = int(summary[kernels.S_N_IMPACTS])
    min_support = summary[kernels.S_MIN_SUPPORT] * block.mass
    message = MESSAGES[status]
    if spec.needs_foundation and min_support < 0:
        message += f"; the foundation spring went into tension (min support force {min_support:.3g} N)"
        warnings.warn(f"{spec.name}: foundation spring in tension (min support force {min_support:.3g} N): "
                      "the block would jump; results past that moment are not physical", stacklevel=3)
    time_of_uplift = summary[kernels.S_TIME_OF_UPLIFT]
    return RockingResult(
        model=spec.name, t=np.arange(history.shape[0]) * dt, theta=history[:, 0].copy(),
        theta_dot=history[:, 1].copy(), y=history[:, 2].copy(), y_dot=history[:, 3].copy(),
        peak_angle=float(summary[kernels.S_PEAK]),
        peak_angle_ratio=float(summary[kernels.S_PEAK] / block.alpha),
        time_of_peak=float(summary[kernels.S_TIME_OF_PEAK]),
        uplifted=bool(summary[kernels.S_UPLIFTED]), overturned=status == Status.OVERTURNED,
        n_impacts=n_impacts, impact_times=impacts[:min(n_impacts, impacts.size)].copy(),
        time_of_uplift=float(time_of_uplift) if time_of_uplift >= 0 else math.nan,
        peak_settlement=float(summary[kernels.S_PEAK_Y]) if spec.needs_foundation else 0.0,
        min_support_force=float(min_support) if spec.needs_foundation else block.mass * params[kernels.P_G],
        status=status, message=message, n_steps=int(summary[kernels.S_N_STEPS]))


def simulate_batch(model, ag, dt, scales, blocks_and_foundations, *, switch="consistent",
                   restitution=None, t_end=None, g=STANDARD_GRAVITY, overturn_angle=math.pi / 2,
                   rtol=DEFAULT_RTOL, atol=DEFAULT_ATOL) -> np.ndarray:
    """Run one record at many scale factors for many (block, k, xi) cases in one compiled call.

    Parameters
    ----------
    scales : array_like, shape (n_scale,)
        Factors applied to ``ag``.
    blocks_and_foundations : list of (Block, k, xi)
        k and xi are ignored (may be None) for Housner.

    Returns
    -------
    ndarray, shape (n_case, n_scale, kernels.N_SUMMARY)
        Summary vectors (see ``kernels.S_*``; status codes as ``Status``).
    """
    spec = get_model(model)
    ag = _ground(ag, dt)
    rows, y0s = [], []
    for block, k, xi in blocks_and_foundations:
        params, y0 = parameter_vector(spec, block, k=k, xi=xi, switch=switch, restitution=restitution,
                                      g=g, overturn_angle=overturn_angle, rtol=rtol, atol=atol)
        rows.append(params)
        y0s.append(y0)
    record_end = (ag.size - 1) * dt
    n_tail = max(0, int(round(((record_end + DEFAULT_TAIL) if t_end is None else t_end) / dt)) + 1 - ag.size)
    scales = np.ascontiguousarray(scales, dtype=np.float64)
    summaries = np.zeros((len(rows), scales.size, kernels.N_SUMMARY))
    kernels.batch_kernel(spec.kernel_code, ag, float(dt), n_tail, scales, np.array(rows),
                         np.array(y0s), summaries)
    return summaries


def simulate_histories(model, ag, dt, cases, *, switch="consistent", restitution=None, t_end=None,
                       g=STANDARD_GRAVITY, overturn_angle=math.pi / 2, rtol=DEFAULT_RTOL, atol=DEFAULT_ATOL):
    """Rotation histories of one ground motion for many (block, k, xi) cases in one compiled call.

    Returns
    -------
    t : ndarray (n,) [s]; theta : ndarray (n_case, n) [rad] (NaN after overturning);
    y : ndarray (n_case, n) [m]; summaries : ndarray (n_case, kernels.N_SUMMARY).
    """
    spec = get_model(model)
    ag = _ground(ag, dt)
    rows, y0s = [], []
    for block, k, xi in cases:
        params, y0 = parameter_vector(spec, block, k=k, xi=xi, switch=switch, restitution=restitution, g=g,
                                      overturn_angle=overturn_angle, rtol=rtol, atol=atol)
        rows.append(params)
        y0s.append(y0)
    record_end = (ag.size - 1) * dt
    n_total = max(2, int(round(((record_end + DEFAULT_TAIL) if t_end is None else t_end) / dt)) + 1)
    n_tail = max(0, n_total - ag.size)
    if n_total < ag.size:
        ag = ag[:n_total]
    histories = np.empty((len(rows), ag.size + n_tail, 4))
    summaries = np.zeros((len(rows), kernels.N_SUMMARY))
    kernels.history_batch_kernel(spec.kernel_code, ag, float(dt), n_tail, np.array(rows), np.array(y0s),
                                 histories, summaries)
    return np.arange(ag.size + n_tail) * dt, histories[:, :, 0], histories[:, :, 2], summaries


from pipeline.models import housner as _housner  # noqa: E402  (registration at import)
from pipeline.models import ssi as _ssi  # noqa: E402

register(_housner.MODEL)
register(_ssi.MODEL)
register(_ssi.PAPER_MODEL)

__all__ = ["MODELS", "RockingResult", "Status", "get_model", "register", "simulate", "simulate_batch",
           "simulate_histories"]
