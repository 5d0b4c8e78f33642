"""The options of a contact term, checked once where the term is made."""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Optional

import numpy as np

from dolfinx_mortar.collective_warnings import warn
from dolfinx_mortar.contact.laws import PenaltyLaw
from dolfinx_mortar.kinds import DUAL_KINDS, BasisKind, KindLike, parse_kind

CONFIGURATIONS = ("initial", "previous", "current")


@dataclass(frozen=True)
class ContactOptions:
    """The options of a contact term (see :class:`~dolfinx_mortar.contact.term.ContactTerm`),
    checked on construction (:meth:`checked`).

    Attributes
    ----------
    kind
        The mortar basis kind.
    law
        The penalty law: penalty, scaling and active set
        (:class:`~dolfinx_mortar.contact.laws.penalty.PenaltyLaw`).
    basis_configuration
        ``"initial"``, ``"previous"`` or ``"current"``
        (:mod:`~dolfinx_mortar.contact.gap_sources.configuration`).
    boundary_modification
        The dual basis rebuilt over the covered part of partly covered facets.
    search_radius
        How far along its normal a slave facet reaches for master facets (None:
        the default of the configuration).
    axisymmetric
        The mesh is the (r, z) meridian of a body of revolution.
    self_contact
        The slave surface is its own master (two-pass, docs/SELF_CONTACT.md).
    """

    kind: BasisKind
    law: PenaltyLaw
    basis_configuration: str = "initial"
    boundary_modification: bool = False
    search_radius: Optional[float] = None
    axisymmetric: bool = False
    self_contact: bool = False

    @property
    def penalty(self) -> float:
        """ε, pressure per length."""
        return self.law.penalty

    def frozen_phase(self) -> "ContactOptions":
        """The options of the "previous" model that solves each load step of the
        current configuration first. In self-contact the dual kinds' boundary
        modification is refused on the current surface only (:meth:`checked`);
        the frozen phase takes it, as ``"previous"`` does: unmodified, the
        collapsing tube's frozen phase read a false penetration and diverged
        before the current surface's own check could name it."""
        modified = self.boundary_modification or (
            self.self_contact and modification_applies(self.kind, self.law))
        return replace(self, boundary_modification=modified)

    @classmethod
    def checked(cls, kind: KindLike, penalty: float, scaling: str, active_set: str,
                basis_configuration: str, boundary_modification: Optional[bool],
                search_radius: Optional[float], elastic_master: bool,
                axisymmetric: bool = False, self_contact: bool = False) -> "ContactOptions":
        """The options from a term's arguments; names the first that is wrong."""
        law = PenaltyLaw.of(kind, penalty, scaling, active_set)
        kind = parse_kind(kind)
        if self_contact:
            check_self_contact(kind, basis_configuration, law.pointwise)
        if basis_configuration not in CONFIGURATIONS:
            raise ValueError(f"unknown basis configuration '{basis_configuration}'; "
                             f"expected {CONFIGURATIONS}")
        if boundary_modification is None:
            # the dual functions are negative near a facet's far node: a facet the
            # master covers only there reads a separation as a penetration. The
            # modification is the cure wherever it is implemented.
            # Not for self-contact on the current surface (refused below).
            boundary_modification = (elastic_master and modification_applies(kind, law)
                                     and not (self_contact and basis_configuration == "current"))
        if basis_configuration == "current" and boundary_modification and law.pointwise:
            raise NotImplementedError("basis_configuration='current' with the boundary "
                                      "modification and the pointwise active set is not "
                                      "implemented; use active_set='nodal'")
        if basis_configuration == "current" and boundary_modification and self_contact:
            raise NotImplementedError(
                "self_contact=True on the current surface with the boundary modification: "
                "where the surface meets itself obliquely a facet is covered by its own "
                "surface over a small piece only, and the basis rebuilt there extrapolates "
                "that piece's gap to the far node (a false penetration of 0.3 element "
                "lengths where the C body's arc meets its arm, docs/SELF_CONTACT.md); use "
                "kind='LmLS*' or 'LmLS', or basis_configuration='previous'")
        if boundary_modification and not (elastic_master and kind in DUAL_KINDS):
            raise ValueError("the consistent boundary modification applies to the dual kinds "
                             "(LcLS*, LcLS) with an elastic master (master_tag)")
        if search_radius is not None and not (np.isfinite(search_radius) and search_radius > 0):
            raise ValueError(f"the search radius must be positive and finite, got "
                             f"{search_radius!r}")
        if law.pointwise and kind in DUAL_KINDS:
            warn("the pointwise active set with a dual kind: ∫M̄_A⟨d⟩ is negative "
                 "next to the contact edge, and Newton did not converge on any "
                 "curved contact tested (Hertz 2D); prefer active_set='nodal'")
        return cls(kind, law, basis_configuration, bool(boundary_modification),
                   None if search_radius is None else float(search_radius), bool(axisymmetric),
                   bool(self_contact))


def modification_applies(kind: BasisKind, law: PenaltyLaw) -> bool:
    """Whether the boundary modification is defined for ``kind`` under ``law``
    (the dual kinds with the nodal active set), the one rule of its defaults."""
    return kind in DUAL_KINDS and not law.pointwise


def check_self_contact(kind: BasisKind, basis_configuration: str, pointwise: bool) -> None:
    """NotImplementedError naming a combination self-contact does not support, and why."""
    if pointwise and kind in DUAL_KINDS:
        raise NotImplementedError(
            "self_contact=True with the pointwise active set and a dual kind: where the two "
            "passes meet at the contact edge the negative dual functions make the pressure "
            "1.6% off its mirror problem (tests/contact/test_self_contact.py); use "
            "active_set='nodal' or kind='LmLS*'")

