"""Processing chain: recipe validation, provenance, and every real record ending at rest."""

from __future__ import annotations

import inspect

import numpy as np
import pytest

from rockfrag.errors import ConfigError
from rockfrag.processing import (
    PROCESSING_STEPS,
    header_corners,
    integrate,
    load_recipe,
    process_record,
    recipe_from_dict,
    tail_checks,
)
from rockfrag.records import read_record


def test_every_real_record_ends_at_rest(all_records):
    recipe = load_recipe()
    for record in all_records:
        processed = process_record(record, recipe)
        velocity, displacement = integrate(processed.acceleration, processed.dt)
        assert abs(velocity[-1]) < 1e-3 * np.max(np.abs(velocity)), record.id
        assert abs(displacement[-1]) < 1e-3 * np.max(np.abs(displacement)), record.id
        assert processed.trace.stats.npts == record.trace.stats.npts, record.id
        # Processing corrects drift; it must not change the strong shaking much.
        ratio = np.max(np.abs(processed.acceleration)) / np.max(np.abs(record.acceleration))
        assert 0.7 < ratio < 1.1, record.id


def test_input_is_not_modified_and_provenance_is_kept(bolu_records):
    record = bolu_records["DUZCE/BOL090"]
    before = record.acceleration.copy()
    processed = process_record(record)
    np.testing.assert_array_equal(record.acceleration, before)
    ours = [line.split(": ", 1)[1] for line in processed.trace.stats.processing if line.startswith("rockfrag")]
    assert [line.split("(")[0] for line in ours] == [name for name, _ in load_recipe().steps]
    assert "bandpass(freqmin=0.1, freqmax=50.0, corners=4" in " ".join(ours)  # the recipe's, not a default
    assert ours[3].endswith(f"; npts {record.trace.stats.npts} -> {record.trace.stats.npts + 2 * 6000}")
    assert "padding" not in processed.trace.stats  # pad tells unpad through the trace; unpad clears it


def test_removes_a_known_drift(bolu_records):
    """A constant acceleration offset (a classic baseline error) is removed."""
    record = bolu_records["DUZCE/BOL090"]
    clean = process_record(record)
    drifting = record.with_trace(record.trace.copy())
    drifting.trace.data = drifting.trace.data + 0.02  # 0.2% g offset -> 31 m of drift over 56 s
    fixed = process_record(drifting)
    assert np.max(np.abs(fixed.acceleration - clean.acceleration)) < 0.01 * np.max(np.abs(clean.acceleration))


def test_qa_flags_a_record_that_drifts_but_keeps_it(bolu_records):
    record = bolu_records["DUZCE/BOL000"]
    drifting = record.acceleration.copy()
    drifting[-500:] += 0.5  # a step near the end: velocity grows in the tail
    flags = tail_checks(drifting, record.dt)
    assert flags and "velocity tail drift" in flags[0]
    assert tail_checks(process_record(record).acceleration, record.dt) == []


def test_header_filter_corners_are_read(records_dir):
    trace = read_record(records_dir / "peer_original/NHERI-SimCenter__EE-UQ/RSN1084_NORTHR_SCS052.AT2")
    assert header_corners(trace) == (0.2, 40.0)


