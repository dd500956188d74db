"""rockfrag.cube - the result schema of a study: a labelled xarray cube and its netCDF file.

Input : per-run summary vectors from the solvers, arranged (record, im_level, soil, block, model),
        plus record, soil, block metadata and the study configuration.
Output: an ``xarray.Dataset`` following CF-1.12 (every variable with ``units`` and ``long_name``,
        ``outcome`` with ``flag_values``/``flag_meanings``), written atomically as compressed netCDF4
        (``reports/cube.nc``) that plain ``xarray.open_dataset`` reads.

Vertical component: every cube says per record whether the record's vertical component was applied
(``vertical_applied``, with the vertical's id and PGA), and in its ``vertical`` attribute whether the study
applied verticals. A study with ``[study] vertical = true`` writes two cubes of the same records, levels and
scale factors: ``cube.nc`` with the verticals and ``COMPARISON_CUBE`` without them (rockfrag.study).

Units: one per quantity in the file, as UDUNITS parses it (``rockfrag.measures.file_units``). Every
acceleration (levels, ``intensity``, ``record_pga``, ``block_uplift_acceleration``, ``record_im`` of an
acceleration measure) is in multiples of g, written "9.80665 m s-2" (UDUNITS reads "g" as grams);
velocities in "m s-1"; the rest SI.

The recommended model's designed sample (rockfrag.models.variants): the ``model`` coordinate holds the models
that answer or serve as references (``housner``, ``ssi``, ``recommended``, the central member); the other
members of the sample live apart, in a ``member`` dimension: every per-model variable ``X`` of theirs is
``member_X`` over (..., member) (``members_apart``), and ``member_cube`` puts them back as a cube of their own
whose ``model`` coordinate is the members' model names (what the fragility stage fits).
"""

from __future__ import annotations

import json

import numpy as np
import xarray as xr

from rockfrag.measures import MEASURES, file_units, parse_units
from rockfrag.models import get_model, model_label
from rockfrag.models.base import Outcome
from rockfrag.models.fields import FIELDS_BY_NAME, MODE_TIME_FIELDS
from rockfrag.models.ssi import PAPER_CITATION
from rockfrag.models.variants import MEMBER_LABELS, member_model, split_variant
from rockfrag.version import __version__

# Kept for the stages that read outcomes (ida, fragility): the one enum is rockfrag.models.base.Outcome.
OUTCOME_NO_UPLIFT, OUTCOME_ROCKING, OUTCOME_OVERTURNED, OUTCOME_FAILED, OUTCOME_FREE_FLIGHT = (
    int(Outcome.NO_UPLIFT), int(Outcome.ROCKING), int(Outcome.OVERTURNED), int(Outcome.FAILED),
    int(Outcome.FREE_FLIGHT))
OUTCOME_MEANINGS = " ".join(o.flag_meaning for o in Outcome)

COMPARISON_CUBE = "cube_without_vertical.nc"
"""The second cube of a ``[study] vertical = true`` study: the same records, levels and scale factors, the
horizontal components alone (the report compares it with ``cube.nc``)."""
VERTICAL_APPLIED, VERTICAL_NOT_APPLIED = "applied", "not applied"
"""Values of a cube's ``vertical`` attribute."""

DIMS = ("record", "im_level", "soil", "block", "model")

STEP_LEVEL = "step_level"
"""The dimension of the runs that place a cell's steps between its levels (rockfrag.steps): ``step_intensity``
(step_level, soil, block, model) [the measure's display unit; NaN: no run] and, of each run, ``step_X`` over
(record, step_level, soil, block, model) for the per-run variables ``X`` the damage states read
(``STEP_RUN_VARIABLES``)."""
STEP_RUN_VARIABLES = ("outcome", "peak_uplift", "peak_angle_ratio", "peak_slip")
"""The per-run variables kept of a step's runs (besides each damage state's own measure)."""

