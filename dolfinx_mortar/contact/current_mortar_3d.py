"""The current-configuration mortar gap against an elastic master in 3D (P1 triangles).

The same construction as ``mortar_integrals.cpp`` for flat triangles, in
:class:`~dolfinx_mortar.contact.jet.Jet` arithmetic: the slave triangle's plane, the
master triangle projected onto it and clipped (Sutherland–Hodgman, the
kernel's tolerances and merging), the clip polygon fanned from its centroid,
each quadrature point mapped back to both triangles along the plane's normal,
and ``d = (x_s − x_m)·n̂`` with n̂ the interpolated averaged nodal normal. The
clipping decisions (which vertex is inside, which crossing exists) are taken
on the values; the polygon's vertices — slave nodes, master nodes or edge
crossings — carry their exact derivatives. A pair's variables are the nodes of
every slave triangle around its three vertices (the averaged normals) and the
master triangle's nodes.

The polygons differ from pair to pair, so pairs are processed one at a time:
this costs about 10–20 ms per pair in Python (see the README's measurements).
"""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt

from dolfinx_mortar.contact.jet import Jet, dot, stack
from dolfinx_mortar.mortar.coupling import MortarCoupling, gather_surface

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


def _sub(a: list, b: list) -> list:
    return [x - y for x, y in zip(a, b)]


def _cross(a: list, b: list) -> list:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _unit(v: list) -> list:
    length = dot(v, v).sqrt()
    return [c / length for c in v]


def _value(x) -> float:
    return float(x.value[0]) if isinstance(x, Jet) else float(x)


def signed_area(polygon: list) -> Jet:
    """Signed area of a planar polygon (shoelace formula), positive counter-clockwise."""
    total = 0.0
    for i, p in enumerate(polygon):
        q = polygon[(i + 1) % len(polygon)]
        total = total + (p[0] * q[1] - q[0] * p[1])
    return total * 0.5


def _longest_edge(polygon: list) -> float:
    return max(float(np.hypot(_value(q[0]) - _value(p[0]), _value(q[1]) - _value(p[1])))
               for p, q in zip(polygon, polygon[1:] + polygon[:1]))


def _classify(s, tolerance: float) -> int:
    """+1 inside, -1 outside, 0 on the line (within the tolerance)."""
    v = _value(s)
    return 1 if v > tolerance else (-1 if v < -tolerance else 0)


def clip_polygon(subject: list, clip: list, tolerance: float) -> list:
    """``clip_polygon`` of ``clipping.cpp`` on 2D points of Jets: the same
    decisions, taken on the values, and the same merging of close points.

    Points within ``tolerance`` of a clip line are on it: kept, and never the
    end of a crossing, so a crossing lies strictly inside its edge (t in (0, 1))."""
    output = list(subject)
    for e in range(len(clip)):
        if not output:
            break
        a, b = clip[e], clip[(e + 1) % len(clip)]
        ex, ey = b[0] - a[0], b[1] - a[1]
        length = (ex * ex + ey * ey).sqrt()
        if _value(length) <= tolerance:
            continue

        def side(p):
            return (ex * (p[1] - a[1]) - ey * (p[0] - a[0])) / length

        points, output = output, []
        for i, p in enumerate(points):
            q = points[(i + 1) % len(points)]
            sp, sq = side(p), side(q)
            cp, cq = _classify(sp, tolerance), _classify(sq, tolerance)
            if cp >= 0:
                output.append(p)
            if cp * cq < 0:
                t = sp / (sp - sq)
                output.append([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])])

    def distance(p, q) -> float:
        return float(np.hypot(_value(p[0]) - _value(q[0]), _value(p[1]) - _value(q[1])))

    merged: list = []
    for p in output:
        if not merged or distance(p, merged[-1]) > tolerance:
            merged.append(p)
    while len(merged) > 1 and distance(merged[0], merged[-1]) <= tolerance:
        merged.pop()
    return merged


def _project_on_triangle(nodes: list, x: list, e1: list, e2: list) -> tuple:
    """Reference coordinates of the point of a flat triangle whose offset from x
    is normal to the plane (e1, e2): a 2×2 linear system, solved exactly."""
    t1, t2, r = _sub(nodes[1], nodes[0]), _sub(nodes[2], nodes[0]), _sub(x, nodes[0])
    a11, a12, a21, a22 = dot(t1, e1), dot(t2, e1), dot(t1, e2), dot(t2, e2)
    b1, b2 = dot(r, e1), dot(r, e2)
    det = a11 * a22 - a12 * a21
    return (b1 * a22 - a12 * b2) / det, (a11 * b2 - b1 * a21) / det


