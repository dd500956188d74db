"""Fuzzing (issue 13): Hypothesis-made corrupt AT2 files, processing recipes, study files and
calibration CSVs, run through ``rockfrag.cli.main`` in this process (a thousand processes would be
too slow; tests/test_reliability.py checks real processes). Every corrupt input must end in exit
status 1 or 2 with one line per problem on stderr, each starting with ``rockfrag:``, and no traceback.

Each generator applies a mutation that is invalid by construction, so a pass is never a fluke of
an input that happened to be valid. Deterministic (derandomized); about 1,100 inputs in total.
"""

from __future__ import annotations

import contextlib
import io
import math
import sys
import tomllib
from collections import Counter
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rockfrag import cli
from tests.reliability_helpers import at2_text, error_lines

FUZZ = settings(derandomize=True, database=None, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
COUNTS = {"at2": 450, "at2_with_good": 20, "recipe": 250, "study": 220, "csv": 160, "binary_study": 30}
"""Examples per fuzz test (sum >= 1,000: the issue's floor)."""
RAN: Counter = Counter()
"""Inputs each fuzz test really ran in this process: its first line counts one (checked by the last test)."""

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("fuzz")]  # in order on one worker: the count runs last

ROOT = Path(__file__).resolve().parents[2]


def run_cli(argv) -> tuple[int, str]:
    """(exit status, stderr) of ``rockfrag argv`` run in this process."""
    stderr, stdout = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(stdout):
        try:
            status = cli.main([str(a) for a in argv])
        except SystemExit as exit_:  # argparse
            status = exit_.code
    return status, stderr.getvalue()


def assert_clean_failure(status, stderr, allowed=(1, 2), max_lines=1):
    lines = error_lines(stderr)
    assert "Traceback" not in stderr, stderr
    assert status in allowed, (status, stderr)
    assert 1 <= len(lines) <= max_lines, stderr
    assert all(line.startswith("rockfrag") for line in lines), stderr


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz")
    good = folder / "good" / "good.AT2"
    good.parent.mkdir()
    good.write_text(at2_text())
    return folder, good


# ---------------------------------------------------------------- AT2 files

GOOD_AT2 = at2_text(npts=60)
GOOD_LINES = GOOD_AT2.splitlines()
HEADER, DATA = GOOD_LINES[:4], GOOD_LINES[4:]
VALUES = " ".join(DATA).split()


def _with_npts_dt(npts, dt, values, units="G"):
    lines = [HEADER[0], HEADER[1], f"ACCELERATION TIME SERIES IN UNITS OF {units}", f"NPTS= {npts}, DT= {dt} SEC"]
    lines += [" ".join(values[i:i + 5]) for i in range(0, len(values), 5)]
    return "\n".join(lines) + "\n"


