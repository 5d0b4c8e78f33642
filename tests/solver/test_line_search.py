"""The library's line search (full step first, else PETSc's l2 step length;
never a step to a residual that is not finite) and the residual it offers to
the solver's next evaluation."""
from __future__ import annotations

import numpy as np
import pytest
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc
from demo_support.laws import neo_hookean_residual
from support import load_demo
from support.meshes import rectangle

from dolfinx_mortar import (ContactTerm, CoulombFriction, LoadPathSolver, NonlinearContactProblem,
                            RigidSphere)
from dolfinx_mortar.solver.newton import EquilibriumTest
from dolfinx_mortar.solver.newton.line_search import FullStepFirst, l2_step_length

BOTTOM, TOP, LEFT = 1, 2, 3


@pytest.mark.parametrize("minimizer", [0.3, 0.9, 1.7])
def test_l2_step_length_is_the_minimizer_of_a_parabola(minimizer):
    """On an exact parabola l2's secant step lands on its minimizer."""
    f = [(lam - minimizer) ** 2 + 0.1 for lam in (0.0, 0.5, 1.0)]
    assert l2_step_length(*f) == pytest.approx(minimizer, rel=1e-14)


def test_l2_step_length_keeps_petscs_safeguards():
    # concave: "always downhill" from λ = 1, along the slope there
    assert l2_step_length(1.0, 1.2, 1.0) == pytest.approx(1.5)
    # a step below the minimum becomes 1/2; one that is not finite, 1
    assert l2_step_length(1.0, 0.25, 1.0) == 0.5
    assert l2_step_length(1.0, np.nan, np.nan) == 1.0


class ArctanProblem:
    """F(x) = arctan(x) per entry: Newton from |x| > 1.39 overshoots, so the
    full step raises ‖F‖ there; near the root it converges quadratically.
    The callbacks FullStepFirst uses, as NonlinearContactProblem has them:
    ``F`` takes the line search's offer first."""

    def __init__(self, n: int):
        self._b = PETSc.Vec().createSeq(n, comm=PETSc.COMM_SELF)
        self.evaluations = 0
        #: offers of the line search that F took instead of evaluating
        self.offers = 0
        self.line_search = None

    def F(self, x: PETSc.Vec, b: PETSc.Vec) -> None:
        if self.line_search is not None and self.line_search.take_offer(x, b):
            self.offers += 1
            return
        self.evaluations += 1
        self.evaluate(x, b)

    def evaluate(self, x: PETSc.Vec, b: PETSc.Vec) -> None:
        b.array[:] = np.arctan(x.array_r)

    def derivative(self, x: np.ndarray) -> np.ndarray:
        return 1 / (1 + x ** 2)

    def vector(self) -> PETSc.Vec:
        return self._b

    def attach(self, snes: PETSc.SNES, shorten: bool = True) -> FullStepFirst:
        """The library's line search on ``snes``, its offers taken by F."""
        self.line_search = FullStepFirst(self, shorten=shorten)
        self.line_search.attach(snes)
        return self.line_search

    def snes(self, line_search: str) -> PETSc.SNES:
        snes = PETSc.SNES().create(PETSc.COMM_SELF)
        n = self._b.getSize()
        J = PETSc.Mat().createAIJ((n, n), nnz=1, comm=PETSc.COMM_SELF)

        def jacobian(_snes, x, A, _P):
            A.zeroEntries()
            A.setDiagonal(PETSc.Vec().createWithArray(self.derivative(x.array_r),
                                                      comm=PETSc.COMM_SELF))
            A.assemble()

        snes.setFunction(lambda _snes, x, b: self.F(x, b), self._b)
        snes.setJacobian(jacobian, J)
        snes.setType("newtonls")
        snes.getKSP().setType("preonly")
        snes.getKSP().getPC().setType("lu")
        opts = PETSc.Options()
        opts["arctan_snes_linesearch_type"] = line_search
        snes.setOptionsPrefix("arctan_")
        snes.setFromOptions()
        del opts["arctan_snes_linesearch_type"]
        return snes


