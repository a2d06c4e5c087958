"""Unit quaternions in NumPy.

Conventions (the whole package follows them; see ``docs/conventions.md``):

* components are ``(w, x, y, z)``, real part first: ``q[..., 0]`` is ``w``;
* the product is Hamilton's (``i * j = k``); ``mul(a, b)`` applies ``b`` first, then ``a``;
* rotations are active and vectors are columns: ``rotate(q, v) == to_matrix(q) @ v``;
* Euler angles follow BVH: ``order="zxy"`` means ``R = Rz @ Rx @ Ry`` (intrinsic, in the
  order the channels are listed), angles in radians;
* every function takes any leading batch shape ``...`` and never modifies its inputs.

``motionlab.core.quat_torch`` has the same functions for torch tensors.
Taught in ``notebooks/00_quaternions_and_fk.ipynb``.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "IDENTITY",
    "EULER_ORDERS",
    "check",
    "mul",
    "conj",
    "inv",
    "normalize",
    "rotate",
    "from_axis_angle",
    "to_axis_angle",
    "from_matrix",
    "to_matrix",
    "from_euler",
    "to_euler",
    "from_xyzw",
    "to_xyzw",
    "slerp",
    "angle_between",
    "canonical",
    "between",
    "yaw",
    "from_yaw",
]

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
"""The identity rotation ``(w, x, y, z) = (1, 0, 0, 0)``."""

EULER_ORDERS = ("xyz", "xzy", "yxz", "yzx", "zxy", "zyx")
"""The six Tait-Bryan orders a BVH ``CHANNELS`` line can use."""

_AXIS = {"x": 0, "y": 1, "z": 2}
_EPS_NORM = 1e-12
_SLERP_NLERP_BELOW = 1e-6  # radians: below this half-angle slerp falls back to nlerp


def _as_float_last(x, size: int, expected: str) -> np.ndarray:
    """``x`` as an array of floats (float64 unless already floating) whose last axis has ``size`` entries."""
    x = np.asarray(x)
    if x.ndim == 0 or x.shape[-1] != size:
        raise ValueError(f"expected {expected}, got shape {x.shape}")
    if not np.issubdtype(x.dtype, np.floating):
        x = x.astype(np.float64)
    return x


def check(q, name: str = "q") -> np.ndarray:
    """Return ``q`` as a float array after checking its last axis has 4 components."""
    return _as_float_last(q, 4, f"{name} as (..., 4) quaternions (w, x, y, z)")


def _check_vec(v, name: str = "v") -> np.ndarray:
    return _as_float_last(v, 3, f"{name} as (..., 3) vectors")


def mul(a, b) -> np.ndarray:
    """Hamilton product ``a ⊗ b`` (rotate by ``b`` first, then by ``a``).

    Parameters
    ----------
    a, b : array, shape (..., 4)   quaternions (w, x, y, z); leading shapes broadcast

    Returns
    -------
    ndarray, shape (..., 4)
    """
    a, b = check(a, "a"), check(b, "b")
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def conj(q) -> np.ndarray:
    """Conjugate ``(w, -x, -y, -z)``; the inverse of a unit quaternion."""
    q = check(q)
    return q * np.array([1.0, -1.0, -1.0, -1.0], dtype=q.dtype)


def inv(q) -> np.ndarray:
    """Inverse ``q* / |q|²`` (equal to :func:`conj` for unit quaternions).

    Raises
    ------
    ValueError for a zero-norm quaternion.
    """
    q = check(q)
    n2 = np.sum(q * q, axis=-1, keepdims=True)
    if np.any(n2 < _EPS_NORM):
        raise ValueError("cannot invert a zero-norm quaternion")
    return conj(q) / n2


def normalize(q, name: str = "q") -> np.ndarray:
    """Scale quaternions to unit length.

    Raises ``ValueError`` for (near) zero-norm input instead of returning NaN.
    """
    q = check(q, name)
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    if np.any(~(n > _EPS_NORM)):
        bad = np.argwhere(~(n[..., 0] > _EPS_NORM))
        raise ValueError(
            f"cannot normalise zero-norm (or NaN) quaternion {name} at index {tuple(int(i) for i in bad[0])}"
        )
    return q / n


def rotate(q, v) -> np.ndarray:
    """Rotate vectors: ``v' = q v q*`` (equal to ``to_matrix(q) @ v``).

    Parameters
    ----------
    q : array, shape (..., 4)   unit quaternions
    v : array, shape (..., 3)   vectors; leading shapes broadcast with ``q``
    """
    q, v = check(q), _check_vec(v)
    w = q[..., :1]
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def from_axis_angle(axis, angle) -> np.ndarray:
    """Quaternion of a rotation by ``angle`` (radians) about ``axis`` (normalised here).

    Parameters
    ----------
    axis : array, shape (..., 3)
    angle : array, shape (...)

    Raises
    ------
    ValueError for a zero-length axis.
    """
    axis = _check_vec(axis, "axis")
    n = np.linalg.norm(axis, axis=-1, keepdims=True)
    if np.any(n < _EPS_NORM):
        raise ValueError("rotation axis has zero length")
    half = 0.5 * np.asarray(angle, dtype=axis.dtype)[..., None]
    return np.concatenate([np.cos(half), np.sin(half) * axis / n], axis=-1)


def to_axis_angle(q) -> tuple[np.ndarray, np.ndarray]:
    """Axis (..., 3) and angle (...) in ``[0, π]`` of unit quaternions.

    The identity returns the x axis and angle 0.
    """
    q = canonical(check(q))
    s = np.linalg.norm(q[..., 1:], axis=-1)
    angle = 2.0 * np.arctan2(s, q[..., 0])
    safe = s > 1e-12
    axis = np.where(safe[..., None], q[..., 1:] / np.where(safe, s, 1.0)[..., None], 0.0)
    axis = np.where(safe[..., None], axis, np.array([1.0, 0.0, 0.0], dtype=q.dtype))
    return axis, angle


def to_matrix(q) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of unit quaternions, acting on column vectors."""
    q = check(q)
    w, x, y, z = np.moveaxis(q, -1, 0)
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz = x * y, x * z, y * z
    wx, wy, wz = w * x, w * y, w * z
    rows = [
        [1 - 2 * (yy + zz), 2 * (xy - wz), 2 * (xz + wy)],
        [2 * (xy + wz), 1 - 2 * (xx + zz), 2 * (yz - wx)],
        [2 * (xz - wy), 2 * (yz + wx), 1 - 2 * (xx + yy)],
    ]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def from_matrix(m) -> np.ndarray:
    """Unit quaternions (w >= 0) of rotation matrices (..., 3, 3); numerically stable branch choice.

    Raises
    ------
    ValueError when ``m`` is not (..., 3, 3), or not a rotation: ``MᵀM`` more than 1e-3 from the
    identity, or a determinant not positive (a reflection).
    """
    m = np.asarray(m)
    if m.ndim < 2 or m.shape[-2:] != (3, 3):
        raise ValueError(f"expected (..., 3, 3) rotation matrices, got shape {m.shape}")
    if not np.issubdtype(m.dtype, np.floating):
        m = m.astype(np.float64)
    off = np.abs(np.swapaxes(m, -1, -2) @ m - np.eye(3)).max(axis=(-2, -1)) if m.size else np.zeros(0)
    if np.any(off > 1e-3) or np.any(np.linalg.det(m) <= 0):
        raise ValueError(
            "expected rotation matrices (orthonormal, determinant +1); a reflection or a scaled matrix has no "
            f"quaternion (largest |MᵀM − I| {float(np.max(off, initial=0.0)):.3g})"
        )
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    # four candidate (unnormalised) quaternions, each accurate where its 4·component² is large
    cand = np.stack(
        [
            np.stack(
                [
                    1 + m00 + m11 + m22,
                    m[..., 2, 1] - m[..., 1, 2],
                    m[..., 0, 2] - m[..., 2, 0],
                    m[..., 1, 0] - m[..., 0, 1],
                ],
                -1,
            ),
            np.stack(
                [
                    m[..., 2, 1] - m[..., 1, 2],
                    1 + m00 - m11 - m22,
                    m[..., 0, 1] + m[..., 1, 0],
                    m[..., 0, 2] + m[..., 2, 0],
                ],
                -1,
            ),
            np.stack(
                [
                    m[..., 0, 2] - m[..., 2, 0],
                    m[..., 0, 1] + m[..., 1, 0],
                    1 - m00 + m11 - m22,
                    m[..., 1, 2] + m[..., 2, 1],
                ],
                -1,
            ),
            np.stack(
                [
                    m[..., 1, 0] - m[..., 0, 1],
                    m[..., 0, 2] + m[..., 2, 0],
                    m[..., 1, 2] + m[..., 2, 1],
                    1 - m00 - m11 + m22,
                ],
                -1,
            ),
        ],
        axis=-2,
    )
    diag = np.stack([1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22], -1)
    best = np.argmax(diag, axis=-1)
    q = np.take_along_axis(cand, best[..., None, None], axis=-2)[..., 0, :]
    return canonical(normalize(q, "from_matrix"))


