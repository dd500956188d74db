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
"""

__version__ = "0.1.0"
