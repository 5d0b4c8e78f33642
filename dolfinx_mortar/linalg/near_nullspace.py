"""The rigid-body modes of each body: the near-nullspace that algebraic
multigrid needs to coarsen elasticity.

Smoothed-aggregation AMG (PETSc GAMG) builds its coarse spaces from the
vectors a matrix attaches as its near-nullspace; without them it coarsens
each displacement component as a scalar field and a penalty contact system
stalls or breaks down (CG with GAMG stopped with ``DIVERGED_INDEFINITE_PC``
on Hertz 3D). The bodies of a contact problem are separate components of one
mesh: each has its own rigid motions, which the contact penalty couples only
weakly, so the modes are built per body.
"""
from __future__ import annotations

from typing import Optional, Sequence

import numpy as np
import scipy.sparse
import scipy.sparse.csgraph
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.dolfinx_compat import ghosted_vector


def body_labels(V: fem.FunctionSpace) -> np.ndarray:
    """A label per local dof block (owned and ghost) that is the same on all
    blocks of one connected body of the mesh and differs between bodies, on
    every rank: the smallest global block index of the body.

    Connected means sharing a dof of V (a vertex for Lagrange spaces).
    """
    imap = V.dofmap.index_map
    n_local = imap.size_local + imap.num_ghosts
    dofs = V.dofmap.list
    n_cells = len(dofs)
    cells = np.repeat(np.arange(n_cells), dofs.shape[1])
    # a bipartite graph of cells and blocks; its components are the bodies
    graph = scipy.sparse.coo_matrix(
        (np.ones(len(cells)), (cells, n_cells + dofs.ravel())),
        shape=(n_cells + n_local, n_cells + n_local))
    _, component = scipy.sparse.csgraph.connected_components(graph, directed=False)
    component = component[n_cells:]
    global_index = imap.local_to_global(np.arange(n_local, dtype=np.int32))
    # The parts of one body on different ranks meet at shared blocks: spread
    # the smallest label over them until no rank changes (as many rounds as
    # the body crosses partitions, plus one).
    labels = ghosted_vector(imap, 1)
    comm = V.mesh.comm
    label_of = np.full(component.max(initial=-1) + 1, np.inf)
    np.minimum.at(label_of, component, global_index.astype(float))
    while True:
        with labels.localForm() as local:
            local.array[:] = -label_of[component]
        # MAX of the negated labels: the smallest label wins at owners
        labels.ghostUpdate(addv=PETSc.InsertMode.MAX_VALUES, mode=PETSc.ScatterMode.REVERSE)
        labels.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with labels.localForm() as local:
            seen = -local.array_r.copy()
        new = label_of.copy()
        np.minimum.at(new, component, seen)
        changed = comm.allreduce(bool(np.any(new < label_of)), op=MPI.LOR)
        label_of = new
        if not changed:
            break
    labels.destroy()
    return label_of[component].astype(np.int64)


def rigid_body_modes(V: fem.FunctionSpace,
                     bodies: Optional[np.ndarray] = None) -> PETSc.NullSpace:
    """The rigid-body modes of each body of V's mesh as a PETSc near-nullspace
    (orthonormal vectors): 3 per body in 2D (2 translations, 1 rotation), 6 in
    3D.

    Parameters
    ----------
    V
        A vector Lagrange space (block size = geometric dimension).
    bodies
        A label per local dof block (:func:`body_labels` by default): equal
        labels are one rigid body.
    """
    gdim = V.mesh.geometry.dim
    bs = V.dofmap.index_map_bs
    if bs != gdim:
        raise ValueError(f"rigid-body modes need a vector space of block size {gdim}, got {bs}")
    imap = V.dofmap.index_map
    n_owned = imap.size_local
    if bodies is None:
        bodies = body_labels(V)
    comm = V.mesh.comm
    names = np.unique(np.concatenate(comm.allgather(np.unique(bodies[:n_owned]))))
    x = _owned_node_coordinates(V)
    # rotations about the body's own centre keep the vectors well scaled
    rotations = [(0, 1)] if gdim == 2 else [(0, 1), (1, 2), (2, 0)]
    vectors = []
    for name in names:
        mine = bodies[:n_owned] == name
        count = comm.allreduce(int(mine.sum()))
        centre = comm.allreduce(x[mine].sum(axis=0)) / max(count, 1)
        xc = x - centre
        for k in range(gdim):
            mode = np.zeros((n_owned, bs))
            mode[mine, k] = 1.0
            vectors.append(mode)
        for i, j in rotations:
            mode = np.zeros((n_owned, bs))
            mode[mine, i] = -xc[mine, j]
            mode[mine, j] = xc[mine, i]
            vectors.append(mode)
    petsc_vectors = []
    for mode in vectors:
        v = ghosted_vector(imap, bs)
        with v.localForm() as local:
            local.array[:n_owned * bs] = mode.ravel()
        v.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        petsc_vectors.append(v)
    _orthonormalize(petsc_vectors)
    return PETSc.NullSpace().create(vectors=petsc_vectors, comm=comm)


