"""Run by .venv-pelicun's Python (tests/test_pelicun.py): load our damage-model CSV and a demand sample with
pelicun's own API (Assessment -> demand.load_sample -> asset.load_cmp_model -> damage.load_model_parameters
-> damage.calculate) and save the damage state of each demand realization.

Usage: python pelicun_damage.py FOLDER. Reads FOLDER/fragility_pelicun.csv and FOLDER/demand.csv (pelicun's
sample layout), writes FOLDER/damage_state.npy (int, one per demand row). Imports pelicun, never pipeline.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd
from pelicun.assessment import Assessment


def damage_states(folder: Path) -> np.ndarray:
    """Damage state index (0 = none) of each demand in ``folder/demand.csv`` for the first component of
    ``folder/fragility_pelicun.csv``."""
    table = pd.read_csv(folder / "fragility_pelicun.csv")
    component = table.ID.iloc[0]
    n_demands = len(pd.read_csv(folder / "demand.csv", skiprows=[1]))
    assessment = Assessment({"PrintLog": False, "Seed": 1, "Verbose": False})
    assessment.demand.load_sample(str(folder / "demand.csv"))
    assessment.stories = 1
    marginals = pd.DataFrame({"Units": ["ea"], "Location": ["1"], "Direction": ["1"], "Theta_0": ["1"],
                              "Blocks": [None]}, index=[component])
    assessment.asset.load_cmp_model({"marginals": marginals})
    assessment.asset.generate_cmp_sample(n_demands)
    assessment.damage.load_model_parameters([str(folder / "fragility_pelicun.csv")],
                                            set(assessment.asset.list_unique_component_ids()))
    assessment.damage.calculate()
    sample = assessment.damage.ds_model.sample
    return np.argmax(sample.to_numpy(), axis=1)  # one-hot quantity per damage state


if __name__ == "__main__":
    target = Path(sys.argv[1])
    np.save(target / "damage_state.npy", damage_states(target))
