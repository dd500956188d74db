"""Shared by the reliability tests (checkpoints, locking, executors, CLI, chaos, issue list) and the fuzz tests:
synthetic AT2 records, small studies, one-line checks."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def at2_text(npts=None, dt=0.01, amplitude_g=0.3, values=None, header_units="G") -> str:
    """A PEER AT2 file: a decaying 1.5 Hz sine of ``amplitude_g`` (or the given values in g)."""
    if values is None:
        time = np.arange(npts or 400) * dt
        values = amplitude_g * np.sin(2 * math.pi * 1.5 * time) * np.exp(-0.4 * time)
    values = list(values)
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD",
             "Synthetic quake, 1/1/2000, Test station, 090",
             f"ACCELERATION TIME SERIES IN UNITS OF {header_units}",
             f"NPTS= {len(values) if npts is None else npts:6d}, DT= {dt:.6g} SEC"]
    for start in range(0, len(values), 5):
        lines.append("".join(f" {v:.7E}" for v in values[start:start + 5]))
    return "\n".join(lines) + "\n"


def write_at2(path: Path, **kwargs) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(at2_text(**kwargs))
    return path


def small_study_text(record_folder, levels=(0.3, 1.0), soils=("sand", "rock"), output=None) -> str:
    """A study of the records in ``record_folder``: few levels, two soils, Housner and SSI."""
    text = (f'soils = {list(soils)!r}\nmodels = ["housner", "ssi"]\n'
            f'[study]\nname = "tiny"\nrecord_sets = ["{record_folder}"]\n')
    if output is not None:
        text += f'output = "{output}"\n'
    text += f"[intensity]\nlevels = {list(levels)!r}\n[solver]\ntail = 2.0\n"
    return text.replace("'", '"')


def error_lines(text: str) -> list[str]:
    """The non-empty lines of a command's stderr."""
    return [line for line in text.splitlines() if line.strip()]


def assert_one_line_error(stderr: str, *fragments: str) -> str:
    """stderr is exactly one line, without a traceback, holding every fragment."""
    lines = error_lines(stderr)
    assert "Traceback" not in stderr, stderr
    assert len(lines) == 1, stderr
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    return lines[0]


QUIET = {"progress": False, "log": lambda message: None, "warn": lambda message: None}
"""run_study keywords for a silent run (no progress bar, no log lines, no warnings)."""


def write_tiny_study(folder: Path) -> Path:
    """One short synthetic record (``folder/records/pulse.AT2``) and its study file ``folder/tiny.toml``:
    2 levels, 2 soils, the 3 default blocks, Housner and SSI."""
    folder = Path(folder)
    write_at2(folder / "records" / "pulse.AT2")
    study = folder / "tiny.toml"
    study.write_text(small_study_text(folder / "records"))
    return study


def records_folder(tmp_path: Path, bad=None, good=True, bad_text=None, bad_bytes=None) -> Path:
    """``tmp_path/records`` with ``good.AT2`` (unless ``good`` is False) and a ``bad.AT2`` written from
    ``write_at2`` arguments (``bad``), text (``bad_text``) or bytes (``bad_bytes``)."""
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


def tiny_run_argv(tmp_path: Path, *extra: str) -> list[str]:
    """``rockfrag run`` arguments for a one-record, one-level, one-soil study written in ``tmp_path``."""
    folder = records_folder(tmp_path)
    study = tmp_path / "study.toml"
    study.write_text(small_study_text(folder, levels=[0.5], soils=["rock"]))
    return ["run", str(study), "--serial", "--no-progress", *extra]
