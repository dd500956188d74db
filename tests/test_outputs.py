"""Result files: one netCDF writer (rockfrag.outputs.write_dataset) that every stage calls; it compresses
every numeric data variable, reads back identical, gives coordinates no fill value, and never leaves a
half-written file."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import rockfrag
from rockfrag.cube import OUTCOME_NO_UPLIFT, OUTCOME_OVERTURNED, OUTCOME_ROCKING
from rockfrag.ida import ida_stage
from rockfrag.outputs import write_dataset

PACKAGE = Path(rockfrag.__file__).parent


def uncompressed(path: Path) -> list[str]:
    """Numeric data variables (with at least one dimension) of a netCDF file that zlib did not compress."""
    with xr.open_dataset(path) as dataset:
        return [str(name) for name, variable in dataset.data_vars.items()
                if variable.ndim and variable.dtype.kind in "biuf" and not variable.encoding.get("zlib")]


def every_kind() -> xr.Dataset:
    """A small dataset with each kind of variable the stages write: floats with NaN, int8 codes, int64
    counts, flags, strings, a scalar, float and string dimension coordinates and an auxiliary coordinate."""
    rng = np.random.default_rng(3)
    dims = ("record", "im_level")
    peak = rng.random((4, 3))
    peak[1, 2] = np.nan
    return xr.Dataset(
        {"peak_angle": (dims, peak, {"long_name": "peak rocking angle", "units": "rad"}),
         "outcome": (dims, rng.integers(0, 3, (4, 3)).astype(np.int8), {"units": "1"}),
         "n_records": (("im_level",), np.array([4, 4, 3], np.int64)),
         "extrapolated": (("im_level",), np.array([True, False, True])),
         "status": (dims, np.array([["fitted", "no fit", ""]] * 4)),
         "n_total": ((), np.int64(12))},
        coords={"record": ["r0", "r1", "r2", "r3"],
                "im_level": ("im_level", [0.1, 0.3, 0.6], {"units": "g"}),
                "record_pga": ("record", [0.2, np.nan, 0.4, 0.1], {"units": "m s-2"})},
        attrs={"title": "every kind", "Conventions": "CF-1.12"})


def test_every_numeric_data_variable_is_compressed_and_reads_back_identical(tmp_path):
    dataset = every_kind()
    path = write_dataset(dataset, tmp_path / "deep" / "every.nc")
    assert path == tmp_path / "deep" / "every.nc"
    with xr.open_dataset(path) as back:
        back.load()
        xr.testing.assert_identical(back, dataset)
        for name in ("peak_angle", "outcome", "n_records", "extrapolated"):
            assert back[name].encoding["zlib"] and back[name].encoding["complevel"] == 4, name
        assert not back.status.encoding.get("zlib")  # variable-length strings take no filter
    assert uncompressed(path) == []


def test_dimension_coordinates_have_no_fill_value_and_auxiliary_ones_keep_theirs(tmp_path):
    path = write_dataset(every_kind(), tmp_path / "every.nc")
    with xr.open_dataset(path) as back:
        assert "_FillValue" not in back.im_level.encoding  # CF: a coordinate variable has no missing values
        assert np.isnan(back.record_pga.encoding["_FillValue"])  # an auxiliary coordinate may have gaps
        assert np.isnan(back.record_pga.values[1])


def test_options_compress_off_and_extra_encoding_merged(tmp_path):
    dataset = every_kind()
    plain = write_dataset(dataset, tmp_path / "plain.nc", compress=False)
    assert set(uncompressed(plain)) == {"peak_angle", "outcome", "n_records", "extrapolated"}
    small = write_dataset(dataset, tmp_path / "small.nc", complevel=9, encoding={"peak_angle": {"dtype": "float32"}})
    with xr.open_dataset(small) as back:
        assert back.peak_angle.encoding["zlib"] and back.peak_angle.encoding["complevel"] == 9
        assert back.peak_angle.encoding["dtype"] == np.float32
        assert back.outcome.encoding["complevel"] == 9


def test_a_failed_write_leaves_the_old_file_and_no_part_file(tmp_path):
    path = write_dataset(every_kind(), tmp_path / "result.nc")
    before = path.read_bytes()
    broken = every_kind().assign_attrs(settings={"a": 1})  # a dict is no netCDF attribute
    with pytest.raises(TypeError):
        write_dataset(broken, path)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.nc"]


def test_stage_writers_compress(tmp_path):
    """ida.nc from a small constructed cube, through the stage function that the pipeline calls."""
    dims = ("record", "im_level", "soil", "block", "model")
    outcome = np.array([[OUTCOME_NO_UPLIFT, OUTCOME_ROCKING, OUTCOME_OVERTURNED]] * 2, np.int8)
    cube = xr.Dataset({"peak_angle_ratio": (dims, np.array([[0.0, 0.4, 1.0], [0.0, 0.2, 1.0]])[..., None, None, None]),
                       "outcome": (dims, outcome[..., None, None, None])},
                      coords={"record": ["r0", "r1"], "im_level": ("im_level", [0.1, 0.2, 0.3], {"units": "g"}),
                              "soil": ["sand"], "block": ["b"], "model": ["housner"]})
    dataset = ida_stage(cube, tmp_path)
    assert uncompressed(tmp_path / "ida.nc") == []
    with xr.open_dataset(tmp_path / "ida.nc") as back:
        xr.testing.assert_identical(back.load(), dataset)


def test_no_module_but_outputs_writes_netcdf():
    """Every netCDF file of the pipeline goes through write_dataset: no other module calls to_netcdf."""
    writers = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path == PACKAGE / "outputs.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if isinstance(node, ast.Attribute) and node.attr == "to_netcdf":
                writers.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}")
    assert writers == [], f"write netCDF files with rockfrag.outputs.write_dataset, not to_netcdf: {writers}"
