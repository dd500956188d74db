"""rockfrag.records.sources - reading a record source for the format plugins: a path or a binary file object.

Input : what obspy hands a plugin (a path, or a file object whose position must be left where it was).
Output: ``read_source`` gives the whole content as bytes and a name for messages; ``read_head`` gives the
        first bytes as text for a format's detector, or "" when they look binary.
"""

from __future__ import annotations

import os

HEAD_BYTES = 4096
"""Bytes a detector reads: enough for any shipped format's header."""


def read_source(source, size: int = -1) -> tuple[bytes, str]:
    """The first ``size`` bytes of ``source`` (all with -1) and a name for messages; a file object is rewound."""
    if hasattr(source, "read"):
        position = source.tell() if hasattr(source, "tell") else None
        data = source.read(size)
        if position is not None:
            source.seek(position)
        if isinstance(data, str):
            data = data.encode("latin-1")
        return data, getattr(source, "name", "<file object>")
    with open(source, "rb") as handle:
        return handle.read(size), os.fspath(source)


def read_head(source, size: int = HEAD_BYTES) -> str:
    """The first ``size`` bytes of ``source`` as Latin-1 text, or "" when empty or binary (a NUL byte)."""
    head, _ = read_source(source, size)
    return "" if not head or b"\x00" in head else head.decode("latin-1")
