"""Run notebooks from top to bottom and store their outputs, ready for strict nbval.

    MOTIONLAB_DATA=/path/to/shared/data python scripts/store_notebook_outputs.py            # all stored notebooks
    MOTIONLAB_DATA=/path/to/shared/data python scripts/store_notebook_outputs.py 04_playback_and_bone_proportions

Each notebook runs in a fresh kernel in CI's settings (``MOTIONLAB_QUICK=1``, off-screen pyvista with
the static Jupyter view, inline matplotlib figures, ``PYTHONHASHSEED=0``), with the course data
(``MOTIONLAB_DATA``, required unless ``--no-data``). Then the outputs are made small and stable:

* PNG figures are re-encoded with a 256-colour palette (typically a third of the size);
* consecutive pieces of one stream are merged (how print output is split depends on timing);
* execution timings and the widget state (the players' pictures again, several 100 kB) are dropped;
* the notebook's metadata records ``motionlab.outputs = "stored"`` (strict nbval, see
  ``tests/nbval_modes.py``), whether the course data was used, and a hash of its code cells
  (``tests/test_notebook_outputs.py`` fails when code changed after the outputs were stored).

The file is replaced atomically (temporary file, then rename). Edit a notebook, run this, commit.
"""

from __future__ import annotations

import argparse
import base64
import hashlib
import io
import os
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = REPO / "notebooks"

STORED = [
    "00_quaternions_and_fk",
    "00b_bvh_file_format",
    "01_preprocessing",
    "02_training_autoencoder",
    "03_latent_iteration",
    "04_playback_and_bone_proportions",
    "05_motion_graphs",
    "06_keypose_interpolation",
    "07_expanding_a_database",
]
"""Notebooks committed with outputs (strict nbval): all of them."""

ENV = {
    "MOTIONLAB_QUICK": "1",
    "PYVISTA_OFF_SCREEN": "true",
    "PYVISTA_JUPYTER_BACKEND": "static",
    "VTK_DEFAULT_OPENGL_WINDOW": "vtkEGLRenderWindow",
    "PYTHONHASHSEED": "0",
    "MOTIONLAB_WEB_EMBED": "0",  # no three.js copy in the web players' outputs: the docs site has it, JupyterLab draws on the 2D canvas
}


def code_hash(nb) -> str:
    """sha256 of the notebook's code cells (sources only), in order."""
    h = hashlib.sha256()
    for cell in nb.cells:
        if cell.cell_type == "code":
            h.update(cell.source.encode("utf-8"))
            h.update(b"\0")
    return h.hexdigest()


def compress_png(b64: str) -> str:
    """A smaller PNG of the same picture (256-colour palette, optimised), or the input if not smaller."""
    from PIL import Image

    raw = base64.b64decode(b64)
    img = Image.open(io.BytesIO(raw)).convert("RGB")
    out = io.BytesIO()
    img.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(out, "PNG", optimize=True)
    return base64.b64encode(out.getvalue()).decode("ascii") if out.tell() < len(raw) else b64


def coalesce_streams(outputs: list) -> list:
    """Consecutive stream outputs of one name merged into one (the split depends on flush timing)."""
    merged = []
    for output in outputs:
        prev = merged[-1] if merged else None
        if prev is not None and output.output_type == prev.output_type == "stream" and output.name == prev.name:
            prev.text += output.text
        else:
            merged.append(output)
    return merged


def tidy(nb, used_data: bool) -> None:
    """Compress figures, merge split streams, drop run-specific metadata, mark the notebook as stored."""
    for cell in nb.cells:
        cell.metadata.pop("execution", None)
        if cell.cell_type == "code":
            cell.outputs = coalesce_streams(cell.outputs)
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            if "image/png" in data:
                data["image/png"] = compress_png(data["image/png"])
            output.get("metadata", {}).pop("execution", None)
    nb.metadata.pop("widgets", None)
    quick = ENV["MOTIONLAB_QUICK"] == "1"  # the docs site says so on the notebook's page
    nb.metadata["motionlab"] = {"outputs": "stored", "data": used_data, "quick": quick, "code_sha256": code_hash(nb)}


def run(name: str, used_data: bool, timeout: int) -> Path:
    import nbformat
    from nbclient import NotebookClient

    path = NOTEBOOKS / f"{name}.ipynb"
    if not path.exists():
        raise SystemExit(f"{path}: no such notebook (names are given without .ipynb)")
    nb = nbformat.read(path, as_version=4)
    for cell in nb.cells:  # start from a clean notebook
        if cell.cell_type == "code":
            cell.outputs, cell.execution_count = [], None
    start = time.perf_counter()
    NotebookClient(
        nb,
        timeout=timeout,
        kernel_name="python3",
        resources={"metadata": {"path": str(NOTEBOOKS)}},
        record_timing=False,
    ).execute()
    tidy(nb, used_data)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{name}.", suffix=".ipynb")
    os.close(fd)
    try:
        nbformat.write(nb, tmp)
        os.chmod(tmp, 0o644)  # mkstemp makes 0600 files
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    print(f"{path.relative_to(REPO)}: {time.perf_counter() - start:.1f} s, {path.stat().st_size / 1024:.0f} kB")
    return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help=f"notebooks to run (default: {', '.join(STORED)})")
    parser.add_argument("--no-data", action="store_true", help="store outputs made without MOTIONLAB_DATA")
    parser.add_argument("--timeout", type=int, default=600, help="seconds per cell")
    args = parser.parse_args(argv)
    names = args.names or STORED
    unknown = [n for n in names if n.removesuffix(".ipynb") not in STORED]
    if unknown:
        print(f"not in STORED (add them there first): {', '.join(unknown)}", file=sys.stderr)
        return 2
    data = os.environ.get("MOTIONLAB_DATA", "")
    used_data = bool(data) and Path(data).is_dir()
    if not used_data and not args.no_data:
        print("MOTIONLAB_DATA is not set: CI compares the outputs made with the course data. "
              "Set it, or pass --no-data.", file=sys.stderr)  # fmt: skip
        return 2
    os.environ.update(ENV)
    os.environ.pop("MPLBACKEND", None)  # inline figures, as a reader sees them
    sys.path.insert(0, str(REPO))
    os.environ["PYTHONPATH"] = os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    for name in names:
        run(name.removesuffix(".ipynb"), used_data, args.timeout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
