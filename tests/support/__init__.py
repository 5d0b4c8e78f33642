"""Test helpers shared across the test folders (not part of the library).

The demos and benchmark scenes are scripts, not modules of the package; the
tests load them with the one loader of demo_support.scripts.
"""
from __future__ import annotations

import os
from pathlib import Path

import pytest

from demo_support.scripts import load_demo, load_script

REPO_ROOT = Path(__file__).resolve().parents[2]
DEMOS = REPO_ROOT / "demos"
BENCHMARKS = REPO_ROOT / "benchmarks"

#: The suite runs with RuntimeWarnings as errors (pyproject.toml), so that a
#: false warning fails it. Where a test provokes one of the library's true
#: warnings on purpose, it says which. A penalty low for its mesh (a
#: conditioning sweep, a coarse demo, a tilted obstacle at ε = 100):
LOW_PENALTY = pytest.mark.filterwarnings(
    "ignore:at convergence the slave surface penetrates:RuntimeWarning")
#: The pointwise active set with a dual kind (the advice to prefer the nodal one):
POINTWISE_WITH_A_DUAL_KIND = pytest.mark.filterwarnings(
    "ignore:the pointwise active set with a dual kind:RuntimeWarning")


def child_environment() -> dict:
    """The environment for a child run: no trace of this process's MPI job (a
    child of an mpirun rank would otherwise try to join that job). The child
    imports the package as this process does (the same PYTHONPATH)."""
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("OMPI_", "PMIX_", "OPAL_", "HYDRA_", "PMI_"))}
    env["OMP_NUM_THREADS"] = "1"
    env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


__all__ = ["REPO_ROOT", "DEMOS", "BENCHMARKS", "LOW_PENALTY", "POINTWISE_WITH_A_DUAL_KIND",
           "child_environment", "load_demo", "load_script"]
