"""The consistent boundary modification in the solver (dual kinds, elastic master)."""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem
from mpi4py import MPI

from dolfinx_mortar import ContactProblem
from support.jacobian_check import jacobian_error
from support.scenes import OVERHANG_GAP as GAP
from support.scenes import overhanging_blocks


def _problem(V, tags, kind, modification, configuration="initial"):
    return ContactProblem(V, tags, 1, master_tag=2, E=1.0, nu=0.3, kind=kind, penalty=1e3,
                          fixed={3: {0: 0.0, 1: 0.0}, 5: {0: 0.0}},
                          tractions={4: [0.0, -0.01]}, boundary_modification=modification,
                          basis_configuration=configuration)


def _covered_gaps(problem):
    n = problem.slave.layout.num_owned
    gaps = problem.nodal_gaps()[:n][problem.contact.evaluate().covered[:n]]
    return np.concatenate(problem.mesh.comm.allgather(gaps))


@pytest.mark.parametrize("configuration", ["initial", "current"])
@pytest.mark.parametrize("kind", ["LcLS*", "LcLS"])
def test_separated_blocks_show_no_false_penetration_with_the_modification(kind, configuration):
    V, tags = overhanging_blocks()
    modified = _covered_gaps(_problem(V, tags, kind, True, configuration))
    if configuration == "current":
        # unmodified, the current surface refuses the false penetration it reads
        with pytest.raises(NotImplementedError, match="false penetration"):
            _problem(V, tags, kind, False, configuration)
        assert np.allclose(modified, -GAP, rtol=0, atol=1e-12)
        return
    plain = _covered_gaps(_problem(V, tags, kind, False))
    # without it, a partly covered facet turns a separated node's gap positive
    assert np.max(plain) > 0.1 * GAP
    # with it, every covered node sees the true gap: the blocks are GAP apart
    assert np.allclose(modified, -GAP, rtol=0, atol=1e-12)


@pytest.mark.parametrize("configuration", ["initial", "current"])
def test_modified_jacobian_matches_finite_differences(configuration):
    """On the current surface the covered part of the facets that the upper block's
    corners cut moves with u, and the rebuilt basis with it: its derivative is part of
    the Jacobian (without it Newton converged linearly, 0.4 per iteration, on these
    blocks pressed; Cattaneo–Mindlin failed)."""
    V, tags = overhanging_blocks()
    problem = _problem(V, tags, "LcLS*", True, configuration)
    problem.set_load(1.0)
    # the upper block pushed into the lower one, with some tilt, and shifted along
    shift = 0.013 if configuration == "current" else 0.0
    problem.u.interpolate(lambda x: np.vstack([np.where(x[1] > GAP / 2, shift, 0.0), np.where(
        x[1] > GAP / 2, -0.06 - 0.01 * x[0], 0.0)]))
    gaps = _covered_gaps(problem)
    assert np.max(gaps) > 0
    assert jacobian_error(problem) < 1e-7


@pytest.mark.parametrize("kind", ["LcLS*", "LcLS"])
def test_modified_current_surface_presses_and_slides_at_newtons_rate(kind):
    """The upper block pressed 1.5·GAP and slid 0.05 on the current surface: the
    corners' partly covered facets carry load. Measured: 8 and 6 Newton iterations
    in the last two steps, the residual falling 2e-4 → 5e-8 → 7e-13 at the end; the
    nodal pressures integrate to the resultant."""
    V, tags = overhanging_blocks()
    problem = ContactProblem(V, tags, 1, master_tag=2, E=1.0, nu=0.3, kind=kind,
                             penalty=1e3, basis_configuration="current",
                             fixed={3: {0: 0.0, 1: 0.0}, 4: {0: 0.05, 1: -1.5 * GAP}})
    result = problem.solve(load_steps=4)
    assert len(result.steps) == 4
    # Newton's rate: the last steps took 5-8 iterations (30 and a stall without the
    # derivative of the rebuilt basis), the residual falling by 1e-4 and more at the end
    residuals = result.steps[-1].residuals
    assert max(step.newton_iterations for step in result.steps) <= 10
    assert residuals[-2] < 1e-3 * residuals[-3]
    force = -problem.contact_force()[1]
    assert force > 0 and abs(problem.normal_force() - force) < 1e-3 * force


