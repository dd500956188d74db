"""The package's import graph: no circles, and no module imports from a layer above its own.

Every ``import`` and ``from ... import`` of every module under ``pipeline/`` counts, those inside
functions and ``if TYPE_CHECKING:`` blocks included: a lazy import hides a circle from Python, not
from a reader. ``from rockfrag.a import b`` is an edge to ``rockfrag.a.b`` when that is a module, else
to ``rockfrag.a``; importing ``rockfrag.a.b`` from outside the package ``rockfrag.a`` also runs
``pipeline/a/__init__.py``, so it is an edge to ``rockfrag.a`` too (a package's own modules importing
each other do not count their shared ``__init__``).
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "pipeline"

LAYERS: list[tuple[str, ...]] = [
    # 0 foundations: the version, exceptions, SI constants, atomic writes, fit numerics on arrays
    ("rockfrag.version", "rockfrag.errors", "rockfrag.units", "rockfrag.outputs", "rockfrag.lognormal_fit"),
    # 1 plumbing shared by stages: value checks, file locks, checkpoints, worker pools, the registries (plugins)
    ("rockfrag.validation", "rockfrag.locking", "rockfrag.checkpoints", "rockfrag.executors", "rockfrag.plugins"),
    # 2 inputs: record readers and signal processing
    ("rockfrag.records", "rockfrag.records.*", "rockfrag.processing"),
    # 3 facts every stage reads: measures, blocks, soils, damage states, hazard curves and each soil's site hazard
    ("rockfrag.measures", "rockfrag.blocks", "rockfrag.soils", "rockfrag.damage_states", "rockfrag.hazard",
     "rockfrag.site_amplification", "rockfrag.site_hazard",
     "rockfrag.plausibility"),  # plausibility: issue 21's checks of a study's blocks and soils
    # 4 the solvers
    ("rockfrag.models", "rockfrag.models.*"),
    # 5 the study definition
    ("rockfrag.config",),
    # 6 results of one kind: the cube, IDA, risk, calibration, the records table, the exchange files (8b)
    ("rockfrag.cube", "rockfrag.ida", "rockfrag.risk", "rockfrag.calibrate", "rockfrag.records_report",
     "rockfrag.exchange"),
    # 7 stages that combine them: the sweep, the fits (which add the risk), the measure ranking
    ("rockfrag.study", "rockfrag.steps", "rockfrag.fragility", "rockfrag.efficiency"),
    # 8 stages built on the sweep
    ("rockfrag.showcase", "rockfrag.applicability"),
    # 9 what the reader gets: the report and the terminal's answer table
    ("rockfrag.report", "rockfrag.report.*", "rockfrag.answer"),
    # 10 the command
    ("rockfrag.cli", "rockfrag.__main__"),
    # 11 the public API: the package root names the stages' functions (imported on first use), api its own
    ("rockfrag", "rockfrag.api"),
]
"""Layer order, bottom first: a module may import its own layer and those below it, never above."""

ALLOWED_EDGES: set[tuple[str, str]] = {
    # study.py takes the version from the package root (``from rockfrag import __version__``), which is now the
    # public API at the top; study.py is being rewritten on another branch (issue 33 left it alone): its import
    # becomes ``from rockfrag.version import __version__`` there, as in every other module, and this entry goes.
    ("rockfrag.study", "rockfrag"),
}
"""Known violations (importer, imported) left for the coordinator to remove after merging the issue 17
branches, or for another branch to remove; each entry says why."""


def module_name(path: Path) -> str:
    """The import name of a module file: the folder ``pipeline/`` is installed as the package ``rockfrag``."""
    parts = ("rockfrag", *path.relative_to(PACKAGE).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict[str, Path]:
    return {module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def imported(name: str, path: Path, node: ast.AST, known: dict[str, Path]) -> set[str]:
    """The pipeline modules one import statement names."""
    if isinstance(node, ast.Import):
        targets = [alias.name for alias in node.names]
    elif isinstance(node, ast.ImportFrom):
        if node.level:  # relative: from the importer's package up
            package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
            base = ".".join(package[:len(package) - node.level + 1] + ([node.module] if node.module else []))
        else:
            base = node.module or ""
        targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base for alias in node.names]
    else:
        return set()
    found = set()
    for target in targets:
        if not (target == "rockfrag" or target.startswith("rockfrag.")):
            continue
        while target not in known:  # an attribute of a module: the module
            target = target.rsplit(".", 1)[0]
        found.add(target)
        parts = target.split(".")
        for depth in range(2, len(parts)):  # packages whose __init__ the import runs
            package = ".".join(parts[:depth])
            if not (name == package or name.startswith(package + ".")):
                found.add(package)
    found.discard(name)
    return found


def imports_of(name: str, path: Path, source: str, known: dict[str, Path]) -> set[str]:
    """The pipeline modules a module's source imports anywhere (module level, functions, branches)."""
    tree = ast.parse(source, filename=str(path))
    return set().union(*(imported(name, path, node, known) for node in ast.walk(tree)))


