"""Counts that say how the contact package is laid out (docs/DESIGN.md, §Architecture).

    /usr/bin/python3 tools/architecture_counts.py [--root TREE] [--compare OLD_TREE] [--markdown]

Each count is of the source as it is, by a rule written here, so that a refactoring is judged by
the same rule before and after: ``--compare OLD`` counts OLD (before) and ``--root`` (after,
default this checkout) in one run. Paths are those of the layout by concept
(``contact/gap_sources/`` …); in a tree with the flat ``contact/`` each is read as its old name
(``OLD_PATHS``, the renames of commit 4c00b53), and an owner in neither is named in the output,
not skipped silently. Only ``ast`` and regular expressions, no import of the package: the system
python3 runs it. The package only (not tests/, demos/). Plain output: each count, before -> after,
then every place of the tree counted after; ``--markdown``: a table, four places a cell.

- Modules over 400 lines (Python and C++); Python classes over 200 and over 250 lines; the
  package's own modules over 400 lines.
- ``basis_configuration ==``/``!=`` and ``.augmented`` (not the module path
  ``contact.newton.augmented``) outside their owners (``OWNERS``); lines
  writing the penalty law (``np.maximum(·, 0.0)`` of a gap, the penalty times a force) in
  ``contact/`` outside ``LAW``; ``einsum`` lines in ``CURRENT``; string-key lookups of what the
  kernels return (``r["gradient"]``).
- Gap-source members read but not declared: the members of the gap-source Protocol (the class
  ``GapSource`` or ``GapModel`` in ``contact/``: its methods and class-level names) against the
  distinct attribute names read on a gap-source object outside the gap-source modules
  (``contact/gap_sources/**``; in the flat tree the files that moved there). A heuristic by name:
  a gap-source object is an expression written as one of ``GAP_SOURCE_EXPRESSIONS`` (``model``,
  ``source``, ``inner``, ``self.model``, ``term.model`` …) or a parameter annotated with the
  Protocol's name; ``getattr``/``hasattr`` on one with a literal name is a read of that name. A
  gap source under another name is missed, and another object so named is taken
  (``NOT_GAP_SOURCES``: modules whose ``model`` is gmsh's are skipped).
- isinstance on gap-source types: ``isinstance``/``issubclass`` with a class defined in a gap-source
  module, and ``getattr``/``hasattr`` on a gap-source object (as above), anywhere in the package.
- Branches on the active set's variant: ``.pointwise`` read in the test of an ``if``, ``while``,
  conditional expression, ``assert`` or comprehension filter, or as an operand of ``and``/``or``/
  ``not``, outside ``VARIANT_OWNERS`` (those that exist are named). A value passed on
  (``keep_points=law.pointwise``) or stored is not a branch.
- Public names of ``PUBLIC_CLASSES``: names without a leading ``_`` that are methods, properties,
  nested classes, class-level assignments or ``self.X = …`` targets anywhere in the class.
- Import cycles: strongly connected components of the graph of the package's modules. A package's
  module is its ``__init__.py``; ``from a.b import c`` is an edge to ``a.b.c`` if that is a
  module, else to ``a.b``; relative imports are resolved; the parent packages Python runs first
  are not edges, nor ``import_module`` strings, nor the compiled ``EXTENSIONS``. Three graphs:
  module-level imports; with those under ``if TYPE_CHECKING:``; with function-local ones too.
  Each component is shown with one shortest cycle through its first module, its edges marked
  ``[type-hint]``/``[function-local]`` where they are not module-level.
- Folders of the package: the lines and number of the ``.py`` files directly in each (its
  subfolders not included, ``__init__.py`` included), flagged over 1,500 lines or 10 modules.
- Imports that reach past a ``contact/`` subpackage's ``__init__`` (to a module or subfolder of
  it) from a module outside that subpackage, all three kinds of import (– in the flat tree).
- Kind questions: calls or property reads of ``kinds.py``'s public functions but ``parse_kind``
  (``is_global``, ``is_partition_of_unity``, ``unstarred_partner``, ``kind_name``), reads of its
  ``*_KINDS`` sets, and comparisons (``in``, ``==``, ``is`` and negations; one per comparison) of a
  ``BasisKind.X`` or of an expression whose name ends in ``kind``, outside ``KIND_OWNERS``
  (``kinds.py`` and the layers that implement the kinds: ``bases/``, ``mortar/``).
"""
from __future__ import annotations

import argparse
import ast
import re
from pathlib import Path
from typing import Optional

from architecture_imports import folder_counts, import_counts
from architecture_tree import Count, Tree, name_of, order, places

