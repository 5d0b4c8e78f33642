"""A model of contact and bulk assembly per rank at 16 … 1,024 ranks, from
the per-rank measurements of :mod:`contact_ranks` at 1 … 16 ranks.

    python3 benchmarks/contact_model.py            # Hertz 3D, --refine 1.5, graph partition

The model (docs/SCALING.md, "A model of the assembly at 16–1,024 ranks"):

    T(P) = bulk(1) / P + contact(P),   contact(P) = a · pairs(P) + floor

- ``bulk(1)``: the bulk assembly CPU on 1 rank; it is taken to fall as 1/P.
- ``a`` and ``floor``: a least-squares line through the busiest rank's
  (segmented pairs, contact CPU) at every measured rank count. ``floor`` is
  what a rank spends on contact whatever it holds (collectives, PETSc's
  parallel products, waiting); it is compared with the contact CPU of the
  ranks that hold no slave facet at the largest rank count.
- ``pairs(P)``: the busiest rank's pairs, measured up to the largest rank
  count P0, then ``pairs(P0) · (P0 / P)^(2/3)``: a contact zone that is a
  surface meets about P^(2/3) of P compact ranks. With a contact layout of
  its own (pairs balanced over all ranks) ``pairs(P) = total / P``.
- A scene ``--scale`` times larger has bulk(1) and the pairs at every P that
  many times larger (the contact zone spread over the ranks in the same
  proportion); ``a`` and ``floor`` stay.

Left out: the linear solver, meshing and output (most of the run's CPU), and
how communication latency grows with the rank count: ``floor`` is measured on
2 cores with up to 16 ranks and is held constant.
"""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Optional, Sequence

import numpy as np

from contact_ranks import HERE, read_rows

MODEL_RANKS = (16, 64, 256, 1024)


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stem", default="contact_ranks_hertz3d_r1.5_graph")
    parser.add_argument("--results", default=str(HERE / "results"))
    parser.add_argument("--scales", type=float, nargs="+", default=[1.0, 100.0])
    return parser.parse_args(argv)


def fit(per_count: dict[int, list[dict]]) -> dict:
    """The model's constants from the per-rank rows of each rank count."""
    busiest = {p: max(rows, key=lambda r: r["pairs"]) for p, rows in per_count.items()}
    pairs = np.array([busiest[p]["pairs"] for p in sorted(busiest)])
    contact = np.array([busiest[p]["contact_total"] for p in sorted(busiest)])
    a, floor = np.polyfit(pairs, contact, 1)
    last = max(per_count)
    idle = [r["contact_total"] for r in per_count[last] if r["slave_facets"] == 0]
    return {"a": a, "floor": floor, "bulk1": busiest[1]["bulk"],
            "total_pairs": sum(r["pairs"] for r in per_count[1]), "last": last,
            "pairs_last": busiest[last]["pairs"],
            "measured_pairs": {p: busiest[p]["pairs"] for p in busiest},
            "idle_median": float(np.median(idle)) if idle else float("nan")}


def busiest_pairs(m: dict, p: int, balanced: bool) -> float:
    if balanced:
        return m["total_pairs"] / p
    if p in m["measured_pairs"]:
        return m["measured_pairs"][p]
    return m["pairs_last"] * (m["last"] / p) ** (2.0 / 3.0)


def rows(m: dict, scale: float) -> list[dict]:
    out = []
    for p in MODEL_RANKS:
        bulk = scale * m["bulk1"] / p
        row = {"ranks": p, "bulk": bulk}
        for tag, balanced in (("graph", False), ("balanced", True)):
            pairs = scale * busiest_pairs(m, p, balanced)
            contact = m["a"] * pairs + m["floor"]
            row.update({f"{tag}_pairs": pairs, f"{tag}_contact": contact,
                        f"{tag}_share": contact / (bulk + contact)})
        out.append(row)
    return out


def markdown(m: dict, scales: Sequence[float]) -> str:
    lines = [f"a = {m['a']:.3g} s per pair, floor = {m['floor']:.3f} s (ranks without slave "
             f"facets at {m['last']} ranks: median {m['idle_median']:.3f} s), bulk(1) = "
             f"{m['bulk1']:.2f} s, {m['total_pairs']:.0f} pairs in all", "",
             "| scene | ranks | bulk/P s | busiest pairs | contact s | contact share | "
             "balanced: pairs | contact s | contact share |", "|" + "---|" * 9]
    for scale in scales:
        for r in rows(m, scale):
            lines.append(f"| ×{scale:g} | {r['ranks']:,} | {r['bulk']:.3g} | "
                         f"{r['graph_pairs']:,.0f} | {r['graph_contact']:.3g} | "
                         f"{100 * r['graph_share']:.0f}% | {r['balanced_pairs']:,.0f} | "
                         f"{r['balanced_contact']:.3g} | {100 * r['balanced_share']:.0f}% |")
    return "\n".join(lines) + "\n"


def main(argv: Optional[Sequence[str]] = None) -> str:
    args = parse_args(argv)
    per_count = {}
    for path in Path(args.results).glob(f"{args.stem}_n*.csv"):
        ranks = read_rows(path)
        per_count[len(ranks)] = ranks
    if 1 not in per_count or len(per_count) < 2:
        raise FileNotFoundError(f"{args.stem}_n*.csv in {args.results} needs 1 rank and at "
                                "least one more rank count")
    text = markdown(fit(per_count), args.scales)
    print(text)
    return text


if __name__ == "__main__":
    main()
