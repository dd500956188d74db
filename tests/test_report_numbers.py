"""One number per fact, and one precision policy (issue 36, items 2 and 3): every probability the report prints
comes from one formatter, and a fact printed on several pages reads the same on each. The check collects every
printed value of a quantity across the pages (the ledger of rockfrag.report.numbers, checked against the pages'
own text) and is shown to fail on a page that prints a fact its own way."""

from __future__ import annotations

import html as html_module
import re

import numpy as np
import pytest

from rockfrag.report import numbers
from tests.helpers import pipeline_results


@pytest.mark.parametrize("value, shown", [
    (0.123, "12%"), (0.0234, "2.3%"), (0.00812, "0.81%"), (0.0010, "0.10%"), (0.004028, "0.40%"), (0.02, "2.0%"),
    (0.00099, "< 0.1%"),
    (0.00052, "< 0.1%"), (0.0, "0%"), (1.0, "100%"), (0.996, "> 99%"), (0.994, "99%"), (0.5, "50%"),
    (0.0999, "10%"), (np.nan, "-"), (None, "-")])
def test_probabilities_print_to_two_significant_figures_and_below_a_tenth_of_a_percent_as_a_bound(value, shown):
    assert numbers.probability(value) == shown


def test_bounds_say_their_side_and_a_certainty_is_not_bounded():
    assert numbers.bound(0.0081, "<") == "< 0.81%"
    assert numbers.bound(0.61, "≥") == "≥ 61%"
    assert numbers.bound(1.0, "≥") == "100%"
    assert numbers.bound(0.0004, "<") == "< 0.1%"


def test_inputs_print_as_stated():
    assert numbers.as_stated(0.35) == "0.35" and numbers.as_stated(2475.0) == "2,475" and numbers.years(50) == \
        "50 years"


def _visible(html: str) -> str:
    return " ".join(html_module.unescape(re.sub(r"<[^>]+>", " ", html)).split())


def _plan(small_pipeline):
    from rockfrag.report import build_plan

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    return results, build_plan(results)


def test_every_fact_prints_the_same_on_every_page_and_the_ledger_is_what_the_pages_print(small_pipeline):
    results, planned = _plan(small_pipeline)
    printed = results.facts.printed
    quantities = {quantity for quantity, _ in printed}
    assert {"P in the design life", "P at a return period", "site intensity"} <= quantities
    assert results.facts.disagreements() == {}
    text = {}
    for page in planned:
        if page.html is not None:
            for section in (page.section, *page.also):
                text[section] = text.get(section, "") + " " + _visible(page.html)
    for (quantity, subject), said in printed.items():
        for shown, section in said:
            assert section in text, (quantity, subject, section)
            assert " ".join(shown.split()) in text[section], (quantity, subject, shown, section)


def test_the_summary_and_the_answer_pages_print_the_same_probability_in_the_design_life(small_pipeline):
    """Read from the pages' tables, not from the ledger: the summary's 'P in N years' of each asset and soil is the
    cell of the same damage state and soil in the answer page's design-life table."""
    from rockfrag.report.adapters import block_name
    from rockfrag.report.answer_page import answer_items
    from rockfrag.report.summary import summary_items

    results, _ = _plan(small_pipeline)
    summary = next(item for item in summary_items(results) if item.kind == "table")
    column = next(i for i, head in enumerate(summary.header) if head.startswith("P in "))
    answers = {block_name(results.config, answer.block): answer for answer in results.answers}
    checked, block = 0, None
    for row in summary.rows:
        if row[0] and not any(row[1:]):  # an asset's heading row
            block = answers[row[0]]
            continue
        soil, state, life = row[0], row[2], row[column]
        if life == "-":
            continue
        table = next(item for item in answer_items(results, block) if item.kind == "table"
                     and item.header[:2] == ["damage state", "limit"])
        cells = next(cells for cells in table.rows if cells[0] == state)
        page = cells[table.header.index(f"on {soil}")].split(", once in")[0]
        assert page == life.split(" (")[0], (block.block, soil, state)
        checked += 1
    assert checked == sum(len(answer.soils) for answer in results.answers)


def test_a_page_that_prints_a_fact_its_own_way_is_caught(small_pipeline, monkeypatch):
    """The seeded defect: the answer pages print P in the design life to three decimals in percent."""
    import rockfrag.report.answer_page as answer_page

    def own_way(results, answer, soil, row):
        return results.facts.say("P in the design life", (answer.block, soil.soil, row.state),
                                 f"{100 * row.probability_in_life:.3f}%")

    monkeypatch.setattr(answer_page, "say_p_in_life", own_way)
    results, _ = _plan(small_pipeline)
    found = results.facts.disagreements()
    assert found and {quantity for quantity, _ in found} == {"P in the design life"}
    for texts in found.values():  # the summary's text and the answer page's own
        sections = [section for printed in texts.values() for section in printed]
        assert "Summary" in sections and any(section.startswith("Answer: ") for section in sections)
