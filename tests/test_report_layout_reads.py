"""Figures and captions after cold read 3 (issue 36): each test fails on the figure or caption the read found.

- the applicability caption names a next page only where the sweep follows (user B2); a soil without a point says
  so on the top axis and why in the legend, and a model drawn as points is a point in the legend (user B3);
- a soil's site hazard curve stops where the hazard given ends (user B7, default B8);
- every IDA panel whose curves lie on the frame says so, the same way (default C1, the recommended steel panel);
- the outcomes legend lists the rocking shading only where it shows; the captions name it (default C2);
- the sweep's ±10% band is visible however large the ratios; one "dotted" entry per legend; the notes under the
  legend are announced only where there are some; one ground-acceleration panel on the showcase page (user C6).
"""

from __future__ import annotations

import dataclasses
import textwrap

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

from rockfrag.report import figures


def _legend_labels(figure) -> list[str]:
    return [text.get_text().replace("\n", " ") for legend in figure.legends for text in legend.get_texts()]


@pytest.fixture(scope="module")
def small_results(small_pipeline):
    from rockfrag.config import load_study
    from rockfrag.report import report_results

    output = small_pipeline.output
    opened = {name: xr.load_dataset(output / f"{name}.nc") for name in ("cube", "ida", "fragility")}
    return report_results(load_study(small_pipeline.study), opened["cube"], opened["ida"], opened["fragility"], None,
                          output)


def _fresh(results, **changes):
    from rockfrag.report import numbers

    return dataclasses.replace(results, facts=numbers.Facts(), **changes)


@pytest.mark.slow
def test_the_applicability_caption_points_to_a_next_page_only_where_the_sweep_follows(small_results):
    from rockfrag.report import SWEEP_NEXT, build_plan

    assert "next page" not in figures_caption(build_plan(_fresh(small_results, applicability=None)), "applicability")
    planned = build_plan(_fresh(small_results))
    names = [page.name for page in planned]
    assert names[names.index("applicability") + 1] == "applicability-sweep"
    assert figures_caption(planned, "applicability").endswith(SWEEP_NEXT)


def figures_caption(planned, name: str) -> str:
    return next(page.caption for page in planned if page.name == name)


@pytest.mark.slow
def test_a_soil_without_a_ratio_says_so_and_why_and_points_are_points_in_the_legend(small_pipeline):
    """The rigid base slides on sand (friction below tan α) and never rocks there: sand has no point. The top axis
    marks it '(no point)', the block's legend entry says why, and each model, drawn as one point (rock alone), is a
    marker in the legend, not a line."""
    cube = xr.load_dataset(small_pipeline.output / "cube.nc")
    changed = cube.copy(deep=True)
    housner = dict(model="housner", soil="sand")
    changed["outcome"].loc[housner] = 0  # never lifts off: it slides
    friction = np.full((changed.sizes["soil"], changed.sizes["block"], changed.sizes["model"]), np.nan)
    changed["friction_static"] = (("soil", "block", "model"), friction)
    changed["friction_static"].loc[housner] = 0.1  # below tan α of every block
    figure = figures.applicability_page(changed, "Read it.")
    try:
        top = [axis for axis in figure.axes[0].child_axes if type(axis).__name__ == "SecondaryAxis"][0]
        ticks = [text.get_text() for text in top.get_xticklabels()]
        assert "sand\n(no point)" in ticks and "rock" in ticks
        labels = _legend_labels(figure)
        assert any("no point on sand: the rigid base slides there and never rocks" in label for label in labels)
        handles = {text.get_text().replace("\n", " "): handle for legend in figure.legends
                   for text, handle in zip(legend.get_texts(), legend.legend_handles)}
        model_entries = [handle for label, handle in handles.items() if not label.startswith(("block", "within",
                                                                                              "300-"))]
        assert model_entries and all(handle.get_linestyle() in ("None", "none") and handle.get_marker() not in
                                     (None, "None", "none", "") for handle in model_entries)
    finally:
        plt.close(figure)


def _hazard(intensity, frequency, source):
    from rockfrag.hazard import HazardCurve

    return HazardCurve(np.asarray(intensity, float), np.asarray(frequency, float), "pga", None, source)


