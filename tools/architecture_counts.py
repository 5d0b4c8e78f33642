"""Counts that say how the contact package is laid out (docs/DESIGN.md, §Architecture).

    /usr/bin/python3 tools/architecture_counts.py [--markdown]

Each count is of the source as it is, by a rule written here, so that a refactoring can be
judged by the same rule before and after:

- modules over 400 lines (Python and C++) and Python classes over 200 lines;
- reads of ``basis_configuration ==``/``!=`` and of ``.augmented`` outside the modules that
  own those choices (the configuration and the Newton entry);
- places that write the penalty law: a positive part ``np.maximum(·, 0.0)`` of a gap, or the
  penalty multiplied into a force, in ``contact/`` outside the law's own module;
- lines with ``einsum`` in the current configuration's Python (derivatives written by hand);
- string-key lookups of what the C++ kernels return (``r["gradient"]``, ``pts["gap"]`` …).
"""
from __future__ import annotations

import argparse
import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "dolfinx_mortar"
KERNELS = ROOT / "kernels"
#: modules allowed to ask which configuration or Newton entry a term has
OWNERS = {"contact/gap_sources/configuration.py", "contact/newton/entry.py", "contact/options.py"}
#: the penalty law's own module
LAW = "contact/laws/penalty.py"
#: the current configuration's Python
CURRENT = ("contact/gap_sources/current/finite_deformation.py", "contact/gap_sources/current/obstacle.py",
           "contact/gap_sources/current/mortar.py")
#: keys of the dictionaries the kernels' bindings return
KERNEL_KEYS = ("value", "gradient", "hessian", "nodes", "value_plus", "gradient_plus", "gap",
               "normals", "weights", "pairs", "slave_N", "master_N", "D", "M", "g")
POSITIVE_PART = re.compile(r"np\.maximum\((?!.*(length|count|tiny|x\[))[^,]+,\s*0\.0\)")
PENALTY_FORCE = re.compile(r"\b(penalty|eps) \*(?! ratio)")


def python_files() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts)


def relative(path: Path) -> str:
    return path.relative_to(PACKAGE).as_posix()


def code_lines(path: Path) -> list[str]:
    """The lines of a Python file without comments and docstring-only lines."""
    out = []
    for line in path.read_text().splitlines():
        stripped = line.split("#", 1)[0]
        out.append(stripped)
    return out


def counts() -> dict[str, object]:
    long_modules = []
    for path in python_files() + sorted(KERNELS.rglob("*.[ch]*")):
        n = len(path.read_text().splitlines())
        if n > 400 and path.suffix in (".py", ".h", ".cpp"):
            long_modules.append(f"{path.relative_to(ROOT).as_posix()} ({n})")
    long_classes = []
    configuration_reads = augmented_reads = law_places = einsum_lines = key_lookups = 0
    key_pattern = re.compile(r"\w+\[\"(" + "|".join(KERNEL_KEYS) + r")\"\]")
    for path in python_files():
        name = relative(path)
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef) and node.end_lineno - node.lineno + 1 > 200:
                long_classes.append(f"{name}:{node.name} ({node.end_lineno - node.lineno + 1})")
        lines = code_lines(path)
        if name not in OWNERS:
            configuration_reads += sum(bool(re.search(r"basis_configuration\s*[!=]=", s))
                                       for s in lines)
            augmented_reads += sum(bool(re.search(r"(?<!contact)\.augmented\b", s)) for s in lines)
        if name.startswith("contact/") and name != LAW:
            law_places += sum(bool(POSITIVE_PART.search(s) or PENALTY_FORCE.search(s))
                              for s in lines)
        if name in CURRENT:
            einsum_lines += sum("einsum" in s for s in lines)
        key_lookups += sum(len(key_pattern.findall(s)) for s in lines)
    return {"modules over 400 lines": long_modules,
            "classes over 200 lines": long_classes,
            "basis_configuration ==/!= outside its owner": configuration_reads,
            ".augmented reads outside its owner": augmented_reads,
            "places the penalty law is written (contact/, outside its module)": law_places,
            "einsum lines in the current configuration's Python": einsum_lines,
            "string-key lookups of kernel results": key_lookups}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--markdown", action="store_true", help="a table row per count")
    args = parser.parse_args()
    for name, value in counts().items():
        shown = (f"{len(value)}: " + ", ".join(value)) if isinstance(value, list) else value
        print(f"| {name} | {shown} |" if args.markdown else f"{name}: {shown}")


if __name__ == "__main__":
    main()
