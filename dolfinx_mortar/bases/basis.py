"""The six mortar bases for the contact pressure on a slave surface (docs/DESIGN.md, §Bases).

For every kind, ``M_A`` is represented through the slave basis ``N``:

- local kinds (LmLS, LmLS*, LcLS*, LcLS): per element ``M_A|_e = Σ_B C^e_BA N_B``
  with ``C^e`` from the C++ kernel :func:`_kernels.basis_coefficients`;
- global kinds: ``M = N L⁻¹`` (GLS) and ``M = N L⁻¹ W`` (GLS*), applied through a
  sparse factorization of ``L``, never a dense inverse.

A surface is anything with ``layout``, ``cells``, ``description``,
``tabulate(quadrature_degree)``, ``default_quadrature_degree()`` and
``locate(points)``: :class:`~dolfinx_mortar.surfaces.nurbs.BSplineCurve`,
:class:`~dolfinx_mortar.surfaces.nurbs.BSplineSurface`,
:class:`~dolfinx_mortar.surfaces.lagrange.LagrangeSurface` and the facet surfaces of
:mod:`dolfinx_mortar.surfaces.facet_surface`.
"""
from __future__ import annotations

import time
from typing import Any, Callable, Optional, Union

import numpy as np
import numpy.typing as npt

from dolfinx_mortar import _kernels
from dolfinx_mortar.kinds import BasisKind, KindLike, is_global, kind_name, parse_kind
from dolfinx_mortar.layout import MassMatrixSolver
from dolfinx_mortar.surfaces.tabulation import Tabulation
from dolfinx_mortar.tolerance import length_scale, zero_length

FloatArray = npt.NDArray[np.float64]
FieldLike = Union[Callable[[FloatArray], FloatArray], FloatArray]


