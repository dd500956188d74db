"""pipeline.study - stage 6: every record x intensity level x soil x block x model -> the cube.

Input : a ``StudyConfig`` (pipeline.config).
Output: ``reports/cube.nc`` (see pipeline.cube) and the ``xarray.Dataset``.

Work unit: one record at all its scale factors for all the cells (block, soil, model) it still
needs, run by the compiled batch solver. A cell's result is checkpointed as one small file named by
a hash of everything it depends on (record checksum, processing recipe, intensity settings, levels,
block, soil, model, solver settings, package version), so an interrupted study resumes where it
stopped and a changed input recomputes only the cells it touches. Housner results do not depend on
the soil: they are computed once per block and shared by every soil.

Executors: in-process (workers=1), all local cores (default, process pool), or dask.distributed
(``scheduler`` address of a running cluster, or ``dask_workers`` to start a LocalCluster). Every
executor runs the same pure task function, so the cube is identical whatever the executor.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from pipeline import __version__
from pipeline.cube import build_cube, write_netcdf
from pipeline.errors import PipelineError
from pipeline.measures import MEASURES
from pipeline.models import DEFAULT_ATOL, DEFAULT_RTOL, get_model, simulate_batch
from pipeline.models.fields import new_summaries
from pipeline.outputs import atomic_path
from pipeline.processing import load_recipe, process_record
from pipeline.records import load_records
from pipeline.soils import soil_block_stiffness


@dataclass(frozen=True)
class Cell:
    """One (block, soil, model) combination for one record; soil is None for rigid-base models."""

    key: str
    block_index: int
    soil_index: int | None
    model: str


def record_intensity(acceleration, dt, config) -> float:
    """The study's intensity measure of a processed record [SI]."""
    return MEASURES[config.measure](acceleration, dt, period=config.period, damping=config.damping)


def _hash(payload) -> str:
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=str).encode()).hexdigest()[:40]


def cells_for_record(record, config, recipe) -> list[Cell]:
    """The cells of one record with their checkpoint keys."""
    common = {"version": __version__, "record": record.metadata.get("sha256", record.id),
              "recipe": recipe.as_dict(), "measure": config.measure, "period": config.period,
              "damping": config.damping, "levels": list(config.levels_si),
              "solver": {**solver_options(config), "tail": config.tail, "rtol": DEFAULT_RTOL, "atol": DEFAULT_ATOL}}
    cells = []
    for block_index, block in enumerate(config.blocks):
        block_spec = {k: v for k, v in asdict(block).items() if k not in ("name", "description")}
        for model in config.models:
            if get_model(model).is_rigid_base:
                cells.append(Cell(_hash({**common, "block": block_spec, "model": model}), block_index, None, model))
                continue
            for soil_index, soil in enumerate(config.soils):
                soil_spec = {k: v for k, v in asdict(soil).items() if k not in ("name", "description")}
                cells.append(Cell(_hash({**common, "block": block_spec, "soil": soil_spec, "model": model}),
                                  block_index, soil_index, model))
    return cells


def solver_options(config) -> dict:
    """The study's solver settings as ``simulate_batch`` keywords (pipeline.models.SolverOptions)."""
    return {"switch": config.switch, "bed": config.bed, "overturn_angle": config.overturn_angle}


def compute_cells(acceleration, dt, scales, jobs, options, tail):
    """Pure task function (runs in a worker): summaries for each job.

    jobs : list of (key, model, block, k, xi); options : ``solver_options``.
    Returns {key: summary records (n_scale,)}.
    """
    results = {}
    t_end = (acceleration.size - 1) * dt + tail
    by_model = {}
    for key, model, block, k, xi in jobs:
        by_model.setdefault(model, []).append((key, block, k, xi))
    for model, group in by_model.items():
        summaries = simulate_batch(model, acceleration, dt, scales, [(b, k, xi) for _, b, k, xi in group],
                                   t_end=t_end, **options)
        for (key, *_), summary in zip(group, summaries):
            results[key] = summary
    return results


class CheckpointStore:
    """One .npy file per finished cell under ``folder``; written atomically."""

    def __init__(self, folder):
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)

    def path(self, key):
        return self.folder / f"{key}.npy"

    def has(self, key):
        return self.path(key).is_file()

    def load(self, key):
        return np.load(self.path(key))

    def save(self, key, array):
        with atomic_path(self.path(key)) as temporary:
            with open(temporary, "wb") as handle:
                np.save(handle, array)


def _warm_up(models):
    """Compile (or load from the on-disk cache) the kernels once before starting workers."""
    from pipeline.blocks import Block

    block = Block(name="warm-up", R=1.0, alpha=0.2, mass=1.0)
    for model in models:
        simulate_batch(model, np.zeros(3), 0.01, [1.0], [(block, 1e4, 0.05)])


