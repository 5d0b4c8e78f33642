"""Which nodes stiffen while nothing penetrates yet, decided the same way on every
partition (dolfinx_mortar.contact.newton.near_contact)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from dolfinx_mortar.contact.newton import penetrates, stiffened_nodes
from dolfinx_mortar.layout import NodeLayout
from dolfinx_mortar.tolerance import length_scale, zero_length

H = 0.1


def point_contact(touching_gap: float):
    """Five covered nodes of a unit-scale surface, the middle one touching at
    ``touching_gap`` (0, or the ±1e-19 another partition's round-off gave),
    the others 0.001, 0.004 and 0.5 away."""
    gaps = np.array([-0.5, -0.004, touching_gap, -0.001, -0.5])
    x = np.column_stack([np.arange(5.0), np.zeros(5)])
    slave = SimpleNamespace(layout=NodeLayout.serial(5), x=x,
                            zero_length=zero_length(length_scale(x)))
    model = SimpleNamespace(slave=slave, node_lengths=np.full(5, H))
    return model, SimpleNamespace(gaps=gaps, gaps_plus=None, covered=np.ones(5, dtype=bool))


@pytest.mark.parametrize("touching_gap", [0.0, 1e-19, -1e-19])
def test_round_off_at_a_touching_node_decides_nothing(touching_gap):
    """The nodes within a tenth of their element of contact stiffen, whatever the
    sign of the touching node's round-off. With ``d̄ ≥ 0`` as the test, +1e-19
    stiffened that node alone (Hertz 3D on 2 ranks: no gap-closing start, 24
    Newton iterations against 16 on one)."""
    model, state = point_contact(touching_gap)
    assert not penetrates(model, state)
    assert stiffened_nodes(model, state).tolist() == [0, 1, 1, 1, 0]


def test_a_real_penetration_keeps_the_exact_active_set():
    model, state = point_contact(1e-6)
    assert penetrates(model, state)
    assert stiffened_nodes(model, state).tolist() == [0, 0, 1, 0, 0]
