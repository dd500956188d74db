"""Write studies/calibration-reference.csv, the sample reference of `rockfrag calibrate` (README).

The reference is not a measurement: it is the rotation history of rockfrag's own `ssi` model (the
paper's 2-DOF SSI-rocking model) for the paper block on an interface of known stiffness and damping,
k = 3.7e8 N/m and xi = 0.042 (between the points of the command's coarse grid), under the processed
DUZCE/BOL090 record scaled by 1.5, sampled every 0.02 s for the first 30 s and rounded to 7
significant digits. Calibrating against it should give back k and xi, which makes it a check of the
command as well as an example of the file layout (two columns with their units in the header; '#'
lines are comments). Run from the repository root:

    python studies/make_calibration_reference.py
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from rockfrag.config import load_study
from rockfrag.models import simulate
from rockfrag.processing import load_recipe, process_record
from rockfrag.records import load_records

RECORD, SCALE, BLOCK = "DUZCE/BOL090", 1.5, "paper"
STIFFNESS, DAMPING = 3.7e8, 0.042  # N/m, -
STEP, DURATION = 0.02, 30.0  # s
TARGET = Path(__file__).with_name("calibration-reference.csv")


def main() -> None:
    """Simulate the reference and write it with a header that says how it was made."""
    study = load_study()
    block = next(b for b in study.blocks if b.name == BLOCK)
    records, _ = load_records([RECORD])
    record = process_record(records[0], load_recipe(study.processing or None))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = simulate("ssi", record.acceleration * SCALE, record.dt, block, k=STIFFNESS, xi=DAMPING,
                          switch=study.switch, t_end=DURATION)
    every = int(round(STEP / record.dt))
    time, theta = result.t[::every], result.theta[::every]
    keep = time <= DURATION + 1e-9
    lines = [
        "# Sample reference for `rockfrag calibrate` (see README, Calibration). NOT a measurement: the",
        f"# rotation of rockfrag's own `ssi` model for the '{BLOCK}' block with k = {STIFFNESS:.3g} N/m and",
        f"# xi = {DAMPING:g}, under the processed {RECORD} record scaled by {SCALE:g} (shipped processing",
        f"# recipe, [solver] switch = {study.switch!r}), every {STEP:g} s for the first {DURATION:g} s.",
        "# Written by studies/make_calibration_reference.py; calibrating against it should give back k and xi:",
        f"#   rockfrag calibrate studies/calibration-reference.csv --record {RECORD} --scale {SCALE:g} "
        f"--block {BLOCK} --soil sand",
        "time [s],theta [rad]",
        *(f"{t:.2f},{value:.7g}" for t, value in zip(time[keep], theta[keep])),
    ]
    TARGET.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"wrote {TARGET} ({int(keep.sum())} rows; peak |theta| {np.max(np.abs(theta)):.4g} rad)")


if __name__ == "__main__":
    main()
