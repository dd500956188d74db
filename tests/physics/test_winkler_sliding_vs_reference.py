"""``winkler`` with friction against the independent scipy reference (tests/physics/winkler_sliding_reference.py,
written from the README's spec, not from the kernel: Newton-Euler with the friction at the base centre's level,
stick-slip located as events, DOP853 at rtol 1e-10 with events at every contact and stick-slip change).

First the reference itself, against what does not come from either: the exact rigid-plastic slip of the
sampled rectangular pulse on a stiff bed, the tied bed's Lagrangian equations (stuck base) and the work-energy
balance (sliding base). Then the kernel against it on the strong part of real records (5 s of Bolu 090 and of
Capitola 000, 0.75 g PGA, 3 s of free motion after), both bed laws, flat sliding, slide-rock and flights.

Requirement (issue 19): peak slip and peak angle within 2% where the response is not chaotic (checked here:
a 1e-6 change of the amplitude moves none of peak slip, peak angle, residual slip by more than 1e-4). Measured (kernel
at its default rtol 1e-6): all three within 1.7e-5 (6.2e-5 where the block flies), the same impacts and flights,
the time the base is not stuck to 1.2e-6 s (5e-4 s with 40 flights), the slip history to 3e-5 of its peak.
The time in each contact mode within 2e-6 s (7.5e-4 s with flights): the kernel booked a step that ends on a contact
change to the mode after it (up to 14 ms off) until this reference showed it.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pytest

from rockfrag.blocks import Block
from rockfrag.models import simulate

from .motions import BLOCK, ground_motion
from .winkler_reference import accelerations
from .winkler_sliding_reference import SlidingBlock, reference_winkler_sliding

G = 9.80665
SKID = Block(name="skid", b=0.75, h=1.0, mass=5000.0)  # b/h = 0.75, the squat machinery skid's
FLAT = Block(name="flat", b=1.0, h=0.5, mass=5000.0)  # b/h = 2: no corner lifts on either bed
BLOCKS = {"slender": BLOCK, "skid": SKID, "flat": FLAT}  # slender: b/h = 0.255
WINDOWS = {"DUZCE/BOL090": (9.0, 14.0), "LOMAP/CAP000": (3.0, 8.0)}  # [s]: the strong part of each record
TAPER = 0.2  # s: a cosine ramp at the window's start (the block starts at rest)
TAIL = 2.0  # s of free motion after the window
XI = 0.05


def window_motion(record_id, pga_g):
    """The strong part of a processed record, scaled so that the whole record's PGA is ``pga_g`` g."""
    ag, dt = ground_motion(record_id)
    start, end = WINDOWS[record_id]
    window = ag[int(round(start / dt)):int(round(end / dt)) + 1].copy()
    ramp = int(round(TAPER / dt))
    window[:ramp] *= 0.5 - 0.5 * np.cos(np.pi * np.arange(ramp) / ramp)
    return window * pga_g * G / np.max(np.abs(ag)), dt


def bed_stiffness(block, omega_over_p):
    return block.mass * (omega_over_p * block.p()) ** 2


CASES = {  # name: (record, PGA [g], block, bed, omega_v / p, (mu_s, mu_k)); what the reference measures on each
    # flat sliding only (mu_s < b/h; the two-spring corners lift only at b/h g): 0.52 s sliding, 50 mm, no impact
    "two-spring, skid slides flat": ("DUZCE/BOL090", 0.75, "skid", "two-spring", 30, (0.35, 0.3)),
    # rocking (to 0.52 alpha) with slide-rock (mu_s > b/h): 0.28 s slide-rock, 41 mm, 6 impacts
    "two-spring, slender slide-rocks": ("DUZCE/BOL090", 0.75, "slender", "two-spring", 30, (0.3, 0.25)),
    # a stiff bed the block bounces off: 40 flights (1.2 s airborne, sliding freely), 47 impacts, 57 mm
    "two-spring, slender flies": ("DUZCE/BOL090", 0.75, "slender", "two-spring", 100, (0.3, 0.25)),
    # flat sliding only (b/h = 2: the continuous bed's corner lifts at b/(3h) g, friction caps the load lower):
    # 0.50 s sliding, 52 mm
    "continuous, flat block slides flat": ("DUZCE/BOL090", 0.75, "flat", "continuous", 30, (0.35, 0.3)),
    # rocking (to 0.40 alpha) with slide-rock (mu_s > b/h): 0.28 s slide-rock, 10 mm, 8 impacts
    "continuous, slender slide-rocks": ("LOMAP/CAP000", 0.75, "slender", "continuous", 30, (0.26, 0.2)),
    # mu_s < b/h, yet the continuous bed lifts a corner at b/3 eccentricity: 0.24 s sliding, 1.32 s slide-rock,
    # 45 impacts, 103 mm
    "continuous, skid slides and rocks": ("LOMAP/CAP000", 0.75, "skid", "continuous", 30, (0.35, 0.3)),
}