COMPONENT_ROTD50, COMPONENT_SINGLE = "RotD50", "single component"
"""Values of a cube's per-record ``record_intensity_component`` and of its ``intensity_component`` attribute (which
is "mixed" when both occur): what the record's intensity, and so its scale factors, is the measure of."""
COMPONENT_MIXED = "mixed"
COMPONENT_DEFINITIONS = {
    COMPONENT_ROTD50: "RotD50 (Boore 2010, BSSA 100(4)): the median over rotation angles 0-179 deg (1 deg apart) of "
                      "the peak of the rotated horizontal component a1 cos(theta) + a2 sin(theta) of the record's "
                      "station pair (for Sa the oscillator responses rotated); both components of a pair have one "
                      "scale factor, and both run",
    COMPONENT_SINGLE: "the record's own horizontal component, as recorded (each component scaled by its own measure)",
}
"""What each component definition means (the cube's and fragility.nc's ``intensity_component_definition``)."""


def credible_attributes(cap, reason, beyond=False) -> dict:
    """The global attributes stating the credible cap: one value when every block has it, else one per block."""
    cap = np.asarray(cap, float)
    return {"credible_intensity_max": float(cap[0]) if np.allclose(cap, cap[0], rtol=1e-12) else cap,
            "credible_intensity_reason": str(reason),
            "beyond_credible": "levels above the cap ran (research), not fitted" if beyond
            else "no levels above the cap"}


def component_attributes(flags) -> dict:
    """The global attributes that state the intensity's component definition, from the per-record flags."""
    kinds = list(dict.fromkeys(str(flag) for flag in flags))
    if kinds == [COMPONENT_ROTD50] or kinds == [COMPONENT_SINGLE]:
        return {"intensity_component": kinds[0], "intensity_component_definition": COMPONENT_DEFINITIONS[kinds[0]]}
    single = sum(str(flag) == COMPONENT_SINGLE for flag in flags)
    return {"intensity_component": COMPONENT_MIXED,
            "intensity_component_definition": f"{COMPONENT_DEFINITIONS[COMPONENT_ROTD50]}; {single} of {len(flags)} "
                                              "records without a partner: "
                                              f"{COMPONENT_DEFINITIONS[COMPONENT_SINGLE]} (record_intensity_component)"}


def _always(model):
    return True


def _foundation(model):
    return model.needs_foundation


def _pulls(model):
    return model.can_pull


def _bed(model):
    return model.uses_bed


# Cube variable: (summary field of rockfrag.models.fields, which models it applies to; NaN elsewhere).
# Units and long names come from the field; derived variables (outcome, peak_angle_ratio,
# support_tension) are added below.
VARIABLES = {
    "peak_angle": ("peak_angle", _always),
    "time_of_peak": ("time_of_peak", _always),
    "n_impacts": ("n_impacts", _always),
    "time_of_uplift": ("time_of_uplift", _always),
    "peak_uplift": ("peak_corner_uplift", _always),
    "peak_settlement": ("peak_settlement", _foundation),
    "min_support_force": ("min_support_force", _foundation),
    "time_of_tension": ("time_of_tension", _pulls),
    "n_flights": ("n_flights", _bed),
    "airborne_time": ("airborne_time", _bed),
    "peak_friction_demand": ("peak_friction_demand", _bed),
    "time_of_free_flight": ("time_of_free_flight", _always),
}

SLIP_VARIABLES = ("peak_slip", "residual_slip", *MODE_TIME_FIELDS)
"""Cube variables of the base's slip and the time in each contact mode [m, s]: finite only in the cells that
run with friction (``friction_static`` finite), NaN where the base is tied (rockfrag.study.cell_friction)."""
FRICTION_VARIABLES = {
    "friction_static": "static friction coefficient mu_s of the base in the cell's runs (NaN: the base is tied, "
                       "no sliding)",
    "friction_kinetic": "kinetic friction coefficient mu_k of the base in the cell's runs (NaN: the base is tied)",
}


