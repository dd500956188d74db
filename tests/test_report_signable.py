"""Findings of the cold reads that kept the default report from being signed (issue 36, /work/tmp/read1 findings 6,
7, 9, 14, 16 and 21), one test each, each shown to fail on the old output: the slip states and overturning, the
probability cells of a state without a curve, one meaning of '< X', the model-form dispersion's source, the soils'
source, the fitted-functions table, the choice of PGA, the applicability pages and the tool words."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
import xarray as xr

from rockfrag.answer import StateAnswer, nested, nested_families
from tests.helpers import ROOT, pipeline_results

NAN3 = (np.nan, np.nan, np.nan)


def _row(state, p_life, at=0.1, limit=None, **changes) -> StateAnswer:
    values = dict(state=state, at_return_periods=((at, np.nan, np.nan),) * 3, annual_frequency=p_life / 50,
                  probability_in_life=p_life, limit=limit, not_reached_below=None)
    values.update(changes)
    return StateAnswer(**values)


def _states() -> xr.Dataset:
    """A fragility's damage-state coordinates as the fits write them (most severe last within each family)."""
    names = ["uplift", "slip-0.05", "slip-0.30", "rocking-0.2", "rocking-0.5", "overturning"]
    edps = ["uplifted", "peak_slip", "peak_slip", "peak_angle_ratio", "peak_angle_ratio", "overturned"]
    return xr.Dataset(coords={"damage_state": names, "damage_state_edp": ("damage_state", edps)})


def test_a_slip_state_is_never_printed_less_likely_than_overturning():
    """Finding 6: the slender cabinet's P(slip ≥ 0.30 m) printed below P(overturning) (17% vs 18%), though the fits
    count a record that overturns as beyond every state, the slip states included. The answers nest overturning
    under the slip states; a slip state of a tied base (no value) stays unknown; uplift is not raised by a slip state
    (a block can slide without lifting off)."""
    rows = [_row("uplift", 0.01, at=0.02), _row("slip-0.05", 0.17, at=0.17), _row("slip-0.30", 0.17, at=0.17),
            _row("rocking-0.2", 0.30, at=0.3), _row("rocking-0.5", 0.20, at=0.2), _row("overturning", 0.18, at=0.18)]
    out = {row.state: row for row in nested(rows, nested_families(_states()))}
    for state in ("slip-0.05", "slip-0.30"):
        assert out[state].probability_in_life == pytest.approx(0.18)
        assert out[state].at_return_periods[0][0] == pytest.approx(0.18)
    assert out["uplift"].probability_in_life == pytest.approx(0.30)  # the rocking family: its own nesting
    tied = [_row(s.state, s.probability_in_life) if not s.state.startswith("slip") else
            _row(s.state, np.nan, at=np.nan) for s in rows]
    out = {row.state: row for row in nested(tied, nested_families(_states()))}
    assert math.isnan(out["slip-0.30"].probability_in_life) and math.isnan(out["slip-0.05"].probability_in_life)


def test_the_answers_say_a_slip_state_counts_overturning(small_pipeline):
    """Finding 6, said where it is printed: the answers' slip states read 'slip ≥ 0.30 m or overturning', and the
    reading page states the two families instead of 'a milder state is never less likely' across them."""
    from rockfrag.report.answer_page import reading_items
    from rockfrag.report.summary import short_names

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    short = short_names(results)
    assert short["slip-0.30"] == "slip ≥ 0.30 m or overturning" and short["overturning"] == "overturning"
    text = " ".join(item.text for item in reading_items(results))
    assert "within its family" in text and "never less likely than overturning" in text
    assert "so a milder state is never less likely than a more severe one." not in text


def test_a_state_without_a_curve_prints_the_records_share_not_zero_percent():
    """The default report printed '0%' at a return period for states whose median lies above the credible cap
    (no curve: the records' fraction at the level, none of 44): a client reads it as impossible. Then it printed
    the count, '0 of 44', which cold read 9 read as a count in a probability column. It prints the share, about
    zero: '≈ 0 (0/44)'; a fitted curve's value below 0.1% stays '< 0.1%'."""
    from rockfrag.report.summary import p_at_return_period

    no_curve = _row("overturning", 4e-4, at=0.0, records=((0, 44, 0.35),) * 3)
    assert [p_at_return_period(no_curve, i, (0.35, 0.47, 0.67)) for i in range(3)] == ["≈ 0 (0/44)"] * 3
    fitted = _row("overturning", 4e-4, at=2e-5, records=((0, 44, 0.35),) * 3)
    assert p_at_return_period(fitted, 0, (0.35, 0.47, 0.67)) == "< 0.1%"


def test_one_meaning_of_a_bound_on_the_summary_and_the_answer_pages(small_pipeline):
    """The reading page said "'< X': no record reached the state up to the largest intensity recorded", the summary
    'up to the credible cap' (the limit the answers use): one sentence now, on both, with the policy that the pages
    print bounds and nested values while the result tables keep each curve's own fit (finding 8)."""
    from rockfrag.report.answer_page import reading_items
    from rockfrag.report.summary import BOUND_POLICY, BOUND_WORDS, summary_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    reading = " ".join(item.text for item in reading_items(results))
    summary = " ".join(item.text for item in summary_items(results))
    assert BOUND_WORDS in reading and BOUND_WORDS in summary and BOUND_POLICY in reading
    for text in (reading, summary):
        assert "up to the largest intensity recorded" not in text
        assert text.count("'< X':") == 1


def test_the_model_form_dispersion_names_its_rating_and_value(small_pipeline):
    """The methods printed 'Model-form dispersion: , FEMA P-695's rating' (an attribute the file does not keep).
    Expected: the rating the study gives (config) and its β from fragility.nc's beta_form (0 where a reference)."""
    from rockfrag.fragility import FORM_RATINGS
    from rockfrag.report.sections import model_form_words

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    fragility = results.fragility.copy()
    fragility["beta_form"] = xr.full_like(fragility["beta"], FORM_RATINGS["fair"]).where(
        fragility.model == "ssi", 0.0)
    text = model_form_words(results.config, fragility)
    assert results.config.model_quality == "fair"
    assert text.startswith("Model-form dispersion β 0.35: FEMA P695's rating 'fair'") and ": ," not in text
    for rating, value in FORM_RATINGS.items():
        assert f"{rating} {value:.2f}" in text


def test_the_soils_source_says_what_the_paper_states_and_what_it_does_not(small_pipeline):
    """Finding 9: the soils' moduli came from 'the paper's Table 1', an unsourced preprint, said as if a reference.
    The methods say they are the paper's stated representative values, that it cites no source and is a preprint,
    and that a site investigation replaces them; the damping ratio is said to be a choice within the paper's range."""
    from rockfrag.report.sections import sources_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    bullet = next(item.text for item in sources_items(results) if item.text.startswith("Soil moduli"))
    for words in ("the values the paper states", "cites no source", "preprint (not peer-reviewed)",
                  "site investigation", "not a measured value"):
        assert words in bullet, words
    damping = {float(v) for v in results.cube.soil_damping_ratio.values}
    assert f"Damping ratio {100 * damping.pop():g}% of each" in bullet


