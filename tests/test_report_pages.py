"""Report pages drawn from small hand-made datasets: each page draws what its result file holds."""

import matplotlib
import numpy as np
import xarray as xr

from rockfrag.report import figures

matplotlib.use("Agg")


def _sweep(models=("ssi", "winkler"), blocks=("paper", "cabinet")):
    """An applicability.nc as rockfrag.applicability writes it (only what the sweep page reads)."""
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
    import matplotlib.pyplot as plt

    plt.close(figure)  # a figure left open fails test_report's no-open-figures check when they share a process


def test_log_minor_ticks_only_inside_the_view_and_the_drawing_unchanged():
    """layout.InView: a log axis's minor ticks are made only where they are drawn, and the page is the same PNG."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import LogLocator, NullFormatter

    from rockfrag.report import figure_png
    from rockfrag.report.layout import log_minor_ticks

    def drawn(in_view):
        figure = plt.figure(figsize=(4, 3))
        axis = figure.add_subplot()
        axis.loglog([0.03, 40.0], [0.2, 7.0])
        axis.set_xlim(0.03, 40.0)
        axis.grid(which="both")
        if in_view:
            log_minor_ticks(axis.xaxis)
        else:
            axis.xaxis.set_minor_locator(LogLocator(subs="auto"))
            axis.xaxis.set_minor_formatter(NullFormatter())
        try:
            png = figure_png(figure)
            return png, len(axis.xaxis.get_minor_ticks()), list(axis.xaxis.get_minorticklocs())
        finally:
            plt.close(figure)

    png, made, shown = drawn(in_view=True)
    png_all, made_all, shown_all = drawn(in_view=False)
    assert png == png_all and np.allclose(shown, [v for v in shown_all if 0.03 <= v <= 40.0])
    assert made == len(shown) < made_all  # the undrawn decades beyond each end are not made