def _axis_quat(axis: str, angle: np.ndarray) -> np.ndarray:
    half = 0.5 * angle
    q = np.zeros(angle.shape + (4,), dtype=angle.dtype)
    q[..., 0] = np.cos(half)
    q[..., 1 + _AXIS[axis]] = np.sin(half)
    return q


def _check_order(order: str) -> str:
    order = order.lower()
    if order not in EULER_ORDERS:
        raise ValueError(f"Euler order must be one of {EULER_ORDERS}, got {order!r}")
    return order


def from_euler(angles, order: str) -> np.ndarray:
    """Quaternions from intrinsic Euler angles, as BVH channels mean them.

    ``order="zxy"`` with ``angles[..., 0..2] = (az, ax, ay)`` gives ``Rz(az) Rx(ax) Ry(ay)``.

    Parameters
    ----------
    angles : array, shape (..., 3)   radians, in the order the axes are listed in ``order``
    order : str                      one of :data:`EULER_ORDERS`
    """
    order = _check_order(order)
    angles = _check_vec(angles, "angles")
    q0 = _axis_quat(order[0], angles[..., 0])
    q1 = _axis_quat(order[1], angles[..., 1])
    q2 = _axis_quat(order[2], angles[..., 2])
    return mul(mul(q0, q1), q2)