def test_the_fitted_functions_table_has_every_state_and_no_row_of_dashes(small_pipeline):
    """Finding 14: 90 rows, 75% '- / -', and only θmax/α ≥ 0.5 and overturning while the answers use uplift, slip and
    θmax/α ≥ 0.2. Every state is a column; no row is all dashes; every finite median of fragility.nc is in it."""
    from rockfrag.report.adapters import block_name, models_of, short_label
    from rockfrag.report.sections import fitted_items
    from rockfrag.report.summary import short_names

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    table = next(item for item in fitted_items(results) if item.kind == "table")
    short = short_names(results)
    assert table.header == ["model", "soil", *short.values()]
    fragility = results.fragility
    scale = 1.0  # the small study's medians are in g
    block, seen, printed = None, 0, set()
    names = {block_name(results.config, b): str(b) for b in fragility.block.values}
    labels = {short_label(m): m.name for m in models_of(fragility)}
    for row in table.rows:
        if row[0] in names and not any(row[1:]):
            block = names[row[0]]
            continue
        cells = row[2:]
        assert any(cell != "-" for cell in cells), row
        assert (block, row[0], tuple(cells)) not in printed, row  # soils with the same curves share one row
        printed.add((block, row[0], tuple(cells)))
        soils = [fragility.soil.values[0]] if row[1] == "(any)" else row[1].split(", ")
        for soil in soils:
            for state, text in zip(short, cells):
                median = float(fragility["median"].sel(model=labels[row[0]], block=block, soil=soil,
                                                       damage_state=state)) * scale
                assert (text == "-") == (not np.isfinite(median)), (row, state)
                if np.isfinite(median):
                    assert text.split(" / ")[0].rstrip("*†‡") == f"{median:#.3g}"  # trailing zeros (cold read 5)
                    seen += 1
    finite = int(np.isfinite(fragility["median"]).sum())
    assert 0 < seen <= finite


def _efficiency(pga: float, pgv: float, p_pulse: float) -> xr.Dataset:
    measures = ["pga", "pgv"]
    shape = (1, 1, 1, 2)
    dims = ("soil", "block", "model", "measure")
    coords = {"soil": ["rock"], "block": ["slender"], "model": ["recommended"], "measure": measures}
    return xr.Dataset({"dispersion": (dims, np.array([pga, pgv]).reshape(shape)),
                       "p_pulse_period": (dims, np.array([p_pulse, 0.5]).reshape(shape))},
                      coords=coords, attrs={"study_measure": "pga"})


def test_the_efficiency_page_says_why_pga_and_what_it_costs():
    """Finding 16: PGV scattered less than PGA (0.28 vs 0.43 for the slender block) and PGA failed the sufficiency
    test on pulse period, yet nothing said why the curves are in PGA. The caption names the hazard's measure as the
    reason, the better measure with both dispersions (as the bars draw them) and the bias the failed test leaves."""
    from rockfrag.report import measure_choice_words

    text = measure_choice_words(_efficiency(0.43, 0.28, 0.001), {"slender": "slender block"})
    assert "because the site's hazard is" in text
    assert "PGV for the slender block (0.28 against 0.43)" in text
    assert "fails the sufficiency test" in text and "biased" in text
    calm = measure_choice_words(_efficiency(0.20, 0.28, 0.5), {"slender": "slender block"})
    assert "scatters less" not in calm and "fails the sufficiency" not in calm


def test_the_applicability_pages_say_what_their_ratio_measures(small_pipeline):
    """Finding 7: the study's page gave the paper's block on steel a ratio of 0.01 (the recommended model's block
    slides there: kinetic friction 0.4 below tan α 0.471) and the sweep about 2 at the same stiffness, unexplained.
    The captions say the study's runs slide and are calibrated while the sweep ties the base and leaves the damping
    uncalibrated; the sweep's claim is checked here: the tensionless bed at the sweep's damping keeps more rocking
    speed at an impact than Housner's r on the stiffest ground, for every default block."""
    from rockfrag.config import load_study
    from rockfrag.models.restitution import free_rocking_restitution
    from rockfrag.report import CAPTIONS, SWEEP_NEXT, sweep_words
    from rockfrag.soils import interface_stiffness

    assert "slides instead of rocking" in CAPTIONS["applicability"] and "differ by design" in SWEEP_NEXT
    applicability = xr.open_dataset(small_pipeline.output / "applicability.nc")
    words = sweep_words(applicability)
    xi = float(applicability.attrs["damping_ratio"])
    assert f"{100 * xi:g}% of critical damping" in words and "ties the base" in words
    assert "tensionless bed" not in words  # the small study's sweep runs the paper's model only
    assert "tensionless bed" in sweep_words(applicability.assign_coords(model=["winkler"]))
    for block in load_study().blocks:
        k = interface_stiffness(float(applicability.shear_modulus.max()), block.E_b, block.footprint_area,
                                block.soil_depth)
        housner = 1 - 1.5 * math.sin(math.atan(block.b / block.h)) ** 2
        assert free_rocking_restitution(block, k, "continuous", xi) > housner, block.name


FORBIDDEN = ("record-cells", "resurrection", "shipped defaults", "β_parameters", "β_model", "study file, else",
             ": , ")
"""Tool words a cold reader found in the client's pages (finding 21), and the empty value of a missing attribute."""


def test_no_client_page_or_caption_speaks_the_tools_words(small_pipeline):
    """Finding 21: "shipped defaults", "record-cells", "resurrection" and variable names stood in the methods,
    captions, glossary and answer pages. The appendix 'How to reproduce this report' may name the defaults."""
    from rockfrag.report import build_plan

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    found = {}
    for page in build_plan(results):
        if page.section == "How to reproduce this report":
            continue
        text = re.sub(r"<[^>]+>", " ", page.html or "") + " " + (page.caption or "")
        if "How to reproduce this report" in page.also:  # the appendix starts on this page: read what precedes it
            text = text[:text.index("How to reproduce this report")]
        hits = [word for word in FORBIDDEN if word in text]
        if hits:
            found[page.title] = hits
    assert found == {}


def test_the_showcase_draws_the_rise_of_the_base_up_and_names_what_rises(small_pipeline):
    """Finding 18: the right column said 'vertical displacement Δy from rest (up +, settlement −)' but drew
    y - y_static, which the models write positive down (a settlement): a block rocking about an edge lifts its base
    centre, drawn as 50-70 mm of 'settlement' on gravel. The line drawn is -(y - y_static) in mm, and the title and
    caption say which point it is; the θ title says whether the rigid base differs by soil (finding 20)."""
    import matplotlib.pyplot as plt

    from rockfrag.report import CAPTIONS
    from rockfrag.report.figures import showcase_response_page

    showcase = xr.open_dataset(small_pipeline.output / "showcase.nc")
    figure = showcase_response_page(showcase, "")
    drawn = [np.asarray(line.get_ydata(), float) for axis in figure.axes for line in axis.get_lines()
             if axis.get_ylabel() == "Δy [mm]" and np.asarray(line.get_ydata()).size == showcase.time.size]
    expected = [-1000 * np.asarray(row, float) for row in showcase.settlement.values if np.isfinite(row).any()]
    assert drawn and len(drawn) == len(expected)
    for line in drawn:
        assert any(np.allclose(line, want, equal_nan=True) for want in expected)
    titles = " ".join(axis.get_title() for axis in figure.axes)
    assert "up +" in titles and "base centre" in titles and "settlement −" not in titles
    rigid = [str(m) for m in showcase.case_model.values if str(m) == "housner"]
    per_soil = any(str(m) == "housner" and str(s) for m, s in zip(showcase.case_model.values,
                                                                   showcase.case_soil.values))
    assert rigid and ("drawn per soil" in titles) == per_soil
    assert "base's centre" in CAPTIONS["showcase-response"] and "up +" in CAPTIONS["showcase-response"]
    plt.close(figure)


