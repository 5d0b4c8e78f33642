"""Sparse products and adds of the contact stiffness (PatternTrackingAdd,
InPlaceAdd, TransposeProduct, kron_identity), on 1 and 2 ranks."""
from __future__ import annotations

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.linalg import aij_blocks
from dolfinx_mortar.linalg.contact_block_pc import tell_preconditioner
from dolfinx_mortar.linalg.in_place_add import InPlaceAdd
from dolfinx_mortar.linalg.sparse_products import (PatternTrackingAdd, TransposeProduct,
                                                     kron_identity, transpose_mat_mult)

N = 40


def _matrix(entries, nnz: int, blocked: bool = False) -> PETSc.Mat:
    """An N × N AIJ matrix (BAIJ with blocks of 1 if ``blocked``) with the
    given (row, col, value) on this rank's rows."""
    if blocked:
        A = PETSc.Mat().createBAIJ((N, N), 1, nnz=(nnz, nnz), comm=MPI.COMM_WORLD)
    else:
        A = PETSc.Mat().createAIJ((N, N), nnz=(nnz, nnz), comm=MPI.COMM_WORLD)
    start, end = A.getOwnershipRange()
    for i, j, v in entries:
        if start <= i < end:
            A.setValue(i, j, v, addv=PETSc.InsertMode.ADD_VALUES)
    A.assemble()
    return A


def _laplacian() -> PETSc.Mat:
    entries = [(i, i, 2.0) for i in range(N)]
    entries += [(i, i + 1, -1.0) for i in range(N - 1)] + [(i + 1, i, -1.0) for i in range(N - 1)]
    A = _matrix(entries, 3)
    A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    return A


def _far_coupling(shift: int, scale: float) -> PETSc.Mat:
    """Entries far off the tridiagonal band, rows on both ranks' parts."""
    return _matrix([(i, (i + shift) % N, scale * (1 + i)) for i in range(0, N, 3)], 1)


def _dense(A: PETSc.Mat) -> np.ndarray:
    """The whole matrix on every rank (small N)."""
    start, end = A.getOwnershipRange()
    local = np.zeros((end - start, N))
    for i in range(start, end):
        cols, vals = A.getRow(i)
        local[i - start, cols] = vals
    return np.vstack(MPI.COMM_WORLD.allgather(local))


def _mallocs(A: PETSc.Mat) -> int:
    return MPI.COMM_WORLD.allreduce(int(A.getInfo()["mallocs"]))


def test_new_entries_are_merged_once_and_the_near_nullspace_is_kept():
    A = _laplacian()
    ones = A.createVecRight()
    ones.set(1.0)
    A.setNearNullSpace(PETSc.NullSpace().create(vectors=[ones]))
    expected = _dense(A)
    add = PatternTrackingAdd()
    K1, K2 = _far_coupling(17, 0.5), _far_coupling(23, -0.25)
    for K in (K1, K1, K2, K1):
        add(A, K)
        A.assemble()
        expected += _dense(K)
        scale = np.max(np.abs(expected))
        assert np.max(np.abs(_dense(A) - expected)) <= 1e-14 * scale
        # new entries were merged with a preallocated rebuild, not added one
        # malloc at a time (the slow path this class exists to avoid)
        assert _mallocs(A) == 0
        nullspace = A.getNearNullSpace()
        assert nullspace is not None and nullspace.handle
        assert abs(nullspace.getVecs()[0].norm() - np.sqrt(N)) <= 1e-12 * np.sqrt(N)
    # entries outside A's pattern still allocate as they come afterwards
    A.setValue(A.getOwnershipRange()[0], N - 1, 1.0, addv=PETSc.InsertMode.ADD_VALUES)
    A.assemble()


