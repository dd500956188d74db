"""rockfrag.validation - the one validation layer: schemas of user values, checked once where they enter.

Input : a value as the user gave it (TOML or Python), the field's name and the file it came from.
Output: the value (numbers as float/int), or one ``ConfigError`` naming the file and the field, saying
        what was found (with its TOML type) and what is allowed, e.g. ``soils_custom.loam.shear_modulus:
        0 out of range; must be a number > 0.0 and <= 1e+13 [Pa]``.

A schema is built from small classes that all have ``check(value, field, source)``: ``Number``,
``Text``, ``Flag``, ``Names``, ``Numbers``, ``Interval``, ``Nullable``, ``Table`` (fixed keys),
``NamedTables`` (``[PREFIX.NAME]`` tables), ``Either`` and ``Checked`` (a function of its own). Study
files (rockfrag.config), processing recipes (rockfrag.processing), calibration options
(rockfrag.calibrate) and solver options (rockfrag.models) declare theirs with them.
"""

from __future__ import annotations

import difflib
import json
import math
import numbers
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from rockfrag.errors import ConfigError


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
        """What the value must be.

        For example ``a number from 0.0 to 0.5``, ``a number > 0.0 and <= 1.0 [s]``, ``a whole number >= 2``.
        """
        kind = "a whole number" if self.integer else "a number"
        unit = f" [{self.unit}]" if self.unit else ""
        low, high = (None if bound is None else self._shown(bound) for bound in (self.low, self.high))
        if low is not None and high is not None and not (self.low_open or self.high_open or self.integer):
            return f"{kind} from {low} to {high}{unit}"
        parts = []
        if low is not None:
            parts.append(f"{'>' if self.low_open else '>='} {low}")
        if high is not None:
            parts.append(f"{'<' if self.high_open else '<='} {high}")
        return f"{kind} {' and '.join(parts)}{unit}" if parts else f"{kind}{unit}"

    def _shown(self, bound: float) -> str:
        """A bound as a whole number (``integer``) or as a real one (``0.0``, ``1e+13``)."""
        text = f"{bound:g}"
        return text if self.integer or any(c in text for c in ".en") else f"{text}.0"

    def check(self, value: Any, field: str, source: str | None) -> float | int:
        """The value as float (int with ``integer``), or a ``ConfigError`` naming the allowed range."""
        wanted = numbers.Integral if self.integer else numbers.Real
        if isinstance(value, bool) or not isinstance(value, wanted) or not math.isfinite(value):
            raise ConfigError(field, f"{shown(value)}; must be {self.describe()}", source)
        too_low = self.low is not None and (value <= self.low if self.low_open else value < self.low)
        too_high = self.high is not None and (value >= self.high if self.high_open else value > self.high)
        if too_low or too_high:
            raise ConfigError(field, f"{value:g} out of range; must be {self.describe()}", source)
        return int(value) if self.integer else float(value)


@dataclass(frozen=True)
class Text:
    """A string, optionally one of ``choices``."""

    choices: tuple[str, ...] = ()
    nonempty: bool = False

    def describe(self) -> str:
        """What the value must be."""
        return f"one of {', '.join(repr(c) for c in self.choices)}" if self.choices else "a string"

    def check(self, value: Any, field: str, source: str | None) -> str:
        """The string, or a ``ConfigError`` listing the allowed choices."""
        allowed = f"; allowed: {', '.join(repr(c) for c in self.choices)}" if self.choices else ""
        if not isinstance(value, str):
            raise ConfigError(field, f"{shown(value)}; must be a string{allowed}", source)
        if self.choices and value not in self.choices:
            raise ConfigError(field, f"{value!r} unknown{did_you_mean(value, self.choices)}{allowed}", source)
        if self.nonempty and not value.strip():
            raise ConfigError(field, "empty; must be a non-empty string", source)
        return value


@dataclass(frozen=True)
class Flag:
    """A boolean (TOML ``true``/``false``)."""

    def describe(self) -> str:
        """What the value must be."""
        return "true or false"

    def check(self, value: Any, field: str, source: str | None) -> bool:
        """The boolean, or a ``ConfigError``."""
        if not isinstance(value, bool):
            raise ConfigError(field, f"{shown(value)}; must be true or false", source)
        return value


