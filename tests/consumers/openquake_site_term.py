"""Run by .venv-openquake's Python (tests/test_site_amplification.py): OpenQuake's own BSSA14 ground motion model
(``openquake.hazardlib.gsim.boore_2014.BooreEtAl2014``, unspecified mechanism: ``sof=False``) at scenarios and site
Vs30s, so that rockfrag's site term and rock medians are checked against an independent implementation.

Usage: python openquake_site_term.py QUERY OUT. QUERY is JSON {"imts": ["PGA", "PGV", "SA(1.0)", ...],
"cases": [[magnitude, rjb_km, vs30_m_s], ...]}; OUT receives {"ln_mean": [[ln median per case] per imt]}, the
natural log of the median (PGA and SA in g, PGV in cm/s). Imports openquake, never rockfrag.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

os.environ.setdefault("NUMBA_DISABLE_JIT", "1")  # one model's means: compiling the engine's kernels takes minutes

import numpy as np  # noqa: E402
from openquake.hazardlib.contexts import simple_cmaker  # noqa: E402
from openquake.hazardlib.gsim.boore_2014 import BooreEtAl2014  # noqa: E402


def ln_means(imts: list[str], cases: list[list[float]]) -> list[list[float]]:
    """ln median of each IMT at each (magnitude, Joyner-Boore distance [km], Vs30 [m/s]) case."""
    rows = []
    for magnitude, distance, vs30 in cases:
        maker = simple_cmaker([BooreEtAl2014(sof=False)], imts, mags=[f"{magnitude:.2f}"])
        ctx = maker.new_ctx(1)
        ctx.mag, ctx.rjb, ctx.rrup, ctx.rake = magnitude, distance, distance, 0.0
        ctx.vs30 = np.array([vs30])
        ctx.z1pt0 = np.array([-999.0])
        mean = maker.get_mean_stds([ctx])[0]  # (gsim, imt, site)
        rows.append(mean[0, :, 0].tolist())
    return np.array(rows).T.tolist()


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("query", type=Path)
    parser.add_argument("out", type=Path)
    arguments = parser.parse_args()
    query = json.loads(arguments.query.read_text())
    arguments.out.write_text(json.dumps({"ln_mean": ln_means(query["imts"], query["cases"])}))