def to_euler(q, order: str) -> np.ndarray:
    """Intrinsic Euler angles (..., 3) in radians, the inverse of :func:`from_euler`.

    The middle angle lies in ``[-π/2, π/2]``; at gimbal lock (middle angle ±π/2) the
    third angle is set to 0 and the first takes the whole remaining rotation.
    """
    order = _check_order(order)
    m = to_matrix(check(q))
    i, j, k = (_AXIS[a] for a in order)
    # sign of the permutation (i, j, k): +1 for cyclic xyz/yzx/zxy, -1 otherwise
    sign = 1.0 if (j - i) % 3 == 1 else -1.0
    # R = R_i(a) R_j(b) R_k(c); then R[i, k] = sign * sin(b)
    # and cos(b) = |(R[i, i], R[i, j])|; atan2 keeps b accurate near ±π/2, where arcsin is not
    sb = np.clip(sign * m[..., i, k], -1.0, 1.0)
    cb = np.hypot(m[..., i, i], m[..., i, j])
    b = np.arctan2(sb, cb)
    a = np.arctan2(-sign * m[..., j, k], m[..., k, k])
    c = np.arctan2(-sign * m[..., i, j], m[..., i, i])
    # a and c come from entries scaled by cos(b): below sqrt(eps) they are noise, so call it locked
    locked = cb < np.sqrt(np.finfo(m.dtype).eps)
    if np.any(locked):
        # c := 0, then R = R_i(a) R_j(±π/2): read a from the j-column
        a_locked = np.arctan2(sign * m[..., k, j], m[..., j, j])
        a = np.where(locked, a_locked, a)
        c = np.where(locked, 0.0, c)
    return np.stack([a, b, c], axis=-1)


