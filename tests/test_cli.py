"""The rockfrag command: records stage output, clean errors, exit codes."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pandas as pd
import pytest

from rockfrag.cli import main


def test_records_writes_table_and_plots(tmp_path, capsys):
    status = main(["records", "--set", "bolu", "--plot", "--output", str(tmp_path), "--no-progress"])
    assert status == 0
    table = pd.read_csv(tmp_path / "records.csv")
    assert list(table["id"]) == ["DUZCE/BOL000", "DUZCE/BOL090"]
    assert {"pga_m_s2", "pgv_m_s", "arias_m_s", "cav_m_s", "d5_95_s", "sa_1s_m_s2"} <= set(table.columns)
    assert (tmp_path / "records" / "DUZCE_BOL090.png").stat().st_size > 10_000
    assert "PGA [g]" in capsys.readouterr().out


def test_bad_file_is_one_line_and_nonzero(tmp_path, bolu_path, capsys):
    """In this process; the same case in a real process: test_cli_reliability's exit-1 test."""
    folder = tmp_path / "mine"
    folder.mkdir()
    shutil.copy(bolu_path, folder / "good.AT2")
    (folder / "bad.AT2").write_text("PEER\nx\nUNITS OF G\nNPTS= 10, DT= .01 SEC\n .1 abc\n")
    status = main(["records", "--set", str(folder), "--output", str(tmp_path / "out"), "--no-progress"])
    stderr = capsys.readouterr().err
    assert status == 1
    assert "Traceback" not in stderr
    assert "bad.AT2, line 5" in stderr and "'abc'" in stderr
    assert len(pd.read_csv(tmp_path / "out" / "records.csv")) == 1  # the good file went on


def test_bad_recipe_exits_2_without_traceback(tmp_path, capsys):
    """In this process; exit 2 in a real process: the bad study and the unreachable scheduler below."""
    recipe = tmp_path / "recipe.toml"
    recipe.write_text('[[steps]]\nname = "taper"\nmax_percentage = 3\n')
    status = main(["records", "--set", "bolu", "--processing", str(recipe), "--output", str(tmp_path)])
    stderr = capsys.readouterr().err
    assert status == 2
    assert "Traceback" not in stderr
    assert "steps[0].max_percentage" in stderr and "0.0 to 0.5" in stderr
    assert not (tmp_path / "records.csv").exists()


