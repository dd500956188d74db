"""Run by .venv-pelicun's Python (tests/test_pelicun.py): load our damage-model CSV with pelicun's own API
(Assessment -> demand.load_sample -> asset.load_cmp_model -> damage.load_model_parameters -> damage.calculate),
every component alone and all of them together, and save P(DS >= k) at each demand level.

Usage: python pelicun_damage.py FOLDER [--alone] [--example FILE]. Reads FOLDER/fragility_pelicun.csv and
FOLDER/demand.csv (pelicun's sample layout: one PGA column per demand level, ``1-PGA-1-<d>``, the level held
over every realization, so that pelicun's Latin hypercube capacities give P(DS >= k) to within one over the
sample size). Writes FOLDER/exceedance.npz: ``together`` (one assessment of every component) and, with
--alone, ``alone`` (one assessment per component), (component, level, k) arrays of P(DS >= k) for k = 1..n (n
the number of limit-state columns), in the file's component order. ``--example FILE`` then runs the Python of
FILE (the README's pelicun example) in FOLDER's parent, in this process: one pelicun import for both. Imports
pelicun, never pipeline.
"""

from __future__ import annotations

import argparse
import os
import runpy
from pathlib import Path

import numpy as np
import pandas as pd
from pelicun.assessment import Assessment


def exceedance(folder: Path, components: list[str], n_levels: int, n_states: int) -> np.ndarray:
    """P(DS >= k) of ``components`` in one assessment: (component, level, k)."""
    n_realizations = len(pd.read_csv(folder / "demand.csv", skiprows=[1]))
    assessment = Assessment({"PrintLog": False, "Seed": 1, "Verbose": False})
    assessment.demand.load_sample(str(folder / "demand.csv"))
    assessment.stories = 1
    directions = ",".join(str(d) for d in range(1, n_levels + 1))  # one performance group per demand level
    marginals = pd.DataFrame({"Units": "ea", "Location": "1", "Direction": directions, "Theta_0": "1",
                              "Blocks": None}, index=components)
    assessment.asset.load_cmp_model({"marginals": marginals})
    assessment.asset.generate_cmp_sample(n_realizations)
    assessment.damage.load_model_parameters([str(folder / "fragility_pelicun.csv")],
                                            set(assessment.asset.list_unique_component_ids()))
    assessment.damage.calculate()
    sample = assessment.damage.ds_model.sample  # columns (cmp, loc, dir, uid, ds): quantity in each state
    result = np.zeros((len(components), n_levels, n_states))
    for (component, _, direction, _, state), quantity in sample.mean().items():
        for k in range(1, int(state) + 1):
            result[components.index(component), int(direction) - 1, k - 1] += quantity
    return result


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("folder", type=Path)
    parser.add_argument("--alone", action="store_true")
    parser.add_argument("--example", type=Path)
    arguments = parser.parse_args()
    target = arguments.folder.resolve()
    table = pd.read_csv(target / "fragility_pelicun.csv")
    names = list(table.ID)
    levels = len(pd.read_csv(target / "demand.csv", nrows=0).columns) - 1
    states = sum(column.endswith("-Family") for column in table.columns)
    computed = {"together": exceedance(target, names, levels, states)}
    if arguments.alone:
        computed["alone"] = np.concatenate([exceedance(target, [name], levels, states) for name in names])
    np.savez(target / "exceedance.npz", **computed)
    if arguments.example:
        os.chdir(target.parent)
        runpy.run_path(str(arguments.example.resolve()), run_name="__main__")
