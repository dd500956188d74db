"""pipeline.validation - the one number-in-range check of user values (study files, blocks, soils).

Input : a value as the user gave it (TOML or Python), the field's name and the file it came from.
Output: the value as float/int, or one ``ConfigError`` saying what was found (with its TOML type) and
        what is allowed, e.g. ``soils_custom.loam.shear_modulus: 0 out of range; must be a number > 0
        and <= 1e+13 [Pa]``.
"""

from __future__ import annotations

import json
import math
import numbers
from dataclasses import dataclass

from pipeline.errors import ConfigError


@dataclass(frozen=True)
class Number:
    """A real (or whole, ``integer=True``) number in a range; booleans are not numbers."""

    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    integer: bool = False
    unit: str = ""

    def describe(self) -> str:
        parts = []
        if self.low is not None:
            parts.append(f"{'>' if self.low_open else '>='} {self.low:g}")
        if self.high is not None:
            parts.append(f"{'<' if self.high_open else '<='} {self.high:g}")
        kind = "a whole number" if self.integer else "a number"
        unit = f" [{self.unit}]" if self.unit else ""
        return f"{kind} {' and '.join(parts)}{unit}" if parts else f"{kind}{unit}"

    def check(self, value, field, source):
        wanted = numbers.Integral if self.integer else numbers.Real
        if isinstance(value, bool) or not isinstance(value, wanted) or not math.isfinite(value):
            raise ConfigError(field, f"{shown(value)}; must be {self.describe()}", source)
        too_low = self.low is not None and (value <= self.low if self.low_open else value < self.low)
        too_high = self.high is not None and (value >= self.high if self.high_open else value > self.high)
        if too_low or too_high:
            raise ConfigError(field, f"{value:g} out of range; must be {self.describe()}", source)
        return int(value) if self.integer else float(value)


def shown(value) -> str:
    """A value as the user wrote it in TOML, with its type."""
    if isinstance(value, bool):
        return f"{str(value).lower()} is a boolean"
    if isinstance(value, int):
        return f"{value} is a whole number"
    if isinstance(value, float):
        return f"{value:g} is a number"
    if isinstance(value, str):
        return f"{value!r} is a string"
    if isinstance(value, list):
        text = json.dumps(value, default=str)
        return f"{text if len(text) < 40 else text[:37] + '...'} is a list"
    if isinstance(value, dict):
        return "a table"
    return f"{value!r} is a {type(value).__name__}"
