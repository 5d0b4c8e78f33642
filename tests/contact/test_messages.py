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


def _two_blocks(depth: float, **options):
    """An upper block [0,1]×[−depth, ½] (slave: its bottom, tag 1) on a lower
    block [0,1]×[−½, 0] (master: its top, tag 5), merged from two meshes with
    elements of 1/8."""
    from mpi4py import MPI
    from dolfinx_mortar import ContactProblem
    from support.meshes import rectangle
    comm = MPI.COMM_WORLD
    upper, upper_tags = rectangle(comm, -depth, 0.5, (8, 6), bottom=1, top=2, left=3)
    lower, lower_tags = rectangle(comm, -0.5, 0.0, (8, 4), bottom=4, top=5, left=6)
    kwargs = dict(E=1.0, nu=0.3, penalty=1e3, fixed={4: {0: 0.0, 1: 0.0}})
    kwargs.update(options)
    master = kwargs.pop("master_tag", 5)
    return ContactProblem.from_two_meshes(upper, upper_tags, 1, lower, lower_tags, master,
                                          **kwargs)


def test_bodies_overlapping_at_the_start_are_named():
    """The slave starts two elements deep inside the master: nothing is paired
    within the search radius, and it was reported as out of reach."""
    with pytest.raises(ValueError, match=r"slave and master overlap at the start: the slave "
                                         r"surface lies 0.25 \(2 slave element lengths\) "
                                         r"inside the master"):
        _two_blocks(0.25)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _two_blocks(0.0)                       # touching: no word


def test_a_two_mesh_master_tag_is_named_as_written():
    """merge_meshes shifts b's tags by tag_offset: a master tag 7 that marks
    nothing was named as the merged tag 17."""
    with pytest.raises(ValueError, match=r"master_tag 7 of mesh_b: facet tag 7 marks no "
                                         r"facets \(tags present: \[4, 5, 6\]\)"):
        _two_blocks(0.0, master_tag=7, tag_offset=10, fixed={14: {0: 0.0, 1: 0.0}})
    with pytest.raises(ValueError, match=r"facet tag values \[1, 2, 3\] mark facets of both "
                                         r"meshes \(mesh_b's \[4, 5, 6\] shifted by "
                                         r"tag_offset -3\)"):
        _two_blocks(0.0, tag_offset=-3)
