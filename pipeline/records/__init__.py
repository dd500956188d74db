"""rockfrag.records - stage 1: record files -> acceleration traces in m/s^2 with metadata.

Input : a record set name from the catalogue (``far-field``, ``near-field-pulse``, ``bolu``, ...),
        a folder of the user's own files, or single files, in any registered format.
Output: ``Record`` objects (an ``obspy.Trace`` of ground acceleration [m/s^2] plus catalogue
        metadata) and, for a batch, the list of ``RecordError`` for files that could not be read.

Formats: rockfrag's own readers (PEER AT2, CSMIP Volume 1, ASDF, text/CSV) sit in
``FORMATS[name] = RecordFormat(is_format, read_format)``, registered at the bottom of this module and
tried in that order, then those of installed packages (entry-point group ``rockfrag.record_formats``,
rockfrag.plugins); their readers take the user's ``units`` and ``dt``. Every other format goes
through ``obspy.read``, which detects its built-in formats (MiniSEED, SAC, K-NET/KiK-net, ...) and
third-party ones through obspy's own entry-point group ``obspy.plugin.waveform`` (a reader there gets no
``units`` or ``dt``: the rockfrag group is for formats that need them). Units: from the file where
it states them (PEER AT2: g; K-NET/KiK-net: the header's scale factor in gal; CSMIP: the data-start
line; ASDF: the StationXML response of raw counts; text: a header such as ``acc [g]``), else the user's.

Components: a file may hold several components (CSMIP, ASDF: ``read_stream``); each becomes one ``Record``
whose metadata say its orientation (``rockfrag.records.components``, whose API is re-exported here).
``group_components`` groups records by event and station into H1, H2 and Z; verticals are marked
(``Record.is_vertical``) and sit only in their own record sets (``three-component``), never in the
horizontal ones.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable, NamedTuple

import numpy as np
import obspy

from rockfrag.errors import ManifestError, RecordError
from rockfrag.plugins import GROUPS, Registry
from rockfrag.records import asdf, csmip, knet, peer_at2
from rockfrag.records import text as text_records
from rockfrag.records.components import ComponentGroup as ComponentGroup
from rockfrag.records.components import component_label, header_metadata, orientation_metadata
from rockfrag.records.components import component_labels as component_labels
from rockfrag.records.components import group_components as group_components
from rockfrag.records.components import split_vertical as split_vertical
from rockfrag.records.manifest import CatalogueEntry, load_catalogue, sha256_of, shipped_records_dir, verify
from rockfrag.units import STANDARD_GRAVITY, acceleration_factor
from rockfrag.validation import did_you_mean

RECORDS_DIR = shipped_records_dir()
"""Folder holding the shipped records and ``MANIFEST.csv`` (override with $ROCKFRAG_RECORDS; see
``manifest.shipped_records_dir``)."""

RECORD_SUFFIXES = {".at2"}
"""File endings picked up when a folder is given, plus text records (``text.TEXT_SUFFIXES`` whose content
is one or two numeric columns) and CSMIP Volume 1, ASDF and K-NET/KiK-net ASCII files (by content); other
formats (MiniSEED, SAC, ...): name the files."""


class RecordFormat(NamedTuple):
    """A registered record format: its detector and its reader."""

    is_format: Callable  # (path) -> bool, never raises
    read_format: Callable  # (path, units=None, dt=None) -> obspy.Stream with acceleration in m/s^2


FORMATS: Registry = Registry(GROUPS["record_formats"], RecordFormat)
"""Record formats by name, in the order they are tried: the shipped ones, then the installed packages'."""


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
    """One acceleration component (horizontal, or vertical up positive), in SI units.

    Attributes
    ----------
    id : str
        Catalogue id (e.g. ``DUZCE/BOL090``) or file stem for user files.
    trace : obspy.Trace
        Ground acceleration [m/s^2]; ``stats.processing`` holds the processing provenance.
    metadata : dict
        event, year, magnitude, station, component, sets, source, sha256, file (K-NET/KiK-net and ASDF
        files: also origin_time), and the orientation: ``orientation`` (vertical/horizontal),
        ``azimuth_deg``, ``orientation_from``, ``channel_code`` (``components.orientation_metadata``). For a
        component of a file holding several, ``sha256`` is the file's followed by ``#`` and the trace's SEED
        id (the identity of the record's samples), ``file_sha256`` the file's alone.
    """

    id: str
    trace: obspy.Trace
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

    @property
    def event(self) -> str:
        """The earthquake (catalogue name, or from the file's header)."""
        return str(self.metadata.get("event") or "")

    @property
    def station(self) -> str:
        """The station (catalogue name; ``NET.STA`` for files with SEED codes)."""
        return str(self.metadata.get("station") or "")

    @property
    def component(self) -> str:
        """``H1``, ``H2``, ``Z`` (vertical), or ``H`` (a horizontal of unstated direction): see ``group_components``."""
        return component_label(self.metadata)

    @property
    def is_vertical(self) -> bool:
        """True for a vertical component: not a horizontal input of a study."""
        return self.metadata.get("orientation") == "vertical"

    def with_trace(self, trace: obspy.Trace) -> Record:
        """A copy of this record (same id, a copy of the metadata) holding ``trace``."""
        return Record(self.id, trace, dict(self.metadata))


