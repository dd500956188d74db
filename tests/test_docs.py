"""The documentation site builds (``make docs``: warnings are errors), has its pages, and its tutorials ran.

The build runs once, on one pytest-xdist worker (``xdist_group``), beside the other tests. Its generated reference
pages are checked against the code they come from (the argument parser, the study schema, the netCDF attributes,
the docstrings), and every tutorial script must have run in this build: its page shows what it printed, and
sphinx-gallery's execution-time table lists it with a time.
"""

from __future__ import annotations

import html
import os
import re
import subprocess
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
SITE = DOCS / "_build" / "html"
TUTORIALS = sorted(path.stem for path in (DOCS / "examples").glob("*.py"))

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("docs")]

PAGES = {
    "getting-started.html": "Getting started",
    "guide/index.html": "User guide",
    "guide/command-line.html": "The command line",
    "guide/studies.html": "Study files",
    "guide/records.html": "Records and their processing",
    "guide/report.html": "How to read the report",
    "guide/exchange.html": "Exchange files",
    "guide/calibration.html": "Calibrating the interface",
    "default-study.html": "The default study and its answer",
    "tutorials/index.html": "Tutorials",
    "theory/index.html": "Theory",
    "theory/intensity.html": "Intensity",
    "theory/site.html": "The site",
    "theory/references.html": "References",
    "verification.html": "Verification",
    "reference/index.html": "Reference",
    "reference/cli.html": "Command line",
    "reference/study-keys.html": "Study keys",
    "reference/outputs.html": "Output variables",
    "reference/api.html": "API",
    "development/index.html": "Development",
    "development/performance.html": "Performance",
    "development/extending.html": "Extending rockfrag",
}
"""Pages the site must have, with the title each must carry."""


@pytest.fixture(scope="module")
def site():
    """Build the site with ``make docs`` (its own command, from scratch) and return the html folder."""
    environment = {key: value for key, value in os.environ.items() if not key.startswith(("MAKE", "MFLAGS"))}
    started = time.perf_counter()
    result = subprocess.run(["make", "--no-print-directory", "docs"], cwd=ROOT, env=environment,
                            capture_output=True, text=True, timeout=900)
    seconds = time.perf_counter() - started
    assert result.returncode == 0, f"make docs failed after {seconds:.0f} s:\n{result.stdout[-6000:]}\n" \
                                   f"{result.stderr[-6000:]}"
    return SITE


def text_of(page: Path) -> str:
    """The visible text of an html page (tags dropped, entities decoded, whitespace folded)."""
    body = re.sub(r"<(script|style)\b.*?</\1>", " ", page.read_text(encoding="utf-8"), flags=re.DOTALL)
    return " ".join(html.unescape(re.sub(r"<[^>]+>", " ", body)).split())


def test_every_page_is_there_with_its_title(site):
    for name, title in PAGES.items():
        page = site / name
        assert page.is_file(), f"the site has no {name}"
        assert re.search(rf"<title>{re.escape(title)}\b", page.read_text(encoding="utf-8")), \
            f"{name} is not titled {title!r}"


def test_the_site_builds_from_docs_only_with_pages_in_the_toctree(site):
    index = (site / "index.html").read_text(encoding="utf-8")
    for name in PAGES:
        assert f'href="{name}"' in index, f"{name} is not reachable from the front page"


def test_the_theory_pages_cite_what_they_rest_on(site):
    """The site term, the convolution, RotD50 and the credible cap are cited, with full references."""
    references = text_of(site / "theory" / "references.html")
    for source in ("Earthquake Spectra 30(3), 1057–1085", "1241–1256", "94(6), 2110–2123", "100(4), 1830–1835",
                   "Table 20.3-1", "Biometrika 26(4), 404–413", "MYG004"):
        assert source in references, f"the references lack {source!r}"
    site_page, intensity = text_of(site / "theory" / "site.html"), text_of(site / "theory" / "intensity.html")
    assert "Seyhan & Stewart" in site_page and "Bazzurro & Cornell" in site_page
    assert "Boore 2010" in intensity and "censored-at-cap" in intensity


