"""rockfrag.models - stage 5: rocking solvers (Housner, the paper's SSI model, the Winkler bed).

Input : a model name, ground acceleration [m/s^2] sampled at dt [s] (optionally a vertical one,
        ``ag_vertical``, same sampling, up positive), a ``Block`` and, for models with a foundation,
        the interface stiffness k [N/m] and damping ratio xi [-] (winkler: or a target restitution that
        calibrates xi, rockfrag.models.restitution).
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
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from rockfrag.blocks import Block
from rockfrag.errors import SolverError
from rockfrag.models import fields, kernels
from rockfrag.models.base import MESSAGES, Outcome, RockingModel, RockingResult
from rockfrag.models.contact import LAWS
from rockfrag.models.fields import SUMMARY_DTYPE, SUMMARY_FIELDS
from rockfrag.models.options import (  # noqa: F401  (the API)
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
from rockfrag.models.restitution import calibrate_dissipation, calibrated_law, radiation_damping
from rockfrag.models.variants import MEMBER_LABELS, OLD_BAND_NAMES, RECOMMENDED, sample_models, split_variant
from rockfrag.units import STANDARD_GRAVITY
from rockfrag.validation import did_you_mean

if TYPE_CHECKING:
    from rockfrag.soils import SoilClass

MODELS: dict[str, RockingModel] = {}

DEFAULT_TAIL = 10.0  # s of free vibration after the record
IMPACT_CAPACITY = 10_000


def register(model: RockingModel) -> None:
    """Add ``model`` to ``MODELS`` under its name (a new model is one module and one call)."""
    MODELS[model.name] = model


def get_model(name: str) -> RockingModel:
    """The registered model called ``name``; a ``SolverError`` listing the valid names otherwise.

    The recommended model's central run (``recommended``) and its sample members (``recommended-<member>``;
    rockfrag.models.variants) are the bed model ``winkler``: a member only sets its parameters.
    """
    model, role = split_variant(name) if isinstance(name, str) else (name, None)
    try:
        spec = MODELS[model]
    except (KeyError, TypeError):
        raise SolverError(f"unknown model {name!r}{did_you_mean(name, MODELS)}; valid models are: "
                          f"{', '.join(MODELS)}") from None
    if role is not None and not spec.uses_bed:
        raise SolverError(f"unknown model {name!r}: only a bed model has sample members")
    return spec


def model_label(name: str) -> str:
    """A model's label for tables and plots; a sample member's says which member it is."""
    model, role = split_variant(name)
    if role == "centre":
        return "recommended: tensionless bed, central member of the designed sample"
    label = get_model(name).label
    return f"{label}, {MEMBER_LABELS[role]}" if role else label


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
        dissipation = calibrate_dissipation(block, k, options.bed, options.restitution, g=options.g)
        if dissipation.note:
            warnings.warn(dissipation.note, stacklevel=3)
        xi = dissipation.xi
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
    """(samples, number of tail samples): the components checked, cut to t_end and stacked for the kernels.

    The samples are (1, n), or with the vertical (2, n) (rows ``kernels.HORIZONTAL``, ``kernels.VERTICAL``).
    """
    ag = _ground(ag, dt)
    vertical = _vertical(ag_vertical, ag)
    ag, n_tail = _time_window(ag, dt, t_end)
    samples = np.empty((1 if vertical is None else 2, ag.size))
    samples[kernels.HORIZONTAL] = ag
    if vertical is not None:
        samples[kernels.VERTICAL] = vertical[:ag.size]
    return samples, n_tail


def simulate(model: str, ag: ArrayLike, dt: float, block: Block, *, ag_vertical: ArrayLike | None = None,
             k: float | None = None, xi: float | None = None, theta0: float = 0.0, thetadot0: float = 0.0,
             t_end: float | None = None, soil: str | SoilClass | None = None, scale: float = 1.0,
             **options: float | str | None) -> RockingResult:
    """Rocking response of ``block`` to ground acceleration ``ag`` [m/s^2] sampled at ``dt`` [s].

    Parameters
    ----------
    model : str
        ``housner``, ``ssi`` (the paper's model), ``ssi-paper`` (its printed equations) or ``winkler``
        (tensionless bed); see ``MODELS``. ``recommended`` runs the study's recommended model on ``soil``
        exactly as the study's central run does (``variants.central_member``: the bed's stiffness from the soil
        (eq. 19), its damping calibrated to the middle of the restitution range, the soil's friction), and
        ``recommended-<member>`` the designed sample's members on ``soil`` (rockfrag.models.variants); these take no
        ``k``, ``xi``, ``bed``, ``restitution`` or ``friction``. ``winkler`` given neither ``xi`` nor
        ``restitution`` (nor ``bed``) runs the recommended bed at ``k``: the ``two-spring`` law calibrated to the
        restitution range's middle, not an arbitrary damping ratio (a named ``bed`` without ``xi``, or a block too
        squat to have a restitution, Housner's r <= 0, keeps ``DEFAULT_XI``).
    ag : array_like, shape (n,)
        Horizontal ground acceleration [m/s^2]: at least 2 samples, all finite.
    dt : float
        Sampling interval of ``ag`` [s], > 0.
    block : Block
        The block (half-width b and half-height h [m], mass [kg]; rockfrag.blocks).
    ag_vertical : array_like, shape (n,), optional
        Vertical ground acceleration [m/s^2, up positive], sampled as ``ag``: gravity becomes
        g + ag_vertical(t) in the ground's frame. Where g + ag_vertical < 0 the block is in free flight:
        the pivot models (housner, ssi) stop there with ``Outcome.FREE_FLIGHT``; winkler flies on.
        None (default) and zeros give the same numbers.
    k : float, optional
        Interface stiffness [N/m], > 0 (winkler: the bed's total vertical stiffness K). Required by the
        models with a foundation (ssi, ssi-paper, winkler); housner ignores it.
    xi : float, optional
        Damping ratio of the foundation [-], from 0 to below 1 (hunt-crossley bed: up to 10); default 0.05
        (``DEFAULT_XI``). winkler: c_total = 2 xi sqrt(K m); hunt-crossley: the same damping at rest.
        winkler with a ``restitution`` target: give none, xi is calibrated and returned in
        ``result.extra["xi"]``. housner ignores it.
    theta0 : float
        Initial rotation [rad] (free rocking); default 0.
    thetadot0 : float
        Initial rotation rate [rad/s]; default 0.
    t_end : float, optional
        End time [s], >= 0; zero ground motion after the record, and a t_end inside the record cuts it.
        Default: the record + 10 s (``DEFAULT_TAIL``).
    soil : str or rockfrag.soils.SoilClass, optional
        The soil of ``recommended`` and its sample members: a shipped soil's name or a ``SoilClass``.
    scale : float
        Factor [-] on ``ag`` (and ``ag_vertical``), applied sample by sample as the study applies its scale
        factors: ``scale=s`` and ``ag * s`` give the same bits, the study's run at scale factor ``s``. Default 1.
    **options : float or str or None
        ``SolverOptions`` fields:
        ``switch`` (ssi): the pivot-switch rule, ``consistent`` (default) or ``continuous``;
        ``bed`` (winkler): the bed's contact law, ``continuous`` (default), ``two-spring`` or
        ``hunt-crossley`` (``BED_TYPES``);
        ``restitution`` [-]: pivot models, the impact coefficient from 0 to 1 (default: Housner's
        1 - 1.5 sin^2 alpha for housner, 1 for ssi, whose spring-dashpot dissipates); winkler, the target
        effective restitution < 1 of free rocking to which the bed's damping is calibrated, at the smallest
        xi where free rocking is reproducible and hits it within 5 % of its loss (the continuous bed then
        takes Hunt-Crossley damping; ``rockfrag.models.restitution.calibrate_dissipation``); ``"housner"`` is
        1 - 1.5 sin^2 alpha of the block;
        ``g`` [m/s^2]: gravity, default 9.80665;
        ``overturn_angle`` [rad]: the |theta| of overturning (terminal), up to pi/2 (default);
        ``rtol`` and ``atol`` [-]: the error per step, relative and as a fraction of each state's scale
        (defaults 1e-6 and 1e-7);
        ``friction`` [-]: Coulomb friction at the base of housner and winkler, one coefficient mu (static =
        kinetic) or a pair (mu_s, mu_k), mu_s >= mu_k > 0 (housner: mu_k <= 4/3); the block may then slide,
        flat or while rocking, with stick-slip. None (default) ties the base horizontally, as before.

    Returns
    -------
    RockingResult
        Histories at the sample times (t [s], theta [rad], theta_dot [rad/s], y [m] and y_dot [m/s], the
        slip u [m] and u_dot [m/s], NaN after overturning, free flight or failure), peaks, impacts, uplift,
        slip (``peak_slip``, ``residual_slip`` [m], ``mode_times`` [s]) and foundation checks in SI units,
        the ``Outcome`` as ``status``; bed models: the damping ratio and contact law used in ``extra``.

    Raises
    ------
    SolverError
        An unknown model; ``ag`` not 1-D with 2 finite samples or more; ``dt`` <= 0 or ``t_end`` < 0;
        ``ag_vertical`` not sampled as ``ag`` or not finite; no ``k`` for a model with a foundation, or
        ``k``, ``xi`` or an option out of range (``friction`` not a positive coefficient or pair with
        mu_s >= mu_k, or given to a tied model such as ssi); winkler given both ``xi`` and ``restitution``, or
        a ``restitution`` target its bed reaches only where free rocking is not reproducible, or not at all
        (the message names the admissible xi and the r they reach). A block whose free rocking dies below
        the measure's resolution at every admissible xi runs at the smallest one with one warning.
    TypeError
        An option that is not a ``SolverOptions`` field.

    Warns
    -----
    UserWarning
        ssi's foundation spring went into tension (real ground cannot pull): the results past that moment
        are not physical.
    """
    model, k, xi, options = _resolve_model(model, block, soil, k, xi, options)
    spec = get_model(model)
    settings = SolverOptions(**options)
    samples, n_tail = _motion(ag, dt, t_end, ag_vertical)
    table, states = parameter_table(spec, [(block, k, xi)], settings)
    state = states[0]
    state[0], state[1] = float(theta0), float(thetadot0)
    history = np.empty((1, samples.shape[1] + n_tail, fields.STATE_SIZE))
    impacts = np.empty((1, IMPACT_CAPACITY))
    if not (math.isfinite(scale) and scale > 0):
        raise SolverError(f"scale = {scale!r}: the factor on the ground motion must be a finite number > 0")
    summaries = kernels.run_cases(spec.kernel_code, samples, dt, n_tail, table, states, histories=history,
                                  impact_times=impacts, scales=np.array([float(scale)]))
    return _result(spec, block, dt, summaries[0, 0], history[0], impacts[0], table[0])


def _resolve_model(model, block, soil, k, xi, options):
    """(solver model, k, xi, options) of a ``simulate`` call: the recommended model and its members resolved.

    The recommended model and its sample members are the study's runs on a soil (one definition:
    ``variants.sample_member``); a plain ``winkler`` call without ``xi`` or ``restitution`` takes the recommended
    bed at its ``k``. Any other name runs as given.
    """
    from rockfrag.models.variants import (
        DEFAULT_DESIGN,
        RECOMMENDED_BED,
        calibrate_to_target,
        member_restitution,
        sample_member,
    )

    name, role = split_variant(model)
    if model in OLD_BAND_NAMES:
        raise SolverError(f"model {model!r}: the restitution band gave way to the designed sample; run "
                          f"{RECOMMENDED!r} or a member: {', '.join(sample_models()[1:])}")
    if name not in MODELS or (role is not None and not MODELS[name].uses_bed):
        accepted = [*MODELS, *sample_models()]
        raise SolverError(f"unknown model {model!r}{did_you_mean(str(model), accepted)}; valid models are: "
                          f"{', '.join(accepted)}")
    if role is not None:
        given = [key for key, value in (("k", k), ("xi", xi)) if value is not None]
        given += [key for key in ("bed", "restitution", "friction") if options.get(key) is not None]
        if given:
            raise SolverError(f"model {model!r} is the study's run on a soil: it takes no {', '.join(given)} "
                              f"(the soil sets them); run 'winkler' to choose them")
        if soil is None:
            raise SolverError(f"model {model!r} needs soil=: a soil name ({', '.join(_soil_names())}) or a "
                              "rockfrag.soils.SoilClass")
        member = sample_member(block, _soil(soil), role, g=options.get("g", STANDARD_GRAVITY))
        return member.model, member.k, member.xi, {**options, "bed": member.bed, "friction": member.friction}
    if soil is not None:
        raise SolverError(f"soil= is for the study's runs on a soil (models {RECOMMENDED!r} and its members "
                          f"{', '.join(sample_models()[1:])}); model {model!r} takes k (and xi) instead")
    spec = get_model(model)
    if spec.uses_bed and xi is None and options.get("restitution") is None and options.get("bed") is None \
            and k is not None:
        bed = RECOMMENDED_BED
        wanted = member_restitution(block, DEFAULT_DESIGN, "centre")
        if not 0 < wanted < 1:  # too squat to rock back (Housner's r <= 0): no target to calibrate to
            return model, k, DEFAULT_XI, {**options, "bed": bed}
        from rockfrag.models.restitution import admissible_xi
        g = options.get("g", STANDARD_GRAVITY)
        dissipation = calibrate_to_target(block, k, bed, wanted, admissible_xi(block, k, bed, g).reachable,
                                          movable=True, g=g)
        return model, k, dissipation.xi, {**options, "bed": calibrated_law(bed)}
    return model, k, xi, options


def _soil_names():
    from rockfrag.soils import SOILS

    return list(SOILS)


def _soil(soil):
    """A ``SoilClass`` from itself or a shipped soil's name (a ``SolverError`` listing them otherwise)."""
    from rockfrag.soils import SOILS

    if isinstance(soil, str):
        if soil not in SOILS:
            raise SolverError(f"unknown soil {soil!r}{did_you_mean(soil, SOILS)}; shipped soils: "
                              f"{', '.join(SOILS)} (or pass a rockfrag.soils.SoilClass)")
        return SOILS[soil]
    return soil


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
        u=history[:, fields.SLIP].copy(), u_dot=history[:, fields.SLIP_RATE].copy(),
        peak_slip=float(summary["peak_slip"]), residual_slip=float(summary["residual_slip"]),
        mode_times={name: float(summary[key]) for name, key in zip(fields.MODE_NAMES, fields.MODE_TIME_FIELDS)},
        status=status, message=message, n_steps=int(summary["n_steps"]), extra=_case_extra(spec, params))


