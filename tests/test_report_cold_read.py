"""Findings of a cold reader of the default study's report (the engineer who would sign it), one test each where
a test can catch the defect again: on the small study's results (fixture ``small_pipeline``) or on hand-made
inputs. Expected values come from the result files or the study, never from the page under test."""

from __future__ import annotations

import html as html_module
import math
import re
from types import SimpleNamespace

import numpy as np
import xarray as xr

from rockfrag.report import numbers
from rockfrag.report.adapters import block_name, short_block_name
from tests.helpers import ROOT, pipeline_results


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
            name = short_block_name(config, block)  # running text: the name without its sizes
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
    # the slender block rocks visibly (the paper's block, 2 records, stays on the IDA frame: its panels carry a note)
    block = next((b for b in map(str, results.cube.block.values) if "slender" in b), str(results.cube.block.values[0]))
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
            shown = _dotted(axis, soil_colour(soil, soils.index(soil)))  # in the soil's colour, as on every page
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
        assert f"{short_block_name(results.config, block)} {row.min():.2g} to {row.max():.3g} times, " \
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


# Cold read 3 (/work/tmp/read3/READ.md): the findings on the words of both reports.

ACTIONS = ("anchor or restrain", "no action", "specialist check")


def _action_cells(results) -> list[str]:
    """Every action the summary, the answer pages' tables and their verdict sentences print."""
    from rockfrag.report.answer_page import answer_items
    from rockfrag.report.summary import summary_items, verdict_items

    cells = []
    for item in summary_items(results):
        if item.kind == "table":
            column = item.header.index("action")
            cells += [row[column] for row in item.rows if any(row[1:])]
    for answer in results.answers:
        for item in answer_items(results, answer):
            if item.kind == "table" and item.rows and item.rows[-1][0] == "action":
                cells += [cell for cell in item.rows[-1][2:]]
        lead = verdict_items(results, answer)[0].text
        cells += [part.split(" on ")[0].split(": ")[-1] for part in lead.rstrip(".").split("; ")
                  if part.split(": ")[-1].startswith(ACTIONS)]
    return cells


def test_every_printed_action_names_a_hazard_that_is_not_a_sites(small_pipeline, tmp_path):
    """Cold read 3, user and default A1: the summary, the answer pages' verdicts and their tables printed a bare
    "no action" / "anchor or restrain" under the shipped example hazard and under an illustrative hazard file: a
    cell copied out of the report loses what it rests on. Every action cell then says "(example hazard)" or
    "(illustrative hazard)"; with a site's hazard file (not marked illustrative), none does."""
    import shutil
    from dataclasses import replace

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    assert all(answer.example_hazard for answer in results.answers)
    cells = _action_cells(results)
    assert len(cells) >= 2 * len(results.answers) and all(cell.startswith(ACTIONS) for cell in cells), cells
    assert all(cell.endswith("example hazard)") for cell in cells), cells

    study, hazard = tmp_path / "study.toml", tmp_path / "hazard.csv"
    shutil.copy(ROOT / "studies" / "user-site-hazard.csv", hazard)
    study.write_text(small_pipeline.study.read_text().replace(
        "[intensity]", '[hazard]\nfile = "hazard.csv"\nreference_vs30 = 760.0\nsite = [23.62, 37.94]\n\n[intensity]'))
    results = pipeline_results(small_pipeline.output, study)
    cells = _action_cells(results)
    assert cells and all(cell.endswith("illustrative hazard)") for cell in cells), cells

    hazard.write_text(hazard.read_text().replace("hand-written ILLUSTRATIVE curve", "the site's hazard study")
                      .replace("not the result of a hazard model", "from the site's own model"))
    results = pipeline_results(small_pipeline.output, study)
    results.__dict__["answers"] = [replace(answer, example_hazard=False) for answer in results.answers]
    cells = _action_cells(results)
    assert cells and not any("hazard" in cell for cell in cells), cells


def test_a_bound_governs_only_where_no_judged_state_is_computed():
    """Cold read 3, default B5: the squat block on sand was 'governed' by overturning that no record reached (a
    bound, '< X': P50 0.029% against 1%) over its computed slip (0.29% against 10%): the choice turned on the second
    figure and the summary printed 'not reached' in every cell. A computed state governs when none is exceeded; the
    bound governs only where every judged state is a bound; an exceeded state governs whatever it is."""
    from types import SimpleNamespace

    from rockfrag.answer import StateAnswer
    from rockfrag.report.summary import GOVERNING_WORDS, governing

    def row(state, p, limit, reached=True):
        return StateAnswer(state=state, at_return_periods=((p, np.nan, np.nan),) * 3, annual_frequency=p / 50,
                           probability_in_life=p, limit=limit, not_reached_below=None if reached else 3.0)

    slip, bound = row("slip-0.30", 0.0029, 0.10), row("overturning", 0.00030, 0.01, reached=False)
    assert bound.probability_in_life / bound.limit > slip.probability_in_life / slip.limit  # the bound is nearer
    assert governing(SimpleNamespace(states=[slip, bound])) is slip
    assert governing(SimpleNamespace(states=[bound])) is bound
    exceeded = row("overturning", 0.02, 0.01, reached=False)
    assert exceeded.exceeds and governing(SimpleNamespace(states=[slip, exceeded])) is exceeded
    assert "the computed state nearest its limit" in GOVERNING_WORDS


def test_a_structural_base_is_said_to_be_at_ground_level_and_a_floor_needs_its_own_motion(small_pipeline):
    """Cold read 3, default A2: 'steel' was judged as if it were equipment on a steel deck, with the ground motion of
    the reference site. The summary says once what a structural base stands for (a plate at ground level under the
    reference site's motion) and that a block on a structure needs the floor's motion, not modelled; a study
    without such a base says nothing of it."""
    from rockfrag.report.adapters import STIFF_BASE
    from rockfrag.report.sections import grounds
    from rockfrag.report.summary import summary_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    note = " ".join(item.text for item in summary_items(results) if item.kind == "note")
    assert "floor spectrum" not in note
    modulus = results.cube.soil_shear_modulus.copy()
    modulus.loc[dict(soil="rock")] = 4 * STIFF_BASE  # rock as stiff as a steel plate: a structural base
    results.cube.coords["soil_shear_modulus"] = modulus
    note = " ".join(item.text for item in summary_items(results) if item.kind == "note")
    assert "'rock': a steel plate at ground level under the reference site's motion" in note
    assert "not a floor of a structure (no floor spectrum)" in note  # said in one sentence
    assert "structural base at ground level (rock; not a soil)" in grounds(results.cube)


def test_the_steel_friction_says_why_class_b_and_where_class_a_would_make_a_block_slide(small_pipeline):
    """Cold read 3, default A2: steel's μ_s 0.50 was 'the slip coefficient of class B steel surfaces (AISC 360-16,
    J3.8), a value for bolted faying surfaces' with no word on why class B; class A (0.30, clean mill scale) is the
    closer value for an unprepared base, and for the paper's block (b/h 0.47) the class decides whether it rocks or
    slides. The words say it is the study's choice, give class A, and name each block whose b/h lies between the
    two, with what the sample's low-friction member does where it too lies below b/h."""
    from rockfrag.report.sections import SLIP_CLASS_A, SLIP_CLASS_B, steel_friction_words
    from rockfrag.soils import SOILS

    # AISC 360-16 J3.8 mean slip coefficients, as printed: class A 0.30, class B 0.50
    assert (SLIP_CLASS_A, SLIP_CLASS_B) == (0.30, 0.50) and SOILS["steel"].friction_static == SLIP_CLASS_B
    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    cube = results.cube.assign_coords(soil=["steel", "rock"])  # sand renamed: the small study has no steel
    slender = {str(b): float(cube.block_b.sel(block=b) / cube.block_h.sel(block=b)) for b in cube.block.values}
    between = [block for block, ratio in slender.items() if SLIP_CLASS_A <= ratio < SLIP_CLASS_B]
    assert between == ["paper"]  # b/h 0.47: the test can tell the blocks apart
    members = ["friction_low", "friction_high"]
    cube["member_friction_static"] = xr.DataArray(np.broadcast_to([0.42, 0.6], (2, 3, 2)).copy(),
                                                  coords={"soil": cube.soil.values, "block": cube.block.values,
                                                          "member": members}, dims=("soil", "block", "member"))
    fragility = results.fragility.assign_coords(soil=["steel", "rock"])
    medians = xr.full_like(fragility["median"].isel(model=0, drop=True), np.nan).expand_dims(member=members).copy()
    fragility["member_median"] = medians
    results.__dict__.update(cube=cube, fragility=fragility)
    words = steel_friction_words(results)
    assert "class B" in words and "class A (0.30)" in words and "the study's choice" in words
    name = block_name(results.config, "paper")
    assert f"the {name[:-1]}; b/h = {slender['paper']:.2f}) rocks with class B" in words or \
        f"the {name} (b/h = {slender['paper']:.2f}) rocks with class B" in words
    assert "low-friction run (μ_s 0.42), whose lift-off has no median" in words
    for block in ("slender-cabinet", "squat-machinery"):
        assert block_name(results.config, block) not in words


