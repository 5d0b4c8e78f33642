"""Contact against a rigid obstacle with the bases on the current slave surface.

``d = −φ(x + u)`` with φ the obstacle's exact signed distance: the obstacle
gives d and its first and second derivatives at the cells' current
quadrature points, and the kernel's Jets carry them through the area element
into ``ĝ_A = ∫ φ_A J d`` (:mod:`~dolfinx_mortar.contact.gap_sources.current.finite_deformation`).
"""
from __future__ import annotations

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar import _kernels
from dolfinx_mortar.contact.gap_sources.current.finite_deformation import (CurrentSurfaceGap, ObstaclePoints,
                                                       SourceGaps)
from dolfinx_mortar.contact.obstacles import RigidObstacle, relative_to
from dolfinx_mortar.contact.laws import PenaltyLaw
from dolfinx_mortar.kinds import BasisKind
from dolfinx_mortar.layout import assemble_blocks
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface

FloatArray = npt.NDArray[np.float64]


class CurrentObstacleGap(CurrentSurfaceGap):
    """Penalty contact with a rigid obstacle, bases on the current surface.

    ``d = −φ(x + u)`` with φ the obstacle's exact signed distance, integrated
    with the slave cell's own rule. Parameters as for
    :class:`CurrentSurfaceGap`, plus the ``obstacle``.
    """

    def __init__(self, slave: LagrangeSurface, obstacle: RigidObstacle, kind: BasisKind,
                 law: PenaltyLaw, quadrature_degree=None):
        if obstacle.gdim != slave.gdim:
            raise ValueError(f"a {obstacle.gdim}D obstacle cannot touch a {slave.gdim}D body")
        super().__init__(slave, kind, law, quadrature_degree)
        self.obstacle = obstacle

    def _obstacle_at(self, x: FloatArray) -> ObstaclePoints:
        # the points are needed here only: a master's gap has its own
        points = np.einsum("qb,cbi->cqi", self.N, x)
        nc, nq, gdim = points.shape
        flat = points.reshape(-1, gdim)
        # the points are relative to the origin, and so is the obstacle as it is now
        obstacle = relative_to(self.obstacle, self.origin)
        return ObstaclePoints(-obstacle.signed_distance(flat).reshape(nc, nq),
                              -obstacle.gradient(flat).reshape(nc, nq, gdim),
                              -obstacle.hessian(flat).reshape(nc, nq, gdim, gdim))

    def _gap(self, u_nodes: FloatArray, W: FloatArray,
             cells: _kernels.SurfaceCellDerivatives) -> SourceGaps:
        layout = self.slave.layout

        def summed(values: FloatArray, gradients: FloatArray
                   ) -> tuple[FloatArray, PETSc.Mat]:
            return (layout.sum_at_functions(self.slave.cells, values),
                    assemble_blocks(layout, self.slave.cells, self.dofs, self.cell_dofs,
                                    gradients))

        g, G_g = summed(cells.gap, cells.gap_gradient)
        source = SourceGaps(g, G_g, self.covered)
        if self.pointwise:
            # ⟨d⟩ and its derivative H(d)∇d at the same points (not split at d = 0)
            source.g_plus, source.G_g_plus = summed(cells.gap_plus, cells.gap_plus_gradient)
        return source
