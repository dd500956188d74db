"""pipeline.damage_states - the limit states a fragility is fitted for.

Input : the shipped registry below, plus ``[damage_states.NAME]`` tables of a study file (``edp``,
        ``threshold``, ``description``).
Output: ``DamageState`` objects in order of increasing severity, read by the study file's schema
        (pipeline.config), the fits (pipeline.fragility) and the report's labels.

A state is reached when its engineering demand parameter ``edp`` (a cube variable, or the outcome
``uplifted`` / ``overturned``) is at least ``threshold``; overturning exceeds every rocking threshold.
A new shipped state is one ``register_damage_state`` call.
"""

from __future__ import annotations

from dataclasses import dataclass

from pipeline.errors import ConfigError

EDPS = ("uplifted", "overturned", "peak_angle_ratio", "peak_angle", "peak_uplift", "n_impacts")
"""Engineering demand parameters a damage state may use: the two outcomes, then cube variables."""


@dataclass(frozen=True)
class DamageState:
    """A limit state: ``edp`` >= ``threshold`` (overturning exceeds every rocking threshold)."""

    name: str
    edp: str  # "uplifted", "overturned", or a cube variable such as "peak_angle_ratio"
    threshold: float
    description: str


DAMAGE_STATES: dict[str, DamageState] = {}
"""The shipped damage states by name, in order of increasing severity."""


def register_damage_state(state: DamageState) -> None:
    """Add a damage state; the registry order is the order of increasing severity."""
    DAMAGE_STATES[state.name] = state


register_damage_state(DamageState("uplift", "uplifted", 1.0, "rocking starts (the heel lifts off)"))
register_damage_state(DamageState("rocking-0.2", "peak_angle_ratio", 0.2, "theta_max/alpha >= 0.2"))
register_damage_state(DamageState("rocking-0.5", "peak_angle_ratio", 0.5, "theta_max/alpha >= 0.5"))
register_damage_state(DamageState("overturning", "overturned", 1.0, "the block overturns"))


def damage_states_from_config(raw: dict) -> list[DamageState]:
    """The shipped damage states plus (or replaced by) the study's ``[damage_states.NAME]`` tables.

    Parameters
    ----------
    raw : dict
        The study as read from its TOML files (``StudyConfig.raw``).

    Returns
    -------
    list of DamageState
        Uplift first, then the rocking states by threshold, overturning last.

    Raises
    ------
    ConfigError
        An unknown ``edp`` or a ``threshold`` that is not a number > 0, naming the field.
    """
    states = dict(DAMAGE_STATES)
    for name, spec in raw.get("damage_states", {}).items():
        edp = spec.get("edp", "peak_angle_ratio")
        if edp not in EDPS:
            raise ConfigError(f"damage_states.{name}.edp", f"{edp!r}; allowed: {', '.join(EDPS)}")
        threshold = spec.get("threshold", 1.0)
        if not isinstance(threshold, (int, float)) or threshold <= 0:
            raise ConfigError(f"damage_states.{name}.threshold", f"{threshold!r}; allowed > 0")
        states[name] = DamageState(name, edp, float(threshold), spec.get("description", ""))
    order = {"uplifted": 0, "overturned": 2}
    return sorted(states.values(), key=lambda s: (order.get(s.edp, 1), s.threshold))
