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

Reliability: checkpoints verify themselves (pipeline.checkpoints; a damaged one is quarantined and
recomputed), the output folder is locked for the run (pipeline.locking), pool workers die with the
study process (parent-death signal), cells of a worker that was killed are retried once in a fresh
pool and then reported, and a record that cannot be processed or scaled is skipped with its reason.
"""

from __future__ import annotations

import ctypes
import hashlib
import json
import os
import signal
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from pipeline import __version__
from pipeline.cube import build_cube, write_netcdf
from pipeline.checkpoints import CheckpointStore
from pipeline.errors import PipelineError, RecordError
from pipeline.locking import output_lock
from pipeline.measures import MEASURES
from pipeline.models import DEFAULT_ATOL, DEFAULT_RTOL, get_model, simulate_batch
from pipeline.models.fields import SUMMARY_DTYPE, new_summaries
from pipeline.processing import load_recipe, process_records
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


def _warm_up(models):
    """Compile (or load from the on-disk cache) the kernels once before starting workers."""
    from pipeline.blocks import Block

    block = Block(name="warm-up", R=1.0, alpha=0.2, mass=1.0)
    for model in models:
        simulate_batch(model, np.zeros(3), 0.01, [1.0], [(block, 1e4, 0.05)])


PR_SET_PDEATHSIG = 1  # linux/prctl.h


def _die_with_parent(parent_pid):
    """Worker initializer: end this worker when the study process dies, even by ``kill -9``.

    Linux delivers SIGKILL on the parent's death (prctl PR_SET_PDEATHSIG); a watchdog thread that
    polls the parent pid covers other systems and the window before prctl took effect.
    """
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):  # not Linux: the watchdog alone
        pass
    if os.getppid() != parent_pid:
        os._exit(1)

    def watch():
        while os.getppid() == parent_pid:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, name="rockfrag-parent-watchdog", daemon=True).start()


def worker_pool(max_workers) -> ProcessPoolExecutor:
    """A process pool whose workers die with this process (use it for every local pool)."""
    return ProcessPoolExecutor(max_workers=max_workers, initializer=_die_with_parent, initargs=(os.getpid(),))


POOL_EXIT_SECONDS = 10.0
"""How long a finished pool's workers may take to exit before they are killed."""


def shutdown_pool(pool, wait=True, timeout=POOL_EXIT_SECONDS):
    """Shut a process pool down; with ``wait``, its workers are gone when this returns.

    ``ProcessPoolExecutor.shutdown(wait=True)`` waits forever if a worker is killed while it holds
    the task queue's lock (the others then never read their exit sentinel); here stragglers are
    killed after ``timeout`` seconds instead.
    """
    processes = list((getattr(pool, "_processes", None) or {}).values())  # private, only to bound the wait
    pool.shutdown(wait=False, cancel_futures=True)
    if not wait:
        return
    deadline = time.monotonic() + timeout
    for process in processes:
        process.join(max(0.0, deadline - time.monotonic()))
    for process in processes:
        if process.is_alive():
            process.kill()
            process.join(1.0)


def _is_lost_worker(error) -> bool:
    """A worker process died under the task (OOM killer, kill -9): the task may be retried."""
    return isinstance(error, BrokenProcessPool) or type(error).__name__ == "KilledWorker"


def _executor(workers, scheduler, dask_workers):
    """(submit, as_completed, shutdown(finished: bool)) for the chosen executor."""
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
            # local dask workers already exit when this process dies (distributed's parent-alive pipe)

        def shutdown(finished):
            client.close()
            if cluster is not None:
                cluster.close()

        return (lambda *a: client.submit(compute_cells, *a, pure=False), dask_completed, shutdown)
    if workers == 1:
        class InProcess:  # computed when asked for, so errors surface where pool errors do
            def __init__(self, arguments):
                self._arguments = arguments

            def result(self):
                return compute_cells(*self._arguments)

        return (lambda *a: InProcess(a), lambda futures: list(futures), lambda finished: None)
    pool = worker_pool(workers or os.cpu_count())
    return (lambda *a: pool.submit(compute_cells, *a), as_completed,
            lambda finished: shutdown_pool(pool, wait=finished))


def run_tasks(tasks, submit_arguments, make_executor, on_result, attempts=2, describe=str):
    """Run ``tasks`` on executors from ``make_executor()``; returns the tasks lost ``attempts`` times.

    A task whose worker process died (BrokenProcessPool, dask KilledWorker) is run again in a fresh
    executor; results already received are kept (``on_result(task, result)`` saw them). Any other
    exception propagates, with a note naming the task (``describe(task)``).
    """
    pending = list(tasks)
    for _ in range(attempts):
        if not pending:
            break
        submit, completed, shutdown = make_executor()
        lost, finished = [], False
        try:
            futures = {}
            for task in pending:
                try:
                    futures[submit(*submit_arguments(task))] = task
                except Exception as error:  # the pool broke while tasks were being submitted
                    if not _is_lost_worker(error):
                        raise
                    lost.append(task)
            for future in completed(list(futures)):
                try:
                    result = future.result()
                except Exception as error:
                    if not _is_lost_worker(error):
                        error.add_note(describe(futures[future]))
                        raise
                    lost.append(futures[future])
                    continue
                on_result(futures[future], result)
            finished = True
        finally:
            # a broken pool is joined before the next one forks, so no thread of it is caught mid-way
            shutdown(bool(lost) or finished)
        pending = lost
    return pending


