"""How a contact term's stiffness enters Newton's linear solve.

- :class:`AssembledEntry`: the contact Jacobian is a sparse matrix added to
  the user's bulk matrix (every kind but GLS/GLS*);
- :class:`AugmentedEntry`: GLS and GLS* have a dense contact stiffness; the
  bulk matrix is left as it is and the exact Newton step comes from a sparse
  augmented system, applied as the KSP's preconditioner
  (:class:`~dolfinx_mortar.contact.newton.augmented.AugmentedNewtonStep`).
"""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.newton.augmented import AugmentedNewtonStep
from dolfinx_mortar.contact.gap_sources import GapSource
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.kinds import BasisKind, is_global

FloatArray = npt.NDArray[np.float64]
DIFFERENT = PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
#: rows whose diagonal is below this fraction of the largest contact diagonal
#: count as unstiffened: a preconditioning choice (such a row is left to
#: multigrid), not a correctness decision
STIFFENED_FRACTION = 1e-12


def stiffened_rows(K: PETSc.Mat, bs: int) -> np.ndarray:
    """Global indices of the owned rows of a contact Jacobian ``K`` with a
    diagonal entry above :data:`STIFFENED_FRACTION` of K's largest (over all
    ranks); whole dof blocks of size ``bs`` (nodes), so that a node's
    directions stay together."""
    diagonal = K.getDiagonal()
    scale = diagonal.norm(PETSc.NormType.NORM_INFINITY)
    values = np.abs(diagonal.array_r).reshape(-1, bs).max(axis=1)
    start = diagonal.getOwnershipRange()[0]
    diagonal.destroy()
    nodes = np.flatnonzero(values > STIFFENED_FRACTION * scale)
    return (start + bs * nodes[:, None] + np.arange(bs)).ravel().astype(PETSc.IntType)


class AssembledEntry:
    """The contact Jacobian assembled into the Newton matrix."""

    #: the entry makes the KSP's step itself (only one such term per problem)
    takes_the_linear_solve = False
    #: the augmented system's Newton step (None: the stiffness is assembled)
    step: Optional[AugmentedNewtonStep] = None

    def __init__(self, comm: MPI.Comm, bs: int):
        self.comm, self.bs = comm, bs
        #: global indices of this rank's rows that the last contact Jacobian
        #: stiffened (for the contact block preconditioner)
        self.stiffened_rows: np.ndarray = np.zeros(0, dtype=PETSc.IntType)

    def add_pattern(self, A: PETSc.Mat, model: GapSource, state: ContactState,
                    friction=None) -> None:
        """Give the bulk matrix ``A`` every entry the contact stiffness may have
        (friction's too, where there is friction)."""
        A.axpy(1.0, model.pattern(state), structure=DIFFERENT)
        if friction is not None:
            A.axpy(1.0, friction.pattern(model, state, state.friction), structure=DIFFERENT)

    def assemble(self, A: PETSc.Mat, model: GapSource, state: ContactState, active: FloatArray,
                 mask: PETSc.Vec, configuration, friction=None) -> bool:
        """``A += K_c`` at ``state`` with ``active`` as H(d̄) (A assembled after),
        with ``friction``'s (:class:`~dolfinx_mortar.contact.friction.tangential.Friction`)
        stiffness where given; returns whether A's pattern changed unseen by PETSc."""
        geometric = configuration.geometric_stiffness(active, self.comm)
        K = model.jacobian(state, active, mask, geometric=geometric)
        if friction is not None:
            K = K.copy()  # the model's product keeps its own matrix for reuse
            K.axpy(1.0, friction.jacobian(model, state, state.friction, active),
                   structure=DIFFERENT)
        self.stiffened_rows = stiffened_rows(K, self.bs)
        changed = configuration.add_stiffness(A, K)
        A.assemble()
        return changed

    def configure_ksp(self, ksp: PETSc.KSP) -> None:
        """Nothing to do: the KSP solves with the assembled matrix."""


class AugmentedEntry(AssembledEntry):
    """GLS/GLS*: the bulk matrix as it is, and the exact step through the
    augmented system as the KSP's preconditioner."""

    takes_the_linear_solve = True
    #: options prefix of the augmented system's KSP
    prefix = "dolfinx_mortar_augmented_"

    def __init__(self, comm: MPI.Comm, bs: int):
        super().__init__(comm, bs)
        #: the exact Newton step of the last :meth:`assemble`
        self.step = AugmentedNewtonStep(comm, self.prefix)

    def add_pattern(self, A: PETSc.Mat, model: GapSource, state: ContactState,
                    friction=None) -> None:
        """Nothing: the contact stiffness never enters the bulk matrix."""

    def assemble(self, A: PETSc.Mat, model: GapSource, state: ContactState, active: FloatArray,
                 mask: PETSc.Vec, configuration, friction=None) -> bool:
        tangential = (friction.augmented_blocks(model, state, state.friction, active)
                      if friction is not None else None)
        self.step.update_from(A, state, model, active, tangential)
        return False

    def configure_ksp(self, ksp: PETSc.KSP) -> None:
        """Make ``ksp`` apply the exact Newton step (a python PC)."""
        ksp.setType("preonly")
        ksp.getPC().setType("python")
        ksp.getPC().setPythonContext(self.step)


def entry_of(kind: BasisKind, comm: MPI.Comm, bs: int) -> AssembledEntry:
    """The Newton entry of a kind."""
    return (AugmentedEntry if is_global(kind) else AssembledEntry)(comm, bs)
