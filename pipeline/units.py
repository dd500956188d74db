"""rockfrag.units - SI constants and converters used at the edges of the pipeline.

Everything inside the package is SI (m, s, rad, kg, N/m, Pa, m/s^2). Converters turn the units
found in record files or given by users into SI, and back for display.
"""

from __future__ import annotations

STANDARD_GRAVITY = 9.80665
"""Standard acceleration of gravity [m/s^2] (CGPM 1901), used to convert g to m/s^2."""

# Factor that turns one unit of acceleration into m/s^2.
ACCELERATION_UNITS = {
    "m/s^2": 1.0,
    "m/s**2": 1.0,
    "m/s2": 1.0,
    "g": STANDARD_GRAVITY,
    "cm/s^2": 0.01,
    "cm/s**2": 0.01,
    "cm/s2": 0.01,
    "gal": 0.01,
    "mm/s^2": 0.001,
}


def acceleration_factor(unit: str) -> float:
    """Factor converting acceleration in ``unit`` to m/s^2.

    Raises
    ------
    ValueError
        If the unit is unknown; the message lists the accepted units.
    """
    key = unit.strip().lower().replace(" ", "")
    for name, factor in ACCELERATION_UNITS.items():
        if name.lower() == key:
            return factor
    raise ValueError(
        f"unknown acceleration unit {unit!r}; accepted: {', '.join(sorted(ACCELERATION_UNITS))}"
    )