def test_a_value_that_rests_on_the_assumed_friction_is_marked_with_the_high_friction_members_median(small_pipeline):
    """Cold read 3, user B1: the clay overturning of the user study, 'once in 7,400,000 years', exists because the
    soil's μ_s (0.35) is below the block's b/h (0.40): the block slides instead of rocking, and nothing beside the
    number said so. On every soil where the block slides before it can rock, the design-life values of the rocking
    states and overturning carry a mark, and a note under the table gives the medians of the designed sample's
    high-friction member (fragility.nc member_median friction_high); no other cell is marked."""
    from rockfrag.report.answer_page import FRICTION_MARK, answer_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    model = results.answers[0].model
    friction = results.cube.friction_static.copy()
    friction.loc[dict(model=model)] = 0.45  # as if the answering runs had base friction (sand 0.45, rock 0.7)
    results.cube["friction_static"] = friction
    members = ["friction_low", "friction_high"]
    median = xr.full_like(results.fragility["median"].sel(model=model, drop=True), np.nan)
    median.loc[dict(soil="rock", damage_state="rocking-0.5")] = 1.234  # the high-friction run rocks on rock
    results.fragility["member_median"] = xr.concat([median * 0.8, median], dim="member").assign_coords(
        member=members)
    results.cube["member_friction_static"] = xr.DataArray(
        np.full((results.cube.sizes["soil"], results.cube.sizes["block"], 2), 0.9),
        coords={"soil": results.cube.soil.values, "block": results.cube.block.values, "member": members},
        dims=("soil", "block", "member"))
    edps = dict(zip(map(str, results.fragility.damage_state.values),
                    map(str, results.fragility.damage_state_edp.values)))
    rocking = {state for state, edp in edps.items() if edp in ("peak_angle_ratio", "overturned")}
    answer = next(answer for answer in results.answers if answer.block == "squat-machinery")
    items = answer_items(results, answer)
    life = next(i for i, item in enumerate(items) if item.kind == "heading" and item.text.startswith("In the design"))
    table, note = items[life + 1], items[life + 2]
    short = {row[0]: state for row, state in zip(table.rows, results.fragility.damage_state.values)}
    soils = [head.removeprefix("on ") for head in table.header[2:]]
    slender = 1.5 / 2.0
    marked = 0
    for row in table.rows[:len(short)]:
        state = short[row[0]]
        for soil, cell in zip(soils, row[2:]):
            mu = next(s.friction_static for s in results.config.soils if s.name == soil)
            expected = state in rocking and mu < slender and cell.strip("- ") != "" and "not computed" not in cell
            assert cell.endswith(f" {FRICTION_MARK}") == expected, (state, soil, cell)
            marked += expected
    assert marked >= 2
    assert note.kind == "note" and note.text.startswith(f"{FRICTION_MARK} friction-driven: on every soil the block")
    assert note.text.endswith("the medians are, on sand (μ_s 0.90): none below the highest intensity studied; "
                              "on rock (μ_s 0.90): θmax/α ≥ 0.5 at 1.2 g."), note.text  # the small study's levels: g
    other = next(answer for answer in results.answers if answer.block == "slender-cabinet")  # b/h 0.2: grips
    assert not any(FRICTION_MARK in cell for item in answer_items(results, other) if item.kind == "table"
                   for row in item.rows for cell in row)


def test_the_bed_frequencies_are_the_closed_forms_of_the_contact_law():
    """Cold read 3, default B4 (the frequencies the lift-off sentence prints): vertical sqrt(k/m); rocking with the
    whole base down sqrt((K_r/m - g h) / j), j = (b² + 4h²)/3 about the base centre, K_r = k b² for the two corner
    springs (k/2 at each corner, ±b) and k b²/3 for the continuous bed (k/2b per metre over the base)."""
    from types import SimpleNamespace

    from rockfrag.config import load_study
    from rockfrag.report.answer_page import bed_frequencies
    from rockfrag.soils import SOILS, soil_block_stiffness

    block = next(block for block in load_study(ROOT / "pipeline" / "defaults.toml").blocks if block.name == "paper")
    soil = SOILS["gravel"]
    k, m, g = soil_block_stiffness(soil, block), block.mass, 9.80665
    j = (block.b ** 2 + 4 * block.h ** 2) / 3
    for bed, share in (("two-spring", 1.0), ("continuous", 1.0 / 3.0)):
        vertical, rocking, settlement = bed_frequencies(SimpleNamespace(bed=bed, calibrates_bed=True), block, soil)
        assert math.isclose(vertical, math.sqrt(k / m) / (2 * math.pi), rel_tol=1e-12)
        assert math.isclose(rocking, math.sqrt((share * k * block.b ** 2 / m - g * block.h) / j) / (2 * math.pi),
                            rel_tol=1e-9)
        assert math.isclose(settlement, m * g / k, rel_tol=1e-12)
    assert math.isclose(settlement * 1000, 2.67, abs_tol=0.01)  # the reader's m g / k = 2.7 mm on gravel


def test_a_lift_off_median_below_both_neighbouring_soils_is_explained_by_the_bed_and_the_records(tmp_path):
    """Cold read 3, default B4: the paper's block lifted off on gravel at a median (0.20 g) below sand's and rock's,
    with no word why, and no word from where a lift is measured (the static settlement, 2.7 mm, exceeds the 1 mm
    lift-off size). The answer page gives, for such a soil, the bed's vertical and rocking frequencies against the
    records' strongest spectral band, the calibrated damping where it is the block's lowest, and that a lift counts
    from the bed's unloaded surface (loss of contact), after the static settlement. Medians that rise with the
    stiffness get no sentence."""
    from types import SimpleNamespace

    import xarray as xr

    from rockfrag.config import load_study
    from rockfrag.report.answer_page import bed_frequencies, bed_resonance_words, records_band
    from tests.helpers import ROOT

    config = load_study(ROOT / "pipeline" / "defaults.toml")
    soils = [soil.name for soil in config.soils]
    assert soils == ["clay", "sand", "gravel", "rock", "steel"]
    medians = xr.DataArray([[[[0.67, 0.31, 0.20, 0.33, 1.5]]]], dims=("model", "block", "damage_state", "soil"),
                           coords={"model": ["recommended"], "block": ["paper"], "damage_state": ["uplift"],
                                   "soil": soils}, attrs={"units": "9.80665 m s-2"})
    fragility = xr.Dataset({"median": medians})
    damping = xr.DataArray([[[0.39, 0.25, 0.06, 0.16, 0.10]]], dims=("model", "block", "soil"),
                           coords={"model": ["recommended"], "block": ["paper"], "soil": soils})
    cube = xr.Dataset({"damping_ratio_calibrated": damping})
    periods = np.geomspace(0.02, 10.0, 60)
    shape = np.exp(-np.log(periods / 0.25) ** 2)  # records whose spectra peak at 0.25 s
    showcase = xr.Dataset({"record_spectrum": (("record", "period"), np.vstack([shape * 2.0, shape * 3.0]) + 0.1),
                           "record_pga": ("record", [1.0, 1.5])}, coords={"period": periods})
    results = SimpleNamespace(fragility=fragility, cube=cube, config=config, showcase=showcase)
    answer = SimpleNamespace(model="recommended", block="paper", unit="g")
    band = records_band(showcase)
    assert band[0] < 0.25 < band[1]
    words = bed_resonance_words(results, answer)
    block = next(block for block in config.blocks if block.name == "paper")
    gravel = next(soil for soil in config.soils if soil.name == "gravel")
    vertical, rocking, settlement = bed_frequencies(config, block, gravel)
    assert words.startswith("On gravel this block lifts off at a lower median than on sand and rock "
                            "(0.20 g against 0.31 g and 0.33 g)")
    two = numbers.two_figures
    assert f"a vertical frequency of {two(vertical)} Hz" in words
    assert f"a rocking frequency (whole base down) of {two(rocking)} Hz, {two(1 / rocking)} s" in words
    assert f"the records' strongest band, {band[0]:.2g} to {band[1]:.2g} s" in words
    assert "damping, calibrated to the impact restitution, is this block's lowest on gravel" in words
    assert words.index("damping") < words.index("vertical frequency")  # the likely reason comes first
    assert f"static settlement, {settlement * 1000:.2g} mm on gravel" in words
    assert "loss of contact" in words and "not from rest" in words
    fragility["median"][:] = [[[[0.1, 0.2, 0.3, 0.4, 0.5]]]]  # rising with the stiffness: nothing to explain
    assert bed_resonance_words(results, answer) == ""


