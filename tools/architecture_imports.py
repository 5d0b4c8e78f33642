"""The import graph and the folder sizes of the package (tools/architecture_counts.py):
cycles among its modules by kind of import, imports past a contact subpackage's face, and
folders over the size limits."""
from __future__ import annotations

import ast
import re

from architecture_tree import Count, Tree, module_name, short

EXTENSIONS = {"dolfinx_mortar._kernels"}
IMPORT_KINDS = ("module-level", "type-hint", "function-local")
#: a folder of the package over these many lines or modules needs subfolders
FOLDER_LINES, FOLDER_MODULES = 1500, 10


def imports(tree: Tree) -> list[tuple[str, str, int, int]]:
    """(importer, imported module, kind: index in IMPORT_KINDS, line) of each package import."""
    known = set(tree.modules) | EXTENSIONS
    out = set()
    for rel, module in tree.ast.items():
        name = module_name(rel)
        package = name if rel.endswith("__init__.py") else name.rpartition(".")[0]

        def visit(node: ast.AST, kind: int) -> None:
            if isinstance(node, ast.Import):
                for alias in node.names:
                    parts = alias.name.split(".")
                    out.update((name, m, kind, node.lineno) for m in next((
                        [".".join(parts[:n])] for n in range(len(parts), 0, -1)
                        if ".".join(parts[:n]) in known), []))
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = package.split(".")[:len(package.split(".")) - node.level + 1]
                    base = ".".join(parts + [node.module] * bool(node.module))
                for alias in node.names:
                    target = f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base
                    out.update([(name, target, kind, node.lineno)] if target in known else [])
            elif isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
                for child in node.body:
                    visit(child, max(kind, 1))
                for child in node.orelse:
                    visit(child, kind)
            else:
                function = isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
                for child in ast.iter_child_nodes(node):
                    visit(child, 2 if function else kind)
        visit(module, 0)
    return sorted(edge for edge in out if edge[1] in tree.modules and edge[1] != edge[0])


def components(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module: each module with those that
    reach it among those it reaches (a search from each module; the package has ~100)."""
    reach = {}
    for v in graph:
        seen, todo = set(), [v]
        while todo:
            todo.extend(graph.get(w := todo.pop(), set()) - seen)
            seen.add(w)
        reach[v] = seen
    parts = {frozenset(w for w in reach[v] if v in reach.get(w, ())) | {v} for v in graph}
    return sorted(sorted(part) for part in parts if len(part) > 1)


def shortest_cycle(part: list[str], graph: dict[str, set[str]]) -> list[str]:
    """A shortest cycle through the component's first module (a breadth-first search)."""
    start, before = part[0], {part[0]: ""}
    queue = [start]
    for v in queue:
        for w in sorted(graph[v] & set(part)):
            if w == start:
                path = [v]
                while path[-1] != start:
                    path.append(before[path[-1]])
                return path[::-1] + [start]
            if w not in before:
                before[w] = v
                queue.append(w)
    return part


def import_counts(tree: Tree) -> dict[str, Count]:
    edges = imports(tree)
    kind_of: dict[tuple[str, str], int] = {}
    for a, b, kind, _ in edges:
        kind_of[(a, b)] = min(kind, kind_of.get((a, b), kind))
    out = {}
    for level, label in enumerate(("module-level imports", "with type-hint imports",
                                   "with type-hint and function-local imports")):
        graph: dict[str, set[str]] = {}
        for (a, b), kind in kind_of.items():
            if kind <= level:
                graph.setdefault(a, set()).add(b)
        items = []
        for part in components(graph):
            path = shortest_cycle(part, graph)
            marks = [" → " + (f"[{IMPORT_KINDS[kind_of[a, b]]}] " if kind_of[a, b] else "")
                     + short(b) for a, b in zip(path, path[1:])]
            rest = [short(m) for m in part if m not in path]
            items.append(f"{len(part)} modules: {short(path[0])}{''.join(marks)}"
                         + (f" (and {', '.join(rest)})" if rest else ""))
        out[f"import cycles, {label}"] = Count(len(items), items)
    subpackages = {rel.split("/")[1] for rel in tree.paths
                   if re.fullmatch(r"contact/\w+/__init__\.py", rel)}
    deep = sorted({f"{tree.modules[a]}:{line} {short(b)}" for a, b, _, line in edges
                   for sub in subpackages if b.startswith(f"dolfinx_mortar.contact.{sub}.")
                   and not a.startswith(f"dolfinx_mortar.contact.{sub}")})
    out["imports past a contact subpackage's __init__"] = Count(
        len(deep) if subpackages else None, deep,
        "" if subpackages else "no subpackages of contact/")
    return out


def folder_counts(tree: Tree) -> dict[str, Count]:
    sizes: dict[str, list[int]] = {}
    for rel, text in tree.text.items():
        folder = f"dolfinx_mortar/{rel.rpartition('/')[0]}/".replace("//", "/")
        size = sizes.setdefault(folder, [0, 0])
        size[0] += len(text.splitlines())
        size[1] += 1
    flagged = [f"{folder} ({lines} lines, {n} modules)" for folder, (lines, n)
               in sorted(sizes.items()) if lines > FOLDER_LINES or n > FOLDER_MODULES]
    return {f"folders over {FOLDER_LINES:,} lines or {FOLDER_MODULES} modules":
            Count(len(flagged), flagged)}
