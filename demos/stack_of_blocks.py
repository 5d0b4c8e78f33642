"""Several contact terms in one problem: a stack of three blocks on a rigid plane.

Three gmsh blocks of one mesh (non-matching at their interfaces), each
narrower than the one below, stand on the rigid plane y = 0; a traction q
presses the top one down (plane strain, small-strain elasticity in UFL, the
left edges on a symmetry line). One ContactTerm per interface, each with a
``name`` that names its output file: ``results/stack_of_blocks_ground.xdmf``,
``…_lower.xdmf``, ``…_upper.xdmf`` (p̂ and p* on that term's slave facets)
next to ``results/stack_of_blocks.xdmf`` (u and the pressure of all terms).
Every interface carries the whole load. Run: ``python3 demos/stack_of_blocks.py``
(or with ``mpirun -n 2``).
"""
import ufl
from dolfinx import fem
from mpi4py import MPI

from dolfinx_mortar import ContactTerm, LoadPathSolver, NonlinearContactProblem, RigidPlane
from demo_support.stack import stacked_blocks

# blocks (x0, x1, y0, y1, mesh size), bottom to top; facet tags of their faces
BLOCKS = [(0.0, 1.0, 0.0, 0.25, 0.05), (0.0, 0.8, 0.25, 0.5, 0.04), (0.0, 0.6, 0.5, 0.75, 0.03)]
BOTTOM = (1, 2, 3)           # each block's bottom face (the slave surfaces)
TOP = (4, 5, 6)              # each block's top face (masters; the last one is loaded)
LEFT = 7                     # the left edges: u_x = 0
q = 0.01                     # traction on the top block's top face

comm = MPI.COMM_WORLD
mesh, facet_tags = stacked_blocks(comm, BLOCKS, BOTTOM, TOP, LEFT)

V = fem.functionspace(mesh, ("Lagrange", 1, (2,)))
u, v = fem.Function(V, name="u"), ufl.TestFunction(V)
E, nu = 1.0, 0.3
mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
eps = ufl.sym(ufl.grad(u))
ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)
F = (ufl.inner(2 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(2), ufl.grad(v)) * ufl.dx
     + q * v[1] * ds(TOP[2]))                                  # q pushes the top face down
left = fem.locate_dofs_topological(V.sub(0), 1, facet_tags.find(LEFT))
bcs = [fem.dirichletbc(0.0, left, V.sub(0))]

penalty = 1e3 * E / 0.03
contacts = [
    ContactTerm(u, facet_tags, BOTTOM[0], obstacle=RigidPlane([0, 0], [0, 1]),
                kind="LcLS*", penalty=penalty, name="ground"),
    ContactTerm(u, facet_tags, BOTTOM[1], master_tag=TOP[0], kind="LcLS*",
                penalty=penalty, name="lower"),
    ContactTerm(u, facet_tags, BOTTOM[2], master_tag=TOP[1], kind="LcLS*",
                penalty=penalty, name="upper"),
]
problem = NonlinearContactProblem(F, u, contacts, bcs)
solver = LoadPathSolver(problem)
result = solver.solve(lambda t: None, load_steps=1, output="results/stack_of_blocks.xdmf")

load = q * (BLOCKS[2][1] - BLOCKS[2][0])
forces = {term.name: term.results.contact_force()[1] for term in contacts}
if comm.rank == 0:
    print(f"{result.newton_iterations} Newton iterations; load {load:.6g}; the vertical "
          "contact force on each slave block: "
          + ", ".join(f"{name} {f:.6g} ({f / load - 1:+.1e})" for name, f in forces.items()))
