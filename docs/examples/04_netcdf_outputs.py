"""
Reading the outputs with xarray
===============================

A study writes its results as netCDF files that follow the CF conventions: every variable carries its
``units`` and ``long_name``, and every dimension is labelled (record, intensity level, soil, block, model, damage
state). xarray opens them as labelled arrays; pandas, pelicun and OpenQuake read the CSV and exchange files
written beside them. :doc:`/reference/outputs` lists every variable.
"""

# %%
# A study's files
# ---------------
# We run the tiny study of :doc:`01_block_and_site` into a temporary folder (a few seconds).
import tempfile
from pathlib import Path

import rockfrag

output = Path(tempfile.mkdtemp(prefix="my-site-"))
config = rockfrag.load_study("my-site.toml")
cube, _ = rockfrag.run_study(config, output=output, workers=1)
rockfrag.run_fragility(config, cube, output=output, notes=lambda line: None)  # the notes: see the first tutorial
print(sorted(path.name for path in output.glob("[!.]*") if path.is_file()))

# %%
# The cube
# --------
# ``cube.nc`` holds one value per record, intensity level, soil, block and model, and the records' and blocks'
# properties as coordinates.
import xarray as xr

cube = xr.open_dataset(output / "cube.nc")
cube

# %%
# Select by label, not by position. The peak rocking angle of the rack under each record at each level, for
# Housner's rigid base:
peak = cube["peak_angle"].sel(soil="my-fill", block="rack", model="housner")
print(peak.attrs["long_name"], f"[{peak.attrs['units']}]")
print(peak.to_pandas().round(4))

# %%
# The levels are multiples of each block's uplift intensity (``im_level``); the physical intensity of each
# level is the coordinate ``intensity``, in the units its attribute names (``9.80665 m s-2``: g):
intensity = cube["intensity"].sel(block="rack")
print(intensity.attrs["long_name"], "|", intensity.attrs["units"])
print(intensity.values.round(3))

# %%
# The outcome of each run is a flag variable, decoded by its ``flag_values`` and ``flag_meanings``:
outcome = cube["outcome"]
meanings = dict(zip(outcome.attrs["flag_values"].tolist(), outcome.attrs["flag_meanings"].split()))
print(meanings)
overturned = (outcome == [code for code, name in meanings.items() if name == "overturned"][0])
print("share of runs overturned per model:")
print(overturned.mean(dim=["record", "im_level", "soil", "block"]).to_pandas().round(3))

# %%
# IDA curves
# ----------
# ``ida.nc`` holds each record's IDA curve (``edp``, theta_max/alpha against the level; overturned runs are
# +inf) and the refined overturning capacities.
import matplotlib.pyplot as plt
import numpy as np

ida = xr.open_dataset(output / "ida.nc")
curves = ida["edp"].sel(soil="my-fill", block="rack", model="recommended")
fig, ax = plt.subplots(figsize=(6, 4))
levels = ida["intensity"].sel(block="rack").values
for record in curves.record.values:
    response = curves.sel(record=record).values
    ax.plot(np.where(np.isfinite(response), response, np.nan), levels, "o-", lw=1, label=record)
    capacity = float(ida["capacity"].sel(record=record, soil="my-fill", block="rack", model="recommended"))
    ax.axhline(capacity, lw=0.5, ls=":", color=ax.lines[-1].get_color())
ax.set_xscale("log")
ax.set_xlabel("peak theta / alpha")
ax.set_ylabel("PGA [g]")
ax.set_title("IDA curves, winkler (band centre); dotted: overturning capacity")
ax.legend(fontsize=8)
fig.tight_layout()

# %%
# Fragility
# ---------
# ``fragility.nc`` has one lognormal curve per model, soil, block and damage state, with its bootstrap bounds,
# what the row is (``status``) and the risk. As a table:
fragility = xr.open_dataset(output / "fragility.nc")
columns = ["median", "beta", "median_low", "median_high", "status", "probability_in_life"]
table = fragility[columns].sel(model="recommended", soil="my-fill", block="rack").to_dataframe()[columns]
print(table.round(3).to_string())

# %%
# The same rows, with every column, are in ``fragility.csv``:
import pandas as pd

csv = pd.read_csv(output / "fragility.csv", comment="#")
print(csv.columns.tolist())

# %%
# Units travel with the numbers: ``median`` is in the units its attribute says, the file's global attributes
# say what produced it.
print(fragility["median"].attrs)
print({key: fragility.attrs[key] for key in ("Conventions", "source", "intensity_measure", "references")})
