"""Test helpers shared across the test folders (not part of the library).

The demos and benchmark scenes are scripts, not modules of the package: the
tests load them from the repository by path, in one place.
"""
from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

REPO_ROOT = Path(__file__).resolve().parents[2]
DEMOS = REPO_ROOT / "demos"
BENCHMARKS = REPO_ROOT / "benchmarks"


def load_script(path: Path) -> ModuleType:
    """Import a script of the repository (a demo or a benchmark) as a module.

    Parameters
    ----------
    path
        The script's path.

    Returns
    -------
    ModuleType
        The executed module, named after the file.
    """
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def load_demo(name: str) -> ModuleType:
    """Import ``demos/<name>.py`` as a module (its ``main`` is then callable)."""
    return load_script(DEMOS / f"{name}.py")
