"""rockfrag.records.csmip - CSMIP Volume 1 ("Uncorrected Accelerogram Data") files, as an obspy waveform plugin.

Input : a CSMIP/CGS Volume 1 text file (the format of the California Strong Motion Instrumentation
        Program, also written by CGS for SCSN stations: ``.RAW``, ``.V1``). One block per channel, each:
        a 13-line text header, an integer header and a real header (fixed-width numbers), a data-start
        line (``35430 Accelerogram points at 100 pts/sec in units of g.  Format: (8f9.6)``), the samples
        in the Fortran format that line states, and an end line (``/& ... End of Data for ... Channel 1``).
Output: an ``obspy.Stream`` with one ``Trace`` per channel of ground acceleration in m/s^2.

What is taken from the header, and where:
- units: the data-start line (``in units of g``), converted to m/s^2 here;
- time step: the data-start line (``at 100 pts/sec``); number of samples: the same line, checked against
  the text header's ``No. of Points``;
- orientation: the text header's ``Chan  1:  90 Deg`` (a horizontal sensor pointing 90 degrees clockwise
  from north), ``Chan  3:  Up`` (vertical, up positive) or ``Down`` (vertical, down positive: stored
  negated, up positive, and the flip is written to ``stats.processing``);
- station and SEED codes: the ``EVENT.NET.STA.LOC.CHA`` token and ``Start time: m/dd/yy, hh:mm:ss.s UTC``
  of header line 4, and ``Station Id. CCC  35.525N, 117.365W`` of line 5. The channel code is the band and
  instrument codes of line 4 (``HN``; ``N`` for an accelerometer if line 4 gives only the band) and the
  orientation code: ``Z`` for Up/Down, ``N`` for 0/360 degrees, ``E`` for 90 degrees, else ``1``/``2``
  in channel order;
- the header's ``Max = -.567 g, at 39.410 sec.``: the samples' signed peak must agree with it to the
  header's three decimals (a check that the file was read as written).

The integer and real headers are read as fixed-width numbers (their fields may touch, as in
``.4778242-999.00000``) and kept in ``stats.csmip.integer_header`` / ``real_header``, undecoded.
Volume 2 (corrected) and Volume 3 (spectra) files are not read: ``is_csmip`` does not recognise them.

Registered with obspy through the entry-point group ``obspy.plugin.waveform`` (see pyproject.toml),
so ``obspy.read("CICCC.RAW")`` detects the format by itself.
"""

from __future__ import annotations

import math
import re

import numpy as np
from obspy import Stream, Trace, UTCDateTime
from obspy.core.util import AttribDict

from rockfrag.errors import RecordError
from rockfrag.records.sources import HEAD_BYTES, read_head, read_source
from rockfrag.units import acceleration_factor

V1_MARKER = "UNCORRECTED ACCELEROGRAM DATA"
"""The first line of every channel block of a Volume 1 file starts with this (any case)."""

TEXT_HEADER_LINES = 13
"""Lines of the text header of a Volume 1 channel block."""

INTEGER_FIELD = 5
REAL_FIELD = 10
"""Widths of the integer header's and real header's fields [characters]."""

HEADER_SEARCH_LINES = 40
"""The data-start line must come within this many lines after the text header."""

_LINE_BREAK = re.compile(r"\r*\n|\r")
_CHANNEL = re.compile(r"^\s*Chan\s+(\d+)\s*:\s*(.*?)\s*$", re.IGNORECASE)
_DEGREES = re.compile(r"^(\d+(?:\.\d*)?)\s*Deg", re.IGNORECASE)
_START = re.compile(r"Start time:\s*(\d{1,2})/\s*(\d{1,2})/\s*(\d{2,4}),\s*(\d{1,2}):\s*(\d{1,2}):\s*(\d+(?:\.\d*)?)"
                    r"\s*UTC", re.IGNORECASE)
_STATION = re.compile(r"Station\s+(?:Id\.|No\.)\s*(\S+)\s+(\d+(?:\.\d*)?)\s*([NS])\s*,\s*(\d+(?:\.\d*)?)\s*([EW])",
                      re.IGNORECASE)
_POINTS = re.compile(r"No\.\s*of\s*Points\s*=\s*(\d+)", re.IGNORECASE)
_MAX = re.compile(r"Max\s*=\s*([-+]?\d*\.?\d+)\s*(\S+?)\s*,", re.IGNORECASE)
_DATA_START = re.compile(r"^\s*(\d+)\s+Accelerogram\s+points\s+at\s+(\d+(?:\.\d*)?)\s*(?:pts|points|samples)\s*/\s*sec"
                         r".*?in\s+units\s+of\s+(\S+?)\.?\s+Format:\s*\(\s*(\d+)\s*[FE]\s*(\d+)\s*\.\s*(\d+)\s*\)",
                         re.IGNORECASE)
