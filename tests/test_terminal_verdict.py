"""The terminal's verdict per asset and soil says what the report's summary page says (issue 32 item 6).

``rockfrag fragility`` prints, after the answer table, one line per block and soil: the action, the governing
damage state, its probability in the design life with the limit, and the reason (where a bound, the credible cap or
the fitted tail decides). The words come from the functions that write the summary page; here they are checked
against the summary page of the small pipeline's report as written (report.html), not against themselves.
"""

from __future__ import annotations

import html
import re

import pytest

from rockfrag.report.summary import terminal_verdicts, verdict_rows
from tests.helpers import pipeline_results


@pytest.fixture(scope="module")
def results(small_pipeline):
    return pipeline_results(small_pipeline.output, small_pipeline.study)


def _page_text(small_pipeline) -> str:
    text = (small_pipeline.output / "report.html").read_text(encoding="utf-8")
    return html.unescape(re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", text)))


def test_every_asset_and_soil_has_a_line_in_the_summary_pages_words(results, small_pipeline):
    text = terminal_verdicts(results)
    page = _page_text(small_pipeline)
    lines = text.splitlines()
    assert lines[0].startswith("Verdict per asset and soil (probabilities in 50 years with ")
    rows = [(answer, row) for answer in results.answers for row in verdict_rows(results, answer)]
    assert len(rows) == results.fragility.sizes["block"] * results.fragility.sizes["soil"]
    for answer, row in rows:
        # the line of this soil holds the action, the state, the probability with its limit and the reason ...
        assert any(row["soil"] in line and row["action"] in line and row["state"] in line and row["life"] in line
                   and line.rstrip().endswith(row["reason"]) for line in lines), (answer.block, row)
        # ... and the report's summary page prints the same words
        for words in (row["action"], row["life"], row["reason"]):
            assert words in page, (answer.block, row["soil"], words)


def test_the_hazard_is_named(results):
    first = terminal_verdicts(results).splitlines()[0]
    assert "hazard" in first and "years" in first
