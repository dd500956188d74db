"""Words a client reads and credible intensities (issue 20, items 2 and 3): one test per defect the issue
lists, each able to catch it again, on the small study's results (fixture ``small_pipeline``) or on hand-made
datasets. Independent values come from the result files, closed forms or the datasets, never from the page."""

from __future__ import annotations

import html as html_module
import re
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

from rockfrag.report.words import CODE_IDENTIFIERS
from tests.helpers import pipeline_results

K0, K = 1e-4, 2.5  # the shipped example hazard: lambda(s) = K0 s^-K


def _visible_text(html: str) -> str:
    text = re.sub(r"<img[^>]*>", " ", html)
    text = re.sub(r"<style>.*?</style>", " ", text, flags=re.S)
    return html_module.unescape(re.sub(r"<[^>]+>", " ", text))


def _snake_case(text: str) -> list[str]:
    """snake_case words that are not file names (cube.nc, fragility.csv, ...) nor study-file settings written as
    the TOML a user types ("[soils_custom.NAME]", "friction_static = μ_s": how to set the block's friction)."""
    return [w for w in re.findall(r"(?<!\[)\b[a-z]{2,}_[a-z0-9_]+\b(?!\.(?:nc|csv|png|pdf|html|toml))(?! = )", text)]


def _figure_text(figure) -> str:
    texts = [t.get_text() for t in figure.findobj(plt.Text)]
    return " ".join(texts)


# ---------------------------------------------------------------- the whole report, as HTML text

def test_no_code_identifier_reaches_the_html(small_pipeline):
    """Except in the closing appendix, which names the keys of the study file (issue 36: 'How to reproduce')."""
    html = (small_pipeline.output / "report.html").read_text()
    text = _visible_text(html[:html.index("id='section-how-to-reproduce-this-report'")])
    assert [word for word in CODE_IDENTIFIERS if word in text] == []
    assert _snake_case(text) == []
    assert "pivot switch rule" not in text and "[ssi]" not in text


def test_blocks_are_named_as_the_client_knows_them(small_pipeline):
    """The paper's block is not called "paper" (defaults.toml [report] block_names), nor a crane portal (issue 36:
    honest names)."""
    text = _visible_text((small_pipeline.output / "report.html").read_text())
    paper = "solid block with the paper's proportions (R = 9.39 m, α = 0.44)"
    assert paper in text and "slender solid block, cabinet-sized" in text
    assert "block 'paper'" not in text and "block paper" not in text and "crane portal" not in text
    assert f"Answer: {paper}" in text


def test_references_and_glossary_pages_cite_the_sources(small_pipeline):
    text = _visible_text((small_pipeline.output / "report.html").read_text())
    seed = "A Simplified Mechanical Model for Rocking Structures on Compliant Foundations"
    for work in (seed, "Housner, G. W. (1963)", "FEMA P695", "FEMA P-58", "ElGawady", "Baker, J. W. (2015)"):
        assert work in text, work
    glossary = text[text.index("Glossary"):]
    for term in ("θmax/α", "β (dispersion)", "IDA", "restitution", "tensionless Winkler bed"):
        assert term in glossary, term


def test_every_figure_has_a_caption_that_says_what_to_read(small_pipeline):
    from rockfrag.report import plan

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    figures = [page for page in plan(results) if page.html is None and page.name != "title"]
    assert "efficiency" in [page.name for page in figures]
    assert [page.name for page in figures if not page.caption.startswith("Read ")] == []


# ---------------------------------------------------------------- the contradictions the issue lists

def test_no_orphan_footnote_mark(small_pipeline, tmp_path):
    """A footnote is printed only when a row carries its mark, and every mark has its footnote."""
    from rockfrag.report.sections import fitted_items as summary_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)

    def marks_and_notes(items):
        cells = " ".join(c for item in items if item.kind == "table" for row in item.rows for c in row)
        notes = [item.text for item in items if item.kind == "note"]
        return {m for m in "*†" if m in cells}, {m for m in "*†" if any(n.startswith(m) for n in notes)}

    marks, notes = marks_and_notes(summary_items(results))
    assert marks == notes
    fragility = results.fragility.copy()
    middle = float(np.median(results.fragility.intensity.values))
    fragility["median"] = fragility["median"].where(False, middle)  # every median inside the studied range
    inside = pipeline_results(small_pipeline.output, small_pipeline.study, fragility=fragility, output=tmp_path)
    inside.largest_recorded.update({b: np.inf for b in inside.largest_recorded})
    assert marks_and_notes(summary_items(inside)) == (set(), set())


