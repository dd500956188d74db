"""rockfrag.records.peer_at2 - PEER AT2 acceleration files, as an obspy waveform plugin.

Input : a PEER ``.AT2`` text file (every header variant described in ``records/SOURCE-README.md``:
        NGA-West2 with or without filter text, NGA-West1 ``NPTS, DT`` line, old PEER / Pacific
        Engineering / CDMG headers, lower-case ``dt``, LF/CRLF/CR/CRCRLF line ends, values without a
        leading zero, no final newline).
Output: an ``obspy.Stream`` with one ``Trace`` of ground acceleration in m/s^2 (converted from g with
        standard gravity at this edge) whose ``stats`` carry event, station, component and units.

Registered with obspy through the entry-point group ``obspy.plugin.waveform`` (see pyproject.toml),
so ``obspy.read("x.AT2")`` detects the format by itself.
"""

from __future__ import annotations

import math
import re

import numpy as np
from obspy import Stream, Trace
from obspy.core.util import AttribDict

from rockfrag.errors import RecordError
from rockfrag.records.sources import HEAD_BYTES, read_head, read_source
from rockfrag.units import acceleration_factor

HEADER_SEARCH_LINES = 10
"""The NPTS/DT line must appear within this many lines of the top of the file."""

_NPTS_DT_EQUALS = re.compile(r"NPTS\s*=\s*(\d+)\s*,?\s*DT\s*=\s*([0-9.Ee+-]+)", re.IGNORECASE)
_NPTS_DT_COLUMNS = re.compile(r"^\s*(\d+)\s+([0-9.Ee+-]+)\s+NPTS\s*,\s*DT", re.IGNORECASE)
_NPTS_ONLY = re.compile(r"NPTS\s*=\s*(\S+)", re.IGNORECASE)
_DT_ONLY = re.compile(r"\bDT\s*=\s*(\S*)", re.IGNORECASE)
_UNITS = re.compile(r"UNITS\s+(?:OF\s+|ARE\s+)?\(?\s*([A-Z/0-9*^.]+)", re.IGNORECASE)
_FILTER_TEXT = re.compile(r"SEC\s*,?\s*(.+)$", re.IGNORECASE)
# Lines end in LF, CRLF, a lone CR, or CR CR LF (ARL360.at2); each of these is one line break.
_LINE_BREAK = re.compile(r"\r*\n|\r")


def _split_lines(text: str) -> list[str]:
    return _LINE_BREAK.split(text)


def _find_npts_dt(lines):
    """Locate the NPTS/DT header line; return (index, npts, dt) or None."""
    for index, line in enumerate(lines[:HEADER_SEARCH_LINES]):
        match = _NPTS_DT_EQUALS.search(line) or _NPTS_DT_COLUMNS.search(line)
        if match:
            return index, match.group(1), match.group(2)
    return None


def is_peer_at2(source) -> bool:
    """True if ``source`` (path or binary file object) looks like a PEER AT2 file. Never raises."""
    try:
        head = read_head(source)
        return bool(head) and _find_npts_dt(_split_lines(head)) is not None
    except Exception:  # detection must never raise, whatever the input (obspy contract)
        return False


def _parse_station_line(line: str) -> dict:
    """Best-effort event/station/component from header line 2 (formats vary, see module doc)."""
    text = re.sub(r"\s*\([^()]*\)\s*$", "", line.strip())  # drop "(ERD)", "(NGA RSN ..)" suffixes
    parts = [part.strip() for part in text.split(",")]
    if len(parts) < 3:
        return {"event": line.strip(), "station": "", "component": ""}
    component = parts[-1].split("/")[-1]
    station = parts[-2]
    event_parts = parts[:-2]
    # NGA-West2: "Event, M/D/YYYY, Station, comp"; drop the date from the event name.
    date = ""
    if len(event_parts) > 1 and re.fullmatch(r"\d{1,2}/\d{1,2}/\d{2,4}", event_parts[-1]):
        date = event_parts.pop()
    event = ", ".join(event_parts)
    # Old PEER: "DUZCE 11/12/99, BOLU, 090": the date and time follow the event name.
    old_style = re.match(r"^(.*?)\s+(\d{1,2}/\d{1,2}/\d{2,4})(?:\s+\d{3,4})?$", event)
    if old_style:
        event, date = old_style.group(1), old_style.group(2)
    return {"event": event, "station": station, "component": component, "date": date}


