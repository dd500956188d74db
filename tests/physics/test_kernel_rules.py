"""The rules that make ``rockfrag.models.jit.kernel`` (compiled without reference counting) safe.

A ``kernel`` borrows the arrays its caller hands it: it must not allocate one (numba refuses to compile
that) nor return one (its caller would release an array nobody counted). And a whole run, friction,
vertical motion and every model included, frees every array it allocates.
"""

from __future__ import annotations

import importlib
import pkgutil

import numpy as np
import pytest

import rockfrag.models
from rockfrag.blocks import Block
from rockfrag.models import simulate_batch, simulate_histories
from rockfrag.models.jit import kernel

numba = pytest.importorskip("numba")
from numba.core import types  # noqa: E402
from numba.core.registry import CPUDispatcher  # noqa: E402
from numba.core.runtime import _nrt_python, rtsys  # noqa: E402

pytestmark = pytest.mark.skipif(not isinstance(kernel(lambda: 0), CPUDispatcher),
                                reason="ROCKFRAG_NO_NUMBA=1: plain Python has no reference counts")

BLOCK = Block(name="rules", R=2.0, alpha=0.2, mass=1.0)
STIFFNESS = (300.0 * BLOCK.p()) ** 2  # [N/m] for a 1 kg block: omega_v / p = 300
CASES = [  # every loop, contact law, friction and the vertical component
    ("housner", (BLOCK, None, None), {"friction": 0.3}),
    ("housner", (BLOCK, None, None), {}),
    ("ssi", (BLOCK, STIFFNESS, 0.2), {}),
    ("winkler", (BLOCK, STIFFNESS, 0.2), {"friction": 0.3}),
    ("winkler", (BLOCK, STIFFNESS, 0.2), {"bed": "two-spring"}),
    ("winkler", (BLOCK, STIFFNESS, 0.2), {"bed": "hunt-crossley"}),
]


def run_every_case():
    """Each case at two scales with a vertical component, with and without histories."""
    t = np.arange(0.0, 4.0, 0.01)
    ag = 3.0 * np.sin(2.0 * np.pi * t)
    for model, case, options in CASES:
        simulate_batch(model, ag, 0.01, [1.0, 2.5], [case], ag_vertical=0.3 * ag, **options)
        simulate_histories(model, ag, 0.01, [case], **options)


def contains_array(numba_type) -> bool:
    if isinstance(numba_type, types.Array):
        return True
    if isinstance(numba_type, types.BaseTuple):
        return any(contains_array(member) for member in numba_type.types)
    return False


def compiled_kernels():
    """(name, dispatcher) of every function of rockfrag.models compiled as a ``kernel``."""
    found = []
    for module_info in pkgutil.iter_modules(rockfrag.models.__path__):
        module = importlib.import_module(f"rockfrag.models.{module_info.name}")
        for name, value in vars(module).items():
            if (isinstance(value, CPUDispatcher) and value.__module__ == module.__name__
                    and value.targetoptions.get("_nrt") is False):
                found.append((f"{module.__name__}.{name}", value))
    return found


def return_types(dispatcher):
    """Return types of every compiled version of ``dispatcher``: in this process, or in numba's on-disk cache.

    A kernel that only other compiled functions call is never loaded into the process when they come from the
    cache (their machine code has it inside), so the cache's index is read too (numba's private API: if it
    changes, this test fails, it does not pass quietly).
    """
    found = [signature.return_type for signature in dispatcher.nopython_signatures]
    cache = dispatcher._cache
    for key in cache._cache_file._load_index():
        loaded = cache.load_overload(key[0], dispatcher.targetctx)
        if loaded is not None:
            found.append(loaded.signature.return_type)
    return found


def test_no_kernel_returns_an_array():
    run_every_case()
    kernels = compiled_kernels()
    assert len(kernels) > 50  # the right-hand sides, steps, events and bookkeeping
    compiled = [(name, returned) for name, dispatcher in kernels for returned in return_types(dispatcher)]
    assert len(compiled) > 50
    returning = [f"{name} -> {returned}" for name, returned in compiled if contains_array(returned)]
    assert returning == []


@kernel
def allocating(n):
    return np.zeros(n).sum()


def test_a_kernel_cannot_allocate():
    with pytest.raises(numba.TypingError, match="array passed into the function"):
        allocating(3)


def test_a_run_frees_every_array_it_allocates():
    run_every_case()  # compiled (or loaded) before counting
    was_counting = _nrt_python.memsys_stats_enabled()
    _nrt_python.memsys_enable_stats()
    try:
        before = rtsys.get_allocation_stats()
        run_every_case()
        after = rtsys.get_allocation_stats()
    finally:
        if not was_counting:
            _nrt_python.memsys_disable_stats()
    allocated = after.alloc - before.alloc
    assert allocated > 0  # the counts are on: the loops' work arrays
    assert after.free - before.free == allocated
    assert after.mi_free - before.mi_free == after.mi_alloc - before.mi_alloc