def test_curves_without_a_median_carry_the_counts_that_justify_it(small_pipeline):
    from rockfrag.report.sections import limitations_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    items = limitations_items(results)
    text = " ".join(item.text for item in items)
    assert "too few exceedances" not in text
    fragility = results.fragility
    unfitted = fragility["median"].isnull() & (fragility.status != "not-reached") | (fragility.status == "not-reached")
    tables = [item for item in items if item.kind == "table" and "why no median" in item.header]
    if not bool(unfitted.any()):
        assert tables == []
        return
    n = int(fragility.n_records)
    for row in tables[0].rows:
        if row[0] and not any(row[1:]):  # a block's heading row
            continue
        counts, why = row[3], row[4]
        if why == "no record reached it":  # a summary row: every model and soil it names
            assert counts == f"0 of {n} at every level"
            continue
        assert re.fullmatch(rf"\d+ of {n} at [\d.]+ g, \d+ of {n} at [\d.]+ g", counts), counts
        low = int(counts.split(" of ")[0])
        if why == "reached below the lowest level":
            assert low > n / 2  # most records reached it at the lowest level


def test_limitations_tables_are_one_table_each_with_the_reason_and_one_row_per_state_no_record_reached(
        small_pipeline, tmp_path):
    """Issue 20, finding 8: the extrapolated and no-median tables were split in two by width, and a state no record
    reached took one row per model and soil."""
    from rockfrag.report.adapters import block_name
    from rockfrag.report.sections import limitations_items
    from rockfrag.report.text import fit_table
    from rockfrag.report.words import state_short_label

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    fragility = results.fragility.copy(deep=True)
    block, state = str(fragility.block.values[0]), str(fragility.damage_state.values[-1])
    label = state_short_label(state, str(fragility.damage_state_description.sel(damage_state=state).values))
    never = (fragility.block == block) & (fragility.damage_state == state)
    fragility["median"] = fragility["median"].where(~never)
    fragility["status"] = fragility["status"].where(~never, "not-reached")
    fragility["empirical_fraction"] = fragility["empirical_fraction"].where(~never, 0.0)
    # one median above the range, so the extrapolated table is drawn too
    other = str(fragility.damage_state.values[0])
    high = float(fragility.intensity.max()) * 10
    fragility["median"] = fragility["median"].where(~((fragility.block == block) & (fragility.damage_state == other)),
                                                    high)
    changed = pipeline_results(small_pipeline.output, small_pipeline.study, fragility=fragility, output=tmp_path)
    items = limitations_items(changed)
    tables = {item.header[-1]: item for item in items if item.kind == "table" and item.header[0] == "model"}
    assert set(tables) == {"median lies", "why no median"}
    for item in tables.values():
        assert len(fit_table(item)) == 1, item.header  # one table, never split into halves
    data = {key: [row for row in item.rows if not (row[0] and not any(row[1:]))] for key, item in tables.items()}
    assert {row[-1] for row in data["median lies"]} == {"above the highest level"}
    name = block_name(changed.config, block)
    rows, under = [], None  # the rows under the block's heading row (issue 36: a long block name read once)
    for row in tables["why no median"].rows:
        if row[0] and not any(row[1:]):
            under = row[0]
        elif under == name and row[2] == label:
            rows.append(row)
    assert len(rows) == 1, rows
    assert rows[0][:2] == ["every model", "every soil"] and rows[0][-1] == "no record reached it"


def test_settlement_axis_says_up_positive_and_draws_the_file_sign(small_pipeline):
    from rockfrag.report import figures

    showcase = pipeline_results(small_pipeline.output, small_pipeline.study).showcase
    # y - y_static: the models write y positive down (rockfrag.models.base: a settlement), the page draws it up +
    assert "y - y_static" in showcase.settlement.attrs["long_name"]
    figure = figures.showcase_response_page(showcase, "")
    try:
        settle = [a for a in figure.axes if a.get_ylabel().startswith("Δy")]
        assert settle and "up +" in settle[0].get_title() + settle[0].get_ylabel()
        assert "down +" not in _figure_text(figure)
        drawn = np.concatenate([line.get_ydata() for axis in settle for line in axis.lines])
        recorded = showcase.settlement.values[showcase.case_soil.values != ""] * 1000
        assert np.nanmin(drawn) == pytest.approx(-np.nanmax(recorded))
        assert np.nanmax(drawn) == pytest.approx(-np.nanmin(recorded))
    finally:
        plt.close(figure)


