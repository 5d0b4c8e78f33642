"""A preconditioner for penalty contact: algebraic multigrid for the bodies,
an exact solve for the dofs that carry contact stiffness.

The penalty adds ``ε·GᵀG`` to the few rows of the contact zone, orders of
magnitude stiffer than the bulk rows around them (ε = 1e3·E/h makes them 1e3
times the bulk diagonal). Multigrid alone then needs ever more iterations:
on Hertz 3D (two bodies, 30k dofs) CG with BoomerAMG took 12, 17, 50 and 139
iterations at ε = 1e1 … 1e4·E/h, GAMG with the rigid-body modes 19 … 582.
Those rows are few (a few hundred of 30k), so this preconditioner solves
them exactly and leaves the rest to multigrid, as a symmetric multiplicative
(block Gauss–Seidel) combination::

    e₁ = A_cc⁻¹ r_c                      (the contact block, factorized)
    e₂ = e₁ + AMG(r − A e₁)              (one multigrid cycle on the whole A)
    e  = e₂ + A_cc⁻¹ (r − A e₂)_c

It is symmetric when A is, so CG may use it: 20 … 22 iterations on the same
matrices, and 15–23 Krylov iterations per Newton iteration in the solver from
12.7k to 81k dofs and ε = 1e1 … 1e4·E/h (docs/SCALING.md).

Options, under the solver's prefix: ``amg_`` for the multigrid (a ``preonly``
KSP; BoomerAMG by default, ``-<prefix>amg_pc_type gamg`` for GAMG with the
rigid-body modes of each body) and ``contact_block_`` for the block's solver
(MUMPS LU by default).
"""
from __future__ import annotations

import time
from typing import Callable, Optional, Sequence

import numpy as np
from petsc4py import PETSc

from dolfinx_mortar.linalg.linear_solver import reset_after_failure

#: the multigrid's options unless the options database has others
AMG_DEFAULTS = {
    "ksp_type": "preonly",
    "pc_type": "hypre",
    "pc_hypre_type": "boomeramg",
    # 0.25 is for 2D scalar problems; hypre's manual suggests 0.5–0.7 in 3D
    # (0.7: 59 against 50 CG iterations for 0.25, in 40% less setup time)
    "pc_hypre_boomeramg_strong_threshold": 0.7,
}
BLOCK_DEFAULTS = {
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
}


