"""Unit quaternions in torch: the twin of :mod:`motionlab.core.quat`, same names and conventions.

``(w, x, y, z)``, Hamilton product, active rotations, BVH (intrinsic) Euler orders, any leading
batch shape. Everything is differentiable; :func:`normalize` and :func:`slerp` keep gradients
finite at the identity and at zero-angle interpolation. Tests check each function against NumPy.

Devices and float types: outputs follow the input tensors (every tensor made inside takes the
device and dtype of an input). An input that is not a tensor (an array, a list, a number) becomes
a tensor on torch's default device, so pass tensors to compute on a GPU. :data:`IDENTITY` is a
float32 CPU constant: use ``IDENTITY.to(x)``.
"""

from __future__ import annotations

import torch

from motionlab.core.quat import EULER_ORDERS

__all__ = [
    "IDENTITY",
    "EULER_ORDERS",
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
    "slerp",
    "angle_between",
    "canonical",
    "yaw",
    "from_yaw",
]

IDENTITY = torch.tensor([1.0, 0.0, 0.0, 0.0])
"""The identity rotation ``(1, 0, 0, 0)`` (float32; use ``.to(x)`` to match another tensor)."""

_AXIS = {"x": 0, "y": 1, "z": 2}
_EPS_NORM = 1e-12


def _check(q: torch.Tensor, name: str = "q", last: int = 4) -> torch.Tensor:
    if not isinstance(q, torch.Tensor):
        q = torch.as_tensor(q, dtype=torch.get_default_dtype())
    elif not q.is_floating_point():  # integers would truncate every weight and angle (the NumPy twin's rule)
        q = q.to(torch.get_default_dtype())
    if q.ndim == 0 or q.shape[-1] != last:
        kind = "quaternions (w, x, y, z)" if last == 4 else "vectors"
        raise ValueError(f"expected {name} as (..., {last}) {kind}, got shape {tuple(q.shape)}")
    return q


def mul(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """Hamilton product ``a ⊗ b`` of (..., 4) tensors (rotate by ``b`` first, then ``a``)."""
    a, b = _check(a, "a"), _check(b, "b")
    aw, ax, ay, az = a.unbind(-1)
    bw, bx, by, bz = b.unbind(-1)
    return torch.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        dim=-1,
    )


def conj(q: torch.Tensor) -> torch.Tensor:
    """Conjugate ``(w, -x, -y, -z)``."""
    q = _check(q)
    return torch.cat([q[..., :1], -q[..., 1:]], dim=-1)


def inv(q: torch.Tensor) -> torch.Tensor:
    """Inverse ``q* / |q|²``.

    Raises
    ------
    ValueError for a zero-norm quaternion.
    """
    q = _check(q)
    n2 = (q * q).sum(-1, keepdim=True)
    if bool((n2 < _EPS_NORM).any()):
        raise ValueError("cannot invert a zero-norm quaternion")
    return conj(q) / n2


def normalize(q: torch.Tensor, name: str = "q", check_zero: bool = True) -> torch.Tensor:
    """Unit-length quaternions.

    With ``check_zero`` (default) a zero-norm input raises ``ValueError``; network heads pass
    ``check_zero=False`` to skip the host sync, and get a tiny epsilon in the denominator.
    """
    q = _check(q, name)
    n = q.norm(dim=-1, keepdim=True)
    if check_zero and bool((~(n > _EPS_NORM)).any()):
        raise ValueError(f"cannot normalise zero-norm (or NaN) quaternion {name}")
    return q / n.clamp_min(_EPS_NORM)