def _orthonormalize(vectors: list[PETSc.Vec]) -> None:
    """Modified Gram–Schmidt, twice, on PETSc vectors in place.

    DOLFINx's ``la.orthonormalize`` takes its own ``la.Vector``; the
    nullspace needs PETSc vectors that outlive this function, and a handful
    of modes does not call for more than this.
    """
    for _ in range(2):
        for i, v in enumerate(vectors):
            for w in vectors[:i]:
                v.axpy(-w.dot(v), w)
            v.normalize()


def _owned_node_coordinates(V: fem.FunctionSpace) -> np.ndarray:
    """Coordinates of the owned dof blocks (nodes), shape (owned, gdim).

    A rank may own a node that none of its cells holds (seen on a 2-rank
    submesh): only cells give coordinates, so each copy that a local cell
    holds contributes and the owner takes their mean.
    tabulate_dof_coordinates leaves such a node unset (a rotation mode then
    had ‖K m‖ = 1).
    """
    gdim = V.mesh.geometry.dim
    bs = V.dofmap.index_map_bs
    imap = V.dofmap.index_map
    position = fem.Function(V)
    position.interpolate(lambda x: x[:gdim])
    held = np.zeros(imap.size_local + imap.num_ghosts)
    held[V.dofmap.list] = 1.0
    sums = ghosted_vector(imap, bs + 1)
    with sums.localForm() as local:
        values = local.array.reshape(-1, bs + 1)
        values[:, :bs] = position.x.array.reshape(-1, bs) * held[:, None]
        values[:, bs] = held
    sums.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    owned = sums.array_r.reshape(-1, bs + 1)
    x = owned[:, :gdim] / owned[:, bs:]
    sums.destroy()
    return x


#: a rigid motion that a bulk matrix resists by less than this fraction of its
#: own scale is free (only the contact can hold it)
FREE_MOTION = 1e-6


def free_rigid_motions(A: PETSc.Mat, modes: list[PETSc.Vec],
                       free_dofs: np.ndarray) -> list[PETSc.Vec]:
    """The combinations of rigid-body ``modes`` that the bulk matrix ``A``
    does not resist: an orthonormal basis of the ``r`` in their span with
    ``|A r| ≤ FREE_MOTION·|A|``.

    A Dirichlet row of A (``free_dofs`` 0 there, 1 elsewhere: the owned
    entries) is a unit row, and counts what ``r`` moves at its dof at A's
    scale; a spring in the user's form counts as it stiffens. The modes must
    be orthonormal (:func:`rigid_body_modes`). Used to decide whether only
    the contact can hold a body (:class:`~dolfinx_mortar.contact.newton.near_contact.NearContactStiffness`).
    Collective.
    """
    scale = A.norm(PETSc.NormType.NORM_INFINITY)
    images = []
    for r in modes:
        y = A.createVecLeft()
        A.mult(r, y)
        y.array[:] = np.where(free_dofs > 0.5, y.array_r, scale * r.array_r)
        images.append(y)
    gram = np.array([[a.dot(b) for b in images] for a in images]) / scale ** 2
    values, vectors = np.linalg.eigh(gram)
    free = []
    for value, c in zip(values, vectors.T):
        # the Gram matrix squares |A r|/|A|, and its eigenvalues are exact to
        # 1e-16 of the largest (about 1): 1e-12 is far above their round-off
        if value > FREE_MOTION ** 2:
            continue
        motion = modes[0].duplicate()
        motion.set(0.0)
        for ck, r in zip(c, modes):
            motion.axpy(ck, r)
        free.append(motion)
    return free


class RigidModes:
    """The rigid-body modes of the bodies of V's mesh, made on first use, and
    those of them that a bulk matrix leaves free.

    Parameters
    ----------
    V
        The displacement's space (a vector Lagrange space).
    """

    def __init__(self, V: fem.FunctionSpace):
        self._V = V
        self._modes: Optional[PETSc.NullSpace] = None

    def near_nullspace(self) -> PETSc.NullSpace:
        """The modes as a near-nullspace (:func:`rigid_body_modes`), made once."""
        if self._modes is None:
            self._modes = rigid_body_modes(self._V)
        return self._modes

    def free_motions(self, A: PETSc.Mat, bcs: Sequence[fem.DirichletBC] = ()) -> list[PETSc.Vec]:
        """The rigid motions that the bulk matrix ``A``, assembled with the
        Dirichlet rows of ``bcs``, does not resist (:func:`free_rigid_motions`).
        Collective."""
        from dolfinx.fem import petsc as fem_petsc
        V = self._V
        free = ghosted_vector(V.dofmap.index_map, V.dofmap.index_map_bs)
        free.set(1.0)
        fem_petsc.set_bc(free, list(bcs), alpha=0.0)
        motions = free_rigid_motions(A, list(self.near_nullspace().getVecs()), free.array_r)
        free.destroy()
        return motions
