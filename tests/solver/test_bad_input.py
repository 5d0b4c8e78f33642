"""Bad input to the contact problem gets an exception (or a warning) that names it."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.kinds import kind_name, parse_kind
from dolfinx_mortar.contact.obstacles import RigidPlane
from dolfinx_mortar import (ContactProblem, ContactTerm, LoadPathSolver,
                            NonlinearContactProblem)
from dolfinx_mortar import ContactDivergenceError
from support.meshes import rectangle

PLANE = RigidPlane([0, 0], [0, 1])


def block(n=(8, 4)):
    """[0,1]x[0,0.5]; tags: 1 bottom (slave), 2 top (load), 3 left."""
    domain, tags = rectangle(MPI.COMM_WORLD, 0.0, 0.5, n, bottom=1, top=2, left=3)
    return fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,))), tags


def problem(V, tags, **overrides):
    options = dict(obstacle=PLANE, E=1.0, nu=0.3, kind="LcLS*", penalty=1e3,
                   fixed={3: {0: 0.0}}, tractions={2: [0.0, -0.01]})
    options.update(overrides)
    return ContactProblem(V, tags, 1, **options)


@pytest.mark.parametrize("E", [np.inf, np.nan, -1.0])
def test_bad_young_modulus(E):
    V, tags = block()
    with pytest.raises(ValueError, match="finite E > 0"):
        problem(V, tags, E=E)


def test_nan_traction_names_the_tag():
    V, tags = block()
    with pytest.raises(ValueError, match="traction on tag 2 .*finite"):
        problem(V, tags, tractions={2: [0.0, np.nan]})


def test_nan_prescribed_value_names_the_tag_and_component():
    V, tags = block()
    with pytest.raises(ValueError, match=r"fixed\[3\]\[0\] = nan"):
        problem(V, tags, fixed={3: {0: np.nan}})
    with pytest.raises(ValueError, match="component 2 does not exist in 2D"):
        problem(V, tags, fixed={3: {2: 0.0}})


def test_non_integer_tags_are_reported():
    V, tags = block()
    with pytest.raises(TypeError, match="tags must be integers.*1.5"):
        problem(V, tags, tractions={1.5: [0.0, -0.01]})


def test_kind_names_are_exact():
    """A name in another case is refused, naming the valid kinds: "LcLs" was
    taken for LcLS though it is as near to LcLS*."""
    assert parse_kind("dual") == parse_kind("LcLS*")
    assert parse_kind("standard") == parse_kind("LmLS*")
    assert parse_kind("weighted") == parse_kind("LmLS")
    for name in ("GLS", "GLS*", "LmLS", "LmLS*", "LcLS*", "LcLS"):
        assert kind_name(parse_kind(name)) == name
    with pytest.raises(ValueError, match=r"'LcLs' \(did you mean 'LcLS\*' or 'LcLS'\? "
                                         r"case matters\); valid kinds are 'GLS', 'GLS\*'.*"
                                         r"'dual' \(LcLS\*\)"):
        parse_kind("LcLs")
    for near_miss in ("gls", "Dual", "lcls*", "LMLS", "GLS* "):
        with pytest.raises(ValueError, match="did you mean"):
            parse_kind(near_miss)
    with pytest.raises(ValueError, match="unknown mortar basis kind 'mortar'; valid"):
        parse_kind("mortar")
    V, tags = block()
    with pytest.raises(ValueError, match=r"did you mean 'GLS' or 'GLS\*'"):
        problem(V, tags, kind="gls")


def test_nearly_incompressible_linear_elements_warn_of_locking():
    V, tags = block()
    with pytest.warns(RuntimeWarning, match="locks"):
        problem(V, tags, nu=0.4999)


def test_deep_initial_penetration_is_warned_about():
    V, tags = block()
    with pytest.warns(RuntimeWarning, match=r"initial configuration penetrates by 0.2 "):
        problem(V, tags, obstacle=RigidPlane([0, 0.2], [0, 1]))


def test_misspelled_petsc_option_is_reported():
    V, tags = block()
    p = problem(V, tags)
    options = PETSc.Options()
    options["typo_snes_rtoll"] = 1e-3
    try:
        with pytest.raises(ValueError, match="-typo_snes_rtoll were set but not used"):
            p.solve(prefix="typo_")
    finally:
        options.delValue("typo_snes_rtoll")


def test_tangled_cells_are_reported():
    domain = mesh.create_rectangle(MPI.COMM_WORLD, [[0, 0], [1, 0.5]], [4, 2])
    x = domain.geometry.x
    inner = np.flatnonzero(np.isclose(x[:, 0], 0.5) & np.isclose(x[:, 1], 0.25))
    x[inner, 0] += 0.4          # past its neighbours at x = 0.75: cells fold over
    _, tags = rectangle(MPI.COMM_WORLD, 0.0, 0.5, (4, 2), bottom=1, top=2, left=3)
    tags = mesh.meshtags(domain, 1, tags.indices, tags.values)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    with pytest.raises(ValueError, match="tangled cells"):
        problem(V, tags)


def test_collapsed_cell_is_reported():
    domain = mesh.create_rectangle(MPI.COMM_WORLD, [[0, 0], [1, 0.5]], [4, 2])
    x = domain.geometry.x
    # the bottom node at x = 0.25 onto its neighbour at 0: a zero-length slave facet
    x[np.isclose(x[:, 0], 0.25) & np.isclose(x[:, 1], 0.0), 0] = 0.0
    _, tags = rectangle(MPI.COMM_WORLD, 0.0, 0.5, (4, 2), bottom=1, top=2, left=3)
    tags = mesh.meshtags(domain, 1, tags.indices, tags.values)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    with pytest.raises(ValueError, match="zero size|degenerate facet"):
        problem(V, tags)


def test_nan_coordinates_are_named_as_such():
    """A NaN node was reported as "a cell of zero size" at the finite vertices
    of a facet next to it."""
    domain = mesh.create_rectangle(MPI.COMM_WORLD, [[0, 0], [1, 0.5]], [4, 2])
    x = domain.geometry.x
    x[np.isclose(x[:, 0], 0.5) & np.isclose(x[:, 1], 0.25), 0] = np.nan
    _, tags = rectangle(MPI.COMM_WORLD, 0.0, 0.5, (4, 2), bottom=1, top=2, left=3)
    tags = mesh.meshtags(domain, 1, tags.indices, tags.values)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    with pytest.raises(ValueError, match=r"NaN or infinite node coordinates: node \d+ .*"
                                         r"is at \[nan, 0.25\]"):
        problem(V, tags)


def test_a_penalty_that_cannot_represent_a_force_is_named():
    """A penalty of 1e-300 was accepted, and Newton's failure blamed on the load
    (nothing in contact)."""
    V, tags = block()
    with pytest.raises(ValueError, match="the penalty 1e-300 cannot represent a contact force"):
        problem(V, tags, penalty=1e-300)


def test_a_penalty_far_below_e_over_h_is_named():
    V, tags = block()        # h = 1/8 (the slave's elements' bounding-box diagonal)
    with pytest.raises(ValueError, match=r"the penalty 1e-12 is 1.[23]e-13 times E/h = 8 "
                                         r"\(E = 1, h = 0.125"):
        problem(V, tags, penalty=1e-12)
    problem(V, tags, penalty=1e-6)           # low, but not beyond representing contact


def test_a_discontinuous_space_is_named():
    """A DG space has no facet dofs: it failed with "P1 line cells need 2 nodes
    each, got cells of shape (8, 0)"."""
    V, tags = block()
    V = fem.functionspace(V.mesh, ("DG", 1, (2,)))
    with pytest.raises(ValueError, match=r"continuous Lagrange \(CG, P1/P2\) space, got a "
                                         r"discontinuous \(DG\) P space of degree 1"):
        problem(V, tags)


