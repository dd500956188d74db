"""rockfrag - seismic fragility of unanchored rocking structures on compliant soil.

The package reads in the order the data flows:

1. ``records``    record files (PEER AT2, obspy formats) -> acceleration traces [m/s^2] + metadata
2. ``processing`` raw trace -> demeaned, filtered, baseline-corrected trace (+ provenance, QA flags)
3. ``measures``   acceleration (array, dt) -> intensity measures (PGA, PGV, Arias, CAV, D5-95, Sa(T))
4. ``soils``      soil classes and blocks -> interface stiffness k (paper eq. 19), damping
5. ``models``     Housner and SSI-rocking solvers (numba kernels) -> peak angle, uplift, overturning
6. ``study``      records x intensity levels x soils x blocks x models -> xarray cube (netCDF)
7. ``ida``        cube -> incremental dynamic analysis curves
8. ``fragility``  cube -> lognormal fragility curves per soil and damage state
9. ``report``     figures -> PNG + PDF
``cli`` ties the stages to the ``rockfrag`` command.
"""

__version__ = "0.1.0"