@st.composite
def corrupt_at2(draw) -> bytes:
    kind = draw(st.sampled_from(["empty", "binary", "no header", "bad token", "non-finite", "truncated",
                                 "extra values", "bad dt", "tiny dt", "huge dt", "few samples", "all zero",
                                 "huge amplitude", "velocity", "garbage tail"]))
    n = len(VALUES)
    if kind == "empty":
        return draw(st.sampled_from([b"", b" ", b"\n\n", b"\r\n \t\n"]))
    if kind == "binary":
        blob = draw(st.binary(min_size=1, max_size=300))
        position = draw(st.integers(0, len(blob)))
        return blob[:position] + b"\x00" + blob[position:]
    if kind == "no header":
        lines = draw(st.lists(st.text(st.characters(blacklist_characters="\x00", blacklist_categories=["Cs"]),
                                      max_size=40), min_size=1, max_size=12))
        text = "\n".join(line for line in lines if "npts" not in line.lower() and "dt" not in line.lower())
        return (text + "\n" + "\n".join(DATA)).encode("utf-8")
    if kind in ("bad token", "non-finite", "garbage tail"):
        values = list(VALUES)
        index = draw(st.integers(0, n - 1))
        if kind == "bad token":
            values[index] = draw(st.sampled_from(["abc", "1.2.3", "--1", "0x1F", "1e", "一", "1,5", "."]))
        elif kind == "non-finite":
            values[index] = draw(st.sampled_from(["nan", "NaN", "inf", "-inf", "1e999", "-Infinity"]))
        else:
            values.append(draw(st.sampled_from(["END", "# comment", "x"])))
        return _with_npts_dt(n, 0.01, values).encode()
    if kind == "truncated":
        keep = draw(st.integers(0, n - 1))
        return _with_npts_dt(n, 0.01, VALUES[:keep]).encode()
    if kind == "extra values":
        extra = draw(st.integers(1, 20))
        return _with_npts_dt(n, 0.01, VALUES + ["1.0E-03"] * extra).encode()
    if kind == "bad dt":
        dt = draw(st.sampled_from(["0", "-0.01", "0.0", "-1e-3", "abc", "", "nan", "inf"]))
        return _with_npts_dt(n, dt, VALUES).encode()
    if kind == "tiny dt":
        dt = draw(st.floats(min_value=1e-300, max_value=9.9e-5))
        return _with_npts_dt(n, f"{dt:.6g}", VALUES).encode()
    if kind == "huge dt":
        dt = draw(st.floats(min_value=0.51, max_value=1e6))
        return _with_npts_dt(n, f"{dt:.6g}", VALUES).encode()
    if kind == "few samples":
        keep = draw(st.integers(1, 2))
        return _with_npts_dt(keep, 0.01, VALUES[:keep]).encode()
    if kind == "all zero":
        return _with_npts_dt(n, 0.01, [draw(st.sampled_from(["0", "0.0", "-0.0", "0.000E+00"]))] * n).encode()
    if kind == "huge amplitude":
        exponent = draw(st.integers(2, 305))
        return _with_npts_dt(n, 0.01, [f"{float(v) * 10.0**exponent * 100:.6E}" for v in VALUES]).encode()
    return _with_npts_dt(n, 0.01, VALUES, units=draw(st.sampled_from(["CM/S", "IN/S"]))) \
        .replace("ACCELERATION", "VELOCITY").encode()


@settings(FUZZ, max_examples=COUNTS["at2"])
@given(content=corrupt_at2(), suffix=st.sampled_from([".AT2", ".at2"]))
def test_fuzz_corrupt_at2_alone_is_a_user_error(workspace, content, suffix):
    RAN["at2"] += 1
    folder, _ = workspace
    path = folder / f"corrupt{suffix}"
    path.write_bytes(content)
    status, stderr = run_cli(["records", "--set", path, "--output", folder / "out", "--no-progress"])
    assert_clean_failure(status, stderr, allowed=(2,), max_lines=2)  # the file's reason, "nothing to do"
    assert str(path) in stderr


@settings(FUZZ, max_examples=COUNTS["at2_with_good"])
@given(content=corrupt_at2())
def test_fuzz_corrupt_at2_next_to_a_good_one_is_skipped(workspace, content):
    RAN["at2_with_good"] += 1
    folder, good = workspace
    path = good.parent / "corrupt.AT2"
    path.write_bytes(content)
    try:
        status, stderr = run_cli(["records", "--set", good.parent, "--output", folder / "out", "--no-progress"])
    finally:
        path.unlink()
    assert_clean_failure(status, stderr, allowed=(1,))
    assert "corrupt.AT2" in stderr and "skipped" in stderr


# ---------------------------------------------------------------- processing recipes

DEFAULT_RECIPE = tomllib.loads((ROOT / "pipeline" / "processing.toml").read_text())
RANGED = {("taper", "max_percentage"): (0.0, 0.5), ("pad", "factor"): (0.0, 20.0),
          ("bandpass", "freqmin"): (1e-3, 10.0), ("bandpass", "freqmax"): (0.5, 1000.0),
          ("bandpass", "corners"): (1, 10), ("bandpass", "nyquist_fraction"): (0.1, 0.99),
          ("baseline", "order"): (3, 12)}
