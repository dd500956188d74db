"""Report: the whole pipeline on a small study produces the PDF and every PNG, none empty."""

from __future__ import annotations

import re

import matplotlib.pyplot as plt
import pytest

from pipeline.cli import main

from .test_study import SMALL


@pytest.fixture(scope="module")
def pipeline_output(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pipeline")
    study = folder / "study.toml"
    study.write_text(SMALL + "\n[fragility]\nbootstrap = 5\n")
    status = main(["fragility", str(study), "--output", str(folder / "reports"), "--no-progress", "--serial"])
    assert status == 0
    return folder / "reports", study


def expected_figures(n_blocks, n_ssi_models=1):
    # summary, records table, spectra, Bolu processing, Bolu comparison, IDA per block,
    # per block: fragility by soil (per SSI model) + by model + outcomes, applicability
    return 5 + n_blocks + n_blocks * (n_ssi_models + 2) + 1 + 1  # + the applicability sweep


@pytest.mark.slow
def test_every_output_file_is_written(pipeline_output):
    output, _ = pipeline_output
    for name in ("cube.nc", "ida.nc", "fragility.nc", "fragility.csv", "fragility_pelicun.csv", "report.pdf",
                 "applicability.nc", "applicability-sweep.png"):
        assert (output / name).stat().st_size > 0, name
    pngs = sorted((output / "figures").glob("*.png"))
    assert len(pngs) == expected_figures(3)
    pdf = (output / "report.pdf").read_bytes()
    pages = len(re.findall(rb"/Type\s*/Page[^s]", pdf))
    assert pages == len(pngs)
    assert not list(output.glob(".*.part"))


@pytest.mark.slow
def test_no_figure_is_empty(pipeline_output):
    import xarray as xr

    from pipeline.config import load_study
    from pipeline.report import build_figures
    from pipeline.soils import soil_block_stiffness

    output, study = pipeline_output
    config = load_study(study)
    cube = xr.open_dataset(output / "cube.nc")
    ida = xr.open_dataset(output / "ida.nc")
    fragility = xr.open_dataset(output / "fragility.nc")
    from pipeline.records import load_records
    from pipeline.processing import process_record
    from pipeline.measures import intensity_measures

    raw, _ = load_records("bolu")
    records = [process_record(r) for r in raw]
    measures = [intensity_measures(r.acceleration, r.dt, sa_periods=(1.0,)) for r in records]
    figures = build_figures(config, cube, ida, fragility, fragility, records, measures, raw[1], records[1], 1.0,
                            soil_block_stiffness)
    for item in figures:
        axes = item.figure.get_axes()
        drawn = sum(len(a.lines) + len(a.collections) + len(a.tables) + len(a.patches) for a in axes)
        assert drawn > 0, item.name
        assert item.figure._suptitle is not None or any(a.get_title() for a in axes), item.name
        plotted = [a for a in axes if a.lines or a.collections]
        if plotted:  # shared axes label only the outer panels: at least one label of each kind
            assert any(a.get_xlabel() for a in plotted) and any(a.get_ylabel() for a in plotted), item.name
            assert all("[" in a.get_xlabel() for a in plotted if a.get_xlabel()), item.name  # units
        plt.close(item.figure)


def test_pdf_is_deterministic(tmp_path):
    from pipeline.report import Figure, write_report

    def one():
        figure, axis = plt.subplots()
        axis.plot([0, 1], [0, 1])
        return [Figure("line", figure, "a line")]

    first, _ = write_report(one(), tmp_path / "a")
    second, _ = write_report(one(), tmp_path / "b")
    assert first.read_bytes() == second.read_bytes()


def test_record_table_is_paginated(all_records):
    from pipeline.report import ROWS_PER_TABLE_PAGE, records_tables

    measures = [{"pga_m_s2": 1.0, "pgv_m_s": 1.0, "arias_m_s": 1.0, "d5_95_s": 1.0, "sa_1s_m_s2": 1.0}] * len(all_records)
    pages = records_tables(all_records, measures)
    assert len(pages) == -(-len(all_records) // ROWS_PER_TABLE_PAGE)
    rows = [len(page.figure.axes[0].tables[0].get_celld()) // 8 - 1 for page in pages]  # minus the header
    assert sum(rows) == len(all_records)
    for page in pages:
        plt.close(page.figure)
