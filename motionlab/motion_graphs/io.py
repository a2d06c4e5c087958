"""Saving and loading motion graphs: one ``.mlgraph`` file, NumPy arrays plus JSON.

The file is an *uncompressed* NumPy ``.npz`` archive (no pickle: it loads with
``allow_pickle=False``): arrays ``local_rot`` (float64, as the graph holds them), ``root_pos``,
``alive``, ``src``, ``dst``, ``cost``, ``kind``, ``offsets``, ``parents`` and ``meta``, the
UTF-8 bytes of a JSON object — format version, fps, joint names, clips, structure table, build
info and the graph's :meth:`~.graph.MotionGraph.summary` — and the routes of the structure
table's links as arrays ``route_*`` (read back as :class:`Routes`). Because the members are stored, not
compressed, :func:`load` *maps* the arrays (``numpy.memmap``, copy-on-write) instead of reading
them: opening a graph reads each member once, in blocks, to check its CRC-32 (so a damaged file
is named, and the pages read do not stay in the process's memory; ``load(..., verify=False)``
leaves that to :func:`verify`, which ``graph-search`` runs in a thread while it searches), and a
search then keeps only the pages it touches. Each
member's data starts at a multiple of :data:`ALIGN` bytes (padding in its zip header), so the
mapped arrays are aligned; files of this version written without the padding load as well.

Files of the previous version (``motionlab-graph-2``, compressed) are still read, whole.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import json
import os
import struct
import zipfile
import zlib
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from motionlab.core import files
from motionlab.core.skeleton import Skeleton
from motionlab.motion_graphs.graph import ClipInfo, GraphError, MotionGraph

__all__ = ["save", "load", "verify", "writer", "read_meta", "Routes", "FORMAT", "READABLE"]

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
    if isinstance(x, (list, tuple, Routes)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    return x


_ROUTE_KEYS = {"exit", "enter", "pieces", "frames", "cost"}
ROUTE_ARRAYS = ("route_exit", "route_enter", "route_frames", "route_cost", "route_piece_start", "route_pieces")


class Routes(Sequence):
    """The routes of one structure-table link, read from the file's route arrays on access.

    Behaves as the list of route dicts the build made (``exit``, ``enter``, ``frames``, ``cost``,
    ``pieces``: a list of ``[clip, first, last]``), so a search reads only the links it uses."""

    def __init__(self, arrays: dict, first: int, count: int):
        self.a, self.first, self.count = arrays, int(first), int(count)
        self._items: list[dict] | None = None

    def __len__(self) -> int:
        return self.count

    def _all(self) -> list[dict]:
        """Every route of the link, made from the arrays at the first access (then kept)."""
        if self._items is None:
            a, s, e = self.a, self.first, self.first + self.count
            starts = np.asarray(a["route_piece_start"][s : e + 1])
            pieces = np.asarray(a["route_pieces"][starts[0] : starts[-1]]).tolist()
            rel = (starts - starts[0]).tolist()
            cols = [np.asarray(a[f"route_{k}"][s:e]).tolist() for k in ("exit", "enter", "frames", "cost")]
            self._items = [
                {"exit": x, "enter": y, "pieces": pieces[rel[k] : rel[k + 1]], "frames": f, "cost": c}
                for k, (x, y, f, c) in enumerate(zip(*cols))
            ]
        return self._items

    def __getitem__(self, k):
        return self._all()[k]

    def __iter__(self):
        return iter(self._all())

    def __eq__(self, other) -> bool:
        return isinstance(other, Sequence) and len(other) == self.count and list(self) == list(other)

    def __repr__(self) -> str:
        return f"Routes({self.count} routes)"


def _pack_routes(table: dict) -> tuple[dict, dict]:
    """The table with each link's routes replaced by ``{"first", "count"}`` into the route arrays,
    and those arrays (links whose routes hold other keys keep them in the JSON)."""
    cols = {k: [] for k in ("exit", "enter", "frames", "cost")}
    pieces, starts, links = [], [0], []
    for link in table.get("links", []):
        routes = list(link.get("routes", []))
        if not all(isinstance(r, dict) and set(r) == _ROUTE_KEYS for r in routes):
            links.append(link)
            continue
        links.append({**link, "routes": {"first": len(starts) - 1, "count": len(routes)}})
        for r in routes:
            for k in cols:
                cols[k].append(r[k])
            pieces.extend(r["pieces"])
            starts.append(len(pieces))
    arrays = {f"route_{k}": np.asarray(v, dtype=np.float64 if k == "cost" else np.int64) for k, v in cols.items()}
    arrays["route_piece_start"] = np.asarray(starts, dtype=np.int64)
    arrays["route_pieces"] = np.asarray(pieces, dtype=np.int64).reshape(-1, 3)
    return {**table, "links": links}, arrays


def _unpack_routes(table: dict, arrays: dict) -> dict:
    """The table as the build made it, with :class:`Routes` reading the route arrays."""
    for link in table.get("links", []):
        r = link.get("routes")
        if isinstance(r, dict) and set(r) == {"first", "count"}:
            link["routes"] = Routes(arrays, r["first"], r["count"])
    return table


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
        "info": graph.info,
        "summary": graph.summary() if summary is None else summary,
    }
    meta["table"], route_arrays = _pack_routes(graph.table)

    def write(fh) -> None:
        _write_aligned(
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
            **route_arrays,
        )

    return write


ALIGN = 64
"""Bytes to which every array's data is aligned in the file (an ``.npy`` header pads the data
to this from the member's start, and the member's data starts on it): a mapped array that is
not aligned to its item size is read by NumPy's slow unaligned loops."""

