"""Shared by several test modules (imported, never collected): the small study that the pipeline-level tests
run once per session (fixture ``small_pipeline`` in conftest.py), and the environments of consumer packages
that pin other versions of our dependencies than the ones the package's own tests run on."""

from __future__ import annotations

import os
from pathlib import Path
from typing import NamedTuple

import pytest

ROOT = Path(__file__).resolve().parents[1]

SMALL_STUDY = """
soils = ["sand", "rock"]
models = ["housner", "ssi"]
[study]
name = "small"
record_sets = ["bolu"]
[intensity]
levels = [0.1, 0.3, 0.6, 1.0]
[blocks.paper]
R = 9.39
alpha = 0.44
mass = 326197.0
E_b = 210e9
footprint_area = 8.0
soil_depth = 2.0
[blocks.slender-cabinet]
b = 0.3
h = 1.5
mass = 2000.0
E_b = 200e9
footprint_area = 0.48
soil_depth = 1.0
[blocks.squat-machinery]
b = 1.5
h = 2.0
mass = 30000.0
"""
"""Bolu's two components, 4 levels, 2 soils, 3 blocks, Housner and SSI: every stage, in seconds."""

REPORT_TABLE = """
[report]
title = "Rocking fragility of the yard equipment"
project = "Harbour crane upgrade"
author = "A. Engineer"
"""

PIPELINE_STUDY = SMALL_STUDY + """
[fragility]
bootstrap = 5
[applicability]
n_g = 3
levels = [2.5]
block_moduli = [210e9]
""" + REPORT_TABLE
"""What ``small_pipeline`` runs through ``rockfrag fragility``: the small study with a short bootstrap, a
3-modulus applicability sweep (the default 13 x 3 x 2 would cost more than all the rest) and a titled report."""

PIPELINE_GROUP = "small-pipeline"
"""xdist group of every test using ``small_pipeline`` (conftest adds it): one worker runs the pipeline once."""


class PipelineRun(NamedTuple):
    """The outputs of one ``rockfrag fragility`` run. Read them; copy the folder before changing anything."""

    output: Path
    """The output folder (cube.nc, fragility.nc, report.pdf, ...)."""
    study: Path
    """The study file the run read."""
    warnings: list
    """Every warning the run raised (warnings.catch_warnings(record=True))."""


CONSUMERS = ROOT / "tests" / "consumers"
CONSUMERS_REQUIRED = "ROCKFRAG_CONSUMERS"
"""Environment variable: ``required`` (set by ``make test``) makes a missing consumer environment a failure."""


def consumer_python(name: str) -> Path:
    """The Python of consumer environment ``.venv-<name>`` (built by ``make consumers`` from
    tests/consumers/<name>.txt), for round trips through a package that pins other versions of our dependencies.

    Parameters
    ----------
    name : str
        The consumer, e.g. ``"pelicun"``.

    Returns
    -------
    Path
        ``.venv-<name>/bin/python``. When the environment is missing or half built the calling test fails
        if ``ROCKFRAG_CONSUMERS=required`` (``make test``, CI), else it is skipped with the command that builds it.
    """
    venv = ROOT / f".venv-{name}"
    python = venv / "bin" / "python"
    if (venv / ".installed").is_file() and python.is_file():
        return python
    log = ROOT / f".venv-{name}.log"
    reason = (f"the {name} environment {venv.name} is not built: make consumers"
              + (f" (the last build's log: {log.name})" if log.is_file() else ""))
    if os.environ.get(CONSUMERS_REQUIRED) == "required":
        pytest.fail(reason)
    pytest.skip(reason)


def pipeline_results(folder: Path, study: Path, **changes):
    """The report's ``Results`` of a pipeline run's output folder (its netCDF files read back), with ``changes``.

    Parameters
    ----------
    folder : Path
        The output folder of a ``rockfrag fragility`` run (``PipelineRun.output``).
    study : Path
        The study file the run read.
    **changes
        Fields of ``rockfrag.report.Results`` to replace (e.g. ``fragility=``, ``runtime_s=``).

    Returns
    -------
    rockfrag.report.Results
    """
    import xarray as xr

    from rockfrag.config import load_study
    from rockfrag.report import Results

    opened = {}
    for name in ("cube", "ida", "fragility", "showcase", "efficiency"):
        with xr.open_dataset(folder / f"{name}.nc") as dataset:
            opened[name] = dataset.load()
    values = dict(config=load_study(study), cube=opened["cube"], ida=opened["ida"], fragility=opened["fragility"],
                  output=folder, showcase=opened["showcase"], efficiency=opened["efficiency"])
    values.update(changes)
    return Results(**values)


def run_study_file(folder: Path, text: str):
    """Write ``text`` as ``study.toml`` in ``folder``, run it as ``rockfrag run --serial`` does and return
    (config, its processed records, cube.nc loaded): the API tests' shared small study."""
    import xarray as xr

    from rockfrag.cli import main
    from rockfrag.config import load_study
    from rockfrag.study import study_records

    (folder / "study.toml").write_text(text)
    assert main(["run", str(folder / "study.toml"), "--output", str(folder / "out"), "--no-progress",
                 "--serial"]) == 0
    config = load_study(folder / "study.toml")
    with xr.open_dataset(folder / "out" / "cube.nc") as cube:
        cube = cube.load()
    return config, study_records(config, log=lambda line: None).records, cube
