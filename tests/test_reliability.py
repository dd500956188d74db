"""Reliability (issue 13): self-verifying checkpoints, records that fail one at a time, process
hygiene (workers die with their parent, lost cells retried, output-folder lock, stale .part files)
and the CLI's exit codes: every failure of the issue's list ends in one line and its exit code."""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import signal
import subprocess
import sys
import textwrap
import threading
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from pipeline import cli
from pipeline.checkpoints import CheckpointStore, DamagedCheckpoint, decode, encode
from pipeline.config import load_study
from pipeline.errors import PipelineError
from pipeline.locking import LOCK_NAME, output_lock
from pipeline.study import run_study, run_tasks
from tests.reliability_helpers import assert_one_line_error, error_lines, small_study_text, write_at2

ROOT = Path(__file__).resolve().parents[1]
QUIET = {"progress": False, "log": lambda message: None, "warn": lambda message: None}


# ---------------------------------------------------------------- checkpoints

def test_checkpoint_round_trip_keeps_plain_and_structured_arrays(tmp_path):
    store = CheckpointStore(tmp_path)
    plain = np.arange(12.0).reshape(3, 4)
    structured = np.zeros(3, dtype=[("peak_angle", "f8"), ("outcome", "i1")])
    structured["peak_angle"] = [0.1, np.nan, 2.0]
    store.save("a", plain)
    store.save("b", structured)
    assert np.array_equal(store.load("a", (3, 4), np.float64), plain)
    loaded = store.load("b", (3,), structured.dtype)
    assert loaded.dtype == structured.dtype and loaded.tobytes() == structured.tobytes()


