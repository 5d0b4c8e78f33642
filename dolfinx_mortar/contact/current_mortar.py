"""Contact with an elastic master, bases and segmentation in the current configuration (2D).

``basis_configuration="current"`` with a master surface (DESIGN.md §3, finite
deformation): the segments, the projection χ and the averaged slave normals
all move with u. ``ĝ_A(u) = ∫ φ_A d`` is computed here exactly as the C++
kernel computes it (``mortar_integrals.cpp``: an auxiliary line through each
flat slave piece, master piece ends projected onto it, the overlap integrated
with the segment rule, every point mapped back to slave and master along the
line's normal, ``d = (x_s − x_m)·n̂`` with n̂ the interpolated averaged nodal
normal), but in :class:`~dolfinx_mortar.contact.jet.Jet` arithmetic, so that ``ĝ``
comes with its exact first and second derivatives with respect to every node
it depends on: the slave cell's, its neighbours' (through the averaged
normals) and the master cell's. The kernel still picks the pairs; its values
must equal these (tested), which ties the two implementations together.

Lines here; P1 triangles in :mod:`dolfinx_mortar.contact.current_mortar_3d`, where the
same construction runs through polygon clipping.
"""
from __future__ import annotations

from typing import Optional, Sequence, Union

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.contact.current_mortar_3d import TrianglePatches, pair_jets_3d
from dolfinx_mortar.contact.finite_deformation import CurrentSurfaceGap
from dolfinx_mortar.contact.jet import Jet, dot, maximum, minimum
from dolfinx_mortar.kinds import KindLike
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.layout import assemble_blocks, assemble_global_blocks
from dolfinx_mortar.mortar.coupling import (MortarCoupling, polynomial_degree, segment_quadrature,
                                   gather_surface)

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
Value = Union[Jet, FloatArray, float]

#: reference nodes of the Lagrange lines, in the kernel's and DOLFINx's order
LINE_NODES = {1: (0.0, 1.0), 2: (0.0, 1.0, 0.5)}
#: flat pieces the kernel splits a line into (facet_subfacets in facet_element.cpp)
LINE_PIECES = {1: ((0.0, 1.0),), 2: ((0.0, 0.5), (0.5, 1.0))}


def line_basis(degree: int, X: Value) -> tuple[list, list]:
    """Lagrange functions N_i and their derivatives at X (a Jet, array or number)."""
    nodes = LINE_NODES[degree]
    N, dN = [], []
    for i, xi in enumerate(nodes):
        others = [xj for j, xj in enumerate(nodes) if j != i]
        scale = 1.0 / np.prod([xi - xj for xj in others])
        factors = [X - xj for xj in others]
        if len(factors) == 1:
            N.append(factors[0] * scale)
            dN.append(scale)
        else:  # two factors (quadratic)
            N.append(factors[0] * factors[1] * scale)
            dN.append((factors[0] + factors[1]) * scale)
    return N, dN


def _combine(weights: Sequence[Value], points: Sequence[list]) -> list:
    """Σ_i w_i x_i for 2D points given as [x, y] lists."""
    out = [weights[0] * points[0][0], weights[0] * points[0][1]]
    for w, p in zip(weights[1:], points[1:]):
        out = [out[0] + w * p[0], out[1] + w * p[1]]
    return out


def _unit(v: list) -> list:
    length = (v[0] * v[0] + v[1] * v[1]).sqrt()
    return [v[0] / length, v[1] / length]


def _values(v: Value) -> FloatArray:
    return v.value if isinstance(v, Jet) else np.asarray(v, dtype=np.float64)


