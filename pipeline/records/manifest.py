"""rockfrag.records.manifest - the record catalogue ``records/MANIFEST.csv``.

Input : ``records/MANIFEST.csv`` (one row per file: id, file, event, year, magnitude, station,
        component, sets, source, units, npts, dt_s, pga_g, sha256, ...).
Output: ``CatalogueEntry`` objects; ``verify`` reports any listed file that is missing or whose
        sha256 differs from the catalogue, by name.

Where the shipped records are (``shipped_records_dir``): the folder ``$ROCKFRAG_RECORDS`` names, else the
package data of an installed wheel (``rockfrag/shipped_records/``, the build maps the checkout's ``records/``
there), else ``records/`` at the top of a clone (an editable install runs the sources in ``pipeline/``).
"""

from __future__ import annotations

import csv
import hashlib
import io
import os
from dataclasses import dataclass, field
from pathlib import Path

from rockfrag.errors import ManifestError

RECORDS_ENVIRONMENT = "ROCKFRAG_RECORDS"
"""The environment variable that names another folder of records (with its ``MANIFEST.csv``)."""


def shipped_records_dir() -> Path:
    """The folder of the shipped records and their ``MANIFEST.csv``.

    Returns
    -------
    Path
        ``$ROCKFRAG_RECORDS`` if set; else ``shipped_records/`` inside the installed package (a wheel); else
        ``records/`` beside the source folder ``pipeline/`` (a clone, or an editable install of it). A folder
        that does not exist is returned as it is: the catalogue's reader names it when it finds no catalogue.
    """
    override = os.environ.get(RECORDS_ENVIRONMENT)
    if override:
        return Path(override)
    package = Path(__file__).resolve().parents[1]
    installed = package / "shipped_records"
    return installed if installed.is_dir() else package.parent / "records"


REQUIRED_COLUMNS = ("id", "file", "event", "year", "magnitude", "station", "component", "sets",
                    "source", "units", "sha256")


@dataclass(frozen=True)
class CatalogueEntry:
    """One record file of the catalogue (metadata as published; acceleration units of the file)."""

    id: str
    path: Path
    event: str
    year: int | None
    magnitude: float | None
    station: str
    component: str
    sets: tuple[str, ...]
    source: str
    units: str
    sha256: str
    extra: dict = field(default_factory=dict, compare=False, repr=False)

    def metadata(self) -> dict:
        """Flat metadata for tables and netCDF attributes."""
        return {"id": self.id, "file": str(self.path), "event": self.event, "year": self.year,
                "magnitude": self.magnitude, "station": self.station, "component": self.component,
                "sets": ";".join(self.sets), "source": self.source, "units": self.units,
                "sha256": self.sha256}


def _number(text, kind):
    text = (text or "").strip()
    return kind(text) if text else None


_PARSED: dict[tuple[str, bytes], tuple[CatalogueEntry, ...]] = {}
"""Catalogues parsed in this process, by path and content: a command reads the catalogue two or three times
(record sets, ids, entries), and the tests run commands by the thousand in one process. Reading the file is
cheap; parsing its rows is what this saves."""


def load_catalogue(manifest_path) -> list[CatalogueEntry]:
    """Parse the catalogue; paths are resolved relative to the manifest's folder.

    A file whose path and bytes were parsed before in this process is not parsed again.
    """
    manifest_path = Path(manifest_path)
    if not manifest_path.is_file():
        raise ManifestError(f"{manifest_path}: record catalogue not found; set ${RECORDS_ENVIRONMENT} to the "
                            "folder holding MANIFEST.csv and its record files")
    key = (str(manifest_path), manifest_path.read_bytes())
    if key not in _PARSED:
        _PARSED[key] = tuple(_parse_catalogue(manifest_path, key[1].decode("utf-8")))
    return list(_PARSED[key])


def _parse_catalogue(manifest_path: Path, text: str) -> list[CatalogueEntry]:
    reader = csv.DictReader(io.StringIO(text, newline=""))
    missing = [c for c in REQUIRED_COLUMNS if c not in (reader.fieldnames or [])]
    if missing:
        raise ManifestError(f"{manifest_path}: missing column(s) {', '.join(missing)}; "
                            f"expected {', '.join(REQUIRED_COLUMNS)}")
    return [CatalogueEntry(id=row["id"], path=manifest_path.parent / row["file"], event=row["event"],
                           year=_number(row["year"], int), magnitude=_number(row["magnitude"], float),
                           station=row["station"], component=row["component"],
                           sets=tuple(s for s in row["sets"].split(";") if s), source=row["source"],
                           units=row["units"], sha256=row["sha256"],
                           extra={k: v for k, v in row.items() if k not in REQUIRED_COLUMNS})
            for row in reader]


def sha256_of(path) -> str:
    """The sha256 of a file's bytes, as hex (read in 1 MiB blocks)."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def verify(entries) -> list[str]:
    """Problems found, one line per file: missing files and sha256 mismatches (empty if none)."""
    problems = []
    for entry in entries:
        if not entry.path.is_file():
            problems.append(f"{entry.path}: listed in the catalogue as {entry.id} but missing")
        elif sha256_of(entry.path) != entry.sha256:
            problems.append(f"{entry.path}: changed since it was catalogued (sha256 differs from "
                            f"MANIFEST.csv); restore the original or update the catalogue")
    return problems