def from_xyzw(q) -> np.ndarray:
    """Reorder (x, y, z, w) quaternions (SciPy, ROS, roma) to motionlab's (w, x, y, z)."""
    q = check(q)
    return np.concatenate([q[..., 3:], q[..., :3]], axis=-1)


def to_xyzw(q) -> np.ndarray:
    """Reorder (w, x, y, z) quaternions to (x, y, z, w)."""
    q = check(q)
    return np.concatenate([q[..., 1:], q[..., :1]], axis=-1)


def canonical(q) -> np.ndarray:
    """Pick the sign with ``w >= 0`` (``q`` and ``-q`` are the same rotation)."""
    q = check(q)
    return np.where(q[..., :1] < 0, -q, q)


def slerp(a, b, t) -> np.ndarray:
    """Spherical linear interpolation along the short arc.

    ``slerp(a, b, t) = sin((1-t)Ω)/sin Ω · a + sin(tΩ)/sin Ω · b'`` with ``cos Ω = |a·b|``
    and ``b' = ±b`` on the same hemisphere as ``a``; for tiny Ω it falls back to normalised lerp.

    Parameters
    ----------
    a, b : array, shape (..., 4)   unit quaternions
    t : array, shape (...)         interpolation weights (0 gives ``a``, 1 gives ``±b``)
    """
    a, b = check(a, "a"), check(b, "b")
    t = np.asarray(t, dtype=np.result_type(a.dtype, b.dtype))[..., None]
    dot = np.sum(a * b, axis=-1, keepdims=True)
    b = np.where(dot < 0, -b, b)
    dot = np.clip(np.abs(dot), 0.0, 1.0)
    omega = np.arccos(dot)
    sin_omega = np.sin(omega)
    small = omega < _SLERP_NLERP_BELOW
    safe_sin = np.where(small, 1.0, sin_omega)
    wa = np.where(small, 1.0 - t, np.sin((1.0 - t) * omega) / safe_sin)
    wb = np.where(small, t, np.sin(t * omega) / safe_sin)
    out = wa * a + wb * b
    return out / np.linalg.norm(out, axis=-1, keepdims=True)


def angle_between(a, b) -> np.ndarray:
    """Geodesic angle (radians, in ``[0, π]``) of the rotation taking ``a`` to ``b``."""
    a, b = check(a, "a"), check(b, "b")
    d = mul(conj(a), b)  # atan2 rather than arccos of the dot product: accurate near 0 too
    return 2.0 * np.arctan2(np.linalg.norm(d[..., 1:], axis=-1), np.abs(d[..., 0]))


def between(u, v) -> np.ndarray:
    """Shortest-arc unit quaternion rotating direction ``u`` onto direction ``v``.

    Antiparallel inputs rotate by π about an axis perpendicular to ``u``.
    """
    u, v = _check_vec(u, "u"), _check_vec(v, "v")
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    u, v = np.broadcast_arrays(u, v)
    w = 1.0 + np.sum(u * v, axis=-1, keepdims=True)
    xyz = np.cross(u, v)
    anti = np.sqrt(w[..., 0] ** 2 + np.sum(xyz * xyz, axis=-1)) < 1e-12  # exactly opposite, to rounding
    if np.any(anti):
        helper = np.where(np.abs(u[..., :1]) < 0.9, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
        perp = np.cross(u, helper)
        xyz = np.where(anti[..., None], perp, xyz)
        w = np.where(anti[..., None], 0.0, w)
    return normalize(np.concatenate([w, xyz], axis=-1))


def yaw(q) -> np.ndarray:
    """Heading angle (radians) about +Y of each rotation: where it sends the +Z axis, projected."""
    q = check(q)
    fwd = rotate(q, np.array([0.0, 0.0, 1.0], dtype=q.dtype))
    return np.arctan2(fwd[..., 0], fwd[..., 2])


def from_yaw(angle) -> np.ndarray:
    """Rotation by ``angle`` radians about the vertical +Y axis, shape (..., 4)."""
    angle = np.asarray(angle, dtype=np.float64)
    return _axis_quat("y", angle)