@pytest.mark.parametrize("damage, reason", [
    (lambda data, other: b"", "empty"),
    (lambda data, other: data[: len(data) // 2], "truncated"),
    (lambda data, other: data[:60], "truncated"),
    (lambda data, other: b"this is a text file\n", "not a rockfrag checkpoint"),
    (lambda data, other: data.replace(b'"sha256": "', b'"sha256": "0'), "sha256"),
    (lambda data, other: data[:-8] + np.float64(np.nan).tobytes(), "sha256"),
    (lambda data, other: data[:-8] + np.float64(123.0).tobytes(), "sha256"),
    (lambda data, other: other, "another cell"),
])
def test_damaged_checkpoint_bytes_are_rejected(damage, reason):
    array = np.linspace(0, 1, 6).reshape(2, 3)
    data = encode("key-1", array)
    with pytest.raises(DamagedCheckpoint, match=reason):
        decode(damage(data, encode("key-2", array)), "key-1", (2, 3), np.float64)


def test_plain_npy_and_wrong_shape_or_dtype_are_rejected(tmp_path):
    import io

    buffer = io.BytesIO()
    np.save(buffer, np.full((2, 3), np.nan))
    with pytest.raises(DamagedCheckpoint, match="not a rockfrag checkpoint"):
        decode(buffer.getvalue(), "k")
    data = encode("k", np.zeros((2, 3)))
    with pytest.raises(DamagedCheckpoint, match="shape"):
        decode(data, "k", (3, 3), np.float64)
    with pytest.raises(DamagedCheckpoint, match="dtype"):
        decode(data, "k", (2, 3), np.float32)


@pytest.fixture(scope="module")
def tiny_study(tmp_path_factory):
    """One short synthetic record, 2 levels, 2 soils, the 3 default blocks, Housner and SSI."""
    folder = tmp_path_factory.mktemp("tiny")
    write_at2(folder / "records" / "pulse.AT2")
    study = folder / "tiny.toml"
    study.write_text(small_study_text(folder / "records"))
    return study


@pytest.fixture(scope="module")
def tiny_reference(tiny_study, tmp_path_factory):
    output = tmp_path_factory.mktemp("reference")
    dataset, stats = run_study(load_study(tiny_study), output=output, workers=1, **QUIET)
    return output, dataset


CORRUPTIONS = {
    "empty": lambda path: path.write_bytes(b""),
    "truncated": lambda path: path.write_bytes(path.read_bytes()[:-40]),
    "text": lambda path: path.write_text("not numbers\n"),
    "plain npy with NaN": lambda path: np.save(open(path, "wb"), np.full((2, 15), np.nan)),
    "value 123": lambda path: path.write_bytes(path.read_bytes()[:-8] + np.float64(123).tobytes()),
    "NaN value": lambda path: path.write_bytes(path.read_bytes()[:-8] + np.float64(np.nan).tobytes()),
    "another cell's file": None,  # filled in the test: a valid checkpoint of another key
}


@pytest.mark.parametrize("kind", list(CORRUPTIONS))
def test_damaged_checkpoint_is_reported_quarantined_and_recomputed(kind, tiny_study, tiny_reference, tmp_path):
    reference_output, reference = tiny_reference
    output = tmp_path / "out"
    shutil.copytree(reference_output, output)
    checkpoints = sorted((output / ".checkpoints").glob("*.ckpt"))
    victim = checkpoints[0]
    if kind == "another cell's file":
        shutil.copy(checkpoints[1], victim)
    else:
        CORRUPTIONS[kind](victim)
    messages = []
    dataset, stats = run_study(load_study(tiny_study), output=output, workers=1, progress=False,
                               log=lambda message: None, warn=messages.append)
    damaged = [m for m in messages if "damaged" in m]
    assert len(damaged) == 1 and victim.name in damaged[0], messages
    assert stats["runs_computed"] == 2  # one cell recomputed at its 2 levels
    assert len(list((output / ".checkpoints" / "quarantine").iterdir())) == 1
    assert dataset.identical(reference)
    assert xr.open_dataset(output / "cube.nc").identical(xr.open_dataset(reference_output / "cube.nc"))


# ---------------------------------------------------------------- the list, as a table

def _records_folder(tmp_path, bad=None, good=True, bad_text=None, bad_bytes=None):
    folder = tmp_path / "records"
    if good:
        write_at2(folder / "good.AT2")
    if bad is not None:
        write_at2(folder / "bad.AT2", **bad)
    if bad_text is not None:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "bad.AT2").write_text(bad_text)
    if bad_bytes is not None:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "bad.AT2").write_bytes(bad_bytes)
    return folder


BAD_RECORDS = [  # (id, arguments of the bad file, words of its one-line reason)
    ("1 sample", {"values": [0.1]}, ["only 1 samples"]),
    ("2 samples", {"values": [0.1, -0.1]}, ["only 2 samples"]),
    ("DT 5 s", {"dt": 5.0}, ["DT = 5 s", "implausible"]),
    ("DT 1e-300", {"dt": 1e-300}, ["DT = 1e-300 s", "implausible"]),
    ("all zero", {"amplitude_g": 0.0}, ["all accelerations are zero"]),
    ("1e305 g", {"amplitude_g": 1e305}, ["implausible", "check the units"]),
    ("empty file", {"text": ""}, ["file is empty"]),
    ("binary file", {"bytes": b"\x00\x01\x02rockfrag\x00" * 10}, ["binary"]),
]


def _bad_folder(tmp_path, spec, good=True):
    spec = dict(spec)
    return _records_folder(tmp_path, good=good, bad_text=spec.pop("text", None),
                           bad_bytes=spec.pop("bytes", None), bad=spec or None)