def test_the_methods_say_how_each_soils_site_hazard_is_made(small_pipeline):
    """Finding 2: the amplification of the example hazard to each soil's site was only an appendix key. The methods
    name the site term and its references, and tabulate each soil's Vs30 and site class from the study."""
    from rockfrag.report.sections import site_hazard_items
    from rockfrag.report.words import REFERENCES

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    items = site_hazard_items(results)
    text = items[0].text
    for work in ("Boore et al. 2014", "Seyhan & Stewart 2014", "Bazzurro & Cornell 2004"):
        assert work in text and work in REFERENCES, work
    assert f"Vs30 {results.config.reference_vs30:,.0f}" in text
    rows = {row[0]: row for row in items[1].rows}
    for soil in results.config.soils:
        assert rows[soil.name][1] == f"{soil.vs30:,.0f}" and rows[soil.name][2].split(" / ")[0] == soil.site_class
    # cold read 8, user C12: a European site's engineer reads Eurocode 8 ground types beside the ASCE classes
    assert items[1].header[2] == "site class: ASCE 7 / EC8" and "EN 1998-1 Table 3.1" in text
    assert rows["sand"][2] == "D / C"  # Vs30 260 m/s: ASCE 7 D (180-360), EC8 C (180-360)


def test_the_limitations_give_each_blocks_depth_and_density_and_speak_of_cranes_only_for_one(small_pipeline):
    """Finding 15: the slender and squat blocks' depth and density were nowhere. The planar-model table gives the
    depth (footprint area over 2b) and the density of a solid block of that mass, from the study's blocks. A study
    without a crane-like block (the small study, the user-site study) no longer reads the crane paragraph; a study
    without a steel base no longer reads the steel slip coefficient."""
    from rockfrag.report.sections import WHAT_A_CRANE_ADDS, limitations_items, sources_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    items = limitations_items(results)
    table = next(item for item in items if item.kind == "table" and "density [kg/m³]" in item.header)
    for block, row in zip(results.config.blocks, table.rows):
        area = block.footprint_area
        depth = area / (2 * block.b)
        assert row[3].removesuffix(" (per metre of length)") == f"{depth:.3g}"
        assert row[3].endswith("(per metre of length)") == (abs(depth - 1.0) <= 0.01), row  # the plane model's 1 m
        assert row[4] == f"{block.mass / (area * 2 * block.h):,.0f}"
    assert WHAT_A_CRANE_ADDS not in [item.text for item in items]
    assert "AISC" not in " ".join(item.text for item in sources_items(results))


def test_the_summary_legend_names_only_the_actions_it_uses(small_pipeline):
    """Finding 27: the legend defined 'Specialist check' and 'Rocking only' where no row used them."""
    from rockfrag.report.summary import summary_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    items = summary_items(results)
    table = next(item for item in items if item.kind == "table")
    legend = items[items.index(table) + 1].text
    actions = " ".join(row[1] for row in table.rows)
    for key, words in (("anchor or restrain", "'Anchor or restrain'"), ("specialist check", "'Specialist check'"),
                       ("no action", "'No action'"), ("rocking only", "'Rocking only'")):
        assert (words in legend) == (key in actions), key


def test_the_default_study_keeps_the_crane_paragraph_and_the_steel_source():
    """The other side of the rule above: the default study's paper block speaks of a crane portal and it has a
    steel base, so its limitations name what a crane adds and its methods the steel slip coefficient's source."""
    from types import SimpleNamespace

    from rockfrag.config import load_study
    from rockfrag.report.sections import _stands_for_a_crane

    config = load_study(None)
    assert _stands_for_a_crane(SimpleNamespace(config=config))
    assert "steel" in [soil.name for soil in config.soils]


def test_the_references_list_only_the_works_the_pages_cite():
    """Without a steel base the pages no longer cite AISC 360-16: the list keeps the paper and what is cited."""
    from rockfrag.report.words import REFERENCES, references_items

    listed = [item.text for item in references_items("as Housner 1963 found; NAVFAC DM-7.02 Table 1")][1:]
    assert [text.split(": ")[0] for text in listed] == ["The paper", "Housner 1963", "NAVFAC DM-7.02"]
    assert len(references_items()) == len(REFERENCES) + 1


def test_the_friction_source_names_each_soils_range_and_the_end_taken(small_pipeline):
    """Read 2, B10 and B5: the methods said 'the lower end of each range' while clay's 0.35 is the upper end of
    NAVFAC DM-7.02's 0.30-0.35, and steel was 'a concrete base on that soil' on one page and steel on steel on
    another. Each soil's range and end are named, as rockfrag.soils.FRICTION_SOURCES states them."""
    import re as regex

    from rockfrag.report.sections import NAVFAC_RANGES, sources_items
    from rockfrag.soils import FRICTION_SOURCES, SOILS

    for soil, words in NAVFAC_RANGES.items():
        numbers = regex.findall(r"\d\.\d\d(?:-\d\.\d\d)?", words)[0]
        assert numbers in FRICTION_SOURCES, soil
        taken = float(numbers.split("-")[-1 if "high end" in words else 0])
        assert SOILS[soil].friction_static == taken, soil
    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    bullet = next(item.text for item in sources_items(results) if item.text.startswith("Base friction"))
    assert "lower end of each range" not in bullet
    for soil in results.config.soils:
        assert NAVFAC_RANGES[soil.name] in bullet
    assert "a steel base on steel" not in results.friction_words  # no steel base in this study


