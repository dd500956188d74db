"""The registries are the only owners of their facts, and an installed package can add to them (issue 35 item 2)."""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from rockfrag.config import load_study
from rockfrag.damage_states import DAMAGE_STATES, DEFAULT_LIMITS, DamageState, register_damage_state
from tests.helpers import SMALL_STUDY


@pytest.fixture
def judged_state():
    """A damage state with its own verdict limit, registered for one test."""
    state = DamageState("rocking-0.7", "peak_angle_ratio", 0.7, "theta_max/alpha >= 0.7", limit=0.05,
                        limit_source="a limit of the test's own")
    register_damage_state(state)
    yield state
    del DAMAGE_STATES[state.name]


def test_shipped_limits_are_the_registrys():
    assert dict(DEFAULT_LIMITS) == {"overturning": 0.01, "rocking-0.5": 0.10, "slip-0.30": 0.10}
    assert list(DEFAULT_LIMITS) == ["overturning", "rocking-0.5", "slip-0.30"]  # most severe first
    assert "ASCE 7-22" in DAMAGE_STATES["overturning"].limit_source
    assert DAMAGE_STATES["rocking-0.2"].limit is None  # reported, not judged


def test_a_registered_limit_is_a_default_of_every_study(judged_state, tmp_path):
    assert DEFAULT_LIMITS["rocking-0.7"] == 0.05
    assert load_study().raw["decision"]["max_probability_in_life"]["rocking-0.7"] == 0.05
    study = tmp_path / "s.toml"
    study.write_text('[decision]\nmax_probability_in_life = { "rocking-0.7" = 0.2 }\n')
    limits = load_study(study).raw["decision"]["max_probability_in_life"]
    assert limits["rocking-0.7"] == 0.2 and limits["overturning"] == 0.01  # the study's own, the rest merged
    names = list(DAMAGE_STATES)
    assert names.index("rocking-0.5") < names.index("rocking-0.7") < names.index("overturning")


def test_a_limit_is_not_a_study_key_of_a_damage_state(tmp_path):
    from rockfrag.errors import ConfigError

    study = tmp_path / "s.toml"
    study.write_text('[damage_states.rocking7]\nedp = "peak_angle_ratio"\nthreshold = 0.7\nlimit = 0.05\n')
    with pytest.raises(ConfigError) as error:
        load_study(study)
    assert "limit" in error.value.field and "allowed: description, edp, threshold" in str(error.value)


# ---------------------------------------------------------------- an installed package adds to the registries

TOY = Path(__file__).resolve().parent / "plugin_toy"
"""The toy plugin's source (docs/plugins.md's worked example): a measure, a damage state, a record format and two
contact laws."""

TOY_STUDY = SMALL_STUDY.replace("[intensity]\nlevels = [0.1, 0.3, 0.6, 1.0]\n", """[intensity]
measure = "a_rms"
component = "single"
levels = [0.02, 0.06, 0.12, 0.2]
""") + "[fragility]\nbootstrap = 5\n"
"""The small study scaled to the toy's measure (no RotD form: each component its own; levels of a_rms in g)."""


def install(source: Path, folder: Path) -> Path:
    """Build ``source``'s wheel with its own backend (no isolation, no network) and install it into a folder.

    A pure-Python wheel is installed by unpacking it: the package beside its ``.dist-info`` (whose
    ``entry_points.txt`` importlib.metadata reads), as pip would put them in site-packages.
    """
    work = folder / "build"
    shutil.copytree(source, work)
    subprocess.run([sys.executable, "-c", "from setuptools import build_meta; build_meta.build_wheel('../dist')"],
                   cwd=work, check=True, capture_output=True)
    site = folder / "site"
    with zipfile.ZipFile(next((folder / "dist").glob("*.whl"))) as wheel:
        wheel.extractall(site)
    return site


def rockfrag_with(site: Path, *arguments: str, cwd: Path) -> subprocess.CompletedProcess:
    """Run ``python *arguments`` with the packages installed in ``site`` importable (a fresh process)."""
    paths = [str(site), *filter(None, [os.environ.get("PYTHONPATH")])]
    return subprocess.run([sys.executable, *arguments], cwd=cwd, capture_output=True, text=True, timeout=600,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(paths)})


@pytest.fixture(scope="module")
def toy_site(tmp_path_factory) -> Path:
    """The toy plugin, built and installed into a folder of its own."""
    return install(TOY, tmp_path_factory.mktemp("toy"))


