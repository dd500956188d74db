"""``make bench``: our sliding models (``friction=``) against the same block on friction elements in OpenSees,
the tool a user would otherwise use (issue 19, item 4: "a benchmark against OpenSees (a rigid block on friction
elements), as the README does for ``winkler``").

Input : a rectangular acceleration pulse (Newmark's closed form) and far-field records (shipped FEMA P695 set,
        default processing), each truncated to its strong part and scaled to a PGA; two blocks (a squat one,
        b/h = 2 >> mu, that can only slide; one with tan(alpha) = 0.6 just above mu = 0.5, that slides and
        rocks); two-spring beds of omega_v/p = 30 (soft) and 300 (stiff).
Output: printed tables: peak slip, residual slip and peak angle of ``simulate("winkler", ..., bed="two-spring",
        friction=mu)`` and of OpenSees, their differences, flights, CPU time per run of each tool, speed-up;
        ``housner`` with friction (the rigid-base limit) beside them; convergence of OpenSees in its shear
        stiffness and step; the parts of the peak-angle difference with the base held (b').

The OpenSees model (openseespy 3.7.1.2, optional extra ``bench``): the rigid block of
``benchmarks/opensees_winkler.py`` (a triangle of very stiff corotational elastic beams from the centre of mass,
which carries m, m and I_c, to the base corners and the base centre), with the base centre free and at each
corner a ``flatSliderBearing`` (FlatSliderSimple2d) from a fixed ground node: ``Coulomb`` friction mu on the
bearing's own normal force, an elastic shear stiffness k0 while it sticks, the vertical (axial) material
``Elastic`` K/2 with damping eta = C/2, no moment stiffness. The bearing is tensionless by itself: where the
axial force would pull it carries nothing (no force, no friction, and its sticking point is reset), so the
block flies freely. Gravity first (static), then UniformExcitation, Newmark average acceleration, Newton, a
fixed step. Slip is the base centre's horizontal displacement relative to the ground, as ours on the bed.

Differences built into the laws, reported rather than hidden:

* Static and kinetic friction: OpenSees' ``Coulomb`` has one coefficient, so every run here has mu_s = mu_k.
  (Its ``VelDependent`` model, mu from mu_slow at rest to mu_fast, is a regularisation in velocity, not a
  stick-slip law with mu_s > mu_k; it is not compared.)
* Sticking: OpenSees sticks through the elastic shear stiffness k0 (elastic-plastic return mapping at each
  corner); ours is event-driven (no stiffness, stick-slip events located). k0 per corner is set by the stick
  frequency omega_h = sqrt(2 k0 / m) (``STICK_FREQUENCY``); its convergence is measured (pulse and records).
* Where friction acts: OpenSees at each corner, mu times that corner's normal force, each with the corner's
  own slip; ours at the base centre's level, bounded by mu times the bed's total normal force F, with the base
  centre's slip. Flat and sliding both give mu F; rocking, a corner's slip rate differs from the base
  centre's by b sin(theta) theta', and the friction's moment arm about the centre of mass by b sin(theta):
  second order, but 10% of h at theta = 0.17 rad for the slide-rock block.
* The dashpot: the bearing carries max(0, k delta + c delta') with delta the corner's penetration of either
  sign, so its dashpot already pushes on a corner that approaches the ground from less than c v / k above
  it; our bed pushes only once the corner is in the ground (delta > 0). With xi = 0 the laws are the same,
  but on an undamped bed a rocking block bounces, and already at xi = 0.05 its peaks are chaotic (part c);
  part b runs at xi = 0.2.
* Where the base is held without sliding: OpenSees' stuck corners stay put, so the base centre of a block
  rocking on one moves by b (1 - cos theta); our tied bed holds the base centre instead. Part b' measures this
  and the dashpot law on the runs of b with the base held (OpenSees with the base centre fixed against the scipy
  reference of tests/physics/winkler_reference.py run with the bearing's law, ``bearing_force``).
"""

from __future__ import annotations

