"""The normal penalty law: the only place it and its derivatives are written.

Every gap model gives nodal gaps ``y_A`` (penetration positive) and the lumped
weights ``W_A = ∫ N_A`` of the surface its bases live on; the law turns them
into the penalty potential

    Π_c = Σ_A (ε/2) W_A^m ⟨y_A⟩²,   y_A = ĝ_A W_A^{−k},   ĝ_A = ∫ φ_A d,

its nodal force ``ω_A ⟨y_A⟩`` (``ω = ε W^m``, the residual is ``Gᵀ ω⟨y⟩``
with ``G = ∂y/∂u``) and the pressure coefficient ``p_A = ε W^{m−k} ⟨y_A⟩``
in a partition-of-unity basis. The exponents come from the kind and the
scaling (docs/DESIGN.md, §Scalings):

- ``"consistent"``: y is the gap of the unstarred partner (``∫ M̄_A d``, k = 1)
  and ω = εW (m = 1), so that a kind and its starred partner give one problem;
- ``"seed"``: y is the kind's own gap ``∫ M_A d`` (k = 0 for a
  partition-of-unity kind, 1 otherwise) and ω = ε (m = 0); GLS* in the seed
  scaling weighs the GLS gap by W² (m = 2).

With the pointwise active set the nodal ``⟨y_A⟩`` is replaced by
``y⁺_A = ∫ M̄_A ⟨d⟩`` (the positive part taken at every point); there is no
potential then, and the virtual work keeps the nodal form.

A frozen configuration holds W fixed, so only ω, the force and the pressure
are used; on the current surface W follows u and the law's derivatives with
respect to ĝ and W enter the exact Jacobian (:meth:`PenaltyLaw.nodal_coefficients`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt

from dolfinx_mortar.kinds import (BasisKind, KindLike, is_global, is_partition_of_unity,
                                  parse_kind, unstarred_partner)

FloatArray = npt.NDArray[np.float64]

SCALINGS = ("consistent", "seed")
ACTIVE_SETS = ("nodal", "pointwise")


def positive_part(x: FloatArray) -> FloatArray:
    """``⟨x⟩ = max(x, 0)``, the Macaulay bracket of the penalty law."""
    return np.maximum(x, 0.0)


def safe_weights(W: FloatArray) -> FloatArray:
    """W with 1 where a node carries no weight (off the slave surface, or not
    covered), so that powers and quotients stay finite; the law's factors
    multiply ⟨y⟩ = 0 or ω = 0 there."""
    return np.where(W > 0, W, 1.0)


@dataclass(frozen=True)
class PenaltyLaw:
    """The penalty law of one contact term (see the module).

    Attributes
    ----------
    penalty
        ε, pressure per length (positive, finite).
    scaling
        ``"consistent"`` or ``"seed"``.
    pointwise
        The pointwise active set (``y⁺ = ∫ M̄ ⟨d⟩``) instead of the nodal ``⟨y⟩``.
    k, m
        Exponents of ``y = ĝ W^{−k}`` and ``ω = ε W^m``.
    gap_kind
        The basis whose integrals are the nodal gaps (the standard basis N for
        GLS/GLS*: their gaps are ``L⁻¹ ∫N d``).
    """

    penalty: float
    scaling: str
    pointwise: bool
    k: int
    m: int
    gap_kind: BasisKind

    @classmethod
    def of(cls, kind: KindLike, penalty: float, scaling: str = "consistent",
           active_set: str = "nodal") -> "PenaltyLaw":
        """The law of a kind, checked: names an unknown kind, scaling or active
        set, and a penalty that is not positive and finite."""
        if scaling not in SCALINGS:
            raise ValueError(f"unknown scaling '{scaling}'; expected one of {SCALINGS}")
        kind = parse_kind(kind)
        if not (isinstance(penalty, (int, float, np.floating, np.integer))
                and np.isfinite(penalty) and penalty > 0):
            raise ValueError(f"the penalty must be positive and finite, got {penalty!r}")
        if active_set not in ACTIVE_SETS:
            raise ValueError(f"unknown active set '{active_set}'; expected {ACTIVE_SETS}")
        consistent = scaling == "consistent"
        if is_global(kind):
            gap, k = BasisKind.LmLS_star, 1
            m = 1 if consistent else (0 if kind == BasisKind.GLS else 2)
        else:
            gap = unstarred_partner(kind) if consistent else kind
            k = 0 if (not consistent and is_partition_of_unity(kind)) else 1
            m = 1 if consistent else 0
        return cls(float(penalty), scaling, active_set == "pointwise", k, m, gap)

    @property
    def has_potential(self) -> bool:
        """Whether the law derives from the potential ``Σ_A (ω_A/2)⟨y_A⟩²``
        (the nodal active set; the pointwise one has none): the contact
        Jacobian is then symmetric on frozen bases, and friction's cone is
        set by its nodal forces."""
        return not self.pointwise

    # -- frozen configurations: W fixed -------------------------------------------------
    def weights(self, W: FloatArray) -> FloatArray:
        """``ω_A = ε W_A^m`` of Π_c = Σ (ω_A/2)⟨y_A⟩²."""
        return self.penalty * W ** self.m

    def weight_derivative(self, W: FloatArray) -> FloatArray:
        """``∂ω_A/∂W_A = ε m W_A^(m−1)`` (W as :func:`safe_weights`)."""
        return self.penalty * self.m * W ** (self.m - 1) if self.m else np.zeros_like(W)

    def force(self, weights: FloatArray, gaps: FloatArray,
              gaps_plus: Optional[FloatArray] = None) -> FloatArray:
        """The nodal force ``ω⟨y⟩`` (pointwise: ``ω y⁺``) of ``R_c = Gᵀ force``."""
        return weights * (gaps_plus if self.pointwise else positive_part(gaps))

    def pressure(self, weights: FloatArray, W: FloatArray, gaps: FloatArray,
                 gaps_plus: Optional[FloatArray] = None) -> FloatArray:
        """``p_A = ω_A⟨y_A⟩ / W_A^k``: the coefficients of the traction in a
        partition-of-unity basis (``ε⟨y_A⟩`` in the consistent scaling); 0 on
        nodes without weight. ``gaps_plus`` replaces ⟨y⟩ when given."""
        force = weights * (positive_part(gaps) if gaps_plus is None else gaps_plus)
        if self.k == 0:
            return force
        return np.divide(force, W, out=np.zeros_like(W), where=W > 0)

    @staticmethod
    def potential(weights: FloatArray, gaps: FloatArray) -> FloatArray:
        """``(ω_A/2)⟨y_A⟩²`` per node: the energy of the penalty springs."""
        return 0.5 * weights * positive_part(gaps) ** 2

    @staticmethod
    def active(gaps: FloatArray) -> npt.NDArray[np.bool_]:
        """``H(y)`` with the generalized derivative of ⟨·⟩ at 0 taken as 1, so
        that touching nodes stiffen without pushing."""
        return gaps >= 0

    # -- the current surface: W follows u -----------------------------------------------
    def nodal_gaps(self, g: FloatArray, W: FloatArray) -> FloatArray:
        """``y = ĝ W^{−k}`` (W as :func:`safe_weights`)."""
        return g * W ** (-self.k)

    def nodal_gap_factors(self, y: FloatArray, W: FloatArray
                          ) -> tuple[FloatArray, Optional[FloatArray]]:
        """The factors of ``∂y = W^{−k} ∂ĝ − k (y/W) ∂W`` (the second None for
        k = 0), W as :func:`safe_weights`."""
        return W ** (-self.k), (-self.k * y / W if self.k else None)

    def energy(self, g: FloatArray, W: FloatArray) -> FloatArray:
        """``(ε/2) W^m ⟨ĝ W^{−k}⟩²`` per node (W as :func:`safe_weights`)."""
        return 0.5 * self.penalty * W ** self.m * positive_part(self.nodal_gaps(g, W)) ** 2

    def nodal_coefficients(self, g: FloatArray, W: FloatArray, active: FloatArray
                           ) -> tuple[FloatArray, ...]:
        """``y`` and the derivatives of F = (ε/2) W^m ⟨ĝ W^{−k}⟩² with respect
        to ĝ and W: ``(y, F_g, F_W, F_gg, F_gW, F_WW)``, with ``active`` (0/1)
        as H(y) in F_gg (W as :func:`safe_weights`)."""
        eps, k, m = self.penalty, self.k, self.m
        y = self.nodal_gaps(g, W)
        yp = positive_part(y)
        Fg = eps * W ** (m - k) * yp
        FW = eps * (m / 2 - k) * W ** (m - 1) * yp ** 2
        Fgg = eps * W ** (m - 2 * k) * active
        FgW = eps * (m - 2 * k) * W ** (m - k - 1) * yp
        FWW = eps * (m / 2 - k) * ((m - 1) - 2 * k) * W ** (m - 2) * yp ** 2
        return y, Fg, FW, Fgg, FgW, FWW

    def pointwise_coefficients(self, y_plus: FloatArray, W: FloatArray
                               ) -> tuple[FloatArray, ...]:
        """The pointwise set's virtual work ``δΠ = F_g δĝ + F_W δW`` with
        ``F_g = ε W^{m−k} y⁺`` and ``F_W = ε (m/2 − k) W^{m−1} y⁺²`` (the nodal
        form with ⟨y⟩ replaced by y⁺), and the derivatives of these with
        respect to y⁺ and W: ``(F_g, F_W, ∂F_g/∂y⁺, ∂F_g/∂W, ∂F_W/∂y⁺,
        ∂F_W/∂W)`` (W as :func:`safe_weights`)."""
        eps, k, m = self.penalty, self.k, self.m
        Fg = eps * W ** (m - k) * y_plus
        FW = eps * (m / 2 - k) * W ** (m - 1) * y_plus ** 2
        return (Fg, FW, eps * W ** (m - k), eps * (m - k) * W ** (m - k - 1) * y_plus,
                2 * eps * (m / 2 - k) * W ** (m - 1) * y_plus,
                eps * (m / 2 - k) * (m - 1) * W ** (m - 2) * y_plus ** 2)
