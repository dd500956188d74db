"""Chaos (issue 13): ``kill -9`` of the study process or of one of its pool workers at random points
of a small study, ten times, then one undisturbed run. The cube must be identical to a clean run's,
no worker may outlive its killed parent, nothing may hold the output lock 10 s after a run ended, and no
``.part`` file may be left behind.

The ten interrupted runs are forked from one process that has imported everything (tests/chaos_zygote.py):
started as ``python -m rockfrag``, each spent about 3 of its 4 s importing, and a kill "at a random point"
mostly fell in the imports. The last run is a fresh ``python -m rockfrag`` process."""

from __future__ import annotations

import fcntl
import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import xarray as xr

from rockfrag.locking import LOCK_NAME
from tests.reliability_helpers import small_study_text, write_at2

ROOT = Path(__file__).resolve().parents[1]
KILLS = 10


def run_environment() -> dict:
    """The environment of the processes that run the study: this checkout's pipeline, stacks dumped on SIGABRT."""
    return {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONFAULTHANDLER": "1"}


def children(pid) -> set[int]:
    """Live child processes of ``pid`` (from /proc)."""
    found = set()
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if int(fields[1]) == pid and fields[0] != "Z":
            found.add(int(entry.name))
    return found


def alive(pid) -> bool:
    try:
        return (Path(f"/proc/{pid}") / "stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


def lock_is_free(folder: Path) -> bool:
    """Whether no process holds ``folder``'s output lock. Pool workers inherit the run's locked descriptor (fork
    copies it): a worker of a killed run that was not seen yet (forked just before the kill) holds the lock until
    it notices its parent is gone and exits, milliseconds later; a run started before then finds the folder in
    use."""
    try:
        descriptor = os.open(folder / LOCK_NAME, os.O_RDWR)
    except FileNotFoundError:
        return True
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    finally:
        os.close(descriptor)  # (releases the lock taken just now)
    return True


def wait_until(predicate, timeout, step=0.02) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(step)
    return predicate()


class Zygote:
    """The forking process of tests/chaos_zygote.py: starts ``rockfrag`` runs as its children, reaps them."""

    def __init__(self, folder: Path):
        self.process = subprocess.Popen([sys.executable, "-m", "tests.chaos_zygote"], cwd=ROOT, env=run_environment(),
                                        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.folder = folder

    def ask(self, **command) -> dict:
        self.process.stdin.write(json.dumps(command) + "\n")
        self.process.stdin.flush()
        answer = self.process.stdout.readline()
        assert answer, f"the chaos zygote died (exit {self.process.wait()})"
        return json.loads(answer)

    def start(self, arguments: list[str], attempt: int) -> tuple[int, Path]:
        stderr = self.folder / f"attempt-{attempt}.stderr"
        return self.ask(run=arguments, stderr=str(stderr))["pid"], stderr

    def close(self) -> None:
        self.process.stdin.close()
        self.process.wait(timeout=30)


@pytest.mark.slow
def test_random_kills_of_parent_and_workers_leave_an_identical_cube(tmp_path):
    """Ten runs forked from one warm process (tests/chaos_zygote.py), so that the kills fall in the runs and not
    in Python's imports, then a last undisturbed run as a fresh ``python -m rockfrag`` process."""
    rng = random.Random(13)
    write_at2(tmp_path / "records" / "pulse-a.AT2", amplitude_g=0.3, npts=2500)
    write_at2(tmp_path / "records" / "pulse-b.AT2", amplitude_g=0.5, dt=0.005, npts=4000)
    study = tmp_path / "chaos.toml"
    study.write_text(small_study_text(tmp_path / "records", levels=[0.3, 1.0]))
    output = tmp_path / "out"
    arguments = ["run", str(study), "--output", str(output), "--no-progress"]
    zygote = Zygote(tmp_path)
    try:
        assert zygote.ask(reference=str(study), output=str(tmp_path / "reference")) == {"ready": True}
        outcomes = [_attempt(zygote, arguments, output, attempt, rng) for attempt in range(KILLS)]
    finally:
        zygote.close()

    final = subprocess.run([sys.executable, "-m", "rockfrag", *arguments], cwd=ROOT, env=run_environment(),
                           capture_output=True, text=True, timeout=180)
    assert final.returncode == 0, final.stderr
    assert "Traceback" not in final.stderr
    with xr.open_dataset(output / "cube.nc") as cube, xr.open_dataset(tmp_path / "reference" / "cube.nc") as reference:
        assert cube.identical(reference)
    assert not list(output.rglob("*.part"))
    assert sum("killed" in outcome for outcome in outcomes) >= KILLS // 2, outcomes
    assert sum(outcome.startswith("parent killed with") and not outcome.endswith(" 0 workers")
               for outcome in outcomes) >= 1, outcomes  # at least one orphan check had workers to check


def _attempt(zygote: Zygote, arguments: list[str], output: Path, attempt: int, rng: random.Random) -> str:
    """One run of the study, its parent or one of its workers killed at a random point; what happened."""
    # forget some finished cells so that every attempt has work left to interrupt
    for checkpoint in (output / ".checkpoints").glob("*.ckpt"):
        if rng.random() < 0.6:
            checkpoint.unlink()
    pid, stderr_path = zygote.start(arguments, attempt)
    target = "worker" if attempt % 2 else "parent"
    during_work = target == "worker" or rng.random() < 0.6  # else: at a random point of start-up
    seen_children: set[int] = set()
    if during_work:
        # the workers seen when they appear count too: a short run's pool may be gone after the random pause
        wait_until(lambda: bool(seen_children.update(children(pid)) or seen_children) or not alive(pid),
                   timeout=90)
        time.sleep(rng.uniform(0.0, 0.1))
    else:  # reading the study and the records, before the pool starts (about 0.3 s)
        deadline = time.monotonic() + rng.uniform(0.0, 0.3)
        while time.monotonic() < deadline and alive(pid):
            time.sleep(0.005)
    seen_children |= children(pid)
    outcome = "finished before the kill"
    if target == "worker":
        running = children(pid)  # a worker seen earlier may have finished
        if running and alive(pid):
            os.kill(rng.choice(sorted(running)), signal.SIGKILL)
            outcome = "worker killed"
        if not wait_until(lambda: not alive(pid), timeout=120):  # a hang: every thread's stack (faulthandler)
            os.kill(pid, signal.SIGABRT)
            zygote.ask(wait=pid)
            pytest.fail(f"run hung after a worker was killed; threads:\n{stderr_path.read_text()[-8000:]}")
        status, stderr = zygote.ask(wait=pid)["status"], stderr_path.read_text()
        assert status == 0, stderr  # the lost cells were retried in a fresh pool
        assert "Traceback" not in stderr
    else:
        if alive(pid):
            os.kill(pid, signal.SIGKILL)
            outcome = f"parent killed with {len(seen_children)} workers"
        zygote.ask(wait=pid)
        assert wait_until(lambda: not any(alive(child) for child in seen_children), timeout=10), \
            f"orphan workers after kill -9 of the parent: {[p for p in seen_children if alive(p)]}"
    # every process of the run is gone, those never seen too: nothing holds the output folder
    assert wait_until(lambda: lock_is_free(output), timeout=10), f"{outcome}: the output lock is held 10 s later"
    return outcome