import math
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.opensees_winkler import gravity_then_excitation, rigid_block_frame  # noqa: E402
from rockfrag.blocks import Block  # noqa: E402
from rockfrag.models import simulate  # noqa: E402
from rockfrag.processing import load_recipe, process_record  # noqa: E402
from rockfrag.records import load_records  # noqa: E402
from rockfrag.units import STANDARD_GRAVITY as G  # noqa: E402
from tests.physics.winkler_reference import reference_winkler  # noqa: E402

SQUAT = Block(name="squat", R=math.hypot(1.0, 0.5), alpha=math.atan2(1.0, 0.5), mass=5000.0)  # b/h = 2
SLIDE_ROCK = Block(name="slide-rock", R=2.0, alpha=math.atan(0.6), mass=5000.0)  # b/h = tan(alpha) = 0.6
MU_FLAT = 0.3  # << b/h = 2 of the squat block: it cannot rock
MU_SLIDE_ROCK = 0.5  # just below b/h = 0.6: slides before it could rock on a rigid base
BEDS = (30.0, 300.0)  # omega_v / p: the bed's vertical frequency over the block's p (soft, stiff)
XI_FLAT = 0.05  # the tied benchmark's damping ratio
XI_SLIDE_ROCK = 0.2  # enough to stop the block bouncing on the two-spring bed (README: xi >= 0.2)
XI_BOUNCING = 0.05  # part c: the tied benchmark's damping, at which the slide-rock block bounces
FLAT_PGAS = (0.6, 1.0)  # [g]: 2 and 3.3 times mu g
SLIDE_ROCK_SCALES = (1.5, 2.5)  # PGA / (g tan alpha)
RECORD_INDICES = (0, 2, 4)  # NORTHR/MUL009, NORTHR/LOS000, DUZCE/BOL000: three stations, two events
STRONG_PART = 15.0  # s of each record kept, starting 2 s before the first 5% of PGA is exceeded
TAIL = 3.0  # s after the record: the slip has stopped
OPENSEES_STEP = 2e-4  # s, as the tied benchmark
STICK_FREQUENCY = 5000.0  # rad/s: omega_h = sqrt(2 k0 / m) of the block stuck on its two bearings
LARGE_MU = 10.0  # OpenSees' stand-in for a tied base (no corner slides)
TINY_MU = 1e-6  # OpenSees' frictionless corners, where the base centre is held instead
PULSE = (0.6 * G, 0.5, 1e-3)  # Newmark's rectangular pulse: amplitude [m/s^2], duration [s], sampling [s]


def opensees_available():
    try:
        import openseespy.opensees  # noqa: F401
    except Exception as error:  # ImportError, or OSError when libblas.so.3 is missing
        return f"{type(error).__name__}: {error}"
    return None


def bed_stiffness(block, omega_over_p):
    """Total vertical stiffness K [N/m] of a bed whose vertical frequency is omega_over_p times p."""
    return block.mass * (omega_over_p * block.p()) ** 2


def newmark_slip(amplitude, duration, mu, g=G):
    """Newmark's (1965) slip [m] of a rigid-plastic block under a rectangular pulse (amplitude > mu g)."""
    excess = amplitude - mu * g
    return excess * duration**2 / 2 + (excess * duration) ** 2 / (2 * mu * g)


def rectangular_pulse(amplitude, duration, dt):
    """Samples of a pulse on [0, duration], then zero, and the duration of the rectangle of the same impulse
    (the last interval is a ramp from the amplitude to 0: both tools interpolate linearly)."""
    n = int(round(duration / dt))
    ag = np.zeros(n + 2)
    ag[:n + 1] = amplitude
    return ag, n * dt + dt / 2


