"""rockfrag_docs - the reference pages generated from the code at every docs build.

Input : the installed ``rockfrag`` (its argument parser, study schema, and the files a tiny study writes)
        and the verification tests' references (``verification_tables``).
Output: MyST markdown fragments in ``docs/_generated/`` that the reference pages include:

- ``cli.md``: every ``rockfrag`` subcommand with its usage and options, from ``rockfrag.cli.build_parser``;
- ``study-keys.md``: every study key, its shipped default, what it must be and its note, from
  ``rockfrag.config.study_keys`` (the same rows as ``rockfrag study --keys``);
- ``outputs.md``: every variable of the netCDF files a study writes, with its dimensions, ``units`` and
  ``long_name`` as the files carry them (a tiny study is run into a temporary folder and its files read back);
- ``verification.md``: the verification tables (``verification_tables``).

Nothing here is typed twice: a changed option, key or attribute changes the page at the next build. A file is
rewritten only when its text changes, so an unchanged page is not re-read by Sphinx.
"""

from __future__ import annotations

import argparse
import logging
import re
import tempfile
import time
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1]
GENERATED = DOCS / "_generated"
TINY_STUDY = DOCS / "examples" / "my-site.toml"
"""The tutorials' tiny study (one block of one's own on one soil of one's own): the output-variable tables
are read from the files it writes."""


def cell(text: object) -> str:
    """One markdown table cell: pipes escaped, line breaks folded."""
    return " ".join(str(text).split()).replace("|", "\\|")


def table(header: list[str], rows: list[list[object]]) -> str:
    """A MyST (GitHub-flavoured) markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(value) for value in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def write_if_changed(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` unless it already holds it (Sphinx re-reads pages whose includes changed)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.is_file() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


# ---------------------------------------------------------------- the command line

def _option_names(action: argparse.Action) -> str:
    if not action.option_strings:
        return f"`{action.metavar or action.dest}`"
    metavar = action.metavar if action.metavar is not None else action.dest.upper()
    if action.nargs == 0:
        shown = ", ".join(f"`{name}`" for name in action.option_strings)
    else:
        if isinstance(metavar, tuple):
            values = " ".join(metavar)
        elif action.nargs in ("+", "*"):
            values = f"{metavar} [{metavar} ...]"
        elif isinstance(action.nargs, int) and action.nargs > 1:
            values = " ".join([metavar] * action.nargs)
        else:
            values = metavar
        shown = ", ".join(f"`{name} {values}`" for name in action.option_strings)
    return shown


def _help_text(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    formatter = parser._get_formatter()
    return formatter._expand_help(action) if action.help else ""


def cli_page() -> str:
    """Every subcommand of ``rockfrag``: its summary, usage line and a table of its arguments."""
    from rockfrag.cli import EXIT_CODES, build_parser

    parser = build_parser()
    subparsers = next(action for action in parser._actions if isinstance(action, argparse._SubParsersAction))
    summaries = {choice.dest: choice.help for choice in subparsers._choices_actions}
    parts = [f"{cell(parser.description)}\n", "```text\n" + parser.format_usage().strip() + "\n```\n"]
    for name, command in subparsers.choices.items():
        rows = [[_option_names(action), _help_text(command, action)] for action in command._actions
                if action.help != argparse.SUPPRESS and not isinstance(action, argparse._HelpAction)]
        parts += [f"# `rockfrag {name}`\n", f"{cell(summaries.get(name, ''))}\n",
                  "```text\n" + command.format_usage().strip() + "\n```\n", table(["argument", "meaning"], rows)]
    parts += ["# Exit status\n", "```text\n" + EXIT_CODES.strip() + "\n```\n"]
    return "\n".join(parts)


# ---------------------------------------------------------------- the study keys

def study_keys_page() -> str:
    """The rows of ``rockfrag study --keys`` for the shipped default study, grouped by table."""
    from rockfrag.config import study_keys

    rows = study_keys()
    parts, group, current = [], [], None

    def flush():
        if group:
            title = f"`[{current}]`" if current else "Top-level keys"
            parts.extend([f"# {title}\n", table(["key", "default", "allowed", "note"], group)])

    for key, _value, default, allowed, note in rows:
        head = key.split(".", 1)[0] if "." in key else ""
        if head != current:
            flush()
            group, current = [], head
        group.append([f"`{key}`", f"`{default}`" if default else "", allowed, note])
    flush()
    return "\n".join(parts)


# ---------------------------------------------------------------- the output variables

OUTPUT_FILES = {
    "cube.nc": "the study cube: one value per record, intensity level, soil, block and model",
    "showcase.nc": "the showcase record's histories for the report",
    "ida.nc": "incremental dynamic analysis curves, fractiles and capacities",
    "efficiency.nc": "the intensity measures ranked by the dispersion of the capacities",
    "fragility.nc": "the lognormal fragility per soil, block, model and damage state, and the risk",
}
"""The netCDF files a study writes (``rockfrag fragility``), in the order the stages write them."""


def run_tiny_study(output: Path) -> None:
    """Run the tutorials' tiny study through the stages of ``rockfrag fragility`` (without the report)."""
    import contextlib
    import io

    from rockfrag.config import load_study
    from rockfrag.efficiency import efficiency_stage
    from rockfrag.fragility import fragility_stage
    from rockfrag.ida import ida_stage
    from rockfrag.showcase import showcase_stage
    from rockfrag.study import run_study, study_records

    quiet = io.StringIO()
    with contextlib.redirect_stdout(quiet), contextlib.redirect_stderr(quiet):
        config = load_study(TINY_STUDY)
        loaded = study_records(config, log=lambda message: None)
        cube, _ = run_study(config, output=output, workers=1, progress=False, loaded=loaded,
                            log=lambda message: None, warn=lambda message: None)
        showcase_stage(config, output, loaded, log=lambda message: None)
        ida = ida_stage(cube, output)
        efficiency_stage(cube, loaded.records, config, output)
        fragility_stage(cube, ida, config, output, progress=False, log=lambda message: None)


