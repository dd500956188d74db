"""Findings of a cold reader of the default study's report (the engineer who would sign it), one test each where
a test can catch the defect again: on the small study's results (fixture ``small_pipeline``) or on hand-made
inputs. Expected values come from the result files or the study, never from the page under test."""

from __future__ import annotations

import html as html_module
import re

import numpy as np

from rockfrag.report.adapters import block_name
from tests.helpers import pipeline_results


def _visible_text(html: str) -> str:
    text = re.sub(r"<img[^>]*>", " ", html)
    text = re.sub(r"<style>.*?</style>", " ", text, flags=re.S)
    return re.sub(r"\s+", " ", html_module.unescape(re.sub(r"<[^>]+>", " ", text)))


def _section(text: str, start: str, end: str) -> str:
    """The text from the heading ``start`` to the next heading ``end``."""
    begin = text.index(start)
    return text[begin:text.index(end, begin + len(start))]


def test_sliding_limitation_says_which_runs_slide(small_pipeline):
    """Finding 3: "every model assumes the base does not slide, which was not checked" was printed although the
    study's friction runs slide (the rigid base where the soil's mu_s < b/h). The limitations' 'Sliding' section
    names, per model, the blocks and soils whose runs include base friction (cube.nc friction_static finite)."""
    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    cube, config = results.cube, results.config
    text = _visible_text((small_pipeline.output / "report.html").read_text())
    sliding = _section(text, "Sliding Each soil", "Extrapolated fragility medians")
    assert "assumes the base does not slide" not in sliding
    slides = np.isfinite(cube.friction_static)
    assert bool(slides.any()) and not bool(slides.all())  # the fixture has both: the test can fail either way
    for model in map(str, cube.model.values):
        on = slides.sel(model=model)
        label = {"housner": "Housner (rigid base)", "ssi": "SSI, paper's model (spring can pull)"}[model]
        assert label in sliding
        sentence = sliding[sliding.index(label):].split(". ")[0]
        if not bool(on.any()):
            assert "the base is tied (no sliding computed) for every block on every soil" in sentence
            continue
        assert "runs with base friction" in sentence
        for block in map(str, cube.block.values):
            soils = [str(s) for s in cube.soil.values if bool(on.sel(block=block, soil=s))]
            name = block_name(config, block)
            if not soils:
                assert f"the {name} on" not in sentence
            elif len(soils) == cube.sizes["soil"]:
                assert f"the {name} on every soil" in sentence
            else:
                assert f"the {name} on {', '.join(soils)}" in sentence


def _dotted(axis, colour=None) -> list[float]:
    """Where the dotted straight lines of a panel (of ``colour``, if given) cross its intensity axis, sorted."""
    from matplotlib.colors import to_rgba

    found = []
    for line in axis.get_lines():
        x, y = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
        if line.get_linestyle() != ":" or x.size != 2 or (colour is not None
                                                           and to_rgba(line.get_color()) != to_rgba(colour)):
            continue
        position = x[0] if x[0] == x[1] else y[0]  # axvline: x fixed; axhline: y fixed
        if np.isfinite(position):
            found.append(float(position))
    return sorted(found)


