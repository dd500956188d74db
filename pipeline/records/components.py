"""rockfrag.records.components - a record is one component of a station's motion: H1, H2 or Z.

Input : read traces (their format's header: CSMIP ``stats.csmip``, ASDF ``stats.asdf``, or only a channel
        name) and loaded ``Record`` objects.
Output: each record's orientation metadata (``orientation_metadata``), its component label
        (``component_label``: ``H1``, ``H2``, ``Z``, or ``H`` for a horizontal of unstated direction), and
        the records grouped by event and station (``group_components``) into ``ComponentGroup`` objects
        holding H1, H2 and Z; the two horizontal components of each station (``horizontal_partners``), which a
        study scales together by their RotD50 (rockfrag.study), and the window they share (``pair_window``).

Orientation, where it comes from:
- CSMIP Volume 1 and ASDF files state it in their header / StationXML (``orientation_from = "header"``);
- other formats only name the channel: a vertical is recognised by its name (SEED codes ending in ``Z``,
  K-NET/KiK-net ``UD``, PEER ``UP``/``DWN``/``V``/``VER``/``VERT``; ``orientation_from = "channel name"``);
- everything else is a horizontal component of unstated direction (``"assumed horizontal"``), as the
  catalogue's FEMA P695 and PEER records are. No record of the horizontal sets is vertical (tested).

Verticals are marked (``Record.is_vertical``, ``metadata["orientation"] == "vertical"``) so that a study
that takes horizontal inputs can leave them out (``split_vertical``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from rockfrag.errors import RecordError
from rockfrag.units import STANDARD_GRAVITY
from rockfrag.version import __version__

_VERTICAL_NAME = re.compile(r"^(?:[A-Z0-9]{2}Z|Z|UD\d?|U-D|UP|DWN|DOWN|V|VER|VERT|VERTICAL)$")
_FIRST_HORIZONTAL = {"N", "1", "NS"}
_SECOND_HORIZONTAL = {"E", "2", "EW"}

HORIZONTAL_ORDER = ("H1", "H2", "H")
"""Order of the horizontal labels inside a group (before numbering them H1, H2, H3, ...)."""


def is_vertical_name(name: str) -> bool:
    """True for a channel or component name that denotes a vertical component (see the module docstring)."""
    return bool(_VERTICAL_NAME.match(str(name or "").strip().upper()))


def orientation_metadata(trace, component: str = "") -> dict:
    """The orientation of ``trace``, as record metadata.

    Parameters
    ----------
    trace : obspy.Trace
        A read trace; ``stats.csmip`` or ``stats.asdf`` (their readers) state the orientation.
    component : str
        The catalogue's component name, also looked at for a vertical name.

    Returns
    -------
    dict
        ``orientation`` (``"vertical"`` or ``"horizontal"``), ``azimuth_deg`` (degrees clockwise from north,
        or None), ``orientation_from`` (``"header"``, ``"channel name"`` or ``"assumed horizontal"``) and
        ``channel_code`` (the trace's channel).
    """
    header = trace.stats.get("csmip") or trace.stats.get("asdf")
    channel = str(trace.stats.channel or "")
    if header is not None:
        vertical, azimuth, source = bool(header["vertical"]), header.get("azimuth"), "header"
    elif is_vertical_name(channel) or is_vertical_name(component):
        vertical, azimuth, source = True, None, "channel name"
    else:
        vertical, azimuth, source = False, None, "assumed horizontal"
    return {"orientation": "vertical" if vertical else "horizontal",
            "azimuth_deg": None if vertical or azimuth is None else float(azimuth),
            "orientation_from": source, "channel_code": channel}


def component_label(metadata: dict) -> str:
    """``Z`` for a vertical; ``H1``/``H2`` for a horizontal whose channel says N or 1 / E or 2; else ``H``."""
    if metadata.get("orientation") == "vertical":
        return "Z"
    code = str(metadata.get("channel_code") or "").strip().upper()
    if code in _FIRST_HORIZONTAL or (len(code) == 3 and code[-1] in _FIRST_HORIZONTAL):
        return "H1"
    if code in _SECOND_HORIZONTAL or (len(code) == 3 and code[-1] in _SECOND_HORIZONTAL):
        return "H2"
    return "H"


def event_description(origin_time=None, magnitude=None, latitude=None, longitude=None, depth_km=None,
                      fallback: str = "") -> str:
    """``2014-08-24 10:20:44 UTC M6.02, 38.22N 122.31W, 11.1 km deep`` from what is known (else ``fallback``)."""
    if origin_time is None:
        return fallback
    text = f"{origin_time.strftime('%Y-%m-%d %H:%M:%S')} UTC"
    if magnitude is not None:
        text += f" M{float(magnitude):g}"
    parts = [text]
    if latitude is not None and longitude is not None:
        parts.append(f"{abs(latitude):.2f}{'N' if latitude >= 0 else 'S'} "
                     f"{abs(longitude):.2f}{'E' if longitude >= 0 else 'W'}")
    if depth_km is not None:
        parts.append(f"{float(depth_km):.3g} km deep")
    return ", ".join(parts)


def header_metadata(trace) -> dict:
    """Event, station and year of a user file's CSMIP or ASDF trace (empty for other formats).

    Returns
    -------
    dict
        ``event`` (ASDF: origin time, magnitude, epicentre and depth from the QuakeML; CSMIP: the header's
        event id and record line), ``event_id``, ``station`` (``NET.STA``), ``station_name``, ``year``,
        ``magnitude`` and, for ASDF, ``origin_time``.
    """
    stats = trace.stats
    station = f"{stats.network}.{stats.station}" if stats.network else str(stats.station)
    if stats.get("csmip"):
        header = stats.csmip
        record = " ".join(str(header["record"]).split())
        event = f"event {header['event_id']}: {record}" if header.get("event_id") else record
        return {"event": event, "event_id": header.get("event_id", ""), "station": station,
                "station_name": header.get("station_name", ""), "year": stats.starttime.year, "magnitude": None}
    if stats.get("asdf"):
        header, event = stats.asdf, stats.asdf.get("event") or {}
        origin = event.get("origin_time")
        depth = event.get("depth_m")
        text = event_description(origin, event.get("magnitude"), event.get("latitude"), event.get("longitude"),
                                 None if depth is None else depth / 1000.0, fallback=header.get("event_id", ""))
        return {"event": text, "event_id": header.get("event_id", ""), "station": station,
                "station_name": header.get("station_name", ""),
                "year": origin.year if origin is not None else stats.starttime.year,
                "magnitude": event.get("magnitude"),
                "origin_time": f"{origin.isoformat()}Z" if origin is not None else ""}
    return {}


@dataclass
class ComponentGroup:
    """The components of one station's record of one event.

    Attributes
    ----------
    event, station : str
        The records' ``event`` and ``station`` metadata.
    components : dict
        Label -> Record: ``H1``, ``H2`` (``H3``, ... if a station has more horizontals), ``Z`` (``Z2``, ...).
    """

    event: str
    station: str
    components: dict = field(default_factory=dict)

    @property
    def h1(self):
        """The first horizontal component, or None."""
        return self.components.get("H1")

    @property
    def h2(self):
        """The second horizontal component, or None."""
        return self.components.get("H2")

    @property
    def z(self):
        """The vertical component (up positive), or None."""
        return self.components.get("Z")

    @property
    def horizontals(self) -> list:
        """The horizontal components, H1 first."""
        return [record for label, record in self.components.items() if label.startswith("H")]

    def aligned(self, cut: bool = False) -> dict:
        """The components over the time window they share: label -> Record with equal start, step and length.

        Components of one station rarely end on the same sample (the shipped CSMIP files differ by up to 2.6 s
        at their ends). Cutting them to the shared window is harmless when every component keeps its peak
        (PGA) and at least ``KEPT_ARIAS`` of its Arias intensity: then the cut is made and stated in each
        record's processing provenance (``stats.processing``: its window, the samples removed, the PGA kept).
        Otherwise the window is no longer the record (a vertical holding only its first 10 s would cut the
        horizontals to pre-event noise): that is an error naming the file, the channels and what the cut would
        do to their PGA, unless ``cut`` asks for it anyway; then the provenance states the PGA it changed.

        Parameters
        ----------
        cut : bool, optional
            Cut to the shared window even where a component loses its peak or its strong motion (default False).

        Returns
        -------
        dict
            Label -> a copy of each record holding the samples from the latest start to the earliest end.

        Raises
        ------
        RecordError
            The components have different time steps, share no time window, or (without ``cut``) the shared
            window leaves out a component's peak or more than 1% of its Arias intensity.
        """
        records = list(self.components.values())
        where = records[0].metadata.get("file") or records[0].id
        steps = {round(record.dt, 9) for record in records}
        if len(steps) > 1:
            raise RecordError(where, f"components of {self.station} have different time steps ({sorted(steps)} s); "
                              "resample them first")
        start = max(record.trace.stats.starttime for record in records)
        end = min(record.trace.stats.endtime for record in records)
        if end <= start:
            raise RecordError(where, f"components of {self.station} share no time window ({self._windows()})")
        aligned = {}
        for label, record in self.components.items():
            trace = record.trace.slice(start, end, nearest_sample=True).copy()
            aligned[label] = record.with_trace(trace)
        length = min(record.trace.stats.npts for record in aligned.values())
        for record in aligned.values():
            record.trace.data = record.trace.data[:length]
        effects = {label: _cut_effect(self.components[label], aligned[label]) for label in aligned}
        if all(removed == 0 for removed, *_ in effects.values()):
            return aligned
        harmful = {label: effect for label, effect in effects.items()
                   if effect[2] < effect[1] or effect[3] < KEPT_ARIAS}
        if harmful and not cut:
            damage = "; ".join(f"{self._channel(label)}'s PGA {before:.3g} g -> {after:.3g} g, Arias intensity "
                               f"{kept:.0%} kept" for label, (_, before, after, kept) in harmful.items())
            raise RecordError(where, f"components of {self.station} differ in length ({self._windows()}); cut to "
                              f"the {float(end - start):.3g} s they share: {damage}. They are not cut without a word: "
                              "give the components over one time window")
        for label, record in aligned.items():
            removed, before, after, kept = effects[label]
            trace = record.trace
            trace.stats.processing = [*trace.stats.get("processing", []),
                                      f"rockfrag {__version__}: cut_to_shared_window(start={start}, end={end}, "
                                      f"samples_removed={removed}, pga_g={before:.4g}->{after:.4g}, "
                                      f"arias_kept={kept:.4f})"]
        return aligned

    def _channel(self, label: str) -> str:
        """``H1 (HNE)``: a component's label and channel code."""
        code = self.components[label].metadata.get("channel_code") or self.components[label].trace.stats.channel
        return f"{label} ({code})" if code else label

    def _windows(self) -> str:
        """Each component's channel, length [s] and samples, for the messages."""
        return ", ".join(f"{self._channel(label)} {record.duration:.4g} s from {record.trace.stats.starttime}, "
                         f"{record.trace.stats.npts} samples" for label, record in self.components.items())


KEPT_ARIAS = 0.99
"""A cut to the components' shared window is made only where each keeps its PGA and this fraction of its Arias
intensity (of the demeaned samples); the shipped three-component records keep 99.99% or more."""


def _cut_effect(whole, cut) -> tuple[int, float, float, float]:
    """(samples removed, PGA before and after [g], fraction of the Arias intensity kept) of one component's cut."""
    mean = float(np.mean(whole.acceleration))
    before, after = whole.acceleration - mean, cut.acceleration - mean
    energy = float(np.sum(before ** 2))
    kept = float(np.sum(after ** 2)) / energy if energy > 0 else 1.0
    return (whole.trace.stats.npts - cut.trace.stats.npts, float(np.max(np.abs(whole.acceleration))) / STANDARD_GRAVITY,
            float(np.max(np.abs(cut.acceleration))) / STANDARD_GRAVITY if cut.trace.stats.npts else 0.0, kept)


def group_key(record) -> tuple[str, str, str]:
    """(event, station, sets): records are components of one motion when all three agree.

    The record sets are part of the key so that two versions of one component from different sources
    (a PEER original and its FEMA P695 export, both "Duzce, Turkey" at "Bolu") stay apart.
    """
    metadata = record.metadata
    return (str(metadata.get("event") or ""), str(metadata.get("station") or ""), str(metadata.get("sets") or ""))


def group_components(records) -> list[ComponentGroup]:
    """Group records by event and station into H1, H2 and Z.

    Parameters
    ----------
    records : iterable of Record
        Loaded records, in any order.

    Returns
    -------
    list of ComponentGroup
        One group per (event, station, record sets), in order of first appearance. Within a group the
        horizontals are labelled H1, H2 (H3, ...) in the order N or 1 first, E or 2 next, others after in
        the given order; the vertical is Z (a second one Z2).
    """
    members: dict[tuple, list] = {}
    for record in records:
        members.setdefault(group_key(record), []).append(record)
    groups = []
    for (event, station, _sets), found in members.items():
        horizontals = [r for r in found if component_label(r.metadata) != "Z"]
        verticals = [r for r in found if component_label(r.metadata) == "Z"]
        horizontals.sort(key=lambda r: HORIZONTAL_ORDER.index(component_label(r.metadata)))
        components = {f"H{i}": record for i, record in enumerate(horizontals, start=1)}
        components.update({("Z" if i == 1 else f"Z{i}"): record for i, record in enumerate(verticals, start=1)})
        groups.append(ComponentGroup(event, station, components))
    return groups


def component_labels(records) -> list[tuple[int, str]]:
    """(group number, label) of each record, in the order given: group numbers count from 1 (``group_components``)."""
    where = {}
    for number, group in enumerate(group_components(records), start=1):
        for label, record in group.components.items():
            where[id(record)] = (number, label)
    return [where[id(record)] for record in records]


def horizontal_partners(records) -> tuple[list, list[str]]:
    """The other horizontal component of each record's station, as an index into ``records``, or None.

    Two records are a pair when they are the only two horizontal components of one event, station and record
    set (``group_components``), the event and station are stated, and they share a time step and a window
    (``pair_window``). Any other record is a single component: a vertical, a horizontal whose station has no
    second one, one of a station with three or more, or one whose event or station is unknown.

    Parameters
    ----------
    records : list of Record
        Loaded or processed records.

    Returns
    -------
    partners : list of int or None
        For each record, the index of its partner in ``records`` (pairs point at each other), or None.
    notes : list of str
        One line per station whose two horizontals could not be paired, with the reason.
    """
    index = {id(record): i for i, record in enumerate(records)}
    partners: list = [None] * len(records)
    notes = []
    for group in group_components(records):
        horizontals = group.horizontals
        if len(horizontals) != 2 or not (group.event and group.station):
            continue
        first, second = horizontals
        if pair_window(first, second) is None:
            notes.append(f"{first.id} and {second.id} ({group.station}) are not paired: they have different time "
                         "steps or share no window; each is scaled by its own component")
            continue
        partners[index[id(first)]], partners[index[id(second)]] = index[id(second)], index[id(first)]
    return partners, notes


def pair_window(first, second) -> tuple[slice, slice] | None:
    """The samples of two components that cover the same time: a slice of each, or None.

    The components must have one time step (within 1e-9 s); the window runs from the later start to the earlier
    end (files without a start time, such as PEER AT2, all start at one epoch: their first samples align).

    Parameters
    ----------
    first, second : Record
        Two components of one station.

    Returns
    -------
    (slice, slice) or None
        Equal-length slices of ``first.acceleration`` and ``second.acceleration``; None when the time steps
        differ or the windows do not overlap.
    """
    dt = first.dt
    if abs(dt - second.dt) > 1e-9:
        return None
    offset = int(round((second.trace.stats.starttime - first.trace.stats.starttime) / dt))
    start_first, start_second = max(0, offset), max(0, -offset)
    length = min(first.trace.stats.npts - start_first, second.trace.stats.npts - start_second)
    if length < 2:
        return None
    return slice(start_first, start_first + length), slice(start_second, start_second + length)


def split_vertical(records) -> tuple[list, list]:
    """(horizontal records, vertical records), each in the order given.

    A study that takes horizontal inputs uses the first list; the second holds the verticals it leaves out.
    """
    horizontal = [record for record in records if record.metadata.get("orientation") != "vertical"]
    vertical = [record for record in records if record.metadata.get("orientation") == "vertical"]
    return horizontal, vertical
