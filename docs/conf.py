"""Sphinx configuration of motionlab's documentation site.

Build (from the repository root, warnings are errors):  bash scripts/build_docs.sh
The notebooks are rendered with their stored outputs (myst-nb, execution off); the API reference
is generated from the docstrings (autodoc + autosummary, numpydoc style through napoleon).
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")  # importing motionlab.viz must not open a window
os.environ.setdefault("MPLBACKEND", "Agg")

project = "motionlab"
author = "the motionlab authors"
copyright = "motionlab authors"  # noqa: A001 (the name Sphinx reads)

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",  # MathJax served from the site itself: formulas render offline too
    # no sphinx.ext.viewcode: the code is in the repository, and its highlighted copy (8 MB) kept the
    # site over its 50 MB budget
]

# --- sources --------------------------------------------------------------------------------
# The site renders the notebooks as committed: they are copied from ../notebooks into
# docs/notebooks (git-ignored) on every build. The instructor's key (instructor/solutions, outside
# notebooks/) is not copied: it stays out of the students' site.
NOTEBOOKS = ROOT / "notebooks"
_copies = Path(__file__).resolve().parent / "notebooks"
_copies.mkdir(exist_ok=True)
for _old in _copies.glob("*.ipynb"):
    if not (NOTEBOOKS / _old.name).exists():
        _old.unlink()


def _page_copy(notebook: Path) -> bytes:
    """The notebook as its page shows it: with a note under the title when its stored outputs were
    made in quick mode (``motionlab.quick`` in its metadata, written by store_notebook_outputs)."""
    nb = json.loads(notebook.read_text(encoding="utf-8"))
    meta = nb.get("metadata", {}).get("motionlab", {})
    if meta.get("quick"):
        data = "with the course data" if meta.get("data") else "on motionlab's synthetic data"
        note = (
            f"```{{note}}\nThe outputs on this page were made in **quick mode** (`MOTIONLAB_QUICK=1`: "
            f"fewer clips, frames and steps, the mode CI checks) {data}. Run the notebook without "
            "`MOTIONLAB_QUICK` for the full-size results; its first output says which mode it ran in.\n```"
        )
        nb["cells"].insert(1, {"cell_type": "markdown", "id": "quick-mode-note", "metadata": {}, "source": note})
    return (json.dumps(nb, indent=1, ensure_ascii=False) + "\n").encode("utf-8")


for _nb in sorted(NOTEBOOKS.glob("*.ipynb")):
    _target, _page = _copies / _nb.name, _page_copy(_nb)
    if not _target.exists() or _target.read_bytes() != _page:
        _target.write_bytes(_page)

exclude_patterns = ["_build", "**/.ipynb_checkpoints"]
# .rst first: autosummary writes its generated API pages with the first suffix
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}

# --- notebooks: stored outputs only ----------------------------------------------------------
nb_execution_mode = "off"
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3
# The players are ipywidgets: without a kernel their widget view is empty, so show the picture
# each one stores beside it (its first frame) instead.
nb_mime_priority_overrides = [("html", "application/vnd.jupyter.widget-view+json", None)]

# --- API reference ---------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
# each object once, on the page of the module that defines it (packages re-export names in __all__)
autodoc_default_options = {"members": True, "ignore-module-all": True}
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the numpydoc sections state shapes and units
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False

# --- HTML ------------------------------------------------------------------------------------
html_theme = "sphinx_book_theme"
html_title = "motionlab"
html_theme_options = {
    "show_toc_level": 2,
    "use_download_button": True,
    "home_page_in_toc": True,
    # the sidebar lists the pages and the API's packages, the current section open; a package's
    # page lists its modules
    "max_navbar_depth": 2,
    "collapse_navbar": True,
}
# three.js for the web players in notebook outputs (motionlab.viz.web): scripts/build_docs.sh vendors
# it from npm (scripts/vendor_three.sh) into build/web/three.min.js, one classic script that defines
# window.THREE, copied into _static/ and loaded on the notebooks' pages (where the players are), so
# players work from file:// offline; the other pages do not load its 0.5 MB.
_THREE = ROOT / "build" / "web" / "three.min.js"
if not _THREE.is_file():
    raise FileNotFoundError(f"{_THREE} is missing: build the site with scripts/build_docs.sh (it runs vendor_three.sh)")
html_static_path: list[str] = [str(_THREE.parent)]


def _three_js_on_notebook_pages(app, pagename, templatename, context, doctree) -> None:
    if pagename.startswith("notebooks/"):
        app.add_js_file(_THREE.name)


def setup(app) -> None:
    app.connect("html-page-context", _three_js_on_notebook_pages)


# numpydoc parameter types here describe shapes and components ("ndarray, shape (T, J, 4),
# (w, x, y, z)"), not Python objects; Sphinx looks up words such as `x` or `start` in them and
# warns when several attributes share the name. Those lookups are not links anyone wrote.
suppress_warnings = ["ref.python"]
