"""The demos' bulk laws beyond small-strain elasticity (the library's own is
:func:`dolfinx_mortar.small_strain.elastic.linear_elastic_residual`)."""
from __future__ import annotations

import ufl
from dolfinx import fem

from dolfinx_mortar.small_strain.axisymmetric import circumference, radius


def deformation_gradient(u: fem.Function, axisymmetric: bool = False) -> ufl.core.expr.Expr:
    """``F = I + ∇u``; ``axisymmetric``: the 3×3 F of a body of revolution in the
    (r, z) half-plane, with the hoop stretch ``1 + u_r/r``."""
    F = ufl.Identity(len(u)) + ufl.grad(u)
    if not axisymmetric:
        return F
    r = radius(u.function_space.mesh)
    return ufl.as_tensor([[F[0, 0], F[0, 1], 0.0],
                          [F[1, 0], F[1, 1], 0.0],
                          [0.0, 0.0, 1.0 + u[0] / r]])


def neo_hookean_energy(u: fem.Function, E, nu: float, axisymmetric: bool = False) -> ufl.Form:
    """The compressible neo-Hookean strain energy ``∫ ψ dx``,
    ``ψ = μ/2 (tr C − d) − μ ln J + λ/2 (ln J)²`` (plane strain in 2D);
    ``E`` may be a number or vary over the cells (a DG0 Function).
    ``axisymmetric``: a body of revolution in the (r, z) half-plane, ``∫ ψ 2πr dx``
    with the hoop stretch in F (the energy of the whole body, as the contact
    terms with ``axisymmetric=True`` count their forces)."""
    F = deformation_gradient(u, axisymmetric)
    d = F.ufl_shape[0]
    J = ufl.det(F)
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    psi = mu / 2 * (ufl.tr(F.T * F) - d) - mu * ufl.ln(J) + lmbda / 2 * ufl.ln(J) ** 2
    if axisymmetric:
        return psi * circumference(u.function_space.mesh) * ufl.dx
    return psi * ufl.dx


def neo_hookean_residual(u: fem.Function, E, nu: float, axisymmetric: bool = False) -> ufl.Form:
    """The first variation of :func:`neo_hookean_energy`."""
    v = ufl.TestFunction(u.function_space)
    return ufl.derivative(neo_hookean_energy(u, E, nu, axisymmetric), u, v)
