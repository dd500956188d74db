"""Overturning ends the slip chain too (cold read, issue 36: P(slip >= 0.30 m) printed below P(overturning)).

A record that overturned counts in every damage state, slip states included (``fragility.exceedance``), so the
counts nest: slip >= 0.30 m is reached by at least the records that overturned. The fits and the answer must keep
that order: ``damage_states.nesting_chains`` puts overturning at the end of both chains, the fits merge a slip
state that crosses overturning into one shared-beta group, and the answer reads each state as "this state or
worse" along both chains.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from rockfrag.answer import nested_families
from rockfrag.damage_states import DAMAGE_STATES, nesting_chains
from rockfrag.fragility import fit_cell, fit_independent
from rockfrag.lognormal_fit import lognormal_cdf

# Counts of a cabinet-like cell (44 records): every overturned record is also in slip >= 0.30 m, and slip rises
# faster. Fitted one by one, the slip curve (beta 0.42) lies below overturning's (beta 0.68) at the low levels.
LEVELS = np.array([0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.3])
SLIP = np.array([1, 3, 8, 16, 30, 40, 44])
OVERTURNED = np.array([1, 3, 8, 15, 22, 28, 33])


def test_overturning_ends_both_chains():
    edps = [state.edp for state in DAMAGE_STATES.values()]
    names = list(DAMAGE_STATES)
    chains = [[names[i] for i in chain] for chain in nesting_chains(edps)]
    assert chains == [["uplift", "rocking-0.2", "rocking-0.5", "overturning"],
                      ["slip-0.05", "slip-0.30", "overturning"]]
    assert nesting_chains(["uplifted", "overturned"]) == [[0, 1]]  # no slip state: one chain


def test_a_slip_state_that_crosses_overturning_shares_its_beta():
    states = [DAMAGE_STATES["slip-0.30"], DAMAGE_STATES["overturning"]]
    exceed = np.array([SLIP, OVERTURNED], float)
    total = np.full_like(exceed, 44.0)
    assert np.all(exceed[0] >= exceed[1])  # the counts nest
    medians, betas = fit_independent(LEVELS, exceed, total)
    grid = np.geomspace(LEVELS[0], LEVELS[-1], 200)
    assert np.any(lognormal_cdf(grid, medians[0], betas[0]) < lognormal_cdf(grid, medians[1], betas[1]) - 1e-6)
    rows, groups = fit_cell(LEVELS, exceed, total, states)
    assert [0, 1] in groups and rows[0].beta == rows[1].beta and rows[0].median < rows[1].median
    assert np.all(lognormal_cdf(grid, rows[0].median, rows[0].beta)
                  >= lognormal_cdf(grid, rows[1].median, rows[1].beta))


def test_the_answer_reads_slip_states_as_this_state_or_overturning():
    names = list(DAMAGE_STATES)
    fragility = xr.Dataset(coords={"damage_state": names,
                                   "damage_state_edp": ("damage_state", [s.edp for s in DAMAGE_STATES.values()])})
    chains = nested_families(fragility)
    assert [names.index("slip-0.05"), names.index("slip-0.30"), names.index("overturning")] in chains
