"""The report an engineer signs (issue 36, items 1, 2, 5 and 6): the summary is page 2 with every asset and soil,
the client's pages speak no tool syntax (only the closing appendix names keys, commands and files), the blocks are
named for what is modelled, and the contents come first."""

from __future__ import annotations

import re

import xarray as xr

from tests.helpers import pipeline_results

TABLES = ("study", "intensity", "solver", "hazard", "decision", "fragility", "damage_states", "applicability",
          "blocks", "blocks_custom", "soils_custom", "checks", "report")
TOOL_SYNTAX = {
    "study key": rf"\[(?:{'|'.join(TABLES)})(?:\.[^\]]+)?\]",
    "snake_case name": r"\b[a-z]{2,}_[a-z0-9_]+\b",
    "file": r"\b[\w-]+\.(?:nc|csv|toml|py|json|xml|txt|png|pdf|html)\b",
    "path": r"\b(?:pipeline|shared|reports|studies|tests)/",
    "setting": r"\b[a-z]{2,}(?:_[a-z]+)* = ",
    "call": r"\b[a-z_]+\(\)",
    "calibrated ξ": r"ξ =? ?\d",
    "jargon": r"\b(?:central member|answering (?:run|model|curve)s?|designed sample|credible cap)\b",
}
"""What an operator types and a client should never read: study keys, names of variables and functions, files,
paths, settings, calls, the damping ratio the bed was calibrated to, and the tool's own words for its runs (cold
read 4: "central member", "answering run", "designed sample", "credible cap")."""


def tool_syntax(text: str) -> list[str]:
    """Every piece of tool syntax in ``text``, named by kind ("study key: [decision]")."""
    return [f"{kind}: {found}" for kind, pattern in TOOL_SYNTAX.items() for found in re.findall(pattern, text)]


def _texts(items) -> str:
    return " ".join([item.text for item in items] + [cell for item in items for cell in [*item.header,
                                                                                       *sum(item.rows, [])]])


def test_the_check_finds_tool_syntax():
    """It can fail: the words the client read on the answer pages before (issue 36, 'Speaks to the operator')."""
    found = tool_syntax('above the 10% the study allows ([decision] max_sliding_share = 0.1); compute it with '
                        '[solver] friction = "all"; see pipeline/hazard_example.csv and fragility.csv; ξ = 0.158')
    kinds = {entry.split(":")[0] for entry in found}
    assert kinds == {"study key", "snake_case name", "file", "path", "setting", "calibrated ξ"}
    assert tool_syntax("a damping ratio calibrated to the restitution (ξ 0.158 in this study)") == [
        "calibrated ξ: ξ 0"]  # cold read 8's methods: text6 had printed it without '='
    assert tool_syntax("the central member's answering run, a designed sample below the credible cap") == [
        "jargon: central member", "jargon: answering run", "jargon: designed sample", "jargon: credible cap"]
    assert tool_syntax("PGA [g], mass [kg], Housner's r = 1 − 1.5 sin²α, μ_s, a_p = 2π·PGV/T_p") == []


def test_no_client_page_speaks_tool_syntax_and_the_appendix_holds_it(small_pipeline):
    from rockfrag.report import build_plan
    from rockfrag.report.answer_page import answer_items, reading_items
    from rockfrag.report.sections import (
        fitted_items,
        limitations_items,
        methods_items,
        reproduce_items,
        title_items,
    )
    from rockfrag.report.summary import summary_items
    from rockfrag.report.words import glossary_items, references_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    pages = {"title": title_items(results), "summary": summary_items(results), "reading": reading_items(results),
             "methods": methods_items(results), "limitations": limitations_items(results),
             "fitted": fitted_items(results), "glossary": glossary_items(), "references": references_items()}
    pages.update({f"answer {answer.block}": answer_items(results, answer) for answer in results.answers})
    found = {name: tool_syntax(_texts(items)) for name, items in pages.items()}
    assert {name: entries for name, entries in found.items() if entries} == {}
    planned = build_plan(results)
    headings = {page.name: tool_syntax(f"{page.title} {page.caption}") for page in planned}
    assert {name: entries for name, entries in headings.items() if entries} == {}
    appendix = _texts(reproduce_items(results))
    for key in ("[hazard] file", "[decision] max_probability_in_life", "[decision] max_sliding_share",
                "[solver] friction", "rockfrag fragility", str(small_pipeline.study),
                # cold read 5, B7: the methods promise the appendix names these
                "[soils_custom.NAME] friction_static, friction_kinetic", "[soils_custom.NAME] shear_modulus",
                "[uncertainty] restitution_range"):
        assert key in appendix, key
    assert planned[-1].section == "How to reproduce this report" or "How to reproduce this report" in \
        planned[-1].also


