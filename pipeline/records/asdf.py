"""rockfrag.records.asdf - ASDF (Adaptable Seismic Data Format) files: raw waveforms in counts -> acceleration.

Input : an ASDF file (HDF5 with the root attribute ``file_format = "ASDF"``; Krischer et al. 2016): per
        station a group ``/Waveforms/NET.STA`` holding the station's ``StationXML`` (bytes) and one dataset
        per trace, named ``NET.STA.LOC.CHA__START__END__TAG`` with the attributes ``starttime`` [ns since
        1970, UTC] and ``sampling_rate`` [Hz]; the events as ``/QuakeML`` (bytes). gmprocess workspaces are
        ASDF files.
Output: an ``obspy.Stream`` of ground acceleration [m/s^2], one trace per channel of the chosen tag.

The raw recordings are the waveforms stored as integers: digitiser counts. Their instrument response is
removed here with obspy's ``Trace.remove_response`` and the station's StationXML: output ``ACC`` (m/s^2),
the pre-filter ``pre_filter(sampling_rate)`` = cosine taper from 0.02 Hz to 0.05 Hz and from 0.8 to 0.9
of the Nyquist frequency (stabilises the deconvolution; the processing stage band-passes 0.1-50 Hz later),
no water level (the taper bounds the gain), the mean removed and 5 % of each end tapered first (obspy's
defaults). Float waveforms (an ASDF file's processed tags, such as gmprocess's ``..._default``) are not
counts; they are read only when ``units`` names their units, and no response is removed from them.

Orientation comes from the StationXML: a channel with ``Dip`` -90 is vertical up (SEED convention), +90
vertical down (stored negated, up positive, the flip written to ``stats.processing``), 0 horizontal with
its ``Azimuth``; where the dip is not given, the channel code's last letter decides (``Z`` vertical up,
``N``/``E``/``1``/``2`` horizontal).

The HDF5 file is read with the ``netCDF4`` library (netCDF-4 files are HDF5 files, and netCDF4-python
opens plain HDF5 groups, datasets and attributes), which the pipeline already needs for its cube: no
further dependency. Neither pyasdf (h5py, dill, prov, lxml, colorama, ...) nor h5py (a second copy of the
HDF5 library) is needed for reading waveforms, StationXML and QuakeML.
"""

from __future__ import annotations

import io
import os

import netCDF4
import numpy as np
import obspy
from obspy import Stream, Trace, UTCDateTime
from obspy.core.util import AttribDict

from rockfrag.errors import RecordError
from rockfrag.units import acceleration_factor

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
"""The first eight bytes of an HDF5 file (without a user block)."""

PRE_FILTER_LOW_HZ = (0.02, 0.05)
"""Corners [Hz] of the pre-filter's low-frequency cosine taper (0 below the first, 1 above the second)."""

PRE_FILTER_HIGH_NYQUIST = (0.8, 0.9)
"""Corners of the pre-filter's high-frequency taper, as fractions of the Nyquist frequency."""

ORIENTATION_CODES = {"Z": True, "N": False, "E": False, "1": False, "2": False}
"""SEED orientation codes read when the StationXML gives no dip: vertical (True) or horizontal."""


def pre_filter(sampling_rate: float) -> tuple[float, float, float, float]:
    """The pre-filter ``(f1, f2, f3, f4)`` [Hz] for ``remove_response`` at ``sampling_rate`` [Hz].

    Parameters
    ----------
    sampling_rate : float
        Samples per second [Hz].

    Returns
    -------
    tuple of float
        ``PRE_FILTER_LOW_HZ`` and ``PRE_FILTER_HIGH_NYQUIST`` times the Nyquist frequency: for 200 Hz,
        (0.02, 0.05, 80, 90) Hz.
    """
    nyquist = 0.5 * float(sampling_rate)
    return (*PRE_FILTER_LOW_HZ, PRE_FILTER_HIGH_NYQUIST[0] * nyquist, PRE_FILTER_HIGH_NYQUIST[1] * nyquist)


