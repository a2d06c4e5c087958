"""Stored notebook outputs: current, from one clean run, small, and really compared by nbval.

The notebooks in ``scripts/store_notebook_outputs.py``'s ``STORED`` list are committed with their
outputs, and ``pytest --nbval`` compares them (``tests/nbval_modes.py``). These tests catch what
nbval alone would not: code edited without re-running the script, outputs from an interactive
session instead of one Run All, oversized figures; and they show that a changed output fails.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import nbformat
import pytest

pytestmark = pytest.mark.backend_free  # no numeric back end changes what it checks (CI runs it once)

REPO = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("store_notebook_outputs", REPO / "scripts" / "store_notebook_outputs.py")
store = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(store)

REGENERATE = "MOTIONLAB_DATA=/path/to/shared/data python scripts/store_notebook_outputs.py {}"
MAX_PNG_KB = 120
MAX_NOTEBOOK_KB = 400


def _read(name: str):
    return nbformat.read(REPO / "notebooks" / f"{name}.ipynb", as_version=4)


@pytest.mark.parametrize("name", store.STORED)
def test_stored_outputs_match_the_code(name):
    nb = _read(name)
    meta = nb.metadata.get("motionlab", {})
    assert meta.get("outputs") == "stored", f"{name}: outputs not stored; run {REGENERATE.format(name)}"
    assert meta.get("code_sha256") == store.code_hash(nb), (
        f"{name}: code cells changed after the outputs were stored; run {REGENERATE.format(name)}"
    )


@pytest.mark.parametrize("name", store.STORED)
def test_stored_outputs_come_from_one_clean_run(name):
    code = [c for c in _read(name).cells if c.cell_type == "code"]
    counts = [c.execution_count for c in code]
    assert counts == list(range(1, len(code) + 1)), f"{name}: execution counts {counts} are not one Run All"
    errors = [o for c in code for o in c.outputs if o.output_type == "error"]
    assert not errors, f"{name}: stored error output {errors[0].get('ename')}"
    stderr = [o.text for c in code for o in c.outputs if o.output_type == "stream" and o.name == "stderr"]
    assert not stderr, f"{name}: warnings in the stored outputs: {stderr[0][:300]}"


@pytest.mark.parametrize("name", store.STORED)
def test_stored_outputs_are_small(name):
    path = REPO / "notebooks" / f"{name}.ipynb"
    assert path.stat().st_size < MAX_NOTEBOOK_KB * 1024, f"{name}: {path.stat().st_size / 1024:.0f} kB"
    for cell in _read(name).cells:
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            assert not {"image/gif", "video/mp4"} & set(data), f"{name}: movies belong in files, not cells"
            if "image/png" in data:
                assert len(data["image/png"]) * 3 / 4 < MAX_PNG_KB * 1024, f"{name}: a PNG over {MAX_PNG_KB} kB"
    assert "widgets" not in _read(name).metadata, f"{name}: widget state stored (large, and never compared)"


def test_notebooks_without_stored_outputs_are_clean():
    """Notebooks not yet in STORED stay without outputs (and run lax)."""
    for path in sorted((REPO / "notebooks").glob("*.ipynb")):
        if path.stem in store.STORED:
            continue
        nb = nbformat.read(path, as_version=4)
        assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), f"{path.name} has outputs"


def _notebook(path: Path, stored_text: str | None, strict: bool) -> None:
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    cell = nbformat.v4.new_code_cell("print(1 + 1)")
    if stored_text is not None:
        cell.execution_count = 1
        cell.outputs = [nbformat.v4.new_output("stream", name="stdout", text=stored_text)]
    nb.cells = [cell]
    if strict:
        nb.metadata["motionlab"] = {"outputs": "stored", "data": False, "code_sha256": store.code_hash(nb)}
    nbformat.write(nb, path)


@pytest.mark.slow
def test_a_changed_output_fails_strict_nbval_and_only_there(tmp_path):
    """One pytest --nbval run over three tiny notebooks: the stale strict one must fail."""
    _notebook(tmp_path / "fresh_strict.ipynb", "2\n", strict=True)
    _notebook(tmp_path / "stale_strict.ipynb", "3\n", strict=True)
    _notebook(tmp_path / "stale_lax.ipynb", "3\n", strict=False)  # not marked stored: lax
    report = tmp_path / "report.xml"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "tests.nbval_modes", "-p", "no:cacheprovider", "--nbval",
         f"--rootdir={tmp_path}", f"--junitxml={report}", "-q", str(tmp_path)],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=240,
    )  # fmt: skip
    outcome = {}
    for case in ET.parse(report).getroot().iter("testcase"):
        failed = case.find("failure") is not None or case.find("error") is not None
        outcome[case.get("classname", "") + case.get("file", "")] = failed
    by_name = {
        n: any(failed for key, failed in outcome.items() if n in key)
        for n in ("fresh_strict", "stale_strict", "stale_lax")
    }
    assert by_name == {"fresh_strict": False, "stale_strict": True, "stale_lax": False}, run.stdout[-3000:]
    assert "Cell outputs differ" in run.stdout


def test_sanitizers_each_have_a_reason():
    lines = (REPO / "tests" / "nbval_sanitize.cfg").read_text().splitlines()
    for i, line in enumerate(lines):
        if line.startswith("regex:"):
            assert i >= 1 and lines[i - 1].startswith("#"), f"sanitizer on line {i + 1} has no reason above it"