def test_contents_and_station_names_are_not_cut(small_pipeline):
    from rockfrag.report import build_plan, records_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    planned = build_plan(results)
    contents = next(page for page in planned if page.name == "contents")
    figure = contents.draw()
    try:
        assert "…" not in _figure_text(figure)
        drawn = re.sub(r"\s+", " ", _figure_text(figure))
        for page in planned:  # every heading and section whole (wrapped lines joined), once, without "(2/3)"
            for title in (page.heading or page.title, page.section):
                assert all(word in drawn for word in title.split()), title
        assert "(2/" not in drawn
    finally:
        plt.close(figure)
    cells = [c for item in records_items(results) for row in item.rows for c in row]
    assert set(map(str, results.cube.record_station.values)) <= set(cells)
    assert set(map(str, results.cube.record_event.values)) <= set(cells)


def test_a_panel_with_points_but_no_curve_says_why():
    """The uplift panel had dots and no curve: a state without a median is named in the page's notes, under the
    legend (issue 36: no note box over the data)."""
    from rockfrag.report import figures
    from rockfrag.report.adapters import model_info

    levels = np.array([0.2, 0.4, 0.8])
    dims = ("soil", "block", "model", "damage_state")
    coords = {"soil": ["clay"], "block": ["b"], "model": ["winkler"], "damage_state": ["uplift", "overturning"],
              "im_level": [0, 1, 2], "intensity": (("block", "im_level"), levels[None, :])}
    fragility = xr.Dataset({
        "median": (dims, [[[[np.nan, 0.5]]]]), "beta": (dims, [[[[np.nan, 0.3]]]]),
        "median_low": (dims, [[[[np.nan, 0.4]]]]), "median_high": (dims, [[[[np.nan, 0.6]]]]),
        "status": (dims, [[[["below-range", "fitted"]]]]),
        "empirical_fraction": (("im_level", *dims), np.array([[1.0, 0.1], [1.0, 0.4], [1.0, 0.9]])[:, None, None,
                                                                                                     None, :]),
    }, coords=coords)
    figure = figures.fragility_by_soil_page(fragility, "b", model_info("winkler"), "")
    try:
        uplift, overturning = [a for a in figure.axes if a.get_visible()][:2]
        notes = [t.get_text() for t in figure.texts if t.get_text().startswith("No curve")]
        words = " ".join(notes[0].split())
        assert len(notes) == 1 and "reached by most records at the lowest level: Winkler" in words
        assert not uplift.texts and not overturning.texts  # nothing over the data
    finally:
        plt.close(figure)


def test_p_values_are_not_shown_beyond_what_they_support():
    from rockfrag.report import figures

    dims = ("soil", "block", "model", "measure")
    shape = (1, 1, 1, 3)
    dataset = xr.Dataset({"dispersion": (dims, np.full(shape, 0.4)),
                          "p_magnitude": (dims, np.array([1e-18, 0.3, 0.02]).reshape(shape)),
                          "p_distance": (dims, np.full(shape, 0.5)), "p_pulse_period": (dims, np.full(shape, 0.5))},
                         coords={"soil": ["clay"], "block": ["b"], "model": ["winkler"],
                                 "measure": ["pga", "avgsa", "pga_ratio"]})
    figure = figures.efficiency_page(dataset, "Read it.")
    try:
        text = _figure_text(figure)
        assert "avgsa" not in text and "pga_ratio" not in text and "AvgSa" in text
        bottom = [a for a in figure.axes if "Sufficiency" in a.get_title()][0]
        points = np.concatenate([c.get_offsets()[:, 1] for c in bottom.collections])
        assert points.min() >= figures.P_FLOOR and bottom.get_ylim()[0] >= 0.5 * figures.P_FLOOR
        assert "1e-18" not in text
    finally:
        plt.close(figure)


def test_a_steel_base_is_not_counted_as_a_soil():
    from rockfrag.report.sections import grounds

    cube = xr.Dataset(coords={"soil": ["clay", "rock", "steel"],
                              "soil_shear_modulus": ("soil", [3.7e7, 1e9, 8e10])})
    assert grounds(cube) == "2 soils (clay, rock) and a structural base at ground level (steel; not a soil)"