def _units_from_header(header_lines) -> tuple[str, bool]:
    """Acceleration unit named in the header, and whether it was stated (else g is assumed)."""
    for line in header_lines:
        upper = line.upper()
        if "VELOCITY" in upper or "DISPLACEMENT" in upper:
            if "ACCELERATION" not in upper:
                return ("not-acceleration:" + line.strip(), True)
        match = _UNITS.search(line)
        if match:
            unit = match.group(1).strip(".()").upper()
            return ({"G": "g", "GAL": "gal", "CM/S/S": "cm/s^2", "CM/SEC/SEC": "cm/s^2",
                     "CM/S2": "cm/s^2", "CM/S^2": "cm/s^2", "M/S/S": "m/s^2",
                     "M/S2": "m/s^2", "M/S^2": "m/s^2"}.get(unit, unit), True)
    return ("g", False)


def _locate_bad_token(lines, first_data_line, predicate):
    """1-based line number and token of the first token for which predicate(token) is true."""
    for offset, line in enumerate(lines[first_data_line:]):
        for token in line.split():
            if predicate(token):
                return first_data_line + offset + 1, token
    return None, None


def _line_of_value(lines, first_data_line, ordinal):
    """1-based line number holding the ordinal-th (1-based) data value (or the last data line)."""
    count, last = 0, first_data_line
    for offset, line in enumerate(lines[first_data_line:]):
        n_tokens = len(line.split())
        if n_tokens:
            last = first_data_line + offset + 1
        count += n_tokens
        if count >= ordinal:
            return first_data_line + offset + 1
    return last


def _not_a_float(token):
    try:
        float(token)
        return False
    except ValueError:
        return True


def _not_finite(token):
    try:
        return not math.isfinite(float(token))
    except ValueError:
        return False