def test_each_soil_panel_marks_its_own_site_intensities(small_pipeline):
    """Finding 11: the dotted "site's intensity" lines sat at one hazard's values on every soil's panel. Where the
    soils have their own site hazards, a panel of one soil (IDA, fragility by model) marks that soil's intensities,
    and a panel of every soil (fragility by soil) marks each soil's in the soil's colour. Expected: each soil's site
    curve (rockfrag.answer.hazard_of) read at 1/T, independently of the report's answers."""
    import matplotlib.pyplot as plt

    from rockfrag.answer import display_scale, hazard_of, intensity_at_frequency
    from rockfrag.report import figures
    from rockfrag.report.adapters import models_of
    from rockfrag.report.layout import soil_colour

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    scale, _ = display_scale(results.cube["intensity"].attrs.get("units", ""))
    soils = list(map(str, results.cube.soil.values))
    expected = {soil: [intensity_at_frequency(hazard_of(results.site_hazards, soil), 1.0 / t) / scale
                       for t in results.return_periods] for soil in soils}
    assert not np.allclose(expected[soils[0]], expected[soils[-1]], rtol=1e-3)  # the soils' hazards differ
    block = str(results.cube.block.values[0])
    marks = results.marks(block)
    model = next(m for m in models_of(results.fragility) if not m.rigid_base)
    for figure, along in ((figures.ida_page(results.ida, block, "", marks=marks), "y"),
                          (figures.fragility_by_model_page(results.fragility, block, soils, "", marks=marks), "x")):
        checked = 0
        for axis in figure.axes:
            soil = getattr(axis, "rockfrag_soil", None)
            if soil is None or getattr(axis, "rockfrag_empty", False):
                continue
            low, high = sorted(axis.get_ylim() if along == "y" else axis.get_xlim())
            shown = _dotted(axis, figures.MARK_COLOUR)
            assert np.allclose(shown, sorted(v for v in expected[soil] if low <= v <= high), rtol=1e-6), soil
            checked += bool(shown)
        assert checked >= 2
        plt.close(figure)
    figure = figures.fragility_by_soil_page(results.fragility, block, model, "", marks=marks)
    panel = next(axis for axis in figure.axes if axis.get_visible() and not getattr(axis, "rockfrag_empty", False)
                 and axis.get_lines())
    low, high = panel.get_xlim()
    for index, soil in enumerate(soils):
        assert np.allclose(_dotted(panel, soil_colour(soil, index)),
                           sorted(v for v in expected[soil] if low <= v <= high), rtol=1e-6), soil
    plt.close(figure)


def test_the_intensity_is_defined_once_and_each_number_says_what_it_is(small_pipeline):
    """Finding 5: "largest PGA of the records, unscaled: 0.78 g" (the pair's RotD50) against "PGA of the processed
    records 0.15 to 0.82 g" (each component's peak), and a "largest 15.9" scale factor no component PGA gives. The
    methods define the RotD50 intensity in words, the component peaks are called so, the records table lists both,
    the answer pages name the largest recorded intensity as the pair's RotD50, and the largest scale factor is
    explained by the weakest record's intensity. Expected values from cube.nc."""
    from rockfrag.report.adapters import record_pga_g

    cube = pipeline_results(small_pipeline.output, small_pipeline.study).cube
    assert str(cube.attrs["intensity_component"]) == "RotD50"
    text = _visible_text((small_pipeline.output / "report.html").read_text())
    methods = _section(text, "Models and their assumptions", "Where the numbers come from")
    pga = record_pga_g(cube)
    assert f"peak ground acceleration of each processed component {pga.min():.2g} to {pga.max():.2g} g" in methods
    assert methods.count("RotD50 (Boore 2010)") == 1 and "median over the directions" in methods
    rotd50 = np.asarray(cube.record_im.isel(block=0).values, float)  # g: the file's unit is 9.80665 m s-2
    assert cube.record_im.attrs["units"] == "9.80665 m s-2"
    factors = np.asarray(cube.scale_factor.values, float)
    assert f"largest {np.nanmax(factors):.3g} (the highest level over the weakest record's intensity, " \
           f"{rotd50.min():.2g} g)" in methods
    assert np.isclose(np.nanmax(factors), float(cube.intensity.max()) / rotd50.min(), rtol=1e-6)
    answers = text[text.index("The tables of each answer page"):]
    assert f"The largest intensity of the records, unscaled (the pair's RotD50 PGA): {rotd50.max():.2g} g" in answers
    assert "The largest PGA of the records" not in answers
    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    from rockfrag.report import records_items

    records = records_items(results)[0]
    column = records.header.index("scaled by: RotD50 PGA of the pair [g]")
    assert [float(row[column]) for row in records.rows] == [round(v, 2) for v in rotd50]
    assert [float(row[records.header.index("PGA [g]")]) for row in records.rows] == [round(v, 2) for v in pga]


