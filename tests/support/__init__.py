"""Test helpers shared across the test folders (not part of the library).

The demos and benchmark scenes are scripts, not modules of the package; the
tests load them with the one loader of demo_support.scripts.
"""
from __future__ import annotations

from pathlib import Path

from demo_support.scripts import load_demo, load_script

REPO_ROOT = Path(__file__).resolve().parents[2]
DEMOS = REPO_ROOT / "demos"
BENCHMARKS = REPO_ROOT / "benchmarks"

__all__ = ["REPO_ROOT", "DEMOS", "BENCHMARKS", "load_demo", "load_script"]