@dataclass(frozen=True)
class Names:
    """A non-empty list of non-empty strings (names of soils, models, blocks, record sets)."""

    example: str

    def describe(self) -> str:
        """What the value must be."""
        return f"a list of names, e.g. {self.example}"

    def check(self, value: Any, field: str, source: str | None) -> list:
        """The list, or a ``ConfigError`` naming the bad item."""
        if not isinstance(value, list):
            raise ConfigError(field, f"{shown(value)}; must be a list of names, e.g. {self.example}", source)
        if not value:
            raise ConfigError(field, f"empty list; name at least one, e.g. {self.example}", source)
        for index, item in enumerate(value):
            if not isinstance(item, str):
                raise ConfigError(f"{field}[{index}]", f"{shown(item)}; must be a name (a string)", source)
            if not item.strip():
                raise ConfigError(f"{field}[{index}]", "empty name", source)
        return value


@dataclass(frozen=True)
class Numbers:
    """A non-empty list of numbers, each checked by ``item``."""

    item: Number

    def describe(self) -> str:
        """What the value must be."""
        return f"a non-empty list of {self.item.describe()}"

    def check(self, value: Any, field: str, source: str | None) -> list:
        """The numbers as floats (ints), or a ``ConfigError`` naming the bad item ``field[i]``."""
        if not isinstance(value, list) or not value:
            raise ConfigError(field, f"{shown(value)}; must be {self.describe()}", source)
        return [self.item.check(v, f"{field}[{i}]", source) for i, v in enumerate(value)]


@dataclass(frozen=True)
class Interval:
    """``[low, high]``: a list or tuple of two numbers, each checked by ``item``, with low < high.

    low <= high is allowed unless ``strict``; ``names`` are what the message calls the two ends.
    """

    item: Number
    names: tuple[str, str] = ("low", "high")
    strict: bool = True

    def describe(self) -> str:
        """What the value must be, e.g. ``[k_min, k_max] with k_min < k_max [N/m]``."""
        low, high = self.names
        unit = f" [{self.item.unit}]" if self.item.unit else ""
        return f"[{low}, {high}] with {low} {'<' if self.strict else '<='} {high}{unit}"

    def check(self, value: Any, field: str, source: str | None) -> tuple[float, float]:
        """(low, high) as numbers, or a ``ConfigError``."""
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            raise ConfigError(field, f"{shown(value)}; must be {self.describe()}", source)
        low, high = (self.item.check(v, f"{field}[{i}]", source) for i, v in enumerate(value))
        if not (low < high if self.strict else low <= high):
            raise ConfigError(field, f"{list(value)}; must be {self.describe()}", source)
        return low, high


@dataclass(frozen=True)
class Nullable:
    """``None`` (the caller's default) or a value checked by ``item`` (Python arguments, not TOML)."""

    item: Any

    def describe(self) -> str:
        """What the value must be."""
        return f"None or {self.item.describe()}"

    def check(self, value: Any, field: str, source: str | None) -> Any:
        """None, or the value as ``item`` checks it."""
        return None if value is None else self.item.check(value, field, source)


@dataclass(frozen=True)
class Table:
    """A table with a fixed set of keys (any other key is an error listing the allowed ones).

    ``required`` keys must be present. ``what`` is what the message calls an unknown key (``key``,
    ``parameter of step 'taper'``); ``misplaced(key)`` may add a hint for a key that belongs elsewhere.
    """

    fields: dict
    required: tuple[str, ...] = ()
    what: str = "key"
    misplaced: Callable[[str], str] | None = None

    def describe(self) -> str:
        """What the value must be."""
        return f"a table with keys {', '.join(sorted(self.fields)) or '(none)'}"

    def check(self, value: Any, field: str, source: str | None) -> dict:
        """The table unchanged, after every key and value in it is checked."""
        if not isinstance(value, dict):
            raise ConfigError(field or "(top level)", f"{shown(value)}; must be a table ([{field}] or {{ ... }})",
                              source)
        for key, item in value.items():
            where = f"{field}.{key}" if field else key
            if key not in self.fields:
                dotted = (f" (a table name with a dot must be quoted: [{field.rsplit('.', 1)[0]}."
                          f"\"{field.rsplit('.', 1)[1]}.{key}\"])" if isinstance(item, dict) and field.count(".") == 1
                          else "")
                hint = self.misplaced(key) if self.misplaced and field else ""
                raise ConfigError(where, unknown_key(key, self.fields, self.what, hint) + dotted, source)
            self.fields[key].check(item, where, source)
        for key in self.required:
            if key not in value:
                where = f"{field}.{key}" if field else key
                raise ConfigError(where, f"missing; must be {self.fields[key].describe()}", source)
        return value


