"""Tabulated slave basis data: what every slave surface hands to the kernels."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt


@dataclass(frozen=True)
class Tabulation:
    """Slave basis functions at the quadrature points of every element.

    Attributes
    ----------
    phi
        N_i(x_q) of the element's local functions, shape (cells, points, functions).
    weights
        Quadrature weight times the surface's measure: the surface Jacobian
        |J|, times 2πr on an axisymmetric surface; shape (cells, points).
    points
        Physical quadrature points, shape (cells, points, gdim).
    geometric_weights
        Quadrature weight times |J| alone (the facets' own size, for
        geometric decisions); None when it equals ``weights``.
    """

    phi: npt.NDArray[np.float64]
    weights: npt.NDArray[np.float64]
    points: npt.NDArray[np.float64]
    geometric_weights: Optional[npt.NDArray[np.float64]] = None

    @property
    def ds_weights(self) -> npt.NDArray[np.float64]:
        """Quadrature weight times |J|: the facets' length or area element."""
        return self.weights if self.geometric_weights is None else self.geometric_weights

    def values_of(self, f) -> npt.NDArray[np.float64]:
        """Evaluate a callable ``f(x)`` at the quadrature points.

        ``x`` has shape (gdim, n) as in DOLFINx interpolation, so ``x[0]`` is the
        first coordinate. Returns shape (cells, points).
        """
        nc, nq, gdim = self.points.shape
        x = self.points.reshape(-1, gdim).T
        values = np.asarray(f(x), dtype=np.float64)
        if values.shape != (nc * nq,):
            raise ValueError(
                f"the callable returned shape {values.shape}; expected ({nc * nq},) "
                f"for {nc * nq} points given as x of shape {x.shape}")
        if not np.all(np.isfinite(values)):
            raise ValueError("the callable returned NaN or infinite values")
        return values.reshape(nc, nq)


def measure_from_tangents(tangents: list) -> npt.NDArray[np.float64]:
    """|t₀| (lines) or |t₀ × t₁| (surfaces, which live in 3D).

    The cross product, not sqrt(|t₀|²|t₁|² − (t₀·t₁)²): that difference
    cancels catastrophically on slivers (94% off at aspect 1e8).
    """
    if len(tangents) == 1:
        return np.linalg.norm(tangents[0], axis=-1)
    t0, t1 = tangents
    return np.linalg.norm(np.cross(t0, t1), axis=-1)
