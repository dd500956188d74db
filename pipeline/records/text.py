"""pipeline.records.text - plain text / CSV acceleration records, the most common exchange format.

Input : a text file with one column (acceleration; the time step from ``dt``) or two columns (time [s],
        acceleration), separated by commas, semicolons, tabs or spaces. Header lines before the numbers
        and ``#`` comments are skipped. Units: ``units`` (g, m/s^2, cm/s^2, gal), or a unit in the
        header written as ``acc [g]``, ``acceleration (cm/s^2)``, ``a_g [m/s2]``.
Output: an ``obspy.Stream`` of one ``Trace`` of ground acceleration [m/s^2] with ``stats.text_record``
        (columns, header, units found in the file).

Errors are ``RecordError`` naming the file, the line and what was expected.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from pipeline.errors import RecordError
from pipeline.units import acceleration_factor

TEXT_SUFFIXES = {".csv", ".txt", ".dat", ".acc", ".tsv"}
"""File endings tried as text records (content decides: see ``is_text_record``)."""

_SEPARATOR = re.compile(r"[,;\t ]+")
_UNIT_IN_HEADER = re.compile(r"[\[(]\s*([A-Za-z/^*0-9 .]+?)\s*[\])]")
_HEAD_BYTES = 65536
DT_TOLERANCE = 1e-3
"""Largest relative spread of the time steps of a time column still taken as uniform sampling."""


def _fields(line: str) -> list[str]:
    return [f for f in _SEPARATOR.split(line.strip()) if f]


def _numbers(line: str) -> list[float] | None:
    try:
        return [float(f) for f in _fields(line)]
    except ValueError:
        return None


def _read_lines(path) -> list[str]:
    raw = Path(path).read_bytes()
    if b"\x00" in raw[:_HEAD_BYTES]:
        raise RecordError(path, "binary content; expected a text file of one or two numeric columns")
    try:
        return raw.decode("utf-8-sig").splitlines()
    except UnicodeDecodeError:
        return raw.decode("latin-1").splitlines()


def is_text_record(path) -> bool:
    """True for a file with a text suffix whose first data line has one or two numbers. Never raises."""
    try:
        if Path(path).suffix.lower() not in TEXT_SUFFIXES:
            return False
        with open(path, "rb") as handle:
            head = handle.read(_HEAD_BYTES)
        if b"\x00" in head:
            return False
        for line in head.decode("utf-8", errors="replace").splitlines():
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            numbers = _numbers(line)
            if numbers is not None:
                return 1 <= len(numbers) <= 2
        return False
    except OSError:
        return False


def _unit_from_header(header: list[str]) -> str | None:
    """The acceleration unit written in the header (the last bracketed unit that is an acceleration)."""
    found = None
    for line in header:
        for candidate in _UNIT_IN_HEADER.findall(line):
            try:
                acceleration_factor(candidate)
            except ValueError:
                continue
            found = candidate.strip()
    return found


def parse_text_record(path, units: str | None = None, dt: float | None = None):
    """(acceleration [m/s^2], dt [s], details) of a one- or two-column text record."""
    lines = _read_lines(path)
    header, rows, first_line = [], [], None
    for number, line in enumerate(lines, start=1):
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        values = _numbers(text)
        if values is None:
            if rows:
                bad = next(f for f in _fields(text) if _numbers(f) is None)
                raise RecordError(path, f"{bad!r} is not a number; expected {len(rows[0])} numeric column(s)",
                                  number)
            header.append(text)
            continue
        if first_line is None:
            first_line = number
            if len(values) not in (1, 2):
                raise RecordError(path, f"{len(values)} columns; expected one (acceleration, with --dt) or two "
                                  "(time [s], acceleration)", number)
        if len(values) != len(rows[0] if rows else values):
            raise RecordError(path, f"{len(values)} columns; the first data line (line {first_line}) has "
                              f"{len(rows[0])}", number)
        rows.append(values)
    if len(rows) < 2:
        raise RecordError(path, f"{len(rows)} data line(s); expected at least 2 samples of one or two numeric "
                          "columns")
    table = np.asarray(rows, dtype=np.float64)
    if not np.all(np.isfinite(table)):
        row = int(np.flatnonzero(~np.all(np.isfinite(table), axis=1))[0])
        raise RecordError(path, "NaN or infinite value; expected finite numbers", _line_of_row(lines, row))

    columns = table.shape[1]
    if columns == 2:
        time, acceleration = table[:, 0], table[:, 1]
        steps = np.diff(time)
        if np.any(steps <= 0):
            row = int(np.flatnonzero(steps <= 0)[0]) + 1
            raise RecordError(path, "time must increase from line to line", _line_of_row(lines, row))
        step = float(np.median(steps))
        if np.max(np.abs(steps - step)) > DT_TOLERANCE * step:
            row = int(np.argmax(np.abs(steps - step))) + 1
            raise RecordError(path, f"uneven time step {steps[row - 1]:g} s (median {step:g} s); expected "
                              "uniform sampling", _line_of_row(lines, row))
        if dt is not None and abs(dt - step) > DT_TOLERANCE * step:
            raise RecordError(path, f"--dt {dt:g} s disagrees with the time column's step {step:g} s")
        dt = step
    else:
        acceleration = table[:, 0]
        if dt is None:
            raise RecordError(path, "one column of accelerations and no time step; state it (--dt SECONDS, or "
                              "dt in the study's [study] table)")
    if not (dt > 0 and np.isfinite(dt)):
        raise RecordError(path, f"time step {dt!r} s; expected > 0")

    in_file = _unit_from_header(header)
    if units is None and in_file is None:
        raise RecordError(path, "acceleration units unknown: the header states none; state them (--units g, "
                          "m/s^2, cm/s^2 or gal, or units in the study's [study] table)")
    if units is not None and in_file is not None and acceleration_factor(units) != acceleration_factor(in_file):
        raise RecordError(path, f"--units {units} disagrees with the header's [{in_file}]")
    unit = units or in_file
    try:
        factor = acceleration_factor(unit)
    except ValueError as error:
        raise RecordError(path, str(error)) from None
    details = {"columns": columns, "header": header, "units_in_file": unit}
    return acceleration * factor, float(dt), details


def _line_of_row(lines, row) -> int:
    """1-based line number of the ``row``-th numeric line (0-based)."""
    seen = -1
    for number, line in enumerate(lines, start=1):
        text = line.split("#", 1)[0].strip()
        if text and _numbers(text) is not None:
            seen += 1
            if seen == row:
                return number
    return len(lines)


def read_text_record(filename, units: str | None = None, dt: float | None = None, **kwargs):
    """An ``obspy.Stream`` with one acceleration trace [m/s^2] from a text record."""
    from obspy import Stream, Trace

    acceleration, step, details = parse_text_record(filename, units=units, dt=dt)
    trace = Trace(data=acceleration)
    trace.stats.delta = step
    trace.stats.station = Path(filename).stem[:20]
    trace.stats.units = "m/s^2"
    trace.stats.quantity = "acceleration"
    trace.stats.text_record = details
    return Stream([trace])
