"""Compile the numba kernels into their on-disk cache (cache=True) in one process, before the test workers
start (``make test``, ``make test-fast``): otherwise each pytest-xdist worker compiles them at once in a fresh
clone, about 25 s of CPU each. A second when the cache is already there. Runs simulate, simulate_batch and
simulate_histories (one compiled entry point, kernels.run_kernel, whose array arguments have the same types in all
three) on one sample case per registered model, and the response-spectrum oscillator; checks nothing."""

from __future__ import annotations

import numpy as np

from rockfrag.blocks import Block
from rockfrag.measures import response_spectrum
from rockfrag.models import MODELS, simulate, simulate_batch, simulate_histories


def warm() -> None:
    """Run each compiled entry point once on a few samples of zero ground motion."""
    block = Block(name="warm-up", R=1.0, alpha=0.2, mass=1.0)
    ground, dt = np.zeros(3), 0.01
    for name in MODELS:
        simulate(name, ground, dt, block, k=1e4, xi=0.05)
        simulate_batch(name, ground, dt, [1.0], [(block, 1e4, 0.05)])
        simulate_histories(name, ground, dt, [(block, 1e4, 0.05)])
    response_spectrum(ground, dt)


if __name__ == "__main__":
    warm()