def read_stream(path: str | Path, format: str | None = None, units: str | None = None,
                dt: float | None = None) -> obspy.Stream:
    """Read every acceleration component of a record file into an ``obspy.Stream`` in m/s^2.

    Parameters and errors as ``read_record``; a CSMIP or ASDF file gives one trace per channel (their
    orientation in ``stats.csmip`` / ``stats.asdf``), other formats one trace.
    """
    path = Path(path)
    if not path.is_file():
        raise RecordError(path, "file not found")
    if path.stat().st_size == 0:
        raise RecordError(path, "file is empty (0 bytes); expected a record")
    name = format if format in FORMATS else (None if format else detect_format(path))
    if name is None and format is None and path.suffix.lower() == ".at2":
        name = "PEER_AT2"  # not recognised, but named as AT2: the reader says what is wrong with it
    if name is not None:
        return FORMATS[name].read_format(path, units=units, dt=dt)
    return obspy.Stream([_read_with_obspy(path, format, units)])


def read_record(path: str | Path, format: str | None = None, units: str | None = None,
                dt: float | None = None) -> obspy.Trace:
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

    Returns
    -------
    obspy.Trace
        Ground acceleration [m/s^2] (``stats.units``), with the format's header in ``stats``.

    Raises
    ------
    RecordError
        The file is missing, not in a readable format, its content is invalid, or it holds several
        components (read those with ``read_stream``).
    """
    stream = read_stream(path, format, units, dt)
    if len(stream) != 1:
        raise RecordError(path, f"holds {len(stream)} components ({', '.join(t.id for t in stream)}); "
                          "read them with read_stream")
    return stream[0]


def _read_with_obspy(path, format, units):
    knet_file = format in (None, "KNET") and knet.is_knet(path)
    if knet_file:
        knet.check_header(path)  # obspy's reader stops with a bare exception on a bad header
    try:
        stream = obspy.read(str(path), format="KNET" if knet_file else format)
    except Exception as error:  # obspy raises TypeError/ValueError/... for unknown content
        reason = " ".join(str(error).split()) or type(error).__name__
        if knet_file:
            raise RecordError(path, f"K-NET/KiK-net samples after the header could not be read ({reason}); "
                              "expected whole numbers of counts, 8 a line") from None
        if format is None and isinstance(error, TypeError) and "Unknown format" in str(error):
            raise RecordError(path, f"not a record format rockfrag or obspy recognises; expected one of "
                              f"{', '.join(list_formats())}, K-NET/KiK-net or another format obspy reads "
                              "(MiniSEED, SAC, ...)") from None
        raise RecordError(path, f"not a readable record ({type(error).__name__}: {reason}); "
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


# ---------------------------------------------------------------- plausibility of a record

MIN_SAMPLES = 3
"""Fewer samples are not a ground motion (a longer record that processing cannot handle is skipped
there, with the step that failed)."""

DT_RANGE = (1e-4, 0.5)
"""Plausible time steps of strong-motion records [s] (published records use 0.001 to 0.05 s)."""

MAX_PEAK_G = 20.0
"""Largest plausible peak ground acceleration [g]; the largest ever recorded is below 5 g."""


def check_record(record) -> None:
    """``RecordError`` naming the file if ``record`` cannot be a ground-acceleration record.

    Checks the number of samples, the time step, and that the accelerations are finite, not all
    zero and not implausibly large (which usually means wrong units).
    """
    source = record.metadata.get("file") or record.id
    data = np.asarray(record.acceleration, dtype=np.float64)
    dt = record.dt
    if data.size < MIN_SAMPLES:
        raise RecordError(source, f"only {data.size} samples; a record needs at least {MIN_SAMPLES}")
    if not (math.isfinite(dt) and DT_RANGE[0] <= dt <= DT_RANGE[1]):
        raise RecordError(source, f"time step DT = {dt:g} s is implausible; allowed "
                          f"{DT_RANGE[0]:g} to {DT_RANGE[1]:g} s")
    if not np.all(np.isfinite(data)):
        raise RecordError(source, "contains NaN or infinite accelerations; expected finite values")
    peak_g = float(np.max(np.abs(data))) / STANDARD_GRAVITY
    if peak_g == 0:
        raise RecordError(source, "all accelerations are zero; nothing to scale")
    if peak_g > MAX_PEAK_G:
        raise RecordError(source, f"peak acceleration {peak_g:.3g} g is implausible; allowed up to "
                          f"{MAX_PEAK_G:g} g (check the units)")


def unique_ids(records) -> list:
    """The records with unique ids.

    A user file whose name clashes with another record's id gets its path's last folders in its id
    (``site-a/X``, ``site-b/X``); catalogue ids never change.
    """
    ids = [r.id for r in records]
    movable = [r.metadata.get("sets") == "user" and bool(r.metadata.get("file")) for r in records]
    for depth in range(2, 64):
        clashing = {i for i in ids if ids.count(i) > 1}
        if not any(i in clashing and m for i, m in zip(ids, movable)):
            break
        ids = ["/".join([*Path(r.metadata["file"]).with_suffix("").parts[-depth:],
                         *([r.metadata["file_trace"]] if r.metadata.get("file_trace") else [])])
               if i in clashing and m else i for i, r, m in zip(ids, records, movable)]
    return [r if i == r.id else Record(i, r.trace, {**r.metadata, "id": i}) for i, r in zip(ids, records)]


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


def _select_component(stream: obspy.Stream, entry: CatalogueEntry) -> obspy.Trace:
    """The trace of a several-component file that a catalogue entry names (``station`` NET.STA, ``component``)."""
    found = [trace for trace in stream if trace.stats.channel == entry.component
             and entry.station in (f"{trace.stats.network}.{trace.stats.station}", trace.stats.station)]
    if len(found) != 1:
        raise RecordError(entry.path, f"catalogue entry {entry.id}: {len(found)} traces of station {entry.station}, "
                          f"channel {entry.component}; expected one among {', '.join(t.id for t in stream)}")
    return found[0]


def _load_entry(entry: CatalogueEntry, streams: dict | None = None) -> Record:
    """The catalogue entry's record; ``streams`` caches several-component files read for earlier entries."""
    key = (str(entry.path), entry.sha256)
    stream = streams.get(key) if streams is not None else None
    if stream is None:
        stream = read_stream(entry.path, units=entry.units)
    metadata = entry.metadata()
    if len(stream) == 1:
        trace = stream[0]
    else:
        if streams is not None:
            streams[key] = stream
        trace = _select_component(stream, entry).copy()
        metadata.update(file_sha256=entry.sha256, sha256=f"{entry.sha256}#{trace.id}")
    metadata.update(orientation_metadata(trace, entry.component))
    return Record(entry.id, trace, metadata)