def pair_gap_3d(values: FloatArray, normal_cells: list, num_slave_nodes: int,
                points: FloatArray, weights: FloatArray, zero: float,
                opposing_normals_only: bool = True) -> Optional[list]:
    """``c_a = ∫ N_a d`` of one slave–master triangle pair, as Jets.

    Parameters
    ----------
    values
        The pair's variables: the coordinates of its ``num_slave_nodes`` slave
        patch nodes (the slave triangle's three first), then of the master
        triangle's three nodes, flattened.
    normal_cells
        For each slave vertex, the triangles around it as triples of patch
        node indices (the averaged normal's cells).
    points, weights
        The triangle rule on each piece of the clip polygon's fan.
    zero
        The zero length of the kernel's decisions
        (:attr:`MortarCoupling.zero_length`).

    Returns None when the pair does not overlap.
    """
    v = Jet.variables(values[None, :])
    nodes = [v[3 * i:3 * i + 3] for i in range(len(values) // 3)]
    own, master = nodes[:3], nodes[num_slave_nodes:num_slave_nodes + 3]
    # every triangle's area-weighted normal at once (a batch over the patch's
    # triangles), then the vertex averages, as the kernel's size-weighted ones
    unique = sorted({cell for cells in normal_cells for cell in cells})
    corners = [[stack([nodes[cell[k]][c] for cell in unique]) for c in range(3)]
               for k in range(3)]
    cell_normals = _cross(_sub(corners[1], corners[0]), _sub(corners[2], corners[0]))
    normals = []
    for cells in normal_cells:
        rows = [unique.index(cell) for cell in cells]
        normals.append(_unit([n.take(rows).sum() for n in cell_normals]))

    centre = [(own[0][k] + own[1][k] + own[2][k]) * (1.0 / 3.0) for k in range(3)]
    normal = _unit(_cross(_sub(own[1], own[0]), _sub(own[2], own[0])))
    e1 = _sub(own[1], own[0])
    along = dot(e1, normal)
    e1 = _unit([c - along * n for c, n in zip(e1, normal)])
    e2 = _cross(normal, e1)

    def plane(p):
        r = _sub(p, centre)
        return [dot(r, e1), dot(r, e2)]

    if opposing_normals_only:
        m_normal = _cross(_sub(master[1], master[0]), _sub(master[2], master[0]))
        if _value(dot(m_normal, normal)) >= 0:
            return None
    slave_polygon = [plane(p) for p in own]
    master_polygon = [plane(p) for p in master]
    if _value(signed_area(master_polygon)) < 0:
        master_polygon.reverse()
    clipped = clip_polygon(slave_polygon, master_polygon, zero)
    # no wider than the zero length: a segment or a point (the kernel's test)
    if len(clipped) < 3 or not 2 * _value(signed_area(clipped)) > zero * _longest_edge(clipped):
        return None
    m = len(clipped)
    g = [sum((q[k] for q in clipped[1:]), clipped[0][k]) * (1.0 / m) for k in range(2)]
    # the fan's triangles (positive ones, as the kernel) × the rule's points: one batch
    fan = []
    for i in range(m):
        a, b = _sub(clipped[i], g), _sub(clipped[(i + 1) % m], g)
        twice_area = a[0] * b[1] - a[1] * b[0]
        if _value(twice_area) > 0:
            fan.append((a, b, twice_area))
    if not fan:
        return None
    nq = len(weights)
    entry = np.repeat(np.arange(len(fan)), nq)
    X0, X1 = np.tile(points[:, 0], len(fan)), np.tile(points[:, 1], len(fan))
    a = [stack([t[0][k] for t in fan]).take(entry) for k in range(2)]
    b = [stack([t[1][k] for t in fan]).take(entry) for k in range(2)]
    twice_area = stack([t[2] for t in fan]).take(entry)
    u = [g[k] + a[k] * X0 + b[k] * X1 for k in range(2)]
    x = [centre[k] + e1[k] * u[0] + e2[k] * u[1] for k in range(3)]
    s0, s1 = _project_on_triangle(own, x, e1, e2)
    m0, m1 = _project_on_triangle(master, x, e1, e2)
    Ns = [1.0 - s0 - s1, s0, s1]
    Nm = [1.0 - m0 - m1, m0, m1]

    def interpolate(N: list, values: list) -> list:
        return [N[0] * values[0][k] + N[1] * values[1][k] + N[2] * values[2][k]
                for k in range(3)]

    d = dot(_sub(interpolate(Ns, own), interpolate(Nm, master)), _unit(interpolate(Ns, normals)))
    weighted = d * twice_area * np.tile(weights, len(fan))
    return [(weighted * N).sum() for N in Ns]


class TrianglePatches:
    """For every local slave triangle: the nodes its averaged normals depend on.

    Built once from the gathered slave surface (the triangles around a vertex
    may live on other ranks).
    """

    def __init__(self, slave):
        copy = gather_surface(slave, slave.x)
        ids = copy.global_ids[copy.cells]                        # (all cells, 3)
        comm = slave.layout.comm
        first = comm.scan(len(slave.cells)) - len(slave.cells)
        around: dict[int, list] = {}
        for c, row in enumerate(ids):
            for node in row:
                around.setdefault(int(node), []).append(c)
        #: per local cell: gathered cells of the patch, node ids, node sources
        self.node_ids: list = []
        self.sources: list = []        # (gathered cell, position) of each patch node
        self.normal_cells: list = []
        for i in range(len(slave.cells)):
            own = first + i
            order = {int(n): k for k, n in enumerate(ids[own])}
            sources = [(own, k) for k in range(3)]
            normal_cells = []
            for node in ids[own]:
                cells = []
                for c in around[int(node)]:
                    triple = []
                    for position, other in enumerate(ids[c]):
                        if int(other) not in order:
                            order[int(other)] = len(order)
                            sources.append((c, position))
                        triple.append(order[int(other)])
                    cells.append(tuple(triple))
                normal_cells.append(cells)
            self.node_ids.append(np.array(list(order), dtype=np.int64))
            self.sources.append(np.array(sources, dtype=np.int64))
            self.normal_cells.append(normal_cells)


def pair_jets_3d(patches: TrianglePatches, slave, u_nodes: FloatArray,
                 coupling: MortarCoupling, points: FloatArray, weights: FloatArray
                 ) -> tuple[FloatArray, FloatArray, FloatArray, npt.NDArray[np.int64]]:
    """Values (pairs, 3), gradients (pairs, 3, nv), Hessians (pairs, 3, nv, nv)
    and global dofs (pairs, nv) of every pair's ``∫ N_a d``; nv is the largest
    variable count on this rank (shorter pairs are padded with unused slots)."""
    copy = gather_surface(slave, slave.x + u_nodes)
    gathered = copy.x.reshape(-1, 3, 3)
    master = coupling.master_copy
    pairs = coupling.pairs
    widths = [3 * (len(patches.node_ids[s]) + 3) for s in pairs[:, 0]]
    nv = max(widths, default=3 * 6)
    P = len(pairs)
    value, grad = np.zeros((P, 3)), np.zeros((P, 3, nv))
    hess, dofs = np.zeros((P, 3, nv, nv)), np.zeros((P, nv), dtype=np.int64)
    for p, (s, m) in enumerate(pairs):
        src = patches.sources[s]
        slave_x = gathered[src[:, 0], src[:, 1]]
        master_nodes = master.cells[m]
        x = np.concatenate([slave_x, master.x[master_nodes]]).ravel()
        ids = np.concatenate([patches.node_ids[s], master.global_ids[master_nodes]])
        w = len(x)
        node_dofs = (ids[:, None] * 3 + np.arange(3)).ravel()
        dofs[p, :w] = node_dofs
        dofs[p, w:] = node_dofs[0]
        c = pair_gap_3d(x, patches.normal_cells[s], len(patches.node_ids[s]), points, weights,
                        coupling.zero_length)
        if c is None:
            continue
        for a, ca in enumerate(c):
            if isinstance(ca, Jet):
                value[p, a] = ca.value[0]
                grad[p, a, :w] = ca.grad[0]
                hess[p, a, :w, :w] = ca.hess[0]
    return value, grad, hess, dofs
