"""pipeline.calibrate - fit the SSI interface stiffness k and damping ratio xi to a reference.

Input : a reference rotation history (table: time, rotation; e.g. from LS-DYNA or a shake-table
        test), the ground motion that produced it [m/s^2], and the block.
Output: ``CalibrationResult``: the best grid point and the locally optimised (k [N/m], xi [-]), the
        Pearson correlation of paper eq. 17 between reference and model rotation (model interpolated
        onto the reference's time steps), the RMS error [rad] and peak-angle error, the implied A/H of
        eq. 19 [m] for given soil and block moduli, the correlation surface; JSON/CSV and PNG writers.

The grid runs through one compiled batch call; the local search (bounded Powell in log k, xi) starts
from the best grid point. Correlation alone can hide an amplitude mismatch: read the RMS and peak
errors too.
"""

from __future__ import annotations

import json
import math
import re
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import minimize

from pipeline.errors import ConfigError, PipelineError
from pipeline.models import simulate_histories
from pipeline.outputs import atomic_path

TIME_UNITS = {"s": 1.0, "ms": 1e-3}
ANGLE_UNITS = {"rad": 1.0, "mrad": 1e-3, "deg": math.pi / 180.0}


@dataclass
class CalibrationResult:
    k_grid: float
    xi_grid: float
    correlation_grid: float
    k: float
    xi: float
    correlation: float
    rms_error: float
    peak_error: float
    peak_reference: float
    peak_model: float
    area_over_depth: float | None
    soil_shear_modulus: float | None
    block_modulus: float
    surface_k: list = field(repr=False, default_factory=list)
    surface_xi: list = field(repr=False, default_factory=list)
    surface: list = field(repr=False, default_factory=list)

    def summary(self) -> dict:
        data = asdict(self)
        for key in ("surface_k", "surface_xi", "surface"):
            data.pop(key)
        data["units"] = {"k": "N/m", "xi": "1", "rms_error": "rad", "peak_error": "1 (relative)",
                         "area_over_depth": "m", "soil_shear_modulus": "Pa", "block_modulus": "Pa"}
        return data


def _unit_from_name(name, units, default):
    match = re.search(r"[\[(]\s*([A-Za-z]+)\s*[\])]|_([A-Za-z]+)$", str(name))
    if match:
        unit = (match.group(1) or match.group(2)).lower()
        if unit in units:
            return unit
    return default


def load_reference(path, time_unit=None, angle_unit=None):
    """Reference (time [s], rotation [rad]) from a table pandas reads; units from flags or headers."""
    path = Path(path)
    if not path.is_file():
        raise PipelineError(f"{path}: reference file not found")
    try:
        table = pd.read_csv(path, comment="#", sep=None, engine="python")
    except Exception as error:
        raise PipelineError(f"{path}: cannot read the reference table ({error})") from None
    numeric = table.select_dtypes("number")
    if numeric.shape[1] < 2 or len(numeric) < 10:
        raise PipelineError(f"{path}: expected two numeric columns (time, rotation) and at least 10 rows")
    time_name, angle_name = numeric.columns[:2]
    time_unit = time_unit or _unit_from_name(time_name, TIME_UNITS, "s")
    angle_unit = angle_unit or _unit_from_name(angle_name, ANGLE_UNITS, "rad")
    if time_unit not in TIME_UNITS:
        raise ConfigError("time_unit", f"{time_unit!r}; allowed: {', '.join(TIME_UNITS)}", str(path))
    if angle_unit not in ANGLE_UNITS:
        raise ConfigError("angle_unit", f"{angle_unit!r}; allowed: {', '.join(ANGLE_UNITS)}", str(path))
    time = numeric[time_name].to_numpy(float) * TIME_UNITS[time_unit]
    rotation = numeric[angle_name].to_numpy(float) * ANGLE_UNITS[angle_unit]
    if not np.all(np.isfinite(time)) or not np.all(np.isfinite(rotation)):
        raise PipelineError(f"{path}: the reference contains non-numeric or non-finite values")
    if np.any(np.diff(time) <= 0):
        raise PipelineError(f"{path}: time must increase strictly")
    return time, rotation


def correlation(reference, model):
    """Pearson correlation of paper eq. 17 (NaN-safe: 0 if either series is constant)."""
    reference = reference - reference.mean()
    model = model - model.mean()
    denominator = math.sqrt(float(np.sum(reference**2) * np.sum(model**2)))
    return float(np.sum(reference * model) / denominator) if denominator > 0 else 0.0


def _scores(time, thetas, ref_time, ref_rotation):
    scores = []
    for theta in thetas:
        theta = np.nan_to_num(theta, nan=math.pi / 2)
        model = np.interp(ref_time, time, theta)
        scores.append((correlation(ref_rotation, model), float(np.sqrt(np.mean((model - ref_rotation) ** 2))),
                       float(np.max(np.abs(model)))))
    return scores


