"""Report: one numbered A4 document with its HTML twin, written only from result files; the pages show
only what the study ran; the limitations come from the run. The pipeline runs once per session (fixture
``small_pipeline`` in conftest.py); the README's outputs table is checked against it in test_readme.py."""

from __future__ import annotations

import re

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
import xarray as xr

from rockfrag.report.adapters import differs_by_soil

A4_LANDSCAPE_POINTS = (842, 595)  # 297 x 210 mm


def _datasets(output):
    opened = {}
    for name in ("cube", "ida", "fragility", "showcase"):
        with xr.open_dataset(output / f"{name}.nc") as dataset:
            opened[name] = dataset.load()
    return opened


@pytest.mark.slow
@pytest.mark.slow
def test_every_netcdf_file_of_the_run_is_compressed(small_pipeline):
    output, _, _ = small_pipeline
    written = sorted(path.name for path in output.glob("*.nc"))
    assert {"cube.nc", "ida.nc", "fragility.nc", "showcase.nc", "applicability.nc", "efficiency.nc"} <= set(written)
    for name in written:
        with xr.open_dataset(output / name) as dataset:
            plain = [str(key) for key, variable in dataset.data_vars.items()
                     if variable.ndim and variable.dtype.kind in "biuf" and not variable.encoding.get("zlib")]
        assert plain == [], f"{name}: numeric variables written without zlib: {plain}"


def test_one_numbered_a4_document_with_an_html_twin(small_pipeline):
    output, _, _ = small_pipeline
    pdf = (output / "report.pdf").read_bytes()
    pages = len(re.findall(rb"/Type\s*/Page[^s]", pdf))
    boxes = {tuple(round(float(v)) for v in box.split()[2:])
             for box in re.findall(rb"/MediaBox\s*\[\s*([\d.\s]+)\]", pdf)}
    assert boxes == {A4_LANDSCAPE_POINTS}, boxes
    pngs = sorted((output / "figures").glob("*.png"))
    html = (output / "report.html").read_text()
    images = re.findall(r"<img alt=", html)
    assert len(pngs) == len(images) >= 10 and pages > len(pngs)  # a PNG per figure page; text pages are HTML text
    assert sorted(int(png.name[:2]) for png in pngs) == [int(png.name[:2]) for png in pngs]  # NN: the page number
    sections = re.findall(r"<section id='page-(\d+)'>", html)
    assert [int(n) for n in sections] == list(range(1, pages + 1))
    assert f"of {pages}</span>" not in html and not re.search(r"\(\d+/\d+\)</h2>", html)  # no PDF pagination
    for target in re.findall(r"href='#page-(\d+)'", html):  # the contents links every page it lists
        assert 1 <= int(target) <= pages
    headed = set(re.findall(r"<section id='page-(\d+)'>\s*<h2>", html))  # a text section over pages: one heading
    assert set(re.findall(r"href='#page-(\d+)'", html)) == headed  # each heading; the contents by the back links
    text_pages = (r"\d+-(title|answer|contents|summary|fitted|methods|limitations|records-table|glossary|references"
                  r"|reproduce)")
    assert not [png.name for png in pngs if re.match(text_pages, png.name)]  # text pages have no PNG
    assert html.count("data:image/png;base64,") == len(pngs)  # figure pages embedded, text pages as HTML
    assert "src='http" not in html and "href='http" not in html  # self-contained


@pytest.mark.slow
def test_title_project_author_and_sections_from_the_study(small_pipeline):
    output, _, _ = small_pipeline
    html = (output / "report.html").read_text()
    for text in ("Rocking fragility of the yard equipment", "Harbour crane upgrade", "A. Engineer"):
        assert text in html
    # a section that starts part-way down a shared page is headed there (h3), not in the page title (h2)
    order = [min(found.start() if (found := re.search(f"<h{level}[^>]*>{title}", html)) else len(html) + 1
                 for level in (2, 3))
             for title in ("Summary", "Contents", "Reading the answer pages", "Fitted fragility functions", "Methods",
                           "Limitations", "IDA curves")]
    assert order == sorted(order)
    assert "θmax/α ≥ 0.5" in html  # damage states by their registry description, not ids
    assert "rocking-0.5:" not in html.split("Methods")[0]


