"""
One block, one record: the API
==============================

``simulate`` runs one model for one block under one ground motion and returns the histories and the peaks.
Here the steel rack of :doc:`01_block_and_site` stands on sand under the Bolu 090 record of the 1999 Düzce
earthquake, computed with Housner's rigid base and with the recommended model, the tensionless bed
(``winkler``) whose impacts lose what experiments measure (:doc:`/theory/models`).
"""

# %%
# The block, the soil and the record
# ----------------------------------
# A ``Block`` takes its half-width ``b`` and half-height ``h`` [m] (or ``R`` and ``alpha``), its mass [kg],
# the Young's modulus of its base ``E_b`` [Pa], its footprint area [m^2] and the soil depth that takes part in
# the interface stiffness [m] (the paper's eq. 19).
import numpy as np

from rockfrag.blocks import Block
from rockfrag.processing import process_record
from rockfrag.records import load_records
from rockfrag.soils import SOILS, soil_block_stiffness

rack = Block(name="rack", b=0.3, h=1.0, mass=1500.0, E_b=200e9, footprint_area=0.36, soil_depth=1.0)
print(f"R = {rack.R:.3f} m, alpha = {rack.alpha:.3f} rad, p = {rack.p():.2f} rad/s")
print(f"uplift on a rigid base at g tan(alpha) = {rack.uplift_acceleration() / 9.80665:.2f} g; "
      f"Housner's restitution r = {rack.housner_restitution():.3f}")

sand = SOILS["sand"]
k = soil_block_stiffness(sand, rack)  # the interface stiffness of eq. 19 [N/m]
print(f"{sand.name}: G = {sand.shear_modulus / 1e6:.0f} MPa, k = {k:.3g} N/m")

record = process_record(load_records("DUZCE/BOL090")[0][0])
ag, dt = record.acceleration, record.dt  # [m/s^2], [s]
print(f"{record.id}: PGA {np.abs(ag).max() / 9.80665:.2f} g, {ag.size} samples at {dt} s")

# %%
# Housner and the recommended model
# ---------------------------------
# ``housner`` needs nothing but the block. ``winkler`` needs the bed's stiffness ``k``; with a target
# ``restitution`` its damping is calibrated so that the block's free rocking loses what the target says at each
# impact. The recommended fragility runs the band from Housner's value to 5% above it; its centre is:
from rockfrag.models import simulate
from rockfrag.models.variants import DEFAULT_BAND, band_target

target = band_target(rack, DEFAULT_BAND, "centre")
scale = 0.7  # the record scaled to 0.58 g
housner = simulate("housner", scale * ag, dt, rack)
winkler = simulate("winkler", scale * ag, dt, rack, k=k, bed="two-spring", restitution=target)
print(f"target restitution {target:.3f}: the bed's damping ratio is calibrated to xi = {winkler.extra['xi']:.3f}")
for name, result in (("housner", housner), ("winkler", winkler)):
    print(f"{name:8s} peak theta/alpha = {result.peak_angle_ratio:.3f}, {result.n_impacts} impacts, "
          f"outcome {result.status.name.lower()}")

# %%
# theta(t)
# --------
# The histories are sampled at the record's time steps (and 10 s of free motion after it). The bed lets the
# rack tilt before its corner lifts and rock at lower shaking, and it keeps more of its motion at each impact.
import matplotlib.pyplot as plt

fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5), sharex=True, height_ratios=[1, 2])
top.plot(np.arange(ag.size) * dt, scale * ag / 9.80665, color="0.4", lw=0.5)
top.set_ylabel("ground [g]")
for name, result in (("Housner (rigid base)", housner), ("winkler (recommended)", winkler)):
    bottom.plot(result.t, result.theta / rack.alpha, lw=0.8, label=name)
bottom.axhline(0, color="0.7", lw=0.5)
bottom.set_xlabel("time [s]")
bottom.set_ylabel("theta / alpha")
bottom.set_xlim(0, 30)
bottom.legend(loc="upper right")
fig.suptitle("Rack on sand, Bolu 090 x 0.7")
fig.tight_layout()

# %%
# Many scale factors at once
# --------------------------
# ``simulate_batch`` runs one record at many scale factors in one compiled call (this is how a study runs its
# stripes) and returns a structured array of the summary fields (``rockfrag.models.fields``). A peak of
# pi / (2 alpha) = 5.39 alpha is a rack that overturned.
from rockfrag.models import simulate_batch

scales = np.array([0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1])
housner_runs = simulate_batch("housner", ag, dt, scales, [(rack, None, None)])
winkler_runs = simulate_batch("winkler", ag, dt, scales, [(rack, k, None)], bed="two-spring", restitution=target)
print("scale    ", " ".join(f"{scale:6.2f}" for scale in scales))
for name, runs in (("housner", housner_runs), ("winkler", winkler_runs)):
    print(f"{name:9s}", " ".join(f"{ratio:6.3f}" for ratio in runs["peak_angle"][0] / rack.alpha))