def bearing_force(theta, theta_dot, y, y_dot, b, K, C, bed="two-spring"):
    """The flatSliderBearing's vertical law as a bed law of tests/physics/winkler_reference.py: each corner
    carries max(0, (K/2) delta + (C/2) delta') with delta = y + s sin(theta) of either sign, so the dashpot
    already pushes on a corner just above the ground (our bed: only once delta > 0)."""
    force = moment = 0.0
    for s in (-b, b):
        pressure = 0.5 * K * (y + s * math.sin(theta)) + 0.5 * C * (y_dot + s * math.cos(theta) * theta_dot)
        if pressure > 0.0:
            force += pressure
            moment += s * pressure
    return force, moment


def opensees_sliding(ag, dt, block, K, xi, mu, t_end, step=OPENSEES_STEP, stick_frequency=STICK_FREQUENCY,
                     hold_centre=False):
    """The block on two flatSliderBearing corners in OpenSees.

    Parameters
    ----------
    ag : numpy.ndarray
        Ground acceleration [m/s^2] sampled at ``dt`` [s].
    dt : float
        Sampling interval [s].
    block : Block
        The block.
    K : float
        Total vertical stiffness of the bed [N/m] (K/2 per corner).
    xi : float
        Damping ratio of the bed [-]: C = 2 xi sqrt(K m), C/2 per corner.
    mu : float
        Coulomb friction coefficient [-] at each corner.
    t_end : float
        Duration of the analysis [s].
    step : float
        Fixed Newmark step [s].
    stick_frequency : float
        omega_h = sqrt(2 k0 / m) [rad/s], which sets the bearings' elastic shear stiffness k0.
    hold_centre : bool
        Fix the base centre horizontally, as our tied bed (give a tiny ``mu``: the corners then slide freely).

    Returns
    -------
    dict
        ``peak_slip``, ``residual_slip`` [m] (|horizontal displacement of the base centre| relative to the
        ground), ``peak_angle`` [rad], ``flew`` (some step with both corners above the ground), ``retries``
        (steps redone at a tenth of the step) and ``cpu`` [s].
    """
    import openseespy.opensees as ops

    started = time.process_time()
    b, h, m = block.b, block.h, block.mass
    C = 2 * xi * math.sqrt(K * m)
    ops.wipe()
    ops.logFile(os.devnull, "-noEcho")  # a step that fails is retried (counted in ``retries``), not printed
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, h)      # centre of mass
    ops.node(2, -b, 0.0)     # base corners
    ops.node(3, b, 0.0)
    ops.node(4, 0.0, 0.0)    # base centre (free: the slip is measured here)
    ops.node(5, -b, 0.0)     # ground under the corners
    ops.node(6, b, 0.0)
    if hold_centre:
        ops.fix(4, 1, 0, 0)
    ops.fix(5, 1, 1, 1)
    ops.fix(6, 1, 1, 1)
    rigid_block_frame(ops, b, h, m, K)
    ops.uniaxialMaterial("Elastic", 1, K / 2, C / 2)  # axial: the bearing itself carries no tension
    ops.uniaxialMaterial("Elastic", 2, 0.0)  # no moment across the bearing
    ops.frictionModel("Coulomb", 1, mu)
    k0 = m * stick_frequency**2 / 2
    for tag, (ground, corner) in ((11, (5, 2)), (12, (6, 3))):
        # the ground node first, so that the bearing's P-Delta moment goes into the ground; local x up
        ops.element("flatSliderBearing", tag, ground, corner, 1, k0, "-P", 1, "-Mz", 2,
                    "-orient", 0.0, 1.0, 0.0, -1.0, 0.0, 0.0)

    gravity_then_excitation(ops, m, ag, dt)
    peak_slip = peak_angle = slip = 0.0
    flew = False
    retries = 0
    for _ in range(int(round(t_end / step))):
        if ops.analyze(1, step) != 0:
            retries += 1
            if ops.analyze(10, step / 10) != 0:  # one retry at a tenth of the step
                raise RuntimeError(f"OpenSees did not converge at t = {ops.getTime():.4f} s")
        slip = abs(ops.nodeDisp(4, 1))
        peak_slip = max(peak_slip, slip)
        peak_angle = max(peak_angle, abs(ops.nodeDisp(1, 3)))
        if ops.nodeDisp(2, 2) > 0.0 and ops.nodeDisp(3, 2) > 0.0:
            flew = True
        if peak_angle > 0.5 * math.pi:
            break
    ops.wipe()
    return {"peak_slip": peak_slip, "residual_slip": slip, "peak_angle": peak_angle, "flew": flew,
            "retries": retries, "cpu": time.process_time() - started}