QA_RANGES = {"tail_seconds": (0.1, 100.0), "velocity_ratio": (0.0, 10.0), "displacement_ratio": (0.0, 10.0)}
IDENTIFIER = st.from_regex(r"[a-z][a-z_]{0,12}", fullmatch=True)


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, float):
        if math.isfinite(value):
            return repr(value)
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f'"{k}" = {_toml_value(v)}' for k, v in value.items()) + "}"
    return str(value)


def recipe_text(steps, qa=None, overrides=None, extra="") -> str:
    parts = []
    for step in steps:
        parts.append("[[steps]]\n" + "".join(f"{k} = {_toml_value(v)}\n" for k, v in step.items()))
    if qa is not None:
        parts.append("[qa]\n" + "".join(f"{k} = {_toml_value(v)}\n" for k, v in qa.items()))
    if overrides is not None:
        parts.append(f"overrides = {_toml_value(overrides)}\n")
    return extra + "\n".join(parts)


def _out_of_range(draw, low, high):
    return draw(st.one_of(st.floats(max_value=low, exclude_max=True, allow_nan=False, allow_infinity=True),
                          st.floats(min_value=high, exclude_min=True, allow_nan=False, allow_infinity=True),
                          st.just(float("nan"))))


NOT_A_NUMBER = st.one_of(st.text(max_size=8), st.booleans(), st.lists(st.integers(), max_size=2),
                         st.just({"a": 1}))


@st.composite
def corrupt_recipe(draw) -> bytes:
    steps = [dict(step) for step in DEFAULT_RECIPE["steps"]]
    kind = draw(st.sampled_from(["unknown step", "unknown parameter", "out of range", "not a number",
                                 "no steps", "steps not a list", "step not a table", "nameless step",
                                 "pad without unpad", "qa unknown", "qa out of range", "qa not a table",
                                 "override unknown step", "override not a table", "syntax", "binary",
                                 "unknown table"]))
    if kind == "binary":
        return b"\x00\xff" + draw(st.binary(max_size=200))
    if kind == "syntax":
        broken = draw(st.sampled_from(["[[steps]\nname = 'x'\n", "steps = [\n", "name = = 1\n",
                                       "[qa]\ntail_seconds = \n", '[[steps]]\nname = "demean\n',
                                       "[[steps]]\nname = demean\n"]))
        return broken.encode()
    qa, overrides, extra = None, None, ""
    if kind == "unknown step":
        name = draw(IDENTIFIER.filter(lambda n: n not in {"demean", "detrend", "taper", "pad", "unpad",
                                                          "bandpass", "baseline"}))
        steps.insert(draw(st.integers(0, len(steps))), {"name": name})
    elif kind == "unknown parameter":
        index = draw(st.integers(0, len(steps) - 1))
        key = draw(IDENTIFIER.filter(lambda k: k not in steps[index] and k not in (
            "max_percentage", "type", "factor", "freqmin", "freqmax", "corners", "nyquist_fraction",
            "use_header_corners", "order")))
        steps[index][key] = draw(st.integers(0, 9))
    elif kind in ("out of range", "not a number"):
        step_name, key = draw(st.sampled_from(sorted(RANGED)))
        step = next(s for s in steps if s["name"] == step_name)
        step[key] = _out_of_range(draw, *RANGED[(step_name, key)]) if kind == "out of range" else draw(NOT_A_NUMBER)
    elif kind == "no steps":
        return draw(st.sampled_from([b"", b"steps = []\n", b"[qa]\ntail_seconds = 5.0\n"]))
    elif kind == "steps not a list":
        return f"steps = {_toml_value(draw(st.one_of(st.integers(), st.text(max_size=5))))}\n".encode()
    elif kind == "step not a table":
        return f"steps = [{_toml_value(draw(st.one_of(st.integers(), st.text(max_size=5))))}]\n".encode()
    elif kind == "nameless step":
        index = draw(st.integers(0, len(steps) - 1))
        steps[index].pop("name")
        if draw(st.booleans()):
            steps[index]["name"] = draw(st.one_of(st.integers(), st.booleans(), st.lists(st.integers(), max_size=2)))
    elif kind == "pad without unpad":
        steps = [s for s in steps if s["name"] != "unpad"]
    elif kind == "qa unknown":
        qa = {draw(IDENTIFIER.filter(lambda k: k not in QA_RANGES)): 1.0}
    elif kind == "qa out of range":
        key = draw(st.sampled_from(sorted(QA_RANGES)))
        qa = {key: draw(st.one_of(NOT_A_NUMBER, st.just(None).map(lambda _: _out_of_range(draw, *QA_RANGES[key]))))}
    elif kind == "qa not a table":
        extra = f"qa = {_toml_value(draw(st.one_of(st.integers(), st.text(max_size=5))))}\n"
    elif kind == "override unknown step":
        overrides = {draw(IDENTIFIER): {draw(IDENTIFIER.filter(lambda n: n not in [s['name'] for s in steps])): {}}}
    elif kind == "override not a table":
        overrides = draw(st.one_of(st.integers().map(lambda v: {"REC": v}),
                                   st.integers().map(lambda v: {"REC": {"taper": v}})))
    elif kind == "unknown table":
        extra = f"{draw(IDENTIFIER.filter(lambda k: k not in ('steps', 'qa', 'overrides')))} = 1\n"
    return recipe_text(steps, qa, overrides, extra).encode()


