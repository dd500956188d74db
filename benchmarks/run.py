"""``make bench``: solver throughput against the scipy reference, the default study's wall time and
memory, scaling from 1 to all cores, the runs hunt-and-fill saves, and the calibration search's time.
Prints a report; never part of the tests.
"""

from __future__ import annotations

import os
import re
import resource
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # this checkout's pipeline and its test suite's scipy references
warnings.simplefilter("ignore")

import calibration  # noqa: E402  (benchmarks/calibration.py)
import fragility as fragility_benchmark  # noqa: E402  (benchmarks/fragility.py)
import sliding as sliding_benchmark  # noqa: E402  (benchmarks/sliding.py)
from opensees_sliding import run as sliding_against_opensees  # noqa: E402  (benchmarks/opensees_sliding.py)
from opensees_winkler import run as winkler_against_opensees  # noqa: E402  (benchmarks/opensees_winkler.py)

from rockfrag.blocks import Block  # noqa: E402
from rockfrag.config import load_study  # noqa: E402
from rockfrag.ida import hunt_and_fill  # noqa: E402
from rockfrag.models import Outcome, get_model, simulate, simulate_batch  # noqa: E402
from rockfrag.processing import process_record  # noqa: E402
from rockfrag.records import load_records  # noqa: E402
from rockfrag.soils import soil_block_stiffness  # noqa: E402
from rockfrag.study import bed_calibration, model_stiffness, solver_options  # noqa: E402
from rockfrag.units import STANDARD_GRAVITY  # noqa: E402
from tests.physics.reference import reference_response  # noqa: E402  (the independent scipy reference)

BLOCK = Block(name="bench", R=2.0, alpha=0.25, mass=5000.0)
SCALES_OF_THRESHOLD = np.array([0.8, 1.2, 1.6, 2.0, 3.0])  # PGA / (g tan alpha)


def far_field():
    records, _ = load_records("far-field")
    return [process_record(r) for r in records]


def solver_throughput(records):
    print("1. Solvers, one core: compiled kernel vs scipy solve_ivp reference (DOP853, rtol 1e-10)")
    motions = [(r.acceleration, r.dt,
                SCALES_OF_THRESHOLD * BLOCK.uplift_acceleration() / np.max(np.abs(r.acceleration)))
               for r in records]
    simulate_batch("housner", motions[0][0], motions[0][1], [1.0], [(BLOCK, None, None)])  # compile / load cache
    simulate_batch("ssi", motions[0][0], motions[0][1], [1.0], [(BLOCK, 1e7, 0.05)])
    simulate("housner", motions[0][0][:10], motions[0][1], BLOCK)  # the matched subset's entry point too
    print(f"   far-field set: {len(records)} components, {SCALES_OF_THRESHOLD.size} scale factors each "
          f"({', '.join(f'{s:g}' for s in SCALES_OF_THRESHOLD)} x the uplift PGA of a 2 m block)")
    print(f"   {'model':8} {'foundation':16} {'kernel runs/s':>13} {'ms/run':>7} | matched subset: "
          f"{'kernel ms':>9} {'scipy ms':>9} {'speed-up':>8}")
    for model, ratio, label in (("housner", None, "rigid"), ("ssi", 30.0, "soft, w/p=30"),
                                ("ssi", 200.0, "stiff, w/p=200")):
        k = BLOCK.mass * (ratio * BLOCK.p()) ** 2 if ratio else None
        start = time.perf_counter()
        n_runs = 0
        for ag, dt, scales in motions:
            simulate_batch(model, ag, dt, scales, [(BLOCK, k, 0.05)])
            n_runs += scales.size
        rate = n_runs / (time.perf_counter() - start)
        # matched subset: the same runs through both solvers (first 30 s of 3 records at 1.2x and 2x;
        # SSI: 20 s of one record, since the reference restarts solve_ivp at each of its many impacts)
        subset = [(ag[:3000], dt, s) for ag, dt, scales in motions[:3] for s in scales[[1, 3]]] \
            if model == "housner" else [(ag[:2000], dt, s) for ag, dt, scales in motions[:1] for s in scales[[1, 3]]]
        start = time.perf_counter()
        for _ in range(5):
            for ag, dt, s in subset:
                simulate(model, ag * s, dt, BLOCK, k=k, xi=0.05, t_end=(ag.size - 1) * dt + 5.0)
        kernel_ms = (time.perf_counter() - start) / (5 * len(subset)) * 1000
        start = time.perf_counter()
        for ag, dt, s in subset:
            reference_response(model, ag * s, dt, BLOCK, k=k, xi=0.05, t_end=(ag.size - 1) * dt + 5.0)
        scipy_ms = (time.perf_counter() - start) / len(subset) * 1000
        print(f"   {model:8} {label:16} {rate:13.0f} {1000 / rate:7.2f} | {'':15}{kernel_ms:9.2f} {scipy_ms:9.0f} "
              f"{scipy_ms / kernel_ms:7.0f}x")


