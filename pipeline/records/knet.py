"""rockfrag.records.knet - K-NET and KiK-net ASCII files (NIED): recognised by content, header checked first.

Input : a file. Output: ``is_knet`` (the file starts with NIED's ``Origin Time`` line, whatever its name:
        ``AKT0139608110312.EW``, ``IWTH270803140843.UD2``, ...) and ``check_header``, which raises a
        ``RecordError`` naming the header line, its field and the reason where obspy's reader would stop with
        a bare exception (a ``ZeroDivisionError`` for a scale factor ``2000(gal)/0``) or misread the file.
        obspy reads the samples (``obspy.read(path, format="KNET")``, in ``rockfrag.records``).

The header is 17 lines, in this order (obspy.io.nied.knet): ``Origin Time``, ``Lat.``, ``Long.``, ``Depth.
(km)``, ``Mag.``, ``Station Code``, ``Station Lat.``, ``Station Long.``, ``Station Height(m)``, ``Record Time``,
``Sampling Freq(Hz)``, ``Duration Time(s)``, ``Dir.``, ``Scale Factor``, ``Max. Acc. (gal)``, ``Last
Correction``, ``Memo.``; the scale factor ``N(gal)/D`` turns counts into gal (N/D gal per count).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

from rockfrag.errors import RecordError

FIRST_LINE = "Origin Time"
"""What a K-NET/KiK-net ASCII file starts with (obspy's own test)."""

_DATE = r"\d{4}/\d{1,2}/\d{1,2} \d{1,2}:\d{2}:\d{2}"
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"

HEADER: tuple[tuple[str, str, str], ...] = (
    # (label, pattern of the value after the label, what it must be)
    ("Origin Time", _DATE, "a date and time YYYY/MM/DD hh:mm:ss (JST)"),
    ("Lat.", _NUMBER, "the epicentre's latitude [deg]"),
    ("Long.", _NUMBER, "the epicentre's longitude [deg]"),
    ("Depth. (km)", _NUMBER, "the depth [km]"),
    ("Mag.", _NUMBER, "the magnitude"),
    ("Station Code", r"\S{1,7}", "a station code of at most 7 characters"),
    ("Station Lat.", _NUMBER, "the station's latitude [deg]"),
    ("Station Long.", _NUMBER, "the station's longitude [deg]"),
    ("Station Height(m)", _NUMBER, "the station's height [m]"),
    ("Record Time", _DATE, "a date and time YYYY/MM/DD hh:mm:ss (JST)"),
    ("Sampling Freq(Hz)", r"(?P<rate>\d+)Hz", "a whole number of Hz > 0, e.g. 100Hz"),
    ("Duration Time(s)", _NUMBER, "the duration [s]"),
    ("Dir.", r"\S+", "a direction (N-S, E-W, U-D, or 1-6 for KiK-net)"),
    ("Scale Factor", rf"(?P<numerator>{_NUMBER})\(gal\)/(?P<denominator>{_NUMBER})",
     "N(gal)/D with N and D > 0: N/D gal per count, e.g. 2000(gal)/8388608"),
    ("Max. Acc. (gal)", _NUMBER, "the peak acceleration [gal]"),
    ("Last Correction", _DATE, "a date and time YYYY/MM/DD hh:mm:ss (JST)"),
    ("Memo.", r".*", "a comment (may be empty)"),
)
"""The header's lines: each label, the pattern its value must match, and what it must be (for the message)."""


def is_knet(path: str | Path) -> bool:
    """True when ``path`` is a file that starts with NIED's ``Origin Time`` line (never raises)."""
    try:
        with open(path, "rb") as handle:
            return handle.read(len(FIRST_LINE)) == FIRST_LINE.encode()
    except OSError:
        return False


def check_header(path: str | Path) -> None:
    """Check a K-NET/KiK-net file's 17 header lines before obspy reads it.

    Parameters
    ----------
    path : str or Path
        The file (``is_knet`` true).

    Raises
    ------
    RecordError
        Naming the line (1-based) and the field: a line missing or out of order, a value that is not what the
        field holds (see ``HEADER``), a sampling frequency of 0 Hz, or a scale factor whose numerator or
        denominator is not a number > 0 (``2000(gal)/0`` is a division by zero).
    """
    try:
        lines = Path(path).read_text(encoding="ascii", errors="replace").splitlines()
    except OSError as error:
        raise RecordError(path, f"cannot read it ({error.strerror})") from None
    for number, (label, pattern, meaning) in enumerate(HEADER, start=1):
        line = lines[number - 1] if number <= len(lines) else ""
        if not line.startswith(label):
            found = f"found {line.strip()[:40]!r}" if line.strip() else "found nothing"
            raise RecordError(path, f"K-NET header: expected the {label!r} line here ({found})", line=number)
        value = line[len(label):].strip()
        match = re.fullmatch(pattern, value)
        if match is None:
            raise RecordError(path, f"K-NET header field {label!r}: {value!r} is not {meaning}", line=number)
        if label == "Sampling Freq(Hz)" and int(match["rate"]) <= 0:
            raise RecordError(path, f"K-NET header field {label!r}: {value!r}; the sampling frequency must be "
                              "> 0 Hz", line=number)
        if label == "Scale Factor":
            for part in ("numerator", "denominator"):
                factor = float(match[part])
                if not (math.isfinite(factor) and factor > 0):
                    raise RecordError(path, f"K-NET header field {label!r}: {value!r} has the {part} "
                                      f"{match[part]}; expected {meaning}", line=number)
