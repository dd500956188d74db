"""rockfrag.api - the public API's own functions: stable, typed signatures over the stages' internal ones.

Input : what a user of ``import rockfrag`` passes. Output: what the stages return. A function is here when the
stage's signature carries internal plumbing (the command's log and cache arguments: ``run_study``), when a user's
step spans stages (``run_fragility``: the IDA and the fits after ``run_study``), or when the stage's function takes
what a user does not hold (``intensity_measures`` of a ``Record``, ``shipped_soils``); the others are the stages'
own functions, which ``rockfrag/__init__.py`` lists.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rockfrag.errors import PipelineError

if TYPE_CHECKING:
    from collections.abc import Callable

    import xarray as xr

    from rockfrag.config import StudyConfig
    from rockfrag.records import Record
    from rockfrag.soils import SoilClass


def run_study(config: StudyConfig, *, output: str | Path | None = None, workers: int | None = None,
              scheduler: str | None = None, progress: bool = False,
              wait: bool = False) -> tuple[xr.Dataset, dict[str, Any]]:
    """Run (or resume) a study and write its cube, ``cube.nc``, as ``rockfrag run`` does.

    Parameters
    ----------
    config : StudyConfig
        The study (``rockfrag.load_study``).
    output : str or Path, optional
        The output folder; default the study's ``study.output``, relative to the working folder. Finished cells
        are checkpointed in its ``.checkpoints/`` and reused by the next run of the same study.
    workers : int, optional
        Size of the process pool (>= 1; 1 runs in this process); default all cores.
    scheduler : str, optional
        ``"local"``: a dask ``LocalCluster`` of ``workers`` processes; an address such as ``"tcp://host:8786"``:
        a running dask cluster (then ``workers`` must be None). Default: the process pool.
    progress : bool, optional
        Show a progress bar on stderr (default False).
    wait : bool, optional
        If another run holds the output folder, wait for it instead of raising (default False).

    Returns
    -------
    cube : xarray.Dataset
        The study cube (record x im_level x soil x block x model; docs/reference/outputs.md), as written to ``cube.nc``.
    statistics : dict
        The run's counts and timings: ``cells``, ``cells_reused``, ``runs_computed``, ``seconds``, ``failures``
        (the records skipped, each with its reason), ...

    Raises
    ------
    PipelineError
        No record could be read, the output folder is unusable or held by another run, or the executor
        options are invalid (``ConfigError`` and ``RecordError`` are kinds of it).
    """
    from rockfrag.executors import check_scheduler
    from rockfrag.study import run_study as run

    if scheduler == "local":
        return run(config, output=output, dask_workers=workers or os.cpu_count(), progress=progress, wait=wait)
    if scheduler is not None and workers is not None:
        raise PipelineError(f"workers={workers} with scheduler={scheduler!r}: a running cluster has its own workers")
    check_scheduler(scheduler)  # whether or not cells remain to compute
    return run(config, output=output, workers=workers, scheduler=scheduler, progress=progress, wait=wait)


def run_fragility(config: StudyConfig, cube: xr.Dataset, *, output: str | Path | None = None,
                  progress: bool = False, notes: Callable[[str], object] | None = None) -> xr.Dataset:
    """Fit the fragility curves and the risk of a study's cube, and write them, as ``rockfrag fragility`` does.

    The step after ``run_study``, without another solver run: the IDA curves and refined overturning capacities
    (``ida.nc``), then one lognormal curve per model, soil, block and damage state with its bootstrap bounds and,
    with the study's hazard curve (or the shipped example curve), the risk in the design life (``fragility.nc``,
    ``fragility.csv`` and the pelicun and OpenQuake exchange files). ``rockfrag fragility`` also writes the
    showcase, the measure ranking and the report.

    Parameters
    ----------
    config : StudyConfig
        The study (``rockfrag.load_study``): its damage states, bootstrap size and seed, confidence, hazard file and
        design life.
    cube : xarray.Dataset
        The study's cube, as ``run_study`` returns it (or ``cube.nc`` opened with xarray).
    output : str or Path, optional
        The folder the files are written into (atomically); default the study's ``study.output``.
    progress : bool, optional
        Show a progress bar of the bootstrap on stderr (default False).
    notes : callable, optional
        Receives one line per fit note (a step fit, a rough dispersion, a state no record reached) and per
        exchange file left out; default: print them to stderr. The notes are also kept in the dataset's attribute
        ``fit_warnings``.

    Returns
    -------
    xarray.Dataset
        The fits merged with the risk, as written to ``fragility.nc`` (model x soil x block x damage_state;
        docs/reference/outputs.md); ``answer_table`` turns it into the answer.

    Raises
    ------
    ConfigError
        The study's hazard curve does not load or is for another intensity measure.
    """
    from rockfrag.fragility import fragility_stage
    from rockfrag.ida import ida_stage

    folder = Path(output or config.output)
    ida = ida_stage(cube, folder)
    fragility, _ = fragility_stage(cube, ida, config, folder, progress=progress, log=notes)
    return fragility


def intensity_measures(record: Record) -> dict[str, float]:
    """The intensity measures of one record that need no block, as ``records.csv`` gives them.

    Parameters
    ----------
    record : Record
        One component, as ``load_records`` reads it; pass it through ``process_record`` first to measure what a
        study measures (PGV, PGD, CAV and the pulse depend on the baseline).

    Returns
    -------
    dict of str to float
        SI values keyed ``<measure>_<unit>``, the columns of ``records.csv``: ``pga_m_s2``, ``pgv_m_s``, ``pgd_m``,
        ``sa_<T>s_m_s2`` (5% damped, at the periods of ``records.csv``), ``arias_m_s``, ``cav_m_s``, ``d5_95_s``,
        ``pulse_period_s``, ``pulse_amplitude_m_s2``, and those of the installed plugins' measures.
    """
    from rockfrag.measures import intensity_measures as measured

    return {key: float(value) for key, value in measured(record.acceleration, record.dt).items()}


def shipped_soils() -> dict[str, SoilClass]:
    """The soils rockfrag ships, by name: clay, sand, gravel and rock (the paper's Table 1) and a steel base.

    A study names them in ``soils``; ``simulate`` takes the name or the ``SoilClass``. A soil of one's own is a
    ``SoilClass`` (or a study's ``[soils_custom.NAME]`` table).

    Returns
    -------
    dict of str to SoilClass
        A new dict on every call (changing it changes nothing in rockfrag): name -> soil, with its shear modulus
        [Pa], Poisson's ratio, density [kg/m^3], friction coefficients, the Vs30 of its site [m/s] and a
        description that cites its source.
    """
    from rockfrag.soils import SOILS

    return dict(SOILS)