def iterates(snes: PETSc.SNES, x0: np.ndarray, iterations: int) -> list[np.ndarray]:
    out = []
    x = PETSc.Vec().createWithArray(x0.copy(), comm=PETSc.COMM_SELF)
    for _ in range(iterations):
        snes.setTolerances(rtol=0.0, atol=0.0, stol=0.0, max_it=1)
        snes.solve(None, x)
        out.append(x.array_r.copy())
    return out


def test_cut_steps_are_petscs_l2_steps_and_other_steps_are_full():
    """From x = (2, 0.1) the full Newton step raises ‖F‖: the step is PETSc's l2
    step to round-off. From there the full step lowers ‖F‖ and is taken whole
    (plain Newton), at one evaluation, with the trial residual offered."""
    x0 = np.array([2.0, 0.1])
    reference = ArctanProblem(2)
    l2 = iterates(reference.snes("l2"), x0, 1)[0]

    problem = ArctanProblem(2)
    snes = problem.snes("basic")
    line_search = problem.attach(snes)
    xs = iterates(snes, x0, 4)
    assert np.allclose(xs[0], l2, rtol=1e-14, atol=1e-15)
    assert line_search.cut_steps == 1
    scale = np.max(np.abs(x0))
    for before, after in zip(xs[:-1], xs[1:]):
        newton = before - (1 + before ** 2) * np.arctan(before)
        assert np.allclose(after, newton, rtol=1e-13, atol=1e-15 * scale)
    assert line_search.full_steps == 3 == problem.offers
    # arctan is odd: Newton converges cubically (e ← −2e³/3)
    e = [np.max(np.abs(x)) / scale for x in xs[1:]]
    assert e[2] < e[1] ** 2.5 and e[1] < e[0] ** 2.5, e


def test_full_steps_only_takes_the_full_step_where_it_raises_the_residual():
    """The frozen phase of a linear bulk: full steps, also where ‖F‖ rises."""
    problem = ArctanProblem(2)
    snes = problem.snes("basic")
    line_search = problem.attach(snes)
    x0 = np.array([2.0, 0.1])
    with line_search.full_steps_only():
        x1 = iterates(snes, x0, 1)[0]
    assert np.allclose(x1, x0 - (1 + x0 ** 2) * np.arctan(x0), rtol=1e-13)
    assert line_search.full_steps == 1 and line_search.cut_steps == 0
    assert line_search.shorten


class LogProblem(ArctanProblem):
    """F(x) = ln(x) per entry, NaN for x ≤ 0 (a law with ln J): Newton's
    step from x is x ln x, which leaves the domain from x > e."""

    def evaluate(self, x: PETSc.Vec, b: PETSc.Vec) -> None:
        with np.errstate(invalid="ignore", divide="ignore"):
            b.array[:] = np.where(x.array_r > 0, np.log(np.abs(x.array_r)), np.nan)

    def derivative(self, x: np.ndarray) -> np.ndarray:
        return 1 / x


@pytest.mark.parametrize("shorten", [True, False])
def test_a_step_to_a_residual_that_is_not_finite_is_halved_until_it_is(shorten):
    """From x = 5 Newton's step on ln x = 0 is 5 ln 5 = 8.05, to x = −3.05
    where ln is not defined: the step is halved (exactly, in binary) until the
    residual is finite, once to x = 0.976, and that residual is offered to the
    basic line search. Plain ``basic`` stops there with a NaN residual."""
    plain = LogProblem(1)
    snes = plain.snes("basic")
    iterates(snes, np.array([5.0]), 1)
    assert snes.getConvergedReason() < 0

    problem = LogProblem(1)
    snes = problem.snes("basic")
    line_search = problem.attach(snes, shorten=shorten)
    x1 = iterates(snes, np.array([5.0]), 1)[0]
    assert x1[0] == pytest.approx(5.0 - 0.5 * 5.0 * np.log(5.0), rel=1e-15)
    assert line_search.halved_steps == 1 and problem.offers == 1
    xs = iterates(snes, x1, 4)
    assert abs(xs[-1][0] - 1.0) < 1e-12