def summaries_to_variables(summaries, blocks, model_names, friction=None):
    """Turn summary records (record, level, soil, block, model) into named arrays (NaN where not applicable).

    ``friction`` (2, soil, block, model): each cell's (mu_s, mu_k), NaN where tied (None: every base tied); the
    ``SLIP_VARIABLES`` are NaN in the tied cells.
    """
    models = [get_model(name) for name in model_names]
    mass = np.array([b.mass for b in blocks])[None, None, None, :, None]
    alpha = np.array([b.alpha for b in blocks])[None, None, None, :, None]
    out = {}
    for name, (field, applies) in VARIABLES.items():
        mask = np.array([applies(model) for model in models])[None, None, None, None, :]
        values = summaries[field] * mass if FIELDS_BY_NAME[field].per_mass else summaries[field]
        out[name] = np.where(mask, values, np.nan)
    sliding = np.zeros(summaries.shape[2:], bool) if friction is None else np.isfinite(friction[0])
    for name in SLIP_VARIABLES:
        out[name] = np.where(sliding[None, None], summaries[name], np.nan)
    out["outcome"] = np.nan_to_num(summaries["status"], nan=int(Outcome.FAILED)).astype(np.int8)
    out["peak_angle_ratio"] = out["peak_angle"] / alpha
    pulls = np.array([model.can_pull for model in models])[None, None, None, None, :]
    tension = np.where(out["min_support_force"] < 0, 1, 0).astype(np.int8)
    out["support_tension"] = np.where(pulls, tension, -1).astype(np.int8)
    return out


DERIVED_ATTRIBUTES = {
    "outcome": {"long_name": "outcome of the run", "units": "1",
                "flag_values": np.array([int(o) for o in Outcome], dtype=np.int8), "flag_meanings": OUTCOME_MEANINGS},
    "peak_angle_ratio": {"long_name": "peak rocking angle over slenderness alpha", "units": "1"},
    "support_tension": {"long_name": "the paper's spring pulled on the block during the run "
                                     "(results after time_of_tension are not physical)", "units": "1",
                        "flag_values": np.array([-1, 0, 1], dtype=np.int8),
                        "flag_meanings": "not_applicable no_tension tension"},
}


