"""Coverage of the calibration intervals (issue 34, item 1): how often the 90 % intervals contain the truth.

Input : nothing. Each case is a reference made by the project's own ``ssi`` model for the paper block at a true
        (k, xi) drawn over the search range (k log-uniform 1e8-1e9 N/m, xi uniform 0.01-0.07; the search range is the
        same: ``--k-range 1e8 1e9``), under a record
        (Bolu 090 x 1.5, as ``studies/calibration-reference.csv``, for half of the cases; Bolu 090 x 2, Nishi-Akashi
        090 x 2, Beverly Hills 009 x 2 and Rio Dell 270 x 3 for the others), sampled every 0.02 s for the first
        30 s, written to 7 significant digits, plus noise of 0, 1, 2, 5 or 10 % of the peak |rotation|, white or
        AR(1) (phi = 0.8 per sample, the same variance). Case i draws from numpy's generator seeded with i.
Output: per case one line (truth, fit, intervals, decisive window, seconds); then the table of
        docs/theory/calibration.md ("Measured coverage"): per noise level and kind the cases, the fraction whose
        interval contains the true k and the true xi, the median interval widths (k relative, xi absolute), the
        cases whose interval is the whole search range, those reported "not identifiable", and the median seconds.
        ``--json PATH`` also writes every case as JSON lines.

Run: ``python benchmarks/calibration_coverage.py [--cases 120] [--first 0] [--json reports/coverage.jsonl]``;
``--table reports/coverage.jsonl`` prints the table of cases already run (e.g. in several parts).
(about 8 s a case on one core of the 2-core machine; not part of ``make bench``).
"""

from __future__ import annotations

import argparse
import json
import math
import time
import warnings

import numpy as np

from rockfrag.calibrate import calibrate
from rockfrag.config import load_study
from rockfrag.models import simulate
from rockfrag.processing import load_recipe, process_record
from rockfrag.records import load_records

K_RANGE, XI_RANGE = (1e8, 1e9), (0.01, 0.07)  # the search range (`--k-range 1e8 1e9`; xi the default)
TRUE_K, TRUE_XI = K_RANGE, XI_RANGE  # the truths are drawn over the whole search range
NOISES = (0.0, 0.01, 0.02, 0.05, 0.10)
KINDS = ("white", "ar1")
PHI = 0.8
MOTIONS = (("DUZCE/BOL090", 1.5),) * 4 + (("DUZCE/BOL090", 2.0), ("PEER/NIS090", 2.0), ("NORTHR/MUL009", 2.0),
                                        ("PEER/RIO270", 3.0))
STEP, DURATION = 0.02, 30.0  # s
CONFIDENCE = 0.9

_MOTIONS: dict = {}


def motion(record: str, scale: float):
    """(ag [m/s^2], dt [s]) of the processed record times ``scale`` (the shipped study's recipe)."""
    if record not in _MOTIONS:
        study = load_study()
        records, _ = load_records([record])
        _MOTIONS[record] = process_record(records[0], load_recipe(study.processing or None))
    processed = _MOTIONS[record]
    return processed.acceleration * scale, processed.dt


