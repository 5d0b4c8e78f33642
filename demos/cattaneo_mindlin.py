"""Cattaneo–Mindlin partial slip: two equal cylinders pressed together, then sheared.

Two elastically similar bodies (plane strain): the upper half of a cylinder of
radius R on the lower half of an equal one (fixed at its flat bottom), so
that the normal and tangential problems decouple. The normal line load P
(per unit length) is applied first as a uniform traction on the upper flat
edge, then a tangential line load Q < μP the same way while P is held. The
contact stays the Hertz strip |x| < a, and a central stick zone |x| < c
remains with (Cattaneo 1938, Mindlin 1949; Johnson, Contact Mechanics §7.1)

    c/a = (1 − Q/(μP))^{1/2},
    q(x) = μ p0 (√(1 − x²/a²) − (c/a) √(1 − x²/c²))  for |x| < c,
    q(x) = μ p0 √(1 − x²/a²)                          for c ≤ |x| ≤ a,

with the Hertz a = √(4PR*/(πE*)), p0 = 2P/(πa), E* = E/(2(1 − ν²)), R* = R/2. The demo
reports a (the Hertz profile fitted to the pressures), c (midway between the
outermost sticking node and the first slipping one on each side) and the L2
error of the tangential traction against q(x) over the contact strip.

The mesh is graded to a/(40·refine) at the contact. The holder's approach δ
and shift s are found by secant steps on the contact resultant (to 1e-5 of
P and Q); s only grows, so that no slip reverses.

    python3 demos/cattaneo_mindlin.py --tangential 0.005 --mu 0.3 --json results/cm.json
"""
from __future__ import annotations

import argparse
import time
from typing import Optional, Sequence

import numpy as np
from mpi4py import MPI

from demo_support.cli import parse_args_and_petsc_options, solver_demo_parser
from demo_support.hertz_fit import fit_hertz_profile
from demo_support.hertz_meshes import FIXED, LOAD, MASTER, SLAVE, half_disk_pair_mesh
from dolfinx_mortar.io.output import write_json


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = solver_demo_parser(__doc__)
    parser.add_argument("--geometry", default="cylinder", choices=("cylinder", "sphere"),
                        help="cylinder (plane strain); sphere needs a 3D model (not yet)")
    parser.add_argument("--radius", type=float, default=1.0, help="radius R (1)")
    parser.add_argument("--force", type=float, default=0.01,
                        help="normal line load P per unit length (0.01)")
    parser.add_argument("--tangential", type=float, default=0.0015,
                        help="tangential line load Q per unit length, below μP (0.0015)")
    parser.add_argument("--mu", type=float, default=0.3, help="friction coefficient μ (0.3)")
    parser.add_argument("--kind", default="LcLS*", help="mortar basis kind (LcLS*)")
    parser.add_argument("--basis-configuration", default="initial",
                        choices=("initial", "previous", "current"))
    parser.add_argument("--refine", type=float, default=1.0,
                        help="mesh density factor: contact size a/(40·refine) (1)")
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
    return parse_args_and_petsc_options(parser, argv)


def reference(args: argparse.Namespace) -> dict:
    """Hertz's a and p0 and Cattaneo–Mindlin's c for the arguments."""
    if not 0 <= args.tangential < args.mu * args.force:
        raise ValueError(f"need 0 ≤ Q < μP for partial slip, got Q = {args.tangential}, "
                         f"μP = {args.mu * args.force}")
    E_star = args.E / (2 * (1 - args.nu ** 2))
    R_star = args.radius / 2      # two equal cylinders
    a = np.sqrt(4 * args.force * R_star / (np.pi * E_star))
    return {"a": a, "p0": 2 * args.force / (np.pi * a),
            "c": a * np.sqrt(1 - args.tangential / (args.mu * args.force))}