def test_a_block_whose_bed_reaches_no_restitution_says_which_r_its_answering_run_has():
    """Cold read 3, default B6: the squat block's page said '(r 0.460 to 0.483 asked; it reaches none of them)' and
    not which r its answering run uses. Its free rocking dies out below what the restitution measure resolves at
    every damping the bed admits, so it runs at the least such damping with r bounded by the measure's resolution
    (rockfrag.models.restitution.resolution_bound: sqrt(drop(0.1 α) / drop(0.6 α)), drop(θ) = cos(α - θ) - cos α)."""
    from types import SimpleNamespace

    from rockfrag.report.answer_page import curve_reason
    from tests.test_report_answer import _restitution_cube

    requested = np.array([[0.94, 0.97, 0.99], [0.46, 0.4715, 0.483]])  # cabinet, skid
    reached = np.array([[0.94, 0.95, 0.95], [np.nan] * 3])
    cube = _restitution_cube(requested, reached, np.array([[0.4, 0.16, 0.16], [0.15, 0.15, 0.15]]),
                             ["cabinet", "skid"])
    alpha = math.atan(0.75)  # the skid's b/h
    cube = cube.assign_coords(block_alpha=("block", [math.atan(0.2), alpha]))
    results = SimpleNamespace(fragility=xr.Dataset(coords={"model": ["recommended"]}), cube=cube)
    skid = curve_reason(results, "recommended", "skid")
    bound = math.sqrt((math.cos(0.9 * alpha) - math.cos(alpha)) / (math.cos(0.4 * alpha) - math.cos(alpha)))
    assert math.isclose(bound, 0.470, abs_tol=5e-4)
    assert (f"its r is not measured but bounded, at most {bound:.3f}, below the middle of the range (0.471)"
            in skid), skid
    assert "not measured" not in curve_reason(results, "recommended", "cabinet")


def test_the_answering_runs_restitution_is_said_per_soil_in_one_plain_sentence():
    """Cold read 3, user C3 and default C4: "On clay, sand the bed cannot ..." and "The answering run itself is below
    the middle of the range (0.813) there: it runs at r sand 0.802" ('there' without an antecedent). Now: "On sand
    the answering run uses r = 0.802, below the middle of the range, 0.813", soils joined with 'and'."""
    from rockfrag.report.answer_page import _band_reach
    from tests.test_report_answer import _restitution_cube

    requested = np.array([[0.793, 0.813, 0.833]])
    cube = _restitution_cube(requested, np.array([[0.793, 0.802, 0.802]]), np.array([[0.3, 0.2, 0.2]]), ["box"])
    cube["restitution_target"].loc[{"soil": "clay"}] = 0.813  # clay reaches the middle, not the upper end
    text = _band_reach(cube)
    assert "On clay and rock the bed cannot dissipate" in text, text
    assert "it reaches at most 0.802 on clay and rock" in text, text  # an equal value said once
    assert "On rock the best-estimate run uses r = 0.802, below the middle of the range, 0.813." in text, text
    assert " there:" not in text and "itself" not in text


def test_the_reading_page_takes_its_example_cell_from_the_report(small_pipeline):
    """Cold read 3, user C2 and default C3: "(for example 5.6% / 17% / 43%)" on the page 'Reading the answer pages'
    was no cell of the report. The example is a cell of this report's own answer tables."""
    from rockfrag.report.answer_page import answer_items, reading_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    text = " ".join(item.text for item in reading_items(results))
    example = re.search(r"\(for example ([^)]*)\)", text)
    assert example is not None and example.group(1) != "5.6% / 17% / 43%"
    cells = {cell for answer in results.answers for item in answer_items(results, answer) if item.kind == "table"
             for row in item.rows for cell in row[1:]}
    assert example.group(1) in cells, example.group(1)
    assert example.group(1).count(" / ") == len(results.answers[0].return_periods) - 1


def test_the_footer_headers_and_formulas_speak_the_clients_spelling(small_pipeline):
    """Cold read 3, user C4 and default C6: every footer ended "study 'user-site'" (the study file's name), the
    planar-model table's header read "density [kg/m^3]" and the methods wrote "r = 1 - 1.5 sin^2(α)" where the
    other pages write sin²α. The footer is the project and title; one spelling of each unit and formula."""
    from rockfrag.report import report_footer
    from rockfrag.report.sections import limitations_items, methods_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    footer = report_footer(results)
    assert "study '" not in footer and results.config.name not in footer.split(" · ")
    assert footer.endswith(results.title)
    assert "study file" not in results.friction_words  # read 4, user B2: the appendix names the setting
    texts = [item.text for item in methods_items(results) + limitations_items(results)]
    headers = [head for item in limitations_items(results) if item.kind == "table" for head in item.header]
    assert "density [kg/m³]" in headers and not any("^" in head for head in headers)
    housner = next(text for text in texts if "Housner (rigid base)" in text and "dissipate" in text)
    assert "sin²α" in housner and not any("sin^2" in text for text in texts)
    from rockfrag.config import load_study
    from rockfrag.report.adapters import block_description

    described = block_description(load_study(ROOT / "pipeline" / "defaults.toml"), "paper")
    assert "2,400 kg/m³" in described and "^" not in described  # the study's 'why' says kg/m^3


def test_a_site_intensity_just_below_a_level_that_prints_the_same_is_told_apart():
    """Cold read 3, user C1: clay's 975-year PGA 0.3721 g printed '0.37 g' beside the levels read '0.3 g / 0.3 g /
    0.37 g' (the level 0.3722 g is just above it, so the level below is read): a reader sees a contradiction. A note
    gives both to the figures that tell them apart; an intensity clear of its next level gets none."""
    from types import SimpleNamespace

    from rockfrag.report.answer_page import knife_edge_words

    levels = [0.24, 0.302, 0.3722, 0.46]
    soil = SimpleNamespace(soil="clay", intensities=(0.323, 0.3698, 0.441))  # 0.65 % below the level 0.3722 g
    answer = SimpleNamespace(soils=[soil], return_periods=(475.0, 975.0, 2475.0), unit="g", intensities=())
    assert knife_edge_words(answer, levels) == ("On clay the 975-year intensity, 0.3698 g, lies just below the level "
                                                "0.3722 g (both print 0.37 g), so the tables read the level below "
                                                "it, 0.30 g.")
    soil.intensities = (0.323, 0.36, 0.441)
    assert knife_edge_words(answer, levels) == ""
    soil.intensities = (0.323, 0.3721, 0.441)  # 0.03 % below: read as at the level (no note, no lower level)
    assert knife_edge_words(answer, levels) == ""


def test_a_level_a_hair_above_the_site_intensity_counts_as_at_it():
    """Cold read 4, user B4: clay's 975-year PGA 0.3721 g read the level below the level 0.3722 g, so its record
    counts were the 475-year ones. A level within 0.5 % above the intensity is read as at it; one 5 % above is not."""
    from rockfrag.answer import level_at_or_below

    levels = [0.24, 0.302, 0.3722, 0.46]
    assert level_at_or_below(levels, 0.3721) == 2  # 0.03 % below the level
    assert level_at_or_below(levels, 0.3722 / 1.05) == 1
    assert level_at_or_below(levels, 0.2) is None


