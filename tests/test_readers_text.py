"""Records as users have them: one- and two-column text/CSV with --dt/--units, K-NET units from its header."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import obspy
import pandas as pd
import pytest

from rockfrag.cli import main
from rockfrag.errors import RecordError
from rockfrag.records import detect_format, load_records, read_record
from rockfrag.records.text import read_columns
from rockfrag.units import STANDARD_GRAVITY

KNET_FILE = Path(obspy.__file__).parent / "io" / "nied" / "tests" / "data" / "test.knet"
SAMPLES = [0.0, 0.1, -0.25, 0.05, 0.0]


def _pulse(peak, n=2000, dt=0.01):
    """A 2 Hz sine under a Hann envelope: band-pass processing leaves its peak within ~1%."""
    time = np.arange(n) * dt
    return "\n".join(f"{a:.6g}" for a in peak * np.sin(2 * np.pi * 2.0 * time) * np.hanning(n)) + "\n"


def _write(folder, name, text):
    path = folder / name
    path.write_text(text)
    return path


def _two_columns(separator=",", header="time [s], acc [g]\n", dt=0.01):
    rows = "".join(f"{i * dt:.4f}{separator}{a}\n" for i, a in enumerate(SAMPLES))
    return header + rows


@pytest.mark.parametrize("separator", [",", ";", "\t", "   "])
def test_two_columns_with_units_in_the_header(tmp_path, separator):
    path = _write(tmp_path, "motion.csv", _two_columns(separator))
    trace = read_record(path)
    assert trace.stats.delta == pytest.approx(0.01)
    np.testing.assert_allclose(trace.data, np.array(SAMPLES) * STANDARD_GRAVITY)
    assert trace.stats.units == "m/s^2"


def test_two_columns_with_units_from_the_user(tmp_path):
    path = _write(tmp_path, "motion.txt", _two_columns(header="# station XYZ\n", dt=0.005))
    trace = read_record(path, units="gal")
    assert trace.stats.delta == pytest.approx(0.005)
    np.testing.assert_allclose(trace.data, np.array(SAMPLES) * 0.01)


def test_one_column_with_dt_and_units(tmp_path):
    path = _write(tmp_path, "motion.txt", "\n".join(str(a) for a in SAMPLES) + "\n")
    trace = read_record(path, units="m/s^2", dt=0.02)
    assert trace.stats.delta == 0.02 and trace.stats.npts == len(SAMPLES)
    np.testing.assert_allclose(trace.data, SAMPLES)


@pytest.mark.parametrize("text, options, words, line", [
    ("0.1\n0.2\n0.3\n", {"units": "g"}, "--dt", None),
    ("0,0.1\n0.01,0.2\n0.02,0.3\n", {}, "--units", None),
    ("0,0.1\n0.01,0.2\n0.05,0.3\n0.06,0.1\n", {"units": "g"}, "uneven time step", 3),
    ("0,0.1\n0.01,0.2\n0.01,0.3\n", {"units": "g"}, "time must increase", 3),
    ("t,a\n0,0.1\n0.01,abc\n0.02,0.3\n", {"units": "g"}, "'abc' is not a number", 3),
    ("0,0.1,5\n0.01,0.2,5\n", {"units": "g"}, "3 columns", 1),
    ("0,0.1\n0.01\n", {"units": "g"}, "1 columns", 2),
    ("time [s], acc [g]\n0,0.1\n0.01,0.2\n", {"units": "gal"}, "disagrees with the header", None),
    ("0,0.1\n0.01,0.2\n", {"units": "g", "dt": 0.02}, "disagrees with the time column", None),
    ("0,0.1\n0.01,nan\n", {"units": "g"}, "NaN or infinite", 2),
    ("header only\n", {"units": "g"}, "expected", None),
    ("0,0.1\n0.01,0.2\n", {"units": "furlongs"}, "unknown acceleration unit", None),
])
def test_bad_text_record_names_file_line_and_problem(tmp_path, text, options, words, line):
    path = _write(tmp_path, "bad.csv", text)
    with pytest.raises(RecordError) as caught:
        read_record(path, format="TEXT", **options)
    assert words in str(caught.value) and str(path) in str(caught.value)
    assert caught.value.line == line


def test_detection_leaves_at2_and_notes_alone(tmp_path, bolu_path):
    assert detect_format(_write(tmp_path, "motion.csv", _two_columns())) == "TEXT"
    assert detect_format(_write(tmp_path, "README.txt", "These are my records.\nSee the report.\n")) is None
    assert detect_format(bolu_path) == "PEER_AT2"


def test_folder_of_text_records_skips_notes(tmp_path):
    folder = tmp_path / "mine"
    folder.mkdir()
    _write(folder, "a.csv", _two_columns())
    _write(folder, "b.txt", _two_columns(header="time [s]; acc [cm/s^2]\n", separator=";"))
    _write(folder, "README.txt", "Two records from the site survey.\n")
    records, failures = load_records(folder)
    assert [r.id for r in records] == ["a", "b"] and failures == []
    np.testing.assert_allclose(records[1].acceleration, np.array(SAMPLES) * 0.01)
    assert records[0].metadata["units"] == "g"


def test_knet_units_come_from_its_header():
    trace = read_record(KNET_FILE)  # no units given: the header states gal through its scale factor
    assert trace.stats.units == "m/s^2"
    header_peak_gal = 4.383  # "Max. Acc. (gal)" line of the file
    assert np.max(np.abs(trace.data)) == pytest.approx(header_peak_gal * 0.01, rel=0.01)


def test_records_command_reads_text_with_dt_and_units(tmp_path, capsys):
    path = _write(tmp_path, "site.txt", _pulse(0.2))
    status = main(["records", "--set", str(path), "--dt", "0.01", "--units", "g", "--output", str(tmp_path / "out"),
                   "--no-progress"])
    assert status == 0
    table = pd.read_csv(tmp_path / "out" / "records.csv")
    assert list(table["id"]) == ["site"]
    assert table["pga_m_s2"].iloc[0] == pytest.approx(0.2 * STANDARD_GRAVITY, rel=0.02)


def test_study_states_units_and_dt_of_its_text_records(tmp_path, capsys):
    path = _write(tmp_path, "site.txt", _pulse(50.0))
    study = _write(tmp_path, "study.toml", f'[study]\nrecord_sets = ["{path}"]\nunits = "gal"\ndt = 0.01\n'
                                           f'output = "{tmp_path / "out"}"\n')
    assert main(["records", str(study), "--no-progress"]) == 0
    table = pd.read_csv(tmp_path / "out" / "records.csv")
    assert table["pga_m_s2"].iloc[0] == pytest.approx(0.5, rel=0.02)


def test_one_column_without_dt_is_skipped_with_its_reason(tmp_path, capsys):
    path = _write(tmp_path, "site.txt", "0.1\n0.2\n0.1\n")
    status = main(["records", "--set", str(path), "--units", "g", "--output", str(tmp_path / "out"), "--no-progress"])
    assert status == 2
    assert "--dt" in capsys.readouterr().err


def test_one_table_reader_gives_header_names_and_lines(tmp_path):
    """records/text.read_columns reads text records and calibration references alike."""
    text = "# exported by the logger\nsite A, north\ntime [s]; theta [deg]; note\n0;0.1;a\n\n0.01;0.2;b\n"
    table = read_columns(_write(tmp_path, "table.csv", text), "two columns", counts=(2,), extra=True)
    assert table.header == ("site A, north", "time [s]; theta [deg]; note")
    assert table.name(0) == "time [s]" and table.name(1) == "theta [deg]" and table.lines == (4, 6)
    np.testing.assert_array_equal(table.values, [[0.0, 0.1], [0.01, 0.2]])
    with pytest.raises(RecordError, match=r"line 3: column 'theta \[deg\]': 'x' is not a number"):
        read_columns(_write(tmp_path, "bad.csv", "time [s], theta [deg]\n0, 1\n0.01, x\n"), "two columns")
    with pytest.raises(RecordError, match=r"line 2: column 'time \[s\]': 'x' is not a number"):  # no 2nd header
        read_columns(_write(tmp_path, "first.csv", "time [s], theta [deg]\nx, 1\n0.01, 2\n"), "two columns",
                     header_lines=1)
    with pytest.raises(RecordError, match=r"line 3: time must increase from line to line \(column 't'\)"):
        read_columns(_write(tmp_path, "back.csv", "t a\n0 1\n0 2\n"), "two columns").time(0)
