"""Which gap model a set of contact options means, and building it.

The only place that chooses among the gap models: the contact term asks for
"the model of these options in this configuration" and then talks to it
through :class:`~dolfinx_mortar.contact.gap_sources.source.GapSource` alone.
"""
from __future__ import annotations

from dataclasses import replace
from functools import partial
from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from dolfinx_mortar.contact.gap_sources.current import CurrentMortarGap
from dolfinx_mortar.contact.gap_sources.current import CurrentObstacleGap
from dolfinx_mortar.contact.gap_sources.frozen import MortarGap, ObstacleGap
from dolfinx_mortar.contact.gap_sources.self_contact import (CurrentSelfContactGap,
                                                             SelfContactGap,
                                                             SelfContactGlobalGap)
from dolfinx_mortar.contact.gap_sources.global_gap import GlobalGap, covered_mass
from dolfinx_mortar.contact.laws import safe_weights
from dolfinx_mortar.contact.obstacles import RigidObstacle
from dolfinx_mortar.contact.options import ContactOptions
from dolfinx_mortar.contact.gap_sources.source import GapSource
from dolfinx_mortar.kinds import DUAL_KINDS, is_global, kind_name
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.tolerance import NEAR_CONTACT

FloatArray = npt.NDArray[np.float64]


def current_model(options: ContactOptions, slave: LagrangeSurface,
                  master: Optional[LagrangeSurface],
                  obstacle: Optional[RigidObstacle]) -> GapSource:
    """The model with the bases on the current surface, exact Jacobian; friction
    measures each step's slip on the frozen model where the step starts."""
    if obstacle is not None:
        model = CurrentObstacleGap(slave, obstacle, options.kind, options.law)
    elif options.self_contact:
        model = CurrentSelfContactGap(slave, options.kind, options.law, options.search_radius)
    else:
        model = CurrentMortarGap(slave, master, options.kind, options.law, options.search_radius,
                                 options.boundary_modification)
    model.frozen_at = partial(frozen_model, options.frozen_phase(), slave, master,
                              obstacle)
    return model


def frozen_model(options: ContactOptions, slave: LagrangeSurface,
                 master: Optional[LagrangeSurface], obstacle: Optional[RigidObstacle],
                 u_nodes: Optional[FloatArray] = None, u_vector=None) -> GapSource:
    """The model with bases and segmentation frozen in the configuration
    ``u_nodes`` (None: the initial one), linear in u about it (exact in u
    against an obstacle). ``u_vector``: the displacement vector of ``u_nodes``
    (an elastic master's model is linear about it)."""
    law = options.law
    if obstacle is not None:
        moved = slave if u_nodes is None else slave.moved(u_nodes)
        model = ObstacleGap(moved, obstacle, law, reference=u_nodes)
        mass = None
    else:
        if u_nodes is not None:  # bases and segmentation in the configuration u
            slave, master = slave.moved(u_nodes), master.moved(u_nodes)
        # the candidates are segmented in equal shares over the ranks: the
        # graph partition often gives one rank the whole contact zone
        coupling = MortarCoupling(slave, master, keep_points=law.pointwise,
                                  search_radius=options.search_radius,
                                  deal_segmentation=True, **pairing_options(options))
        source = SelfContactGap if options.self_contact else MortarGap
        model = source(coupling, law, None if u_nodes is None else u_vector,
                       boundary_modification=options.boundary_modification)
        mass = covered_mass(coupling) if is_global(options.kind) else None
    if is_global(options.kind):
        # a self-contact surface's global L is that of the surface against itself,
        # over the part its own other side covers (both passes share it)
        return (SelfContactGlobalGap if options.self_contact else GlobalGap)(model, law, mass)
    return model


def pairing_options(options: ContactOptions) -> dict:
    """What decides which facets a frozen configuration pairs, besides the
    radius: the ``MortarCoupling`` options of its bases, for every search that
    asks what they would pair. The search-radius check once paired with the
    slave's own normals instead of the interface normals: on a 3D self-contact
    slab (LcLS*) it found masters that the bases never pair, at every radius, and
    widened it 0.05 → 3.2, then warned that the pressure was cut off."""
    return {"interface_normals": True, "self_contact": options.self_contact}