def build_cube(config, records, record_im, scale_factors, summaries, stiffness, provenance, *,
               intensity=None, capacities=None, capacity_stats=None, verticals=None,
               vertical_applied=False, calibration=None, friction=None, partners=None,
               component_im=None, uplift=None, credible=None, model_stiffness=None) -> xr.Dataset:
    """Assemble the labelled cube.

    records : list of Record (metadata); record_im : (n_record, n_block) (or (n_record,)) IM of each
    processed record [SI]; scale_factors : (n_record, n_level, n_block) (or (n_record, n_level));
    summaries : summary records (n_record, n_level, n_soil, n_block, n_model); stiffness : (n_soil, n_block)
    interface stiffness [N/m]; provenance : dict of JSON-able facts; intensity : (n_block, n_level)
    physical intensity of every level [SI] (default: the absolute levels); capacities : (4, n_record,
    n_soil, n_block, n_model) adaptive overturning capacity, bracket and extra runs as scale factors
    (rockfrag.study.gather_capacities) or None; capacity_stats : its run accounting; verticals : the
    processed vertical component of each record (a Record, or None where it has none), or None when the
    study takes no verticals; vertical_applied : whether the runs applied those verticals (the cube's
    ``vertical_applied`` flag per record, and its ``vertical`` attribute); friction : (2, n_soil, n_block,
    n_model) each cell's base friction (mu_s, mu_k) [-], NaN where tied (rockfrag.study.friction_grid; None:
    every base tied): the cube's ``friction_static``/``friction_kinetic`` and where ``SLIP_VARIABLES`` apply;
    partners : the record id of each record's partner in RotD50 scaling ("" or None: scaled by its own
    component; None for all: no pairs); component_im : (n_record, n_block) each record's own component's
    measure [SI] (default: ``record_im``); uplift : (n_block,) each block's uplift intensity [SI] of relative
    levels (rockfrag.study.uplift_intensity; default: the lowest level over its multiple); credible : (cap
    (n_block,) [SI], reason, beyond) the credible cap on the intensity (rockfrag.study.credible_cap), its reason
    and whether levels run beyond it, or None (no cap: a cube made by hand).

    Layout: ``im_level`` is the level index: multiples of each block's uplift intensity (units "1")
    with ``levels.relative_to = "uplift"``, else the levels in the measure's display unit. The physical
    intensity is always the (block, im_level) coordinate ``intensity`` [display unit]; read it, not
    ``im_level``, for intensities. Intensities, ``record_im`` and every acceleration are stored in the
    measure's display unit (g for accelerations), with ``units`` as UDUNITS parses them (see module docstring).
    """
    model_names = list(config.models)
    n_block = len(config.blocks)
    if friction is None:
        friction = np.full((2, len(config.soils), n_block, len(model_names)), np.nan)
    values = summaries_to_variables(summaries, config.blocks, model_names, friction)
    measure = MEASURES[config.measure]
    acceleration_units = file_units("m/s^2")
    g_factor = parse_units(acceleration_units)[0]  # SI value of one unit of acceleration_units
    measure_name = measure.describe(**config.measure_options)
    record_im = np.asarray(record_im, float)
    if record_im.ndim == 1:
        record_im = np.repeat(record_im[:, None], n_block, axis=1)
    scale_factors = np.asarray(scale_factors, float)
    if scale_factors.ndim == 2:
        scale_factors = np.repeat(scale_factors[:, :, None], n_block, axis=2)
    partners = [str(p or "") for p in (partners if partners is not None else [""] * len(records))]
    flags = [COMPONENT_ROTD50 if p else COMPONENT_SINGLE for p in partners]
    component_im = record_im if component_im is None else np.asarray(component_im, float).reshape(record_im.shape)
    if intensity is None:
        intensity = np.broadcast_to(config.levels_si, (n_block, len(config.levels)))
    intensity = np.asarray(intensity, float)
    data_vars = {}
    for name, array in values.items():
        if name in DERIVED_ATTRIBUTES:
            data_vars[name] = (DIMS, array, dict(DERIVED_ATTRIBUTES[name]))
        else:
            field = FIELDS_BY_NAME[VARIABLES[name][0] if name in VARIABLES else name]
            data_vars[name] = (DIMS, array, {"long_name": field.long_name, "units": field.units})
    data_vars["scale_factor"] = (("record", "im_level", "block"), scale_factors,
                                 {"long_name": "factor applied to the processed record", "units": "1"})
    if capacities is not None:
        capacity_dims = ("record", "soil", "block", "model")
        for index, (name, long_name) in enumerate((
                ("capacity_scale_factor", "overturning capacity as a scale factor: midpoint of the adaptive "
                                          "bracket (NaN: no overturning found)"),
                ("capacity_scale_lower", "largest scale factor found to survive below the capacity"),
                ("capacity_scale_upper", "smallest scale factor found to overturn"),
                ("capacity_runs", "solver runs added to the stripes to refine the capacity"))):
            data_vars[name] = (capacity_dims, capacities[index], {"long_name": long_name, "units": "1"})
    vertical_flag, vertical_coords = _vertical_variables(records, verticals, vertical_applied, g_factor,
                                                         acceleration_units)
    data_vars["vertical_applied"] = vertical_flag
    data_vars["interface_stiffness"] = (("soil", "block"), stiffness,
                                        {"long_name": "interface stiffness k (paper eq. 19)", "units": "N m-1"})
    data_vars.update(_calibration_variables(calibration, model_names, stiffness.shape))
    if model_stiffness is not None:
        data_vars["bed_stiffness"] = (("soil", "block", "model"), model_stiffness, {
            "long_name": "bed stiffness K each model runs (paper eq. 19; a stiffness member's G scaled)",
            "units": "N m-1"})
    credible_attrs = {}
    if credible is not None:
        cap, reason, beyond = credible
        cap = np.asarray(cap, float) / measure.display_factor
        data_vars["credible_intensity_max"] = ("block", cap, {
            "long_name": f"credible cap on the {measure_name}: the fits, risk and exchange files use only the levels "
                         f"at or below it ({reason})", "units": measure.cf_units()})
        inside = intensity / measure.display_factor <= cap[:, None] * (1 + 1e-9)
        data_vars["credible_level"] = (("block", "im_level"), inside.astype(np.int8),
                                       {"long_name": "1 where the level lies at or below the credible cap",
                                        "units": "1", "flag_values": np.array([0, 1], np.int8),
                                        "flag_meanings": "beyond_credible credible"})
        credible_attrs = credible_attributes(cap, reason, beyond)
    for index, (name, long_name) in enumerate(FRICTION_VARIABLES.items()):
        data_vars[name] = (("soil", "block", "model"), friction[index], {"long_name": long_name, "units": "1"})
    coords = {
        "record": ("record", [r.id for r in records], {"long_name": "record id (records/MANIFEST.csv)"}),
        **_level_coordinates(config, measure_name, intensity, uplift),
        "soil": ("soil", [s.name for s in config.soils], {"long_name": "soil class"}),
        "block": ("block", [b.name for b in config.blocks], {"long_name": "block"}),
        "model": ("model", model_names, {"long_name": "rocking model"}),
        "model_label": ("model", [model_label(name) for name in model_names], {"long_name": "rocking model"}),
        "record_event": ("record", [str(r.metadata.get("event", "")) for r in records], {"long_name": "earthquake"}),
        "record_station": ("record", [str(r.metadata.get("station", "")) for r in records], {"long_name": "station"}),
        "record_component": ("record", [str(r.metadata.get("component", "")) for r in records],
                             {"long_name": "component"}),
        "record_pga": ("record", [float(np.max(np.abs(r.acceleration))) / g_factor for r in records],
                       {"long_name": "PGA of the processed record", "units": acceleration_units}),
        **vertical_coords,
        "record_im": (("record", "block"), record_im / measure.display_factor,
                      {"long_name": f"{measure_name} of the processed record as the study scales it (its pair's "
                                    "RotD50 where record_intensity_component says so, else its own component)",
                       "units": measure.cf_units()}),
        "record_component_im": (("record", "block"), component_im / measure.display_factor,
                                {"long_name": f"{measure_name} of the processed record's own component",
                                 "units": measure.cf_units()}),
        "record_intensity_component": ("record", flags, {
            "long_name": "what record_im and the scale factors are the measure of: RotD50 of the station's pair of "
                         "horizontal components, or the single component"}),
        "record_partner": ("record", partners, {
            "long_name": "record id of the other horizontal component of the record's pair (empty: none)"}),
        "soil_shear_modulus": ("soil", [s.shear_modulus for s in config.soils],
                               {"long_name": "soil shear modulus G_s", "units": "Pa"}),
        "soil_constrained_modulus": ("soil", [s.constrained_modulus for s in config.soils],
                                     {"long_name": "soil constrained modulus 2G(1-nu)/(1-2nu) (paper's E_d)",
                                      "units": "Pa"}),
        "soil_damping_ratio": ("soil", [s.damping_ratio for s in config.soils],
                               {"long_name": "damping ratio xi of the vertical dashpot", "units": "1"}),
        "soil_friction_static": ("soil", [s.friction_static for s in config.soils],
                                 {"long_name": "static friction coefficient mu_s of a base on the soil", "units": "1"}),
        "soil_friction_kinetic": ("soil", [s.friction_kinetic for s in config.soils],
                                  {"long_name": "kinetic friction coefficient mu_k of a base on the soil",
                                   "units": "1"}),
        "block_R": ("block", [b.R for b in config.blocks], {"long_name": "semi-diagonal R", "units": "m"}),
        "block_alpha": ("block", [b.alpha for b in config.blocks], {"long_name": "slenderness angle alpha",
                                                                    "units": "rad"}),
        "block_b": ("block", [b.b for b in config.blocks], {"long_name": "half-width b", "units": "m"}),
        "block_h": ("block", [b.h for b in config.blocks], {"long_name": "half-height h", "units": "m"}),
        "block_mass": ("block", [b.mass for b in config.blocks], {"long_name": "mass", "units": "kg"}),
        "block_uplift_acceleration": ("block", [b.uplift_acceleration() / g_factor for b in config.blocks],
                                      {"long_name": "Housner uplift threshold g tan(alpha)",
                                       "units": acceleration_units}),
    }
    dataset = xr.Dataset(data_vars, coords=coords)
    dataset.attrs = {
        "Conventions": "CF-1.12",
        "title": f"rockfrag study '{config.name}': rocking response cube",
        "institution": "rockfrag",
        "source": f"rockfrag {__version__}",
        "rockfrag_version": __version__,
        "intensity_measure": config.measure,
        "intensity_measure_long_name": measure_name,
        **component_attributes(flags),
        **credible_attrs,
        "levels_relative_to": config.levels_relative_to,
        **{key: value for key, value in (capacity_stats or {}).items()},
        "study_config": config.as_json(),
        "config_hash": config.config_hash,
        "record_checksums": json.dumps({r.id: r.metadata.get("sha256", "") for r in records}),
        "processing": json.dumps(provenance.get("processing", {})),
        "processing_steps": json.dumps(provenance.get("processing_steps", {})),
        "references": f"Housner (1963); SSI-rocking model from the Lagrangian of the paper: {PAPER_CITATION}; "
                      "tensionless Winkler bed (Psycharis & Jennings 1983; Chopra & Yim 1985)",
        "winkler_bed": config.bed,
        "restitution": str(config.restitution),
        "restitution_range": json.dumps(list(config.design.restitution_range)),
        "friction_factor": config.design.friction_factor,
        "stiffness_factor": config.design.stiffness_factor,
        "vertical": VERTICAL_APPLIED if vertical_applied else VERTICAL_NOT_APPLIED,
        "friction": config.friction,
    }
    return members_apart(dataset)


