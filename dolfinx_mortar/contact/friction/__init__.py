"""Coulomb friction of a contact term: the slip, its history, the tangential
residual and Jacobian (docs/FRICTION.md)."""
from dolfinx_mortar.contact.friction.tangential import Friction

__all__ = ["Friction"]
