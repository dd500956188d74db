"""rockfrag.damage_states - the limit states a fragility is fitted for.

Input : the shipped registry below, plus ``[damage_states.NAME]`` tables of a study file (``edp``,
        ``threshold``, ``description``).
Output: ``DamageState`` objects in order of increasing severity, read by the study file's schema
        (rockfrag.config), the fits (rockfrag.fragility) and the report's labels.

A state is reached when its engineering demand parameter ``edp`` (a cube variable, or the outcome
``uplifted`` / ``overturned``) is at least ``threshold``; overturning exceeds every rocking threshold.

Uplift has a size: a run uplifts when a corner of the base rises at least ``UPLIFT_FRACTION`` of the block's
half-width b or at least ``UPLIFT_MIN_LIFT`` (whichever is smaller, ``uplift_lift``) above the ground, or the
block overturns or leaves the ground (free flight). A smaller lift is a tilt on the bed: the heel of a block on a
compliant bed parts from it by fractions of a millimetre long before the block rocks about its toe, and calling
that rocking would count the bed's give as the block's motion. A pivot model (Housner's rigid base, the paper's
model) has no bed to tilt on: its corner lifts only when the block pivots about the other one, at g tan(alpha), and
any lift is rocking. The fits (rockfrag.fragility.exceedance, ``tilts``) and the report's words ("tilts on the
bed", "rocks") read this one rule.

Slip states (``edp = "peak_slip"``, threshold in metres) are a family of their own beside the rocking ones:
they apply only to the cells that run with friction at the base (rockfrag.study.cell_friction; elsewhere the
fits mark them ``not-applicable``), do not nest with the rocking states, and sort after uplift and before the
rocking states (so the two most severe states stay the rocking ones and overturning).
A state may carry the verdict's limit: ``limit``, the largest acceptable probability of reaching it in the design
life, and ``limit_source``, where that number comes from. The shipped limits (``DEFAULT_LIMITS``, the defaults of
``[decision] max_probability_in_life``) and the report's "where the numbers come from" read them here, the one place.
A new shipped state is one ``register_damage_state`` call; an installed package adds one through the entry-point
group ``rockfrag.damage_states`` (rockfrag.plugins, docs/plugins.md).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field

from rockfrag.errors import ConfigError
from rockfrag.plugins import GROUPS, Registry

SLIP_EDPS = ("peak_slip",)
NOT_APPLICABLE = "not-applicable"
"""The fragility ``status`` of a slip state in a cell whose base is tied (no friction: no slip to fit)."""
"""EDPs of the slip family: the peak horizontal slip of the base [m]."""
EDPS = ("uplifted", "overturned", "peak_angle_ratio", "peak_angle", "peak_uplift", "n_impacts", *SLIP_EDPS)
"""Engineering demand parameters a damage state may use: the two outcomes, then cube variables."""


@dataclass(frozen=True)
class DamageState:
    """A limit state: ``edp`` >= ``threshold`` (overturning exceeds every rocking threshold)."""

    name: str
    edp: str  # "uplifted", "overturned", or a cube variable such as "peak_angle_ratio"
    threshold: float
    description: str
    limit: float | None = field(default=None, metadata={"study_key": False})
    """Largest acceptable probability of reaching the state in the design life (0-1]; None: reported, not judged."""
    limit_source: str = field(default="", metadata={"study_key": False})
    """Where ``limit`` comes from, in the words of the report's sources section."""


def severity_order(state: DamageState) -> tuple[float, float]:
    """Sort key of the damage states: uplift, slip states, rocking states (each by threshold), overturning."""
    order = {"uplifted": 0.0, "overturned": 2.0, **{edp: 0.5 for edp in SLIP_EDPS}}
    return order.get(state.edp, 1.0), state.threshold


DAMAGE_STATES: Registry = Registry(GROUPS["damage_states"], DamageState, order=severity_order)
"""The shipped and installed (plugin) damage states by name, in order of increasing severity."""


def register_damage_state(state: DamageState) -> None:
    """Add a damage state; the registry is kept in the order of increasing severity (``severity_order``)."""
    DAMAGE_STATES[state.name] = state


class _Limits(Mapping):
    """Damage state name -> its ``limit``, for the registered states that have one, most severe first.

    Read afresh on each use, so the states an installed package adds count.
    """

    def _limits(self) -> dict[str, float]:
        most_severe_first = reversed(list(DAMAGE_STATES.values()))
        return {state.name: state.limit for state in most_severe_first if state.limit is not None}

    def __getitem__(self, name: str) -> float:
        return self._limits()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._limits())

    def __len__(self) -> int:
        return len(self._limits())

    def __repr__(self) -> str:
        return repr(self._limits())


DEFAULT_LIMITS: Mapping[str, float] = _Limits()
"""``[decision] max_probability_in_life`` when the study gives none: each registered state's ``limit``."""

STUDY_CHOICE = "the study's choice (its study file, else the shipped defaults)"
"""How the report names a value that is a choice rather than a published fact."""


UPLIFT_FRACTION = 0.01
"""Uplift: the lift of a base corner, as a fraction of the half-width b, that counts as lift-off [-]."""
UPLIFT_MIN_LIFT = 0.001
"""Uplift: a lift of a base corner of at least this much counts as lift-off whatever the block's size [m]."""


