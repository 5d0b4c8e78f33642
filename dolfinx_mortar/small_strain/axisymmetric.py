"""Axisymmetric small-strain elasticity in the (r, z) half-plane, as UFL.

A body of revolution under loads that are symmetric about its axis is a 2D
problem in the meridian plane: x[0] is the radius r ≥ 0, x[1] the axial
coordinate z, the displacement (u_r, u_z). Its strain has the hoop part
ε_θθ = u_r / r, and every volume and surface integral carries the
circumference 2πr, so that forces and energies are those of the whole body —
the same convention as the contact term with ``axisymmetric=True``.
"""
from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem


def radius(mesh) -> ufl.core.expr.Expr:
    """r, the first coordinate of the (r, z) mesh."""
    return ufl.SpatialCoordinate(mesh)[0]


def axisymmetric_strain(w) -> ufl.core.expr.Expr:
    """The 3×3 small strain of an axisymmetric displacement (w_r, w_z), in the
    (r, z, θ) basis: the meridian part sym(∇w) and the hoop part w_r / r."""
    r = radius(w.ufl_function_space().mesh)
    g = ufl.grad(w)
    return ufl.as_tensor([[g[0, 0], 0.5 * (g[0, 1] + g[1, 0]), 0.0],
                          [0.5 * (g[0, 1] + g[1, 0]), g[1, 1], 0.0],
                          [0.0, 0.0, w[0] / r]])


def circumference(mesh) -> ufl.core.expr.Expr:
    """2πr: the weight of every integral over the (r, z) half-plane."""
    return 2 * np.pi * radius(mesh)


def axisymmetric_elastic_residual(u: fem.Function, E: float, nu: float) -> ufl.Form:
    """``∫ σ(u) : ε(v) 2πr dx`` of isotropic small-strain elasticity on a body
    of revolution (the strain of :func:`axisymmetric_strain`)."""
    mesh = u.function_space.mesh
    if mesh.geometry.dim != 2:
        raise ValueError(f"axisymmetric elasticity needs a 2D (r, z) mesh, got a "
                         f"{mesh.geometry.dim}D one")
    mu = E / (2 * (1 + nu))
    lmbda = E * nu / ((1 + nu) * (1 - 2 * nu))
    v = ufl.TestFunction(u.function_space)
    eps = axisymmetric_strain(u)
    sigma = 2 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(3)
    return ufl.inner(sigma, axisymmetric_strain(v)) * circumference(mesh) * ufl.dx