def parse_peer_at2(source, headonly: bool = False):
    """Parse a PEER AT2 file into (acceleration [m/s^2] array, dt [s], header dict).

    Raises
    ------
    RecordError
        Naming the file, the line and what was expected, for: empty or binary files, a missing
        NPTS/DT line, missing or non-positive DT, non-numeric or non-finite values, and fewer or
        more values than NPTS.
    """
    raw, name = read_source(source)
    if not raw.strip():
        raise RecordError(name, "file is empty; expected a PEER AT2 header and acceleration values")
    if b"\x00" in raw[:HEAD_BYTES]:
        raise RecordError(name, "file is binary (contains NUL bytes); expected a PEER AT2 text file")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    lines = _split_lines(text)

    found = _find_npts_dt(lines)
    if found is None:
        _explain_missing_header(lines, name)
    header_index, npts_text, dt_text = found
    npts = int(npts_text)
    try:
        dt = float(dt_text.rstrip(","))
    except ValueError:
        raise RecordError(name, f"DT {dt_text!r} is not a number; expected a time step in seconds",
                          line=header_index + 1) from None
    if not (math.isfinite(dt) and dt > 0):
        raise RecordError(name, f"DT = {dt_text} is not a positive time step; expected DT > 0 s",
                          line=header_index + 1)
    if npts <= 0:
        raise RecordError(name, f"NPTS = {npts} is not a positive number of samples",
                          line=header_index + 1)

    header_lines = lines[:header_index + 1]
    unit, stated = _units_from_header(header_lines)
    if unit.startswith("not-acceleration:"):
        raise RecordError(name, "header describes velocity or displacement, not acceleration "
                          f"({unit.split(':', 1)[1]!r}); expected an acceleration (AT2) file", line=3)
    try:
        factor = acceleration_factor(unit)
    except ValueError as error:
        raise RecordError(name, str(error), line=3) from None

    station_info = _parse_station_line(lines[1] if header_index >= 1 else "")
    filter_match = _FILTER_TEXT.search(lines[header_index].strip())
    header = {
        "title": lines[0].strip(),
        "event": station_info.get("event", ""),
        "date": station_info.get("date", ""),
        "station": station_info.get("station", ""),
        "component": station_info.get("component", ""),
        "units_in_file": unit,
        "units_stated": stated,
        "npts": npts,
        "dt": dt,
        "filter": filter_match.group(1).strip(" ,") if filter_match else "",
        "header_lines": header_index + 1,
    }
    if headonly:
        return np.empty(0), dt, header

    first_data_line = header_index + 1
    tokens = " ".join(lines[first_data_line:]).split()
    try:
        values = np.array(tokens, dtype=np.float64)
    except ValueError:
        line_no, token = _locate_bad_token(lines, first_data_line, _not_a_float)
        raise RecordError(name, f"value {token!r} is not a number; expected NPTS = {npts} "
                          "numeric acceleration values after the header", line=line_no) from None
    if not np.all(np.isfinite(values)):
        line_no, token = _locate_bad_token(lines, first_data_line, _not_finite)
        raise RecordError(name, f"value {token!r} is not finite; expected finite accelerations",
                          line=line_no)
    if values.size < npts:
        raise RecordError(name, f"truncated data: found {values.size} values but the header says "
                          f"NPTS = {npts}", line=_line_of_value(lines, first_data_line, values.size))
    if values.size > npts:
        raise RecordError(name, f"found {values.size} values but the header says NPTS = {npts}; "
                          "expected exactly NPTS values (first extra value on this line)",
                          line=_line_of_value(lines, first_data_line, npts + 1))
    return values * factor, dt, header


def _explain_missing_header(lines, name):
    """Raise the most specific RecordError for a file whose NPTS/DT line was not found."""
    for index, line in enumerate(lines[:HEADER_SEARCH_LINES]):
        npts = _NPTS_ONLY.search(line)
        dt = _DT_ONLY.search(line)
        if npts and not dt:
            raise RecordError(name, "DT is missing from the NPTS line; expected 'NPTS= n, DT= dt SEC'",
                              line=index + 1)
        if dt and not npts:
            raise RecordError(name, "NPTS is missing; expected 'NPTS= n, DT= dt SEC'", line=index + 1)
        if npts and dt:
            raise RecordError(name, f"cannot read NPTS/DT from {line.strip()!r}; expected "
                              "'NPTS= n, DT= dt SEC' with NPTS a whole number and DT > 0",
                              line=index + 1)
    raise RecordError(name, f"no NPTS/DT line in the first {HEADER_SEARCH_LINES} lines; expected a "
                      "PEER AT2 header ('NPTS= n, DT= dt SEC' or 'n dt NPTS, DT')")


def read_peer_at2(filename, headonly: bool = False, **kwargs):
    """Read a PEER AT2 file into an ``obspy.Stream`` (acceleration in m/s^2).

    This is the ``readFormat`` hook obspy calls for format ``PEER_AT2``.
    """
    data, dt, header = parse_peer_at2(filename, headonly=headonly)
    trace = Trace(data=data)
    trace.stats.delta = dt
    trace.stats.station = header["station"]
    trace.stats.channel = header["component"]
    if headonly:
        trace.stats.npts = header["npts"]
    trace.stats.units = "m/s^2"
    trace.stats.quantity = "acceleration"
    trace.stats.peer_at2 = AttribDict(header)
    trace.stats._format = "PEER_AT2"
    return Stream([trace])
