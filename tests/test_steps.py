"""Steps where the physics puts them (issue 34 item 3): where each step row lies and how it was placed."""

from __future__ import annotations

import numpy as np
import pytest

from rockfrag.damage_states import DAMAGE_STATES
from rockfrag.fragility import fit_cell

UPLIFT, ROCKING = DAMAGE_STATES["uplift"], DAMAGE_STATES["rocking-0.2"]
LEVELS = np.array([0.1, 0.2, 0.4, 0.8])


def test_a_rigid_base_under_its_own_pga_steps_at_g_tan_alpha():
    exceed = np.array([[0, 0, 10, 10]], float)
    total = np.full((1, 4), 10.0)
    rows, _ = fit_cell(LEVELS, exceed, total, [UPLIFT], threshold=0.3, unit="g")
    assert rows[0].median == 0.3 and rows[0].beta == 0 and rows[0].status == "deterministic-threshold"
    assert rows[0].step_method.startswith("exact: g tan(alpha)")


def test_a_separated_state_steps_at_the_geometric_middle_of_its_bracket():
    exceed = np.array([[0, 0, 10, 10]], float)  # none at 0.2 g, all at 0.4 g
    rows, _ = fit_cell(LEVELS, exceed, np.full((1, 4), 10.0), [ROCKING], unit="g")
    assert rows[0].status == "separated" and rows[0].beta == 0
    assert rows[0].median == pytest.approx(np.sqrt(0.2 * 0.4))
    assert "geometric middle of the bracket 0.2-0.4 g" in rows[0].step_method


def test_a_quasi_separated_state_steps_at_its_mixed_level_and_a_curve_has_no_step():
    rows, _ = fit_cell(LEVELS, np.array([[0, 4, 10, 10]], float), np.full((1, 4), 10.0), [ROCKING], unit="g")
    assert rows[0].median == pytest.approx(0.2) and "the one level where some records" in rows[0].step_method
    rows, _ = fit_cell(LEVELS, np.array([[1, 4, 7, 9]], float), np.full((1, 4), 10.0), [ROCKING], unit="g")
    assert rows[0].beta > 0 and rows[0].step_method == ""


def test_a_step_at_the_lowest_level_below_half_is_inside_the_range_not_above_it():
    # the tiny study's uplift row (a winkler bed, 4 records): 1 of 4 uplifted at the lowest level, all 4 from the next
    # on. The median lies between the two lowest levels; it was reported 'above-range' ("reached only at the highest
    # level by 4 of 4 records; the median lies above 3 g") with no median
    levels = np.array([0.101, 0.2, 0.393, 0.774, 1.524, 3.0])
    exceed, total = np.array([[1, 4, 4, 4, 4, 4]], float), np.full((1, 6), 4.0)
    rows, _ = fit_cell(levels, exceed, total, [UPLIFT], unit="g", cap=3.0)
    assert rows[0].status == "separated" and rows[0].beta == 0
    assert levels[0] <= rows[0].median < levels[1]
    assert "the one level where some records" in rows[0].step_method
    assert not any("above" in warning for warning in rows[0].warnings)
    # half or more at the lowest level: the median lies below it; at most half at the highest: above it
    below, _ = fit_cell(levels, np.array([[2, 4, 4, 4, 4, 4]], float), total, [UPLIFT], unit="g")
    above, _ = fit_cell(levels, np.array([[0, 0, 0, 0, 0, 2]], float), total, [ROCKING], unit="g")
    assert below[0].status == "below-range" and above[0].status == "above-range"
