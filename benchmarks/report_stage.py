"""Time the report stage alone on the result files of a finished study (not part of the tests).

Usage: ``python benchmarks/report_stage.py OUTPUT_DIR [STUDY.toml [WORKERS]]`` (WORKERS 1: no PNG worker) -
reads cube.nc, ida.nc, fragility.nc (and showcase.nc, applicability.nc) from OUTPUT_DIR, rewrites report.pdf,
report.html and figures/, and prints the wall time and the number of pages.
"""

from __future__ import annotations

import resource
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # this checkout's pipeline, not an installed one


def main(output, study=None, workers=None):
    output = Path(output)
    missing = [name for name in ("cube.nc", "ida.nc", "fragility.nc") if not (output / name).is_file()]
    if missing:
        raise SystemExit(f"report_stage: {output} has no {', '.join(missing)}; run `make fragility` first (or "
                         "`rockfrag fragility STUDY --output DIR` and give DIR)")
    # imported after the check: a missing study is one line at once, not after 3 s of importing matplotlib
    import xarray as xr

    from rockfrag.config import load_study
    from rockfrag.report import report_stage

    config = load_study(study or None)
    datasets = {}
    for name in ("cube", "ida", "fragility"):
        with xr.open_dataset(output / f"{name}.nc") as dataset:
            datasets[name] = dataset.load()
    started, cpu = time.perf_counter(), _cpu_seconds()
    pdf, pngs = report_stage(config, datasets["cube"], datasets["ida"], datasets["fragility"], None, output,
                             progress=False, workers=int(workers) if workers else None)
    elapsed, cpu = time.perf_counter() - started, _cpu_seconds() - cpu
    pages = (output / "report.html").read_text(encoding="utf-8").count("<section id='page-")
    print(f"report stage: {elapsed:.1f} s wall, {cpu:.1f} s CPU (this process and its PNG worker) for "
          f"{pages} pages, {len(pngs)} of them figures ({elapsed / pages:.2f} s per page); {pdf}")
    return elapsed


def _cpu_seconds():
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


if __name__ == "__main__":
    main(*sys.argv[1:4])
