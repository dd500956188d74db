"""rockfrag.applicability - when Housner's rigid base is good enough (paper section 2).

Input : blocks, a record set, a few intensity levels (multiples of each block's uplift PGA) and a
        sweep of soil shear modulus G_s (default 10 MPa - 100 GPa) and block modulus E_b.
Output: ``reports/applicability.nc`` with, per compared model (``winkler``, the admissible tensionless
        bed, and the paper's ``ssi``), block, E_b, level and G_s: the ratio of the model's to Housner's
        median peak angle, the difference in overturning fraction, and the median correlation of the
        rotation histories; and per block, E_b and level the modulus above which Housner stays within
        the tolerance (10% by default), to compare with the paper's 300-1000 MPa, also expressed as the
        relative stiffness E_b/G_s. A figure (``applicability-sweep.png``) shows it.
"""

from __future__ import annotations

import hashlib
import json
import warnings
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import xarray as xr
from tqdm import tqdm

from rockfrag.calibrate import correlation
from rockfrag.executors import shutdown_pool, worker_pool
from rockfrag.models import get_model, simulate_histories
from rockfrag.models.base import Outcome
from rockfrag.outputs import atomic_path, write_dataset
from rockfrag.soils import interface_stiffness
from rockfrag.study import StudyRecords, study_records
from rockfrag.version import __version__

DEFAULT_SHEAR_MODULI = np.geomspace(10e6, 100e9, 13)
DEFAULT_LEVEL_FACTORS = (1.5, 2.5, 4.0)
DEFAULT_MODELS = ("winkler", "ssi")  # compared with Housner: the admissible bed first, the paper's model beside it


def _record_task(acceleration, dt, pga, blocks, block_moduli, level_factors, shear_moduli, xi, tail, models,
                 options):
    """Pure task: for one record, Housner and each compared model at each block/E_b/level/G_s."""
    n_m, n_b, n_e, n_l, n_g = len(models), len(blocks), len(block_moduli), len(level_factors), len(shear_moduli)
    peak_h = np.full((n_b, n_l), np.nan)
    over_h = np.zeros((n_b, n_l))
    peak_s = np.full((n_m, n_b, n_e, n_l, n_g), np.nan)
    over_s = np.zeros((n_m, n_b, n_e, n_l, n_g))
    corr = np.full((n_m, n_b, n_e, n_l, n_g), np.nan)
    t_end = (acceleration.size - 1) * dt + tail
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for b, block in enumerate(blocks):
            cases = []
            for modulus in block_moduli:
                stiff_block = replace(block, E_b=modulus)
                for shear in shear_moduli:
                    k = interface_stiffness(shear, modulus, block.footprint_area, block.soil_depth)
                    cases.append((stiff_block, k, xi))
            for lv, factor in enumerate(level_factors):
                ag = acceleration * factor * block.uplift_acceleration() / pga
                _, theta_h, _, summary_h = simulate_histories("housner", ag, dt, [(block, None, None)], t_end=t_end)
                peak_h[b, lv] = summary_h["peak_angle"][0]
                over_h[b, lv] = summary_h["status"][0] == Outcome.OVERTURNED
                reference = np.nan_to_num(theta_h[0], nan=np.pi / 2)
                for m, model in enumerate(models):
                    _, theta_s, _, summary_s = simulate_histories(model, ag, dt, cases, t_end=t_end, **options)
                    for index in range(len(cases)):
                        e, g = divmod(index, n_g)
                        peak_s[m, b, e, lv, g] = summary_s["peak_angle"][index]
                        over_s[m, b, e, lv, g] = summary_s["status"][index] == Outcome.OVERTURNED
                        corr[m, b, e, lv, g] = correlation(reference, np.nan_to_num(theta_s[index], nan=np.pi / 2))
    return peak_h, over_h, peak_s, over_s, corr


def threshold_modulus(shear_moduli, ratio, tolerance):
    """Smallest G_s from which |ratio - 1| <= tolerance holds for every stiffer value (log interpolation).

    NaN if even the stiffest G_s is outside the tolerance; the softest G_s if all are inside.
    """
    error = np.abs(np.asarray(ratio) - 1.0)
    inside = error <= tolerance
    if not inside[-1] or np.isnan(error[-1]):
        return np.nan
    outside = np.flatnonzero(~inside)
    if outside.size == 0:
        return float(shear_moduli[0])
    j = outside[-1]  # last G outside; j + 1 is inside
    x0, x1 = np.log(shear_moduli[j]), np.log(shear_moduli[j + 1])
    e0, e1 = error[j], error[j + 1]
    fraction = (e0 - tolerance) / (e0 - e1) if e0 != e1 else 1.0
    return float(np.exp(x0 + fraction * (x1 - x0)))