def per_run_cost(records):
    """ms and integration steps per run of each model on each default soil, the default study's blocks."""
    print("\n1b. Per-run cost, one core: the default blocks and soils, far-field set at 1.5 and 3 x uplift PGA")
    config = load_study()
    print(f"   {'model':20} {'block':16}" + "".join(f"{s.name:>16}" for s in config.soils))
    cases = [("housner", {}), ("ssi", {}), ("winkler", {"bed": "continuous"}), ("winkler", {"bed": "two-spring"})]
    for model, options in cases:
        label = model + (f" ({options['bed']})" if options else "")
        for block in config.blocks:
            cells = []
            soils = config.soils[:1] if get_model(model).is_rigid_base else config.soils
            for soil in soils:
                k = soil_block_stiffness(soil, block)
                simulate_batch(model, records[0].acceleration[:50], records[0].dt, [1.0], [(block, k, 0.05)], **options)
                start = time.perf_counter()
                runs = steps = 0
                for record in records:
                    scales = np.array([1.5, 3.0]) * block.uplift_acceleration() / np.max(np.abs(record.acceleration))
                    out = simulate_batch(model, record.acceleration, record.dt, scales, [(block, k, 0.05)], **options)
                    runs += out.size
                    steps += out["n_steps"].sum()
                elapsed = time.perf_counter() - start
                cells.append(f"{elapsed / runs * 1e3:6.2f} ms {steps / runs / 1e3:5.1f}k")
                if get_model(model).is_rigid_base:
                    cells[-1] += " (all soils)"
            print(f"   {label:20} {block.name:16}" + "".join(f"{c:>16}" for c in cells))
    omega = [f"{s.name} {np.sqrt(soil_block_stiffness(s, b) / b.mass) / b.p():.0f}" for b in config.blocks[:1]
             for s in config.soils]
    print(f"   (ms per run and integration steps per run; omega_v/p of the paper block: {', '.join(omega)}.")
    print("    Steps end on every sample, so soft beds cost about one step per sample; on rock and steel the")
    print("    steps resolve the contact changes and the bed's ringing after each landing, see README Performance.)")