class MortarBasis:
    """One mortar basis kind on one slave surface.

    Parameters
    ----------
    kind
        A kind name or alias (see :func:`dolfinx_mortar.kinds.parse_kind`).
    surface
        The slave surface.
    quadrature_degree
        Degree of the quadrature rule for ``L``, ``W`` and the integrals of
        fields; default: the surface's.

    Raises
    ------
    ValueError
        For an unknown kind, an empty surface, a degenerate element, or lumped
        weights that do not allow the kind (e.g. quadratic triangles without
        the transformed basis).
    """

    def __init__(self, kind: KindLike, surface: Any,
                 quadrature_degree: Optional[int] = None):
        clock = time.perf_counter()
        self.kind: BasisKind = parse_kind(kind)
        self.surface = surface
        self.layout = surface.layout
        self.cells = np.asarray(surface.cells, dtype=np.int64)
        num_elements = self.layout.comm.allreduce(len(self.cells))
        if num_elements == 0:
            raise ValueError(f"the slave surface ({surface.description}) has no elements")
        self.quadrature_degree = quadrature_degree or surface.default_quadrature_degree()
        tab = surface.tabulate(self.quadrature_degree)
        self.tabulation: Tabulation = tab
        self._element_mass: Optional[FloatArray] = None
        #: W^e_A = ∫_e N_A dA, shape (cells, functions)
        self.element_weights = _kernels.element_integrals(tab.phi, tab.weights)
        #: W_A = ∫ N_A dA at owned and ghost functions
        self.lumped_weights = self.layout.sum_at_functions(self.cells, self.element_weights)
        #: each function's own length, (∫ N_A ds)^(1/tdim) with the facets'
        #: measure alone (no 2πr on an axisymmetric surface): the one scale of
        #: the geometric decisions at a node (near contact, stiffened nodes)
        self.node_lengths = np.power(np.maximum(self.layout.sum_at_functions(
            self.cells, _kernels.element_integrals(tab.phi, tab.ds_weights)), 0.0),
            1.0 / surface.tdim)
        nodal_at_cells = self.lumped_weights[self.cells]
        gdim = tab.points.shape[2]
        scale = length_scale(tab.points.reshape(-1, gdim), self.layout.comm)
        try:
            geometric = (self.element_weights if tab.geometric_weights is None
                         else _kernels.element_integrals(tab.phi, tab.geometric_weights))
            _kernels.check_element_measures(geometric, tab.points, surface.tdim, scale)
            if tab.geometric_weights is not None:
                # every rank raises, so that none waits in a collective
                messages = self.layout.comm.allgather(
                    _on_axis_message(self.element_weights, geometric, scale))
                if any(messages):
                    raise ValueError(next(m for m in messages if m))
            _kernels.check_lumped_weights(self.kind, self.element_weights, nodal_at_cells)
            if is_global(self.kind):
                self.coefficients = None
                mass = self.layout.assemble_matrix(self.cells, self.element_mass)
                mass.setOption(mass.Option.SYMMETRIC, True)
                self.mass_solver: Optional[MassMatrixSolver] = MassMatrixSolver(self.layout, mass)
            else:
                self.mass_solver = None
                dual = self.kind in (BasisKind.LcLS_star, BasisKind.LcLS)
                mass = self.element_mass if dual else np.zeros((0, 0, 0))
                self.coefficients = _kernels.basis_coefficients(
                    self.kind, mass, self.element_weights, nodal_at_cells)
        except ValueError as err:
            raise ValueError(f"{surface.description}: {err}{_hint(surface)}") from None
        #: wall time in seconds of the construction on this rank (benchmarks)
        self.construction_time = time.perf_counter() - clock

    @property
    def element_mass(self) -> FloatArray:
        """L^e_AB = ∫_e N_A N_B dA, shape (cells, functions, functions).

        Computed on first use: the lumped kinds never need it, and at 1e6
        quadratic elements it is 0.65 GB.
        """
        if self._element_mass is None:
            tab = self.tabulation
            self._element_mass = _kernels.element_mass_matrices(tab.phi, tab.weights)
        return self._element_mass

    # -- integrals ---------------------------------------------------------------
    def element_integrals(self, f: FieldLike) -> FloatArray:
        """∫_e N_B f dA per element, shape (cells, functions).

        ``f`` is a callable of x (shape (gdim, n), DOLFINx style) or an array of
        values at the quadrature points, shape (cells, points).
        """
        tab = self.tabulation
        values = tab.values_of(f) if callable(f) else np.asarray(f, dtype=np.float64)
        if values.shape != tab.weights.shape:
            raise ValueError(f"field values have shape {values.shape}, expected "
                             f"{tab.weights.shape} (cells, quadrature points)")
        return _kernels.element_integrals(tab.phi, tab.weights * values)

    def nodal_values(self, f: FieldLike) -> FloatArray:
        """``f_A = ∫ M_A f dA`` at the owned and ghost functions of this rank."""
        g = self.element_integrals(f)
        if self.mass_solver is None:
            contributions = np.einsum("cba,cb->ca", self.coefficients, g)
            return self.layout.sum_at_functions(self.cells, contributions)
        x = self.mass_solver.solve(self.layout.sum_at_functions(self.cells, g))
        return x * self.lumped_weights if self.kind == BasisKind.GLS_star else x

    # -- fields on the surface ---------------------------------------------------
    def mortar_coefficients(self, nodal: FloatArray) -> FloatArray:
        """Per-element slave coefficients ``q^e`` of ``Σ_A M_A p_A``.

        On element e, ``Σ_A M_A p_A = Σ_B N_B q^e_B``; shape (cells, functions).
        Discontinuous across elements for the dual kinds.
        """
        nodal = np.asarray(nodal, dtype=np.float64)
        if self.mass_solver is None:
            return np.einsum("cba,ca->cb", self.coefficients, nodal[self.cells])
        rhs = nodal * self.lumped_weights if self.kind == BasisKind.GLS_star else nodal
        return self.mass_solver.solve(rhs)[self.cells]

    def evaluate(self, cells: npt.ArrayLike, phi: FloatArray) -> FloatArray:
        """All ``M_A`` at points, given their cells and slave basis values there.

        Returns a dense array (points, local functions). For GLS and GLS* this
        needs one solve per point and all functions on one rank.
        """
        cells = np.asarray(cells, dtype=np.int64)
        phi = np.asarray(phi, dtype=np.float64)
        n = self.layout.size_local
        out = np.zeros((len(cells), n))
        rows = np.repeat(np.arange(len(cells)), self.cells.shape[1])
        if self.mass_solver is None:
            values = np.einsum("rb,rba->ra", phi, self.coefficients[cells])
            np.add.at(out, (rows, self.cells[cells].ravel()), values.ravel())
            return out
        if self.layout.comm.size > 1:
            raise NotImplementedError(
                f"dense evaluation of the global kind {kind_name(self.kind)} needs the whole "
                "surface on one rank; use mortar_coefficients() in parallel")
        np.add.at(out, (rows, self.cells[cells].ravel()), phi.ravel())
        M = np.array([self.mass_solver.solve(row) for row in out])  # M = N L⁻¹ (L = Lᵀ)
        return M * self.lumped_weights[None, :] if self.kind == BasisKind.GLS_star else M


