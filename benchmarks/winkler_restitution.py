"""Effective coefficient of restitution of the `winkler` model: r(xi, alpha) for both beds.

Input : nothing (a block of R = 2 m, mass 5 t, at several alpha; beds at omega_v/p = 300 and 1000).
Output: a table on stdout and reports/winkler_restitution.png (r against xi, one panel per bed).

The block is launched from the settled bed with the angular velocity that takes a rigid block to
0.6 alpha, then rocks freely. Successive peaks theta_k give r_k = sqrt(drop_{k+1} / drop_k),
drop = cos(alpha - theta) - cos(alpha) (the rigid block's impact speed squared), the quantity Housner's
r = 1 - 1.5 sin^2(alpha) predicts; the table gives the median of the first four impacts and the
number of flights (bounces) in 6 s. Not a test: `python benchmarks/winkler_restitution.py`.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pipeline.blocks import Block  # noqa: E402
from pipeline.models import simulate  # noqa: E402
from pipeline.units import STANDARD_GRAVITY as G  # noqa: E402
from tests.physics.winkler_reference import effective_restitution, rocking_peaks  # noqa: E402

ALPHAS = (0.1, 0.15, 0.25, 0.4)
XIS = (0.0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.7, 0.9)
STIFFNESS_RATIOS = (300, 1000)  # omega_v / p
BEDS = ("two-spring", "continuous")


def launch_rate(block, fraction=0.6):
    """theta'(0) [rad/s] that takes a rigid block on a rigid base to fraction * alpha."""
    drop = math.cos(block.alpha * (1 - fraction)) - math.cos(block.alpha)
    return math.sqrt(2 * block.mass * G * block.R * drop / (4 / 3 * block.mass * block.R**2))


def restitution(block, omega_over_p, xi, bed):
    """(median effective r of the first four impacts, number of flights) of free rocking."""
    K = block.mass * (omega_over_p * block.p()) ** 2
    result = simulate("winkler", np.zeros(2), 1e-3, block, k=K, xi=xi, bed=bed, thetadot0=-launch_rate(block),
                      t_end=6.0)
    peaks = rocking_peaks(result.theta)
    peaks = peaks[peaks > 0.1 * block.alpha]
    r = effective_restitution(peaks, block.alpha)[:4]
    return (float(np.median(r)) if r.size else math.nan), result.n_flights


def matching_xi(xis, rs, target):
    """Smallest xi above which r stays within 0.5% of the target (NaN if never)."""
    close = np.abs(np.asarray(rs) / target - 1) < 5e-3
    for i in range(len(xis)):
        if close[i:].all():
            return xis[i]
    return math.nan


def run(print=print, png=ROOT / "reports" / "winkler_restitution.png"):
    warnings.simplefilter("ignore")
    print("Winkler bed: effective restitution r per impact (median of the first four; flights in brackets)")
    print("block R = 2 m; launched to 0.6 alpha on the settled bed; Housner r = 1 - 1.5 sin^2(alpha)")
    curves = {}
    for bed in BEDS:
        for ratio in STIFFNESS_RATIOS:
            print(f"\n  {bed} bed, omega_v/p = {ratio}")
            print("  alpha  Housner | " + " ".join(f"xi={xi:<6g}" for xi in XIS) + " | xi matching Housner")
            for alpha in ALPHAS:
                block = Block(name="r", R=2.0, alpha=alpha, mass=5000.0)
                rows = [restitution(block, ratio, xi, bed) for xi in XIS]
                rs = [r for r, _ in rows]
                curves[bed, ratio, alpha] = rs
                match = matching_xi(XIS, rs, block.housner_restitution())
                print(f"  {alpha:5.2f}  {block.housner_restitution():7.4f} | "
                      + " ".join(f"{r:.3f}({n:>3})"[:10].ljust(9) for r, n in rows)
                      + f" | {'none' if math.isnan(match) else f'>= {match:g}'}")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:  # pragma: no cover
        print("matplotlib missing: no figure")
        return curves
    figure, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    for axis, bed in zip(axes, BEDS):
        for k, alpha in enumerate(ALPHAS):
            colour = f"C{k}"
            for ratio, style in zip(STIFFNESS_RATIOS, ("--", "-")):
                axis.plot(XIS, curves[bed, ratio, alpha], style, color=colour, marker="o", markersize=3,
                          label=f"alpha = {alpha}, omega_v/p = {ratio}")
            axis.axhline(1 - 1.5 * math.sin(alpha) ** 2, color=colour, linestyle=":", linewidth=1)
        axis.set_title(f"{bed} bed (dotted: Housner's r)")
        axis.set_xlabel("bed damping ratio xi [-]")
        axis.grid(alpha=0.3)
    axes[0].set_ylabel("effective restitution r [-]")
    axes[1].legend(fontsize=7, loc="lower right")
    figure.tight_layout()
    Path(png).parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(png, dpi=120)
    plt.close(figure)
    print(f"\n  figure: {png}")
    return curves


if __name__ == "__main__":
    run()
