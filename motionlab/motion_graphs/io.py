"""Saving and loading motion graphs: one ``.mlgraph`` file, NumPy arrays plus JSON.

The file is a NumPy ``.npz`` archive (no pickle: it loads with ``allow_pickle=False``):
arrays ``local_rot``, ``root_pos``, ``alive``, ``src``, ``dst``, ``cost``, ``kind``,
``offsets``, ``parents`` and one string array ``meta`` holding JSON — format version, fps,
joint names, clips, structure table and build info.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import json
import os
import zipfile
import zlib
from pathlib import Path

import numpy as np

from motionlab.core import files
from motionlab.core.skeleton import Skeleton
from motionlab.motion_graphs.graph import ClipInfo, GraphError, MotionGraph

__all__ = ["save", "load", "writer", "FORMAT"]

FORMAT = "motionlab-graph-2"
"""Version 2: style cells hold pooled takes (version 1 held one clip per style)."""


def _jsonable(x):
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    return x


def writer(graph: MotionGraph):
    """``write(fh)``: writes ``graph`` in the ``.mlgraph`` format to a binary file ``fh`` (for
    :func:`motionlab.core.files.atomic_write_all`, which writes several files as one)."""
    sk = graph.skeleton
    meta = {
        "format": FORMAT,
        "fps": graph.fps,
        "names": list(sk.names),
        "end_sites": {str(k): v.tolist() for k, v in sk.end_sites.items()},
        "clips": [c.to_dict() for c in graph.clips],
        "table": graph.table,
        "info": graph.info,
    }

    def write(fh) -> None:
        np.savez_compressed(
            fh,
            meta=np.array(json.dumps(_jsonable(meta))),
            local_rot=graph.local_rot.astype(np.float32),
            root_pos=graph.root_pos,
            alive=graph.alive,
            src=graph.src,
            dst=graph.dst,
            cost=graph.cost,
            kind=graph.kind,
            offsets=sk.offsets,
            parents=sk.parents,
        )

    return write


def save(path: str | os.PathLike, graph: MotionGraph, overwrite: bool = False) -> Path:
    """Write ``graph`` to ``path`` (``.mlgraph`` added if there is no suffix), atomically.

    Raises ``FileExistsError`` when the file exists and ``overwrite`` is False.
    """
    path = Path(path)
    if path.suffix == "":
        path = path.with_suffix(".mlgraph")
    return files.atomic_write(path, writer(graph), overwrite=overwrite, binary=True, what="motion graph")


def load(path: str | os.PathLike) -> MotionGraph:
    """Read a graph written by :func:`save`.

    Raises :class:`GraphError` naming the file for anything else: a file that is not a zip
    archive, a truncated or damaged one, or an archive without the graph's entries.
    """
    path = Path(path)
    if path.is_dir():
        raise GraphError(f"{path} is a folder, not a motion graph file (.mlgraph)")
    if not path.is_file():
        raise FileNotFoundError(f"no motion graph file at {path}")
    with open(path, "rb") as fh:
        magic = fh.read(4)
    if magic != b"PK\x03\x04":
        raise GraphError(
            f"{path} is not a motion graph file: expected the zip archive that graph-build writes "
            f"(it starts with PK), found {magic!r}"
        )
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
        meta = json.loads(str(arrays["meta"]))
    except KeyError:
        raise GraphError(f"{path} is not a motion graph file (no 'meta' entry)") from None
    except (ValueError, OSError, EOFError, zipfile.BadZipFile, zlib.error) as e:
        raise GraphError(
            f"{path} is truncated or damaged and cannot be read as a motion graph ({type(e).__name__})"
        ) from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        found = meta.get("format") if isinstance(meta, dict) else None
        hint = "; rebuild it with motionlab graph-build" if str(found).startswith("motionlab-graph-") else ""
        raise GraphError(f"{path}: unknown format {found!r}, expected {FORMAT!r}{hint}")
    need = ("local_rot", "root_pos", "alive", "src", "dst", "cost", "kind", "offsets", "parents")
    missing = [k for k in need if k not in arrays]
    if missing:
        raise GraphError(f"{path} is not a complete motion graph file (missing {missing})")
    try:
        sk = Skeleton(
            tuple(meta["names"]),
            arrays["parents"],
            arrays["offsets"],
            {int(k): np.array(v) for k, v in meta["end_sites"].items()},
        )
        rot = arrays["local_rot"].astype(np.float64)
        rot /= np.linalg.norm(rot, axis=-1, keepdims=True)
        return MotionGraph(
            sk,
            float(meta["fps"]),
            [ClipInfo(**c) for c in meta["clips"]],
            rot,
            arrays["root_pos"],
            arrays["alive"].astype(bool),
            arrays["src"].astype(np.int64),
            arrays["dst"].astype(np.int64),
            arrays["cost"].astype(np.float64),
            arrays["kind"].astype(np.int8),
            meta["table"],
            meta["info"],
        )
    except (KeyError, TypeError, ValueError) as e:
        raise GraphError(f"{path}: damaged motion graph metadata ({type(e).__name__}: {e})") from None
