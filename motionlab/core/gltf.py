"""Write a Motion as glTF 2.0 binary (``.glb``), the format web viewers and game engines read.

What a file holds:

* the **skeleton** as a node hierarchy: one node per joint, named as the joint, whose rest
  transform is the joint's offset (translation) with no rotation (motionlab's rest pose);
* a **skin** over those nodes: the joints in motionlab's order, with inverse bind matrices
  ``inv(B_j)``, where ``B_j`` is the translation to joint ``j``'s rest world position;
* a **mesh** that makes the skin visible and valid: a thin box along every bone (and every end
  site), weighted to the bone's parent joint, and a small cube at every joint, weighted to it;
* the **motion** as one animation: a rotation channel per joint (quaternions, LINEAR), a
  translation channel for the root (and for every joint when the motion has ``local_pos``),
  sampled at the frame times ``t_k = k / fps`` seconds.

glTF shares motionlab's world: right-handed, +Y up, metres, so positions are written as they
are. One edge converts: glTF quaternions are ``(x, y, z, w)``, motionlab's ``(w, x, y, z)``
(:func:`motionlab.core.quat.to_xyzw`). Numbers are stored as float32 (about 1e-7 relative).

A GLB file is a 12-byte header (``glTF``, version 2, total length) followed by two chunks: the
JSON document, then the binary buffer every accessor points into (glTF 2.0 specification, §4.4).

Taught in ``notebooks/04_playback_and_bone_proportions.ipynb``; ``docs/gltf.md`` shows how to
open a file in Blender or three.js.
"""

from __future__ import annotations

import json
import os
import struct
from pathlib import Path

import numpy as np

from motionlab.core import files, quat
from motionlab.core.motion import Motion

__all__ = ["dumps", "save", "SUFFIX"]

SUFFIX = ".glb"
"""The file ending :func:`save` writes (binary glTF)."""

_FLOAT, _USHORT, _UINT = 5126, 5123, 5125  # glTF componentType codes
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_TYPES = {1: "SCALAR", 3: "VEC3", 4: "VEC4", 16: "MAT4"}
_CODES = {np.dtype(np.float32): _FLOAT, np.dtype(np.uint16): _USHORT, np.dtype(np.uint32): _UINT}

# the 12 triangles of a box whose corner ``4 i + 2 j + k`` is (end i, side j, side k)
_BOX_TRIANGLES = np.array(
    [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
     [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]],
    dtype=np.uint32,
)  # fmt: skip