def ours(ag, dt, block, K, xi, mu, t_end, repeats=5):
    """The result of simulate("winkler", two-spring, friction=mu) and its CPU time per run [s]."""
    result = simulate("winkler", ag, dt, block, k=K, xi=xi, bed="two-spring", friction=mu, t_end=t_end)
    started = time.process_time()
    for _ in range(repeats):
        simulate("winkler", ag, dt, block, k=K, xi=xi, bed="two-spring", friction=mu, t_end=t_end)
    return result, (time.process_time() - started) / repeats


def strong_part(ag, dt):
    first = int(np.argmax(np.abs(ag) > 0.05 * np.max(np.abs(ag))))
    start = max(0, first - int(2.0 / dt))
    return ag[start:start + int(STRONG_PART / dt) + 1]


def chosen_records():
    """[(id, strong part of the processed record [m/s^2], dt [s])] of the chosen far-field records."""
    records, _ = load_records("far-field")
    recipe = load_recipe()
    motions = []
    for index in RECORD_INDICES:
        processed = process_record(records[index], recipe)
        motions.append((records[index].id, strong_part(processed.acceleration, processed.dt), processed.dt))
    return motions


def relative(theirs, mine):
    return theirs / mine - 1 if mine > 0 else math.nan


HEADER = (f"   {'record':14} {'scale':>5} {'w/p':>4} | {'ours: slip':>10} {'resid':>6} {'angle':>7} | "
          f"{'OpenSees:':>9} {'slip':>6} {'resid':>6} {'angle':>7} | {'d slip':>7} {'d resid':>7} {'d angle':>7} | "
          f"{'flights':>7} | {'ours ms':>7} {'OS s':>5} {'speed-up':>8} | {'housner':>7} {'angle':>6} | "
          f"{'ours+0.1%':>9}")
UNITS = (f"   {'':14} {'':>5} {'':>4} | {'[mm]':>10} {'[mm]':>6} {'[mrad]':>7} | {'':>9} {'[mm]':>6} {'[mm]':>6} "
         f"{'[mrad]':>7} | {'':>7} {'':>7} {'':>7} | {'':>7} | {'':>7} {'':>5} {'':>8} | {'slip':>7} {'[mrad]':>6} |"
         f" {'slip, angle':>9}")


