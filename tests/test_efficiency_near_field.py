"""The shipped near-field pulse study runs end to end on a tiny subset: cube, IDA, measure ranking."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rockfrag.config import load_study
from rockfrag.efficiency import efficiency_dataset, efficiency_table
from rockfrag.ida import ida_dataset
from rockfrag.study import run_study, study_records

STUDY = Path(__file__).resolve().parents[1] / "studies" / "near-field-pulse.toml"
SUBSET = ["NORTHR/RRS_032", "IMPVALL/H-E06_233", "LANDERS/LCN_239"]


def test_near_field_pulse_study_runs_on_a_subset(tmp_path):
    config = load_study(STUDY, overrides={
        "study": {"record_sets": SUBSET}, "soils": ["rock"], "models": ["housner"],
        "solver": {"friction": "none"},  # overturning capacities of rocking blocks: the skid would slide on rock
        # beyond the credible cap: the capacities of research IDA to overturning, not hunted only up to 3 g
        "intensity": {"levels": {"start": 0.5, "stop": 30.0, "count": 6, "relative_to": "uplift"},
                      "beyond_credible": True}})
    assert config.name == "near-field-pulse" and config.relative_levels
    loaded = study_records(config, log=lambda m: None)
    cube, stats = run_study(config, output=tmp_path, workers=1, progress=False, log=lambda m: None, loaded=loaded)
    ida = ida_dataset(cube)
    capacity = ida.capacity.sel(model="housner").isel(soil=0)
    # every block overturns under every pulse record within the study's levels (or just above them)
    assert np.isfinite(capacity.values).all()
    ratio = capacity / cube.block_uplift_intensity
    assert (ratio > 1.0).all() and (ratio < 40.0).all()
    efficiency = efficiency_dataset(cube, loaded.records, config)
    assert np.isfinite(efficiency.record_pulse_period.values).all()
    assert (efficiency.record_pulse_period.values > 0.3).all()  # pulse periods of these records: ~1-5 s
    table = efficiency_table(efficiency)
    assert set(table["measure"]) >= {"pga", "pgv_ratio", "avgsa", "pulse_amplitude"}
    assert (tmp_path / "cube.nc").is_file() and stats["capacity_runs"] > 0
