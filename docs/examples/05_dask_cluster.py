"""
Running on a dask cluster
=========================

A study is a grid of independent cells (one record on one block, soil and model at every level), so it spreads
over processes or machines. ``run_study`` runs the cells in this process (``workers=1``), on a pool of local
processes (``workers=N``), or on dask.distributed: a ``LocalCluster`` it starts (``scheduler="local"``,
``workers=N``) or a cluster that is already running (``scheduler="tcp://host:8786"``). The cube is the same
whichever runs it.

Here a ``LocalCluster`` of two worker processes runs the tiny study of :doc:`01_block_and_site`; on a real
cluster the scheduler's address is all that changes.
"""

# %%
# A cluster in a script
# ---------------------
# A ``LocalCluster`` starts its workers as new Python processes, and each of them imports the script that
# started it: in a script of your own, start the cluster only under ``if __name__ == "__main__":`` (as below),
# or the workers would start clusters of their own. One thread per worker process: the solvers are compiled
# numba code that holds the interpreter, so processes, not threads, run in parallel.
import tempfile
from pathlib import Path

import numpy as np
from dask.distributed import LocalCluster

import rockfrag


def run_on_local_cluster(config, output, n_workers=2):
    """Run a study on a LocalCluster of ``n_workers`` processes; returns the cube and the run's statistics."""
    with LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        print(f"cluster at {cluster.scheduler_address} with {len(cluster.workers)} workers")
        return rockfrag.run_study(config, output=output, scheduler=cluster.scheduler_address)


# %%
# Run the study on it
# -------------------
# ``scheduler`` is the address of any running scheduler. The records are read and processed here; the cells
# go to the workers, and their results come back into one cube, written here.
if __name__ == "__main__":
    config = rockfrag.load_study("my-site.toml")
    cube, statistics = run_on_local_cluster(config, Path(tempfile.mkdtemp(prefix="my-site-dask-")))
    print(f"{statistics['runs_computed']} runs on the cluster in {statistics['seconds']:.1f} s")

# %%
# The same cube
# -------------
# The same study in this process gives the same numbers, bit for bit: a cell does not depend on where or in
# which order it runs.
if __name__ == "__main__":
    here, _ = rockfrag.run_study(config, output=Path(tempfile.mkdtemp(prefix="my-site-here-")), workers=1)
    same = all(np.array_equal(cube[name].values, here[name].values, equal_nan=True)
               for name in ("peak_angle", "outcome", "capacity_scale_factor"))
    print("identical cubes:", same)

# %%
# A running cluster
# -----------------
# On machines of your own, start a scheduler (``dask scheduler``) and workers (``dask worker
# tcp://scheduler-host:8786`` on each machine, with rockfrag installed), then give the scheduler's address:
# ``run_study(config, scheduler="tcp://scheduler-host:8786")``. On the command line the same choice is
# ``--scheduler local --workers 2`` (a LocalCluster of two processes) or ``--scheduler ADDRESS`` on
# ``rockfrag run`` and ``rockfrag fragility``::
#
#     rockfrag run my-site.toml --scheduler local --workers 2
#     rockfrag fragility my-site.toml --scheduler tcp://scheduler-host:8786
#
# Checkpoints are written as cells finish, wherever they ran: a study interrupted on a cluster resumes from
# them at the next run, on the cluster or not.
