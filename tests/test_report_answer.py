"""The answer pages (issue 20, item 1): return-period intensities, P(each damage state) with its band, the
design-life risk and the verdict, checked against closed forms on hand-made datasets (no study run)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from scipy.stats import lognorm

from rockfrag.answer import (
    ANCHOR,
    CHECK_SLIDING,
    NO_ACTION,
    NO_VERDICT,
    answer_model,
    block_answers,
    intensity_at_frequency,
    percent,
    verdict_sentence,
)
from rockfrag.hazard import HazardCurve, load_hazard

K0, K = 1e-4, 2.5  # the shipped example: lambda(s) = K0 s^-K [1/yr], s = PGA [g]


def _power_law(source="site.csv"):
    s = np.geomspace(0.01, 3.0, 40)
    return HazardCurve(s, K0 * s ** -K, "pga", None, source)


def _fragility(medians, betas=0.4, models=("housner", "winkler"), soils=("clay", "rock"), empirical=None):
    """A fragility.nc of one block: overturning and one rocking state per soil and model, medians in g."""
    states = ["rocking-0.5", "overturning"]
    dims = ("soil", "block", "model", "damage_state")
    shape = (len(soils), 1, len(models), len(states))
    median = np.broadcast_to(np.asarray(medians, float), shape).copy()
    beta = np.broadcast_to(np.asarray(betas, float), shape).copy()
    levels = np.geomspace(0.1, 4.0, 8)
    fraction = np.full((levels.size, *shape), 0.5) if empirical is None else empirical
    g = {"units": "9.80665 m s-2"}
    return xr.Dataset({
        "median": (dims, median, g), "beta": (dims, beta),
        "median_low": (dims, median * 0.8, {**g, "long_name": "90% two-sided interval: lower bound"}),
        "median_high": (dims, median * 1.25, g),
        "status": (dims, np.full(shape, "fitted")),
        "empirical_fraction": (("im_level", *dims), fraction),
        "studied_im_min": (("block",), [levels[0]], g), "studied_im_max": (("block",), [levels[-1]], g),
    }, coords={"soil": list(soils), "block": ["cabinet"], "model": list(models), "damage_state": states,
               "damage_state_description": ("damage_state", ["theta_max/alpha >= 0.5", "the block overturns"]),
               "im_level": np.arange(levels.size), "intensity": (("block", "im_level"), levels[None, :], g)},
        attrs={"design_life_years": 50.0})


def test_return_period_intensity_is_the_closed_form_of_the_power_law():
    hazard = _power_law()
    for period in (475.0, 975.0, 2475.0, 1e5):  # the last beyond the tabulated curve: its power law
        assert intensity_at_frequency(hazard, 1 / period) == pytest.approx((K0 * period) ** (1 / K), rel=1e-9)
    shipped = load_hazard(None)
    assert intensity_at_frequency(shipped, 1 / 2475) == pytest.approx((K0 * 2475) ** (1 / K), rel=1e-3)


def test_probabilities_at_the_return_periods_and_in_life_against_scipy():
    fragility = _fragility([[[[0.3, 0.6]]]])
    answer = block_answers(fragility, _power_law(), (475.0, 2475.0), limits={"overturning": 0.01})[0]
    assert answer.model == "winkler"  # the admissible bed, not the rigid base
    clay = answer.soils[0]
    overturning = clay.states[1]
    for index, period in enumerate((475.0, 2475.0)):
        im = (K0 * period) ** (1 / K)
        p, low, high = overturning.at_return_periods[index]
        assert p == pytest.approx(lognorm.cdf(im, 0.4, scale=0.6), rel=1e-9)
        assert (low, high) == (pytest.approx(lognorm.cdf(im, 0.4, scale=0.75)),
                               pytest.approx(lognorm.cdf(im, 0.4, scale=0.48)))  # band from the median's bounds
    # lambda = K0 median^-K exp(K^2 beta^2 / 2) for a power-law hazard (Cornell et al. 2002)
    closed = K0 * 0.6 ** -K * math.exp(K ** 2 * 0.4 ** 2 / 2)
    assert overturning.annual_frequency == pytest.approx(closed, rel=0.02)
    assert overturning.probability_in_life == pytest.approx(1 - math.exp(-50 * overturning.annual_frequency))


def test_the_verdict_follows_the_stated_limits_and_the_sliding_share():
    fragility = _fragility([[[[0.3, 0.6]]], [[[0.3, 3.0]]]])  # clay: overturns often; rock: rarely
    hazard = _power_law()
    answer = block_answers(fragility, hazard, limits={"overturning": 0.01},
                           sliding={("cabinet", "clay"): 0.0, ("cabinet", "rock"): 0.0})[0]
    clay, rock = answer.soils
    assert clay.states[1].probability_in_life > 0.01 > rock.states[1].probability_in_life
    assert (clay.verdict, rock.verdict) == (ANCHOR, NO_ACTION)
    assert not clay.states[0].exceeds  # a state without a limit is reported, not judged
    lenient = block_answers(fragility, hazard, limits={"overturning": 0.9})[0]
    assert [s.verdict for s in lenient.soils] == [NO_ACTION, NO_ACTION]
    sliding = block_answers(fragility, hazard, limits={"overturning": 0.01}, max_sliding_share=0.1,
                            sliding={("cabinet", "clay"): 0.05, ("cabinet", "rock"): 0.4})[0]
    assert [s.verdict for s in sliding.soils] == [ANCHOR, CHECK_SLIDING]
    # a block that must be anchored is told so even where it also slides (the client read "check sliding" only)
    both = block_answers(fragility, hazard, limits={"overturning": 0.01}, max_sliding_share=0.1,
                         sliding={("cabinet", "clay"): 0.4, ("cabinet", "rock"): 0.4})[0]
    assert [s.verdict for s in both.soils] == [ANCHOR, CHECK_SLIDING]
    assert block_answers(fragility, None)[0].soils[0].verdict == NO_VERDICT
    sentence = verdict_sentence(answer, "slender electrical cabinet", {"overturning": "the block overturns"})
    assert "anchor it on clay" in sentence and "no action on rock" in sentence
    assert f"{percent(clay.states[1].probability_in_life)}, above the 1% limit" in sentence
    assert "example" not in sentence


def test_the_shipped_example_hazard_is_said_in_the_verdicts_sentence():
    answer = block_answers(_fragility([[[[0.3, 0.6]]]]), load_hazard(None))[0]
    assert answer.example_hazard
    assert verdict_sentence(answer, "cabinet").startswith("With the shipped example hazard curve")


def test_a_state_no_record_reached_below_the_largest_recorded_intensity_is_said_so():
    """Never a median of 11 g: 'not reached below X', and P(in life) bounded by P(intensity > X in life)."""
    levels = np.geomspace(0.1, 4.0, 8)
    shape = (levels.size, 2, 1, 2, 2)
    empirical = np.where((levels >= 2.0)[:, None, None, None, None], 0.6, 0.0) * np.ones(shape)
    fragility = _fragility([[[[3.0, 11.0]]]], empirical=empirical)
    hazard = _power_law()
    overturning = block_answers(fragility, hazard, largest_recorded={"cabinet": 0.8})[0].soils[0].states[1]
    assert overturning.not_reached_below == 0.8
    assert overturning.annual_frequency == pytest.approx(K0 * 0.8 ** -K, rel=1e-6)
    reached = block_answers(fragility, hazard, largest_recorded={"cabinet": 2.5})[0].soils[0].states[1]
    assert reached.not_reached_below is None  # some records reached it below 2.5 g


def test_the_recommended_rows_answer_when_present():
    fragility = _fragility([[[[0.3, 0.6]]]], models=("recommended", "housner", "winkler"))
    assert answer_model(fragility) == "recommended"
    assert block_answers(fragility, _power_law())[0].model == "recommended"


@pytest.mark.parametrize("value, shown", [(0.123, "12%"), (0.0234, "2.3%"), (0.00071, "0.071%"), (0.0, "0%"),
                                          (1e-7, "<0.01%"), (0.9996, ">99%"), (float("nan"), "-")])
def test_probabilities_are_rounded_to_what_they_support(value, shown):
    assert percent(value) == shown


def test_the_study_states_the_limits_and_return_periods(tmp_path):
    from rockfrag.config import load_study
    from rockfrag.errors import ConfigError

    study = tmp_path / "s.toml"
    study.write_text('[hazard]\nreturn_periods = [100.0, 2475.0]\n[decision]\nmax_probability_in_life = '
                     '{ overturning = 0.02 }\n')
    raw = load_study(study).raw
    assert raw["hazard"]["return_periods"] == [100.0, 2475.0]
    assert raw["decision"]["max_probability_in_life"] == {"overturning": 0.02, "rocking-0.5": 0.10,
                                                          "slip-0.30": 0.10}  # merged
    for text, field in (('[decision]\nmax_probability_in_life = { toppling = 0.01 }\n',
                         "decision.max_probability_in_life.toppling"),
                        ('[decision]\nmax_probability_in_life = { overturning = 2.0 }\n',
                         "decision.max_probability_in_life.overturning"),
                        ('[hazard]\nreturn_periods = [0.5]\n', "hazard.return_periods[0]")):
        study.write_text(text)
        with pytest.raises(ConfigError) as error:
            load_study(study)
        assert error.value.field == field


def test_the_motion_at_each_return_period_comes_from_the_runs_at_the_level_at_or_below():
    """Issue 19, 36: what the block does at each return-period intensity, each record counted at its most severe
    motion. Mode times where the base slides; the outcome where it is tied (no mode times); the recommended curve
    reads its central member's runs; the level is the one at or below the intensity, as the probability table reads
    it (issue 20, finding 4)."""
    import xarray as xr

    from rockfrag.models.fields import MODE_TIME_FIELDS
    from rockfrag.models.variants import RECOMMENDED
    from rockfrag.report.answer_page import NO_LEVEL, motion_counts

    levels = np.array([0.1, 0.3, 1.0])  # g
    times = np.zeros((4, 3, 1, 1, 2, len(MODE_TIME_FIELDS)))  # record, level, soil, block, model, mode
    times[:, 0, ..., 0] = 10.0   # at rest at 0.1 g
    times[:, 1, ..., 1] = 10.0   # slides at 0.3 g; one record also rocks for 2 s
    times[0, 1, ..., 2] = 2.0
    times[:, 2, ..., 0] = 30.0   # at 1 g mostly at rest, but every record slides and rocks for a while: that
    times[:, 2, ..., 3] = 1.0    # is what it does (the longest mode would say "at rest")
    times[..., 1, :] = np.nan    # the second model is tied: no mode times
    outcome = np.zeros((4, 3, 1, 1, 2), np.int8)
    outcome[0, 1, ..., 0] = 1    # the centre: the record that rocked lifted off, and all do at 1 g
    outcome[:, 2, ..., 0] = 1
    outcome[:, 1:, ..., 1] = 1   # tied: rocks from 0.3 g
    outcome[:3, 2, ..., 1] = 2   # ... and 3 of 4 records overturn at 1 g
    dims = ("record", "im_level", "soil", "block", "model")
    cube = xr.Dataset({field: (dims, times[..., k]) for k, field in enumerate(MODE_TIME_FIELDS)} |
                      {"outcome": (dims, outcome)},
                      coords={"soil": ["clay"], "block": ["skid"], "model": ["recommended", "housner"],
                              "intensity": (("block", "im_level"), levels[None, :], {"units": "g"})})
    assert motion_counts(cube, "skid", RECOMMENDED, "clay", [0.11, 0.32, 1.1], 1.0) == \
        ["at rest 4 (of 4)", "slides 3, rocks 1 (of 4)", "slides and rocks 4 (of 4)"]
    assert motion_counts(cube, "skid", "housner", "clay", [0.1, 0.3, 1.0], 1.0) == \
        ["at rest 4 (of 4)", "rocks 4 (of 4)", "rocks 1, overturns 3 (of 4)"]
    # 0.28 g reads the 0.1 g level (at or below, as the P table), not the nearer 0.3 g; below 0.1 g no level
    assert motion_counts(cube, "skid", "housner", "clay", [0.28, 0.09], 1.0) == ["at rest 4 (of 4)", NO_LEVEL]
    assert motion_counts(None, "skid", "housner", "clay", [0.1], 1.0) == ["-"]


def _tied_cube(outcome):
    """A cube of one tied cell (housner, no mode times) from outcome codes (record, level), levels 0.1/0.3/1 g."""
    levels = np.array([0.1, 0.3, 1.0])
    dims = ("record", "im_level", "soil", "block", "model")
    return xr.Dataset({"outcome": (dims, np.asarray(outcome, np.int8)[:, :, None, None, None])},
                      coords={"soil": ["sand"], "block": ["cabinet"], "model": ["housner"],
                              "intensity": (("block", "im_level"), levels[None, :], {"units": "g"})})


def test_the_motions_count_as_the_fits_do_and_every_record_once():
    """The client read "at rest (100% of the records)" beside 10 of 44 records lifting off (at rest or worse is
    always 100%), "rocks (50%)" where 22 of 44 rocked and 22 overturned, and a record that overturned at a lower
    level counted as rocking (resurrection). Each record is now counted once, at its most severe motion."""
    from rockfrag.report.answer_page import motion_counts

    outcome = np.zeros((44, 3), int)
    outcome[0, 0] = 1                     # one record of 44 lifts off at 0.1 g: the rest stay at rest
    outcome[:22, 1], outcome[22:, 1] = 1, 2  # 22 rock, 22 overturn at 0.3 g
    outcome[:, 2] = 1                     # at 1 g every record rocks: the 22 overturned at 0.3 g resurrect
    outcome[0, 2] = 2
    motions = motion_counts(_tied_cube(outcome), "cabinet", "housner", "sand", [0.1, 0.3, 1.0], 1.0)
    assert motions == ["at rest 43, rocks 1 (of 44)", "rocks 22, overturns 22 (of 44)",
                       "rocks 21, overturns 23 (of 44)"]


def test_the_motion_table_and_the_probability_table_agree_on_one_cell():
    """One definition, level and counting rule: the records that overturn in the motion table are the count of
    records in the probability table's cell, at the same level (issue 20, finding 4)."""
    from rockfrag.answer import _records_at
    from rockfrag.damage_states import DAMAGE_STATES
    from rockfrag.fragility import exceedance
    from rockfrag.report.answer_page import motion_counts

    outcome = np.zeros((10, 3), int)
    outcome[:, 1:] = 1
    outcome[:3, 1] = 2  # 3 of 10 overturn at 0.3 g; at 1 g 2 more do, and the first 3 resurrect (rock)
    outcome[3:5, 2] = 2
    cube = _tied_cube(outcome)
    fraction = exceedance(cube, DAMAGE_STATES["overturning"]).sel(soil="sand", block="cabinet", model="housner") \
        .mean("record").values
    for im in (0.5, 2.0):
        reached, total, level = _records_at(np.array([0.1, 0.3, 1.0]), fraction, 10, im)
        motion = motion_counts(cube, "cabinet", "housner", "sand", [im], 1.0)[0]
        assert f"overturns {reached} (of {total})" in motion, (im, level, motion)
    assert reached == 5  # the resurrected records count as overturned at 1 g


