"""Three-component records: the shipped CSMIP Volume 1 and ASDF files, their readers, the catalogue's
provenance, component grouping (H1, H2, Z) and the records table; verticals never in horizontal sets."""

from __future__ import annotations

import csv
import shutil
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import netCDF4
import numpy as np
import obspy
import pandas as pd
import pytest

from rockfrag.errors import RecordError
from rockfrag.processing import load_recipe
from rockfrag.records import (
    group_components,
    load_records,
    read_record,
    read_stream,
    record_sets,
    split_vertical,
)
from rockfrag.records.asdf import is_asdf, pre_filter, read_asdf
from rockfrag.records.csmip import is_csmip, read_csmip
from rockfrag.records.manifest import sha256_of
from rockfrag.records_report import records_stage
from rockfrag.units import STANDARD_GRAVITY

ROOT = Path(__file__).resolve().parents[1]
RIDGECREST = ROOT / "records" / "ridgecrest-2019"
NAPA = ROOT / "records" / "south-napa-2014" / "workspace.h5"
V1_FILES = {"CCC": RIDGECREST / "CICCC.RAW", "CLC": RIDGECREST / "CICLC.v1", "TOW2": RIDGECREST / "CITOW2.RAW"}
STATIONS = {"CI.CCC", "CI.CLC", "CI.TOW2", "CE.68150"}
WHEEL_PATHS = {"ridgecrest-2019/CICCC.RAW": "gmprocess/data/demo/ci38457511/raw/CICCC.RAW",
               "ridgecrest-2019/CICLC.v1": "gmprocess/data/demo/ci38457511/raw/CICLC.v1",
               "ridgecrest-2019/CITOW2.RAW": "gmprocess/data/demo/ci38457511/raw/CITOW2.RAW",
               "south-napa-2014/workspace.h5": "gmprocess/data/demo/nc72282711/workspace.h5"}


def _rows(records_dir):
    with open(records_dir / "MANIFEST.csv", newline="") as handle:
        return [row for row in csv.DictReader(handle) if "three-component" in row["sets"].split(";")]


@pytest.fixture(scope="module")
def three_component():
    records, failures = load_records("three-component")
    assert not failures, failures
    return records


# ---------------------------------------------------------------- catalogue and provenance

def test_catalogue_lists_four_stations_with_h1_h2_z(records_dir):
    rows = _rows(records_dir)
    assert len(rows) == 12 and {row["station"] for row in rows} == STATIONS
    assert sorted(record_sets()["ridgecrest-2019"]) == sorted(r["id"] for r in rows if r["station"].startswith("CI."))
    for row in rows:
        # package, version, path inside the wheel, sha256 and licence
        assert row["source"] == f"PyPI gmprocess 2.8.0:{WHEEL_PATHS[row['file']]}", row["id"]
        assert "licence: public domain" in row["notes"] and "CC0" in row["notes"], row["id"]
        assert row["sha256"] == sha256_of(records_dir / row["file"]), row["id"]
    assert sum((records_dir / name).stat().st_size for name in WHEEL_PATHS) < 5_000_000


def test_horizontal_sets_hold_no_vertical_and_far_field_is_unchanged(all_records):
    verticals = sorted(r.id for r in all_records if r.is_vertical)
    assert verticals == ["RIDGECREST/CI.CCC.HNZ", "RIDGECREST/CI.CLC.HNZ", "RIDGECREST/CI.TOW2.HNZ",
                         "SOUTHNAPA/CE.68150.HNZ"]
    sets = record_sets()
    horizontal_sets = [name for name in sets if name not in ("all", "three-component", "ridgecrest-2019",
                                                             "south-napa-2014")]
    assert set(horizontal_sets) == {"far-field", "near-field", "near-field-pulse", "near-field-no-pulse",
                                    "peer-original", "bolu"}
    assert not {i for name in horizontal_sets for i in sets[name]} & {r.id for r in all_records if r.is_vertical}
    assert len(sets["far-field"]) == 44 and len(sets["all"]) == 139
    # a single-component record keeps its file's sha256 as its identity (study checkpoints, cube checksums)
    bolu = next(r for r in all_records if r.id == "DUZCE/BOL090")
    assert bolu.metadata["sha256"] == sha256_of(bolu.metadata["file"]) and bolu.component == "H"


# ---------------------------------------------------------------- CSMIP Volume 1