def test_a_1d_mesh_is_named():
    """Contact on an interval mesh ended in a numpy IndexError."""
    domain = mesh.create_interval(MPI.COMM_WORLD, 4, [0.0, 1.0])
    ends = [mesh.locate_entities_boundary(domain, 0, lambda x, e=e: np.isclose(x[0], e))
            for e in (0.0, 1.0)]
    facets = np.concatenate(ends).astype(np.int32)
    values = np.concatenate([np.full(len(f), tag, dtype=np.int32)
                             for f, tag in zip(ends, (1, 2))])
    order = np.argsort(facets)
    tags = mesh.meshtags(domain, 0, facets[order], values[order])
    u = fem.Function(fem.functionspace(domain, ("Lagrange", 1, (1,))))
    with pytest.raises(ValueError, match="contact needs a 2D or 3D mesh, got a mesh of "
                                         "topological dimension 1 in 1D"):
        ContactTerm(u, tags, 1, master_tag=2, penalty=1e3)


def test_an_obstacle_facing_into_the_body_is_named():
    """A plane whose normal points into the block (the block inside the
    obstacle, every slave node on its surface) stalled with the out-of-reach
    hint. Warned about, as a master facing away is."""
    V, tags = block()
    with pytest.warns(RuntimeWarning, match=r"the obstacle RigidPlane\(point=\[0.0, 0.0\], "
                                            r"normal=\[0.0, -1.0\]\) faces away from the "
                                            "slave surface"):
        problem(V, tags, obstacle=RigidPlane([0, 0], [0, -1]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        problem(V, tags)                     # the same plane facing the block: no word


def test_a_nan_load_is_named():
    """update(t) setting a traction's Constant to NaN ended in "petsc4py Error:
    error code -1" raised from inside SNES."""
    V, tags = block()
    u, v = fem.Function(V), ufl.TestFunction(V)
    pull = fem.Constant(V.mesh, PETSc.ScalarType(0.0))
    ds = ufl.Measure("ds", domain=V.mesh, subdomain_data=tags)
    F = ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx - pull * v[1] * ds(2)
    contact = ContactTerm(u, tags, 1, obstacle=PLANE, penalty=1e3)
    left = fem.locate_dofs_topological(V, 1, tags.find(3))
    nonlinear = NonlinearContactProblem(F, u, contact, [fem.dirichletbc(np.zeros(2), left, V)])

    def update(t):
        pull.value = np.nan

    with pytest.raises(ContactDivergenceError, match=r"Constant 0 of the residual form is NaN "
                                                     r"or infinite \(nan\): the residual is "
                                                     "not finite after the load update"):
        LoadPathSolver(nonlinear).solve(update, 1, max_cuts=0)