def _head(source, size=8) -> bytes:
    if hasattr(source, "read"):
        position = source.tell()
        head = source.read(size)
        source.seek(position)
        return head
    with open(source, "rb") as handle:
        return handle.read(size)


def _open(source):
    """(netCDF4.Dataset, name for messages) of a path or a binary file object."""
    if hasattr(source, "read"):
        position = source.tell()
        data = source.read()
        source.seek(position)
        name = getattr(source, "name", "<file object>")
        return netCDF4.Dataset("inmemory.h5", mode="r", memory=data), name
    return netCDF4.Dataset(os.fspath(source), mode="r"), os.fspath(source)


def is_asdf(source) -> bool:
    """True if ``source`` (path or binary file object) is an HDF5 file whose ``file_format`` is ASDF. Never raises."""
    try:
        if _head(source) != HDF5_SIGNATURE:
            return False
        dataset, _ = _open(source)
        try:
            return str(dataset.getncattr("file_format")) == "ASDF" if "file_format" in dataset.ncattrs() else False
        finally:
            dataset.close()
    except Exception:  # detection must never raise, whatever the input (obspy contract)
        return False


def _bytes(variable) -> bytes:
    return np.asarray(variable[:]).tobytes()


def _waveforms(station_group):
    """{tag: [(SEED id, dataset)]} of a station group (every variable but StationXML)."""
    tags: dict[str, list] = {}
    for name, variable in station_group.variables.items():
        if name == "StationXML":
            continue
        parts = name.split("__")
        if len(parts) != 4:
            continue
        tags.setdefault(parts[3], []).append((parts[0], variable))
    return tags


def _choose_tag(tags: dict, tag: str | None, units: str | None, name: str) -> str:
    if tag is not None:
        if tag not in tags:
            raise RecordError(name, f"no waveforms tagged {tag!r}; the file holds {', '.join(sorted(tags))}")
        return tag
    raw = sorted(t for t, items in tags.items() if all(np.issubdtype(v.dtype, np.integer) for _, v in items))
    if len(raw) == 1:
        return raw[0]
    if not raw and len(tags) == 1 and units is not None:
        return next(iter(tags))
    if not raw:
        raise RecordError(name, f"no raw waveforms (integer counts) among the tags {', '.join(sorted(tags))}; "
                          "name a tag and the units of its samples")
    raise RecordError(name, f"several tags hold raw waveforms ({', '.join(raw)}); name one (tag=...)")


def _orientation(channel, code: str, name: str) -> tuple[float | None, float]:
    """(azimuth [deg] or None, dip [deg]: 0 horizontal, -90 up, 90 down) from StationXML or the channel code."""
    dip = getattr(channel, "dip", None) if channel is not None else None
    azimuth = getattr(channel, "azimuth", None) if channel is not None else None
    if dip is not None and abs(abs(float(dip)) - 90.0) < 1e-6:
        return None, float(dip)
    if dip is not None and abs(float(dip)) < 1e-6:
        return (float(azimuth) % 360.0 if azimuth is not None else None), 0.0
    if dip is not None:
        raise RecordError(name, f"channel {code}: dip {float(dip):g} deg is neither horizontal nor vertical")
    letter = code[-1:].upper()
    if letter not in ORIENTATION_CODES:
        raise RecordError(name, f"channel {code}: no dip in the StationXML and orientation code {letter!r} is not "
                          f"one of {', '.join(ORIENTATION_CODES)}")
    if ORIENTATION_CODES[letter]:
        return None, -90.0
    return (float(azimuth) % 360.0 if azimuth is not None else None), 0.0