def test_a_soils_hazard_curve_stops_where_the_given_hazard_ends():
    """The reference curve ends at 3 g (1e-6 /yr); a soil's curve carried from it was drawn on to 12 g. Its part
    below the reference's rarest frequency rests on nothing given and is not drawn."""
    from rockfrag.site_hazard import SiteHazards

    given = np.geomspace(0.05, 3.0, 40)
    reference = _hazard(given, 1e-4 * given ** -2.5 * 0.0185, "reference")
    soil_grid = np.geomspace(0.0125, 12.0, 120)
    soil = _hazard(soil_grid, 2e-6 * soil_grid ** -2.5, "sand")
    sites = SiteHazards({"sand": soil, "rock": reference}, reference, 760.0)
    figure = figures.hazard_page(sites, [475, 2475], "Read it.")
    try:
        axis = figure.axes[0]
        sand = next(line for line in axis.get_lines() if line.get_label() == "sand")
        rarest = reference.annual_frequency.min()
        assert np.min(sand.get_ydata()) >= rarest * (1 - 1e-9)
        assert np.max(sand.get_ydata()) <= reference.annual_frequency.max() * (1 + 1e-9)
        assert len(sand.get_ydata()) > 20  # the given part is drawn
    finally:
        plt.close(figure)


def test_every_ida_panel_whose_curves_lie_on_the_frame_says_so():
    """The recommended model's panels of the paper's block (default study): on clay θmax/α stays below 0.05 in
    every record (0.004-0.044), on steel in all but 2 of 616 runs (84% fractile at most 0.002). Both say so,
    as the panels below 0.01 did; a panel whose records rock does not."""
    rng = np.random.default_rng(1)
    clay = rng.uniform(0.004, 0.044, (44, 14))
    steel = np.where(rng.uniform(size=(44, 14)) < 0.003, 0.16, rng.uniform(0.0, 0.002, (44, 14)))
    steel[0, -1] = 0.16
    rocking = rng.uniform(0.0, 1.2, (44, 14))
    for edp in (clay, steel):
        note = figures.frame_note(edp, np.quantile(edp, 0.84, axis=0))
        assert "the curves lie on the left axis" in note or "(84% fractile): on the left axis" in note
    assert figures.frame_note(rocking, np.quantile(rocking, 0.84, axis=0)) == ""
    assert figures.frame_note(np.full((2, 3), np.nan), np.full(3, np.nan)) == "not run"


@pytest.mark.slow
def test_the_outcomes_legend_lists_the_rocking_shading_only_where_it_shows(small_pipeline):
    """A panel with one pair of curves shades rocking without overturning between them; where uplift and
    overturning coincide nothing shows, and the legend then does not list the shading."""
    from rockfrag.report import CAPTIONS, OUTCOMES_SHADING

    assert "shaded orange" in OUTCOMES_SHADING and "{shading}" in CAPTIONS["outcomes"]
    fragility = xr.load_dataset(small_pipeline.output / "fragility.nc")
    block = str(fragility.block.values[0])
    changed = fragility.copy(deep=True)
    probability = changed["outcome_probability"]
    overturned = probability.sel(outcome_class="overturned")
    probability.loc[dict(outcome_class="no_uplift")] = 1 - overturned
    probability.loc[dict(outcome_class="rocking")] = 0.0
    uplift_states = [str(s) for s, edp in zip(changed.damage_state.values, changed.damage_state_edp.values)
                     if str(edp) == "uplifted"]
    for state in uplift_states:
        changed["empirical_fraction"].loc[dict(damage_state=state)] = np.nan
    figure = figures.outcomes_page(changed, block, "Read it.")
    try:
        assert "rocking without overturning" not in _legend_labels(figure)
    finally:
        plt.close(figure)


@pytest.mark.slow
def test_the_sweeps_band_is_visible_however_large_the_ratios(small_pipeline):
    """Ratios up to 17 on a linear axis drew the ±10% band as a hairline; on a log axis it keeps its height."""
    applicability = xr.load_dataset(small_pipeline.output / "applicability.nc")
    applicability["peak_angle_ratio_to_housner"] = applicability.peak_angle_ratio_to_housner * 1.0
    applicability["peak_angle_ratio_to_housner"][..., 0] = 17.0  # the softest soil: a large ratio
    figure = figures.sweep_page(applicability, "Read it.")
    try:
        figure.draw_without_rendering()
        axis = figure.axes[0]
        band = [patch for patch in axis.patches if abs(patch.get_facecolor()[0] - 0.8) < 0.01]
        assert band, "no ±10% band"
        height = band[0].get_window_extent().height
        assert height >= 0.04 * axis.get_window_extent().height
    finally:
        plt.close(figure)