def test_in_place_add_writes_into_both_blocks_and_refuses_entries_the_pattern_lacks():
    """K's entries land in A's diagonal and off-diagonal blocks (the far
    coupling crosses the ranks' column ranges), with new values on the same
    pattern, a new pattern inside A's, and nothing added where K has an entry
    A lacks on one rank only."""
    A = _laplacian()
    assert aij_blocks.supports(A)      # Debian's PETSc: the fast path is the one taken
    add = PatternTrackingAdd()
    assert add(A, _far_coupling(17, 0.5))           # A gains K's pattern once
    A.assemble()
    expected = _dense(A)
    in_place = InPlaceAdd()
    for K in (_far_coupling(17, 0.25), _far_coupling(17, -2.0), _laplacian(),
              _far_coupling(17, 3.0)):
        before = A.getInfo()["nz_used"]
        assert in_place(A, K)
        A.assemble()
        expected += _dense(K)
        assert np.max(np.abs(_dense(A) - expected)) <= 1e-14 * np.max(np.abs(expected))
        assert A.getInfo()["nz_used"] == before and _mallocs(A) == 0
    # one entry outside A's pattern, on the last rank's rows alone
    lacking = _matrix([(N - 1, 0, 1.0), (N - 1, N - 1, 1.0)], 2)
    assert not in_place(A, lacking)
    A.assemble()
    assert np.array_equal(_dense(A), expected)


def test_the_newton_matrix_after_a_rebuild_takes_in_place_adds_again():
    """After PatternTrackingAdd rebuilt A (new storage), the positions are
    found again: the adds that follow are exact, and report no new pattern."""
    A = _laplacian()
    add = PatternTrackingAdd()
    expected = _dense(A)
    for K, changed in ((_far_coupling(17, 1.0), True), (_far_coupling(17, 2.0), False),
                       (_far_coupling(23, 1.0), True), (_far_coupling(17, 4.0), False),
                       (_far_coupling(23, 8.0), False)):
        assert add(A, K) == changed
        A.assemble()
        expected += _dense(K)
        assert np.max(np.abs(_dense(A) - expected)) <= 1e-14 * np.max(np.abs(expected))


def test_a_matrix_whose_arrays_are_not_reached_is_added_by_petsc():
    """A BAIJ Newton matrix (not AIJ: no in-place add): the same sums, and A's
    pattern is rebuilt only where K's pattern changed."""
    entries = [(i, i, 4.0) for i in range(N)] + [(i, (i + 1) % N, -1.0) for i in range(N)]
    A = _matrix(entries, 3, blocked=True)
    A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    assert not aij_blocks.supports(A)
    expected = _dense(A)
    add = PatternTrackingAdd()
    far = [(i, (i + 17) % N, 1.0 + i) for i in range(0, N, 3)]
    for scale, changed in ((1.0, True), (2.0, False), (-0.5, False)):
        K = _matrix([(i, j, scale * v) for i, j, v in far], 1, blocked=True)
        assert add(A, K) == changed
        A.assemble()
        expected += _dense(K)
        assert np.max(np.abs(_dense(A) - expected)) <= 1e-14 * np.max(np.abs(expected))


def _lu(A: PETSc.Mat) -> PETSc.KSP:
    ksp = PETSc.KSP().create(MPI.COMM_WORLD)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    return ksp


def _relative_residual(ksp: PETSc.KSP, A: PETSc.Mat) -> float:
    b = A.createVecLeft()
    b.set(1.0)
    x = b.duplicate()
    ksp.solve(b, x)
    r = b.duplicate()
    A.mult(x, r)
    r.axpy(-1.0, b)
    return r.norm() / b.norm()


def test_a_changed_pattern_is_reported_and_a_reset_solver_solves_the_new_matrix():
    """The rebuild does not raise A's nonzero state, so a factorized KSP would
    keep the analysis of the old pattern; the caller resets it when told."""
    A = _laplacian()
    for i in range(N):     # diagonally dominant, so that LU is well conditioned
        if A.getOwnershipRange()[0] <= i < A.getOwnershipRange()[1]:
            A.setValue(i, i, 3.0, addv=PETSc.InsertMode.ADD_VALUES)
    A.assemble()
    ksp = _lu(A)
    assert _relative_residual(ksp, A) < 1e-12
    add = PatternTrackingAdd()
    K = _far_coupling(17, 0.05)
    assert add(A, K)                   # a new pattern
    A.assemble()
    ksp.getPC().reset()
    ksp.setOperators(A)
    assert _relative_residual(ksp, A) < 1e-12
    assert not add(A, K)               # the same pattern again: only values
    A.assemble()
    assert _relative_residual(ksp, A) < 1e-12


