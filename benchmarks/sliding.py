"""Bench 1d: the per-run cost of sliding (``friction``) against the tied base, section 1b's runs.

The default study's blocks and soils, far-field components at 1.5 and 3 x uplift PGA, one core: ms per run
tied and with mu = 0.5 (static = kinetic), and their ratio (requirement: at most 2). ``make bench`` runs it
over the whole far-field set; ``python benchmarks/sliding.py 6`` over the first 6 components.
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
warnings.simplefilter("ignore")

from rockfrag.config import load_study  # noqa: E402
from rockfrag.models import get_model, simulate_batch  # noqa: E402
from rockfrag.processing import process_record  # noqa: E402
from rockfrag.records import load_records  # noqa: E402
from rockfrag.soils import soil_block_stiffness  # noqa: E402

FRICTION = 0.5
CASES = [("housner", {}), ("winkler", {"bed": "continuous"}), ("winkler", {"bed": "two-spring"})]


def cost(model, block, k, records, **options):
    """(ms per run, ms per simulated second, integration steps, mean peak slip [m]) over the records at 1.5 and 3 x
    uplift PGA. Times are this process's CPU time (robust to a loaded machine); the steps do not depend on it."""
    simulate_batch(model, records[0].acceleration[:50], records[0].dt, [1.0], [(block, k, 0.05)], **options)
    start = time.process_time()
    runs = 0
    steps = 0.0
    simulated = 0.0
    slips = []
    for record in records:
        scales = np.array([1.5, 3.0]) * block.uplift_acceleration() / np.max(np.abs(record.acceleration))
        out = simulate_batch(model, record.acceleration, record.dt, scales, [(block, k, 0.05)], **options)
        runs += out.size
        simulated += out["t_end"].sum()
        steps += out["n_steps"].sum()
        slips.extend(out["peak_slip"].ravel())
    elapsed = time.process_time() - start
    return elapsed / runs * 1e3, elapsed / simulated * 1e3, steps, float(np.mean(slips))


def run(records, soils=None):
    """Print the table: per model, block and soil, tied ms -> sliding ms (ratio), mean peak slip."""
    config = load_study()
    soils = [s for s in config.soils if soils is None or s.name in soils]
    print(f"\n1d. Sliding (friction = {FRICTION}) against the tied base, one core, {len(records)} far-field "
          "components at 1.5 and 3 x uplift PGA: CPU ms per run tied -> sliding (ratio; ratio per simulated second; "
          "ratio of integration steps), mean peak slip")
    print("   (a tied run that overturns stops early; the same block sliding usually runs to the end, so the ratio")
    print("    per run mixes cost and duration; the ratio per simulated second compares the cost of the physics; the")
    print("    ratio of steps is the same cost free of the machine's noise: a step costs the same tied or sliding)")
    print(f"   {'model':22} {'block':16}" + "".join(f"{s.name:>42}" for s in soils))
    worst = worst_rate = worst_steps = 0.0
    for model, options in CASES:
        label = model + (f" ({options['bed']})" if options else "")
        for block in config.blocks:
            cells = []
            for soil in (soils[:1] if get_model(model).is_rigid_base else soils):
                k = soil_block_stiffness(soil, block)
                tied, tied_rate, tied_steps, _ = cost(model, block, k, records, **options)
                sliding, sliding_rate, sliding_steps, slip = cost(model, block, k, records, friction=FRICTION,
                                                                  **options)
                worst = max(worst, sliding / tied)
                worst_rate = max(worst_rate, sliding_rate / tied_rate)
                worst_steps = max(worst_steps, sliding_steps / tied_steps)
                cells.append(f"{tied:6.2f} -> {sliding:6.2f} ({sliding / tied:4.2f}; {sliding_rate / tied_rate:4.2f}; "
                             f"{sliding_steps / tied_steps:4.2f}) {slip * 100:4.1f}cm")
            print(f"   {label:22} {block.name:16}" + "".join(f"{c:>42}" for c in cells)
                  + ("  (all soils)" if get_model(model).is_rigid_base else ""))
    print(f"   largest ratio sliding / tied: {worst:.2f} per run, {worst_rate:.2f} per simulated second, "
          f"{worst_steps:.2f} in integration steps per run (requirement: <= 2)")
    return worst


if __name__ == "__main__":
    count = int(sys.argv[1]) if len(sys.argv) > 1 else None
    loaded, _ = load_records("far-field")
    run([process_record(r) for r in loaded[:count]])
