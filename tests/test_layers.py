"""The import layers of CONTRIBUTING.md: ``core`` imports nothing above it (lazy imports included)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import motionlab

pytestmark = pytest.mark.backend_free  # no numeric back end changes what it checks (CI runs it once)

PACKAGE = Path(motionlab.__file__).parent
ABOVE_CORE = ("synthetic", "retargeting", "motion_graphs", "interpolation", "viz", "demo", "cli", "commands", "data")


def _runtime_names(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, module) for imports made by name at run time: where a module calls
    ``importlib.import_module`` or ``__import__``, every ``"motionlab..."`` string it spells counts
    as imported (``cli.py`` imports its parts from a tuple of names)."""
    calls = [
        n for n in ast.walk(tree)
        if isinstance(n, ast.Call) and (
            isinstance(n.func, ast.Attribute) and n.func.attr == "import_module"
            or isinstance(n.func, ast.Name) and n.func.id in ("import_module", "__import__")
        )
    ]  # fmt: skip
    if not calls:
        return []
    return [
        (n.lineno, n.value)
        for n in ast.walk(tree)
        if isinstance(n, ast.Constant) and isinstance(n.value, str) and n.value.startswith("motionlab.")
        and n.value.replace(".", "").replace("_", "").isalnum()
    ]  # fmt: skip


def _imports(text: str, module_path: tuple[str, ...]) -> list[tuple[int, str]]:
    """(line, module) of every import in a module's source, at any depth (inside functions too),
    and of the modules it imports by name at run time (:func:`_runtime_names`).

    ``module_path`` is the module's dotted name as parts (to resolve relative imports).
    """
    tree = ast.parse(text)
    found = _runtime_names(tree)
    for node in ast.walk(tree):
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


SYSTEMS = ("retargeting", "motion_graphs", "interpolation")


def _part(module: str) -> str | None:
    """The top-level part of ``motionlab`` that a dotted module name lies in (``None`` outside)."""
    parts = module.split(".")
    return parts[1] if parts[0] == "motionlab" and len(parts) > 1 else None


def _package_imports() -> dict[str, list[tuple[str, int, str]]]:
    """For each part of the package, ``(file, line, imported module)`` of every import in it."""
    found: dict[str, list[tuple[str, int, str]]] = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        name = path.relative_to(PACKAGE.parent).with_suffix("").parts
        if name[-1] == "__init__":
            name = name[:-1] + ("__init__",)  # relative imports resolve against the package itself
        part = name[1] if len(name) > 2 else None
        for line, module in _imports(path.read_text(), name if name[-1] != "__init__" else name[:-1] + ("x",)):
            found.setdefault(part, []).append((str(path.relative_to(PACKAGE.parent)), line, module))
    return found


def test_the_three_systems_do_not_import_each_other_and_viz_imports_none_of_them():
    bad = []
    for part, imports in _package_imports().items():
        if part not in SYSTEMS + ("viz",):
            continue
        forbidden = set(SYSTEMS) - {part}
        bad += [f"{f}:{line} ({part}) imports {m}" for f, line, m in imports if _part(m) in forbidden]
    assert not bad, "the systems and viz depend on core and synthetic only:\n" + "\n".join(bad)


def _modules() -> dict[str, list[str]]:
    """Every module of the package (dotted name) and the modules it imports (:func:`_imports`)."""
    modules = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parent).with_suffix("").parts
        dotted = ".".join(rel[:-1] if rel[-1] == "__init__" else rel)
        resolve = rel if rel[-1] != "__init__" else rel[:-1] + ("x",)
        modules[dotted] = [m for _, m in _imports(path.read_text(), resolve)]
    return modules


def test_no_import_loop_between_modules():
    """Imports between motionlab's modules, lazy ones inside functions and ones by name through
    importlib included, form no cycle."""
    loops = _loops(_modules())
    assert not loops, "import loops:\n" + "\n".join(loops)


def test_the_loop_rule_sees_an_importlib_circle():
    """``cli.py`` importing its parts by name while a part imports ``motionlab.cli`` back is a loop."""
    top = "import importlib\nPARTS = ('motionlab.part',)\nfor n in PARTS:\n    importlib.import_module(n)\n"
    part = "def f():\n    from motionlab.top import Error\n"
    modules = {
        "motionlab.top": [m for _, m in _imports(top, ("motionlab", "top"))],
        "motionlab.part": [m for _, m in _imports(part, ("motionlab", "part"))],
    }
    assert _loops(modules) == ["motionlab.part -> motionlab.top -> motionlab.part"]


CLI_MODULES = ("motionlab.cli", "motionlab.cli_args", "motionlab.__main__", "motionlab.commands")
CLI_SUFFIXES = (".cli", ".cli_options", ".expand_cli")


def _is_cli(module: str) -> bool:
    return module.startswith(CLI_MODULES) or module.endswith(CLI_SUFFIXES)


def test_library_code_imports_no_command_line_module():
    """The command line sits on the library: no library module imports a CLI module, lazily or not."""
    bad = [
        f"{name} imports {m}"
        for name, imports in _modules().items()
        if not _is_cli(name)
        for m in imports
        if _is_cli(m)
    ]
    assert not bad, "library code must not import the command line:\n" + "\n".join(bad)


def _loops(modules: dict[str, list[str]]) -> list[str]:
    """The import cycles among ``modules`` (dotted name -> imported names)."""
    graph = {
        name: {m for m in imports if m in modules and m != name and not name.startswith(m + ".")}
        for name, imports in modules.items()
    }
    state: dict[str, int] = {}
    loops: list[str] = []

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                loops.append(" -> ".join(stack[stack.index(nxt) :] + [nxt]))
            elif nxt not in state:
                visit(nxt, stack + [nxt])
        state[node] = 2

    for name in sorted(graph):
        if name not in state:
            visit(name, [name])
    return loops


def test_the_package_and_the_notebooks_never_import_the_studies():
    """``experiments/`` imports motionlab like a user; neither motionlab nor a notebook imports it."""
    import json

    bad = []
    for path in sorted(PACKAGE.rglob("*.py")):
        name = path.relative_to(PACKAGE.parent).with_suffix("").parts
        bad += [f"{path.relative_to(PACKAGE.parent)}:{line} imports {m}"
                for line, m in _imports(path.read_text(), name) if m.split(".")[0] == "experiments"]  # fmt: skip
    for path in sorted((PACKAGE.parent / "notebooks").glob("*.ipynb")):
        cells = json.loads(path.read_text())["cells"]
        source = "\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "code")
        source = "\n".join(line for line in source.splitlines() if not line.lstrip().startswith(("%", "!")))
        bad += [
            f"{path.name}: imports {m}" for _, m in _imports(source, ("notebook",)) if m.split(".")[0] == "experiments"
        ]
    assert not bad, "the studies in experiments/ are not part of the package:\n" + "\n".join(bad)