def test_curves_that_cross_below_the_data_are_read_as_this_state_or_worse():
    """The example study's rock row: theta/alpha >= 0.5 at 0.97 g (beta 0.55) and overturning at 1.13 g (beta 0.67)
    cross at 0.48 g, so at the 475-year 0.30 g overturning alone would be likelier than the milder state. The
    answer reads each state as "this state or worse": the milder state takes the severe one's larger value."""
    fragility = _fragility([[[[0.974, 1.133]]]], betas=[[[[0.549, 0.667]]]])
    answer = block_answers(fragility, _power_law(), (475.0, 2475.0))[0]
    milder, severe = answer.soils[0].states
    im = (K0 * 475.0) ** (1 / K)
    own = lognorm.cdf(im, 0.549, scale=0.974)
    assert lognorm.cdf(im, 0.667, scale=1.133) > own  # the fitted curves do cross there
    assert severe.at_return_periods[0][0] == pytest.approx(lognorm.cdf(im, 0.667, scale=1.133), rel=1e-9)
    for milder_values, severe_values in zip(milder.at_return_periods, severe.at_return_periods):
        assert np.all(np.asarray(milder_values) >= np.asarray(severe_values))
    assert milder.at_return_periods[0][0] == pytest.approx(severe.at_return_periods[0][0])
    assert milder.probability_in_life >= severe.probability_in_life
    # where the milder curve is above (2,475 years: 0.72 g), it keeps its own value
    im = (K0 * 2475.0) ** (1 / K)
    if lognorm.cdf(im, 0.549, scale=0.974) > lognorm.cdf(im, 0.667, scale=1.133):
        assert milder.at_return_periods[1][0] == pytest.approx(lognorm.cdf(im, 0.549, scale=0.974), rel=1e-9)


