"""The pointwise active set ``d̄⁺_A = ∫ M̄_A ⟨d⟩``, its derivative (docs/DESIGN.md, §Active sets).

With the nodal active set the penalty acts on ``⟨d̄_A⟩``; with the pointwise
one the nodal pressure is ``p_A = ε d̄⁺_A``, integrated only where the slave
penetrates (the seed's ``p_A = ∫ M_A ε⟨d⟩``). The contact virtual work stays
``Σ_A ω_A d̄⁺_A δd̄_A``, so the residual is ``Gᵀ(ω d̄⁺)`` and the Jacobian
``Gᵀ diag(ω) G⁺`` (plus curvature), with ``G⁺ = ∂d̄⁺/∂u`` — unsymmetric, which
MUMPS' LU takes as it is. Moving the boundary of {d > 0} adds nothing to
``G⁺`` because the integrand vanishes there.

- Rigid obstacle: cells that the contact boundary cuts are split at d = 0
  (:mod:`dolfinx_mortar.contact.gap_sources.cut_quadrature`); uncut cells keep their Gauss rule, so
  a fully penetrating surface gives the nodal result to round-off.
- Elastic master: ⟨d⟩ at the segment quadrature points; segments are not
  split (the kink costs quadrature accuracy on the few cut segments only).
"""
from __future__ import annotations

from typing import Optional, Protocol

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.contact.gap_sources.cut_quadrature import positive_part_rule
from dolfinx_mortar.contact.obstacles import relative_to
from dolfinx_mortar.contact.laws import positive_part
from dolfinx_mortar.surfaces.tabulation import measure_from_tangents
from dolfinx_mortar.layout import NodeLayout, assemble_blocks

FloatArray = npt.NDArray[np.float64]

#: sub-pieces per reference edge of a cut cell (see cut_quadrature)
CUT_SUBDIVISIONS = 8


def _assemble_gap_derivative(model, row_cells: npt.NDArray[np.int64],
                             cols: npt.NDArray[np.int64], blocks: FloatArray) -> PETSc.Mat:
    nb = len(row_cells)
    nd = model.slave.cells.shape[1]
    width = cols.shape[1] if nb else nd * model.slave.gdim
    return assemble_blocks(model.slave.layout, row_cells.reshape(nb, nd), model.dofs,
                           cols.reshape(nb, width), blocks.reshape(nb, nd, width))


def obstacle_positive_gaps(model, u_nodes: FloatArray, points: FloatArray
                           ) -> tuple[FloatArray, PETSc.Mat]:
    """``d̄⁺`` at the local slave nodes and ``G⁺`` against a rigid obstacle.

    ``u_nodes``: displacement at the local slave-layout nodes, (nodes, gdim);
    ``points``: the current quadrature points that ``model.evaluate`` returned
    (relative to ``model.origin``).
    """
    slave, tab = model.slave, model.tabulation
    cells, gdim = slave.cells, slave.gdim
    if model.reference is not None:
        u_nodes = u_nodes - model.reference
    nc, nq, nd = tab.phi.shape
    # current nodal positions relative to the model's origin, as the points are
    x_nodes = (slave.x - model.origin) + u_nodes
    obstacle = relative_to(model.obstacle, model.origin)
    xq = points.reshape(nc, nq, gdim)
    d = -obstacle.signed_distance(xq.reshape(-1, gdim)).reshape(nc, nq)
    d_nodes = -obstacle.signed_distance(x_nodes[cells].reshape(-1, gdim)).reshape(nc, nd)
    samples = np.concatenate([d, d_nodes], axis=1)
    full = np.all(samples > 0, axis=1)
    mixed = np.flatnonzero(np.any(samples > 0, axis=1) & ~full)

    # fully penetrating cells: the Gauss rule, as for the nodal gaps
    f = np.flatnonzero(full)
    nu = obstacle.gradient(xq[f].reshape(-1, gdim)).reshape(len(f), nq, gdim)
    wd = tab.weights[f] * d[f]
    values = [np.einsum("cqa,cq->ca", model.Mbar[f], wd)]
    rows = [cells[f]]
    blocks = [-np.einsum("cq,cqa,cqk,cqb->cabk", tab.weights[f], model.Mbar[f], nu,
                         tab.phi[f])]

    # cut cells: a rule on their penetrating part
    reference = slave.reference

    def gap_at(c: npt.NDArray[np.int64], X: FloatArray) -> FloatArray:
        N, _ = reference.tabulate(X, transformed=False)
        return -obstacle.signed_distance(np.einsum("nb,nbk->nk", N, x_nodes[cells[c]]))

    degree = 2 * reference.degree + 2
    owner, X, w_ref, _ = positive_part_rule(reference.cell, mixed, gap_at, degree,
                                            subdivisions=CUT_SUBDIVISIONS)
    c = mixed[owner]
    N, dN = reference.tabulate(X, transformed=False)
    coords = slave.x[cells[c]] - model.origin       # as x_nodes (r unchanged)
    tangents = [np.einsum("nb,nbk->nk", dN[:, t, :], coords) for t in range(slave.tdim)]
    # the surface's own measure, as its tabulation's weights (2πr ds if axisymmetric)
    w = (w_ref * measure_from_tangents(tangents)
         * slave.radial_factor(np.einsum("nb,nbk->nk", N, coords)))
    x = np.einsum("nb,nbk->nk", N, x_nodes[cells[c]])
    dq = -obstacle.signed_distance(x)
    # the rule covers {d > 0} up to the bisection tolerance: clip the rest
    dq = positive_part(dq)
    Mbar = np.einsum("nb,nba->na", N, model.coefficients_std[c])
    values.append(Mbar * (w * dq)[:, None])
    rows.append(cells[c])
    blocks.append(-np.einsum("n,na,nk,nb->nabk", w, Mbar, obstacle.gradient(x), N))

    row_cells = np.concatenate(rows)
    gaps = slave.layout.sum_at_functions(row_cells, np.concatenate(values))
    cols = model.node_dofs(row_cells).reshape(len(row_cells), nd * gdim)
    G = _assemble_gap_derivative(model, row_cells, cols,
                                 np.concatenate(blocks).reshape(len(row_cells), nd, nd * gdim))
    return gaps, G