def test_a_probability_read_from_a_curve_that_fails_its_fit_test_is_marked_on_the_answer_page(small_pipeline):
    """Cold read 3, default C5: the paper block's uplift on steel (β 1.12, the fitted table's ‡: it fails its
    goodness-of-fit test) gave the answer page 7.2% / 11% / 19% and 8.4% in 50 years without a word. Its cells
    there carry ‡ and a note says what it means; a curve that passes the test carries none."""
    from rockfrag.report.adapters import GOF_LEVEL
    from rockfrag.report.answer_page import POOR_FIT_MARK, answer_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    answer = results.answers[0]
    soil = answer.soils[0]
    fitted = [row for row in soil.states if row.not_reached_below is None and row.below_lowest is None
              and np.isfinite(row.probability_in_life)]
    assert fitted
    gof = results.fragility.gof_p_value.copy()
    gof[:] = 0.5
    gof.loc[dict(model=answer.model, block=answer.block, soil=soil.soil, damage_state=fitted[0].state)] = 0.01
    results.fragility["gof_p_value"] = gof
    items = answer_items(results, answer)
    marked = [(row[0], cell) for item in items if item.kind == "table" for row in item.rows
              for cell in row[1:] if cell.endswith(POOR_FIT_MARK)]
    assert len(marked) == 2, marked  # its probabilities at the return periods and in the design life
    assert any(item.kind == "note" and item.text.startswith(f"{POOR_FIT_MARK} read from a fitted curve")
               and f"p < {GOF_LEVEL:g}" in item.text for item in items)
    gof[:] = 0.5
    results.fragility["gof_p_value"] = gof
    assert not any(cell.endswith(POOR_FIT_MARK) for item in answer_items(results, answer) if item.kind == "table"
                   for row in item.rows for cell in row)


def test_a_tables_lead_in_never_ends_a_page_without_its_table():
    """Cold read 3 nit (orphan table headings): a line that introduces a table ("Records that reached each state at
    those levels (of 44):") stood at the foot of a page and its table began on the next. A heading or a lead-in
    paragraph ending with a colon goes to the page its table starts on; other paragraphs stay."""
    from rockfrag.report.text import _lines, paginate, paragraph, table

    capacity = 40
    filler = [paragraph(f"Line {i}.") for i in range(18)]  # 2 lines each: 36 of the page's 40
    lead = paragraph("Records that reached each state at those levels (of 44):")
    rows = [[f"state {i}", "1 / 2 / 3"] for i in range(30)]
    pages = paginate(filler + [lead, table(["damage state", "on clay"], rows)], capacity)
    assert sum(_lines(item) for item in filler) + _lines(lead) <= capacity  # the lead-in alone would fit
    for page in pages:
        assert not (page[-1].kind == "paragraph" and page[-1].text.endswith(":")), [i.text for i in page[-2:]]
    start = next(i for i, page in enumerate(pages) if any(item.kind == "table" for item in page))
    assert lead in pages[start]
    plain = paragraph("A sentence that introduces nothing.")
    pages = paginate(filler + [plain, table(["damage state", "on clay"], rows)], capacity)
    assert plain in pages[0]


def test_the_sufficiency_sentence_names_the_runs_its_test_rests_on():
    """Cold read 3, user B5 and default B2: "At a given PGA this block's overturning still depends on the records'
    pulse period" read as a property of the answering curve, while the test rests on Housner's rigid base on sand
    alone (the one cell with enough overturning records). Where the answering model was not tested, the sentence
    names the runs it rests on (soils named unless the test holds on every soil)."""
    import xarray as xr

    from rockfrag.report.answer_page import sufficiency_words

    dims = ("soil", "block", "model", "measure")
    p = np.full((2, 1, 2, 1), np.nan)
    p[1, 0, 0, 0] = 1e-3  # sand, housner: depends on the pulse period; the recommended runs untested
    efficiency = xr.Dataset({"p_pulse_period": (dims, p)},
                            coords={"soil": ["clay", "sand"], "block": ["box"], "model": ["housner", "recommended"],
                                    "measure": ["pga"]})
    words = sufficiency_words(efficiency, "box", "pga", "PGA", "recommended")
    assert words.startswith("Whether PGA alone predicts this block's overturning: at a given PGA the overturning "
                            "still depends on the records' pulse period in the runs of Housner (rigid base) on sand, "
                            "the only model for which this was checked (the check needs each record's exact "
                            "overturning intensity, which the study finds only for a base held against sliding); for "
                            "the recommended model, whose base slides, it is not known (the measure-efficiency page"), \
        words  # cold read 7: 'not in' read as 'tested, no dependence'; cold read 12: no tool words

    p[0, 0, 0, 0] = 1e-3  # the same on every soil (a tied rigid base): no soil named
    words = sufficiency_words(efficiency.assign(p_pulse_period=(dims, p)), "box", "pga", "PGA", "recommended")
    assert "in the runs of Housner (rigid base), the only model for which this was checked" in words
    p[1, 0, 1, 0] = 1e-3  # the answering model tested too: the sentence is about its curve, no qualification
    words = sufficiency_words(efficiency.assign(p_pulse_period=(dims, p)), "box", "pga", "PGA", "recommended")
    assert "in the runs of" not in words and "pulse period" in words


def test_a_table_split_by_a_page_break_leaves_no_single_row_on_the_next_page():
    """Cold read 3 nit (found on the read-4 reports): the paper block's design-life table broke with its last row,
    'action', alone under a repeated header on the next page. A split leaves at least two rows to the next page."""
    from rockfrag.report.text import SHORT_TABLE, paginate, paragraph, table

    rows = [[f"state {i}", "1%"] for i in range(SHORT_TABLE + 4)]  # a short table is never split (cold read 12)
    split = 0
    for lines in range(20, 40):  # every position of the break
        filler = [paragraph("x " * 70 * max(lines - 1, 1))]  # a paragraph of about ``lines`` lines
        after = [paragraph("y " * 70 * 30)]  # more text after the table: the page cannot just stretch
        pages = paginate(filler + [table(["damage state", "on steel"], rows)] + after, 40)
        parts = [item for page in pages for item in page if item.kind == "table"]
        if len(parts) > 1:
            split += 1
            assert all(len(part.rows) >= 2 for part in parts), [len(part.rows) for part in parts]
    assert split


def test_a_computed_value_below_the_print_floor_with_its_return_period_gets_a_note():
    """Cold read 4, user C: '< 0.1%, once in 2,900,000 years §' mixed the print floor with a computed return period;
    a note under the design-life table says the value is computed and below the floor. A bound '< 0.81%' or a
    value above the floor gets none."""
    from rockfrag.report.answer_page import FLOOR_WITH_PERIOD_WORDS, below_floor_with_period

    assert below_floor_with_period([["θmax/α ≥ 0.2", "none", "< 0.1%, once in 2,900,000 years §", "1.4%"]])
    assert not below_floor_with_period([["overturning", "1%", "< 0.81%", "0.28%, once in 18,000 years"]])
    assert not below_floor_with_period([["overturning", "< 0.1%, once in 9 years", "0.28%"]])  # the limit column
    assert "computed" in FLOOR_WITH_PERIOD_WORDS and "print floor" in FLOOR_WITH_PERIOD_WORDS


def test_a_work_cited_with_an_ampersand_is_in_the_references():
    """Cold read 5, default B8: Seyhan & Stewart 2014 and Bazzurro & Cornell 2004 were cited by the methods but left
    out of the references: the pages' text is HTML ('&amp;'), in which the short name was not found."""
    from rockfrag.report.words import references_items

    text = " ".join(item.text for item in references_items("the model of Seyhan &amp; Stewart 2014 (Bazzurro &amp; "
                                                           "Cornell 2004)"))
    assert "Seyhan, E., Stewart, J. P. (2014)" in text and "Bazzurro, P., Cornell, C. A. (2004)" in text
    assert "Shenton, H. W." not in text  # not cited


def test_a_block_less_deep_than_wide_is_said_on_the_summary_to_be_judged_across_its_width_only():
    """Cold read 5, default A: the squat skid (3 m wide, 2 m deep) was judged across its width, b/h 0.75; across its
    depth (b/h 0.5) it is less stable, which only the limitations said. The summary names such a block; a block at
    least as deep as wide is not named."""
    from types import SimpleNamespace

    from rockfrag.report.summary import weaker_direction_words

    skid = SimpleNamespace(name="skid", b=1.5, h=2.0, footprint_area=6.0)
    square = SimpleNamespace(name="square", b=1.5, h=2.0, footprint_area=9.0)
    config = SimpleNamespace(blocks=(skid, square), raw={})
    words = weaker_direction_words(SimpleNamespace(config=config))
    assert "skid (b/h 0.5 across its 2 m depth)" in words, words
    assert "square" not in words and words.startswith("Judged across the width only")
    assert weaker_direction_words(SimpleNamespace(config=SimpleNamespace(blocks=(square,), raw={}))) == ""