@pytest.mark.parametrize("station", list(V1_FILES))
def test_v1_file_reads_three_channels_with_header_units_and_orientation(station, records_dir):
    path = V1_FILES[station]
    assert is_csmip(path)
    stream = read_csmip(path)
    rows = {row["component"]: row for row in _rows(records_dir) if row["station"] == f"CI.{station}"}
    assert [t.stats.channel for t in stream] == ["HNE", "HNN", "HNZ"]
    for trace in stream:
        header, row = trace.stats.csmip, rows[trace.stats.channel]
        assert trace.id == f"CI.{station}..{trace.stats.channel}" and trace.stats.delta == 0.01
        assert trace.stats.npts == int(row["npts"]) and trace.stats.units == "m/s^2"
        assert np.max(np.abs(trace.data)) / STANDARD_GRAVITY == pytest.approx(float(row["pga_g"]), abs=6e-5)
        assert abs(np.max(np.abs(trace.data)) / STANDARD_GRAVITY - abs(header.stated_peak)) <= 5e-4
    assert [t.stats.csmip.orientation for t in stream] == ["90 Deg", "360 Deg", "Up"]
    assert [(t.stats.csmip.azimuth, t.stats.csmip.dip) for t in stream] == [(90.0, 0.0), (0.0, 0.0), (None, -90.0)]


def test_v1_samples_start_time_and_end_match_the_text(tmp_path):
    stream = read_csmip(V1_FILES["CCC"])
    lines = V1_FILES["CCC"].read_bytes().decode("latin-1").splitlines()
    first = [float(v) for v in lines[28].split()]  # the first data line of channel 1, read independently
    np.testing.assert_allclose(stream[0].data[:8], np.array(first) * STANDARD_GRAVITY, rtol=0, atol=1e-15)
    end = lines.index(next(line for line in lines if "End of Data for Station Channel   1" in line))
    last = [float(v) for v in lines[end - 1].split()]
    np.testing.assert_allclose(stream[0].data[-len(last):], np.array(last) * STANDARD_GRAVITY, atol=1e-15)
    assert stream[0].stats.starttime == obspy.UTCDateTime(2019, 7, 6, 3, 19, 37)
    assert read_csmip(V1_FILES["CLC"])[0].stats.starttime == obspy.UTCDateTime(2019, 7, 6, 3, 16, 8)


def _edited_copy(tmp_path, edit, name="edited.RAW"):
    text = V1_FILES["CCC"].read_bytes().decode("latin-1")
    target = tmp_path / name
    target.write_bytes(edit(text).encode("latin-1"))
    return target


@pytest.mark.parametrize(("edit", "message"), [
    (lambda t: t.replace("Chan  1:  90 Deg", "Chan  1:  Long  ", 1), "orientation 'Long' is not understood"),
    (lambda t: t.replace("in units of g.", "in units of furlongs.", 1), "furlongs"),
    (lambda t: t.replace("  .000027  .000021", "  .000027  .0000x1", 1), "'.0000x1' is not a number"),
    (lambda t: t.replace("  .000027  .000021", "  .900027  .000021", 1), "disagrees with the header's Max"),
    (lambda t: t[:t.index("End of Data for Station Channel   1") - 200] + "\r\n"
     + t[t.index("/&  ----------  End of Data for Station Channel   1"):], "values"),
    (lambda t: t.replace("35430 Accelerogram points", "35430 Accelerogram pints", 1), "no data-start line"),
])
def test_v1_damage_is_one_error_naming_file_and_line(tmp_path, edit, message):
    path = _edited_copy(tmp_path, edit)
    with pytest.raises(RecordError, match=message) as caught:
        read_csmip(path)
    assert "edited.RAW" in str(caught.value) and caught.value.line is not None


def test_v1_down_channel_is_stored_up_positive(tmp_path):
    path = _edited_copy(tmp_path, lambda t: t.replace("Chan  3:  Up  ", "Chan  3:  Down", 1))
    up, down = read_csmip(V1_FILES["CCC"])[2], read_csmip(path)[2]
    np.testing.assert_array_equal(down.data, -up.data)
    assert down.stats.channel == "HNZ" and "negated" in down.stats.processing[-1]


def test_v1_is_not_mistaken_for_other_formats(records_dir):
    assert not is_csmip(records_dir / "fema_p695/farfield/DUZCE/BOL000.AT2") and not is_csmip(NAPA)
    assert not is_asdf(V1_FILES["CCC"])


def test_obspy_reads_v1_through_the_declared_entry_points(tmp_path):
    """obspy.read detects the format through pyproject's obspy.plugin.waveform entry points (installed here
    as a throw-away distribution, as `pip install -e .` would)."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    groups = {g: v for g, v in project["project"]["entry-points"].items() if g.startswith("obspy.plugin")}
    assert groups["obspy.plugin.waveform"]["CSMIP"] == "rockfrag.records.csmip"
    info = tmp_path / "rockfrag_plugin_check-0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: rockfrag-plugin-check\nVersion: 0\n")
    (info / "entry_points.txt").write_text("".join(
        f"[{group}]\n" + "".join(f"{k} = {v}\n" for k, v in points.items()) + "\n" for group, points in groups.items()))
    script = textwrap.dedent(f"""
        import sys; sys.path[:0] = [{str(tmp_path)!r}, {str(ROOT)!r}]
        import obspy
        stream = obspy.read({str(V1_FILES['TOW2'])!r})
        print(len(stream), stream[0].stats._format, stream[2].id, stream[2].stats.units)
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=tmp_path)
    assert result.stdout.split() == ["3", "CSMIP", "CI.TOW2..HNZ", "m/s^2"], result.stderr[-2000:]


