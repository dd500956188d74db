"""rockfrag.models.jit - the one switch between compiled and plain-Python kernels.

Input : the environment variable ROCKFRAG_NO_NUMBA. Output: two decorators, or no-ops with the same
call forms when ROCKFRAG_NO_NUMBA=1 (debugging, coverage, and the property test that the compiled
kernels equal the plain-Python ones):

- ``njit``: numba's decorator, for the few functions that allocate arrays (the entry points, which allocate
  each response's work arrays);
- ``kernel``: every other compiled function (the time loops, right-hand sides, steps, events, bookkeeping).
  It is cached and compiled without numba's reference counting (``_nrt=False``): a kernel only borrows the
  arrays it is handed, and its caller keeps them alive.

Why ``kernel`` exists: the helpers pass arrays inside small records (a step, the system, the work arrays)
through a dozen compiled calls per integration step, and numba counts every such borrow with two atomic
instructions (NRT_incref/NRT_decref). Measured on the 2026-11-26 machine, those took 33-42% of a run's
time; without them a Housner run is 4-5x and a winkler run 3-4x faster, with bit-identical results. The
rules that make this safe are checked by numba and by tests/physics/test_kernel_rules.py: a ``kernel`` cannot
allocate (numba refuses to compile an allocation without reference counting) and must not return an
array (the test inspects every compiled signature), and a run frees every array it allocates.

The first solver call after an install (or a change of a kernel's source) compiles them, 25-45 s on 2 cores;
later runs load them from numba's on-disk cache. ``COMPILE_NOTICE`` says so on stderr, once per process, when numba
starts compiling a solver (its ``numba:compile`` event, which a cache hit does not raise).
"""

from __future__ import annotations

import os
import sys

COMPILE_NOTICE = ("rockfrag: compiling the solvers (first run after an install or a change of their code, about "
                  "30 s on 2 cores; later runs load them from the cache)...")
"""The line printed when the solvers compile (not when they load from numba's cache)."""

COMPILED = os.environ.get("ROCKFRAG_NO_NUMBA", "") in ("", "0")
"""Whether the kernels are compiled by numba (False: plain Python, ROCKFRAG_NO_NUMBA=1)."""

if not COMPILED:
    def njit(*args, **kwargs):
        """Stand-in for numba's ``njit``: returns the function unchanged (``@njit`` and ``@njit(...)``)."""
        if args and callable(args[0]):
            return args[0]
        return lambda function: function

    def kernel(function):
        """Stand-in for ``kernel``: returns the function unchanged."""
        return function
else:
    from numba import njit
    from numba.core.cpu import CPUTargetOptions

    # ``_nrt`` is numba's own (private) switch, there since numba 0.49; a release without it would reject it at
    # the first call, so it is looked up here and, if gone, the kernels count references as before (slower, the
    # same numbers; tests/physics/test_kernel_rules.py then fails, to say so).
    KERNEL_OPTIONS = {"cache": True, "_nrt": False} if hasattr(CPUTargetOptions, "_nrt") else {"cache": True}

    def kernel(function):
        """Compile a function of the time loops: cached, without reference counting (see the module docstring)."""
        return njit(**KERNEL_OPTIONS)(function)

    from numba.core import event

    class CompileNotice(event.Listener):
        """Prints ``COMPILE_NOTICE`` once, when numba starts compiling a function of ``rockfrag.models``."""

        shown = False

        def on_start(self, started):
            """A compilation starts: the notice, the first time it is one of the solvers'."""
            function = getattr(started.data.get("dispatcher"), "py_func", None)
            if not self.shown and getattr(function, "__module__", "").startswith("rockfrag.models"):
                self.shown = True
                print(COMPILE_NOTICE, file=sys.stderr, flush=True)

        def on_end(self, ended):
            """Nothing to do when it ends."""

    FIRST_COMPILE = CompileNotice()
    event.register("numba:compile", FIRST_COMPILE)

__all__ = ["COMPILED", "kernel", "njit"]