HERE = Path(__file__).resolve().parents[1]
#: modules allowed to ask which configuration or Newton entry a term has
OWNERS = ("contact/gap_sources/configuration.py", "contact/newton/entry.py", "contact/options.py")
#: the penalty law's own module
LAW = "contact/laws/penalty.py"
#: the current configuration's Python
CURRENT = ("contact/gap_sources/current/finite_deformation.py",
           "contact/gap_sources/current/obstacle.py", "contact/gap_sources/current/mortar.py")
#: keys of the dictionaries the kernels' bindings return
KERNEL_KEYS = ("value", "gradient", "hessian", "nodes", "value_plus", "gradient_plus", "gap",
               "normals", "weights", "pairs", "slave_N", "master_N", "D", "M", "g")
POSITIVE_PART = re.compile(r"np\.maximum\((?!.*(length|count|tiny|x\[))[^,]+,\s*0\.0\)")
PENALTY_FORCE = re.compile(r"\b(penalty|eps) \*(?! ratio)")
PROTOCOL_NAMES = ("GapSource", "GapModel")
GAP_SOURCE_EXPRESSIONS = {"model", "source", "inner", "self.model", "self._model", "self.source",
                          "self._source", "self.inner", "term.model", "self.term.model",
                          "model.inner", "term.source", "self.term.source"}
NOT_GAP_SOURCES = {"io/gmsh_io.py"}
#: the modules that may branch on the active set's variant (pointwise or nodal): the law
#: that holds it, the frozen sources' one choice of their positive gaps (point_gaps_of), and
#: the options' check of their combinations
VARIANT_OWNERS = ("contact/laws/penalty.py", "contact/laws/active_set.py",
                  "contact/gap_sources/pointwise.py", "contact/options.py")
PUBLIC_CLASSES = {"ContactTerm": "contact/term.py",
                  "NonlinearContactProblem": "solver/nonlinear_problem.py",
                  "LoadPathSolver": "solver/load_path.py"}
KIND_OWNERS = ("kinds.py", "bases/", "mortar/")
def existing_counts(tree: Tree) -> dict[str, Count]:
    """The counts of the first refactoring (docs/CONTACT_AXES.md), by the same rules."""
    long = {"modules over 400 lines": [], "classes over 200 lines": [],
            "classes over 250 lines": [], "package modules over 400 lines": []}
    for path in list(tree.paths.values()) + sorted((tree.root / "kernels").rglob("*.[ch]*")):
        n = len(path.read_text().splitlines())
        if n > 400 and path.suffix in (".py", ".h", ".cpp"):
            long["modules over 400 lines"].append(f"{path.relative_to(tree.root).as_posix()} ({n})")
            if path.suffix == ".py":
                long["package modules over 400 lines"].append(
                    f"{path.relative_to(tree.package).as_posix()} ({n})")
    (owners, owners_note), (law, law_note) = tree.owned(OWNERS), tree.owned([LAW])
    current, current_note = tree.owned(CURRENT)
    key_pattern = re.compile(r"\w+\[\"(" + "|".join(KERNEL_KEYS) + r")\"\]")
    # (row, note, which modules the rule reads, what a line counts)
    rules = (("basis_configuration ==/!= outside its owner", owners_note, lambda m: m not in owners,
              lambda s: bool(re.search(r"basis_configuration\s*[!=]=", s))),
             # not the module's own path (contact.newton.augmented, as contact.augmented was)
             (".augmented reads outside its owner", owners_note, lambda m: m not in owners,
              lambda s: bool(re.search(r"(?<!contact)(?<!newton)\.augmented\b", s))),
             ("places the penalty law is written (contact/, outside its module)", law_note,
              lambda m: m.startswith("contact/") and m not in law,
              lambda s: bool(POSITIVE_PART.search(s) or PENALTY_FORCE.search(s))),
             ("einsum lines in the current configuration's Python", current_note,
              lambda m: m in current, lambda s: "einsum" in s),
             ("string-key lookups of kernel results", "", lambda m: True,
              lambda s: len(key_pattern.findall(s))))
    rows = {row: Count(0, note=note) for row, note, _, _ in rules}
    for name, module in tree.ast.items():
        for node in ast.walk(module):
            n = node.end_lineno - node.lineno + 1 if isinstance(node, ast.ClassDef) else 0
            for limit in (200, 250):
                if n > limit:
                    long[f"classes over {limit} lines"].append(f"{name}:{node.name} ({n})")
        lines = [line.split("#", 1)[0] for line in tree.text[name].splitlines()]
        for row, _, reads, counted in rules:
            rows[row].value += sum(map(counted, lines)) if reads(name) else 0
    return {key: Count(len(items), items) for key, items in long.items()} | rows


