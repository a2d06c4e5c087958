"""The studies use motionlab as any user would (style.md §9): no file in ``experiments/`` or
``benchmarks/`` imports, reads, assigns or monkeypatches a ``_private`` name of motionlab.

A name counts as motionlab's when a file binds it by importing from motionlab (``import
motionlab.x as y``, ``from motionlab.x import y``); ``y._name`` is then private use, as are
``from motionlab.x import _name``, ``setattr(y, "_name", ...)`` (``monkeypatch.setattr`` too) and a
dotted target ``"motionlab.x._name"``. Dunder names (``__file__``) are public.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CHECKED = ("experiments", "benchmarks")
DOTTED = re.compile(r"^motionlab(\.\w+)*\._(?!_)\w*")
ATTR_CALLS = ("setattr", "getattr", "delattr", "hasattr")


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _motionlab_names(tree: ast.AST) -> tuple[set[str], list[tuple[int, str]]]:
    """Names the module binds to motionlab objects, and ``(line, text)`` of private imports."""
    names, bad = set(), []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "motionlab":
                    names.add(a.asname or "motionlab")
                    if any(_private(p) for p in a.name.split(".")):
                        bad.append((node.lineno, f"import {a.name}"))
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").split(".")[0] == "motionlab":
            for a in node.names:
                names.add(a.asname or a.name)
                if _private(a.name) or any(_private(p) for p in node.module.split(".")):
                    bad.append((node.lineno, f"from {node.module} import {a.name}"))
    return names, bad


def _root_name(node: ast.AST) -> str | None:
    """``a`` of an attribute chain ``a.b.c``."""
    while isinstance(node, ast.Attribute):
        node = node.value
    return node.id if isinstance(node, ast.Name) else None


def violations(source: str) -> list[tuple[int, str]]:
    """``(line, what)`` of every use of a motionlab private name in a module's source."""
    tree = ast.parse(source)
    names, bad = _motionlab_names(tree)
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _private(node.attr) and _root_name(node.value) in names:
            bad.append((node.lineno, f"{ast.unparse(node)} ({type(node.ctx).__name__.lower()})"))
        elif isinstance(node, ast.Call) and _by_name(node, names):
            bad.append((node.lineno, ast.unparse(node)))
    return sorted(set(bad))


def _string(node: ast.AST) -> str:
    return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else ""


def _by_name(call: ast.Call, names: set[str]) -> bool:
    """Whether a ``setattr``-like call names a motionlab private attribute: ``(module, "_name")``
    with ``module`` one of ``names``, or a dotted ``"motionlab.x._name"``."""
    func = call.func.attr if isinstance(call.func, ast.Attribute) else getattr(call.func, "id", "")
    args = call.args
    if func not in ATTR_CALLS or not args:
        return False
    on_module = len(args) >= 2 and _root_name(args[0]) in names and _private(_string(args[1]))
    return on_module or bool(DOTTED.match(_string(args[0])))


def test_no_study_or_benchmark_uses_a_motionlab_private_name():
    found = []
    for folder in CHECKED:
        for path in sorted((ROOT / folder).rglob("*.py")):
            found += [f"{path.relative_to(ROOT)}:{line}: {what}" for line, what in violations(path.read_text())]
    assert not found, "motionlab's private names used outside the package (pass a parameter instead):\n" + "\n".join(
        found
    )


def test_the_rule_catches_reads_writes_imports_and_monkeypatches():
    source = (
        "import motionlab.interpolation.detect as det\n"
        "from motionlab.interpolation import detect, gaps\n"
        "from motionlab.interpolation.stride import _sample\n"
        "import motionlab\n"
        "BODY = detect._track_features\n"
        "gaps._feet_on_floor = gaps.lift_above_floor\n"
        "det._track_features, det.TRACK_CONTEXT = f, 0.0\n"
        "x = motionlab.interpolation.detect._body_pose(m)\n"
        "def t(monkeypatch):\n"
        "    monkeypatch.setattr(gaps, '_feet_on_floor', gaps.lift_above_floor)\n"
        "    monkeypatch.setattr('motionlab.interpolation.gaps._feet_on_floor', None)\n"
    )
    assert [line for line, _ in violations(source)] == [3, 5, 6, 7, 8, 10, 11]


def test_the_rule_leaves_public_use_and_other_modules_alone():
    source = (
        "import motionlab\n"
        "from motionlab.interpolation import detect, gaps\n"
        "import bench_reproducibility as b\n"
        "print(motionlab.__version__, detect.TRACK_CONTEXT, gaps.fill)\n"
        "b._run_pairs(2)\n"
        "class C:\n"
        "    def f(self):\n"
        "        return self._cache\n"
        "detect.track(m, g, features=detect.track_features, context=0.0)\n"
    )
    assert violations(source) == []
