"""Several bodies under one contact term: a stack of three blocks on a rigid plane.

Three gmsh blocks of one mesh, [0, 1] wide, meshed with 0.05, 0.04 and 0.03 (non-matching at
their interfaces), stand on the rigid plane y = 0; a uniform traction q presses the top one
down (plane strain, small-strain elasticity in UFL, the left edges on a symmetry line). One
term holds the ground contact; ONE self-contact term holds both interfaces between the blocks,
given as the list of their four faces' tags: nobody says which face is slave or master, and
the pairs between the blocks are found by the search (docs/SELF_CONTACT.md). Every interface
carries the uniform pressure q, to round-off (a patch test); with
``--configuration current`` the pressure on the deformed faces, q/(1 + ν(1 + ν)q/E) (the
blocks widen). ``--mu M --shear S``: Coulomb friction μ = M on the interfaces and a
tangential traction S·q on the top face, which the interfaces pass down in stick and slip
(the ground stays frictionless; the left edges hold the blocks). Run:
``python3 demos/stack_one_term.py [--kind K] [--configuration C] [--steps N] [--mu M]
[--shear S] [--json F]`` (or with ``mpirun -n 2``).
"""
import argparse
import json

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from dolfinx_mortar import (ContactTerm, CoulombFriction, LoadPathSolver, NonlinearContactProblem,
                            RigidPlane)
from demo_support.stack import stacked_blocks
from dolfinx_mortar.small_strain.elastic import linear_elastic_residual

# blocks (x0, x1, y0, y1, mesh size), bottom to top; facet tags of their faces
BLOCKS = [(0.0, 1.0, 0.0, 0.25, 0.05), (0.0, 1.0, 0.25, 0.5, 0.04), (0.0, 1.0, 0.5, 0.75, 0.03)]
BOTTOM = (1, 2, 3)           # each block's bottom face
TOP = (4, 5, 6)              # each block's top face (the last one is loaded)
LEFT = 7                     # the left edges: u_x = 0
q = 0.01                     # the traction on the top block's top face


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kind", default="LcLS*", help="mortar basis kind (LcLS*)")
    parser.add_argument("--configuration", default="initial",
                        help="basis_configuration of both terms (initial)")
    parser.add_argument("--steps", type=int, default=1, help="load steps (1)")
    parser.add_argument("--mu", type=float, default=0.0,
                        help="Coulomb friction on the interfaces (0: frictionless)")
    parser.add_argument("--shear", type=float, default=0.0,
                        help="tangential traction on the top face, a fraction of q (0)")
    parser.add_argument("--json", help="write the figures to this file")
    args = parser.parse_args(argv)
    comm = MPI.COMM_WORLD
    mesh, facet_tags = stacked_blocks(comm, BLOCKS, BOTTOM, TOP, LEFT)
    V = fem.functionspace(mesh, ("Lagrange", 1, (2,)))
    u, v = fem.Function(V, name="u"), ufl.TestFunction(V)
    E = 1.0
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)
    load = fem.Constant(mesh, 0.0)     # q at the end of the load path
    F = (linear_elastic_residual(u, E, 0.3) + load * v[1] * ds(TOP[2])
         - args.shear * load * v[0] * ds(TOP[2]))
    left = fem.locate_dofs_topological(V.sub(0), 1, facet_tags.find(LEFT))
    bcs = [fem.dirichletbc(0.0, left, V.sub(0))]
    penalty = 1e3 * E / 0.03
    options = {"kind": args.kind, "penalty": penalty,
               "basis_configuration": args.configuration}
    ground = ContactTerm(u, facet_tags, BOTTOM[0], obstacle=RigidPlane([0, 0], [0, 1]),
                         name="ground", **options)
    friction = CoulombFriction(args.mu) if args.mu > 0 else None
    interfaces = ContactTerm(u, facet_tags, [TOP[0], BOTTOM[1], TOP[1], BOTTOM[2]],
                             self_contact=True, name="blocks", friction=friction, **options)
    problem = NonlinearContactProblem(F, u, [ground, interfaces], bcs)

    def ramp(t: float) -> None:
        load.value = t * q

    result = LoadPathSolver(problem).solve(ramp, load_steps=args.steps)
    pressures = interfaces.results.surface_pressure(gather=True)
    on_faces = pressures.x[:, 1] > 0.0                 # every node of the four faces
    figures = {
        "newton_iterations": result.newton_iterations,
        "ground_force": float(ground.results.contact_force()[1]), "load": q,
        "interface_pressure_min": float(pressures.p[on_faces].min()),
        "interface_pressure_max": float(pressures.p[on_faces].max()),
        "interface_nodes": int(on_faces.sum()),
        "internal_force": float(np.linalg.norm(interfaces.results.contact_force())),
        # what each face receives from the block it touches: ±q up/down
        "face_forces": {str(tag): interfaces.results.contact_force(tag=tag).tolist()
                        for tag in (TOP[0], BOTTOM[1], TOP[1], BOTTOM[2])},
    }
    if friction is not None:
        # the tangential traction against the Coulomb cone, node by node
        # gathered in the same order as the pressures (both by the nodes' coordinates)
        traction = interfaces.results.surface_friction(gather=True)
        q_t, state = np.abs(traction.q[on_faces, 0]), traction.stick_slip[on_faces]
        figures["friction_over_cone_max"] = float(np.max(q_t / (args.mu * pressures.p[on_faces])))
        figures["slip_nodes"] = int(np.sum(state == 2))
        figures["stick_nodes"] = int(np.sum(state == 1))
        figures["face_friction_forces"] = {
            str(tag): interfaces.results.tangential_force(tag=tag).tolist()
            for tag in (TOP[0], BOTTOM[1], TOP[1], BOTTOM[2])}
    if comm.rank == 0:
        print(f"{figures['newton_iterations']} Newton iterations; ground force "
              f"{figures['ground_force']:.10g} for the load {q}; pressure on the "
              f"{figures['interface_nodes']} interface nodes {figures['interface_pressure_min']:.10g}"
              f" … {figures['interface_pressure_max']:.10g}")
        if args.json:
            with open(args.json, "w") as f:
                json.dump(figures, f, indent=1)
    return figures


if __name__ == "__main__":
    main()