@pytest.mark.parametrize("data, field", [
    ({"steps": []}, "steps"),
    ({"steps": [{"name": "wiggle"}]}, "steps[0]"),
    ({"steps": [{"name": "taper", "max_percentage": 0.9}]}, "steps[0].max_percentage"),
    ({"steps": [{"name": "taper", "width": 0.1}]}, "steps[0].width"),
    ({"steps": [{"name": "bandpass", "corners": "four"}]}, "steps[0].corners"),
    ({"steps": [{"name": "demean"}], "qa": {"tail_seconds": -1}}, "qa.tail_seconds"),
    ({"steps": [{"name": "bandpass", "freqmin": 0.1, "freqmax": 50.0}, {"name": "pad"}]}, "steps"),
    ({"steps": [{"name": "pad"}, {"name": "unpad"}]}, "steps"),  # pad reads the band-pass step's corner
    ({"steps": [{"name": "bandpass", "freqmin": 0.1}]}, "steps[0].freqmax"),  # the recipe sets both corners
    ({"steps": [{"name": "bandpass", "freqmin": 0.1, "freqmax": 50.0, "use_header_corners": "yes"}]},
     "steps[0].use_header_corners"),
    ({"steps": [{"name": "taper", "type": "kaiser"}]}, "steps[0].type"),
    ({"steps": [{"name": "baseline", "order": 6.5}]}, "steps[0].order"),
    ({"steps": [{"name": "demean"}], "overrides": {"X": {"bandpass": {"freqmax": -1.0}}}},
     "overrides.X.bandpass.freqmax"),
    ({"steps": [{"name": "demean"}], "filters": []}, "filters"),
    ({"steps": [{"name": "demean"}], "overrides": {"X": {"bandpass": {"freqmin": 0.2}}}},
     "overrides.X.bandpass"),
])
def test_bad_recipes_name_the_field(data, field):
    with pytest.raises(ConfigError) as caught:
        recipe_from_dict(data, source="user.toml")
    assert caught.value.field == field
    assert "user.toml" in str(caught.value)


def test_recipe_messages_name_the_allowed_range_and_keys():
    with pytest.raises(ConfigError, match=r"steps\[0\]\.max_percentage: 0\.9 out of range; must be a number from "
                                          r"0\.0 to 0\.5"):
        recipe_from_dict({"steps": [{"name": "taper", "max_percentage": 0.9}]}, source="user.toml")
    with pytest.raises(ConfigError, match=r"freqmax: missing; must be a number from 0\.5 to 1000\.0 \[Hz\]"):
        recipe_from_dict({"steps": [{"name": "bandpass", "freqmin": 0.1}]}, source="user.toml")
    with pytest.raises(ConfigError, match=r"unknown parameter of step 'taper' \(did you mean 'type'\?\); "
                                          r"allowed: max_percentage, type"):
        recipe_from_dict({"steps": [{"name": "taper", "typ": "hann"}]}, source="user.toml")


def test_the_shipped_recipe_is_the_authority_for_the_band_pass_corners():
    bandpass = dict(load_recipe().steps)["bandpass"]
    assert (bandpass["freqmin"], bandpass["freqmax"]) == (0.1, 50.0)
    defaults = PROCESSING_STEPS["bandpass"].defaults
    assert "freqmin" not in defaults and "freqmax" not in defaults
    parameters = inspect.signature(PROCESSING_STEPS["bandpass"].run).parameters
    assert parameters["freqmax"].default is inspect.Parameter.empty


def test_per_record_override_changes_only_that_record(bolu_records, tmp_path):
    path = tmp_path / "recipe.toml"
    default = (__import__("rockfrag").__path__[0] + "/processing.toml")
    path.write_text(open(default).read() + '\n[overrides."DUZCE/BOL090".bandpass]\nfreqmin = 0.5\n')
    recipe = load_recipe(path)
    record = bolu_records["DUZCE/BOL090"]
    default_result = process_record(record)
    overridden = process_record(record, recipe)
    assert "bandpass(freqmin=0.5, freqmax=50.0" in " ".join(overridden.trace.stats.processing)
    assert "'freqmin': 0.5" in " ".join(overridden.trace.stats.processing)  # obspy's own record of the filter
    # the pad follows the overridden corner: 1.5 * 4 / 0.5 Hz = 12 s of zeros at each end
    npts = record.trace.stats.npts
    assert f"pad(factor=1.5); npts {npts} -> {npts + 2 * 1200}" in " ".join(overridden.trace.stats.processing)
    assert not np.allclose(default_result.acceleration, overridden.acceleration)
    other = bolu_records["DUZCE/BOL000"]
    np.testing.assert_array_equal(process_record(other, recipe).acceleration, process_record(other).acceleration)
