"""Bad input to the contact problem gets an exception (or a warning) that names it."""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem, mesh
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.kinds import kind_name, parse_kind
from dolfinx_mortar.contact.obstacles import RigidPlane
from dolfinx_mortar import ContactProblem
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
