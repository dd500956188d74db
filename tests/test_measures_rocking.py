"""Measures made for rocking, and the measure registry, against hand calculations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockfrag.blocks import Block
from rockfrag.efficiency import ranked_measures
from rockfrag.hazard import _measure_from_imt, load_hazard
from rockfrag.measures import (
    MEASURES,
    average_spectral_acceleration,
    cav,
    define_measure,
    display_units,
    scaling_measures,
    short_label,
    velocity_pulse,
)
from rockfrag.units import STANDARD_GRAVITY as G

BLOCK = Block(name="cabinet", b=0.3, h=1.5, mass=2000.0)  # tan(alpha) = 0.2, R = sqrt(0.09 + 2.25)


def cosine_pulse(amplitude, period, dt=0.001, lead=1.0, trail=3.0):
    """One cycle of a_p cos(w_p t) after ``lead`` s of rest: velocity (a_p/w_p) sin(w_p t), one full cycle."""
    t = np.arange(0.0, lead + period + trail, dt)
    inside = (t >= lead) & (t < lead + period)
    return np.where(inside, amplitude * np.cos(2 * np.pi * (t - lead) / period), 0.0)


def test_pga_ratio_is_pga_over_g_tan_alpha():
    acceleration = np.array([0.0, 0.5, -1.2, 0.3]) * G  # PGA 1.2 g
    assert MEASURES["pga_ratio"](acceleration, 0.01, BLOCK) == pytest.approx(1.2 / 0.2, rel=1e-12)


def test_pgv_ratio_of_a_cosine_pulse_by_hand():
    a_p, period = 3.0, 0.8
    acceleration = cosine_pulse(a_p, period, dt=0.0005)
    pgv = a_p * period / (2 * np.pi)  # peak of (a_p/w_p) sin(w_p t)
    p = math.sqrt(3 * G / (4 * math.hypot(0.3, 1.5)))
    expected = p * pgv / (G * 0.2)
    assert MEASURES["pgv_ratio"](acceleration, 0.0005, BLOCK) == pytest.approx(expected, rel=2e-3)


def test_per_block_measure_refuses_to_run_without_a_block():
    with pytest.raises(ValueError, match="per block"):
        MEASURES["pga_ratio"](np.ones(4), 0.01)


def test_velocity_pulse_recovers_period_and_amplitudes_of_a_cosine_pulse():
    a_p, period = 2.5, 1.3
    found_period, v_p, found_a_p = velocity_pulse(cosine_pulse(a_p, period), 0.001)
    # the jump of the sampled pulse at its start shifts the crossings by a few samples (dt = 1 ms)
    assert found_period == pytest.approx(period, abs=5e-3)
    assert v_p == pytest.approx(a_p * period / (2 * np.pi), abs=a_p * 0.001)  # + a_p dt/2 from the jump
    assert found_a_p == pytest.approx(a_p, rel=8e-3)


def test_avgsa_of_a_step_is_twice_the_step_when_undamped():
    """Undamped SDOF under a suddenly applied a0: absolute acceleration a0 (1 - cos wt), peak 2 a0 at
    every period (the record is long enough to reach it at the longest period)."""
    a0 = 1.7
    acceleration = np.full(4000, a0)
    value = average_spectral_acceleration(acceleration, 0.002, 0.1, 2.0, damping=0.0)
    assert value == pytest.approx(2 * a0, rel=1e-3)


def test_avgsa_lies_between_the_extreme_spectral_ordinates(bolu_records):
    record = bolu_records["DUZCE/BOL090"]
    value = MEASURES["avgsa"](record.acceleration, record.dt, period=1.0, damping=0.05)
    sa = [MEASURES["sa"](record.acceleration, record.dt, period=t) for t in np.geomspace(0.2, 3.0, 10)]
    assert min(sa) < value < max(sa)
    assert value == pytest.approx(math.exp(np.mean(np.log(sa))), rel=1e-9)  # geometric mean, 0.2T..3T


@pytest.mark.parametrize("name", sorted(MEASURES))
def test_every_measure_scales_with_its_exponent(bolu_records, name):
    record = bolu_records["DUZCE/BOL000"]
    measure = MEASURES[name]
    value = measure(record.acceleration, record.dt, BLOCK)
    doubled = measure(2.0 * record.acceleration, record.dt, BLOCK)
    assert doubled == pytest.approx(2.0**measure.scaling_exponent * value, rel=1e-9)


def test_registry_describes_every_measure_and_feeds_the_config_units():
    for name, measure in MEASURES.items():
        assert measure.name == name and measure.si_unit and measure.display_unit and measure.describe()
        assert measure.short_label() and (name in scaling_measures()) == measure.scalable
    assert display_units("pga") == ("g", G) and display_units("pgv_ratio") == ("1", 1.0)
    assert display_units("pulse_period") == ("", 1.0)  # a record property: no study scales to it
    assert "0.5" in MEASURES["avgsa"].describe(period=2.5, period_range=(0.5, 7.0))


@pytest.mark.parametrize("name, options, label", [
    ("pga", {}, "PGA"), ("pgv", {"period": 2.0}, "PGV"), ("sa", {"period": 0.5, "damping": 0.02}, "Sa(0.5 s)"),
    ("avgsa", {"period": 1.0}, "AvgSa(0.2-3 s)"), ("avgsa", {"period_range": (0.5, 7.0)}, "AvgSa(0.5-7 s)"),
])
def test_the_label_is_read_back_from_the_long_name_the_cube_holds(name, options, label):
    """The report labels its axes from a result file's ``im_level`` long name: the registry's label with
    the study's options, whatever text surrounds the long name."""
    measure = MEASURES[name]
    assert measure.short_label(**options) == label
    described = f"intensity level: multiple of the block's uplift intensity ({measure.describe(**options)})"
    assert short_label(name, described) == label
    assert short_label("", described) == label  # an old file without ``intensity_measure``: found by its long name