def test_the_summary_is_page_two_with_every_asset_and_soil_and_the_contents_follow(small_pipeline):
    from rockfrag.report import build_plan
    from rockfrag.report.adapters import block_name
    from rockfrag.report.summary import EXAMPLE_WARNING, summary_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    planned = build_plan(results)
    assert [page.section for page in planned[:3]] == ["Title", "Summary", "Contents"]
    items = summary_items(results)
    assert items[0].text == EXAMPLE_WARNING and items[0].kind == "strong"  # the shipped example: said first
    table = next(item for item in items if item.kind == "table")
    rows, block = set(), None
    for row in table.rows:
        if row[0] and not any(row[1:]):
            block = row[0]
        else:
            rows.add((block, row[0]))
            assert row[1].split(" (")[0] in ("anchor or restrain", "no action", "specialist check", "no verdict"), row
            assert row[-1] and row[-1] != "-", row  # a reason on every row
    expected = {(block_name(results.config, b), str(s)) for b in results.cube.block.values
                for s in results.cube.soil.values}
    assert rows == expected
    for head in ("governing damage state", "P in 50 years (limit)", "β (records / model)", "reason"):
        assert head in table.header, head


def test_the_summary_beta_prints_both_parts_that_add_to_the_total(small_pipeline):
    """Cold read 8, user B3: "0.53 (records)" hid a model part of 0.35 beside the records' 0.39. Each summary β
    prints its two parts, and they add in squares to the total (to the printed rounding)."""
    import numpy as np

    from rockfrag.report.summary import summary_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    fragility = results.fragility.copy()  # the small study samples no model: give every row a model part
    fragility["beta_record_to_record"] = fragility["beta"]
    fragility["beta_model"] = xr.full_like(fragility["beta"], 0.35)
    fragility["beta"] = np.hypot(fragility["beta_record_to_record"], fragility["beta_model"])
    results.__dict__["fragility"] = fragility
    table = next(item for item in summary_items(results) if item.kind == "table")
    column = table.header.index("β (records / model)")
    cells = [row[column] for row in table.rows if re.fullmatch(r"[\d.]+ \([\d.]+ / [\d.]+\)", row[column] or "")]
    assert cells, [row[column] for row in table.rows]
    for cell in cells:
        total, records, model = map(float, re.findall(r"[\d.]+", cell))
        assert model == 0.35 and abs(total - (records ** 2 + model ** 2) ** 0.5) <= 0.011, cell


def test_a_site_hazard_removes_the_warning(small_pipeline, tmp_path):
    from dataclasses import replace

    from rockfrag.report.summary import EXAMPLE_WARNING, summary_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    answers = [replace(answer, example_hazard=False) for answer in results.answers]
    site = pipeline_results(small_pipeline.output, small_pipeline.study)
    site.__dict__["answers"] = answers  # the cached property, as a study with its own hazard file gives it
    assert EXAMPLE_WARNING not in [item.text for item in summary_items(site)]


def test_the_default_blocks_are_named_for_what_is_modelled_and_crane_only_beside_what_a_crane_adds():
    """Issue 36 item 5: "crane portal" was the paper's solid block; its name and description now say what it is,
    and "crane" appears only where the limitations name what a crane adds."""
    from rockfrag.config import load_study
    from rockfrag.report.adapters import block_description, block_name
    from rockfrag.report.sections import WHAT_A_CRANE_ADDS

    config = load_study(None)
    names = {block.name: block_name(config, block.name) for block in config.blocks}
    assert names["paper"] == "solid block with the paper's proportions (R = 9.39 m, α = 0.44)"
    assert all("crane" not in name and "solid block" in name for name in names.values())
    for block in config.blocks:
        description = block_description(config, block.name)
        assert description.count("kg/m^3") + description.count("t,") + description.count(" t ") >= 1
        if "crane" in description:
            assert "limitations" in description
    for mechanism in ("wheels on rails", "derail", "tie-downs", "flexible", "pendulum"):
        assert mechanism in WHAT_A_CRANE_ADDS, mechanism


def test_each_word_of_the_glossary_has_one_meaning():
    """'band' had two meanings; the restitution band gave way to the sensitivity runs, which the glossary names."""
    from rockfrag.report.words import GLOSSARY

    terms = [term for term, _ in GLOSSARY]
    assert len(terms) == len(set(terms))
    assert "band" not in terms and "sensitivity runs" in terms and "confidence bounds" in terms
    text = " ".join(meaning for _, meaning in GLOSSARY)
    assert "two meanings" not in text


