"""The shipped user study, studies/user-site.toml, loads as written: its block, its two soils, its own site hazard
(an illustrative OpenQuake-layout curve beside it, which says so) carried to each soil's site. The whole run takes
minutes and is not repeated here: `rockfrag fragility studies/user-site.toml` runs it (docs, "The default study").
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rockfrag import load_hazard, load_study
from rockfrag.cli import main
from rockfrag.site_hazard import study_site_hazards

ROOT = Path(__file__).resolve().parents[1]
STUDY = ROOT / "studies" / "user-site.toml"
HAZARD = ROOT / "studies" / "user-site-hazard.csv"


def test_the_study_checks_with_the_command(capsys):
    assert main(["study", str(STUDY)]) == 0
    assert "is valid" in capsys.readouterr().out


def test_the_study_is_one_block_of_its_own_on_two_soils_with_its_site_hazard():
    config = load_study(STUDY)
    assert [soil.name for soil in config.soils] == ["clay", "sand"]
    assert [block.name for block in config.blocks] == ["enclosure"]
    block = config.blocks[0]
    assert (block.b, block.h, block.mass) == (0.6, 1.5, 4500.0)
    assert "solid block" in config.raw["report"]["block_names"][block.name]  # the name the client reads
    assert Path(config.hazard_file).resolve() == HAZARD.resolve()  # relative to the study file, not the working folder
    assert config.reference_vs30 == 760.0 and config.record_sets == ("far-field",)


def test_the_hazard_file_says_it_is_illustrative_and_reads_as_an_openquake_export():
    header = HAZARD.read_text(encoding="utf-8").splitlines()[0]
    assert "ILLUSTRATIVE" in header and "not the result of a hazard model" in header and "vs30=760" in header
    curve = load_hazard(HAZARD)
    assert curve.measure == "pga" and curve.notes["investigation_time_years"] == 50.0
    # the return-period intensities its header states, from the curve as read (poe -> rate, log-log)
    for period, stated in ((475, 0.30), (975, 0.39), (2475, 0.54)):
        pga = np.exp(np.interp(np.log(1 / period), np.log(curve.annual_frequency[::-1]),
                               np.log(curve.intensity[::-1])))
        assert pga == pytest.approx(stated, abs=0.006), f"{period}-year PGA"


def test_each_soil_gets_its_own_site_curve_from_the_reference_rock():
    config = load_study(STUDY)
    hazards = study_site_hazards(config)
    assert list(hazards) == ["clay", "sand"] and hazards.reference_vs30 == 760.0
    reference = load_hazard(HAZARD)
    # a soft site amplifies weak rock shaking (BSSA14's site term at Vs30 150 and 260 m/s against 760): at 0.1 g
    # on rock the clay and sand sites are exceeded more often than the rock site
    for soil in ("clay", "sand"):
        site = hazards[soil]
        at = float(np.exp(np.interp(np.log(0.1), np.log(site.intensity), np.log(site.annual_frequency))))
        rock = float(np.exp(np.interp(np.log(0.1), np.log(reference.intensity), np.log(reference.annual_frequency))))
        assert at > rock, soil