@pytest.mark.slow
def test_one_dotted_entry_per_legend_and_notes_announced_only_where_drawn(small_results):
    """Default C2 and read 3: an IDA page listed 'dotted: the site's intensity ...' and 'dotted, in each soil's
    colour ...' (its per-soil panels drew the marks in one colour, its every-soil panels in the soils'); fragility
    captions announced 'notes under the legend' on pages with none."""
    from rockfrag.report import CAPTIONS, NOTES_WORDS, build_plan

    assert "notes under the legend" not in CAPTIONS["fragility-soils"] + CAPTIONS["fragility-models"]
    for page in build_plan(_fresh(small_results)):
        if page.html is not None or not page.name.startswith(("ida-", "fragility-", "outcomes-")):
            continue
        figure = page.draw()
        try:
            dotted = [label for label in _legend_labels(figure) if label.lower().startswith("dotted")]
            assert len(dotted) <= 1, (page.name, dotted)
            if page.name.startswith("fragility-"):
                noted = any(text.get_text().startswith("No curve") for text in figure.texts)
                assert noted == page.caption.endswith(NOTES_WORDS), page.name
        finally:
            plt.close(figure)
    fitted = small_results.fragility.copy(deep=True)
    fitted["median"] = fitted["median"].fillna(1.0)
    fitted["beta"] = fitted["beta"].fillna(0.5)
    assert not figures.has_page_notes(fitted, str(fitted.block.values[0]))


@pytest.mark.slow
def test_the_showcase_page_draws_the_ground_acceleration_once(small_pipeline):
    showcase = xr.load_dataset(small_pipeline.output / "showcase.nc")
    figure = figures.showcase_response_page(showcase, "Read it.")
    try:
        grounds = [axis for axis in figure.axes if axis.get_title().startswith("ground acceleration")]
        assert len(grounds) == 1
    finally:
        plt.close(figure)


def _tick_texts(axis) -> list[str]:
    """The labels of the major ticks inside the view, as drawn (after a draw: formatters run then)."""
    axis.figure.canvas.draw()
    low, high = sorted(axis.get_view_interval())
    return [tick.label1.get_text() for tick in axis.get_major_ticks() if low <= tick.get_loc() <= high]


def test_intensity_and_period_axes_are_labelled_in_plain_numbers():
    """Cold read 4: the hazard page's PGA axis and the spectra page's period and Sa axes read 10^-1, 10^0 (mathtext);
    an engineer reads 0.1, 0.5, 1 g and 0.1, 1 s. The hazard page's annual frequency keeps 10^n."""
    import xarray as xr

    from rockfrag.site_hazard import SiteHazards

    given = np.geomspace(0.03, 3.0, 40)
    reference = _hazard(given, 1e-4 * given ** -2.5 * 0.0185, "reference")
    figure = figures.hazard_page(SiteHazards({"rock": reference}, reference, 760.0), [475, 2475], "Read it.")
    try:
        x = _tick_texts(figure.axes[0].xaxis)
        assert len(x) >= 3 and all(text and "^" not in text and "$" not in text for text in x), x
        assert float(x[0]) < float(x[-1])
    finally:
        plt.close(figure)
    periods = np.geomspace(0.02, 10.0, 60)
    spectra = np.exp(np.random.default_rng(2).normal(0.0, 0.4, (10, 60))) * 9.81 / (1 + periods)
    showcase = xr.Dataset({"record_spectrum": (("record", "period"), spectra)}, coords={"period": periods})
    figure = figures.spectra_page(showcase, "Read it.")
    try:
        for axis in (figure.axes[0].xaxis, figure.axes[0].yaxis):
            texts = _tick_texts(axis)
            assert len(texts) >= 3 and all(t and "^" not in t and "$" not in t for t in texts), texts
    finally:
        plt.close(figure)