def moved(u_nodes: FloatArray, since: Optional[FloatArray], comm: MPI.Comm) -> bool:
    """Whether the nodal displacement differs from ``since`` (None: zero) on any rank."""
    local = np.any(u_nodes != 0) if since is None else not np.array_equal(u_nodes, since)
    return comm.allreduce(bool(local), op=MPI.LOR)


def refuse_false_penetration(options: ContactOptions, slave: LagrangeSurface,
                             master: Optional[LagrangeSurface], current: GapSource, u,
                             u_nodes: FloatArray,
                             in_contact: bool = False) -> Optional[MortarCoupling]:
    """Refuse a dual kind on the current surface against an elastic master
    where it reads a penetration that is not there (NotImplementedError).

    A dual function is negative over part of its element: where the master
    covers only that part (cut by the search radius, or by the master's
    edge), ``∫ M̄_A d`` turns a separation into a penetration (two equal
    cylinders at u = 0: 0.009 where the search radius cuts, 0.037 at the
    surfaces' end with a larger radius, and Newton diverged to vertices of
    1e87). The boundary modification cures it, on the current surface too
    (where it is the default); this check is for the current surface without
    it (self-contact, where it is refused, or turned off). Its nodal gaps are
    compared here, where the term is made, with the modified ones of the
    frozen model: a node that only the current surface sees penetrating stops
    the construction, with the way out. A master that covers the slave's
    elements in full (a cylinder on a wider block) passes. Returns the frozen
    model's coupling where it was made (None elsewhere), for the term's other
    checks.

    ``in_contact``: u is where a load step's frozen phase converged, with the
    surfaces pressed. The two models' normals differ at the contact edge, so
    only a node whose mean gap ``ĝ_A/W_A`` reads a penetration deeper than
    :data:`~dolfinx_mortar.tolerance.NEAR_CONTACT` of its element length, where
    the frozen model reads none, is false (where the term is made, any depth).
    """
    if not (master is not None and options.kind in DUAL_KINDS and not options.law.pointwise
            and not options.boundary_modification):
        return None
    frozen = replace(options, basis_configuration="previous", boundary_modification=True)
    modified = frozen_model(frozen, slave, master, None, u_nodes, u.x.petsc_vec.copy())
    owned = slave.layout.num_owned
    state = current.evaluate(u, None)
    gaps = state.gaps[:owned]
    reference = modified.evaluate(u, None).gaps[:owned]
    comm = slave.layout.comm
    tolerance = slave.zero_length
    least = tolerance
    lengths = current.basis.node_lengths[:owned]
    if in_contact:
        gaps = gaps / safe_weights(state.lumped_weights[:owned])
        least = np.maximum(tolerance, NEAR_CONTACT * lengths)
    false = (gaps > least) & (reference <= tolerance)
    worst = comm.allreduce((float(gaps[false].max()) if false.any() else 0.0, comm.rank),
                           op=MPI.MAXLOC)
    count = comm.allreduce(int(false.sum()))
    if count == 0:
        return modified.coupling
    where = ""
    if comm.rank == worst[1]:
        node = int(np.flatnonzero(false)[np.argmax(gaps[false])])
        where = "at " + np.array2string(slave.x[node] + u_nodes[node], precision=4)
        if in_contact:       # a mean gap: in element lengths too
            where = f"{gaps[node] / lengths[node]:.3g} element lengths, {where}"
    where = comm.bcast(where, root=worst[1])
    other = "itself (self-contact)" if options.self_contact else "an elastic master"
    when = ", where the load step's frozen phase converged" if in_contact else ""
    raise NotImplementedError(
        f"{kind_name(options.kind)} on the current surface against {other} reads a false "
        f"penetration at {count} slave node(s) (largest {worst[0]:.3g}, {where}{when}): "
        "the master covers their elements only in part (cut by the search radius or the "
        "master's edge), where the dual functions are negative. The boundary modification "
        "cures this (boundary_modification=True, the default between two bodies; refused in "
        "self-contact on the current surface). Use a kind with positive functions "
        "(kind='LmLS*' or 'LmLS') or basis_configuration='previous'.")