# ---------------------------------------------------------------- ASDF

def _raw_counts(channel):
    with netCDF4.Dataset(NAPA) as dataset:
        dataset.set_auto_mask(False)
        group = dataset["Waveforms/CE.68150"]
        variables = {name.split("__")[0] + "/" + name.split("__")[3]: v[:] for name, v in group.variables.items()
                     if "__" in name}
        station_xml = np.asarray(group.variables["StationXML"][:]).tobytes()
    return variables[f"CE.68150..{channel}/nc72282711_unprocessed"], \
        variables[f"CE.68150..{channel}/nc72282711_default"], station_xml


@pytest.mark.parametrize("channel", ["HNE", "HNN", "HNZ"])
def test_asdf_response_removed_agrees_with_sensitivity_and_with_gmprocess(channel, records_dir, tmp_path):
    trace = read_asdf(NAPA).select(channel=channel)[0]
    counts, processed_cm_s2, station_xml = _raw_counts(channel)
    (tmp_path / "station.xml").write_bytes(station_xml)
    inventory = obspy.read_inventory(str(tmp_path / "station.xml"))
    sensitivity = inventory.select(channel=channel)[0][0][0].response.instrument_sensitivity.value  # counts/(m/s^2)
    peak = float(np.max(np.abs(trace.data)))
    # the FBA-11 is flat where the energy is: counts / sensitivity within 0.5 %
    assert peak == pytest.approx(np.max(np.abs(counts - counts.mean())) / sensitivity, rel=5e-3)
    # gmprocess's own processed trace of the same file (cm/s^2, band-passed): within 2 %
    assert peak == pytest.approx(np.max(np.abs(processed_cm_s2)) / 100.0, rel=2e-2)
    row = next(r for r in _rows(records_dir) if r["component"] == channel and r["station"] == "CE.68150")
    assert peak / STANDARD_GRAVITY == pytest.approx(float(row["pga_g"]), abs=6e-5)
    assert trace.stats.npts == int(row["npts"]) == counts.size and trace.stats.sampling_rate == 200.0
    assert trace.stats.processing[-1].startswith("rockfrag asdf: remove_response(StationXML of CE.68150, "
                                                 "output='ACC', pre_filt=(0.02, 0.05, 80.0, 90.0) Hz")
    assert "0x" not in " ".join(trace.stats.processing)  # no memory address: reproducible provenance


def test_asdf_orientation_event_and_tags(tmp_path):
    stream = read_asdf(NAPA)
    assert [(t.stats.channel, t.stats.asdf.vertical, t.stats.asdf.azimuth) for t in stream] == \
        [("HNE", False, 90.0), ("HNN", False, 0.0), ("HNZ", True, None)]
    event = stream[0].stats.asdf.event
    assert event["magnitude"] == pytest.approx(6.02) and event["origin_time"].year == 2014
    assert pre_filter(200.0) == (0.02, 0.05, 80.0, 90.0)
    with pytest.raises(RecordError, match="holds floats, not raw counts"):
        read_asdf(NAPA, tag="nc72282711_default")
    processed = read_asdf(NAPA, tag="nc72282711_default", units="cm/s^2")
    assert processed[0].stats.npts == 6997 and not processed[0].stats.get("processing")
    with pytest.raises(RecordError, match="nc72282711_unprocessed"):
        read_asdf(NAPA, tag="no-such-tag")
    plain = tmp_path / "plain.nc"
    with netCDF4.Dataset(plain, "w") as dataset:
        dataset.title = "not ASDF"
    assert is_asdf(NAPA) and not is_asdf(plain)
    with pytest.raises(RecordError, match="ASDF"):
        read_asdf(plain)


# ---------------------------------------------------------------- records, groups, table

def test_three_component_set_loads_as_twelve_components(three_component, records_dir):
    assert len(three_component) == 12
    identities = {r.metadata["sha256"] for r in three_component}
    assert len(identities) == 12  # one file, three components: three identities
    for record in three_component:
        assert record.metadata["file_sha256"] == sha256_of(record.metadata["file"])
        assert record.metadata["sha256"] == f"{record.metadata['file_sha256']}#{record.trace.id}"
        assert record.trace.stats.channel == record.metadata["component"]
        assert record.is_vertical == (record.metadata["component"] == "HNZ")
    horizontal, vertical = split_vertical(three_component)
    assert len(horizontal) == 8 and [r.component for r in vertical] == ["Z"] * 4