# --- cold read 5 (issue 36): figures and captions the readers of /work/tmp/read5 found ---------------------------


@pytest.mark.slow
def test_a_panel_with_points_names_the_models_whose_base_is_tied(small_results):
    """Default C (pp. 30, 35, 36) and user C1: a slip panel drew Housner's points but not the paper's model, whose
    runs tie the base, and said nothing; the panel now names the tied models (an empty panel already said why)."""
    fragility = small_results.fragility
    block = str(fragility.block.values[0])
    models = figures.models_of(fragility)
    tied = {(str(state), str(soil)): figures.tied_models(fragility, block, str(state), models, str(soil))
            for state in fragility.damage_state.values for soil in fragility.soil.values}
    assert any(tied.values()), "the small study ties no base: the test needs a slip state of a tied model"
    figure = figures.fragility_by_model_page(fragility, block, [str(fragility.soil.values[0])], "Read it.")
    try:
        notes = [text.get_text().replace("\n", " ") for text in figure.texts]
        assert any("its base is tied" in note for note in notes), notes
    finally:
        plt.close(figure)


@pytest.mark.slow
def test_a_page_of_every_soil_names_the_soils_where_a_model_ties_the_base(small_results):
    """figs6's closing report: on a page of every soil (fragility by soil) a model tied on some soils only was
    named nowhere (``tied_models`` asked for every soil at once), so Housner's slip series on gravel, rock and steel
    were missing from the default p. 32 without a word. Seeded: one model's slip runs tied on the first soil only."""
    from rockfrag.fragility import NOT_APPLICABLE

    fragility = small_results.fragility.copy(deep=True)
    block = str(fragility.block.values[0])
    models = figures.models_of(fragility)
    slips = [str(s) for s, edp in zip(fragility.damage_state.values, fragility.damage_state_edp.values)
             if str(edp) != "uplifted" and "slip" in str(s)]
    assert slips and fragility.sizes["soil"] > 1, "the small study needs a slip state and two soils"
    soil = str(fragility.soil.values[0])
    reference = next(m for m in models if m.rigid_base)
    other = [m for m in models if m.name != reference.name]
    where = dict(block=block, damage_state=slips, model=reference.name)
    fragility["status"] = fragility["status"].astype(object)
    for state in slips:
        fragility["status"].loc[dict(where, damage_state=state)] = [
            NOT_APPLICABLE if str(s) == soil else "fitted" for s in fragility.soil.values]
    fragility["empirical_fraction"].loc[dict(where, soil=soil)] = np.nan
    for state in slips:  # another series has points in the panel, so the note is the page's, not the panel's
        fragility["empirical_fraction"].loc[dict(block=block, damage_state=state, model=other[0].name)] = 0.5
    assert figures.tied_soils(fragility, block, slips[0], reference) == [soil]
    figure = figures.fragility_by_soil_page(fragility, block, other[0], "Read it.")
    try:
        notes = " ".join(text.get_text().replace("\n", " ") for text in figure.texts)
        assert f"{figures.panel_label(reference)} on {soil}: no points in the" in notes, notes
    finally:
        plt.close(figure)


@pytest.mark.slow
def test_a_fragility_page_marks_a_fit_that_fails_its_goodness_of_fit_test(small_results):
    """Cold read 7 (default pp. 32-33): the answer table marked the paper block's lift-off on steel ‡ (gof p 0.0034,
    beta 1.12, its points well above the curve), its fragility pages said nothing. Seeded: one fitted series fails."""
    fragility = small_results.fragility.copy(deep=True)
    block = str(fragility.block.values[0])
    fitted = np.isfinite(fragility["median"].sel(block=block)) & np.isfinite(fragility["beta"].sel(block=block))
    model, soil, state = next((m, str(s), str(d)) for m in figures.models_of(fragility) if not m.rigid_base
                              for s in fragility.soil.values for d in fragility.damage_state.values
                              if bool(fitted.sel(model=m.name, soil=s, damage_state=d)))
    fragility["gof_p_value"] = xr.full_like(fragility["median"], 0.5)
    clean = figures.fragility_by_soil_page(fragility, block, model, "Read it.")
    try:
        assert "goodness-of-fit" not in " ".join(text.get_text() for text in clean.texts)
    finally:
        plt.close(clean)
    fragility["gof_p_value"].loc[dict(block=block, model=model.name, soil=soil, damage_state=state)] = 0.003
    figure = figures.fragility_by_soil_page(fragility, block, model, "Read it.")
    try:
        notes = " ".join(text.get_text().replace("\n", " ") for text in figure.texts)
        assert "‡ The fit fails its goodness-of-fit test" in notes and f"on {soil}" in notes, notes
    finally:
        plt.close(figure)


