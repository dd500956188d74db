"""Record catalogue, record sets, batch loading with failures, obspy-native formats."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from pipeline.errors import ManifestError, RecordError
from pipeline.records import list_formats, load_records, read_record, record_sets
from pipeline.records.manifest import load_catalogue, verify


def test_catalogue_sets_have_the_published_sizes():
    sets = record_sets()
    assert len(sets["far-field"]) == 44  # FEMA P695 Table A-4: 22 records x 2 components
    assert len(sets["near-field-pulse"]) == 28
    assert len(sets["near-field-no-pulse"]) == 28
    assert len(sets["peer-original"]) == 27
    assert sorted(sets["bolu"]) == ["DUZCE/BOL000", "DUZCE/BOL090"]


def test_catalogue_checksums_match_shipped_files(records_dir):
    assert verify(load_catalogue(records_dir / "MANIFEST.csv")) == []


def test_changed_file_is_reported_by_name(tmp_path, records_dir):
    copy = tmp_path / "records"
    shutil.copytree(records_dir, copy)
    target = copy / "fema_p695/farfield/DUZCE/BOL000.AT2"
    target.write_text(target.read_text().replace("7.762130E-06", "7.762131E-06", 1))
    records, failures = load_records("bolu", records_dir=copy)
    assert [r.id for r in records] == ["DUZCE/BOL090"]  # the other file goes on
    assert len(failures) == 1 and "BOL000.AT2" in str(failures[0]) and "changed" in str(failures[0])


def test_record_metadata_and_units(bolu_records):
    record = bolu_records["DUZCE/BOL090"]
    assert record.metadata["event"] == "Duzce, Turkey" and record.metadata["year"] == 1999
    assert record.trace.stats.units == "m/s^2"
    assert record.dt == 0.01 and record.duration == pytest.approx(55.89)


def test_user_folder_with_one_bad_file(tmp_path, bolu_path):
    shutil.copy(bolu_path, tmp_path / "good.AT2")
    (tmp_path / "bad.AT2").write_text("PEER\nx\nUNITS OF G\nNPTS= 10, DT= .01 SEC\n .1 .2\n")
    records, failures = load_records(str(tmp_path))
    assert [r.id for r in records] == ["good"]
    assert len(failures) == 1 and "bad.AT2" in str(failures[0]) and "truncated" in str(failures[0])


def test_unknown_selection_lists_the_sets():
    with pytest.raises(ManifestError, match="far-field"):
        load_records("no-such-set")


def test_obspy_native_format_needs_units(tmp_path, bolu_path):
    trace = read_record(bolu_path)
    native = trace.copy()
    native.data = native.data * 100.0  # store in cm/s^2
    native.stats.pop("units")
    native.stats.station = "BOLU"
    path = tmp_path / "bolu.mseed"
    native.write(str(path), format="MSEED")
    with pytest.raises(RecordError, match="units unknown"):
        read_record(path)
    again = read_record(path, units="cm/s^2")
    np.testing.assert_allclose(again.data, trace.data, rtol=1e-12)
    assert "PEER_AT2" in list_formats()
