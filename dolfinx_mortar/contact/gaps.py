"""Penalty mortar contact terms for the Newton solver (DESIGN.md §3).

With nodal gaps ``d̄_A`` and their derivative ``G = ∂d̄/∂u`` (a sparse matrix,
slave functions × displacement dofs), the penalty potential
``Π_c = Σ_A (ω_A/2) ⟨d̄_A⟩²`` gives

- residual ``R_c = Gᵀ (ω ⟨d̄⟩)``,
- Jacobian ``K_c = Gᵀ diag(ω H(d̄)) G + Σ_A ω_A ⟨d̄_A⟩ ∂²d̄_A/∂u²``,

exact for the nodal active set (semi-smooth Newton). The scalings:

- ``"consistent"``: ``d̄_A = ∫ M̄_A d`` with the unstarred partner ``M̄`` (a
  length) and ``ω_A = ε W_A``; a kind and its starred partner give the same
  problem;
- ``"seed"``: ``d_A = ∫ M_A d`` with the kind itself and ``ω_A = ε``.

Two gap models: :class:`ObstacleGap` (rigid analytic obstacle, exact and
nonlinear in u) and :class:`MortarGap` (elastic master, small deformation:
segmented once, linear in u).
"""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.bases.basis import MortarBasis
from dolfinx_mortar.kinds import (BasisKind, KindLike, is_global, is_partition_of_unity,
                                  parse_kind, unstarred_partner)
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.layout import MassMatrixSolver, NodeLayout, assemble_blocks
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.contact.obstacles import RigidObstacle

FloatArray = npt.NDArray[np.float64]

SCALINGS = ("consistent", "seed")


def gap_kind(kind: KindLike, scaling: str) -> BasisKind:
    """The basis whose integrals define the nodal gaps for a scaling.

    For GLS/GLS* this is the standard basis N: their gaps are ``L⁻¹ ∫N d``
    (:class:`GlobalGap`).
    """
    if scaling not in SCALINGS:
        raise ValueError(f"unknown scaling '{scaling}'; expected one of {SCALINGS}")
    kind = parse_kind(kind)
    if is_global(kind):
        return BasisKind.LmLS_star
    return unstarred_partner(kind) if scaling == "consistent" else kind


def dof_layout(nodes: NodeLayout, bs: int) -> NodeLayout:
    """The layout of the blocked dofs (node·bs + k) of a node layout."""
    ghosts = (nodes.ghosts[:, None] * bs + np.arange(bs)[None, :]).ravel()
    return NodeLayout(nodes.comm, nodes.num_owned * bs, ghosts)