class _Buffer:
    """The binary chunk under construction, with its bufferViews and accessors."""

    def __init__(self) -> None:
        self.parts: list[bytes] = []
        self.size = 0
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def add(self, array: np.ndarray, width: int, target: int | None = None, bounds: bool = False) -> int:
        """Append ``array`` (rows of ``width`` components) as a new accessor; returns its index."""
        data = np.ascontiguousarray(array).tobytes()
        view = {"buffer": 0, "byteOffset": self.size, "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        pad = -len(data) % 4  # every view starts 4-byte aligned
        self.parts.append(data + b"\0" * pad)
        self.size += len(data) + pad
        self.views.append(view)
        rows = np.asarray(array).reshape(-1, width)
        accessor = {
            "bufferView": len(self.views) - 1,
            "componentType": _CODES[rows.dtype],
            "count": int(rows.shape[0]),
            "type": _TYPES[width],
        }
        if bounds:
            accessor["min"] = [float(v) for v in rows.min(axis=0)]
            accessor["max"] = [float(v) for v in rows.max(axis=0)]
        self.accessors.append(accessor)
        return len(self.accessors) - 1

    def to_bytes(self) -> bytes:
        return b"".join(self.parts)


def _check_motion(motion: Motion) -> None:
    if not isinstance(motion, Motion):
        raise TypeError(f"expected a motionlab Motion, got {type(motion).__name__}")
    if motion.num_frames < 1:
        raise ValueError("cannot write a motion with no frames as glTF: an animation needs at least one keyframe")
    for label, values in (("local_rot", motion.local_rot), ("root_pos", motion.root_pos)):
        if not np.all(np.isfinite(values)):
            frame = int(np.argwhere(~np.isfinite(values))[0, 0])
            raise ValueError(f"motion {motion.name!r}: {label} is not finite at frame {frame}")
    if motion.local_pos is not None and not np.all(np.isfinite(motion.local_pos)):
        frame = int(np.argwhere(~np.isfinite(motion.local_pos))[0, 0])
        raise ValueError(f"motion {motion.name!r}: local_pos is not finite at frame {frame}")
    _check_float32(motion)
    norms = np.linalg.norm(motion.local_rot, axis=-1)
    if np.any(norms < 1e-8):
        frame, joint = (int(v) for v in np.argwhere(norms < 1e-8)[0])
        raise ValueError(
            f"motion {motion.name!r}: local_rot of joint {motion.skeleton.names[joint]!r} at frame {frame} "
            "is a zero quaternion, not a rotation"
        )


_FLOAT32_MAX = float(np.finfo(np.float32).max)


def _check_float32(motion: Motion) -> None:
    """Refuse what float32 accessors cannot hold: lengths beyond float32, or a last key time beyond it."""
    sk = motion.skeleton
    for label, values in (("root_pos", motion.root_pos), ("local_pos", motion.local_pos), ("offsets", sk.offsets)):
        if values is None:
            continue
        big = np.abs(values) > _FLOAT32_MAX / 1e3  # room for the mesh and bind matrices built from them
        if np.any(big):
            where = tuple(int(v) for v in np.argwhere(big)[0])
            raise ValueError(
                f"motion {motion.name!r}: {label} holds {float(values[where]):g} at {where}, beyond what glTF's "
                f"float32 numbers hold (|v| < {_FLOAT32_MAX / 1e3:.3g} m)"
            )
    last = (motion.num_frames - 1) / motion.fps
    if not (np.isfinite(motion.fps) and last < _FLOAT32_MAX):
        raise ValueError(
            f"motion {motion.name!r}: {motion.num_frames} frames at {motion.fps:g} fps end at {last:g} s, "
            "beyond what glTF's float32 key times hold"
        )


def _box_corners(a: np.ndarray, b: np.ndarray, half_width: np.ndarray) -> np.ndarray:
    """The 8 corners (N, 8, 3) of boxes around the segments ``a[n] -> b[n]`` (N, 3), ``half_width[n]`` wide."""
    d = b - a
    d = d / np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1e-12)
    helper = np.where(np.abs(d[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    u = np.cross(d, helper)
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    v = np.cross(d, u)
    ends = np.stack([a, b], axis=1)  # (N, 2, 3)
    side = np.array([-1.0, 1.0])[None, :] * np.asarray(half_width, dtype=np.float64).reshape(-1, 1)  # (N, 2)
    corners = (
        ends[:, :, None, None, :]
        + side[:, None, :, None, None] * u[:, None, None, None, :]
        + side[:, None, None, :, None] * v[:, None, None, None, :]
    )
    return corners.reshape(-1, 8, 3)


def _mesh(motion: Motion) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rest-pose positions (V, 3), joint index per vertex (V,) and triangles (F, 3) of the bone mesh."""
    sk = motion.skeleton
    rest = sk.rest_positions()
    extent = float(np.ptp(rest, axis=0).max()) if sk.num_joints > 1 else 0.0
    size = 0.012 * extent if extent > 0 else 0.01
    # bones: parent joint -> joint, and joint -> end site, each owned by the joint it starts at
    segments = [(int(sk.parents[j]), rest[j]) for j in range(1, sk.num_joints) if np.linalg.norm(sk.offsets[j]) > 1e-9]
    segments += [(j, rest[j] + tip) for j, tip in sk.end_sites.items() if np.linalg.norm(tip) > 1e-9]
    owners = np.array([s[0] for s in segments] + list(range(sk.num_joints)), dtype=np.int64)
    a = np.concatenate([rest[owners[: len(segments)]], rest - [0.0, 1.5 * size, 0.0]])
    b = np.concatenate([np.reshape([s[1] for s in segments], (-1, 3)), rest + [0.0, 1.5 * size, 0.0]])
    widths = np.concatenate([np.full(len(segments), size), np.full(sk.num_joints, 1.5 * size)])
    corners = _box_corners(a, b, widths)
    owner = np.repeat(owners, 8)
    triangles = (_BOX_TRIANGLES[None] + 8 * np.arange(len(a), dtype=np.uint32)[:, None, None]).reshape(-1, 3)
    return corners.reshape(-1, 3), owner, triangles


def _skin_and_mesh(motion: Motion, buf: _Buffer) -> tuple[dict, dict]:
    """The skin (inverse bind matrices) and the skinned bone mesh, written into ``buf``."""
    rest = motion.skeleton.rest_positions()
    inverse_bind = np.tile(np.eye(4), (len(rest), 1, 1))
    inverse_bind[:, :3, 3] = -rest
    # glTF matrices are column-major: the transpose of each row-major 4x4, flattened
    ibm = buf.add(inverse_bind.transpose(0, 2, 1).astype(np.float32), 16)
    skin = {"joints": list(range(len(rest))), "inverseBindMatrices": ibm, "skeleton": 0}
    positions, owner, triangles = _mesh(motion)
    joints = np.zeros((len(owner), 4), dtype=np.uint16)
    joints[:, 0] = owner
    weights = np.zeros((len(owner), 4), dtype=np.float32)
    weights[:, 0] = 1.0
    attributes = {
        "POSITION": buf.add(positions.astype(np.float32), 3, _ARRAY_BUFFER, bounds=True),
        "JOINTS_0": buf.add(joints, 4, _ARRAY_BUFFER),
        "WEIGHTS_0": buf.add(weights, 4, _ARRAY_BUFFER),
    }
    indices = buf.add(triangles.astype(np.uint32).reshape(-1), 1, _ELEMENT_ARRAY_BUFFER)
    mesh = {"name": "bones", "primitives": [{"attributes": attributes, "indices": indices, "material": 0}]}
    return skin, mesh


def _continuous(q: np.ndarray) -> np.ndarray:
    """Quaternions (T, J, 4) with signs flipped so neighbouring frames lie on one hemisphere."""
    if len(q) < 2:
        return q
    flip = np.sum(q[1:] * q[:-1], axis=-1) < 0
    sign = np.concatenate([np.ones((1, q.shape[1])), np.cumprod(np.where(flip, -1.0, 1.0), axis=0)])
    return q * sign[..., None]


def _animation(motion: Motion, buf: _Buffer) -> dict:
    """One animation: a rotation channel per joint, translation for the root (or every joint)."""
    times = buf.add((np.arange(motion.num_frames) / motion.fps).astype(np.float32), 1, bounds=True)
    rotations = quat.to_xyzw(_continuous(quat.normalize(motion.local_rot))).astype(np.float32)
    translations = motion.translations().astype(np.float32)
    moving = range(motion.skeleton.num_joints) if motion.local_pos is not None else [0]
    samplers, channels = [], []
    for j in range(motion.skeleton.num_joints):
        keys = [("rotation", rotations[:, j])] + ([("translation", translations[:, j])] if j in moving else [])
        for path, values in keys:
            output = buf.add(np.ascontiguousarray(values), values.shape[-1])
            samplers.append({"input": times, "output": output, "interpolation": "LINEAR"})
            channels.append({"sampler": len(samplers) - 1, "target": {"node": j, "path": path}})
    return {
        "name": motion.name or "motion",
        "samplers": samplers,
        "channels": channels,
        "extras": {"fps": motion.fps, "frames": motion.num_frames},
    }


def _document(motion: Motion) -> tuple[dict, bytes]:
    """The glTF JSON document and its binary buffer."""
    sk = motion.skeleton
    buf = _Buffer()
    nodes = []
    for j, name in enumerate(sk.names):
        node = {"name": name, "translation": [float(v) for v in sk.offsets[j]]}
        children = sk.children(j)
        if children:
            node["children"] = children
        nodes.append(node)
    skin, mesh = _skin_and_mesh(motion, buf)
    animation = _animation(motion, buf)
    nodes.append({"name": f"{motion.name or 'motion'}_bones", "mesh": 0, "skin": 0})
    doc = {
        "asset": {"version": "2.0", "generator": "motionlab"},
        "scene": 0,
        "scenes": [{"name": motion.name or "motion", "nodes": [0, len(nodes) - 1]}],
        "nodes": nodes,
        "skins": [skin],
        "meshes": [mesh],
        "materials": [
            {
                "name": "bone",
                "pbrMetallicRoughness": {"baseColorFactor": [0.75, 0.78, 0.85, 1.0], "metallicFactor": 0.0},
                "doubleSided": True,
            }
        ],
        "animations": [animation],
        "accessors": buf.accessors,
        "bufferViews": buf.views,
    }
    data = buf.to_bytes()
    doc["buffers"] = [{"byteLength": len(data)}]
    return doc, data


def dumps(motion: Motion) -> bytes:
    """The binary glTF 2.0 (GLB) file of a motion: skeleton, skin, bone mesh and animation.

    Parameters
    ----------
    motion : Motion
        ``local_rot`` (T, J, 4) unit quaternions (w, x, y, z), written as (x, y, z, w);
        ``root_pos`` (T, 3) and offsets in metres, written as they are (glTF is metres, +Y up);
        frame ``k`` is keyed at ``k / fps`` seconds.

    Returns
    -------
    bytes
        A GLB file: header, JSON chunk, binary chunk (see the module docstring for the contents).
        The nodes' own transforms are the rest pose (the bind pose of the skin); the animation
        moves them.

    Raises
    ------
    TypeError
        ``motion`` is not a :class:`~motionlab.core.motion.Motion`.
    ValueError
        The motion has no frames, holds non-finite values, values or key times beyond float32, or
        zero quaternions.
    """
    _check_motion(motion)
    doc, data = _document(motion)
    try:
        text = json.dumps(doc, separators=(",", ":"), allow_nan=False).encode("utf-8")
    except ValueError:  # a number JSON cannot write: never a file that no reader opens
        raise ValueError(
            f"motion {motion.name!r}: a value is not a finite number and cannot be written as glTF"
        ) from None
    text += b" " * (-len(text) % 4)
    data += b"\0" * (-len(data) % 4)
    length = 12 + 8 + len(text) + 8 + len(data)
    header = struct.pack("<4sII", b"glTF", 2, length)
    return header + struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(data), b"BIN\0") + data


def save(path: str | os.PathLike, motion: Motion, overwrite: bool = False) -> Path:
    """Write a motion as a ``.glb`` file (see :func:`dumps`) and return ``Path(path)``.

    The path is checked (suffix, then :func:`~motionlab.core.files.check_output`) before the motion is
    converted, so nothing is written when it is refused;
    the bytes then go through :func:`~motionlab.core.files.atomic_write`.

    Parameters
    ----------
    path : str or PathLike   the destination, ending in ``.glb``
    motion : Motion
    overwrite : bool         replace an existing file (default: refuse)

    Raises
    ------
    ValueError
        ``path`` does not end in ``.glb``, or the motion cannot be written (see :func:`dumps`).
    OSError
        as :func:`motionlab.core.files.check_output` says for ``path``.
    """
    path = Path(path)
    if path.suffix.lower() != SUFFIX:
        raise ValueError(f"a glTF binary file must end in {SUFFIX}, got {path.name!r}")
    files.check_output(path, overwrite, "glTF file")
    data = dumps(motion)
    return files.atomic_write(path, lambda f: f.write(data), overwrite=overwrite, binary=True, what="glTF file")
