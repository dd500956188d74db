"""Fragility fits + bootstrap on a cube of the default study's size (44 records x 40 levels x 5 soils x
3 blocks x 3 models, 4 damage states, 100 bootstrap samples). Target: <= 20 s on 2 cores together with
the measure ranking. The cube is synthetic (lognormal capacities), so the benchmark needs no solver run.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import xarray as xr

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # this checkout's pipeline, not an installed one

from rockfrag.cube import OUTCOME_NO_UPLIFT, OUTCOME_OVERTURNED, OUTCOME_ROCKING  # noqa: E402
from rockfrag.fragility import fragility_dataset  # noqa: E402

SHAPE = {"record": 44, "im_level": 40, "soil": 5, "block": 3, "model": 3}


def default_sized_cube(seed=0) -> xr.Dataset:
    rng = np.random.default_rng(seed)
    levels = np.geomspace(0.05, 3.0, SHAPE["im_level"])
    dims = tuple(SHAPE)
    shape = tuple(SHAPE.values())
    tan_alpha = np.array([0.47, 0.2, 0.75])  # paper, slender cabinet, squat machinery [g]
    median_over = (np.array([2.0, 0.6, 2.5])[None, :, None] * rng.uniform(0.8, 1.2, (SHAPE["soil"], 1, SHAPE["model"])))
    z = rng.normal(size=(SHAPE["record"], 1, 1, 1, 1))
    im = levels[None, :, None, None, None]
    capacity = median_over[None, None] * np.exp(0.4 * z + 0.1 * rng.normal(size=shape))
    ratio = np.clip(im / capacity, 0, 0.99)
    outcome = np.where(im >= capacity, OUTCOME_OVERTURNED,
                       np.where(im > tan_alpha[None, None, None, :, None], OUTCOME_ROCKING, OUTCOME_NO_UPLIFT))
    return xr.Dataset({"peak_angle_ratio": (dims, ratio), "outcome": (dims, outcome.astype(np.int8))},
                      coords={"record": [f"r{i}" for i in range(SHAPE["record"])],
                              "im_level": ("im_level", levels, {"units": "g"}),
                              "soil": ["clay", "sand", "gravel", "rock", "steel"],
                              "block": ["paper", "slender-cabinet", "squat-machinery"],
                              "model": ["housner", "ssi", "winkler"],
                              "block_alpha": ("block", np.arctan(tan_alpha))},
                      attrs={"intensity_measure": "pga"})


def run(print=print):
    cube = default_sized_cube()
    cells = SHAPE["soil"] * SHAPE["block"] * SHAPE["model"]
    print(f"\nFragility fits + bootstrap: synthetic cube of the default study's size "
          f"({' x '.join(f'{v} {k}' for k, v in SHAPE.items())}), 4 damage states")
    fragility_dataset(cube.isel(soil=[0], block=[0], model=[0]), n_bootstrap=5)  # imports, first call
    for n_bootstrap in (0, 100):
        start = time.perf_counter()
        dataset = fragility_dataset(cube, n_bootstrap=n_bootstrap, seed=0)
        elapsed = time.perf_counter() - start
        methods = dict(zip(*np.unique(dataset.fit_method.values, return_counts=True)))
        print(f"   {n_bootstrap:3d} bootstrap samples: {elapsed:5.2f} s for {cells} cells "
              f"({elapsed / cells * 1000:.0f} ms/cell); methods {methods}")
    print("   target: fits + bootstrap + measure ranking <= 20 s on 2 cores")


if __name__ == "__main__":
    run()