def test_an_illustrative_hazard_file_is_said_so_first_and_the_hazard_is_drawn(small_pipeline, tmp_path):
    """Read 2, user report A1: the user study's hazard file says in its header that it is 'ILLUSTRATIVE ... not the
    result of a hazard model', yet its summary gave a bare 'no action' and no page drew the curve. The summary's
    first line says so, the answer pages' verdicts name it, and a 'Site hazard' page draws each soil's curve with
    the return periods' frequencies. A file that does not say so gets neither warning."""
    import shutil

    import matplotlib.pyplot as plt

    from rockfrag.report import build_plan
    from rockfrag.report.figures import hazard_page
    from rockfrag.report.summary import (
        ILLUSTRATIVE_WARNING,
        ILLUSTRATIVE_WORDS,
        illustrative_hazard,
        summary_items,
        verdict_items,
    )

    study = tmp_path / "study.toml"
    hazard = tmp_path / "hazard.csv"
    shutil.copy(ROOT / "studies" / "user-site-hazard.csv", hazard)
    text = small_pipeline.study.read_text().replace("[intensity]", '[hazard]\nfile = "hazard.csv"\n'
                                                    "reference_vs30 = 760.0\nsite = [23.62, 37.94]\n\n[intensity]")
    study.write_text(text)
    results = pipeline_results(small_pipeline.output, study)
    assert illustrative_hazard(results)
    items = summary_items(results)
    assert items[0].text == ILLUSTRATIVE_WARNING and items[0].kind == "strong"
    lead = verdict_items(results, results.answers[0])[0].text
    assert lead.startswith(f"With {ILLUSTRATIVE_WORDS}")
    planned = build_plan(results)
    assert any(page.name == "hazard" for page in planned)
    figure = hazard_page(results.site_hazards, results.return_periods, "")
    lines = [line for line in figure.axes[0].get_lines() if np.asarray(line.get_xdata()).size > 2]
    assert len(lines) == len({id(curve) for curve in results.site_hazards.values()}) + (
        results.site_hazards.reference is not None and all(curve is not results.site_hazards.reference
                                                            for curve in results.site_hazards.values()))
    dotted = sorted(float(line.get_ydata()[0]) for line in figure.axes[0].get_lines() if line.get_linestyle() == ":"
                    and np.asarray(line.get_ydata()).size == 2)
    assert np.allclose(dotted, sorted(1.0 / t for t in results.return_periods))
    plt.close(figure)
    hazard.write_text(hazard.read_text().replace("hand-written ILLUSTRATIVE curve", "the site's hazard study")
                      .replace("not the result of a hazard model", "from the site's own model"))
    results = pipeline_results(small_pipeline.output, study)
    assert not illustrative_hazard(results)
    assert ILLUSTRATIVE_WARNING not in [item.text for item in summary_items(results)]


def test_the_answer_page_says_where_the_block_slides_before_it_can_rock(small_pipeline):
    """Cold read 1 finding 4, read 2 user B2: on clay (μ_s 0.35 below the enclosure's b/h 0.40) the block slides
    instead of rocking, and the report's clay answer rests on that assumed friction without saying so. The answer
    page names each such soil (with base friction in the answering runs) and b/h; none where μ_s ≥ b/h."""
    from rockfrag.report.answer_page import slides_first_words

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    cube = results.cube
    checked = 0
    for answer in results.answers:
        b, h = float(cube.block_b.sel(block=answer.block)), float(cube.block_h.sel(block=answer.block))
        expected = [soil.name for soil in results.config.soils if soil.friction_static < b / h
                    and np.isfinite(float(cube.friction_static.sel(model=answer.model, block=answer.block,
                                                                   soil=soil.name)))]
        words = slides_first_words(results, answer)
        if not expected:
            assert words == ""
            continue
        checked += 1
        assert words.startswith(f"On {', '.join(expected)} the soil's base friction") and f"b/h = {b / h:.2f}" in words
    assert checked == 0  # the small study's answering model (the paper's SSI) ties every base: no sentence
    friction = cube.friction_static.copy()
    friction.loc[dict(model=results.answers[0].model)] = 0.45  # as if its runs had base friction
    results.cube["friction_static"] = friction
    said = {answer.block: slides_first_words(results, answer) for answer in results.answers}
    assert said["squat-machinery"].startswith("On every soil the soil's base friction (μ_s sand 0.45, rock 0.7) is "
                                              "below this block's b/h = 0.75")  # said once, not soil by soil
    assert said["paper"].startswith("On sand the soil's base friction (μ_s sand 0.45)")
    assert said["slender-cabinet"] == ""  # b/h = 0.2: every soil grips enough


def test_the_sensitivity_page_wraps_its_titles_and_marks_a_soil_without_a_median():
    """Read 2, default B7: the three block names ran into each other above the sensitivity panels and the first was
    clipped; a soil with no median was a blank column. Titles wrap within their panel; such a soil is labelled."""
    import matplotlib.pyplot as plt

    from rockfrag.report.figures import sensitivity_page

    blocks = ["paper", "slender", "squat"]
    soils, parameters = ["clay", "sand"], ["restitution", "friction", "stiffness"]
    spread = np.full((3, 2, 3, 1), 0.05)
    spread[:, 0, 2, 0] = np.nan  # no median on clay for the squat block
    fragility = xr.Dataset(
        {"median_sensitivity": (("parameter", "soil", "block", "damage_state"), spread),
         "beta_form": (("model", "block", "damage_state"), np.full((1, 3, 1), 0.35)),
         "median": (("soil", "block", "damage_state"), np.ones((2, 3, 1)))},
        coords={"parameter": parameters, "soil": soils, "block": blocks, "damage_state": ["overturning"],
                "model": ["recommended"]})
    names = {b: f"a long block name for {b} with its size (0.6 m × 3.0 m, 2 t)" for b in blocks}
    figure = sensitivity_page(fragility, "", names=names)
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    titles = [axis.title.get_window_extent(renderer) for axis in figure.axes if axis.get_visible()]
    for index, box in enumerate(titles):
        assert box.x0 >= 0 and box.x1 <= figure.bbox.x1
        for other in titles[index + 1:]:
            assert not box.overlaps(other)
    squat = figure.axes[2]
    assert [t.get_text() for t in squat.get_xticklabels()][0] == "clay\n(no median)"
    assert "beta_form" not in " ".join(t.get_text() for axis in figure.axes for t in axis.texts) + " ".join(
        text.get_text() for legend in figure.legends for text in legend.get_texts())
    plt.close(figure)


def test_the_fitted_table_marks_a_fit_that_fails_its_goodness_of_fit_test(small_pipeline):
    """Read 2, default B9: the paper block's uplift on steel (gof p 0.0034) fed an answer page unflagged. A fitted
    cell whose fit fails the test (p < 0.05) is marked ‡ and the note says what it means; none otherwise."""
    from rockfrag.report.sections import fitted_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    fragility = results.fragility.copy()
    fragility["gof_p_value"] = xr.full_like(fragility["median"], 0.5)
    plain = fitted_items(pipeline_results(small_pipeline.output, small_pipeline.study, fragility=fragility))
    assert "‡" not in " ".join(cell for item in plain if item.kind == "table" for row in item.rows for cell in row)
    fragility["gof_p_value"] = xr.full_like(fragility["median"], 0.003)
    items = fitted_items(pipeline_results(small_pipeline.output, small_pipeline.study, fragility=fragility))
    cells = [cell for item in items if item.kind == "table" for row in item.rows for cell in row[2:] if cell != "-"]
    assert cells and all("‡" in cell for cell in cells if cell)
    assert any(item.text.startswith("‡ the fit fails its goodness-of-fit test") for item in items)


