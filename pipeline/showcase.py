"""rockfrag.showcase - study-time data for the report: record-set measures and spectra, showcase histories.

Input : the study configuration and its processed records (``study.StudyRecords``).
Output: ``reports/showcase.nc`` holding
        * per record (dim ``record``; ``period`` for spectra): PGA [m/s^2], PGV [m/s], Arias
          intensity [m/s], D5-95 [s], Sa(1 s) [m/s^2] and the 5%-damped spectrum of each processed record;
        * for the showcase record (dim ``time_ground``): raw and processed acceleration [m/s^2],
          velocity [m/s] and displacement [m];
        * for every model and soil of the showcase block (dims ``case``, ``time``): the rocking angle
          theta(t) [rad] and the vertical displacement of the foundation y - y_static [m]; a rigid-base
          model is one case (soil "").
        The showcase record is ``[report] showcase_record`` or, when the study contains it, Duezce 1999
        Bolu 090 (the paper's record); the block is ``[report] showcase_block`` or the study's first block.
        The report only reads this file; it never runs a solver. Reused when its inputs are unchanged.
"""

from __future__ import annotations

import hashlib
import json
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from rockfrag.errors import ConfigError, PipelineError
from rockfrag.measures import intensity_measures, response_spectrum, significant_window
from rockfrag.models import get_model, simulate
from rockfrag.models.variants import calibrate_models, split_variant
from rockfrag.outputs import write_dataset
from rockfrag.processing import integrate, process_record
from rockfrag.records import load_records
from rockfrag.soils import soil_block_stiffness
from rockfrag.study import StudyRecords, cell_friction, study_records
from rockfrag.version import __version__

PAPER_RECORD = "DUZCE/BOL090"
SPECTRUM_PERIODS = np.geomspace(0.02, 10.0, 60)
FILE_NAME = "showcase.nc"


def report_settings(config) -> dict:
    """The study's ``[report]`` table (title, project, author, showcase_record, showcase_block, ...)."""
    settings = config.raw.get("report", {})
    return settings if isinstance(settings, dict) else {}


def is_rigid_base(model) -> bool:
    """True when the model's result does not depend on the soil (e.g. Housner)."""
    return model.is_rigid_base


def showcase_record_id(config, record_ids) -> str | None:
    """The record the showcase pages draw, or None (no showcase pages)."""
    named = str(report_settings(config).get("showcase_record", "") or "")
    if named:
        return named
    return PAPER_RECORD if PAPER_RECORD in record_ids else None


def showcase_block(config):
    """The block of the showcase pages: ``[report] showcase_block`` or the study's first block."""
    name = str(report_settings(config).get("showcase_block", "") or "")
    if not name:
        return config.blocks[0]
    for block in config.blocks:
        if block.name == name:
            return block
    raise ConfigError("report.showcase_block", f"unknown block {name!r}; blocks of the study: "
                      f"{', '.join(b.name for b in config.blocks)}", config.source)


def record_set_variables(records) -> dict:
    """Measures and 5%-damped spectra of the processed records (dims record, period)."""
    measures = [intensity_measures(r.acceleration, r.dt, sa_periods=(1.0,)) for r in records]
    spectra = np.array([response_spectrum(r.acceleration, r.dt, SPECTRUM_PERIODS)["sa"] for r in records])

    def column(key):
        return ("record", np.array([m[key] for m in measures]))

    return {
        "record_pga": (*column("pga_m_s2"), {"long_name": "PGA of the processed record", "units": "m/s^2"}),
        "record_pgv": (*column("pgv_m_s"), {"long_name": "PGV of the processed record", "units": "m/s"}),
        "record_arias": (*column("arias_m_s"), {"long_name": "Arias intensity of the processed record",
                                                "units": "m/s"}),
        "record_d5_95": (*column("d5_95_s"), {"long_name": "significant duration D5-95", "units": "s"}),
        "record_sa_1s": (*column("sa_1s_m_s2"), {"long_name": "Sa(1 s, 5%) of the processed record",
                                                 "units": "m/s^2"}),
        "record_spectrum": (("record", "period"), spectra,
                            {"long_name": "5%-damped spectral acceleration of the processed record",
                             "units": "m/s^2"}),
    }