def per_run_cost_band(records):
    """1b with the anchored dissipation: the default study's sample members at their calibrated xi."""
    print("\n1b'. Per-run cost, one core, anchored dissipation: winkler (two-spring), the recommended model's")
    print("     sample members, xi calibrated per block and soil (the default study's runs), same records and levels")
    config = load_study()
    stiffness = model_stiffness(config)
    calibration = bed_calibration(config, stiffness)
    stiffness = stiffness[:, :, [config.models.index(v) for v in calibration.variants]]
    options = solver_options(config)
    print(f"   {'model':20} {'block':16}" + "".join(f"{s.name:>22}" for s in config.soils))
    for v, variant in enumerate(calibration.variants):
        for b, block in enumerate(config.blocks):
            cells = []
            for s in range(len(config.soils)):
                case = [(block, stiffness[s, b, v], calibration.xi[s, b, v])]
                simulate_batch("winkler", records[0].acceleration[:50], records[0].dt, [1.0], case, **options)
                start = time.perf_counter()
                runs = steps = 0
                for record in records:
                    scales = np.array([1.5, 3.0]) * block.uplift_acceleration() / np.max(np.abs(record.acceleration))
                    out = simulate_batch("winkler", record.acceleration, record.dt, scales, case, **options)
                    runs += out.size
                    steps += out["n_steps"].sum()
                elapsed = time.perf_counter() - start
                cells.append(f"{elapsed / runs * 1e3:6.2f} ms {steps / runs / 1e3:5.1f}k xi {case[0][2]:.2f}")
            print(f"   {variant:20} {block.name:16}" + "".join(f"{c:>22}" for c in cells))


def accuracy_and_chaos(records, anchored=False):
    """How many winkler runs are chaotic, and the default tolerance's error on the regular and chaotic ones.

    A run counts as chaotic when a 1e-7 relative change of the record's amplitude moves its peak angle by
    more than 1e-6 (both at rtol 1e-10); the reference is the rtol 1e-10 run itself."""
    mark = "'" if anchored else ""
    print(f"\n1c{mark}. Accuracy at the default tolerance (rtol 1e-6) against rtol 1e-10, and how many runs are "
          "chaotic")
    print("    (winkler, " + ("two-spring bed, xi calibrated to the restitution range's middle (recommended runs)"
                              if anchored else "continuous bed, each soil's xi = 5%") +
          ", default blocks, 4 far-field records at 0.5, 0.9, 1.5, 2.5 x uplift PGA;")
    print("     chaotic: a 1e-7 change of amplitude moves the peak angle by more than 1e-6 at rtol 1e-10)")
    config = load_study()
    calibration = bed_calibration(config, model_stiffness(config)) if anchored else None
    options = solver_options(config) if anchored else {"bed": "continuous"}
    levels = np.array([0.5, 0.9, 1.5, 2.5])
    print(f"   {'soil':8} {'runs':>5} {'chaotic':>8} | error, regular runs: {'median':>8} {'max':>8} | "
          f"chaotic runs: {'median':>8} {'p90':>8}")
    for soil in config.soils:
        sensitivity, error = [], []
        for b, block in enumerate(config.blocks):
            k = soil_block_stiffness(soil, block)
            xi = soil.damping_ratio if calibration is None else float(
                calibration.xi[config.soils.index(soil), b, calibration.variants.index("recommended")])
            for record in records[::11]:
                scales = levels * block.uplift_acceleration() / np.max(np.abs(record.acceleration))
                window = {"t_end": (record.acceleration.size - 1) * record.dt + 10.0, **options}
                cases = [(block, k, xi)]
                truth = simulate_batch("winkler", record.acceleration, record.dt, scales, cases, rtol=1e-10,
                                       atol=1e-11, **window)[0]
                nudged = simulate_batch("winkler", record.acceleration, record.dt, scales * (1 + 1e-7), cases,
                                        rtol=1e-10, atol=1e-11, **window)[0]
                default = simulate_batch("winkler", record.acceleration, record.dt, scales, cases, **window)[0]
                overturned = int(Outcome.OVERTURNED)
                standing = np.all([run["status"] != overturned for run in (truth, nudged, default)], axis=0)
                peak = truth["peak_angle"][standing]
                sensitivity += list(np.abs(nudged["peak_angle"][standing] - peak) / peak)
                error += list(np.abs(default["peak_angle"][standing] - peak) / peak)
        sensitivity, error = np.array(sensitivity), np.array(error)
        chaotic = sensitivity > 1e-6
        regular_error = error[~chaotic] if np.any(~chaotic) else np.array([np.nan])
        chaotic_error = error[chaotic] if np.any(chaotic) else np.array([np.nan])
        print(f"   {soil.name:8} {error.size:5d} {chaotic.mean():8.0%} | {'':21}{np.median(regular_error):8.1e} "
              f"{regular_error.max():8.1e} | {'':14}{np.median(chaotic_error):8.1e} "
              f"{np.quantile(chaotic_error, 0.9):8.1e}")
    print("   (overturned runs are left out; in a chaotic run no tolerance gives a reproducible peak angle, only the")
    print("    distribution over records is meaningful)")


