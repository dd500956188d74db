"""Shared fixtures: paths to shipped records, loaded records, one small pipeline run, a headless matplotlib.
Collection hooks: tests of the small pipeline run share one xdist worker; under xdist the slow tests start first."""

from __future__ import annotations

import warnings
from pathlib import Path

import matplotlib
import pytest

from tests.helpers import PIPELINE_GROUP, PIPELINE_STUDY, PipelineRun

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parents[1]
RECORDS = ROOT / "records"


@pytest.hookimpl(tryfirst=True)  # before xdist's own hook, which reads the xdist_group marks
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Put every test that uses ``small_pipeline`` in one xdist group, so that one worker runs the pipeline
    (``--dist loadgroup``; a test that forgets the mark cannot make the other worker run it again), and the tests
    of a module that share a module-scoped fixture in a group of their own (one worker computes it). Under xdist,
    move the ``slow`` tests to the front (stable), so that the longest ones do not start last and leave one
    worker idle at the end; without xdist the order stays as collected (module fixtures are set up once)."""
    for item in items:
        if item.get_closest_marker("xdist_group"):
            continue
        if "small_pipeline" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.xdist_group(PIPELINE_GROUP))
        elif _uses_a_module_fixture(item):  # else each worker that runs one of them computes the fixture again
            item.add_marker(pytest.mark.xdist_group(f"module-fixture:{item.module.__name__}"))
    if hasattr(config, "workerinput"):  # an xdist worker (each collects the same list, sorted the same way)
        items.sort(key=lambda item: item.get_closest_marker("slow") is None)


def _uses_a_module_fixture(item: pytest.Item) -> bool:
    """Whether the test uses a module- or class-scoped fixture (computed once per worker that runs its tests)."""
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return False
    return any(definition.scope in ("module", "class") for definitions in info.name2fixturedefs.values()
               for definition in definitions)


@pytest.fixture(scope="session")
def records_dir() -> Path:
    return RECORDS


@pytest.fixture(scope="session")
def bolu_path() -> Path:
    """The FEMA P695 export of Duzce 1999, Bolu 090 (PGA 0.8224 g)."""
    return RECORDS / "fema_p695" / "farfield" / "DUZCE" / "BOL090.AT2"


@pytest.fixture(scope="session")
def all_records():
    from rockfrag.records import load_records

    records, failures = load_records("all")
    assert not failures, failures
    return records


@pytest.fixture(scope="session")
def bolu_records():
    from rockfrag.records import load_records

    records, failures = load_records("bolu")
    assert not failures
    return {record.id: record for record in records}


@pytest.fixture(scope="session")
def small_pipeline(tmp_path_factory: pytest.TempPathFactory) -> PipelineRun:
    """``rockfrag fragility`` on the small study (tests/helpers.py PIPELINE_STUDY), run once per session: the
    report, outputs-table and README tests read its folder. Read only: copy the folder before changing it."""
    from rockfrag.cli import main

    folder = tmp_path_factory.mktemp("pipeline")
    study = folder / "study.toml"
    study.write_text(PIPELINE_STUDY)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        # --applicability: a study file's run skips the sweep by default; the report and outputs tests read it
        status = main(["fragility", str(study), "--output", str(folder / "reports"), "--no-progress", "--serial",
                       "--applicability"])
    assert status == 0
    return PipelineRun(folder / "reports", study, caught)