def _padded(series, n):
    out = np.full(n, np.nan)
    out[:series.size] = series
    return out


def ground_motion_variables(raw, processed) -> dict:
    """Raw and processed acceleration, velocity and displacement on one time axis (dim time_ground)."""
    n = max(raw.acceleration.size, processed.acceleration.size)
    variables = {}
    for stage, record in (("raw", raw), ("processed", processed)):
        velocity, displacement = integrate(record.acceleration, record.dt)
        for quantity, series, units in (("acceleration", record.acceleration, "m/s^2"),
                                        ("velocity", velocity, "m/s"), ("displacement", displacement, "m")):
            variables[f"ground_{quantity}_{stage}"] = (
                "time_ground", _padded(np.asarray(series, dtype=float), n),
                {"long_name": f"ground {quantity} of the showcase record, {stage}", "units": units})
    return variables, np.arange(n) * processed.dt


def response_cases(config, block):
    """(model name, soil or None, friction) for every case of the showcase, as the study runs its cells.

    The recommended model runs its central member only. A rigid-base model runs once (soil None) while its base is
    tied on every soil; where base friction lets it slide on some soil (``study.cell_friction``) it runs once per
    soil, as the study does. friction is the
    base's (mu_s, mu_k) [-] or None (tied).
    """
    cases = []
    for name in config.models:
        if split_variant(name)[1] not in (None, "centre"):
            continue  # the recommended model's sample members: the showcase draws its central run
        slides = [cell_friction(block, soil, name, config.friction) for soil in config.soils]
        if is_rigid_base(get_model(name)) and not any(slides):
            cases.append((name, None, None))
        else:
            cases.extend((name, soil, friction) for soil, friction in zip(config.soils, slides))
    return cases


def simulate_cases(config, block, record):
    """theta(t), y(t) - y_static and the minimum support force of every showcase case."""
    t_end = record.duration + config.tail
    thetas, settlements, support = [], [], []
    time = None
    for name, soil, friction in response_cases(config, block):
        rigid = is_rigid_base(get_model(name))
        options = {"friction": friction}
        if not rigid:
            options.update(k=soil_block_stiffness(soil, block), xi=soil.damping_ratio)
        if not rigid and config.calibrates_bed and get_model(name).uses_bed:  # as the study runs it
            calibration = calibrate_models([block], [soil.name], np.array([[[options["k"]]]]), [name],
                                           config.restitution, config.design, config.bed)
            options.update(xi=float(calibration.xi[0, 0, 0]), bed=calibration.law)
        else:
            options["bed"] = config.bed
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # tension is recorded below, not warned about
            result = simulate(get_model(name).name, record.acceleration, record.dt, block, switch=config.switch,
                              t_end=t_end, overturn_angle=config.overturn_angle, **options)
        time = result.t if time is None or result.t.size > time.size else time
        thetas.append(result.theta)
        if rigid:
            settlements.append(np.full(result.t.size, np.nan))
            support.append(np.nan)
        else:
            settlements.append(result.y - result.y[0])
            support.append(result.min_support_force)
    n = time.size
    return time, np.array([_padded(t, n) for t in thetas]), np.array([_padded(s, n) for s in settlements]), \
        np.array(support, dtype=float)


