"""Lagrange slave surfaces: P1/P2 lines, P1/P2 triangles, Q1/Q2 (9-node) and
8-node serendipity quadrilaterals, tabulated through Basix.

Nodes of each cell follow Basix's reference ordering (vertices, then edges, then
the interior), which is the ordering DOLFINx uses for facet closures.
"""
from __future__ import annotations

from functools import cached_property
from typing import Optional

import basix
import numpy as np
import numpy.typing as npt

from dolfinx_mortar import _kernels
from dolfinx_mortar.errors import DegenerateGeometryError
from dolfinx_mortar.layout import NodeLayout
from dolfinx_mortar.surfaces.tabulation import Tabulation, measure_from_tangents
from dolfinx_mortar.tolerance import GEOMETRIC_TOLERANCE, length_scale, zero_length

FloatArray = npt.NDArray[np.float64]

_CELL_TYPES = {"interval": basix.CellType.interval,
               "triangle": basix.CellType.triangle,
               "quadrilateral": basix.CellType.quadrilateral}

_FACET_TYPES = {("interval", 1, False): _kernels.FacetType.P1_line,
                ("interval", 2, False): _kernels.FacetType.P2_line,
                ("triangle", 1, False): _kernels.FacetType.P1_triangle,
                ("triangle", 2, False): _kernels.FacetType.P2_triangle,
                ("quadrilateral", 1, False): _kernels.FacetType.Q1_quadrilateral,
                ("quadrilateral", 2, False): _kernels.FacetType.Q2_quadrilateral,
                ("quadrilateral", 2, True): _kernels.FacetType.Q8_quadrilateral}

# Reflections of the reference cell in Basix ordering: lines swap their ends;
# triangles and quadrilaterals swap vertices 1 and 2, and with them the edges
# that meet there.
_REFLECTIONS = {("interval", 1, False): [1, 0],
                ("interval", 2, False): [1, 0, 2],
                ("triangle", 1, False): [0, 2, 1],
                ("triangle", 2, False): [0, 2, 1, 3, 5, 4],
                ("quadrilateral", 1, False): [0, 2, 1, 3],
                ("quadrilateral", 2, False): [0, 2, 1, 3, 5, 4, 7, 6, 8],
                ("quadrilateral", 2, True): [0, 2, 1, 3, 5, 4, 7, 6]}

#: α of the transformed quadratic basis (Popp, Gitterle, Gee, Wall 2010;
#: Wohlmuth, Popp, Gee, Wall 2012): Ñ_v = N_v + α Σ_{edges e ∋ v} N_e,
#: Ñ_e = (1 - 2α) N_e. With α = 1/5 every Ñ has a positive integral on
#: 6-node triangles (2A/15, A/5), 8-node quads (A/20, A/5) and axisymmetric
#: P2 lines with a vertex on the axis (2πh²/15 there).
QUADRATIC_TRANSFORM_ALPHA = 0.2