def compare(motions, block, mu, xi, scales, relative_to, print, beds=BEDS):
    """One row per record, scale and bed: ours, OpenSees, differences, times, housner, our sensitivity.

    ``relative_to`` is "g" (scales are PGA in g) or "uplift" (PGA in g tan alpha of the block)."""
    rows = []
    for record_id, ag, dt in motions:
        t_end = (ag.size - 1) * dt + TAIL
        for scale in scales:
            pga = scale * (G if relative_to == "g" else block.uplift_acceleration())
            scaled = ag * pga / np.max(np.abs(ag))
            rigid = simulate("housner", scaled, dt, block, friction=mu, t_end=t_end)
            for omega_over_p in beds:
                K = bed_stiffness(block, omega_over_p)
                mine, my_time = ours(scaled, dt, block, K, xi, mu, t_end)
                theirs = opensees_sliding(scaled, dt, block, K, xi, mu, t_end)
                nudged = simulate("winkler", scaled * 1.001, dt, block, k=K, xi=xi, bed="two-spring", friction=mu,
                                  t_end=t_end)
                row = {"record": record_id, "scale": scale, "bed": omega_over_p, "ours": mine, "theirs": theirs,
                       "our_time": my_time, "rigid": rigid, "scaled": scaled, "dt": dt, "t_end": t_end, "K": K,
                       "d_slip": relative(theirs["peak_slip"], mine.peak_slip),
                       "d_residual": relative(theirs["residual_slip"], mine.residual_slip),
                       "d_angle": relative(theirs["peak_angle"], mine.peak_angle),
                       "nudge_slip": relative(nudged.peak_slip, mine.peak_slip),
                       "nudge_angle": relative(nudged.peak_angle, mine.peak_angle)}
                rows.append(row)
                print(f"   {record_id:14} {scale:5.2g} {omega_over_p:4.0f} | {mine.peak_slip * 1e3:10.1f} "
                      f"{mine.residual_slip * 1e3:6.1f} {mine.peak_angle * 1e3:7.2f} | {'':>9} "
                      f"{theirs['peak_slip'] * 1e3:6.1f} {theirs['residual_slip'] * 1e3:6.1f} "
                      f"{theirs['peak_angle'] * 1e3:7.2f} | {row['d_slip']:+7.1%} {row['d_residual']:+7.1%} "
                      f"{row['d_angle']:+7.1%} | {mine.n_flights:4d}/{'y' if theirs['flew'] else 'n'}"
                      f"{'' if not theirs['retries'] else '*'} | {my_time * 1e3:7.1f} {theirs['cpu']:5.2f} "
                      f"{theirs['cpu'] / my_time:7.0f}x | {rigid.peak_slip * 1e3:7.1f} {rigid.peak_angle * 1e3:6.2f} |"
                      f" {row['nudge_slip']:+.1%}, {row['nudge_angle']:+.1%}")
    return rows


def pulse_check(print):
    """Newmark's rectangular pulse on the squat block: housner, winkler (stiff bed) and OpenSees against the
    closed form, OpenSees at three stick frequencies and half the step."""
    amplitude, duration, dt = PULSE
    ag, effective = rectangular_pulse(amplitude, duration, dt)
    exact = newmark_slip(amplitude, effective, MU_FLAT)
    t_end = 2.0
    print(f"\n   0) Newmark's rigid-plastic block: squat block (b/h = 2), mu = {MU_FLAT}, rectangular pulse "
          f"{amplitude / G:g} g for {duration:g} s (sampled at {dt:g} s): closed form {exact * 1e3:.2f} mm")
    rigid = simulate("housner", ag, dt, SQUAT, friction=MU_FLAT, t_end=t_end)
    print(f"      housner (rigid base)           peak slip {rigid.peak_slip * 1e3:8.3f} mm  "
          f"{relative(rigid.peak_slip, exact):+.1e}  residual {relative(rigid.residual_slip, exact):+.1e}")
    results = []
    for omega_over_p in BEDS:
        K = bed_stiffness(SQUAT, omega_over_p)
        mine = simulate("winkler", ag, dt, SQUAT, k=K, xi=XI_FLAT, bed="two-spring", friction=MU_FLAT, t_end=t_end)
        print(f"      winkler, omega_v/p = {omega_over_p:3.0f}         peak slip {mine.peak_slip * 1e3:8.3f} mm  "
              f"{relative(mine.peak_slip, exact):+.1e}  residual {relative(mine.residual_slip, exact):+.1e}")
        for frequency, step in ((STICK_FREQUENCY / 2, OPENSEES_STEP), (STICK_FREQUENCY, OPENSEES_STEP),
                                (2 * STICK_FREQUENCY, OPENSEES_STEP), (STICK_FREQUENCY, OPENSEES_STEP / 2)):
            theirs = opensees_sliding(ag, dt, SQUAT, K, XI_FLAT, MU_FLAT, t_end, step=step, stick_frequency=frequency)
            results.append((omega_over_p, frequency, step, relative(theirs["peak_slip"], exact)))
            print(f"      OpenSees, omega_v/p = {omega_over_p:3.0f}, omega_h = {frequency:5.0f} rad/s, step "
                  f"{step:.0e} s: peak slip {theirs['peak_slip'] * 1e3:8.3f} mm  {results[-1][3]:+.1e}  "
                  f"residual {relative(theirs['residual_slip'], exact):+.1e}  ({theirs['cpu']:.2f} s CPU)")
    return exact, rigid.peak_slip, results