def members_apart(dataset: xr.Dataset) -> xr.Dataset:
    """The cube with the recommended model's sample members (all but the central one) in a ``member`` dimension.

    Every per-model variable ``X`` of the members becomes ``member_X`` over ``member`` instead of ``model``; the
    ``model`` coordinate keeps the others (``housner``, ``ssi``, ``recommended``). A cube without members is
    returned as it is.
    """
    names = [str(m) for m in dataset.model.values if split_variant(str(m))[1] not in (None, "centre")]
    if not names:
        return dataset
    members = dataset.sel(model=names)
    out = dataset.drop_sel(model=names)
    for name, variable in members.data_vars.items():
        if "model" in variable.dims:
            out[f"member_{name}"] = variable.drop_vars(["model", "model_label"], errors="ignore").rename(
                model="member").assign_attrs(long_name=f"sample member: {variable.attrs.get('long_name', name)}")
    roles = [split_variant(name)[1] for name in names]
    out = out.assign_coords(
        member=("member", roles, {"long_name": "member of the recommended model's designed sample (one parameter "
                                                "at the low or high end of its range, the others central)"}),
        member_label=("member", [MEMBER_LABELS[role] for role in roles],
                      {"long_name": "what the member changes from the central member"}))
    return out


def member_cube(cube: xr.Dataset) -> xr.Dataset | None:
    """The sample members as a cube of their own (``model`` = ``recommended-<member>``); None without members."""
    if "member" not in cube.dims:
        return None
    prefixed = [name for name in cube.data_vars if name.startswith("member_") and "member" in cube[name].dims]
    plain = [name for name in cube.data_vars if "model" not in cube[name].dims and name not in prefixed]
    members = cube[plain].drop_vars(["model", "model_label"], errors="ignore").drop_dims("model", errors="ignore")
    for name in prefixed:
        variable = cube[name]
        members[name.removeprefix("member_")] = variable.assign_attrs(
            long_name=variable.attrs.get("long_name", name).removeprefix("sample member: "))
    members = members.drop_vars(["member_label"], errors="ignore").rename(member="model")
    return members.assign_coords(model=[member_model(str(role)) for role in members.model.values])


