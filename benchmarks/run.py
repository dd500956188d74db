"""``make bench``: throughput of the compiled solvers against the scipy reference (one core).

Far-field records (processed) scaled around the uplift threshold of a 2 m block; Housner and SSI on
soft (omega/p = 30) and stiff (omega/p = 200) foundations. Prints runs per second and the speed-up
at matched accuracy (the kernel agrees with the reference to ~1e-5 on peak angle, see
tests/physics/test_kernels_vs_scipy.py).
"""

from __future__ import annotations

import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests", "physics"))
warnings.simplefilter("ignore")

from reference import reference_response  # noqa: E402

from pipeline.blocks import Block  # noqa: E402
from pipeline.models import simulate, simulate_batch  # noqa: E402
from pipeline.processing import process_record  # noqa: E402
from pipeline.records import load_records  # noqa: E402

BLOCK = Block(name="bench", R=2.0, alpha=0.25, mass=5000.0)
SCALES_OF_THRESHOLD = np.array([0.8, 1.2, 1.6, 2.0, 3.0])  # PGA / (g tan alpha)


def main():
    records, _ = load_records("far-field")
    motions = []
    for record in records:
        processed = process_record(record)
        pga = np.max(np.abs(processed.acceleration))
        motions.append((processed.acceleration, processed.dt, SCALES_OF_THRESHOLD * BLOCK.uplift_acceleration() / pga))
    n_records = len(motions)
    seconds = sum((m[0].size - 1) * m[1] for m in motions) / n_records
    print(f"far-field set: {n_records} components, mean length {seconds:.1f} s, "
          f"{SCALES_OF_THRESHOLD.size} scale factors each ({', '.join(f'{s:g}' for s in SCALES_OF_THRESHOLD)} x uplift PGA)")
    cases = [("housner", None, "rigid"), ("ssi", 30.0, "soft, w/p = 30"), ("ssi", 200.0, "stiff, w/p = 200")]
    # warm-up (compilation is cached on disk after the first run)
    simulate_batch("housner", motions[0][0], motions[0][1], [1.0], [(BLOCK, None, None)])
    simulate_batch("ssi", motions[0][0], motions[0][1], [1.0], [(BLOCK, 1e7, 0.05)])
    print(f"\n{'model':8} {'foundation':18} {'kernel runs/s':>14} {'ms/run':>8} {'scipy runs/s':>13} {'speed-up':>9}")
    for model, ratio, label in cases:
        k = BLOCK.mass * (ratio * BLOCK.p()) ** 2 if ratio else None
        start = time.perf_counter()
        n_runs = 0
        for ag, dt, scales in motions:
            simulate_batch(model, ag, dt, scales, [(BLOCK, k, 0.05)])
            n_runs += scales.size
        kernel_rate = n_runs / (time.perf_counter() - start)
        # reference on a subset (it is slow): Housner 4 records x 2 scales, SSI 2 records x 1 scale
        start = time.perf_counter()
        n_ref = 0
        subset = [(m, s) for m in motions[:4] for s in m[2][[1, 3]]] if model == "housner" else \
            [(m, m[2][1]) for m in motions[:2]]
        for (ag, dt, _), scale in subset:
            reference_response(model, ag * scale, dt, BLOCK, k=k, xi=0.05, t_end=(ag.size - 1) * dt + 10.0)
            n_ref += 1
        reference_rate = n_ref / (time.perf_counter() - start)
        print(f"{model:8} {label:18} {kernel_rate:14.1f} {1000 / kernel_rate:8.2f} {reference_rate:13.2f} "
              f"{kernel_rate / reference_rate:8.0f}x")


if __name__ == "__main__":
    main()
