"""pytest plugin: strict nbval for notebooks stored with outputs, lax for the others.

Loaded by the repository's ``conftest.py``. With ``pytest --nbval`` every notebook is collected by
nbval; this plugin then picks the mode per notebook:

* a notebook whose metadata says ``"motionlab": {"outputs": "stored"}`` (written by
  ``scripts/store_notebook_outputs.py``) is compared output by output (strict), with the
  sanitizers of ``tests/nbval_sanitize.cfg`` applied to both sides;
* any other notebook (committed without outputs) only has to run without errors (lax), as with
  ``--nbval-lax``;
* a stored notebook made with the course data (``"data": true``) runs lax, with a warning, when
  ``MOTIONLAB_DATA`` is not set: its outputs show real clips that cannot be reproduced without it.

``--nbval-lax`` keeps every notebook lax.
"""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path

import pytest

SANITIZE = Path(__file__).with_name("nbval_sanitize.cfg")


def stored_mode(path: Path) -> dict | None:
    """The notebook's ``motionlab`` metadata when its outputs are stored, else None."""
    try:
        meta = json.loads(Path(path).read_text(encoding="utf-8")).get("metadata", {}).get("motionlab", {})
    except (OSError, ValueError):
        return None
    return meta if meta.get("outputs") == "stored" else None


def _has_data() -> bool:
    root = os.environ.get("MOTIONLAB_DATA", "")
    return bool(root) and Path(root).is_dir()


def pytest_configure(config):
    opt = config.option
    if getattr(opt, "nbval", False) and not getattr(opt, "nbval_sanitize_with", None) and SANITIZE.exists():
        opt.nbval_sanitize_with = str(SANITIZE)


@pytest.hookimpl(hookwrapper=True)
def pytest_collect_file(file_path, parent):
    outcome = yield
    if file_path.suffix != ".ipynb" or not getattr(parent.config.option, "nbval", False):
        return
    meta = stored_mode(file_path)
    strict = meta is not None
    if strict and meta.get("data") and not _has_data():
        warnings.warn(
            f"{file_path.name}: outputs were stored with the course data; MOTIONLAB_DATA is not set, "
            "so its outputs are not compared (lax mode)",
            stacklevel=1,
        )
        strict = False
    for collector in outcome.get_result() or []:
        if hasattr(collector, "compare_outputs"):
            collector.compare_outputs = strict


def pytest_report_header(config):
    if getattr(config.option, "nbval", False):
        return "notebooks: strict nbval where outputs are stored (metadata motionlab.outputs), lax elsewhere"
    return None
