"""rockfrag.api - the public API's own functions: stable, typed signatures over the stages' internal ones.

Input : what a user of ``import rockfrag`` passes. Output: what the stages return. Only functions whose stage
signature carries internal plumbing (the command's log and cache arguments) get a function here; the others are
the stages' own functions, which ``rockfrag/__init__.py`` lists.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rockfrag.errors import PipelineError

if TYPE_CHECKING:
    import xarray as xr

    from rockfrag.config import StudyConfig


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
