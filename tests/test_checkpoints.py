"""Checkpoints verify themselves (issue 13): a checkpoint round-trips bit for bit, damaged bytes are
rejected with their reason, and a damaged checkpoint in a study's folder is reported, quarantined and
recomputed, giving the same cube."""

from __future__ import annotations

import io
import shutil

import numpy as np
import pytest
import xarray as xr

from rockfrag.checkpoints import CheckpointStore, DamagedCheckpoint, decode, encode
from rockfrag.config import load_study
from rockfrag.study import run_study
from tests.reliability_helpers import QUIET, write_tiny_study


def test_checkpoint_round_trip_keeps_plain_and_structured_arrays(tmp_path):
    store = CheckpointStore(tmp_path)
    plain = np.arange(12.0).reshape(3, 4)
    structured = np.zeros(3, dtype=[("peak_angle", "f8"), ("outcome", "i1")])
    structured["peak_angle"] = [0.1, np.nan, 2.0]
    store.save("a", plain)
    store.save("b", structured)
    assert np.array_equal(store.load("a", (3, 4), np.float64), plain)
    loaded = store.load("b", (3,), structured.dtype)
    assert loaded.dtype == structured.dtype and loaded.tobytes() == structured.tobytes()


@pytest.mark.parametrize("damage, reason", [
    (lambda data, other: b"", "empty"),
    (lambda data, other: data[: len(data) // 2], "truncated"),
    (lambda data, other: data[:60], "truncated"),
    (lambda data, other: b"this is a text file\n", "not a rockfrag checkpoint"),
    (lambda data, other: data.replace(b'"sha256": "', b'"sha256": "0'), "sha256"),
    (lambda data, other: data[:-8] + np.float64(np.nan).tobytes(), "sha256"),
    (lambda data, other: data[:-8] + np.float64(123.0).tobytes(), "sha256"),
    (lambda data, other: other, "another cell"),
])


def test_damaged_checkpoint_bytes_are_rejected(damage, reason):
    array = np.linspace(0, 1, 6).reshape(2, 3)
    data = encode("key-1", array)
    with pytest.raises(DamagedCheckpoint, match=reason):
        decode(damage(data, encode("key-2", array)), "key-1", (2, 3), np.float64)


def test_plain_npy_and_wrong_shape_or_dtype_are_rejected(tmp_path):
    buffer = io.BytesIO()
    np.save(buffer, np.full((2, 3), np.nan))
    with pytest.raises(DamagedCheckpoint, match="not a rockfrag checkpoint"):
        decode(buffer.getvalue(), "k")
    data = encode("k", np.zeros((2, 3)))
    with pytest.raises(DamagedCheckpoint, match="shape"):
        decode(data, "k", (3, 3), np.float64)
    with pytest.raises(DamagedCheckpoint, match="dtype"):
        decode(data, "k", (2, 3), np.float32)


@pytest.fixture(scope="module")
def tiny_study(tmp_path_factory):
    """One short synthetic record, 2 levels, 2 soils, the 3 default blocks, Housner and SSI."""
    return write_tiny_study(tmp_path_factory.mktemp("tiny"))


@pytest.fixture(scope="module")
def tiny_reference(tiny_study, tmp_path_factory):
    output = tmp_path_factory.mktemp("reference")
    dataset, stats = run_study(load_study(tiny_study), output=output, workers=1, **QUIET)
    return output, dataset


CORRUPTIONS = {
    "empty": lambda path: path.write_bytes(b""),
    "truncated": lambda path: path.write_bytes(path.read_bytes()[:-40]),
    "text": lambda path: path.write_text("not numbers\n"),
    "plain npy with NaN": lambda path: np.save(open(path, "wb"), np.full((2, 15), np.nan)),
    "value 123": lambda path: path.write_bytes(path.read_bytes()[:-8] + np.float64(123).tobytes()),
    "NaN value": lambda path: path.write_bytes(path.read_bytes()[:-8] + np.float64(np.nan).tobytes()),
    "another cell's file": None,  # filled in the test: a valid checkpoint of another key
}


@pytest.mark.parametrize("kind", list(CORRUPTIONS))
def test_damaged_checkpoint_is_reported_quarantined_and_recomputed(kind, tiny_study, tiny_reference, tmp_path):
    reference_output, reference = tiny_reference
    output = tmp_path / "out"
    shutil.copytree(reference_output, output)
    checkpoints = sorted((output / ".checkpoints").glob("*.ckpt"))
    victim = checkpoints[0]
    if kind == "another cell's file":
        shutil.copy(checkpoints[1], victim)
    else:
        CORRUPTIONS[kind](victim)
    messages = []
    dataset, stats = run_study(load_study(tiny_study), output=output, workers=1, progress=False,
                               log=lambda message: None, warn=messages.append)
    damaged = [m for m in messages if "damaged" in m]
    assert len(damaged) == 1 and victim.name in damaged[0], messages
    assert stats["runs_computed"] == 2  # one cell recomputed at its 2 levels
    assert len(list((output / ".checkpoints" / "quarantine").iterdir())) == 1
    assert dataset.identical(reference)
    assert xr.open_dataset(output / "cube.nc").identical(xr.open_dataset(reference_output / "cube.nc"))
