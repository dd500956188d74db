"""The public API is fully typed and documented in numpydoc sections (issue 17, the style gate).

ruff checks the docstring *format* of every public function; this test checks what ruff cannot: that the
entry points a user calls have an annotation on every parameter and on the return, and that their docstrings
hold the numpydoc sections a reader looks for (Parameters and Returns, with every parameter described).
"""

from __future__ import annotations

import inspect
import re

import pytest

from rockfrag import calibrate, config, fragility, hazard, models, outputs, processing, records, risk

PUBLIC_API = [
    models.simulate,
    models.simulate_batch,
    models.simulate_histories,
    records.load_records,
    processing.process_record,
    config.load_study,
    calibrate.calibrate,
    fragility.fragility_dataset,
    fragility.fragility_stage,
    fragility.pelicun_table,
    risk.risk_dataset,
    hazard.load_hazard,
    hazard.study_hazard,
    outputs.write_dataset,
]
"""The functions the README and the docs tell users to call."""


def _section(doc: str, title: str) -> str | None:
    """The body of numpydoc section ``title`` (up to the next section), or None if absent."""
    match = re.search(rf"^\s*{title}\n\s*-{{{len(title)}}}\n(.*?)(?=^\s*\w[\w ]*\n\s*-{{3,}}\n|\Z)", doc,
                      flags=re.S | re.M)
    return match.group(1) if match else None


@pytest.mark.parametrize("function", PUBLIC_API, ids=lambda f: f"{f.__module__}.{f.__name__}")
def test_public_function_is_fully_typed(function):
    signature = inspect.signature(function)
    untyped = [name for name, parameter in signature.parameters.items()
               if parameter.annotation is inspect.Parameter.empty]
    assert not untyped, f"{function.__qualname__}: parameters without a type annotation: {untyped}"
    assert signature.return_annotation is not inspect.Signature.empty, f"{function.__qualname__}: no return type"


@pytest.mark.parametrize("function", PUBLIC_API, ids=lambda f: f"{f.__module__}.{f.__name__}")
def test_public_function_has_numpydoc_sections(function):
    doc = inspect.getdoc(function) or ""
    parameters = _section(doc, "Parameters")
    assert parameters is not None, f"{function.__qualname__}: no 'Parameters' section"
    assert _section(doc, "Returns") is not None, f"{function.__qualname__}: no 'Returns' section"
    names = re.findall(r"^(\*{0,2}\w[\w, *]*?)(?: :|$)", parameters, flags=re.M)  # "a, b : int" lines
    described = {name.strip().lstrip("*") for line in names for name in line.split(",")}
    missing = [name for name in inspect.signature(function).parameters
               if name not in described and name.lstrip("*") not in described]
    assert not missing, f"{function.__qualname__}: parameters not described in 'Parameters': {missing}"


def test_the_section_parser_can_fail():
    """The checks above find a missing section and an undescribed parameter (they are not vacuous)."""
    def undocumented(a: int, b: int) -> int:
        """Add.

        Parameters
        ----------
        a : int
            One number.

        Returns
        -------
        int
        """
        return a + b

    with pytest.raises(AssertionError, match=r"not described.*\['b'\]"):
        test_public_function_has_numpydoc_sections(undocumented)
    with pytest.raises(AssertionError, match="no 'Parameters' section"):
        test_public_function_has_numpydoc_sections(lambda: None)