class ContactBlockPreconditioner:
    """A petsc4py python PC context (``pc.setPythonContext``).

    Parameters
    ----------
    prefix
        The solver's options prefix; the multigrid reads ``<prefix>amg_…``, the
        block solver ``<prefix>contact_block_…``.
    near_nullspace
        Called once when the multigrid is GAMG: the rigid-body modes to attach.

    Attributes
    ----------
    contact_rows
        The global indices (this rank's owned rows) of the rows that carry
        contact stiffness in the operator of the next set-up: given by the
        Jacobian's assembly (:func:`tell_preconditioner`).
    """

    def __init__(self, prefix: str = "",
                 near_nullspace: Optional[Callable[[], PETSc.NullSpace]] = None):
        self.contact_rows = np.zeros(0, dtype=PETSc.IntType)
        self.prefix = prefix
        self.near_nullspace = near_nullspace
        self.amg: Optional[PETSc.KSP] = None
        self.block: Optional[PETSc.KSP] = None
        self.rows: Optional[PETSc.IS] = None
        self.A: Optional[PETSc.Mat] = None
        self._work: list = []
        #: rows in the exact block at the last setup (all ranks)
        self.block_size = 0
        #: wall times (s) of the setups: multigrid and block factorization
        self.timings: dict[str, float] = {}

    # -- petsc4py python PC interface --------------------------------------------------
    def setUp(self, pc: PETSc.PC) -> None:
        A, _ = pc.getOperators()
        comm = A.getComm()
        self.A = A
        clock = time.perf_counter()
        if self.amg is None:
            self.amg = self._ksp(comm, "amg_", AMG_DEFAULTS)
        self.amg.setOperators(A)
        if self.amg.getPC().getType() == "gamg" and self.near_nullspace is not None:
            A.setNearNullSpace(self.near_nullspace())
        self.amg.setUp()
        self._add("amg_setup", clock)
        clock = time.perf_counter()
        rows = np.asarray(self.contact_rows, dtype=PETSc.IntType)
        if self.rows is not None:
            self.rows.destroy()
        self.rows = PETSc.IS().createGeneral(rows, comm=comm)
        self.block_size = self.rows.getSize()
        if self.block_size > 0:
            if self.block is None:
                self.block = self._ksp(comm, "contact_block_", BLOCK_DEFAULTS)
            sub = A.createSubMatrix(self.rows, self.rows)
            # the block changes size as the active set moves
            self.block.reset()
            self.block.setOperators(sub)
            self.block.setUp()
            sub.destroy()
        self._add("block_setup", clock)
        self._work = []

    def apply(self, pc: PETSc.PC, r: PETSc.Vec, e: PETSc.Vec) -> None:
        if self.block_size == 0:
            self.amg.solve(r, e)
            return
        if not self._work:
            self._work = [r.duplicate() for _ in range(2)]
        residual, correction = self._work
        self._solve_block(r, e)
        self._correct(r, e, residual, correction, self.amg.solve)
        self._correct(r, e, residual, correction, self._solve_block)

    def applyTranspose(self, pc: PETSc.PC, r: PETSc.Vec, e: PETSc.Vec) -> None:
        # the symmetric product is its own transpose when A and the AMG are symmetric
        self.apply(pc, r, e)

    def view(self, pc: PETSc.PC, viewer: PETSc.Viewer) -> None:
        if self.amg is None:   # -ksp_view_pre: before the first set-up
            viewer.printfASCII("contact block preconditioner (not set up yet)\n")
            return
        viewer.printfASCII(f"contact block preconditioner: {self.block_size} rows solved "
                           f"exactly, multigrid ({self.amg.getPC().getType()}) for the rest\n")

    def reset(self, pc: PETSc.PC) -> None:
        """PCReset: the operator's nonzero pattern changed (the current
        configuration's contact pairs moved). The multigrid must forget the
        converted matrix it reuses: BoomerAMG set up again on the old
        structure returned NaN at the first Krylov iteration (DOLFINx
        0.9/0.11, PETSc 3.22/3.25)."""
        for ksp in (self.amg, self.block):
            if ksp is not None:
                ksp.reset()

    def destroy(self, pc: PETSc.PC) -> None:
        for obj in (self.amg, self.block, self.rows, *self._work):
            if obj is not None:
                obj.destroy()
        self.amg = self.block = self.rows = None
        self._work = []

    # -- the parts -------------------------------------------------------------------
    def _correct(self, r, e, residual, correction, solve) -> None:
        """e += solve(r − A e)."""
        self.A.mult(e, residual)
        residual.aypx(-1.0, r)
        solve(residual, correction)
        e.axpy(1.0, correction)

    def _solve_block(self, r: PETSc.Vec, e: PETSc.Vec) -> None:
        """e = the block's solution on the contact rows, 0 elsewhere."""
        e.zeroEntries()
        r_c = r.getSubVector(self.rows)
        e_c = e.getSubVector(self.rows)
        self.block.solve(r_c, e_c)
        r.restoreSubVector(self.rows, r_c)
        e.restoreSubVector(self.rows, e_c)

    def _ksp(self, comm, name: str, defaults: dict) -> PETSc.KSP:
        ksp = PETSc.KSP().create(comm)
        prefix = self.prefix + name
        ksp.setOptionsPrefix(prefix)
        db = PETSc.Options()
        added = [key for key in defaults if not db.hasName(prefix + key)]
        for key in added:
            db[prefix + key] = defaults[key]
        ksp.setFromOptions()
        for key in added:
            db.delValue(prefix + key)
        return ksp

    def _add(self, name: str, since: float) -> None:
        self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - since


def tell_preconditioner(ksp: PETSc.KSP, stiffened_rows: Sequence[np.ndarray],
                        pattern_changed: bool) -> None:
    """What ``ksp``'s preconditioner needs to know of the Jacobian just
    assembled for it: a new set-up (symbolic factorization, multigrid) where
    the contact changed the matrix's pattern in a way PETSc does not notice
    (:class:`~dolfinx_mortar.linalg.sparse_products.PatternTrackingAdd`), and,
    for a :class:`ContactBlockPreconditioner`, the rows the contact terms
    stiffened (one array per term).

    A preconditioner whose last set-up failed is set up afresh too
    (:func:`~dolfinx_mortar.linalg.linear_solver.reset_after_failure`). Each
    new pattern used to reset it by chance; since the contact stiffness is
    added in place (a new Newton attempt after a cut-back keeps the pattern),
    nothing did, and MUMPS's error escaped a load path on 2 ranks."""
    pc = ksp.getPC()
    if not reset_after_failure(ksp) and pattern_changed:
        pc.reset()
    if pc.getType() == "python":
        context = pc.getPythonContext()
        if isinstance(context, ContactBlockPreconditioner):
            rows = list(stiffened_rows) or [np.zeros(0, dtype=PETSc.IntType)]
            context.contact_rows = np.unique(np.concatenate(rows)).astype(PETSc.IntType)
