"""Which linear solver a Newton step uses: MUMPS LU, or a Krylov method
preconditioned by multigrid plus an exact contact block.

``"direct"``
    MUMPS LU of the Newton matrix, every iteration (robust; memory and time
    grow fast with the size in 3D).
``"iterative"``
    CG (the nodal active set on the initial or previous configuration: a
    symmetric Newton matrix) or GMRES (pointwise active set, current
    configuration), preconditioned by
    :class:`~dolfinx_mortar.linalg.contact_block_pc.ContactBlockPreconditioner`,
    with Eisenstat–Walker forcing terms so that early Newton iterations are not
    solved more accurately than they are worth.
``"auto"``
    ``"iterative"`` in 3D from :data:`ITERATIVE_FROM_DOFS` dofs on, ``"direct"``
    otherwise and always for the GLS kinds (README, "Linear solvers";
    docs/SCALING.md).

Every option stays overridable under the solver's prefix
(``-dolfinx_mortar_ksp_type``, ``-dolfinx_mortar_amg_pc_type gamg``, …).
"""
from __future__ import annotations

from petsc4py import PETSc

LINEAR_SOLVERS = ("auto", "direct", "iterative")

#: 3D problems from this many dofs on are solved iteratively by "auto". On
#: Hertz 3D with two bodies the iterative path took 22 s against MUMPS's 27 s at
#: 30k dofs and 94 s against 229 s at 81k (docs/SCALING.md). Below 50k dofs the
#: gain is small, and MUMPS has fewer ways to fail.
ITERATIVE_FROM_DOFS = 50_000

DIRECT_OPTIONS = {
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
    # MUMPS sizes its workspace from the analysis; parallel pivoting can exceed
    # it (INFOG(1) = -9). 100% extra costs memory only.
    "mat_mumps_icntl_14": 100,
}


def iterative_options(symmetric: bool) -> dict:
    """The Krylov path's options (without prefix)."""
    return {
        "ksp_type": "cg" if symmetric else "gmres",
        "pc_type": "python",
        # rtol is then the true residual's reduction, what the Newton test sees
        "ksp_norm_type": "unpreconditioned",
        "ksp_rtol": 1e-8,
        "ksp_max_it": 1000,
        "ksp_gmres_restart": 100,
        # inexact Newton: KSP rtol from the nonlinear convergence (Eisenstat–Walker),
        # capped at 0.01. PETSc's default starts at 0.3 and may reach 0.9: Newton then
        # needed 33 iterations instead of 21 on Hertz 3D at 30k dofs (26.0 s against
        # 22.1 s; fixed 1e-8: 16 iterations, 27.0 s), and every iteration costs
        # assembly and a preconditioner setup
        "snes_ksp_ew": True,
        "snes_ksp_ew_rtol0": 0.01,
        "snes_ksp_ew_rtolmax": 0.01,
    }


def choose_linear_solver(requested: str, num_dofs: int, gdim: int, augmented: bool) -> str:
    """``"direct"`` or ``"iterative"`` for a problem (see the module's text)."""
    if requested not in LINEAR_SOLVERS:
        raise ValueError(f"linear_solver must be one of {LINEAR_SOLVERS}, got {requested!r}")
    if augmented:
        if requested == "iterative":
            raise NotImplementedError(
                "the GLS kinds solve their augmented Newton system directly (MUMPS): "
                "no iterative path for it yet (README, 'Linear solvers'; docs/SCALING.md)")
        return "direct"
    if requested != "auto":
        return requested
    return "iterative" if gdim == 3 and num_dofs >= ITERATIVE_FROM_DOFS else "direct"


def reset_after_failure(ksp: PETSc.KSP) -> bool:
    """Reset ``ksp``'s preconditioner if its last set-up failed, so that the
    next one starts afresh; returns whether it did (the operators must then
    be set again, as SNES does after each Jacobian).

    MUMPS keeps a failed factorization's state: the next numeric
    factorization on the same pattern is followed by a solve that fails with
    INFOG(1) = -3, or (where PETSc saw the failure) gives Inf, however good
    the new matrix is."""
    pc = ksp.getPC()
    failed = (pc.getFailedReason() != PETSc.PC.FailedReason.NOERROR
              or ksp.getConvergedReason() == PETSc.KSP.ConvergedReason.DIVERGED_PCSETUP_FAILED)
    if failed:
        pc.reset()
    return failed