def test_levels_are_stated_per_block_as_multiples_of_its_uplift(small_pipeline):
    """Finding 13: "0.5 to 15.1 times the uplift intensity of each block" held for one block only (the range over
    every block). Levels re-spaced per block (level_multiple, as the default study's) are stated per block: each
    block's own multiples and intensities. The small study's absolute levels made relative here."""
    from rockfrag.report.sections import methods_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    cube = results.cube
    uplift = np.array([0.1, 0.25, 0.4])[:cube.sizes["block"]]  # g, a different uplift per block
    multiples = cube.intensity / xr_array(uplift, cube)
    im_level = cube.im_level.copy()
    im_level.attrs = {**im_level.attrs, "units": "1"}
    relative = cube.assign(level_multiple=multiples.transpose("block", "im_level")).assign_coords(im_level=im_level)
    results = pipeline_results(small_pipeline.output, small_pipeline.study, cube=relative)
    text = " ".join(item.text for item in methods_items(results) if item.kind == "paragraph")
    for index, block in enumerate(map(str, cube.block.values)):
        row = np.asarray(multiples.sel(block=block).values, float)
        levels = np.asarray(cube.intensity.sel(block=block).values, float)
        assert f"{block_name(results.config, block)} {row.min():.2g} to {row.max():.3g} times, " \
               f"{levels.min():.2g} to {levels.max():.2g} g" in text
    overall = np.asarray(multiples.values, float)
    assert f"{overall.min():.3g} to {overall.max():.3g} times the uplift intensity of each block" not in text


def xr_array(values, cube):
    """``values`` along the cube's blocks, as a DataArray."""
    import xarray as xr

    return xr.DataArray(np.asarray(values, float), coords={"block": cube.block.values}, dims="block")


def test_contents_numbers_a_section_by_the_page_its_heading_is_on():
    """Finding 23: a section that starts part-way down a page (Methods after the fitted-functions table) was
    numbered by the next page, where its text continues ("Methods 14", its heading on p. 13)."""
    from rockfrag.report import contents_rows
    from rockfrag.report.layout import Page

    def page(section, heading, also=()):
        return Page(section.lower(), section, heading, lambda: None, "", also=also, heading=heading)

    planned = [page("Title", "Title"), page("Fitted curves", "Fitted fragility functions", also=("Methods",)),
               page("Methods", "Methods and assumptions"), page("Methods", "Methods and assumptions"),
               page("Limitations", "Limitations: where the models are outside their validity")]
    rows = contents_rows(planned, position=2)  # the contents is page 2: the fitted table is page 3
    assert ("section", "Methods", 3) in rows and ("page", "Methods and assumptions", 3) in rows
    assert [row for row in rows if row[2] in (4, 5)] == []  # Methods' own pages are not listed again
    assert ("section", "Limitations", 6) in rows


def test_every_contents_row_names_a_title_on_its_page(small_pipeline):
    """The contents of the small pipeline's report: each row's page holds its section (as the page's own or one
    starting part-way down it) or its heading."""
    from rockfrag.report import build_plan, contents_rows, plan

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    planned = plan(results)
    pages = build_plan(results)
    position = next(i for i, p in enumerate(pages, start=1) if p.name == "contents")
    first_heading = {}
    for p in planned:
        first_heading.setdefault(p.section, p.heading or p.title)
    for kind, text, number in contents_rows(planned, position):
        page = pages[number - 1]
        if kind == "section":
            assert text == page.section or text in page.also, (text, number)
        else:
            # a section that starts part-way down a page and ends on it is no page's own: its heading is in the text
            assert text == (page.heading or page.title) or text in [first_heading.get(s) for s in page.also] \
                or text in (page.html or ""), (text, number)


def test_the_example_hazard_is_said_once_and_referred_to(small_pipeline):
    """Findings 15/22: "not a site's hazard" was said about ten times in different words (and once garbled:
    "amplified from the shipped example hazard, which is no site's to the soil's site class"). The summary says it
    in full, once; every other page before the appendix refers to it in the same few words."""
    from rockfrag.report.summary import EXAMPLE_HAZARD_WORDS, EXAMPLE_WARNING

    html = (small_pipeline.output / "report.html").read_text()
    text = _visible_text(html[:html.index("id='section-how-to-reproduce-this-report'")])
    assert text.count(EXAMPLE_WARNING) == 1
    assert text.count("no verdict in this report applies to a real site") == 1
    assert "shipped example" not in text and "which is no site's" not in text
    assert text.count(EXAMPLE_HAZARD_WORDS) >= 3  # the title page, the answer pages, the methods
