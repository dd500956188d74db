"""rockfrag.records.text - plain text / CSV acceleration records, and the one reader of numeric text tables.

Text is the most common exchange format; tables with units in the header are read here also for
calibration references.

Input : a text file with one column (acceleration; the time step from ``dt``) or two columns (time [s],
        acceleration), separated by commas, semicolons, tabs or spaces. Header lines before the numbers
        and ``#`` comments are skipped. Units: ``units`` (g, m/s^2, cm/s^2, gal), or a unit in the
        header written as ``acc [g]``, ``acceleration (cm/s^2)``, ``a_g [m/s2]``.
Output: an ``obspy.Stream`` of one ``Trace`` of ground acceleration [m/s^2] with ``stats.text_record``
        (columns, header, units found in the file). ``read_columns`` gives any such table as a
        ``ColumnTable`` (values, header lines, column names, line numbers).

Errors are ``RecordError`` naming the file, the line and what was expected.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from obspy import Stream, Trace

from rockfrag.errors import RecordError
from rockfrag.units import acceleration_factor

TEXT_SUFFIXES = {".csv", ".txt", ".dat", ".acc", ".tsv"}
"""File endings tried as text records (content decides: see ``is_text_record``)."""

_SEPARATOR = re.compile(r"[,;\t ]+")
_HEADER_SEPARATOR = re.compile(r"\s*[,;\t]\s*")
_BRACKETED = re.compile(r"[\[({]\s*([^\[\](){}]*?)\s*[\])}]")
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


def _read_lines(path, what: str) -> list[str]:
    raw = Path(path).read_bytes()
    if b"\x00" in raw[:_HEAD_BYTES]:
        raise RecordError(path, f"binary content; expected a text file of {what}")
    try:
        return raw.decode("utf-8-sig").splitlines()
    except UnicodeDecodeError:
        return raw.decode("latin-1").splitlines()


def bracketed_units(text: str) -> list[str]:
    """Units written in brackets in a header or column name: ``'time [ms], theta (deg)'`` -> ``['ms', 'deg']``."""
    return [unit.strip() for unit in _BRACKETED.findall(text)]


@dataclass(frozen=True)
class ColumnTable:
    """Numeric columns of a text table, with the text above them (``read_columns``)."""

    path: str
    values: np.ndarray
    """shape (rows, columns), finite float64."""
    header: tuple[str, ...]
    """The text lines above the numbers (``#`` comments left out)."""
    names: tuple[str, ...]
    """The column names, from the last header line, or () when it has fewer cells than columns."""
    lines: tuple[int, ...]
    """1-based line number of each row."""

    def name(self, column: int) -> str:
        """The header's name of a column (0-based), else ``"column N"`` (1-based)."""
        return self.names[column] if column < len(self.names) else f"column {column + 1}"

    def time(self, column: int = 0) -> np.ndarray:
        """The column, checked to increase from line to line (a ``RecordError`` names the first line that does not)."""
        values = self.values[:, column]
        steps = np.diff(values)
        if np.any(steps <= 0):
            row = int(np.flatnonzero(steps <= 0)[0]) + 1
            raise RecordError(self.path, f"time must increase from line to line (column {self.name(column)!r})",
                              self.lines[row])
        return values


def _column_names(header: list[str], count: int) -> tuple[str, ...]:
    """The cells of the last header line if it names at least ``count`` columns, else ().

    The line is split at commas, semicolons or tabs, else at spaces.
    """
    last = header[-1] if header else ""
    cells = _HEADER_SEPARATOR.split(last) if _HEADER_SEPARATOR.search(last) else last.split()
    return tuple(cell.strip() for cell in cells) if len(cells) >= count else ()


def read_columns(path, what: str, counts: tuple[int, ...] = (1, 2), extra: bool = False,
                 header_lines: int | None = None, max_rows: int | None = None) -> ColumnTable:
    """The numeric columns of a text table: comma, semicolon, tab or space separated; ``#`` comments.

    Parameters
    ----------
    path : str or Path
        The file.
    what : str
        What the file should hold, for the messages (``"two columns (time, rotation)"``).
    counts : tuple of int
        Numbers of numeric columns the first data line may have; every other line has as many.
    extra : bool
        Cells after the first ``max(counts)`` may hold anything and are left out.
    header_lines : int, optional
        At most this many lines above the numbers (a further line that is not numbers is a data line
        with a text cell); any number if None.
    max_rows : int, optional
        More data lines than this is an error (a unit or export mistake, not a table to read).

    Returns
    -------
    ColumnTable
        Lines before the first all-numeric line are the header; the cells of its last line name the
        columns. A later line that is not numbers, a line with another number of columns, or a NaN or
        infinite value is a ``RecordError`` naming the line (and the column, where the header names it).
    """
    lines = _read_lines(path, what)
    used = max(counts) if extra else None
    header, rows, numbers, names = [], [], [], ()
    for number, line in enumerate(lines, start=1):
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        cells = _fields(text)[:used]
        try:
            values = [float(cell) for cell in cells]
        except ValueError:
            if rows or (header_lines is not None and len(header) >= header_lines):
                names = names if rows else _column_names(header, len(cells))
                column = next(i for i, cell in enumerate(cells) if _numbers(cell) is None)
                named = f"column {names[column]!r}: " if column < len(names) else ""
                expected = f"{len(rows[0])} numeric column(s)" if rows else what
                raise RecordError(path, f"{named}{cells[column]!r} is not a number; expected {expected}",
                                  number) from None
            header.append(text)
            continue
        if not rows:
            if len(values) not in counts:
                raise RecordError(path, f"{len(values)} columns; expected {what}", number)
            names = _column_names(header, len(values))
        elif len(values) != len(rows[0]):
            raise RecordError(path, f"{len(values)} columns; the first data line (line {numbers[0]}) has "
                              f"{len(rows[0])}", number)
        rows.append(values)
        numbers.append(number)
        if max_rows is not None and len(rows) > max_rows:
            raise RecordError(path, f"more than {max_rows} rows; expected {what} (resample the table)")
    table = np.asarray(rows, dtype=np.float64).reshape(len(rows), len(rows[0]) if rows else 0)
    if not np.all(np.isfinite(table)):
        row = int(np.flatnonzero(~np.all(np.isfinite(table), axis=1))[0])
        raise RecordError(path, "NaN or infinite value; expected finite numbers", numbers[row])
    return ColumnTable(str(path), table, tuple(header), names, tuple(numbers))


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


def _unit_from_header(header) -> str | None:
    """The acceleration unit written in the header (the last bracketed unit that is an acceleration)."""
    found = None
    for line in header:
        for candidate in bracketed_units(line):
            try:
                acceleration_factor(candidate)
            except ValueError:
                continue
            found = candidate
    return found


RECORD_COLUMNS = "one column (acceleration, with --dt) or two (time [s], acceleration)"


def parse_text_record(path, units: str | None = None, dt: float | None = None):
    """(acceleration [m/s^2], dt [s], details) of a one- or two-column text record."""
    table = read_columns(path, RECORD_COLUMNS)
    if len(table.values) < 2:
        raise RecordError(path, f"{len(table.values)} data line(s); expected at least 2 samples of {RECORD_COLUMNS}")
    columns = table.values.shape[1]
    if columns == 2:
        time, acceleration = table.time(0), table.values[:, 1]
        steps = np.diff(time)
        step = float(np.median(steps))
        if np.max(np.abs(steps - step)) > DT_TOLERANCE * step:
            row = int(np.argmax(np.abs(steps - step))) + 1
            raise RecordError(path, f"uneven time step {steps[row - 1]:g} s (median {step:g} s); expected "
                              "uniform sampling", table.lines[row])
        if dt is not None and abs(dt - step) > DT_TOLERANCE * step:
            raise RecordError(path, f"--dt {dt:g} s disagrees with the time column's step {step:g} s")
        dt = step
    else:
        acceleration = table.values[:, 0]
        if dt is None:
            raise RecordError(path, "one column of accelerations and no time step; state it (--dt SECONDS, or "
                              "dt in the study's [study] table)")
    if not (dt > 0 and np.isfinite(dt)):
        raise RecordError(path, f"time step {dt!r} s; expected > 0")

    in_file = _unit_from_header(table.header)
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
    details = {"columns": columns, "header": list(table.header), "units_in_file": unit}
    return acceleration * factor, float(dt), details


def read_text_record(filename, units: str | None = None, dt: float | None = None, **kwargs):
    """An ``obspy.Stream`` with one acceleration trace [m/s^2] from a text record."""
    acceleration, step, details = parse_text_record(filename, units=units, dt=dt)
    trace = Trace(data=acceleration)
    trace.stats.delta = step
    trace.stats.station = Path(filename).stem[:20]
    trace.stats.units = "m/s^2"
    trace.stats.quantity = "acceleration"
    trace.stats.text_record = details
    return Stream([trace])