_END = re.compile(r"End\s+of\s+Data", re.IGNORECASE)
_UNIT_NAMES = {"g": "g", "cm/sec2": "cm/s^2", "cm/sec/sec": "cm/s^2", "cm/s2": "cm/s^2", "cm/s/s": "cm/s^2",
               "gal": "gal", "m/sec2": "m/s^2", "m/s2": "m/s^2"}


def _read_text(source) -> tuple[str, str]:
    """The file's text and a name for messages; ``source`` is a path or a binary file object."""
    data, name = read_source(source)
    if b"\x00" in data[:HEAD_BYTES]:
        raise RecordError(name, "file is binary (contains NUL bytes); expected a CSMIP Volume 1 text file")
    return data.decode("latin-1"), name


def is_csmip(source) -> bool:
    """True if ``source`` (path or binary file object) starts like a CSMIP Volume 1 file. Never raises."""
    try:
        head = read_head(source)
        if not head:
            return False
        lines = _LINE_BREAK.split(head)
        return (lines[0].strip().upper().startswith(V1_MARKER)
                and any(_CHANNEL.match(line) for line in lines[1:TEXT_HEADER_LINES]))
    except Exception:  # detection must never raise, whatever the input (obspy contract)
        return False


def _fixed_width(lines: list[str], width: int) -> list[str]:
    """The non-blank fixed-width fields of ``lines`` (fields may touch: ``.4778242-999.00000``)."""
    fields = []
    for line in lines:
        text = line.rstrip()
        fields.extend(field for start in range(0, len(text), width) if (field := text[start:start + width].strip()))
    return fields


def _numbers(fields: list[str], kind: type, name: str, line: int) -> list:
    try:
        return [kind(field) for field in fields]
    except ValueError:
        bad = next(f for f in fields if not _is_number(f, kind))
        raise RecordError(name, f"header value {bad!r} is not a number", line=line) from None


def _is_number(text: str, kind: type) -> bool:
    try:
        kind(text)
        return True
    except ValueError:
        return False


def _orientation(text: str, name: str, line: int) -> tuple[str, float | None, float]:
    """(orientation as written, azimuth [deg] or None, dip [deg]: 0 horizontal, -90 up, 90 down)."""
    upper = text.split()[0].upper() if text.split() else ""
    if upper == "UP":
        return "Up", None, -90.0
    if upper in ("DOWN", "DN"):
        return "Down", None, 90.0
    degrees = _DEGREES.match(text)
    if degrees:
        return text.strip(), float(degrees.group(1)) % 360.0, 0.0
    raise RecordError(name, f"channel orientation {text.strip()!r} is not understood; expected 'NNN Deg' "
                      "(a horizontal azimuth), 'Up' or 'Down'", line=line)


def _start_time(line: str) -> UTCDateTime | None:
    match = _START.search(line)
    if not match:
        return None
    month, day, year, hour, minute, second = match.groups()
    year = int(year)
    if year < 100:  # two-digit years: CSMIP records start in the 1930s
        year += 1900 if year >= 30 else 2000
    return UTCDateTime(year, int(month), int(day), int(hour), int(minute)) + float(second)


def _codes(line: str) -> dict:
    """Event id and SEED codes from the first token of header line 4 (``38457511.CI.CCC.--.HN``), if there."""
    token = line.split()[0] if line.split() else ""
    parts = token.split(".")
    if len(parts) != 5:
        return {}
    event_id, network, station, location, channel = parts
    return {"event_id": event_id, "network": network, "station": station,
            "location": "" if set(location) <= {"-"} else location, "channel_prefix": channel}


def _channel_code(prefix: str, dip: float, azimuth: float | None, horizontal_index: int) -> str:
    band = prefix[:1] or "H"
    instrument = prefix[1:2] or "N"  # the file holds acceleration: N (accelerometer)
    if dip != 0.0:
        return band + instrument + "Z"
    if math.isclose(azimuth, 0.0, abs_tol=1e-6) or math.isclose(azimuth, 360.0, abs_tol=1e-6):
        return band + instrument + "N"
    if math.isclose(azimuth, 90.0, abs_tol=1e-6):
        return band + instrument + "E"
    return band + instrument + str(horizontal_index)