def rotate(q: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """Rotate (..., 3) vectors by (..., 4) unit quaternions: ``v' = q v q*``."""
    q, v = _check(q), _check(v, "v", 3)
    w = q[..., :1]
    u = q[..., 1:]
    u, v = torch.broadcast_tensors(u, v)
    t = 2.0 * torch.linalg.cross(u, v, dim=-1)
    return v + w * t + torch.linalg.cross(u, t, dim=-1)


def from_axis_angle(axis: torch.Tensor, angle: torch.Tensor) -> torch.Tensor:
    """Quaternion of a rotation by ``angle`` (radians, shape ``(...)``) about ``axis`` (..., 3)."""
    axis = _check(axis, "axis", 3)
    axis = axis / axis.norm(dim=-1, keepdim=True).clamp_min(_EPS_NORM)
    half = 0.5 * torch.as_tensor(angle, dtype=axis.dtype, device=axis.device)[..., None]
    return torch.cat([torch.cos(half), torch.sin(half) * axis], dim=-1)


def to_axis_angle(q: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Axis (..., 3) and angle (...) in ``[0, π]``; the identity returns the x axis, angle 0."""
    q = canonical(_check(q))
    s = q[..., 1:].norm(dim=-1)
    angle = 2.0 * torch.atan2(s, q[..., 0])
    safe = s > 1e-12
    x_axis = torch.zeros_like(q[..., 1:])
    x_axis[..., 0] = 1.0
    axis = torch.where(safe[..., None], q[..., 1:] / torch.where(safe, s, torch.ones_like(s))[..., None], x_axis)
    return axis, angle


def to_matrix(q: torch.Tensor) -> torch.Tensor:
    """Rotation matrices (..., 3, 3) acting on column vectors."""
    q = _check(q)
    w, x, y, z = q.unbind(-1)
    xx, yy, zz = x * x, y * y, z * z
    xy, xz, yz = x * y, x * z, y * z
    wx, wy, wz = w * x, w * y, w * z
    return torch.stack(
        [
            1 - 2 * (yy + zz),
            2 * (xy - wz),
            2 * (xz + wy),
            2 * (xy + wz),
            1 - 2 * (xx + zz),
            2 * (yz - wx),
            2 * (xz - wy),
            2 * (yz + wx),
            1 - 2 * (xx + yy),
        ],
        dim=-1,
    ).reshape(q.shape[:-1] + (3, 3))


# Intended twin of quat.from_matrix (§2: torch twins keep the algorithm; tests/core/test_quat_torch.py pins them equal).
def from_matrix(m: torch.Tensor) -> torch.Tensor:
    """Unit quaternions (w >= 0) of (..., 3, 3) rotation matrices.

    Raises
    ------
    ValueError when ``m`` is not (..., 3, 3), or not a rotation: ``MᵀM`` more than 1e-3 from the
    identity, or a determinant not positive (a reflection).
    """
    if m.ndim < 2 or tuple(m.shape[-2:]) != (3, 3):
        raise ValueError(f"expected (..., 3, 3) rotation matrices, got shape {tuple(m.shape)}")
    if not m.is_floating_point():
        m = m.to(torch.get_default_dtype())
    if m.numel():
        off = (m.transpose(-1, -2) @ m - torch.eye(3, dtype=m.dtype, device=m.device)).abs().amax(dim=(-2, -1))
        if bool((off > 1e-3).any()) or bool((torch.linalg.det(m) <= 0).any()):
            raise ValueError(
                "expected rotation matrices (orthonormal, determinant +1); a reflection or a scaled matrix has no "
                f"quaternion (largest |MᵀM − I| {float(off.max()):.3g})"
            )
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    cand = torch.stack(
        [
            torch.stack(
                [
                    1 + m00 + m11 + m22,
                    m[..., 2, 1] - m[..., 1, 2],
                    m[..., 0, 2] - m[..., 2, 0],
                    m[..., 1, 0] - m[..., 0, 1],
                ],
                -1,
            ),
            torch.stack(
                [
                    m[..., 2, 1] - m[..., 1, 2],
                    1 + m00 - m11 - m22,
                    m[..., 0, 1] + m[..., 1, 0],
                    m[..., 0, 2] + m[..., 2, 0],
                ],
                -1,
            ),
            torch.stack(
                [
                    m[..., 0, 2] - m[..., 2, 0],
                    m[..., 0, 1] + m[..., 1, 0],
                    1 - m00 + m11 - m22,
                    m[..., 1, 2] + m[..., 2, 1],
                ],
                -1,
            ),
            torch.stack(
                [
                    m[..., 1, 0] - m[..., 0, 1],
                    m[..., 0, 2] + m[..., 2, 0],
                    m[..., 1, 2] + m[..., 2, 1],
                    1 - m00 - m11 + m22,
                ],
                -1,
            ),
        ],
        dim=-2,
    )
    diag = torch.stack([1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22], -1)
    best = diag.argmax(-1)
    q = torch.gather(cand, -2, best[..., None, None].expand(*best.shape, 1, 4))[..., 0, :]
    return canonical(normalize(q, "from_matrix", check_zero=False))


def _axis_quat(axis: str, angle: torch.Tensor) -> torch.Tensor:
    half = 0.5 * angle
    zero = torch.zeros_like(half)
    comps = [torch.cos(half), zero, zero, zero]
    comps[1 + _AXIS[axis]] = torch.sin(half)
    return torch.stack(comps, dim=-1)


def _check_order(order: str) -> str:
    order = order.lower()
    if order not in EULER_ORDERS:
        raise ValueError(f"Euler order must be one of {EULER_ORDERS}, got {order!r}")
    return order


def from_euler(angles: torch.Tensor, order: str) -> torch.Tensor:
    """Quaternions from intrinsic (BVH) Euler angles (..., 3) in radians; see ``quat.from_euler``."""
    order = _check_order(order)
    angles = _check(angles, "angles", 3)
    q0 = _axis_quat(order[0], angles[..., 0])
    q1 = _axis_quat(order[1], angles[..., 1])
    q2 = _axis_quat(order[2], angles[..., 2])
    return mul(mul(q0, q1), q2)


def to_euler(q: torch.Tensor, order: str) -> torch.Tensor:
    """Intrinsic Euler angles (..., 3), the inverse of :func:`from_euler`; see ``quat.to_euler``."""
    order = _check_order(order)
    m = to_matrix(_check(q))
    i, j, k = (_AXIS[a] for a in order)
    sign = 1.0 if (j - i) % 3 == 1 else -1.0
    sb = (sign * m[..., i, k]).clamp(-1.0, 1.0)
    cb = torch.hypot(m[..., i, i], m[..., i, j])
    b = torch.atan2(sb, cb)  # accurate near ±π/2, where asin is not
    a = torch.atan2(-sign * m[..., j, k], m[..., k, k])
    c = torch.atan2(-sign * m[..., i, j], m[..., i, i])
    locked = cb < torch.finfo(m.dtype).eps ** 0.5
    a = torch.where(locked, torch.atan2(sign * m[..., k, j], m[..., j, j]), a)
    c = torch.where(locked, torch.zeros_like(c), c)
    return torch.stack([a, b, c], dim=-1)


def canonical(q: torch.Tensor) -> torch.Tensor:
    """Pick the sign with ``w >= 0``."""
    q = _check(q)
    return torch.where(q[..., :1] < 0, -q, q)


def slerp(a: torch.Tensor, b: torch.Tensor, t: torch.Tensor | float) -> torch.Tensor:
    """Short-arc spherical linear interpolation; nlerp below a tiny angle (finite gradients)."""
    a, b = _check(a, "a"), _check(b, "b")
    t = torch.as_tensor(t, dtype=a.dtype, device=a.device)[..., None]
    dot = (a * b).sum(-1, keepdim=True)
    b = torch.where(dot < 0, -b, b)
    dot = dot.abs().clamp(0.0, 1.0 - 1e-7)
    omega = torch.acos(dot)
    small = omega < 1e-3
    sin_omega = torch.where(small, torch.ones_like(omega), torch.sin(omega))
    wa = torch.where(small, 1.0 - t, torch.sin((1.0 - t) * omega) / sin_omega)
    wb = torch.where(small, t, torch.sin(t * omega) / sin_omega)
    out = wa * a + wb * b
    return out / out.norm(dim=-1, keepdim=True).clamp_min(_EPS_NORM)


def angle_between(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """Geodesic angle in ``[0, π]`` between rotations (gradient-safe near 0 via atan2)."""
    a, b = _check(a, "a"), _check(b, "b")
    d = mul(conj(a), b)
    return 2.0 * torch.atan2(d[..., 1:].norm(dim=-1), d[..., 0].abs())


def yaw(q: torch.Tensor) -> torch.Tensor:
    """Heading angle about +Y: where each rotation sends +Z, projected on the ground."""
    z = torch.zeros(q.shape[:-1] + (3,), dtype=q.dtype, device=q.device)
    z[..., 2] = 1.0
    fwd = rotate(q, z)
    return torch.atan2(fwd[..., 0], fwd[..., 2])


def from_yaw(angle: torch.Tensor) -> torch.Tensor:
    """Rotation by ``angle`` about +Y, shape (..., 4)."""
    return _axis_quat("y", torch.as_tensor(angle))
