"""Saving and loading motion graphs: one ``.mlgraph`` file, NumPy arrays plus JSON.

The file is an *uncompressed* NumPy ``.npz`` archive (no pickle: it loads with
``allow_pickle=False``): arrays ``local_rot`` (float64, as the graph holds them), ``root_pos``,
``alive``, ``src``, ``dst``, ``cost``, ``kind``, ``offsets``, ``parents`` and ``meta``, the
UTF-8 bytes of a JSON object — format version, fps, joint names, clips, structure table, build
info and the graph's :meth:`~.graph.MotionGraph.summary`. Because the members are stored, not
compressed, :func:`load` *maps* the arrays (``numpy.memmap``, copy-on-write) instead of reading
them: opening a graph reads only its JSON, and a search reads only the pages it touches.

Files of the previous version (``motionlab-graph-2``, compressed) are still read, whole.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import json
import os
import struct
import zipfile
import zlib
from pathlib import Path

import numpy as np

from motionlab.core import files
from motionlab.core.skeleton import Skeleton
from motionlab.motion_graphs.graph import ClipInfo, GraphError, MotionGraph

__all__ = ["save", "load", "writer", "read_meta", "FORMAT", "READABLE"]

FORMAT = "motionlab-graph-3"
"""Version 3: uncompressed members, mapped on load; ``meta`` is UTF-8 bytes and holds the summary."""

READABLE = ("motionlab-graph-2", FORMAT)
"""Versions :func:`load` reads (2: compressed, read whole; 1 held one clip per style: rebuild)."""

ARRAYS = ("local_rot", "root_pos", "alive", "src", "dst", "cost", "kind", "offsets", "parents")
_DTYPES = {"local_rot": np.float64, "root_pos": np.float64, "alive": np.bool_, "src": np.int64,
           "dst": np.int64, "cost": np.float64, "kind": np.int8}  # fmt: skip


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


def writer(graph: MotionGraph, summary: dict | None = None):
    """``write(fh)``: writes ``graph`` in the ``.mlgraph`` format to a binary file ``fh`` (for
    :func:`motionlab.core.files.atomic_write_all`, which writes several files as one).

    ``summary``: ``graph.summary()`` when the caller has it (computed here otherwise)."""
    sk = graph.skeleton
    meta = {
        "format": FORMAT,
        "fps": graph.fps,
        "names": list(sk.names),
        "end_sites": {str(k): v.tolist() for k, v in sk.end_sites.items()},
        "clips": [c.to_dict() for c in graph.clips],
        "table": graph.table,
        "info": graph.info,
        "summary": graph.summary() if summary is None else summary,
    }

    def write(fh) -> None:
        np.savez(
            fh,
            meta=np.frombuffer(json.dumps(_jsonable(meta)).encode("utf-8"), dtype=np.uint8),
            local_rot=np.asarray(graph.local_rot, dtype=np.float64),
            root_pos=np.asarray(graph.root_pos, dtype=np.float64),
            alive=np.asarray(graph.alive, dtype=bool),
            src=np.asarray(graph.src, dtype=np.int64),
            dst=np.asarray(graph.dst, dtype=np.int64),
            cost=np.asarray(graph.cost, dtype=np.float64),
            kind=np.asarray(graph.kind, dtype=np.int8),
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


def _member_offset(fh, info: zipfile.ZipInfo) -> int:
    """Byte offset in the file of a stored zip member's data (after its local header)."""
    fh.seek(info.header_offset)
    head = fh.read(30)
    if len(head) < 30 or head[:4] != b"PK\x03\x04":
        raise ValueError("bad local header")
    name_len, extra_len = struct.unpack("<HH", head[26:30])
    return info.header_offset + 30 + name_len + extra_len


def _mapped(path: Path, fh, info: zipfile.ZipInfo, size: int) -> np.ndarray:
    """A stored ``.npy`` member as a copy-on-write memory map (its header read, its data not)."""
    fh.seek(_member_offset(fh, info))
    version = np.lib.format.read_magic(fh)
    if version == (1, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh)
    elif version == (2, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh)
    else:
        raise ValueError(f"npy version {version}")
    if dtype.hasobject:
        raise ValueError("object array")
    offset = fh.tell()
    nbytes = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
    if offset + nbytes > size:
        raise EOFError("member runs past the end of the file")
    if nbytes == 0:
        return np.zeros(shape, dtype=dtype)
    return np.memmap(path, dtype=dtype, mode="c", offset=offset, shape=shape, order="F" if fortran else "C")


