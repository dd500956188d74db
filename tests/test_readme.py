"""The README's and the documentation pages' examples run as printed: the Python blocks execute (on one shipped
record), every `rockfrag` line parses with the real command-line parser, every `make` target named exists, and the
outputs table (docs/reference/outputs.md) names what `rockfrag fragility` writes, checked on the session's small
pipeline run (fixture ``small_pipeline``). The README is the front page; the long sections it held are pages of the
documentation site (docs/), read here as written (their Markdown sources)."""

from __future__ import annotations

import re
import shlex
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
PAGES = sorted(path for folder in ("docs", "docs/guide", "docs/theory", "docs/development", "docs/reference")
               for path in (ROOT / folder).glob("*.md"))
"""The hand-written pages of the documentation site (not the generated reference, the tutorials or the build)."""
SOURCES = {"README.md": README, **{str(path.relative_to(ROOT)): path.read_text(encoding="utf-8") for path in PAGES}}
TEXT = "\n".join(SOURCES.values())
FENCE = re.compile(r"^```([^\n]*)\n(.*?)^```", re.MULTILINE | re.DOTALL)  # any info string: ```{toctree} too


def code_blocks(language, text=None):
    """The bodies of the fenced blocks in ``language`` ("" for none) of ``text``, else of every source."""
    texts = [text] if text is not None else SOURCES.values()
    return [body for source in texts for lang, body in FENCE.findall(source) if lang.strip() == language]


def command_lines(program):
    lines = []
    for body in code_blocks(""):
        for line in body.splitlines():
            line = line.split("#", 1)[0].strip()
            if line.startswith(program + " "):
                lines.append(line)
    return lines


def test_readme_has_python_examples_and_commands():
    assert code_blocks("python", README), "the README lost its Python example"
    assert command_lines("rockfrag") and command_lines("make")
    assert len(PAGES) >= 15, "the documentation pages are not where this test reads them"


def test_readme_is_a_front_page_that_says_where_the_docs_are():
    assert len(README.splitlines()) <= 250, "the README is a front page of at most 250 lines"
    for needed in ("make fragility", "make test", "make docs", "docs/_build/html/index.html", "```python"):
        assert needed in README, f"the front page lost {needed!r}"


@pytest.mark.parametrize("number", range(len(code_blocks("python"))))
def test_python_example_runs_as_printed(number, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # an example that writes files writes them here
    namespace = {"__name__": "__readme__"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # physics warnings (e.g. tension) are fine to print
        exec(compile(code_blocks("python")[number], f"python block {number + 1} of the README and docs", "exec"),
             namespace)
    assert capsys.readouterr().out.strip(), "the example should print what it computed"


def test_every_rockfrag_line_parses():
    from rockfrag.cli import build_parser

    parser = build_parser()
    checked = 0
    for line in command_lines("rockfrag"):
        words = shlex.split(line)[1:]
        words = [w for w in words if not (w.startswith("[") and w.endswith("]"))]  # optional arguments shown as [x]
        if not words or words[0].isupper():  # `rockfrag COMMAND --help` is a pattern, not a command
            continue
        try:
            parser.parse_args(words)
        except SystemExit as error:
            pytest.fail(f"documented line does not parse: {line!r} (exit {error.code})")
        checked += 1
    assert checked >= 5


def test_every_make_target_exists():
    makefile = (ROOT / "Makefile").read_text()
    targets = set(re.findall(r"^([a-z][\w-]*):", makefile, re.MULTILINE))
    named = {shlex.split(line)[1] for line in command_lines("make")}
    named |= set(re.findall(r"`make ([a-z][\w-]*)`", TEXT))
    missing = named - targets
    assert not missing, f"the README or the docs name make targets the Makefile lacks: {sorted(missing)}"


def test_readme_says_where_rockfrag_lives():
    assert ".venv/bin/rockfrag" in README


def outputs_table() -> dict[str, str]:
    """{file cell: written-by cell} of the outputs table (docs/reference/outputs.md, "The files")."""
    section = SOURCES["docs/reference/outputs.md"].split("## The files", 1)[1].split("\n## ", 1)[0]
    rows = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 3 and cells[0].startswith("`"):
            rows[cells[0]] = cells[1]
    return rows


def test_outputs_table_names_a_command_for_every_file():
    rows = outputs_table()
    assert rows, "outputs table not found"
    for name, writer in rows.items():
        assert "rockfrag" in writer, f"{name}: no command named in the 'written by' column"


@pytest.mark.slow
def test_outputs_table_matches_what_fragility_writes(small_pipeline):
    claimed, not_claimed = [], []
    for cell, writer in outputs_table().items():
        cell = re.sub(r"\{(\w+),\w+\}", r"\1", cell)  # calibration.{json,csv} -> calibration.json
        names = [name.strip("` ").rstrip("/") for name in cell.split(",")]
        (claimed if "rockfrag fragility" in writer else not_claimed).extend(names)
    assert "cube.nc" in claimed and "records.csv" in not_claimed
    output = small_pipeline.output
    for name in claimed:
        found = list(output.glob(name))
        assert found and all(p.is_dir() or p.stat().st_size > 0 for p in found), f"table: fragility writes {name}"
    for name in not_claimed:
        assert not list(output.glob(name)), f"the outputs table says only another command writes {name}"
    assert not list(output.glob(".*.part"))


def runnable_commands() -> list[str]:
    """The documented `rockfrag` lines that run on shipped inputs in seconds: `rockfrag study` and every line on a
    shipped file under studies/ (the default-study runs take minutes: CI's clean clone covers those through the
    same commands on the small study; dask lines start a cluster of processes, tested on their own elsewhere)."""
    lines = []
    for line in command_lines("rockfrag"):
        words = [w for w in shlex.split(line)[1:] if not (w.startswith("[") and w.endswith("]"))]
        if not words or words[0].isupper() or "--scheduler" in words:
            continue  # a pattern, or dask: the local cluster is tested in test_executors.py and test_study.py
        if words[0] == "study" or any(w.startswith("studies/") for w in words):
            lines.append(" ".join(words))
    return list(dict.fromkeys(lines))


@pytest.mark.slow
@pytest.mark.xdist_group("readme-commands")
def test_readme_commands_on_shipped_inputs_run_as_printed(tmp_path, capsys):
    """Each such line runs with the real `rockfrag` and exits 0 (outputs go to a temporary folder)."""
    from rockfrag.cli import main

    commands = runnable_commands()
    assert any(c.startswith("fragility studies/example.toml") for c in commands)
    assert any(c.startswith("calibrate studies/calibration-reference.csv") for c in commands)
    output = tmp_path / "out"
    for command in commands:
        words = shlex.split(command)
        if words[0] != "study":
            words += ["--output", str(output), "--no-progress"]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            status = main(words)
        assert status == 0, f"documented line failed: rockfrag {command}: {capsys.readouterr().err[-500:]}"