def test_the_run_time_says_when_the_simulations_were_reused():
    """Cold read 5, default C15: 'run time 9 s' beside 80,000 simulations read as all of them in 9 s."""
    from rockfrag.report.sections import run_time_line

    reused = run_time_line(9.0, {"cells": 10, "cells_reused": 10, "runs_computed": 0})
    assert "reused from the earlier run are not in it" in reused
    assert "reused" not in run_time_line(9.0, {"cells": 10, "cells_reused": 0, "runs_computed": 100})


def _power_hazard():
    """A hazard curve lambda = 1e-3 (x / 0.2 g)^-2.5 from 0.01 to 10 g."""
    from rockfrag.hazard import HazardCurve

    x = np.geomspace(0.01, 10.0, 400)
    return HazardCurve(x, 1e-3 * (x / 0.2) ** -2.5, "pga", None, "test")


def _life_by_hand(hazard, median: float, beta: float, cap: float, years: float = 50.0) -> float:
    """P in ``years`` of a lognormal fragility over ``hazard``'s drops up to ``cap`` plus lambda(cap) (the bound)."""
    from scipy.stats import norm

    x, frequency = hazard.intensity, hazard.annual_frequency
    mids, drops = np.sqrt(x[1:] * x[:-1]), -np.diff(frequency)
    keep = mids <= cap
    rate = np.sum(drops[keep] * norm.cdf(np.log(mids[keep] / median) / beta)) + frequency[x <= cap][-1]
    return 1 - math.exp(-years * rate)


def _restitution_effect_study(limit: float):
    """A box on clay (its bed reaches the restitution range's upper end) and on rock (it does not: the best-estimate
    run sits at the lower end), overturning judged against ``limit``; the upper-end run on clay lowers the median
    by 10 %. Returns the results and rock's probability in 50 years with its median and with 0.9 times it, each
    integrated here over the hazard curve's drops (independent of rockfrag.fragility.capped_frequency)."""
    from types import SimpleNamespace

    from rockfrag.answer import StateAnswer
    from tests.test_report_answer import _restitution_cube

    cube = _restitution_cube(np.array([[0.728, 0.746, 0.764]]), np.array([[0.728, 0.746, 0.764]]),
                             np.array([[0.4, 0.2, 0.1]]), ["box"])
    for name in ("restitution_target", "member_restitution_target"):
        cube[name].loc[{"soil": "rock"}] = 0.728  # rock's bed reaches none above the range's lower end
    coords = {"soil": ["clay", "rock"], "block": ["box"], "model": ["recommended"], "damage_state": ["overturning"],
              "member": ["restitution_low", "restitution_high"]}
    median = np.array([0.5, 0.6]).reshape(2, 1, 1, 1)
    member = np.array([[0.55, 0.45], [0.6, 0.6]]).T.reshape(2, 2, 1, 1)  # (member, soil, block, state)
    fragility = xr.Dataset({"median": (("soil", "block", "model", "damage_state"), median),
                            "beta": (("soil", "block", "model", "damage_state"), np.full((2, 1, 1, 1), 0.5)),
                            "member_median": (("member", "soil", "block", "damage_state"), member),
                            "credible_max": (("block",), [3.0])}, coords=coords)
    hazard = _power_hazard()

    def life(m):
        return _life_by_hand(hazard, m, 0.5, cap=3.0)

    p_rock, p_shifted = life(0.6), life(0.6 * 0.9)
    soils = []
    for soil, m in (("clay", 0.5), ("rock", 0.6)):
        p = life(m)
        soils.append(SimpleNamespace(soil=soil, states=(StateAnswer("overturning", (), -math.log(1 - p) / 50, p,
                                                                    limit, None),)))
    answer = SimpleNamespace(block="box", soils=tuple(soils), design_life=50.0)
    results = SimpleNamespace(fragility=fragility, cube=cube, answers=[answer], site_hazards=None, hazard=hazard)
    return results, p_rock, p_shifted


def test_a_best_estimate_below_the_middle_of_the_range_says_what_the_missing_side_is_worth():
    """Cold read 5, default B4: "On rock and steel the answering run uses r = 0.728, below the middle of the range,
    0.746" said nothing of how much the left-out side matters. Now the page gives the median's change from the
    best-estimate run to the upper-end run where a bed reached it (clay: 0.5 -> 0.45 g, 10 %), and whether the same
    change on the soils below the middle takes a judged state across its limit."""
    from rockfrag.report.answer_page import curve_reason

    results, p_rock, p_shifted = _restitution_effect_study(limit=0.5)
    assert p_shifted > p_rock  # a lower median: more likely; the limit below straddles them
    text = curve_reason(results, "recommended", "box")
    assert "On rock the best-estimate run uses r = 0.728, below the middle of the range, 0.746." in text, text
    assert ("measured on clay, where the bed reaches r = 0.764: from the best-estimate run to that one the median of "
            "overturning drops by 10%") in text, text
    assert "the same change on rock takes no damage state across its limit, so no verdict changes." in text, text
    straddled, _, _ = _restitution_effect_study(limit=math.sqrt(p_rock * p_shifted))
    text = curve_reason(straddled, "recommended", "box")
    assert "the same change on rock would take overturning on rock across its limit." in text, text


def test_the_high_friction_medians_say_what_they_give_in_the_design_life_and_against_the_limits():
    """Cold read 5, user C6: the friction note gave the clay medians with the friction at the high end (0.98 / 1.5 /
    2.1 g) but not what they mean for the verdict. Now it gives their probability in the design life over the soil's
    hazard, with the largest β of the state's curves on the other soils (clay has none), and says whether each is
    within its limit."""
    from types import SimpleNamespace

    from rockfrag.answer import StateAnswer
    from rockfrag.report import numbers
    from rockfrag.report.answer_page import _friction_high_verdict

    coords = {"soil": ["clay", "sand", "rock"], "block": ["box"], "model": ["recommended"],
              "damage_state": ["overturning"], "member": ["friction_high"]}
    beta = np.array([np.nan, 0.6, 0.45]).reshape(3, 1, 1, 1)  # clay: no curve; sand's β is the largest
    high = np.array([1.2, 3.5, 4.0]).reshape(1, 3, 1, 1)
    fragility = xr.Dataset({"beta": (("soil", "block", "model", "damage_state"), beta),
                            "median": (("soil", "block", "model", "damage_state"), beta * np.nan),
                            "member_median": (("member", "soil", "block", "damage_state"), high),
                            "credible_max": (("block",), [3.0])}, coords=coords)
    hazard = _power_hazard()
    expected = _life_by_hand(hazard, 1.2, 0.6, cap=3.0)

    def text(limit):
        states = (StateAnswer("overturning", (), np.nan, 1e-5, limit, 3.0),)
        answer = SimpleNamespace(block="box", model="recommended", return_periods=(475.0,), design_life=50.0,
                                 soils=tuple(SimpleNamespace(soil=s, states=states) for s in coords["soil"]))
        results = SimpleNamespace(fragility=fragility, site_hazards=None, hazard=hazard)
        return _friction_high_verdict(results, answer, ["clay"], ["overturning"])

    assert 0.001 < expected < 0.05  # printed with its digits, and a limit on either side below is meaningful
    within = text(0.05)
    assert within == (f" In 50 years these medians give {numbers.probability(expected)} for overturning (each with "
                      "the largest β of its state's curves on the other soils, 0.60): within the limits."), within
    assert text(expected / 2).endswith("): above its limit: overturning."), text(expected / 2)


def test_a_block_modelled_per_metre_of_its_length_is_not_said_to_have_a_less_stable_depth():
    """Cold read 7, default B: the summary said 'Judged across the width only, not across a less stable depth: solid
    block with the paper's proportions (b/h 0.059 across its 1 m depth)' while its description says 1 m is the plane
    model per metre of a long block. A block 1 m deep (the plane model's default footprint, 2b x 1 m) is said to be
    per metre of its length, not a weaker direction; a 2 m deep skid still is."""
    from types import SimpleNamespace

    from rockfrag.report.summary import weaker_direction_words

    strip = SimpleNamespace(name="wall", b=3.999, h=8.5, footprint_area=8.0)  # 1.0002 m deep: per metre
    skid = SimpleNamespace(name="skid", b=1.5, h=2.0, footprint_area=6.0)
    words = weaker_direction_words(SimpleNamespace(config=SimpleNamespace(blocks=(strip, skid), raw={})))
    assert words.startswith("Judged across the width only, not across a less stable depth: skid (b/h 0.5"), words
    assert "wall (b/h" not in words and "The wall is computed per metre of a long wall-like block" in words, words
    alone = weaker_direction_words(SimpleNamespace(config=SimpleNamespace(blocks=(strip,), raw={})))
    # cold read 9: the sentence had no verb ("Per metre of a long wall-like block (...): wall.")
    assert alone == ("The wall is computed per metre of a long wall-like block (the plane model; no less stable "
                     "depth)."), alone


