"""The demos' bulk laws beyond small-strain elasticity (the library's own is
:func:`dolfinx_mortar.small_strain.elastic.linear_elastic_residual`)."""
from __future__ import annotations

import ufl
from dolfinx import fem


def neo_hookean_energy(u: fem.Function, E, nu: float) -> ufl.Form:
    """The compressible neo-Hookean strain energy ``∫ ψ dx``,
    ``ψ = μ/2 (tr C − d) − μ ln J + λ/2 (ln J)²`` (plane strain in 2D);
    ``E`` may be a number or vary over the cells (a DG0 Function)."""
    d = len(u)
    F = ufl.Identity(d) + ufl.grad(u)
    J = ufl.det(F)
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    psi = mu / 2 * (ufl.tr(F.T * F) - d) - mu * ufl.ln(J) + lmbda / 2 * ufl.ln(J) ** 2
    return psi * ufl.dx


def neo_hookean_residual(u: fem.Function, E, nu: float) -> ufl.Form:
    """The first variation of :func:`neo_hookean_energy`."""
    v = ufl.TestFunction(u.function_space)
    return ufl.derivative(neo_hookean_energy(u, E, nu), u, v)
