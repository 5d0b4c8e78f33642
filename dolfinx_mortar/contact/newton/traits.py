"""What a Newton solver asks of a contact term, and what its Jacobian assembly did."""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np


@dataclass(frozen=True)
class NewtonTraits:
    """What a Newton solver needs to know of a contact term."""

    #: the contact Jacobian is symmetric (the nodal active set on frozen bases)
    symmetric: bool
    #: the matrix pattern may change inside a Newton solve
    moving_pattern: bool
    #: the bases follow u (the current configuration: two phases per step)
    follows_u: bool
    #: the term makes the linear solve's step itself (GLS kinds: the augmented system)
    takes_the_linear_solve: bool
    #: the term has Coulomb friction (its Jacobian is unsymmetric in slip)
    frictional: bool


class JacobianAssembly(NamedTuple):
    """What :meth:`ContactTerm.assemble_jacobian
    <dolfinx_mortar.contact.term.ContactTerm.assemble_jacobian>` did."""

    #: the matrix's nonzero pattern changed in a way PETSc does not see (reset the KSP)
    pattern_changed: bool
    #: global indices of this rank's rows the contact stiffened (none for GLS kinds)
    stiffened_rows: np.ndarray