@functools.cache
def import_graph() -> dict[str, set[str]]:
    """{module: the pipeline modules it imports}, parsed once per process (the tests below only read it)."""
    known = modules()
    return {name: imports_of(name, path, path.read_text(encoding="utf-8"), known) for name, path in known.items()}


def layer_of(name: str) -> int | None:
    for index, layer in enumerate(LAYERS):
        for pattern in layer:
            if name == pattern or (pattern.endswith(".*") and name.startswith(pattern[:-1])):
                return index
    return None


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` as [a, b, ..., a], or None (iterative depth-first search)."""
    state: dict[str, int] = {}  # 1 on the current path, 2 done
    for root in sorted(graph):
        if root in state:
            continue
        path, stack = [root], [iter(sorted(graph[root]))]
        state[root] = 1
        while stack:
            child = next(stack[-1], None)
            if child is None:
                state[path.pop()] = 2
                stack.pop()
            elif state.get(child) == 1:
                return path[path.index(child):] + [child]
            elif child not in state and child in graph:
                state[child] = 1
                path.append(child)
                stack.append(iter(sorted(graph[child])))
    return None


def test_the_graph_is_read_from_every_import_lazy_ones_included():
    known = modules()
    source = """
import numpy
from rockfrag.errors import ConfigError
from rockfrag import measures

if TYPE_CHECKING:
    from rockfrag.blocks import Block

def stage():
    import rockfrag.cube
    from rockfrag.models.base import Outcome
    from rockfrag.models import fields
"""
    found = imports_of("rockfrag.hazard", PACKAGE / "hazard.py", source, known)
    assert found == {"rockfrag.errors", "rockfrag.measures", "rockfrag.blocks", "rockfrag.cube", "rockfrag.models.base",
                     "rockfrag.models", "rockfrag.models.fields"}  # models/__init__ runs for models.base and .fields
    inside = imports_of("rockfrag.models.ssi", PACKAGE / "models" / "ssi.py", "from rockfrag.models.base import X",
                        known)
    assert inside == {"rockfrag.models.base"}  # within its package, a module does not count the package __init__
    graph = import_graph()
    assert "rockfrag.config" in graph and "rockfrag.models.kernels" in graph and "rockfrag.report.adapters" in graph
    assert "rockfrag.damage_states" in graph["rockfrag.config"]


def test_the_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set(), "c": {"a", "b"}}) is None


def test_there_are_no_import_cycles():
    graph = {name: {d for d in deps if (name, d) not in ALLOWED_EDGES} for name, deps in import_graph().items()}
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_every_module_has_a_layer():
    missing = sorted(name for name in modules() if layer_of(name) is None)
    assert not missing, f"modules in no layer: {missing}; add each to LAYERS in {Path(__file__).name}"


def test_no_module_imports_from_a_layer_above_its_own():
    upward = [f"{name} (layer {layer_of(name)}) imports {target} (layer {layer_of(target)})"
              for name, targets in sorted(import_graph().items()) for target in sorted(targets)
              if (name, target) not in ALLOWED_EDGES and layer_of(name) is not None
              and layer_of(target) is not None and layer_of(target) > layer_of(name)]
    assert not upward, "upward imports:\n" + "\n".join(upward)


def test_allowed_edges_are_still_needed():
    graph = import_graph()
    stale = sorted(edge for edge in ALLOWED_EDGES if edge[1] not in graph.get(edge[0], set()))
    assert not stale, f"allowed edges no longer in the code, remove them from ALLOWED_EDGES: {stale}"
