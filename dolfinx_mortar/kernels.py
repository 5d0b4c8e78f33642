"""The C++ kernels, as Python sees them.

Facet geometry (shape functions, normals, bounding boxes), segmentation and
the mortar integrals, and the per-element basis coefficients: array in, array
out, no DOLFINx. The Python layers above call these; they are public so that a
user (and the tests) can check a kernel on its own. The compiled module is
``dolfinx_mortar._kernels``; this module is its documented name.
"""


def _explain(error: ImportError) -> str:
    """What to do when the compiled module cannot be imported."""
    from pathlib import Path

    here = Path(__file__).resolve().parent
    lines = [f"dolfinx_mortar's compiled kernels (dolfinx_mortar._kernels) cannot be imported: "
             f"{error}"]
    built = sorted(p.name for p in here.glob("_kernels*") if p.suffix in (".so", ".pyd"))
    if (here.parent / "pyproject.toml").is_file() and (here.parent / "kernels").is_dir():
        lines.append(
            f"Python is importing the source tree {here} instead of the installed package "
            "(the kernels are built into the installed package, not into the checkout): run "
            "from another directory than the checkout, or with `python3 -P` (Python 3.11+; or "
            "PYTHONSAFEPATH=1), so that the current directory is not put first on sys.path.")
        if built:
            lines.append(f"{', '.join(built)} in the source tree: an old in-tree build, "
                         "`make clean` removes it.")
    elif built:
        # there is a module and it does not load: built for another Python, or a library missing
        lines.append(f"{here} has {', '.join(built)}, which does not load for this Python "
                     "(built for another Python version, or a library is missing): reinstall "
                     "dolfinx_mortar with this Python.")
    lines.append(
        "dolfinx_mortar must be installed, which builds the kernels: `make setup` in the "
        "checkout (a virtual environment .venv, then use .venv/bin/python), or "
        "`pip install --no-build-isolation .` in the checkout into an environment that has "
        "DOLFINx (e.g. a venv made with `python3 -m venv --system-site-packages`).")
    return "\n".join(lines)


try:
    from dolfinx_mortar import _kernels
except ImportError as _error:
    raise ImportError(_explain(_error), name="dolfinx_mortar._kernels") from _error

__all__ = [name for name in dir(_kernels) if not name.startswith("_")]
globals().update({name: getattr(_kernels, name) for name in __all__})
