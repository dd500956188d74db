"""Process hygiene (issue 13, rockfrag.executors): a task whose worker is killed is retried once in a
fresh pool, then reported alone while its neighbours finish; pool workers die with their parent; a pool
shuts down in bounded time; and the study keeps the records whose workers survived."""

from __future__ import annotations

import operator
import os
import signal
import subprocess
import sys
import textwrap
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import pytest

from rockfrag.config import load_study
from rockfrag.errors import PipelineError
from rockfrag.executors import Executor, check_workers, make_executor, run_tasks, shutdown_pool, worker_pool
from rockfrag.study import compute_cells, run_study
from tests.reliability_helpers import QUIET, small_study_text, write_at2, write_tiny_study

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def tiny_study(tmp_path_factory):
    """One short synthetic record, 2 levels, 2 soils, the 3 default blocks, Housner and SSI."""
    return write_tiny_study(tmp_path_factory.mktemp("tiny"))


def _kill_own_worker_once(marker, value):
    """Task for a pool: the first call kills its own worker process (as the OOM killer would)."""
    if value == "always" or not os.path.exists(marker):
        open(marker, "w").close()
        os.kill(os.getpid(), signal.SIGKILL)
    return value


def _pool_factory(marker):
    def make() -> Executor:
        pool = ProcessPoolExecutor(max_workers=1)
        return Executor(lambda value: pool.submit(_kill_own_worker_once, marker, value), as_completed,
                        lambda finished: pool.shutdown(wait=finished, cancel_futures=True))
    return make


def test_killed_worker_cells_are_retried_once_in_a_fresh_pool(tmp_path):
    received = []
    lost = run_tasks(["a", "b"], lambda task: (task,), _pool_factory(str(tmp_path / "marker")),
                     lambda task, result: received.append(result))
    assert lost == [] and sorted(received) == ["a", "b"]


def test_cells_lost_twice_are_reported_and_finished_ones_kept(tmp_path):
    received = []
    marker = str(tmp_path / "marker")
    lost = run_tasks(["always"], lambda task: (task,), _pool_factory(marker),
                     lambda task, result: received.append(result))
    assert lost == ["always"] and received == []


def test_workers_die_with_their_parent(tmp_path):
    """kill -9 of the study process takes its pool workers with it (no orphans at ~180 MB each)."""
    script = tmp_path / "parent.py"
    script.write_text(textwrap.dedent("""
        import os, sys, time
        from concurrent.futures import ProcessPoolExecutor
        from rockfrag.executors import die_with_parent

        def pid(_):
            time.sleep(0.2)
            return os.getpid()

        if __name__ == "__main__":
            pool = ProcessPoolExecutor(2, initializer=die_with_parent, initargs=(os.getpid(),))
            print(" ".join(map(str, sorted(set(pool.map(pid, range(4)))))), flush=True)
            time.sleep(60)
    """))
    parent = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True, cwd=ROOT,
                              env={**os.environ, "PYTHONPATH": str(ROOT)})
    workers = [int(p) for p in parent.stdout.readline().split()]
    assert workers and all(Path(f"/proc/{p}").exists() for p in workers)
    parent.kill()
    parent.wait()
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and any(_alive(p) for p in workers):
        time.sleep(0.05)
    orphans = [p for p in workers if _alive(p)]
    for pid in orphans:  # do not leave them behind when the test fails
        os.kill(pid, signal.SIGKILL)
    assert not orphans


def _alive(pid) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as handle:
            return handle.read().split(")")[-1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def test_run_study_rejects_nonpositive_workers(tiny_study, tmp_path):
    for workers, dask_workers in ((0, None), (-1, None), (None, 0), (None, -3)):
        with pytest.raises(PipelineError, match=">= 1"):
            run_study(load_study(tiny_study), output=tmp_path, workers=workers, dask_workers=dask_workers, **QUIET)


def _oom_on_fine_sampling(acceleration, dt, *args):
    """compute_cells, except that a worker given the 0.005 s record is killed (as by the OOM killer)."""
    if dt == 0.005:
        os.kill(os.getpid(), signal.SIGKILL)
    return compute_cells(acceleration, dt, *args)


def test_record_whose_worker_dies_twice_is_reported_and_the_rest_kept(tmp_path, monkeypatch):
    write_at2(tmp_path / "records" / "coarse.AT2", amplitude_g=0.3)
    write_at2(tmp_path / "records" / "fine.AT2", amplitude_g=0.3, dt=0.005, npts=800)
    study = tmp_path / "study.toml"
    study.write_text(small_study_text(tmp_path / "records", levels=[0.5], soils=["rock"]))
    monkeypatch.setattr("rockfrag.study.compute_cells", _oom_on_fine_sampling)
    warnings = []
    dataset, stats = run_study(load_study(study), output=tmp_path / "out", workers=2, progress=False,
                               log=lambda message: None, warn=warnings.append)
    assert list(dataset.record.values) == ["coarse"]
    assert len(stats["failures"]) == 1 and "fine.AT2" in stats["failures"][0]
    assert "worker process died twice" in stats["failures"][0]
    assert any("skipped" in w and "fine.AT2" in w for w in warnings)
    cells = [p for p in (tmp_path / "out" / ".checkpoints").glob("*.ckpt") if "capacity" not in p.name]
    assert len(cells) == 6  # coarse's cells (3 blocks x housner + ssi on rock) are kept


def _block_forever(_):
    time.sleep(3600)


def test_pool_shutdown_is_bounded_when_a_worker_never_exits():
    """A worker stuck forever (as when another was killed holding the queue lock) is killed, not awaited."""
    pool = worker_pool(1)
    pool.submit(_block_forever, 0)
    time.sleep(0.5)
    workers = list(pool._processes.values())
    started = time.monotonic()
    shutdown_pool(pool, wait=True, timeout=1.0)
    assert time.monotonic() - started < 5 and not any(p.is_alive() for p in workers)


def test_only_the_task_that_kills_its_worker_is_lost_not_its_neighbours(tmp_path):
    received = []
    make = _pool_factory(str(tmp_path / "marker"))
    lost = run_tasks(["always", "a", "b", "c"], lambda task: (task,), make,
                     lambda task, result: received.append(result), isolate=make)
    assert lost == ["always"] and sorted(received) == ["a", "b", "c"]


@pytest.mark.parametrize("options", [{"workers": 1}, {"workers": 2}, {"dask_workers": 1}],
                         ids=["in process", "process pool", "dask LocalCluster"])
def test_every_executor_gives_the_same_results(options):
    if "dask_workers" in options:
        pytest.importorskip("dask.distributed")
    received = {}
    lost = run_tasks([1, 2, 3], lambda task: (task, 10), lambda: make_executor(operator.mul, **options),
                     received.__setitem__)
    assert lost == [] and received == {1: 10, 2: 20, 3: 30}


def test_worker_counts_must_be_whole_numbers_of_at_least_one():
    check_workers(None, None)
    check_workers(3, 2)
    for workers, dask_workers, option in ((0, None, "workers"), (2.0, None, "workers"), (True, None, "workers"),
                                          (None, 0, "--workers")):
        with pytest.raises(PipelineError, match=f"^{option} .*>= 1"):
            check_workers(workers, dask_workers)