# ---------------------------------------------------------------- credible intensities

def test_intensity_axes_are_log_and_mark_the_hazard_and_the_extrapolation(small_pipeline):
    from rockfrag.report import figures
    from rockfrag.report.adapters import models_of

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    block = str(results.cube.block.values[1])
    marks = results.marks(block)
    assert marks.return_periods == (475.0, 975.0, 2475.0)
    np.testing.assert_allclose(marks.intensities, [(K0 * t) ** (1 / K) for t in marks.return_periods], rtol=1e-3)
    # a PGA study: the largest PGA the records are scaled by (their pair's RotD50)
    assert marks.largest == pytest.approx(float(results.cube.record_im.max()))
    model = next(m for m in models_of(results.fragility) if not m.rigid_base)
    pages = [figures.ida_page(results.ida, block, "", marks=marks),
             figures.fragility_by_soil_page(results.fragility, block, model, "", marks=marks),
             figures.outcomes_page(results.fragility, block, "", marks=marks)]
    try:
        for index, figure in enumerate(pages):
            axes = [a for a in figure.axes if a.get_visible() and a.lines
                    and not getattr(a, "rockfrag_empty", False)]  # an empty panel says why, without marks
            for axis in axes:
                along = "y" if index == 0 else "x"
                assert (axis.get_yscale() if along == "y" else axis.get_xscale()) == "log"
                data = [line.get_ydata() if along == "y" else line.get_xdata() for line in axis.lines]
                constant = {round(float(d[0]), 6) for d in data if len(d) == 2 and d[0] == d[1]}
                soil = getattr(axis, "rockfrag_soil", None)  # a panel of one soil marks its own site intensities
                site = marks.for_soil(soil).intensities if soil is not None or not marks.by_soil else \
                    [im for _, values in marks.by_soil for im in values]
                for value in (*site, marks.largest):
                    low, high = axis.get_ylim() if along == "y" else axis.get_xlim()
                    if low <= value <= high:
                        assert round(value, 6) in constant, (figure.texts[0].get_text(), value)
                assert "extrapolation by scaling" in " ".join(axis.get_legend_handles_labels()[1])
            assert "2,475" in _figure_text(figure)  # above the panels, or in the IDA's legend
    finally:
        for figure in pages:
            plt.close(figure)


def test_the_methods_page_states_the_scale_factors(small_pipeline):
    from rockfrag.report.sections import methods_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    with xr.open_dataset(small_pipeline.output / "cube.nc") as cube:
        factors = cube.scale_factor.values
    text = " ".join(item.text for item in methods_items(results))
    assert f"median {np.nanmedian(factors):.2g}, largest {np.nanmax(factors):.3g}" in text


def test_the_kinetic_friction_ratio_is_read_from_the_soils_not_written_twice():
    """Issue 20: the sources said "Kinetic friction 0.8 × static" while the shipped soils are 0.85 × (steel 0.8 ×)."""
    import rockfrag.soils
    from rockfrag.report.sections import _kinetic_words
    from rockfrag.soils import SOILS

    words = _kinetic_words(list(SOILS.values()))
    ratio = rockfrag.soils.KINETIC_OVER_STATIC
    usual = [s.name for s in SOILS.values() if round(ratio * s.friction_static, 2) == s.friction_kinetic]
    assert usual and f"{ratio:g} × static (rounded to 0.01" in words and f") on {', '.join(usual)}" in words
    # cold read 8: rock's 0.7 x 0.85 = 0.595 printed 0.59 read as a rounding slip; the text says what was taken
    assert SOILS["rock"].friction_static == 0.7 and "rock's 0.595 taken as 0.59" in words
    assert "sand's" not in words  # 0.3825: no half to say
    for soil in SOILS.values():
        if soil.name not in usual:
            assert f"on {soil.name} {soil.friction_kinetic / soil.friction_static:.2g} × static" in words


def test_the_glossary_explains_flight_and_the_pulse_measures():
    from rockfrag.report.words import GLOSSARY

    terms = " ".join(term for term, _ in GLOSSARY)
    for word in ("flies", "free flight", "pulse period", "pulse acceleration"):
        assert word in terms, word