def _restitution_cube(requested, reached, xi, blocks):
    """A cube with the central member (model ``recommended``) and the restitution members (``member``).

    The arrays are (block, run), their columns the low end, the centre and the high end; every soil the same.
    """
    soils = ["clay", "rock"]

    def central(values):
        return (("soil", "block", "model"), np.broadcast_to(values[None, :, 1, None], (2, len(blocks), 1)).copy())

    def ends(values):
        return (("soil", "block", "member"), np.broadcast_to(values[None, :, [0, 2]], (2, len(blocks), 2)).copy())

    data = {}
    for name, values in (("restitution_requested", requested), ("restitution_target", reached),
                         ("damping_ratio_calibrated", xi)):
        data[name], data[f"member_{name}"] = central(values), ends(values)
    return xr.Dataset(data, coords={"soil": soils, "block": blocks, "model": ["recommended"],
                                    "member": ["restitution_low", "restitution_high"]})


def test_the_answer_says_where_the_bed_could_not_reach_the_range():
    """The example study's log warned that the bed runs the range's centre and upper end at a lower r than asked;
    the answer page must say it too (beta_parameters there leaves out the less dissipative side)."""
    from rockfrag.report.answer_page import _band_reach

    requested = np.array([[0.825, 0.845, 0.866]])
    cube = _restitution_cube(requested, np.array([[0.825, 0.836, 0.836]]), np.array([[0.3, 0.2, 0.2]]), ["cabinet"])
    cube["restitution_target"].loc[{"soil": "rock"}] = cube.restitution_requested.sel(soil="rock").values
    cube["member_restitution_target"].loc[{"soil": "rock"}] = cube.member_restitution_requested.sel(
        soil="rock").values
    text = _band_reach(cube)
    assert "On clay the bed" in text and "clay, rock" not in text and "0.866" in text and "0.836" in text
    assert _band_reach(cube.assign(restitution_target=cube.restitution_requested,
                                   member_restitution_target=cube.member_restitution_requested)) == ""


