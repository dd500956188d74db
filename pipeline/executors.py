"""rockfrag.executors - where a stage's independent tasks run: in process, on local worker processes or on dask.

In : a pure task function (picklable, module level), one tuple of arguments per task, and the choice of
     executor: ``workers`` (1: in this process; n: a local process pool of n workers; None: one per
     core) or dask.distributed (``scheduler``: the address of a running cluster; ``dask_workers``: a
     LocalCluster of that many single-threaded worker processes started for the run).
Out: each task's result, handed to a callback as it arrives (``run_tasks``), and the tasks whose worker
     process died twice (killed by the OOM killer or ``kill -9``), which the caller reports.

Worker hygiene: local pool workers die with the process that started them, even when it is killed by
``kill -9`` (``worker_pool``); a pool is shut down within a bounded time even if a worker hangs
(``shutdown_pool``); a task whose worker died is retried once in a fresh executor and then, alone, in
a one-worker pool, so that only the task that kills its own worker is lost, not its neighbours.
The study (rockfrag.study) and the applicability sweep (rockfrag.applicability) run their tasks here;
every executor runs the same pure function, so results do not depend on the executor.
"""

from __future__ import annotations

import ctypes
import os
import signal
import threading
import time
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from typing import Any, NamedTuple

from rockfrag.errors import PipelineError

PR_SET_PDEATHSIG = 1  # linux/prctl.h

POOL_EXIT_SECONDS = 10.0
"""How long a finished pool's workers may take to exit before they are killed [s]."""


class Executor(NamedTuple):
    """One round of tasks on one executor: how to submit, collect and shut down.

    Attributes
    ----------
    submit : callable
        ``submit(*arguments)`` starts one task and returns its future (anything with ``.result()``).
    completed : callable
        ``completed(futures)`` yields the futures as they finish.
    shutdown : callable
        ``shutdown(finished)`` releases the executor; ``finished`` is True when every task was
        collected or a worker was lost (then the workers are waited for, so that none is caught
        mid-way when the next executor forks), False when an error interrupts the round.
    """

    submit: Callable[..., Any]
    completed: Callable[[list], Iterable]
    shutdown: Callable[[bool], None]


def die_with_parent(parent_pid: int) -> None:
    """Worker initializer: end this worker when the study process dies, even by ``kill -9``.

    Linux delivers SIGKILL on the parent's death (prctl PR_SET_PDEATHSIG); a watchdog thread that
    polls the parent pid covers other systems and the window before prctl took effect.

    Parameters
    ----------
    parent_pid : int
        Process id of the process that starts the pool.
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


def worker_pool(max_workers: int | None) -> ProcessPoolExecutor:
    """A process pool whose workers die with this process (use it for every local pool).

    Parameters
    ----------
    max_workers : int or None
        Number of worker processes (None: one per core).

    Returns
    -------
    concurrent.futures.ProcessPoolExecutor
    """
    return ProcessPoolExecutor(max_workers=max_workers, initializer=die_with_parent, initargs=(os.getpid(),))


DASK_CONNECT_SECONDS = 10.0
"""How long ``--scheduler tcp://...`` waits for the scheduler [s]; ``ROCKFRAG_DASK_CONNECT_TIMEOUT`` overrides."""


def connect_timeout() -> float:
    """Seconds to wait for a dask scheduler: ``ROCKFRAG_DASK_CONNECT_TIMEOUT`` if set (> 0), else 10 s."""
    value = os.environ.get("ROCKFRAG_DASK_CONNECT_TIMEOUT", "")
    try:
        seconds = float(value)
    except ValueError:
        return DASK_CONNECT_SECONDS
    return seconds if seconds > 0 else DASK_CONNECT_SECONDS


