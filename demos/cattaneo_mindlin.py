"""Cattaneo–Mindlin partial slip: two equal cylinders or spheres pressed together, then sheared.

Two elastically similar bodies, so that the normal and tangential problems
decouple:

- ``--geometry cylinder`` (plane strain): the upper half of a cylinder of
  radius R on the lower half of an equal one, loads per unit length;
- ``--geometry sphere`` (3D): two equal hemispheres, modelled as the half
  y ≥ 0 (the lateral load along x keeps that symmetry), loads on the whole
  sphere.

The lower body is fixed at its flat bottom. A rigid holder moves the upper
flat face without turning it (a body loaded by forces alone would roll):
down until the contact carries the normal load P, then sideways until it
carries Q < μP while P is held. The contact stays Hertz's (half-width or
radius a), and a central stick zone of size c remains, with (Cattaneo 1938,
Mindlin 1949; Johnson, Contact Mechanics §7.1–7.2)

    c/a = (1 − Q/(μP))^{1/2} (cylinder),   (1 − Q/(μP))^{1/3} (sphere),
    q(r) = μ p0 (√(1 − r²/a²) − (c/a) √(1 − r²/c²))  for r < c,
    q(r) = μ p0 √(1 − r²/a²)                          for c ≤ r ≤ a.

Hertz with R* = R/2 and E* = E/(2(1 − ν²)): a = √(4PR*/(πE*)),
p0 = 2P/(πa) for the cylinders; a = (3PR*/(4E*))^{1/3}, p0 = 3P/(2πa²) for the
spheres. The demo reports a (the Hertz profile fitted to the pressures), c,
and the L2 error of the tangential traction against q over the contact. c is
read from the nodes: for the cylinder midway between the outermost sticking
node and the next one on each side, and for the sphere from the sticking
nodes' area, πc² = Σ W_A (doubled for the half model).

The mesh is graded to a/(40·refine) at the contact for the cylinder, and to
a/(8·refine) for the sphere. The holder's approach δ and shift s are found by
secant steps on the contact resultant (to 1e-5 of P and Q). s only grows, so
that no slip reverses.

    python3 demos/cattaneo_mindlin.py --tangential 0.0015 --mu 0.3 --json results/cm.json
    python3 demos/cattaneo_mindlin.py --geometry sphere --json results/cm_sphere.json
"""
from __future__ import annotations

import argparse
import time
from typing import Optional, Sequence

import numpy as np
from mpi4py import MPI

from demo_support.cli import parse_args_and_petsc_options, solver_demo_parser
from demo_support.hertz_fit import fit_hertz_profile
from demo_support.hertz_meshes import (FIXED, LOAD, MASTER, SLAVE, SYMMETRY_Y,
                                      half_disk_pair_mesh, half_sphere_pair_mesh)
from dolfinx_mortar.io.output import write_json


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = solver_demo_parser(__doc__)
    parser.add_argument("--geometry", default="cylinder", choices=("cylinder", "sphere"),
                        help="two cylinders (plane strain) or two spheres (3D half model)")
    parser.add_argument("--radius", type=float, default=1.0, help="radius R (1)")
    parser.add_argument("--force", type=float, default=None,
                        help="normal load P: per unit length for the cylinder (0.01), on the "
                             "whole sphere (0.0015); a ≈ 0.1 R")
    parser.add_argument("--tangential", type=float, default=None,
                        help="tangential load Q, below μP (default μP/2)")
    parser.add_argument("--mu", type=float, default=0.3, help="friction coefficient μ (0.3)")
    parser.add_argument("--kind", default="LcLS*", help="mortar basis kind (LcLS*)")
    parser.add_argument("--basis-configuration", default="initial",
                        choices=("initial", "previous", "current"))
    parser.add_argument("--refine", type=float, default=1.0,
                        help="mesh density factor: contact size a/(40·refine) for the "
                             "cylinder, a/(8·refine) for the sphere (1)")
    parser.add_argument("--penalty", type=float, default=1e3,
                        help="penalty ε as a multiple of E/h_contact (1e3)")
    parser.add_argument("--tangential-penalty", type=float, default=None,
                        help="ε_T as a multiple of E/h_contact (default: the library's, ε/10)")
    parser.add_argument("--load-steps", type=int, default=4,
                        help="steps of the approach's first guess (4)")
    parser.add_argument("--tangential-steps", type=int, default=4,
                        help="steps of the shift's first guess (4)")
    parser.add_argument("--output", default=None, help="XDMF file for the steps")
    parser.add_argument("--json", default=None, help="write the key figures as JSON here")
    args = parse_args_and_petsc_options(parser, argv)
    if args.force is None:
        args.force = 0.01 if args.geometry == "cylinder" else 0.0015
    if args.tangential is None:
        args.tangential = 0.5 * args.mu * args.force
    return args


