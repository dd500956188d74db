"""The registries are the only owners of their facts, and an installed package can add to them (issue 35 item 2)."""

from __future__ import annotations

import pytest

from rockfrag.config import load_study
from rockfrag.damage_states import DAMAGE_STATES, DEFAULT_LIMITS, DamageState, register_damage_state


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