# ---------------------------------------------------------------- verdicts from the fit's tail (issue 20, report)

def _tail_case(first_reached_index):
    """Overturning median 1 g, beta 0.6; no record overturned below level ``first_reached_index`` (10 records)."""
    levels = np.geomspace(0.1, 4.0, 8)
    shape = (levels.size, 2, 1, 2, 2)
    reached = np.clip((np.arange(levels.size) - first_reached_index + 1) * 0.3, 0.0, 1.0)
    empirical = reached[:, None, None, None, None] * np.ones(shape)
    fragility = _fragility([[[[0.5, 1.0]]]], betas=0.6, empirical=empirical).assign(n_records=10)
    return levels, block_answers(fragility, _power_law(), limits={"overturning": 0.01})[0]


def _supported(lower, median=1.0, beta=0.6):
    """P(overturning in 50 years) from the intensities above ``lower`` only, by quadrature of the power law."""
    from scipy.integrate import quad

    rate = quad(lambda s: lognorm.cdf(s, beta, scale=median) * K * K0 * s ** (-K - 1), lower, np.inf)[0]
    return 1 - math.exp(-50 * rate)


def test_a_verdict_from_the_fits_tail_below_every_record_is_said_so():
    """The client read 2.2% at 0.3 g where no record overturned: the records table says what the records did at the
    level at or below the intensity, and the reason says when the verdict rests on the fitted curve's tail alone."""
    from types import SimpleNamespace

    from rockfrag.report import numbers
    from rockfrag.report.summary import p_at_return_period, reason

    levels, answer = _tail_case(5)  # first overturning at 1.39 g, far above the 2,475-year 0.57 g
    overturning = answer.soils[0].states[1]
    assert overturning.first_reached == pytest.approx(levels[5])
    assert overturning.probability_in_life > 0.01  # above the limit ...
    assert overturning.supported_probability == pytest.approx(_supported(levels[5]), rel=0.02)
    assert overturning.supported_probability < 0.01 and overturning.tail_only  # ... only through the tail
    sentence = verdict_sentence(answer, "cabinet", {"overturning": "the block overturns"})
    assert "anchor it on clay and rock" in sentence
    assert f"rests on the fitted curve's tail alone on clay and rock: no record reached the state below " \
           f"{levels[5]:.2g} g" in sentence
    assert percent(overturning.supported_probability) in sentence
    results = SimpleNamespace(facts=numbers.Facts())
    assert reason(results, answer, answer.soils[0]) == f"fitted tail only: no record below {levels[5]:.2g} g"
    im = (K0 * 475.0) ** (1 / K)
    below = levels[levels <= im][-1]
    assert overturning.records[0] == (0, 10, pytest.approx(below))
    p = lognorm.cdf(im, 0.6, scale=1.0)
    assert p_at_return_period(overturning, 0, answer.intensities) == numbers.probability(p)

    levels, answer = _tail_case(2)  # 3 of 10 overturned at 0.29 g, below the 475-year 0.30 g
    overturning = answer.soils[0].states[1]
    assert not overturning.tail_only and "tail" not in verdict_sentence(answer, "cabinet")
    assert "tail" not in reason(results, answer, answer.soils[0])
    assert overturning.supported_probability == pytest.approx(_supported(levels[2]), rel=0.02)
    assert overturning.records[0][0] == 3
    no_records = block_answers(_fragility([[[[0.5, 1.0]]]], betas=0.6), _power_law())[0]
    assert not no_records.soils[0].states[1].records  # no n_records: the cell keeps its value and band only