def reference(args: argparse.Namespace) -> dict:
    """Hertz's a, p0 and approach δ, and Cattaneo–Mindlin's c for the arguments."""
    if not 0 <= args.tangential < args.mu * args.force:
        raise ValueError(f"need 0 ≤ Q < μP for partial slip, got Q = {args.tangential}, "
                         f"μP = {args.mu * args.force}")
    E_star = args.E / (2 * (1 - args.nu ** 2))
    R_star = args.radius / 2      # two equal bodies
    P, ratio = args.force, 1 - args.tangential / (args.mu * args.force)
    if args.geometry == "cylinder":
        a = np.sqrt(4 * P * R_star / (np.pi * E_star))
        # the approach of two cylinders (Johnson §5.6), a first guess for the holder
        approach = P / (np.pi * E_star) * (2 * np.log(4 * args.radius / a) - 1)
        return {"a": a, "p0": 2 * P / (np.pi * a), "c": a * ratio ** (1 / 2),
                "approach": approach}
    a = (3 * P * R_star / (4 * E_star)) ** (1 / 3)
    return {"a": a, "p0": 3 * P / (2 * np.pi * a ** 2), "c": a * ratio ** (1 / 3),
            "approach": a ** 2 / R_star}


def tangential_traction(r: np.ndarray, ref: dict, mu: float) -> np.ndarray:
    """Johnson's q at distance r from the centre of contact (positive, along −Q
    on the upper body)."""
    a, c, p0 = ref["a"], ref["c"], ref["p0"]
    q = mu * p0 * np.sqrt(np.maximum(0.0, 1 - (r / a) ** 2))
    inside = np.abs(r) < c
    q[inside] -= mu * p0 * (c / a) * np.sqrt(1 - (r[inside] / c) ** 2)
    return q


def stick_zone(x: np.ndarray, states: np.ndarray) -> float:
    """Half the width of the central stick zone: on each side midway between
    the outermost sticking node and the next node, which slips or is apart."""
    order = np.argsort(x)
    x, states = x[order], states[order]
    stick = np.flatnonzero(states == 1)
    if len(stick) == 0:
        return 0.0
    first, last = stick[0], stick[-1]
    left = 0.5 * (x[first] + x[first - 1]) if first > 0 else x[first]
    right = 0.5 * (x[last] + x[last + 1]) if last + 1 < len(x) else x[last]
    return 0.5 * (right - left)


def build(args: argparse.Namespace, ref: dict, comm: MPI.Comm):
    """The mesh, the contact term, the problem and the holder's displacement
    Constants (approach δ, shift s)."""
    from dolfinx import fem
    from petsc4py import PETSc
    from dolfinx_mortar import ContactTerm, CoulombFriction
    from dolfinx_mortar.small_strain.elastic import linear_elastic_residual
    from dolfinx_mortar.solver.nonlinear_problem import NonlinearContactProblem
    sphere = args.geometry == "sphere"
    h = ref["a"] / ((8 if sphere else 40) * args.refine)
    if sphere:
        domain, tags = half_sphere_pair_mesh(args.radius, ref["a"], h, comm)
    else:
        domain, tags = half_disk_pair_mesh(args.radius, ref["a"], h, 1, comm)
    dim = domain.geometry.dim
    V = fem.functionspace(domain, ("Lagrange", 1, (dim,)))
    u = fem.Function(V, name="displacement")
    eps_t = None if args.tangential_penalty is None else args.tangential_penalty * args.E / h
    contact = ContactTerm(u, tags, SLAVE, master_tag=MASTER, kind=args.kind,
                          penalty=args.penalty * args.E / h,
                          basis_configuration=args.basis_configuration,
                          friction=CoulombFriction(args.mu, eps_t))
    approach = fem.Constant(domain, PETSc.ScalarType(0.0))
    shift = fem.Constant(domain, PETSc.ScalarType(0.0))
    fdim = dim - 1
    fixed = fem.locate_dofs_topological(V, fdim, tags.find(FIXED))
    top = tags.find(LOAD)
    vertical = V.sub(dim - 1)
    bcs = [fem.dirichletbc(np.zeros(dim, dtype=PETSc.ScalarType), fixed, V),
           fem.dirichletbc(shift, fem.locate_dofs_topological(V.sub(0), fdim, top), V.sub(0)),
           fem.dirichletbc(approach, fem.locate_dofs_topological(vertical, fdim, top), vertical)]
    if sphere:
        plane = fem.locate_dofs_topological(V.sub(1), fdim, tags.find(SYMMETRY_Y))
        bcs.append(fem.dirichletbc(PETSc.ScalarType(0.0), plane, V.sub(1)))
    problem = NonlinearContactProblem(linear_elastic_residual(u, args.E, args.nu), u, contact,
                                      bcs)
    return contact, problem, approach, shift, h


