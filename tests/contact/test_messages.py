"""Set-ups that cannot work say why where the contact term is made, not in a
Newton failure: a master out of reach, a master facing away."""
from __future__ import annotations

import warnings

import pytest
from dolfinx import fem

from dolfinx_mortar import ContactTerm
from support.scenes import OVERHANG_GAP, overhanging_blocks

SLAVE, MASTER, UPPER_TOP = 1, 2, 4


@pytest.fixture(scope="module")
def blocks():
    V, tags = overhanging_blocks()
    return fem.Function(V), tags


@pytest.mark.parametrize("configuration", ["initial", "previous", "current"])
def test_a_master_beyond_the_search_radius_is_named(blocks, configuration):
    """The blocks are OVERHANG_GAP apart; within a fifth of that nothing is paired."""
    u, tags = blocks
    with pytest.warns(RuntimeWarning, match="no slave facet finds a master facet within the "
                                            "search radius 0.01") as record:
        ContactTerm(u, tags, SLAVE, master_tag=MASTER, kind="LmLS*", penalty=1e3,
                    search_radius=OVERHANG_GAP / 5, basis_configuration=configuration)
    never = any("it never will" in str(w.message) for w in record)
    assert never == (configuration == "initial")


def test_a_master_facing_away_is_named(blocks):
    """The upper block's top as the master: within reach, but its outward
    normal points up, as the slave's does."""
    u, tags = blocks
    with pytest.warns(RuntimeWarning, match="the master surface faces away from the slave"):
        ContactTerm(u, tags, SLAVE, master_tag=UPPER_TOP, kind="LmLS*", penalty=1e3,
                    search_radius=1.0)


def test_a_master_in_reach_is_not_warned_about(blocks):
    u, tags = blocks
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ContactTerm(u, tags, SLAVE, master_tag=MASTER, kind="LmLS*", penalty=1e3)