class ReferenceLagrange:
    """Nodal Lagrange basis on a reference facet, optionally transformed.

    Parameters
    ----------
    cell
        ``"interval"``, ``"triangle"`` or ``"quadrilateral"``.
    degree
        1 or 2.
    serendipity
        Use the 8-node serendipity quadrilateral instead of the 9-node one.
    quadratic_transform
        Apply the transformed quadratic basis (for quadratic triangles and
        quads), which makes every ∫N_A positive so that the lumped and dual kinds
        are defined.
    """

    def __init__(self, cell: str, degree: int, serendipity: bool = False,
                 quadratic_transform: bool = False):
        if cell not in _CELL_TYPES:
            raise ValueError(f"unknown facet cell '{cell}'; expected one of "
                             f"{sorted(_CELL_TYPES)}")
        if degree not in (1, 2):
            raise ValueError(f"Lagrange slave facets of degree {degree} are not "
                             "supported (degree 1 or 2)")
        if serendipity and (cell != "quadrilateral" or degree != 2):
            raise ValueError("serendipity elements are the 8-node quadrilateral only")
        self.cell = cell
        self.cell_type = _CELL_TYPES[cell]
        self.degree = degree
        self.serendipity = serendipity
        self.tdim = len(basix.topology(self.cell_type)) - 1
        if serendipity:
            self._element = basix.create_element(
                basix.ElementFamily.serendipity, self.cell_type, 2,
                basix.LagrangeVariant.legendre, basix.DPCVariant.legendre, False)
            # Basix's serendipity dofs are moments; make the basis nodal at the
            # vertices and edge midpoints.
            nodes = self._serendipity_nodes()
            V = self._element.tabulate(0, nodes)[0, :, :, 0]
            self._to_nodal = np.linalg.inv(V)
            self.nodes = nodes
        else:
            self._element = basix.create_element(
                basix.ElementFamily.P, self.cell_type, degree,
                basix.LagrangeVariant.equispaced, False)
            self._to_nodal = None
            self.nodes = self._element.points
        self.num_functions = len(self.nodes)
        self.facet_type = _FACET_TYPES[(cell, degree, serendipity)]
        #: node permutation that reflects the reference cell (flips the normal)
        self.reflection = np.array(_REFLECTIONS[(cell, degree, serendipity)])
        self.transform = self._quadratic_transform() if quadratic_transform else None
        names = {("interval", 1): "P1 line", ("interval", 2): "P2 line",
                 ("triangle", 1): "P1 triangle", ("triangle", 2): "P2 (6-node) triangle",
                 ("quadrilateral", 1): "Q1 quadrilateral",
                 ("quadrilateral", 2): "Q2 (9-node) quadrilateral"}
        self.name = ("8-node serendipity quadrilateral" if serendipity
                     else names[(cell, degree)])
        if quadratic_transform:
            self.name += " with the transformed quadratic basis"

    def _serendipity_nodes(self) -> FloatArray:
        vertices = basix.geometry(self.cell_type)
        edges = basix.topology(self.cell_type)[1]
        mids = np.array([vertices[e].mean(axis=0) for e in edges])
        return np.vstack([vertices, mids])

    def standard_coefficients(self, C: FloatArray) -> FloatArray:
        """Per-cell coefficients (cells, nd, nd) in the standard basis: ``T C`` (or ``C``)."""
        return C if self.transform is None else np.einsum("ab,cbd->cad", self.transform, C)

    def _quadratic_transform(self) -> FloatArray:
        if self.degree != 2:
            raise ValueError("the transformed quadratic basis applies to quadratic facets only")
        if self.cell == "quadrilateral" and not self.serendipity:
            raise ValueError("9-node quadrilaterals need no transformed basis: all "
                             "their ∫N_A are positive")
        nv = len(basix.geometry(self.cell_type))
        edges = basix.topology(self.cell_type)[1]
        a = QUADRATIC_TRANSFORM_ALPHA
        T = np.eye(self.num_functions)
        for k, edge in enumerate(edges):
            T[nv + k, nv + k] = 1.0 - 2.0 * a
            for v in edge:
                T[nv + k, v] = a
        return T

    def tabulate(self, X: FloatArray, transformed: bool = True) -> tuple[FloatArray, FloatArray]:
        """Values (n, nd) and reference gradients (n, tdim, nd) at points X.

        The gradients are of the untransformed basis: they serve the geometry
        map, which is always isoparametric in the standard basis.
        """
        X = np.asarray(X, dtype=np.float64)
        if len(X) == 0:  # Basix aborts the process on an empty point set
            nd = self.num_functions
            return np.zeros((0, nd)), np.zeros((0, self.tdim, nd))
        t = self._element.tabulate(1, X)[..., 0]
        if self._to_nodal is not None:
            t = t @ self._to_nodal
        values, grads = t[0], np.moveaxis(t[1:], 0, 1)
        if transformed and self.transform is not None:
            values = values @ self.transform
        return values, grads


