"""Shared by the reliability, fuzz and chaos tests: synthetic AT2 records, small studies, one-line checks."""

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