def protocol(tree: Tree) -> tuple[Optional[str], set[str]]:
    """The gap-source Protocol's name and its declared members, with those of
    the Protocols that extend it (``GlobalGapSource``: what GLS's augmented
    step asks of its source)."""
    found, extensions = None, []
    for rel, module in tree.ast.items():
        for node in ast.walk(module) if rel.startswith("contact/") else ():
            if isinstance(node, ast.ClassDef) and node.name in PROTOCOL_NAMES:
                found = node
            elif isinstance(node, ast.ClassDef):
                extensions.append(node)
    if found is None:
        return None, set()
    declared = class_level_names(found)
    for node in extensions:
        bases = {ast.unparse(b) for b in node.bases}
        if found.name in bases and "Protocol" in bases:
            declared |= class_level_names(node)
    return found.name, declared


def class_level_names(node: ast.ClassDef) -> set[str]:
    """The methods, nested classes and assigned names of a class body."""
    names = set()
    for item in node.body:
        if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(item.name)
        targets = [item.target] if isinstance(item, ast.AnnAssign) else getattr(item, "targets", [])
        names |= {n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)}
    return names


def gap_source_objects(module: ast.Module, protocol_name: Optional[str]) -> set[int]:
    """The ids of the expressions that the rule takes for a gap source."""
    objects = {id(node) for node in ast.walk(module) if isinstance(node, (ast.Name, ast.Attribute))
               and ast.unparse(node) in GAP_SOURCE_EXPRESSIONS}
    for node in ast.walk(module) if protocol_name else ():
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            a = node.args
            typed = {p.arg for p in a.posonlyargs + a.args + a.kwonlyargs if p.annotation
                     and re.search(rf"\b{protocol_name}\b", ast.unparse(p.annotation))}
            objects |= {id(n) for n in ast.walk(node) if isinstance(n, ast.Name) and n.id in typed}
    return objects


def gap_source_counts(tree: Tree) -> dict[str, Count]:
    name, declared = protocol(tree)
    classes = {node.name for rel, module in tree.ast.items() if tree.in_gap_sources(rel)
               for node in ast.walk(module) if isinstance(node, ast.ClassDef)}
    undeclared: dict[str, list[str]] = {}
    asked = []
    for rel, module in tree.ast.items():
        objects = set() if rel in NOT_GAP_SOURCES else gap_source_objects(module, name)
        for node in ast.walk(module):
            read = (node.attr if isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Load)
                    and id(node.value) in objects else None)
            call = name_of(node.func) if isinstance(node, ast.Call) else None
            if call in ("getattr", "hasattr") and node.args and id(node.args[0]) in objects:
                key = node.args[1] if len(node.args) > 1 else None
                read = key.value if isinstance(getattr(key, "value", None), str) else "?"
                asked.append(f"{rel}:{node.lineno} {call}(…, {read!r})")
            if call in ("isinstance", "issubclass") and len(node.args) == 2:
                types = getattr(node.args[1], "elts", [node.args[1]])
                if hits := [ast.unparse(t) for t in types if name_of(t) in classes]:
                    asked.append(f"{rel}:{node.lineno} {call}(…, {', '.join(hits)})")
            if read and not tree.in_gap_sources(rel) and read not in declared \
                    and not read.startswith("__"):
                undeclared.setdefault(read, []).append(f"{rel}:{node.lineno}")
    return {"gap-source members read but not declared (distinct names)": Count(
                len(undeclared) if name else None, places(undeclared),
                "" if name else f"no {' or '.join(PROTOCOL_NAMES)} in contact/"),
            "isinstance/getattr on gap-source types": Count(len(asked), sorted(asked, key=order))}


def variant_branches(tree: Tree) -> dict[str, Count]:
    owners, _ = tree.owned(VARIANT_OWNERS)
    found: dict[str, list[str]] = {}
    for rel, module in tree.ast.items():
        tests = []
        for node in ast.walk(module) if rel not in owners else ():
            if isinstance(node, (ast.If, ast.While, ast.IfExp, ast.Assert)):
                tests.append(node.test)
            tests += getattr(node, "ifs", []) + getattr(node, "values", []) if isinstance(
                node, (ast.comprehension, ast.BoolOp)) else []
            if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
                tests.append(node.operand)
        reads = sorted({(n.lineno, n.col_offset) for t in tests for n in ast.walk(t)
                        if isinstance(n, ast.Attribute) and n.attr == "pointwise"
                        and isinstance(n.ctx, ast.Load)})
        if reads:
            found[rel] = [str(line) for line, _ in reads]
    owner = f"owner {', '.join(sorted(owners))}" if owners else "no owner in this tree"
    return {"branches on .pointwise outside the variant's owner": Count(
        sum(map(len, found.values())), places(found), f"{len(found)} modules; {owner}")}