class _GapBase:
    """Shared state: the slave surface, the gap basis and the node weights ω."""

    def __init__(self, slave: LagrangeSurface, kind: KindLike, penalty: float,
                 scaling: str):
        if not np.isfinite(penalty) or penalty <= 0:
            raise ValueError(f"the penalty must be positive and finite, got {penalty}")
        self.slave = slave
        self.kind = parse_kind(kind)
        self.scaling = scaling
        self.penalty = float(penalty)
        self.basis = MortarBasis(gap_kind(kind, scaling), slave)
        W = self.basis.lumped_weights
        #: ω_A of Π_c = Σ (ω_A/2)⟨d̄_A⟩²
        self.weights = self.penalty * (W if scaling == "consistent" else np.ones_like(W))
        self.dofs = dof_layout(slave.layout, slave.gdim)
        T = slave.reference.transform
        C = self.basis.coefficients
        #: M̄ = N_std C_std on each slave cell (N_std: the displacement's basis)
        self.coefficients_std = C if T is None else np.einsum("ab,cbd->cad", T, C)

    @property
    def lumped_weights(self) -> FloatArray:
        """``W_A = ∫ N_A`` of the configuration the bases live in (over the
        covered part with the boundary modification)."""
        return getattr(self, "_weights_source", self.basis.lumped_weights)

    def nodal_pressures(self, gaps: FloatArray, positive_part: bool = True) -> FloatArray:
        """Pressure coefficients ``p_A`` of the contact traction in a PU basis.

        The traction is ``Σ_A ω_A ⟨d_A⟩ M_A`` with ``M`` the gap basis. A non-PU
        ``M_A`` is ``M*_A / W_A``, so ``p_A = ω_A ⟨d_A⟩ / W_A`` (in the
        consistent scaling ``ε⟨d̄_A⟩``); a PU gap basis (seed scaling with a
        starred kind) gives ``p_A = ω_A ⟨d_A⟩`` directly. ``positive_part=False``
        takes ``gaps`` as they are (the pointwise active set's ``d̄⁺``, which is
        already an integral of ⟨d⟩ and may be negative for dual kinds).
        """
        force = self.weights * (np.maximum(gaps, 0.0) if positive_part else gaps)
        if is_partition_of_unity(self.basis.kind):
            return force
        W = self.lumped_weights
        return np.divide(force, W, out=np.zeros_like(W), where=W > 0)

    def _node_dofs(self, nodes: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
        """Global dofs (node·bs + k) of local nodes, shape nodes.shape + (bs,)."""
        g = self.slave.layout.global_indices[nodes]
        bs = self.slave.gdim
        return g[..., None] * bs + np.arange(bs)


class ObstacleGap(_GapBase):
    """Nodal gaps against a rigid analytic obstacle: ``d = −φ(x + u)``.

    Exact in u (no segmentation: the obstacle lies below every slave point).
    """

    def __init__(self, slave: LagrangeSurface, obstacle: RigidObstacle, kind: KindLike,
                 penalty: float, scaling: str = "consistent",
                 quadrature_degree: Optional[int] = None,
                 reference: Optional[FloatArray] = None):
        super().__init__(slave, kind, penalty, scaling)
        #: nodal displacement that moved ``slave`` to its configuration (or None)
        self.reference = reference
        if obstacle.gdim != slave.gdim:
            raise ValueError(f"a {obstacle.gdim}D obstacle cannot touch a {slave.gdim}D body")
        self.obstacle = obstacle
        self.tabulation = slave.tabulate(quadrature_degree or 2 * slave.reference.degree + 2,
                                         transformed=False)
        tab = self.tabulation
        #: M̄_A at the quadrature points, per cell: (cells, points, functions)
        self.Mbar = np.einsum("cqb,cba->cqa", tab.phi, self.coefficients_std)
        #: slave nodes with something below them (here: all; the obstacle is unbounded)
        self.covered = slave.layout.on_cells(slave.cells)

    def evaluate(self, u_nodes: FloatArray) -> tuple[FloatArray, PETSc.Mat, FloatArray]:
        """Nodal gaps, G, and the obstacle Hessian data at the quadrature points.

        ``u_nodes``: displacement at the local slave-layout nodes, (nodes, gdim).
        """
        tab, cells = self.tabulation, self.slave.cells
        if self.reference is not None:  # the surface already carries the reference
            u_nodes = u_nodes - self.reference
        u_q = np.einsum("cqb,cbk->cqk", tab.phi, u_nodes[cells])
        x = (tab.points + u_q).reshape(-1, self.slave.gdim)
        nc, nq, nd = tab.phi.shape
        d = -self.obstacle.signed_distance(x).reshape(nc, nq)
        nu = self.obstacle.gradient(x).reshape(nc, nq, self.slave.gdim)
        wd = tab.weights * d
        gaps = self.slave.layout.sum_at_functions(cells, np.einsum("cqa,cq->ca", self.Mbar, wd))
        # ∂d̄_A/∂u_(B,k) = −Σ_q w M̄_A ν_k N_B
        blocks = -np.einsum("cq,cqa,cqk,cqb->cabk", tab.weights, self.Mbar, nu, tab.phi)
        G = assemble_blocks(self.slave.layout, cells, self.dofs,
                            self._node_dofs(cells).reshape(nc, nd * self.slave.gdim),
                            blocks.reshape(nc, nd, nd * self.slave.gdim))
        return gaps, G, x

    def curvature_blocks(self, coefficients: FloatArray, x: FloatArray) -> Optional[FloatArray]:
        """Element matrices of Σ_A c_A ∂²d̄_A/∂u², or None for a flat obstacle."""
        H = self.obstacle.hessian(x)
        if not np.any(H):
            return None
        tab, cells = self.tabulation, self.slave.cells
        nc, nq, nd = tab.phi.shape
        gdim = self.slave.gdim
        cM = np.einsum("ca,cqa->cq", coefficients[cells], self.Mbar) * tab.weights
        blocks = -np.einsum("cq,cqkl,cqb,cqe->cbkel", cM, H.reshape(nc, nq, gdim, gdim),
                            tab.phi, tab.phi)
        return blocks.reshape(nc, nd * gdim, nd * gdim)


class MortarGap(_GapBase):
    """Nodal gaps against an elastic master in the same mesh, small deformation.

    Segmented once, in the configuration of ``reference`` (the displacement
    the coupling was built with; None: the undeformed one), and linear about it:
    ``d̄_A(u) = d̄_A⁰ + n_A·(Σ_B D̄_AB Δu_B − Σ_C M̄_AC Δu_C)``, ``Δu = u − reference``.
    """

    def __init__(self, coupling: MortarCoupling, kind: KindLike, penalty: float,
                 scaling: str = "consistent", reference: Optional[PETSc.Vec] = None,
                 boundary_modification: bool = False):
        self.reference = reference
        super().__init__(coupling.slave, kind, penalty, scaling)
        if coupling.master.layout is not coupling.slave.layout and (
                coupling.master.layout.size_global != coupling.slave.layout.size_global):
            raise ValueError("MortarGap needs slave and master in one mesh (one displacement "
                             "space); two meshes are supported by MortarCoupling only")
        self.coupling = coupling
        self._weights_source = self.basis.lumped_weights
        if boundary_modification:
            # dual basis rebuilt over the covered part of every covered cell
            # (Popp et al. 2013); its ∫_cov M̄_A = 1 pairs it with W_cov
            C = coupling._covered_coefficients(self.basis.kind)
            T = self.slave.reference.transform
            self.coefficients_std = C if T is None else np.einsum("ab,cbd->cad", T, C)
            _, _, W_cov = coupling.covered_element_mass()
            self._weights_source = W_cov
            if scaling == "consistent":
                self.weights = self.penalty * W_cov
        C = self.coefficients_std[coupling.pairs[:, 0]]
        Dn, Mn, gn = coupling.raw_pairs
        Dg = np.einsum("pba,pbc->pac", C, Dn)        # ∫ M̄_A N_B
        Mg = np.einsum("pba,pbc->pac", C, Mn)        # ∫ M̄_A N^m_C
        g0 = np.einsum("pba,pb->pa", C, gn)
        slave_cells = self.slave.cells[coupling.pairs[:, 0]]
        self.gaps0 = self.slave.layout.sum_at_functions(slave_cells, g0)
        #: slave nodes with master below them; the others have no gap at all
        self.covered = self.slave.layout.on_cells(slave_cells)
        n = coupling.normals[slave_cells]                      # (pairs, ns, gdim)
        master_nodes = coupling.master_global_ids[coupling.master_cells[coupling.pairs[:, 1]]]
        bs = self.slave.gdim
        slave_dofs = self._node_dofs(slave_cells)              # (pairs, ns, bs)
        master_dofs = master_nodes[..., None] * bs + np.arange(bs)
        blocks = np.concatenate([np.einsum("pab,pak->pabk", Dg, n),
                                 -np.einsum("pac,pak->pack", Mg, n)], axis=2)
        npairs, ns = slave_cells.shape
        # explicit sizes: a rank may own no pair, and reshape(0, -1) is ambiguous
        width = (ns + master_nodes.shape[1]) * bs
        cols = np.concatenate([slave_dofs, master_dofs], axis=1).reshape(npairs, width)
        self.G = assemble_blocks(self.slave.layout, slave_cells, self.dofs, cols,
                                 blocks.reshape(npairs, ns, width))
        #: the segment points for the pointwise active set (None: nodal only)
        self.points = None
        if coupling.points is not None:
            from dolfinx_mortar.contact.pointwise import MortarPointGaps
            self.points = MortarPointGaps(self)

    def evaluate(self, u: PETSc.Vec) -> FloatArray:
        """Nodal gaps at the local slave nodes for the displacement vector ``u``."""
        if self.reference is not None:
            u = u.copy()
            u.axpy(-1.0, self.reference)
        Gu = self.G.createVecLeft()
        self.G.mult(u, Gu)
        return self.gaps0 + self.slave.layout.to_local(Gu)


def covered_mass(coupling: MortarCoupling) -> tuple[MassMatrixSolver, FloatArray]:
    """``L_AB = ∫_cov N_A N_B`` over the covered slave area, factorized, and its
    row sums ``W_A = ∫_cov N_A``. Nodes with no covered support get a unit row
    (their gap is 0 and their weight 0)."""
    slave = coupling.slave
    L, covered_cells, W = coupling.covered_element_mass()
    matrix = slave.layout.assemble_matrix(slave.cells[covered_cells], L[covered_cells])
    return MassMatrixSolver(slave.layout, matrix), W


class GlobalGap:
    """Nodal gaps of GLS and GLS*: ``d̄ = L⁻¹ ĝ(u)`` with ``ĝ_B = ∫ N_B d``.

    ``M_A`` has global support, so ``G = L⁻¹ Ĝ`` is dense; only the sparse
    ``Ĝ = ∂ĝ/∂u`` and ``L`` are assembled, and the Newton step solves the
    augmented system of DESIGN.md §3 (see :class:`AugmentedNewtonStep`).
    ``inner`` computes ``ĝ`` and ``Ĝ`` (a standard-basis gap model).
    """

    def __init__(self, inner, kind: KindLike, penalty: float, scaling: str):
        self.inner = inner
        self.kind = parse_kind(kind)
        self.scaling = scaling
        self.slave = inner.slave
        self.basis = MortarBasis(BasisKind.GLS, self.slave)
        if isinstance(inner, MortarGap):
            # The projection d̄ = L⁻¹ĝ must see d only where it exists: with L
            # over the whole surface, the uncovered part counts as d = 0 and
            # the gaps ring past the covered zone (a node beyond it got
            # d̄ = +0.31 h on two touching cylinders at zero load).
            self.mass, W = covered_mass(inner.coupling)
        else:
            self.mass, W = self.basis._solver, self.basis.lumped_weights
        #: W_A = ∫ N_A over the part that enters the projection
        self.lumped_weights = W
        # Π_c = Σ (ω_A/2)⟨d̄_A⟩² in terms of the GLS gap d̄ (∫M_A = 1):
        # consistent ω = εW; seed GLS ω = ε; seed GLS* (d_A = W_A d̄_A) ω = εW².
        if scaling == "consistent":
            self.weights = penalty * W
        elif self.kind == BasisKind.GLS:
            self.weights = penalty * np.ones_like(W)
        else:
            self.weights = penalty * W ** 2
        self.dofs = inner.dofs
        self.covered = inner.covered
        #: owned local nodes of the slave surface (the rows the Newton step needs)
        owned = np.unique(self.slave.cells)
        self.surface_rows = owned[owned < self.slave.layout.num_owned]
        self.weights = np.where(self.covered, self.weights, 0.0)

    def nodal_pressures(self, gaps: FloatArray, positive_part: bool = True) -> FloatArray:
        """``p_A = ω_A⟨d̄_A⟩/W_A`` (coefficients of the traction in the PU basis GLS*)."""
        W = self.lumped_weights
        force = self.weights * (np.maximum(gaps, 0.0) if positive_part else gaps)
        return np.divide(force, W, out=np.zeros_like(W), where=W > 0)