def test_the_data_supported_part_of_the_annual_frequency_is_the_integral_above_the_lower_limit():
    from rockfrag.risk import annual_frequency

    hazard = _power_law()
    whole = annual_frequency(1.0, 0.6, hazard)
    assert annual_frequency(1.0, 0.6, hazard, lower=1e-3) == pytest.approx(whole, rel=1e-3)
    assert annual_frequency(1.0, 0.6, hazard, lower=1.5) == pytest.approx(-math.log(1 - _supported(1.5)) / 50,
                                                                          rel=0.01)
    assert annual_frequency(1.0, 0.0, hazard, lower=2.0) == pytest.approx(K0 * 2.0 ** -K)  # a step below it


def test_the_answer_pages_state_the_planar_model_and_where_the_friction_comes_from_once(small_pipeline):
    """A client took the soil's friction for the plinth's, and the planar model's limits were on another page; the
    same paragraph then stood on every block's page (issue 36: common text once). The page before the answers
    says both once; the limitations give each block's b."""
    from rockfrag.report.answer_page import answer_items, reading_items
    from rockfrag.report.sections import limitations_items, sources_items
    from tests.helpers import pipeline_results

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    common = " ".join(item.text for item in reading_items(results))
    assert "planar model" in common and "bottom edge" in common
    for soil in results.config.soils:
        assert f"{soil.name} {soil.friction_static:g}/{soil.friction_kinetic:g}" in common
    assert "soil class's default coefficient" in common and "plinth" in common and "shim" in common
    for answer in results.answers:
        text = " ".join(item.text for item in answer_items(results, answer))
        assert results.friction_words not in text and "bottom edge" not in text  # said once, before
    limitations = limitations_items(results)
    words = " ".join(item.text for item in limitations)
    assert "Planar model" in words and "twisting (wobbling)" in words and "three-dimensional rocking" in words
    planar = next(item for item in limitations if item.kind == "table" and "half-width b" in item.header[1])
    for block, row in zip(results.cube.block.values, planar.rows):
        assert row[1] == f"{float(results.cube.block_b.sel(block=block)):.3g}"
    assert results.friction_words not in words and "Reading the answer pages" in words  # said once, referred to
    sources = " ".join(item.text for item in sources_items(results))
    assert results.friction_words not in sources and "NAVFAC DM-7.02" in sources


def test_the_seed_paper_is_cited_from_its_copy_and_named_in_full_on_the_methods_page(small_pipeline):
    from rockfrag.report.sections import methods_items
    from rockfrag.report.words import PAPER_CITATION, PAPER_TITLE, REFERENCES
    from tests.helpers import ROOT, pipeline_results

    assert REFERENCES["paper"].startswith(PAPER_CITATION) and "doi:10.20944/" in PAPER_CITATION
    copy = ROOT.parent / "shared" / "seed" / "rocking-ssi-paper.txt"
    if copy.is_file():  # the title as the copy gives it (no authors, journal or year there: none invented)
        assert PAPER_TITLE in copy.read_text(encoding="utf-8").splitlines()[:5]
    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    assert any(PAPER_CITATION in item.text for item in methods_items(results))