def test_the_applicability_legend_says_why_a_block_or_soil_has_no_point(small_pipeline):
    """Read 2, default B7: the paper block had no clay and sand points without a word, and the squat block's 'no run
    rocked without overturning in both models' did not parse. A drawn block names its soils without a point; a
    block without any says 'no point' and why."""
    import matplotlib.pyplot as plt

    from rockfrag.report.figures import applicability_page

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    figure = applicability_page(results.cube, "")
    labels = [text.get_text() for legend in figure.legends for text in legend.get_texts()]
    labels += [line.get_label() for axis in figure.axes for line in axis.get_lines()]
    blocks = [label for label in labels if label.startswith("block: ")]
    assert blocks
    for label in blocks:
        assert "no run rocked without overturning in both models" not in label or "no point" in label, label
    plt.close(figure)


def test_the_sensitivity_page_draws_each_soils_governing_state():
    """Cold read 7 (user B5, default item 4): the page drew overturning only, so clay, whose verdict rests on slip
    >= 0.30 m, was an empty 'no median' column although fragility.nc has that state's spread. Each soil's bars are
    now of its governing state, named under the panel."""
    import matplotlib.pyplot as plt

    from rockfrag.report.figures import sensitivity_page

    soils, parameters, states = ["clay", "sand"], ["restitution", "friction", "stiffness"], ["slip-0.30", "overturning"]
    spread = np.full((3, 2, 1, 2), np.nan)
    spread[:, 0, 0, 0] = [0.01, 0.08, 0.02]  # clay: slip only (overturning not reached)
    spread[:, 1, 0, 1] = [0.03, 0.01, 0.02]  # sand: overturning
    fragility = xr.Dataset(
        {"median_sensitivity": (("parameter", "soil", "block", "damage_state"), spread),
         "beta_form": (("model", "block", "damage_state"), np.full((1, 1, 2), 0.35))},
        coords={"parameter": parameters, "soil": soils, "block": ["box"], "damage_state": states,
                "model": ["recommended"]})
    old = sensitivity_page(fragility, "")  # overturning everywhere: clay has no median
    assert [t.get_text() for t in old.axes[0].get_xticklabels()][0] == "clay\n(no median)"
    plt.close(old)
    figure = sensitivity_page(fragility, "", governing={("box", "clay"): "slip-0.30", ("box", "sand"): "overturning"})
    try:
        axis = figure.axes[0]
        assert [t.get_text() for t in axis.get_xticklabels()] == ["clay", "sand"]
        heights = sorted(round(patch.get_height(), 3) for patch in axis.patches)
        assert heights == [0.01, 0.01, 0.02, 0.02, 0.03, 0.08]  # clay's slip spread is drawn
        label = axis.get_xlabel().replace("\n", " ")
        assert "on clay" in label and "on sand" in label and "governing state" in label, label
        assert "governing damage state" in figure.texts[0].get_text() or any(
            "governing damage state" in t.get_text() for t in figure.texts)
    finally:
        plt.close(figure)


def test_the_sensitivity_page_of_five_soils_and_mixed_states_keeps_its_words_off_the_caption():
    """The governing states' words under a panel of five soils, two of them without a median, ran into the caption
    of the default report (p. 41); the layout check finds no defect on such a page now."""
    import matplotlib.pyplot as plt

    from rockfrag.report import CAPTIONS
    from rockfrag.report.figures import sensitivity_page
    from tests.test_report_layout import layout_defects

    soils, blocks = ["clay", "sand", "gravel", "rock", "steel"], ["paper", "cabinet", "skid"]
    states, parameters = ["slip-0.30", "overturning"], ["restitution", "friction", "stiffness"]
    spread = np.full((3, 5, 3, 2), 0.05)
    spread[:, 2:4, 0, 1] = np.nan  # the paper block's overturning on gravel and rock: no median
    fragility = xr.Dataset(
        {"median_sensitivity": (("parameter", "soil", "block", "damage_state"), spread),
         "beta_form": (("model", "block", "damage_state"), np.full((1, 3, 2), 0.35))},
        coords={"parameter": parameters, "soil": soils, "block": blocks, "damage_state": states,
                "model": ["recommended"]})
    governing = {(b, s): "overturning" if b == "cabinet" or (b == "paper" and s in ("gravel", "rock")) else "slip-0.30"
                 for b in blocks for s in soils}
    names = {"paper": "solid block with the paper's proportions (R = 9.39 m, α = 0.44)",
             "cabinet": "slender solid block, cabinet-sized (0.6 m × 3.0 m, 2 t)",
             "skid": "squat solid block, skid-sized (3 m × 4 m, 30 t)"}
    figure = sensitivity_page(fragility, CAPTIONS["sensitivity"], names=names, governing=governing)
    try:
        assert layout_defects(figure) == []
        assert "* no median" in figure.axes[0].get_xlabel().replace("\n", " ")
    finally:
        plt.close(figure)


def test_the_site_hazard_page_ends_at_the_highest_level_and_marks_the_site_intensities(small_pipeline):
    """Cold read 9 (default B5): the site hazard's axis ran to 10 g while the study stops at 3 g, and it marked no
    intensity although the methods say every intensity axis does. The axis ends at the highest level run; beyond
    the largest unscaled record it is shaded; each soil's site intensity at each return period is a point on its
    curve at 1/T, the values the answer pages print."""
    import matplotlib.pyplot as plt

    from rockfrag.report import build_plan, hazard_marks

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    marks = hazard_marks(results)
    page = next(page for page in build_plan(results) if page.name == "hazard")
    figure = page.draw()
    try:
        axis = figure.axes[0]
        assert axis.get_xlim()[1] <= marks["highest"] * (1 + 1e-9) and marks["highest"] < 10
        shaded = [patch for patch in axis.patches if patch.get_label().startswith("beyond the largest")]
        assert shaded and shaded[0].get_x() == pytest.approx(marks["largest"])
        points = {(round(float(x), 9), round(float(y), 12)) for line in axis.get_lines() if line.get_marker() == "o"
                  for x, y in zip(line.get_xdata(), line.get_ydata())}
        answer = results.answers[0]
        expected = {(round(float(im), 9), round(1.0 / t, 12)) for soil in answer.soils
                    for im, t in zip(soil.intensities, answer.return_periods)}
        assert expected and expected <= points, (expected - points)
    finally:
        plt.close(figure)


def test_a_calibrated_bed_damping_at_its_floor_is_marked_in_the_appendix():
    """Cold read 9, user B1: the appendix gave 0.158 on clay and on sand, which read as a floor, not a calibration,
    and nothing said so. A cell whose restitution is the most the bed reaches (the target at or above it) or whose
    block's rocking dies (asked, none reached) is the least admissible damping: marked '(floor)'."""
    from rockfrag.report.sections import at_damping_floor

    soils, blocks = ["clay", "sand", "rock"], ["box"]
    cube = xr.Dataset({
        "restitution_requested": (("soil", "block", "model"), [[[0.813]], [[0.813]], [[0.46]]]),
        "restitution_target": (("soil", "block", "model"), [[[0.813]], [[0.790]], [[np.nan]]]),
        "restitution_reachable": (("soil", "block", "bound"), [[[0.788, 0.8129]], [[0.70, 0.802]], [[np.nan, np.nan]]]),
    }, coords={"soil": soils, "block": blocks, "model": ["recommended"], "bound": ["low", "high"]})
    assert at_damping_floor(cube, "recommended", "box", "clay")  # hits its target at the bed's most restitution
    assert not at_damping_floor(cube, "recommended", "box", "sand")  # 0.790 inside 0.70-0.802: calibrated
    assert at_damping_floor(cube, "recommended", "box", "rock")  # rocking dies: the least admissible damping


