"""Checks of a contact term's set-up against its geometry, made where the term
is made: an obstacle facing into the slave body (warned about), bodies
overlapping at the start, a penalty that cannot represent a force or is far
below E/h (refused). Each is collective and names the cause (they were Newton
failures blamed on the load or on a master out of reach).
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from dolfinx_mortar.collective_warnings import warn
from dolfinx_mortar.contact.checks.thresholds import DEEP_PENETRATION
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.surfaces.facet_surface import nodal_displacement
from dolfinx_mortar.tolerance import length_scale, zero_length


def warn_if_the_obstacle_faces_away(obstacle, slave, comm: MPI.Comm) -> None:
    """Warn when an obstacle's outward normal (the gradient of its signed
    distance) nowhere faces the slave surface's outward normal: it points into
    the slave body (a RigidPlane with its normal flipped), and nothing can
    ever touch. It was reported as Newton "stalled" with nothing in reach
    (collective). A warning, as for a master facing away
    (:meth:`~dolfinx_mortar.contact.checks.range_checks.RangeChecks.warn_if_no_master_is_in_reach`).
    """
    facing = False
    if len(slave.cells):
        normals = slave.cell_normals()                              # (cells, nodes, gdim)
        x = slave.x[slave.cells]
        with np.errstate(invalid="ignore", divide="ignore"):
            outward = obstacle.gradient(x.reshape(-1, slave.gdim)).reshape(x.shape)
        # unit vectors: facing where they point against each other at all
        facing = bool(np.any(np.einsum("cng,cng->cn", normals, outward) < 0))
    if not comm.allreduce(facing, op=MPI.LOR):
        warn(f"the obstacle {obstacle!r} faces away from the slave surface: at "
             "every slave node its outward normal points the same way as the "
             "slave's outward normal (or across it), so the obstacle's normal "
             "points into the slave body and nothing can touch it. The obstacle's "
             "normal must point out of the obstacle, towards the body (for a "
             "RigidPlane: flip its normal)", comm)


#: how many times the search radius a check of an initial overlap looks
OVERLAP_SEARCH_FACTORS = (4.0, 16.0)


def check_initial_overlap(term, coupling, built_at_u: bool) -> None:
    """Refuse a slave body that starts inside the master beyond the search radius.

    Against an elastic master whose segmentation ``coupling`` paired no facet,
    the surfaces are searched again with wider radii
    (:data:`OVERLAP_SEARCH_FACTORS`); where a slave node lies behind the master
    surface by more than DEEP_PENETRATION slave element lengths
    (:mod:`~dolfinx_mortar.contact.checks.thresholds`), the bodies overlap. Two blocks
    overlapping by two elements were reported as out of reach (collective).
    ``built_at_u``: the segmentation was made at the present u (not at u = 0).

    Raises
    ------
    ValueError
        Naming the depth and a slave node, on every rank.
    """
    comm = term.comm
    if term.master is None or coupling is None or comm.allreduce(len(coupling.pairs)) > 0:
        return
    moved = built_at_u
    displacements = ([nodal_displacement(surface, term.u) for surface in (term.slave, term.master)]
                     if moved else [None, None])
    for factor in OVERLAP_SEARCH_FACTORS:
        radius = factor * coupling.search_radius
        wide = MortarCoupling(term.slave, term.master, *displacements, search_radius=radius)
        if comm.allreduce(len(wide.pairs)) == 0:
            continue
        gap = wide.operators("LmLS*").nodal_gap()        # ∫N_A d over the covered part
        covered = wide.covered_element_mass()[2]         # ∫_cov N_A
        depth = np.full(len(covered), -np.inf)
        np.divide(gap, covered, out=depth, where=covered > 0)
        ratio, d, x = term.results.deepest(depth)
        if ratio > DEEP_PENETRATION:
            raise ValueError(
                f"slave and master overlap at the start: the slave surface lies {d:.3g} "
                f"({ratio:.3g} slave element lengths) inside the master at the slave node "
                f"{x}, beyond the search radius {coupling.search_radius:.3g}, so no facet is "
                "paired and the contact cannot act. Move the bodies apart, or check the "
                "slave and master tags")
        return


def refuse_a_self_overlap(ratio: float, depth: float, where: list,
                          global_kind: bool = False) -> None:
    """A self-contact surface whose deepest node (``ratio`` element lengths, ``depth``,
    at ``where``; the same on every rank) lies more than DEEP_PENETRATION inside the
    body at the start is refused: with two bodies it is warned about only.
    ``global_kind``: the term's kind is GLS or GLS*, whose ``L⁻¹`` can read such
    a depth where no overlap is (the message says so)."""
    if ratio > DEEP_PENETRATION:
        hint = ("; with a GLS kind it is also what a node reads where its own surface "
                "covers its facets over a sliver only: the covered part's L is nearly "
                "singular there and L⁻¹ amplifies that piece's gap (the C slab in 3D: a "
                "node 1% covered read about 7 element lengths deep where LmLS* reads it 1.4 "
                "element lengths apart; docs/SELF_CONTACT.md): a local kind reads the "
                "true gap"
                if global_kind else "")
        raise ValueError(f"the surface overlaps itself at the start: the node {where} lies "
                         f"{depth:.3g} ({ratio:.3g} element lengths) inside the body's own "
                         "surface. A self-contact surface must start without overlaps: "
                         "check the geometry and the tag; or a wall of the body thinner "
                         "than the search radius pairs with its own other side through "
                         f"the material: pass a search_radius below the wall's thickness{hint}")


#: a penalty below this many times E/h is refused where E is known
#: (:class:`~dolfinx_mortar.small_strain.elastic.ContactProblem`): at a strain
#: of 1e-3 it lets the bodies pass through each other by 1e5 element lengths
LOWEST_PENALTY_OVER_E_H = 1e-8


def slave_element_lengths(slave, comm: MPI.Comm) -> tuple[float, float]:
    """The smallest and largest slave element length over all ranks (each
    element's the diagonal of its nodes' bounding box)."""
    x = slave.x[slave.cells]
    local = np.linalg.norm(x.max(axis=1) - x.min(axis=1), axis=1) if len(x) else np.zeros(0)
    return (comm.allreduce(float(np.min(local, initial=np.inf)), op=MPI.MIN),
            comm.allreduce(float(np.max(local, initial=0.0)), op=MPI.MAX))


def check_penalty_represents_a_force(penalty: float, slave, comm: MPI.Comm) -> None:
    """Refuse a penalty so small that no penetration the geometry can measure
    gives a force: ε · h_min^(gdim−1) · (the geometry's zero length) below the
    smallest normal float. A penalty of 1e-300 was accepted and the failure
    blamed on the load (nothing ever touched). Collective.

    Raises
    ------
    ValueError
        Naming the penalty, on every rank.
    """
    h_min, _ = slave_element_lengths(slave, comm)
    zero = zero_length(length_scale(slave.x, comm))
    force = penalty * h_min ** (slave.gdim - 1) * zero
    if force < np.finfo(np.float64).tiny:
        raise ValueError(f"the penalty {penalty:.3g} cannot represent a contact force: a "
                         f"penetration at the geometry's round-off ({zero:.3g}) over the "
                         f"smallest slave element ({h_min:.3g}) gives a force {force:.3g}, "
                         "below the smallest normal floating-point number; the penalty must be "
                         "of the order of E/h (Young's modulus over the element length) "
                         "or larger")


def check_penalty_against_stiffness(penalty: float, E: float, slave, comm: MPI.Comm) -> None:
    """Refuse a penalty below :data:`LOWEST_PENALTY_OVER_E_H` times E/h, with h
    the largest slave element length (collective).

    Raises
    ------
    ValueError
        Naming the penalty, E, h and E/h, on every rank.
    """
    _, h_max = slave_element_lengths(slave, comm)
    scale = E / h_max
    if penalty < LOWEST_PENALTY_OVER_E_H * scale:
        raise ValueError(f"the penalty {penalty:.3g} is {penalty / scale:.2g} times E/h = "
                         f"{scale:.3g} (E = {E:.3g}, h = {h_max:.3g} the largest slave element "
                         "length): the bodies would pass through each other by many element "
                         "lengths. Use a penalty of about 10 to 1000 E/h")
