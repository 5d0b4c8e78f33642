"""The univariate B-spline basis on an open knot vector: the building block of
:mod:`~dolfinx_mortar.surfaces.nurbs`' curves and tensor-product surfaces.

Debian 12 ships no NURBS library for Python that fits (we need vectorized basis
values and derivatives per knot span, nothing more), so the Cox–de Boor
recursion (Piegl & Tiller, *The NURBS Book*, A2.2) is written here.
"""
from __future__ import annotations

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


def open_uniform_knots(degree: int, n_elements: int) -> FloatArray:
    """Open (clamped) uniform knot vector on [0, 1]."""
    if degree < 1:
        raise ValueError(f"B-spline degree must be at least 1, got {degree}")
    if n_elements < 1:
        raise ValueError(f"need at least one element, got {n_elements}")
    inner = np.linspace(0.0, 1.0, n_elements + 1)
    return np.concatenate([np.zeros(degree), inner, np.ones(degree)])


class BSplineBasis1D:
    """Univariate B-spline basis on a clamped knot vector.

    Parameters
    ----------
    degree
        Polynomial degree p ≥ 1.
    knots
        Non-decreasing knot vector whose first and last knots repeat p + 1 times.
    """

    def __init__(self, degree: int, knots: npt.ArrayLike):
        knots = np.asarray(knots, dtype=np.float64)
        p = int(degree)
        if p < 1:
            raise ValueError(f"B-spline degree must be at least 1, got {p}")
        if knots.ndim != 1 or np.any(np.diff(knots) < 0):
            raise ValueError("knot vector must be one-dimensional and non-decreasing")
        if (np.any(knots[: p + 1] != knots[0]) or np.any(knots[-p - 1:] != knots[-1])
                or knots[-1] <= knots[0]):
            raise ValueError(f"knot vector must be open: first and last knots repeated "
                             f"{p + 1} times around a non-empty interval")
        self.degree = p
        self.knots = knots
        self.num_functions = len(knots) - p - 1
        spans = np.arange(p, self.num_functions)
        #: knot-span index of every element (non-empty spans only)
        self.element_spans = spans[knots[spans + 1] > knots[spans]]

    @property
    def num_elements(self) -> int:
        """The number of elements (non-empty knot spans)."""
        return len(self.element_spans)

    def element_bounds(self) -> tuple[FloatArray, FloatArray]:
        """Parameter intervals [a_e, b_e] of the elements."""
        s = self.element_spans
        return self.knots[s], self.knots[s + 1]

    def locate(self, xi: FloatArray) -> npt.NDArray[np.int64]:
        """Element index containing each parameter (right-continuous, last closed)."""
        xi = np.asarray(xi, dtype=np.float64)
        lo, hi = self.knots[0], self.knots[-1]
        if np.any(xi < lo - 1e-14 * (hi - lo)) or np.any(xi > hi + 1e-14 * (hi - lo)):
            raise ValueError(f"parameters must lie in [{lo}, {hi}]")
        a, _ = self.element_bounds()
        e = np.searchsorted(a, xi, side="right") - 1
        return np.clip(e, 0, self.num_elements - 1)

    def _values(self, p: int, spans: npt.NDArray[np.int64], xi: FloatArray) -> FloatArray:
        # The NURBS Book A2.2, vectorized over points: the p + 1 non-zero
        # functions N_{span-p..span, p}(xi).
        U = self.knots
        n = len(xi)
        N = np.zeros((n, p + 1))
        N[:, 0] = 1.0
        left = np.zeros((n, p + 1))
        right = np.zeros((n, p + 1))
        for j in range(1, p + 1):
            left[:, j] = xi - U[spans + 1 - j]
            right[:, j] = U[spans + j] - xi
            saved = np.zeros(n)
            for r in range(j):
                temp = N[:, r] / (right[:, r + 1] + left[:, j - r])
                N[:, r] = saved + right[:, r + 1] * temp
                saved = left[:, j - r] * temp
            N[:, j] = saved
        return N

    def tabulate(self, elements: npt.NDArray[np.int64],
                 xi: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Values and first derivatives of the p + 1 functions active on each element.

        Returns arrays of shape (len(xi), p + 1); local function k of element e
        is global function ``first_function(e) + k``.
        """
        p, U = self.degree, self.knots
        spans = self.element_spans[elements]
        xi = np.asarray(xi, dtype=np.float64)
        N = self._values(p, spans, xi)
        # N'_{i,p} = p N_{i,p-1}/(u_{i+p} - u_i) - p N_{i+1,p-1}/(u_{i+p+1} - u_{i+1})
        lower = self._values(p - 1, spans, xi)  # N_{span-p+1..span, p-1}
        dN = np.zeros_like(N)
        for k in range(p + 1):
            i = spans - p + k
            if k >= 1:
                d = U[i + p] - U[i]
                dN[:, k] += np.where(d > 0, p * lower[:, k - 1] / np.where(d > 0, d, 1), 0)
            if k <= p - 1:
                d = U[i + p + 1] - U[i + 1]
                dN[:, k] -= np.where(d > 0, p * lower[:, k] / np.where(d > 0, d, 1), 0)
        return N, dN

    def first_function(self, elements: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
        """The global index of the first function active on each element."""
        return self.element_spans[elements] - self.degree
