"""Command lines of the demos and benchmarks: their own options plus PETSc's.

``hertz2d.py --refine 2 -dolfinx_mortar_snes_monitor`` should work as a PETSc
user expects: arguments with a single leading dash go to the PETSc options
database (an option followed by a value that does not start with a dash takes
that value), everything else to argparse.
"""
from __future__ import annotations

import argparse
import sys
from typing import Optional, Sequence


def parse_args_and_petsc_options(parser: argparse.ArgumentParser,
                                 argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    """Parse ``argv`` (default ``sys.argv[1:]``); put PETSc options in the database.

    Raises the parser's usage error for unknown ``--options``.
    """
    args, rest = parser.parse_known_args(sys.argv[1:] if argv is None else list(argv))
    options = {}
    i = 0
    while i < len(rest):
        item = rest[i]
        if not item.startswith("-") or item.startswith("--") or len(item) < 2:
            parser.error(f"unrecognized argument: {item}")
        has_value = i + 1 < len(rest) and not rest[i + 1].startswith("-")
        options[item[1:]] = rest[i + 1] if has_value else ""
        i += 2 if has_value else 1
    if options:
        from petsc4py import PETSc
        database = PETSc.Options()
        for key, value in options.items():
            database[key] = value
    return args


def add_contact_options(parser: argparse.ArgumentParser) -> None:
    """The solver options every contact demo offers (see ContactProblem)."""
    parser.add_argument("--active-set", default="nodal", choices=("nodal", "pointwise"),
                        help="penalty on the nodal gaps (nodal) or on ⟨d⟩ (pointwise)")
    parser.add_argument("--boundary-modification", action=argparse.BooleanOptionalAction,
                        default=None,
                        help="dual kinds on an elastic master: basis over the covered part "
                             "of partly covered facets (default: the library's, on for dual "
                             "kinds against an elastic master, nodal set, initial/previous)")
    parser.add_argument("--linear-solver", default="auto",
                        choices=("auto", "direct", "iterative"),
                        help="MUMPS, Krylov + multigrid + exact contact block, or by size "
                             "(auto: iterative for 3D from 50k dofs)")
    parser.add_argument("--basis-configuration", default="initial",
                        choices=("initial", "previous", "current"),
                        help="configuration of the bases: initial, previous step, current")


def solver_demo_parser(doc: str) -> argparse.ArgumentParser:
    """The parser of a contact demo: its docstring's first paragraph, a note on
    PETSc options, and the material (--E, --nu)."""
    parser = argparse.ArgumentParser(
        description=doc.split("\n\n")[0],
        epilog="PETSc options (single dash) go to the options database, e.g. "
               "-dolfinx_mortar_snes_monitor -dolfinx_mortar_snes_linesearch_type bt")
    parser.add_argument("--E", type=float, default=1.0, help="Young's modulus (1)")
    parser.add_argument("--nu", type=float, default=0.3, help="Poisson's ratio (0.3)")
    return parser