def _events(dataset, name) -> dict:
    """{resource id: obspy Event} from the file's QuakeML (empty if it has none)."""
    if "QuakeML" not in dataset.variables:
        return {}
    try:
        catalog = obspy.read_events(io.BytesIO(_bytes(dataset.variables["QuakeML"])), format="QUAKEML")
    except Exception as error:  # obspy raises several types for malformed XML
        raise RecordError(name, f"QuakeML is not readable ({type(error).__name__}: {error})") from None
    events = {}
    for event in catalog:
        resource = str(event.resource_id)
        events[resource] = event
        events[resource.rsplit("/", 1)[-1]] = event  # waveforms may name the event without the smi: prefix
    return events


def _event_header(event) -> dict:
    if event is None:
        return {}
    origin = event.preferred_origin() or (event.origins[0] if event.origins else None)
    magnitude = event.preferred_magnitude() or (event.magnitudes[0] if event.magnitudes else None)
    header = {}
    if origin is not None:
        header.update({"origin_time": origin.time, "latitude": origin.latitude, "longitude": origin.longitude,
                       "depth_m": origin.depth})
    if magnitude is not None:
        header.update({"magnitude": magnitude.mag, "magnitude_type": magnitude.magnitude_type or ""})
    return header


def read_asdf(filename, headonly: bool = False, units: str | None = None, dt: float | None = None,
              tag: str | None = None, **kwargs) -> Stream:
    """Read the waveforms of an ASDF file as ground acceleration [m/s^2].

    Parameters
    ----------
    filename : str, Path or binary file object
        The ASDF (HDF5) file.
    headonly : bool
        Accepted for obspy's interface; the samples are read anyway.
    units : str, optional
        Units of float (already converted) waveforms; ignored for raw counts, whose units come from the
        StationXML response.
    dt : float, optional
        Ignored: each waveform states its sampling rate.
    tag : str, optional
        The waveform tag to read; by default the one tag whose waveforms are integer counts.

    Returns
    -------
    obspy.Stream
        One trace per waveform of the tag, sorted by SEED id: acceleration [m/s^2] (response removed from
        counts, see the module docstring), ``stats.asdf`` with the tag, the event (id, origin time,
        magnitude), the station's site name and coordinates, and the orientation (``azimuth`` [deg] or
        None, ``dip`` [deg], ``vertical``, ``pre_filter`` [Hz] for counts).

    Raises
    ------
    RecordError
        The file is not ASDF, holds no waveforms, no or several raw tags, a waveform without a StationXML
        response, or an orientation that is neither horizontal nor vertical.
    """
    try:
        dataset, name = _open(filename)
    except OSError as error:
        raise RecordError(getattr(filename, "name", filename), f"not readable as HDF5 ({error})") from None
    try:
        dataset.set_auto_mask(False)
        if "file_format" not in dataset.ncattrs() or str(dataset.getncattr("file_format")) != "ASDF":
            raise RecordError(name, "HDF5 file without file_format = 'ASDF'; expected an ASDF file")
        if "Waveforms" not in dataset.groups or not dataset["Waveforms"].groups:
            raise RecordError(name, "ASDF file holds no waveforms (/Waveforms is empty)")
        stations = dataset["Waveforms"].groups
        tags: dict[str, list] = {}
        for station_name, group in stations.items():
            for found_tag, items in _waveforms(group).items():
                tags.setdefault(found_tag, []).extend((station_name, seed_id, v) for seed_id, v in items)
        if not tags:
            raise RecordError(name, "ASDF file holds no waveforms (/Waveforms/NET.STA groups are empty)")
        chosen = _choose_tag({t: [(s, v) for _, s, v in items] for t, items in tags.items()}, tag, units, name)
        events = _events(dataset, name)
        inventories = {}
        traces = []
        for station_name, seed_id, variable in sorted(tags[chosen], key=lambda item: item[1]):
            if station_name not in inventories:
                group = stations[station_name]
                if "StationXML" not in group.variables:
                    raise RecordError(name, f"station {station_name} has no StationXML; its response is needed")
                inventories[station_name] = obspy.read_inventory(io.BytesIO(_bytes(group.variables["StationXML"])),
                                                                 format="STATIONXML")
            traces.append(_trace(variable, seed_id, chosen, inventories[station_name], events, units, name))
    finally:
        dataset.close()
    return Stream(traces)


