"""pipeline.records - stage 1: record files -> acceleration traces in m/s^2 with metadata.

Input : a record set name from the catalogue (``far-field``, ``near-field-pulse``, ``bolu``, ...),
        a folder of the user's own files, or single files, in any registered format.
Output: ``Record`` objects (an ``obspy.Trace`` of ground acceleration [m/s^2] plus catalogue
        metadata) and, for a batch, the list of ``RecordError`` for files that could not be read.

Formats: rockfrag's own readers (PEER AT2, text/CSV) sit in ``FORMATS[name] = RecordFormat(is_format,
read_format)``, registered at the bottom of this module and tried in that order; their readers take
the user's ``units`` and ``dt``. Every other format goes through ``obspy.read``, which detects its
built-in formats (MiniSEED, SAC, K-NET/KiK-net, ...) and third-party ones through obspy's own
entry-point group ``obspy.plugin.waveform``: that is the one extension mechanism (the former
``pipeline.record_formats`` group is gone). Units: from the file where it states them (PEER AT2: g;
K-NET/KiK-net: the header's scale factor in gal; text: a header such as ``acc [g]``), else the user's.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, NamedTuple

import numpy as np

from pipeline.errors import ManifestError, RecordError
from pipeline.records import peer_at2
from pipeline.records import text as text_records
from pipeline.records.manifest import CatalogueEntry, load_catalogue, sha256_of, verify
from pipeline.units import acceleration_factor

RECORDS_DIR = Path(os.environ.get("ROCKFRAG_RECORDS", Path(__file__).resolve().parents[2] / "records"))
"""Folder holding the shipped records and ``MANIFEST.csv`` (override with $ROCKFRAG_RECORDS)."""

RECORD_SUFFIXES = {".at2"}
"""File endings picked up when a folder is given, plus text records (``text.TEXT_SUFFIXES`` whose content
is one or two numeric columns); other formats: name the files."""


class RecordFormat(NamedTuple):
    is_format: Callable  # (path) -> bool, never raises
    read_format: Callable  # (path, units=None, dt=None) -> obspy.Stream with acceleration in m/s^2


FORMATS: dict[str, RecordFormat] = {}


def register_format(name: str, is_format: Callable, read_format: Callable) -> None:
    """Make a record format available to ``read_record`` (auto-detected in registration order)."""
    FORMATS[name] = RecordFormat(is_format, read_format)


def list_formats() -> list[str]:
    """Names of the record formats this installation reads itself (plus obspy's formats)."""
    return list(FORMATS)


def detect_format(path) -> str | None:
    """Name of the first registered format that recognises ``path``, or None."""
    for name, fmt in FORMATS.items():
        if fmt.is_format(path):
            return name
    return None


@dataclass
class Record:
    """One horizontal acceleration component, in SI units.

    Attributes
    ----------
    id : str
        Catalogue id (e.g. ``DUZCE/BOL090``) or file stem for user files.
    trace : obspy.Trace
        Ground acceleration [m/s^2]; ``stats.processing`` holds the processing provenance.
    metadata : dict
        event, year, magnitude, station, component, sets, source, sha256, file.
    """

    id: str
    trace: object
    metadata: dict = field(default_factory=dict)

    @property
    def acceleration(self) -> np.ndarray:
        """Ground acceleration samples [m/s^2], shape (npts,)."""
        return self.trace.data

    @property
    def dt(self) -> float:
        """Time step [s]."""
        return float(self.trace.stats.delta)

    @property
    def duration(self) -> float:
        """Record length [s]."""
        return self.dt * (self.trace.stats.npts - 1)

    def with_trace(self, trace) -> "Record":
        return Record(self.id, trace, dict(self.metadata))


def read_record(path, format: str | None = None, units: str | None = None, dt: float | None = None):
    """Read one acceleration record into an ``obspy.Trace`` in m/s^2.

    Parameters
    ----------
    path : str or Path
        The record file.
    format : str, optional
        A registered format name (see ``list_formats()``) or an obspy format name; detected if omitted.
    units : str, optional
        Acceleration units of the file's samples (``g``, ``m/s^2``, ``cm/s^2``, ``gal``). Required for
        formats that do not state them (text without a unit in its header, MiniSEED, SAC, ...); ignored
        for PEER AT2 (g) and K-NET/KiK-net (the header's scale factor in gal), whose headers state them.
    dt : float, optional
        Time step [s] of one-column text records (files with a time column or a header state theirs).

    Raises
    ------
    RecordError
        The file is missing, not in a readable format, or its content is invalid.
    """
    path = Path(path)
    if not path.is_file():
        raise RecordError(path, "file not found")
    name = format if format in FORMATS else (None if format else detect_format(path))
    if name is not None:
        stream = FORMATS[name].read_format(path, units=units, dt=dt)
        return stream[0]
    return _read_with_obspy(path, format, units)


def _read_with_obspy(path, format, units):
    import obspy

    try:
        stream = obspy.read(str(path), format=format)
    except Exception as error:  # obspy raises TypeError/ValueError/... for unknown content
        raise RecordError(path, f"not a readable record ({type(error).__name__}: {error}); "
                          f"expected one of {', '.join(list_formats())} or a format obspy reads") from None
    if len(stream) != 1:
        raise RecordError(path, f"holds {len(stream)} traces; expected one horizontal acceleration "
                          "component per file")
    trace = stream[0]
    if trace.stats._format == "KNET":
        # obspy's calib is the header's scale factor with gal -> m/s^2 applied; NIED's counts carry a
        # constant offset (the header's Max. Acc. is taken after removing the mean)
        units = "m/s^2"
        trace.data = np.asarray(trace.data, dtype=np.float64) - np.mean(trace.data)
    if units is None:
        units = trace.stats.get("units")
    if units is None:
        raise RecordError(path, f"acceleration units unknown for format {trace.stats._format}; "
                          "state them (units='g', 'm/s^2', 'cm/s^2' or 'gal')")
    try:
        factor = acceleration_factor(units)
    except ValueError as error:
        raise RecordError(path, str(error)) from None
    data = np.asarray(trace.data, dtype=np.float64) * float(trace.stats.calib) * factor
    if not np.all(np.isfinite(data)):
        raise RecordError(path, "contains NaN or infinite samples; expected finite accelerations")
    trace.data = data
    trace.stats.calib = 1.0
    trace.stats.units = "m/s^2"
    trace.stats.quantity = "acceleration"
    return trace


# ---------------------------------------------------------------- catalogue and record sets

def catalogue(records_dir=None) -> list[CatalogueEntry]:
    """The shipped catalogue (``records/MANIFEST.csv``)."""
    return load_catalogue(Path(records_dir or RECORDS_DIR) / "MANIFEST.csv")


def record_sets(records_dir=None) -> dict[str, list[str]]:
    """Named record sets -> record ids, from the catalogue's ``sets`` column (plus ``all``)."""
    sets: dict[str, list[str]] = {}
    entries = catalogue(records_dir)
    for entry in entries:
        for name in entry.sets:
            sets.setdefault(name, []).append(entry.id)
    sets["all"] = [entry.id for entry in entries]
    return sets


def _load_entry(entry: CatalogueEntry) -> Record:
    trace = read_record(entry.path, units=entry.units)
    return Record(entry.id, trace, entry.metadata())


def _load_user_file(path: Path, units, dt=None) -> Record:
    trace = read_record(path, units=units, dt=dt)
    header = trace.stats.get("peer_at2") or trace.stats.get("text_record") or {}
    metadata = {"id": path.stem, "file": str(path), "event": header.get("event", ""),
                "year": None, "magnitude": None, "station": header.get("station", trace.stats.station),
                "component": header.get("component", trace.stats.channel), "sets": "user",
                "source": str(path), "units": units or header.get("units_in_file", ""),
                "sha256": sha256_of(path)}
    return Record(path.stem, trace, metadata)


def load_records(selection, records_dir=None, units: str | None = None, verify_checksums=True,
                 dt: float | None = None):
    """Load a record set by name, a folder of files, or a list of these.

    Parameters
    ----------
    selection : str, Path or list
        Set names (``record_sets()``), record ids, folders or files.
    units : str, optional
        Acceleration units for user files in formats that do not state them.
    dt : float, optional
        Time step [s] of the user's one-column text records.
    verify_checksums : bool
        Check catalogue files against their sha256 (a changed file is reported by name).

    Returns
    -------
    records : list of Record
        The records that were read, in catalogue or file-name order, without duplicates.
    failures : list of RecordError
        One per file that could not be read; the other files go on.
    """
    items = [selection] if isinstance(selection, (str, Path)) else list(selection)
    entries = {entry.id: entry for entry in catalogue(records_dir)}
    sets = record_sets(records_dir)
    records, failures, seen = [], [], set()

    def add(loader, key, target):
        if key in seen:
            return
        seen.add(key)
        try:
            records.append(loader(target))
        except RecordError as error:
            failures.append(error)

    for item in items:
        text = str(item)
        if text in sets or text in entries:
            for entry in (entries[i] for i in sets.get(text, [text])):
                problems = verify([entry]) if verify_checksums and entry.id not in seen else []
                if problems:
                    seen.add(entry.id)
                    failures.append(RecordError(entry.path, problems[0].split(": ", 1)[1]))
                else:
                    add(_load_entry, entry.id, entry)
        elif Path(text).is_dir():
            files = sorted(p for p in Path(text).rglob("*")
                           if p.suffix.lower() in RECORD_SUFFIXES or text_records.is_text_record(p))
            if not files:
                raise RecordError(text, f"folder holds no record files ({', '.join(sorted(RECORD_SUFFIXES))}, "
                                  "or text/CSV of one or two numeric columns)")
            for path in files:
                add(lambda p: _load_user_file(p, units, dt), str(path), path)
        elif Path(text).is_file():
            add(lambda p: _load_user_file(p, units, dt), text, Path(text))
        else:
            raise ManifestError(f"unknown record selection {text!r}: not a record set "
                                f"({', '.join(sorted(sets))}), a record id, a folder or a file")
    return records, failures


register_format("PEER_AT2", peer_at2.is_peer_at2, peer_at2.read_peer_at2)
register_format("TEXT", text_records.is_text_record, text_records.read_text_record)
