"""Contact laws: the normal penalty law and Coulomb friction's return mapping
(one home per law, docs/DESIGN.md, §Architecture)."""
from dolfinx_mortar.contact.laws.coulomb import (SEPARATED, SLIP, STICK, CoulombFriction,
                                                 ReturnMapping)
from dolfinx_mortar.contact.laws.law import NormalLaw, TangentialLaw, check_tangential_law
from dolfinx_mortar.contact.laws.penalty import PenaltyLaw, positive_part, safe_weights

__all__ = ["CoulombFriction", "NormalLaw", "TangentialLaw", "check_tangential_law", "PenaltyLaw", "ReturnMapping", "SEPARATED", "SLIP", "STICK",
           "positive_part", "safe_weights"]