def test_bad_study_exits_2_with_the_field(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text('[intensity]\nlevels = { start = 0.5, stop = 0.1, count = 5 }\n')
    result = subprocess.run([sys.executable, "-m", "rockfrag", "run", str(study), "--output", str(tmp_path / "out")],
                            capture_output=True, text=True)
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert "intensity.levels" in result.stderr and str(study) in result.stderr
    assert not (tmp_path / "out" / "cube.nc").exists()


@pytest.mark.slow
def test_unreachable_scheduler_is_one_line(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text('soils = ["rock"]\n[study]\nrecord_sets = ["bolu"]\n[intensity]\nlevels = [0.5]\n')
    result = subprocess.run([sys.executable, "-m", "rockfrag", "run", str(study), "--output", str(tmp_path / "out"),
                             "--scheduler", "tcp://127.0.0.1:9", "--no-progress"], capture_output=True, text=True,
                            env={**os.environ, "ROCKFRAG_DASK_CONNECT_TIMEOUT": "1"})  # 10 s by default
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert "cannot connect to the dask scheduler" in result.stderr
    assert not (tmp_path / "out").exists()  # nor its empty .checkpoints folder


@pytest.mark.slow
def test_the_scheduler_is_checked_when_every_cell_is_checkpointed(tmp_path, capsys, monkeypatch):
    """A rerun with nothing left to compute starts no executor: the address is still checked (issue 33)."""
    study = tmp_path / "study.toml"
    study.write_text('soils = ["rock"]\nmodels = ["housner"]\n[study]\nrecord_sets = ["DUZCE/BOL090"]\n'
                     '[intensity]\nlevels = [0.5]\ncapacity_resolution = 0.0\n'
                     '[blocks.cabinet]\nb = 0.3\nh = 1.1\nmass = 400.0\n')
    output = tmp_path / "out"
    assert main(["run", str(study), "--output", str(output), "--serial", "--no-progress"]) == 0
    capsys.readouterr()
    assert main(["run", str(study), "--output", str(output), "--serial", "--no-progress"]) == 0
    assert "1 of 1 cells reused" in capsys.readouterr().out  # nothing left to compute
    monkeypatch.setenv("ROCKFRAG_DASK_CONNECT_TIMEOUT", "1")
    status = main(["run", str(study), "--output", str(output), "--scheduler", "tcp://127.0.0.1:9", "--no-progress"])
    error = capsys.readouterr().err
    assert status == 2 and error.count("\n") == 1 and "cannot connect to the dask scheduler at 'tcp://127.0.0.1:9'" \
        in error


# ---------------------------------------------------------------- a failed command leaves no trace (issue 21)

def test_a_failed_command_leaves_no_empty_folder_or_lock_behind(tmp_path, capsys):
    output = tmp_path / "new" / "reports"  # neither folder exists yet
    status = main(["calibrate", str(tmp_path / "missing.csv"), "--record", "DUZCE/BOL090", "--output", str(output)])
    assert status == 2 and "missing.csv: reference file not found" in capsys.readouterr().err
    assert not (tmp_path / "new").exists()


def test_a_failed_command_leaves_an_existing_folder_as_it_found_it(tmp_path, capsys):
    from rockfrag.locking import LOCK_NAME

    empty, used = tmp_path / "empty", tmp_path / "used"
    empty.mkdir()
    used.mkdir()
    (used / LOCK_NAME).write_text("1\n")  # left by an earlier, successful run
    (used / "cube.nc").write_bytes(b"earlier results")
    for folder in (empty, used):
        assert main(["calibrate", str(tmp_path / "missing.csv"), "--record", "DUZCE/BOL090",
                     "--output", str(folder)]) == 2
    assert empty.is_dir() and not list(empty.iterdir())
    assert sorted(p.name for p in used.iterdir()) == sorted([LOCK_NAME, "cube.nc"])
    capsys.readouterr()


def test_output_lock_cleans_up_only_after_a_failure(tmp_path):
    import pytest

    from rockfrag.locking import LOCK_NAME, output_lock

    with pytest.raises(RuntimeError):
        with output_lock(tmp_path / "a" / "b"):
            raise RuntimeError("the command failed")
    assert not (tmp_path / "a").exists()
    with pytest.raises(RuntimeError):
        with output_lock(tmp_path / "kept"):
            (tmp_path / "kept" / "partial.csv").write_text("written before the failure")
            raise RuntimeError("the command failed")
    assert sorted(p.name for p in (tmp_path / "kept").iterdir()) == ["partial.csv"]
    with output_lock(tmp_path / "done"):
        pass
    assert (tmp_path / "done" / LOCK_NAME).is_file()  # a successful run keeps its lock file, as before


def test_a_run_waiting_on_a_failed_run_locks_the_new_lock_file(tmp_path):
    """The waiting run must not hold a lock on the file the failed run removed (two runs in one folder)."""
    import fcntl
    import textwrap
    import time

    import pytest

    from rockfrag.locking import LOCK_NAME, output_lock

    output = tmp_path / "out"
    script = textwrap.dedent(f"""
        import time
        from rockfrag.locking import output_lock
        try:
            with output_lock({str(output)!r}):
                print("locked", flush=True)
                time.sleep(1.5)
                raise RuntimeError("failed")
        except RuntimeError:
            pass
    """)
    failing = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert failing.stdout.readline().strip() == "locked"
    started = time.monotonic()
    with output_lock(output, wait=True):
        assert time.monotonic() - started > 0.5  # it waited for the failing run
        with open(output / LOCK_NAME) as other:  # the file at the path is the one held
            with pytest.raises(BlockingIOError):
                fcntl.flock(other, fcntl.LOCK_EX | fcntl.LOCK_NB)
    failing.wait(timeout=30)
