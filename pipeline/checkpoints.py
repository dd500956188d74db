"""rockfrag.checkpoints - one self-verifying file per finished study cell.

Input : a folder (``<output>/.checkpoints``), cell keys (hashes of everything a cell depends on)
        and the NumPy arrays computed for them (any dtype NumPy saves without pickling, structured
        dtypes with named fields included).
Output: ``<key>.ckpt`` files. Each holds a one-line JSON header (format, key, shape, dtype, byte
        count and sha256 of the payload) followed by the array in ``.npy`` format.

A checkpoint that cannot be trusted (empty, truncated, text, a plain ``.npy``, edited values, a
wrong key, shape or dtype) is reported in one line, moved to ``quarantine/`` and treated as
missing, so the study recomputes that cell and goes on; a damaged file can never reach the cube.
"""

from __future__ import annotations

import hashlib
import io
import json
import time
from pathlib import Path

import numpy as np

from rockfrag.outputs import atomic_path

MAGIC = b"rockfrag-checkpoint 1\n"
"""First bytes of every checkpoint file; a different format version is quarantined and recomputed."""

SUFFIX = ".ckpt"
QUARANTINE = "quarantine"
FOLDER = ".checkpoints"
"""The folder of a study's cell checkpoints inside its output folder (the study writes it, the report dates by it)."""


class DamagedCheckpoint(Exception):
    """A checkpoint file failed to load or verify (internal: the store quarantines it)."""


def _descr(dtype) -> object:
    """JSON-comparable description of a dtype (plain or structured)."""
    return json.loads(json.dumps(np.lib.format.dtype_to_descr(np.dtype(dtype))))


def encode(key: str, array: np.ndarray) -> bytes:
    """The bytes of a checkpoint file for ``array`` under ``key``."""
    buffer = io.BytesIO()
    np.save(buffer, np.ascontiguousarray(array), allow_pickle=False)
    payload = buffer.getvalue()
    header = {"key": key, "shape": list(array.shape), "dtype": _descr(array.dtype),
              "bytes": len(payload), "sha256": hashlib.sha256(payload).hexdigest()}
    return MAGIC + json.dumps(header, sort_keys=True).encode() + b"\n" + payload


def decode(data: bytes, key: str, shape=None, dtype=None) -> np.ndarray:
    """The array stored in checkpoint bytes; ``DamagedCheckpoint`` saying why if it does not verify."""
    if not data:
        raise DamagedCheckpoint("empty file")
    if not data.startswith(MAGIC):
        raise DamagedCheckpoint("not a rockfrag checkpoint (unknown format or text)")
    end = data.find(b"\n", len(MAGIC))
    if end < 0:
        raise DamagedCheckpoint("truncated header")
    try:
        header = json.loads(data[len(MAGIC):end])
        expected_key, stored_shape, stored_dtype = header["key"], header["shape"], header["dtype"]
        n_bytes, digest = int(header["bytes"]), str(header["sha256"])
    except (ValueError, KeyError, TypeError):
        raise DamagedCheckpoint("unreadable header") from None
    payload = data[end + 1:]
    if expected_key != key:
        raise DamagedCheckpoint(f"holds the result of another cell ({str(expected_key)[:12]}...)")
    if len(payload) != n_bytes:
        raise DamagedCheckpoint(f"truncated: {len(payload)} of {n_bytes} bytes")
    if hashlib.sha256(payload).hexdigest() != digest:
        raise DamagedCheckpoint("content does not match its sha256 (edited or damaged)")
    if shape is not None and list(shape) != stored_shape:
        raise DamagedCheckpoint(f"shape {tuple(stored_shape)}, expected {tuple(shape)}")
    if dtype is not None and _descr(dtype) != stored_dtype:
        raise DamagedCheckpoint(f"dtype {stored_dtype}, expected {_descr(dtype)}")
    try:
        array = np.load(io.BytesIO(payload), allow_pickle=False)
    except (ValueError, OSError, EOFError) as error:
        raise DamagedCheckpoint(f"unreadable array ({error})") from None
    if list(array.shape) != stored_shape or _descr(array.dtype) != stored_dtype:
        raise DamagedCheckpoint("array does not match its header")
    return array


class CheckpointStore:
    """Verified checkpoints of finished cells in ``folder``; written atomically.

    ``log`` receives one line per damaged checkpoint found (default: print).
    """

    def __init__(self, folder, log=print):
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.log = log
        self.quarantined: list[Path] = []

    def path(self, key) -> Path:
        """The checkpoint file of ``key`` (which may not exist yet)."""
        return self.folder / f"{key}{SUFFIX}"

    def has(self, key) -> bool:
        """A file exists for ``key`` (not yet verified)."""
        return self.path(key).is_file()

    def save(self, key, array) -> None:
        """Write ``array`` as the checkpoint of ``key``, with its key, shape, dtype and sha256, atomically."""
        data = encode(key, np.asarray(array))
        with atomic_path(self.path(key)) as temporary:
            with open(temporary, "wb") as handle:
                handle.write(data)

    def load(self, key, shape=None, dtype=None) -> np.ndarray:
        """The verified array of ``key``; ``DamagedCheckpoint`` if it does not verify."""
        try:
            data = self.path(key).read_bytes()
        except OSError as error:
            raise DamagedCheckpoint(f"cannot be read ({error.strerror})") from None
        return decode(data, key, shape, dtype)

    def load_verified(self, keys, shape=None, dtype=None) -> dict:
        """{key: array} of the keys whose checkpoint verifies; damaged ones are quarantined."""
        found = {}
        for key in keys:
            if not self.has(key):
                continue
            try:
                found[key] = self.load(key, shape, dtype)
            except DamagedCheckpoint as problem:
                self.quarantine(key, str(problem))
        return found

    def quarantine(self, key, reason) -> Path:
        """Move a damaged checkpoint aside (kept for inspection) and say so in one line."""
        source = self.path(key)
        target_folder = self.folder / QUARANTINE
        target_folder.mkdir(exist_ok=True)
        stamp = time.strftime("%Y%m%dT%H%M%S")
        target = target_folder / f"{source.name}.{stamp}"
        for number in range(1, 1000):
            if not target.exists():
                break
            target = target_folder / f"{source.name}.{stamp}.{number}"
        source.replace(target)
        self.quarantined.append(target)
        self.log(f"rockfrag: checkpoint {source} is damaged ({reason}); moved to {target} and recomputing")
        return target