_PAD_ID = 0xD935
"""Zip extra-field id of the padding (the one Android's ``zipalign`` writes; readers skip it)."""


def _write_aligned(fh, **arrays: np.ndarray) -> None:
    """``np.savez(fh, **arrays)`` (stored, zip64, no pickle) with each member's data starting at
    a multiple of :data:`ALIGN` bytes in the file, padded by an extra field of its local header."""
    with zipfile.ZipFile(fh, mode="w", compression=zipfile.ZIP_STORED, allowZip64=True) as z:
        for name, a in arrays.items():
            info = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type, info.CRC, info.compress_size, info.file_size = zipfile.ZIP_STORED, 0, 0, 0
            header = len(info.FileHeader(zip64=True)) + 4  # with the padding field's own 4 bytes
            pad = -(z.fp.tell() + header) % ALIGN
            info.extra = struct.pack("<HH", _PAD_ID, pad) + bytes(pad)
            with z.open(info, mode="w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asanyarray(a), allow_pickle=False)


def save(path: str | os.PathLike, graph: MotionGraph, overwrite: bool = False, summary: dict | None = None) -> Path:
    """Write ``graph`` to ``path`` (``.mlgraph`` added if there is no suffix), atomically.

    ``summary``: ``graph.summary()`` when the caller has it (computed here otherwise).
    Raises ``FileExistsError`` when the file exists and ``overwrite`` is False.
    """
    path = Path(path)
    if path.suffix == "":
        path = path.with_suffix(".mlgraph")
    return files.atomic_write(path, writer(graph, summary), overwrite=overwrite, binary=True, what="motion graph")


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


_CRC_BLOCK = 1 << 20
"""Bytes read at a time to check a member's CRC-32."""


def _check_crc(path: Path, fh, info: zipfile.ZipInfo, size: int) -> None:
    """Raise :class:`GraphError` when a stored member's bytes do not give the CRC-32 its zip entry
    records (a mapped array is never read through :mod:`zipfile`, which would check it)."""
    offset = _member_offset(fh, info)
    if offset + info.file_size > size:
        raise EOFError("member runs past the end of the file")
    crc, left, block = 0, info.file_size, memoryview(bytearray(_CRC_BLOCK))
    fh.seek(offset)
    while left:  # read in blocks, not mapped: the pages read do not stay in the process's memory
        got = fh.readinto(block[: min(left, _CRC_BLOCK)])
        if not got:
            raise EOFError("member runs past the end of the file")
        crc, left = zlib.crc32(block[:got], crc), left - got
    if crc != info.CRC:
        raise GraphError(
            f"{path} is damaged: the bytes of its {info.filename[: -len('.npy')]!r} array do not match the "
            "checksum written with them; build the graph again (graph-build)"
        )


def _check_crcs(path: Path, entries: dict) -> None:
    """:func:`_check_crc` of every zip entry of ``entries`` (name -> ZipInfo), one pass over the file."""
    size = path.stat().st_size
    with open(path, "rb") as fh:
        for e in entries.values():
            _check_crc(path, fh, e, size)


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

    def meta() -> dict:
        with zipfile.ZipFile(path) as z:
            if "meta.npy" not in z.namelist():
                raise GraphError(f"{path} is not a motion graph file (no 'meta' entry)")
            return _read_meta(z)

    return _named(path, meta)


def _members(path: Path, z: zipfile.ZipFile) -> tuple[dict, dict, bool]:
    """Meta, the zip entries of the arrays by name, and whether they are mapped (version 3, stored)."""
    names = {n[: -len(".npy")]: z.getinfo(n) for n in z.namelist() if n.endswith(".npy")}
    if "meta" not in names:
        raise GraphError(f"{path} is not a motion graph file (no 'meta' entry)")
    meta = _read_meta(z)
    missing = [k for k in ARRAYS if k not in names]
    if missing:
        raise GraphError(f"{path} is not a complete motion graph file (missing {missing})")
    entries = {k: names[k] for k in ARRAYS + tuple(k for k in ROUTE_ARRAYS if k in names)}
    mapped = meta["format"] == FORMAT and all(e.compress_type == zipfile.ZIP_STORED for e in entries.values())
    return meta, entries, mapped


def _arrays(path: Path, verify: bool) -> tuple[dict, dict]:
    """Meta and arrays of a graph file: mapped for version 3 (their CRC-32s checked first when
    ``verify``), read whole for version 2 (:mod:`zipfile` checks them as it reads)."""
    with zipfile.ZipFile(path) as z:
        meta, entries, mapped = _members(path, z)
        if mapped:
            if verify:
                _check_crcs(path, entries)
            size = path.stat().st_size
            with open(path, "rb") as fh:
                return meta, {k: _mapped(path, fh, e, size) for k, e in entries.items()}
        arrays = {}
        for k, e in entries.items():
            with z.open(e) as f:
                arrays[k] = np.lib.format.read_array(f, allow_pickle=False)
        return meta, arrays


def _named(path: Path, read):
    """``read()``, its errors turned into :class:`GraphError` naming ``path``."""
    try:
        return read()
    except GraphError as e:
        raise GraphError(str(e) if str(path) in str(e) else f"{path}: {e}") from None
    except (ValueError, OSError, EOFError, zipfile.BadZipFile, zlib.error) as e:
        raise _damaged(path, e) from None


def verify(path: str | os.PathLike) -> None:
    """Check the CRC-32 of every array of a graph file against its zip entry, as :func:`load`
    does unless told not to: the file is read once, in blocks, and nothing is kept.

    Raises as :func:`load` does for a damaged, truncated or foreign file.
    """
    path = _open(path)

    def crcs() -> None:
        with zipfile.ZipFile(path) as z:
            _, entries, mapped = _members(path, z)
        if mapped:  # (version 2's compressed arrays are checked by zipfile as load reads them)
            _check_crcs(path, entries)

    _named(path, crcs)


def load(path: str | os.PathLike, verify: bool = True) -> MotionGraph:
    """Read a graph written by :func:`save`; its arrays are memory-mapped (module docstring).

    ``verify=False`` leaves out the check of the arrays' CRC-32s: then call :func:`verify` (for
    example in a thread while the graph is searched, as ``graph-search`` does) before anything
    made from the graph is trusted or written.

    Raises :class:`GraphError` naming the file for anything else: a file that is not a zip
    archive, a truncated or damaged one (every array's CRC-32 is checked), an archive without the graph's entries, or a format
    version it cannot read (``motionlab-graph-1``: rebuild it). ``FileNotFoundError`` when there
    is no file.
    """
    path = _open(path)
    meta, arrays = _named(path, lambda: _arrays(path, verify))
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
                           a["root_pos"], a["alive"], a["src"], a["dst"], a["cost"], a["kind"],
                           _unpack_routes(meta["table"], arrays), meta["info"])  # fmt: skip
    except (KeyError, TypeError, ValueError) as e:
        raise GraphError(f"{path}: damaged motion graph metadata ({type(e).__name__}: {e})") from None