@pytest.mark.parametrize("command", ["records", "run"])
@pytest.mark.parametrize("name, spec, words", BAD_RECORDS, ids=[case[0] for case in BAD_RECORDS])
def test_bad_record_is_skipped_with_its_reason_and_the_rest_run(name, spec, words, command, tmp_path, capsys):
    folder = _bad_folder(tmp_path, spec)
    output = tmp_path / "out"
    if command == "records":
        argv = ["records", "--set", str(folder), "--output", str(output), "--no-progress"]
    else:
        study = tmp_path / "study.toml"
        study.write_text(small_study_text(folder, levels=[0.5], soils=["rock"]))
        argv = ["run", str(study), "--output", str(output), "--serial", "--no-progress"]
    status = cli.main(argv)
    captured = capsys.readouterr()
    assert status == cli.EXIT_PARTIAL, captured.err
    line = assert_one_line_error(captured.err, "skipped", "bad.AT2", *words)
    assert line.startswith("rockfrag: skipped")
    if command == "records":
        assert list(pd.read_csv(output / "records.csv")["id"]) == ["good"]
    else:
        assert list(xr.open_dataset(output / "cube.nc").record.values) == ["good"]


@pytest.mark.parametrize("name, spec, words", BAD_RECORDS, ids=[case[0] for case in BAD_RECORDS])
def test_only_bad_records_is_a_user_error(name, spec, words, tmp_path, capsys):
    folder = _bad_folder(tmp_path, spec, good=False)
    status = cli.main(["records", "--set", str(folder), "--output", str(tmp_path / "out"), "--no-progress"])
    captured = capsys.readouterr()
    assert status == cli.EXIT_USER_ERROR
    lines = error_lines(captured.err)
    assert "Traceback" not in captured.err and len(lines) == 2  # the skipped file, then "nothing to do"
    assert all(word in lines[0] for word in words) and "no record" in lines[1]


def test_same_file_names_in_two_folders_get_ids_from_their_paths(tmp_path, capsys):
    write_at2(tmp_path / "records" / "site-a" / "X.AT2", amplitude_g=0.2)
    write_at2(tmp_path / "records" / "site-b" / "X.AT2", amplitude_g=0.4)
    status = cli.main(["records", "--set", str(tmp_path / "records"), "--output", str(tmp_path / "out"),
                       "--no-progress"])
    assert status == 0, capsys.readouterr().err
    table = pd.read_csv(tmp_path / "out" / "records.csv")
    assert sorted(table["id"]) == ["site-a/X", "site-b/X"]
    pga = table.set_index("id")["raw_pga_g"]
    assert pga["site-b/X"] == pytest.approx(2 * pga["site-a/X"], rel=1e-6)  # each id has its own file


def test_same_content_twice_is_skipped_as_a_duplicate(tmp_path, capsys):
    write_at2(tmp_path / "records" / "one.AT2")
    write_at2(tmp_path / "records" / "two.AT2")
    status = cli.main(["records", "--set", str(tmp_path / "records"), "--output", str(tmp_path / "out"),
                       "--no-progress"])
    assert status == cli.EXIT_PARTIAL
    assert_one_line_error(capsys.readouterr().err, "two.AT2", "same content as record one", "duplicate")


def test_same_file_named_twice_is_read_once(tmp_path, capsys):
    path = write_at2(tmp_path / "records" / "one.AT2")
    relative = os.path.relpath(path)
    status = cli.main(["records", "--set", str(path), "--set", relative, "--output", str(tmp_path / "out"),
                       "--no-progress"])
    assert status == 0, capsys.readouterr().err
    assert len(pd.read_csv(tmp_path / "out" / "records.csv")) == 1


def _tiny_run_argv(tmp_path, *extra):
    folder = _records_folder(tmp_path)
    study = tmp_path / "study.toml"
    study.write_text(small_study_text(folder, levels=[0.5], soils=["rock"]))
    return ["run", str(study), "--serial", "--no-progress", *extra]


