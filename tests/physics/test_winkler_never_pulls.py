"""The bed never pulls: a property test over random blocks, beds, damping and generated ground motions.

Three independent views of the same property on every run:
1. the product's reported ``min_support_force`` is >= 0;
2. the spec's pointwise law applied to the product's own state history never gives tension, and the
   product's minimum is not above the law's minimum on the samples (it saw at least those states);
3. momentum: the centre of mass falls at y_cm'' = g - F/m (y_cm = y - h cos theta, down), so the bed's
   impulse over each sample interval is m (g dt - delta(y' + h sin(theta) theta')), exactly, whatever
   the law; it must not be negative (a pulling bed shows up here even if the product misreports F).
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rockfrag.blocks import Block
from rockfrag.models import simulate

from .winkler_reference import bed_force

G = 9.80665
DT = 0.01


def ground_motion(seed, duration, peak):
    """A few windowed sines (0.5-6 Hz, random phases) scaled to the peak acceleration [m/s^2]."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration, DT)
    motion = sum(rng.uniform(0.3, 1.0) * np.sin(2 * np.pi * rng.uniform(0.5, 6.0) * t + rng.uniform(0, 2 * np.pi))
                 for _ in range(rng.integers(1, 5)))
    motion *= np.sin(np.pi * t / duration) ** 2
    return motion * peak / np.max(np.abs(motion))


def bed_impulses(response, block, dt):
    """Impulse of the bed [N s] over each sample interval, from the momentum of the centre of mass."""
    finite = np.isfinite(response.theta)
    theta, rate, y_rate = response.theta[finite], response.theta_dot[finite], response.y_dot[finite]
    falling = y_rate + block.h * np.sin(theta) * rate
    return block.mass * (G * dt - np.diff(falling))


@settings(max_examples=30, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(half_width=st.floats(0.2, 2.0), alpha=st.floats(0.1, 0.6), mass=st.floats(1e2, 1e6),
       omega_over_p=st.floats(10.0, 500.0), xi=st.sampled_from([0.0, 0.02, 0.05, 0.2, 0.5]),
       bed=st.sampled_from(["continuous", "two-spring"]), seed=st.integers(0, 2**31),
       intensity=st.floats(0.3, 4.0))
def test_the_bed_never_pulls(half_width, alpha, mass, omega_over_p, xi, bed, seed, intensity):
    block = Block(name="random", b=half_width, h=half_width / math.tan(alpha), mass=mass)
    K = mass * (omega_over_p * block.p()) ** 2
    C = 2 * xi * math.sqrt(K * mass)
    weight = mass * G
    ag = ground_motion(seed, 4.0, intensity * block.uplift_acceleration())
    response = simulate("winkler", ag, DT, block, k=K, xi=xi, bed=bed, t_end=6.0)
    assert response.success
    assert response.min_support_force >= 0.0

    law = np.array([bed_force(th, thd, y, yd, block.b, K, C, bed)[0]
                    for th, thd, y, yd in zip(response.theta, response.theta_dot, response.y, response.y_dot)
                    if math.isfinite(th)])
    assert np.all(law >= 0.0)
    assert response.min_support_force <= law.min() + 1e-6 * weight

    impulses = bed_impulses(response, block, DT)
    assert impulses.min() >= -1e-4 * weight * DT, f"net pull {impulses.min():.3g} N s over one interval"