@pytest.mark.slow
def test_no_figure_warning_and_no_open_figures(small_pipeline):
    _, _, caught = small_pipeline
    assert not [w for w in caught if "More than 20 figures" in str(w.message)]
    assert plt.get_fignums() == []


def _results(output, study, **changes):
    from rockfrag.config import load_study
    from rockfrag.report import Results

    opened = _datasets(output)
    values = dict(config=load_study(study), cube=opened["cube"], ida=opened["ida"], fragility=opened["fragility"],
                  output=output, showcase=opened["showcase"])
    values.update(changes)
    return Results(**values)


@pytest.mark.slow
def test_pages_cover_only_the_study(small_pipeline):
    from rockfrag.report import plan

    output, study, _ = small_pipeline
    results = _results(output, study)
    names = [page.name for page in plan(results)]
    blocks = list(results.cube.block.values)
    assert sorted(n[4:] for n in names if n.startswith("ida-")) == sorted(blocks)
    assert "showcase-response" in names  # the study has Bolu
    without = [page.section for page in plan(_results(output, study, showcase=results.showcase.drop_vars(
        [v for v in results.showcase.variables if "record" not in results.showcase[v].dims and v != "period"])))]
    assert "Showcase record" not in without
    # one 'fragility by soil' page per foundation model, none for the rigid base
    assert not [n for n in names if n.startswith("fragility-soils-") and n.endswith("-housner")]


@pytest.mark.slow
def test_figure_pages_rigid_base_once_legend_outside_shared_scales(small_pipeline):
    from rockfrag.report import figures
    from rockfrag.report.adapters import models_of
    from rockfrag.report.layout import PAGE_SIZE

    output, study, _ = small_pipeline
    results = _results(output, study)
    block = str(results.cube.block.values[0])
    page = figures.ida_page(results.ida, block, "")
    titles = [a.get_title() for a in page.axes if a.get_visible()]
    rigid = [m for m in models_of(results.cube) if m.rigid_base]
    founded = [m for m in models_of(results.cube) if not m.rigid_base]
    # a rigid base once, unless base friction makes its runs differ by soil (then a panel per soil)
    edp = results.ida.edp.sel(block=block)
    sliding = [m for m in rigid if not all(np.array_equal(edp.sel(model=m.name).isel(soil=0).values,
                                                          edp.sel(model=m.name).isel(soil=i).values, equal_nan=True)
                                           for i in range(1, results.cube.sizes["soil"]))]
    soils = results.cube.sizes["soil"]
    assert len(titles) == len(rigid) - len(sliding) + (len(founded) + len(sliding)) * soils
    assert sum("housner" in t.lower() for t in titles) == (0 if sliding else 1)  # else a row headed by it
    headings = [t.get_text() for t in page.texts]
    assert all(any(m.label.split(" (")[0] in h for h in headings) for m in sliding)
    assert tuple(page.get_size_inches()) == PAGE_SIZE
    _assert_legend_outside(page)
    plt.close(page)

    page = figures.showcase_response_page(results.showcase, "")
    theta_axes = [a for a in page.axes if a.get_ylabel().startswith("θ [")]
    assert len(theta_axes) == results.cube.sizes["soil"]
    assert len({a.get_ylim() for a in theta_axes}) == 1  # one scale for the compared panels
    start, end = theta_axes[0].get_xlim()
    attrs = results.showcase.attrs
    window = (float(attrs["strong_motion_start_s"]), float(attrs["strong_motion_end_s"]))
    assert window[0] - 5 <= start <= window[0] and window[1] <= end <= window[1] + 10
    assert end - start < float(results.showcase.time.values[-1])  # cropped, not the whole record
    _assert_legend_outside(page)
    lines = [line for a in theta_axes for line in a.lines]
    styles = {(line.get_color(), str(line.get_linestyle())) for line in lines}
    assert len(styles) == results.cube.sizes["model"]  # models in distinct colours and line styles
    plt.close(page)

    page = figures.fragility_by_soil_page(results.fragility, block, founded[0], "")
    _assert_legend_outside(page)
    labels = [t.get_text() for legend in page.legends for t in legend.get_texts()]
    # the rigid base listed once, or per soil where base friction makes its curves differ (adapters.soils_of)
    housner = results.fragility["median"].sel(model="housner", block=block)
    expected = results.cube.sizes["soil"] if differs_by_soil(housner) else 1
    assert sum("housner" in label.lower() for label in labels) == expected
    plt.close(page)


