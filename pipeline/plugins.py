"""rockfrag.plugins - the registries, and the installed packages (plugins) that add to them.

Input : the entry points of the installed distributions (``importlib.metadata``) in the groups of ``GROUPS``.
Output: ``Registry``, the name -> object mapping every registry of rockfrag is (measures, damage states, record
        formats, contact laws); on its first read it loads the entry points of its group once and adds what they name.

A package adds a measure, a damage state or a record format by naming an object in its ``pyproject.toml``::

    [project.entry-points."rockfrag.measures"]
    cav = "rockfrag_cav:CAV"            # a rockfrag.measures.Measure named "cav"

    [project.entry-points."rockfrag.damage_states"]
    "rocking-0.8" = "rockfrag_cav:ROCKING_08"   # a rockfrag.damage_states.DamageState

    [project.entry-points."rockfrag.record_formats"]
    MYFORMAT = "my_reader:FORMAT"       # a rockfrag.records.RecordFormat(is_format, read_format)

The entry point's name is the name the object is registered under (and must be the object's own ``name`` where it
has one). Loading is lazy (nothing is imported until a registry is first read, e.g. when a study is checked) and
happens once per process; a plugin that cannot be imported, or names an object of the wrong kind, raises one
``PluginError`` naming the distribution, the group and the entry point, on every read of that registry (so no
result is computed with half a registry). docs/plugins.md is the worked example.

A contact law is a module (``NAME`` and four numba-compiled hooks) named in the group ``rockfrag.contact_laws``::

    [project.entry-points."rockfrag.contact_laws"]
    toy-hertz = "rockfrag_toy.bed_hertz"

rockfrag.models.contact reads that registry when it is imported and calls a plugin's hooks through their addresses
(its docstring says why and how).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, MutableMapping
from importlib.metadata import EntryPoint, entry_points

from rockfrag.errors import PipelineError

GROUPS = {"measures": "rockfrag.measures", "damage_states": "rockfrag.damage_states",
          "record_formats": "rockfrag.record_formats", "contact_laws": "rockfrag.contact_laws"}
"""The entry-point group of each registry (``contact_laws``: rockfrag.models.contact.CONTACT_LAWS)."""


class PluginError(PipelineError):
    """An installed plugin cannot be loaded: names the distribution, the entry point and what is wrong."""


def _where(entry_point: EntryPoint) -> str:
    """'package 1.0, entry point rockfrag.measures: cav = module:object'."""
    dist = entry_point.dist
    package = f"package {dist.metadata['Name']} {dist.version}, " if dist is not None else ""
    return f"{package}entry point {entry_point.group}: {entry_point.name} = {entry_point.value}"


class Registry(MutableMapping):
    """A registry: name -> object, in registration order (or ``order``), completed by its plugins on first read.

    Parameters
    ----------
    group : str
        The entry-point group whose objects are added (``GROUPS``).
    kind : type
        The class every plugin object must be an instance of.
    order : callable, optional
        Sort key of the values: the registry is kept sorted by it (damage states by severity).
    check : callable, optional
        ``check(name, value)``: what is wrong with a plugin's object beyond its kind and name, as one phrase, or
        None (contact laws: the module's hooks).

    Notes
    -----
    Writing (``registry[name] = value``, the shipped registrations at import time) never loads the plugins;
    reading (``[]``, ``in``, iteration, ``len``, ``get``, ``values``) does, once.
    """

    def __init__(self, group: str, kind: type, order: Callable | None = None, check: Callable | None = None):
        self.group, self.kind, self._order, self._check = group, kind, order, check
        self._items: dict = {}
        self._loaded = False
        self._error: PluginError | None = None

    def __setitem__(self, name, value) -> None:
        self._items[name] = value
        if self._order is not None:
            self._items = dict(sorted(self._items.items(), key=lambda item: self._order(item[1])))

    def __getitem__(self, name):
        return self._plugged()[name]

    def __delitem__(self, name) -> None:
        del self._plugged()[name]

    def __iter__(self) -> Iterator:
        return iter(self._plugged())

    def __len__(self) -> int:
        return len(self._plugged())

    def __repr__(self) -> str:
        return f"Registry({self.group!r}, {list(self._items)})"

    def _plugged(self) -> dict:
        """The items, after adding the plugins of the group (once; a broken plugin raises on every read)."""
        if not self._loaded:
            self._loaded = True  # before loading: a plugin that reads the registry as it is imported sees the shipped
            try:
                for entry_point in entry_points(group=self.group):
                    self[entry_point.name] = self._load(entry_point)
            except PluginError as error:
                self._error = error
        if self._error is not None:
            raise self._error
        return self._items

    def _load(self, entry_point: EntryPoint):
        """The object an entry point names, checked to be of the registry's kind and name."""
        try:
            value = entry_point.load()
        except Exception as error:  # noqa: BLE001 - any failure of a third party's import is reported as its own
            raise PluginError(f"{_where(entry_point)}: cannot be loaded: {type(error).__name__}: {error}") from error
        if not isinstance(value, self.kind):
            raise PluginError(f"{_where(entry_point)}: names a {type(value).__name__}; the group "
                              f"{self.group} needs a {self.kind.__module__}.{self.kind.__name__}")
        own = getattr(value, "name", entry_point.name)
        if own != entry_point.name:
            raise PluginError(f"{_where(entry_point)}: the {self.kind.__name__} is named {own!r}; the entry point's "
                              "name must be the same")
        problem = self._check(entry_point.name, value) if self._check is not None else None
        if problem:
            raise PluginError(f"{_where(entry_point)}: {problem}")
        return value


def installed_plugins() -> dict[str, list[str]]:
    """The entry points installed in each group of ``GROUPS``, as 'name = module:object (package)' lines."""
    listed = {}
    for key, group in GROUPS.items():
        listed[key] = [f"{ep.name} = {ep.value}" + (f" ({ep.dist.metadata['Name']})" if ep.dist else "")
                       for ep in entry_points(group=group)]
    return listed