def test_a_median_below_the_lowest_level_is_bounded_by_the_records_not_read_from_the_fits_tail():
    """The client read "uplift 98%, once in 13 years" from a median of 0.069 g, below the lowest level run (0.1 g),
    where every record had already lifted off: the page gives the records' fraction there as a lower bound."""
    from types import SimpleNamespace

    from rockfrag.report import numbers
    from rockfrag.report.summary import p_at_return_period, p_in_life, reason

    levels = np.geomspace(0.1, 4.0, 8)
    empirical = np.ones((levels.size, 2, 1, 2, 2))
    empirical[:, :, :, :, 1] = np.where(levels >= 1.0, 0.5, 0.0)[:, None, None, None]  # overturning: in range
    fragility = _fragility([[[[0.069, 1.5]]]], betas=0.3, empirical=empirical).assign(n_records=10)
    answer = block_answers(fragility, _power_law())[0]
    uplift, overturning = answer.soils[0].states
    assert uplift.below_lowest == (pytest.approx(0.1), 10, 10) and overturning.below_lowest is None
    # in life: the records' 100% at 0.1 g times P(PGA > 0.1 g), not the fit's P(PGA > 0.069 g)-like value
    assert uplift.annual_frequency == pytest.approx(K0 * 0.1 ** -K, rel=1e-6)
    fitted = K0 * 0.069 ** -K * math.exp(K ** 2 * 0.3 ** 2 / 2)
    assert uplift.annual_frequency < 0.5 * fitted
    assert p_in_life(uplift) == numbers.bound(uplift.probability_in_life, "≥") and p_in_life(uplift).startswith("≥")
    assert p_at_return_period(uplift, 0, answer.intensities) == "100%"  # every record: a certainty
    assert not p_in_life(overturning).startswith("≥")
    judged = block_answers(fragility, _power_law(), limits={"rocking-0.5": 0.1})[0]
    assert "in 50 years at least " in verdict_sentence(judged, "cabinet")  # a lower bound is said so in the verdict
    assert reason(SimpleNamespace(facts=numbers.Facts()), judged, judged.soils[0]) == \
        "10 of 10 records already at 0.10 g: a bound"


def test_the_sample_paragraph_is_the_blocks_own_and_says_when_the_restitution_range_is_one_run():
    """The client read the study-wide β ranges and the cabinet's r on the crane's and the skid's pages, and the skid's
    page did not say that its restitution runs were one run (no spread by construction). The β of each row is
    the summary's now; the calibrated damping ratio is printed nowhere (issue 36's precision policy)."""
    from types import SimpleNamespace

    from rockfrag.report.answer_page import curve_reason

    models = ["recommended"]
    requested = np.array([[0.73, 0.75, 0.76], [0.94, 0.97, 0.99], [0.46, 0.47, 0.48]])  # crane, cabinet, skid
    reached = np.array([[0.73, 0.75, 0.76], [0.94, 0.95, 0.95], [np.nan] * 3])
    xi = np.array([[0.5, 0.4, 0.3], [0.4, 0.16, 0.16], [0.15, 0.15, 0.15]])
    blocks = ["crane", "cabinet", "skid"]
    cube = _restitution_cube(requested, reached, xi, blocks)
    fdims = ("soil", "block", "model", "damage_state")
    beta_model = np.zeros((2, 3, 1, 1))
    beta_model[:, 0], beta_model[:, 1] = 0.3, 0.41
    r2r = np.broadcast_to(np.array([0.5, 1.17, 0.2])[None, :, None, None], (2, 3, 1, 1))
    fragility = xr.Dataset({"beta_model": (fdims, beta_model), "beta_record_to_record": (fdims, r2r)},
                           coords={"soil": ["clay", "rock"], "block": blocks, "model": models,
                                   "damage_state": ["overturning"]})
    results = SimpleNamespace(fragility=fragility, cube=cube)
    crane, cabinet, skid = (curve_reason(results, "recommended", b) for b in blocks)
    assert crane == ""  # the range reached and not collapsed: nothing of its own to say
    assert "0.990" in cabinet and "0.950" in cabinet and "collapses" not in cabinet
    assert "On every soil the restitution range collapses to one run" in skid
    assert "it reaches none of them" in skid and "because there is one run" in skid and "0.990" not in skid
    assert all("ξ" not in text and "0.15" not in text for text in (crane, cabinet, skid))  # no calibrated ξ


def _friction_cube():
    """20 records at 0.24/0.31/0.41/0.54 g on gravel (mu_s 0.55): 0, 0, 0 and 9 records need more friction. The
    recommended model is tied on gravel and slides (friction computed) on clay; the plain bed is tied on both."""
    levels = np.array([0.24, 0.31, 0.41, 0.54])
    demand = np.full((20, 4, 2, 1, 2), 0.3)
    demand[:9, 3] = 0.8
    friction = np.array([[[0.45, np.nan]], [[np.nan, np.nan]]])  # (soil, block, model): clay centre slides
    dims = ("record", "im_level", "soil", "block", "model")
    return xr.Dataset({"peak_friction_demand": (dims, demand), "outcome": (dims, np.ones(demand.shape, np.int8)),
                       "friction_static": (("soil", "block", "model"), friction),
                       "soil_friction_static": (("soil",), [0.45, 0.55])},
                      coords={"soil": ["clay", "gravel"], "block": ["crane"], "model": ["recommended", "winkler"],
                              "intensity": (("block", "im_level"), levels[None, :], {"units": "g"})})