def test_the_toy_plugin_is_not_installed_here():
    from rockfrag.measures import MEASURES

    assert "a_rms" not in MEASURES and "rocking-0.8" not in DAMAGE_STATES  # the test below sees it in its process only


def test_a_plugin_measure_and_damage_state_run_in_the_small_study(toy_site, tmp_path):
    import numpy as np
    import xarray as xr

    from rockfrag.processing import process_record
    from rockfrag.records import load_records
    from rockfrag.units import STANDARD_GRAVITY

    (tmp_path / "study.toml").write_text(TOY_STUDY)
    run = rockfrag_with(toy_site, "-m", "rockfrag", "fragility", "study.toml", "--output", "out", "--no-progress",
                        "--serial", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    # the study scaled each record to the toy's measure: a_rms of the processed record, computed here by hand
    cube = xr.open_dataset(tmp_path / "out" / "cube.nc")
    assert cube.attrs["intensity_measure"] == "a_rms"
    records, _ = load_records("bolu")
    by_hand = {r.id: np.sqrt(np.mean(process_record(r).acceleration ** 2)) / STANDARD_GRAVITY for r in records}
    expected = np.array([by_hand[r] for r in cube.record.values])[:, None]  # every block alike
    np.testing.assert_allclose(cube.record_im.transpose("record", "block").values,
                               np.broadcast_to(expected, (cube.sizes["record"], cube.sizes["block"])), rtol=1e-9)
    # the toy's damage state is fitted between theta_max/alpha >= 0.5 and overturning, with the fits' counts
    fragility = xr.open_dataset(tmp_path / "out" / "fragility.nc")
    states = list(fragility.damage_state.values)
    assert states.index("rocking-0.5") + 1 == states.index("rocking-0.8") == states.index("overturning") - 1
    reached = (cube.peak_angle_ratio >= 0.8) | (cube.outcome == 2)  # 2: overturned (the cube's flag_meanings)
    counted = cube.outcome != 3  # 3: the solver failed (not counted)
    by_count = (reached & counted).sum("record") / counted.sum("record")
    fraction = fragility.empirical_fraction.sel(damage_state="rocking-0.8")
    np.testing.assert_allclose(fraction.transpose(*by_count.dims).values, by_count.values, atol=1e-12)
    assert float(by_count.max()) > 0 and float(by_count.min()) < 1  # the state is reached in some cells only
    # an exchange file that cannot carry the rows says so in one line and writes none
    said = [line for line in run.stderr.splitlines() if "pelicun has no demand type" in line]
    assert len(said) == 1 and "'a_rms'" in said[0] and not (tmp_path / "out" / "fragility_pelicun.csv").exists()
    # the state's verdict limit and its source reach the report
    page = html.unescape((tmp_path / "out" / "report.html").read_text())
    assert "(close to overturning)', 5% in the design life: the toy plugin's own limit" in page


def test_a_plugin_record_format_limit_and_records_column(toy_site, tmp_path):
    import json

    (tmp_path / "quake.toy").write_text("dt = 0.01\n" + "\n".join(f"{0.5 * (-1) ** k:g}" for k in range(400)))
    script = """
import json
from rockfrag.config import load_study
from rockfrag.measures import intensity_measures
from rockfrag.records import detect_format, load_records
(record,), failures = load_records("quake.toy")
print(json.dumps({"format": detect_format("quake.toy"), "dt": record.dt, "n": len(record.acceleration),
                  "limit": load_study().raw["decision"]["max_probability_in_life"]["rocking-0.8"],
                  "a_rms": intensity_measures(record.acceleration, record.dt)["a_rms_m_s2"]}))
"""
    run = rockfrag_with(toy_site, "-c", script, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    found = json.loads(run.stdout.splitlines()[-1])
    assert found["format"] == "TOY" and found["dt"] == 0.01 and found["n"] == 400
    assert found["limit"] == 0.05 and found["a_rms"] == pytest.approx(0.5, rel=1e-12)  # |a| = 0.5 m/s^2 throughout


BROKEN = """[build-system]
requires = ["setuptools>=61"]
build-backend = "setuptools.build_meta"
[project]
name = "rockfrag-broken"
version = "0.1"
[project.entry-points."rockfrag.measures"]
gone = "rockfrag_gone:MEASURE"
[project.entry-points."rockfrag.damage_states"]
gravity = "rockfrag.units:STANDARD_GRAVITY"
[tool.setuptools]
packages = []
"""
"""A plugin whose measure's module does not exist and whose damage state is a number."""


def test_a_broken_plugin_is_one_error_naming_it(tmp_path):
    source = tmp_path / "broken"
    source.mkdir()
    (source / "pyproject.toml").write_text(BROKEN)
    site = install(source, tmp_path / "installed")
    (tmp_path / "study.toml").write_text(SMALL_STUDY)
    run = rockfrag_with(site, "-m", "rockfrag", "fragility", "study.toml", "--output", "out", "--no-progress",
                        cwd=tmp_path)
    assert run.returncode == 2 and "Traceback" not in run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rockfrag: error: package rockfrag-broken 0.1, entry point "
                                                   "rockfrag.measures: gone = rockfrag_gone:MEASURE: cannot be loaded")
    assert not (tmp_path / "out" / "cube.nc").exists()
    run = rockfrag_with(site, "-c", "from rockfrag.damage_states import DAMAGE_STATES; DAMAGE_STATES['uplift']",
                        cwd=tmp_path)
    assert "rockfrag.damage_states: gravity = rockfrag.units:STANDARD_GRAVITY: names a float; the group " \
           "rockfrag.damage_states needs a rockfrag.damage_states.DamageState" in run.stderr


def test_the_plugins_page_documents_every_group_and_includes_the_toy():
    from rockfrag.plugins import GROUPS

    root = Path(__file__).resolve().parents[1]
    page = (root / "docs" / "plugins.md").read_text(encoding="utf-8")
    assert all(f"`{group}`" in page for group in GROUPS.values())
    included = re.findall(r"```\{literalinclude\} \.\./(\S+)", page)
    assert sorted(included) == ["tests/plugin_toy/pyproject.toml", "tests/plugin_toy/rockfrag_toy/__init__.py",
                                "tests/plugin_toy/rockfrag_toy/bed_hertz.py"]
    assert "\nplugins\n" in (root / "docs" / "index.md").read_text(encoding="utf-8")  # in the site's toctree


@pytest.mark.parametrize("states, labels", [(6, 2), (7, 1), (9, 1)])
def test_a_page_of_more_states_than_shipped_labels_its_probability_axis_once(states, labels):
    """Six states fill two rows, each row labelled; seven (a plugin's state) need three rows, where a row is
    shorter than the label: then one label, beside the middle row, instead of three running into each other."""
    import matplotlib.pyplot as plt
    import numpy as np

    from rockfrag.report.figures import _grid, _probability_axes

    rows, columns = _grid(states)
    figure, axes = plt.subplots(rows, columns, squeeze=False, figsize=(11.7, 8.3))
    _probability_axes(axes, np.array([0.1, 1.0]), "PGA [g]", "probability of the damage state [-]")
    labelled = [axis for axis in axes.flat if axis.get_ylabel()]
    assert len(labelled) == labels and all(axis in axes[:, 0] for axis in labelled)
    renderer = figure.canvas.get_renderer()
    boxes = [axis.yaxis.label.get_window_extent(renderer) for axis in labelled]
    assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])
    plt.close(figure)


