"""Effective coefficient of restitution of the `winkler` model: r(xi, alpha) per bed, and its calibration.

Input : nothing (a block of R = 2 m, mass 5 t, at several alpha; beds at omega_v/p = 30-1000).
Output: tables on stdout and reports/winkler_restitution.png (r against xi, one panel per bed).

The measure is the project's definition (rockfrag.models.restitution.free_rocking_restitution): the block
is launched from the settled bed with the angular velocity that takes a rigid block to 0.6 alpha, then
rocks freely; successive peaks theta_k give r_k = sqrt(drop_{k+1} / drop_k), drop = cos(alpha - theta) -
cos(alpha) (the rigid block's impact speed squared), the quantity Housner's r = 1 - 1.5 sin^2(alpha)
predicts; r is the median of the first four impacts ("nan": the block overturns on the launch).

1. r(xi) of the three laws (two-spring and continuous Kelvin-Voigt, hunt-crossley) at omega_v/p = 300, 1000;
2. the calibration (issues 18 and 34) over alpha 0.1-0.4 and omega_v/p 30-1000, both beds: the admissible xi
   and the r they reach, and per target (Housner's value, the band's middle, min(1.05 x Housner, 0.99)) the xi
   the rule chooses (or its refusal) with the largest miss over the rule's launches and samplings; with
   ``--reference`` also r of the independent scipy reference at that xi (about 10 minutes more);
3. the default blocks on the five soils: admissible xi, the band's xi, and the time the rule adds to the
   study's set-up. Not a test: `python benchmarks/winkler_restitution.py [--reference]`.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from rockfrag.blocks import Block  # noqa: E402
from rockfrag.errors import SolverError  # noqa: E402
from rockfrag.models import restitution  # noqa: E402

ALPHAS = (0.1, 0.15, 0.25, 0.4)
XIS = {"two-spring": (0.0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.7, 0.9),
       "continuous": (0.0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.7, 0.9),
       "hunt-crossley": (0.0, 0.01, 0.03, 0.1, 0.2, 0.3, 0.5, 1.0, 2.0, 4.0, 10.0)}
STIFFNESS_RATIOS = (300, 1000)  # omega_v / p of the r(xi) tables
CALIBRATION_RATIOS = (30, 100, 300, 1000)
CALIBRATION_ALPHAS = (0.1, 0.2, 0.3, 0.4)
BEDS = tuple(XIS)


def stiffness(block, omega_over_p):
    """The bed's total stiffness K [N/m] for omega_v / p."""
    return block.mass * (omega_over_p * block.p()) ** 2


def matching_xi(xis, rs, target):
    """Smallest xi above which r stays within 0.5% of the target (NaN if never)."""
    close = [abs(r / target - 1) < 5e-3 for r in rs]
    for i in range(len(xis)):
        if all(close[i:]):
            return xis[i]
    return math.nan


def r_tables(print=print):
    """r(xi) per bed, stiffness ratio and alpha: {(bed, ratio, alpha): [r per xi]}."""
    curves = {}
    for bed in BEDS:
        for ratio in STIFFNESS_RATIOS:
            print(f"\n  {bed} bed, omega_v/p = {ratio}")
            print("  alpha  Housner | " + " ".join(f"xi={xi:<6g}" for xi in XIS[bed]) + " | xi matching Housner")
            for alpha in ALPHAS:
                block = Block(name="r", R=2.0, alpha=alpha, mass=5000.0)
                rs = [restitution.free_rocking_restitution(block, stiffness(block, ratio), bed, xi) for xi in XIS[bed]]
                curves[bed, ratio, alpha] = rs
                match = matching_xi(XIS[bed], rs, block.housner_restitution())
                print(f"  {alpha:5.2f}  {block.housner_restitution():7.4f} | " + " ".join(f"{r:<9.4f}" for r in rs)
                      + f" | {'none' if math.isnan(match) else f'>= {match:g}'}")
    return curves


def calibration_table(print=print, check_reference=False):
    """The rule of issue 34 per bed over the grid: admissible xi, the range they reach, and per target the
    calibrated xi (or the refusal) with r re-measured at every launch and sampling of the rule; with
    ``check_reference`` also by the independent scipy reference (tests/physics/winkler_reference.py) at the
    calibrated xi. Returns the number of hits outside the tolerance (0 expected)."""
    failures = 0
    reference = _reference() if check_reference else None
    for bed in ("two-spring", "continuous"):
        law = restitution.calibrated_law(bed)
        print(f"\n  {bed} bed calibrated ({law} xi): admissible xi, the r they reach; per target (Housner, middle, "
              "top = min(1.05 x, 0.99)) the xi chosen and the largest |r - target| over the launches 0.5/0.6/0.7 alpha "
              "and half/double sampling" + (" | r of the scipy reference" if reference else ""))
        for ratio in CALIBRATION_RATIOS:
            for alpha in CALIBRATION_ALPHAS:
                block = Block(name="r", R=2.0, alpha=alpha, mass=5000.0)
                K = stiffness(block, ratio)
                admissible = restitution.admissible_xi(block, K, bed)
                housner = block.housner_restitution()
                cells = []
                for target in (housner, 0.5 * (housner + min(1.05 * housner, 0.99)), min(1.05 * housner, 0.99)):
                    try:
                        dissipation = restitution.calibrate_dissipation(block, K, bed, target)
                    except SolverError as error:
                        cells.append("refused" + (" (not reproducible)" if "not reproducible" in str(error) else ""))
                        continue
                    if dissipation.decision == "dies":
                        cells.append(f"dies, xi {dissipation.xi:.3g}")
                        continue
                    runs = [restitution.free_rocking_restitution(block, K, law, dissipation.xi, fraction=f,
                                                                 sampling=s)
                            for f, s in ((0.6, 1.0), (0.5, 1.0), (0.7, 1.0), (0.6, 0.5), (0.6, 2.0))]
                    worst = max(abs(r - target) for r in runs)
                    cell = f"xi {dissipation.xi:.3g} off {worst:.4f}/{dissipation.tolerance:.4f}"
                    failures += worst > dissipation.tolerance
                    if reference:
                        exact = reference.reference_winkler(np.zeros(2), 0.01 / block.p(), block.b, block.h,
                                                            block.mass, K, dissipation.xi, law,
                                                            t_end=24.0 / block.p(),
                                                            thetadot0=-restitution.launch_rate(block))
                        peaks = reference.rocking_peaks(exact["theta"])
                        r = float(np.median(reference.effective_restitution(peaks[peaks > 0.1 * alpha], alpha)[:4]))
                        cell += f" | ref {r:.4f}"
                        failures += abs(r - target) > dissipation.tolerance
                    cells.append(cell)
                print(f"  omega_v/p {ratio:4d} alpha {alpha:4.2f} (Housner {housner:.4f}): {admissible.describe()}")
                print("      " + "; ".join(cells))
    print(f"\n  hits outside the tolerance: {failures}")
    return failures


