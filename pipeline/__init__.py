"""rockfrag - seismic fragility of unanchored rocking structures on compliant soil.

The package reads in the order the data flows:

1. ``records``      record files (PEER AT2, obspy formats) -> acceleration traces [m/s^2] + metadata
2. ``processing``   raw trace -> demeaned, filtered, baseline-corrected trace (+ provenance, QA flags)
3. ``measures``     acceleration (array, dt) -> intensity measures (PGA, PGV, Arias, CAV, D5-95, Sa(T))
4. ``blocks``, ``soils``  block geometry and moduli; soil classes -> interface stiffness k (paper eq. 19)
5. ``models``       Housner and SSI-rocking solvers (numba kernels) -> peak angle, uplift, overturning
6. ``config``, ``study``, ``cube``  study file -> records x levels x soils x blocks x models -> cube.nc
7. ``ida``          cube -> incremental dynamic analysis curves, fractiles, capacities -> ida.nc
8. ``fragility``, ``risk``  cube -> lognormal fragility per soil and damage state; hazard -> risk
9. ``report``       figures -> PNG + PDF
Beside the flow: ``calibrate`` (fit k and xi to a reference, paper eq. 17) and ``applicability``
(where is the rigid base good enough). ``cli`` ties the stages to the ``rockfrag`` command.
"""

__version__ = "0.1.0"
