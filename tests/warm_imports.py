"""Import every module of the package and of the test suite once, so that Python writes their bytecode (and
that of the libraries they import) before the test processes start (``make test``: beside the kernel compile,
on the core it leaves idle). Without it, pytest and each of its workers compile the same few thousand library
modules side by side at start-up (``--no-compile`` installs; the Makefile explains why). Checks nothing."""

from __future__ import annotations

import importlib
import pkgutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def warm() -> int:
    """Import pipeline.* and tests.*; returns the number of modules imported."""
    count = 0
    for package in ("pipeline", "tests"):
        for module in pkgutil.walk_packages([str(ROOT / package)], f"{package}."):
            if module.name.rsplit(".", 1)[-1] != "__main__":  # (it would run the command line)
                importlib.import_module(module.name)
                count += 1
    return count


if __name__ == "__main__":
    warm()