def uplift_lift(b):
    """The smallest lift of a base corner [m] that counts as uplift for a block of half-width ``b`` [m].

    ``UPLIFT_FRACTION`` of b or ``UPLIFT_MIN_LIFT``, whichever is smaller (a small object lifts off in less than a
    millimetre); works on floats and arrays (xarray included).
    """
    scaled = UPLIFT_FRACTION * b
    return scaled.clip(max=UPLIFT_MIN_LIFT) if hasattr(scaled, "clip") else min(scaled, UPLIFT_MIN_LIFT)


UPLIFT_WORDS = (f"a base corner lifts at least {UPLIFT_MIN_LIFT * 1000:g} mm (or {UPLIFT_FRACTION:.0%} of the "
                "half-width b, if that is less) off a compliant bed, or the block pivots about an edge of a rigid "
                "base")
"""What uplift means, in the words every page uses (a smaller lift is a tilt on the bed)."""

TILT_WORDS = "tilts on the bed"
"""A run whose base corner lifts less than ``uplift_lift``: the bed gives under the toe, the block does not rock."""

register_damage_state(DamageState("uplift", "uplifted", 1.0, f"lift-off: {UPLIFT_WORDS}"))
register_damage_state(DamageState("rocking-0.2", "peak_angle_ratio", 0.2, "theta_max/alpha >= 0.2"))
register_damage_state(DamageState(
    "rocking-0.5", "peak_angle_ratio", 0.5, "theta_max/alpha >= 0.5", limit=0.10,
    limit_source="the 10% in 50 years of the conventional 475-year design level (older codes, Eurocode 8), applied "
                 "here to damage short of collapse: " + STUDY_CHOICE))
register_damage_state(DamageState(
    "overturning", "overturned", 1.0, "the block overturns", limit=0.01,
    limit_source="the 1% probability of collapse in 50 years that ASCE 7-22's risk-targeted ground motions aim at "
                 "(ASCE 7-22)"))
register_damage_state(DamageState("slip-0.05", "peak_slip", 0.05,
                                  "the base slid 0.05 m or more (cables, pipes and anchors strained)"))
register_damage_state(DamageState(
    "slip-0.30", "peak_slip", 0.30, "the base slid 0.30 m or more: a large slip, enough to leave a plinth whose "
    "edge is 0.30 m beyond the base (an assumed, typical edge distance) where the block stands on one", limit=0.10,
    limit_source="the 10% in 50 years of the conventional 475-year design level, as for θmax/α ≥ 0.5: " + STUDY_CHOICE))


def is_slip_state(state: DamageState) -> bool:
    """Whether ``state`` is of the slip family (its EDP is a slip of the base)."""
    return state.edp in SLIP_EDPS


def edp_family(edp: str) -> str:
    """The family of a state with this EDP, "slip" or "rocking".

    States of one family nest (more severe: reached later); the two families do not. The one rule every reader of
    families uses (the fits, the answer pages, the exchange files).
    """
    return "slip" if edp in SLIP_EDPS else "rocking"


def state_family(state: DamageState) -> str:
    """``edp_family`` of a state."""
    return edp_family(state.edp)


def families_of(edps) -> dict[str, list[int]]:
    """Indices of the states of each family, in the given order (of severity): {"rocking": [...], "slip": [...]}.

    Parameters
    ----------
    edps : sequence of str
        Each state's EDP (a cube's ``damage_state_edp``), in order of severity.

    Returns
    -------
    dict of str to list of int
        The families that have states, rocking first.
    """
    families: dict[str, list[int]] = {"rocking": [], "slip": []}
    for index, edp in enumerate(edps):
        families[edp_family(str(edp))].append(index)
    return {family: members for family, members in families.items() if members}


def nesting_chains(edps) -> list[list[int]]:
    """The chains of states that nest, each in order of severity: the rocking states; the slip states, overturning.

    A record that overturned counts as beyond every damage state (``rockfrag.fragility.exceedance``), slip states
    included, so overturning is the most severe member of both chains: P(slip >= x) is never below P(overturning).
    The slip and rocking states do not nest with each other. The one rule for the fits' non-crossing groups and the
    answer's "this state or worse".

    Parameters
    ----------
    edps : sequence of str
        Each state's EDP, in order of severity.

    Returns
    -------
    list of list of int
        The rocking chain first (if any), then the slip chain (if any).
    """
    families = families_of(edps)
    chains = [families["rocking"]] if "rocking" in families else []
    if "slip" in families:
        overturning = [index for index, edp in enumerate(edps) if str(edp) == "overturned"]
        chains.append(families["slip"] + overturning)
    return chains


def damage_states_from_config(raw: dict) -> list[DamageState]:
    """The shipped damage states plus (or replaced by) the study's ``[damage_states.NAME]`` tables.

    Parameters
    ----------
    raw : dict
        The study as read from its TOML files (``StudyConfig.raw``).

    Returns
    -------
    list of DamageState
        Uplift first, then the slip states, then the rocking states, each by threshold, overturning last.

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
    return sorted(states.values(), key=severity_order)

