"""``make bench``: the two-spring `winkler` block against the same model built in OpenSees, the tool a user
would otherwise use (issue 10, "Against the tool a user would otherwise use").

Input : far-field records (shipped FEMA P695 set, default processing), each truncated to its strong
        part and scaled to multiples of Housner's uplift acceleration g tan(alpha); one block and bed.
Output: printed table: peak angle of both tools, their difference, flights, wall time per run, speed-up.

The OpenSees model (openseespy 3.7.1.2, optional extra ``bench``): a rigid block as a triangle of very
stiff massless elastic beams with corotational geometry (exact large rotations) from the centre of
mass, which carries m, m and I_c, to the two base corners and the base centre; the base centre is
fixed horizontally (the same no-sliding tie as our model); at each corner a zeroLength element in the
vertical direction with a Parallel material of Elastic-No-Tension (ENT, K/2) and a linear Viscous
dashpot C/2; gravity first (static, load control), then UniformExcitation with the record,
Newmark average acceleration, Newton, at a fixed step. This is the classic two-spring model as users
build it. One difference is built in and reported, not hidden: the OpenSees dashpot acts in parallel
at all times, so it pulls on a corner that lifts off (our bed's pressure is max(0, k delta + c delta')
and vanishes out of the ground). The run with the dashpot-always law of the scipy reference
(tests/physics/winkler_reference.py) shows how much of the difference that accounts for.

openseespy's Linux wheel needs the system BLAS/LAPACK: ``apt-get install -y libblas3 liblapack3``
(Debian/Ubuntu). Without them (or without openseespy) this section prints one line and is skipped.
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rockfrag.blocks import Block  # noqa: E402
from rockfrag.models import simulate  # noqa: E402
from rockfrag.processing import load_recipe, process_record  # noqa: E402
from rockfrag.records import load_records  # noqa: E402
from rockfrag.units import STANDARD_GRAVITY as G  # noqa: E402
from tests.physics.winkler_reference import dashpot_always_force, reference_winkler  # noqa: E402

BLOCK = Block(name="bench", R=2.0, alpha=0.25, mass=5000.0)
OMEGA_OVER_P = 30.0  # bed's vertical frequency over p (soft soil for this block)
XI = 0.05
STRONG_PART = 15.0  # s of each record kept, starting 2 s before the first 5% of PGA is exceeded
TAIL = 3.0  # s after the record
OPENSEES_STEP = 2e-4  # s, as measured in the issue (7-11 s per Bolu run)
GROUNDED_SCALES = (1.2, 1.5, 2.5)  # PGA / (g tan alpha): the block rocks; whether it flies is checked per run
FLYING_SCALES = (5.0,)


def strong_part(ag, dt):
    first = int(np.argmax(np.abs(ag) > 0.05 * np.max(np.abs(ag))))
    start = max(0, first - int(2.0 / dt))
    return ag[start:start + int(STRONG_PART / dt) + 1]


def opensees_available():
    try:
        import openseespy.opensees  # noqa: F401
    except Exception as error:  # ImportError, or OSError when libblas.so.3 is missing
        return f"{type(error).__name__}: {error}"
    return None


def rigid_block_frame(ops, b, h, m, K):
    """The block as OpenSees elements: its mass and rotary inertia at node 1 (the centre of mass) and a triangle of
    corotational beams 1e4 times stiffer than the bed K [N/m] joining it to the corners (nodes 2, 3) and the base
    centre (node 4). The benchmarks' one rigid block (opensees_sliding.py builds on it too).
    """
    ops.mass(1, m, m, m * (b * b + h * h) / 3)
    ops.geomTransf("Corotational", 1)
    longest = 2 * math.hypot(b, h)
    modulus = 1e4 * K * max(longest, longest**3)  # beams 1e4 times stiffer than the bed: a rigid block
    for tag, (i, j) in enumerate(((1, 2), (1, 3), (2, 4), (4, 3), (1, 4)), start=1):
        ops.element("elasticBeamColumn", tag, i, j, 1.0, modulus, 1.0, 1)


def gravity_then_excitation(ops, m, ag, dt):
    """Settle the block of mass m [kg] under gravity (static, ten load steps), then set up the transient analysis
    of the horizontal ground acceleration ag [m/s^2] sampled at dt [s] (Newmark average acceleration, Newton)."""
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(1, 0.0, -m * G, 0.0)
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-12, 50)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 0.1)
    ops.analysis("Static")
    if ops.analyze(10) != 0:
        raise RuntimeError("OpenSees gravity analysis failed")
    ops.loadConst("-time", 0.0)

    ops.timeSeries("Path", 2, "-dt", dt, "-values", *np.append(ag, 0.0).tolist())
    ops.pattern("UniformExcitation", 2, 1, "-accel", 2)
    ops.wipeAnalysis()
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-10, 50)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")


def opensees_two_spring(ag, dt, block, K, xi, t_end, step=OPENSEES_STEP):
    """Peak |theta| [rad], whether both corners were ever off the ground, and the CPU time [s]."""
    import openseespy.opensees as ops

    started = time.process_time()
    b, h, m = block.b, block.h, block.mass
    C = 2 * xi * math.sqrt(K * m)
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.node(1, 0.0, h)      # centre of mass
    ops.node(2, -b, 0.0)     # base corners
    ops.node(3, b, 0.0)
    ops.node(4, 0.0, 0.0)    # base centre, tied horizontally to the ground
    ops.node(5, -b, 0.0)     # ground under the corners
    ops.node(6, b, 0.0)
    ops.fix(4, 1, 0, 0)
    ops.fix(5, 1, 1, 1)
    ops.fix(6, 1, 1, 1)
    rigid_block_frame(ops, b, h, m, K)
    ops.uniaxialMaterial("ENT", 1, K / 2)
    ops.uniaxialMaterial("Viscous", 2, C / 2, 1.0)
    ops.uniaxialMaterial("Parallel", 3, 1, 2)
    ops.element("zeroLength", 11, 5, 2, "-mat", 3, "-dir", 2)
    ops.element("zeroLength", 12, 6, 3, "-mat", 3, "-dir", 2)

    gravity_then_excitation(ops, m, ag, dt)
    peak, flew = 0.0, False
    for _ in range(int(round(t_end / step))):
        if ops.analyze(1, step) != 0:
            ok = ops.analyze(10, step / 10)  # one retry at a tenth of the step
            if ok != 0:
                raise RuntimeError(f"OpenSees did not converge at t = {ops.getTime():.4f} s")
        theta = ops.nodeDisp(1, 3)
        peak = max(peak, abs(theta))
        if ops.nodeDisp(2, 2) > 0.0 and ops.nodeDisp(3, 2) > 0.0:
            flew = True
        if peak > 0.5 * math.pi:
            break
    ops.wipe()
    return peak, flew, time.process_time() - started


def ours(ag, dt, block, K, xi, t_end, repeats=20):
    """Peak |theta| [rad], n_flights and the CPU time per run [s] of simulate("winkler", two-spring)."""
    result = simulate("winkler", ag, dt, block, k=K, xi=xi, bed="two-spring", t_end=t_end)
    started = time.process_time()
    for _ in range(repeats):
        simulate("winkler", ag, dt, block, k=K, xi=xi, bed="two-spring", t_end=t_end)
    return result.peak_angle, result.n_flights, (time.process_time() - started) / repeats


def scaled_records(n_records):
    """[(id, strong part of the processed record [m/s^2], dt [s])] of the first far-field records."""
    records, _ = load_records("far-field")
    recipe = load_recipe()
    motions = []
    for record in records[:n_records]:
        processed = process_record(record, recipe)
        motions.append((record.id, strong_part(processed.acceleration, processed.dt), processed.dt))
    return motions


def compare(motions, scales, xi, K, print, with_reference=False):
    """Rows (id, scale, ours, OpenSees, diff, flights, OpenSees flew, ours s, OpenSees s, ours at +0.1%[,
    reference with the pulling dashpot])."""
    rows = []
    for record_id, ag, dt in motions:
        t_end = (ag.size - 1) * dt + TAIL
        for scale in scales:
            scaled = ag * scale * BLOCK.uplift_acceleration() / np.max(np.abs(ag))
            our_peak, flights, our_time = ours(scaled, dt, BLOCK, K, xi, t_end)
            their_peak, their_flight, their_time = opensees_two_spring(scaled, dt, BLOCK, K, xi, t_end)
            nudged = simulate("winkler", scaled * 1.001, dt, BLOCK, k=K, xi=xi, bed="two-spring", t_end=t_end)
            tight = simulate("winkler", scaled, dt, BLOCK, k=K, xi=xi, bed="two-spring", t_end=t_end, rtol=1e-8,
                             atol=1e-9)
            row = [record_id, scale, our_peak, their_peak, their_peak / our_peak - 1, flights, their_flight,
                   our_time, their_time, nudged.peak_angle, tight.peak_angle]
            line = (f"   {record_id:16} {scale:5.1f} {our_peak / BLOCK.alpha:8.4f} {their_peak / BLOCK.alpha:8.4f} "
                    f"{row[4]:+7.2%} {flights:4d}/{'y' if their_flight else 'n'} {our_time * 1e3:8.2f} "
                    f"{their_time:10.2f} {their_time / our_time:7.0f}x {nudged.peak_angle / our_peak - 1:+8.2%} "
                    f"{their_peak / tight.peak_angle - 1:+8.2%}")
            if with_reference:
                pulling = reference_winkler(scaled, dt, BLOCK.b, BLOCK.h, BLOCK.mass, K, xi, "two-spring",
                                            t_end=t_end, law=dashpot_always_force)["peak_angle"]
                row.append(pulling)
                line += f" | {their_peak / pulling - 1:+.3%}"
            rows.append(row)
            print(line)
    return rows


HEADER = (f"   {'record':16} {'scale':>5} {'ours':>8} {'OpenSees':>8} {'diff':>7} {'flights':>7} "
          f"{'ours ms':>8} {'OpenSees s':>10} {'speed-up':>8} {'ours+0.1%':>9} {'vs tight':>8}")


def run(print=print, n_records=5):
    warnings.simplefilter("ignore")
    print("\nWinkler two-spring bed vs the same block in OpenSees (zeroLength ENT springs + dashpots, no sliding)")
    missing = opensees_available()
    if missing:
        print(f"   skipped: openseespy not importable ({missing}); install with "
              "`pip install -e '.[bench]'` and, on Debian/Ubuntu, `apt-get install -y libblas3 liblapack3`")
        return None
    print("   (openseespy's Linux wheel needs the system BLAS/LAPACK: apt-get install -y libblas3 liblapack3)")
    K = BLOCK.mass * (OMEGA_OVER_P * BLOCK.p()) ** 2
    print(f"   block R = {BLOCK.R} m, alpha = {BLOCK.alpha}, m = {BLOCK.mass:g} kg; bed K = {K:.3g} N/m "
          f"(omega_v/p = {OMEGA_OVER_P:g}); OpenSees: Newmark, fixed step {OPENSEES_STEP:g} s; records: first "
          f"{STRONG_PART:g} s from 2 s before 5% of PGA, + {TAIL:g} s; scale = PGA / (g tan alpha)")
    print("   peak angles in units of alpha; flights: ours (count) / OpenSees (some step with both corners up);\n"
          "   times are CPU time of this process (robust to a loaded machine); ours+0.1%: our peak change when the "
          "record is scaled by 1.001;\n   vs tight: OpenSees against ours at rtol 1e-8 (default 1e-6)")
    motions = scaled_records(n_records)
    simulate("winkler", np.zeros(3), 0.01, BLOCK, k=K, xi=0.0, bed="two-spring")  # compile / load the cache

    print("\n   a) the same contact law: xi = 0 (no dashpot; spring K/2 in compression only at each corner)")
    print(HEADER)
    same = compare(motions, GROUNDED_SCALES + FLYING_SCALES, 0.0, K, print)
    print(f"\n   b) xi = {XI} as users build it: Parallel(ENT, Viscous) - the OpenSees dashpot also acts out of the "
          "ground and pulls on a lifting corner;\n      last column: OpenSees vs our scipy reference with that "
          "dashpot-always law (tests/physics/winkler_reference.py)")
    print(HEADER + " | vs pulling-dashpot reference")
    users = compare(motions, (2.0,), XI, K, print, with_reference=True)

    rows = same + users
    speedups = np.array([r[8] / r[7] for r in rows])
    print(f"\n   speed-up over OpenSees: median {np.median(speedups):.0f}x, min {speedups.min():.0f}x "
          f"(target >= 300x); ours {np.median([r[7] for r in rows]) * 1e3:.1f} ms/run, "
          f"OpenSees {np.median([r[8] for r in rows]):.1f} s/run")
    grounded = [r for r in same if r[5] == 0 and not r[6]]
    flying = [r for r in same if r[5] > 0 or r[6]]
    if grounded:
        print(f"   a) never airborne ({len(grounded)} runs): peak angles agree within "
              f"{max(abs(r[4]) for r in grounded):.3%} (target 2%)")
    if flying:
        print(f"   a) airborne ({len(flying)} runs): differences " + ", ".join(f"{r[4]:+.2%}" for r in flying)
              + "\n      against ours at rtol 1e-8: " + ", ".join(f"{r[3] / r[10] - 1:+.2%}" for r in flying)
              + "\n      in flight the response is sensitive (see ours+0.1%): each landing is an impact whose "
              "outcome depends on the landing instant and state, which OpenSees' fixed Newmark step resolves "
              "without event location")
        bounded = [r for r in flying if max(r[3], r[10]) < 0.5 * math.pi]  # neither overturned
        if bounded:
            worst = max(bounded, key=lambda r: abs(r[3] / r[10] - 1))
            record_id, scale = worst[0], worst[1]
            ag, dt = next((a, d) for i, a, d in motions if i == record_id)
            scaled = ag * scale * BLOCK.uplift_acceleration() / np.max(np.abs(ag))
            finer, _, seconds = opensees_two_spring(scaled, dt, BLOCK, K, 0.0, (ag.size - 1) * dt + TAIL,
                                                    step=OPENSEES_STEP / 4)
            print(f"      step check on the largest difference against ours at rtol 1e-8 ({record_id} x{scale:g}): "
                  f"OpenSees {worst[3] / BLOCK.alpha:.4f} alpha at step {OPENSEES_STEP:g} s, {finer / BLOCK.alpha:.4f} "
                  f"at {OPENSEES_STEP / 4:g} s ({seconds:.1f} s CPU); ours {worst[2] / BLOCK.alpha:.4f} (rtol 1e-6), "
                  f"{worst[10] / BLOCK.alpha:.4f} (rtol 1e-8)")
    print(f"   b) xi = {XI}: OpenSees differs from our tensionless bed by "
          + ", ".join(f"{r[4]:+.1%}" for r in users)
          + f"; it matches the pulling-dashpot reference within {max(abs(r[3] / r[11] - 1) for r in users):.3%}: "
          "the difference is the dashpot pulling on the lifting corner, not the solver")
    return rows


if __name__ == "__main__":
    run()
