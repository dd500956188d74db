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
# the interface stiffness [m] (the paper's eq. 19). Everything here comes from the package's root:
# ``import rockfrag``.
import numpy as np

import rockfrag

rack = rockfrag.Block(name="rack", b=0.3, h=1.0, mass=1500.0, E_b=200e9, footprint_area=0.36, soil_depth=1.0)
print(f"R = {rack.R:.3f} m, alpha = {rack.alpha:.3f} rad, p = {rack.p():.2f} rad/s")
print(f"uplift on a rigid base at g tan(alpha) = {rack.uplift_acceleration() / 9.80665:.2f} g; "
      f"Housner's restitution r = {rack.housner_restitution():.3f}")

records, failures = rockfrag.load_records("DUZCE/BOL090")
record = rockfrag.process_record(records[0])
ag, dt = record.acceleration, record.dt  # [m/s^2], [s]
print(f"{record.id}: PGA {np.abs(ag).max() / 9.80665:.2f} g, {ag.size} samples at {dt} s")

# %%
# Housner and the recommended model
# ---------------------------------
# ``housner`` needs nothing but the block. ``recommended`` needs the soil: it is the study's recommended run,
# the tensionless bed with the soil's stiffness (eq. 19) and friction, its damping calibrated so that the
# block's free rocking loses what experiments measure at each impact (the centre of the restitution band).
# With the processed record times a cell's ``scale_factor`` from ``cube.nc`` (or ``scale=``: the same bits) and
# the cell's soil, it returns that cell's numbers bit for bit.
scale = 0.7  # the record scaled to 0.58 g
housner = rockfrag.simulate("housner", ag, dt, rack, scale=scale)
recommended = rockfrag.simulate("recommended", ag, dt, rack, soil="sand", scale=scale)
print(f"on sand the recommended bed's damping ratio is xi = {recommended.extra['xi']:.3f} "
      f"({recommended.extra['bed']} contact)")
for name, result in (("housner", housner), ("recommended", recommended)):
    print(f"{name:12s} peak theta/alpha = {result.peak_angle_ratio:.3f}, {result.n_impacts} impacts, "
          f"peak slip {result.peak_slip * 1000:.1f} mm, outcome {result.status.name.lower()}")

# %%
# theta(t)
# --------
# The histories are sampled at the record's time steps (and 10 s of free motion after it). The bed lets the
# rack tilt before its corner lifts and rock at lower shaking, and it keeps more of its motion at each impact.
import matplotlib.pyplot as plt

fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5), sharex=True, height_ratios=[1, 2])
top.plot(np.arange(ag.size) * dt, scale * ag / 9.80665, color="0.4", lw=0.5)
top.set_ylabel("ground [g]")
for name, result in (("Housner (rigid base)", housner), ("recommended (bed, sliding)", recommended)):
    bottom.plot(result.t, result.theta / rack.alpha, lw=0.8, label=name)
bottom.axhline(0, color="0.7", lw=0.5)
bottom.set_xlabel("time [s]")
bottom.set_ylabel("theta / alpha")
bottom.set_xlim(0, 30)
bottom.legend(loc="upper right")
fig.suptitle("Rack on sand, Bolu 090 x 0.7")
fig.tight_layout()

# %%
# Many scale factors, and the shipped soils
# -----------------------------------------
# A study runs each record at many scale factors; ``simulate`` with ``scale=`` gives the same bits as a study's
# cell. Here the rack under Bolu 090 at eight scale factors, on each shipped soil (``shipped_soils``: the paper's
# Table 1 and a steel base). A peak of pi / (2 alpha) = 5.39 alpha is a rack that overturned.
soils = rockfrag.shipped_soils()
for name, soil in soils.items():
    print(f"{name:7s} G = {soil.shear_modulus / 1e6:7.0f} MPa, mu = {soil.friction_static:.2f}: {soil.description}")

scales = np.array([0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1])
print("\nscale          ", " ".join(f"{scale:6.2f}" for scale in scales))
runs = {"housner": [rockfrag.simulate("housner", ag, dt, rack, scale=scale) for scale in scales]}
for name in ("sand", "rock"):
    runs[f"recommended, {name}"] = [rockfrag.simulate("recommended", ag, dt, rack, soil=soils[name], scale=scale)
                                    for scale in scales]
for name, results in runs.items():
    print(f"{name:17s}", " ".join(f"{result.peak_angle_ratio:6.3f}" for result in results))