def test_a_class_e_soil_is_a_limitation_of_the_generic_site_term(small_pipeline):
    """Cold read 9, user B5: the class-E clay's hazard came from the generic site term, which lowers its strong
    shaking below the reference's, and the limitations did not say a site response analysis is what it needs."""
    from types import SimpleNamespace

    from rockfrag.report.sections import site_response_items
    from rockfrag.site_hazard import SiteHazards
    from rockfrag.soils import SOILS

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    sites = results.site_hazards
    assert SOILS["clay"].site_class == "E" and SOILS["sand"].site_class == "D"
    carried = SiteHazards({"clay": sites["sand"], "sand": sites["sand"]}, sites.reference, sites.reference_vs30)
    study = SimpleNamespace(site_hazards=carried, return_periods=results.return_periods,
                            config=SimpleNamespace(soils=(SOILS["clay"], SOILS["sand"])))
    items = site_response_items(study)
    assert items[0].text == "Site response" and items[1].text.startswith("On clay (site class E, soft soil)")
    assert "ASCE 7-16 Section 11.4.8" in items[1].text and "sand" not in items[1].text
    study.config = SimpleNamespace(soils=(SOILS["sand"],))
    assert site_response_items(study) == []


def test_the_sensitivity_page_marks_a_lower_bound_and_a_zero_bar():
    """Cold read 9, user B4 (and the coordinator's look at the user study's page): a bar from one end of its range
    alone is a lower bound, and the sand's restitution bar of 0 (both ends gave the same median) looked like a
    parameter with no run. The first is marked ≥, the second 0, and no other bar is marked."""
    import matplotlib.pyplot as plt

    from rockfrag.report import SENSITIVITY_MARK_WORDS
    from rockfrag.report.figures import SPREAD_BOUND_MARK, SPREAD_ZERO_MARK, sensitivity_marks, sensitivity_page

    parameters = ["restitution", "friction", "stiffness"]
    spread = np.array([0.0, 0.136, 0.015])[:, None, None, None]
    members = [f"{p}_{end}" for p in parameters for end in ("low", "high")]
    member_median = np.array([1.995, 1.995, np.nan, 1.873, 1.898, 1.999])[:, None, None, None]
    fragility = xr.Dataset(
        {"median_sensitivity": (("parameter", "soil", "block", "damage_state"), spread),
         "member_median": (("member", "soil", "block", "damage_state"), member_median),
         "beta_form": (("model", "block", "damage_state"), np.full((1, 1, 1), 0.35))},
        coords={"parameter": parameters, "member": members, "soil": ["sand"], "block": ["box"],
                "damage_state": ["overturning"], "model": ["recommended"]})
    figure = sensitivity_page(fragility, "")
    try:
        marks = {(round(text.xy[1], 3), text.get_text()) for text in figure.axes[0].texts if hasattr(text, "xy")}
        assert marks == {(0.0, SPREAD_ZERO_MARK), (0.136, SPREAD_BOUND_MARK)}, marks
    finally:
        plt.close(figure)
    assert sensitivity_marks(fragility) == [SPREAD_BOUND_MARK, SPREAD_ZERO_MARK]
    assert "marked ≥ is a lower bound" in SENSITIVITY_MARK_WORDS["≥"] and "marked 0" in SENSITIVITY_MARK_WORDS["0"]


def test_the_methods_compare_eq19_with_an_elastic_half_space():
    """Cold read 12, user B3: eq. 19 gave the enclosure 66.8 MN/m on clay where Gazetas' rigid footing on a
    half-space of the same G and nu gives 162 MN/m (2.4 times, beyond the sensitivity runs' x 2), and the report did
    not say so. The methods now give both and which way the difference acts; a per-metre block is left out (a long
    strip has no finite static half-space stiffness); a steel base is no soil."""
    from types import SimpleNamespace

    from rockfrag.blocks import Block
    from rockfrag.report.sections import half_space_words
    from rockfrag.soils import SoilClass, soil_block_stiffness

    clay = SoilClass("clay", 37.142857e6, 0.3, 1800.0)
    steel = SoilClass("steel", 80e9, 0.3, 7850.0)
    enclosure = Block("enclosure", b=0.6, h=1.5, mass=4500.0, footprint_area=1.8, soil_depth=1.0, E_b=30e9)
    strip = Block("wall", b=2.0, h=5.0, mass=50e3, E_b=30e9)  # per metre of length
    blocks, soils = [enclosure, strip], [clay, steel]
    stiffness = xr.DataArray([[soil_block_stiffness(s, b) for b in blocks] for s in soils],
                             coords={"soil": ["clay", "steel"], "block": ["enclosure", "wall"]})
    cube = xr.Dataset({"interface_stiffness": stiffness,
                       "soil_shear_modulus": ("soil", [s.shear_modulus for s in soils])})
    config = SimpleNamespace(blocks=blocks, soils=soils, design=SimpleNamespace(stiffness_factor=2.0),
                             raw={})
    text = half_space_words(config, cube)
    assert "enclosure (H 1 m): 2.4 × eq. 19's k (clay 162 MN/m), beyond the sensitivity runs' × or ÷ 2" in text, text
    # the per-metre wall against Gazetas' strip, 0.73 G / (1 - nu) per metre (default study B5: 0.26 x for the paper's)
    strip = 0.73 * 37.142857e6 / 0.7
    ratio = strip / soil_block_stiffness(clay, blocks[1])
    assert f"wall (H 2 m, per metre, as a strip): {ratio:.2g} × eq. 19's k (clay {strip / 1e6:.3g} MN/m)" in text, text
    assert "is different" in text and "steel" not in text and "Not compared" not in text
    assert half_space_words(SimpleNamespace(blocks=blocks, soils=soils, raw={},
                                            design=SimpleNamespace(stiffness_factor=3.0)), cube).count("within") == 2


def test_the_clay_adhesion_caveat_errs_the_way_each_blocks_contact_pressure_says():
    """Cold read 12, user B2: the enclosure presses 24.5 kPa, so μ_s p = 8.6 kPa, below the adhesion of even a soft
    clay (10-35 kPa, NAVFAC DM-7.02): undrained it grips more, and the caveat said it slides more easily. A block
    whose μ_s p exceeds a stiff clay's 60 kPa slides more easily; between, it depends on the clay."""
    from types import SimpleNamespace

    from rockfrag.blocks import Block
    from rockfrag.report.sections import adhesion_words
    from rockfrag.soils import SoilClass

    clay = SoilClass("clay", 37.142857e6, 0.3, 1800.0, friction_static=0.35, friction_kinetic=0.3)
    light = Block("enclosure", b=0.6, h=1.5, mass=4500.0, footprint_area=1.8, soil_depth=1.0, E_b=30e9)
    heavy = Block("tower", b=1.0, h=8.0, mass=60e3, footprint_area=2.0, E_b=30e9)  # 294 kPa: μ_s p 103 kPa
    middle = Block("skid", b=1.5, h=2.0, mass=30e3, footprint_area=9.0, E_b=30e9)  # 32.7 kPa: μ_s p 11 kPa
    config = SimpleNamespace(blocks=[light, heavy, middle], soils=[clay], raw={})
    cube = xr.Dataset(coords={"block": ["enclosure", "tower", "skid"], "soil": ["clay"]})
    text = adhesion_words(config, cube, ["clay"])
    assert "enclosure on clay 24.5 kPa, μ_s p 8.58 kPa" in text, text
    assert "tower on clay 294 kPa, μ_s p 103 kPa" in text
    assert "For enclosure on clay that is below the adhesion of even a soft clay" in text
    assert "slip probabilities here are, if anything, high" in text
    assert "For tower on clay it is above the adhesion of even a stiff clay" in text
    assert "For skid on clay it lies within" in text


