"""An argument bad on one rank only raises the same error on every rank.

Before, the rank with the bad argument raised while the others went on into
the next collective and waited for ever (a NaN penalty on rank 1 hung a
2-rank run). On 2 ranks the bad argument is given on rank 1 only; on one
rank these are plain argument checks.
"""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem
from mpi4py import MPI

from dolfinx_mortar import ContactProblem, ContactTerm, NonlinearContactProblem, RigidPlane
from dolfinx_mortar.input_checks import collective_checks
from support.scenes import block_on_plane

COMM = MPI.COMM_WORLD
PLANE = RigidPlane([0, 0], [0, 1])


def on_last_rank(good, bad):
    """``bad`` on the last rank, ``good`` on the others."""
    return bad if COMM.rank == COMM.size - 1 else good


@pytest.fixture(scope="module")
def space():
    return block_on_plane(n=(4, 2))


def term(space, **overrides):
    V, tags = space
    options = dict(obstacle=PLANE, kind="LcLS*", penalty=1e3)
    options.update(overrides)
    return ContactTerm(fem.Function(V), tags, 1, **options)


@pytest.mark.parametrize("argument, good, bad, error, message", [
    ("penalty", 1e3, np.nan, ValueError, "the penalty must be positive and finite, got nan"),
    ("kind", "LcLS*", "LcLS**", ValueError, r"unknown mortar basis kind 'LcLS\*\*'"),
    ("basis_configuration", "initial", "intial", ValueError,
     "unknown basis configuration 'intial'"),
    ("search_radius", None, -1.0, ValueError, "search radius must be positive"),
    ("friction", None, 0.3, TypeError, "friction must be a friction law"),
    ("obstacle", PLANE, RigidPlane([0, 0, 0], [0, 0, 1]), ValueError,
     "a 3D obstacle in a 2D mesh"),
])
def test_a_contact_term_argument_bad_on_one_rank_raises_on_all(space, argument, good, bad,
                                                                error, message):
    with pytest.raises(error, match=message):
        term(space, **{argument: on_last_rank(good, bad)})


def test_a_slave_tag_marking_nothing_on_one_rank_raises_on_all(space):
    V, tags = space
    with pytest.raises(ValueError, match=r"facet tag 9 marks no facets \(tags present"):
        ContactTerm(fem.Function(V), tags, on_last_rank(1, 9), obstacle=PLANE, penalty=1e3)


@pytest.mark.parametrize("overrides, message", [
    (dict(E=np.nan), "need a finite E > 0"),
    (dict(tractions={2: [0.0, np.inf]}), "traction on tag 2 is"),
    (dict(fixed={3: {5: 0.0}}), "component 5 does not exist in 2D"),
])
def test_a_contact_problem_argument_bad_on_one_rank_raises_on_all(space, overrides, message):
    V, tags = space
    options = dict(obstacle=PLANE, E=1.0, nu=0.3, penalty=1e3, fixed={3: {0: 0.0}},
                   tractions={2: [0.0, -0.01]})
    options.update({key: on_last_rank(options.get(key), value)
                    for key, value in overrides.items()})
    with pytest.raises(ValueError, match=message):
        ContactProblem(V, tags, 1, **options)


def test_a_term_on_another_u_on_one_rank_raises_on_all(space):
    contact = term(space)
    u = on_last_rank(contact.u, fem.Function(contact.u.function_space))
    with pytest.raises(ValueError, match="every contact term must be built on the problem's u"):
        NonlinearContactProblem(ufl_residual(contact.u), u, contact)


def ufl_residual(u):
    import ufl
    v = ufl.TestFunction(u.function_space)
    return ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx


def test_the_first_failing_rank_is_the_one_every_rank_reports():
    """Every rank fails with its own message: all raise the lowest rank's, with
    its exception type."""
    with pytest.raises(TypeError, match="rank 0"):
        with collective_checks(COMM):
            if COMM.rank == 0:
                raise TypeError("rank 0")
            raise KeyError(f"rank {COMM.rank}")


def test_checks_that_pass_everywhere_do_not_raise():
    with collective_checks(COMM):
        value = 1
    assert value == 1
