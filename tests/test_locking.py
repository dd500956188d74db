"""The output folder is locked for a run (issue 13): a second run stops with one line or waits with
``--wait``, the other run's temporary files are left alone, stale ``.part`` files of a free folder are
removed, and the lock is reentrant within one process."""

from __future__ import annotations

import fcntl
import os
import subprocess
import sys
import threading
import time

import pytest

from rockfrag import cli, locking
from rockfrag.locking import LOCK_NAME, output_lock
from tests.reliability_helpers import assert_one_line_error, tiny_run_argv


def test_second_run_on_a_locked_folder_stops_with_one_line(tmp_path, capsys):
    output = tmp_path / "out"
    output.mkdir()
    with open(output / LOCK_NAME, "w") as handle:  # another run, alive (this process's pid), holds the folder
        fcntl.flock(handle, fcntl.LOCK_EX)
        handle.write(f"{os.getpid()}\n")
        handle.flush()
        (output / ".cube.nc.abc.part").write_text("being written by the other run")
        status = cli.main(tiny_run_argv(tmp_path, "--output", str(output)))
        captured = capsys.readouterr()
        assert status == cli.EXIT_USER_ERROR
        assert_one_line_error(captured.err, str(output), "in use by another rockfrag run", f"pid {os.getpid()}")
        assert (output / ".cube.nc.abc.part").exists()  # the other run's temporary file is untouched
    assert not (output / "cube.nc").exists()


def run_while_held(tmp_path, output, release, *options) -> tuple[int, float]:
    """``rockfrag run`` of the tiny study into ``output`` while another holder has its lock; ``release`` (called
    when the run ends, however) lets go of it. Returns the exit status and the run's wall time [s]."""
    started = time.monotonic()
    try:
        status = cli.main(tiny_run_argv(tmp_path, "--output", str(output), *options))
    finally:
        release()
    return status, time.monotonic() - started


def test_wait_lets_a_second_run_start_when_the_first_one_ends(tmp_path, capsys):
    output = tmp_path / "out"
    output.mkdir()
    handle = open(output / LOCK_NAME, "w")  # another run (alive: this process's pid) holds the folder, ends 1 s later
    fcntl.flock(handle, fcntl.LOCK_EX)
    handle.write(f"{os.getpid()}\n")
    handle.flush()
    released = threading.Timer(1.0, handle.close)
    released.start()
    status, seconds = run_while_held(tmp_path, output, released.join, "--wait")
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert seconds >= 1.0
    waiting = [line for line in captured.err.splitlines() if "waiting for it to finish" in line]
    assert len(waiting) == 1 and f"pid {os.getpid()}" in waiting[0] and str(output) in waiting[0]
    assert (output / "cube.nc").is_file()


def held_for_a_dead_owner(output):
    """The folder's lock held by an open file of this process (as a pool worker of a killed run holds its
    parent's), the lock file naming a process that has ended (the killed run)."""
    ended = subprocess.Popen([sys.executable, "-c", ""])
    ended.wait()
    output.mkdir()
    handle = open(output / LOCK_NAME, "w")
    fcntl.flock(handle, fcntl.LOCK_EX)
    handle.write(f"{ended.pid}\n")
    handle.flush()
    return handle


def test_a_lock_a_dead_runs_worker_still_holds_is_waited_for(tmp_path, capsys):
    """A run started just after another was killed in the same folder: the killed run's pool worker holds the lock
    for a moment (here 0.5 s), and the new run takes it then instead of stopping with "in use"."""
    output = tmp_path / "out"
    handle = held_for_a_dead_owner(output)
    released = threading.Timer(0.5, handle.close)
    released.start()
    status, seconds = run_while_held(tmp_path, output, released.join)
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert seconds >= 0.5 and "in use" not in captured.err
    assert (output / "cube.nc").is_file()


def test_the_wait_for_a_dead_runs_worker_is_bounded(tmp_path, capsys, monkeypatch):
    """A lock of a dead owner that stays held past the grace period is "in use", with the usual one line."""
    monkeypatch.setattr(locking, "ORPHAN_GRACE_SECONDS", 0.3)
    output = tmp_path / "out"
    handle = held_for_a_dead_owner(output)
    status, seconds = run_while_held(tmp_path, output, handle.close)
    captured = capsys.readouterr()
    assert status == cli.EXIT_USER_ERROR and seconds >= 0.3
    assert_one_line_error(captured.err, str(output), "in use by another rockfrag run")


def test_stale_part_files_are_removed_when_the_folder_is_free(tmp_path, capsys):
    output = tmp_path / "out"
    (output / ".checkpoints").mkdir(parents=True)
    stale = [output / ".cube.nc.x1y2.part", output / ".checkpoints" / ".abc.ckpt.q9.part"]
    for path in stale:
        path.write_bytes(b"half-written")
    assert cli.main(tiny_run_argv(tmp_path, "--output", str(output))) == 0, capsys.readouterr().err
    assert not any(path.exists() for path in stale) and (output / "cube.nc").is_file()


def test_lock_is_reentrant_in_one_process_and_released(tmp_path):
    with output_lock(tmp_path):
        with output_lock(tmp_path):
            pass
        with open(tmp_path / LOCK_NAME) as handle:
            with pytest.raises(BlockingIOError):
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    with open(tmp_path / LOCK_NAME) as handle:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)  # free again


def test_a_failed_block_removes_the_empty_folders_it_made_and_keeps_the_rest(tmp_path):
    """A run that fails before its first cell leaves no empty ``.checkpoints`` (nor its new output folder)
    behind; in a folder that was there, what was there stays, and so does a new folder that holds a file."""
    new = tmp_path / "new" / "reports"
    with pytest.raises(RuntimeError), output_lock(new):
        (new / ".checkpoints").mkdir()
        raise RuntimeError("the scheduler did not answer")
    assert not (tmp_path / "new").exists()

    used = tmp_path / "used"
    (used / "figures").mkdir(parents=True)  # an earlier run's, empty
    with pytest.raises(RuntimeError), output_lock(used):
        (used / ".checkpoints" / "deeper").mkdir(parents=True)
        (used / "kept").mkdir()
        (used / "kept" / "cell.ckpt").write_text("a finished cell")
        raise RuntimeError("failed later")
    assert sorted(p.name for p in used.iterdir()) == ["figures", "kept"]
