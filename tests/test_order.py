"""tests/order.py: the tests that need the real-motion network come last, all else in its order."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from tests import order

pytestmark = pytest.mark.backend_free  # no numeric back end changes what it checks (CI runs it once)

ROOT = Path(__file__).resolve().parents[1]


def _item(name: str, path: str, marked: bool = False):
    item = SimpleNamespace(name=name, path=Path(path), markers=["real_network"] if marked else [])
    item.get_closest_marker = lambda m: object() if m in item.markers else None
    item.add_marker = lambda mark: item.markers.append(mark.name)
    return item


def test_the_real_network_tests_and_notebooks_go_last_in_their_order():
    items = [
        _item("a", "tests/core/test_bvh.py"),
        _item("b", "tests/retargeting/test_real.py", marked=True),
        _item("c", "tests/retargeting/test_real.py"),
        _item("cell 0", "notebooks/03_latent_iteration.ipynb"),
        _item("cell 1", "notebooks/03_latent_iteration.ipynb"),
        _item("d", "notebooks/05_motion_graphs.ipynb"),
        _item("e", "tests/retargeting/test_cli_rigs.py", marked=True),
    ]
    order.pytest_collection_modifyitems(items)
    assert [i.name for i in items] == ["a", "c", "d", "b", "cell 0", "cell 1", "e"]
    assert [i.name for i in items if "real_network" in i.markers] == ["b", "cell 0", "cell 1", "e"]


def test_not_real_network_leaves_out_every_cell_of_the_notebooks_named_there():
    """``-m "not real_network"`` (what CI runs while the network trains) leaves out the cells of
    the notebooks that need the network and keeps the others' (the hook marks them first)."""
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", "-m", "not real_network",
         "--nbval", f"notebooks/{order.NOTEBOOKS[0]}", "notebooks/01_preprocessing.ipynb"],
        cwd=ROOT, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert run.returncode == 0, run.stdout + run.stderr
    kept = [line for line in run.stdout.splitlines() if "::" in line]
    assert kept and all(t.startswith("notebooks/01_preprocessing.ipynb::") for t in kept), kept


def test_every_notebook_named_there_exists():
    root = Path(__file__).resolve().parents[1] / "notebooks"
    assert all((root / name).is_file() for name in order.NOTEBOOKS)