USER_ERRORS = [  # (id, argv builder, words of the one line); each must end with rc 2
    ("output is a file", lambda t: (t / "file").write_text("x") and
     ["records", "--set", "bolu", "--output", str(t / "file")], ["is a file"]),
    ("output below a file", lambda t: (t / "file").write_text("x") and
     ["records", "--set", "bolu", "--output", str(t / "file" / "sub")], ["cannot create the output folder"]),
    ("run output is a file", lambda t: (t / "file").write_text("x") and
     _tiny_run_argv(t, "--output", str(t / "file")), ["is a file"]),
    ("--workers -1", lambda t: _tiny_run_argv(t, "--output", str(t / "out"), "--workers", "-1"),
     ["--workers", "-1", ">= 1"]),
    ("--workers 0", lambda t: _tiny_run_argv(t, "--output", str(t / "out"), "--workers", "0"),
     ["--workers", "0"]),
    ("--set ''", lambda t: ["records", "--set", "", "--output", str(t / "out")], ["--set", "empty"]),
    ("study is a folder", lambda t: ["run", str(t), "--output", str(t / "out")], []),
]


@pytest.mark.parametrize("name, build, words", USER_ERRORS, ids=[case[0] for case in USER_ERRORS])
def test_user_error_is_one_line_and_exit_2(name, build, words, tmp_path, capsys):
    argv = build(tmp_path)
    try:
        status = cli.main(argv)
    except SystemExit as stop:  # a usage error found by argparse
        status = stop.code
    captured = capsys.readouterr()
    assert status == cli.EXIT_USER_ERROR, captured.err
    assert_one_line_error(captured.err, "error:", *words)


def test_second_run_on_a_locked_folder_stops_with_one_line(tmp_path, capsys):
    output = tmp_path / "out"
    output.mkdir()
    with open(output / LOCK_NAME, "w") as handle:  # another run holds the folder
        fcntl.flock(handle, fcntl.LOCK_EX)
        handle.write("4242\n")
        handle.flush()
        (output / ".cube.nc.abc.part").write_text("being written by the other run")
        status = cli.main(_tiny_run_argv(tmp_path, "--output", str(output)))
        captured = capsys.readouterr()
        assert status == cli.EXIT_USER_ERROR
        assert_one_line_error(captured.err, str(output), "in use by another rockfrag run", "pid 4242")
        assert (output / ".cube.nc.abc.part").exists()  # the other run's temporary file is untouched
    assert not (output / "cube.nc").exists()


def test_wait_lets_a_second_run_start_when_the_first_one_ends(tmp_path, capsys):
    output = tmp_path / "out"
    output.mkdir()
    handle = open(output / LOCK_NAME, "w")  # another run holds the folder, and ends 1 s later
    fcntl.flock(handle, fcntl.LOCK_EX)
    handle.write("4242\n")
    handle.flush()
    released = threading.Timer(1.0, handle.close)
    released.start()
    started = time.monotonic()
    try:
        status = cli.main(_tiny_run_argv(tmp_path, "--output", str(output), "--wait"))
    finally:
        released.join()
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert time.monotonic() - started >= 1.0
    waiting = [line for line in captured.err.splitlines() if "waiting for it to finish" in line]
    assert len(waiting) == 1 and "pid 4242" in waiting[0] and str(output) in waiting[0]
    assert (output / "cube.nc").is_file()


def test_stale_part_files_are_removed_when_the_folder_is_free(tmp_path, capsys):
    output = tmp_path / "out"
    (output / ".checkpoints").mkdir(parents=True)
    stale = [output / ".cube.nc.x1y2.part", output / ".checkpoints" / ".abc.ckpt.q9.part"]
    for path in stale:
        path.write_bytes(b"half-written")
    assert cli.main(_tiny_run_argv(tmp_path, "--output", str(output))) == 0, capsys.readouterr().err
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


def test_internal_error_is_one_line_with_a_log_and_exit_3(tmp_path, capsys, monkeypatch):
    def broken_stage(*args, **kwargs):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr("pipeline.records_report.records_stage", broken_stage)
    output = tmp_path / "out"
    status = cli.main(["records", "--set", "bolu", "--output", str(output), "--no-progress"])
    captured = capsys.readouterr()
    assert status == cli.EXIT_INTERNAL_ERROR == 3
    line = assert_one_line_error(captured.err, "internal error in stage 'records'", "records bolu",
                                 "ZeroDivisionError: a bug")
    logs = list(output.glob("rockfrag-error-*.log"))
    assert len(logs) == 1 and str(logs[0]) in line
    assert "Traceback" in logs[0].read_text() and "broken_stage" in logs[0].read_text()


