"""An independent glTF reader for the tests: pygltflib parses the file, and the joint positions
are computed here from the nodes and the animation samplers (own TRS matrices, own quaternion
to matrix), never with motionlab's FK or quaternion code.

Every test that writes a ``.glb`` checks it with :func:`assert_glb_matches`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pygltflib

_DTYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
_WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def read(path_or_bytes) -> pygltflib.GLTF2:
    """Parse a GLB file (a path or its bytes) with pygltflib."""
    if isinstance(path_or_bytes, (bytes, bytearray)):
        return pygltflib.GLTF2.load_from_bytes(bytes(path_or_bytes))
    return pygltflib.GLTF2.load_binary(str(Path(path_or_bytes)))


def accessor(gltf: pygltflib.GLTF2, index: int) -> np.ndarray:
    """The rows (count, width) of accessor ``index``, read from the binary chunk."""
    acc = gltf.accessors[index]
    view = gltf.bufferViews[acc.bufferView]
    blob = gltf.binary_blob()
    dtype = np.dtype(_DTYPES[acc.componentType])
    width = _WIDTHS[acc.type]
    start = (view.byteOffset or 0) + (acc.byteOffset or 0)
    assert view.byteStride in (None, 0, width * dtype.itemsize), "the reader handles packed views only"
    return np.frombuffer(blob, dtype=dtype, count=acc.count * width, offset=start).reshape(acc.count, width)


def _rotation_matrix(xyzw: np.ndarray) -> np.ndarray:
    """3x3 matrix of an (x, y, z, w) unit quaternion (the glTF order), written out from scratch."""
    x, y, z, w = np.asarray(xyzw, dtype=np.float64) / np.linalg.norm(xyzw)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _trs(translation, rotation, scale) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = _rotation_matrix(rotation) * np.asarray(scale, dtype=np.float64)[None, :]
    m[:3, 3] = translation
    return m


def world_matrices(gltf: pygltflib.GLTF2, frame: int, animation: int = 0) -> np.ndarray:
    """World 4x4 matrix of every node at keyframe ``frame`` of ``animation`` (nodes not animated keep their TRS)."""
    n = len(gltf.nodes)
    trs = [
        [list(node.translation or [0, 0, 0]), list(node.rotation or [0, 0, 0, 1]), list(node.scale or [1, 1, 1])]
        for node in gltf.nodes
    ]
    anim = gltf.animations[animation]
    slot = {"translation": 0, "rotation": 1, "scale": 2}
    for channel in anim.channels:
        sampler = anim.samplers[channel.sampler]
        times = accessor(gltf, sampler.input)[:, 0]
        assert 0 <= frame < len(times), f"frame {frame} outside the {len(times)} keyframes"
        trs[channel.target.node][slot[channel.target.path]] = accessor(gltf, sampler.output)[frame].astype(float)
    parent = [-1] * n
    for i, node in enumerate(gltf.nodes):
        for c in node.children or []:
            parent[c] = i
    world: list[np.ndarray | None] = [None] * n

    def resolve(i: int) -> np.ndarray:
        if world[i] is None:
            local = _trs(*trs[i])
            world[i] = local if parent[i] < 0 else resolve(parent[i]) @ local
        return world[i]

    return np.stack([resolve(i) for i in range(n)])


def assert_glb_matches(path_or_bytes, motion, frames=None, rel_tol: float = 1e-4) -> pygltflib.GLTF2:
    """Check a GLB file against ``motion``: joint names and hierarchy, frame times ``k / fps``, world
    joint positions at several frames (to ``rel_tol`` of the body height), and the skin (each joint's
    cube, skinned with the inverse bind matrices, sits on the joint). Returns the parsed file."""
    gltf = read(path_or_bytes)
    sk = motion.skeleton
    skin = gltf.skins[0]
    joints = list(skin.joints)
    assert [gltf.nodes[j].name for j in joints] == list(sk.names)
    for j in range(1, sk.num_joints):
        assert joints[sk.parents[j]] in [i for i, node in enumerate(gltf.nodes) if joints[j] in (node.children or [])]
    times = accessor(gltf, gltf.animations[0].samplers[0].input)[:, 0]
    np.testing.assert_allclose(times, np.arange(motion.num_frames) / motion.fps, rtol=1e-6, atol=1e-6)
    if frames is None:
        frames = sorted({0, motion.num_frames // 3, motion.num_frames // 2, motion.num_frames - 1})
    expected = motion.global_positions()
    tol = rel_tol * max(sk.height(), 1e-3)
    inverse_bind = accessor(gltf, skin.inverseBindMatrices).reshape(-1, 4, 4).transpose(0, 2, 1).astype(float)
    primitive = gltf.meshes[0].primitives[0]
    positions = accessor(gltf, primitive.attributes.POSITION).astype(float)
    rest = np.c_[positions, np.ones(len(positions))]
    owner = accessor(gltf, primitive.attributes.JOINTS_0)[:, 0].astype(int)
    for k in frames:
        world = world_matrices(gltf, k)[joints]
        got = world[:, :3, 3]
        err = np.abs(got - expected[k]).max()
        assert err <= tol, f"frame {k}: joint positions {err:.3g} m off (tolerance {tol:.3g} m)"
        skinned = np.einsum("vab,vb->va", (world @ inverse_bind)[owner], rest)[:, :3]
        cubes = skinned[-8 * sk.num_joints :].reshape(sk.num_joints, 8, 3).mean(axis=1)
        err = np.abs(cubes - expected[k]).max()
        assert err <= tol, f"frame {k}: skinned joint cubes {err:.3g} m off (tolerance {tol:.3g} m)"
    return gltf
