"""Distribution of slave functions over MPI ranks, and the global operations on them.

A :class:`NodeLayout` says which slave functions a rank owns and which it sees
as ghosts (DOLFINx's convention: owned first, ghosts after, contiguous global
ownership ranges). Everything that couples elements — summing element
contributions at functions, the global mass matrix ``L`` and its factorization —
goes through PETSc, so one code path serves a serial B-spline curve and a
distributed DOLFINx facet surface.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from petsc4py import PETSc

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

#: PETSc options prefix of the mass-matrix solver (override e.g. with
#: ``-dolfinx_mortar_mass_pc_factor_mat_solver_type superlu_dist``).
MASS_SOLVER_PREFIX = "dolfinx_mortar_mass_"


class NodeLayout:
    """Owned and ghost slave functions of this rank.

    Parameters
    ----------
    comm
        The communicator.
    num_owned
        Number of functions this rank owns (local indices 0..num_owned-1).
    ghosts
        Global indices of the ghost functions (local indices num_owned...).
    """

    def __init__(self, comm: MPI.Comm, num_owned: int, ghosts: npt.ArrayLike):
        self.comm = comm
        self.num_owned = int(num_owned)
        self.ghosts = np.asarray(ghosts, dtype=np.int64)
        self.offset = comm.scan(self.num_owned) - self.num_owned
        self.size_global = comm.allreduce(self.num_owned)
        self._ghosted: Optional[PETSc.Vec] = None

    @classmethod
    def serial(cls, n: int) -> "NodeLayout":
        """All of ``n`` functions on one rank (B-spline curves and surfaces)."""
        return cls(MPI.COMM_SELF, n, np.zeros(0, dtype=np.int64))

    @property
    def size_local(self) -> int:
        """Owned plus ghost functions."""
        return self.num_owned + len(self.ghosts)

    @property
    def global_indices(self) -> IntArray:
        """Global index of every local function."""
        return np.concatenate([np.arange(self.offset, self.offset + self.num_owned,
                                         dtype=np.int64), self.ghosts])

    def _ghosted_vector(self) -> PETSc.Vec:
        """The layout's ghosted vector, made on first use (collective) and kept.

        Making one is several collectives (its layout, its scatter's set-up),
        and the solves make many: 588 in the two iterative-path friction tests
        (tests/contact/test_friction_scenes.py), which on 4 ranks on 2 cores
        took 10.6 and 11.1 s before, 10.3 and 9.9 s after. Every use
        overwrites all of its entries first.
        """
        if self._ghosted is None:
            self._ghosted = PETSc.Vec().createGhost(self.ghosts.astype(PETSc.IntType),
                                                    size=(self.num_owned, PETSc.DECIDE),
                                                    comm=self.comm)
        return self._ghosted

    def on_cells(self, cells: IntArray) -> npt.NDArray[np.bool_]:
        """Whether each local function belongs to one of ``cells`` on any rank.

        A count, not a test of a computed weight against zero: ∫N_A of a
        quadratic triangle's vertex is 0 analytically and ±1e-17 in floats,
        so ``W_A > 0`` decided coverage by the CPU's round-off.
        """
        return self.sum_at_functions(cells, np.ones(np.shape(cells))) > 0.5

    def owned_on_cells(self, cells: IntArray) -> IntArray:
        """The owned functions that belong to one of ``cells`` on any rank (collective).

        Not the owned entries of ``np.unique(cells)``: a node can be owned by a rank
        that holds none of its surface cells (its bulk cells only), and such a node
        was left out of the GLS Newton system on 8 ranks.
        """
        return np.flatnonzero(self.on_cells(cells)[: self.num_owned])

    def sum_at_functions(self, cells: IntArray, element_values: FloatArray) -> FloatArray:
        """Σ over all elements on all ranks of element values at each local function.

        Parameters
        ----------
        cells
            Local function indices of each element, shape (cells, functions).
        element_values
            Per-element values, shape (cells, functions).

        Returns
        -------
        Totals at owned and ghost functions, shape (size_local,).
        """
        local = np.bincount(np.asarray(cells).ravel(),
                            weights=np.asarray(element_values).ravel(),
                            minlength=self.size_local)
        return self.complete(local)

    def max_at_functions(self, cells: IntArray, element_values: FloatArray) -> FloatArray:
        """The largest over all elements on all ranks of element values at each
        local function (0 at a function on no element; values ≥ 0).

        A rank can own a function whose elements all live on other ranks (it
        holds only the function's bulk cells): its local largest is 0 there.
        """
        local = np.zeros(self.size_local)
        np.maximum.at(local, np.asarray(cells).ravel(), np.asarray(element_values).ravel())
        return self.complete(local, PETSc.InsertMode.MAX)

    def complete(self, partial: FloatArray,
                 combine: PETSc.InsertMode = PETSc.InsertMode.ADD) -> FloatArray:
        """Combine partial values across ranks (added, or ``PETSc.InsertMode.MAX``:
        the largest), then copy the results to the ghosts."""
        vec = self._ghosted_vector()
        with vec.localForm() as lf:
            lf.array[:] = partial
        vec.ghostUpdate(addv=combine, mode=PETSc.ScatterMode.REVERSE)
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with vec.localForm() as lf:
            out = lf.array.copy()
        return out

    def vector(self, values: Optional[FloatArray] = None) -> PETSc.Vec:
        """A distributed PETSc vector holding the owned part of ``values``."""
        vec = PETSc.Vec().createMPI((self.num_owned, PETSc.DECIDE), comm=self.comm)
        if values is not None:
            vec.array[:] = values[: self.num_owned]
        return vec

    def to_local(self, vec: PETSc.Vec) -> FloatArray:
        """Owned and ghost values of a distributed vector in this layout."""
        ghosted = self._ghosted_vector()
        ghosted.array[:] = vec.array_r
        ghosted.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with ghosted.localForm() as lf:
            out = lf.array.copy()
        return out

    def assemble_matrix(self, cells: IntArray, element_matrices: FloatArray) -> PETSc.Mat:
        """Assemble square element matrices into a distributed AIJ matrix.

        Rows of functions that no element touches (possible when the layout is a
        DOLFINx function space and the surface a part of its boundary) get a unit
        diagonal, so the matrix stays invertible without renumbering the surface.
        """
        cells = np.asarray(cells, dtype=np.int64)
        return assemble_blocks(self, cells, self, self.global_indices[cells],
                               element_matrices, unit_diagonal=True)


def _block_matrix(rows: NodeLayout, cols: NodeLayout, bound: npt.NDArray,
                  row_global: IntArray, col_global: IntArray, blocks: FloatArray) -> PETSc.Mat:
    """A rows × cols AIJ matrix preallocated with ``bound`` nonzeros per owned
    row (more allocate as they come), with the blocks added (not assembled)."""
    bound = np.minimum(bound, cols.size_global).astype(PETSc.IntType)
    # the diagonal part has this rank's owned columns, which can be none (a
    # master surface on 8 ranks): PETSc refuses room for 1 in a part 0 wide
    mat = PETSc.Mat().createAIJ(((rows.num_owned, rows.size_global),
                                 (cols.num_owned, cols.size_global)),
                                nnz=(np.minimum(bound, cols.num_owned), bound),
                                comm=rows.comm)
    mat.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    nb, nr = row_global.shape
    if nb > 0:  # petsc4py divides by the batch size
        nc = np.asarray(col_global).shape[1]
        mat.setValuesRCV(row_global.astype(PETSc.IntType),
                         np.asarray(col_global, dtype=PETSc.IntType),
                         np.ascontiguousarray(blocks, dtype=np.float64).reshape(nb, nr * nc),
                         addv=PETSc.InsertMode.ADD_VALUES)
    return mat


def assemble_blocks(rows: NodeLayout, row_cells: IntArray, cols: NodeLayout,
                    col_global: IntArray, blocks: FloatArray,
                    unit_diagonal: bool = False) -> PETSc.Mat:
    """Assemble dense blocks into a distributed AIJ matrix (rows × cols).

    Parameters
    ----------
    rows, cols
        Layouts of the row and column functions.
    row_cells
        Local row indices of each block, shape (blocks, nr).
    col_global
        Global column indices of each block, shape (blocks, nc).
    blocks
        Values, shape (blocks, nr, nc); added where blocks overlap.
    unit_diagonal
        Put 1 on the diagonal of owned rows that no block touches (square
        matrices only).
    """
    row_cells = np.asarray(row_cells, dtype=np.int64)
    nb = row_cells.shape[0]
    nc = np.asarray(col_global).shape[1] if nb else 1
    touches = rows.sum_at_functions(row_cells, np.ones(row_cells.shape))
    # Each touching block adds at most nc columns; off-rank contributions make
    # an exact count costly, so preallocate this bound.
    mat = _block_matrix(rows, cols, touches[: rows.num_owned] * nc + 1,
                        rows.global_indices[row_cells], col_global, blocks)
    if unit_diagonal:
        untouched = (rows.offset + np.flatnonzero(touches[: rows.num_owned] == 0)
                     ).astype(PETSc.IntType)
        if len(untouched) > 0:
            mat.setValuesRCV(untouched[:, None], untouched[:, None],
                             np.ones((len(untouched), 1)),
                             addv=PETSc.InsertMode.ADD_VALUES)
    mat.assemble()
    return mat


def assemble_global_blocks(layout: NodeLayout, row_global: IntArray, col_global: IntArray,
                           blocks: FloatArray, cols: Optional[NodeLayout] = None) -> PETSc.Mat:
    """Assemble dense blocks into an AIJ matrix over ``layout`` (× ``cols``,
    default ``layout``), with rows given by global index: they may be owned by
    any rank (PETSc sends them).

    Needed where a block's rows are not this rank's functions or ghosts, e.g.
    the second derivatives of a slave–master pair, whose master rows can live
    anywhere. ``blocks``: (blocks, nr, nc), added where they overlap.
    Collective. Every owned row is preallocated for the blocks of all ranks
    (one reduction over the global rows).
    """
    row_global = np.asarray(row_global, dtype=np.int64)
    nc = np.asarray(col_global).shape[1] if row_global.shape[0] else 1
    # every owned row gets room for the blocks of all ranks that touch it: the
    # blocks a rank computes need not be its own rows (the Hessians of the
    # current configuration are shared out evenly), and entries that arrive
    # beyond the preallocation are one malloc each
    comm = layout.comm
    touches = np.bincount(row_global.ravel(), minlength=layout.size_global).astype(np.int64)
    if comm.size > 1:
        owned_counts = np.array(comm.allgather(layout.num_owned), dtype=np.int64)
        mine = np.empty(layout.num_owned, dtype=np.int64)
        comm.Reduce_scatter(touches, mine, recvcounts=owned_counts, op=MPI.SUM)
        touches = mine
    mat = _block_matrix(layout, cols or layout, touches * nc + 1, row_global, col_global,
                        blocks)
    mat.assemble()
    return mat


class MassMatrixSolver:
    """A sparse direct factorization of the global slave mass matrix ``L``.

    ``L`` is never inverted densely (docs/DESIGN.md, §Bases). The default is a Cholesky
    factorization by MUMPS; the PETSc options database can change it under the
    prefix :data:`MASS_SOLVER_PREFIX`.
    """

    def __init__(self, layout: NodeLayout, matrix: PETSc.Mat):
        self.layout = layout
        self.matrix = matrix
        ksp = PETSc.KSP().create(layout.comm)
        ksp.setOperators(matrix)
        ksp.setType("preonly")
        ksp.getPC().setType("cholesky")
        ksp.getPC().setFactorSolverType("mumps")
        ksp.setOptionsPrefix(MASS_SOLVER_PREFIX)
        ksp.setFromOptions()
        ksp.setUp()
        self.ksp = ksp
        self._rhs = layout.vector()
        self._sol = layout.vector()

    def solve(self, rhs: FloatArray) -> FloatArray:
        """Solve ``L x = rhs`` for local (owned + ghost) arrays; returns local ``x``."""
        self._rhs.array[:] = rhs[: self.layout.num_owned]
        self.ksp.solve(self._rhs, self._sol)
        reason = self.ksp.getConvergedReason()
        if reason < 0:
            raise RuntimeError(f"the mass-matrix solve failed (KSP reason {reason})")
        return self.layout.to_local(self._sol)