@settings(FUZZ, max_examples=COUNTS["recipe"])
@given(content=corrupt_recipe())
def test_fuzz_corrupt_recipe_is_a_user_error(workspace, content):
    RAN["recipe"] += 1
    folder, good = workspace
    path = folder / "recipe.toml"
    path.write_bytes(content)
    status, stderr = run_cli(["records", "--set", good, "--processing", path, "--output", folder / "out",
                              "--no-progress"])
    assert_clean_failure(status, stderr, allowed=(2,))
    assert str(path) in stderr


# ---------------------------------------------------------------- study files

STUDY_NUMBERS = {  # (table, key): (low, high, low_open)
    ("intensity", "period"): (0.01, 20.0, False), ("intensity", "damping"): (0.0, 0.5, False),
    ("solver", "tail"): (0.0, 600.0, False), ("solver", "overturn_angle"): (0.0, math.pi / 2, True),
    ("hazard", "design_life"): (0.0, 10000.0, True), ("fragility", "bootstrap"): (0, 100000, False),
    ("fragility", "seed"): (0, 2**32, False), ("fragility", "confidence"): (0.0, 1.0, True),
}
STUDY_TABLES = {"study": {"name", "record_sets", "processing", "output"},
                "intensity": {"measure", "period", "damping", "levels"},
                "solver": {"switch", "tail", "overturn_angle"}, "hazard": {"file", "design_life"},
                "fragility": {"bootstrap", "seed", "confidence"}}