def convergence_check(row, xi, mu, block, print):
    """OpenSees on one record at twice the stick frequency and at half the step, against its default."""
    base = row["theirs"]
    print(f"      {row['record']} x{row['scale']:g}, omega_v/p = {row['bed']:g}: OpenSees peak slip / peak angle "
          f"{base['peak_slip'] * 1e3:.2f} mm / {base['peak_angle'] * 1e3:.2f} mrad (omega_h {STICK_FREQUENCY:g} "
          f"rad/s, step {OPENSEES_STEP:g} s)")
    changes = []
    for label, kwargs in ((f"omega_h x2 ({2 * STICK_FREQUENCY:g} rad/s)", {"stick_frequency": 2 * STICK_FREQUENCY}),
                          (f"step / 2 ({OPENSEES_STEP / 2:g} s)", {"step": OPENSEES_STEP / 2})):
        other = opensees_sliding(row["scaled"], row["dt"], block, row["K"], xi, mu, row["t_end"], **kwargs)
        change = (relative(other["peak_slip"], base["peak_slip"]), relative(other["peak_angle"], base["peak_angle"]))
        changes.append(change)
        print(f"      {label:28}: peak slip {change[0]:+.2%}, peak angle {change[1]:+.2%} ({other['cpu']:.1f} s CPU)")
    return changes


def tied_check(rows, xi, block, print):
    """The runs with the base held, to split the peak-angle difference into its parts: ours (friction=None: the
    base centre held, our bed law); the scipy reference (tests/physics/winkler_reference.py) with the bearing's
    law (``bearing_force``); OpenSees with the base centre held and frictionless corners (the same law: a
    solver check); OpenSees with the corners held (mu = LARGE_MU): a block that rocks on a corner that stays
    put, where our tied bed holds the base centre and lets the corner move by b (1 - cos theta)."""
    out = []
    for row in rows:
        args = (row["scaled"], row["dt"])
        mine = simulate("winkler", *args, block, k=row["K"], xi=xi, bed="two-spring", t_end=row["t_end"])
        law = reference_winkler(*args, block.b, block.h, block.mass, row["K"], xi, "two-spring", t_end=row["t_end"],
                                law=bearing_force)["peak_angle"]
        centre = opensees_sliding(*args, block, row["K"], xi, TINY_MU, row["t_end"], hold_centre=True)["peak_angle"]
        corners = opensees_sliding(*args, block, row["K"], xi, LARGE_MU, row["t_end"])["peak_angle"]
        parts = (relative(law, mine.peak_angle), relative(centre, law), relative(corners, centre),
                 relative(corners, mine.peak_angle))
        out.append(parts)
        print(f"      {row['record']:14} x{row['scale']:<4g}| {mine.peak_angle * 1e3:7.2f} {law * 1e3:9.2f} "
              f"{centre * 1e3:10.2f} {corners * 1e3:11.2f} | {parts[0]:+7.1%} {parts[1]:+8.3%} {parts[2]:+7.1%} "
              f"{parts[3]:+7.1%} | {row['d_angle']:+7.1%}")
    return out


def spread(values, digits=1):
    values = [v for v in values if not math.isnan(v)]
    return f"{min(values):+.{digits}%} to {max(values):+.{digits}%}" if values else "-"


