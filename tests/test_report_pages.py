"""Report pages drawn from small hand-made datasets: each page draws what its result file holds."""

import matplotlib
import numpy as np
import xarray as xr

from pipeline.report import figures

matplotlib.use("Agg")


def _sweep(models=("ssi", "winkler"), blocks=("paper", "cabinet")):
    """An applicability.nc as pipeline.applicability writes it (only what the sweep page reads)."""
    shape = (len(models), len(blocks), 2, 3, 5)
    ratio = 1.0 + np.arange(np.prod(shape)).reshape(shape) / 1000.0
    return xr.Dataset(
        {"peak_angle_ratio_to_housner": (("model", "block", "block_modulus", "level", "shear_modulus"), ratio)},
        coords={"model": list(models), "model_label": ("model", [m.upper() for m in models]), "block": list(blocks),
                "block_modulus": [30e9, 200e9], "level": [1.2, 2.0, 3.0],
                "shear_modulus": np.geomspace(1e7, 1e10, 5)},
        attrs={"tolerance": 0.1, "n_records": 3})


def test_the_sweep_page_draws_one_panel_per_model_and_block_from_the_sweep_file():
    dataset = _sweep()
    figure = figures.sweep_page(dataset, "caption")
    titled = [axis for axis in figure.axes if axis.get_title()]
    assert sorted(axis.get_title() for axis in titled) == sorted(
        f"{block}: {model.upper()}" for model in ("ssi", "winkler") for block in ("paper", "cabinet"))
    first = next(axis for axis in titled if axis.get_title() == "cabinet: WINKLER")
    drawn = first.get_lines()[0].get_ydata()
    np.testing.assert_array_equal(drawn, dataset.peak_angle_ratio_to_housner.sel(model="winkler",
                                                                                  block="cabinet").values[0, 0])