class Holder:
    """The rigid holder of the upper body: it moves its flat face by (s, −δ)
    along x and the vertical without turning it, and finds the δ and s that
    make the contact carry P and Q (a body loaded by forces alone would roll).
    ``share``: the modelled share of the body (½ for the half sphere);
    ``force``: P, the scale of the absolute residual tolerance."""

    def __init__(self, contact, problem, approach, shift, steps: int, share: float = 1.0,
                 force: float = 1.0):
        from dolfinx_mortar import LoadPathSolver
        self.contact, self.approach, self.shift = contact, approach, shift
        self.share = share
        # a secant correction is a step of about 1e-5 of the forces: 1e-8 of
        # its own force fell below the residual's round-off with GLS*
        # (3e-14, through L⁻¹), so 1e-10 of P is accepted too
        self.solver = LoadPathSolver(problem, petsc_options={"snes_atol": 1e-10 * force})
        self.steps = steps
        self.newton_iterations = self.load_steps = self.cut_backs = 0

    def forces(self) -> tuple[float, float]:
        """(P, Q) that the contact carries: the resultant on the upper body."""
        C = self.contact.results.contact_force() / self.share
        return float(C[-1]), float(-C[0])

    def move(self, constant, target: float, steps: int) -> None:
        start = float(constant.value)

        def update(t: float) -> None:
            constant.value = start + t * (target - start)

        result = self.solver.solve(update, load_steps=steps)
        self.newton_iterations += result.newton_iterations
        self.load_steps += len(result.steps)
        self.cut_backs += len(result.cut_backs)

    def reach(self, constant, which: int, target: float, guess: float,
              rtol: float = 1e-5, max_corrections: int = 8) -> None:
        """Move ``constant`` (δ or s) until force ``which`` (0: P, 1: Q) is
        ``target``: ``guess`` in the holder's steps, then secant corrections of
        one step each. Q grows concavely in s, so the secant through the
        origin reaches it from below: s never moves back (which would
        reverse the slip)."""
        points = [(0.0, 0.0)]
        self.move(constant, guess, self.steps)
        points.append((guess, self.forces()[which]))
        for _ in range(max_corrections):
            (x0, f0), (x1, f1) = points[-2], points[-1]
            if abs(f1 - target) <= rtol * abs(target):
                return
            slope = (f1 - f0) / (x1 - x0) if which == 0 else f1 / x1
            self.move(constant, x1 + (target - f1) / slope, 1)
            points.append((float(constant.value), self.forces()[which]))
        raise RuntimeError(f"the holder did not reach the force {target} (last {points[-1]})")