def test_the_sliding_share_is_the_records_at_the_level_at_or_below_the_intensity_not_a_grid_average():
    """The client read 11-12% (an unweighted average over the levels up to the 2,475-year PGA) where 41-45% of the
    records at the 0.54 g level needed more friction; and a cell that slides was judged by another model's ties."""
    from rockfrag.report.adapters import sliding_at, sliding_share

    cube = _friction_cube()
    models = ["recommended", "winkler"]
    assert sliding_share(cube, models, "crane", "gravel", None, 0.57) == pytest.approx(0.45)
    assert sliding_at(cube, models, "crane", "gravel", 0.57) == (pytest.approx(0.45), pytest.approx(0.54), False)
    assert sliding_at(cube, models, "crane", "gravel", 0.5)[:2] == (0.0, pytest.approx(0.41))
    assert np.isnan(sliding_at(cube, models, "crane", "gravel", 0.2)[1])  # no level run this low
    share, _, computed = sliding_at(cube, models, "crane", "clay", 0.57)
    assert computed and np.isnan(share)  # friction computed: the slip states answer, not the plain bed's ties


def test_check_sliding_names_its_level_its_threshold_and_how_to_compute_the_sliding():
    fragility = _fragility([[[[0.3, 3.0]]]])
    answer = block_answers(fragility, _power_law(), limits={"overturning": 0.01}, max_sliding_share=0.1,
                           sliding={("cabinet", "clay"): 0.45, ("cabinet", "rock"): np.nan})[0]
    clay, rock = answer.soils
    assert (clay.verdict, rock.verdict) == (CHECK_SLIDING, NO_ACTION)
    im = (K0 * 2475.0) ** (1 / K)
    levels = np.geomspace(0.1, 4.0, 8)
    assert clay.sliding_level == pytest.approx(levels[levels <= im][-1])
    sentence = verdict_sentence(answer, "crane")
    assert f"45% of the records at {clay.sliding_level:.2g} g, the level run at or below the 2,475-year " \
           "intensity, need" in sentence
    assert "10% the study allows ([decision] max_sliding_share" in sentence
    # it says why sliding was not computed, without asking for a rerun to get a verdict
    assert "this study did not compute sliding there" in sentence and "[solver] friction setting" in sentence
    assert 'friction = "all"' not in sentence and "compute it with" not in sentence


def test_answer_page_says_when_the_measure_is_not_sufficient():
    """The efficiency stage's sufficiency test reaches the answer: p < 0.05 for a parameter of the study's measure is
    one sentence naming it; sufficient (or no test for the block) is none."""
    import xarray as xr

    from rockfrag.report.answer_page import sufficiency_words

    dims = ("soil", "block", "model", "measure")
    p = np.full((1, 2, 1, 2), 0.5)
    p[0, 0, 0, 0] = 1e-5  # block a, study measure pga: depends on the pulse period
    efficiency = xr.Dataset({"p_pulse_period": (dims, p), "p_magnitude": (dims, np.full_like(p, 0.3))},
                            coords={"soil": ["clay"], "block": ["a", "b"], "model": ["housner"],
                                    "measure": ["pga", "pgv"]})
    words = sufficiency_words(efficiency, "a", "pga", "PGA")
    assert "pulse period" in words and "magnitude" not in words and "PGA" in words
    assert "p <" not in words and "p =" not in words  # the p-values are on the efficiency page
    assert sufficiency_words(efficiency, "b", "pga", "PGA") == ""
    assert sufficiency_words(efficiency, "a", "pgv", "PGV") == ""
    assert sufficiency_words(efficiency, "missing", "pga", "PGA") == ""
    assert sufficiency_words(None, "a", "pga", "") == ""


def test_an_anchor_verdict_says_how_the_anchorage_is_designed(small_pipeline):
    """'Anchor it' came without a design basis (client read): the answer pages point to the code procedure, once,
    exactly where a verdict is 'anchor'."""
    from dataclasses import replace

    from rockfrag.report.answer_page import ANCHOR_DESIGN, reading_items
    from tests.helpers import pipeline_results

    assert "ASCE 7-22 Chapter 13" in ANCHOR_DESIGN and "F_p" in ANCHOR_DESIGN
    for anchored in (False, True):
        results = pipeline_results(small_pipeline.output, small_pipeline.study)
        answers = results.answers
        verdicts = [[ANCHOR if anchored and i == 0 else NO_ACTION for i, _ in enumerate(a.soils)] for a in answers]
        results.__dict__["answers"] = [replace(answer, soils=[replace(s, verdict=v) for s, v in zip(answer.soils, vs)])
                                       for answer, vs in zip(answers, verdicts)]
        texts = [item.text for item in reading_items(results)]
        assert (ANCHOR_DESIGN in texts) == anchored