def _trace(variable, seed_id, tag, inventory, events, units, name) -> Trace:
    samples = np.asarray(variable[:])
    network, station, location, channel = seed_id.split(".")
    attributes = {key: variable.getncattr(key) for key in variable.ncattrs()}
    if "starttime" not in attributes or "sampling_rate" not in attributes:
        raise RecordError(name, f"waveform {seed_id} ({tag}) lacks the starttime or sampling_rate attribute")
    trace = Trace(data=samples)
    trace.stats.update({"network": network, "station": station, "location": location, "channel": channel,
                        "sampling_rate": float(attributes["sampling_rate"])})
    trace.stats.starttime = UTCDateTime(ns=int(attributes["starttime"]))
    try:
        coordinates = inventory.get_coordinates(trace.id, trace.stats.starttime)
        selected = inventory.select(network=network, station=station, location=location, channel=channel,
                                    time=trace.stats.starttime)
        channel_info = selected[0][0][0]
        site = selected[0][0].site.name or ""
    except Exception:  # obspy raises several types when the inventory lacks the channel
        raise RecordError(name, f"waveform {seed_id}: no matching channel in the station's StationXML") from None
    azimuth, dip = _orientation(channel_info, channel, name)
    event_id = str(attributes.get("event_id", ""))
    header = AttribDict({"tag": tag, "event_id": event_id, "station_name": site, "azimuth": azimuth, "dip": dip,
                         "vertical": dip != 0.0, "latitude": coordinates.get("latitude"),
                         "longitude": coordinates.get("longitude"), "event": _event_header(events.get(event_id))})
    if np.issubdtype(samples.dtype, np.integer):
        trace.data = samples.astype(np.float64)
        corners = pre_filter(trace.stats.sampling_rate)
        try:
            trace.remove_response(inventory=inventory, output="ACC", pre_filt=corners, water_level=None,
                                  zero_mean=True, taper=True, taper_fraction=0.05)
        except Exception as error:  # obspy raises ValueError/ObsPyException for a missing or bad response
            raise RecordError(name, f"waveform {seed_id}: instrument response cannot be removed "
                              f"({type(error).__name__}: {error})") from None
        # obspy's own line names the inventory object by its memory address: write a reproducible one instead
        trace.stats.processing = [*trace.stats.processing[:-1],
                                  f"rockfrag asdf: remove_response(StationXML of {network}.{station}, output='ACC', "
                                  f"pre_filt={tuple(float(f'{c:.6g}') for c in corners)} Hz, water_level=None, "
                                  "zero_mean=True, taper=True, taper_fraction=0.05)"]
        header.update({"units_in_file": "counts", "pre_filter": corners})
    else:
        if units is None:
            raise RecordError(name, f"waveform {seed_id} ({tag}) holds floats, not raw counts; state their units "
                              "(units='g', 'm/s^2', 'cm/s^2' or 'gal')")
        try:
            trace.data = samples.astype(np.float64) * acceleration_factor(units)
        except ValueError as error:
            raise RecordError(name, str(error)) from None
        header["units_in_file"] = units
    if dip > 0:
        trace.data = -trace.data
        trace.stats.processing = [*trace.stats.get("processing", []),
                                  "rockfrag asdf: channel points down (dip +90); samples negated to store up positive"]
    if not np.all(np.isfinite(trace.data)):
        raise RecordError(name, f"waveform {seed_id}: NaN or infinite samples")
    trace.stats.units = "m/s^2"
    trace.stats.quantity = "acceleration"
    trace.stats.asdf = header
    trace.stats._format = "ASDF"
    return trace