def draw(index: int) -> dict:
    """The case ``index``: truth, noise, record (numpy's generator seeded with the index)."""
    rng = np.random.default_rng(index)
    k = float(math.exp(rng.uniform(math.log(TRUE_K[0]), math.log(TRUE_K[1]))))
    xi = float(rng.uniform(*TRUE_XI))
    noise = NOISES[index % len(NOISES)]
    kind = KINDS[(index // len(NOISES)) % len(KINDS)]
    record, scale = MOTIONS[int(rng.integers(len(MOTIONS)))]
    return {"index": index, "k": k, "xi": xi, "noise": noise, "kind": kind, "record": record, "scale": scale,
            "seed": int(rng.integers(1 << 31))}


def reference(case: dict, block, switch: str):
    """(time [s], rotation [rad], ag [m/s^2], dt [s]) of a case: the ssi model's rotation plus noise."""
    ag, dt = motion(case["record"], case["scale"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = simulate("ssi", ag, dt, block, k=case["k"], xi=case["xi"], switch=switch, t_end=DURATION)
    every = int(round(STEP / dt))
    time_, theta = result.t[::every], result.theta[::every]
    keep = time_ <= DURATION + 1e-9
    time_, theta = time_[keep], np.array([float(f"{value:.7g}") for value in theta[keep]])
    rng = np.random.default_rng(case["seed"])
    sigma = case["noise"] * float(np.max(np.abs(theta)))
    if case["kind"] == "white":
        noise = rng.normal(0.0, sigma, theta.size)
    else:
        shocks = rng.normal(0.0, sigma * math.sqrt(1.0 - PHI**2), theta.size)
        noise = np.empty_like(shocks)
        noise[0] = rng.normal(0.0, sigma)
        for i in range(1, noise.size):
            noise[i] = PHI * noise[i - 1] + shocks[i]
    return time_, theta + noise, ag, dt


def run_case(case: dict, block, switch: str) -> dict:
    """Calibrate one case; the truth, the fit, the intervals and whether they contain the truth."""
    time_, rotation, ag, dt = reference(case, block, switch)
    started, cpu = time.perf_counter(), time.process_time()
    result = calibrate(time_, rotation, ag, dt, block, switch=switch, k_range=K_RANGE, xi_range=XI_RANGE,
                       confidence=CONFIDENCE)
    seconds, cpu = time.perf_counter() - started, time.process_time() - cpu
    return dict(case, fit_k=result.k, fit_xi=result.xi, k_low=result.k_low, k_high=result.k_high,
                xi_low=result.xi_low, xi_high=result.xi_high, identifiable=result.identifiable,
                decisive_window=result.decisive_window, seconds=seconds, cpu_seconds=cpu,
                simulations=result.n_simulations, deviance_limits=result.deviance_limits,
                covers_k=bool(result.k_low <= case["k"] <= result.k_high),
                covers_xi=bool(result.xi_low <= case["xi"] <= result.xi_high),
                whole_range=bool(result.k_low <= K_RANGE[0] * (1 + 1e-9) and result.k_high >= K_RANGE[1] * (1 - 1e-9))
                or bool(result.xi_low <= XI_RANGE[0] + 1e-12 and result.xi_high >= XI_RANGE[1] - 1e-12))


def table(rows: list[dict]) -> str:
    """The coverage table (markdown): per noise level and kind, then all cases."""
    lines = ["| noise (of the peak) | cases | k covered | xi covered | median width of k | median width of xi | "
             "whole range | not identifiable | median s (CPU) |", "|---|---|---|---|---|---|---|---|---|"]

    def line(label, chosen):
        if not chosen:
            return
        k_width = np.median([(r["k_high"] - r["k_low"]) / r["k"] for r in chosen])
        xi_width = np.median([r["xi_high"] - r["xi_low"] for r in chosen])
        lines.append(f"| {label} | {len(chosen)} | {np.mean([r['covers_k'] for r in chosen]):.0%} | "
                     f"{np.mean([r['covers_xi'] for r in chosen]):.0%} | {k_width:.2%} | {xi_width:.4f} | "
                     f"{sum(r['whole_range'] for r in chosen)} | {sum(not r['identifiable'] for r in chosen)} | "
                     f"{np.median([r['seconds'] for r in chosen]):.1f} "
                     f"({np.median([r['cpu_seconds'] for r in chosen]):.1f}) |")

    for noise in NOISES:
        for kind in KINDS:
            line(f"{noise:.0%} {kind}" if noise else "0", [r for r in rows if r["noise"] == noise and (
                r["kind"] == kind or noise == 0.0)] if noise or kind == KINDS[0] else [])
    line("**all**", rows)
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=120)
    parser.add_argument("--first", type=int, default=0)
    parser.add_argument("--json", default=None, help="write every case as JSON lines here")
    parser.add_argument("--table", default=None, metavar="JSON", help="only print the table of the cases in JSON")
    args = parser.parse_args(argv)
    if args.table:
        rows = [json.loads(line) for line in open(args.table, encoding="utf-8") if line.strip()]
        print(f"{len(rows)} cases; wall time per case {min(r['seconds'] for r in rows):.1f}-"
              f"{max(r['seconds'] for r in rows):.1f} s (CPU {min(r['cpu_seconds'] for r in rows):.1f}-"
              f"{max(r['cpu_seconds'] for r in rows):.1f} s)\n")
        print(table(rows))
        return 0
    study = load_study()
    block = next(b for b in study.blocks if b.name == "paper")
    rows, started = [], time.perf_counter()
    sink = open(args.json, "a", encoding="utf-8") if args.json else None
    for index in range(args.first, args.first + args.cases):
        row = run_case(draw(index), block, study.switch)
        rows.append(row)
        if sink:
            sink.write(json.dumps(row) + "\n")
            sink.flush()
        print(f"{index:4d} {row['record']} x{row['scale']:g} k {row['k']:.4g} xi {row['xi']:.4f} "
              f"{row['noise']:.0%} {row['kind']:5s}: fit {row['fit_k']:.4g} {row['fit_xi']:.4f}, "
              f"k [{row['k_low']:.4g}, "
              f"{row['k_high']:.4g}] {'ok' if row['covers_k'] else 'MISS'}, xi [{row['xi_low']:.4f}, "
              f"{row['xi_high']:.4f}] {'ok' if row['covers_xi'] else 'MISS'}, window {row['decisive_window']}, "
              f"{'identifiable' if row['identifiable'] else 'NOT identifiable'}, {row['seconds']:.1f} s "
              f"({row['cpu_seconds']:.1f} s CPU)", flush=True)
    print(f"\n{len(rows)} cases in {time.perf_counter() - started:.0f} s wall; slowest case "
          f"{max(r['seconds'] for r in rows):.1f} s ({max(r['cpu_seconds'] for r in rows):.1f} s CPU)\n")
    print(table(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