def test_a_probability_read_below_the_lowest_level_is_marked_as_the_fit_extrapolated():
    """Cold read 7, default B (cold read 5, C4): the squat block's 475-year values ('3.8%' on clay) are read where
    'no level run this low', and the cell had no mark. A fitted value there carries '*' with a note; a value at a
    level run, 'not reached', a count, a bound from the records and '-' do not."""
    from rockfrag.answer import StateAnswer
    from rockfrag.report.answer_page import BELOW_LEVELS_MARK, BELOW_LEVELS_WORDS, _below_levels_mark

    records = ((0, 44, float("nan")), (0, 44, 0.37), (1, 44, 0.44))  # (reached, of, level read; NaN: none this low)
    row = StateAnswer("slip-0.05", ((0.038,), (0.075,), (0.15,)), 4e-4, 0.021, None, None, records)
    assert _below_levels_mark("3.8%", row, 0) == f"3.8%{BELOW_LEVELS_MARK}"
    assert _below_levels_mark("< 0.1%", row, 0) == f"< 0.1%{BELOW_LEVELS_MARK}"
    assert _below_levels_mark("7.5%", row, 1) == "7.5%"
    for cell in ("not reached", "≈ 0 (0/44)", "≥ 19%", "-"):
        assert _below_levels_mark(cell, row, 0) == cell
    assert BELOW_LEVELS_WORDS.startswith(f"{BELOW_LEVELS_MARK} read at a site intensity below the lowest level run")


def test_a_soil_whose_site_term_lowers_the_reference_intensity_is_not_called_amplified():
    """Cold read 7, default B: the methods' hazard table called rock (Vs30 1,080 m/s) 'amplified' beside site PGAs
    below the reference's (0.24 / 0.32 / 0.47 g against 0.30 / 0.39 / 0.57 g). The word follows the curves at each
    return period: amplified, de-amplified, or both with the return periods (a soft soil's nonlinear term)."""
    from rockfrag.hazard import HazardCurve
    from rockfrag.report.sections import site_term_words
    from rockfrag.site_hazard import SiteHazards

    x = np.geomspace(0.01, 10.0, 400)
    frequency = 1e-3 * (x / 0.2) ** -2.5  # reference: 0.148 / 0.198 / 0.287 g at 475 / 975 / 2,475 years

    def curve(intensity):
        return HazardCurve(intensity, frequency, "pga", None, "test")

    sites = SiteHazards({"stiff": curve(0.8 * x), "soft": curve(1.2 * x), "clay": curve(x * (x / 0.22) ** -0.3)},
                        reference=curve(x), reference_vs30=760.0)
    periods = (475.0, 975.0, 2475.0)
    assert site_term_words(sites, "stiff", periods) == "de-amplified"
    assert site_term_words(sites, "soft", periods) == "amplified"
    # ratio (x / 0.22)^-0.3 at the reference's 0.148 / 0.198 / 0.287 g: 1.13, 1.03, 0.92
    assert site_term_words(sites, "clay", periods) == "amplified at 475 and 975 years, de-amplified at 2,475 years"


def test_the_paper_is_named_on_the_title_page_where_the_title_page_speaks_of_it(small_pipeline):
    """Cold read 5, default C2: page 1 said "the paper's proportions" and "SSI, paper's model" while the paper was
    named only in the methods and references. The title page names it (title, a preprint) where it speaks of it."""
    from rockfrag.models.ssi import PAPER_TITLE
    from rockfrag.report.sections import title_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    text = " ".join(item.text for item in title_items(results))
    assert "paper" in text.replace(PAPER_TITLE, "")  # the small study's title page speaks of it: the test can fail
    assert f"'The paper' on these pages: {PAPER_TITLE}, a preprint" in text, text


def test_the_methods_say_which_damping_ratio_each_foundation_model_runs_with():
    """Cold read 7, user B6: the methods said the recommended model runs 'on ... the soil's damping ratio' (0.05 in
    the soils table) while cube.nc holds its calibrated ratio, 0.158 on both soils. A model with a calibrated ratio
    is said to run with it, with its range; one without keeps the soil's."""
    from rockfrag.report.sections import calibrated_damping, damping_words

    calibrated = np.array([[[np.nan, 0.158]], [[np.nan, 0.0251]]])  # (soil, block, model): ssi none, recommended
    cube = xr.Dataset({"damping_ratio_calibrated": (("soil", "block", "model"), calibrated)},
                      coords={"soil": ["clay", "sand"], "block": ["box"], "model": ["ssi", "recommended"]})
    words = damping_words(cube, "recommended")
    assert "calibrated per block and soil" in words and "not the soil's ξ" in words, words
    assert "0.158" not in words  # issue 36: no calibrated ξ on the client's pages; the appendix gives it
    assert calibrated_damping(cube, "recommended") == "0.0251 to 0.158"
    assert damping_words(cube, "ssi") == "the soil's damping ratio" and calibrated_damping(cube, "ssi") == ""
    single = cube.copy(deep=True)
    single["damping_ratio_calibrated"].loc[{"model": "recommended"}] = 0.158
    assert calibrated_damping(single, "recommended") == "0.158"


def test_an_answer_page_says_what_flying_is_where_many_records_fly(monkeypatch):
    """Cold read 7 (user B1): 38 of 44 records made the enclosure 'fly' on sand at the 2,475-year level while 3
    reached θmax/α 0.2, and nothing said what the hops are or whether they move a verdict. Where more than a quarter
    of the records fly, a note says they are the bed's rebound (not a damage state), likely high (radiation damping),
    and compares the overturning median with the rigid base's, which cannot hop."""
    from types import SimpleNamespace

    from rockfrag.report import answer_page

    def tallies(cube, block, model, soil, intensities, scale):
        flies = {"clay": 0, "sand": 38}[soil]
        return [{motion: 0 for motion in answer_page.MOTIONS} | {"flies": flies, "at rest": 44 - flies}]

    monkeypatch.setattr(answer_page, "motion_tallies", tallies)
    median = xr.DataArray(np.array([[[[2.0]], [[1.85]]], [[[2.0]], [[1.85]]]]),
                          dims=("soil", "model", "block", "damage_state"), attrs={"units": "g"},
                          coords={"soil": ["clay", "sand"], "model": ["recommended", "housner"], "block": ["box"],
                                  "damage_state": ["overturning"]})
    results = SimpleNamespace(cube=xr.Dataset(), fragility=xr.Dataset({"median": median}))
    answer = SimpleNamespace(block="box", model="recommended", unit="g", intensities=(0.5,),
                             soils=[SimpleNamespace(soil="clay", intensities=(0.5,)),
                                    SimpleNamespace(soil="sand", intensities=(0.5,))])
    words = answer_page.flight_words(results, answer, 1.0)
    assert words.startswith("'Flies' on sand: after an impact the block rebounds"), words
    assert "Gazetas 1991" in words and "not a damage state" in words
    assert "the overturning median, 2.00 g, lies 8% above the rigid base's 1.85 g" in words
    monkeypatch.setattr(answer_page, "motion_tallies", lambda *args: [{m: 0 for m in answer_page.MOTIONS} |
                                                                       {"at rest": 44}])
    assert answer_page.flight_words(results, answer, 1.0) == ""
    # cold read 12, default B2: a soil with a few flights is named beside the one with many
    monkeypatch.setattr(answer_page, "motion_tallies", lambda cube, block, model, soil, *args: [
        {m: 0 for m in answer_page.MOTIONS} | {"flies": {"clay": 7, "sand": 38}[soil]}])
    assert answer_page.flight_words(results, answer, 1.0).startswith("'Flies' on clay and sand: after an impact")


