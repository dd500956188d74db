"""Write the bytecode of the package, of the test suite and of the libraries they import once, before the test
processes start (``make test``: beside the kernel compile, on the core it leaves idle). Without it, pytest and each
of its workers compile the same few thousand library modules side by side at start-up (``--no-compile`` installs;
the Makefile explains why) and each rewrites the test modules' asserts. Imports every ``pipeline`` module, then
collects the tests as pytest does (its assert-rewritten bytecode is cached too). Runs no test, checks nothing."""

from __future__ import annotations

import contextlib
import importlib
import io
import pkgutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LAZY = ("dask.distributed",)
"""Libraries the package imports only when it needs them and the tests then start: the dask executor (about 300
modules with tornado and msgpack, imported by the dask tests in-process and in `rockfrag --scheduler` runs)."""


def warm() -> int:
    """Import rockfrag.* (the folder pipeline/) and collect the tests; returns pytest's exit status (0: collected)."""
    for module in pkgutil.walk_packages([str(ROOT / "pipeline")], "rockfrag."):
        if module.name.rsplit(".", 1)[-1] != "__main__":  # (it would run the command line)
            importlib.import_module(module.name)
    for name in LAZY:
        importlib.import_module(name)
    with contextlib.redirect_stdout(io.StringIO()):  # (the list of tests; a collection error shows in the run itself)
        return int(pytest.main(["--collect-only", "-q", "-p", "no:cacheprovider", str(ROOT / "tests")]))


if __name__ == "__main__":
    warm()