# ---------------------------------------------------------------- a contact law from a plugin

CONTACT_SCRIPT = """
import json, tempfile
from pathlib import Path
import numpy as np
import rockfrag
from rockfrag.models import BED_TYPES, contact

report = {"codes": {name: code for name, code in BED_TYPES.items()}}
block = rockfrag.Block(name="cabinet", b=0.3, h=1.5, mass=2000.0, E_b=200e9, footprint_area=0.48, soil_depth=1.0)
[record], _ = rockfrag.load_records("DUZCE/BOL090")
processed = rockfrag.process_record(record)
k, xi = 5e8, 0.2
runs = {bed: rockfrag.simulate("winkler", processed.acceleration, processed.dt, block, k=k, xi=xi, bed=bed, scale=0.9)
        for bed in ("two-spring", "toy-two-spring")}
shipped, plugin = runs["two-spring"], runs["toy-two-spring"]
report["histories_equal"] = all(np.array_equal(getattr(shipped, name), getattr(plugin, name))
                                for name in ("t", "theta", "y"))
report["impacts"] = [shipped.n_impacts, plugin.n_impacts]
report["peak_ratio"] = shipped.peak_angle_ratio
report["plugin_bed"] = plugin.extra["bed"]
# a small study on each law: the plugin's on a pool of two processes (each compiles the hooks itself)
cubes = {}
for bed, workers in (("two-spring", 1), ("toy-two-spring", 2)):
    Path(f"{bed}.toml").write_text(STUDY.replace("BED", bed))
    cubes[bed], _ = rockfrag.run_study(rockfrag.load_study(f"{bed}.toml"), output=bed, workers=workers)
a, b = cubes["two-spring"], cubes["toy-two-spring"]
report["cube_variables"] = [name for name in a.data_vars if "model" in a[name].dims]
report["cube_unequal"] = [name for name in report["cube_variables"]
                          if not np.array_equal(a[name].values, b[name].values, equal_nan=True)]
report["overturned"] = int((a.outcome == 2).sum())
# the shipped law's runs stop once settled (a linear bed's test) and add the rest of the tail at rest in one sum;
# the plugin's run to the end, step by step
report["rest"] = [a.time_at_rest.values.ravel().tolist(), b.time_at_rest.values.ravel().tolist()]
# the Hertzian bed: a block left at rest settles where K y^(3/2) / sqrt(b) = m g
rest = rockfrag.simulate("winkler", np.zeros(300), 0.01, block, k=k, xi=0.3, bed="toy-hertz")
report["hertz"] = [float(rest.y[-1]), float(np.abs(rest.theta).max())]
print(json.dumps(report))
"""

