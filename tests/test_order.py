"""tests/order.py: the tests that need the real-motion network come last, all else in its order."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from tests import order


def _item(name: str, path: str, marked: bool = False):
    marker = object() if marked else None
    return SimpleNamespace(
        name=name, path=Path(path), get_closest_marker=lambda m: marker if m == "real_network" else None
    )


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


def test_every_notebook_named_there_exists():
    root = Path(__file__).resolve().parents[1] / "notebooks"
    assert all((root / name).is_file() for name in order.NOTEBOOKS)
