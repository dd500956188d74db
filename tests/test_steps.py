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