def showcase_dataset(config, records, recipe, load=None) -> xr.Dataset:
    """Everything ``showcase.nc`` holds (see the module docstring); ``load`` reads a record by id."""
    ids = [r.id for r in records]
    data_vars = record_set_variables(records)
    coords = {"record": ("record", ids, {"long_name": "record id"}),
              "period": ("period", SPECTRUM_PERIODS, {"long_name": "oscillator period", "units": "s"})}
    attrs = {"title": f"rockfrag study '{config.name}': showcase histories and record-set measures",
             "source": f"rockfrag {__version__}", "config_hash": config.config_hash, "showcase_record": ""}
    record_id = showcase_record_id(config, ids)
    if record_id is not None:
        raw_records, failures = (load or load_records)(record_id)
        if failures or len(raw_records) != 1:
            raise ConfigError("report.showcase_record", f"{record_id!r} must name exactly one readable record "
                              f"({failures[0] if failures else f'{len(raw_records)} records found'})",
                              config.source)
        raw = raw_records[0]
        processed = process_record(raw, recipe)
        block = showcase_block(config)
        ground, ground_time = ground_motion_variables(raw, processed)
        time, theta, settlement, support = simulate_cases(config, block, processed)
        cases = response_cases(config, block)
        start, end = significant_window(processed.acceleration, processed.dt)  # the records table's D5-95
        data_vars.update(ground)
        data_vars.update({
            "theta": (("case", "time"), theta, {"long_name": "rocking angle theta (NaN after overturning)",
                                                "units": "rad"}),
            "settlement": (("case", "time"), settlement, {
                "long_name": "vertical displacement of the foundation from its static position, y - y_static",
                "units": "m"}),
            "min_support_force": ("case", support, {"long_name": "minimum vertical foundation force "
                                                               "(negative: the foundation pulled)", "units": "N"}),
            "interface_stiffness": ("case", [np.nan if is_rigid_base(get_model(name))
                                             else soil_block_stiffness(soil, block) for name, soil, _ in cases],
                                    {"long_name": "interface stiffness k (paper eq. 19)", "units": "N m-1"}),
        })
        coords.update({
            "time_ground": ("time_ground", ground_time, {"long_name": "time", "units": "s"}),
            "time": ("time", time, {"long_name": "time", "units": "s"}),
            "case_model": ("case", [name for name, _, _ in cases], {"long_name": "rocking model"}),
            "case_soil": ("case", ["" if soil is None else soil.name for _, soil, _ in cases],
                          {"long_name": "soil class (empty: a rigid base tied on every soil)"}),
            "case_friction_static": ("case", [np.nan if friction is None else friction[0] for _, _, friction in cases],
                                     {"long_name": "static friction coefficient of the base (NaN: tied base)",
                                      "units": "1"}),
        })
        attrs.update({
            "showcase_record": raw.id, "showcase_event": str(raw.metadata.get("event", "")),
            "showcase_station": str(raw.metadata.get("station", "")),
            "showcase_component": str(raw.metadata.get("component", "")),
            "showcase_block": block.name, "block_R_m": block.R, "block_alpha_rad": block.alpha,
            "strong_motion_start_s": start, "strong_motion_end_s": end,
            "strong_motion_definition": "5% to 95% of the Arias intensity of the processed record",
        })
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def input_hash(config, records, recipe) -> str:
    """Hash of everything ``showcase.nc`` depends on."""
    settings = report_settings(config)
    payload = {"version": __version__, "recipe": recipe.as_dict(), "models": list(config.models),
               "records": [r.metadata.get("sha256", r.id) for r in records],
               "soils": [repr(s) for s in config.soils], "blocks": [repr(b) for b in config.blocks],
               "showcase": [settings.get("showcase_record", ""), settings.get("showcase_block", "")],
               "solver": [config.switch, config.tail, config.overturn_angle, config.bed, str(config.restitution),
                          repr(config.design), config.friction]}
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=str).encode()).hexdigest()[:16]


def showcase_stage(config, output, loaded: StudyRecords | None = None, log=print) -> xr.Dataset:
    """Write ``showcase.nc`` (or reuse it when its inputs are unchanged); returns the dataset.

    ``loaded`` may pass the study's ``StudyRecords`` (``study.study_records(config)``) to avoid reading
    the records again.
    """
    path = Path(output) / FILE_NAME
    loaded = loaded or study_records(config, log)
    records, recipe = loaded.records, loaded.recipe
    if not records:
        raise PipelineError("no record to describe in showcase.nc")
    key = input_hash(config, records, recipe)
    if path.is_file():
        with xr.open_dataset(path) as cached:
            if cached.attrs.get("input_hash") == key:
                log(f"reused {path} (inputs unchanged)")
                return cached.load()
    dataset = showcase_dataset(config, records, recipe)
    dataset.attrs["input_hash"] = key
    write_dataset(dataset, path)
    log(f"wrote {path}")
    return dataset
