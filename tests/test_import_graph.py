"""The package's import graph: no circles, and no module imports from a layer above its own.

Every ``import`` and ``from ... import`` of every module under ``pipeline/`` counts, those inside
functions and ``if TYPE_CHECKING:`` blocks included: a lazy import hides a circle from Python, not
from a reader. ``from pipeline.a import b`` is an edge to ``pipeline.a.b`` when that is a module, else
to ``pipeline.a``; importing ``pipeline.a.b`` from outside the package ``pipeline.a`` also runs
``pipeline/a/__init__.py``, so it is an edge to ``pipeline.a`` too (a package's own modules importing
each other do not count their shared ``__init__``).
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "pipeline"

LAYERS: list[tuple[str, ...]] = [
    # 0 foundations: the version, exceptions, SI constants, atomic writes, fit numerics on arrays
    ("pipeline", "pipeline.errors", "pipeline.units", "pipeline.outputs", "pipeline.lognormal_fit"),
    # 1 plumbing shared by stages: value checks, file locks, checkpoints, worker pools
    ("pipeline.validation", "pipeline.locking", "pipeline.checkpoints", "pipeline.executors"),
    # 2 inputs: record readers and signal processing
    ("pipeline.records", "pipeline.records.*", "pipeline.processing"),
    # 3 facts every stage reads: measures, blocks, soils, damage states, hazard curves
    ("pipeline.measures", "pipeline.blocks", "pipeline.soils", "pipeline.damage_states", "pipeline.hazard",
     "pipeline.plausibility"),  # plausibility: issue 21's checks of a study's blocks and soils
    # 4 the solvers
    ("pipeline.models", "pipeline.models.*"),
    # 5 the study definition
    ("pipeline.config",),
    # 6 results of one kind: the cube, IDA, risk, calibration, the records table, the exchange files (8b)
    ("pipeline.cube", "pipeline.ida", "pipeline.risk", "pipeline.calibrate", "pipeline.records_report",
     "pipeline.exchange"),
    # 7 stages that combine them: the sweep, the fits (which add the risk), the measure ranking
    ("pipeline.study", "pipeline.fragility", "pipeline.efficiency"),
    # 8 stages built on the sweep
    ("pipeline.showcase", "pipeline.applicability"),
    # 9 what the reader gets: the report and the terminal's answer table
    ("pipeline.report", "pipeline.report.*", "pipeline.answer"),
    # 10 the command
    ("pipeline.cli", "pipeline.__main__"),
]
"""Layer order, bottom first: a module may import its own layer and those below it, never above."""

ALLOWED_EDGES: set[tuple[str, str]] = set()
"""Known violations (importer, imported) left for the coordinator to remove after merging the issue 17
branches; each entry says why. Empty: the graph is clean."""


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
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
        if not (target == "pipeline" or target.startswith("pipeline.")):
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
from pipeline.errors import ConfigError
from pipeline import measures

if TYPE_CHECKING:
    from pipeline.blocks import Block

def stage():
    import pipeline.cube
    from pipeline.models.base import Outcome
    from pipeline.models import fields
"""
    found = imports_of("pipeline.hazard", PACKAGE / "hazard.py", source, known)
    assert found == {"pipeline.errors", "pipeline.measures", "pipeline.blocks", "pipeline.cube", "pipeline.models.base",
                     "pipeline.models", "pipeline.models.fields"}  # models/__init__ runs for models.base and .fields
    inside = imports_of("pipeline.models.ssi", PACKAGE / "models" / "ssi.py", "from pipeline.models.base import X",
                        known)
    assert inside == {"pipeline.models.base"}  # within its package, a module does not count the package __init__
    graph = import_graph()
    assert "pipeline.config" in graph and "pipeline.models.kernels" in graph and "pipeline.report.adapters" in graph
    assert "pipeline.damage_states" in graph["pipeline.config"]


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