CALIBRATION_VARIABLES = {
    "restitution_requested": "effective restitution of free rocking asked of the bed (the sample's restitution "
                             "range, or the target)",
    "restitution_target": "effective restitution the bed's damping is calibrated to (the requested one, or the "
                          "nearest the bed reaches)",
    "damping_ratio_calibrated": "damping ratio xi of the bed calibrated to the restitution target",
}


def _calibration_variables(calibration, model_names, shape) -> dict:
    """The bed models' restitution targets and calibrated damping per (soil, block, model); NaN elsewhere."""
    if calibration is None:
        return {}
    arrays = {name: np.full((*shape, len(model_names)), np.nan) for name in CALIBRATION_VARIABLES}
    for v, model in enumerate(calibration.variants):
        m = model_names.index(model)
        arrays["restitution_requested"][..., m] = calibration.requested[..., v]
        arrays["restitution_target"][..., m] = calibration.target[..., v]
        arrays["damping_ratio_calibrated"][..., m] = calibration.xi[..., v]
    out = {name: (("soil", "block", "model"), arrays[name], {"long_name": long_name, "units": "1"})
           for name, long_name in CALIBRATION_VARIABLES.items()}
    out["restitution_reachable"] = (("soil", "block", "bound"), calibration.reachable, {
        "long_name": "lowest and highest effective restitution the bed's calibrated law reaches at its admissible xi",
        "units": "1"})
    return out


