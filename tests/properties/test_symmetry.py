"""Properties that hold for any ground motion: mirror symmetry of rocking, linearity of spectra."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rockfrag.blocks import Block
from rockfrag.measures import response_spectrum
from rockfrag.models import simulate

BLOCK = Block(name="p", R=1.0, alpha=0.2, mass=1000.0)

pytestmark = pytest.mark.filterwarnings("ignore:.*foundation spring in tension")


def pulse_train(amplitudes, periods):
    """A sum of sine pulses [m/s^2] sampled at 0.01 s."""
    t = np.arange(0.0, 4.0, 0.01)
    ag = np.zeros_like(t)
    for i, (amplitude, period) in enumerate(zip(amplitudes, periods)):
        start = 0.5 * i
        window = (t >= start) & (t <= start + period)
        ag[window] += amplitude * np.sin(2 * np.pi * (t[window] - start) / period)
    return ag


motions = st.tuples(st.lists(st.floats(1.0, 8.0), min_size=1, max_size=4),
                    st.lists(st.floats(0.2, 1.5), min_size=4, max_size=4))


@settings(max_examples=25, deadline=None, derandomize=True)
@given(motion=motions, model=st.sampled_from(["housner", "ssi"]))
def test_mirrored_ground_motion_mirrors_the_response(motion, model):
    """Reversing the sign of the ground motion reverses the rotation, exactly (the block is symmetric)."""
    ag = pulse_train(*motion)
    k = BLOCK.mass * (40 * BLOCK.p()) ** 2 if model == "ssi" else None
    forward = simulate(model, ag, 0.01, BLOCK, k=k, xi=0.05, t_end=6.0)
    mirrored = simulate(model, -ag, 0.01, BLOCK, k=k, xi=0.05, t_end=6.0)
    np.testing.assert_array_equal(forward.theta, -mirrored.theta)
    np.testing.assert_array_equal(forward.y, mirrored.y)
    assert forward.n_impacts == mirrored.n_impacts and forward.status == mirrored.status


@settings(max_examples=25, deadline=None, derandomize=True)
@given(motion=motions, factor=st.floats(0.1, 10.0))
def test_spectrum_is_linear_in_the_input(motion, factor):
    ag = pulse_train(*motion)
    periods = [0.1, 0.5, 2.0]
    base = response_spectrum(ag, 0.01, periods)
    scaled = response_spectrum(factor * ag, 0.01, periods)
    np.testing.assert_allclose(scaled["sa"], factor * base["sa"], rtol=1e-10)
    np.testing.assert_allclose(scaled["sd"], factor * base["sd"], rtol=1e-10)


@pytest.mark.slow
def test_plain_python_kernels_give_the_compiled_numbers():
    """ROCKFRAG_NO_NUMBA=1 runs the same kernels as plain Python (debugging): same results."""
    code = ("import numpy as np; from rockfrag.models import simulate; from rockfrag.blocks import Block;"
            "b = Block(name='p', R=1.0, alpha=0.2, mass=1000.0);"
            "r = simulate('ssi', np.zeros(2), 0.01, b, k=1e8, xi=0.05, theta0=0.1, t_end=2.0);"
            "print(repr(r.peak_angle), r.n_impacts, repr(float(r.impact_times[0])))")
    outputs = []
    for flag in ("0", "1"):
        environment = dict(os.environ, ROCKFRAG_NO_NUMBA=flag)
        result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=environment,
                                check=True)
        outputs.append(result.stdout.split())
    compiled, plain = outputs
    assert compiled[1] == plain[1]
    assert float(compiled[0]) == pytest.approx(float(plain[0]), rel=1e-12)
    assert float(compiled[2]) == pytest.approx(float(plain[2]), rel=1e-12)