def test_a_lower_bound_of_every_record_is_printed_as_a_certainty():
    """'\u2265100%' read oddly on the default report (every record uplifted at that level): it is 100%."""
    from rockfrag.report.numbers import bound

    assert bound(1.0, "\u2265") == "100%" and bound(0.61, "\u2265") == "\u2265 61%"
    assert bound(0.996, "\u2265") == "> 99%"


def test_the_summary_reason_gives_the_records_at_the_levels_either_side_of_the_intensity():
    """Cold read 12, user B1: the sand's 2,475-year PGA is 0.60 g, between the levels 0.52 g (0 of 44 overturned)
    and 0.65 g (1 of 44); the reason read "0 of 44 at 0.52 g: fitted tail" alone. Where none reached the state at
    the level below and some at the level above, it names both."""
    from types import SimpleNamespace

    from rockfrag.report import numbers
    from rockfrag.report.summary import reason

    levels = np.geomspace(0.1, 4.0, 8)
    im = (K0 * 2475.0) ** (1 / K)
    above = int(np.flatnonzero(levels > im)[0])
    shape = (levels.size, 2, 1, 2, 2)
    reached = np.clip((np.arange(levels.size) - above + 1) * 0.3, 0.0, 1.0)  # none below the intensity, 3 above
    fragility = _fragility([[[[0.5, 1.0]]]], betas=0.6, empirical=reached[:, None, None, None, None]
                           * np.ones(shape)).assign(n_records=10)
    answer = block_answers(fragility, _power_law(), limits={"overturning": 0.5})[0]
    overturning = answer.soils[0].states[1]
    assert overturning.records[-1] == (0, 10, pytest.approx(levels[above - 1]))
    assert overturning.records_above == (3, 10, pytest.approx(levels[above]))
    said = reason(SimpleNamespace(facts=numbers.Facts()), answer, answer.soils[0])
    assert said == f"0-3 of 10 at {levels[above - 1]:.2g}-{levels[above]:.2g} g", said


def test_a_soil_whose_bed_falls_short_only_within_tolerance_is_said_to_run_at_the_middle():
    """Cold read 12, default C3: gravel's bed reached at most 0.742, below the middle 0.746, yet only rock and steel
    were said to run their best estimate below the middle. Gravel's shortfall is within the calibration's tolerance
    (5% of the loss 1 - r: ± 0.013), so its best estimate counts as at the middle; the page now says so."""
    from rockfrag.report.answer_page import _band_reach

    requested = np.array([[0.728, 0.746, 0.764]])
    cube = _restitution_cube(requested, np.array([[0.728, 0.746, 0.742]]), np.array([[0.1, 0.06, 0.06]]), ["paper"])
    text = _band_reach(cube)
    assert "the bed's most, r 0.742, lies within the calibration's tolerance of the middle (± 0.013)" in text, text
    assert "best-estimate run uses" not in text


def test_the_answer_page_gives_each_verdicts_margin_and_the_srss_alternative():
    """Cold read 12, user B1 and B4: how far the governing median may fall before the verdict changes (the factor at
    which P in 50 years reaches the limit), and the probabilities with the model's two parts added by SRSS. Both
    checked here against the closed form of a power-law hazard: lambda = K0 m^-K exp(K^2 beta^2 / 2)."""
    from types import SimpleNamespace

    from rockfrag.report import numbers
    from rockfrag.report.answer_page import robustness_words

    fragility = _fragility([[[[0.5, 1.0]]]], betas=0.6, models=("recommended",)).assign(
        beta_record_to_record=lambda d: d.beta * 0 + 0.5, beta_form=lambda d: d.beta * 0 + 0.35,
        beta_parameters=lambda d: d.beta * 0 + 0.2)
    fragility["beta"] = np.hypot(fragility.beta_record_to_record, fragility.beta_form)  # the larger of the two
    answer = block_answers(fragility, _power_law(), limits={"overturning": 0.01})[0]
    results = SimpleNamespace(fragility=fragility, hazard=_power_law(), site_hazards=None, facts=numbers.Facts(),
                              answers=[answer], cube=None, config=None)
    words = robustness_words(results, answer)

    def p50(median, beta):  # the closed form, with the curve's own range ignored (its ends far from the median)
        return 1 - math.exp(-50 * K0 * median ** -K * math.exp(K * K * beta * beta / 2))

    beta = math.hypot(0.5, 0.35)
    # the factor f at which P50 reaches 1%: K0 (f m)^-K exp(K² β²/2) = -ln(0.99)/50
    factor = (K0 * math.exp(K * K * beta * beta / 2) / (-math.log(0.99) / 50)) ** (1 / K) / 1.0
    way = f"fall {100 * (1 - factor):.0f}%" if factor < 1 else f"rise {100 * (factor - 1):.0f}%"
    assert f"would have to {way} on clay (overturning" in words, (words, factor)
    srss = math.sqrt(0.5 ** 2 + 0.35 ** 2 + 0.2 ** 2)
    assert f"{numbers.probability(p50(1.0, srss))} on clay (β {numbers.dispersion(srss)})" in words, words
