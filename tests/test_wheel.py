"""The package as a user installs it: a wheel built from the checkout, installed into a fresh environment, runs
from an empty folder with the shipped records it carries (issue 33).

The wheel is built from a copy of the files the build reads (pyproject.toml, README.md, pipeline/, records/), so
the checkout gets no build/ folder. Its dependencies install from uv's cache, pinned to the versions of the test
environment (uv pip freeze): uv links them in about 2 s, and the test resolves the wheel's own dependency list.
Under ``make test`` (about 20 s, most of it the new environment's first imports): ``import rockfrag``,
``rockfrag records`` on a shipped record and ``rockfrag study`` on the example study copied into the empty
folder. The example's whole ``rockfrag fragility`` from the wheel compiles the numba kernels afresh (1-1.5 min
on 2 cores): it runs where ``ROCKFRAG_WHEEL_PIPELINE=1``, which ``.ci/run`` sets for its second step.
"""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
UV = Path(sys.executable).parent / "uv"
BUILD_INPUTS = ("pyproject.toml", "README.md", "pipeline", "records")
"""What the build reads from the checkout."""

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group(name="wheel")]


def _run(command, cwd, env=None, timeout=600) -> subprocess.CompletedProcess:
    result = subprocess.run([str(part) for part in command], cwd=cwd, env=env, capture_output=True, text=True,
                            timeout=timeout)
    assert result.returncode == 0, f"{' '.join(map(str, command))} -> {result.returncode}\n{result.stdout}\n" \
                                   f"{result.stderr}"
    return result


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(the wheel, the fresh environment's bin folder, an environment for its commands)."""
    if not UV.is_file():
        pytest.skip(f"uv is not in {UV.parent} (make install puts it there)")
    work = tmp_path_factory.mktemp("wheel")
    source = work / "source"
    for name in BUILD_INPUTS:
        origin = ROOT / name
        if origin.is_dir():
            shutil.copytree(origin, source / name, ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
        else:
            source.mkdir(exist_ok=True)
            shutil.copy(origin, source / name)
    _run([UV, "build", "--quiet", "--wheel", "--out-dir", work / "dist", source], cwd=work)
    wheel = next((work / "dist").glob("rockfrag-*.whl"))
    frozen = _run([UV, "pip", "freeze", "--python", sys.executable], cwd=work).stdout.splitlines()
    pins = [line for line in frozen if line and not line.startswith(("-e", "rockfrag")) and " @ " not in line]
    (work / "pins.txt").write_text("\n".join(pins) + "\n")
    _run([UV, "venv", "--quiet", "--python", sys.executable, work / "venv"], cwd=work)
    _run([UV, "pip", "install", "--quiet", "--python", work / "venv" / "bin" / "python", "--constraint",
          work / "pins.txt", wheel], cwd=work)
    env = {key: value for key, value in os.environ.items()
           if key not in ("ROCKFRAG_RECORDS", "PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    env["PATH"] = f"{work / 'venv' / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    return wheel, work / "venv" / "bin", env


@pytest.fixture
def empty_folder(tmp_path):
    folder = tmp_path / "empty"
    folder.mkdir()
    return folder


def test_the_wheel_carries_every_catalogued_record_as_package_data(installed):
    wheel = installed[0]
    names = set(zipfile.ZipFile(wheel).namelist())
    with open(ROOT / "records" / "MANIFEST.csv", newline="", encoding="utf-8") as handle:
        listed = {f"rockfrag/shipped_records/{row['file']}" for row in csv.DictReader(handle)}
    assert len(listed) > 100 and not listed - names, sorted(listed - names)[:5]
    assert {"rockfrag/shipped_records/MANIFEST.csv", "rockfrag/shipped_records/P695-SITES.csv"} <= names
    sources = {f"rockfrag/{path.relative_to(ROOT / 'pipeline').as_posix()}" for path in (ROOT / "pipeline").rglob("*")
               if path.is_file() and "__pycache__" not in path.parts and path.suffix not in (".nbi", ".nbc")}
    assert not sources - names, f"files of pipeline/ missing from the wheel (package-data): {sorted(sources - names)}"
    assert not [name for name in names if name.startswith(("pipeline/", "records/", "tests/"))]


def test_the_installed_package_runs_from_an_empty_folder(installed, empty_folder):
    _, bin_folder, env = installed
    found = _run([bin_folder / "python", "-c", "import rockfrag, rockfrag.records as r; "
                  "print(rockfrag.__file__); print(r.RECORDS_DIR)"], cwd=empty_folder, env=env).stdout.split()
    package = Path(found[0]).parent
    assert package.parent.name == "site-packages" and bin_folder.parent in package.parents
    assert Path(found[1]) == package / "shipped_records"

    listed = _run([bin_folder / "rockfrag", "records", "--set", "DUZCE/BOL090", "--no-progress"], cwd=empty_folder,
                  env=env)
    assert "DUZCE/BOL090" in listed.stdout
    with open(empty_folder / "reports" / "records.csv", newline="", encoding="utf-8") as handle:
        assert [row["id"] for row in csv.DictReader(handle)] == ["DUZCE/BOL090"]

    shutil.copy(ROOT / "studies" / "example.toml", empty_folder)
    checked = _run([bin_folder / "rockfrag", "study", "example.toml"], cwd=empty_folder, env=env)
    assert "is valid" in checked.stdout and "output reports-example" in checked.stdout


@pytest.mark.skipif(os.environ.get("ROCKFRAG_WHEEL_PIPELINE") != "1",
                    reason="the example study's whole run from a fresh wheel compiles the kernels (1-1.5 min): "
                           "ROCKFRAG_WHEEL_PIPELINE=1 runs it (.ci/run does)")
def test_the_example_study_runs_whole_from_the_wheel(installed, empty_folder):
    _, bin_folder, env = installed
    shutil.copy(ROOT / "studies" / "example.toml", empty_folder)
    done = _run([bin_folder / "rockfrag", "fragility", "example.toml", "--no-progress"], cwd=empty_folder, env=env,
                timeout=1200)
    output = empty_folder / "reports-example"
    for name in ("cube.nc", "fragility.csv", "report.pdf", "report.html"):
        assert (output / name).is_file(), name
    assert "Overturning, model recommended (10 records)" in done.stdout