class KinkProblem(ArctanProblem):
    """A node held open a hair from contact: ``F₀ = x₀ − 1 + ε⟨x₀⟩`` (the
    bulk pushes it onto a penalty ε = 1e10), ``F₁ = x₁ − 1`` a dof that only
    the full step puts right, and ``F₂ = x₂ − 1`` keeps ‖x‖ at the scale 1.
    From x = (−1e-9, 0, 1) the Jacobian has no contact stiffness, the Newton
    step takes the node 1 deep, and ‖F‖ along it is least at the kink."""

    PENALTY = 1e10

    def evaluate(self, x: PETSc.Vec, b: PETSc.Vec) -> None:
        x0, x1, x2 = x.array_r
        b.array[:] = [x0 - 1.0 + self.PENALTY * max(x0, 0.0), x1 - 1.0, x2 - 1.0]

    def derivative(self, x: np.ndarray) -> np.ndarray:
        return np.array([1.0 + self.PENALTY * (x[0] >= 0), 1.0, 1.0])


def test_a_step_stalled_at_a_kink_is_taken_whole():
    """Where ``l2`` shortens the step to round-off (``‖Δx‖ ≤ stol·‖x‖``) while
    ‖F‖ is not, the full step is taken uphill (``kink_steps``): the next
    Jacobian sees the penalty and Newton lands on the root. Without it, the
    library's convergence test stops the solve ("Newton step at round-off")
    and PETSc's own calls it converged, with ‖F‖ = 1."""
    start, newton = np.array([-1e-9, 0.0, 1.0]), np.ones(3)
    norms = []
    for step in (0.0, 0.5, 1.0):
        b = PETSc.Vec().createSeq(3, comm=PETSc.COMM_SELF)
        KinkProblem(3).evaluate(PETSc.Vec().createWithArray(start + step * (newton - start),
                                                            comm=PETSc.COMM_SELF), b)
        norms.append(b.norm() ** 2)
    stol = 1e-8     # PETSc's default
    assert l2_step_length(*norms) * np.linalg.norm(newton - start) < stol

    problem = KinkProblem(3)
    snes = problem.snes("basic")
    # the library's test (PETSc's own stops where ‖F‖ rises 1e4-fold)
    test = EquilibriumTest()
    snes.setConvergenceTest(test)
    problem.line_search = line_search = FullStepFirst(problem)
    line_search.attach(snes, round_off=test.floor)
    x = PETSc.Vec().createWithArray(start.copy(), comm=PETSc.COMM_SELF)
    snes.solve(None, x)
    assert snes.getConvergedReason() in (PETSc.SNES.ConvergedReason.CONVERGED_FNORM_RELATIVE,
                                         PETSc.SNES.ConvergedReason.CONVERGED_FNORM_ABS)
    assert x.array_r[0] == pytest.approx(1.0 / (1.0 + KinkProblem.PENALTY), rel=1e-8)
    assert x.array_r[1] == pytest.approx(1.0, rel=1e-12)
    assert line_search.kink_steps == 1


class CountingContactTerm(ContactTerm):
    """A contact term that counts its evaluations."""

    evaluations = 0

    def update(self, bcs=()):
        self.evaluations += 1
        return super().update(bcs)


def pressed_block(configuration: str = "current", friction=None):
    """A neo-Hookean block pressed by its top face onto a rigid disk."""
    domain, tags = rectangle(MPI.COMM_WORLD, 0.0, 0.5, (12, 6), bottom=BOTTOM, top=TOP,
                             left=LEFT)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    u = fem.Function(V)
    F = neo_hookean_residual(u, 1.0, 0.3)
    contact = CountingContactTerm(u, tags, BOTTOM, obstacle=RigidSphere([0.5, -2.0], 2.0),
                                  kind="LcLS*", penalty=200.0,
                                  basis_configuration=configuration, friction=friction)
    push = fem.Constant(domain, PETSc.ScalarType(0.0))
    left = fem.locate_dofs_topological(V.sub(0), 1, tags.find(LEFT))
    top = fem.locate_dofs_topological(V.sub(1), 1, tags.find(TOP))
    bcs = [fem.dirichletbc(PETSc.ScalarType(0.0), left, V.sub(0)),
           fem.dirichletbc(push, top, V.sub(1))]
    return NonlinearContactProblem(F, u, contact, bcs), contact, push


