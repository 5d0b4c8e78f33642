"""Coulomb's friction law with a tangential penalty: the return mapping.

Beside the normal law (:mod:`~dolfinx_mortar.contact.laws.penalty`), which
gives each slave node A its normal force ``f_N,A = ω_A⟨y_A⟩``, friction gives
it a tangential force ``f_T,A`` (a gdim-vector in the node's tangent plane)
from the mortar-weighted tangential slip increment ``Δy_T,A`` of a load step
(:mod:`~dolfinx_mortar.contact.friction.tangential`):

- trial (elastic predictor): ``f* = P_A f_T,A^n + ω_T,A Δy_T,A`` with
  ``ω_T = ε_T W^m`` (the normal weights with ε_T for ε) and ``f_T^n`` the
  force of the last accepted step turned into the present tangent plane;
- stick where ``|f*| ≤ μ f_N``: ``f_T = f*``;
- slip otherwise (radial return onto the cone): ``f_T = μ f_N f*/|f*|``.

Written with forces, not tractions, the cone is the same in either scaling:
``|f_T| ≤ μ f_N`` is ``|q_A| ≤ μ p_A`` for the coefficients ``q = f_T/W^k``,
``p = f_N/W^k`` of the tractions in a partition-of-unity basis.

A node without normal contact (y < 0) carries no tangential force and no
stiffness; a node that just touches (y = 0, f_N = 0) sticks with the stiffness
ω_T, so that a body held only by friction is not singular at first touch.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]

#: the stick/slip state of a slave node in :attr:`ReturnMapping.state`
SEPARATED, STICK, SLIP = 0, 1, 2

#: ε_T / ε by default. The elastic slip before sliding, μp/ε_T, is then ten
#: penetrations p/ε (about 1e-4 of an element at ε = 1e3 E/h): a stick band
#: Newton can land in. On the slip-limit grid (docs/FRICTION.md) 36 of 40 runs
#: converged against 32 with ε_T = ε, with the same Cattaneo–Mindlin figures
#: (stick zone and traction error to 0.01%).
DEFAULT_TANGENTIAL_FRACTION = 0.1


def _checked_number(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise TypeError(f"{name} must be a real number, got {value!r}")
    value = float(value)
    if not np.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return value


@dataclass(frozen=True)
class CoulombFriction:
    """Coulomb friction of a contact term.

    Parameters
    ----------
    mu
        The friction coefficient μ ≥ 0 (μ = 0 is frictionless, with the
        friction machinery still run: a check of it).
    tangential_penalty
        ε_T, tangential stiffness per length (as the normal ε). None (default):
        ε_T = ε/10 (:data:`DEFAULT_TANGENTIAL_FRACTION` of the normal penalty).
    """

    mu: float
    tangential_penalty: Optional[float] = None

    def __post_init__(self):
        mu = _checked_number(self.mu, "the friction coefficient mu")
        if mu < 0:
            raise ValueError(f"the friction coefficient mu must be ≥ 0, got {mu!r}")
        object.__setattr__(self, "mu", mu)
        if self.tangential_penalty is not None:
            eps_t = _checked_number(self.tangential_penalty, "the tangential penalty")
            if not eps_t > 0:
                raise ValueError(f"the tangential penalty must be positive, got {eps_t!r}")
            object.__setattr__(self, "tangential_penalty", eps_t)

    def penalty(self, normal_penalty: float) -> float:
        """ε_T, by default :data:`DEFAULT_TANGENTIAL_FRACTION` of the normal ε."""
        if self.tangential_penalty is None:
            return DEFAULT_TANGENTIAL_FRACTION * normal_penalty
        return self.tangential_penalty

    def return_mapping(self, trial: FloatArray, normal_force: FloatArray,
                       tangential_weights: FloatArray, active: npt.NDArray[np.bool_]
                       ) -> "ReturnMapping":
        """The tangential forces and their derivatives at every node.

        Parameters
        ----------
        trial
            ``f*`` per node, (nodes, gdim).
        normal_force
            ``f_N = ω⟨y⟩`` per node.
        tangential_weights
            ``ω_T`` per node.
        active
            ``H(y)``: the nodes in normal contact (touching counts).
        """
        size = np.linalg.norm(trial, axis=1)
        limit = self.mu * normal_force
        stick = active & (size <= limit)
        slip = active & ~stick
        n, gdim = trial.shape
        direction = np.zeros_like(trial)
        np.divide(trial, size[:, None], out=direction, where=slip[:, None])
        force = np.where(stick[:, None], trial, 0.0) + (limit * slip)[:, None] * direction
        eye = np.eye(gdim)[None]
        # ∂f_T/∂Δy_T: ω_T I in stick; μ f_N ω_T/|f*| (I − t⊗t) in slip
        ratio = np.zeros(n)
        np.divide(limit * tangential_weights, size, out=ratio, where=slip)
        tangent = (np.where(stick, tangential_weights, 0.0)[:, None, None] * eye
                   + ratio[:, None, None] * (eye - direction[:, :, None] * direction[:, None, :]))
        state = np.full(n, SEPARATED, dtype=np.int8)
        state[stick], state[slip] = STICK, SLIP
        # ∂f_T/∂f_N in slip: μ t
        return ReturnMapping(force, tangent, self.mu * direction, state, direction, ratio)


@dataclass
class ReturnMapping:
    """The result of :meth:`CoulombFriction.return_mapping` per node.

    Attributes
    ----------
    force
        ``f_T``, (nodes, gdim).
    tangent
        ``∂f_T/∂Δy_T``, (nodes, gdim, gdim).
    normal_tangent
        ``∂f_T/∂f_N`` (μ t on slipping nodes, 0 elsewhere), (nodes, gdim).
    state
        :data:`SEPARATED`, :data:`STICK` or :data:`SLIP` per node.
    direction
        ``t = f*/|f*|`` on slipping nodes (0 elsewhere), (nodes, gdim).
    slip_stiffness
        ``μ f_N ω_T/|f*|`` on slipping nodes (0 elsewhere): the stiffness of
        the slip branch across t, and its secant stiffness along t.
    """

    force: FloatArray
    tangent: FloatArray
    normal_tangent: FloatArray
    state: npt.NDArray[np.int8]
    direction: FloatArray
    slip_stiffness: FloatArray

    def secant_tangent(self) -> FloatArray:
        """``∂f_T/∂Δy_T`` with the slip branch's secant ``μ f_N ω_T/|f*|`` along
        t in place of its exact 0: what Newton uses while nodes still change
        between stick and slip (:meth:`~dolfinx_mortar.contact.friction.tangential.Friction.jacobian`)."""
        t = self.direction
        return self.tangent + self.slip_stiffness[:, None, None] * t[:, :, None] * t[:, None, :]
