"""The tutorials teach the public API: ``import rockfrag`` and the names of its ``__all__``, nothing internal.

Issue 35: "document ``import rockfrag`` and its public API, not pipeline". A tutorial that imports
``rockfrag.study`` or calls ``rockfrag.cli.main`` teaches a module that may change between versions; this test
reads every tutorial's syntax tree (cheap: nothing runs) and names each such use.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import rockfrag

TUTORIALS = sorted((Path(__file__).resolve().parents[1] / "docs" / "examples").glob("*.py"))


def internal_uses(source: str) -> list[str]:
    """Each import of a rockfrag submodule and each ``rockfrag.<name>`` outside ``rockfrag.__all__``, with its line."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "rockfrag":
            if node.module != "rockfrag" or any(alias.name not in rockfrag.__all__ for alias in node.names):
                found.append(f"line {node.lineno}: from {node.module} import ...")
        elif isinstance(node, ast.Import):
            found += [f"line {node.lineno}: import {alias.name}" for alias in node.names
                      if alias.name.startswith("rockfrag.")]
        elif isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "rockfrag" \
                and node.attr not in rockfrag.__all__:
            found.append(f"line {node.lineno}: rockfrag.{node.attr}")
    return found


@pytest.mark.parametrize("tutorial", TUTORIALS, ids=lambda path: path.stem)
def test_tutorial_uses_the_public_api_alone(tutorial):
    assert not internal_uses(tutorial.read_text(encoding="utf-8")), \
        f"{tutorial.name} uses what is not rockfrag's public API: {internal_uses(tutorial.read_text())}"


def test_the_check_finds_each_kind_of_internal_use():
    source = ("import rockfrag\nimport rockfrag.cli\nfrom rockfrag.study import run_study\n"
              "from rockfrag import simulate, study_records\nrockfrag.cli.main([])\nrockfrag.simulate\n")
    assert internal_uses(source) == ["line 2: import rockfrag.cli", "line 3: from rockfrag.study import ...",
                                     "line 4: from rockfrag import ...", "line 5: rockfrag.cli"]
    assert TUTORIALS, "no tutorial found"