def test_a_label_that_needs_options_it_cannot_find_falls_back_on_the_name():
    assert short_label("sa", "intensity level") == "SA"
    assert short_label("pga", "") == "PGA"  # nothing to fill in
    assert short_label("", "") == "intensity" and short_label("unknown") == "UNKNOWN"


def test_pelicun_and_openquake_names_are_registered_once():
    assert MEASURES["pga"].pelicun_demand == ("Peak Ground Acceleration", "g")
    assert MEASURES["pgv"].pelicun_demand == ("Peak Ground Velocity", "mps")
    assert MEASURES["sa"].pelicun_demand == ("Spectral Acceleration", "g") and MEASURES["sa"].uses_period
    assert [m.openquake_imt for m in MEASURES.values() if m.openquake_imt] == ["PGA", "PGV", "SA(T)"]
    assert not MEASURES["avgsa"].uses_period  # defined over a range, not at one period


@pytest.fixture
def cav_measure():
    """A measure added as a newcomer would add it: one ``define_measure`` definition (removed afterwards)."""
    @define_measure("cav_test", si_unit="m/s", long_name="cumulative absolute velocity", label="CAV",
                    openquake_imt="CAV", openquake_factor=0.01)
    def _cav(acceleration, dt, block, options):
        return cav(acceleration, dt)

    yield MEASURES["cav_test"]
    del MEASURES["cav_test"]


def test_one_definition_reaches_every_reader_of_the_registry(cav_measure, tmp_path):
    assert cav_measure(np.array([1.0, -1.0, 1.0]), 0.5) == pytest.approx(1.0)
    assert "cav_test" in scaling_measures() and "cav_test" in ranked_measures()
    assert display_units("cav_test") == ("m/s", 1.0)
    assert short_label("cav_test", "intensity level: cumulative absolute velocity") == "CAV"
    assert _measure_from_imt("CAV", "here") == ("cav_test", None, 0.01)
    curve = tmp_path / "hazard.csv"
    curve.write_text("# measure = cav_test\n# units = m/s\nintensity,annual_frequency\n0.1,1e-2\n0.2,2e-3\n")
    assert load_hazard(curve, "cav_test").label == "CAV"
