"""Figure 2: a rigid sphere interpenetrating a flat quadratic NURBS surface.

No contact is enforced: the sphere (radius R, centre above the middle of the
unit square) sinks a depth δ into the plane z = 0, and the raw penalty pressure
p = ε⟨d⟩ with d = R - |x - c| (minus the exact signed distance; docs/DESIGN.md, §Penalty contact)
is fitted by every mortar basis kind:

- nodal pressures ``p_A = ∫ M̄_A p dA`` with ``M̄`` the unstarred partner
  (∫M̄_A = 1, so ``p_A`` is a pressure; a kind and its starred partner share it),
- the smoothed pressure ``p̂ = Σ_A N_A p_A`` (the least-squares fit),
- the mortar pressure ``p* = Σ_A M_A p_A`` with the kind's own ``M_A``.

For a partition-of-unity kind ``p*`` approximates ``p``. For a non-PU kind
``M_A = M*_A / W_A`` is a density per unit area, so ``p*`` is of order ``p/W_A``:
higher than its PU partner's, and growing as the mesh is refined.

    python3 demos/fig2_sphere_nurbs.py --elements 8 --levels 3 --json results/fig2_pressures.json
"""
from __future__ import annotations

import argparse
from typing import Optional, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from dolfinx_mortar import KIND_NAMES, MortarBasis, nurbs  # noqa: E402
from dolfinx_mortar.kinds import is_partition_of_unity, kind_name, unstarred_partner  # noqa: E402
from dolfinx_mortar.io.output import save_figure, write_json  # noqa: E402


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--elements", type=int, default=8,
                        help="elements per direction on the coarsest level (8)")
    parser.add_argument("--levels", type=int, default=3,
                        help="refinement levels, each halving h (3)")
    parser.add_argument("--degree", type=int, default=2, help="NURBS degree (2)")
    parser.add_argument("--radius", type=float, default=1.0, help="sphere radius R (1)")
    parser.add_argument("--depth", type=float, default=0.05,
                        help="interpenetration δ of the sphere into the plane (0.05)")
    parser.add_argument("--penalty", type=float, default=1.0,
                        help="penalty ε, pressure per length (1)")
    parser.add_argument("--weights-jitter", type=float, default=0.0,
                        help="make the surface rational: weights 1 + jitter·U(-1,1) (0)")
    parser.add_argument("--quadrature-degree", type=int, default=12,
                        help="Gauss rule degree per element; high because ⟨d⟩ has a kink (12)")
    parser.add_argument("--output", default="results/fig2_pressures.png", help="PNG path")
    parser.add_argument("--json", default=None, help="write the key figures as JSON here")
    return parser.parse_args(argv)


def raw_pressure(x: np.ndarray, radius: float, depth: float, penalty: float) -> np.ndarray:
    """p = ε⟨R - |x - c|⟩ on the plane z = 0, sphere centre c = (½, ½, R - δ)."""
    r2 = (x[0] - 0.5) ** 2 + (x[1] - 0.5) ** 2
    d = radius - np.sqrt(r2 + (radius - depth) ** 2)
    return penalty * np.maximum(d, 0.0)


def make_surface(n: int, degree: int, jitter: float) -> nurbs.BSplineSurface:
    weights = None
    if jitter > 0:
        rng = np.random.default_rng(0)
        m = n + degree
        weights = 1.0 + jitter * rng.uniform(-1, 1, (m, m))
    return nurbs.BSplineSurface(degree=degree, n_elements=n, weights=weights)


def fit(surface, p, quadrature_degree: int) -> dict:
    """Nodal pressures, and per kind the element coefficients of p̂ and p*."""
    out = {}
    nodal = {}
    for kind in KIND_NAMES:
        partner = kind_name(unstarred_partner(kind))
        if partner not in nodal:
            nodal[partner] = MortarBasis(partner, surface, quadrature_degree).nodal_values(p)
        basis = MortarBasis(kind, surface, quadrature_degree)
        pA = nodal[partner]
        out[kind] = {"basis": basis, "nodal": pA,
                     "smoothed": pA[surface.cells],
                     "mortar": basis.mortar_coefficients(pA)}
    return out