def test_the_glossary_has_every_word_of_the_motion_tables_and_every_mark():
    """Cold read 7: the motion tables' 'slides and rocks', 'at rest' and the marks §, ‡ were not in the glossary."""
    from rockfrag.report.words import GLOSSARY

    terms = " ".join(term for term, _ in GLOSSARY)
    for word in ("at rest", "tilts on the bed", "slides", "slides and rocks", "rocks", "flies", "overturns"):
        assert word in terms, word
    for mark in ("*", "†", "‡", "§", "≥"):
        assert mark in terms, mark


def test_slip_states_carry_their_unit_in_table_headers():
    """Issue 20: the answer tables headed the slip states "slip 0.05" and "slip 0.30", with no unit."""
    from rockfrag.damage_states import DAMAGE_STATES, is_slip_state
    from rockfrag.report.words import state_short_label

    slips = [state for state in DAMAGE_STATES.values() if is_slip_state(state)]
    assert slips
    for state in slips:
        label = state_short_label(state.name, state.description)
        assert label.endswith(" m") and f"{state.threshold:.2f}" in label, label
    assert state_short_label("rocking-0.5", "theta_max/alpha >= 0.5") == "θmax/α ≥ 0.5"


def test_the_records_table_says_station_names_are_the_sources_own(small_pipeline):
    """A client read 'Beverly Hills - Mulhol' as cut by the report: it is the catalogue's own abbreviation (the
    manifest's, shown whole), and the table says so."""
    import csv

    from rockfrag.report import STATION_NAMES, records_items
    from tests.helpers import pipeline_results

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    items = records_items(results)
    assert items[-1].text == STATION_NAMES
    manifest = Path(__file__).resolve().parents[1] / "records" / "MANIFEST.csv"
    with manifest.open(encoding="utf-8") as handle:
        stations = {row["id"]: row["station"] for row in csv.DictReader(handle)}
    for record, station in zip(results.cube.record.values, results.cube.record_station.values):
        assert str(station) == stations[str(record)]


def test_the_other_direction_of_a_deep_block_is_checked_not_handed_to_the_client():
    """Cold read 7, user C13: 'Check the other direction as a block of its own b' for a block the report could check
    itself (the enclosure across its 1.5 m depth: b/h 0.50, stockier than the 0.40 studied)."""
    import xarray as xr

    from rockfrag.config import load_study
    from rockfrag.report.sections import _other_direction_words

    config = load_study()
    cube = xr.Dataset(coords={"block": [b.name for b in config.blocks]})
    words = _other_direction_words(config, cube)
    cabinet = next(b for b in config.blocks if b.name == "slender-cabinet")
    depth = cabinet.footprint_area / (2 * cabinet.b)  # 0.8 m: b/h (0.4 / 1.5) = 0.27 against 0.20 across its width
    assert f"b/h {depth / 2 / cabinet.h:.2g} across its {depth:.3g} m depth, stockier than the 0.2 studied" in words
    assert "b/h 0.75 across its 3 m depth, the same as the 0.75 studied" in words  # the square skid
    assert "paper" not in words and "R = 9.39" not in words  # a strip per metre of length has no other direction


def test_the_methods_give_the_sliding_first_levels_start_in_numbers():
    """Cold read 8, user B1: 'start at the same multiple of its sliding onset' beside '0.44 to 7.54 times' read as
    a contradiction; the sentence now gives the start per block (0.5 × 0.35 g, about 0.44 times its uplift)."""
    from rockfrag.config import load_study
    from rockfrag.report.sections import _sliding_first_levels

    words = _sliding_first_levels(load_study("studies/user-site.toml"))
    assert "0.5 × 0.35 g, about 0.44 times its uplift intensity" in words, words


def test_the_dagger_note_gives_one_largest_intensity_once_when_every_block_shares_it(small_pipeline):
    """Cold read 8's default fitted table: "(solid block ... 0.78 g, slender ... 0.78 g, squat ... 0.78 g)": one
    record set, one value, said three times. Said once ("0.78 g, every block"); per block only where they differ."""
    from rockfrag.report.sections import fitted_items

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    blocks = list(map(str, results.cube.block.values))
    assert len(blocks) > 1
    results.largest_recorded = dict.fromkeys(blocks, 0.01)  # below every median: every cell gets its dagger
    dagger = next(item.text for item in fitted_items(results) if item.text.startswith("† "))
    assert "(0.01 g, every block)" in dagger, dagger
    results.largest_recorded = {block: 0.01 * (index + 1) for index, block in enumerate(blocks)}
    dagger = next(item.text for item in fitted_items(results) if item.text.startswith("† "))
    assert "every block" not in dagger and "0.02 g" in dagger, dagger


