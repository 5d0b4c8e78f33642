"""The worked examples of docs/DESIGN.md, §Architecture: a new friction law and
a new rigid obstacle are each one class that implements an interface
(:class:`~dolfinx_mortar.contact.laws.TangentialLaw`,
:class:`~dolfinx_mortar.contact.obstacles.RigidObstacle`), given to a contact
term and registered nowhere else."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from dolfinx_mortar import ContactProblem, CoulombFriction, RigidPlane, RigidSphere
from dolfinx_mortar.contact.laws import SEPARATED, SLIP, STICK, ReturnMapping
from support.scenes import block_on_plane


# -- a new law: Tresca friction (a slip threshold that ignores the pressure) -------------
@dataclass(frozen=True)
class TrescaFriction:
    """|q_T| ≤ τ: the tangential traction slips at a constant shear strength."""

    shear_strength: float
    tangential_penalty: float

    def penalty(self, normal_penalty: float) -> float:
        return self.tangential_penalty

    def return_mapping(self, trial, normal_force, tangential_weights, active):
        # the nodal force's bound τ W, with W = ω_T / ε_T (consistent scaling)
        limit = self.shear_strength * tangential_weights / self.tangential_penalty
        size = np.linalg.norm(trial, axis=1)
        stick = active & (size <= limit)
        slip = active & ~stick
        direction = np.zeros_like(trial)
        np.divide(trial, size[:, None], out=direction, where=slip[:, None])
        force = np.where(stick[:, None], trial, 0.0) + (limit * slip)[:, None] * direction
        eye = np.eye(trial.shape[1])[None]
        ratio = np.zeros(len(size))
        np.divide(limit * tangential_weights, size, out=ratio, where=slip)
        tangent = (np.where(stick, tangential_weights, 0.0)[:, None, None] * eye
                   + ratio[:, None, None] * (eye - direction[:, :, None] * direction[:, None, :]))
        state = np.full(len(size), SEPARATED, dtype=np.int8)
        state[stick], state[slip] = STICK, SLIP
        # the bound does not depend on the normal force
        return ReturnMapping(force, tangent, np.zeros_like(trial), state, direction, ratio)


# -- a new obstacle: a ball written from its signed distance only ------------------------
class Ball:
    """``φ(x) = |x − c| − R``: the RigidObstacle interface, nothing else."""

    def __init__(self, center, radius):
        self.initial_center = np.asarray(center, dtype=float)
        self.radius = float(radius)
        self.gdim = len(self.initial_center)
        self.displacement = np.zeros(self.gdim)

    def signed_distance(self, x):
        return np.linalg.norm(x - self.initial_center - self.displacement, axis=1) - self.radius

    def gradient(self, x):
        r = x - self.initial_center - self.displacement
        return r / np.linalg.norm(r, axis=1)[:, None]

    def hessian(self, x):
        r = x - self.initial_center - self.displacement
        length = np.linalg.norm(r, axis=1)
        unit = r / length[:, None]
        return (np.eye(self.gdim)[None] - unit[:, :, None] * unit[:, None, :]) / length[:, None, None]


def solve(obstacle, friction, kind="LcLS*"):
    V, tags = block_on_plane(n=(8, 4))
    problem = ContactProblem(V, tags, 1, obstacle=obstacle, E=1.0, nu=0.3, kind=kind,
                             penalty=1e3 * 8, fixed={3: {0: 0.0}},
                             tractions={2: [0.002, -0.01]}, friction=friction)
    problem.solve(load_steps=2, max_cuts=0)
    return problem


def test_a_users_obstacle_gives_the_library_balls_answer():
    """The same block pressed on a large ball and pushed sideways with Coulomb
    friction, against the user's Ball and against RigidSphere: the same
    displacements node by node (round-off: the user's obstacle is evaluated in
    absolute coordinates, the library's about a local origin). The ball's
    curvature enters the Jacobian and its tangent planes the slip."""
    center, radius = [0.5, -5.0], 5.0
    ours = solve(Ball(center, radius), CoulombFriction(0.3)).u.x.array
    library = solve(RigidSphere(center, radius), CoulombFriction(0.3)).u.x.array
    scale = MPI.COMM_WORLD.allreduce(float(np.max(np.abs(library))), op=MPI.MAX)
    error = MPI.COMM_WORLD.allreduce(float(np.max(np.abs(ours - library))), op=MPI.MAX)
    assert scale > 0 and error < 1e-9 * scale


def test_a_users_friction_law_sets_the_slip_traction():
    """Tresca friction, written in this file: where the block slips its
    tangential traction is the shear strength τ, whatever the pressure (which
    varies along the block); where it sticks it is below τ. Coulomb's μp on
    the same nodes differs, so the term did use the user's law."""
    tau = 2e-4
    problem = solve(RigidPlane([0.0, 0.0], [0.0, 1.0]), TrescaFriction(tau, 100.0))
    friction = problem.contact.results.surface_friction(gather=True)
    pressure = problem.contact.results.surface_pressure(gather=True).p
    size = np.linalg.norm(friction.q, axis=1)
    slip, stick = friction.stick_slip == SLIP, friction.stick_slip == STICK
    assert slip.sum() > 0 and stick.sum() > 0
    assert np.allclose(size[slip], tau, rtol=1e-10, atol=0)
    assert np.all(size[stick] <= tau * (1 + 1e-10))
    assert np.ptp(pressure[slip]) > 0.1 * np.max(pressure)   # Coulomb's bound would vary