def study_records(config, log=print):
    """The study's records, processed with its recipe: (records, failures, recipe).

    Every stage that needs the study's records (study, applicability, report) takes them from here,
    so ``rockfrag fragility`` reads and processes them once. A record that cannot be read or
    processed is skipped and reported (``log``); the others go on.
    """
    recipe = load_recipe(config.processing or None)
    raw_records, failures = load_records(list(config.record_sets), units=config.record_units or None,
                                         dt=config.record_dt)
    processed, processing_failures = process_records(raw_records, recipe)
    failures = [*failures, *processing_failures]
    for failure in failures:
        log(f"rockfrag: skipped {failure}")
    if not processed:
        raise PipelineError("no record could be read; nothing to run")
    return processed, failures, recipe


def _check_workers(workers, dask_workers):
    for option, value in (("--workers", dask_workers), ("workers", workers)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value <= 0):
            raise PipelineError(f"{option} {value!r}: expected a whole number of worker processes >= 1")


def _scalable(records, record_im, log):
    """Split records into those with a positive finite intensity and RecordErrors for the rest."""
    keep, failures = [], []
    for index, (record, im) in enumerate(zip(records, record_im)):
        if np.isfinite(im) and im > 0:
            keep.append(index)
        else:
            failure = RecordError(record.metadata.get("file") or record.id,
                                  f"record {record.id}: intensity measure is {im:g}; it cannot be scaled")
            log(f"rockfrag: skipped {failure}")
            failures.append(failure)
    return keep, failures


def _to_stderr(message):
    print(message, file=sys.stderr)


def run_study(config, *, output=None, workers=None, scheduler=None, dask_workers=None,
              progress=True, log=print, loaded=None, wait=False, warn=_to_stderr):
    """Run (or resume) a study and write ``cube.nc``; returns (dataset, statistics dict).

    ``loaded`` may pass the result of ``study_records`` to avoid reading the records again.
    ``log`` receives progress lines, ``warn`` one line per skipped record or damaged checkpoint.
    The output folder is locked for the run (a second run stops, or waits with ``wait=True``).
    """
    _check_workers(workers, dask_workers)
    output = Path(output or config.output)
    with output_lock(output, wait=wait):
        return _run_locked(config, output, workers, scheduler, dask_workers, progress, log, warn, loaded)


def _run_locked(config, output, workers, scheduler, dask_workers, progress, log, warn, loaded):
    from tqdm import tqdm

    started = time.perf_counter()
    records, failures, recipe = loaded or study_records(config, warn)
    failures = list(failures)
    record_im = np.array([record_intensity(r.acceleration, r.dt, config) for r in records])
    keep, unscalable = _scalable(records, record_im, warn)
    failures += unscalable
    if not keep:
        raise PipelineError("no record has a positive intensity measure; nothing to run")
    records, record_im = [records[i] for i in keep], record_im[keep]
    scale_factors = config.levels_si[None, :] / record_im[:, None]
    stiffness = np.array([[soil_block_stiffness(soil, block) for block in config.blocks] for soil in config.soils])

    n_levels = len(config.levels)
    store = CheckpointStore(output / ".checkpoints", log=warn)
    all_cells = [cells_for_record(record, config, recipe) for record in records]
    results = store.load_verified([c.key for cells in all_cells for c in cells], (n_levels,), SUMMARY_DTYPE)
    tasks = []
    for index, cells in enumerate(all_cells):
        missing = [c for c in cells if c.key not in results]
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

    lost = []
    if tasks:
        _warm_up(config.models)
        with tqdm(total=runs_total, unit="run", desc="study", disable=not progress, smoothing=0.1) as bar:
            def keep_result(task, computed):
                for key, summary in computed.items():
                    store.save(key, summary)
                    results[key] = summary
                bar.update(len(task[1]) * n_levels)

            lost = run_tasks(tasks,
                             lambda task: (records[task[0]].acceleration, records[task[0]].dt,
                                           scale_factors[task[0]], task[1], solver_options(config),
                                           config.tail),
                             lambda: _executor(workers, scheduler, dask_workers), keep_result,
                             describe=lambda task: f"record {records[task[0]].id}")
    if lost:
        lost_indices = {index for index, _ in lost}
        for index in sorted(lost_indices):
            record = records[index]
            failure = RecordError(record.metadata.get("file") or record.id,
                                  f"record {record.id}: a worker process died twice while computing its cells "
                                  "(out of memory?); finished cells are kept, rerun to retry")
            warn(f"rockfrag: skipped {failure}")
            failures.append(failure)
        kept = [i for i in range(len(records)) if i not in lost_indices]
        if not kept:
            raise PipelineError("every record's computation was lost (worker processes killed); "
                                "finished cells are kept, rerun to continue")
        records, record_im, scale_factors = [records[i] for i in kept], record_im[kept], scale_factors[kept]
        all_cells = [all_cells[i] for i in kept]

    summaries = new_summaries((len(records), n_levels, len(config.soils), len(config.blocks), len(config.models)))
    for r, cells in enumerate(all_cells):
        for cell in cells:
            model_index = config.models.index(cell.model)
            result = results[cell.key]
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
                  "seconds": elapsed, "failures": [str(f) for f in failures],
                  "checkpoints_quarantined": [str(p) for p in store.quarantined]}
    return dataset, statistics