@dataclass(frozen=True)
class NamedTables:
    """``[PREFIX.NAME]`` tables: any name, each a ``Table``."""

    table: Table

    def describe(self) -> str:
        """What the value must be."""
        return "tables [PREFIX.NAME]"

    def check(self, value: Any, field: str, source: str | None) -> dict:
        """The tables unchanged, after each is checked by ``table``."""
        if not isinstance(value, dict):
            raise ConfigError(field, f"{shown(value)}; must be tables [{field}.NAME]", source)
        for name, item in value.items():
            if not isinstance(item, dict):
                raise ConfigError(f"{field}.{name}", f"{shown(item)}; must be a table [{field}.{name}] with keys "
                                  f"{', '.join(sorted(self.table.fields))}", source)
            self.table.check(item, f"{field}.{name}", source)
        return value


@dataclass(frozen=True)
class Either:
    """A list (the first spec) or tables (the second), chosen by the value's TOML type."""

    as_list: Names
    as_tables: NamedTables

    def describe(self) -> str:
        """What the value must be."""
        return f"{self.as_list.describe()}, or {self.as_tables.describe()}"

    def check(self, value: Any, field: str, source: str | None) -> Any:
        """The value as the spec of its type checks it."""
        return (self.as_list if isinstance(value, list) else self.as_tables).check(value, field, source)


@dataclass(frozen=True)
class Checked:
    """A value checked by its own function ``function(value, field, source)`` (returns the value)."""

    function: Callable[[Any, str, str | None], Any]
    description: str = "see the documentation"

    def describe(self) -> str:
        """What the value must be."""
        return self.description

    def check(self, value: Any, field: str, source: str | None) -> Any:
        """What ``function`` returns."""
        return self.function(value, field, source)


def schema_keys(spec: Any, prefix: str = "") -> list[tuple[str, str]]:
    """Every key a schema accepts, as (dotted key, what its value must be), in declaration order.

    Parameters
    ----------
    spec : schema object
        A ``Table`` (walked key by key), ``NamedTables`` (its keys shown under ``PREFIX.NAME``), ``Either``
        (both forms) or a leaf (``Number``, ``Text``, ...).
    prefix : str
        The dotted key of ``spec`` ("" at the top level).

    Returns
    -------
    list of (str, str)
        One row per leaf key: its dotted name and ``describe()`` of its spec (type, range, unit).
    """
    if isinstance(spec, Table):
        return [row for key, item in spec.fields.items()
                for row in schema_keys(item, f"{prefix}.{key}" if prefix else key)]
    if isinstance(spec, NamedTables):
        return schema_keys(spec.table, f"{prefix}.NAME")
    if isinstance(spec, Either):
        return [(prefix, spec.as_list.describe())] + schema_keys(spec.as_tables, prefix)
    return [(prefix, spec.describe())]


def unknown_key(key: str, allowed, what: str = "key", hint: str = "") -> str:
    """The reason for an unknown key: ``unknown key (did you mean 'x'?); allowed: ...``.

    Parameters
    ----------
    key : str
        The key as the user wrote it.
    allowed : iterable of str
        The keys the table takes.
    what : str
        What the message calls the key (``key``, ``parameter of step 'taper'``).
    hint : str
        More advice, after the did-you-mean, e.g. `` (top-level keys ... come first)``.
    """
    return f"unknown {what}{did_you_mean(key, allowed)}{hint}; allowed: {', '.join(sorted(allowed)) or 'none'}"


DID_YOU_MEAN_CUTOFF = 0.7
"""How close (difflib ratio, 0-1) a choice must be to what the user wrote to be suggested."""


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """`` (did you mean 'winkler'?)`` for the choice closest to ``word``, or '' if none is close.

    The one did-you-mean of the package: study keys and names (models, soils, blocks, measures,
    damage-state EDPs), command-line options and record selections.

    Parameters
    ----------
    word : str
        What the user wrote.
    choices : iterable of str
        The valid names.

    Returns
    -------
    str
        The hint with a leading space, ready to append to a message; '' if no choice is within
        ``DID_YOU_MEAN_CUTOFF`` or ``word`` is not a string.
    """
    if not isinstance(word, str):
        return ""
    close = difflib.get_close_matches(word, [str(choice) for choice in choices], n=1, cutoff=DID_YOU_MEAN_CUTOFF)
    return f" (did you mean {close[0]!r}?)" if close else ""


def shown(value: Any) -> str:
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