def test_every_tutorial_ran_in_this_build(site):
    assert len(TUTORIALS) >= 5
    times = text_of(site / "tutorials" / "sg_execution_times.html")
    for stem in TUTORIALS:
        page = site / "tutorials" / f"{stem}.html"
        assert page.is_file(), f"tutorial {stem} has no page"
        assert "sphx-glr-script-out" in page.read_text(encoding="utf-8"), f"tutorial {stem} printed nothing"
        match = re.search(rf"\b{re.escape(stem)}\.py\s*\)?\s+(\d+):(\d+\.\d+)", times)
        assert match, f"tutorial {stem} is not in the execution times of this build"
        assert int(match[1]) * 60 + float(match[2]) > 0, f"tutorial {stem} took no time: it did not run"


def test_the_plotting_tutorials_drew_their_figures(site):
    for stem in TUTORIALS:
        source = (DOCS / "examples" / f"{stem}.py").read_text(encoding="utf-8")
        if "plt." in source or ".plot(" in source:
            images = list((DOCS / "tutorials" / "images").glob(f"sphx_glr_{stem}_*.png"))
            assert [image for image in images if "thumb" not in image.name], f"tutorial {stem} drew no figure"


def test_cli_reference_has_every_subcommand_and_option(site):
    import argparse

    from rockfrag.cli import build_parser

    page = text_of(site / "reference" / "cli.html")
    parser = build_parser()
    commands = next(action for action in parser._actions if isinstance(action, argparse._SubParsersAction))
    assert len(commands.choices) >= 6
    for name, command in commands.choices.items():
        assert f"rockfrag {name}" in page
        for action in command._actions:
            if action.help != argparse.SUPPRESS:
                for option in action.option_strings:
                    assert option in page, f"rockfrag {name} {option} is missing from the CLI reference"


def test_study_key_reference_has_every_schema_key(site):
    from rockfrag.config import study_keys

    page = text_of(site / "reference" / "study-keys.html")
    rows = study_keys()
    assert len(rows) > 40
    for key, _value, _default, allowed, _note in rows:
        assert key in page, f"study key {key} is missing from the reference"
        assert " ".join(allowed.split()) in page, f"the allowed values of {key} are missing"


def test_output_reference_carries_the_files_own_attributes(site):
    from rockfrag.cube import SLIP_VARIABLES, VARIABLES
    from rockfrag.models.fields import FIELDS_BY_NAME

    page = text_of(site / "reference" / "outputs.html")
    for name in ("cube.nc", "ida.nc", "fragility.nc"):
        assert name in page
    # the cube's run variables take their units and long names from the kernel's summary fields
    fields = {name: FIELDS_BY_NAME[field] for name, (field, _) in VARIABLES.items()}
    fields.update({name: FIELDS_BY_NAME[name] for name in SLIP_VARIABLES})
    assert len(fields) > 15
    for name, field in fields.items():
        assert f"{name} record, im_level, soil, block, model {field.units} {field.long_name}" in page, \
            f"the cube variable {name} is not listed with its units and long name"


def test_api_reference_documents_the_modules_from_their_docstrings(site):
    import rockfrag.models

    page = (site / "reference" / "api" / "rockfrag.models.html").read_text(encoding="utf-8")
    assert 'id="rockfrag.models.simulate"' in page
    summary = rockfrag.models.simulate.__doc__.split("\n")[0].replace("``", "")  # literals lose their quotes
    assert summary in text_of(site / "reference" / "api" / "rockfrag.models.html")
    assert len(list((site / "reference" / "api").glob("rockfrag.*.html"))) >= 40


def test_verification_tables_were_computed_in_this_build(site):
    page = text_of(site / "verification.html")
    assert "relative difference" in page
    assert not re.search(r"\bnan\b", page, flags=re.IGNORECASE), "a verification row came out NaN"