def variables_table(path: Path) -> str:
    """Every variable of one netCDF file with its dimensions, units and long name, as the file stores them."""
    import netCDF4

    rows = []
    with netCDF4.Dataset(path) as dataset:
        for name, variable in dataset.variables.items():
            attrs = variable.__dict__
            rows.append([f"`{name}`", ", ".join(variable.dimensions), f"`{attrs['units']}`" if "units" in attrs
                         else "", attrs.get("long_name", "")])
    return table(["variable", "dimensions", "units", "long_name"], rows)


def outputs_page() -> str:
    """A table per netCDF file of the tiny study, read back from the files."""
    with tempfile.TemporaryDirectory(prefix="rockfrag-docs-") as folder:
        output = Path(folder)
        run_tiny_study(output)
        parts = []
        for name, what in OUTPUT_FILES.items():
            if not (output / name).is_file():
                raise FileNotFoundError(f"the tiny study {TINY_STUDY} wrote no {name}: update OUTPUT_FILES")
            parts += [f"# `{name}`\n", f"{what[0].upper()}{what[1:]}.\n", variables_table(output / name)]
    return "\n".join(parts)


# ---------------------------------------------------------------- the API

API = DOCS / "reference" / "api"
"""One page per module of ``rockfrag`` (generated; ``reference/api.md`` lists them)."""


def module_names() -> list[str]:
    """Every module of the installed ``rockfrag``, in the package's order (``__main__`` runs the CLI: left out)."""
    import pkgutil

    import rockfrag

    names = ["rockfrag"]
    for module in pkgutil.walk_packages(rockfrag.__path__, "rockfrag."):
        if module.name.rsplit(".", 1)[-1] != "__main__":
            names.append(module.name)
    return names


def public_members(module_name: str) -> list[str]:
    """The module's ``__all__``, else the public functions and classes it defines, in source order."""
    import importlib
    import inspect

    module = importlib.import_module(module_name)
    if hasattr(module, "__all__"):
        return [name for name in module.__all__ if not inspect.ismodule(getattr(module, name))]
    members = [(name, value) for name, value in vars(module).items() if not name.startswith("_")
               and (inspect.isfunction(value) or inspect.isclass(value))
               and getattr(value, "__module__", None) == module_name]

    def line(item):
        try:
            return inspect.getsourcelines(item[1])[1]
        except (OSError, TypeError):
            return 0

    return [name for name, _ in sorted(members, key=line)]


def _directive(module_name: str, member: str) -> str:
    """The autodoc directive that documents one member (classes with their public methods)."""
    import importlib
    import inspect

    value = getattr(importlib.import_module(module_name), member)
    if inspect.isclass(value) and issubclass(value, BaseException):
        return f".. autoexception:: {module_name}.{member}"
    if inspect.isclass(value):
        return f".. autoclass:: {module_name}.{member}\n   :members:"
    if callable(value):
        return f".. autofunction:: {module_name}.{member}"
    return f".. autodata:: {module_name}.{member}\n   :no-value:"


def api_pages() -> str:
    """Write one page per module (summary table, then autodoc of the members); returns the modules' table."""
    API.mkdir(parents=True, exist_ok=True)
    docnames = []
    for name in module_names():
        members = public_members(name)
        summary = ["", ".. autosummary::", "", *(f"   {member}" for member in members), ""] if members else []
        text = "\n".join([name, "=" * len(name), "", f".. automodule:: {name}", "   :no-members:", *summary,
                          *(f"{_directive(name, member)}\n" for member in members)])
        write_if_changed(API / f"{name}.rst", text + "\n")
        docnames.append(name)
    for old in {path.stem for path in API.glob("*.rst")} - set(docnames):
        (API / f"{old}.rst").unlink()
    listing = ["```{eval-rst}", ".. autosummary::", "", *(f"   {name}" for name in docnames), "", "```", "",
               "```{toctree}", ":hidden:", "", *(f"/reference/api/{name}" for name in docnames), "```"]
    return "\n".join(listing) + "\n"