def calibrate(ref_time, ref_rotation, ag, dt, block, *, k_range=(1e8, 9e8), xi_range=(0.01, 0.07),
              n_k=25, n_xi=7, soil_shear_modulus=None, switch="consistent", local=True):
    """Grid search then local optimisation of (k, xi) maximising eq. 17's correlation."""
    if not 0 < k_range[0] < k_range[1]:
        raise ConfigError("k_range", f"{k_range}; need 0 < k_min < k_max [N/m]")
    if not 0 <= xi_range[0] <= xi_range[1] < 1:
        raise ConfigError("xi_range", f"{xi_range}; need 0 <= xi_min <= xi_max < 1")
    t_end = max(ref_time[-1], (len(ag) - 1) * dt)
    k_values = np.geomspace(*k_range, n_k)
    xi_values = np.linspace(*xi_range, n_xi) if n_xi > 1 else np.array([xi_range[0]])
    cases = [(block, k, xi) for k in k_values for xi in xi_values]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        time, thetas, _, _ = simulate_histories("ssi", ag, dt, cases, switch=switch, t_end=t_end)
    scores = _scores(time, thetas, ref_time, ref_rotation)
    surface = np.array([s[0] for s in scores]).reshape(n_k, len(xi_values))
    best = int(np.argmax(surface))
    k_best, xi_best = cases[best][1], cases[best][2]
    grid_score = float(surface.flat[best])

    def objective(params):
        k, xi = math.exp(params[0]), params[1]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t, th, _, _ = simulate_histories("ssi", ag, dt, [(block, k, xi)], switch=switch, t_end=t_end)
        return -_scores(t, th, ref_time, ref_rotation)[0][0]

    k_fit, xi_fit = k_best, xi_best
    if local:
        result = minimize(objective, x0=[math.log(k_best), xi_best], method="Powell",
                          bounds=[(math.log(k_range[0]), math.log(k_range[1])), xi_range],
                          options={"xtol": 1e-3, "ftol": 1e-6, "maxfev": 200})
        if -result.fun >= grid_score:
            k_fit, xi_fit = math.exp(result.x[0]), float(result.x[1])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t, th, _, _ = simulate_histories("ssi", ag, dt, [(block, k_fit, xi_fit)], switch=switch, t_end=t_end)
    score, rms, peak_model = _scores(t, th, ref_time, ref_rotation)[0]
    peak_reference = float(np.max(np.abs(ref_rotation)))
    area_over_depth = None
    if soil_shear_modulus:
        area_over_depth = k_fit * (1.0 / soil_shear_modulus + 1.0 / block.E_b)  # eq. 19 solved for A/H
    return CalibrationResult(
        k_grid=float(k_best), xi_grid=float(xi_best), correlation_grid=grid_score, k=float(k_fit), xi=float(xi_fit),
        correlation=score, rms_error=rms, peak_error=(peak_model - peak_reference) / peak_reference,
        peak_reference=peak_reference, peak_model=peak_model, area_over_depth=area_over_depth,
        soil_shear_modulus=soil_shear_modulus, block_modulus=block.E_b, surface_k=k_values.tolist(),
        surface_xi=xi_values.tolist(), surface=surface.tolist())


def write_outputs(result: CalibrationResult, ref_time, ref_rotation, ag, dt, block, output, switch="consistent"):
    """calibration.json, calibration.csv, calibration-fit.png and calibration-surface.png."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    summary = result.summary()
    with atomic_path(output / "calibration.json") as temporary:
        temporary.write_text(json.dumps(summary, indent=2))
    with atomic_path(output / "calibration.csv") as temporary:
        pd.DataFrame([{k: v for k, v in summary.items() if k != "units"}]).to_csv(temporary, index=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t, th, y, _ = simulate_histories("ssi", ag, dt, [(block, result.k, result.xi)], switch=switch,
                                         t_end=max(ref_time[-1], (len(ag) - 1) * dt))
    figure, axis = plt.subplots(figsize=(10, 4.5), constrained_layout=True)
    axis.plot(ref_time, ref_rotation, color="k", lw=1.0, label="reference")
    axis.plot(t, th[0], color="C3", lw=0.9, ls="--",
              label=f"SSI-rocking, k = {result.k:.3g} N/m, ξ = {result.xi:.3f}")
    axis.set_xlabel("time [s]")
    axis.set_ylabel("rotation θ [rad]")
    axis.set_title(f"Calibration: correlation {result.correlation:.3f}, RMS error {result.rms_error:.2e} rad, "
                   f"peak error {result.peak_error:+.1%}")
    axis.grid(alpha=0.3)
    axis.legend()
    with atomic_path(output / "calibration-fit.png") as temporary:
        figure.savefig(temporary, dpi=120, format="png")
    plt.close(figure)
    figure, axis = plt.subplots(figsize=(7, 5), constrained_layout=True)
    surface = np.array(result.surface)
    mesh = axis.pcolormesh(np.array(result.surface_xi) * 100, np.array(result.surface_k), surface, shading="nearest",
                           cmap="viridis")
    axis.set_yscale("log")
    axis.plot(result.xi * 100, result.k, "r*", ms=14, label="optimum")
    axis.plot(result.xi_grid * 100, result.k_grid, "wo", ms=7, mfc="none", label="best grid point")
    axis.set_xlabel("damping ratio ξ [%]")
    axis.set_ylabel("interface stiffness k [N/m]")
    axis.set_title("Correlation with the reference (paper eq. 17)")
    axis.legend(fontsize=8)
    figure.colorbar(mesh, label="Pearson correlation [-]")
    with atomic_path(output / "calibration-surface.png") as temporary:
        figure.savefig(temporary, dpi=120, format="png")
    plt.close(figure)
    return [output / name for name in ("calibration.json", "calibration.csv", "calibration-fit.png",
                                       "calibration-surface.png")]
