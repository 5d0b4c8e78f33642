"""Self-contact: a surface that is its own master, in two passes (docs/SELF_CONTACT.md)."""
from dolfinx_mortar.contact.gap_sources.self_contact.sources import (CurrentSelfContactGap,
                                                                     SelfContactGap,
                                                                     SelfContactGlobalGap)

__all__ = ["CurrentSelfContactGap", "SelfContactGap", "SelfContactGlobalGap"]