def test_no_paragraph_is_repeated(small_pipeline):
    """The same paragraph stood on every block's answer page (issue 36): a text common to the blocks is said once."""
    from rockfrag.report import build_plan

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    paragraphs = [text for page in build_plan(results) if page.html
                  for text in re.findall(r"<(?:p|li)[^>]*>(.*?)</(?:p|li)>", page.html, flags=re.S)
                  if len(text) >= 100]
    repeated = {text[:80] for text in paragraphs if paragraphs.count(text) > 1}
    assert repeated == set()


def test_the_last_page_of_a_run_of_text_is_never_near_empty():
    """Pages 13 and 25 of the default report held a few lines each (issue 36): a run's last page that would hold
    less than half a page shares the last two pages' lines evenly."""
    import rockfrag.report.text as text
    from rockfrag.report.text import BALANCE, _lines, paginate, paragraph, table

    capacity = 40
    items = [paragraph("a line of text " * 8) for _ in range(14)] + [table(["a", "b"], [[str(n), "x"] for n in
                                                                                      range(18)])]
    unbalanced = text._paginate(items, capacity)  # 28 lines of text and a 20-line table: 8 lines left over
    assert [sum(_lines(item) for item in page) for page in unbalanced][-1] < BALANCE * capacity
    pages = paginate(items, capacity)
    lines = [sum(_lines(item) for item in page) for page in pages]
    assert len(pages) == 2 and all(count <= capacity for count in lines)
    assert min(lines) >= BALANCE * capacity * 0.8, lines
    rows = [row for page in pages for item in page if item.kind == "table" for row in item.rows]
    assert rows == [[str(n), "x"] for n in range(18)]  # every row once, in order


def test_a_verdict_whose_sliding_was_not_computed_says_it_covers_rocking_only():
    """A study that ties a base (its [solver] friction) gets verdicts that say so (issue 32 item 3): the summary's
    action reads "no action (rocking only)" there, and a verdict that is itself the sliding check does not."""
    from types import SimpleNamespace

    from rockfrag.answer import CHECK_SLIDING, NO_ACTION
    from rockfrag.report.summary import action

    assert action(NO_ACTION, SimpleNamespace(tied=True, verdict=NO_ACTION)) == "no action (rocking only)"
    assert action(NO_ACTION, SimpleNamespace(tied=False, verdict=NO_ACTION)) == "no action"
    assert action(CHECK_SLIDING, SimpleNamespace(tied=True, verdict=CHECK_SLIDING)) == "specialist check"
    assert action(NO_ACTION) == "no action"


def test_cold_read_8_default_text_corrections(small_pipeline):
    """Cold read 8 (default text B1, C3, C11): the design-life value above the 475-year one on clay unexplained; the
    blocks' k in software notation ("1.5e+08"); the exact-threshold uplift rows' beta 0.15 read as a response's."""
    from rockfrag.report.answer_page import reading_items
    from rockfrag.report.sections import fitted_items, methods_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    reading = _texts(reading_items(results))
    assert "it can exceed the probability at the 475-year intensity" in reading
    methods = methods_items(results)
    blocks = next(item for item in methods if item.kind == "table" and "b [m]" in item.header)
    assert any("[MN/m]" in head for head in blocks.header)
    assert not any("e+" in cell for row in blocks.rows for cell in row), blocks.rows
    fitted = _texts(fitted_items(results))
    assert "a β of about 0.15: their scatter, not a record-to-record dispersion" in fitted
    assert "close to the uplift intensity the levels are set from" in fitted  # cold read 9, user C2: 0.398 vs 0.401 g
    # user B4: the static settlement the reading guide counts a lift from, referred to but never printed
    block, soil = str(results.cube.block.values[0]), str(results.cube.soil.values[0])
    settlement = float(results.cube.block_mass.sel(block=block)) * 9.80665 / float(
        results.cube.interface_stiffness.sel(block=block, soil=soil)) * 1e3
    assert f"{soil} {settlement:.3g}" in _texts(methods), settlement


def test_the_fitted_table_says_why_a_rigid_bases_slip_rows_repeat_across_blocks():
    """Cold read 8 (default text C2): Housner's slip rows of the paper block and the squat skid on clay and sand were
    identical (0.779 / 0.25, 1.58 / 0.38) and read as a copy error; a rigid base sliding without lifting off slides
    alike whatever its size. The note is said where rows repeat, not elsewhere."""
    import numpy as np
    import xarray as xr

    from rockfrag.report.sections import _same_rigid_slips

    median = np.array([[[[0.78, 1.58]], [[0.78, 1.58]]]])  # (soil, block, model, state)
    fragility = xr.Dataset({"median": (("soil", "block", "model", "damage_state"), median)},
                           coords={"soil": ["clay"], "block": ["paper", "skid"], "model": ["housner"],
                                   "damage_state": ["slip-0.05", "slip-0.30"]})
    assert _same_rigid_slips(fragility)
    fragility["median"].loc[dict(block="skid")] = [[[0.80, 1.58]]]
    assert not _same_rigid_slips(fragility)


