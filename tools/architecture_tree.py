"""The package tree the architecture counts read, and the small helpers they share
(tools/architecture_counts.py)."""
from __future__ import annotations

import ast
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

GAP_SOURCES = "contact/gap_sources/"

#: path in the layout by concept: path in the flat contact/ (ea0a892), both under contact/
OLD_PATHS = {f"contact/{new}": f"contact/{old}" for new, old in (pair.split(":") for pair in """
    checks/range_checks.py:checks.py checks/setup_checks.py:setup_checks.py
    friction/state.py:friction_state.py friction/tangential.py:friction.py
    gap_sources/choice.py:models.py gap_sources/configuration.py:configuration.py
    gap_sources/current/finite_deformation.py:finite_deformation.py
    gap_sources/current/mortar.py:current_mortar.py
    gap_sources/current/obstacle.py:current_obstacle.py
    gap_sources/cut_quadrature.py:cut_quadrature.py gap_sources/frozen.py:gaps.py
    gap_sources/global_gap.py:global_gap.py gap_sources/pointwise.py:pointwise.py
    gap_sources/source.py:state.py laws/coulomb.py:friction_law.py laws/penalty.py:penalty_law.py
    newton/augmented.py:augmented.py newton/entry.py:newton_entry.py
    newton/near_contact.py:active_set.py obstacles/analytic.py:obstacles.py
    results/contact_results.py:results.py""".split())}


@dataclass
class Count:
    """A number (None: nothing to count by this rule in this tree), its places and a note."""
    value: Optional[int]
    items: list[str] = field(default_factory=list)
    note: str = ""

    def shown(self) -> str:
        number = "–" if self.value is None else str(self.value)
        return number + (f" ({self.note})" if self.note else "")


def module_name(rel: str) -> str:
    parts = rel[:-3].split("/")
    return ".".join(["dolfinx_mortar", *(parts[:-1] if parts[-1] == "__init__" else parts)])


def short(module: str) -> str:
    return module.removeprefix("dolfinx_mortar.")


def name_of(node: ast.AST) -> Optional[str]:
    """The name a Name or an Attribute ends in."""
    return getattr(node, "id", getattr(node, "attr", None))


def order(place: str) -> list[tuple[int, str]]:
    """A sort key of ``file:line …``: by file, then by line number."""
    return [(int(p), "") if p.isdigit() else (-1, p) for p in re.split(r"[: ]", place)]


def places(found: dict[str, list[str]]) -> list[str]:
    """``key (where, …)`` for each key, its places in file and line order, once each."""
    return [f"{key} ({', '.join(sorted(set(where), key=order))})"
            for key, where in sorted(found.items())]


class Tree:
    """The package of one checkout, parsed once."""

    def __init__(self, root: Path):
        self.root = Path(root).resolve()
        self.package = self.root / "dolfinx_mortar"
        if not self.package.is_dir():
            raise SystemExit(f"{root}: no dolfinx_mortar/ package there")
        self.paths = {p.relative_to(self.package).as_posix(): p for p in
                      sorted(self.package.rglob("*.py")) if "__pycache__" not in p.parts}
        self.text = {rel: p.read_text() for rel, p in self.paths.items()}
        self.ast = {rel: ast.parse(text) for rel, text in self.text.items()}
        self.new_layout = (self.package / GAP_SOURCES).is_dir()
        self.modules = {module_name(rel): rel for rel in self.paths}

    def where(self, rel: str) -> Optional[str]:
        """A path of the layout by concept as this tree has it (None: not in this tree)."""
        old = None if self.new_layout else OLD_PATHS.get(rel)
        return rel if rel in self.paths else (old if old in self.paths else None)

    def owned(self, rels) -> tuple[set[str], str]:
        """The owners that this tree has, and a note naming those it has not."""
        missing = [r for r in rels if self.where(r) is None]
        return {self.where(r) for r in rels} - {None}, (
            f"not in this tree: {', '.join(missing)}" if missing else "")

    def in_gap_sources(self, rel: str) -> bool:
        return rel.startswith(GAP_SOURCES) if self.new_layout else rel in {
            old for new, old in OLD_PATHS.items() if new.startswith(GAP_SOURCES)}
