"""The dual basis rebuilt over the covered part on the current surface
(``gap_sources.current.covered_dual``): its gaps are those of ``C = L⁻¹ diag(W)``,
and the chain rule through ``L⁻¹`` that gives their first and second derivatives
from the pairs' ``(c, L)`` agrees with central differences along a path."""
from __future__ import annotations

import numpy as np
import pytest

from dolfinx_mortar.contact.gap_sources.current.covered_dual import SLIVER, CoveredDual


def _path(nd: int, seed: int):
    """c(t) and a symmetric positive definite L(t), quadratic in t."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((3, nd, nd))
    c = rng.standard_normal((3, nd))

    def at(t: float):
        M = 2 * np.eye(nd) + 0.3 * (A[0] + t * A[1] + t * t * A[2])
        return c[0] + t * c[1] + t * t * c[2], M @ M.T
    return at


def _dual(c, L, nd):
    return CoveredDual.of(np.array([0]), L[None], c[None], np.full((1, nd), 10.0))


@pytest.mark.parametrize("nd", [2, 3, 4])
def test_gaps_are_those_of_the_rebuilt_coefficients(nd):
    c, L = _path(nd, nd)(0.2)
    dual = _dual(c, L, nd)
    g, W = dual.gaps()
    C = dual.coefficients(np.eye(nd))[0]
    assert np.allclose(C, np.linalg.solve(L, np.diag(L.sum(axis=1))), rtol=1e-13, atol=0)
    assert np.allclose(g[0], C.T @ c, rtol=1e-12, atol=1e-14)
    assert np.allclose(W[0], L.sum(axis=1), rtol=1e-14)
    # the rebuilt basis is dual over the covered part: ∫ φ_a N_b = δ_ab W_b
    assert np.allclose(C.T @ L, np.diag(L.sum(axis=1)), rtol=0, atol=1e-12)


@pytest.mark.parametrize("nd", [2, 3, 4])
def test_first_and_second_derivatives_agree_with_central_differences(nd):
    at = _path(nd, 10 + nd)
    rng = np.random.default_rng(nd)
    F, FW = rng.standard_normal((2, nd))
    t, h = 0.3, 1e-4

    def q(s):
        c, L = at(s)
        return np.concatenate([c, L.ravel()])

    def objective(s):
        g, W = _dual(*at(s), nd).gaps()
        return g[0], W[0], F @ g[0] + FW @ W[0]
    dual = _dual(*at(t), nd)
    dq = (q(t + h) - q(t - h)) / (2 * h)
    ddq = (q(t + h) - 2 * q(t) + q(t - h)) / h ** 2
    (gp, Wp, fp), (g0, _, f0), (gm, Wm, fm) = objective(t + h), objective(t), objective(t - h)
    Gamma, Omega = dual.gap_rows()
    assert np.allclose((gp - gm) / (2 * h), Gamma[0] @ dq, rtol=0, atol=1e-7 * np.abs(g0).max())
    assert np.allclose((Wp - Wm) / (2 * h), Omega[0] @ dq, rtol=0, atol=1e-9)
    second = dual.pair_weights(F[None], FW[None])[0] @ ddq + dq @ dual.cross_blocks(F[None])[0] @ dq
    assert abs((fp - 2 * f0 + fm) / h ** 2 - second) < 1e-6 * abs(second)


def test_a_sliver_takes_the_positive_functions():
    """A cell covered over 1e-5 of its length near one node: ∫_cov N of the far node
    is 5e-11 of the cell, below SLIVER; its gaps are ∫ N_a d (C = I), without the
    L⁻¹ of a matrix singular to round-off, and their second derivative has no cross
    terms."""
    s = 1e-5
    L = np.array([[s - s ** 2 + s ** 3 / 3, s ** 2 / 2 - s ** 3 / 3],
                  [s ** 2 / 2 - s ** 3 / 3, s ** 3 / 3]])
    assert L.sum(axis=1).min() < SLIVER
    c = np.array([-0.3 * s, -0.1 * s ** 2])
    dual = _dual(c, L, 2)
    assert dual.sliver[0]
    g, _ = dual.gaps()
    assert np.array_equal(g[0], c)
    assert np.array_equal(dual.coefficients(np.zeros((2, 2)))[0], np.eye(2))
    assert not np.any(dual.cross_blocks(np.ones((1, 2))))