def test_a_sliding_blocks_lift_off_by_soil_is_explained():
    """Cold read 7 (default B): the squat skid lifted off on sand and rock, on clay in 2 of 44 and never on gravel or
    steel, against the soils' stiffness order, with no word why. The page says what it goes with: the bed damping
    calibrated per soil (gravel's and steel's 1.6 times) and the lowest friction (clay)."""
    from types import SimpleNamespace

    from rockfrag.report.answer_page import lift_off_by_soil_words

    names = ["clay", "sand", "gravel", "rock", "steel"]
    top = {"clay": 0.05, "sand": 0.48, "gravel": 0.0, "rock": 0.8, "steel": 0.0}
    fraction = np.array([[[[[0.0, top[s]]]]] for s in names])  # (soil, model, block, state, level)
    fragility = xr.Dataset({"empirical_fraction": (("soil", "model", "block", "damage_state", "im_level"), fraction)},
                           coords={"soil": names, "model": ["recommended"], "block": ["skid"],
                                   "damage_state": ["uplift"]})
    xi = {"clay": 0.0995, "sand": 0.0995, "gravel": 0.1575, "rock": 0.0995, "steel": 0.1575}
    cube = xr.Dataset({"damping_ratio_calibrated": (("soil", "model", "block"),
                                                    np.array([[[xi[s]]] for s in names]))},
                      coords={"soil": names, "model": ["recommended"], "block": ["skid"]})
    soils = [SimpleNamespace(name=s, friction_static=mu) for s, mu in zip(names, (0.35, 0.45, 0.55, 0.7, 0.5))]
    results = SimpleNamespace(fragility=fragility, cube=cube, config=SimpleNamespace(soils=soils))
    answer = SimpleNamespace(model="recommended", block="skid")
    words = lift_off_by_soil_words(results, answer, soils)
    assert "lifts off on sand and rock (at most 48% and 80% of the records" in words, words
    assert "hardly on clay (its friction, μ_s 0.35, is the lowest" in words
    assert "never on gravel and steel, whose bed damping, set per soil by its calibration to the restitution, is " \
        "1.6 times" in words
    every = xr.Dataset({"empirical_fraction": fragility.empirical_fraction * 0 + 1.0})
    assert lift_off_by_soil_words(SimpleNamespace(fragility=every, cube=cube, config=results.config), answer,
                                  soils) == ""


def test_a_value_under_the_floor_without_a_curve_has_no_return_period(small_pipeline):
    """Cold read 8, user B2: '< 0.1%, once in 7,800,000 years' for overturning on clay, where no record reached the
    state near the site and no curve was fitted: the return period read as spurious precision. Without a curve the
    cell says '< 0.1%' alone; a fitted curve's value under the floor keeps its return period."""
    import dataclasses

    from rockfrag.report.answer_page import answer_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    answer = results.answers[0]
    soil = answer.soils[0]
    index = next(i for i, row in enumerate(soil.states) if row.state == "overturning")
    tiny = dataclasses.replace(soil.states[index], probability_in_life=1e-5, annual_frequency=2e-7,
                               not_reached_below=None, below_lowest=None)
    states = list(soil.states)
    states[index] = tiny
    soils = list(answer.soils)
    soils[0] = dataclasses.replace(soil, states=type(soil.states)(states))
    answer = dataclasses.replace(answer, soils=type(answer.soils)(soils))

    def cell(median):
        results.fragility["median"].loc[dict(model=answer.model, block=answer.block, soil=soil.soil,
                                             damage_state="overturning")] = median
        items = answer_items(results, answer)
        life = next(i for i, item in enumerate(items) if item.kind == "heading" and item.text.startswith("In the"))
        table = next(item for item in items[life:] if item.kind == "table")
        row = next(row for row in table.rows if row[0] == "overturning")
        return row[table.header.index(f"on {soil.soil}")]

    assert cell(np.nan).startswith("< 0.1%") and "once in" not in cell(np.nan)
    assert "< 0.1%, once in 5,000,000 years" in cell(9.0)


def test_the_summary_says_how_many_governing_medians_rest_on_scaled_records():
    """Cold read 8, user B6: both 'no action' verdicts rested on medians (1.56 g, 2.00 g) above the largest unscaled
    0.78 g, which only the fitted table's dagger said. The summary's note counts them."""
    from types import SimpleNamespace

    from rockfrag.report import summary

    def soil(name, state):
        row = SimpleNamespace(state=state, limit=0.1, probability_in_life=0.01, exceeds=False, not_reached_below=None)
        return SimpleNamespace(soil=name, states=[row])

    median = xr.DataArray([[[[1.56]]], [[[0.5]]]], dims=("soil", "model", "block", "damage_state"),
                          coords={"soil": ["clay", "sand"], "model": ["recommended"], "block": ["box"],
                                  "damage_state": ["slip-0.30"]}, attrs={"units": "g"})
    answer = SimpleNamespace(block="box", model="recommended", unit="g",
                             soils=[soil("clay", "slip-0.30"), soil("sand", "slip-0.30")])
    results = SimpleNamespace(fragility=xr.Dataset({"median": median}), answers=[answer],
                              largest_recorded={"box": 0.78})
    assert summary.scaled_medians_words(results) == (
        "1 of 2 governing medians exceed the largest recorded intensity, 0.78 g (extrapolation by scaling, † in the "
        "fitted table).")
    results.largest_recorded = {"box": 2.0}
    assert summary.scaled_medians_words(results) == ""


def test_the_title_page_lists_blocks_and_models_without_parentheses_inside_parentheses(small_pipeline):
    """Cold read 8, user C2: "1 block (enclosure E-1 (a solid block 1.2 m x 3.0 m, 4.5 t)) and 3 models (Housner
    (rigid base); ...)". The run's size names its blocks and models after colons; no parenthesis opens inside
    another."""
    from rockfrag.report.sections import models_of, title_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    first = title_items(results)[0].text
    depth, deepest = 0, 0
    for character in first:
        depth += {"(": 1, ")": -1}.get(character, 0)
        deepest = max(deepest, depth)
    assert depth == 0 and deepest == 1, first
    assert any("(" in model.label for model in models_of(results.cube)), "the test needs a label with parentheses"
    assert " models: " in first and (" block: " in first or " blocks: " in first), first


def test_a_lift_off_well_below_g_tan_alpha_is_explained_by_the_beds_rocking_mode():
    """Cold read 8, default C7: the cabinet lifted off at 0.097 g on clay, half its rigid-base g·tanα = 0.20 g, and
    the page said only "earlier on a compliant bed". The answer page names the soils below 0.8 g·tanα with their
    shares, the bed's rocking frequency on each (rockfrag's closed form, bed_frequencies) and the records' band,
    and bounds the static part, h·δ/b² (two-spring bed: (k b² − m g h) θ = m a h, lift at θ = δ/b)."""
    from types import SimpleNamespace

    import xarray as xr

    from rockfrag.config import load_study
    from rockfrag.report.answer_page import EARLY_LIFT, bed_frequencies, early_lift_words
    from tests.helpers import ROOT

    config = load_study(ROOT / "pipeline" / "defaults.toml")
    soils = [soil.name for soil in config.soils]
    block = next(block for block in config.blocks if block.name == "slender-cabinet")
    rigid = block.b / block.h
    assert abs(rigid - 0.2) < 1e-9 and config.calibrates_bed
    medians = xr.DataArray([[[[0.097, 0.099, 0.12, 0.17, 0.24]]]], dims=("model", "block", "damage_state", "soil"),
                           coords={"model": ["recommended"], "block": [block.name], "damage_state": ["uplift"],
                                   "soil": soils}, attrs={"units": "9.80665 m s-2"})
    results = SimpleNamespace(fragility=xr.Dataset({"median": medians}), config=config, showcase=None,
                              cube=xr.Dataset(attrs={"intensity_measure": "pga"}))
    answer = SimpleNamespace(model="recommended", block=block.name, unit="g")
    words = early_lift_words(results, answer)
    assert words.startswith("Below the rigid base's g·tanα = 0.20 g: this block lifts off at a median of 0.097 g on "
                            "clay, 0.099 g on sand and 0.12 g on gravel (0.49, 0.50 and 0.60 times g·tanα)"), words
    assert "rock" not in words.split("(rocking")[0].replace("rocks", "")  # 0.17 g is 0.85 of it: not early
    for soil in config.soils[:3]:
        rocking = bed_frequencies(config, block, soil)[1]
        assert f"{soil.name} {numbers.two_figures(rocking)} Hz, {numbers.two_figures(1 / rocking)} s" in words
    clay = config.soils[0]
    static = block.h * bed_frequencies(config, block, clay)[2] / block.b ** 2
    assert f"{numbers.two_figures(100 * static)}% at most" in words and static < 0.02
    # cold read 12, default B1: a median below the lowest level run is the fit's extrapolation, and says so
    fraction = xr.DataArray(np.array([24, 22, 15, 2, 0])[None, :, None, None, None] / 44.0,
                            dims=("im_level", "soil", "block", "model", "damage_state"),
                            coords={"soil": soils, "block": [block.name], "model": ["recommended"],
                                    "damage_state": ["uplift"]})
    results.fragility = xr.Dataset({"median": medians, "empirical_fraction": fraction, "n_records": 44,
                                    "studied_im_min": ("block", [0.0995])}, coords={"block": [block.name]})
    words = early_lift_words(results, answer)
    assert "0.097 g on clay (*), 0.099 g on sand (*) and 0.12 g on gravel (0.49" in words, words
    assert words.endswith("(*) below the lowest level run, 0.0995 g: the fit's extrapolation, where 24 of 44 records "
                          "on clay and 22 of 44 on sand already lift off (the fitted table marks such a median).")
    results.fragility = xr.Dataset({"median": medians})
    medians[:] = [[[[0.2, 0.2, 0.12, 0.2, 0.2]]]]  # an early dip below its neighbours: bed_resonance_words' case
    assert 0.12 < EARLY_LIFT * rigid and early_lift_words(results, answer) == ""
    medians[:] = [[[[0.19, 0.19, 0.19, 0.2, 0.21]]]]
    assert early_lift_words(results, answer) == ""