def test_the_summary_says_which_soils_are_representative_classes_not_the_sites():
    """Cold read 12, user B4: the summary, the page that is signed, called them "the site's clay and sand" while
    their moduli are the paper's representative values and their friction a class's; only the methods said so."""
    from dataclasses import replace
    from types import SimpleNamespace

    from rockfrag.report.summary import representative_soils_words
    from rockfrag.soils import SOILS

    measured = replace(SOILS["sand"], shear_modulus=95e6)  # a site investigation's modulus: not a shipped class
    results = SimpleNamespace(config=SimpleNamespace(soils=[SOILS["clay"], measured]), cube=xr.Dataset())
    assert representative_soils_words(results) == ("Clay: representative class of ground, not site measurements "
                                                   "(Methods).")
    results.config.soils = [measured]
    assert representative_soils_words(results) == ""


def test_the_appendix_names_the_exchange_files_the_run_wrote(tmp_path):
    """Cold read 12, user C17: fragility_pelicun.csv and the OpenQuake files were named nowhere in the report."""
    from rockfrag.report.sections import NAVFAC_RANGES, exchange_files

    assert exchange_files(tmp_path) == []
    (tmp_path / "fragility_pelicun.csv").write_text("ID\n")
    (tmp_path / "fragility_openquake.xml").write_text("<nrml/>")
    assert exchange_files(tmp_path) == ["fragility_pelicun.csv", "fragility_openquake.xml"]
    # user C12: which way the sand's low friction end errs is said beside it
    assert "more sliding and less rocking" in NAVFAC_RANGES["sand"]


def test_a_reference_models_points_are_open_and_the_answers_filled(small_pipeline):
    """Cold read 12, user C8: on one soil the recommended model's and the rigid base's points had one colour and one
    marker. The rigid base's points are now open (white inside), the page's model's filled."""
    import matplotlib.colors as mcolors
    import matplotlib.pyplot as plt

    from rockfrag.report.adapters import models_of
    from rockfrag.report.figures import fragility_by_soil_page

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    fragility = results.fragility
    model = next(m for m in models_of(fragility) if not m.rigid_base)  # the SSI model, solid; Housner dashed
    figure = fragility_by_soil_page(fragility, str(fragility.block.values[0]), model, "")
    try:
        points = [line for axis in figure.axes for line in axis.get_lines()
                  if line.get_marker() == "o" and line.get_linestyle() in ("None", "none", "")]
        assert points
        white = mcolors.to_rgba("white")
        filled = [mcolors.to_rgba(p.get_markerfacecolor()) != white for p in points]
        assert any(filled) and not all(filled)  # the page's model filled, the rigid base open
    finally:
        plt.close(figure)


def test_the_limitations_check_that_the_ground_carries_each_block():
    """Cold read 12, default A1: no page said whether a clay carries the paper's block (400 kPa). The limitations'
    'Bearing' gives every block's pressure and what carries it, names the block a clay may not carry, and its
    answer page says the verdict presumes ground or a foundation that does."""
    from types import SimpleNamespace

    from rockfrag.report.sections import bearing_items
    from rockfrag.soils import SOILS

    paper = SimpleNamespace(name="paper", mass=326197.0, footprint_area=8.0, b=4.0)
    light = SimpleNamespace(name="light", mass=2000.0, footprint_area=0.48, b=0.3)
    config = SimpleNamespace(blocks=[paper, light], soils=[SOILS["clay"], SOILS["sand"]], raw={})
    cube = xr.Dataset(coords={"block": ["paper", "light"], "soil": ["clay", "sand"]})
    items = bearing_items(config, cube)
    text = " ".join(item.text for item in items if item.kind == "paragraph")
    assert "Where the ground may not carry the block (paper on clay)" in text, text
    rows = {(row[0], row[1]): row for row in next(item for item in items if item.kind == "table").rows}
    assert rows[("paper", "clay")][2:] == ["400", "s_u ≥ 78 kPa (233 kPa with a factor of safety 3): only the "
                                                  "stiffer part of the class"]
    assert rows[("light", "clay")][3].endswith("any clay of the class")
    assert rows[("light", "sand")][3].startswith("ultimate 125 kPa under its width: p is 33% of it")


def test_the_efficiency_caption_names_a_sufficient_measure_beside_a_better_one_that_fails():
    """Cold read 12, default figures B2: the caption named AvgSa (0.25, failing sufficiency) as scattering less than
    PGA (0.43) for the slender block and left out PGV (0.29), which scatters less too and passes every test."""
    from rockfrag.report import measure_choice_words

    measures = ["pga", "pgv", "avgsa"]
    dims = ("soil", "block", "model", "measure")
    shape = (1, 1, 1, 3)
    data = xr.Dataset({"dispersion": (dims, np.array([0.43, 0.29, 0.25]).reshape(shape)),
                       "p_pulse_period": (dims, np.array([0.0001, 0.21, 0.001]).reshape(shape))},
                      coords={"soil": ["rock"], "block": ["slender"], "model": ["recommended"], "measure": measures},
                      attrs={"study_measure": "pga"})
    text = measure_choice_words(data, {"slender": "slender block"})
    assert "though it fails the sufficiency test too (against pulse period); PGV (0.29) has less scatter too and " \
           "passes every sufficiency test" in text, text


def test_the_limitations_say_what_two_corner_springs_leave_out():
    """Cold read 12, default B4: 'the tensionless Winkler bed' is two springs, k/2 under each corner, whose rocking
    stiffness k b² is three times a distributed bed's k b²/3; the limitations now say so, for that bed only."""
    from types import SimpleNamespace

    from rockfrag.report.sections import bed_form_words

    text = bed_form_words(SimpleNamespace(bed="two-spring"))
    assert "k b², three times a distributed bed's k b²/3" in text and "Psycharis & Jennings 1983" in text
    assert bed_form_words(SimpleNamespace(bed="continuous")) == ""