def _on_axis_message(weighted: FloatArray, geometric: FloatArray,
                     scale: float) -> Optional[str]:
    """An axisymmetric facet on the axis (r = 0 all along) sweeps no surface:
    its measure ∫2πr ds is zero against its length times the geometry's scale."""
    swept = weighted.sum(axis=1)
    on_axis = swept <= zero_length(scale) * 2 * np.pi * geometric.sum(axis=1)
    if not np.any(on_axis):
        return None
    c = int(np.flatnonzero(on_axis)[0])
    return (f"slave facet {c} lies on the axis r = 0: as an axisymmetric surface it sweeps "
            "no area (tag only the facets that touch)")


def _hint(surface: Any) -> str:
    reference = getattr(surface, "reference", None)
    if (reference is not None and reference.degree == 2 and reference.cell != "interval"
            and reference.transform is None):
        return ("; quadratic triangle vertex functions integrate to zero and 8-node "
                "quad vertex functions to a negative value: pass "
                "quadratic_transform=True to use the transformed quadratic basis")
    return ""


# -- convenience functions (one basis per call) -----------------------------------
def evaluate(kind: KindLike, surface: Any, x: Any,
             quadrature_degree: Optional[int] = None) -> FloatArray:
    """Values of all ``M_A`` at points ``x``, shape (points, functions).

    ``x`` are parameters in [0, 1] (or (n, 2) for a surface) for B-splines and
    NURBS, and ``(cells, X_reference)`` for Lagrange surfaces.
    """
    basis = MortarBasis(kind, surface, quadrature_degree)
    cells, phi = surface.locate(x)
    return basis.evaluate(cells, phi)


def nodal_pressures(kind: KindLike, surface: Any, p_raw: FieldLike,
                    quadrature_degree: Optional[int] = None) -> FloatArray:
    """Nodal pressures ``p_A = ∫ M_A p dA`` of a raw pressure field ``p``."""
    return MortarBasis(kind, surface, quadrature_degree).nodal_values(p_raw)


def smoothed_pressure(surface: Any, nodal: FloatArray, x: Any) -> FloatArray:
    """``p̂ = Σ_A N_A p_A`` at points ``x`` (same conventions as :func:`evaluate`)."""
    cells, phi = surface.locate(x)
    return np.einsum("rb,rb->r", phi, np.asarray(nodal)[np.asarray(surface.cells)[cells]])


def mortar_pressure(kind: KindLike, surface: Any, nodal: FloatArray, x: Any,
                    quadrature_degree: Optional[int] = None) -> FloatArray:
    """``p* = Σ_A M_A p_A`` at points ``x`` (same conventions as :func:`evaluate`)."""
    basis = MortarBasis(kind, surface, quadrature_degree)
    cells, phi = surface.locate(x)
    return np.einsum("rb,rb->r", phi, basis.mortar_coefficients(nodal)[cells])