def _assert_legend_outside(figure):
    figure.canvas.draw()
    right = max(a.get_window_extent().x1 for a in figure.axes if a.get_visible())
    assert figure.legends, "no legend"
    for legend in figure.legends:
        assert legend.get_window_extent().x0 >= right


def _fake_cube(tension, friction=None):
    """A cube of 10 records x 2 levels x 2 soils x 1 block x 2 models with given tension flags."""
    shape = (10, 2, 2, 1, 2)
    coords = {"record": [f"r{i}" for i in range(10)], "im_level": [0.1, 0.2], "soil": ["clay", "rock"],
              "block": ["b"], "model": ["housner", "ssi"]}
    data = {"outcome": (list(coords), np.ones(shape, dtype=np.int8)),
            "support_tension": (list(coords), tension)}
    if friction is not None:
        data["peak_friction_demand"] = (list(coords), friction)
    return xr.Dataset(data, coords=coords)


def test_limitations_state_the_tension_fraction_per_soil_and_block():
    from rockfrag.report.adapters import model_info, run_fraction, tension_flag

    tension = np.full((10, 2, 2, 1, 2), np.nan)
    tension[..., 1] = 0.0
    tension[:3, :, 0, 0, 1] = 1.0  # 3 of 10 records pulled on clay at both levels
    tension[:1, 0, 1, 0, 1] = 1.0  # 1 of 20 runs on rock
    cube = _fake_cube(tension)
    fraction = run_fraction(cube, tension_flag(cube), model_info("ssi"))
    assert float(fraction.sel(soil="clay", block="b")) == pytest.approx(0.3)
    assert float(fraction.sel(soil="rock", block="b")) == pytest.approx(0.05)
    assert run_fraction(cube, tension_flag(cube), model_info("housner")) is None  # not computed: NaN


def test_tension_flag_not_applicable_is_not_counted():
    from rockfrag.report.adapters import model_info, run_fraction, tension_flag

    flags = np.full((10, 2, 2, 1, 2), -1, dtype=np.int8)  # -1: the model cannot pull (tensionless, rigid)
    flags[..., 1] = 0
    flags[:2, :, 1, 0, 1] = 1
    cube = _fake_cube(flags)
    assert run_fraction(cube, tension_flag(cube), model_info("housner")) is None
    fraction = run_fraction(cube, tension_flag(cube), model_info("ssi"))
    assert float(fraction.sel(soil="rock", block="b")) == pytest.approx(0.2)
    assert float(fraction.sel(soil="clay", block="b")) == 0.0


def test_tension_falls_back_to_negative_support_force():
    from rockfrag.report.adapters import model_info, run_fraction, tension_flag

    force = np.full((10, 2, 2, 1, 2), 1000.0)
    force[:5, :, 1, 0, 1] = -1.0
    cube = _fake_cube(np.zeros_like(force)).drop_vars("support_tension")
    cube["min_support_force"] = (list(cube.outcome.dims), force)
    fraction = run_fraction(cube, tension_flag(cube), model_info("ssi"))
    assert float(fraction.sel(soil="rock", block="b")) == pytest.approx(0.5)
    assert float(fraction.sel(soil="clay", block="b")) == 0.0


def test_sliding_fraction_above_the_friction_coefficient():
    from rockfrag.report.adapters import friction_flag, model_info, run_fraction

    demand = np.full((10, 2, 2, 1, 2), 0.2)
    demand[:4, 1, 0, 0, 1] = 0.7  # 4 of 20 runs on clay need more than mu = 0.5
    cube = _fake_cube(np.zeros_like(demand), demand)
    fraction = run_fraction(cube, friction_flag(cube, 0.5), model_info("ssi"))
    assert float(fraction.sel(soil="clay", block="b")) == pytest.approx(0.2)
    assert float(fraction.sel(soil="rock", block="b")) == 0.0
    assert friction_flag(cube.drop_vars("peak_friction_demand"), 0.5) is None


def _fake_fragility(medians, levels=(0.1, 1.0)):
    coords = {"soil": ["clay"], "block": ["b"], "model": ["ssi"], "damage_state": ["a", "b", "c"],
              "im_level": list(levels)}
    return xr.Dataset({"median": (("soil", "block", "model", "damage_state"), np.array(medians).reshape(1, 1, 1, 3))},
                      coords=coords)


