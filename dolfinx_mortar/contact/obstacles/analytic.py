"""Rigid analytic obstacles: they are never meshed (docs/DESIGN.md, §Penalty contact).

An obstacle is its signed distance φ (positive outside the obstacle), with the
gradient and Hessian the exact contact Jacobian needs. The penetration of a
slave point x is d = −φ(x).

Obstacles move rigidly along a load path: ``obstacle.move_to(d)`` places it at
its initial position plus the translation ``d`` (for example from the
load-path callback of :class:`~dolfinx_mortar.solver.load_path.LoadPathSolver`).
"""
from __future__ import annotations

import copy
from typing import Protocol, Sequence

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


class RigidObstacle(Protocol):
    """What the contact terms need of a rigid obstacle. ``x`` has shape (n, gdim)."""

    gdim: int
    #: the translation from the initial position (gdim,)
    displacement: FloatArray

    def signed_distance(self, x: FloatArray) -> FloatArray: ...

    def gradient(self, x: FloatArray) -> FloatArray: ...

    def hessian(self, x: FloatArray) -> FloatArray: ...


def _vector(v: Sequence[float], name: str) -> FloatArray:
    a = np.asarray(v, dtype=np.float64)
    if a.ndim != 1 or len(a) not in (2, 3) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be a finite 2D or 3D vector, got {v!r}")
    return a


class Translatable:
    """A rigid obstacle placed by a reference point (``anchor``) that moves."""

    anchor_name = "point"
    #: the attributes that :meth:`__repr__` shows, in the constructor's order
    shown: tuple[str, ...] = ()

    def __repr__(self) -> str:
        """The obstacle as it is now, e.g. ``RigidPlane(point=[0, 0], normal=[0, 1])``
        (for messages that name it)."""
        def value(name):
            v = getattr(self, name)
            return [float(f"{c:.6g}") for c in v] if np.ndim(v) else float(f"{v:.6g}")
        return (f"{type(self).__name__}("
                + ", ".join(f"{name}={value(name)}" for name in self.shown) + ")")

    def _init_anchor(self) -> None:
        self._initial = getattr(self, self.anchor_name).copy()
        self.displacement = np.zeros(len(self._initial))

    def move_to(self, displacement: Sequence[float]) -> None:
        """Place the obstacle at its initial position translated by ``displacement``."""
        d = _vector(displacement, "displacement")
        if len(d) != len(self._initial):
            raise ValueError(f"a {len(d)}D displacement for a {len(self._initial)}D obstacle")
        self.displacement = d
        setattr(self, self.anchor_name, self._initial + d)


class RigidPlane(Translatable):
    """The half-space behind a plane through ``point`` with outward ``normal``.

    The normal points out of the obstacle, into the space where the body is.
    """

    shown = ("point", "normal")

    def __init__(self, point: Sequence[float], normal: Sequence[float]):
        self.point = _vector(point, "point")
        n = _vector(normal, "normal")
        if len(n) != len(self.point):
            raise ValueError("point and normal differ in dimension")
        length = np.linalg.norm(n)
        if length == 0:
            raise ValueError("the plane's normal is zero")
        self.normal = n / length
        self.gdim = len(n)
        self._init_anchor()

    def signed_distance(self, x: FloatArray) -> FloatArray:
        return (x - self.point) @ self.normal

    def gradient(self, x: FloatArray) -> FloatArray:
        return np.broadcast_to(self.normal, x.shape).copy()

    def hessian(self, x: FloatArray) -> FloatArray:
        return np.zeros((len(x), self.gdim, self.gdim))


class RigidSphere(Translatable):
    """A solid ball (a disk in 2D: the section of a rigid cylinder)."""

    anchor_name = "center"
    shown = ("center", "radius")

    def __init__(self, center: Sequence[float], radius: float):
        self.center = _vector(center, "center")
        if not radius > 0:
            raise ValueError(f"the radius must be positive, got {radius}")
        self.radius = float(radius)
        self.gdim = len(self.center)
        self._init_anchor()

    def signed_distance(self, x: FloatArray) -> FloatArray:
        return np.linalg.norm(x - self.center, axis=1) - self.radius

    def gradient(self, x: FloatArray) -> FloatArray:
        r = x - self.center
        return r / np.linalg.norm(r, axis=1)[:, None]

    def hessian(self, x: FloatArray) -> FloatArray:
        r = x - self.center
        length = np.linalg.norm(r, axis=1)
        unit = r / length[:, None]
        eye = np.eye(self.gdim)[None]
        return (eye - unit[:, :, None] * unit[:, None, :]) / length[:, None, None]


class RigidCylinder(Translatable):
    """A solid circular cylinder in 3D with an axis through ``point`` along ``axis``."""

    shown = ("point", "axis", "radius")

    def __init__(self, point: Sequence[float], axis: Sequence[float], radius: float):
        self.point = _vector(point, "point")
        a = _vector(axis, "axis")
        if len(a) != 3 or len(self.point) != 3:
            raise ValueError("RigidCylinder is 3D; in 2D use RigidSphere (a disk)")
        self.axis = a / np.linalg.norm(a)
        if not radius > 0:
            raise ValueError(f"the radius must be positive, got {radius}")
        self.radius = float(radius)
        self.gdim = 3
        self._init_anchor()

    def _radial(self, x: FloatArray) -> FloatArray:
        r = x - self.point
        return r - np.outer(r @ self.axis, self.axis)

    def signed_distance(self, x: FloatArray) -> FloatArray:
        return np.linalg.norm(self._radial(x), axis=1) - self.radius

    def gradient(self, x: FloatArray) -> FloatArray:
        r = self._radial(x)
        return r / np.linalg.norm(r, axis=1)[:, None]

    def hessian(self, x: FloatArray) -> FloatArray:
        r = self._radial(x)
        length = np.linalg.norm(r, axis=1)
        unit = r / length[:, None]
        P = np.eye(3) - np.outer(self.axis, self.axis)
        return (P[None] - unit[:, :, None] * unit[:, None, :]) / length[:, None, None]


class _Shifted:
    """A user's obstacle seen from ``origin``: evaluated at ``origin + x``."""

    def __init__(self, obstacle: RigidObstacle, origin: FloatArray):
        self.obstacle, self.origin = obstacle, origin
        self.gdim = obstacle.gdim
        self.displacement = obstacle.displacement

    def signed_distance(self, x: FloatArray) -> FloatArray:
        return self.obstacle.signed_distance(x + self.origin)

    def gradient(self, x: FloatArray) -> FloatArray:
        return self.obstacle.gradient(x + self.origin)

    def hessian(self, x: FloatArray) -> FloatArray:
        return self.obstacle.hessian(x + self.origin)


def relative_to(obstacle: RigidObstacle, origin: FloatArray) -> RigidObstacle:
    """The obstacle as it is now, in coordinates relative to ``origin``
    (:func:`~dolfinx_mortar.tolerance.local_origin`).

    The library's obstacles are moved by ``−origin`` (their reference point
    minus a point near it: exact or rounded at the scene's scale), so that
    ``|x − c| − R`` keeps the digits of the local size far from the origin (at
    |x| = 1e6 it loses 1e-10 absolute: 1e-5 of a 1e-5 gap). Another obstacle
    is evaluated at ``origin + x``, in absolute coordinates as before.
    """
    if not isinstance(obstacle, Translatable):
        return _Shifted(obstacle, origin)
    local = copy.copy(obstacle)
    setattr(local, local.anchor_name, getattr(obstacle, obstacle.anchor_name) - origin)
    return local