class LagrangeSurface:
    """A slave surface made of Lagrange facets, given by arrays.

    Parameters
    ----------
    cell
        ``"interval"``, ``"triangle"`` or ``"quadrilateral"``.
    degree
        1 or 2.
    x
        Node coordinates, shape (nodes, gdim), with gdim > tdim.
    cells
        Local node indices of each facet in Basix ordering, shape (cells, nd).
    layout
        How the nodes are distributed; ``None`` means serial.
    serendipity, quadratic_transform
        See :class:`ReferenceLagrange`.
    axisymmetric
        Lines in the (r, z) half-plane r ≥ 0 standing for the surfaces they
        sweep about the axis r = 0: every integral is taken with the measure
        2πr ds (docs/AXISYMMETRIC.md). P2 lines then always use the transformed
        quadratic basis: a P2 vertex on the axis has ∫N 2πr ds = 0 (exactly, on
        a straight facet), which leaves the lumped and dual kinds undefined;
        transformed, it is 2πh²/15 > 0.
    """

    #: the nodes of each facet's cell of the volume mesh (local, as ``cells``), where the
    #: surface was taken from one (:func:`~dolfinx_mortar.surfaces.facet_surface.facet_surface`)
    volume_nodes: Optional[npt.NDArray[np.int64]] = None
    #: each cell's facet tag, where the surface was taken from tagged facets
    #: (:func:`~dolfinx_mortar.surfaces.facet_surface.facet_surface`)
    cell_tags: Optional[npt.NDArray[np.int32]] = None

    def __init__(self, cell: str, degree: int, x: npt.ArrayLike, cells: npt.ArrayLike,
                 layout: Optional[NodeLayout] = None, serendipity: bool = False,
                 quadratic_transform: bool = False, check_cells: bool = True,
                 axisymmetric: bool = False):
        quadratic_transform = quadratic_transform or (axisymmetric and degree == 2)
        self.reference = ReferenceLagrange(cell, degree, serendipity, quadratic_transform)
        self.x = np.asarray(x, dtype=np.float64)
        self.cells = np.asarray(cells, dtype=np.int64)
        if self.x.ndim != 2 or self.x.shape[1] <= self.reference.tdim:
            raise ValueError(f"node coordinates must have shape (nodes, gdim) with gdim > "
                             f"{self.reference.tdim} for {cell} facets, got {self.x.shape}")
        if self.cells.ndim != 2 or self.cells.shape[1] != self.reference.num_functions:
            raise ValueError(f"{self.reference.name} cells need "
                             f"{self.reference.num_functions} nodes each, got cells of "
                             f"shape {self.cells.shape}")
        if not np.all(np.isfinite(self.x)):
            raise ValueError("node coordinates contain NaN or infinite values")
        self.layout = layout or NodeLayout.serial(len(self.x))
        if len(self.x) != self.layout.size_local:
            raise ValueError(f"{len(self.x)} node coordinates for a layout of "
                             f"{self.layout.size_local} local nodes")
        if len(self.cells) and (self.cells.min() < 0 or self.cells.max() >= len(self.x)):
            raise ValueError("cell node indices out of range")
        self.tdim = self.reference.tdim
        self.gdim = self.x.shape[1]
        self.axisymmetric = bool(axisymmetric)
        self.description = self.reference.name + (" (axisymmetric)" if axisymmetric else "")
        if check_cells:  # collective: callers that skip it may call on some ranks only
            if axisymmetric:
                self._check_half_plane()
            self._check_degenerate_cells()

    def _check_half_plane(self) -> None:
        """Axisymmetric surfaces are lines in r ≥ 0: a node at r < 0 (beyond
        round-off, judged against the geometry's scale) is a mesh on the wrong
        side of the axis, or not an (r, z) mesh at all."""
        if self.gdim != 2 or self.tdim != 1:
            raise ValueError(f"axisymmetric surfaces are lines in the (r, z) plane, got "
                             f"{self.reference.name} facets in {self.gdim}D")
        comm = self.layout.comm
        scale = length_scale(self.x, comm)
        r_min = min(comm.allgather(float(np.min(self.x[:, 0], initial=np.inf))))
        if r_min < -zero_length(scale):
            raise ValueError(f"axisymmetric surface with a node at r = {r_min:.6g} < 0: the "
                             "(r, z) mesh must lie in r ≥ 0 (x is the radius, y the axis)")

    def check_displaced(self, displacement: FloatArray) -> None:
        """Raise :class:`~dolfinx_mortar.errors.DegenerateGeometryError` on every
        rank if the surface displaced by ``displacement`` (local nodes, gdim)
        has a degenerate cell, as :meth:`moved` would, without making it
        (collective)."""
        self._check_degenerate_cells(self.x + displacement)

    def _check_degenerate_cells(self, x: Optional[FloatArray] = None) -> None:
        """Refuse facets of zero size, and triangles or quadrilaterals of zero
        height (collinear vertices), judged against the geometry's scale.

        A zero-length cell measures 0, 5.6e-17 or 1.1e-16 at |x| = 1 depending
        on the CPU's BLAS kernels, so it cannot be caught by its measure
        being zero; downstream it gave dual coefficients of 1e16 or a
        singular factorization with no hint at the mesh.
        """
        comm = self.layout.comm
        x = self.x if x is None else x
        message = self._degenerate_cells_message(x) if len(self.cells) else None
        # every rank raises, so that none waits in a collective for the other
        messages = [m for m in comm.allgather(message) if m] if comm.size > 1 else [message]
        if messages and messages[0]:
            raise DegenerateGeometryError(messages[0])

    def _degenerate_cells_message(self, x: FloatArray) -> Optional[str]:
        nv = {"interval": 2, "triangle": 3, "quadrilateral": 4}[self.reference.cell]
        vertices = x[self.cells[:, :nv]]                           # (cells, nv, gdim)
        zero = zero_length(length_scale(x))
        offsets = vertices[:, :, None, :] - vertices[:, None, :, :]
        size = np.linalg.norm(offsets, axis=-1).max(axis=(1, 2))  # largest vertex distance
        bad = size <= zero
        what = "zero length" if self.tdim == 1 else "zero size"
        if self.tdim == 2 and not np.any(bad):
            # twice the area of the vertex polygon from its diagonals (Basix
            # quadrilateral order 0, 1, 3, 2), exact where sqrt(EG − F²) is not
            if nv == 3:
                d1, d2 = vertices[:, 1] - vertices[:, 0], vertices[:, 2] - vertices[:, 0]
            else:
                d1, d2 = vertices[:, 3] - vertices[:, 0], vertices[:, 2] - vertices[:, 1]
            twice_area = np.linalg.norm(np.cross(d1, d2), axis=-1)
            bad = twice_area / size <= zero      # the height over the longest distance
            what = "collinear vertices (zero height)"
        if not np.any(bad):
            return None
        c = int(np.flatnonzero(bad)[0])
        return (f"degenerate facet: cell {c} of the {self.description} surface has {what} "
                f"below {GEOMETRIC_TOLERANCE:g} × the geometry's length scale "
                f"(vertices {vertices[c].tolist()}); {int(np.sum(bad))} such cell(s) on this "
                "rank")

    @property
    def facet_type(self):
        """The kernels' :class:`FacetType` of the cells."""
        return self.reference.facet_type

    def cell_normals(self, x: Optional[FloatArray] = None) -> FloatArray:
        """Unit normal of each cell at each of its nodes, (cells, nodes, gdim).

        The normal follows the node ordering: (t_y, -t_x) in 2D, ∂x/∂X₀ × ∂x/∂X₁ in 3D.
        """
        x = self.x if x is None else x
        return _kernels.element_node_normals(self.facet_type, x,
                                             self.cells.astype(np.int32))

    @cached_property
    def owned_nodes(self) -> npt.NDArray[np.int64]:
        """The local nodes this rank owns on any rank's cells of this surface
        (:meth:`NodeLayout.owned_on_cells`; collective on first use, then kept:
        the friction Jacobian asks for them at every Newton iteration)."""
        return self.layout.owned_on_cells(self.cells)

    @cached_property
    def zero_length(self) -> float:
        """Lengths at or below this are zero on this surface: the geometric
        tolerance times its length scale over every rank (collective on first
        use; the coordinates do not change)."""
        return zero_length(length_scale(self.x, self.layout.comm))

    def moved(self, displacement: FloatArray) -> "LagrangeSurface":
        """The same surface with its nodes displaced (a new configuration)."""
        return self._like(self.x + displacement, self.cells, check_cells=True)

    def reflected(self, which: npt.ArrayLike) -> "LagrangeSurface":
        """The same surface with the cells marked in ``which`` reflected (normal flipped)."""
        cells = self.cells.copy()
        which = np.asarray(which, dtype=bool)
        cells[which] = cells[which][:, self.reference.reflection]
        # the same facets (checked already); callers reflect on some ranks only
        return self._like(self.x, cells, check_cells=False)

    def _like(self, x: FloatArray, cells: npt.NDArray, check_cells: bool) -> "LagrangeSurface":
        like = LagrangeSurface(self.reference.cell, self.reference.degree, x, cells,
                               layout=self.layout, serendipity=self.reference.serendipity,
                               quadratic_transform=self.reference.transform is not None,
                               check_cells=check_cells, axisymmetric=self.axisymmetric)
        like.volume_nodes = self.volume_nodes
        like.cell_tags = self.cell_tags
        return like

    @property
    def num_elements(self) -> int:
        return len(self.cells)

    @property
    def num_functions(self) -> int:
        return self.layout.size_local

    def default_quadrature_degree(self) -> int:
        # Exact for L^e on affine facets; two more for curved quadratic ones.
        return 2 * self.reference.degree + (2 if self.reference.degree > 1 else 0)

    def tabulate_at(self, cells: npt.NDArray[np.int64],
                    X: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Basis values, physical points and surface Jacobians at reference points.

        ``X`` has shape (n, tdim): one reference point per entry of ``cells``.
        """
        X = np.asarray(X, dtype=np.float64).reshape(-1, self.tdim)
        N, dN = self.reference.tabulate(X)
        N_geo, _ = self.reference.tabulate(X, transformed=False)
        coords = self.x[self.cells[cells]]  # (n, nd, gdim)
        origin = coords[:, :1, :]
        coords = coords - origin            # local: see tabulate
        x = origin[:, 0, :] + np.einsum("nk,nkg->ng", N_geo, coords)
        tangents = [np.einsum("nk,nkg->ng", dN[:, t, :], coords) for t in range(self.tdim)]
        return N, x, measure_from_tangents(tangents) * self.radial_factor(x)

    def tabulate(self, quadrature_degree: Optional[int] = None,
                 transformed: bool = True) -> Tabulation:
        """Basis values, weights·|J| and points at a Basix rule on every facet.

        ``transformed=False`` gives the standard Lagrange basis even when the
        surface uses the transformed quadratic basis (displacements are always
        interpolated in the standard one).
        """
        q = quadrature_degree or self.default_quadrature_degree()
        X, wq = basix.make_quadrature(self.reference.cell_type, q)
        N, dN = self.reference.tabulate(X, transformed=transformed)
        N_geo, _ = self.reference.tabulate(X, transformed=False)
        coords = self.x[self.cells]  # (nc, nd, gdim)
        # relative to each cell's first node: round-off of its size, not |x| (|J| at 1e8: 1e-5)
        origin = coords[:, :1, :]
        coords = coords - origin
        # matmul broadcasts over cells and is several times faster than einsum here
        points = origin + N_geo @ coords
        tangents = [dN[:, t, :] @ coords for t in range(self.tdim)]  # (nc, nq, gdim) each
        ds = measure_from_tangents(tangents) * wq[None, :]
        nc, nq = len(self.cells), len(X)
        phi = np.broadcast_to(N, (nc, nq, N.shape[1]))
        if not self.axisymmetric:
            return Tabulation(phi=np.ascontiguousarray(phi), weights=ds, points=points)
        return Tabulation(phi=np.ascontiguousarray(phi), weights=ds * self.radial_factor(points),
                          points=points, geometric_weights=ds)

    def radial_factor(self, x: FloatArray) -> FloatArray:
        """The factor of the measure at points x (..., gdim): 2πr on an
        axisymmetric surface (r clamped at 0: an axis node may sit at −1e-17),
        else 1."""
        if not self.axisymmetric:
            return np.ones(x.shape[:-1])
        return 2 * np.pi * np.maximum(x[..., 0], 0.0)

    def locate(self, points):
        """Lagrange surfaces take evaluation points as ``(cells, X_reference)``."""
        cells, X = points
        cells = np.asarray(cells, dtype=np.int64)
        N, _, _ = self.tabulate_at(cells, X)
        return cells, N
