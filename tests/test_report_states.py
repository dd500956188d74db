"""Uplift has a size (issue 36, item 3): the damage-state registry states it, the fits count it, and the report's
words follow it. A 0.1 mm lift of a block on gravel was "rocks (61%)" and tiny bounces "flies (100%)"; a lift below
the size is now a tilt on the bed, and the motion table's lifting records are the uplift count of the P table."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from rockfrag.damage_states import DAMAGE_STATES, TILT_WORDS, UPLIFT_FRACTION, UPLIFT_MIN_LIFT, uplift_lift
from rockfrag.fragility import exceedance
from rockfrag.models.base import Outcome

ROCKING, OVERTURNED, FLIGHT, AT_REST = int(Outcome.ROCKING), int(Outcome.OVERTURNED), int(Outcome.FREE_FLIGHT), \
    int(Outcome.NO_UPLIFT)


def test_the_registry_states_the_uplift_size():
    assert (UPLIFT_FRACTION, UPLIFT_MIN_LIFT) == (0.01, 0.001)
    assert uplift_lift(4.0) == pytest.approx(0.001)    # a large block: 1 mm
    assert uplift_lift(0.05) == pytest.approx(0.0005)  # a 10 cm wide object: 1% of b
    assert np.allclose(uplift_lift(xr.DataArray([0.05, 4.0])).values, [0.0005, 0.001])
    description = DAMAGE_STATES["uplift"].description
    assert "1 mm" in description and "1% of the half-width b" in description


def _cube(lift_mm, outcome, model="recommended", b=0.3, times=None):
    """One level of a cube: records with a peak corner lift [mm] and an outcome, on one soil, block and model."""
    lift = np.asarray(lift_mm, float)[:, None, None, None, None] / 1000.0
    code = np.asarray(outcome, np.int8)[:, None, None, None, None]
    dims = ("record", "im_level", "soil", "block", "model")
    variables = {"peak_uplift": (dims, lift), "outcome": (dims, code)}
    for field, values in (times or {}).items():
        variables[field] = (dims, np.asarray(values, float)[:, None, None, None, None])
    return xr.Dataset(variables, coords={"soil": ["gravel"], "block": ["cabinet"], "model": [model],
                                         "block_b": ("block", [b]),
                                         "intensity": (("block", "im_level"), [[0.3]], {"units": "g"})})


def test_a_lift_below_the_size_on_a_bed_is_no_uplift_and_a_pivot_model_has_no_tilt():
    lifts, outcomes = [0.1, 0.9, 1.1, 0.2, 0.0, 0.05], [ROCKING, ROCKING, ROCKING, OVERTURNED, AT_REST, FLIGHT]
    reached = exceedance(_cube(lifts, outcomes), DAMAGE_STATES["uplift"]).values.ravel()
    assert list(reached) == [0, 0, 1, 1, 0, 1]  # overturning and flight off the ground lift off, whatever the size
    rigid = exceedance(_cube(lifts, outcomes, model="housner"), DAMAGE_STATES["uplift"]).values.ravel()
    assert list(rigid) == [1, 1, 1, 1, 0, 1]  # a rigid base lifts a corner only by pivoting: rocking at any size
    small = exceedance(_cube([0.6, 0.4], [ROCKING, ROCKING], b=0.05), DAMAGE_STATES["uplift"]).values.ravel()
    assert list(small) == [1, 0]  # a 10 cm wide object: 0.5 mm is the size


def test_the_motion_table_says_tilts_below_the_size_and_its_lifting_records_are_the_uplift_count():
    from rockfrag.report.answer_page import motion_counts

    lifts = [0.1, 0.1, 0.5, 2.0, 3.0, 0.05, 0.0]
    outcomes = [ROCKING, ROCKING, ROCKING, ROCKING, OVERTURNED, ROCKING, AT_REST]
    times = {"time_at_rest": [9.0] * 7, "time_sliding": [0, 0, 0, 0, 0, 1.0, 0],
             "time_rocking": [1.0, 0, 1.0, 1.0, 1.0, 0, 0], "time_slide_rocking": [0] * 7,
             "time_in_flight": [0, 0.1, 0, 0, 0, 0, 0]}  # the second record bounces 0.1 mm: not flight
    cube = _cube(lifts, outcomes, times=times)
    shown = motion_counts(cube, "cabinet", "recommended", "gravel", [0.3], 1.0)[0]
    assert shown == f"at rest 1, {TILT_WORDS} 3, slides 1, rocks 1, overturns 1 (of 7)"
    uplifted = int(exceedance(cube, DAMAGE_STATES["uplift"]).sum())
    lifting = sum(int(n) for words, n in (part.rsplit(" ", 1) for part in shown.split(" (of")[0].split(", "))
                  if words in ("rocks", "slides and rocks", "flies", "overturns"))
    assert lifting == uplifted == 2
    assert "flies" not in shown and "rocks 3" not in shown


def test_the_outcome_fractions_of_the_result_file_count_a_tilt_on_the_bed_as_no_uplift():
    """Cold read 7 (default figures, finding 1): fragility.nc's outcome_probability counted runs that only tilt on
    the bed (a corner lifted less than the uplift size) as rocking: 17 of 44 on rock at 0.234 g where the motion
    table and the outcomes page, from the same runs, count 4. The file now counts as the uplift state does."""
    from rockfrag.fragility import three_outcomes

    lifts, outcomes = [0.1, 0.9, 1.1, 0.2, 0.0], [ROCKING, ROCKING, ROCKING, OVERTURNED, AT_REST]
    fractions = three_outcomes(_cube(lifts, outcomes)).values[:, 0, 0, 0, 0]
    np.testing.assert_allclose(fractions, [3 / 5, 1 / 5, 1 / 5])  # two tilts and the record at rest: no uplift
    rigid = three_outcomes(_cube(lifts, outcomes, model="housner")).values[:, 0, 0, 0, 0]
    np.testing.assert_allclose(rigid, [1 / 5, 3 / 5, 1 / 5])  # a pivot model has no tilt
    uplift = exceedance(_cube(lifts, outcomes), DAMAGE_STATES["uplift"]).values.ravel()
    assert uplift.mean() == pytest.approx(fractions[1] + fractions[2])  # the file agrees with the uplift state