def _case_extra(spec, params) -> dict:
    """``RockingResult.extra`` of a bed model: its damping ratio xi [-] and contact law; empty otherwise.

    With a restitution target these are the calibrated xi and law (``hunt-crossley`` for a continuous bed).
    """
    if not spec.uses_bed:
        return {}
    return {"xi": float(params["xi"]), "bed": LAWS[int(params["bed"])].NAME}


def simulate_batch(model: str, ag: ArrayLike, dt: float, scales: ArrayLike,
                   blocks_and_foundations: Sequence[tuple[Block, float | None, float | None]], *,
                   ag_vertical: ArrayLike | None = None, t_end: float | None = None,
                   **options: float | str | None) -> np.ndarray:
    """Run one record at many scale factors for many (block, k, xi) cases in one compiled call.

    Parameters
    ----------
    model : str
        A name in ``MODELS`` (see ``simulate``).
    ag : array_like, shape (n,)
        Horizontal ground acceleration [m/s^2] at scale factor 1: at least 2 samples, all finite.
    dt : float
        Sampling interval of ``ag`` [s], > 0.
    scales : array_like, shape (n_scale,)
        Factors [-] applied to ``ag`` (and to ``ag_vertical``: the ratio of vertical to horizontal stays).
    blocks_and_foundations : sequence of (Block, k, xi)
        The cases: a block, the interface stiffness k [N/m] and the damping ratio xi [-] (None: 0.05), as
        in ``simulate``. k and xi are ignored (may be None) for rigid-base models; with a winkler
        ``restitution`` target xi must be None (it is calibrated per case).
    ag_vertical : array_like, shape (n,), optional
        Vertical ground acceleration [m/s^2, up positive] at scale factor 1, sampled as ``ag`` (see
        ``simulate``).
    t_end : float, optional
        End time [s], >= 0 (see ``simulate``). Default: the record + 10 s.
    **options : float or str or None
        ``SolverOptions`` fields, as in ``simulate`` (``switch``, ``bed``, ``restitution``, ``g``,
        ``overturn_angle``, ``rtol``, ``atol``, ``friction``).

    Returns
    -------
    ndarray of ``fields.SUMMARY_DTYPE`` records, shape (n_case, n_scale)
        ``summaries["peak_angle"]`` etc., in the units of ``SUMMARY_FIELDS`` except ``min_support_force``,
        which is per unit mass here [m/s^2] (times the block's mass: [N]); ``status`` holds ``Outcome``
        codes.

    Raises
    ------
    SolverError
        No case; an unknown model; invalid ``ag``, ``dt``, ``t_end`` or ``ag_vertical``; a case or option
        out of range (as in ``simulate``).
    TypeError
        An option that is not a ``SolverOptions`` field.
    """
    spec = get_model(model)
    samples, n_tail = _motion(ag, dt, t_end, ag_vertical)
    table, states = parameter_table(spec, blocks_and_foundations, SolverOptions(**options))
    scales = np.ascontiguousarray(scales, dtype=np.float64)
    return kernels.run_cases(spec.kernel_code, samples, dt, n_tail, table, states, scales=scales)


