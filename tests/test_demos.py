"""The figure demos run, write complete results, and show the paper's statements."""
from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest
from mpi4py import MPI

DEMOS = Path(__file__).resolve().parent.parent / "demos"


def load(name):
    spec = importlib.util.spec_from_file_location(name, DEMOS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture
def out(tmp_path_factory):
    # one folder per rank: both ranks run the serial demos under mpirun
    return tmp_path_factory.mktemp(f"rank{MPI.COMM_WORLD.rank}")


def test_fig1_bases(out):
    figures = load("fig1_bases").main(["--output", str(out / "f1.png"),
                                       "--json", str(out / "f1.json")])
    assert (out / "f1.png").stat().st_size > 10_000
    assert json.loads((out / "f1.json").read_text()) == figures
    for kind, f in figures["kinds"].items():
        if f["partition_of_unity"]:
            assert f["max_abs_sum_minus_one"] < 1e-12
        else:
            assert f["max_abs_integral_minus_one"] < 1e-12
    assert figures["kinds"]["LmLS*"]["min_value"] >= 0.0   # B-splines are non-negative
    assert figures["kinds"]["LcLS*"]["min_value"] < -1.0   # dual functions are not


def test_fig2_sphere_reproduces_the_papers_statements(out):
    figures = load("fig2_sphere_nurbs").main(["--levels", "2", "--output", str(out / "f2.png"),
                                              "--json", str(out / "f2.json")])
    assert (out / "f2.png").stat().st_size > 10_000
    rows = {(r["elements_per_direction"], r["kind"]): r for r in figures["table"]}
    for n in (8, 16):
        err = {k: rows[(n, k)]["l2_error_smoothed"] for k in ("GLS", "LmLS", "LcLS")}
        assert err["GLS"] < err["LcLS"] < err["LmLS"]          # GLS best, LmLS worst
        for pu, non_pu in (("GLS*", "GLS"), ("LmLS*", "LmLS"), ("LcLS*", "LcLS")):
            assert (rows[(n, non_pu)]["max_mortar_over_max_raw"]
                    > 10 * rows[(n, pu)]["max_mortar_over_max_raw"])
    for k in ("GLS", "LmLS", "LcLS"):                           # refinement helps
        assert rows[(16, k)]["l2_error_smoothed"] < 0.6 * rows[(8, k)]["l2_error_smoothed"]


def test_demo_command_lines_pass_petsc_options_to_the_database():
    import argparse

    from petsc4py import PETSc

    from dolfinx_mortar.demo_support.cli import parse_args_and_petsc_options
    parser = argparse.ArgumentParser()
    parser.add_argument("--refine", type=float, default=1.0)
    args = parse_args_and_petsc_options(parser, ["--refine", "2", "-cli_test_snes_monitor",
                                                 "-cli_test_snes_rtol", "1e-3"])
    options = PETSc.Options()
    assert args.refine == 2.0
    assert options.hasName("cli_test_snes_monitor")
    assert options.getReal("cli_test_snes_rtol") == 1e-3
    options.delValue("cli_test_snes_monitor")
    options.delValue("cli_test_snes_rtol")
    with pytest.raises(SystemExit):
        parse_args_and_petsc_options(parser, ["--bogus"])


def test_quickstart_runs_and_balances(tmp_path, monkeypatch):
    """The README's example, as printed there: it converges, and the contact
    force on the block is what the top face's support holds (equilibrium)."""
    import runpy
    from dolfinx_mortar import reaction_force
    from mpi4py import MPI
    workdir = MPI.COMM_WORLD.bcast(str(tmp_path), root=0)
    monkeypatch.chdir(workdir)
    scene = runpy.run_path(str(DEMOS / "quickstart.py"))
    force = scene["contact"].contact_force()
    assert force[1] > 0 and abs(force[0]) < 1e-8 * force[1]
    reaction = reaction_force(scene["problem"], scene["facet_tags"], scene["TOP"])
    assert reaction == pytest.approx(-force, rel=1e-8, abs=1e-10 * force[1])