def results(args: argparse.Namespace, contact, ref: dict) -> dict:
    """a, c and the tangential traction's error, gathered on every rank."""
    comm = contact.comm
    slave = contact.slave
    sphere = args.geometry == "sphere"
    state = contact.evaluate()
    mine = slave.owned_nodes
    # distance from the centre of contact in the contact plane
    r = np.linalg.norm(slave.x[:, :2], axis=1) if sphere else slave.x[:, 0]
    x = np.concatenate(comm.allgather(r[mine]))
    p = np.concatenate(comm.allgather(contact.results.nodal_pressures(state)[mine]))
    states = contact.results.slip_states(state)
    fit = fit_hertz_profile(np.abs(x), p, ref["a"])
    if sphere:
        # πc² = the sticking nodes' area, twice that of the half model
        area = comm.allreduce(float(np.sum(state.lumped_weights[mine][states[mine] == 1])))
        c = float(np.sqrt(2 * area / np.pi))
    else:
        c = stick_zone(x, np.concatenate(comm.allgather(states[mine])))
    q = contact.results.tangential_tractions(state)[:, 0]
    tab = slave.tabulate(6, transformed=False)
    q_hat = np.einsum("cqb,cb->cq", tab.phi, q[slave.cells])
    rq = (np.linalg.norm(tab.points[..., :2], axis=-1) if sphere else tab.points[..., 0])
    near = (np.abs(rq) < 1.5 * ref["a"]) & (tab.points[..., -1] < 0.5 * args.radius)
    # the traction on the upper body opposes Q: compare it with q ≥ 0
    orientation = -np.sign(args.tangential) if args.tangential else 1.0
    exact = tangential_traction(rq, ref, args.mu)
    err2 = comm.allreduce(float(np.sum((tab.weights * (orientation * q_hat - exact) ** 2)[near])))
    ref2 = comm.allreduce(float(np.sum((tab.weights * exact ** 2)[near])))
    summary = contact.results.friction_summary(state)
    return {"a": fit.a, "p0": fit.p0, "c": c,
            "q_l2_error": float(np.sqrt(err2 / ref2)) if ref2 > 0 else float("nan"),
            "normal_force": contact.results.normal_force(state),
            "tangential_force": summary["tangential_force"],
            "stick_nodes": summary["stick_nodes"], "slip_nodes": summary["slip_nodes"],
            "dissipation": summary["dissipation"]}


def run(args: argparse.Namespace, comm: MPI.Comm) -> dict:
    ref = reference(args)
    clock = time.perf_counter()
    contact, problem, approach, shift, h = build(args, ref, comm)
    holder = Holder(contact, problem, approach, shift, args.load_steps,
                    share=0.5 if args.geometry == "sphere" else 1.0, force=args.force)
    holder.reach(approach, 0, args.force, -ref["approach"])
    if args.tangential > 0:
        holder.steps = args.tangential_steps
        # below the tangential stiffness of full stick: reached from below
        holder.reach(shift, 1, args.tangential,
                     0.5 * abs(float(approach.value)) * args.tangential / args.force)
    wall = time.perf_counter() - clock
    figures = results(args, contact, ref)
    P, Q = holder.forces()
    V = problem.u.function_space
    figures.update({
        "a_hertz": ref["a"], "p0_hertz": ref["p0"], "c_analytic": ref["c"],
        "c_error": figures["c"] / ref["c"] - 1 if ref["c"] > 0 else float("nan"),
        "a_error": figures["a"] / ref["a"] - 1, "P": P, "Q": Q,
        "Q_over_muP": args.tangential / (args.mu * args.force),
        "approach": -float(approach.value), "shift": float(shift.value),
        "dofs": int(V.dofmap.index_map.size_global * V.dofmap.index_map_bs),
        "h_contact": h, "newton_iterations": holder.newton_iterations,
        "load_steps": holder.load_steps, "cut_backs": holder.cut_backs,
        "wall_time": wall, "kind": args.kind, "mu": args.mu, "refine": args.refine,
        "geometry": args.geometry, "ranks": comm.size})
    return figures


def main(argv: Optional[Sequence[str]] = None) -> dict:
    args = parse_args(argv)
    comm = MPI.COMM_WORLD
    f = run(args, comm)
    if comm.rank == 0:
        print(f"Cattaneo–Mindlin, {args.geometry} ({args.kind}, {f['dofs']} dofs, "
              f"{comm.size} rank(s)): Q/μP = {f['Q_over_muP']:.3f}")
        print(f"  contact half-width a = {f['a']:.6g}  (Hertz {f['a_hertz']:.6g}, "
              f"error {100 * f['a_error']:+.2f}%)")
        print(f"  stick zone c         = {f['c']:.6g}  (analytic {f['c_analytic']:.6g}, "
              f"error {100 * f['c_error']:+.2f}%; h = {f['h_contact']:.3g})")
        print(f"  tangential traction L2 error {100 * f['q_l2_error']:.2f}%; "
              f"{f['stick_nodes']} nodes stick, {f['slip_nodes']} slip")
        print(f"  Newton iterations {f['newton_iterations']} in {f['load_steps']} steps, "
              f"wall time {f['wall_time']:.2f} s")
    if args.json and comm.rank == 0:
        write_json(args.json, f)
    return f


if __name__ == "__main__":
    main()