def shutdown_pool(pool: ProcessPoolExecutor, wait: bool = True, timeout: float = POOL_EXIT_SECONDS) -> None:
    """Shut a process pool down; with ``wait``, its workers are gone when this returns.

    ``ProcessPoolExecutor.shutdown(wait=True)`` waits forever if a worker is killed while it holds
    the task queue's lock (the others then never read their exit sentinel); here stragglers are
    killed after ``timeout`` seconds instead.

    Parameters
    ----------
    pool : concurrent.futures.ProcessPoolExecutor
        The pool; its pending tasks are cancelled.
    wait : bool
        Wait for the workers to exit (False: return at once).
    timeout : float
        Time [s] the workers have to exit before they are killed.
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


def is_lost_worker(error: BaseException) -> bool:
    """True when a worker process died under the task (OOM killer, kill -9): the task may be retried."""
    return isinstance(error, BrokenProcessPool) or type(error).__name__ == "KilledWorker"


def check_workers(workers: int | None, dask_workers: int | None = None) -> None:
    """Raise a PipelineError naming the option unless each worker count given is a whole number >= 1.

    Parameters
    ----------
    workers : int or None
        Local worker processes (the ``workers`` argument of the stage).
    dask_workers : int or None
        Workers of a local dask cluster (``--workers`` with ``--scheduler local``).
    """
    for option, value in (("--workers", dask_workers), ("workers", workers)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value <= 0):
            raise PipelineError(f"{option} {value!r}: expected a whole number of worker processes >= 1")


class _InProcess:
    """A task computed when its result is asked for, so that its errors surface where pool errors do."""

    def __init__(self, function, arguments):
        self._function = function
        self._arguments = arguments

    def result(self):
        return self._function(*self._arguments)


def in_process_executor(function: Callable[..., Any]) -> Executor:
    """Run ``function`` in this process, one task at a time, in the order submitted."""
    return Executor(lambda *a: _InProcess(function, a), lambda futures: list(futures), lambda finished: None)


def pool_executor(function: Callable[..., Any], n_workers: int) -> Executor:
    """Run ``function`` on a fresh local pool of ``n_workers`` processes that die with this one."""
    pool = worker_pool(n_workers)
    return Executor(lambda *a: pool.submit(function, *a), as_completed,
                    lambda finished: shutdown_pool(pool, wait=finished))


def dask_executor(function: Callable[..., Any], scheduler: str | None = None,
                  dask_workers: int | None = None) -> Executor:
    """Run ``function`` on dask.distributed: the cluster at ``scheduler``, else a LocalCluster.

    Parameters
    ----------
    function : callable
        The pure task function (submitted with ``pure=False``: every task runs).
    scheduler : str or None
        Address of a running scheduler, e.g. ``tcp://host:8786``.
    dask_workers : int or None
        Worker processes of the LocalCluster started when no scheduler is given (one thread each).

    Returns
    -------
    Executor
        Its shutdown closes the client and the LocalCluster.
    """
    from dask.distributed import Client, LocalCluster  # optional dependency, only for dask runs
    from dask.distributed import as_completed as dask_completed

    cluster = None
    if scheduler:
        try:
            client = Client(scheduler, timeout=f"{connect_timeout():g}s")
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

    return Executor(lambda *a: client.submit(function, *a, pure=False), dask_completed, shutdown)


def check_scheduler(scheduler: str | None) -> None:
    """Connect to the dask scheduler at ``scheduler`` once and let go: the address is checked before the run.

    A run whose cells are all checkpointed never starts an executor, so without this check an address that
    answers nothing would pass unnoticed (exit 0); with it, every run with ``--scheduler ADDRESS`` has
    reached its cluster.

    Parameters
    ----------
    scheduler : str or None
        The address of a running scheduler (``tcp://host:8786``); None and ``"local"`` (a cluster this process
        starts itself) need no check.

    Raises
    ------
    PipelineError
        No scheduler answered at ``scheduler`` within ``connect_timeout()`` seconds.
    """
    if not scheduler or scheduler == "local":
        return
    from dask.distributed import Client  # optional dependency, only for dask runs

    try:
        client = Client(scheduler, timeout=f"{connect_timeout():g}s")
    except (OSError, TimeoutError, ValueError) as error:
        raise PipelineError(f"cannot connect to the dask scheduler at {scheduler!r} ({error}); "
                            "expected the address of a running scheduler, e.g. tcp://host:8786") from None
    client.close()


def make_executor(function: Callable[..., Any], workers: int | None = None, scheduler: str | None = None,
                  dask_workers: int | None = None) -> Executor:
    """The executor a stage's options choose.

    That is dask if ``scheduler`` or ``dask_workers`` is given, else this process (``workers`` 1) or a
    local pool of ``workers`` processes (None: one per core).
    """
    if scheduler or dask_workers:
        return dask_executor(function, scheduler, dask_workers)
    if workers == 1:
        return in_process_executor(function)
    return pool_executor(function, workers or os.cpu_count())


def run_tasks(tasks: Sequence, submit_arguments: Callable[[Any], tuple], make_executor: Callable[[], Executor],
              on_result: Callable[[Any, Any], None], attempts: int = 2, describe: Callable[[Any], str] = str,
              isolate: Callable[[], Executor] | None = None) -> list:
    """Run ``tasks`` on executors from ``make_executor()``; returns the tasks lost ``attempts`` times.

    A task whose worker process died (BrokenProcessPool, dask KilledWorker) is run again in a fresh
    executor; results already received are kept (``on_result(task, result)`` saw them). A broken pool
    fails every task it still held, so the tasks lost in the last attempt are run once more one by one
    on ``isolate()`` executors (if given): only a task that kills its own worker is returned. Any other
    exception propagates, with a note naming the task (``describe(task)``).

    Parameters
    ----------
    tasks : sequence
        The tasks, in any form the callbacks understand.
    submit_arguments : callable
        ``submit_arguments(task)``: the arguments of the executor's ``submit`` for one task.
    make_executor : callable
        Returns a fresh ``Executor`` for each attempt.
    on_result : callable
        Called with ``(task, result)`` as each result arrives.
    attempts : int
        Rounds on fresh executors before a task counts as lost.
    describe : callable
        ``describe(task)``: a note naming the task on an error.
    isolate : callable or None
        Returns a one-worker ``Executor`` for the last retry, one task at a time.

    Returns
    -------
    list
        The tasks whose worker died in every attempt.
    """
    pending = list(tasks)
    for _ in range(attempts):
        if not pending:
            break
        pending = _run_round(pending, submit_arguments, make_executor(), on_result, describe)
    if pending and isolate is not None and len(pending) > 1:
        pending = [task for task in pending
                   for task in _run_round([task], submit_arguments, isolate(), on_result, describe)]
    return pending


def _run_round(pending, submit_arguments, executor, on_result, describe) -> list:
    """Submit ``pending`` to one executor; the tasks lost with a dead worker."""
    submit, completed, shutdown = executor
    lost, finished = [], False
    try:
        futures: dict[Any, Any] = {}  # future (pool, dask or in-process) -> task
        for task in pending:
            try:
                futures[submit(*submit_arguments(task))] = task
            except Exception as error:  # the pool broke while tasks were being submitted
                if not is_lost_worker(error):
                    raise
                lost.append(task)
        for future in completed(list(futures)):
            try:
                result = future.result()
            except Exception as error:
                if not is_lost_worker(error):
                    error.add_note(describe(futures[future]))
                    raise
                lost.append(futures[future])
                continue
            on_result(futures[future], result)
        finished = True
    finally:
        # a broken pool is joined before the next one forks, so no thread of it is caught mid-way
        shutdown(bool(lost) or finished)
    return lost