def test_survivals_above_a_first_overturning_level_are_sized_on_the_recommended_curves():
    """Cold read 9 (default B8): "131 times here a record survived a level above its first overturning level" did
    not say how many fall on the verdicts' curves nor what they are worth. Synthetic records overturn from a level
    on; some survive the level above. Counted as survivals the median can only rise (fewer exceedances at every
    level), and a cell without survivals is not refitted; the sentence gives the count and the rise."""
    from types import SimpleNamespace

    import numpy as np
    import xarray as xr

    from rockfrag.cube import OUTCOME_NO_UPLIFT, OUTCOME_OVERTURNED, OUTCOME_ROCKING
    from rockfrag.report.sections import _survivals, survival_shifts

    rng = np.random.default_rng(7)
    levels = np.geomspace(0.2, 3.0, 10)
    capacity = np.exp(rng.normal(np.log(0.8), 0.4, 60))
    first = (levels[None, :] >= capacity[:, None])
    outcome = np.where(first, OUTCOME_OVERTURNED, OUTCOME_ROCKING).astype(float)
    survivors = np.flatnonzero(first.any(1))[:9]
    for record in survivors:  # the level above the first overturning one: survived
        level = int(np.argmax(first[record]))
        if level + 1 < levels.size:
            outcome[record, level + 1] = OUTCOME_ROCKING
    outcome[:, 0] = np.where(first[:, 0], OUTCOME_OVERTURNED, OUTCOME_NO_UPLIFT)
    soils, models = ["clay", "sand"], ["housner", "recommended"]
    cube_outcome = np.broadcast_to(outcome[:, :, None, None, None], (60, 10, 2, 1, 2)).copy()
    cube_outcome[:, :, 1, :, :] = np.where(first, OUTCOME_OVERTURNED, OUTCOME_ROCKING)[:, :, None, None]  # sand: none
    cube = xr.Dataset({"outcome": (("record", "im_level", "soil", "block", "model"), cube_outcome),
                       "intensity": (("block", "im_level"), levels[None])},
                      coords={"soil": soils, "block": ["box"], "model": models})
    resurrected = np.array([[[len(survivors), len(survivors)]], [[0, 0]]])  # (soil, block, model)
    fragility = xr.Dataset({"n_resurrected": (("soil", "block", "model"), resurrected)},
                           coords={"soil": soils, "block": ["box"], "model": models})
    results = SimpleNamespace(cube=cube, fragility=fragility, config=SimpleNamespace(raw={}, blocks=()))
    answering, changes = survival_shifts(results)
    assert answering == len(survivors) and set(changes) == {("box", "clay")}, changes
    assert 0 < changes[("box", "clay")] < 0.5
    text = _survivals(results, 2 * len(survivors))
    assert text.startswith(f"{2 * len(survivors)} times here a record survived") and \
        f"; {len(survivors)} of them on the recommended curves: counted as survivals instead" in text, text
    assert "(box)" in text


def test_one_meaning_of_the_star_and_the_dash_between_the_reading_guide_and_the_glossary(small_pipeline):
    """Cold read 9 (default B7): the glossary gave '*' to a probability read below the lowest level, the reading guide
    spoke only of '-' there. '*' marks the fitted curve carried outside the levels (a median, or a probability read
    below them); '-' is the records' table's cell there; both pages say so."""
    from rockfrag.report.answer_page import BELOW_LEVELS_MARK, reading_items
    from rockfrag.report.summary import GOVERNING_WORDS
    from rockfrag.report.words import GLOSSARY

    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    guide = " ".join(item.text for item in reading_items(results))
    assert f"extrapolated below the levels run, and carries '{BELOW_LEVELS_MARK}'" in guide
    marks = next(text for key, text in GLOSSARY if key.startswith("marks"))
    assert "* the fitted curve carried outside the intensities run" in marks and "shows '-'" in marks
    # cold read 9 (default B6): the ranking of two states under the print floor was invisible
    assert "nearest its limit as a share of it, a value under the print floor at its own value" in GOVERNING_WORDS
