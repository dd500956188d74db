"""Findings of a cold reader of the default study's report (the engineer who would sign it), one test each where
a test can catch the defect again: on the small study's results (fixture ``small_pipeline``) or on hand-made
inputs. Expected values come from the result files or the study, never from the page under test."""

from __future__ import annotations

import html as html_module
import re

import numpy as np

from rockfrag.report.adapters import block_name
from tests.helpers import pipeline_results


def _visible_text(html: str) -> str:
    text = re.sub(r"<img[^>]*>", " ", html)
    text = re.sub(r"<style>.*?</style>", " ", text, flags=re.S)
    return re.sub(r"\s+", " ", html_module.unescape(re.sub(r"<[^>]+>", " ", text)))


def _section(text: str, start: str, end: str) -> str:
    """The text from the heading ``start`` to the next heading ``end``."""
    begin = text.index(start)
    return text[begin:text.index(end, begin + len(start))]


def test_sliding_limitation_says_which_runs_slide(small_pipeline):
    """Finding 3: "every model assumes the base does not slide, which was not checked" was printed although the
    study's friction runs slide (the rigid base where the soil's mu_s < b/h). The limitations' 'Sliding' section
    names, per model, the blocks and soils whose runs include base friction (cube.nc friction_static finite)."""
    results = pipeline_results(small_pipeline.output, small_pipeline.study)
    cube, config = results.cube, results.config
    text = _visible_text((small_pipeline.output / "report.html").read_text())
    sliding = _section(text, "Sliding Each soil", "Extrapolated fragility medians")
    assert "assumes the base does not slide" not in sliding
    slides = np.isfinite(cube.friction_static)
    assert bool(slides.any()) and not bool(slides.all())  # the fixture has both: the test can fail either way
    for model in map(str, cube.model.values):
        on = slides.sel(model=model)
        label = {"housner": "Housner (rigid base)", "ssi": "SSI, paper's model (spring can pull)"}[model]
        assert label in sliding
        sentence = sliding[sliding.index(label):].split(". ")[0]
        if not bool(on.any()):
            assert "the base is tied (no sliding computed) for every block on every soil" in sentence
            continue
        assert "runs with base friction" in sentence
        for block in map(str, cube.block.values):
            soils = [str(s) for s in cube.soil.values if bool(on.sel(block=block, soil=s))]
            name = block_name(config, block)
            if not soils:
                assert f"the {name} on" not in sentence
            elif len(soils) == cube.sizes["soil"]:
                assert f"the {name} on every soil" in sentence
            else:
                assert f"the {name} on {', '.join(soils)}" in sentence
