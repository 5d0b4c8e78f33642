"""tools/architecture_counts.py counts what its rules say, on small made-up packages.

Each rule meets a case it must count and a near case it must not (a stored ``.pointwise``, a
declared member, a kind question in its owner, a subpackage imported through its ``__init__``),
in the layout by concept and in the flat ``contact/`` the tool maps to it. No DOLFINx: the tool
reads the source with ``ast``.
"""
from __future__ import annotations

import importlib.util
import sys
import textwrap
from pathlib import Path

import pytest

TOOL = Path(__file__).resolve().parents[2] / "tools" / "architecture_counts.py"


@pytest.fixture(scope="module")
def tool():
    # the tool's modules import each other as a script's siblings
    sys.path.insert(0, str(TOOL.parent))
    spec = importlib.util.spec_from_file_location("architecture_counts", TOOL)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module        # dataclasses look their module up by name
    spec.loader.exec_module(module)
    yield module
    del sys.modules[spec.name]
    sys.path.remove(str(TOOL.parent))


def write(root: Path, files: dict[str, str]) -> Path:
    for rel, text in files.items():
        path = root / "dolfinx_mortar" / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))
    return root


KINDS = """
    DUAL_KINDS = (1, 2)
    def parse_kind(kind): return kind
    def is_global(kind): return kind == 0
"""
SOURCE = """
    from typing import Protocol
    class {name}(Protocol):
        moving_pattern: bool
        def evaluate(self, u): ...
"""
USER = """
    from dolfinx_mortar.contact.{frozen} import ObstacleGap
    from dolfinx_mortar.kinds import DUAL_KINDS, is_global
    def use(model, other: "{name}", law, kind):
        model.evaluate(1)                     # declared
        model.moving_pattern                  # declared
        coupling = model.coupling             # not declared
        other.weights                         # not declared, through the annotation
        if isinstance(model, ObstacleGap):    # a gap-source type
            getattr(model, "inner", None)     # a type question, and inner not declared
        if law.pointwise:                     # a branch
            pass
        x = 1 if law.pointwise else 2         # a branch
        keep = law.pointwise                  # stored, not a branch
        both = law.pointwise and keep         # a branch: an operand of and
        flip = not law.pointwise              # a branch: an operand of not
        if is_global(kind) or 2 in DUAL_KINDS:   # two kind questions
            pass
"""


def new_layout(root: Path) -> Path:
    return write(root, {
        "__init__.py": "",
        "kinds.py": KINDS,
        "bases/__init__.py": "",
        "bases/basis.py": "from dolfinx_mortar.kinds import is_global\nx = is_global(0)\n",
        "contact/__init__.py": "",
        "contact/gap_sources/__init__.py":
            "from dolfinx_mortar.contact.gap_sources.source import GapSource\n",
        "contact/gap_sources/source.py": SOURCE.format(name="GapSource"),
        "contact/gap_sources/frozen.py": "class ObstacleGap:\n    pass\n",
        "contact/laws/__init__.py": "",
        "contact/laws/penalty.py": "def f(self):\n    return 1 if self.pointwise else 0\n",
        "contact/user.py": textwrap.dedent(USER.format(frozen="gap_sources.frozen",
                                                       name="GapSource"))
        + "from dolfinx_mortar.contact.gap_sources import GapSource\n",   # through __init__
        # the module path contact.newton.augmented is not a read of .augmented
        "contact/mentions.py": '"""See :mod:`~dolfinx_mortar.contact.newton.augmented`."""\n'
                               "def f(term):\n    return term.augmented\n",
        "contact/term.py": """
            class ContactTerm:
                options = None
                def __init__(self):
                    self.u, self._hidden = 1, 2
                @property
                def state(self): return self._hidden
                def _private(self): self.model = None
        """,
        # a module-level cycle (relative import), a type-hint one, a function-local one
        "a.py": "import dolfinx_mortar.b\n",
        "b.py": "from . import a\n",
        "c.py": "from typing import TYPE_CHECKING\n"
                "if TYPE_CHECKING:\n    from dolfinx_mortar.d import D\n",
        "d.py": "from dolfinx_mortar.c import TYPE_CHECKING\n",
        "e.py": "def f():\n    from dolfinx_mortar.g import y\n",
        "g.py": "from dolfinx_mortar import e\ny = 1\n",
        # a folder of 11 modules, one of them with a 260-line class in 1,600 lines
        **{f"big/m{i}.py": "" for i in range(10)},
        "big/__init__.py": "class Long:\n" + "    x = 1\n" * 259 + "\n" * 1340,
    })


