"""Record catalogue, record sets, batch loading with failures, obspy-native formats, duplicates by content,
K-NET metadata and selections that name nothing."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import obspy
import pytest

from rockfrag.errors import ManifestError, RecordError
from rockfrag.records import list_formats, load_records, read_record, record_sets, same_samples
from rockfrag.records.manifest import load_catalogue, verify


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


# ---------------------------------------------------------------- issue 21: duplicates, K-NET metadata, typos

KNET_FILE = Path(obspy.__file__).parent / "io" / "nied" / "tests" / "data" / "test.knet"
"""obspy's K-NET sample: Origin Time 1996/08/11 03:12:00 (JST), Mag. 5.9, station AKT013, E-W."""


def _knet_as_csv(path, digits=6, demean=False):
    """The K-NET sample's samples in gal as a two-column CSV, written from obspy's counts (not our reader)."""
    raw = obspy.read(str(KNET_FILE))[0]
    gal = raw.data.astype(float) * raw.stats.calib * 100.0  # obspy's calib is in m/s^2 per count
    if demean:
        gal -= gal.mean()
    rows = "\n".join(f"{i * raw.stats.delta:.2f},{value:.{digits}g}" for i, value in enumerate(gal))
    path.write_text(f"time [s],acc [gal]\n{rows}\n")
    return path


@pytest.mark.parametrize("digits, demean", [(6, False), (4, True)])
def test_a_csv_and_a_knet_file_with_the_same_samples_keep_one(tmp_path, digits, demean):
    knet = tmp_path / "AKT0139608110312.EW"
    shutil.copy(KNET_FILE, knet)
    csv = _knet_as_csv(tmp_path / "akt013_ew.csv", digits, demean)
    records, failures = load_records([str(knet), str(csv)])
    assert [r.id for r in records] == ["AKT0139608110312"]
    assert len(failures) == 1
    message = str(failures[0])
    assert message.startswith(str(csv)) and "same samples as record AKT0139608110312" in message
    assert "skipped as a duplicate" in message


def test_a_scaled_copy_is_not_a_duplicate(tmp_path):
    csv = _knet_as_csv(tmp_path / "akt013_ew.csv")
    doubled = tmp_path / "doubled.csv"
    lines = csv.read_text().splitlines()
    doubled.write_text("\n".join([lines[0]] + [f"{t},{2 * float(a):.6g}" for t, a in
                                               (line.split(",") for line in lines[1:])]) + "\n")
    records, failures = load_records([str(KNET_FILE), str(doubled)])
    assert len(records) == 2 and failures == []


def test_a_user_copy_of_a_catalogue_record_is_a_duplicate(tmp_path, bolu_records):
    bolu = bolu_records["DUZCE/BOL090"]
    copy = tmp_path / "mine.csv"
    g = bolu.acceleration / 9.80665
    copy.write_text("acc [g]\n" + "\n".join(f"{value:.7g}" for value in g) + "\n")
    records, failures = load_records(["DUZCE/BOL090", str(copy)], dt=bolu.dt)
    assert [r.id for r in records] == ["DUZCE/BOL090"]
    assert "same samples as record DUZCE/BOL090" in str(failures[0])


def test_catalogue_originals_beside_their_exports_are_both_kept():
    """PEER/BOL090 (the genuine PEER file) agrees with DUZCE/BOL090 (the P695 export) within 6e-7 x PGA;
    the catalogue lists both on purpose, so records of the catalogue are not compared with one another."""
    records, failures = load_records(["DUZCE/BOL090", "PEER/BOL090"])
    assert [r.id for r in records] == ["DUZCE/BOL090", "PEER/BOL090"] and failures == []
    assert same_samples(*records)


def test_knet_header_gives_event_magnitude_origin_time_and_station(tmp_path):
    path = tmp_path / "AKT0139608110312.EW"
    shutil.copy(KNET_FILE, path)
    header = {line[:18].strip(): line[18:].strip() for line in KNET_FILE.read_text().splitlines()[:6]}
    records, failures = load_records(str(path))
    metadata = records[0].metadata
    assert failures == [] and header["Origin Time"] == "1996/08/11 03:12:00"  # JST = UTC + 9 h
    assert metadata["origin_time"] == "1996-08-10T18:12:00Z" and metadata["year"] == 1996
    assert metadata["magnitude"] == float(header["Mag."]) == 5.9
    assert metadata["station"] == header["Station Code"] == "AKT013" and metadata["component"] == "EW"
    assert metadata["event"] == "1996-08-10 18:12:00 UTC M5.9, 38.92N 140.63E, 7 km deep"
    assert metadata["units"] == "gal"


@pytest.mark.parametrize("selection, error, fragments", [
    ("far-feild", ManifestError, ["unknown record selection 'far-feild'", "did you mean 'far-field'?"]),
    ("near-field-puls", ManifestError, ["did you mean 'near-field-pulse'?"]),
    ("DUZCE/BOL09", ManifestError, ["did you mean 'DUZCE/BOL090'?"]),
    ("no-such-set", ManifestError, ["unknown record selection", "far-field, near-field"]),
])
def test_a_misspelt_record_set_gets_a_did_you_mean(selection, error, fragments):
    with pytest.raises(error) as caught:
        load_records(selection)
    assert "\n" not in str(caught.value)
    for fragment in fragments:
        assert fragment in str(caught.value)


def test_a_missing_record_file_says_not_found(tmp_path):
    (tmp_path / "cabinet_record.csv").write_text("acc [g]\n0.1\n0.2\n")
    with pytest.raises(RecordError) as caught:
        load_records(str(tmp_path / "cabinet_recrod.csv"))
    assert str(caught.value) == f"{tmp_path / 'cabinet_recrod.csv'}: not found (did you mean 'cabinet_record.csv'?)"
    with pytest.raises(RecordError, match="not found; no such file or folder in"):
        load_records(str(tmp_path / "quake.AT2"))
    with pytest.raises(RecordError, match="not found; the folder .*missing does not exist either"):
        load_records(str(tmp_path / "missing" / "quake.AT2"))