class MortarPointGaps:
    """``d̄⁺`` and ``G⁺`` against an elastic master, from the segment points.

    Small deformation as in :class:`~dolfinx_mortar.contact.gap_sources.frozen.MortarGap`:
    ``d_q(u) = d_q⁰ + n_q·(Σ_B N_B Δu_B − Σ_C N^m_C Δu_C)`` at every segment
    quadrature point q, ``Δu = u − reference``.
    """

    def __init__(self, model):
        coupling = model.coupling
        if coupling.points is None:
            raise ValueError("the pointwise active set needs MortarCoupling(..., "
                             "keep_points=True)")
        self.model = model
        pts = coupling.points
        pair = pts.pairs.astype(np.int64)
        slave_cell = coupling.pairs[pair, 0]
        master_cells = coupling.master_cells[coupling.pairs[pair, 1]]
        self.rows = model.slave.cells[slave_cell]               # (points, ns)
        self.d0 = pts.gap
        n = pts.normals
        bs = model.slave.gdim
        Ns, Nm = pts.slave_N, pts.master_N
        npts = len(self.d0)
        slave_dofs = model.node_dofs(self.rows)
        master_dofs = (coupling.master_global_ids[master_cells][..., None] * bs
                       + np.arange(bs))
        width = (Ns.shape[1] + Nm.shape[1]) * bs
        #: ∂d_q/∂u per point, and the global dofs it acts on
        self.dd = np.concatenate([np.einsum("qb,qk->qbk", Ns, n),
                                  -np.einsum("qc,qk->qck", Nm, n)], axis=1).reshape(npts, width)
        self.cols = np.concatenate([slave_dofs, master_dofs], axis=1).reshape(npts, width)
        #: w_q M̄_A(q)
        self.wM = pts.weights[:, None] * np.einsum(
            "qb,qba->qa", Ns, model.coefficients_std[slave_cell])
        points = NodeLayout(model.slave.layout.comm, npts, np.zeros(0, dtype=np.int64))
        self.point_derivative = assemble_blocks(points, np.arange(npts)[:, None], model.dofs,
                                                self.cols, self.dd[:, None, :])

    def point_gaps(self, u: PETSc.Vec) -> FloatArray:
        """d at every local segment point for the displacement vector u."""
        reference = self.model.reference
        if reference is not None:
            u = u.copy()
            u.axpy(-1.0, reference)
        d = self.point_derivative.createVecLeft()
        self.point_derivative.mult(u, d)
        return self.d0 + d.array_r

    def positive_gaps(self, u: PETSc.Vec, u_nodes: Optional[FloatArray] = None,
                      x: Optional[FloatArray] = None) -> tuple[FloatArray, PETSc.Mat]:
        """``d̄⁺`` at the local slave nodes and ``G⁺`` for the displacement vector u."""
        d = self.point_gaps(u)
        active = d > 0
        layout = self.model.slave.layout
        gaps = layout.sum_at_functions(self.rows, self.wM * positive_part(d)[:, None])
        a = np.flatnonzero(active)
        blocks = np.einsum("qa,qw->qaw", self.wM[a], self.dd[a])
        return gaps, _assemble_gap_derivative(self.model, self.rows[a], self.cols[a], blocks)


class PointGaps(Protocol):
    """The active set's positive gaps of a frozen source: ``d̄⁺`` and ``G⁺``
    for the pointwise set, None for the nodal one."""

    def positive_gaps(self, u: PETSc.Vec, u_nodes: FloatArray, x: Optional[FloatArray]
                      ) -> tuple[Optional[FloatArray], Optional[PETSc.Mat]]:
        """At the displacement vector ``u`` (its nodal values ``u_nodes``, and
        the current quadrature points ``x`` against an obstacle)."""


class ObstaclePointGaps:
    """``d̄⁺`` and ``G⁺`` against a rigid obstacle (:func:`obstacle_positive_gaps`)."""

    def __init__(self, model):
        self.model = model

    def positive_gaps(self, u: PETSc.Vec, u_nodes: FloatArray, x: Optional[FloatArray]
                      ) -> tuple[FloatArray, PETSc.Mat]:
        return obstacle_positive_gaps(self.model, u_nodes, x)


class NodalSet:
    """The nodal active set: the penalty acts on ⟨d̄_A⟩, there is no ``d̄⁺``."""

    def positive_gaps(self, u: PETSc.Vec, u_nodes: FloatArray, x: Optional[FloatArray]
                      ) -> tuple[None, None]:
        return None, None


def point_gaps_of(model) -> PointGaps:
    """The positive gaps of a frozen source's active set: the one place where
    the frozen sources' variant (nodal or pointwise, the law's) is chosen."""
    if not model.law.pointwise:
        return NodalSet()
    return ObstaclePointGaps(model) if model.coupling is None else MortarPointGaps(model)