def test_a_friction_just_above_b_over_h_says_what_the_low_friction_run_does():
    """Cold read 9, user B2: sand's μ_s 0.45 is 12.5% above the enclosure's b/h 0.40, inside the sample's friction
    factor 1.2; its low-friction run (μ_s 0.375) slides first, and its rocking median moved from 0.97 g to 2.97 g
    while the page spoke of clay's friction only. Such a soil gets a sentence with the medians that move; clay
    (below b/h: slides_first_words' case) and a soil far above b/h do not."""
    from types import SimpleNamespace

    import xarray as xr

    from rockfrag.config import load_study
    from rockfrag.report.answer_page import friction_margin_words
    from rockfrag.report.summary import short_names
    from tests.helpers import ROOT

    config = load_study(ROOT / "studies" / "user-site.toml")
    assert [soil.name for soil in config.soils] == ["clay", "sand"] and config.design.friction_factor == 1.2
    states = ["uplift", "slip-0.05", "slip-0.30", "rocking-0.2", "rocking-0.5", "overturning"]
    central = [[[[0.31, 0.69, 1.56, np.nan, np.nan, np.nan], [0.36, 0.98, 1.77, 0.97, 1.44, 2.0]]]]
    low = [[[[0.33, 0.60, 1.40, np.nan, np.nan, np.nan]], [[0.43, 0.74, 1.70, 2.97, np.nan, np.nan]]]]
    fragility = xr.Dataset(
        {"median": (("model", "block", "soil", "damage_state"), central, {"units": "9.80665 m s-2"}),
         "member_median": (("member", "soil", "block", "damage_state"), low)},
        coords={"model": ["recommended"], "block": ["enclosure"], "soil": ["clay", "sand"], "damage_state": states,
                "member": ["friction_low"]})
    cube = xr.Dataset(coords={"block": ["enclosure"], "block_b": ("block", [0.6]), "block_h": ("block", [1.5])})
    results = SimpleNamespace(fragility=fragility, cube=cube, config=config)
    words = friction_margin_words(results, SimpleNamespace(model="recommended", block="enclosure", unit="g"))
    assert words.startswith("On sand the base friction (μ_s 0.45) is only 13% above this block's b/h = 0.40: at the "
                            "low end of its range (μ_s 0.375, a sensitivity run) the block slides before it can "
                            "rock"), words
    short = short_names(results)
    assert f"{short['rocking-0.2']} from 0.97 g to 3.0 g" in words
    assert f"{short['slip-0.05']} from 0.98 g to 0.74 g" in words
    assert f"{short['rocking-0.5']} and {short['overturning']} lose their medians" in words
    assert short["slip-0.30"] not in words  # 1.77 to 1.70 g: under 10%
    assert "clay" not in words
    fragility["member_median"][:] = fragility["median"].values.transpose(0, 2, 1, 3)  # the low run moves nothing
    assert friction_margin_words(results, SimpleNamespace(model="recommended", block="enclosure", unit="g")) == ""


def test_a_state_whose_value_is_mostly_the_bound_above_the_cap_does_not_govern_a_computed_one(small_pipeline):
    """Cold read 9 (default text B1): overturning governed the paper block on gravel at 4.7% of its 1% limit, 93% of
    it the bound for the shaking above 3 g (every stronger motion counted as overturning), over a computed slip at
    3.0% of its limit; the summary printed three '≈ 0' and hid the slip row. Such a value ranks as a bound."""
    from rockfrag.answer import StateAnswer
    from rockfrag.report.summary import BOUND_SHARE, governing

    def state(name, probability, limit, share):
        return StateAnswer(name, ((0.0, np.nan, np.nan),) * 3, probability, probability, limit, None,
                           above_cap_share=share)

    slip = state("slip-0.30", 0.0030, 0.10, 0.0)
    bounded = state("overturning", 0.00047, 0.01, 0.93)
    soil = SimpleNamespace(states=[slip, bounded])
    assert governing(soil) is slip
    computed = state("overturning", 0.00047, 0.01, 0.2)
    assert governing(SimpleNamespace(states=[slip, computed])) is computed  # mostly computed: nearer its limit
    alone = SimpleNamespace(states=[bounded])
    assert governing(alone) is bounded and BOUND_SHARE == 0.5  # only bounds: the nearest bound governs
    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    shares = [row.above_cap_share for answer in results.answers for soil in answer.soils for row in soil.states]
    assert shares and all(0.0 <= share <= 1.0 + 1e-9 for share in shares) and max(shares) > 0


def test_a_lift_off_above_g_tan_alpha_on_a_bed_is_explained_by_the_uplift_size():
    """Cold read 12, default B3: the cabinet lifted off at 0.243 g on the steel base, 22% above the rigid base's
    0.20 g, against "earlier on a compliant bed". At the first level above g·tanα most records lift a corner but
    few by the uplift size (1 mm) that a bed's lift needs: the page counts both."""
    from types import SimpleNamespace

    import xarray as xr

    from rockfrag.config import load_study
    from rockfrag.report.answer_page import late_lift_words
    from tests.helpers import ROOT

    config = load_study(ROOT / "pipeline" / "defaults.toml")
    soils = [soil.name for soil in config.soils]
    block = "slender-cabinet"
    medians = xr.DataArray([[[[0.097, 0.099, 0.12, 0.17, 0.243]]]], dims=("model", "block", "damage_state", "soil"),
                           coords={"model": ["recommended"], "block": [block], "damage_state": ["uplift"],
                                   "soil": soils}, attrs={"units": "9.80665 m s-2"})
    levels = np.array([0.168, 0.218, 0.284])
    lift = np.zeros((44, 3, len(soils), 1, 1))
    lift[:33, 1, -1] = 0.5e-3  # steel at 0.218 g: 33 corners rose, 21 of them short of 1 mm
    lift[:12, 1, -1] = 2e-3
    cube = xr.Dataset({"peak_uplift": (("record", "im_level", "soil", "block", "model"), lift),
                       "intensity": (("block", "im_level"), levels[None, :], {"units": "9.80665 m s-2"})},
                      coords={"soil": soils, "block": [block], "model": ["recommended"]},
                      attrs={"intensity_measure": "pga"})
    results = SimpleNamespace(fragility=xr.Dataset({"median": medians}), config=config, cube=cube)
    answer = SimpleNamespace(model="recommended", block=block, unit="g")
    assert late_lift_words(results, answer) == (
        "Above the rigid base's g·tanα = 0.20 g: this block lifts off on steel at a median of 0.24 g; at 0.22 g a "
        "corner of 33 of 44 records rose, of 12 by the uplift size. On a bed a lift counts only once a base corner "
        "rises the uplift size (1 mm here), where the rigid base counts any pivoting: the block first rocks through "
        "angles too small for that (a tilt on the bed), so its lift-off is counted later.")
    medians[:] = [[[[0.097, 0.099, 0.12, 0.17, 0.21]]]]  # within 10% of g·tanα: nothing to explain
    assert late_lift_words(results, answer) == ""