def test_group_components_gives_h1_h2_z_per_station(three_component):
    groups = group_components(three_component)
    assert [(g.event, g.station) for g in groups] == [
        ("Ridgecrest, California", "CI.CCC"), ("Ridgecrest, California", "CI.CLC"),
        ("Ridgecrest, California", "CI.TOW2"), ("South Napa, California", "CE.68150")]
    for group in groups:
        assert list(group.components) == ["H1", "H2", "Z"]
        assert (group.h1.trace.stats.channel, group.h2.trace.stats.channel, group.z.trace.stats.channel) == \
            ("HNN", "HNE", "HNZ")
    aligned = groups[0].aligned()  # CCC: 35402, 35430 and 35406 samples from the same start
    assert {r.trace.stats.npts for r in aligned.values()} == {35402}
    assert len({r.trace.stats.starttime.ns for r in aligned.values()}) == 1
    np.testing.assert_array_equal(aligned["H2"].acceleration, groups[0].h2.acceleration[:35402])


def test_group_keeps_versions_from_different_sets_apart(bolu_records):
    records, _ = load_records(["bolu", "PEER/BOL090"])
    groups = group_components(records)
    assert [{k: r.id for k, r in g.components.items()} for g in groups] == [
        {"H1": "DUZCE/BOL000", "H2": "DUZCE/BOL090"}, {"H1": "PEER/BOL090"}]


def test_aligned_refuses_different_time_steps(three_component):
    group = group_components(three_component)[0]
    group.components["Z"] = group.z.with_trace(group.z.trace.copy().decimate(2, no_filter=True))
    with pytest.raises(RecordError, match="different time steps"):
        group.aligned()


def test_user_files_give_one_record_per_component(tmp_path):
    folder = tmp_path / "mine"
    folder.mkdir()
    shutil.copy(V1_FILES["CCC"], folder / "CICCC.RAW")
    shutil.copy(NAPA, folder / "napa.h5")
    records, failures = load_records(str(folder))
    assert not failures
    assert [r.id for r in records] == ["CICCC/CI.CCC..HNE", "CICCC/CI.CCC..HNN", "CICCC/CI.CCC..HNZ",
                                       "napa/CE.68150..HNE", "napa/CE.68150..HNN", "napa/CE.68150..HNZ"]
    groups = group_components(records)
    assert [(g.station, list(g.components)) for g in groups] == [("CI.CCC", ["H1", "H2", "Z"]),
                                                                 ("CE.68150", ["H1", "H2", "Z"])]
    assert records[3].metadata["event"].startswith("2014-08-24 10:20:44 UTC M6.02")
    assert records[3].metadata["magnitude"] == pytest.approx(6.02) and records[0].metadata["year"] == 2019
    with pytest.raises(RecordError, match="holds 3 components .*read_stream"):
        read_record(folder / "CICCC.RAW")
    assert len(read_stream(folder / "CICCC.RAW")) == 3


def test_same_file_in_two_folders_keeps_component_ids_apart(tmp_path):
    for name in ("site-a", "site-b"):
        (tmp_path / name).mkdir()
    shutil.copy(V1_FILES["CCC"], tmp_path / "site-a" / "X.RAW")
    other = V1_FILES["CLC"].read_bytes().replace(b".CI.CLC.--.HN", b".CI.CCC.--.HN")  # other samples, same codes
    (tmp_path / "site-b" / "X.RAW").write_bytes(other)
    records, failures = load_records([str(tmp_path / "site-a"), str(tmp_path / "site-b")])
    assert not failures
    assert [r.id for r in records] == [f"{site}/X/CI.CCC..{channel}" for site in ("site-a", "site-b")
                                       for channel in ("HNE", "HNN", "HNZ")]


def test_records_table_shows_groups_and_each_components_pga(three_component, tmp_path):
    table, _ = records_stage(three_component, load_recipe(), tmp_path, progress=False)
    written = pd.read_csv(tmp_path / "records.csv")
    assert list(written["group"]) == [1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4]
    assert list(written["axis"]) == ["H2", "H1", "Z"] * 4  # catalogue order: HNE, HNN, HNZ
    assert list(written["orientation"]) == ["horizontal", "horizontal", "vertical"] * 4
    napa = written[written["station"] == "CE.68150"].set_index("axis")
    # processed PGA per component; gmprocess's WaveFormMetrics in the same file: 37.3 and 33.9 %g horizontal, 21.5 %g Z
    assert napa["pga_g"].to_dict() == pytest.approx({"H1": 0.339, "H2": 0.373, "Z": 0.215}, abs=0.003)