def test_extrapolated_medians_from_the_studied_range(tmp_path):
    from rockfrag.report.adapters import extrapolation

    table = extrapolation(_fake_fragility([0.5, 2.0, np.nan]), tmp_path)
    assert list(table.status) == ["within", "above-range", "no fit"]
    per_block = _fake_fragility([0.5, 2.0, 0.05])
    per_block["intensity"] = (("block", "im_level"), [[0.01, 3.0]])  # the per-block levels of the new layout
    assert list(extrapolation(per_block, tmp_path).status) == ["within", "within", "within"]


def test_extrapolated_medians_from_the_fragility_csv_status_column(tmp_path):
    from rockfrag.report.adapters import extrapolation

    pd.DataFrame({"soil": ["clay"] * 3, "block": ["b"] * 3, "model": ["ssi"] * 3, "damage_state": ["a", "b", "c"],
                  "status": ["ok", "extrapolated-above", "ok"]}).to_csv(tmp_path / "fragility.csv", index=False)
    table = extrapolation(_fake_fragility([0.5, 0.6, 0.7]), tmp_path)
    assert list(table.status) == ["within", "above-range", "within"]


def test_text_pages_split_long_tables_with_their_header():
    from rockfrag.report.text import heading, paginate, paragraph, table

    items = [heading("h"), paragraph("p"), table(["a", "b"], [[str(i), str(i)] for i in range(100)])]
    pages = paginate(items, capacity=30)
    tables = [item for page in pages for item in page if item.kind == "table"]
    rows = [row for item in tables for row in item.rows if row[0] != "(continued)"]
    assert len(rows) == 100 and len(pages) == 4
    assert all(page[0].kind != "heading" or len(page) > 1 for page in pages)
    # cold read 8, user C11: the header came back on the next page with nothing saying the table went on
    assert [item.rows[0] for item in tables[1:]] == [["(continued)", ""]] * 3


def test_a_split_table_says_which_group_continues():
    """A table with group headings (an asset, a soil) opens its next page with the group it cuts, "(continued)";
    where the next page opens with a group of its own, its heading says where it starts. No row is lost, none is
    doubled, and the balancing of the last two pages (which joins and re-splits) keeps one continuation row."""
    from rockfrag.report.text import paginate, table

    rows = []
    for group in ("clay", "sand", "gravel"):
        rows += [[group, "", ""]] + [[f"{group} {i}", "x", "y"] for i in range(20)]
    for capacity in range(18, 40):
        pages = paginate([table(["key", "value", "more"], rows)], capacity=capacity)
        tables = [item for page in pages for item in page if item.kind == "table"]
        kept = [row for item in tables for row in item.rows if not row[0].endswith("(continued)")]
        assert kept == rows, capacity
        for before, after in zip(tables, tables[1:]):
            first = after.rows[0]
            group = next(row[0] for row in reversed(before.rows) if not any(row[1:]))
            if any(first[1:]):
                raise AssertionError(f"{capacity}: a page opens without a group heading: {first}")
            assert first[0] in (f"{group} (continued)", "clay", "sand", "gravel"), (capacity, first)
            if first[0] in ("clay", "sand", "gravel"):
                assert before.rows[-1][0] == f"{group} 19" or not any(before.rows[-1][1:]), capacity


def test_a_wrapped_cell_is_not_split_across_two_pages():
    """Issue 20: a limitations row's wrapped model name ended at the top of the next page ("low edge"), away
    from its row."""
    from rockfrag.report.text import paginate, table

    rows = [[f"row {i}", "x"] for i in range(26)] + [["row 26", "first line"], ["", "second line"],
                                                       ["", "third line"]] + [["row 27", "y"]] * 30
    for capacity in range(28, 34):  # wherever the page break falls
        pages = paginate([table(["key", "value"], rows)], capacity=capacity)
        tables = [item for page in pages for item in page if item.kind == "table"]
        assert sum(len(t.rows) for t in tables if t.rows[0][0] != "(continued)") + sum(
            len(t.rows) - 1 for t in tables if t.rows[0][0] == "(continued)") == len(rows)
        assert all(t.rows[0][0] for t in tables), capacity  # no page starts with a continuation line