def _read_meta(z: zipfile.ZipFile) -> dict:
    with z.open("meta.npy") as f:
        m = np.lib.format.read_array(f, allow_pickle=False)
    meta = json.loads(m.tobytes().decode("utf-8") if m.dtype == np.uint8 else str(m))
    if not isinstance(meta, dict) or meta.get("format") not in READABLE:
        found = meta.get("format") if isinstance(meta, dict) else None
        hint = "; rebuild it with motionlab graph-build" if str(found).startswith("motionlab-graph-") else ""
        raise GraphError(f"unknown format {found!r}, expected {FORMAT!r}{hint}")
    return meta


def _open(path) -> Path:
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
    return path


def _damaged(path: Path, e: Exception) -> GraphError:
    return GraphError(f"{path} is truncated or damaged and cannot be read as a motion graph ({type(e).__name__})")


def read_meta(path: str | os.PathLike) -> dict:
    """The JSON part of a graph file (format, fps, clips, table, info and, from version 3 on,
    ``summary``) without touching its arrays. Raises as :func:`load`."""
    path = _open(path)
    try:
        with zipfile.ZipFile(path) as z:
            if "meta.npy" not in z.namelist():
                raise GraphError(f"{path} is not a motion graph file (no 'meta' entry)")
            return _read_meta(z)
    except GraphError as e:
        raise GraphError(str(e) if str(path) in str(e) else f"{path}: {e}") from None
    except (ValueError, OSError, EOFError, zipfile.BadZipFile, zlib.error) as e:
        raise _damaged(path, e) from None


def _arrays(path: Path) -> tuple[dict, dict]:
    """Meta and arrays of a graph file: mapped for version 3, read whole for version 2."""
    with zipfile.ZipFile(path) as z:
        names = {n[: -len(".npy")]: z.getinfo(n) for n in z.namelist() if n.endswith(".npy")}
        if "meta" not in names:
            raise GraphError(f"{path} is not a motion graph file (no 'meta' entry)")
        meta = _read_meta(z)
        missing = [k for k in ARRAYS if k not in names]
        if missing:
            raise GraphError(f"{path} is not a complete motion graph file (missing {missing})")
        stored = all(names[k].compress_type == zipfile.ZIP_STORED for k in ARRAYS)
        if meta["format"] == FORMAT and stored:
            size = path.stat().st_size
            with open(path, "rb") as fh:
                return meta, {k: _mapped(path, fh, names[k], size) for k in ARRAYS}
        arrays = {}
        for k in ARRAYS:
            with z.open(names[k]) as f:
                arrays[k] = np.lib.format.read_array(f, allow_pickle=False)
        return meta, arrays


def load(path: str | os.PathLike) -> MotionGraph:
    """Read a graph written by :func:`save`; its arrays are memory-mapped (module docstring).

    Raises :class:`GraphError` naming the file for anything else: a file that is not a zip
    archive, a truncated or damaged one, an archive without the graph's entries, or a format
    version it cannot read (``motionlab-graph-1``: rebuild it). ``FileNotFoundError`` when there
    is no file.
    """
    path = _open(path)
    try:
        meta, arrays = _arrays(path)
    except GraphError as e:
        raise GraphError(str(e) if str(path) in str(e) else f"{path}: {e}") from None
    except (ValueError, OSError, EOFError, zipfile.BadZipFile, zlib.error) as e:
        raise _damaged(path, e) from None
    try:
        sk = Skeleton(
            tuple(meta["names"]),
            np.array(arrays["parents"]),
            np.array(arrays["offsets"]),
            {int(k): np.array(v) for k, v in meta["end_sites"].items()},
        )
        if meta["format"] != FORMAT:  # version 2 kept rotations as float32: back to unit float64
            rot = arrays["local_rot"].astype(np.float64)
            arrays["local_rot"] = rot / np.linalg.norm(rot, axis=-1, keepdims=True)
        a = {k: arrays[k] if arrays[k].dtype == t else arrays[k].astype(t) for k, t in _DTYPES.items()}
        return MotionGraph(sk, float(meta["fps"]), [ClipInfo(**c) for c in meta["clips"]], a["local_rot"],
                           a["root_pos"], a["alive"], a["src"], a["dst"], a["cost"], a["kind"], meta["table"],
                           meta["info"])  # fmt: skip
    except (KeyError, TypeError, ValueError) as e:
        raise GraphError(f"{path}: damaged motion graph metadata ({type(e).__name__}: {e})") from None
