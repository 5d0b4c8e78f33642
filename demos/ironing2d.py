"""Ironing in 2D after Puso & Laursen (2004): a stiff half-cylindrical die pressed into a
neo-Hookean slab and slid along it on the current configuration, frictionless or with
Coulomb friction (``--mu 0.3``, the paper's).

The scene, its outputs and the figures: :mod:`demo_support.ironing`.

    python3 demos/ironing2d.py --csv results/ironing2d.csv \
        --png results/ironing2d.png --output results/ironing2d.xdmf
"""
from __future__ import annotations

from typing import Optional, Sequence

from mpi4py import MPI

from demo_support.ironing import parse_args, run


def main(argv: Optional[Sequence[str]] = None) -> dict:
    """Run the demo; returns the key figures (and the per-step rows under "steps")."""
    return run(parse_args(__doc__, 2, argv), MPI.COMM_WORLD)


if __name__ == "__main__":
    main()
