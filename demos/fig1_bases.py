"""Figure 1: the six mortar bases on a 1D quadratic NURBS curve.

One panel per kind (GLS, GLS*, LmLS, LmLS*, LcLS*, LcLS), each showing every
M_A over the parameter interval, as in Figure 1 of Duong, De Lorenzis and Sauer.

    python3 demos/fig1_bases.py --elements 5 --degree 2 --json results/fig1_bases.json
"""
from __future__ import annotations

import argparse
from typing import Optional, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from dolfinx_mortar import KIND_NAMES, MortarBasis, nurbs  # noqa: E402
from dolfinx_mortar.kinds import is_partition_of_unity  # noqa: E402
from dolfinx_mortar.io.output import save_figure, write_json  # noqa: E402

DESCRIPTION = {
    "GLS": "global least squares  M = N L⁻¹",
    "GLS*": "global biorthogonal  M = N L⁻¹ W",
    "LmLS": "weighted standard  M = N W⁻¹",
    "LmLS*": "standard  M = N",
    "LcLS*": "dual  M|e = N (Le)⁻¹ We",
    "LcLS": "M|e = N (Le)⁻¹ We W⁻¹",
}


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--elements", type=int, default=5, help="number of elements (5)")
    parser.add_argument("--degree", type=int, default=2, help="B-spline degree (2)")
    parser.add_argument("--weights", type=float, nargs="+", default=None,
                        help="rational weights, one per function (default: all 1)")
    parser.add_argument("--points", type=int, default=1001,
                        help="evaluation points per curve (1001)")
    parser.add_argument("--output", default="results/fig1_bases.png", help="PNG path")
    parser.add_argument("--json", default=None, help="write the key figures as JSON here")
    return parser.parse_args(argv)


def main(argv: Optional[Sequence[str]] = None) -> dict:
    args = parse_args(argv)
    curve = nurbs.BSplineCurve(degree=args.degree, n_elements=args.elements,
                               weights=args.weights)
    # Points just inside each element, so discontinuous kinds show both one-sided limits.
    a, b = curve.basis.element_bounds()
    per_element = max(args.points // curve.num_elements, 8)
    s = np.linspace(0.0, 1.0, per_element)
    xi = (a[:, None] + (b - a)[:, None] * s[None, :]).ravel()
    elements = np.repeat(np.arange(curve.num_elements), per_element)
    phi, _, _ = curve.tabulate_at(elements, xi)

    fig, axes = plt.subplots(2, 3, figsize=(13, 6.5), sharex=True)
    figures = {"elements": curve.num_elements, "degree": curve.degree,
               "functions": curve.num_functions, "kinds": {}}
    for ax, kind in zip(axes.ravel(), KIND_NAMES):
        basis = MortarBasis(kind, curve)
        M = basis.evaluate(elements, phi)
        tab = basis.tabulation
        Mq = basis.evaluate(np.repeat(np.arange(curve.num_elements), tab.weights.shape[1]),
                            tab.phi.reshape(-1, tab.phi.shape[2]))
        integrals = tab.weights.ravel() @ Mq
        for A in range(curve.num_functions):
            for e in range(curve.num_elements):
                sl = slice(e * per_element, (e + 1) * per_element)
                ax.plot(xi[sl], M[sl, A], color=f"C{A % 10}", lw=1.4)
        ax.axhline(0.0, color="0.6", lw=0.6)
        for knot in np.unique(curve.basis.knots):
            ax.axvline(knot, color="0.85", lw=0.6, zorder=0)
        pu = is_partition_of_unity(kind)
        ax.set_title(f"{kind}: {DESCRIPTION[kind]}\n"
                     f"{'Σ M_A = 1' if pu else '∫ M_A dA = 1'}", fontsize=10)
        figures["kinds"][kind] = {
            "partition_of_unity": pu,
            "max_abs_sum_minus_one": float(np.max(np.abs(M.sum(axis=1) - 1.0))),
            "max_abs_integral_minus_one": float(np.max(np.abs(integrals - 1.0))),
            "min_value": float(M.min()),
            "max_value": float(M.max()),
        }
    for ax in axes[1]:
        ax.set_xlabel("ξ")
    fig.suptitle(f"Mortar shape functions on a degree-{curve.degree} "
                 f"{'NURBS' if args.weights else 'B-spline'} curve, "
                 f"{curve.num_elements} elements")
    fig.tight_layout()
    save_figure(args.output, fig, dpi=130)
    plt.close(fig)
    print(f"wrote {args.output}")
    print(f"{'kind':6s} {'PU':>3s} {'max|ΣM-1|':>10s} {'max|∫M-1|':>10s} {'min M':>8s} {'max M':>8s}")
    for kind, f in figures["kinds"].items():
        print(f"{kind:6s} {'yes' if f['partition_of_unity'] else 'no':>3s} "
              f"{f['max_abs_sum_minus_one']:10.2e} {f['max_abs_integral_minus_one']:10.2e} "
              f"{f['min_value']:8.3f} {f['max_value']:8.3f}")
    if args.json:
        write_json(args.json, figures)
        print(f"wrote {args.json}")
    return figures


if __name__ == "__main__":
    main()
