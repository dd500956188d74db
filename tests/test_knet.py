"""K-NET/KiK-net files as users have them: found inside folders, and a bad header named by line, field and reason;
an empty file is called empty (issue 33's traps)."""

from __future__ import annotations

import shutil
from pathlib import Path

import obspy
import pytest

from rockfrag.cli import main
from rockfrag.errors import RecordError
from rockfrag.records import load_records, read_record
from rockfrag.records.knet import HEADER, check_header, is_knet

KNET_FILE = Path(obspy.__file__).parent / "io" / "nied" / "tests" / "data" / "test.knet"
"""obspy's K-NET sample: station AKT013, E-W, scale factor 2000(gal)/8388608."""


def _with_line(tmp_path, number, text, name="AKT0139608110312.EW"):
    """The sample with its header line ``number`` (1-based) replaced by ``text``."""
    lines = KNET_FILE.read_text().splitlines(keepends=True)
    lines[number - 1] = text + "\n"
    path = tmp_path / name
    path.write_text("".join(lines))
    return path


def test_knet_files_inside_folders_load(tmp_path):
    site = tmp_path / "site" / "event-1"
    site.mkdir(parents=True)
    shutil.copy(KNET_FILE, site / "AKT0139608110312.EW")
    (site / "notes.txt").write_text("not a record\n")
    records, failures = load_records(str(tmp_path / "site"))
    assert [record.id for record in records] == ["AKT0139608110312"] and not failures
    direct = read_record(KNET_FILE)
    assert records[0].trace.stats.npts == direct.stats.npts and records[0].metadata["station"] == "AKT013"


def test_a_folder_of_knet_files_is_named_in_the_empty_folder_message(tmp_path):
    (tmp_path / "empty").mkdir()
    with pytest.raises(RecordError, match="K-NET/KiK-net ASCII"):
        load_records(str(tmp_path / "empty"))


def test_the_sample_header_passes_the_check():
    assert is_knet(KNET_FILE) and len(HEADER) == 17
    check_header(KNET_FILE)


@pytest.mark.parametrize("text, fragments", [
    ("Scale Factor      2000(gal)/0", ["line 14", "'Scale Factor'", "denominator 0", "N and D > 0"]),
    ("Scale Factor      0(gal)/8388608", ["line 14", "numerator 0"]),
    ("Scale Factor      2000/8388608", ["line 14", "'Scale Factor'", "is not N(gal)/D"]),
    ("Sampling Freq(Hz) 0Hz", ["line 11", "must be > 0 Hz"]),
    ("Sampling Freq(Hz) fastHz", ["line 11", "'Sampling Freq(Hz)'", "whole number of Hz"]),
    ("Lat.              north", ["line 2", "'Lat.'", "latitude"]),
    ("Origin Time       yesterday", ["line 1", "date and time"]),
])
def test_a_bad_header_names_the_line_the_field_and_the_reason(tmp_path, text, fragments):
    path = _with_line(tmp_path, 14 if text.startswith("Scale") else 11 if text.startswith("Sampling")
                      else 2 if text.startswith("Lat.") else 1, text)
    with pytest.raises(RecordError) as caught:
        read_record(path)
    message = str(caught.value)
    assert str(path) in message and all(fragment in message for fragment in fragments), message
    assert "ZeroDivisionError" not in message and "not a readable record" not in message


def test_a_missing_header_line_is_named(tmp_path):
    lines = KNET_FILE.read_text().splitlines(keepends=True)
    path = tmp_path / "short.EW"
    path.write_text("".join(lines[:13] + lines[14:]))  # no Scale Factor line
    with pytest.raises(RecordError, match=r"line 14: K-NET header: expected the 'Scale Factor' line here"):
        read_record(path)


def test_the_command_skips_a_bad_knet_file_with_one_line_and_runs_the_rest(tmp_path, capsys):
    folder = tmp_path / "mine"
    folder.mkdir()
    shutil.copy(KNET_FILE, folder / "AKT0139608110312.EW")
    _with_line(folder, 14, "Scale Factor      2000(gal)/0", name="AKT0139608110312.NS")
    status = main(["records", "--set", str(folder), "--output", str(tmp_path / "out"), "--no-progress"])
    error = capsys.readouterr().err
    assert status == 1, error
    assert error.count("\n") == 1 and "AKT0139608110312.NS, line 14" in error and "denominator 0" in error


def test_an_empty_file_is_called_empty(tmp_path, capsys):
    path = tmp_path / "record.csv"
    path.write_bytes(b"")
    with pytest.raises(RecordError, match="file is empty \\(0 bytes\\)"):
        read_record(path)
    status = main(["records", "--set", str(path), "--output", str(tmp_path / "out"), "--no-progress"])
    error = capsys.readouterr().err
    assert status == 2 and "file is empty" in error and "Unknown format" not in error


def test_an_unknown_format_says_which_formats_are_read(tmp_path):
    path = tmp_path / "record.xyz"
    path.write_bytes(b"\x00\x01 binary nonsense " * 20)
    with pytest.raises(RecordError) as caught:
        read_record(path)
    message = str(caught.value)
    assert "not a record format rockfrag or obspy recognises" in message and "PEER_AT2" in message
    assert "TypeError" not in message
