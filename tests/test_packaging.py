"""The build installs the folder ``pipeline/`` as the import package ``rockfrag``, with every sub-package."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_subpackage_of_the_source_folder_is_installed():
    setuptools = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    source = ROOT / setuptools["package-dir"]["rockfrag"]
    folders = {init.parent.relative_to(source) for init in source.rglob("__init__.py")}
    expected = {".".join(("rockfrag", *folder.parts)) for folder in folders}
    missing = expected - set(setuptools["packages"])
    assert not missing, f"add to [tool.setuptools] packages: {sorted(missing)}"


def test_the_package_imports_as_rockfrag_from_the_source_folder():
    import rockfrag

    assert Path(rockfrag.__file__).resolve().parent == ROOT / "pipeline"
