"""rockfrag - seismic fragility of unanchored rocking structures on compliant soil.

The package reads in the order the data flows:

1. ``records``      record files (PEER AT2, text/CSV, obspy formats) -> acceleration traces [m/s^2] + metadata
2. ``processing``   raw trace -> demeaned, filtered, baseline-corrected trace (+ provenance, QA flags);
   ``records_report``  the processed records -> records.csv and per-record figures (``rockfrag records``)
3. ``measures``     acceleration (array, dt) -> intensity measures (PGA, PGV, Arias, CAV, D5-95, Sa(T), ...):
                    one registered definition per measure, read by every stage
4. ``blocks``, ``soils``, ``plausibility``  block geometry and moduli; soil classes -> interface stiffness k
                    (paper eq. 19); the physical plausibility of each block on each soil
5. ``models``       Housner, SSI-rocking and Winkler-bed solvers (numba kernels) -> peak angle, uplift, overturning
6. ``config``, ``study``, ``executors``, ``cube``  study file -> records x levels x soils x blocks x models, run in
                    process, on a process pool or on dask -> cube.nc; ``showcase`` -> showcase.nc for the report
7. ``ida``          cube -> incremental dynamic analysis curves, fractiles, capacities -> ida.nc;
                    ``efficiency`` ranks the measures by the capacities -> efficiency.nc
8. ``damage_states``, ``fragility``, ``lognormal_fit``  cube -> lognormal fragility per soil and damage state;
   ``hazard``, ``risk``  site hazard curve -> annual frequency and probability in the design life
9. ``report``       result files -> numbered PDF, its HTML twin and one PNG per page

Beside the flow: ``calibrate`` (fit k and xi to a reference, paper eq. 17) and ``applicability``
(where is the rigid base good enough). Shared by the stages: ``validation`` (schemas of user values),
``errors``, ``units`` (SI constants), ``outputs`` (atomic writes, the one netCDF writer),
``checkpoints`` and ``locking``. ``cli`` ties the stages to the ``rockfrag`` command (``__main__``:
``python -m rockfrag``).

The public API is this package's ``__all__``: ``import rockfrag``, then ``rockfrag.simulate``, ``rockfrag.Block``,
``rockfrag.load_study``, ``rockfrag.run_study``, ... Everything else is internal: its modules may change between
versions. Each name is imported from its stage on first use (module ``__getattr__``), so ``import rockfrag`` stays
light for the command line (the version alone, ``rockfrag.version``); ``api`` holds the API's own functions where
a stage's signature carries internal plumbing or a user's step spans stages (``run_fragility``).
"""

from __future__ import annotations

import importlib

from rockfrag.version import __version__

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing (a third of the root's import time)
if TYPE_CHECKING:  # the names as type checkers and readers see them; at run time __getattr__ imports each
    from rockfrag.answer import answer_table
    from rockfrag.api import intensity_measures, run_fragility, run_study, shipped_soils
    from rockfrag.blocks import Block
    from rockfrag.config import load_study
    from rockfrag.errors import ConfigError, PipelineError, RecordError, SolverError
    from rockfrag.fragility import fragility_dataset
    from rockfrag.hazard import load_hazard
    from rockfrag.models import simulate
    from rockfrag.processing import load_recipe, process_record
    from rockfrag.records import load_records
    from rockfrag.risk import annual_frequency, probability_in_life, risk_dataset
    from rockfrag.soils import SoilClass

_HOMES = {
    # the model
    "simulate": "rockfrag.models", "Block": "rockfrag.blocks", "SoilClass": "rockfrag.soils",
    "shipped_soils": "rockfrag.api",
    # the study: definition, inputs, run
    "load_study": "rockfrag.config", "load_records": "rockfrag.records", "load_recipe": "rockfrag.processing",
    "process_record": "rockfrag.processing", "intensity_measures": "rockfrag.api", "run_study": "rockfrag.api",
    # from the cube to the answer and the risk
    "run_fragility": "rockfrag.api", "answer_table": "rockfrag.answer",
    "fragility_dataset": "rockfrag.fragility", "load_hazard": "rockfrag.hazard", "risk_dataset": "rockfrag.risk",
    "annual_frequency": "rockfrag.risk", "probability_in_life": "rockfrag.risk",
    # what the functions raise
    "PipelineError": "rockfrag.errors", "ConfigError": "rockfrag.errors", "RecordError": "rockfrag.errors",
    "SolverError": "rockfrag.errors",
}
"""Each public name and the module that defines it."""

__all__ = [
    "__version__",
    "simulate", "Block", "SoilClass", "shipped_soils",
    "load_study", "load_records", "load_recipe", "process_record", "intensity_measures", "run_study",
    "run_fragility", "answer_table", "fragility_dataset", "load_hazard", "risk_dataset", "annual_frequency",
    "probability_in_life",
    "PipelineError", "ConfigError", "RecordError", "SolverError",
]
"""The public API (tests/test_public_api.py: each name has a home in ``_HOMES``, and each function is typed and
documented)."""


def __getattr__(name: str) -> object:
    """A public name, imported from its module on first use (then cached here)."""
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'rockfrag' has no attribute {name!r}")
    value = getattr(importlib.import_module(home), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The module's names with the public ones not imported yet."""
    return sorted({*globals(), *_HOMES})
