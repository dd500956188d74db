"""Run by .venv-openquake's Python (tests/test_openquake.py): read our fragility_openquake.xml with OpenQuake's
own NRML reader (``openquake.hazardlib.nrml.to_python``, the call the engine makes on a fragility file; importing
``openquake.risklib`` registers its fragility-model reader), evaluate every function with OpenQuake's own
fragility functions, and run risklib's classical damage on a hazard curve.

Usage: python openquake_fragility.py FOLDER [FOLDER ...] [--example FILE] (one import of OpenQuake for several
files; ``--example`` then runs the Python of FILE, the README's OpenQuake example, in the first FOLDER's parent,
in this process). Reads each
FOLDER/fragility_openquake.xml and FOLDER/query.json
({"levels": [intensity...], "hazard": {"imls": [...], "poes": [...], "investigation_time": years,
"risk_investigation_time": years}}). Writes FOLDER/openquake.json: the model's id, categories and limit states,
and per function (in the file's order) its id, IMT, format, minIML, maxIML, the (mean, stddev) per limit state
(a continuous function) or its IMLs and the table of P per limit state and IML as read (a discrete one),
P(limit state | level) from ``FragilityFunctionList.build`` and, from ``scientific.classical_damage``, the
probability of reaching each limit state in the risk investigation time. Imports openquake, never pipeline.
"""

from __future__ import annotations

import argparse
import json
import os
import runpy
from pathlib import Path

os.environ.setdefault("NUMBA_DISABLE_JIT", "1")  # the reader calls no compiled kernel; compiling them takes minutes

import numpy as np  # noqa: E402
from openquake.hazardlib import nrml  # noqa: E402
from openquake.risklib import read_nrml, scientific  # noqa: E402, F401 (read_nrml registers the fragility reader)


def read(folder: Path) -> dict:
    """What OpenQuake reads from ``folder/fragility_openquake.xml`` and computes with it."""
    query = json.loads((folder / "query.json").read_text())
    hazard = query["hazard"]
    model = nrml.to_python(str(folder / "fragility_openquake.xml"))
    functions = []
    for (imt, function_id), functions_list in model.items():
        built = functions_list.build(model.limitStates)
        levels = np.array(query["levels"], float)
        poos = scientific.classical_damage(built, np.array(hazard["imls"], float), np.array(hazard["poes"], float),
                                           hazard["investigation_time"], hazard["risk_investigation_time"])
        continuous = functions_list.format == "continuous"  # else discrete: poes at its imls
        functions.append({
            "id": function_id, "imt": imt, "format": functions_list.format,
            "minIML": getattr(functions_list, "minIML", None), "maxIML": getattr(functions_list, "maxIML", None),
            "mean": functions_list.array[:, 0].tolist() if continuous else None,
            "stddev": functions_list.array[:, 1].tolist() if continuous else None,
            "imls": None if continuous else list(functions_list.imls),
            "table": None if continuous else functions_list.array.tolist(),
            "poes": [function(levels).tolist() for function in built],
            "in_life": (1 - np.cumsum(poos)[:-1]).tolist(),  # P(reaching limit state k) from P(damage state k)
        })
    return {"id": model.id, "assetCategory": model.assetCategory, "lossCategory": model.lossCategory,
            "limitStates": list(model.limitStates), "functions": functions}


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("folders", type=Path, nargs="+")
    parser.add_argument("--example", type=Path)
    arguments = parser.parse_args()
    for target in arguments.folders:
        (target / "openquake.json").write_text(json.dumps(read(target)))
    if arguments.example:
        os.chdir(arguments.folders[0].resolve().parent)
        runpy.run_path(str(arguments.example.resolve()), run_name="__main__")