@st.composite
def corrupt_study(draw) -> bytes:
    kind = draw(st.sampled_from(["unknown key", "unknown top key", "out of range", "unknown soil",
                                 "unknown model", "bad levels", "bad measure", "bad switch", "bad block",
                                 "syntax", "empty lists", "wrong type"]))
    if kind == "wrong type":
        table, key = draw(st.sampled_from(sorted(STUDY_NUMBERS)))
        return f"[{table}]\n{key} = {_toml_value(draw(NOT_A_NUMBER))}\n".encode()
    if kind == "syntax":
        return draw(st.sampled_from([b"[study\n", b"soils = [\n", b"[intensity]\nlevels = \n",
                                     b'[study]\nname = "x\n', b"= 1\n", b"[blocks.a]\nb = 1.0\nb = 2.0\n"]))
    if kind == "unknown key":
        table = draw(st.sampled_from(sorted(STUDY_TABLES)))
        key = draw(IDENTIFIER.filter(lambda k: k not in STUDY_TABLES[table]))
        return f"[{table}]\n{key} = 1\n".encode()
    if kind == "unknown top key":
        key = draw(IDENTIFIER.filter(lambda k: k not in {"soils", "models", "soils_custom", "blocks",
                                                         "damage_states", *STUDY_TABLES}))
        return f"{key} = 1\n".encode()
    if kind == "out of range":
        table, key = draw(st.sampled_from(sorted(STUDY_NUMBERS)))
        low, high, low_open = STUDY_NUMBERS[(table, key)]
        below = st.floats(max_value=low, exclude_max=not low_open, allow_nan=False)
        above = st.floats(min_value=high, exclude_min=True, allow_nan=False, allow_infinity=False)
        value = draw(st.one_of(below, above))
        if key in ("bootstrap", "seed"):
            value = draw(st.one_of(st.integers(max_value=-1), st.integers(min_value=int(high) + 1, max_value=2**62)))
        return f"[{table}]\n{key} = {_toml_value(value)}\n".encode()
    if kind == "unknown soil":
        name = draw(IDENTIFIER.filter(lambda n: n not in {"clay", "sand", "gravel", "rock", "steel"}))
        return f'soils = ["rock", "{name}"]\n'.encode()
    if kind == "unknown model":
        name = draw(IDENTIFIER.filter(lambda n: n not in {"housner", "ssi", "ssi_paper", "winkler"}))
        return f'models = ["housner", "{name}"]\n'.encode()
    if kind == "bad levels":
        levels = draw(st.sampled_from(["[]", "[0.5, 0.1]", "[0.2, 0.2]", "{ start = 1.0, stop = 0.5, count = 4 }",
                                       "{ start = 0.1, stop = 1.0, count = 0 }",
                                       "{ start = 0.1, stop = 1.0, count = 4, spacing = 'cubic' }"]))
        return f"[intensity]\nlevels = {levels}\n".encode()
    if kind == "bad measure":
        measure = draw(IDENTIFIER.filter(lambda m: m not in {"pga", "pgv", "sa"}))
        return f'[intensity]\nmeasure = "{measure}"\n'.encode()
    if kind == "bad switch":
        switch = draw(IDENTIFIER.filter(lambda m: m not in {"consistent", "continuous"}))
        return f'[solver]\nswitch = "{switch}"\n'.encode()
    if kind == "bad block":
        bad = draw(st.sampled_from(["b = -1.0\nh = 2.0\nmass = 10.0\n", "b = 1.0\nh = 2.0\nR = 3.0\nalpha = 0.3\n",
                                    "b = 1.0\nh = 2.0\ncolour = 'red'\n", "b = 1.0\nh = 0.0\nmass = 10.0\n"]))
        return f"[blocks.{draw(IDENTIFIER)}]\n{bad}".encode()
    return draw(st.sampled_from([b"soils = []\n", b"models = []\n", b"[study]\nrecord_sets = []\n"]))


@settings(FUZZ, max_examples=COUNTS["study"])
@given(content=corrupt_study())
def test_fuzz_corrupt_study_is_a_user_error(workspace, content):
    RAN["study"] += 1
    folder, _ = workspace
    path = folder / "study.toml"
    path.write_bytes(content)
    status, stderr = run_cli(["run", path, "--output", folder / "out", "--serial", "--no-progress"])
    assert_clean_failure(status, stderr, allowed=(2,))
    assert str(path) in stderr
    assert not (folder / "out" / "cube.nc").exists()


# ---------------------------------------------------------------- calibration references