def test_a_heavy_blocks_clay_verdict_says_it_holds_for_a_drained_base():
    """Cold read 12 (default text, round 2): the limitations said the paper block's slip on saturated clay is
    unconservative (μ_s p 140 kPa above any clay's adhesion, 10-60 kPa), and its answer page did not. It now says the
    equivalent friction (0.03-0.15 under 400 kPa) and that the clay verdict holds for a drained base."""
    from types import SimpleNamespace

    from rockfrag.report.answer_page import bearing_words
    from rockfrag.soils import SOILS

    paper = SimpleNamespace(name="paper", mass=326197.0, footprint_area=8.0, b=4.0)
    light = SimpleNamespace(name="light", mass=4500.0, footprint_area=1.8, b=0.6)
    results = SimpleNamespace(config=SimpleNamespace(blocks=[paper, light], soils=[SOILS["clay"], SOILS["sand"]]))
    soils = [SimpleNamespace(soil="clay"), SimpleNamespace(soil="sand")]
    text = bearing_words(results, SimpleNamespace(block="paper", soils=soils))
    assert "an equivalent friction of only 0.03-0.15 under its 400 kPa, against μ_s 0.35" in text, text
    assert "holds for a drained base" in text
    assert bearing_words(results, SimpleNamespace(block="light", soils=soils)) == ""


def test_the_kinetic_slip_caption_is_said_only_where_the_lift_off_share_falls():
    """Cold read 12: the paper block's lift-off share on steel fell (20 to 17 of 44) unexplained; the sentence added
    for it then stood on the user study's sand, whose share rises. It is said only where the share falls."""
    from types import SimpleNamespace

    from rockfrag.report import kinetic_slip_words
    from rockfrag.soils import SOILS

    block = SimpleNamespace(name="paper", b=4.0, h=8.5)
    levels = np.array([0.8, 1.0, 1.25, 1.56])
    share = np.array([16, 20, 17, 25]) / 44.0
    dims = ("im_level", "soil", "block", "model", "damage_state")
    fragility = xr.Dataset({"empirical_fraction": (dims, share[:, None, None, None, None]), "n_records": 44},
                           coords={"soil": ["steel"], "block": ["paper"], "model": ["recommended"],
                                   "damage_state": ["uplift"],
                                   "intensity": (("block", "im_level"), levels[None, :], {"units": "9.80665 m s-2"})})
    cube = xr.Dataset({"friction_static": (("soil", "block", "model"), [[[0.5]]])},
                      coords={"soil": ["steel"], "block": ["paper"], "model": ["recommended"]})
    results = SimpleNamespace(config=SimpleNamespace(blocks=[block], soils=[SOILS["steel"]]), cube=cube,
                              fragility=fragility)
    text = kinetic_slip_words(results, "paper", "recommended")
    assert "on steel (μ_k 0.400 against 0.471) it falls from 20 to 17 of 44 between 1.00 and 1.25 g" in text, text
    fragility["empirical_fraction"][:] = (np.array([16, 20, 22, 25]) / 44.0)[:, None, None, None, None]
    assert kinetic_slip_words(results, "paper", "recommended") == ""


def test_a_gripping_base_on_clay_gets_the_held_bases_overturning_probability():
    """Cold read 12 (user, round 3): the enclosure's 8.58 kPa lies below any clay's adhesion, so undrained it grips
    and rocks; the reader computed the held base's overturning on the clay's hazard (0.04%) and asked for it in the
    report. The limitations give it from the model whose base is held there, against the closed form of a
    power-law hazard."""
    from types import SimpleNamespace

    from rockfrag.hazard import HazardCurve
    from rockfrag.report.sections import gripping_base_words
    from rockfrag.soils import SOILS

    k0, k = 1e-4, 2.5
    s = np.geomspace(0.001, 100.0, 400)
    hazard = HazardCurve(s, k0 * s ** -k, "pga", None, "site.csv")
    block = SimpleNamespace(name="enclosure", b=0.6, h=1.5, mass=4500.0, footprint_area=1.8)
    dims = ("soil", "block", "model", "damage_state")
    fragility = xr.Dataset({"median": (dims, [[[[1.0], [1.85]]]], {"units": "9.80665 m s-2"}),
                            "beta": (dims, [[[[0.5], [0.5]]]])},
                           coords={"soil": ["clay"], "block": ["enclosure"], "model": ["recommended", "ssi"],
                                   "damage_state": ["overturning"]}, attrs={"design_life_years": 50.0})
    cube = xr.Dataset({"friction_static": (("soil", "block", "model"), [[[0.35, np.nan]]])},
                      coords={"soil": ["clay"], "block": ["enclosure"], "model": ["recommended", "ssi"]})
    results = SimpleNamespace(cube=cube, fragility=fragility, site_hazards=None, hazard=hazard,
                              config=SimpleNamespace(blocks=[block], soils=[SOILS["clay"]], raw={}, design_life=50.0),
                              decision={"max_probability_in_life": {"overturning": 0.01}})
    text = gripping_base_words(results, ["clay"])
    expected = 1 - np.exp(-50 * k0 * 1.85 ** -k * np.exp(k * k * 0.25 / 2))
    from rockfrag.report import numbers

    assert f"overturns in 50 years with {numbers.probability(expected)} against the 1% limit" in text, (text, expected)
    assert "whose base is held there" in text


def test_the_showcase_caption_says_where_the_rigid_base_slides_without_rocking():
    """Cold read 12 (user round 2 B5; default figures round 2 B1): on clay the rigid base only slides, its θ = 0 hid
    under the other lines unexplained; the sentence then claimed the bed slides too on sand, where it rocks. It names
    the soils whose μ_s is below b/h and says only what the rigid base does there."""
    from types import SimpleNamespace

    from rockfrag.report import showcase_slide_words
    from rockfrag.soils import SOILS

    block = SimpleNamespace(name="paper", b=4.0, h=8.5)
    showcase = xr.Dataset(coords={"case_soil": ("case", ["clay", "sand", "rock"])},
                          attrs={"showcase_block": "paper"})
    results = SimpleNamespace(showcase=showcase, config=SimpleNamespace(
        blocks=[block], soils=[SOILS["clay"], SOILS["sand"], SOILS["rock"]]))
    text = showcase_slide_words(results)
    assert text.startswith(" On clay and sand the base friction is below b/h = 0.47: the rigid base slides"), text
    assert "its θ stays 0 under the other lines" in text and "the bed mostly slides" not in text


def test_the_summary_marks_a_clay_verdict_that_holds_for_a_drained_base():
    """Cold read 12 (default text, round 3): the paper block's clay verdict holds for a drained base only (its
    undrained adhesion is an equivalent friction of 0.03-0.15 under 400 kPa); its answer page said so, the summary's
    row did not. The action carries ◊ there, and only there."""
    from types import SimpleNamespace

    from rockfrag.report.summary import DRAINED_WORDS, drained_words
    from rockfrag.soils import SOILS

    paper = SimpleNamespace(name="paper", mass=326197.0, footprint_area=8.0, b=4.0)
    light = SimpleNamespace(name="light", mass=4500.0, footprint_area=1.8, b=0.6)
    results = SimpleNamespace(config=SimpleNamespace(blocks=[paper, light], soils=[SOILS["clay"], SOILS["sand"]]))
    assert drained_words(results, "paper", "clay") == DRAINED_WORDS
    assert drained_words(results, "paper", "sand") == "" and drained_words(results, "light", "clay") == ""
