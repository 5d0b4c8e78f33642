"""XDMF output of a contact solve: u and p̂ on the mesh, p̂ and p* on the slave facets.

With friction the slave facets carry the tangential traction ``q_hat_x``,
``q_hat_y`` (``q_hat_z``) and the nodes' ``stick_slip`` state (0 separated,
1 stick, 2 slip) too.

Every converged step goes to ``<output>.xdmf`` (displacement and nodal
pressure on the mesh, the sum over the contact terms) and to one file per
contact term with ``p_hat`` and ``p_star`` per slave facet (``p*`` may jump):
``<output>_<name>.xdmf`` for a term made with ``name=...``; for a term
without a name ``<output>_slave.xdmf`` when it is the only term,
``<output>_slave<slave_tag>.xdmf`` among several (``run_slave3.xdmf`` for
slave tag 3). Two terms that would write the same file are refused. The
files are complete on disk after every step
(:mod:`dolfinx_mortar.io.xdmf_series`).
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Optional, Sequence

import numpy as np
import dolfinx
from dolfinx import fem

from dolfinx_mortar import dolfinx_compat
from dolfinx_mortar.io.surface_output import SlaveSurfaceOutput, surface_output_path
from dolfinx_mortar.io.xdmf_series import XdmfSeries


def check_term_name(name: Optional[str]) -> Optional[str]:
    """A contact term's name as given, if it can name a file; None stays None.

    Raises
    ------
    TypeError, ValueError
        For a name that is no string, or not made of letters, digits, ``_``, ``-``.
    """
    if name is None:
        return None
    if not isinstance(name, str):
        raise TypeError(f"a contact term's name must be a string, not {type(name).__name__}")
    if not re.fullmatch(r"[A-Za-z0-9_-]+", name):
        raise ValueError(f"a contact term's name names its output file (<output>_<name>.xdmf): "
                         f"letters, digits, '_' and '-' only, not {name!r}")
    return name


def output_names(contacts: Sequence) -> list[str]:
    """What each contact term's output file is named after (see the module docstring).

    Raises
    ------
    ValueError
        If two terms would write the same file.
    """
    names = [term.name if term.name is not None
             else "slave" if len(contacts) == 1
             else "slave" + "-".join(map(str, np.atleast_1d(term.slave_tag)))
             for term in contacts]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ValueError(f"several contact terms would write <output>_{twice[0]}.xdmf: give "
                         "each ContactTerm its own name= (names of the terms: "
                         f"{', '.join(names)})")
    return names


class ContactOutput:
    """Writes the steps of a contact solve (see the module docstring).

    Parameters
    ----------
    path
        The mesh file's ``.xdmf`` path.
    u
        The displacement Function.
    contacts
        The contact terms (:class:`~dolfinx_mortar.contact.term.ContactTerm`).
    """

    def __init__(self, path: Path, u: fem.Function, contacts: Sequence):
        path = Path(path)
        self.u, self.contacts = u, list(contacts)
        names = output_names(self.contacts)         # refused before any file is made
        mesh = u.function_space.mesh
        self.mesh_output = XdmfSeries(path, mesh)
        self.surface_outputs = [SlaveSurfaceOutput(term.slave, surface_output_path(path, name))
                                for term, name in zip(self.contacts, names)]
        V = u.function_space
        degree = dolfinx_compat.coordinate_element(mesh).degree
        self.V1 = fem.functionspace(mesh, ("Lagrange", degree, (mesh.geometry.dim,)))
        self.Q, q_to_v = V.sub(0).collapse()
        self.q_nodes = np.asarray(q_to_v) // V.dofmap.index_map_bs
        self.Q1 = (fem.functionspace(mesh, ("Lagrange", degree))
                   if self.Q.ufl_element().degree != degree else None)
        # P2 pressure on a P1 mesh: the vertex values are copied, not interpolated; evaluating
        # the P2 basis at the vertices left 1e-16 where the pressure is 0.
        self.vertex_copy = None
        if self.Q1 is not None and degree == 1:
            def vertex_dofs(space):
                layout = space.dofmap.dof_layout
                local = [layout.entity_dofs(0, v)[0] for v in range(num_vertices)]
                return space.dofmap.list.reshape(-1, layout.num_dofs)[:, local].ravel()
            num_vertices = dolfinx.cpp.mesh.cell_num_entities(mesh.topology.cell_type, 0)
            self.vertex_copy = (vertex_dofs(self.Q1), vertex_dofs(self.Q))

    def write(self, t: float, states: Sequence) -> None:
        """Add the step at pseudo-time ``t`` with each term's contact state."""
        total = np.zeros(self.contacts[0].slave.layout.size_local)
        for term, state, out in zip(self.contacts, states, self.surface_outputs):
            pressures = term.results.nodal_pressures(state)
            total += pressures
            fields = {"p_hat": pressures[term.slave.cells],
                      "p_star": term.results.mortar_traction(state)}
            if term.friction is not None:
                # the tangential traction by component and the stick (1) / slip (2) state
                q = term.results.tangential_tractions(state)
                for k, axis in enumerate("xyz"[: q.shape[1]]):
                    fields[f"q_hat_{axis}"] = q[term.slave.cells, k]
                fields["stick_slip"] = term.results.slip_states(state)[term.slave.cells]
            out.write(fields, t)
        u1 = fem.Function(self.V1, name="displacement")
        u1.interpolate(self.u)
        p = fem.Function(self.Q, name="contact_pressure")
        p.x.array[:] = total[self.q_nodes]
        if self.Q1 is not None:
            p1 = fem.Function(self.Q1, name="contact_pressure")
            if self.vertex_copy is not None:
                q1_dofs, q_dofs = self.vertex_copy
                p1.x.array[q1_dofs] = p.x.array[q_dofs]
            else:
                p1.interpolate(p)
            p = p1
        self.mesh_output.write((u1, p), t)
