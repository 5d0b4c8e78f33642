"""How the contact enters Newton: the assembled or augmented entry of its
stiffness, and the stiffness of the nodes near contact before anything touches."""
from dolfinx_mortar.contact.newton.assembly import TermAssembly
from dolfinx_mortar.contact.newton.entry import entry_of
from dolfinx_mortar.contact.newton.traits import JacobianAssembly, NewtonTraits
from dolfinx_mortar.contact.newton.near_contact import (NearContactStiffness, gap_closing_force,
                                                        penetrates, stiffened_nodes)

__all__ = ["JacobianAssembly", "NearContactStiffness", "NewtonTraits", "TermAssembly", "entry_of", "gap_closing_force", "penetrates",
           "stiffened_nodes"]
