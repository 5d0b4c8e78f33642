"""The interfaces of the contact laws (docs/DESIGN.md, §Architecture).

A tangential law is given to a contact term as ``friction=``; the term and
its friction ask it through :class:`TangentialLaw` only, so a new law is one
class with these two methods (docs/DESIGN.md shows Tresca friction, tested in
tests/contact/test_new_law_and_obstacle.py). The normal law is the penalty
law of the term's options (:class:`~dolfinx_mortar.contact.laws.penalty.PenaltyLaw`),
asked through :class:`NormalLaw`; a new normal law implements it and is
built where the options are checked (:mod:`~dolfinx_mortar.contact.options`).
"""
from __future__ import annotations

from typing import Optional, Protocol, runtime_checkable

import numpy as np
import numpy.typing as npt

from dolfinx_mortar.contact.laws.coulomb import ReturnMapping
from dolfinx_mortar.kinds import BasisKind

FloatArray = npt.NDArray[np.float64]


@runtime_checkable
class TangentialLaw(Protocol):
    """A friction law: the tangential forces of the slave nodes from their
    trial forces, with the derivatives Newton needs."""

    def penalty(self, normal_penalty: float) -> float:
        """ε_T, the tangential penalty, given the normal ε."""

    def return_mapping(self, trial: FloatArray, normal_force: FloatArray,
                       tangential_weights: FloatArray, active: npt.NDArray[np.bool_]
                       ) -> ReturnMapping:
        """The tangential forces per node from the trial forces ``f* = P f_T^n +
        ω_T Δy_T`` (nodes, gdim), the normal forces ``f_N``, ``ω_T`` and the
        nodes in normal contact; with ``∂f_T/∂Δy_T`` (the tangent),
        ``∂f_T/∂f_N``, the stick/slip states and the slip directions."""


@runtime_checkable
class NormalLaw(Protocol):
    """The normal contact law as the gap sources, friction and the results ask it
    (implemented by :class:`~dolfinx_mortar.contact.laws.penalty.PenaltyLaw`).

    With nodal gaps ``y = ĝ W^{−k}`` and weights ``ω = ε W^m``, the contact
    potential is ``Σ_A (ω_A/2)⟨y_A⟩²``. ``W`` arguments are the lumped weights.
    """

    #: ε, pressure per length
    penalty: float
    #: the pointwise active set (``y⁺ = ∫ M̄ ⟨d⟩``) instead of the nodal ``⟨y⟩``
    pointwise: bool
    #: exponents of ``y = ĝ W^{−k}`` and ``ω = ε W^m``
    k: int
    m: int
    #: the basis whose integrals are the nodal gaps
    gap_kind: BasisKind
    #: the law derives from a potential (symmetric Jacobian on frozen bases)
    has_potential: bool

    def weights(self, W: FloatArray) -> FloatArray:
        """``ω_A = ε W_A^m``."""

    def weight_derivative(self, W: FloatArray) -> FloatArray:
        """``∂ω_A/∂W_A``."""

    def force(self, weights: FloatArray, gaps: FloatArray,
              gaps_plus: Optional[FloatArray] = None) -> FloatArray:
        """The nodal normal forces ``ω⟨y⟩`` (pointwise: ``ω y⁺``)."""

    def pressure(self, weights: FloatArray, W: FloatArray, gaps: FloatArray,
                 gaps_plus: Optional[FloatArray] = None) -> FloatArray:
        """The nodal pressures ``ω_A⟨y_A⟩ / W_A^k``."""

    def potential(self, weights: FloatArray, gaps: FloatArray) -> FloatArray:
        """``(ω_A/2)⟨y_A⟩²`` per node."""

    def active(self, gaps: FloatArray) -> npt.NDArray[np.bool_]:
        """``H(y)``: the nodes that touch or penetrate."""

    def nodal_gaps(self, g: FloatArray, W: FloatArray) -> FloatArray:
        """``y = ĝ W^{−k}``."""

    def nodal_gap_factors(self, y: FloatArray, W: FloatArray
                          ) -> tuple[FloatArray, Optional[FloatArray]]:
        """The factors of ``∂y = W^{−k} ∂ĝ − k (y/W) ∂W``."""

    def energy(self, g: FloatArray, W: FloatArray) -> FloatArray:
        """``(ε/2) W^m ⟨ĝ W^{−k}⟩²`` per node."""

    def nodal_coefficients(self, g: FloatArray, W: FloatArray, active: FloatArray
                           ) -> tuple[FloatArray, ...]:
        """``y`` and the first and second derivatives of the nodal energy in ĝ and W."""

    def pointwise_coefficients(self, y_plus: FloatArray, W: FloatArray
                               ) -> tuple[FloatArray, ...]:
        """The pointwise set's virtual work coefficients and their derivatives."""


def check_tangential_law(friction: object) -> None:
    """TypeError unless ``friction`` implements :class:`TangentialLaw` (or is None)."""
    if friction is not None and not isinstance(friction, TangentialLaw):
        raise TypeError(f"friction must be a friction law such as CoulombFriction (with "
                        f"penalty() and return_mapping()), or None; got "
                        f"{type(friction).__name__}")