def _vertical_variables(records, verticals, applied, g_factor, acceleration_units) -> tuple[tuple, dict]:
    """Per record: whether its vertical component was applied, the vertical's id and its PGA [g].

    Returns the flag variable and the two coordinates (beside ``record_pga``).
    """
    verticals = list(verticals) if verticals is not None else [None] * len(records)
    flags = np.array([int(applied and vertical is not None) for vertical in verticals], dtype=np.int8)
    pgas = [float(np.max(np.abs(v.acceleration))) / g_factor if v is not None else np.nan for v in verticals]
    flag = ("record", flags, {
        "long_name": "the record's vertical component was applied: gravity g + a_v(t) in every model",
        "units": "1", "flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": "horizontal_only with_vertical"})
    return flag, {
        "record_vertical": ("record", [v.id if v is not None else "" for v in verticals],
                            {"long_name": "record id of the vertical component of the record's station "
                                          "(empty: none in the study)"}),
        "record_vertical_pga": ("record", pgas, {
            "long_name": "PGA of the processed vertical component (NaN: none in the study)",
            "units": acceleration_units}),
    }


def _shared(values, listed):
    """The levels every block shares, (n_level,): the study's listed ones where they are those; None if none."""
    if not np.allclose(values, values[:1], rtol=1e-9):
        return None
    if listed.size == values.shape[1] and np.allclose(values[0], listed, rtol=1e-9):
        return listed
    return values[0]


def _level_coordinates(config, measure_name, intensity, uplift=None) -> dict:
    """``im_level`` and the per-block intensities, in the measure's display unit (``Measure.cf_units``).

    ``im_level`` holds what the blocks' levels share: the absolute levels when every block has the same, the
    multiples of each block's uplift intensity when those are the same, else the level's number (1, 2, ...: a
    grid re-spaced per block up to the credible cap). ``intensity`` (block, im_level) always holds the levels, and
    with relative levels ``level_multiple`` (block, im_level) their multiples of the block's uplift intensity.
    """
    measure = MEASURES[config.measure]
    units = measure.cf_units()
    n_level = intensity.shape[1]
    numbers = ("im_level", np.arange(1.0, n_level + 1.0), {
        "long_name": f"intensity level number: each block's levels ({measure_name}) are its own, re-spaced up to the "
                     "credible cap (intensity, level_multiple)", "units": "1"})
    extra = {}
    listed = np.asarray(config.levels, float)
    if config.relative_levels:
        uplift = intensity[:, 0] / float(config.levels[0]) if uplift is None else np.asarray(uplift, float)
        multiples = intensity / uplift[:, None]
        extra["block_uplift_intensity"] = ("block", uplift / measure.display_factor, {
            "long_name": f"{measure_name} at which the block starts to rock (rockfrag.study.uplift_intensity; "
                         "exact g tan(alpha) only under each component's own PGA, else the records' median)",
            "units": units})
        extra["level_multiple"] = (("block", "im_level"), multiples, {
            "long_name": "the level as a multiple of the block's uplift intensity", "units": "1"})
        shared = _shared(multiples, listed)
        level = numbers if shared is None else ("im_level", shared, {
            "long_name": f"intensity level: multiple of the block's uplift intensity ({measure_name})", "units": "1"})
    else:
        shared = _shared(intensity / measure.display_factor, listed)
        level = numbers if shared is None else ("im_level", shared, {
            "long_name": f"intensity level: {measure_name}", "units": units})
    return {"im_level": level, **extra,
            "intensity": (("block", "im_level"), intensity / measure.display_factor,
                          {"long_name": f"{measure_name} of the level for the block", "units": units})}