def errors(surface, fits: dict, p, quadrature_degree: int) -> dict:
    """Relative L2 error of p̂ and max p*/max p, per kind, on the quadrature points."""
    tab = fits["GLS"]["basis"].tabulation
    pq = tab.values_of(p)
    norm = np.sqrt(np.sum(tab.weights * pq ** 2))
    result = {}
    for kind, f in fits.items():
        p_hat = np.einsum("cqb,cb->cq", tab.phi, f["smoothed"])
        p_star = np.einsum("cqb,cb->cq", tab.phi, f["mortar"])
        result[kind] = {
            "l2_error_smoothed": float(np.sqrt(np.sum(tab.weights * (p_hat - pq) ** 2)) / norm),
            "max_mortar_over_max_raw": float(p_star.max() / pq.max()),
        }
    return result


def plot_cut(args, surface, fits, p, path) -> None:
    s = np.linspace(0.0, 1.0, 801)
    pts = np.column_stack([s, np.full_like(s, 0.5)])
    cells, phi = surface.locate(pts)
    raw = p(pts.T)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    styles = {"GLS": "C0", "GLS*": "C0", "LmLS": "C1", "LmLS*": "C1", "LcLS*": "C2", "LcLS": "C2"}
    ax = axes[0]
    ax.plot(s, raw, "k", lw=2.2, label="raw p = ε⟨d⟩")
    for kind in ("GLS", "LmLS", "LcLS"):
        v = np.einsum("rb,rb->r", phi, fits[kind]["smoothed"][cells])
        ax.plot(s, v, styles[kind], lw=1.4, label=f"p̂ {kind} = {kind}*")
    ax.set_title("smoothed pressure p̂ = N_A p_A")
    for ax, pu in ((axes[1], True), (axes[2], False)):
        ax.plot(s, raw, "k", lw=2.2, label="raw p")
        for kind in KIND_NAMES:
            if is_partition_of_unity(kind) != pu:
                continue
            v = np.einsum("rb,rb->r", phi, fits[kind]["mortar"][cells])
            ax.plot(s, v, styles[kind], lw=1.4, label=f"p* {kind}")
        ax.set_title("mortar pressure p* = M_A p_A, " + ("PU kinds" if pu else "non-PU kinds"))
    for ax in axes:
        ax.set_xlabel("x (cut y = ½ through the sphere's centre)")
        ax.set_xlim(0.1, 0.9)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("pressure / ε")
    fig.suptitle(f"Rigid sphere R={args.radius}, δ={args.depth} on a degree-{args.degree} "
                 f"NURBS plane, {surface.bases[0].num_elements}² elements")
    fig.tight_layout()
    save_figure(path, fig, dpi=130)
    plt.close(fig)


def main(argv: Optional[Sequence[str]] = None) -> dict:
    args = parse_args(argv)
    if args.depth <= 0 or args.depth >= args.radius:
        raise SystemExit("--depth must lie in (0, radius)")

    def p(x):
        return raw_pressure(x, args.radius, args.depth, args.penalty)

    table = []
    for level in range(args.levels):
        n = args.elements * 2 ** level
        surface = make_surface(n, args.degree, args.weights_jitter)
        fits = fit(surface, p, args.quadrature_degree)
        if level == 0:
            plot_cut(args, surface, fits, p, args.output)
            print(f"wrote {args.output}")
        for kind, e in errors(surface, fits, p, args.quadrature_degree).items():
            table.append({"elements_per_direction": n, "kind": kind, **e})

    print(f"\n{'n':>4s} " + " ".join(f"{k:>10s}" for k in KIND_NAMES))
    for label, key in (("relative L2 error of p̂", "l2_error_smoothed"),
                       ("max p* / max p", "max_mortar_over_max_raw")):
        print(label)
        for level in range(args.levels):
            n = args.elements * 2 ** level
            row = {r["kind"]: r[key] for r in table if r["elements_per_direction"] == n}
            print(f"{n:4d} " + " ".join(f"{row[k]:10.4g}" for k in KIND_NAMES))
    contact_radius = np.sqrt(args.radius ** 2 - (args.radius - args.depth) ** 2)
    figures = {"radius": args.radius, "depth": args.depth, "penalty": args.penalty,
               "degree": args.degree, "contact_radius": float(contact_radius),
               "max_raw_pressure": args.penalty * args.depth, "table": table}
    if args.json:
        write_json(args.json, figures)
        print(f"wrote {args.json}")
    return figures


if __name__ == "__main__":
    main()
