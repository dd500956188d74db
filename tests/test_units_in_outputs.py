"""Units in the netCDF outputs: every variable and coordinate states units UDUNITS parses correctly ("g"
is grams there: multiples of g are "9.80665 m s-2"), and within one file one quantity has one unit, so that
record PGAs, levels, intensities, capacities and medians can be compared as read (issue 21, item 2)."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from rockfrag.config import load_study
from rockfrag.measures import (
    MEASURES,
    convert_units,
    file_units,
    parse_units,
    udunits,
    unit_label,
)
from rockfrag.study import run_study

from .test_study import SMALL

# A small parser of the units our outputs may write: an optional numeric factor, then one of these (quantity,
# SI value). The canonical UDUNITS spellings, and "m/s^2", "m/s" that UDUNITS also reads (checked by hand with
# cf-units 3: Unit("m/s^2") == Unit("m s-2"); Unit("g") is grams, Unit("9.80665 m s-2") converts 1 -> 9.80665).
BASE_UNITS = {
    "m s-2": ("acceleration", 1.0), "m/s^2": ("acceleration", 1.0),
    "m s-1": ("velocity", 1.0), "m/s": ("velocity", 1.0),
    "m": ("length", 1.0), "km": ("length", 1000.0),
    "rad": ("angle", 1.0), "1": ("dimensionless", 1.0), "s": ("time", 1.0), "yr-1": ("rate", 1.0),
    "Pa": ("pressure", 1.0), "N m-1": ("stiffness", 1.0), "N": ("force", 1.0), "kg": ("mass", 1.0),
}


def parse(units: str) -> tuple[str, float]:
    """(quantity, SI value of one unit) of a ``units`` attribute; AssertionError if UDUNITS would misread it."""
    found = re.fullmatch(r"\s*(?:([0-9.]+(?:[eE][-+]?\d+)?)\s+)?(.+?)\s*", str(units))
    assert found and found.group(2) in BASE_UNITS, (
        f"units {units!r} is not a UDUNITS unit we write" + (" (UDUNITS reads 'g' as grams)" if units == "g" else ""))
    quantity, value = BASE_UNITS[found.group(2)]
    return quantity, value * float(found.group(1) or 1.0)


def numeric_variables(dataset: xr.Dataset):
    """(name, variable) of every numeric data variable and coordinate."""
    for name, variable in [*dataset.data_vars.items(), *dataset.coords.items()]:
        if variable.dtype.kind in "biuf":
            yield str(name), variable


INTENSITY_LIKE = ("acceleration", "velocity")
"""Quantities that must have one unit string per file (levels, record measures, capacities, medians); other
lengths may differ on purpose (a rupture distance in km beside a block's size in m)."""


def check_file(dataset: xr.Dataset, label: str, skip=()) -> dict[str, str]:
    """Every numeric variable declares parseable units, and each intensity-like quantity has one unit string
    in the file. Returns {quantity: units} of the intensity-like ones."""
    seen: dict[str, tuple[str, str]] = {}
    for name, variable in numeric_variables(dataset):
        if name in skip:
            continue
        assert "units" in variable.attrs, f"{label}: {name} has no units"
        units = variable.attrs["units"]
        quantity, _ = parse(units)
        if quantity not in INTENSITY_LIKE:
            continue
        first = seen.setdefault(quantity, (units, name))
        assert first[0] == units, f"{label}: {name} in {units!r} but {first[1]} in {first[0]!r} ({quantity})"
    return {quantity: units for quantity, (units, _) in seen.items()}


def test_the_parser_rejects_what_udunits_misreads():
    with pytest.raises(AssertionError, match="grams"):
        parse("g")
    with pytest.raises(AssertionError):
        parse("SI unit of the measure")
    assert parse("9.80665 m s-2") == ("acceleration", 9.80665)
    assert parse("m/s^2") == parse("m s-2") == ("acceleration", 1.0)


def test_the_measure_registry_derives_every_units_string():
    assert MEASURES["pga"].cf_units() == MEASURES["sa"].cf_units() == "9.80665 m s-2"
    assert MEASURES["pga"].cf_units(display=False) == "m s-2"
    assert MEASURES["pgv"].cf_units() == "m s-1" and MEASURES["pga_ratio"].cf_units() == "1"
    assert file_units("m/s^2") == "9.80665 m s-2" and file_units("N/m") == "N m-1"
    assert udunits("m/s^2", 9.80665) == "9.80665 m s-2"
    for measure in MEASURES.values():
        for display in (True, False):
            _, value = parse(measure.cf_units(display))
            assert value == pytest.approx(measure.display_factor if display else 1.0)
            assert parse_units(measure.cf_units(display))[0] == pytest.approx(value)
    assert parse_units("g") == (9.80665, "m s-2")  # files written before: read back correctly
    assert unit_label("9.80665 m s-2") == "g" and unit_label("m s-1") == "m/s"
    assert convert_units(9.80665, "m/s^2", "9.80665 m s-2") == pytest.approx(1.0)
    with pytest.raises(ValueError):
        convert_units(1.0, "m s-1", "m s-2")


@pytest.fixture(scope="module")
def fragility_run(small_pipeline):
    """The session's shared `rockfrag fragility` run of the small study (absolute levels in g, capacities)."""
    return small_pipeline.output


@pytest.mark.slow
def test_every_netcdf_output_states_one_parseable_unit_per_quantity(fragility_run):
    written = sorted(fragility_run.glob("*.nc"))
    assert {"cube.nc", "ida.nc", "fragility.nc", "showcase.nc"} <= {path.name for path in written}
    for path in written:
        with xr.open_dataset(path) as dataset:
            check_file(dataset, path.name)


@pytest.mark.slow
def test_record_pgas_levels_intensities_and_fits_share_one_unit(fragility_run):
    opened = {}
    for name in ("cube", "ida", "fragility"):
        with xr.open_dataset(fragility_run / f"{name}.nc") as dataset:
            opened[name] = dataset.load()
    cube, ida, fragility = opened["cube"], opened["ida"], opened["fragility"]
    g = "9.80665 m s-2"
    for dataset, names in ((cube, ("im_level", "intensity", "record_pga", "record_im", "block_uplift_acceleration")),
                           (ida, ("intensity", "first_overturn_im", "capacity", "capacity_lower", "im_fractile")),
                           (fragility, ("intensity", "median", "capacity_median", "studied_im_min"))):
        for name in names:
            assert dataset[name].attrs["units"] == g, name
    # values are what the units say: the record's intensity (its pair's RotD50 PGA) x its scale factor is the
    # level, in the same unit
    scaled = (cube.record_im * cube.scale_factor).transpose("block", "im_level", "record")
    np.testing.assert_allclose(scaled, cube.intensity.broadcast_like(scaled), rtol=1e-9)
    np.testing.assert_allclose(cube.im_level.values, [0.1, 0.3, 0.6, 1.0])  # the study's levels [g]
    assert fragility.attrs["intensity_unit"] == g and fragility.attrs["intensity_unit_label"] == "g"


@pytest.mark.slow
def test_efficiency_capacities_state_parseable_units(fragility_run):
    path = fragility_run / "efficiency.nc"
    if not path.exists():
        pytest.skip("no efficiency.nc in this run")
    with xr.open_dataset(path) as dataset:
        units = check_file(dataset, path.name)
        assert units["acceleration"] == "9.80665 m s-2" and units["velocity"] == "m s-1"
        assert dataset.median_capacity_pga_ratio.attrs["units"] == "1"
        medians = {name: dataset[f"median_capacity_{name}"].load() for name in ("pga", "pgv", "pga_ratio")}
    # the table gives each median in the unit the file states, and names it
    table = pd.read_csv(fragility_run / "efficiency.csv", keep_default_na=False, na_values=[""])
    for name, label in (("pga", "g"), ("pgv", "m/s"), ("pga_ratio", "1")):
        rows = table[table.measure == name]
        assert set(rows.units.astype(str)) == {label}, name
        in_file = [medians[name].sel(soil=r.soil, block=r.block, model=r.model).item() for r in rows.itertuples()]
        np.testing.assert_allclose(rows.median_capacity, in_file, rtol=1e-5)


def test_a_pgv_study_keeps_velocities_and_accelerations_apart(tmp_path):
    study = tmp_path / "pgv.toml"
    study.write_text(SMALL.replace('record_sets = ["bolu"]', 'record_sets = ["DUZCE/BOL090"]')
                     .replace("[intensity]", '[intensity]\nmeasure = "pgv"\ncapacity_resolution = 0.0')
                     .replace("levels = [0.1, 0.3, 0.6, 1.0]", "levels = [0.2, 0.5]")
                     .replace('models = ["housner", "ssi"]', 'models = ["housner"]'))
    cube, _ = run_study(load_study(study), output=tmp_path / "out", workers=1, progress=False, log=lambda m: None)
    units = check_file(cube, "cube.nc (pgv)")
    assert units["velocity"] == "m s-1" and units["acceleration"] == "9.80665 m s-2"
    assert cube.im_level.attrs["units"] == cube.record_im.attrs["units"] == "m s-1"
    assert cube.record_pga.attrs["units"] == cube.block_uplift_acceleration.attrs["units"]


def test_every_variable_of_fragility_nc_has_a_long_name(small_pipeline):
    """CF: every data variable and coordinate of the fits says what it is (text labels too: model, damage_state)."""
    import xarray as xr

    with xr.open_dataset(small_pipeline.output / "fragility.nc") as fragility:
        unnamed = [name for name, variable in fragility.variables.items() if not variable.attrs.get("long_name")]
    assert not unnamed, f"fragility.nc variables without a long_name: {unnamed}"