CONTACT_STUDY = """
soils = ["sand", "rock"]
models = ["winkler"]
[study]
record_sets = ["bolu"]
[intensity]
levels = [0.1, 0.3, 0.6, 1.0]
capacity_resolution = 0.0
[solver]
bed = "BED"
restitution = ""
[blocks.slender-cabinet]
b = 0.3
h = 1.5
mass = 2000.0
E_b = 200e9
footprint_area = 0.48
soil_depth = 1.0
"""
"""Bolu's two components at 4 levels on 2 soils, the tensionless bed alone, on the law BED at each soil's xi."""


def test_a_plugin_contact_law_runs_as_a_shipped_one(toy_site, tmp_path):
    """toy-two-spring is two-spring written out in the plugin: every number equal, bit for bit, which shows the
    plugin's hooks are called as the shipped law's are (but the time at rest, to rounding: a plugin law's run does not
    stop once settled); toy-hertz is another law, checked against its closed form."""
    script = f"STUDY = {CONTACT_STUDY!r}\n" + CONTACT_SCRIPT
    run = rockfrag_with(toy_site, "-c", script, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    found = json.loads(run.stdout.splitlines()[-1])
    assert found["codes"]["two-spring"] == 1 and {found["codes"]["toy-hertz"], found["codes"]["toy-two-spring"]} \
        == {16, 17}  # the registry's order after the shipped codes
    assert found["histories_equal"] and found["impacts"][0] == found["impacts"][1] > 0
    assert 0.05 < found["peak_ratio"] < 1 and found["plugin_bed"] == "toy-two-spring"  # it rocked, and not trivially
    assert "peak_angle" in found["cube_variables"] and set(found["cube_unequal"]) <= {"time_at_rest"}
    # the one difference: the plugin law's runs do not stop once settled, and sum their time at rest step by step
    np.testing.assert_allclose(*found["rest"], rtol=1e-12, atol=0)
    assert found["overturned"] > 0  # the study reaches overturning: the comparison covers the whole outcome range
    g, b, omega2 = 9.80665, 0.3, 5e8 / 2000.0
    settled, tilt = found["hertz"]
    assert settled == pytest.approx((g * np.sqrt(b) / omega2) ** (2 / 3), rel=1e-9) and tilt == 0.0
    assert abs(settled / (g / omega2) - 1) > 1  # not the linear bed's settlement: the law is another


def test_a_contact_law_module_without_its_hooks_is_refused(monkeypatch):
    """The registry's check names the entry point and what the module lacks, in the one line of a PluginError."""
    import sys
    import types
    from importlib.metadata import EntryPoint

    from rockfrag.models import contact
    from rockfrag.plugins import PluginError

    law = types.ModuleType("half_a_law")
    law.NAME, law.force = "half", lambda x, params, sin_t, cos_t: (0.0, 0.0)
    monkeypatch.setitem(sys.modules, "half_a_law", law)
    entry_point = EntryPoint(name="half", value="half_a_law", group="rockfrag.contact_laws")
    with pytest.raises(PluginError, match=r"^entry point rockfrag.contact_laws: half = half_a_law: a contact law "
                                          r"module needs .*; module half_a_law lacks indicator, indicators, "
                                          r"full_contact$"):
        contact.CONTACT_LAWS._load(entry_point)
    law.indicator = law.indicators = law.full_contact = law.force
    law.NAME = "other"
    with pytest.raises(PluginError, match="the module's NAME is 'other'; the entry point's name must be the same"):
        contact.CONTACT_LAWS._load(entry_point)
    law.NAME = "half"
    assert contact.CONTACT_LAWS._load(entry_point) is law