def _load_user_file(path: Path, units, dt=None) -> list[Record]:
    """One record per component of a user's file: id the file's stem (``stem/NET.STA.LOC.CHA`` if several)."""
    stream = read_stream(path, units=units, dt=dt)
    digest = sha256_of(path)
    records = []
    for trace in stream:
        stats = trace.stats
        header = stats.get("peer_at2") or stats.get("text_record") or stats.get("csmip") or stats.get("asdf") or {}
        metadata = {"id": path.stem, "file": str(path), "event": header.get("event", ""),
                    "year": None, "magnitude": None, "station": header.get("station", stats.station),
                    "component": header.get("component", stats.channel), "sets": "user",
                    "source": str(path), "units": units or header.get("units_in_file", ""),
                    "sha256": digest}
        if stats.get("knet"):
            metadata.update(knet_metadata(stats))
        metadata.update(header_metadata(trace))
        metadata.update(orientation_metadata(trace, metadata["component"]))
        if len(stream) > 1:
            metadata.update(id=f"{path.stem}/{trace.id}", file_sha256=digest, sha256=f"{digest}#{trace.id}",
                            file_trace=trace.id)
        records.append(Record(metadata["id"], trace, metadata))
    return records


def knet_metadata(stats) -> dict:
    """Event, origin time, year, magnitude and station from a K-NET/KiK-net header (obspy's ``stats.knet``).

    Parameters
    ----------
    stats : obspy.core.trace.Stats
        The trace's stats as obspy reads a K-NET/KiK-net ASCII file: ``stats.knet`` holds the origin
        time ``evot`` (UTC), epicentre ``evla``/``evlo`` [deg], depth ``evdp`` [km] and magnitude ``mag``.

    Returns
    -------
    dict
        ``event`` (origin time, magnitude, epicentre and depth, e.g. ``1996-08-10 18:12:00 UTC M5.9,
        38.92N 140.63E, 7 km deep``), ``origin_time`` (ISO 8601, UTC), ``year``, ``magnitude``, ``station``
        and ``units`` (gal, the header's scale factor).
    """
    header = stats.knet
    origin = header.get("evot")
    magnitude = header.get("mag")
    parts = [f"{origin.strftime('%Y-%m-%d %H:%M:%S')} UTC" if origin is not None else "K-NET event"]
    if magnitude is not None:
        parts[0] += f" M{magnitude:g}"
    if header.get("evla") is not None and header.get("evlo") is not None:
        latitude, longitude = float(header["evla"]), float(header["evlo"])
        parts.append(f"{abs(latitude):.2f}{'N' if latitude >= 0 else 'S'} "
                     f"{abs(longitude):.2f}{'E' if longitude >= 0 else 'W'}")
    if header.get("evdp") is not None:
        parts.append(f"{float(header['evdp']):g} km deep")
    return {"event": ", ".join(parts), "origin_time": f"{origin.isoformat()}Z" if origin is not None else "",
            "year": origin.year if origin is not None else None,
            "magnitude": float(magnitude) if magnitude is not None else None,
            "station": str(stats.station), "units": "gal"}


