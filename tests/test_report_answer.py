"""The answer pages (issue 20, item 1): return-period intensities, P(each damage state) with its band, the
design-life risk and the verdict, checked against closed forms on hand-made datasets (no study run)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from scipy.stats import lognorm

from pipeline.answer import (
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
from pipeline.hazard import HazardCurve, load_hazard

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
    from pipeline.config import load_study
    from pipeline.errors import ConfigError

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


def test_the_governing_mode_at_each_return_period_comes_from_the_runs_at_the_nearest_level():
    """Issue 19: which mode governs at each return-period intensity. Mode times where the base slides; the
    outcome where it is tied (no mode times); the recommended curve reads the band centre's runs."""
    import xarray as xr

    from pipeline.models.fields import MODE_TIME_FIELDS
    from pipeline.models.variants import RECOMMENDED
    from pipeline.report.answer_page import governing_modes

    levels = np.array([0.1, 0.3, 1.0])  # g
    times = np.zeros((4, 3, 1, 1, 2, len(MODE_TIME_FIELDS)))  # record, level, soil, block, model, mode
    times[:, 0, ..., 0] = 10.0   # at rest at 0.1 g
    times[:, 1, ..., 1] = 10.0   # slides at 0.3 g (one record also rocks for 2 s: not half of them)
    times[0, 1, ..., 2] = 2.0
    times[:, 2, ..., 0] = 30.0   # at 1 g mostly at rest, but every record slides and rocks for a while: that
    times[:, 2, ..., 3] = 1.0    # is what it does (the longest mode would say "at rest")
    times[..., 1, :] = np.nan    # the second model is tied: no mode times
    outcome = np.zeros((4, 3, 1, 1, 2), np.int8)
    outcome[:, 1:, ..., 1] = 1   # tied: rocks from 0.3 g
    outcome[:3, 2, ..., 1] = 2   # ... and 3 of 4 records overturn at 1 g
    dims = ("record", "im_level", "soil", "block", "model")
    cube = xr.Dataset({field: (dims, times[..., k]) for k, field in enumerate(MODE_TIME_FIELDS)} |
                      {"outcome": (dims, outcome)},
                      coords={"soil": ["clay"], "block": ["skid"], "model": ["winkler-centre", "housner"],
                              "intensity": (("block", "im_level"), levels[None, :], {"units": "g"})})
    assert governing_modes(cube, "skid", RECOMMENDED, "clay", [0.11, 0.28, 0.9], 1.0) == \
        ["at rest (100% of the records)", "slides (100% of the records)", "slides and rocks (100% of the records)"]
    assert governing_modes(cube, "skid", "housner", "clay", [0.1, 0.3, 1.0], 1.0) == \
        ["at rest (100% of the records)", "rocks (100% of the records)", "overturns (75% of the records)"]
    assert governing_modes(None, "skid", "housner", "clay", [0.1], 1.0) == ["-"]


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


def test_the_answer_says_where_the_bed_could_not_reach_the_band():
    """The example study's log warned that the bed runs the band's centre and upper edge at a lower r than asked;
    the answer page must say it too (beta_model there leaves out the less dissipative side)."""
    from pipeline.report.answer_page import _band_reach

    dims = ("soil", "block", "model")
    requested = np.array([[[np.nan, 0.825, 0.845, 0.866]], [[np.nan, 0.825, 0.845, 0.866]]])
    reached = np.array([[[np.nan, 0.825, 0.836, 0.836]], [[np.nan, 0.825, 0.845, 0.866]]])
    cube = xr.Dataset({"restitution_requested": (dims, requested), "restitution_target": (dims, reached)},
                      coords={"soil": ["clay", "rock"], "block": ["cabinet"],
                              "model": ["housner", "winkler-low", "winkler-centre", "winkler-high"]})
    text = _band_reach(cube)
    assert "On clay the bed" in text and "clay, rock" not in text and "0.866" in text and "0.836" in text
    assert _band_reach(cube.assign(restitution_target=cube.restitution_requested)) == ""