@pytest.mark.slow
def test_the_outcomes_caption_names_the_orange_band_only_where_it_shows(small_results):
    """User C2: 'shaded orange where a panel has one pair of curves' stood in a caption whose page has no band."""
    from rockfrag.report import OUTCOMES_SHADING, build_plan

    fragility = small_results.fragility
    planned = build_plan(_fresh(small_results))
    for block in map(str, fragility.block.values):
        caption = figures_caption(planned, f"outcomes-{block}")
        assert (OUTCOMES_SHADING in caption) == figures.rocking_shaded(fragility, block), block
    flat = fragility.copy(deep=True)  # uplift and overturning coincide: nothing to shade
    probability = flat["outcome_probability"]
    probability.loc[dict(outcome_class="no_uplift")] = 1 - probability.sel(outcome_class="overturned")
    flat["empirical_fraction"].loc[dict(damage_state=[str(s) for s, edp in zip(
        flat.damage_state.values, flat.damage_state_edp.values) if str(edp) == "uplifted"])] = np.nan
    assert not figures.rocking_shaded(flat, str(flat.block.values[0]))


def test_an_outcomes_panel_title_stays_on_one_line():
    """User C5: on a page of three panels "SSI, paper's model (spring can pull)" wrapped to two lines and sat
    above its neighbours' one-line titles."""
    from rockfrag.report.layout import chars_across, new_page, panels

    ssi = next(m for m in figures.models_of(xr.Dataset(coords={"model": ["housner", "ssi", "recommended"]}))
               if m.name == "ssi")
    figure = new_page("Outcomes", "Read it.")
    try:
        axis = panels(figure, 1, 3)[0, 1]
        assert "\n" in textwrap.fill(figures.short_label(ssi), chars_across(axis, 9.5))  # the old title wrapped
        assert "\n" not in figures.one_line_title(ssi, axis, 9.5)
    finally:
        plt.close(figure)


def test_the_captions_say_what_the_drawing_shows():
    """Default C: the by-soil page's model line was not named (dash-dot); the spectra caption did not say where
    the records are listed; 'the processed displacement ends at rest' where the raw one did too."""
    from rockfrag.report import CAPTIONS

    assert "{lines}" in CAPTIONS["fragility-soils"]
    assert "Records section" in CAPTIONS["spectra"]
    assert "ends at rest" not in CAPTIONS["showcase-processing"]
    coords = {"model": ["housner", "ssi", "recommended"]}
    fragility = xr.Dataset(coords=coords)
    by_name = {m.name: m for m in figures.models_of(fragility)}
    assert figures.line_words(fragility, by_name["ssi"]) == "dash-dot"
    assert figures.line_words(fragility, by_name["recommended"]) == "thick solid"


def test_the_showcase_caption_says_which_soils_hardly_rock():
    """Default C (p. 26): on steel both panels were flat at the page's θ scale and nothing said why."""
    time = np.linspace(0.0, 10.0, 101)
    theta = np.array([np.sin(time) * a for a in (0.0, 1e-3, 1e-2, 1e-4)])
    showcase = xr.Dataset({"theta": (("case", "time"), theta)}, coords={
        "time": time, "case_model": ("case", ["housner", "ssi", "ssi", "ssi"]),
        "case_soil": ("case", ["", "clay", "sand", "steel"])})
    assert figures.quiet_soils(showcase) == ["steel"]
    assert "On steel the block hardly lifts off" in figures.quiet_words(showcase)
    showcase["theta"][3] = np.sin(time) * 5e-3
    assert figures.quiet_words(showcase) == ""


