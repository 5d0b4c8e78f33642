"""The library's own exception for geometry that cannot be evaluated."""
from __future__ import annotations


class DegenerateGeometryError(ValueError):
    """A contact surface with facets of zero size (collinear, collapsed or
    infinitely stretched).

    On a mesh the user gave, it names a meshing error. Inside Newton it means
    that a trial point has deformed the surface beyond what can be measured;
    :class:`~dolfinx_mortar.solver.nonlinear_problem.NonlinearContactProblem`
    then returns a NaN residual (a failed trial point, so that the line search
    shortens the step or the load step is cut back) and keeps the message in
    ``evaluation_error``.
    """
