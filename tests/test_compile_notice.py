"""One line on stderr when the solvers compile for the first time, none when they load from numba's cache."""

from __future__ import annotations

import subprocess
import sys

import numba
import pytest

from rockfrag.models import jit

pytestmark = pytest.mark.skipif(not hasattr(jit, "FIRST_COMPILE"), reason="ROCKFRAG_NO_NUMBA: nothing compiles")


def _compile(module: str) -> None:
    """Compile (never load: no cache) a tiny function that says it belongs to ``module``."""
    def add_one(x):
        return x + 1

    add_one.__module__ = module
    assert numba.njit(add_one)(1) == 2


def test_a_solver_compiling_prints_the_notice_once(monkeypatch, capsys):
    monkeypatch.setattr(jit.FIRST_COMPILE, "shown", False)
    _compile("rockfrag.measures")  # not a solver: no notice
    assert capsys.readouterr().err == ""
    _compile("rockfrag.models.kernels")
    _compile("rockfrag.models.winkler")
    assert capsys.readouterr().err == jit.COMPILE_NOTICE + "\n"
    assert "compiling the solvers (first run" in jit.COMPILE_NOTICE


def test_solvers_loaded_from_the_cache_print_nothing():
    """make test compiles the kernels into their cache first (tests/warm_kernels.py): a new process loads them."""
    code = ("import numpy as np, rockfrag; "
            "r = rockfrag.simulate('housner', np.zeros(3), 0.01, rockfrag.Block(b=0.3, h=1.1, mass=400.0)); "
            "print(r.peak_angle)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "0.0" and "compiling" not in done.stderr