def test_the_hazard_legend_gives_each_carried_sites_vs30():
    """Default C (p. 23): rock's curve lay below the reference site's (Vs30 760 m/s) it is carried from and nothing
    said rock's site is stiffer; the legend now gives each carried site's Vs30 and the caption what it means."""
    import dataclasses as dc

    from rockfrag.report import CAPTIONS, stiffer_site_words
    from rockfrag.site_hazard import SiteHazards

    given = np.geomspace(0.05, 3.0, 40)
    reference = _hazard(given, 1e-4 * given ** -2.5 * 0.0185, "reference")
    rock = dc.replace(_hazard(given, 0.7e-4 * given ** -2.5 * 0.0185, "rock"), notes={"site_vs30_m_s": 1080.0})
    figure = figures.hazard_page(SiteHazards({"rock": rock}, reference, 760.0), [475], "Read it.")
    try:
        assert "rock (Vs30 1,080 m/s)" in [line.get_label() for line in figure.axes[0].get_lines()]
    finally:
        plt.close(figure)
    assert "stiffer than the reference" not in CAPTIONS["hazard"]  # said where such a site is drawn, only there
    soil = dc.make_dataclass("Soil", ["name", "vs30"])
    sites = SiteHazards({"rock": rock}, reference, 760.0)
    assert "Rock: a site stiffer than the reference" in stiffer_site_words([soil("rock", 1080.0)], sites)
    assert stiffer_site_words([soil("rock", 500.0)], sites) == ""  # cold read 11: the user study has none
    assert stiffer_site_words([soil("clay", 1080.0)], sites) == ""  # not drawn


def test_a_pages_notes_group_a_models_soils_so_ten_series_fit():
    """Default C (pp. 30, 36): ten series without a curve were listed one by one, overflowed the legend's column
    and fell back to 'No curve, points only: 10 series on this page; the limitations list each'. One model's soils
    are now joined."""
    soils = ["clay", "sand", "gravel", "rock", "steel"]
    series = [f"SSI, paper's model on {soil}" for soil in soils] + [f"Housner (rigid base) on {soil}"
                                                                   for soil in soils[2:]]
    words = figures._series_words(series)
    assert words == "SSI, paper's model on clay, sand, gravel, rock, steel; Housner (rigid base) on gravel, rock, steel"
    assert len(words) < len("; ".join(series)) * 0.6
    assert figures._series_words(["recommended", "recommended"]) == "recommended"
    # cold read 12, default figures: "Recommended on gravel, steel, clay, sand, rock": the report's soil order now
    shuffled = [f"Recommended on {soil}" for soil in ("gravel", "steel", "clay", "sand", "rock")]
    assert figures._series_words(shuffled, soils) == "Recommended on clay, sand, gravel, rock, steel"


@pytest.mark.slow
def test_a_fitted_median_outside_the_levels_is_said_under_the_legend(small_results):
    """Default C (p. 31): the recommended lift-off on gravel has its median (0.200 g) below the lowest level run
    (fragility.csv 'extrapolated'); the figure showed the curve entering at 0.58 and said nothing."""
    fragility = small_results.fragility.copy(deep=True)
    block = next(str(b) for b in fragility.block.values if np.isfinite(fragility["median"].sel(block=b)).any())
    model, soil, state = next((m, str(s), str(d)) for m in figures.models_of(fragility) if not m.rigid_base
                              for s in fragility.soil.values for d in fragility.damage_state.values
                              if np.isfinite(float(fragility["median"].sel(block=block, model=m.name, soil=s,
                                                                           damage_state=d))))
    fragility["status"].loc[dict(block=block, model=model.name, soil=soil, damage_state=state)] = "extrapolated"
    figure = figures.fragility_by_soil_page(fragility, block, model, "Read it.")
    try:
        notes = " ".join(text.get_text().replace("\n", " ") for text in figure.texts)
        assert "Median outside the levels run" in notes and soil in notes.split("Median outside")[1], notes
    finally:
        plt.close(figure)