@st.composite
def corrupt_reference(draw) -> bytes:
    n = draw(st.integers(12, 40))
    time = [round(0.01 * i, 4) for i in range(n)]
    theta = [round(0.001 * math.sin(i / 3.0), 6) for i in range(n)]
    kind = draw(st.sampled_from(["few rows", "one column", "text cell", "non-finite", "not increasing",
                                 "empty", "header only", "binary"]))
    if kind == "empty":
        return b""
    if kind == "binary":
        return b"\x00" + draw(st.binary(max_size=200))
    header = "time [s],theta [rad]"
    if kind == "header only":
        return (header + "\n").encode()
    if kind == "few rows":
        keep = draw(st.integers(1, 9))
        time, theta = time[:keep], theta[:keep]
    if kind == "one column":
        return ("time [s]\n" + "\n".join(map(str, time)) + "\n").encode()
    rows = [[str(t), str(a)] for t, a in zip(time, theta)]
    if kind in ("text cell", "non-finite"):
        row, column = draw(st.integers(0, len(rows) - 1)), draw(st.integers(0, 1))
        rows[row][column] = (draw(st.sampled_from(["abc", "n/a?", "--", "1.2.3", "x1"])) if kind == "text cell"
                             else draw(st.sampled_from(["nan", "inf", "-inf"])))
    if kind == "not increasing":
        i = draw(st.integers(1, len(rows) - 1))
        rows[i][0] = rows[i - 1][0] if draw(st.booleans()) else str(-1.0 - i)
    return (header + "\n" + "\n".join(",".join(r) for r in rows) + "\n").encode()


@settings(FUZZ, max_examples=COUNTS["csv"])
@given(content=corrupt_reference())
def test_fuzz_corrupt_calibration_reference_is_a_user_error(workspace, content):
    RAN["csv"] += 1
    folder, good = workspace
    path = folder / "reference.csv"
    path.write_bytes(content)
    status, stderr = run_cli(["calibrate", path, "--record", good, "--output", folder / "out", "--grid-only",
                              "--n-k", "2", "--n-xi", "2"])
    assert_clean_failure(status, stderr, allowed=(2,))
    assert str(path) in stderr


@settings(FUZZ, max_examples=COUNTS["binary_study"])
@given(content=st.binary(max_size=200))
def test_fuzz_binary_study_file_is_a_user_error(workspace, content):
    """A binary study file (issue 13); wrongly typed values are rows of test_reliability_issue_list."""
    RAN["binary_study"] += 1
    folder, _ = workspace
    path = folder / "binary.toml"
    path.write_bytes(b"\x00\xff" + content)
    status, stderr = run_cli(["run", path, "--output", folder / "out", "--serial", "--no-progress"])
    assert_clean_failure(status, stderr, allowed=(2,))
    assert str(path) in stderr


FUZZ_TESTS = {"at2": test_fuzz_corrupt_at2_alone_is_a_user_error,
              "at2_with_good": test_fuzz_corrupt_at2_next_to_a_good_one_is_skipped,
              "recipe": test_fuzz_corrupt_recipe_is_a_user_error, "study": test_fuzz_corrupt_study_is_a_user_error,
              "csv": test_fuzz_corrupt_calibration_reference_is_a_user_error,
              "binary_study": test_fuzz_binary_study_file_is_a_user_error}


def test_the_fuzz_ran_at_least_a_thousand_inputs(request):
    """Counts what the fuzz tests above really ran (RAN), not what they ask for: each selected one ran its
    COUNTS inputs through the CLI, and when all are selected, at least 1,000 together. Last in the module, which
    pytest runs in order (under xdist the module is one group, on one worker)."""
    module = sys.modules[__name__]
    selected = {item.name for item in request.session.items if getattr(item, "module", None) is module}
    expected = {kind: COUNTS[kind] for kind, test in FUZZ_TESTS.items() if test.__name__ in selected}
    if not expected:
        pytest.skip("no fuzz test selected: nothing to count")
    ran = {kind: RAN[kind] for kind in expected}
    elsewhere = "ran in another process? (xdist: --dist loadgroup)" if 0 in ran.values() else ""
    assert ran == expected, elsewhere
    if len(expected) == len(FUZZ_TESTS):
        assert sum(RAN.values()) >= 1000