def public_names(tree: Tree) -> dict[str, Count]:
    out = {}
    for cls, rel in PUBLIC_CLASSES.items():
        where = tree.where(rel)
        node = next((n for n in ast.walk(tree.ast[where]) if isinstance(n, ast.ClassDef)
                     and n.name == cls), None) if where else None
        names = class_level_names(node) | {
            n.attr for n in ast.walk(node) if isinstance(n, ast.Attribute) and isinstance(
                n.ctx, ast.Store) and name_of(n.value) == "self"} if node else set()
        public = sorted(n for n in names if not n.startswith("_"))
        out[f"public names of {cls}"] = Count(len(public), public) if node else Count(
            None, note=f"no {cls} in {rel}")
    return out


def kind_questions(tree: Tree) -> dict[str, Count]:
    kinds = tree.ast.get("kinds.py")
    if kinds is None:
        return {"kind questions outside the kinds' owners": Count(None, note="no kinds.py")}
    predicates = {n.name for n in kinds.body if isinstance(n, ast.FunctionDef)
                  and not n.name.startswith("_")} - {"parse_kind"}
    sets = {t.id for n in kinds.body for t in getattr(n, "targets", [getattr(n, "target", None)])
            if isinstance(t, ast.Name) and t.id.endswith("_KINDS")}
    comparisons = (ast.In, ast.NotIn, ast.Eq, ast.NotEq, ast.Is, ast.IsNot)

    def kind_like(e: ast.AST) -> bool:
        return (name_of(e) or "").endswith("kind") or getattr(e, "id", None) in sets or (
            isinstance(e, ast.Attribute) and name_of(e.value) == "BasisKind")

    found: dict[str, list[str]] = {}
    for rel, module in tree.ast.items():
        asked, seen = [], set()
        owner = any(rel == o or (o.endswith("/") and rel.startswith(o)) for o in KIND_OWNERS)
        for node in ast.walk(module) if not owner else ():
            if isinstance(node, ast.Compare) and all(isinstance(o, comparisons) for o in node.ops) \
                    and any(map(kind_like, [node.left, *node.comparators])):
                asked.append((node.lineno, ast.unparse(node)[:40]))
                seen |= {id(n) for n in ast.walk(node)}
            elif isinstance(node, ast.Call) and name_of(node.func) in predicates \
                    and id(node) not in seen:
                asked.append((node.lineno, f"{name_of(node.func)}()"))
                seen.add(id(node.func))
            elif id(node) not in seen and (getattr(node, "id", None) in sets or (
                    isinstance(node, ast.Attribute) and node.attr in predicates)):
                asked.append((node.lineno, name_of(node)))
        if asked:
            found[rel] = [f"{line} {what}" for line, what in sorted(asked)]
    return {"kind questions outside the kinds' owners": Count(
        sum(map(len, found.values())), places(found), f"{len(found)} modules")}


def counts(root: Path = HERE) -> dict[str, Count]:
    tree = Tree(root)
    out = existing_counts(tree)
    for rule in (gap_source_counts, variant_branches, public_names, import_counts,
                 folder_counts, kind_questions):
        out |= rule(tree)
    return out


def cell(count: Count, limit: int = 4) -> str:
    more = len(count.items) - limit
    items = count.items[:limit] + [f"… {more} more"] * (more > 0)
    return (count.shown() + (": " + "; ".join(items) if items else "")).replace("|", "\\|")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", type=Path, default=HERE, help="the checkout to count (after)")
    parser.add_argument("--compare", type=Path, help="an older checkout (before), counted too")
    parser.add_argument("--markdown", action="store_true", help="a markdown table")
    args = parser.parse_args()
    after = counts(args.root)
    before = counts(args.compare) if args.compare else None
    if args.markdown:
        print("| count | before | after |\n|---|---|---|" if before
              else "| count | value |\n|---|---|")
        for name, count in after.items():
            print(f"| {name} | {cell(before[name]) + ' | ' if before else ''}{cell(count)} |")
        return
    for name, count in after.items():      # the lists: of the tree counted after
        print(f"{name}: {before[name].shown() + ' -> ' if before else ''}{count.shown()}")
        print("".join(f"    {item}\n" for item in count.items), end="")


if __name__ == "__main__":
    main()