def run_applicability(records, blocks, *, shear_moduli=DEFAULT_SHEAR_MODULI, block_moduli=(30e9, 210e9),
                      level_factors=DEFAULT_LEVEL_FACTORS, xi=0.05, tail=5.0, tolerance=0.10, workers=None,
                      progress=True, models=DEFAULT_MODELS, options=None) -> xr.Dataset:
    """The sweep over records (in parallel) and its summary dataset.

    models : foundation models compared with Housner; options : solver keywords (e.g. ``bed``).
    """
    models = [name for name in models if not get_model(name).is_rigid_base]
    options = dict(options or {})
    shear_moduli = np.asarray(shear_moduli, float)
    arguments = [(r.acceleration, r.dt, float(np.max(np.abs(r.acceleration))), list(blocks), list(block_moduli),
                  list(level_factors), shear_moduli, xi, tail, list(models), options) for r in records]
    if workers == 1:
        results = [_record_task(*a) for a in tqdm(arguments, desc="applicability", disable=not progress)]
    else:
        pool = worker_pool(workers)  # its workers die with this process
        try:
            futures = [pool.submit(_record_task, *a) for a in arguments]
            results = [f.result() for f in tqdm(futures, desc="applicability", unit="rec", disable=not progress)]
        finally:
            shutdown_pool(pool)
    peak_h = np.array([r[0] for r in results])
    over_h = np.array([r[1] for r in results])
    peak_s = np.array([r[2] for r in results])
    over_s = np.array([r[3] for r in results])
    corr = np.array([r[4] for r in results])
    # medians over the records that did not overturn in either model
    # arrays: (record, model, block, E_b, level, G_s); Housner (record, block, level)
    housner_peak = peak_h[:, None, :, None, :, None]
    survived = (over_h[:, None, :, None, :, None] == 0) & (over_s == 0)
    model_angles = np.where(survived, peak_s, np.nan)
    housner_angles = np.where(survived, np.broadcast_to(housner_peak, peak_s.shape), np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ratio = np.nanmedian(model_angles, axis=0) / np.nanmedian(housner_angles, axis=0)
        overturn_difference = over_s.mean(axis=0) - over_h.mean(axis=0)[None, :, None, :, None]
        median_correlation = np.nanmedian(corr, axis=0)
    thresholds = np.full(ratio.shape[:4], np.nan)
    for index in np.ndindex(*ratio.shape[:4]):
        thresholds[index] = threshold_modulus(shear_moduli, ratio[index], tolerance)
    dims = ("model", "block", "block_modulus", "level", "shear_modulus")
    coords = {"model": ("model", list(models), {"long_name": "model compared with Housner's rigid base"}),
              "model_label": ("model", [get_model(name).label for name in models], {"long_name": "model"}),
              "block": [b.name for b in blocks],
              "block_modulus": ("block_modulus", np.asarray(block_moduli, float),
                                {"long_name": "block Young's modulus E_b", "units": "Pa"}),
              "level": ("level", np.asarray(level_factors, float),
                        {"long_name": "PGA over the block's uplift PGA g tan(alpha)", "units": "1"}),
              "shear_modulus": ("shear_modulus", shear_moduli, {"long_name": "soil shear modulus G_s", "units": "Pa"}),
              "block_R": ("block", [b.R for b in blocks], {"long_name": "semi-diagonal R", "units": "m"}),
              "block_alpha": ("block", [b.alpha for b in blocks], {"long_name": "slenderness alpha", "units": "rad"})}
    dataset = xr.Dataset({
        "peak_angle_ratio_to_housner": (dims, ratio, {"long_name": "median peak angle of the model over Housner's "
                                                                   "(records surviving in both)", "units": "1"}),
        "overturning_fraction_difference": (dims, overturn_difference,
                                            {"long_name": "overturning fraction of the model minus Housner's",
                                             "units": "1"}),
        "history_correlation": (dims, median_correlation,
                                {"long_name": "median Pearson correlation of the model's and Housner's rotation "
                                              "histories", "units": "1"}),
        "threshold_shear_modulus": (dims[:4], thresholds,
                                    {"long_name": f"G_s above which Housner stays within {tolerance:.0%} of the model",
                                     "units": "Pa"}),
        "threshold_relative_stiffness": (dims[:4], coords["block_modulus"][1][None, None, :, None] / thresholds,
                                         {"long_name": "relative stiffness E_b / G_s at the threshold", "units": "1"}),
    }, coords=coords)
    dataset.attrs = {"Conventions": "CF-1.12", "title": "rockfrag applicability of the rigid-base model",
                     "tolerance": tolerance, "n_records": len(records), "damping_ratio": xi,
                     "paper_threshold": "G_s between 300 and 1000 MPa"}
    return dataset


def sweep_figure(dataset):
    """Median SSI/Housner peak-angle ratio against G_s, one panel per block."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tolerance = dataset.attrs["tolerance"]
    n_blocks = dataset.sizes["block"]
    n_models = dataset.sizes["model"]
    figure, axes = plt.subplots(n_models, n_blocks, figsize=(4.6 * n_blocks, 3.6 * n_models + 1.2), sharey=True,
                                squeeze=False, constrained_layout=True)
    shear = dataset.shear_modulus.values / 1e6
    styles = ["-", "--", ":", "-."]
    for row, model in enumerate(dataset.model.values):
        label = str(dataset.model_label.values[row]) if "model_label" in dataset.coords else str(model)
        for axis, block in zip(axes[row], dataset.block.values):
            for e_index, modulus in enumerate(dataset.block_modulus.values):
                for l_index, level in enumerate(dataset.level.values):
                    ratio = dataset.peak_angle_ratio_to_housner.sel(model=model, block=block).values[e_index, l_index]
                    axis.semilogx(shear, ratio, color=f"C{l_index}", ls=styles[e_index % 4], marker=".",
                                  label=f"E_b = {modulus / 1e9:.0f} GPa, PGA = {level:g}·g·tanα")
            axis.axhspan(1 - tolerance, 1 + tolerance, color="0.85")
            axis.axvspan(300, 1000, color="C2", alpha=0.12)
            axis.axhline(1.0, color="k", lw=0.7)
            axis.set_title(f"{block}: {label}", fontsize=9)
            axis.set_xlabel("soil shear modulus G_s [MPa]")
            axis.grid(alpha=0.3, which="both")
        axes[row, 0].set_ylabel("median θmax model / Housner [-]")
    axes[0, -1].legend(fontsize=6.5, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    figure.suptitle(f"Rigid-base error against soil stiffness (grey: ±{tolerance:.0%}; green: paper's 300-1000 MPa)")
    figure.get_layout_engine().set(rect=(0, 0.045, 1, 0.955))
    figure.text(0.01, 0.005, f"Median over {dataset.attrs['n_records']} records that survived in both models; "
                "solid: concrete block, dashed: steel block (relative stiffness E_b/G_s).",
                fontsize=8, style="italic")
    return figure


def write_applicability(dataset: xr.Dataset, output: str | Path) -> list[Path]:
    """Write ``applicability.nc`` (compressed) and ``applicability-sweep.png`` into ``output``.

    Returns
    -------
    list of Path
        The two files written, each replaced atomically.
    """
    import matplotlib.pyplot as plt  # lazily, as sweep_figure: importing pyplot costs ~1.7 s

    output = Path(output)
    write_dataset(dataset, output / "applicability.nc")
    figure = sweep_figure(dataset)
    path = output / "applicability-sweep.png"
    with atomic_path(path) as temporary:
        figure.savefig(temporary, dpi=120, format="png")
    plt.close(figure)
    return [output / "applicability.nc", path]


def applicability_stage(config, output, workers=None, progress=True, log=print,
                        loaded: StudyRecords | None = None):
    """Run the study's sweep (``config.applicability``), or reuse ``applicability.nc`` when its inputs are unchanged.

    ``loaded`` may pass the study's ``StudyRecords`` (``study.study_records(config)``) to avoid reading
    the records again.
    """
    output = Path(output)
    loaded = loaded or study_records(config, log)
    records, recipe = loaded.records, loaded.recipe
    sweep = config.applicability  # the study's [applicability] table: one definition for every caller
    # the recommended model's sample members are one model here: the sweep runs each foundation model once, at xi = 0.05
    models = list(dict.fromkeys(get_model(name).name for name in config.models
                                if not get_model(name).is_rigid_base)) or list(DEFAULT_MODELS)
    models.sort(key=lambda name: get_model(name).can_pull)  # the admissible (tensionless) models first
    options = {"switch": config.switch, "bed": config.bed}
    key = hashlib.sha256(json.dumps({
        "version": __version__, "recipe": recipe.as_dict(), "blocks": [repr(b) for b in config.blocks],
        "models": models, "options": options, "sweep": asdict(sweep),
        "records": [r.metadata.get("sha256", r.id) for r in records]}, sort_keys=True).encode()).hexdigest()[:16]
    existing = output / "applicability.nc"
    if existing.is_file():
        with xr.open_dataset(existing) as cached:
            if cached.attrs.get("input_hash") == key:
                log(f"reused {existing} (inputs unchanged)")
                return cached.load()
    dataset = run_applicability(records, config.blocks, shear_moduli=sweep.shear_moduli,
                                block_moduli=sweep.block_moduli, level_factors=sweep.levels,
                                tolerance=sweep.tolerance, workers=workers, progress=progress, models=models,
                                options=options)
    dataset.attrs["input_hash"] = key
    for path in write_applicability(dataset, output):
        log(f"wrote {path}")
    return dataset
