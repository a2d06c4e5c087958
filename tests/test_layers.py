"""The import layers of CONTRIBUTING.md: ``core`` imports nothing above it (lazy imports included)."""

from __future__ import annotations

import ast
from pathlib import Path

import motionlab

PACKAGE = Path(motionlab.__file__).parent
ABOVE_CORE = ("synthetic", "retargeting", "motion_graphs", "interpolation", "viz", "demo", "cli", "commands", "data")


def _imports(text: str, module_path: tuple[str, ...]) -> list[tuple[int, str]]:
    """(line, module) of every import in a module's source, at any depth (inside functions too).

    ``module_path`` is the module's dotted name as parts (to resolve relative imports).
    """
    found = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = module_path[: -node.level] if node.level else ()
            module = ".".join(base + ((node.module,) if node.module else ()))
            found.append((node.lineno, module))
            found += [(node.lineno, f"{module}.{a.name}") for a in node.names]  # `from motionlab import demo`
    return found


def _above_core(module: str) -> bool:
    parts = module.split(".")
    return parts[0] == "motionlab" and len(parts) > 1 and parts[1] in ABOVE_CORE


def test_core_imports_nothing_above_it():
    bad = []
    for path in sorted((PACKAGE / "core").rglob("*.py")):
        name = path.relative_to(PACKAGE.parent).with_suffix("").parts
        for line, module in _imports(path.read_text(), name):
            if _above_core(module):
                bad.append(f"{path.relative_to(PACKAGE.parent)}:{line} imports {module}")
    assert not bad, "core must not import from the layers above it:\n" + "\n".join(bad)


def test_the_rule_catches_what_core_cli_used_to_do():
    source = "def f():\n    from motionlab import synthetic\n    from motionlab.demo import run_demo\n    from .. import viz\n"
    found = [m for _, m in _imports(source, ("motionlab", "core", "cli")) if _above_core(m)]
    assert found == ["motionlab.synthetic", "motionlab.demo", "motionlab.demo.run_demo", "motionlab.viz"]
    fine = "from motionlab.core import quat\nimport numpy as np\nfrom . import bvh\n"
    assert not [m for _, m in _imports(fine, ("motionlab", "core", "fk")) if _above_core(m)]


def test_every_command_is_still_registered():
    from motionlab.cli import build_parser

    commands = build_parser()._subparsers._group_actions[0].choices
    for name in ("info", "convert", "synth", "demo", "retarget", "view"):
        assert name in commands
