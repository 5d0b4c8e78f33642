"""Test helpers shared across the test folders (not part of the library).

The demos and benchmark scenes are scripts, not modules of the package; the
tests load them with the one loader of demo_support.scripts.
"""
from __future__ import annotations

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


__all__ = ["REPO_ROOT", "DEMOS", "BENCHMARKS", "LOW_PENALTY", "POINTWISE_WITH_A_DUAL_KIND",
           "load_demo", "load_script"]