def _reference():
    """The scipy reference module of the tests (tests/physics/winkler_reference.py)."""
    import importlib

    sys.path.insert(0, str(ROOT))
    return importlib.import_module("tests.physics.winkler_reference")


def default_blocks(print=print):
    """Admissible xi and the band's calibration for the default blocks on the five soils, with the set-up's time:
    the xi grids alone (what the study measured before the rule) and the whole calibration of every variant."""
    import time

    from rockfrag.config import load_study
    from rockfrag.models.variants import calibrate_models, sample_models
    from rockfrag.soils import soil_block_stiffness

    study = load_study()
    stiffness_table = np.array([[soil_block_stiffness(soil, block) for block in study.blocks] for soil in study.soils])
    law = restitution.calibrated_law(study.bed)
    restitution.free_rocking_restitution(study.blocks[0], 1e9, law, 0.2)  # compiled kernel warm
    restitution._free_rocking.cache_clear()
    for cached in (restitution.restitution_grid, restitution.stability, restitution.admissible_xi,
                   restitution._calibrated):
        cached.cache_clear()
    started = time.perf_counter()
    for s in range(len(study.soils)):
        for b, block in enumerate(study.blocks):
            restitution.restitution_grid(block, float(stiffness_table[s, b]), law)
    grids = time.perf_counter() - started
    restitution_runs = sample_models()[:3]  # the centre and the two restitution members (the same K)
    calibration = calibrate_models(list(study.blocks), [soil.name for soil in study.soils],
                                   np.repeat(stiffness_table[:, :, None], 3, axis=2), restitution_runs,
                                   "recommended", study.design, study.bed)
    total = time.perf_counter() - started
    print(f"\n  default study ({study.bed} bed): the xi grids {grids:.2f} s, the whole calibration {total:.2f} s "
          f"(the rule adds {total - grids:.2f} s; one core, load {__import__('os').getloadavg()[0]:.1f})")
    print("  block            soil    admissible xi (r they reach)                 xi of low / centre / high edge")
    for s, soil in enumerate(study.soils):
        for b, block in enumerate(study.blocks):
            admissible = restitution.admissible_xi(block, float(stiffness_table[s, b]), study.bed)
            xis = " / ".join(f"{x:.3g}" for x in calibration.xi[s, b])
            print(f"  {block.name:16s} {soil.name:7s} {admissible.describe():44s} {xis}")
    return total - grids


def run(print=print, png=ROOT / "reports" / "winkler_restitution.png"):
    warnings.simplefilter("ignore")
    print("Winkler bed: effective restitution r per impact (median of the first four)")
    print("block R = 2 m; launched to 0.6 alpha on the settled bed; Housner r = 1 - 1.5 sin^2(alpha)")
    curves = r_tables(print)
    calibration_table(print, check_reference="--reference" in sys.argv)
    default_blocks(print)
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:  # pragma: no cover
        print("matplotlib missing: no figure")
        return curves
    figure, axes = plt.subplots(1, len(BEDS), figsize=(16, 4.2), sharey=True)
    for axis, bed in zip(axes, BEDS):
        for k, alpha in enumerate(ALPHAS):
            colour = f"C{k}"
            for ratio, style in zip(STIFFNESS_RATIOS, ("--", "-")):
                axis.plot(XIS[bed], curves[bed, ratio, alpha], style, color=colour, marker="o", markersize=3,
                          label=f"alpha = {alpha}, omega_v/p = {ratio}")
            axis.axhline(1 - 1.5 * math.sin(alpha) ** 2, color=colour, linestyle=":", linewidth=1)
        axis.set_title(f"{bed} bed (dotted: Housner's r)")
        axis.set_xlabel("bed damping ratio xi [-]")
        axis.set_xscale("symlog", linthresh=0.01)
        axis.set_xlim(left=0.0)
        axis.grid(alpha=0.3)
    axes[0].set_ylabel("effective restitution r [-]")
    axes[-1].legend(fontsize=7, loc="lower left")
    figure.tight_layout()
    Path(png).parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(png, dpi=120)
    plt.close(figure)
    print(f"\n  figure: {png}")
    return curves


if __name__ == "__main__":
    run()