def _executor(workers, scheduler, dask_workers):
    """(submit, as_completed, shutdown) for the chosen executor."""
    if scheduler or dask_workers:
        from dask.distributed import Client, LocalCluster
        from dask.distributed import as_completed as dask_completed

        cluster = None
        if scheduler:
            try:
                client = Client(scheduler, timeout="10s")
            except (OSError, TimeoutError, ValueError) as error:
                raise PipelineError(f"cannot connect to the dask scheduler at {scheduler!r} ({error}); "
                                    "expected the address of a running scheduler, e.g. tcp://host:8786") from None
        else:
            cluster = LocalCluster(n_workers=dask_workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)

        def shutdown():
            client.close()
            if cluster is not None:
                cluster.close()

        return (lambda *a: client.submit(compute_cells, *a, pure=False), dask_completed, shutdown)
    if workers == 1:
        class Immediate:
            def __init__(self, value):
                self._value = value

            def result(self):
                return self._value

        return (lambda *a: Immediate(compute_cells(*a)), lambda futures: list(futures), lambda: None)
    pool = ProcessPoolExecutor(max_workers=workers or os.cpu_count())
    return (lambda *a: pool.submit(compute_cells, *a), as_completed,
            lambda: pool.shutdown(wait=False, cancel_futures=True))


def study_records(config, log=print):
    """The study's records, processed with its recipe: (records, failures, recipe).

    Every stage that needs the study's records (study, applicability, report) takes them from here,
    so ``rockfrag fragility`` reads and processes them once.
    """
    recipe = load_recipe(config.processing or None)
    raw_records, failures = load_records(list(config.record_sets), units=config.record_units or None,
                                         dt=config.record_dt)
    for failure in failures:
        log(f"rockfrag: skipped {failure}")
    if not raw_records:
        raise PipelineError("no record could be read; nothing to run")
    return [process_record(record, recipe) for record in raw_records], failures, recipe


def run_study(config, *, output=None, workers=None, scheduler=None, dask_workers=None,
              progress=True, log=print, loaded=None):
    """Run (or resume) a study and write ``cube.nc``; returns (dataset, statistics dict).

    ``loaded`` may pass the result of ``study_records`` to avoid reading the records again.
    """
    from tqdm import tqdm

    started = time.perf_counter()
    output = Path(output or config.output)
    records, failures, recipe = loaded or study_records(config, log)
    record_im = np.array([record_intensity(r.acceleration, r.dt, config) for r in records])
    if np.any(record_im <= 0):
        bad = records[int(np.argmin(record_im))].id
        raise PipelineError(f"record {bad}: intensity measure is zero; it cannot be scaled")
    scale_factors = config.levels_si[None, :] / record_im[:, None]
    stiffness = np.array([[soil_block_stiffness(soil, block) for block in config.blocks] for soil in config.soils])

    store = CheckpointStore(output / ".checkpoints")
    for stale in list(output.glob(".*.part")) + list(store.folder.glob(".*.part")):
        stale.unlink(missing_ok=True)  # left by a killed run; the finished files are complete
    all_cells = [cells_for_record(record, config, recipe) for record in records]
    n_levels = len(config.levels)
    tasks = []
    for index, (record, cells) in enumerate(zip(records, all_cells)):
        missing = [c for c in cells if not store.has(c.key)]
        if missing:
            jobs = [(c.key, c.model, config.blocks[c.block_index],
                     None if c.soil_index is None else stiffness[c.soil_index, c.block_index],
                     None if c.soil_index is None else config.soils[c.soil_index].damping_ratio)
                    for c in missing]
            tasks.append((index, jobs))
    n_cells = sum(len(c) for c in all_cells)
    n_missing = sum(len(jobs) for _, jobs in tasks)
    runs_total = n_missing * n_levels
    log(f"study '{config.name}': {len(records)} records x {n_levels} levels x {len(config.soils)} soils x "
        f"{len(config.blocks)} blocks x {len(config.models)} models; {n_cells - n_missing} of {n_cells} "
        f"cells from checkpoints, {runs_total} runs to do")

    if tasks:
        _warm_up(config.models)
        submit, completed, shutdown = _executor(workers, scheduler, dask_workers)
        try:
            futures = {}
            for index, jobs in tasks:
                record = records[index]
                future = submit(record.acceleration, record.dt, scale_factors[index], jobs,
                                solver_options(config), config.tail)
                futures[future] = jobs
            with tqdm(total=runs_total, unit="run", desc="study", disable=not progress, smoothing=0.1) as bar:
                for future in completed(list(futures)):
                    for key, summary in future.result().items():
                        store.save(key, summary)
                    bar.update(len(futures[future]) * n_levels)
        finally:
            shutdown()

    summaries = new_summaries((len(records), n_levels, len(config.soils), len(config.blocks), len(config.models)))
    for r, cells in enumerate(all_cells):
        for cell in cells:
            model_index = config.models.index(cell.model)
            result = store.load(cell.key)
            if cell.soil_index is None:
                summaries[r, :, :, cell.block_index, model_index] = result[:, None]
            else:
                summaries[r, :, cell.soil_index, cell.block_index, model_index] = result
    provenance = {"processing": recipe.as_dict(),
                  "processing_steps": {r.id: list(r.trace.stats.get("processing", [])) for r in records}}
    dataset = build_cube(config, records, record_im, scale_factors, summaries, stiffness, provenance)
    write_netcdf(dataset, output / "cube.nc")
    elapsed = time.perf_counter() - started
    statistics = {"runs_computed": runs_total, "cells_reused": n_cells - n_missing, "cells": n_cells,
                  "seconds": elapsed, "failures": [str(f) for f in failures]}
    return dataset, statistics