# ---------------------------------------------------------------- duplicates by content

SAME_SAMPLES = 1e-3
"""Two records are the same when their time steps agree to 1e-4, they have as many samples, and their
samples, less their means, agree within this fraction of the peak: e.g. a K-NET file and a CSV export
of it (the same motion written with four or more significant digits)."""


def same_samples(record, other) -> bool:
    """True if ``record`` and ``other`` hold the same accelerations, whatever their files' formats.

    Parameters
    ----------
    record, other : Record
        Records in m/s^2.

    Returns
    -------
    bool
        Same number of samples, time steps within 1e-4, and demeaned samples within ``SAME_SAMPLES``
        of the larger peak.
    """
    if record.trace.stats.npts != other.trace.stats.npts or not math.isclose(record.dt, other.dt, rel_tol=1e-4):
        return False
    first = np.asarray(record.acceleration, dtype=np.float64)
    second = np.asarray(other.acceleration, dtype=np.float64)
    first, second = first - first.mean(), second - second.mean()
    peak = max(float(np.max(np.abs(first))), float(np.max(np.abs(second))))
    return peak > 0 and float(np.max(np.abs(first - second))) <= SAME_SAMPLES * peak


def _duplicate_of(record, kept) -> Record | None:
    """The kept record holding the same samples as ``record``, when either is the user's own file.

    Catalogue entries are not compared with one another: the catalogue lists genuine PEER originals
    beside their FEMA P695 exports on purpose (records/MANIFEST.csv notes).
    """
    user = record.metadata.get("sets") == "user"
    for other in kept:
        if (user or other.metadata.get("sets") == "user") and same_samples(record, other):
            return other
    return None


# ---------------------------------------------------------------- selections that name nothing

def _looks_like_a_path(text: str) -> bool:
    """A selection written as a file or folder (a separator, a suffix, or ``.``/``~`` first)."""
    return "/" in text or os.sep in text or bool(Path(text).suffix) or text.startswith((".", "~"))


def _unknown_selection(text: str, sets, entries) -> Exception:
    """The error for a selection that is no set, id, folder or file: "not found" for a path."""
    names = [*sets, *entries]
    hint = did_you_mean(text, names)
    if not hint and _looks_like_a_path(text):
        path = Path(text)
        if path.parent.is_dir():
            siblings = [p.name for p in path.parent.iterdir()]
            near = did_you_mean(path.name, siblings)
            folder = "the current folder" if str(path.parent) == "." else str(path.parent)
            where = near or f"; no such file or folder in {folder}"
        else:
            where = f"; the folder {path.parent} does not exist either"
        return RecordError(text, f"not found{where}")
    return ManifestError(f"unknown record selection {text!r}{hint}: not a record set "
                         f"({', '.join(sorted(sets))}), a record id, a folder or a file")