def test_showcase_record_is_bolu_or_the_named_one():
    import tomllib
    from importlib.resources import files

    from rockfrag.config import study_from_dict
    from rockfrag.showcase import showcase_record_id

    defaults = tomllib.loads(files("rockfrag").joinpath("defaults.toml").read_text())
    config = study_from_dict(defaults)
    assert showcase_record_id(config, ["DUZCE/BOL090", "X/Y"]) == "DUZCE/BOL090"
    assert showcase_record_id(config, ["X/Y"]) is None
    named = study_from_dict({**defaults, "report": {**defaults["report"], "showcase_record": "X/Y"}})
    assert showcase_record_id(named, ["A/B"]) == "X/Y"


@pytest.mark.slow
def test_showcase_file_has_units_and_the_studys_cases(small_pipeline):
    output, study, _ = small_pipeline
    showcase = _datasets(output)["showcase"]
    for name, variable in showcase.data_vars.items():
        assert variable.attrs.get("units") and variable.attrs.get("long_name"), name
    models = list(map(str, showcase.case_model.values))
    soils = list(map(str, showcase.case_soil.values))
    # a rigid base runs once where it is tied on every soil, per soil where friction lets it slide on one
    # (the small study's block slides on one of its two soils: tests/test_study_sliding.py has the rule)
    sliding = np.isfinite(showcase.case_friction_static.values)
    housner = [i for i, m in enumerate(models) if m == "housner"]
    assert sliding[housner].any() and [soils[i] for i in housner] == [s for s in soils if s][:len(housner)]
    assert models.count("ssi") == 2 and not sliding[[i for i, m in enumerate(models) if m == "ssi"]].any()
    assert np.nanmax(np.abs(showcase.theta.values)) > 0  # the block rocks under Bolu


def test_efficiency_page_is_drawn_on_the_page_size_from_efficiency_nc():
    from rockfrag.report import figures
    from rockfrag.report.layout import PAGE_SIZE

    dims = ("soil", "block", "model", "measure")
    dataset = xr.Dataset({name: (dims, np.full((1, 2, 1, 2), value)) for name, value in
                          (("dispersion", 0.4), ("p_magnitude", 0.3), ("p_distance", 0.2), ("p_pulse_period", 0.1))},
                         coords={"soil": ["clay"], "block": ["a", "b"], "model": ["winkler"],
                                 "measure": ["pga", "pgv"]})
    figure = figures.efficiency_page(dataset, "Read it.", names={"a": "cabinet A"})
    assert tuple(figure.get_size_inches()) == PAGE_SIZE
    labels = [t.get_text() for legend in figure.legends for t in legend.get_texts()]
    assert any(label.startswith("cabinet A,") for label in labels)  # one bar per test: block, model, soils
    assert any(label.startswith("b,") for label in labels)
    plt.close(figure)


def _housner_the_same_on_every_soil(fragility):
    """The fragility with Housner's cells on every soil those of rock (a base tied on every soil)."""
    changed = fragility.copy(deep=True)
    for name, variable in changed.data_vars.items():
        if {"soil", "model"} <= set(variable.dims):
            rock = variable.sel(model="housner", soil="rock")
            for soil in changed.soil.values:
                changed[name].loc[dict(model="housner", soil=soil)] = rock
    return changed


def _housner_slides_on_rock(fragility):
    """The fragility with Housner's rock cells changed, as base friction that lets it slide on rock would."""
    changed = fragility.copy(deep=True)
    where = dict(model="housner", soil="rock")
    changed["median"].loc[where] = changed["median"].loc[where] * 1.5
    changed["outcome_probability"].loc[where] = changed["outcome_probability"].loc[where] * 0.5
    return changed


