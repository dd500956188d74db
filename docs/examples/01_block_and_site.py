"""
Your own block and site
=======================

From a study file to the answer: a block of your own (a steel server rack) on the soil of your own site (a loose
fill), under four far-field records. The study is tiny so that it runs in seconds; a real one takes more records
(ten at the least, see the warnings below) and more intensity levels.

This is what ``rockfrag fragility my-site.toml`` does, stage by stage, without the report.
"""

# %%
# The study file
# --------------
# A study is one TOML file. Keys you leave out take the shipped defaults (``rockfrag study --keys`` lists every
# key with its default, its allowed range and its unit; so does :doc:`/reference/study-keys`). This one is
# ``docs/examples/my-site.toml`` in the repository: copy it and change the block, the soil and the records.
from pathlib import Path

study_file = Path("my-site.toml")
print(study_file.read_text())

# %%
# Check it before anything runs
# -----------------------------
# Everything here comes from the package's root, ``import rockfrag``. ``load_study`` reads the file and checks
# every value against its allowed range before anything runs (on the command line: ``rockfrag study
# my-site.toml``). The study it returns holds the blocks and soils as objects, in SI units:
import rockfrag

config = rockfrag.load_study(study_file)
[rack] = config.blocks
print(f"block {rack.name}: b = {rack.b} m, h = {rack.h} m, alpha = {rack.alpha:.3f} rad, "
      f"uplift at g tan(alpha) = {rack.uplift_acceleration() / 9.80665:.2f} g")
print("soils:", [f"{soil.name} (G = {soil.shear_modulus / 1e6:g} MPa)" for soil in config.soils])

# %%
# A mistake is one line naming the file, the key and what it must be. Here a copy of the file with a Poisson's
# ratio of 0.55 (above the 0.5 of an incompressible soil):
import tempfile

mistaken = Path(tempfile.mkdtemp()) / "my-site-mistaken.toml"
mistaken.write_text(study_file.read_text().replace("poisson_ratio = 0.40", "poisson_ratio = 0.55"))
try:
    rockfrag.load_study(mistaken)
except rockfrag.ConfigError as error:
    print(error)

# %%
# Run the study
# -------------
# The runs go into an output folder (here a temporary one; the study's ``[study] output`` otherwise).
# ``run_study`` writes ``cube.nc``: every record at every intensity level on every soil for every block and
# model. A run that is interrupted resumes from its checkpoints.
output = Path(tempfile.mkdtemp(prefix="my-site-"))
cube, statistics = rockfrag.run_study(config, output=output, workers=1)
print(f"{statistics['runs_computed']} runs in {statistics['seconds']:.1f} s")

# %%
# The cube holds the models the study asked for, with the recommended bed (``winkler``) run at three
# restitutions of its impacts: the low edge, centre and high edge of the band that experiments support
# (:doc:`/theory/models`).
print(cube.model.values.tolist())

# %%
# From the cube to the answer
# ---------------------------
# ``run_fragility`` fits the fragility curves and the risk from the cube, without another solver run, and
# writes the incremental dynamic analysis (``ida.nc``) and the fits with the risk (``fragility.nc``,
# ``fragility.csv`` and the exchange files). Its notes go to ``notes`` (stderr by default; here the page):
fragility = rockfrag.run_fragility(config, cube, output=output, notes=print)

# %%
# The notes are part of the answer: with four records the dispersion is rough, and a damage state whose
# records all change at one level is a step (beta = 0), never a made-up small beta.
#
# The answer
# ----------
# One line per block and soil: the median intensity of overturning (PGA in g here) from the recommended model,
# its bootstrap bounds, the dispersion beta and, with a hazard curve, the probability of overturning in the
# design life. No ``[hazard] file`` is given here, so the shipped example curve is used and the line says so.
print(rockfrag.answer_table(fragility))

# %%
# Reading the answer
# ------------------
# The median is the PGA at which half the records overturn the rack; beta is the spread of the lognormal
# fragility curve around it. The curve and the fraction of records that overturned at each level (the points it
# was fitted to) are in ``fragility.nc``:
import matplotlib.pyplot as plt
import numpy as np
from scipy.stats import norm

row = fragility.sel(model="recommended", soil="my-fill", block="rack", damage_state="overturning")
median, beta = float(row["median"]), float(row["beta"])
levels = fragility["intensity"].sel(block="rack").values  # the levels run, in g
pga = np.geomspace(levels[0], levels[-1], 200)

fig, ax = plt.subplots(figsize=(6, 4))
ax.plot(pga, norm.cdf(np.log(pga / median) / beta), label=f"lognormal: median {median:.2f} g, beta {beta:.2f}")
ax.plot(levels, row["empirical_fraction"], "o", label="fraction of records overturned")
ax.set_xscale("log")
ax.set_xlabel("PGA [g]")
ax.set_ylabel("P(overturning | PGA)")
ax.set_title("Rack on my fill: the recommended model")
ax.legend()
fig.tight_layout()

# %%
# The same study from the command line writes these files and the report::
#
#     rockfrag fragility docs/examples/my-site.toml
#
# :doc:`04_netcdf_outputs` reads the files with xarray, and :doc:`/reference/outputs` lists every variable.