def test_modified_problem_closes_the_gap_and_presses():
    """The upper top pushed down by 1.5·GAP: Newton converges and the contact
    pressure of the covered nodes is positive and finite."""
    V, tags = overhanging_blocks()
    problem = ContactProblem(V, tags, 1, master_tag=2, E=1.0, nu=0.3, kind="LcLS*",
                             penalty=1e3, boundary_modification=True,
                             fixed={3: {0: 0.0, 1: 0.0}, 5: {0: 0.0},
                                    4: {1: -1.5 * GAP}})
    result = problem.solve(load_steps=2)
    assert len(result.steps) == 2
    assert problem.normal_force() > 0
    n = problem.slave.layout.num_owned
    p = problem.nodal_pressures()[:n][problem.gap_model.covered[:n]]
    assert np.all(np.isfinite(p))


def test_modification_is_refused_where_it_does_not_apply():
    V, tags = overhanging_blocks()
    with pytest.raises(ValueError, match="dual kinds"):
        _problem(V, tags, "LmLS*", True)


@pytest.mark.parametrize("axisymmetric", [False, True])
def test_two_touching_cylinders_see_their_true_separation_by_default(axisymmetric):
    """Two cylinders (or spheres) touching at a point part slowly: where the
    search radius ends, a slave facet is covered by the master near its far
    node only, and a dual function (negative there) mixes the separation of
    its covered part into the node's gap. The default switches the modification
    on for the dual kinds against an elastic master: the last covered node
    sees the separation of the surfaces there. Off, it saw half of it (with
    gaps along the slave normal alone, before the interface normals, it even
    saw a penetration of 0.5 element lengths)."""
    from dolfinx_mortar import ContactTerm
    from demo_support.hertz_meshes import MASTER, SLAVE, quarter_disk_mesh
    from support import load_demo
    demo = load_demo("hertz_axisymmetric")    # its two-sphere mesh at the default size
    a = demo.hertz(demo.parse_args(["--obstacle", "sphere"]))["a"]
    h = a / 40
    domain, tags = quarter_disk_mesh(1.0, a, h, "disk", 1, MPI.COMM_WORLD)
    u = fem.Function(fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,))))

    def gaps(**options) -> tuple[float, float]:
        """The largest nodal gap and, at the covered node farthest from the axis,
        its gap over the separation of the two unit circles there."""
        contact = ContactTerm(u, tags, SLAVE, master_tag=MASTER, kind="LcLS*", penalty=1e3,
                              axisymmetric=axisymmetric, **options)
        n = contact.slave.layout.num_owned
        gap = contact.results.nodal_gaps()[:n]
        covered = contact.evaluate().covered[:n]
        r = contact.slave.x[:n, 0]
        last = (float(np.max(r[covered], initial=-np.inf)), 0.0)
        if covered.any():
            i = np.flatnonzero(covered)[np.argmax(r[covered])]
            separation = 2 * (1 - np.sqrt(1 - r[i] ** 2))
            last = (float(r[i]), float(-gap[i] / separation))
        comm = domain.comm
        return (comm.allreduce(float(np.max(gap, initial=-np.inf)), op=MPI.MAX),
                max(comm.allgather(last))[1])
    largest, edge = gaps()
    # the bodies touch at the axis node only: no gap above round-off
    assert largest <= 1e-12 * h
    assert abs(edge - 1) < 1e-3, edge
    largest, edge = gaps(boundary_modification=False)
    assert largest <= 1e-12 * h
    assert edge < 0.6, edge


def test_the_modification_is_on_by_default_only_where_it_applies():
    from dolfinx_mortar import ContactTerm, RigidPlane
    V, tags = overhanging_blocks()
    u = fem.Function(V)

    def default(**options) -> bool:
        return ContactTerm(u, tags, 1, penalty=1e3, **options).options.boundary_modification
    assert default(master_tag=2, kind="LcLS*") and default(master_tag=2, kind="LcLS")
    assert not default(master_tag=2, kind="LmLS")
    assert not default(obstacle=RigidPlane([0, 0.1], [0, -1]), kind="LcLS*")
    assert not default(master_tag=2, kind="LmLS*", basis_configuration="current")
    assert default(master_tag=2, kind="LcLS*", basis_configuration="current")
    with pytest.warns(RuntimeWarning, match="pointwise active set with a dual kind"):
        assert not default(master_tag=2, kind="LcLS*", active_set="pointwise")