def simulate_histories(model: str, ag: ArrayLike, dt: float, cases: Sequence[tuple[Block, float | None, float | None]],
                       *, ag_vertical: ArrayLike | None = None, t_end: float | None = None,
                       **options: float | str | None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Rotation and settlement histories of one ground motion for many (block, k, xi) cases in one compiled call.

    Parameters
    ----------
    model : str
        A name in ``MODELS`` (see ``simulate``).
    ag : array_like, shape (n,)
        Horizontal ground acceleration [m/s^2]: at least 2 samples, all finite.
    dt : float
        Sampling interval of ``ag`` [s], > 0.
    cases : sequence of (Block, k, xi)
        The cases: a block, the interface stiffness k [N/m] and the damping ratio xi [-] (None: 0.05), as
        in ``simulate``; k and xi are ignored (may be None) for rigid-base models.
    ag_vertical : array_like, shape (n,), optional
        Vertical ground acceleration [m/s^2, up positive], sampled as ``ag`` (see ``simulate``).
    t_end : float, optional
        End time [s], >= 0 (see ``simulate``). Default: the record + 10 s.
    **options : float or str or None
        ``SolverOptions`` fields, as in ``simulate`` (``switch``, ``bed``, ``restitution``, ``g``,
        ``overturn_angle``, ``rtol``, ``atol``, ``friction``).

    Returns
    -------
    t : ndarray, shape (n_t,)
        Sample times [s] from 0, step ``dt``.
    theta : ndarray, shape (n_case, n_t)
        Rotation [rad]; NaN after overturning, free flight or failure.
    y : ndarray, shape (n_case, n_t)
        Settlement [m], positive down, of the active pivot (ssi) or the base centre (winkler); zeros for
        housner; NaN as theta.
    summaries : ndarray of ``fields.SUMMARY_DTYPE`` records, shape (n_case,)
        As from ``simulate_batch`` (``min_support_force`` per unit mass [m/s^2]).

    Raises
    ------
    SolverError
        No case; an unknown model; invalid ``ag``, ``dt``, ``t_end`` or ``ag_vertical``; a case or option
        out of range (as in ``simulate``).
    TypeError
        An option that is not a ``SolverOptions`` field.
    """
    spec = get_model(model)
    samples, n_tail = _motion(ag, dt, t_end, ag_vertical)
    table, states = parameter_table(spec, cases, SolverOptions(**options))
    n_total = samples.shape[1] + n_tail
    histories = np.empty((len(table), n_total, fields.STATE_SIZE))
    summaries = kernels.run_cases(spec.kernel_code, samples, dt, n_tail, table, states, histories=histories)
    return np.arange(n_total) * dt, histories[:, :, 0], histories[:, :, 2], summaries[:, 0]


from rockfrag.models import housner as _housner  # noqa: E402  (registration at import)
from rockfrag.models import ssi as _ssi  # noqa: E402
from rockfrag.models import winkler as _winkler  # noqa: E402

register(_housner.MODEL)
register(_ssi.MODEL)
register(_ssi.PAPER_MODEL)
register(_winkler.MODEL)

__all__ = ["BED_TYPES", "MODELS", "Outcome", "RockingResult", "SUMMARY_DTYPE", "SUMMARY_FIELDS", "SWITCH_RULES",
           "SolverOptions", "calibrate_dissipation", "get_model", "radiation_damping", "register", "simulate",
           "simulate_batch", "simulate_histories"]