def test_a_by_soil_title_names_the_references_it_draws():
    """Cold read 7, user C4: 'Fragility by soil: ..., SSI, paper's model (spring can pull)' over panels that draw
    Housner (rigid base) too."""
    fragility = xr.Dataset(coords={"model": ["housner", "ssi", "recommended"]})
    models = {m.name: m for m in figures.models_of(fragility)}
    title = figures.fragility_by_soil_title(fragility, "box", models["ssi"], "enclosure E-1")
    assert title == (f"Fragility by soil: enclosure E-1, {figures.short_label(models['ssi'])}, with "
                     f"{figures.short_label(models['housner'])} for reference")
    alone = xr.Dataset(coords={"model": ["recommended"]})
    assert "for reference" not in figures.fragility_by_soil_title(alone, "box", models["recommended"])


def test_the_outcomes_page_says_which_soils_lines_coincide():
    """Cold read 7, default p. 41: in the Housner and SSI panels the gravel, rock and steel curves coincide, so one
    line showed for three soils without a word."""
    models = {m.name: m for m in figures.models_of(xr.Dataset(coords={"model": ["housner", "ssi", "recommended"]}))}
    rise, flat = np.array([0.0, 0.5, 1.0]), np.zeros(3)
    pairs = [(models["housner"], [("clay", 0, flat, flat), ("gravel", 2, rise, flat), ("rock", 3, rise, flat)]),
             (models["ssi"], [("clay", 0, rise, flat), ("gravel", 2, rise, rise * 0.1)]),
             (models["recommended"], [("clay", 0, rise, flat), ("gravel", 2, rise * 0.9, flat * 0.5 + 0.1)])]
    words = figures.coinciding_words(pairs)
    assert words == ("Lines that coincide (the last drawn hides the others): "
                     f"{figures.panel_label(models['housner'])}: gravel = rock; "
                     f"{figures.panel_label(models['ssi'])}: P(uplift) on every soil.")
    assert figures.coinciding_words([(models["recommended"], [("clay", 0, rise, flat)])]) == ""


def test_the_ida_rigid_row_of_a_block_that_slides_on_every_soil_says_so(small_pipeline):
    """Cold read 9 (default figures B4): the squat skid's shared rigid-base row read 'its rocking is the same on every
    soil', flat at zero, while it slides on every soil (μ_s below its b/h 0.75). A rigid row that never rocked on a
    block whose every soil's friction is below its b/h says that it slides; otherwise the row keeps its heading."""
    import matplotlib.pyplot as plt
    import numpy as np
    import xarray as xr

    from rockfrag.report import figures

    ida = xr.open_dataset(small_pipeline.output / "ida.nc").load()
    block = str(ida.block.values[0])

    def headings(dataset):
        figure = figures.ida_page(dataset, block, "Read it.")
        try:
            return [t.get_text() for t in figure.texts]
        finally:
            plt.close(figure)

    ratio = float(ida.block_b.sel(block=block)) / float(ida.block_h.sel(block=block))
    still = ida.copy()
    rigid = [str(m) for m in ida.model.values if str(m) == "housner"]
    assert rigid, ida.model.values
    edp = still.edp.values.copy()
    index = list(map(str, ida.model.values)).index("housner")
    axis = still.edp.dims.index("model")
    np.moveaxis(edp, axis, 0)[index] = 0.0
    still["edp"] = still.edp.copy(data=edp)
    still = still.assign_coords(soil_friction_static=("soil", np.full(ida.sizes["soil"], 0.9 * ratio)))
    assert figures.RIGID_SLIDES in headings(still)
    tied = still.assign_coords(soil_friction_static=("soil", np.full(ida.sizes["soil"], 1.1 * ratio)))
    assert figures.RIGID_SLIDES not in headings(tied)


def test_the_return_period_lines_say_whose_hazard_they_mark():
    """Cold read 12, default figures: the dotted return-period lines did not say they come from the example hazard,
    so a page copied out alone showed 'the site's intensities' as if real. The legend entry carries the tag."""
    from rockfrag.report.adapters import CredibleMarks

    figure, axis = plt.subplots()
    try:
        axis.set_xscale("log")
        axis.set_xlim(0.1, 3.0)
        figures.mark_intensities(axis, CredibleMarks((475, 2475), (0.3, 0.6), 0.8, tag="example hazard"))
        labels = [line.get_label() for line in axis.get_lines()]
        assert any(label.endswith("475, 2,475 years (example hazard)") for label in labels), labels
    finally:
        plt.close(figure)