def _read_samples(lines: list[str], first: int, npts: int, per_line: int, width: int,
                  name: str) -> tuple[np.ndarray, int]:
    """The ``npts`` samples from ``lines[first]`` on, ``per_line`` fields of ``width`` characters a line.

    Returns the samples (as written, float64) and the index of the line after the channel's end line.
    """
    n_lines = -(-npts // per_line)
    body = lines[first:first + n_lines]
    values = []
    for offset, line in enumerate(body):
        if _END.search(line):
            raise RecordError(name, f"truncated data: {len(values)} values before the end line; the data-start "
                              f"line says {npts}", line=first + offset + 1)
        for column in range(per_line):
            field = line[column * width:(column + 1) * width].strip()
            if not field:
                continue
            try:
                values.append(float(field))
            except ValueError:
                raise RecordError(name, f"value {field!r} is not a number; expected {npts} values in "
                                  f"{per_line} fields of {width} characters", line=first + offset + 1) from None
    if len(values) != npts:
        raise RecordError(name, f"found {len(values)} values but the data-start line says {npts}",
                          line=first + len(body))
    end = first + n_lines
    if end >= len(lines) or not _END.search(lines[end]):
        raise RecordError(name, f"expected the channel's end line ('End of Data for ... Channel') after {npts} "
                          "values", line=min(end, len(lines) - 1) + 1)
    data = np.asarray(values, dtype=np.float64)
    if not np.all(np.isfinite(data)):
        raise RecordError(name, "contains NaN or infinite values; expected finite accelerations", line=first + 1)
    return data, end + 1


def _check_peak(text: list[str], data: np.ndarray, unit: str, name: str, line: int) -> float | None:
    """The header's signed ``Max`` [file units], after checking the samples' peak against it to its decimals."""
    peak = next((m for header_line in text if (m := _MAX.search(header_line))), None)
    if peak is None or _UNIT_NAMES.get(peak.group(2).lower(), peak.group(2)) != unit:
        return None
    decimals = len(peak.group(1).partition(".")[2])
    found = float(np.max(np.abs(data)))
    if abs(found - abs(float(peak.group(1)))) > 0.5 * 10.0 ** -decimals + 1e-9:
        raise RecordError(name, f"the samples' peak {found:.{decimals + 1}f} {unit} disagrees with the "
                          f"header's Max = {peak.group(1)} {unit}", line=line)
    return float(peak.group(1))


def _read_channel(lines: list[str], start: int, name: str, horizontal_index: int) -> tuple[Trace, int]:
    """Parse the channel block starting at ``lines[start]``; returns (trace, index of the next line)."""
    text = lines[start:start + TEXT_HEADER_LINES]
    if len(text) < TEXT_HEADER_LINES:
        raise RecordError(name, f"text header has {len(text)} lines; expected {TEXT_HEADER_LINES}", line=start + 1)
    channel_line = next(((i, m) for i, line in enumerate(text) if (m := _CHANNEL.match(line))), None)
    if channel_line is None:
        raise RecordError(name, "no 'Chan  N: orientation' line in the text header", line=start + 1)
    orientation, azimuth, dip = _orientation(channel_line[1].group(2), name, start + channel_line[0] + 1)

    data_index = next((i for i in range(start + TEXT_HEADER_LINES,
                                        min(len(lines), start + TEXT_HEADER_LINES + HEADER_SEARCH_LINES))
                       if _DATA_START.match(lines[i])), None)
    if data_index is None:
        raise RecordError(name, "no data-start line ('N Accelerogram points at R pts/sec in units of U. "
                          f"Format: (8f9.6)') within {HEADER_SEARCH_LINES} lines after the text header",
                          line=start + TEXT_HEADER_LINES + 1)
    npts_text, rate_text, unit_text, per_line, width, _decimals = _DATA_START.match(lines[data_index]).groups()
    npts, rate, per_line, width = int(npts_text), float(rate_text), int(per_line), int(width)
    if npts <= 0 or not rate > 0 or per_line <= 0 or width <= 0:
        raise RecordError(name, "data-start line needs a positive number of points, sampling rate and format",
                          line=data_index + 1)
    unit = _UNIT_NAMES.get(unit_text.lower(), unit_text)
    try:
        factor = acceleration_factor(unit)
    except ValueError as error:
        raise RecordError(name, f"units {unit_text!r}: {error}", line=data_index + 1) from None
    stated = next((m for line in text if (m := _POINTS.search(line))), None)
    if stated and int(stated.group(1)) != npts:
        raise RecordError(name, f"text header says No. of Points = {stated.group(1)} but the data-start line "
                          f"says {npts}", line=data_index + 1)

    # integer header (I5 fields, no decimal points) then real header (F10 fields): the lines in between
    between = lines[start + TEXT_HEADER_LINES:data_index]
    n_integer = next((i for i, line in enumerate(between) if "." in line), len(between))
    integer_lines, real_lines = between[:n_integer], between[n_integer:]
    integers = _numbers(_fixed_width(integer_lines, INTEGER_FIELD), int, name,
                        start + TEXT_HEADER_LINES + 1)
    reals = _numbers(_fixed_width(real_lines, REAL_FIELD), float, name,
                     start + TEXT_HEADER_LINES + len(integer_lines) + 1)

    data, end = _read_samples(lines, data_index + 1, npts, per_line, width, name)
    stated_peak = _check_peak(text, data, unit, name, start + 1)

    codes = _codes(text[3])
    station_match = next((m for line in text if (m := _STATION.search(line))), None)
    header = AttribDict({
        "volume": "V1", "title": text[0].strip(), "record": re.sub(r"\(.*\)\s*$", "", text[1]).strip(),
        "channel_number": int(channel_line[1].group(1)), "orientation": orientation,
        "azimuth": azimuth, "dip": dip, "vertical": dip != 0.0, "units_in_file": unit,
        "station_name": re.split(r"\s{2,}", text[5].strip())[0],
        "event_id": codes.get("event_id", ""), "stated_peak": stated_peak, "npts": npts,
        "sampling_rate": rate, "integer_header": integers, "real_header": reals,
    })
    if station_match:
        latitude = float(station_match.group(2)) * (1 if station_match.group(3).upper() == "N" else -1)
        longitude = float(station_match.group(4)) * (1 if station_match.group(5).upper() == "E" else -1)
        header.update({"station_code": station_match.group(1), "latitude": latitude, "longitude": longitude})

    sign = 1.0
    processing = []
    if orientation == "Down":
        sign = -1.0
        processing.append("rockfrag csmip: channel points Down; samples negated to store up positive")
    trace = Trace(data=sign * data * factor)
    trace.stats.sampling_rate = rate
    trace.stats.network = codes.get("network", "")
    trace.stats.station = codes.get("station") or header.get("station_code", "")
    trace.stats.location = codes.get("location", "")
    trace.stats.channel = _channel_code(codes.get("channel_prefix", ""), dip, azimuth, horizontal_index)
    start_time = _start_time(text[3])
    if start_time is not None:
        trace.stats.starttime = start_time
    trace.stats.units = "m/s^2"
    trace.stats.quantity = "acceleration"
    trace.stats.csmip = header
    trace.stats._format = "CSMIP"
    if processing:
        trace.stats.processing = processing
    return trace, end


def read_csmip(filename, headonly: bool = False, units: str | None = None, dt: float | None = None, **kwargs):
    """Read a CSMIP Volume 1 file into an ``obspy.Stream``, one trace per channel, acceleration in m/s^2.

    This is the ``readFormat`` hook obspy calls for format ``CSMIP``; rockfrag calls it with ``units`` and
    ``dt``, which are ignored (the header states both).

    Parameters
    ----------
    filename : str, Path or binary file object
        The Volume 1 file.
    headonly : bool
        Accepted for obspy's interface; the samples are read anyway (the header's peak is checked on them).

    Returns
    -------
    obspy.Stream
        One ``Trace`` per channel block, in file order: ground acceleration [m/s^2], SEED codes and start
        time from the header, ``stats.csmip`` with the orientation (``azimuth`` [deg clockwise from north]
        or None, ``dip`` [deg]: 0 horizontal, -90 up, 90 down; ``vertical``) and the rest of the header.

    Raises
    ------
    RecordError
        Naming the file and line: not a Volume 1 block, an orientation that is not understood, a missing
        data-start or end line, a number of values other than stated, units that are not an acceleration,
        or samples whose peak disagrees with the header's ``Max``.
    """
    text, name = _read_text(filename)
    lines = _LINE_BREAK.split(text)
    traces, index, horizontals = [], 0, 0
    while index < len(lines):
        if not lines[index].strip():
            index += 1
            continue
        if not lines[index].strip().upper().startswith(V1_MARKER):
            what = "a CSMIP Volume 1 file" if traces else "a CSMIP Volume 1 file (first line 'Uncorrected " \
                                                          "Accelerogram Data')"
            raise RecordError(name, f"expected {what}; found {lines[index].strip()[:60]!r}", line=index + 1)
        trace, index = _read_channel(lines, index, name, horizontals + 1)
        if not trace.stats.csmip.vertical:
            horizontals += 1
        traces.append(trace)
    if not traces:
        raise RecordError(name, "file is empty; expected a CSMIP Volume 1 file")
    return Stream(traces)