# ---------------------------------------------------------------- docstrings as the code writes them

# The docstrings are numpydoc for the API and plain text with aligned columns in the module headers (STYLE.md:
# "Input : ... / Output: ..."). Two plain-text habits are reStructuredText markup by accident: |x| (a
# substitution reference in RST, an absolute value here) and a lone * (emphasis in RST, a glob or product here).
LITERAL = re.compile(r"(``.+?``)")
PARAMETER_LINE = re.compile(r"^\s*\*{1,2}\w+\s*(:|,|$)")  # numpydoc's own escaping handles *args, **options
EMPHASIS = re.compile(r"(?<![\w*\\])\*(?=[^\s*])[^*]*?(?<=[^\s\\])\*(?![\w*])")


def _escape_outside_literals(line: str) -> str:
    if PARAMETER_LINE.match(line) or line.lstrip().startswith(("+-", "+=", "..")):
        return line
    parts = LITERAL.split(line)
    for index in range(0, len(parts), 2):  # the even parts lie outside ``literals``
        text = parts[index].replace("|", "\\|")
        kept = [match.span() for match in EMPHASIS.finditer(text)]
        text = "".join(char if char != "*" or any(low <= position < high for low, high in kept) else "\\*"
                       for position, char in enumerate(text))
        parts[index] = text
    return "".join(parts)


def _rst_problems(text: str) -> list[str]:
    """Docutils' complaints about ``text`` as reStructuredText, bar Sphinx's own roles and directives."""
    import io

    from docutils import nodes
    from docutils.core import publish_doctree

    doctree = publish_doctree(text, settings_overrides={"report_level": 5, "halt_level": 5,
                                                        "warning_stream": io.StringIO()})
    problems = []
    for message in doctree.findall(nodes.system_message):
        words = message.astext()
        if message["level"] >= 2 and "Unknown interpreted text role" not in words \
                and "Unknown directive type" not in words and "No role entry" not in words:
            problems.append(words)
    return problems


def plain_text_guard(app, what, name, obj, options, lines) -> None:
    """Escape accidental markup; show a module header that is not valid RST as the text it is.

    Connected to ``autodoc-process-docstring`` before numpydoc, so numpydoc sees the escaped text.
    """
    if what in ("data", "attribute") and obj is not None and lines and \
            "\n".join(lines).strip() == str(type(obj).__doc__ or "").strip():
        lines[:] = []  # a value without a docstring of its own: not the docstring of its type (numpy.dtype)
        return
    lines[:] = [_escape_outside_literals(line) for line in lines]
    if what == "module" and _rst_problems("\n".join(lines)):
        title, rest = lines[:1], lines[1:]
        lines[:] = [*title, "", "::", "", *("    " + line for line in rest)]


# ---------------------------------------------------------------- Sphinx

PAGES = {
    "cli.md": cli_page,
    "study-keys.md": study_keys_page,
    "outputs.md": outputs_page,
    "api-modules.md": api_pages,
}


def generate(app) -> None:
    """Write every generated fragment (Sphinx ``builder-inited``), timing each in the build log."""
    import verification_tables
    from sphinx.util import logging

    logger = logging.getLogger(__name__)
    pages = {**PAGES, "verification.md": verification_tables.page}
    for name, make in pages.items():
        started = time.perf_counter()
        write_if_changed(GENERATED / name, make())
        logger.info(f"rockfrag_docs: _generated/{name} in {time.perf_counter() - started:.1f} s")


def _quiet_root_logger() -> None:
    """Undo the root-logger set-up that accessible-pygments (furo's) does when imported.

    accessible-pygments 0.0.5 calls ``logging.basicConfig(level=INFO)`` at import: every library's INFO lines (the
    dask cluster of a tutorial) would be printed into the build log. Import it now and restore the root logger.
    """
    root = logging.getLogger()
    handlers, level = list(root.handlers), root.level
    try:
        import a11y_pygments  # noqa: F401
    except ImportError:
        return
    for handler in [handler for handler in root.handlers if handler not in handlers]:
        root.removeHandler(handler)
    root.setLevel(level)


def setup(app):
    """Register the generator with Sphinx."""
    _quiet_root_logger()
    app.connect("builder-inited", generate)
    app.connect("autodoc-process-docstring", plain_text_guard, priority=400)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
