"""Docstrings are contracts: a public function that raises says so, and no docstring cites a
page of results (results move; ``README, Table 1`` went to ``docs/results_retargeting.md``).

Read from the source (``ast``), so the check needs no import of torch or pyvista.
"""

from __future__ import annotations

import ast
import functools
import re
from pathlib import Path

import pytest

pytestmark = pytest.mark.backend_free  # no numeric back end changes what it checks (CI runs it once)

PACKAGE = Path(__file__).resolve().parents[1] / "motionlab"

RAISES = re.compile(r"\b[Rr]aises\b")
"""A "Raises" section (numpydoc) or a sentence such as "raises ValueError when ..."."""

CITES_RESULTS = re.compile(r"\bREADME\b(?!\.md)")
"""A citation of the README for results ("README, Table 1", "the README's Table 1"): results
belong to the docs pages, under the command that prints them, and a docstring states the
contract instead. A path to a README file (``$MOTIONLAB_DATA/README.md``) and a paper's table
("Table 1 of paper A") are not flagged."""


@functools.cache
def _modules() -> tuple[tuple[Path, ast.Module], ...]:
    """Every module of the package and its syntax tree (read once per session)."""
    return tuple((path, ast.parse(path.read_text(encoding="utf-8"))) for path in sorted(PACKAGE.rglob("*.py")))


def _raises_directly(fn: ast.AST) -> bool:
    """True when ``fn``'s own body (not a nested function or class) has ``raise X``."""
    stack = list(ast.iter_child_nodes(fn))
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)):
            continue
        if isinstance(node, ast.Raise) and node.exc is not None:
            return True
        stack.extend(ast.iter_child_nodes(node))
    return False


def _public_functions(body, prefix: str = ""):
    """``(qualified name, node)`` of the public functions and public classes' methods
    (``__init__`` included: its errors are the class's)."""
    for node in body:
        if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            yield from _public_functions(node.body, f"{prefix}{node.name}.")
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and (
            not node.name.startswith("_") or node.name == "__init__"
        ):
            yield prefix + node.name, node


def _undocumented_raises() -> list[tuple[str, str, int]]:
    out = []
    for path, tree in _modules():
        for name, fn in _public_functions(tree.body):
            doc = ast.get_docstring(fn) or ""
            if _raises_directly(fn) and not RAISES.search(doc):
                out.append((str(path.relative_to(PACKAGE)), name, fn.lineno))
    return out


def _citations() -> list[tuple[str, str, int]]:
    out = []
    for path, tree in _modules():
        for node in ast.walk(tree):
            documented = isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
            if documented and CITES_RESULTS.search(ast.get_docstring(node) or ""):
                name = getattr(node, "name", "<module>")
                out.append((str(path.relative_to(PACKAGE)), name, getattr(node, "lineno", 1)))
    return out


def test_every_public_function_that_raises_says_so():
    missing = [m for m in _undocumented_raises()]
    assert not missing, "public functions that raise without a 'Raises' in their docstring:\n" + "\n".join(
        f"  motionlab/{f}:{line} {name}" for f, name, line in missing
    )


def test_no_docstring_cites_a_results_page():
    found = [c for c in _citations()]
    assert not found, "docstrings citing the README for results:\n" + "\n".join(
        f"  motionlab/{f}:{line} {name}" for f, name, line in found
    )


def test_the_checks_can_fail():
    """The checks see a function that raises without saying so, and a citation."""
    tree = ast.parse(
        'def f(x):\n    """Half of x."""\n    if x < 0:\n        raise ValueError(x)\n    return x / 2\n'
        'def g():\n    """Measured in the README, Table 1."""\n'
    )
    (name, fn), (_, g) = list(_public_functions(tree.body))
    assert name == "f" and _raises_directly(fn) and not RAISES.search(ast.get_docstring(fn))
    assert not _raises_directly(g) and CITES_RESULTS.search(ast.get_docstring(g))
