"""A process that forks ``rockfrag`` runs for the chaos test (tests/test_reliability_chaos.py).

Each ``python -m rockfrag run`` of the chaos study spent about 3 of its 4 s importing (numpy, scipy, obspy's
filters, xarray) and loading the compiled kernels: eleven of them were most of the test's minute. This process
pays that once. It computes the reference cube in-process (which imports and loads everything a run needs),
then forks each run on request: the child is a real ``rockfrag run`` process (its own pool of workers, its own
lock and checkpoints) that the test can ``kill -9``, started in milliseconds. It never forks with a second thread
alive (checked), so the child holds no lock another thread took.

Protocol: one JSON object per line on stdin, one JSON answer per line on stdout.

- ``{"reference": STUDY, "output": DIR}``: run STUDY in this process (``run_study``, one worker) into DIR;
  answers ``{"ready": true}``.
- ``{"run": [ARGS...], "stderr": PATH}``: fork ``rockfrag ARGS`` (stdout to /dev/null, stderr to PATH); answers
  ``{"pid": PID}``.
- ``{"wait": PID}``: reap that child; answers ``{"status": CODE}`` (its exit code, or minus the killing signal).

Run as ``python -m tests.chaos_zygote`` from the repository root; it exits at the end of stdin.
"""

from __future__ import annotations

import json
import os
import sys
import threading


def _answer(message: dict) -> None:
    sys.stdout.write(json.dumps(message) + "\n")
    sys.stdout.flush()


def _child(main, arguments: list[str], stderr_path: str) -> None:
    """In the forked child: ``main(ARGS)`` (rockfrag's) with stdout to /dev/null and stderr to ``stderr_path``; never
    returns."""
    status = 70
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
        os.dup2(os.open(stderr_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644), 2)
        os.dup2(os.open(os.devnull, os.O_RDONLY), 0)  # the commands are the parent's, not the run's
        status = main(arguments)
    except SystemExit as stop:
        status = 0 if stop.code is None else stop.code if isinstance(stop.code, int) else 1
    except BaseException:  # noqa: BLE001 - what `python -m rockfrag` would print before dying
        import traceback

        traceback.print_exc()
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)


def serve() -> None:
    """Answer the commands on stdin until it ends."""
    import tqdm

    from rockfrag.cli import main  # once, here: every child starts with it imported

    tqdm.tqdm.monitor_interval = 0  # no monitor thread: this process forks
    for line in sys.stdin:
        command = json.loads(line)
        if "reference" in command:
            from rockfrag.config import load_study
            from rockfrag.study import run_study

            run_study(load_study(command["reference"]), output=command["output"], workers=1, progress=False,
                      log=lambda message: None, warn=lambda message: None)
            _answer({"ready": True})
        elif "run" in command:
            alive = [thread.name for thread in threading.enumerate() if thread is not threading.main_thread()]
            if alive:
                raise RuntimeError(f"chaos zygote: will not fork beside threads {alive}")
            sys.stdout.flush()
            sys.stderr.flush()
            pid = os.fork()
            if pid == 0:
                _child(main, command["run"], command["stderr"])
            _answer({"pid": pid})
        elif "wait" in command:
            _, status = os.waitpid(command["wait"], 0)
            _answer({"status": os.waitstatus_to_exitcode(status)})
        else:
            raise ValueError(f"chaos zygote: unknown command {command}")


if __name__ == "__main__":
    serve()