def test_a_failed_factorization_is_set_up_afresh_for_the_next_matrix():
    """MUMPS keeps a failed factorization's state: the next matrix on the same
    pattern (a new Newton attempt after a cut-back, its stiffness added in
    place) then failed its solve with INFOG(1) = -3 on 2 ranks. The solver is
    told, and solves it."""
    A = _laplacian()
    start, end = A.getOwnershipRange()

    def fill(singular: bool) -> None:
        A.zeroEntries()
        for i in range(start, end):
            A.setValue(i, i, 0.0 if singular else 4.0)
        A.assemble()

    fill(False)
    ksp = _lu(A)
    assert _relative_residual(ksp, A) < 1e-12
    fill(True)                         # every pivot zero: the factorization fails
    b, x = A.createVecLeft(), A.createVecRight()
    b.set(1.0)
    ksp.solve(b, x)
    assert ksp.getConvergedReason() == PETSc.KSP.ConvergedReason.DIVERGED_PCSETUP_FAILED
    fill(False)
    tell_preconditioner(ksp, [], pattern_changed=False)
    ksp.setOperators(A)                # as SNES does after the Jacobian
    assert _relative_residual(ksp, A) < 1e-12


def test_plain_subset_add_would_malloc():
    """What the check above guards against: the same K added with
    SUBSET_NONZERO_PATTERN allocates entry by entry."""
    A = _laplacian()
    A.axpy(1.0, _far_coupling(17, 0.5), structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
    A.assemble()
    assert _mallocs(A) > 0


def _rectangular(rows: int, shift: int, seed: int) -> PETSc.Mat:
    """A rows × N matrix with three entries per row at columns that depend on
    ``shift``, values from ``seed``; rows on both ranks' parts."""
    rng = np.random.default_rng(seed)
    G = PETSc.Mat().createAIJ((rows, N), nnz=(3, 3), comm=MPI.COMM_WORLD)
    start, end = G.getOwnershipRange()
    values = rng.normal(size=(rows, 3))
    for i in range(start, end):
        columns = [(i * 7 + shift * k) % N for k in (1, 2, 3)]
        G.setValues([i], sorted(set(columns)), values[i, :len(set(columns))])
    G.assemble()
    return G


def _dense_rectangular(G: PETSc.Mat) -> np.ndarray:
    start, end = G.getOwnershipRange()
    local = np.zeros((end - start, G.getSize()[1]))
    for i in range(start, end):
        cols, vals = G.getRow(i)
        local[i - start, cols] = vals
    return np.vstack(MPI.COMM_WORLD.allgather(local))


def test_transpose_product_reuses_only_an_unchanged_pattern():
    """Gᵀ·(s G) with new values on the same pattern reuses the matrix (numeric
    phase only) and equals the fresh product; a new pattern makes a new one."""
    product = TransposeProduct()
    previous = None
    for shift, seed, reused in ((3, 1, False), (3, 2, True), (5, 3, False), (5, 4, True),
                                (3, 5, False)):
        G = _rectangular(15, shift, seed)
        SG = G.copy()
        scale = G.createVecLeft()
        scale.setArray(np.linspace(0.5, 2.0, scale.getSize())[slice(*scale.getOwnershipRange())])
        SG.diagonalScale(scale, None)
        K = product(G, SG)
        assert (K is previous) == reused
        previous = K
        dense = _dense_rectangular(G)
        expected = dense.T @ (np.linspace(0.5, 2.0, len(dense))[:, None] * dense)
        assert np.max(np.abs(_dense(K) - expected)) <= 1e-14 * np.max(np.abs(expected))
        assert np.allclose(_dense(K), _dense(transpose_mat_mult(G, SG)), rtol=0,
                           atol=1e-14 * np.max(np.abs(expected)))


def test_kron_identity_is_the_kronecker_product_with_the_identity():
    """L ⊗ I_bs, the friction blocks' mass matrix of the GLS kinds (row i·bs + k)."""
    entries = [(i, (3 * i + 7) % N, 1.0 + i) for i in range(N)] + [(i, i, 10.0) for i in range(N)]
    L = _matrix(entries, 2)
    for bs in (2, 3):
        expected = np.kron(_dense_rectangular(L), np.eye(bs))
        assert np.array_equal(_dense_rectangular(kron_identity(L, bs)), expected)
