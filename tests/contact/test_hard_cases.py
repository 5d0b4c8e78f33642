"""Hard cases for numerical stability (issue 5).

The scenes and the pass criteria live in benchmarks/hard_case_scenes.py, which
also feeds the table of benchmarks/hard_cases.py: the tests and the table show
the same numbers. Where a kind fails a case, the test is a strict xfail whose
reason gives the measured figure, so the failure stays visible and a fix shows
up as an XPASS.

Operator-level cases run on COMM_SELF on every rank (dense condition numbers
need the whole matrix); the problem-level cases run on COMM_WORLD and give the
same numbers on 1 and 2 ranks.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest
from support import BENCHMARKS, LOW_PENALTY, load_script

scenes = load_script(BENCHMARKS / "hard_case_scenes.py")

ALL_KINDS = scenes.ALL_KINDS


def failed(case: str, row: dict) -> list:
    return [c for c in scenes.check(case, row) if not c[4]]


def assert_passes(case: str, row: dict) -> None:
    bad = failed(case, row)
    assert not bad, f"{case} {row.get('kind')}: " + "; ".join(
        f"{m} = {v:.3g} (need {op} {lim:g})" for m, v, op, lim, _ in bad)


def xfail(*values, reason: str):
    return pytest.param(*values, marks=pytest.mark.xfail(strict=True, reason=reason))


# -- 1. contact boundary sweeping across a slave element edge ----------------------------
@lru_cache(maxsize=None)
def _sweep():
    return {(r["kind"], r["boundary_modification"]): r for r in scenes.sweep()}


SWEEP_VARIANTS = [(k, False) for k in ALL_KINDS] + [(k, True) for k in scenes.DUAL_KINDS]


@pytest.mark.parametrize("kind, modified", SWEEP_VARIANTS)
def test_sweep_penalty_jacobian_stays_conditioned(kind, modified):
    """cond(K + Gᵀ εW G) over the sweep within 2× its value with the contact
    edge on the node: a barely touched node only adds a tiny stiffness."""
    assert_passes("sweep-jacobian", _sweep()[kind, modified])


_D_REASON = ("contact block D over the touched nodes: cond grows like t^-3 (t = sliver/h) "
             "for standard and global kinds, t^-2 for the dual ones; measured growth at "
             "t = 1e-4: {}")


@pytest.mark.parametrize("kind, modified", [
    xfail("GLS", False, reason=_D_REASON.format("9.5e11")),
    xfail("GLS*", False, reason=_D_REASON.format("9.5e11")),
    xfail("LmLS", False, reason=_D_REASON.format("7.5e11")),
    xfail("LmLS*", False, reason=_D_REASON.format("7.3e11")),
    xfail("LcLS*", False, reason=_D_REASON.format("1.0e8")),
    xfail("LcLS", False, reason=_D_REASON.format("1.0e8")),
    xfail("LcLS*", True, reason=_D_REASON.format("1.0e8 (D = diag(W_cov): W_cov ~ t^2)")),
    ("LcLS", True),   # modified LcLS: D = I on the touched nodes
])
def test_sweep_contact_block_conditioning(kind, modified):
    """cond(D) over the touched nodes within 1e3× its value with the edge on a node."""
    assert_passes("sweep-contact-block", _sweep()[kind, modified])


@pytest.mark.parametrize("kind", [
    xfail("LcLS*", reason="modified dual coefficients on the sliver grow like 1/t: "
                          "max |C| 2 → 6.0e4 at t = 1e-4"),
    xfail("LcLS", reason="modified dual coefficients on the sliver grow like 1/t^3: "
                         "max |C| 32 → 9.6e13 at t = 1e-4"),
])
def test_sweep_boundary_modification_keeps_coefficients_bounded(kind):
    """The consistent boundary modification rebuilds the dual basis on the
    covered part: on a sliver its coefficients explode (the seed's warning)."""
    assert_passes("sweep-modified-coefficients", _sweep()[kind, True])


@lru_cache(maxsize=None)
def _elastic_sweep(kind: str, modified: bool, dim: int) -> dict:
    return scenes.elastic_sweep(kind, modified, dim=dim)


_GLS_SLIVER = ("L over the covered area has a row of size ~ sliver·h for the node covered only "
               "by the sliver: its nodal pressure grows like 1/sliver, max|p_A|/median p = "
               "2.5, 66, 687, 5.5e3, 5.3e4 for slivers 0.5 … 1e-4 (3D: up to 2.4e5)")
_MODIFIED_SLIVER = ("the modified dual function of the sliver node averages the penetration over "
                    "the sliver, at the master's corner (a stress singularity): max|p_A|/median "
                    "p = 3.1, 43, 513, 588, 588 for slivers 0.5 … 1e-4 — bounded, but 588× "
                    "(3D: 538)")


@LOW_PENALTY
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("kind, modified", SWEEP_VARIANTS)
def test_elastic_master_sweep_keeps_the_newton_matrix_conditioned(kind, modified, dim):
    """In the solver, an elastic master whose edge leaves a sliver (0.5 … 1e-4 of
    a facet) covered: cond of the Newton matrix at the solution within 10×."""
    assert_passes("sweep-elastic", _elastic_sweep(kind, modified, dim))


@pytest.mark.parametrize("kind, modified", [
    xfail("GLS", False, reason=_GLS_SLIVER),
    xfail("GLS*", False, reason=_GLS_SLIVER),
    ("LmLS", False), ("LmLS*", False), ("LcLS*", False), ("LcLS", False),
    xfail("LcLS*", True, reason=_MODIFIED_SLIVER),
    xfail("LcLS", True, reason=_MODIFIED_SLIVER),
])
@pytest.mark.parametrize("dim", [2, 3])
def test_elastic_master_sweep_keeps_nodal_pressures_bounded(kind, modified, dim):
    """No nodal pressure above 20× the median while the sliver shrinks: this is
    where the seed expects trouble, and it shows for the bases that are rebuilt
    over the covered area (GLS projected on it, the modified dual kinds)."""
    assert_passes("sweep-elastic-pressure", _elastic_sweep(kind, modified, dim))


def test_sweep_covered_area_is_the_overlap():
    r = _sweep()["LcLS*", False]
    expected = [1.0 - (3 / 8 + t / 8) for t in r["offsets"]]
    assert np.allclose(r["covered_area"], expected, rtol=0, atol=1e-14)


# -- 2. quadratic slave facets ------------------------------------------------------------
@pytest.mark.parametrize("variant", ["P2-triangle", "Q8", "Q9"])
@pytest.mark.parametrize("kind", ALL_KINDS)
def test_quadratic_facets_transfer_linear_fields_exactly(kind, variant):
    """D·f_s = M·f_m for f = 1, x, y and the exact covered area (P2 triangles
    and Q8 with the transformed basis)."""
    assert_passes("quadratic-identities", scenes.quadratic_identities(kind, variant))


@pytest.mark.parametrize("kind", ALL_KINDS)
def test_quadratic_tetrahedra_pass_the_patch_test(kind):
    """3D patch test with P2 tetrahedra: transformed P2 triangle slave facets."""
    for orientation in ("finer-slave", "finer-master"):
        assert_passes("patch", scenes.patch_test_run(kind, 3, 2, 0.35, 0.5, orientation))


# -- 3. mesh-size ratio 1:10 ----------------------------------------------------------------
@pytest.mark.parametrize("orientation", ["finer-slave", "finer-master"])
@pytest.mark.parametrize("kind", ALL_KINDS)
def test_patch_test_with_mesh_size_ratio_ten(kind, orientation):
    assert_passes("patch", scenes.patch_test_run(kind, 2, 1, 0.02, 0.2, orientation))


# -- 4. penalty up to 1e4·E/h -------------------------------------------------------------
@pytest.mark.parametrize("kind", ALL_KINDS)
def test_penetration_falls_as_one_over_the_penalty(kind):
    """Hertz 2D on a rigid plane, ε = 1e1..1e4·E/h: max d̄ ∝ ε^-1 (slope within
    0.05), at most 10 Newton iterations per load step, cond of the Newton
    matrix growing no faster than ε^1.1."""
    assert_passes("penalty", scenes.penalty_sweep(kind))


# -- 5. grazing contact ----------------------------------------------------------------------
@pytest.mark.parametrize("kind", ALL_KINDS)
def test_grazing_disk_converges_with_non_negative_pressure(kind):
    assert_passes("grazing", scenes.grazing(kind))


# -- 6. 3D coincident nodes and edges --------------------------------------------------------
@pytest.mark.parametrize("variant", [("tetrahedron", False), ("tetrahedron", True),
                                     ("hexahedron", False)],
                         ids=["tet-identical", "tet-crossing-diagonals", "hex-identical"])
@pytest.mark.parametrize("kind", ALL_KINDS)
def test_coincident_interface_meshes(kind, variant):
    """Identical interface meshes (and coincident nodes with crossing
    diagonals): exact covered area, no failed projection, exact patch test."""
    assert_passes("coincident", scenes.coincident_patch(kind, *variant))


@pytest.mark.parametrize("noise", [1e-13, 1e-12, 1e-11, 1e-10])
@pytest.mark.parametrize("variant", [("tetrahedron", False), ("tetrahedron", True)],
                         ids=["tet-identical", "tet-crossing-diagonals"])
@pytest.mark.parametrize("kind", ALL_KINDS)
def test_near_coincident_interface_meshes(kind, variant, noise):
    """The master's interface nodes moved in-plane by round-off (noise × h), as
    two separately meshed conforming faces are: the patch test still holds to
    1e-8. Before the clipping computed crossings consistently with its
    tolerance, 1e-12 h gave pressures 20-50% off (LmLS, LcLS) or no Newton
    convergence (GLS, GLS*): crossing points extrapolated off their edges
    covered 1.18 times the interface."""
    assert_passes("coincident", scenes.coincident_patch(kind, *variant, noise=noise))


# -- 7. curved on curved: Hertz with two elastic bodies ---------------------------------------
@pytest.mark.parametrize("kind", ALL_KINDS)
def test_touching_cylinders_have_no_penetration_at_zero_load(kind):
    """GLS kinds failed here while L spanned the whole slave surface: the
    projection counted the uncovered part as d = 0 and rang past the covered
    zone (the first uncovered node got d̄ = +0.31 h). L now spans the covered
    part only (contact_terms.covered_mass)."""
    assert_passes("spurious-gap", scenes.spurious_gap(kind))


@pytest.mark.parametrize("kind", [pytest.param("GLS", marks=pytest.mark.slow),
                                  pytest.param("GLS*", marks=pytest.mark.slow),
                                  "LmLS", "LmLS*", "LcLS*", "LcLS"])
def test_two_cylinders_match_hertz(kind):
    """p0 and a within 3% (contact size a/20)."""
    assert_passes("cylinders", scenes.two_cylinders(kind))


@pytest.mark.slow
@pytest.mark.parametrize("kind", ALL_KINDS)
def test_two_spheres_match_hertz(kind):
    """p0 within 9% and a within 6% of the fitted Hertz profile (contact size a/8, ~20 s).

    The slave is a cap r < 1.5a fully covered by the search: the whole
    quarter-hemisphere had partly covered cells where the master left the
    search radius, and the dual kinds turned their large negative gaps into
    positive nodal gaps there (p0 error +392, i.e. ×393)."""
    assert_passes("spheres", scenes.two_spheres(kind))


@pytest.mark.parametrize("refine", [0.5, 1.0])
def test_two_equal_cylinders_match_hertz_within_half_a_percent(refine):
    """Two equal cylinders (R = 1, two bodies in one gmsh mesh, the default LcLS* in the
    initial configuration) at h = a/20 and a/40. Before the interface normals a user's
    two-mesh run fitted p0 +1.18% and a −1.05% at a/40, the error growing under
    refinement; now p0 −0.03%, −0.02% (and +0.002% at a/80) and a −0.10%, −0.14%
    (−0.19%: a is within 0.2% at every size, not converging further)."""
    r = scenes.two_cylinders("LcLS*", R1=1.0, R2=1.0, refine=refine)
    assert abs(r["p0_error"]) < 5e-3 and abs(r["a_error"]) < 5e-3, r
    assert abs(r["force_error"]) < 1e-6, r
