"""Functions fit on a screen (style guide §9, issue 31): none in ``motionlab/`` is over 80 lines.

A function's length runs from its first decorator (or ``def``) to its last line, docstring
included. A function that would read worse split carries ``# long-function: <reason>`` on its
``def`` line. ``ALLOWED`` lists the functions still being split on other branches; shrink it
as they land.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import motionlab

pytestmark = pytest.mark.backend_free  # no numeric back end changes what it checks (CI runs it once)

PACKAGE = Path(motionlab.__file__).parent
LIMIT = 80
MARK = "# long-function:"

ALLOWED: set[str] = set()


def long_functions(source: str, limit: int = LIMIT) -> list[tuple[str, int, int]]:
    """``(name, first line, length)`` of every function in ``source`` longer than ``limit`` lines
    whose ``def`` line does not carry :data:`MARK` with a reason."""
    lines = source.splitlines()
    found = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        first = min([node.lineno] + [d.lineno for d in node.decorator_list])
        length = node.end_lineno - first + 1
        reason = lines[node.lineno - 1].partition(MARK)[2].strip()
        if length > limit and not reason:
            found.append((node.name, first, length))
    return found


def test_no_function_is_over_80_lines():
    too_long = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        for name, line, length in long_functions(path.read_text(encoding="utf-8")):
            if f"{rel}::{name}" not in ALLOWED:
                too_long.append(f"motionlab/{rel}:{line} {name}: {length} lines")
    assert not too_long, f"functions over {LIMIT} lines (split into named stages, see §9):\n" + "\n".join(too_long)


def test_the_allow_list_names_only_long_functions():
    """An entry whose function was split (or renamed) must leave the list."""
    stale = []
    for entry in sorted(ALLOWED):
        rel, name = entry.split("::")
        path = PACKAGE / rel
        names = [n for n, _, _ in long_functions(path.read_text(encoding="utf-8"))] if path.exists() else []
        if name not in names:
            stale.append(entry)
    assert not stale, "no longer over the limit; remove from ALLOWED: " + ", ".join(stale)


def test_the_rule_counts_decorators_and_docstrings_and_honours_a_reason():
    body = "\n".join(f"    x{i} = {i}" for i in range(78))
    short = f'def f():\n    """Doc."""\n{body}\n'  # 80 lines
    assert long_functions(short) == []
    decorated = "@staticmethod\n" + short  # 81 lines
    assert long_functions(decorated) == [("f", 1, 81)]
    reason = short.replace("def f():", "def f():  # long-function: one vectorised kernel", 1) + "    y = 1\n"
    assert long_functions(reason) == []
    nested = "class A:\n    def g(self):\n" + "\n".join(f"        y{i} = {i}" for i in range(81)) + "\n"
    assert long_functions(nested) == [("g", 2, 82)]
