"""Second-order forward-mode differentiation over a batch of small problems.

The current-configuration mortar gap (``current_mortar.py``) needs exact first
and second derivatives of a few hundred arithmetic operations per slave–master
pair: segment ends, projections and averaged normals all move with u. No
automatic-differentiation package is in the fixed Debian stack (no jax, no
autograd), so this module carries (value, gradient, Hessian) through the
operations that computation uses, vectorized over a leading batch axis.
"""
from __future__ import annotations

from typing import Optional, Union

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
Scalar = Union[float, FloatArray]


def _outer(a: FloatArray, b: FloatArray) -> FloatArray:
    return a[:, :, None] * b[:, None, :]


class Jet:
    """A batch of scalars with their gradients and Hessians.

    ``value`` (B,), ``grad`` (B, n), ``hess`` (B, n, n) or None for zero. Mixed
    with floats or (B,) arrays, those count as constants.
    """

    __slots__ = ("value", "grad", "hess")
    __array_ufunc__ = None  # ndarray ∘ Jet defers to the Jet's reflected operators

    def __init__(self, value: FloatArray, grad: FloatArray, hess: Optional[FloatArray] = None):
        self.value, self.grad, self.hess = value, grad, hess

    @classmethod
    def variables(cls, values: FloatArray) -> list["Jet"]:
        """One Jet per column of ``values`` (B, n), seeded as the n variables."""
        B, n = values.shape
        eye = np.eye(n)
        return [cls(values[:, i].copy(), np.broadcast_to(eye[i], (B, n))) for i in range(n)]

    # -- helpers -----------------------------------------------------------------------
    def _scaled(self, c: Scalar) -> "Jet":
        c = np.asarray(c, dtype=np.float64)
        cg = c[..., None] if c.ndim else c
        return Jet(self.value * c, self.grad * cg,
                   None if self.hess is None else self.hess * (cg[..., None] if c.ndim else c))

    def _unary(self, f: FloatArray, f1: FloatArray, f2: FloatArray) -> "Jet":
        """The chain rule for y = f(x) with f' = f1 and f'' = f2 at x."""
        hess = f2[:, None, None] * _outer(self.grad, self.grad)
        if self.hess is not None:
            hess = hess + f1[:, None, None] * self.hess
        return Jet(f, f1[:, None] * self.grad, hess)

    @staticmethod
    def _add_hess(a: Optional[FloatArray], b: Optional[FloatArray]) -> Optional[FloatArray]:
        if a is None:
            return b
        return a if b is None else a + b

    # -- arithmetic --------------------------------------------------------------------
    def __add__(self, other) -> "Jet":
        if isinstance(other, Jet):
            return Jet(self.value + other.value, self.grad + other.grad,
                       self._add_hess(self.hess, other.hess))
        return Jet(self.value + other, self.grad, self.hess)

    __radd__ = __add__

    def __neg__(self) -> "Jet":
        return Jet(-self.value, -self.grad, None if self.hess is None else -self.hess)

    def __sub__(self, other) -> "Jet":
        return self + (-other)

    def __rsub__(self, other) -> "Jet":
        return (-self) + other

    def __mul__(self, other) -> "Jet":
        if not isinstance(other, Jet):
            return self._scaled(other)
        a, b = self, other
        hess = _outer(a.grad, b.grad)
        hess = hess + hess.transpose(0, 2, 1)
        if a.hess is not None:
            hess = hess + a.hess * b.value[:, None, None]
        if b.hess is not None:
            hess = hess + b.hess * a.value[:, None, None]
        return Jet(a.value * b.value,
                   a.grad * b.value[:, None] + b.grad * a.value[:, None], hess)

    __rmul__ = __mul__

    def reciprocal(self) -> "Jet":
        r = 1.0 / self.value
        return self._unary(r, -r * r, 2.0 * r * r * r)

    def __truediv__(self, other) -> "Jet":
        if isinstance(other, Jet):
            return self * other.reciprocal()
        return self._scaled(1.0 / np.asarray(other, dtype=np.float64))

    def __rtruediv__(self, other) -> "Jet":
        return self.reciprocal() * other

    def sqrt(self) -> "Jet":
        s = np.sqrt(self.value)
        return self._unary(s, 0.5 / s, -0.25 / (s * self.value))

    def constant(self) -> FloatArray:
        """The value alone (to take a derivative-free branch decision)."""
        return self.value

    def take(self, indices: npt.ArrayLike) -> "Jet":
        """The batch entries ``indices`` (repeats allowed)."""
        i = np.asarray(indices)
        return Jet(self.value[i], self.grad[i], None if self.hess is None else self.hess[i])

    def sum(self) -> "Jet":
        """The sum over the batch, as a batch of one."""
        return Jet(self.value.sum(keepdims=True), self.grad.sum(axis=0, keepdims=True),
                   None if self.hess is None else self.hess.sum(axis=0, keepdims=True))


def where(condition: npt.NDArray[np.bool_], a: Union[Jet, Scalar], b: Union[Jet, Scalar],
          like: Jet) -> Jet:
    """``a`` where ``condition`` holds, else ``b``, batch entry by entry."""
    def lift(x):
        if isinstance(x, Jet):
            return x
        return Jet(np.broadcast_to(np.asarray(x, dtype=np.float64), like.value.shape),
                   np.zeros_like(like.grad))
    a, b = lift(a), lift(b)
    c = np.asarray(condition)
    hess = None
    if a.hess is not None or b.hess is not None:
        zero = np.zeros(a.grad.shape + a.grad.shape[-1:])
        hess = np.where(c[:, None, None], zero if a.hess is None else a.hess,
                        zero if b.hess is None else b.hess)
    return Jet(np.where(c, a.value, b.value), np.where(c[:, None], a.grad, b.grad), hess)


def stack(jets: list) -> Jet:
    """One Jet whose batch is the concatenation of the given Jets' batches (a
    batch of one broadcasts as usual in the arithmetic that follows)."""
    grads = [np.broadcast_to(j.grad, (len(j.value), j.grad.shape[-1])) for j in jets]
    hess = None
    if any(j.hess is not None for j in jets):
        n = grads[0].shape[-1]
        hess = np.concatenate([np.zeros((len(j.value), n, n)) if j.hess is None else j.hess
                               for j in jets])
    return Jet(np.concatenate([j.value for j in jets]), np.concatenate(grads), hess)


def maximum(a: Jet, b: Jet) -> Jet:
    """The larger of two Jets (the derivatives of the one taken)."""
    return where(a.value >= b.value, a, b, like=a)


def minimum(a: Jet, b: Jet) -> Jet:
    """The smaller of two Jets (the derivatives of the one taken)."""
    return where(a.value <= b.value, a, b, like=a)


def dot(a: list, b: list) -> Jet:
    """Σ_k a_k b_k for vectors given as lists of Jets (or constants)."""
    out = a[0] * b[0]
    for x, y in zip(a[1:], b[1:]):
        out = out + x * y
    return out
