"""Chaos (issue 13): ``kill -9`` of the study process or of one of its pool workers at random points
of a small study, ten times, then one undisturbed run. The cube must be identical to a clean run's,
no worker may outlive its killed parent, and no ``.part`` file may be left behind."""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import xarray as xr

from pipeline.config import load_study
from pipeline.study import run_study
from tests.reliability_helpers import small_study_text, write_at2

ROOT = Path(__file__).resolve().parents[1]
KILLS = 10


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


def wait_until(predicate, timeout, step=0.02) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(step)
    return predicate()


@pytest.mark.slow
def test_random_kills_of_parent_and_workers_leave_an_identical_cube(tmp_path):
    rng = random.Random(13)
    write_at2(tmp_path / "records" / "pulse-a.AT2", amplitude_g=0.3, npts=1000)
    write_at2(tmp_path / "records" / "pulse-b.AT2", amplitude_g=0.5, dt=0.005, npts=1600)
    study = tmp_path / "chaos.toml"
    study.write_text(small_study_text(tmp_path / "records", levels=[0.3, 1.0]))
    reference, _ = run_study(load_study(study), output=tmp_path / "reference", workers=1, progress=False,
                             log=lambda message: None, warn=lambda message: None)

    output = tmp_path / "out"
    command = [sys.executable, "-m", "pipeline", "run", str(study), "--output", str(output), "--no-progress"]
    environment = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONFAULTHANDLER": "1"}
    outcomes = []
    for attempt in range(KILLS):
        # forget some finished cells so that every attempt has work left to interrupt
        for checkpoint in (output / ".checkpoints").glob("*.ckpt"):
            if rng.random() < 0.6:
                checkpoint.unlink()
        process = subprocess.Popen(command, cwd=ROOT, env=environment, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.PIPE, text=True)
        target = "worker" if attempt % 2 else "parent"
        during_work = target == "worker" or rng.random() < 0.6  # else: at a random point of start-up
        seen_children: set[int] = set()
        if during_work:
            # the workers seen when they appear count too: a short run's pool may be gone after the random pause
            wait_until(lambda: bool(seen_children.update(children(process.pid)) or seen_children)
                       or process.poll() is not None, timeout=90)
            time.sleep(rng.uniform(0.0, 0.2))
        else:
            deadline = time.monotonic() + rng.uniform(0.2, 3.0)
            while time.monotonic() < deadline and process.poll() is None:
                time.sleep(0.02)
        seen_children |= children(process.pid)
        if target == "worker":
            running = children(process.pid)  # a worker seen earlier may have finished
            if running and process.poll() is None:
                os.kill(rng.choice(sorted(running)), signal.SIGKILL)
                outcomes.append("worker killed")
            try:
                _, stderr = process.communicate(timeout=120)
            except subprocess.TimeoutExpired:  # a hang: dump every thread's stack (faulthandler) for the report
                process.send_signal(signal.SIGABRT)
                _, stderr = process.communicate(timeout=30)
                pytest.fail(f"run hung after a worker was killed; threads:\n{stderr[-8000:]}")
            assert process.returncode == 0, stderr  # the lost cells were retried in a fresh pool
            assert "Traceback" not in stderr
        else:
            if process.poll() is None:
                process.kill()
                outcomes.append(f"parent killed with {len(seen_children)} workers")
            process.wait()
            process.stderr.close()
            assert wait_until(lambda: not any(alive(pid) for pid in seen_children), timeout=10), \
                f"orphan workers after kill -9 of the parent: {[p for p in seen_children if alive(p)]}"

    final = subprocess.run(command, cwd=ROOT, env=environment, capture_output=True, text=True, timeout=180)
    assert final.returncode == 0, final.stderr
    assert "Traceback" not in final.stderr
    with xr.open_dataset(output / "cube.nc") as cube:
        assert cube.identical(reference)
    assert not list(output.rglob("*.part"))
    assert sum("killed" in outcome for outcome in outcomes) >= KILLS // 2, outcomes
    assert sum(outcome.startswith("parent killed with") and not outcome.endswith(" 0 workers")
               for outcome in outcomes) >= 1, outcomes  # at least one orphan check had workers to check