def test_internal_error_log_falls_back_to_the_temp_folder(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    (tmp_path / "file").write_text("x")
    args = cli.build_parser().parse_args(["records", "--output", str(tmp_path / "file" / "out")])
    assert cli._report_internal_error(args, RuntimeError("boom")) == 3
    line = assert_one_line_error(capsys.readouterr().err, "RuntimeError: boom")
    assert str(tmp_path / "tmp") in line and len(list((tmp_path / "tmp").glob("rockfrag-error-*.log"))) == 1


def test_help_documents_the_exit_codes(capsys):
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    text = capsys.readouterr().out
    for code in ("0 ", "1 ", "2 ", "3 "):
        assert f"\n  {code}" in text
    assert "internal error" in text
    readme = (ROOT / "README.md").read_text()
    assert "| 3 |" in readme and "internal error" in readme


def test_internal_error_in_a_real_process(tmp_path):
    """A real process: one stderr line, rc 3, no traceback on the terminal."""
    code = textwrap.dedent(f"""
        import sys
        import pipeline.records_report as stage
        def broken(*a, **k):
            raise KeyError("surprise")
        stage.records_stage = broken
        from pipeline.cli import main
        sys.exit(main(["records", "--set", "bolu", "--output", {str(tmp_path)!r}, "--no-progress"]))
    """)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert result.returncode == 3
    assert_one_line_error(result.stderr, "internal error in stage 'records'", "KeyError")


def test_bad_records_in_a_real_process_exit_1(tmp_path):
    folder = _bad_folder(tmp_path, {"dt": 1e-300})
    result = subprocess.run([sys.executable, "-m", "pipeline", "records", "--set", str(folder), "--output",
                             str(tmp_path / "out"), "--no-progress"], capture_output=True, text=True, cwd=ROOT)
    assert result.returncode == 1
    assert_one_line_error(result.stderr, "bad.AT2", "DT = 1e-300")


# ---------------------------------------------------------------- process hygiene

def _kill_own_worker_once(marker, value):
    """Task for a pool: the first call kills its own worker process (as the OOM killer would)."""
    if value == "always" or not os.path.exists(marker):
        open(marker, "w").close()
        os.kill(os.getpid(), signal.SIGKILL)
    return value


def _pool_factory(marker):
    def make():
        pool = ProcessPoolExecutor(max_workers=1)
        return (lambda value: pool.submit(_kill_own_worker_once, marker, value), as_completed,
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
        from pipeline.study import _die_with_parent

        def pid(_):
            time.sleep(0.2)
            return os.getpid()

        if __name__ == "__main__":
            pool = ProcessPoolExecutor(2, initializer=_die_with_parent, initargs=(os.getpid(),))
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


def test_cube_lists_every_record_checksum_when_names_clash(tmp_path):
    write_at2(tmp_path / "records" / "a" / "X.AT2", amplitude_g=0.2)
    write_at2(tmp_path / "records" / "b" / "X.AT2", amplitude_g=0.4)
    study = tmp_path / "study.toml"
    study.write_text(small_study_text(tmp_path / "records", levels=[0.5], soils=["rock"]))
    dataset, _ = run_study(load_study(study), output=tmp_path / "out", workers=1, **QUIET)
    assert sorted(dataset.record.values) == ["a/X", "b/X"]
    assert sorted(json.loads(dataset.attrs["record_checksums"])) == ["a/X", "b/X"]


def test_internal_error_in_a_cell_names_the_record(tiny_study, tmp_path, capsys, monkeypatch):
    def broken_cells(*args, **kwargs):
        raise IndexError("kernel bug")

    monkeypatch.setattr("pipeline.study.compute_cells", broken_cells)
    status = cli.main(["run", str(tiny_study), "--output", str(tmp_path / "out"), "--serial", "--no-progress"])
    assert status == cli.EXIT_INTERNAL_ERROR
    assert_one_line_error(capsys.readouterr().err, "stage 'run'", str(tiny_study), "(record pulse, block ",
                          "IndexError: kernel bug")


def test_user_file_id_never_takes_a_catalogue_id(tmp_path):
    from pipeline.records import load_records

    write_at2(tmp_path / "mine" / "x" / "DUZCE" / "BOL090.AT2", amplitude_g=0.2)
    write_at2(tmp_path / "mine" / "y" / "BOL090.AT2", amplitude_g=0.3)
    records, failures = load_records(["DUZCE/BOL090", str(tmp_path / "mine")])
    ids = [r.id for r in records]
    assert not failures and len(set(ids)) == 3 and "DUZCE/BOL090" in ids
    assert records[0].metadata["file"].endswith("BOL090.AT2") and "x/DUZCE/BOL090" in ids and "y/BOL090" in ids


_real_compute_cells = __import__("pipeline.study", fromlist=["compute_cells"]).compute_cells


def _oom_on_fine_sampling(acceleration, dt, *args):
    """compute_cells, except that a worker given the 0.005 s record is killed (as by the OOM killer)."""
    if dt == 0.005:
        os.kill(os.getpid(), signal.SIGKILL)
    return _real_compute_cells(acceleration, dt, *args)


def test_record_whose_worker_dies_twice_is_reported_and_the_rest_kept(tmp_path, monkeypatch):
    write_at2(tmp_path / "records" / "coarse.AT2", amplitude_g=0.3)
    write_at2(tmp_path / "records" / "fine.AT2", amplitude_g=0.3, dt=0.005, npts=800)
    study = tmp_path / "study.toml"
    study.write_text(small_study_text(tmp_path / "records", levels=[0.5], soils=["rock"]))
    monkeypatch.setattr("pipeline.study.compute_cells", _oom_on_fine_sampling)
    warnings = []
    dataset, stats = run_study(load_study(study), output=tmp_path / "out", workers=2, progress=False,
                               log=lambda message: None, warn=warnings.append)
    assert list(dataset.record.values) == ["coarse"]
    assert len(stats["failures"]) == 1 and "fine.AT2" in stats["failures"][0]
    assert "worker process died twice" in stats["failures"][0]
    assert any("skipped" in w and "fine.AT2" in w for w in warnings)
    cells = [p for p in (tmp_path / "out" / ".checkpoints").glob("*.ckpt") if "capacity" not in p.name]
    assert len(cells) == 6  # coarse's cells (3 blocks x housner + ssi on rock) are kept


@pytest.mark.parametrize("npts", [3, 5, 9])
def test_short_record_that_processing_cannot_handle_is_skipped_not_a_traceback(npts, tmp_path, capsys):
    write_at2(tmp_path / "records" / "good.AT2")
    write_at2(tmp_path / "records" / "short.AT2", values=[0.1, -0.2, 0.15, -0.05, 0.02, 0.3, -0.1, 0.05, 0.01][:npts])
    status = cli.main(["records", "--set", str(tmp_path / "records"), "--output", str(tmp_path / "out"),
                       "--no-progress"])
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    if status == cli.EXIT_PARTIAL:  # skipped by processing, with the step that failed
        assert_one_line_error(captured.err, "short.AT2", "cannot be processed")
    else:
        assert status == 0 and len(pd.read_csv(tmp_path / "out" / "records.csv")) == 2


def _block_forever(_):
    time.sleep(3600)


def test_pool_shutdown_is_bounded_when_a_worker_never_exits():
    """A worker stuck forever (as when another was killed holding the queue lock) is killed, not awaited."""
    from pipeline.study import shutdown_pool, worker_pool

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