def project_along_line(degree: int, nodes: list, x: list, e1: list, start: float) -> Jet:
    """Reference coordinate X of the cell point whose offset from x is normal to e1.

    Newton on the values first; then two Newton steps in Jet arithmetic from
    the converged value, which make the first and then the second derivatives
    exact (implicit function theorem, Newton's map has zero slope at its root).
    """
    xv = [_values(c) for c in x]
    ev = [_values(c) for c in e1]
    nv = [[_values(c) for c in p] for p in nodes]
    X = np.full(xv[0].shape, start)
    for _ in range(30):
        N, dN = line_basis(degree, X)
        p = _combine(N, nv)
        t = _combine(dN, nv)
        step = (((p[0] - xv[0]) * ev[0] + (p[1] - xv[1]) * ev[1])
                / (t[0] * ev[0] + t[1] * ev[1]))
        X = X - step
        if np.all(np.abs(step) < 1e-15):
            break
    Xj: Value = X
    for _ in range(2):
        N, dN = line_basis(degree, Xj)
        p = _combine(N, nodes)
        t = _combine(dN, nodes)
        Xj = Xj - dot([p[0] - x[0], p[1] - x[1]], e1) / dot(t, e1)
    return Xj


class CurrentMortarGap(CurrentSurfaceGap):
    """Penalty contact with an elastic master in one mesh, everything on the
    current configuration, exact Jacobian (2D: lines; 3D: P1 triangles).

    Parameters
    ----------
    slave, master
        The surfaces in the reference configuration (one displacement space).
    kind, penalty, scaling
        As for :class:`~dolfinx_mortar.contact.finite_deformation.CurrentSurfaceGap`.
    search_radius
        As for :class:`~dolfinx_mortar.mortar.coupling.MortarCoupling` (pairs are found
        again at every evaluation).
    """

    moving_pattern = True

    def __init__(self, slave: LagrangeSurface, master: LagrangeSurface, kind: KindLike,
                 penalty: float, scaling: str = "consistent",
                 search_radius: Optional[float] = None):
        if slave.gdim == 3 and not (slave.reference.name == master.reference.name == "P1 triangle"):
            raise NotImplementedError(
                "basis_configuration='current' with an elastic master in 3D is implemented "
                "for P1 triangle facets only (got "
                f"{slave.reference.name} and {master.reference.name})")
        if master.layout.size_global != slave.layout.size_global:
            raise ValueError("slave and master must share one displacement space (one mesh)")
        super().__init__(slave, kind, penalty, scaling)
        self.master, self.search_radius = master, search_radius
        self.slave_degree = slave.reference.degree
        self.master_degree = master.reference.degree
        degree = polynomial_degree(slave) + max(polynomial_degree(slave),
                                                 polynomial_degree(master))
        self.segment_points, self.segment_weights = segment_quadrature(slave.tdim, degree)
        if slave.gdim == 2:
            self._neighbours = self._normal_neighbours()
        else:
            self._patches = TrianglePatches(slave)
        self.covered = np.zeros(slave.layout.size_local, dtype=bool)
        #: the kernel's coupling at the last evaluation (pairs, reference values)
        self.coupling: Optional[MortarCoupling] = None

    def _normal_neighbours(self) -> tuple[IntArray, FloatArray]:
        """For both end nodes of every local slave cell: the other slave cell
        (index into the gathered surface, −1 if none) and the reference
        coordinate of the shared node in it. The averaged normal at a node
        depends on both cells, so both cells' nodes are variables of a pair."""
        slave = self.slave
        copy = gather_surface(slave, slave.x)
        ids = copy.global_ids[copy.cells]                              # (all cells, nd)
        comm = slave.layout.comm
        first = comm.scan(len(slave.cells)) - len(slave.cells)
        cells_at: dict[int, list] = {}
        for c, row in enumerate(ids):
            for position in (0, 1):
                cells_at.setdefault(int(row[position]), []).append((c, float(position)))
        other = np.full((len(slave.cells), 2), -1, dtype=np.int64)
        position = np.zeros((len(slave.cells), 2))
        for i in range(len(slave.cells)):
            own = first + i
            for end in (0, 1):
                node = int(ids[own, end])
                rest = [entry for entry in cells_at[node] if entry[0] != own]
                if len(rest) > 1:
                    raise ValueError(f"slave node {node} is shared by {len(rest) + 1} facets: "
                                     "the averaged normal needs a manifold slave curve")
                if rest:
                    other[i, end], position[i, end] = rest[0]
        return other, position

    # -- the pair computation --------------------------------------------------------------
    def _pair_variables(self, u_nodes: FloatArray, coupling: MortarCoupling
                        ) -> tuple[FloatArray, IntArray]:
        """Values (pairs, nv) and global dofs (pairs, nv) of a pair's variables:
        the slave cell's nodes, the nodes of the cells beyond either end (for
        the normals) and the master cell's nodes, two coordinates each."""
        slave = self.slave
        pairs = coupling.pairs
        xs = slave.x + u_nodes
        copy = gather_surface(slave, xs)
        nd = slave.cells.shape[1]
        gathered_x = copy.x.reshape(-1, nd, 2)
        gathered_ids = copy.global_ids.reshape(-1, nd)
        own = pairs[:, 0]
        blocks_x = [xs[slave.cells[own]]]
        blocks_id = [slave.layout.global_indices[slave.cells[own]]]
        other, _ = self._neighbours
        for end in (0, 1):
            # a missing neighbour is stood in for by the cell itself (a valid
            # normal, weighted by zero), so no 0/0 enters the derivatives
            o = other[own, end]
            safe = np.where(o >= 0, o, 0)
            blocks_x.append(np.where((o >= 0)[:, None, None], gathered_x[safe], blocks_x[0]))
            blocks_id.append(np.where((o >= 0)[:, None], gathered_ids[safe], blocks_id[0]))
        master_cells = coupling.master_copy.cells[pairs[:, 1]]
        blocks_x.append(coupling.master_copy.x[master_cells])
        blocks_id.append(coupling.master_copy.global_ids[master_cells])
        x = np.concatenate(blocks_x, axis=1)                               # (pairs, nodes, 2)
        ids = np.concatenate(blocks_id, axis=1)
        # explicit sizes: a rank may have no pair, and reshape(0, -1) is ambiguous
        nv = 2 * x.shape[1]
        dofs = (ids[..., None] * 2 + np.arange(2)).reshape(len(pairs), nv)
        return x.reshape(len(pairs), nv), dofs

    def pair_gaps(self, values: FloatArray, pairs: IntArray) -> list[Jet]:
        """``c_a = ∫ N_a d`` of every pair as Jets in the pair's variables."""
        ps, pm = self.slave_degree, self.master_degree
        ns, nm = ps + 1, pm + 1
        v = Jet.variables(values)
        node = [[v[2 * i], v[2 * i + 1]] for i in range(3 * ns + nm)]
        own, ends, master = node[:ns], (node[ns:2 * ns], node[2 * ns:3 * ns]), node[3 * ns:]
        other, position = self._neighbours
        has_other = (other[pairs[:, 0]] >= 0).astype(np.float64)
        shared_at = position[pairs[:, 0]]

        def cell_normal(nodes: list, degree: int, X: Value) -> list:
            t = _combine(line_basis(degree, X)[1], nodes)
            return [t[1], -t[0]]    # size-weighted, as the kernel's

        # averaged nodal normals at the slave cell's nodes (element_node_normals + average)
        normals = []
        for a, Xa in enumerate(LINE_NODES[ps]):
            n = cell_normal(own, ps, Xa)
            if a < 2:
                m = cell_normal(ends[a], ps, shared_at[:, a])
                n = [n[0] + m[0] * has_other[:, a], n[1] + m[1] * has_other[:, a]]
            normals.append(_unit(n))

        # an overlap no longer than the zero length counts as none (the kernel's
        # decision, against the same length scale)
        zero = self.coupling.zero_length
        acc: list = [0.0] * ns
        for X0, X1 in LINE_PIECES[ps]:
            p0 = _combine(line_basis(ps, X0)[0], own)
            p1 = _combine(line_basis(ps, X1)[0], own)
            centre = [(p0[0] + p1[0]) * 0.5, (p0[1] + p1[1]) * 0.5]
            chord = [p1[0] - p0[0], p1[1] - p0[1]]
            size = dot(chord, chord).sqrt()
            e1 = [chord[0] / size, chord[1] / size]
            normal = [e1[1], -e1[0]]
            s0 = dot([p0[0] - centre[0], p0[1] - centre[1]], e1)
            s1 = dot([p1[0] - centre[0], p1[1] - centre[1]], e1)
            for Y0, Y1 in LINE_PIECES[pm]:
                q0 = _combine(line_basis(pm, Y0)[0], master)
                q1 = _combine(line_basis(pm, Y1)[0], master)
                m_normal = _unit([q1[1] - q0[1], -(q1[0] - q0[0])])
                opposing = _values(dot(m_normal, normal)) < 0
                m0 = dot([q0[0] - centre[0], q0[1] - centre[1]], e1)
                m1 = dot([q1[0] - centre[0], q1[1] - centre[1]], e1)
                lo = maximum(s0, minimum(m0, m1))
                hi = minimum(s1, maximum(m0, m1))
                length = hi - lo
                on = (opposing & (length.value > zero)).astype(np.float64)
                for t, w in zip(self.segment_points[:, 0], self.segment_weights):
                    s = lo + length * t
                    x = [centre[0] + e1[0] * s, centre[1] + e1[1] * s]
                    Xs = project_along_line(ps, own, x, e1, 0.5 * (X0 + X1))
                    Ym = project_along_line(pm, master, x, e1, 0.5 * (Y0 + Y1))
                    Ns = line_basis(ps, Xs)[0]
                    xs = _combine(Ns, own)
                    xm = _combine(line_basis(pm, Ym)[0], master)
                    n = _combine(Ns, normals)
                    d = dot([xs[0] - xm[0], xs[1] - xm[1]], _unit(n))
                    weighted = d * length * (w * on)
                    acc = [acc[a] + weighted * Ns[a] for a in range(ns)]
        return acc

    # -- CurrentSurfaceGap hooks ------------------------------------------------------------
    def _gap(self, u_nodes: FloatArray, e: dict) -> tuple[FloatArray, PETSc.Mat, dict]:
        slave, layout = self.slave, self.slave.layout
        coupling = MortarCoupling(slave.moved(u_nodes), self.master.moved(u_nodes),
                                  search_radius=self.search_radius)
        self.coupling = coupling
        pairs = coupling.pairs
        cells = slave.cells[pairs[:, 0]]
        ns = cells.shape[1]
        if slave.gdim == 3:
            value, grad, hess, dofs = pair_jets_3d(self._patches, slave, u_nodes, coupling,
                                                   self.segment_points, self.segment_weights)
        else:
            values, dofs = self._pair_variables(u_nodes, coupling)
            nv = values.shape[1]
            if len(pairs):
                c = self.pair_gaps(values, pairs)
                value = np.column_stack([ca.value for ca in c])
                grad = np.stack([ca.grad for ca in c], axis=1)             # (p, ns, nv)
                hess = np.stack([ca.hess for ca in c], axis=1)             # (p, ns, nv, nv)
            else:
                value, grad = np.zeros((0, ns)), np.zeros((0, ns, nv))
                hess = np.zeros((0, ns, nv, nv))
        # φ_a = Σ_b N_b C_ba
        value = value @ self.C
        grad = np.einsum("pbn,ba->pan", grad, self.C)
        hess = np.einsum("pbmn,ba->pamn", hess, self.C)
        g = layout.sum_at_functions(cells, value)
        self.covered = layout.on_cells(cells)
        G_g = assemble_blocks(layout, cells, self.dofs, dofs, grad)
        return g, G_g, {"cells": cells, "dofs": dofs, "hess": hess, "value": value}

    def _gap_hessian(self, data: dict, Fg: FloatArray) -> PETSc.Mat:
        blocks = np.einsum("pa,pamn->pmn", Fg[data["cells"]], data["hess"])
        return assemble_global_blocks(self.dofs, data["dofs"], data["dofs"], blocks)
