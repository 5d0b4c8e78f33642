"""Second-order forward-mode arithmetic: gradients and Hessians against differences."""
from __future__ import annotations

import numpy as np
import pytest

from dolfinx_mortar.contact.jet import Jet, maximum, minimum


def composite(v):
    """Every operation the segmentation uses: + − × ÷, sqrt, min/max, constants
    and per-entry constant arrays (the batch has two entries)."""
    x, y, z = v
    r = (x * x + 2.0 * y * y + 0.5).sqrt()
    s = maximum(x * y, z - 1.0) + minimum(y / (1.5 + z), 0.3 * x)
    return (r * s - 3.0) / (2.0 + x * z * z) + np.array([0.1, 0.2]) * y


def value(points):
    return composite(Jet.variables(points)).value


def test_jet_gradient_and_hessian_match_central_differences():
    # two batch entries, on either side of the max/min switches
    points = np.array([[0.7, -0.4, 0.9], [1.3, 0.8, -0.2]])
    f = composite(Jet.variables(points))
    x, y, z = points.T
    by_hand = ((np.sqrt(x * x + 2 * y * y + 0.5) * (np.maximum(x * y, z - 1)
                                                   + np.minimum(y / (1.5 + z), 0.3 * x)) - 3)
               / (2 + x * z * z) + np.array([0.1, 0.2]) * y)
    assert np.allclose(f.value, by_hand, rtol=1e-14)
    h = 1e-5
    for i in range(3):
        e = np.zeros(3)
        e[i] = h
        grad = (value(points + e) - value(points - e)) / (2 * h)
        assert np.allclose(f.grad[:, i], grad, atol=1e-9)
        jp, jm = composite(Jet.variables(points + e)), composite(Jet.variables(points - e))
        assert np.allclose(f.hess[:, :, i], (jp.grad - jm.grad) / (2 * h), atol=1e-8)
    assert np.allclose(f.hess, f.hess.transpose(0, 2, 1), atol=1e-14)


def test_jet_reflected_operators_with_numpy_scalars():
    x = Jet.variables(np.array([[2.0]]))[0]
    for f, df in [(np.float64(3.0) * x, 3.0), (np.float64(1.0) - x, -1.0),
                  (np.float64(4.0) / x, -1.0), (np.float64(1.0) + x, 1.0)]:
        assert f.grad[0, 0] == pytest.approx(df)