def load_records(selection: str | Path | Iterable[str | Path], records_dir: str | Path | None = None,
                 units: str | None = None, verify_checksums: bool = True,
                 dt: float | None = None) -> tuple[list[Record], list[RecordError]]:
    """Load a record set by name, a folder of files, or a list of these.

    Parameters
    ----------
    selection : str, Path or list
        Set names (``record_sets()``), record ids, folders or files.
    records_dir : str or Path, optional
        Folder of the catalogue (``MANIFEST.csv`` and its files); ``RECORDS_DIR`` if omitted.
    units : str, optional
        Acceleration units for user files in formats that do not state them (``g``, ``m/s^2``,
        ``cm/s^2``, ``gal``).
    dt : float, optional
        Time step [s] of the user's one-column text records.
    verify_checksums : bool
        Check catalogue files against their sha256 (a changed file is reported by name).

    Returns
    -------
    records : list of Record
        The records that were read, in catalogue or file-name order, without duplicates: a file named
        twice is read once, and a file with the same bytes (sha256) or the same samples as a record
        read before it (``same_samples``: a CSV export of a K-NET file, say) is skipped.
    failures : list of RecordError
        One per file that could not be read or was skipped as a duplicate; the other files go on.

    Raises
    ------
    ManifestError
        A selection that is no record set or record id (with a did-you-mean).
    RecordError
        A selection written as a path that does not exist ("not found"), or a folder without records.
    """
    items = [selection] if isinstance(selection, (str, Path)) else list(selection)
    entries = {entry.id: entry for entry in catalogue(records_dir)}
    sets = record_sets(records_dir)
    records, failures, seen, contents, streams = [], [], set(), {}, {}

    def add(loader, key, target):
        if key in seen:
            return
        seen.add(key)
        try:
            loaded = loader(target)
        except RecordError as error:
            failures.append(error)
            return
        for record in loaded if isinstance(loaded, list) else [loaded]:
            keep(record)

    def keep(record):
        try:
            check_record(record)
        except RecordError as error:
            failures.append(error)
            return
        digest = record.metadata.get("sha256")
        if digest and digest in contents:
            failures.append(RecordError(record.metadata.get("file") or record.id,
                                        f"same content as record {contents[digest]}; skipped as a duplicate"))
            return
        same = _duplicate_of(record, records)
        if same is not None:
            failures.append(RecordError(record.metadata.get("file") or record.id,
                                        f"same samples as record {same.id} ({same.metadata.get('file') or same.id}, "
                                        f"within {SAME_SAMPLES:.1%} of the peak); skipped as a duplicate"))
            return
        contents[digest] = record.id
        records.append(record)

    for item in items:
        text = str(item)
        if not text.strip():
            raise ManifestError("empty record selection ''; name a record set, a record id, a folder or a file")
        if text in sets or text in entries:
            for entry in (entries[i] for i in sets.get(text, [text])):
                problems = verify([entry]) if verify_checksums and entry.id not in seen else []
                if problems:
                    seen.add(entry.id)
                    failures.append(RecordError(entry.path, problems[0].split(": ", 1)[1]))
                else:
                    add(lambda e: _load_entry(e, streams), entry.id, entry)
        elif Path(text).is_dir():
            files = sorted(p for p in Path(text).rglob("*")
                           if p.suffix.lower() in RECORD_SUFFIXES or text_records.is_text_record(p)
                           or csmip.is_csmip(p) or asdf.is_asdf(p) or knet.is_knet(p))
            if not files:
                raise RecordError(text, f"folder holds no record files ({', '.join(sorted(RECORD_SUFFIXES))}, "
                                  "CSMIP Volume 1, ASDF, K-NET/KiK-net ASCII, or text/CSV of one or two numeric "
                                  "columns)")
            for path in files:
                add(lambda p: _load_user_file(p, units, dt), str(path.resolve()), path)
        elif Path(text).is_file():
            add(lambda p: _load_user_file(p, units, dt), str(Path(text).resolve()), Path(text))
        else:
            raise _unknown_selection(text, sets, entries)
    return unique_ids(records), failures


register_format("PEER_AT2", peer_at2.is_peer_at2, peer_at2.read_peer_at2)
register_format("CSMIP", csmip.is_csmip, csmip.read_csmip)
register_format("ASDF", asdf.is_asdf, asdf.read_asdf)
register_format("TEXT", text_records.is_text_record, text_records.read_text_record)
