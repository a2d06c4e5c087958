"""Forward kinematics and friends, in NumPy.

FK walks the joints once in topological order; every step is vectorised over all leading
dimensions (frames, batches), so there is no Python loop over frames (:func:`fk` works on
blocks of frames laid out component by component, so each step is one long vector operation)::

    global_rot[j] = global_rot[parent[j]] ⊗ local_rot[j]
    global_pos[j] = global_pos[parent[j]] + rotate(global_rot[parent[j]], local_pos[j])

Taught in ``notebooks/00_quaternions_and_fk.ipynb``. ``fk_torch`` is the torch twin.
"""

from __future__ import annotations

import math

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

    Raises
    ------
    ValueError when ``local_rot`` is not (..., J, 4) or ``local_pos`` not (..., J, 3) for the
    same J.
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
    n = math.prod(batch)
    rot = np.broadcast_to(local_rot, batch + (num_joints, 4)).reshape(n, num_joints, 4)
    pos = np.broadcast_to(local_pos, batch + (num_joints, 3)).reshape(n, num_joints, 3)
    global_rot = np.empty((n, num_joints, 4), dtype=local_rot.dtype)
    global_pos = np.empty((n, num_joints, 3), dtype=local_rot.dtype)
    for start in range(0, n, _CHUNK):
        stop = min(start + _CHUNK, n)
        _fk_block(rot[start:stop], pos[start:stop], parents, global_rot[start:stop], global_pos[start:stop])
    return global_rot.reshape(batch + (num_joints, 4)), global_pos.reshape(batch + (num_joints, 3))


_CHUNK = 2048
"""Frames per block of :func:`fk`: a 22-joint block's rows stay in the CPU cache."""


def _fk_block(rot, pos, parents, out_rot, out_pos) -> None:
    """FK of ``m`` frames, component-major: each quaternion or vector component of a joint is one
    contiguous row of ``m`` frames, so every step is one long vector operation.

    ``rot`` (m, J, 4) and ``pos`` (m, J, 3) in; ``out_rot`` (m, J, 4) and ``out_pos`` (m, J, 3)
    are written. Per joint ``j`` with parent ``p``: ``g[j] = g[p] ⊗ q[j]`` and
    ``x[j] = x[p] + v + w t + u × t`` with ``t = 2 u × v``, ``(w, u) = g[p]``, ``v`` = local offset.
    """
    m, num_joints = rot.shape[:2]
    q = np.ascontiguousarray(rot.reshape(m, num_joints * 4).T).reshape(num_joints, 4, m)
    v = np.ascontiguousarray(pos.reshape(m, num_joints * 3).T).reshape(num_joints, 3, m)
    g = np.empty_like(q)
    x = np.empty_like(v)
    g[0] = q[0]
    x[0] = v[0]
    t = np.empty((3, m), dtype=q.dtype)
    tmp = np.empty(m, dtype=q.dtype)
    for j in range(1, num_joints):
        p = parents[j]
        aw, ax, ay, az = g[p]
        bw, bx, by, bz = q[j]
        vx, vy, vz = v[j]
        # t = 2 u × v
        np.multiply(ay, vz, out=t[0])
        t[0] -= np.multiply(az, vy, out=tmp)
        np.multiply(az, vx, out=t[1])
        t[1] -= np.multiply(ax, vz, out=tmp)
        np.multiply(ax, vy, out=t[2])
        t[2] -= np.multiply(ay, vx, out=tmp)
        t *= 2.0
        # x[j] = x[p] + v + w t + u × t
        xj = x[j]
        np.add(x[p], v[j], out=xj)
        xj += np.multiply(aw, t, out=np.empty_like(t))
        xj[0] += np.multiply(ay, t[2], out=tmp)
        xj[0] -= np.multiply(az, t[1], out=tmp)
        xj[1] += np.multiply(az, t[0], out=tmp)
        xj[1] -= np.multiply(ax, t[2], out=tmp)
        xj[2] += np.multiply(ax, t[1], out=tmp)
        xj[2] -= np.multiply(ay, t[0], out=tmp)
        # g[j] = g[p] ⊗ q[j]  (Hamilton product, as quat.mul)
        gw, gx, gy, gz = g[j]
        np.multiply(aw, bw, out=gw)
        gw -= np.multiply(ax, bx, out=tmp)
        gw -= np.multiply(ay, by, out=tmp)
        gw -= np.multiply(az, bz, out=tmp)
        np.multiply(aw, bx, out=gx)
        gx += np.multiply(ax, bw, out=tmp)
        gx += np.multiply(ay, bz, out=tmp)
        gx -= np.multiply(az, by, out=tmp)
        np.multiply(aw, by, out=gy)
        gy -= np.multiply(ax, bz, out=tmp)
        gy += np.multiply(ay, bw, out=tmp)
        gy += np.multiply(az, bx, out=tmp)
        np.multiply(aw, bz, out=gz)
        gz += np.multiply(ax, by, out=tmp)
        gz -= np.multiply(ay, bx, out=tmp)
        gz += np.multiply(az, bw, out=tmp)
    out_rot.reshape(m, num_joints * 4).T[...] = g.reshape(num_joints * 4, m)
    out_pos.reshape(m, num_joints * 3).T[...] = x.reshape(num_joints * 3, m)


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
    """Unit vectors (..., J, 3) from each joint's parent to the joint (root and zero bones: 0; a
    bone with a position that is not finite: NaN)."""
    global_pos = np.asarray(global_pos)
    parents = _check_parents(parents, global_pos.shape[-2])
    bones = global_pos - global_pos[..., np.maximum(parents, 0), :]
    bones[..., 0, :] = 0.0
    n = np.linalg.norm(bones, axis=-1, keepdims=True)
    return np.where((n > 1e-9) | np.isnan(n), bones / np.where(n > 1e-9, n, 1.0), 0.0)


def joint_angles(global_pos, parents) -> np.ndarray:
    """Bend angle (..., J) in radians between each bone and its parent bone, from positions alone.

    For joint ``j`` with parent ``p`` and grandparent ``g`` this is the angle between the
    directions ``g→p`` and ``p→j`` (0 = straight, π = folded back). Joints whose parent is the
    root, and zero-length bones, get 0; a bone with a position that is not finite, NaN.
    """
    parents = _check_parents(parents, np.shape(global_pos)[-2])
    d = bone_directions(global_pos, parents)
    dp = d[..., np.maximum(parents, 0), :]
    cos = np.clip(np.sum(d * dp, axis=-1), -1.0, 1.0)
    valid = (np.linalg.norm(d, axis=-1) > 0.5) & (np.linalg.norm(dp, axis=-1) > 0.5)
    return np.where(valid | np.isnan(cos), np.arccos(cos), 0.0)
