"""Which gap model a set of contact options means, and building it.

The only place that chooses among the gap models: the contact term asks for
"the model of these options in this configuration" and then talks to it
through :class:`~dolfinx_mortar.contact.state.GapModel` alone.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, replace
from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from dolfinx_mortar.contact.current_mortar import CurrentMortarGap
from dolfinx_mortar.contact.finite_deformation import CurrentObstacleGap
from dolfinx_mortar.contact.gaps import MortarGap, ObstacleGap, gap_kind
from dolfinx_mortar.contact.global_gap import GlobalGap, covered_mass
from dolfinx_mortar.contact.obstacles import RigidObstacle
from dolfinx_mortar.contact.state import GapModel
from dolfinx_mortar.kinds import (DUAL_KINDS, BasisKind, KindLike, is_global, kind_name,
                                  parse_kind)
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface

FloatArray = npt.NDArray[np.float64]

ACTIVE_SETS = ("nodal", "pointwise")
CONFIGURATIONS = ("initial", "previous", "current")


@dataclass(frozen=True)
class ContactOptions:
    """The options of a contact term (see :class:`~dolfinx_mortar.contact.term.ContactTerm`),
    checked on construction."""

    kind: BasisKind
    penalty: float
    scaling: str = "consistent"
    active_set: str = "nodal"
    basis_configuration: str = "initial"
    boundary_modification: bool = False
    search_radius: Optional[float] = None
    axisymmetric: bool = False

    @classmethod
    def checked(cls, kind: KindLike, penalty: float, scaling: str, active_set: str,
                basis_configuration: str, boundary_modification: Optional[bool],
                search_radius: Optional[float], elastic_master: bool,
                axisymmetric: bool = False) -> "ContactOptions":
        gap_kind(kind, scaling)  # names an unknown kind or scaling
        kind = parse_kind(kind)
        if not (isinstance(penalty, (int, float, np.floating, np.integer))
                and np.isfinite(penalty) and penalty > 0):
            raise ValueError(f"the penalty must be positive and finite, got {penalty!r}")
        if active_set not in ACTIVE_SETS:
            raise ValueError(f"unknown active set '{active_set}'; expected {ACTIVE_SETS}")
        if basis_configuration not in CONFIGURATIONS:
            raise ValueError(f"unknown basis configuration '{basis_configuration}'; "
                             f"expected {CONFIGURATIONS}")
        if boundary_modification is None:
            # the dual functions are negative near a facet's far node: a facet the
            # master covers only there reads a separation as a penetration. The
            # modification is the cure wherever it is implemented.
            boundary_modification = (elastic_master and kind in DUAL_KINDS
                                     and basis_configuration != "current"
                                     and active_set == "nodal")
        if basis_configuration == "current" and boundary_modification:
            raise NotImplementedError("basis_configuration='current' with the boundary "
                                      "modification is not implemented")
        if boundary_modification and not (elastic_master and kind in DUAL_KINDS):
            raise ValueError("the consistent boundary modification applies to the dual kinds "
                             "(LcLS*, LcLS) with an elastic master (master_tag)")
        if search_radius is not None and not (np.isfinite(search_radius) and search_radius > 0):
            raise ValueError(f"the search radius must be positive and finite, got "
                             f"{search_radius!r}")
        if active_set == "pointwise" and kind in DUAL_KINDS:
            warnings.warn("the pointwise active set with a dual kind: ∫M̄_A⟨d⟩ is negative "
                          "next to the contact edge, and Newton did not converge on any "
                          "curved contact tested (Hertz 2D); prefer active_set='nodal'",
                          RuntimeWarning, stacklevel=4)
        return cls(kind, float(penalty), scaling, active_set, basis_configuration,
                   bool(boundary_modification),
                   None if search_radius is None else float(search_radius), bool(axisymmetric))


def current_model(options: ContactOptions, slave: LagrangeSurface,
                  master: Optional[LagrangeSurface],
                  obstacle: Optional[RigidObstacle]) -> GapModel:
    """The model with the bases on the current surface, exact Jacobian."""
    pointwise = options.active_set == "pointwise"
    if obstacle is not None:
        return CurrentObstacleGap(slave, obstacle, options.kind, options.penalty,
                                  options.scaling, pointwise=pointwise)
    return CurrentMortarGap(slave, master, options.kind, options.penalty, options.scaling,
                            options.search_radius, pointwise=pointwise)


def frozen_model(options: ContactOptions, slave: LagrangeSurface,
                 master: Optional[LagrangeSurface], obstacle: Optional[RigidObstacle],
                 u_nodes: Optional[FloatArray] = None, u_vector=None) -> GapModel:
    """The model with bases and segmentation frozen in the configuration
    ``u_nodes`` (None: the initial one), linear in u about it (exact in u
    against an obstacle). ``u_vector``: the displacement vector of ``u_nodes``
    (an elastic master's model is linear about it)."""
    pointwise = options.active_set == "pointwise"
    if obstacle is not None:
        moved = slave if u_nodes is None else slave.moved(u_nodes)
        model = ObstacleGap(moved, obstacle, options.kind, options.penalty, options.scaling,
                            reference=u_nodes, pointwise=pointwise)
        mass = None
    else:
        if u_nodes is not None:  # bases and segmentation in the configuration u
            slave, master = slave.moved(u_nodes), master.moved(u_nodes)
        coupling = MortarCoupling(slave, master, keep_points=pointwise,
                                  search_radius=options.search_radius,
                                  interface_normals=True)
        model = MortarGap(coupling, options.kind, options.penalty, options.scaling,
                          None if u_nodes is None else u_vector,
                          boundary_modification=options.boundary_modification)
        mass = covered_mass(coupling) if is_global(options.kind) else None
    if is_global(options.kind):
        return GlobalGap(model, options.kind, options.penalty, options.scaling, mass)
    return model


def moved(u_nodes: FloatArray, since: Optional[FloatArray], comm: MPI.Comm) -> bool:
    """Whether the nodal displacement differs from ``since`` (None: zero) on any rank."""
    local = np.any(u_nodes != 0) if since is None else not np.array_equal(u_nodes, since)
    return comm.allreduce(bool(local), op=MPI.LOR)


def refuse_false_penetration(options: ContactOptions, slave: LagrangeSurface,
                             master: Optional[LagrangeSurface], current: GapModel, u,
                             u_nodes: FloatArray) -> Optional[MortarCoupling]:
    """Refuse a dual kind on the current surface against an elastic master
    where it reads a penetration that is not there (NotImplementedError).

    A dual function is negative over part of its element: where the master
    covers only that part (cut by the search radius, or by the master's
    edge), ``∫ M̄_A d`` turns a separation into a penetration (two equal
    cylinders at u = 0: 0.009 where the search radius cuts, 0.037 at the
    surfaces' end with a larger radius, and Newton diverged to vertices of
    1e87). In the initial
    and previous configurations the boundary modification cures it; on the
    current surface it is not differentiated (which elements are partly
    covered changes with u). Its nodal gaps are compared here, where the term
    is made, with the modified ones of the frozen model: a node that only the
    current surface sees penetrating stops the construction, with the way
    out. A master that covers the slave's elements in full (a cylinder on a
    wider block) passes. Returns the frozen model's coupling where it was made
    (None elsewhere), for the term's other checks.
    """
    if not (options.basis_configuration == "current" and master is not None
            and options.kind in DUAL_KINDS and options.active_set == "nodal"):
        return None
    frozen = replace(options, basis_configuration="previous", boundary_modification=True)
    modified = frozen_model(frozen, slave, master, None, u_nodes, u.x.petsc_vec.copy())
    owned = slave.layout.num_owned
    gaps = current.evaluate(u, None).gaps[:owned]
    reference = modified.evaluate(u, None).gaps[:owned]
    comm = slave.layout.comm
    tolerance = slave.zero_length
    false = (gaps > tolerance) & (reference <= tolerance)
    worst = comm.allreduce((float(gaps[false].max()) if false.any() else 0.0, comm.rank),
                           op=MPI.MAXLOC)
    count = comm.allreduce(int(false.sum()))
    if count == 0:
        return modified.coupling
    where = ""
    if comm.rank == worst[1]:
        node = int(np.flatnonzero(false)[np.argmax(gaps[false])])
        where = np.array2string(slave.x[node] + u_nodes[node], precision=4)
    where = comm.bcast(where, root=worst[1])
    raise NotImplementedError(
        f"{kind_name(options.kind)} on the current surface against an elastic master reads "
        f"a false penetration at {count} slave node(s) (largest {worst[0]:.3g} at {where}): "
        "the master covers their elements only in part (cut by the search radius or the "
        "master's edge), where the dual functions are negative. The boundary modification "
        "that cures this in the 'initial' and 'previous' configurations is not "
        "differentiated for 'current'. Use a kind with positive functions (kind='LmLS*' or "
        "'LmLS') or basis_configuration='previous'.")