@lru_cache(maxsize=None)
def both(case):
    """(reference dict, product RockingResult, product with the amplitude 1e-6 larger) for one case."""
    record_id, pga_g, block_name, bed, omega_over_p, friction = CASES[case]
    block = BLOCKS[block_name]
    ag, dt = window_motion(record_id, pga_g)
    t_end = (ag.size - 1) * dt + TAIL
    K = bed_stiffness(block, omega_over_p)
    reference = reference_winkler_sliding(ag, dt, block.b, block.h, block.mass, K, XI, *friction, bed, t_end=t_end)
    runs = [simulate("winkler", scaled, dt, block, k=K, xi=XI, bed=bed, friction=friction, t_end=t_end)
            for scaled in (ag, ag * (1 + 1e-6))]
    return reference, *runs


# --- the reference against what comes from neither it nor the kernel ---------------------------------------

def exact_pulse_slip(amplitude, n, dt, mu_k, g=G):
    """Rigid-plastic slip [m] and stop time [s] under samples ``amplitude`` at 0..n dt, then 0, interpolated
    linearly (so a ramp to 0 over the last interval), for a block sliding from t = 0 (amplitude > mu_s g)."""
    duration, excess = n * dt, amplitude - mu_k * g
    rate = excess * duration  # at the ramp's start
    slip = excess * duration**2 / 2 + rate * dt + amplitude * dt**2 / 3 - mu_k * g * dt**2 / 2
    rate += amplitude * dt / 2 - mu_k * g * dt  # at the ramp's end
    return slip + rate**2 / (2 * mu_k * g), duration + dt + rate / (mu_k * g)


@pytest.mark.parametrize("bed", ["two-spring", "continuous"])
def test_reference_slides_as_a_rigid_plastic_block_on_a_stiff_bed(bed):
    """A block too squat to rock (b/h = 2 >> mu) on a stiff bed (omega_v/p = 300) under a 0.6 g pulse of
    0.5 s: the exact slip of the sampled pulse to 1e-5 (measured 1.7e-6 two-spring, 5.0e-6 continuous; 1.5e-7
    and 4.5e-7 at omega_v/p = 1000: the bed's settling and tilt, falling as (p/omega_v)^2), the stop time to
    1e-13 s, then it sticks."""
    dt, n, amplitude, friction = 0.01, 50, 0.6 * G, (0.35, 0.3)
    ag = np.zeros(n + 2)
    ag[:n + 1] = amplitude
    K = bed_stiffness(FLAT, 300)
    reference = reference_winkler_sliding(ag, dt, FLAT.b, FLAT.h, FLAT.mass, K, XI, *friction, bed, t_end=2.0)
    slip, stop = exact_pulse_slip(amplitude, n, dt, friction[1])
    assert reference["peak_slip"] == pytest.approx(slip, rel=1e-5)
    assert reference["residual_slip"] == reference["peak_slip"]  # stuck after the stop
    assert reference["time_sliding"] == pytest.approx(stop, abs=1e-9)
    assert reference["n_impacts"] == 0 and reference["time_slide_rocking"] == 0.0


def random_states(block, K, count, seed):
    """States (theta, theta', y, y', u, u') around the settled block, some with a corner or both lifted."""
    rng = np.random.default_rng(seed)
    y_static = block.mass * G / K
    alpha = block.alpha
    return np.column_stack([rng.uniform(-0.5, 0.5, count) * alpha, rng.normal(0, 1, count) * block.p() * alpha,
                            rng.uniform(-1, 3, count) * y_static, rng.normal(0, 1, count) * y_static * 30,
                            rng.normal(0, 0.1, count), rng.normal(0, 0.3, count)])


@pytest.mark.parametrize("bed", ["two-spring", "continuous"])
def test_reference_stuck_equations_are_the_tied_beds(bed):
    """Stuck, the reference's Newton-Euler solution equals the tied bed's Lagrangian 2x2 system
    (winkler_reference.accelerations) and its friction is the horizontal force that holds the base centre."""
    K = bed_stiffness(BLOCK, 30)
    model = SlidingBlock(BLOCK.b, BLOCK.h, BLOCK.mass, K, 2 * XI * math.sqrt(K * BLOCK.mass), 0.5, 0.4, bed)
    j = (BLOCK.b**2 + 4 * BLOCK.h**2) / 3
    for x, ag in zip(random_states(BLOCK, K, 200, 1), np.random.default_rng(2).normal(0, 5, 200)):
        theta_dd, y_dd, friction, force = model.stuck(x, ag)
        force, moment = model.bed_load(x)
        expected = accelerations(x[0], x[1], x[2], ag, force, moment, BLOCK.h, j)
        assert (theta_dd, y_dd) == pytest.approx(expected, rel=1e-12, abs=1e-12 * (abs(ag) + G))
        # the centre of mass's horizontal acceleration in the ground's frame, with the base centre held
        x_cc = BLOCK.h * (math.cos(x[0]) * theta_dd - math.sin(x[0]) * x[1] ** 2)
        assert friction == pytest.approx(x_cc + ag, rel=1e-12, abs=1e-12 * (abs(ag) + G))


