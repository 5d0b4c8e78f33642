"""The Newton side of a contact term: its Newton entry, the stiffness of the
nodes near contact, the Dirichlet masks and the last state
(:class:`~dolfinx_mortar.contact.term.ContactTerm` hands on to it)."""
from __future__ import annotations

from contextlib import contextmanager
from typing import Callable, Iterator, Optional, Sequence

import numpy as np
import numpy.typing as npt
from dolfinx.fem import petsc as fem_petsc
from petsc4py import PETSc

from dolfinx_mortar.contact.gap_sources import GapSource
from dolfinx_mortar.contact.newton.entry import entry_of
from dolfinx_mortar.contact.newton.near_contact import NearContactStiffness, gap_closing_force
from dolfinx_mortar.contact.newton.traits import JacobianAssembly, NewtonTraits
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.dolfinx_compat import ghosted_vector
from dolfinx_mortar.kinds import BasisKind

FloatArray = npt.NDArray[np.float64]


class TermAssembly:
    """What a contact term needs to enter Newton (see the module).

    Parameters
    ----------
    V
        The displacement's function space.
    kind
        The mortar kind (GLS kinds enter through the augmented system).
    configuration
        The term's configuration (:mod:`~dolfinx_mortar.contact.gap_sources.configuration`).
    """

    def __init__(self, V, kind: BasisKind, configuration):
        self.V, self.configuration = V, configuration
        self.entry = entry_of(kind, V.mesh.comm, V.dofmap.index_map_bs)
        self.near_contact = NearContactStiffness()
        #: the contact state of the last update (None: none since the source was made)
        self.state: Optional[ContactState] = None
        self._masks: dict = {}

    def traits(self, law, source: GapSource, frictional: bool) -> NewtonTraits:
        """What a Newton solver needs to know of the term (:class:`NewtonTraits`)."""
        follows_u = self.configuration.follows_u
        return NewtonTraits(symmetric=law.has_potential and not (follows_u or frictional),
                            moving_pattern=source.moving_pattern, follows_u=follows_u,
                            takes_the_linear_solve=self.entry.takes_the_linear_solve,
                            frictional=frictional)

    def evaluate(self, source: GapSource, friction, u) -> ContactState:
        """The contact state at the present u with every dof kept (results)."""
        u.x.scatter_forward()
        state = source.evaluate(u, None)
        if friction is not None:
            friction.add_to(state, source, u, self.active(source, state), None)
        return state

    def update(self, source: GapSource, friction, u, bcs: Sequence) -> ContactState:
        """The contact state at the present values of u, with friction's
        forces, the Dirichlet columns of ``bcs`` dropped."""
        u.x.scatter_forward()
        self.state = None
        # petsc4py defers the destruction of a parallel PETSc object whose
        # Python handle dies to a collective garbage_cleanup, which nothing
        # else calls: the matrices of each evaluation piled up (ironing 3D at
        # 2k dofs grew by 15 MB/s to over 5 GB with PETSc 3.18; a small block
        # on 2 ranks of 3.22 by 0.5 MB per evaluation). An evaluation is
        # collective, so every rank reaches this point together.
        PETSc.garbage_cleanup(self.V.mesh.comm)
        mask = self.mask(bcs)
        state = source.evaluate(u, mask)
        if friction is not None:
            friction.add_to(state, source, u, self.active(source, state), mask)
        self.state = state
        return state

    def mask(self, bcs: Sequence = ()) -> PETSc.Vec:
        """1 on free dofs, 0 on the dofs of ``bcs`` (the contact terms skip those)."""
        key = tuple(id(bc) for bc in bcs)
        if key not in self._masks:
            m = ghosted_vector(self.V.dofmap.index_map, self.V.dofmap.index_map_bs)
            m.set(1.0)
            fem_petsc.set_bc(m, list(bcs), alpha=0.0)
            self._masks[key] = m
        return self._masks[key]

    def active(self, source: GapSource, state: ContactState) -> FloatArray:
        """The nodes that get contact stiffness (0/1; :class:`NearContactStiffness`)."""
        return self.near_contact.mask(source, state)

    def jacobian(self, A: PETSc.Mat, source: GapSource, friction, bcs: Sequence,
                 timings: dict[str, float]) -> JacobianAssembly:
        """``A += K_c`` at the last state (GLS: the augmented step prepared
        instead, its factorization's time in ``timings``)."""
        changed = self.entry.assemble(A, source, self.state, self.active(source, self.state),
                                      self.mask(bcs), self.configuration, friction)
        if self.entry.step is not None:
            timings["augmented_factorization"] = self.entry.step.factorization_time
        return JacobianAssembly(changed, self.entry.stiffened_rows)

    def add_pattern(self, A: PETSc.Mat, source: GapSource, friction) -> None:
        """Give ``A`` every entry the contact stiffness may have, at the last state."""
        self.entry.add_pattern(A, source, self.state, friction)
        self.configuration.new_matrix()
        if source.moving_pattern or self.configuration.pattern_grows:
            # the pairs, and so the pattern, change with u: new entries are
            # allocated as they come
            A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)

    def settle(self, source: GapSource, free_motions: Callable[[], list]) -> None:
        """Decide, where nothing touches yet and some node is near contact,
        whether those nodes need stiffness without force (collective)."""
        if self.state is not None and self.near_contact.due(source, self.state):
            self.near_contact.decide(source, self.state, free_motions())

    @contextmanager
    def closing(self, source: GapSource) -> Iterator[Optional[PETSc.Vec]]:
        """The gap-closing pull, with the near nodes stiffened inside the block."""
        self.near_contact.closing = True
        try:
            yield gap_closing_force(source, self.state)
        finally:
            self.near_contact.closing = False