def run(print=print):
    warnings.simplefilter("ignore")
    print("\nSliding (friction) against the same block in OpenSees (flatSliderBearing corners, Coulomb friction)")
    missing = opensees_available()
    if missing:
        print(f"   skipped: openseespy not importable ({missing}); install with "
              "`pip install -e '.[bench]'` and, on Debian/Ubuntu, `apt-get install -y libblas3 liblapack3`")
        return None
    print(f"   OpenSees: rigid frame as the tied benchmark, at each corner a flatSliderBearing (Coulomb mu, axial "
          f"Elastic K/2 with eta = C/2, tensionless),\n   stick stiffness k0 = m omega_h^2 / 2 per corner with "
          f"omega_h = {STICK_FREQUENCY:g} rad/s; Newmark, fixed step {OPENSEES_STEP:g} s. Ours: winkler two-spring "
          f"bed, friction = (mu, mu)\n   (OpenSees' Coulomb has one coefficient). Records: first {STRONG_PART:g} s "
          f"from 2 s before 5% of PGA, + {TAIL:g} s. Times: CPU of this process per run.")
    print("   d: OpenSees / ours - 1; flights: ours (count) / OpenSees (some step with both corners up; * a step "
          "redone at a tenth);\n   housner: rigid base with the same friction; ours+0.1%: our peak slip and angle "
          "change when the record is scaled by 1.001")
    simulate("winkler", np.zeros(3), 0.01, SQUAT, k=bed_stiffness(SQUAT, 30), xi=0.0, bed="two-spring",
             friction=0.3)  # compile / load the cache
    exact, rigid_slip, pulse = pulse_check(print)

    motions = chosen_records()
    print(f"\n   a) flat sliding: squat block (b/h = 2, R = {SQUAT.R:.3f} m, m = {SQUAT.mass:g} kg), mu = {MU_FLAT}, "
          f"xi = {XI_FLAT}, PGA {' and '.join(f'{s:g}' for s in FLAT_PGAS)} g")
    print(HEADER)
    print(UNITS)
    flat = compare(motions, SQUAT, MU_FLAT, XI_FLAT, FLAT_PGAS, "g", print)

    print(f"\n   b) slide-rock: block tan(alpha) = 0.6 (R = {SLIDE_ROCK.R:g} m, alpha = {SLIDE_ROCK.alpha:.3f}), "
          f"mu = {MU_SLIDE_ROCK}, xi = {XI_SLIDE_ROCK}, PGA {' and '.join(f'{s:g}' for s in SLIDE_ROCK_SCALES)} "
          "x g tan(alpha)")
    print(HEADER)
    print(UNITS)
    rocking = compare(motions, SLIDE_ROCK, MU_SLIDE_ROCK, XI_SLIDE_ROCK, SLIDE_ROCK_SCALES, "uplift", print)

    print(f"\n   c) slide-rock at xi = {XI_BOUNCING} (the tied benchmark's damping): the block bounces on the soft bed")
    print(HEADER)
    print(UNITS)
    bouncing = compare(motions, SLIDE_ROCK, MU_SLIDE_ROCK, XI_BOUNCING, SLIDE_ROCK_SCALES[-1:], "uplift", print,
                       beds=BEDS[:1])

    print("\n   convergence of OpenSees on records (stick stiffness and step):")
    largest_flat = max(flat, key=lambda r: r["ours"].peak_slip)
    flat_changes = convergence_check(largest_flat, XI_FLAT, MU_FLAT, SQUAT, print)
    soft_rocking = [r for r in rocking if r["bed"] == BEDS[0]]
    largest_rocking = max(soft_rocking, key=lambda r: r["ours"].peak_angle)
    rocking_changes = convergence_check(largest_rocking, XI_SLIDE_ROCK, MU_SLIDE_ROCK, SLIDE_ROCK, print)

    print(f"\n   b') the soft-bed runs of b) with the base held: peak angle [mrad] of ours (friction=None: base centre "
          "held, our bed law),\n      the scipy reference with the bearing's law (base centre held), OpenSees with "
          f"the base centre held (corners mu = {TINY_MU:g}),\n      OpenSees with the corners held (mu = "
          f"{LARGE_MU:g}); the parts: bed law, solver, where the base is held, all; and b)'s sliding difference")
    print(f"      {'record':14} {'scale':5}| {'ours':>7} {'ref law':>9} {'OS centre':>10} {'OS corners':>11} | "
          f"{'law':>7} {'solver':>8} {'held':>7} {'all':>7} | {'sliding':>7}")
    tied = tied_check(soft_rocking, XI_SLIDE_ROCK, SLIDE_ROCK, print)

    rows = flat + rocking + bouncing
    speedups = np.array([r["theirs"]["cpu"] / r["our_time"] for r in rows])
    print(f"\n   speed-up over OpenSees: median {np.median(speedups):.0f}x, "
          f"{speedups.min():.0f}-{speedups.max():.0f}x; "
          f"ours {np.median([r['our_time'] for r in rows]) * 1e3:.1f} ms/run (median; soft bed "
          f"{np.median([r['our_time'] for r in rows if r['bed'] == BEDS[0]]) * 1e3:.1f}, stiff "
          f"{np.median([r['our_time'] for r in rows if r['bed'] == BEDS[1]]) * 1e3:.1f}), OpenSees "
          f"{np.median([r['theirs']['cpu'] for r in rows]):.1f} s/run")
    at_default = [e for bed, f, s, e in pulse if f == STICK_FREQUENCY and s == OPENSEES_STEP]
    print(f"   0) pulse: housner {relative(rigid_slip, exact):+.1e} of Newmark; OpenSees at omega_h "
          f"{STICK_FREQUENCY:g} rad/s " + ", ".join(f"{e:+.1e}" for e in at_default)
          + f" (soft, stiff bed); at omega_h {STICK_FREQUENCY / 2:g} / {2 * STICK_FREQUENCY:g} and at half the step: "
          + ", ".join(f"{e:+.1e}" for bed, f, s, e in pulse if f != STICK_FREQUENCY or s != OPENSEES_STEP))
    print(f"   a) flat sliding ({len(flat)} runs): peak slip {spread([r['d_slip'] for r in flat])}, residual slip "
          f"{spread([r['d_residual'] for r in flat])}; ours against housner on the stiff bed: "
          f"{spread([relative(r['ours'].peak_slip, r['rigid'].peak_slip) for r in flat if r['bed'] == BEDS[1]])}")
    for bed in BEDS:
        part = [r for r in rocking if r["bed"] == bed]
        print(f"   b) slide-rock, omega_v/p = {bed:g} ({len(part)} runs, peak angles "
              f"{min(r['ours'].peak_angle for r in part) * 1e3:.2f}-{max(r['ours'].peak_angle for r in part) * 1e3:.2f}"
              f" mrad, alpha = {SLIDE_ROCK.alpha * 1e3:.0f} mrad): peak slip "
              f"{spread([r['d_slip'] for r in part])}, peak angle {spread([r['d_angle'] for r in part])}, residual "
              f"{spread([r['d_residual'] for r in part])}; ours+0.1% within "
              f"{max(max(abs(r['nudge_slip']), abs(r['nudge_angle'])) for r in part):.1%}")
    print(f"   b') held base, soft bed, OpenSees against ours: peak angle {spread([t[3] for t in tied])}; of which "
          f"the bearing's dashpot law {spread([t[0] for t in tied])}, the solver (OpenSees against the reference with "
          f"that law) {spread([t[1] for t in tied], 3)},\n       corners held instead of the centre "
          f"{spread([t[2] for t in tied])}")
    print(f"   c) xi = {XI_BOUNCING}: peak slip {spread([r['d_slip'] for r in bouncing])}, peak angle "
          f"{spread([r['d_angle'] for r in bouncing])}; a 0.1% change of amplitude moves our peaks by "
          f"{spread([r['nudge_slip'] for r in bouncing] + [r['nudge_angle'] for r in bouncing])}: bouncing is "
          "chaotic, no tool gives a reproducible peak")
    print("   convergence (omega_h x2, step/2): flat "
          + ", ".join(f"slip {a:+.2%} angle {b:+.2%}" for a, b in flat_changes)
          + "; slide-rock " + ", ".join(f"slip {a:+.2%} angle {b:+.2%}" for a, b in rocking_changes))
    return {"pulse": pulse, "flat": flat, "rocking": rocking, "bouncing": bouncing, "tied": tied}


if __name__ == "__main__":
    run()