def test_a_bullet_list_ends_with_space_before_the_paragraph_that_follows():
    """Cold read 8 (default text C9): a paragraph ran on straight after the last bullet of the verdict list."""
    import matplotlib.pyplot as plt

    from rockfrag.report.text import LINE, bullet, draw_text_page, paragraph

    def gap(items):
        figure = draw_text_page("t", items)
        tops = [text.get_position()[1] for text in figure.texts if text.get_text() in ("last bullet", "after")]
        plt.close(figure)
        return tops[0] - tops[1]

    spaced = gap([bullet("first"), bullet("last bullet"), paragraph("after")])
    assert spaced > 1.5 * LINE  # one line of the bullet, and the space
    assert gap([bullet("first"), bullet("last bullet"), bullet("after")]) < 1.1 * LINE


def test_the_contents_list_each_figure_page_by_the_title_it_draws(small_pipeline):
    """Cold read 8, user C7/C13: the contents called p. 24 "Model uncertainty: sensitivity of the median" while its
    title read "Model uncertainty: which parameter moves the recommended median (...)"; the applicability and
    efficiency pages differed too. Every figure page's drawn title is the title the contents list."""
    import matplotlib.pyplot as plt

    from rockfrag.report import build_plan
    from rockfrag.report.layout import TITLE_SIZE

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    checked = []
    for page in build_plan(results):
        if page.html is not None or page.name == "contents":
            continue
        figure = page.draw()
        try:
            bold = [text.get_text() for text in figure.texts if text.get_weight() == "bold"
                    and text.get_position()[1] > 0.95 and text.get_fontsize() >= 9.0 - 1e-9]
        finally:
            plt.close(figure)
        assert bold == [page.title], (page.name, bold, page.title)
        assert ") (" not in page.title, page.title  # "enclosure E-1 (a solid block ...) (R = 1.62 m, ...)"
        checked.append(page.name)
    assert {"sensitivity", "applicability", "efficiency"} & set(checked) and TITLE_SIZE >= 9, checked


def test_the_showcase_title_gives_r_and_alpha_without_a_second_pair_of_parentheses():
    """Cold read 8: "the enclosure E-1 (a solid block 1.2 m × 3.0 m, 4.5 t) (R = 1.62 m, α = 0.381 rad)"."""
    from rockfrag.report.figures import showcase_response_title

    showcase = xr.Dataset(attrs={"showcase_block": "enclosure", "block_R_m": 1.6155, "block_alpha_rad": 0.3805,
                                 "showcase_event": "Duzce, Turkey", "showcase_station": "Bolu",
                                 "showcase_component": "BOL090"})
    title = showcase_response_title(showcase, "enclosure E-1 (a solid block 1.2 m × 3.0 m, 4.5 t)")
    assert title == ("Duzce, Turkey, Bolu station, component 090: the enclosure E-1 (a solid block 1.2 m × 3.0 m, "
                     "4.5 t), R = 1.62 m, α = 0.381 rad, rocking on each soil"), title
    named = showcase_response_title(showcase, "block (R = 1.62 m, α = 0.381)")
    assert named.endswith(": the block (R = 1.62 m, α = 0.381) rocking on each soil"), named


def test_running_text_names_a_block_without_its_sizes(small_pipeline):
    """Cold read 8, user C1: "enclosure E-1 (a solid block 1.2 m × 3.0 m, 4.5 t)" stood whole about 30 times, inside
    sentences too. Titles, tables and the summary keep the whole name; running text drops the closing sizes."""
    from types import SimpleNamespace

    from rockfrag.report.adapters import block_name, short_block_name
    from rockfrag.report.sections import methods_items

    config = SimpleNamespace(raw={"report": {"block_names": {
        "enclosure": "enclosure E-1 (a solid block 1.2 m × 3.0 m, 4.5 t)", "bare": "(2 t)"}}})
    assert short_block_name(config, "enclosure") == "enclosure E-1"
    assert short_block_name(config, "bare") == "(2 t)" and short_block_name(config, "other") == "other"
    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    settlement = next(item.text for item in methods_items(results) if "m g / k" in item.text or "m·g/k" in item.text)
    for block in map(str, results.cube.block.values):
        short, whole = short_block_name(results.config, block), block_name(results.config, block)
        assert short != whole and f"{short}: " in settlement and f"{whole}: " not in settlement, settlement


def test_no_page_speaks_of_how_the_report_was_reviewed(small_pipeline):
    """The developers' notes ('cold read 9', 'finding 30') belong in the code, not on a page: the whole report,
    appendix included, names none."""
    html = (small_pipeline.output / "report.html").read_text()
    assert not re.findall(r"(?i)\bcold read\b|\bfindings? \d", html)
