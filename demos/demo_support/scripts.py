"""Load the repository's demo scripts as modules (for benchmarks and tests).

The demos are scripts, not modules of the package; the benchmarks and tests
call their functions (``main``, ``run``, ``build_mesh``). One loader for all.
"""
from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

#: the checkout's demos/ (this package sits in it, outside the installed library)
DEMOS = Path(__file__).resolve().parents[1]


def load_script(path: Path) -> ModuleType:
    """Import a script by its path as a module named after the file.

    Parameters
    ----------
    path
        The script.

    Returns
    -------
    ModuleType
        The executed module.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no script at {path}")
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def load_demo(name: str) -> ModuleType:
    """Import ``demos/<name>.py`` as a module."""
    return load_script(DEMOS / f"{name}.py")
