"""PEER AT2 reader: every header variant, obspy auto-detection, and clear errors on bad input."""

from __future__ import annotations

import csv
import io
import re

import numpy as np
import obspy
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rockfrag.errors import RecordError
from rockfrag.records.peer_at2 import is_peer_at2, parse_peer_at2
from rockfrag.units import STANDARD_GRAVITY

VARIANT_FILES = {
    "nga-west2": "peer_original/NHERI-SimCenter__EE-UQ/RSN125_FRIULI.A_A-TMZ000.AT2",
    "nga-west2 with filter text": "peer_original/NHERI-SimCenter__EE-UQ/RSN1084_NORTHR_SCS052.AT2",
    "nga-west2 CRLF":
        "peer_original/GeorgePapazafeiropoulos__PEER-Ground-Motion-Data-Base-Reader/RSN1633_MANJIL_ABBAR--L.AT2",
    "nga-west1 'NPTS, DT'": "peer_original/arkottke__pystrata/NIS090.AT2",
    "old PEER Pacific Engineering": "peer_original/adzetto__DASK_26/BOL090.AT2",
    "old PEER CDMG": "peer_original/OpenSees__OpenSees/RIO270.AT2",
    "lower-case dt without SEC": "peer_original/OpenSees__OpenSees/ANLA196.AT2",
    "lower-case dt with SEC": "peer_original/OpenSees__OpenSees/PBFEAS.AT2",
    "CR CR LF line ends": "peer_original/OpenSees__OpenSees/ARL360.at2",
    "Peknold 8F10.5, no final newline": "peer_original/OpenSees__OpenSees/elCentro.AT2",
    "FEMA P695 export": "fema_p695/farfield/DUZCE/BOL000.AT2",
}


def _manifest(records_dir):
    with open(records_dir / "MANIFEST.csv", newline="") as handle:
        return {row["file"]: row for row in csv.DictReader(handle)}


@pytest.mark.parametrize("variant", list(VARIANT_FILES))
def test_every_header_variant_reads_with_obspy_autodetection(variant, records_dir):
    relative = VARIANT_FILES[variant]
    row = _manifest(records_dir)[relative]
    stream = obspy.read(str(records_dir / relative))  # no format given: the plugin detects it
    trace = stream[0]
    assert trace.stats._format == "PEER_AT2"
    assert trace.stats.npts == int(row["npts"])
    assert trace.stats.delta == pytest.approx(float(row["dt_s"]))
    # The catalogue's PGA [g] was computed independently from the raw file.
    assert np.max(np.abs(trace.data)) / STANDARD_GRAVITY == pytest.approx(float(row["pga_g"]), abs=6e-5)
    assert trace.stats.units == "m/s^2"


def test_every_shipped_file_matches_catalogue(records_dir):
    for relative, row in _manifest(records_dir).items():
        if not relative.lower().endswith(".at2"):
            continue  # CSMIP and ASDF files: tests/test_three_component.py
        data, dt, header = parse_peer_at2(records_dir / relative)
        assert data.size == int(row["npts"]), relative
        assert np.max(np.abs(data)) / STANDARD_GRAVITY == pytest.approx(float(row["pga_g"]), abs=6e-5), relative


def test_bolu_pga_matches_published_value(bolu_path):
    data, dt, header = parse_peer_at2(bolu_path)
    assert round(np.max(np.abs(data)) / STANDARD_GRAVITY, 2) == 0.82  # PEER / FEMA P695 Table A-4
    assert dt == 0.01 and data.size == 5590


def test_genuine_and_exported_bolu_agree(records_dir, bolu_path):
    genuine, _, header = parse_peer_at2(records_dir / "peer_original/adzetto__DASK_26/BOL090.AT2")
    exported, _, _ = parse_peer_at2(bolu_path)
    assert np.max(np.abs(genuine - exported)) < 1e-6 * np.max(np.abs(genuine)) * 10
    assert header["station"] == "BOLU" and header["component"] == "090"
    assert header["event"] == "DUZCE"


def test_header_metadata_nga_west2(records_dir):
    stream = obspy.read(str(records_dir / VARIANT_FILES["nga-west2 with filter text"]))
    header = stream[0].stats.peer_at2
    assert header.event == "Northridge-01"
    assert header.station == "Sylmar - Converter Sta"
    assert header.component == "52"
    assert "POLE" in header.filter


def test_detection_never_raises_and_rejects_other_files(tmp_path):
    assert not is_peer_at2(tmp_path / "missing.AT2")
    (tmp_path / "x.bin").write_bytes(bytes(range(256)) * 4)
    assert not is_peer_at2(tmp_path / "x.bin")
    (tmp_path / "x.txt").write_text("hello\nworld\n")
    assert not is_peer_at2(tmp_path / "x.txt")
    assert not is_peer_at2(io.BytesIO(b""))


# ---------------------------------------------------------------- bad input

HEADER = ("PEER NGA STRONG MOTION DATABASE RECORD\nTest, 1/1/2000, Station, 090\n"
          "ACCELERATION TIME SERIES IN UNITS OF G\n")


