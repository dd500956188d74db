"""The registration of the bed contact laws (pipeline/models/contact.py): every registered law is
reached through every compiled dispatcher by its own code, its option name selects it, and a code
that is not registered is refused instead of falling through to another law."""

from __future__ import annotations

import numpy as np
import pytest

from rockfrag.blocks import Block
from rockfrag.models import BED_TYPES, SolverOptions, contact, get_model, parameter_record

BLOCK = Block(name="registry", R=2.0, alpha=0.25, mass=5000.0)
STIFFNESS = 5000.0 * 300.0**2  # [N/m]


def _params(name):
    params, state = parameter_record(get_model("winkler"), BLOCK, STIFFNESS, 0.1, SolverOptions(bed=name))
    return params, state


def _states(y_static, count=40):
    """Random states around the settled one: in full contact, on one corner and in flight."""
    rng = np.random.default_rng(2024)
    return [np.array([rng.uniform(-0.02, 0.02), rng.normal(0.0, 0.5),
                      y_static * rng.uniform(-1.0, 3.0), rng.normal(0.0, 0.05)]) for _ in range(count)]


def test_option_names_are_the_laws_own():
    assert BED_TYPES == {law.NAME: code for code, law in contact.LAWS.items()}
    assert len(set(contact.LAWS)) == len(BED_TYPES), "two laws share a code or a name"


@pytest.mark.parametrize("code", sorted(contact.LAWS))
def test_every_dispatcher_reaches_the_laws_own_hooks(code):
    law = contact.LAWS[code]
    params, settled = _params(law.NAME)
    assert params["bed"] == code
    out_dispatched = np.empty(contact.N_CONTACT_INDICATORS)
    out_own = np.empty(contact.N_CONTACT_INDICATORS)
    for x in _states(settled[2]):
        sin_t, cos_t = np.sin(x[0]), np.cos(x[0])
        assert contact.bed_force_at(x, params, sin_t, cos_t) == law.force(x, params, sin_t, cos_t)
        assert contact.bed_full_contact(x, params, sin_t) == law.full_contact(x, params, sin_t)
        for index in range(contact.N_CONTACT_INDICATORS):
            assert contact.contact_indicator(index, x, params) == law.indicator(index, x, params)
        contact.contact_indicators(x, params, out_dispatched)
        law.indicators(x, params, out_own)
        np.testing.assert_array_equal(out_dispatched, out_own)


def test_the_laws_differ_so_a_crossed_branch_would_show():
    """The equality test above can only catch a branch that calls the wrong law if the laws differ."""
    forces = set()
    for code, law in contact.LAWS.items():
        params, settled = _params(law.NAME)
        x = np.array([0.004, 0.1, settled[2], 0.0])
        forces.add(law.force(x, params, np.sin(x[0]), np.cos(x[0])))
    assert len(forces) == len(contact.LAWS)


def test_an_unregistered_code_is_refused():
    params, settled = _params("continuous")
    params["bed"] = max(contact.LAWS) + 1
    x = settled.copy()
    with pytest.raises(ValueError, match="not registered"):
        contact.bed_force_at(x, params, 0.0, 1.0)
    with pytest.raises(ValueError, match="not registered"):
        contact.contact_indicators(x, params, np.empty(contact.N_CONTACT_INDICATORS))