def test_the_rules_in_the_layout_by_concept(tool, tmp_path):
    counts = tool.counts(new_layout(tmp_path))
    undeclared = counts["gap-source members read but not declared (distinct names)"]
    assert undeclared.value == 3
    assert [item.split()[0] for item in undeclared.items] == ["coupling", "inner", "weights"]
    types = counts["isinstance/getattr on gap-source types"]
    assert [item.split(" ", 1)[1] for item in types.items] == [
        "isinstance(…, ObstacleGap)", "getattr(…, 'inner')"]
    branches = counts["branches on .pointwise outside the variant's owner"]
    assert branches.value == 4 and branches.items == ["contact/user.py (11, 13, 15, 16)"]
    assert "owner contact/laws/penalty.py" in branches.note
    assert counts["public names of ContactTerm"].items == ["model", "options", "state", "u"]
    assert counts["public names of LoadPathSolver"].value is None
    cycles = [counts[f"import cycles, {label}"].items for label in (
        "module-level imports", "with type-hint imports",
        "with type-hint and function-local imports")]
    assert cycles[0] == ["2 modules: a → b → a"]
    assert cycles[1] == cycles[0] + ["2 modules: c → [type-hint] d → c"]
    assert cycles[2] == cycles[1][:1] + ["2 modules: c → [type-hint] d → c",
                                          "2 modules: e → [function-local] g → e"]
    assert counts["imports past a contact subpackage's __init__"].items == [
        "contact/user.py:2 contact.gap_sources.frozen"]
    assert counts["folders over 1,500 lines or 10 modules"].items == [
        "dolfinx_mortar/big/ (1600 lines, 11 modules)"]
    assert counts["classes over 250 lines"].items == ["big/__init__.py:Long (260)"]
    assert counts["package modules over 400 lines"].value == 1
    assert counts[".augmented reads outside its owner"].value == 1
    kinds = counts["kind questions outside the kinds' owners"]
    assert kinds.items == ["contact/user.py (17 is_global(), 17 2 in DUAL_KINDS)"]


def test_the_flat_layout_is_read_through_the_old_names(tool, tmp_path):
    root = write(tmp_path, {
        "__init__.py": "", "contact/__init__.py": "",
        "contact/state.py": SOURCE.format(name="GapModel"),
        "contact/gaps.py": "class ObstacleGap:\n"
                           "    def f(self, model):\n        return model.slave\n",
        "contact/penalty_law.py": "def f(self):\n    return 1 if self.pointwise else 0\n",
        "contact/user.py": USER.format(frozen="gaps", name="GapModel"),
    })
    counts = tool.counts(root)
    # gaps.py is a gap source: its model.slave is not a read from outside
    undeclared = counts["gap-source members read but not declared (distinct names)"]
    assert [item.split()[0] for item in undeclared.items] == ["coupling", "inner", "weights"]
    assert counts["isinstance/getattr on gap-source types"].value == 2
    branches = counts["branches on .pointwise outside the variant's owner"]
    assert branches.items == ["contact/user.py (11, 13, 15, 16)"]
    assert "owner contact/penalty_law.py" in branches.note
    assert counts["imports past a contact subpackage's __init__"].value is None
    assert "contact/newton/entry.py" in counts[".augmented reads outside its owner"].note
    assert counts["kind questions outside the kinds' owners"].value is None


def test_compare_prints_both_trees(tool, tmp_path, monkeypatch, capsys):
    after = new_layout(tmp_path / "after")
    before = write(tmp_path / "before", {"__init__.py": "", "contact/__init__.py": "",
                                         **{f"contact/m{i}.py": "" for i in range(11)}})
    monkeypatch.setattr(sys, "argv", ["architecture_counts.py", "--root", str(after),
                                      "--compare", str(before), "--markdown"])
    tool.main()
    table = capsys.readouterr().out.splitlines()
    assert table[0] == "| count | before | after |"
    assert "| folders over 1,500 lines or 10 modules | 1: dolfinx_mortar/contact/ (0 lines, " \
           "12 modules) | 1: dolfinx_mortar/big/ (1600 lines, 11 modules) |" in table