def test_a_rigid_base_that_slides_on_some_soils_is_drawn_from_each_soils_own_cell(small_pipeline):
    """The fragility-by-soil reference and the outcomes page took Housner from the first soil's cell."""
    from rockfrag.lognormal_fit import lognormal_cdf
    from rockfrag.report import figures
    from rockfrag.report.adapters import model_info

    output, study, _ = small_pipeline
    # the small study's Housner slides on sand and is tied on rock: start from it tied everywhere, then let rock's
    # differ, so that both sides of the rule are drawn
    fragility = _housner_the_same_on_every_soil(_datasets(output)["fragility"])
    block = "paper"
    for dataset, per_soil in ((fragility, False), (_housner_slides_on_rock(fragility), True)):
        figure = figures.fragility_by_soil_page(dataset, block, model_info("ssi"), "caption")
        try:
            state = next(s for s in map(str, dataset.damage_state.values)
                         if np.isfinite(dataset["median"].sel(model="housner", block=block, damage_state=s)).all())
            axis = figure.axes[list(map(str, dataset.damage_state.values)).index(state)]
            housner = {line.get_label(): line for line in axis.get_lines() if line.get_label().startswith("Housner")}
            if not per_soil:
                assert [label for label in housner if " on " in label] == []
                continue
            assert sorted(housner) == sorted(f"{model_info('housner').label} on {s}" for s in ("sand", "rock"))
            for soil, line in ((s, housner[f"{model_info('housner').label} on {s}"]) for s in ("sand", "rock")):
                row = dataset.sel(model="housner", block=block, soil=soil, damage_state=state)
                expected = lognormal_cdf(line.get_xdata(), float(row["median"]), float(row["beta"]))
                np.testing.assert_allclose(line.get_ydata(), expected)
        finally:
            plt.close(figure)
        figure = figures.outcomes_page(dataset, block, "caption")
        try:
            axis = next(a for a in figure.axes if a.get_title().startswith("Housner"))
            labels = [line.get_label() for line in axis.get_lines()
                      if not line.get_label().startswith(("_", "P("))]  # not the key's entries
            assert labels == (["sand", "rock"] if per_soil else ["any soil (rigid base)"])
        finally:
            plt.close(figure)


def test_the_run_count_is_the_studys_cells_a_sliding_rigid_base_once_per_friction_pair():
    """The title page counted a rigid base once per block, where the study runs it per friction pair."""
    from rockfrag.report.sections import Results, n_runs, runs_words

    dims = ("soil", "block", "model")
    friction = np.full((2, 3, 2), np.nan)  # soils sand, rock; blocks a (tied), b (slides on sand), c (both)
    friction[0, 1, 0] = 0.45
    friction[:, 2, 0] = [0.45, 0.7]
    cube = xr.Dataset({"friction_static": (dims, friction), "friction_kinetic": (dims, friction * 0.8)},
                      coords={"soil": ["sand", "rock"], "block": ["a", "b", "c"], "model": ["housner", "ssi"],
                              "record": range(4), "im_level": range(5)}, attrs={"capacity_runs": 17})
    cells = (1 + 2 + 2) + 3 * 2  # housner: tied once; tied + sand; sand + rock. ssi: per soil
    assert n_runs(cube) == cells * 4 * 5
    results = Results(None, cube, None, None, None, run={"runs_computed": 20, "cells_reused": 9, "cells": 11})
    words = runs_words(results)
    assert words.startswith(f"{cells * 20} simulations on the intensity grid and 17 more refining")
    assert ("20 of them were computed for this report, the results of 9 of its 11 record, block, soil and model "
            "combinations in an earlier run of the same study") in words
    assert "all computed for this report" in runs_words(Results(None, cube, None, None, None, run={
        "runs_computed": 220, "cells_reused": 0, "cells": 11}))


def test_the_title_page_says_in_words_that_results_came_from_an_earlier_run_and_when_they_were_computed(tmp_path):
    """Issue 20: "this run computed 0 grid runs and took 3036 of its 3036 cells from the checkpoints of an earlier
    run" meant nothing to a client, and the report gave no date."""
    import os

    from rockfrag.report.sections import Results, results_date, runs_words

    cube = xr.Dataset(coords={"soil": ["sand"], "block": ["a"], "model": ["ssi"], "record": range(2),
                              "im_level": range(3)})
    words = runs_words(Results(None, cube, None, None, None, run={"runs_computed": 0, "cells_reused": 4, "cells": 4}))
    assert "all results were computed in an earlier run of the same study, and this report was redrawn" in words
    assert "checkpoint" not in words and "0 " not in words.split(";")[1]
    assert results_date(tmp_path) is None
    (tmp_path / "cube.nc").write_bytes(b"")
    os.utime(tmp_path / "cube.nc", (0, 1_700_000_000))  # 14 November 2023, 22:13 UTC
    assert results_date(tmp_path) == "2023-11-14"
    checkpoints = tmp_path / ".checkpoints"
    checkpoints.mkdir()
    (checkpoints / "k.ckpt").write_bytes(b"")
    os.utime(checkpoints / "k.ckpt", (0, 1_600_000_000))  # 13 September 2020: when the cells were computed
    assert results_date(tmp_path) == "2020-09-13"