def test_an_offered_residual_is_used_once_and_only_at_its_point():
    problem, contact, push = pressed_block()
    push.value = -0.01
    u = problem.u
    u.interpolate(lambda x: np.vstack([0.01 * x[1], -0.002 - 0.02 * x[1]]))
    fem.petsc.set_bc(u.x.petsc_vec, problem.bcs)
    x = u.x.petsc_vec.copy()
    fresh, b = problem.vector().duplicate(), problem.vector().duplicate()
    problem.F(x, fresh)
    before = contact.evaluations

    problem.line_search.offer(x, fresh)
    problem.F(x, b)                       # the offer: copied, no evaluation
    assert contact.evaluations == before
    assert np.array_equal(b.array_r, fresh.array_r)
    problem.F(x, b)                       # an offer serves one call only
    assert contact.evaluations == before + 1
    assert np.array_equal(b.array_r, fresh.array_r)

    y = x.copy()
    y.array[:] += 1e-4 * np.random.default_rng(MPI.COMM_WORLD.rank).normal(size=y.array.shape)
    fem.petsc.set_bc(y, problem.bcs)
    at_y = problem.vector().duplicate()
    problem.F(y, at_y)
    problem.line_search.offer(x, fresh)
    problem.F(y, b)                       # not the offer's point: assembled
    assert contact.evaluations == before + 3
    assert np.array_equal(b.array_r, at_y.array_r)


def test_current_surface_steps_cost_one_residual_when_taken_whole():
    """One Newton solve on the current surface from the solution at a nearby
    load, with the library's line search and with PETSc's l2: the same
    solution to the Newton tolerance; l2 evaluates the residual three times
    per iteration, the library's once per full step and three times per cut
    one (and once at the start, as both do)."""
    problem, contact, push = pressed_block()
    start = LoadPathSolver(problem)
    start.solve(lambda t: setattr(push, "value", -0.02 * t), load_steps=2)
    x0 = problem.u.x.petsc_vec.copy()
    push.value = -0.025
    solutions, counts = [], []
    line_search = problem.line_search
    for options in ({}, {"snes_linesearch_type": "l2"}):
        solver = LoadPathSolver(problem, petsc_options=options)
        with solver.options():
            snes = solver.create_snes()
            x = x0.copy()
            before = contact.evaluations
            steps = (line_search.full_steps, line_search.cut_steps)
            snes.solve(None, x)
            assert snes.getConvergedReason() > 0
            counts.append((contact.evaluations - before, snes.getIterationNumber(),
                           solver.line_search, line_search.full_steps - steps[0],
                           line_search.cut_steps - steps[1]))
            solutions.append(x.array_r.copy())
            snes.destroy()
    (ours, iterations, attached, full, cut), (theirs, l2_iterations, none, *l2_steps) = counts
    assert attached is line_search and none is None and l2_steps == [0, 0]
    assert full + cut == iterations
    assert full >= 2
    assert ours == 1 + full + 3 * cut
    assert theirs == 1 + 3 * l2_iterations
    comm = MPI.COMM_WORLD
    norm = np.sqrt(comm.allreduce(np.sum(solutions[1] ** 2)))
    difference = np.sqrt(comm.allreduce(np.sum((solutions[0] - solutions[1]) ** 2)))
    assert difference < 1e-9 * norm