def run_study_subprocess(args, output):
    command = [sys.executable, "-m", "rockfrag", "run", *args, "--output", str(output), "--no-progress"]
    start = time.perf_counter()
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    finished = subprocess.run(command, check=True, capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return elapsed, max(peak, before) / 1024, finished.stdout + finished.stderr


def study_timing():
    cores = os.cpu_count()
    print(f"\n2. Default study end to end (rockfrag run, {cores} cores, fresh output folder)")
    with tempfile.TemporaryDirectory() as folder:
        elapsed, peak_mb, log = run_study_subprocess([], Path(folder) / "default")
    counted = re.search(r"(\d+) runs to do", log)  # the study's own count: stripes of every model and member
    runs = int(counted.group(1)) if counted else 0
    print(f"   {runs} stripe runs in {elapsed:.1f} s wall ({runs / elapsed:.0f} runs/s, refining runs not counted; "
          f"budget 300 s, issue 32); peak RSS of the largest process {peak_mb:.0f} MB")
    print("\n3. Scaling: 8 far-field records, default levels/soils/blocks/models")
    study = Path(tempfile.mkdtemp()) / "eight.toml"
    records, _ = load_records("far-field")
    ids = ", ".join(f'"{r.id}"' for r in records[:8])
    study.write_text(f"[study]\nname = \"scaling\"\nrecord_sets = [{ids}]\n")
    with tempfile.TemporaryDirectory() as folder:
        serial = run_study_subprocess([str(study), "--serial"], Path(folder) / "one")[0]
        parallel = run_study_subprocess([str(study)], Path(folder) / "all")[0]
    print(f"   1 core: {serial:.1f} s   {cores} cores: {parallel:.1f} s   speed-up {serial / parallel:.2f}x "
          f"(efficiency {serial / parallel / cores:.0%})")


def hunt_and_fill_savings(records):
    print("\n4. Overturning capacity: hunt-and-fill vs a uniform grid of the same resolution (2%)")
    block = load_study().blocks[1]  # slender cabinet
    total_adaptive = total_uniform = 0
    for record in records[:10]:
        pga = np.max(np.abs(record.acceleration))

        def overturns(im_g):
            return simulate("housner", record.acceleration * im_g * STANDARD_GRAVITY / pga, record.dt, block).overturned

        capacity, lower, upper, runs = hunt_and_fill(overturns, start=0.1, step=0.1, tolerance=0.02)
        total_adaptive += runs
        total_uniform += int(np.ceil(np.log(3.0 / 0.05) / np.log(1.02)))  # 0.05-3 g at 2 % spacing
    print(f"   10 records: {total_adaptive} adaptive runs vs {total_uniform} uniform runs "
          f"({1 - total_adaptive / total_uniform:.0%} saved)")


if __name__ == "__main__":
    records = far_field()
    solver_throughput(records)
    per_run_cost(records)
    per_run_cost_band(records)
    sliding_benchmark.run(records)
    accuracy_and_chaos(records)
    accuracy_and_chaos(records, anchored=True)
    study_timing()
    hunt_and_fill_savings(records)
    winkler_against_opensees()
    sliding_against_opensees()  # prints one line and skips without openseespy, as the tied section
    print("\n5. ", end="")
    calibration.run()
    print("\n6. ", end="")
    fragility_benchmark.run(print=print)
