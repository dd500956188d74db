"""pipeline.models.jit - the one switch between compiled and plain-Python kernels.

Input : the environment variable PIPELINE_NO_NUMBA. Output: ``njit``, numba's decorator, or a
no-op with the same call forms when PIPELINE_NO_NUMBA=1 (debugging, coverage, and the property test
that the compiled kernels equal the plain-Python ones).
"""

from __future__ import annotations

import os

if os.environ.get("PIPELINE_NO_NUMBA", "") not in ("", "0"):
    def njit(*args, **kwargs):
        """Stand-in for numba's ``njit``: returns the function unchanged (``@njit`` and ``@njit(...)``)."""
        if args and callable(args[0]):
            return args[0]
        return lambda function: function
else:
    from numba import njit  # noqa: F401

__all__ = ["njit"]