@pytest.mark.parametrize("bed", ["two-spring", "continuous"])
def test_reference_sliding_equations_balance_work_and_energy(bed):
    """Sliding, d/dt(kinetic + gravity) per unit mass equals the power of the inertial force -ag, of the
    friction H at the base centre (H u') and of the bed's pressures on the base (-(F y' + M cos(theta) theta')),
    at random states; the friction's own power is then -mu_k F |u'| <= 0."""
    K = bed_stiffness(BLOCK, 30)
    model = SlidingBlock(BLOCK.b, BLOCK.h, BLOCK.mass, K, 2 * XI * math.sqrt(K * BLOCK.mass), 0.5, 0.4, bed)
    h, j_c = BLOCK.h, (BLOCK.b**2 + BLOCK.h**2) / 3
    for x, ag in zip(random_states(BLOCK, K, 200, 3), np.random.default_rng(4).normal(0, 5, 200)):
        direction = 1 if x[5] > 0 else -1
        theta_dd, y_dd, u_dd, friction, force = model.sliding(x, ag, direction)
        _, moment = model.bed_load(x)
        sin_t, cos_t = math.sin(x[0]), math.cos(x[0])
        xc_dot, zc_dot = x[5] + h * cos_t * x[1], -x[3] - h * sin_t * x[1]
        xc_dd = u_dd + h * cos_t * theta_dd - h * sin_t * x[1] ** 2
        zc_dd = -y_dd - h * sin_t * theta_dd - h * cos_t * x[1] ** 2
        energy_rate = xc_dot * xc_dd + zc_dot * zc_dd + j_c * x[1] * theta_dd + G * zc_dot
        power = -ag * xc_dot + friction * x[5] - force * x[3] - moment * cos_t * x[1]
        assert energy_rate == pytest.approx(power, abs=1e-9 * (abs(power) + abs(G * zc_dot) + 1e-3))
        assert friction * x[5] == pytest.approx(-0.4 * force * abs(x[5]), abs=1e-15)


# --- the kernel against the reference on real records ------------------------------------------------------

@pytest.mark.parametrize("case", list(CASES))
def test_peak_and_residual_slip_and_peak_angle_match_reference(case):
    reference, product, nudged = both(case)
    block = BLOCKS[CASES[case][2]]
    assert reference["peak_slip"] > 1e-3 and not reference["overturned"] and not product.overturned
    for name, floor in (("peak_slip", 1e-3), ("peak_angle", 1e-3 * block.alpha), ("residual_slip", 1e-3)):
        value = getattr(product, name)  # floor: a scale below which a relative change means nothing
        regular = abs(getattr(nudged, name) - value) <= 1e-4 * max(value, floor)
        assert regular, f"{name} is sensitive here: not a case for comparison"
        assert value == pytest.approx(reference[name], rel=2e-2, abs=1e-9 * floor)  # requirement
        assert value == pytest.approx(reference[name], rel=1e-4, abs=1e-9 * floor)  # achieved (rtol 1e-6)


def time_tolerance(reference):
    """[s]: the kernel's event times at rtol 1e-6 (measured 1.2e-6 s; 5e-4 s in the case with 40 flights)."""
    return 1e-3 if reference["n_flights"] else 1e-5


@pytest.mark.parametrize("case", list(CASES))
def test_impacts_flights_sliding_time_and_slip_history_match_reference(case):
    reference, product, _ = both(case)
    assert product.n_impacts == reference["n_impacts"]
    assert product.n_flights == reference["n_flights"]
    # the time the base is not stuck: sliding, flat or rocking, or flying (where it cannot stick)
    moving = sum(product.mode_times[name] for name in ("slide", "slide_rock", "flight"))
    assert moving == pytest.approx(sum(reference[key] for key in (
        "time_sliding", "time_slide_rocking", "time_in_flight")), abs=time_tolerance(reference))
    assert moving > 0.1  # each case slides for a while
    np.testing.assert_allclose(product.u, reference["u"], atol=1e-4 * reference["peak_slip"])


MODES = {"rest": "time_at_rest", "slide": "time_sliding", "rock": "time_rocking", "slide_rock": "time_slide_rocking",
         "flight": "time_in_flight"}


def test_time_in_each_mode_matches_reference():
    for case in CASES:
        reference, product, _ = both(case)
        for name, key in MODES.items():
            assert product.mode_times[name] == pytest.approx(reference[key], abs=time_tolerance(reference)), (
                case, name)
