"""Effective coefficient of restitution of the `winkler` model: r(xi, alpha) per bed, and its calibration.

Input : nothing (a block of R = 2 m, mass 5 t, at several alpha; beds at omega_v/p = 30-1000).
Output: tables on stdout and reports/winkler_restitution.png (r against xi, one panel per bed).

The measure is the project's definition (rockfrag.models.restitution.free_rocking_restitution): the block
is launched from the settled bed with the angular velocity that takes a rigid block to 0.6 alpha, then
rocks freely; successive peaks theta_k give r_k = sqrt(drop_{k+1} / drop_k), drop = cos(alpha - theta) -
cos(alpha) (the rigid block's impact speed squared), the quantity Housner's r = 1 - 1.5 sin^2(alpha)
predicts; r is the median of the first four impacts ("nan": the block overturns on the launch).

1. r(xi) of the three laws (two-spring and continuous Kelvin-Voigt, hunt-crossley) at omega_v/p = 300, 1000;
2. the calibration (issue 18): per bed, the range of r it reaches, the xi of Housner's value and of
   min(1.05 x Housner, 0.99), and how r of the calibrated bed depends on the amplitude (launch to 0.3,
   0.6 and 0.9 alpha). Not a test: `python benchmarks/winkler_restitution.py`.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rockfrag.blocks import Block  # noqa: E402
from rockfrag.errors import SolverError  # noqa: E402
from rockfrag.models import restitution  # noqa: E402

ALPHAS = (0.1, 0.15, 0.25, 0.4)
XIS = {"two-spring": (0.0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.7, 0.9),
       "continuous": (0.0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.7, 0.9),
       "hunt-crossley": (0.0, 0.01, 0.03, 0.1, 0.2, 0.3, 0.5, 1.0, 2.0, 4.0, 10.0)}
STIFFNESS_RATIOS = (300, 1000)  # omega_v / p of the r(xi) tables
CALIBRATION_RATIOS = (30, 100, 300, 1000)
CALIBRATION_ALPHAS = (0.1, 0.25, 0.4)
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


def calibration_table(print=print):
    """The calibration per bed: reachable range, xi of the band's edges and r at 0.3/0.6/0.9 alpha."""
    for bed in ("two-spring", "continuous"):
        law = restitution.calibrated_law(bed)
        print(f"\n  {bed} bed calibrated ({law} xi): the range of r it reaches, and r of the calibrated bed "
              "launched to 0.3 / 0.6 / 0.9 alpha")
        print("  omega_v/p  alpha  Housner  range           | target  xi       r at 0.3   0.6     0.9 alpha")
        for ratio in CALIBRATION_RATIOS:
            for alpha in CALIBRATION_ALPHAS:
                block = Block(name="r", R=2.0, alpha=alpha, mass=5000.0)
                K = stiffness(block, ratio)
                low, high = restitution.reachable_range(block, K, bed)
                housner = block.housner_restitution()
                for target in (housner, min(1.05 * housner, 0.99)):
                    try:
                        xi = restitution.calibrate_dissipation(block, K, bed, target)
                    except SolverError:
                        row = "out of reach"
                    else:
                        rs = [restitution.free_rocking_restitution(block, K, law, xi, fraction=fraction)
                              for fraction in (0.3, 0.6, 0.9)]
                        row = f"{xi:<8.3g} " + " ".join(f"{r:.4f}" for r in rs)
                    print(f"  {ratio:9d}  {alpha:5.2f}  {housner:.4f}   {low:.4f}-{high:.4f}   | {target:.4f}  {row}")


def run(print=print, png=ROOT / "reports" / "winkler_restitution.png"):
    warnings.simplefilter("ignore")
    print("Winkler bed: effective restitution r per impact (median of the first four)")
    print("block R = 2 m; launched to 0.6 alpha on the settled bed; Housner r = 1 - 1.5 sin^2(alpha)")
    curves = r_tables(print)
    calibration_table(print)
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
