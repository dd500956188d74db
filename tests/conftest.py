"""Shared fixtures: paths to shipped records, loaded records, a headless matplotlib."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parents[1]
RECORDS = ROOT / "records"


@pytest.fixture(scope="session")
def records_dir() -> Path:
    return RECORDS


@pytest.fixture(scope="session")
def bolu_path() -> Path:
    """The FEMA P695 export of Duzce 1999, Bolu 090 (PGA 0.8224 g)."""
    return RECORDS / "fema_p695" / "farfield" / "DUZCE" / "BOL090.AT2"


@pytest.fixture(scope="session")
def all_records():
    from pipeline.records import load_records

    records, failures = load_records("all")
    assert not failures, failures
    return records


@pytest.fixture(scope="session")
def bolu_records():
    from pipeline.records import load_records

    records, failures = load_records("bolu")
    assert not failures
    return {record.id: record for record in records}
