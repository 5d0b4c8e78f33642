"""Quick start: your own DOLFINx model plus penalty mortar contact.

A gmsh block [0, 2] × [0, 1] (plane strain, small-strain elasticity written in
UFL here — any material law works the same way) is pushed by its top face onto
a rigid disk of radius 1 below it; the dual mortar basis (LcLS*) carries the
contact pressure. Run: ``python3 demos/quickstart.py`` (or with
``mpirun -n 2``); results in ``results/quickstart*.xdmf``.
"""
import gmsh
import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar import ContactTerm, LoadPathSolver, NonlinearContactProblem, RigidSphere
from dolfinx_mortar.io.gmsh_io import model_to_mesh  # DOLFINx's, in every supported release

BOTTOM, TOP = 1, 2                       # facet tags: the slave surface and the loaded face
comm = MPI.COMM_WORLD
gmsh.initialize(["", "-v", "0"])
if comm.rank == 0:
    gmsh.model.occ.addRectangle(0, 0, 0, 2, 1)
    gmsh.model.occ.synchronize()
    for line in gmsh.model.getEntities(1):
        y = gmsh.model.occ.getCenterOfMass(*line)[1]
        if np.isclose(y, 0) or np.isclose(y, 1):
            gmsh.model.addPhysicalGroup(1, [line[1]], BOTTOM if np.isclose(y, 0) else TOP)
    gmsh.model.addPhysicalGroup(2, [1], 1)
    gmsh.option.setNumber("Mesh.CharacteristicLengthMax", 0.05)
    gmsh.model.mesh.generate(2)
mesh, _, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=2)
gmsh.finalize()

V = fem.functionspace(mesh, ("Lagrange", 1, (mesh.geometry.dim,)))
u, v = fem.Function(V, name="u"), ufl.TestFunction(V)
E, nu = 1.0, 0.3
mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
eps = ufl.sym(ufl.grad(u))
F = ufl.inner(2 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(2), ufl.grad(v)) * ufl.dx

push = fem.Constant(mesh, PETSc.ScalarType((0.0, 0.0)))   # the top face's displacement
top = fem.locate_dofs_topological(V, 1, facet_tags.find(TOP))
bcs = [fem.dirichletbc(push, top, V)]

disk = RigidSphere([1.0, -1.0], 1.0)                         # touches the block at (1, 0)
contact = ContactTerm(u, facet_tags, BOTTOM, obstacle=disk, kind="LcLS*", penalty=1e3 / 0.05)
problem = NonlinearContactProblem(F, u, contact, bcs)
solver = LoadPathSolver(problem, petsc_options={"snes_max_it": 30})


def load_path(t: float) -> None:
    """Pseudo-time t ∈ (0, 1]: push the top face down by up to 0.02."""
    push.value = (0.0, -0.02 * t)


result = solver.solve(load_path, load_steps=4, output="results/quickstart.xdmf")
force = contact.results.contact_force()                         # resultant on the block (vector)
if comm.rank == 0:
    print(f"{len(result.steps)} steps, {result.newton_iterations} Newton iterations; "
          f"contact force on the block: ({force[0]:.3e}, {force[1]:.3e})")
