"""RotD50 and RotD100 (Boore 2010) of a pair of horizontal components, and the study's pair scaling.

Closed forms: a single component (the other zero) has at angle theta the peak P |cos theta|, so RotD100 = P and
RotD50 = P cos 45 deg (the two middle angles of 0-179 deg both give |cos 45|, 1 deg apart); two sinusoids of
equal amplitude in quadrature (a circular motion) have the same peak at every angle. Independent references:
rotating the ground motion itself instead of the responses (the oscillator is linear), and pyrotd (test-only).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import xarray as xr

from rockfrag.blocks import Block
from rockfrag.config import load_study
from rockfrag.damage_states import DAMAGE_STATES
from rockfrag.fragility import fragility_dataset
from rockfrag.measures import MEASURES, pga, pgv, rotated_peaks, spectral_acceleration
from rockfrag.processing import process_record
from rockfrag.records import load_records
from rockfrag.records.components import horizontal_partners, pair_window
from rockfrag.study import run_study

ROTATABLE = [name for name, measure in MEASURES.items() if measure.rotatable]
OPTIONS = {"period": 0.5, "damping": 0.05}
BLOCK = Block(name="b", b=0.3, h=1.5, mass=2000.0)


@pytest.fixture(scope="module")
def bolu():
    first, second = (process_record(record) for record in load_records("bolu")[0])
    return first, second


def test_every_scalable_measure_but_the_pulse_has_a_rotated_form():
    assert set(ROTATABLE) == {"pga", "pgv", "sa", "avgsa", "pga_ratio", "pgv_ratio"}


@pytest.mark.parametrize("name", ROTATABLE)
def test_a_measures_histories_give_its_own_value(name, bolu):
    """The histories a measure rotates are the ones whose peaks make it: one definition, two uses."""
    record = bolu[0]
    measure = MEASURES[name]
    histories = measure.histories(record.acceleration, record.dt, BLOCK, {**OPTIONS, "period_range": None})
    peaks = np.max(np.abs(histories), axis=-1)
    value = peaks[0] if peaks.size == 1 else np.exp(np.mean(np.log(peaks)))
    assert value == pytest.approx(measure(record.acceleration, record.dt, BLOCK, **OPTIONS), rel=1e-12)


@pytest.mark.parametrize("name", ROTATABLE)
def test_a_single_component_has_rotd100_its_peak_and_rotd50_its_peak_over_root_two(name, bolu):
    record = bolu[1]
    measure = MEASURES[name]
    own = measure(record.acceleration, record.dt, BLOCK, **OPTIONS)
    zero = np.zeros_like(record.acceleration)
    if name != "avgsa":  # one channel: exactly P and P cos 45
        assert measure.rotd(record.acceleration, zero, record.dt, 100, BLOCK, **OPTIONS) == pytest.approx(own,
                                                                                                     rel=1e-12)
        assert measure.rotd(record.acceleration, zero, record.dt, 50, BLOCK, **OPTIONS) == pytest.approx(
            own * np.cos(np.radians(45.0)), rel=1e-12)
    # the second component alone at angle 90: the same, whichever slot it is in
    assert measure.rotd(zero, record.acceleration, record.dt, 50, BLOCK, **OPTIONS) == pytest.approx(
        measure.rotd(record.acceleration, zero, record.dt, 50, BLOCK, **OPTIONS), rel=1e-12)


def test_circular_motion_has_the_same_peak_at_every_angle():
    dt, amplitude = 0.001, 3.0
    t = np.arange(0, 10.0, dt)
    omega = 2 * np.pi * 2.0  # 500 samples a cycle: the sampled peak is within 2e-5 of the amplitude
    peaks = rotated_peaks(amplitude * np.cos(omega * t), amplitude * np.sin(omega * t))
    np.testing.assert_allclose(peaks, amplitude, rtol=3e-5)
    assert MEASURES["pga"].rotd(amplitude * np.cos(omega * t), amplitude * np.sin(omega * t), dt) == pytest.approx(
        amplitude, rel=3e-5)


def test_rotd50_lies_between_the_extremes_and_is_symmetric_in_the_pair(bolu):
    first, second = bolu
    for name in ("pga", "pgv", "sa"):
        measure = MEASURES[name]
        rotd50 = measure.rotd(first.acceleration, second.acceleration, first.dt, 50, **OPTIONS)
        rotd100 = measure.rotd(first.acceleration, second.acceleration, first.dt, 100, **OPTIONS)
        swapped = measure.rotd(second.acceleration, first.acceleration, first.dt, 50, **OPTIONS)
        assert swapped == pytest.approx(rotd50, rel=1e-12)
        own = [measure(r.acceleration, r.dt, **OPTIONS) for r in bolu]
        assert rotd50 <= rotd100 and max(own) <= rotd100 * (1 + 1e-12)
        # the geometric mean of the as-recorded pair is close to RotD50 (Boore 2010: within a few percent)
        assert np.sqrt(own[0] * own[1]) == pytest.approx(rotd50, rel=0.1)


def test_rotated_oscillator_responses_equal_the_oscillator_of_the_rotated_motion(bolu):
    """Sa: rotating the responses (what rotd does) and rotating the ground motion give the same peaks."""
    first, second = bolu
    angles = [0.0, 17.0, 45.0, 90.0, 133.0]
    histories = [MEASURES["sa"].histories(r.acceleration, r.dt, None, {**OPTIONS, "period_range": None})[0]
                 for r in bolu]
    by_responses = rotated_peaks(*histories, angles=angles)
    by_motion = [spectral_acceleration(np.cos(np.radians(a)) * first.acceleration
                                       + np.sin(np.radians(a)) * second.acceleration, first.dt, 0.5) for a in angles]
    np.testing.assert_allclose(by_responses, by_motion, rtol=1e-10)
    velocity = [pgv(np.cos(np.radians(a)) * first.acceleration + np.sin(np.radians(a)) * second.acceleration,
                    first.dt) for a in angles]
    np.testing.assert_allclose(rotated_peaks(*[MEASURES["pgv"].histories(r.acceleration, r.dt, None, {})[0]
                                               for r in bolu], angles=angles), velocity, rtol=1e-10)
    assert by_responses[0] == pytest.approx(spectral_acceleration(first.acceleration, first.dt, 0.5), rel=1e-12)
    assert rotated_peaks(first.acceleration, second.acceleration, angles=[0.0])[0] == pga(first.acceleration)


def test_rotd_agrees_with_pyrotd(bolu):
    """pyrotd (Kottke), an independent implementation: PGA in the time domain, Sa in the frequency domain."""
    with warnings.catch_warnings():  # pyrotd 0.6 imports pkg_resources, which warns that it is deprecated
        warnings.simplefilter("ignore")
        pyrotd = pytest.importorskip("pyrotd")
    first, second = bolu
    g = 9.80665
    reference = pyrotd.calc_rotated_peaks(first.dt, first.acceleration / g, second.acceleration / g,
                                          peak_type="pga", percentiles=[50, 100])
    for theirs, percentile in zip(reference["pga"], (50, 100)):
        ours = MEASURES["pga"].rotd(first.acceleration, second.acceleration, first.dt, percentile) / g
        assert ours == pytest.approx(float(theirs), rel=1e-9)
    velocity = pyrotd.calc_rotated_peaks(first.dt, first.acceleration / g, second.acceleration / g,
                                         peak_type="pgv", percentiles=[50, 100])["pgv"]  # cm/s, Fourier-integrated
    for theirs, percentile in zip(velocity, (50, 100)):
        ours = MEASURES["pgv"].rotd(first.acceleration, second.acceleration, first.dt, percentile) * 100
        assert ours == pytest.approx(float(theirs), rel=0.005)
    # pyrotd's oscillator is in the Fourier domain and gives the pseudo-acceleration w^2 Sd; ours is the exact
    # recurrence's absolute acceleration, within 1% of it at 5% damping here (pyrotd 0.6.1's osc_type "sa" is not
    # the absolute acceleration: 0.98 g against a pseudo-acceleration of 0.32 g at 1.5 s, so it is not used)
    for period in (0.2, 0.5, 1.0):
        spectrum = pyrotd.calc_rotated_spec_accels(first.dt, first.acceleration / g, second.acceleration / g,
                                                   [1 / period], osc_damping=0.05, percentiles=[50, 100],
                                                   osc_type="psa")
        for theirs, percentile in zip(spectrum["spec_accel"], (50, 100)):
            ours = MEASURES["sa"].rotd(first.acceleration, second.acceleration, first.dt, percentile,
                                       period=period) / g
            assert ours == pytest.approx(float(theirs), rel=0.01)


def test_pairs_are_the_two_horizontals_of_a_station(bolu):
    records, _ = load_records("far-field")
    partners, notes = horizontal_partners(records)
    assert not notes and all(p is not None for p in partners)
    for index, partner in enumerate(partners):
        assert partners[partner] == index != partner
        assert (records[index].event, records[index].station) == (records[partner].event, records[partner].station)
    three, _ = load_records("three-component")
    partners, _ = horizontal_partners(three)
    for record, partner in zip(three, partners):  # verticals stay single; each station's H1 and H2 pair
        assert (partner is None) == record.is_vertical
    first, second = bolu
    window = pair_window(first, second)
    assert first.acceleration[window[0]].size == second.acceleration[window[1]].size


RotD_STUDY = """
soils = ["rock"]
models = ["housner"]
[study]
name = "pairs"
record_sets = ["DUZCE/BOL000", "DUZCE/BOL090", "KOBE/NIS000"]
[intensity]
levels = [0.1, 0.2, 0.35, 0.6]
capacity_resolution = 0.0
[solver]
friction = "none"
[blocks.slender-cabinet]
b = 0.3
h = 1.5
mass = 2000.0
"""


@pytest.fixture(scope="module")
def pair_cube(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pairs")
    (folder / "study.toml").write_text(RotD_STUDY)
    lines = []
    cube, _ = run_study(load_study(folder / "study.toml"), output=folder / "out", workers=1, progress=False,
                        log=lines.append, warn=lambda *_: None)
    return cube, lines, xr.open_dataset(folder / "out" / "cube.nc")


def test_a_pair_has_one_scale_factor_and_its_scaled_rotd50_is_the_level(pair_cube, bolu):
    cube, lines, written = pair_cube
    scales = cube.scale_factor.isel(block=0)
    np.testing.assert_array_equal(scales.sel(record="DUZCE/BOL000"), scales.sel(record="DUZCE/BOL090"))
    first, second = bolu
    for level, scale in zip(cube.im_level.values * 9.80665, scales.sel(record="DUZCE/BOL000").values):
        assert MEASURES["pga"].rotd(first.acceleration * scale, second.acceleration * scale,
                                    first.dt) == pytest.approx(level, rel=1e-12)
    # NIS000 came without its NIS090: it keeps its own component, and the study says so
    nis = process_record(load_records(["KOBE/NIS000"])[0][0])
    assert scales.sel(record="KOBE/NIS000").values[-1] == pytest.approx(0.6 * 9.80665 / pga(nis.acceleration))
    assert list(written.record_intensity_component.values) == ["RotD50", "RotD50", "single component"]
    assert list(written.record_partner.values) == ["DUZCE/BOL090", "DUZCE/BOL000", ""]
    assert written.attrs["intensity_component"] == "mixed"
    assert "1 of 3 records without a partner" in written.attrs["intensity_component_definition"]
    assert any("1 pairs" in line and "KOBE/NIS000" in line for line in lines)


def test_under_rotd50_the_rigid_uplift_is_a_fitted_curve(pair_cube):
    """A component lifts at g tan(alpha) of its own PGA, 0.7-1.4 times its pair's RotD50: no exact step, but a
    lognormal fit of each record's exact threshold (tests/test_steps.py checks those against runs)."""
    cube, _, _ = pair_cube
    uplift = [s for s in DAMAGE_STATES.values() if s.edp == "uplifted"]
    fits = fragility_dataset(cube, uplift, n_bootstrap=0)
    assert (fits.fit_method.values == "exact-thresholds").all() and (fits.beta.values > 0).all()
    assert fits.attrs["intensity_component"] == "mixed"
    own = cube.assign(record_im=cube.record_component_im).assign_attrs(intensity_component="single component")
    single = fragility_dataset(own, uplift, n_bootstrap=0)
    assert (single.fit_method.values == "exact-g-tan-alpha").all()


def test_a_measure_without_a_rotated_form_needs_single_components(tmp_path):
    from rockfrag.errors import ConfigError
    study = tmp_path / "pulse.toml"
    study.write_text('[intensity]\nmeasure = "pulse_amplitude"\n')
    with pytest.raises(ConfigError, match="intensity.component"):
        load_study(study)
    study.write_text('[intensity]\nmeasure = "pulse_amplitude"\ncomponent = "single"\n')
    assert load_study(study).component == "single"