@pytest.mark.parametrize("configuration", ["initial", "previous", "current"])
def test_a_neo_hookean_block_pressed_and_slid_takes_the_requested_steps(configuration):
    """A rigid disk pressed into a neo-Hookean block (ln J) and slid by 30
    element lengths in 8 steps, with the library's defaults. With ``basic`` in
    the frozen phases it took 72 steps for the 12 requested and 60 cut-backs
    ("current"; 28 and 26 steps with "initial" and "previous"), most ending in
    a NaN residual (J ≤ 0) or at the maximum of Newton iterations; the line
    search now halves steps to a residual that is not finite and shortens
    frozen-phase steps of a nonlinear bulk."""
    figures = load_demo("press_and_slide").main(
        ["--press-steps", "4", "--slide-steps", "8", "--configuration", configuration,
         "--quiet"])
    assert figures["requested_steps"] == 12
    assert figures["cut_backs"] <= 1, figures["cut_backs"]
    assert figures["load_steps"] <= 13
    assert figures["steps"][-1]["t"] == 1.0


@pytest.mark.parametrize("configuration", ["previous", "current"])
def test_a_linear_bulk_keeps_full_frozen_steps_and_a_nonlinear_or_rubbing_one_shortens_them(
        configuration):
    """Frozen phases shorten steps for a nonlinear bulk or friction only; the
    current surface's phase always does (a linear bulk's Hertz 3D on two bodies
    diverged to 1e134 in it with full steps)."""
    problem, contact, _ = pressed_block(configuration)
    V = problem.u.function_space
    u, v = problem.u, ufl.TestFunction(V)
    linear = NonlinearContactProblem(ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx, u,
                                     contact, problem.bcs)
    rubbing, rubbing_contact, _ = pressed_block(configuration, CoulombFriction(0.3))
    u, v = rubbing.u, ufl.TestFunction(rubbing.u.function_space)
    frictional = NonlinearContactProblem(ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx, u,
                                         rubbing_contact, rubbing.bcs)
    for bulk, frozen_shortens in ((problem, True), (linear, False), (frictional, True)):
        solver = LoadPathSolver(bulk)
        with solver.options():
            snes = solver.create_snes()
            line_search = solver.line_search
            assert line_search is bulk.line_search
            assert line_search.shortens_frozen_steps == frozen_shortens
            assert line_search.shorten == (frozen_shortens or configuration == "current")
            with line_search.frozen_phase():
                assert line_search.shorten == frozen_shortens
            with line_search.full_steps_only():
                assert not line_search.shorten
            snes.destroy()


def test_a_trial_point_that_collapses_the_surface_is_a_nan_residual():
    """Where a Newton trial point collapses the contact surface (every node
    moved to one point), the residual is NaN on every rank and the problem
    says why, instead of a ValueError escaping from inside the SNES callback
    (the line search then halves the step, or the load step is cut back)."""
    problem, _, _ = pressed_block()
    u = problem.u
    u.interpolate(lambda x: -x[: 2])
    b = problem.vector().duplicate()
    problem.F(u.x.petsc_vec, b)
    assert np.all(np.isnan(b.array_r))
    assert "degenerate" in problem.evaluation_error
    u.x.array[:] = 0.0
    problem.F(u.x.petsc_vec, b)
    assert np.all(np.isfinite(b.array_r)) and problem.evaluation_error is None


def test_the_problems_own_snes_takes_the_library_line_search_unless_one_is_chosen():
    """``problem.solve()`` (the 0.10-style path) halves steps to a non-finite
    residual and shortens a nonlinear bulk's steps as the load path does."""
    problem, contact, push = pressed_block("previous")
    push.value = -0.01
    assert problem.solve() is problem.u
    assert problem.solver.getConvergedReason() > 0
    assert problem.line_search.shorten
    assert problem.line_search.full_steps + problem.line_search.cut_steps >= 1
    chosen = NonlinearContactProblem(neo_hookean_residual(problem.u, 1.0, 0.3), problem.u,
                                     contact, problem.bcs,
                                     petsc_options={"snes_linesearch_type": "bt"})
    problem.u.x.array[:] = 0.0
    assert chosen.solve() is problem.u
    assert chosen.solver.getConvergedReason() > 0
    unused = chosen.line_search
    assert unused.full_steps + unused.cut_steps + unused.halved_steps == 0