def _write(tmp_path, text, name="bad.AT2"):
    path = tmp_path / name
    path.write_bytes(text.encode("latin-1") if isinstance(text, str) else text)
    return path


@pytest.mark.parametrize("body, pattern, line", [
    ("NPTS=  6, DT= .01 SEC\n .1 .2 .3\n .4 .5\n", r"truncated data: found 5 values.*NPTS = 6", 6),
    ("NPTS=  4, DT= .01 SEC\n .1 .2 .3\n .4 .5\n", r"found 5 values.*NPTS = 4", 6),
    ("NPTS=  4, DT= .01 SEC\n .1 .2\n abc .4\n", r"'abc' is not a number", 6),
    ("NPTS=  4, DT= .01 SEC\n .1 .2\n .3 NaN\n", r"'NaN' is not finite", 6),
    ("NPTS=  4, DT= .01 SEC\n .1 inf\n .3 .4\n", r"'inf' is not finite", 5),
    ("NPTS=  4, DT= 0 SEC\n .1 .2 .3 .4\n", r"DT = 0 is not a positive time step", 4),
    ("NPTS=  4, DT= -.01 SEC\n .1 .2 .3 .4\n", r"not a positive time step", 4),
    ("NPTS=  4\n .1 .2 .3 .4\n", r"DT is missing", 4),
    ("DT= .01 SEC\n .1 .2 .3 .4\n", r"NPTS is missing", 4),
])
def test_corrupt_files_give_one_clear_error(tmp_path, body, pattern, line):
    path = _write(tmp_path, HEADER + body)
    with pytest.raises(RecordError) as caught:
        parse_peer_at2(path)
    assert re.search(pattern, str(caught.value)), str(caught.value)
    assert str(path) in str(caught.value)
    assert caught.value.line == line


def test_empty_and_binary_files(tmp_path):
    with pytest.raises(RecordError, match="empty"):
        parse_peer_at2(_write(tmp_path, b"", "empty.AT2"))
    with pytest.raises(RecordError, match="binary"):
        parse_peer_at2(_write(tmp_path, b"\x00\x01\x02garbage" * 50, "garbage.AT2"))
    with pytest.raises(RecordError, match="no NPTS/DT line"):
        parse_peer_at2(_write(tmp_path, "just some\ntext\n", "text.AT2"))


def test_velocity_file_is_refused(tmp_path):
    text = HEADER.replace("ACCELERATION", "VELOCITY").replace("UNITS OF G", "UNITS OF CM/S") + \
        "NPTS= 2, DT= .01 SEC\n .1 .2\n"
    with pytest.raises(RecordError, match="not acceleration"):
        parse_peer_at2(_write(tmp_path, text))


# Hypothesis: corruptions of a real file are always reported as RecordError naming the file and line.

@pytest.fixture(scope="module")
def real_text(records_dir):
    return (records_dir / VARIANT_FILES["old PEER Pacific Engineering"]).read_text()


def _lines(text):
    return text.split("\n")


corruption = st.one_of(
    st.tuples(st.just("truncate"), st.integers(1, 400)),
    st.tuples(st.just("extra"), st.integers(1, 20)),
    st.tuples(st.just("token"), st.sampled_from(["abc", "1.2.3", "--5", "0x1F", "1e", "#"])),
    st.tuples(st.just("nonfinite"), st.sampled_from(["nan", "NaN", "inf", "-Infinity", "1e999"])),
)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(kind=corruption, position=st.integers(4, 1000))
def test_hypothesis_corruptions_of_real_file(tmp_path, real_text, kind, position):
    lines = _lines(real_text)
    name, value = kind
    data_lines = list(range(4, len(lines) - 1))
    target = data_lines[position % len(data_lines)]
    if name == "truncate":
        tokens = " ".join(lines[4:]).split()
        lines = lines[:4] + [" ".join(tokens[: len(tokens) - value])]
    elif name == "extra":
        lines.append(" 0.1" * value)
    else:
        tokens = lines[target].split()
        tokens[position % len(tokens)] = value
        lines[target] = "   ".join(tokens)
    path = _write(tmp_path, "\n".join(lines), "corrupt.AT2")
    with pytest.raises(RecordError) as caught:
        parse_peer_at2(path)
    message = str(caught.value)
    assert str(path) in message
    if name in ("token", "nonfinite"):
        assert caught.value.line == target + 1, message
        assert value in message


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(ending=st.sampled_from(["\n", "\r\n", "\r", "\r\r\n"]), final_newline=st.booleans(),
       strip_zero=st.booleans())
def test_hypothesis_harmless_layout_changes_read_identically(tmp_path, real_text, ending, final_newline,
                                                              strip_zero):
    reference, dt_reference, _ = parse_peer_at2(io.BytesIO(real_text.encode()))
    text = real_text.rstrip("\n")
    if strip_zero:
        text = re.sub(r"(?<![0-9])0\.(\d)", r".\1", text)
    text = text.replace("\n", ending) + (ending if final_newline else "")
    data, dt, _ = parse_peer_at2(_write(tmp_path, text.encode(), "layout.AT2"))
    assert dt == dt_reference
    np.testing.assert_array_equal(data, reference)
