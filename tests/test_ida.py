"""IDA: resurrection kept, capacities, fractiles both ways, hunt-and-fill against a known capacity."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from rockfrag.cube import OUTCOME_NO_UPLIFT, OUTCOME_OVERTURNED, OUTCOME_ROCKING
from rockfrag.ida import first_crossing_im, hunt_and_fill, ida_dataset, overturning_capacities


def constructed_cube(ratios, outcomes, levels):
    """A cube with one soil, block and model from (record, level) arrays."""
    ratios = np.asarray(ratios, float)[:, :, None, None, None]
    outcomes = np.asarray(outcomes, np.int8)[:, :, None, None, None]
    dims = ("record", "im_level", "soil", "block", "model")
    return xr.Dataset({"peak_angle_ratio": (dims, ratios), "outcome": (dims, outcomes)},
                      coords={"record": [f"r{i}" for i in range(ratios.shape[0])],
                              "im_level": ("im_level", levels, {"units": "g"}),
                              "soil": ["sand"], "block": ["b"], "model": ["housner"]})


LEVELS = np.array([0.1, 0.2, 0.3, 0.4, 0.5])
R, OT, N = OUTCOME_ROCKING, OUTCOME_OVERTURNED, OUTCOME_NO_UPLIFT
# record 0 overturns at 0.3, survives 0.4 (resurrection) and overturns again at 0.5
# record 1 never overturns; record 2 overturns from 0.4 on
RATIOS = [[0.0, 0.3, 1.0, 0.6, 1.0], [0.0, 0.1, 0.2, 0.4, 0.8], [0.0, 0.2, 0.5, 1.0, 1.0]]
OUTCOMES = [[N, R, OT, R, OT], [N, R, R, R, R], [N, R, R, OT, OT]]


def test_resurrection_is_represented_not_smoothed():
    ida = ida_dataset(constructed_cube(RATIOS, OUTCOMES, LEVELS))
    curve = ida.edp.isel(soil=0, block=0, model=0).sel(record="r0").values
    assert np.isinf(curve[2]) and curve[3] == pytest.approx(0.6) and np.isinf(curve[4])
    assert ida.first_overturn_im.sel(record="r0").item() == 0.3
    assert ida.last_resurrection_free_im.sel(record="r0").item() == 0.5
    assert ida.resurrected.sel(record="r0").item() == 1
    assert np.isnan(ida.first_overturn_im.sel(record="r1").item())
    assert ida.first_overturn_im.sel(record="r2").item() == 0.4
    assert ida.last_resurrection_free_im.sel(record="r2").item() == 0.4
    assert ida.resurrected.sel(record="r2").item() == 0


def test_fractiles_count_overturning_as_infinite_response():
    ida = ida_dataset(constructed_cube(RATIOS, OUTCOMES, LEVELS))
    median = ida.edp_fractile.sel(fractile=0.5).isel(soil=0, block=0, model=0).values
    # at 0.3: responses inf, 0.2, 0.5 -> median 0.5; at 0.5: inf, 0.8, inf -> median inf
    assert median[2] == pytest.approx(0.5)
    assert np.isinf(median[4])


def test_intensity_given_response_interpolates_first_crossing():
    edp = np.array([[0.0, 0.2, 0.6, np.inf], [0.0, 0.1, 0.2, 0.3]])
    levels = np.array([1.0, 2.0, 3.0, 4.0])
    capacity = first_crossing_im(edp, levels, 0.4)
    assert capacity[0] == pytest.approx(2.5)  # halfway between 0.2 at 2 and 0.6 at 3
    assert np.isnan(capacity[1])
    assert first_crossing_im(edp, levels, 1.0)[0] == 4.0  # the flatline


def test_overturning_capacities_of_a_record_that_survives_the_top():
    first, stable = overturning_capacities(np.array([[R, OT, R]]), np.array([1.0, 2.0, 3.0]))
    assert first[0] == 2.0 and np.isnan(stable[0])


def test_hunt_and_fill_brackets_a_known_capacity_with_fewer_runs():
    capacity = 0.737
    calls = []

    def overturns(im):
        calls.append(im)
        return im >= capacity

    found, lower, upper, runs = hunt_and_fill(overturns, start=0.05, step=0.05, tolerance=0.01)
    assert lower < capacity <= upper and (upper - lower) <= 0.01 * upper
    assert found == pytest.approx(capacity, rel=0.01)
    uniform_runs = int(np.ceil((1.0 - 0.05) / (0.01 * capacity)))  # a uniform grid of the same resolution
    assert runs == len(calls) and runs < uniform_runs / 5