def tangential_traction(x: np.ndarray, ref: dict, mu: float) -> np.ndarray:
    """Johnson's q(x) of the partial slip (positive, along −Q on the upper body)."""
    a, c, p0 = ref["a"], ref["c"], ref["p0"]
    q = mu * p0 * np.sqrt(np.maximum(0.0, 1 - (x / a) ** 2))
    inside = np.abs(x) < c
    q[inside] -= mu * p0 * (c / a) * np.sqrt(1 - (x[inside] / c) ** 2)
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
    h = ref["a"] / (40 * args.refine)
    domain, tags = half_disk_pair_mesh(args.radius, ref["a"], h, 1, comm)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    u = fem.Function(V, name="displacement")
    eps_t = None if args.tangential_penalty is None else args.tangential_penalty * args.E / h
    contact = ContactTerm(u, tags, SLAVE, master_tag=MASTER, kind=args.kind,
                          penalty=args.penalty * args.E / h,
                          basis_configuration=args.basis_configuration,
                          friction=CoulombFriction(args.mu, eps_t))
    approach = fem.Constant(domain, PETSc.ScalarType(0.0))
    shift = fem.Constant(domain, PETSc.ScalarType(0.0))
    fixed = fem.locate_dofs_topological(V, 1, tags.find(FIXED))
    top = tags.find(LOAD)
    bcs = [fem.dirichletbc(np.zeros(2, dtype=PETSc.ScalarType), fixed, V),
           fem.dirichletbc(shift, fem.locate_dofs_topological(V.sub(0), 1, top), V.sub(0)),
           fem.dirichletbc(approach, fem.locate_dofs_topological(V.sub(1), 1, top), V.sub(1))]
    problem = NonlinearContactProblem(linear_elastic_residual(u, args.E, args.nu), u, contact,
                                      bcs)
    return contact, problem, approach, shift, h


class Holder:
    """The rigid holder of the upper cylinder: it moves its flat edge by
    (s, −δ) without turning, and finds the δ and s that make the contact
    carry P and Q (a cylinder loaded by forces alone would roll)."""

    def __init__(self, contact, problem, approach, shift, steps: int):
        from dolfinx_mortar import LoadPathSolver
        self.contact, self.approach, self.shift = contact, approach, shift
        self.solver = LoadPathSolver(problem)
        self.steps = steps
        self.newton_iterations = self.load_steps = self.cut_backs = 0

    def forces(self) -> tuple[float, float]:
        """(P, Q) that the contact carries: the resultant on the upper body."""
        C = self.contact.results.contact_force()
        return float(C[1]), float(-C[0])

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
    comm = contact.mesh.comm
    slave = contact.slave
    state = contact.evaluate()
    n = slave.layout.num_owned
    on = np.zeros(slave.layout.size_local, dtype=bool)
    on[slave.cells] = True
    mine = np.flatnonzero(on[:n])
    x = np.concatenate(comm.allgather(slave.x[mine, 0]))
    p = np.concatenate(comm.allgather(contact.results.nodal_pressures(state)[mine]))
    states = np.concatenate(comm.allgather(contact.results.slip_states(state)[mine]))
    fit = fit_hertz_profile(np.abs(x), p, ref["a"])
    q = contact.results.tangential_tractions(state)[:, 0]
    tab = slave.tabulate(6, transformed=False)
    q_hat = np.einsum("cqb,cb->cq", tab.phi, q[slave.cells])
    xq = tab.points[..., 0]
    near = (np.abs(xq) < 1.5 * ref["a"]) & (tab.points[..., 1] < 0.5 * args.radius)
    # the traction on the upper body opposes Q: compare it with q(x) ≥ 0
    orientation = -np.sign(args.tangential) if args.tangential else 1.0
    exact = tangential_traction(xq, ref, args.mu)
    err2 = comm.allreduce(float(np.sum((tab.weights * (orientation * q_hat - exact) ** 2)[near])))
    ref2 = comm.allreduce(float(np.sum((tab.weights * exact ** 2)[near])))
    summary = contact.results.friction_summary(state)
    return {"a": fit.a, "p0": fit.p0, "c": stick_zone(x, states),
            "q_l2_error": float(np.sqrt(err2 / ref2)) if ref2 > 0 else float("nan"),
            "normal_force": contact.results.normal_force(state),
            "tangential_force": summary["tangential_force"],
            "stick_nodes": summary["stick_nodes"], "slip_nodes": summary["slip_nodes"],
            "dissipation": summary["dissipation"]}


def run(args: argparse.Namespace, comm: MPI.Comm) -> dict:
    if args.geometry == "sphere":
        raise NotImplementedError("the sphere's Cattaneo–Mindlin problem is 3D (a lateral "
                                  "force is not axisymmetric); only the cylinder is built")
    ref = reference(args)
    clock = time.perf_counter()
    contact, problem, approach, shift, h = build(args, ref, comm)
    holder = Holder(contact, problem, approach, shift, args.load_steps)
    # the approach of two cylinders (Johnson §5.6), a first guess for δ
    E_star = args.E / (2 * (1 - args.nu ** 2))
    guess = args.force / (np.pi * E_star) * (2 * np.log(4 * args.radius / ref["a"]) - 1)
    holder.reach(approach, 0, args.force, -guess)
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
