"""Forward kinematics and friends, in NumPy.

FK walks the joints once in topological order; every step is vectorised over all leading
dimensions (frames, batches), so there is no Python loop over frames::

    global_rot[j] = global_rot[parent[j]] ⊗ local_rot[j]
    global_pos[j] = global_pos[parent[j]] + rotate(global_rot[parent[j]], local_pos[j])

Taught in ``notebooks/00_quaternions_and_fk.ipynb``. ``fk_torch`` is the torch twin.
"""

from __future__ import annotations

import numpy as np

from motionlab.core import quat

__all__ = ["fk", "fk_positions", "global_to_local", "local_to_global", "bone_directions", "joint_angles"]


def _check_parents(parents, num_joints: int) -> np.ndarray:
    parents = np.asarray(parents, dtype=np.int64)
    if parents.shape != (num_joints,):
        raise ValueError(f"expected {num_joints} parent indices, got shape {parents.shape}")
    # joint 0 is the root; any other order would read joints not yet computed
    index = np.arange(num_joints)
    ok = np.where(index == 0, parents == -1, (parents >= 0) & (parents < index))
    if not np.all(ok):
        j = int(np.flatnonzero(~ok)[0])
        raise ValueError(f"expected parents[0] == -1 and 0 <= parents[j] < j, got parents[{j}] = {int(parents[j])}")
    return parents


def fk(local_rot, local_pos, parents) -> tuple[np.ndarray, np.ndarray]:
    """Forward kinematics: joint transforms relative to the parent -> world.

    Parameters
    ----------
    local_rot : ndarray, shape (..., J, 4)   unit quaternions (w, x, y, z), relative to parent
    local_pos : ndarray, shape (..., J, 3)   offset from the parent joint (root: world position),
                                             metres; leading shapes broadcast with ``local_rot``
    parents   : ndarray of int, shape (J,)   parent index; -1 for the root; parents[j] < j

    Returns
    -------
    global_rot : ndarray, shape (..., J, 4)
    global_pos : ndarray, shape (..., J, 3)
    """
    local_rot = quat.check(local_rot, "local_rot")
    if local_rot.ndim < 2:
        raise ValueError(f"expected local_rot of shape (..., J, 4), got {local_rot.shape}")
    num_joints = local_rot.shape[-2]
    local_pos = np.asarray(local_pos, dtype=local_rot.dtype)
    if local_pos.ndim < 2 or local_pos.shape[-2:] != (num_joints, 3):
        raise ValueError(
            f"expected local_pos of shape (..., {num_joints}, 3) to match local_rot, got {local_pos.shape}"
        )
    parents = _check_parents(parents, num_joints)
    batch = np.broadcast_shapes(local_rot.shape[:-2], local_pos.shape[:-2])
    local_rot = np.broadcast_to(local_rot, batch + local_rot.shape[-2:])
    local_pos = np.broadcast_to(local_pos, batch + local_pos.shape[-2:])
    global_rot = np.empty(batch + (num_joints, 4), dtype=local_rot.dtype)
    global_pos = np.empty(batch + (num_joints, 3), dtype=local_rot.dtype)
    global_rot[..., 0, :] = local_rot[..., 0, :]
    global_pos[..., 0, :] = local_pos[..., 0, :]
    for j in range(1, num_joints):
        p = parents[j]
        global_rot[..., j, :] = quat.mul(global_rot[..., p, :], local_rot[..., j, :])
        global_pos[..., j, :] = global_pos[..., p, :] + quat.rotate(global_rot[..., p, :], local_pos[..., j, :])
    return global_rot, global_pos


def fk_positions(local_rot, local_pos, parents) -> np.ndarray:
    """World joint positions (..., J, 3) only; see :func:`fk`."""
    return fk(local_rot, local_pos, parents)[1]


def local_to_global(local_rot, parents) -> np.ndarray:
    """Global rotations (..., J, 4) from local ones (the rotation half of FK)."""
    local_rot = quat.check(local_rot, "local_rot")
    parents = _check_parents(parents, local_rot.shape[-2])
    out = np.empty_like(local_rot)
    out[..., 0, :] = local_rot[..., 0, :]
    for j in range(1, local_rot.shape[-2]):
        out[..., j, :] = quat.mul(out[..., parents[j], :], local_rot[..., j, :])
    return out


def global_to_local(global_rot, parents) -> np.ndarray:
    """Local rotations (..., J, 4): ``local[j] = global[parent]⁻¹ ⊗ global[j]`` (root unchanged)."""
    global_rot = quat.check(global_rot, "global_rot")
    parents = _check_parents(parents, global_rot.shape[-2])
    out = global_rot.copy()
    out[..., 1:, :] = quat.mul(quat.conj(global_rot[..., parents[1:], :]), global_rot[..., 1:, :])
    return out


def bone_directions(global_pos, parents) -> np.ndarray:
    """Unit vectors (..., J, 3) from each joint's parent to the joint (root and zero bones: 0)."""
    global_pos = np.asarray(global_pos)
    parents = _check_parents(parents, global_pos.shape[-2])
    bones = global_pos - global_pos[..., np.maximum(parents, 0), :]
    bones[..., 0, :] = 0.0
    n = np.linalg.norm(bones, axis=-1, keepdims=True)
    return np.where(n > 1e-9, bones / np.where(n > 1e-9, n, 1.0), 0.0)


def joint_angles(global_pos, parents) -> np.ndarray:
    """Bend angle (..., J) in radians between each bone and its parent bone, from positions alone.

    For joint ``j`` with parent ``p`` and grandparent ``g`` this is the angle between the
    directions ``g→p`` and ``p→j`` (0 = straight, π = folded back). Joints whose parent is the
    root, and zero-length bones, get 0.
    """
    parents = _check_parents(parents, np.shape(global_pos)[-2])
    d = bone_directions(global_pos, parents)
    dp = d[..., np.maximum(parents, 0), :]
    cos = np.clip(np.sum(d * dp, axis=-1), -1.0, 1.0)
    valid = (np.linalg.norm(d, axis=-1) > 0.5) & (np.linalg.norm(dp, axis=-1) > 0.5)
    return np.where(valid, np.arccos(cos), 0.0)
