"""In-betweening: fill N frames between two known poses, batched over many gaps at once.

A pose is ``m(t) = [h(t), r_1(t) … r_J(t)]``: the root position ``h`` and every joint's local
rotation. Between the last known frame ``a`` and the next known frame ``b``:

* rotations: SLERP (:mod:`motionlab.interpolation.slerp`) with a chosen α(k), or
  ``"hermite"``: the rotation vector relative to ``q_a`` follows the cubic Hermite curve from 0 to
  ``d = log(q_a⁻¹ q_b)`` whose end slopes are the angular velocities seen just before and just
  after the gap, ``q(s) = q_a ⊗ exp(h₁₀(s) ω_a H + h₀₁(s) d + h₁₁(s) ω_b H)``, each counted over
  ``H = min(L, horizon)`` frames (:data:`ANGULAR_HORIZON`: a velocity says how a joint goes on for a
  while, not across a long gap); with no ``ω_b``, the quadratic
  ``exp(ω_a H s + (d − ω_a H) s²)``; when ``ω_a H = ω_b H = d`` either *is* SLERP;
* root: linear, or ``"hermite"``: a cubic Hermite curve whose end tangents are the root velocities
  before and after the gap (``p'(0) = v_a L``, ``p'(1) = v_b L``, ``L = N + 1``); with no ``v_b``
  the curve is the quadratic through both ends with start slope ``v_a L``.

``interpolate`` works on plain arrays with any leading batch shape: one call fills every window of
a benchmark. :func:`fill_between` and :func:`inbetween` are the :class:`~motionlab.core.motion.Motion`
wrappers.

Taught in ``notebooks/06_keypose_interpolation.ipynb``.
"""

from __future__ import annotations

import numpy as np

from motionlab.core import quat
from motionlab.core.motion import Motion
from motionlab.interpolation import alignment
from motionlab.interpolation.slerp import alphas

__all__ = [
    "ANGULAR_HORIZON",
    "ROOT_MODES",
    "ROTATION_MODES",
    "interpolate",
    "zero_velocity",
    "fill_between",
    "inbetween",
    "log",
    "exp",
    "concatenate",
]

ROOT_MODES = ("linear", "hermite")
ROTATION_MODES = ("slerp", "hermite")


def log(q) -> np.ndarray:
    """Rotation vectors (..., 3) of unit quaternions: axis × angle, angle in [0, π] (short arc)."""
    q = quat.canonical(quat.check(q))
    s = np.linalg.norm(q[..., 1:], axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, q[..., :1])
    scale = np.where(s > 1e-12, angle / np.where(s > 1e-12, s, 1.0), 2.0)
    return q[..., 1:] * scale


def exp(v) -> np.ndarray:
    """Unit quaternions (..., 4) of rotation vectors (..., 3) (inverse of :func:`log`)."""
    v = np.asarray(v, dtype=np.float64)
    angle = np.linalg.norm(v, axis=-1, keepdims=True)
    half = 0.5 * angle
    sinc = np.where(angle > 1e-12, np.sin(half) / np.where(angle > 1e-12, angle, 1.0), 0.5)
    return np.concatenate([np.cos(half), v * sinc], axis=-1)


ANGULAR_HORIZON = 14 / 30
"""Seconds over which ``"hermite"`` rotations follow the angular velocities at a gap's ends (14
frames at 30 fps), chosen on clips kept apart from those it is scored on
(``python -m experiments.interpolation.hermite_horizon``, docs/results_interpolation.md)."""


def _check_pair(rot_a, pos_a, rot_b, pos_b):
    rot_a, rot_b = quat.check(rot_a, "rot_a"), quat.check(rot_b, "rot_b")
    pos_a, pos_b = np.asarray(pos_a, dtype=np.float64), np.asarray(pos_b, dtype=np.float64)
    if rot_a.shape != rot_b.shape or rot_a.ndim < 2:
        raise ValueError(f"expected rot_a and rot_b of equal shape (..., J, 4), got {rot_a.shape} and {rot_b.shape}")
    if pos_a.shape != rot_a.shape[:-2] + (3,) or pos_b.shape != pos_a.shape:
        raise ValueError(
            f"expected root positions of shape {rot_a.shape[:-2] + (3,)} to match rotations {rot_a.shape}, "
            f"got {pos_a.shape} and {pos_b.shape}"
        )
    return rot_a, pos_a, rot_b, pos_b


def interpolate(
    rot_a,
    pos_a,
    rot_b,
    pos_b,
    num: int,
    curve: str = "linear",
    root: str = "linear",
    rotation: str = "slerp",
    vel_a=None,
    vel_b=None,
    ang_vel_a=None,
    ang_vel_b=None,
    horizon: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The ``num`` frames between pose ``a`` and pose ``b``.

    Parameters
    ----------
    rot_a, rot_b : array, shape (..., J, 4)   local rotations (w, x, y, z) at the bounding frames
    pos_a, pos_b : array, shape (..., 3)      root positions, metres
    num : int                                 N, frames to create (>= 0)
    curve : str                               α(k) for ``slerp``/``linear`` (see ``slerp.alphas``)
    root : ``"linear"`` or ``"hermite"``
    rotation : ``"slerp"`` or ``"hermite"``
    vel_a, vel_b : array (..., 3), optional   root velocity (metres/frame) just before / after
    ang_vel_a : array (..., J, 3), optional   rotation vector per frame just before the gap, in each
                                              joint's own frame: ``log(q[t-1]⁻¹ q[t])``
    ang_vel_b : array (..., J, 3), optional   the same just after the gap: ``log(q[t]⁻¹ q[t+1])``
    horizon : float, optional                 frames over which the angular velocities count
                                              (``H = min(N + 1, horizon)``); None: the whole gap

    Returns
    -------
    rot : ndarray, shape (..., N, J, 4)
    pos : ndarray, shape (..., N, 3)

    Raises
    ------
    ValueError for an unknown ``root`` or ``rotation`` mode, root or angular velocities of the
    wrong shape, or a horizon that is not a positive number.
    """
    rot_a, pos_a, rot_b, pos_b = _check_pair(rot_a, pos_a, rot_b, pos_b)
    if root not in ROOT_MODES:
        raise ValueError(f"root interpolation must be one of {ROOT_MODES}, got {root!r}")
    if rotation not in ROTATION_MODES:
        raise ValueError(f"rotation interpolation must be one of {ROTATION_MODES}, got {rotation!r}")
    a = alphas(num, curve)  # (N,)
    length = num + 1
    s = np.arange(1, num + 1, dtype=np.float64) / length  # plain time fraction for Hermite curves

    # ---- rotations: (..., N, J, 4)
    qa, qb = rot_a[..., None, :, :], rot_b[..., None, :, :]
    if rotation == "slerp" or ang_vel_a is None:
        rot = quat.slerp(qa, qb, a[:, None])
    else:
        rot = quat.mul(qa, exp(_hermite_rotvec(rot_a, rot_b, ang_vel_a, ang_vel_b, s, _span(length, horizon))))

    # ---- root: (..., N, 3)
    pa, pb = pos_a[..., None, :], pos_b[..., None, :]
    if root == "linear" or vel_a is None:
        pos = pa + a[:, None] * (pb - pa)
    else:
        for name, v in (("vel_a", vel_a), ("vel_b", vel_b)):
            if v is not None and np.shape(v) != pos_a.shape:
                raise ValueError(f"expected {name} of shape {pos_a.shape}, got {np.shape(v)}")
        m0 = np.asarray(vel_a, dtype=np.float64)[..., None, :] * length
        ss = s[:, None]
        if vel_b is None:
            pos = pa + m0 * ss + (pb - pa - m0) * ss * ss
        else:
            m1 = np.asarray(vel_b, dtype=np.float64)[..., None, :] * length
            h00, h10, h01, h11 = _hermite_basis(ss)
            pos = h00 * pa + h10 * m0 + h01 * pb + h11 * m1
    return rot, pos


def _span(length: int, horizon: float | None) -> float:
    """Frames the end velocities count over: ``min(length, horizon)`` (``length`` for None)."""
    if horizon is None:
        return float(length)
    if not (np.isfinite(horizon) and horizon > 0):
        raise ValueError(f"expected a horizon of a positive number of frames, got {horizon!r}")
    return float(min(length, horizon))


def _hermite_rotvec(rot_a, rot_b, ang_vel_a, ang_vel_b, s: np.ndarray, span: float) -> np.ndarray:
    """(..., N, J, 3) rotation vectors relative to ``rot_a`` at the time fractions ``s`` (N,): the
    cubic Hermite curve from 0 to ``log(rot_a⁻¹ rot_b)`` with end slopes ``ω span`` (the quadratic
    with the start slope alone when ``ang_vel_b`` is None)."""
    shape = rot_a.shape[:-1] + (3,)
    w = [None if v is None else np.asarray(v, dtype=np.float64) * span for v in (ang_vel_a, ang_vel_b)]
    for name, v in zip(("ang_vel_a", "ang_vel_b"), w):
        if v is not None and v.shape != shape:
            raise ValueError(f"expected {name} of shape {shape}, got {v.shape}")
    d = log(quat.mul(quat.conj(rot_a), rot_b))[..., None, :, :]
    w0 = w[0][..., None, :, :]
    t = s[:, None, None]
    if w[1] is None:
        return w0 * t + (d - w0) * t * t
    _, h10, h01, h11 = _hermite_basis(t)
    return h10 * w0 + h01 * d + h11 * w[1][..., None, :, :]


def _hermite_basis(s: np.ndarray) -> tuple[np.ndarray, ...]:
    """The cubic Hermite basis ``(h00, h10, h01, h11)`` at time fractions ``s`` (any shape)."""
    return 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, 3 * s**2 - 2 * s**3, s**3 - s**2


def zero_velocity(rot_a, pos_a, num: int) -> tuple[np.ndarray, np.ndarray]:
    """The zero-velocity baseline: the last known pose repeated ``num`` times.

    Returns ``(..., N, J, 4)`` rotations and ``(..., N, 3)`` root positions.
    """
    rot_a = quat.check(rot_a, "rot_a")
    pos_a = np.asarray(pos_a, dtype=np.float64)
    rot = np.broadcast_to(rot_a[..., None, :, :], rot_a.shape[:-2] + (num,) + rot_a.shape[-2:]).copy()
    pos = np.broadcast_to(pos_a[..., None, :], pos_a.shape[:-1] + (num, 3)).copy()
    return rot, pos


def _velocities(motion: Motion, t: int, forward: bool, joint: int = 0) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Velocity (3,) of joint ``joint``'s translation (the root position for joint 0) and joint
    angular velocities (J, 3) at frame ``t`` from its neighbour."""
    n = t + 1 if forward else t - 1
    if not 0 <= n < motion.num_frames:
        return None, None
    path = motion.translations()[[t, n], joint]
    if not (np.all(np.isfinite(motion.local_rot[n])) and np.all(np.isfinite(path))):
        return None, None
    if forward:
        v = path[1] - path[0]
        w = log(quat.mul(quat.conj(motion.local_rot[t]), motion.local_rot[n]))
    else:
        v = path[0] - path[1]
        w = log(quat.mul(quat.conj(motion.local_rot[n]), motion.local_rot[t]))
    return v, w


def fill_between(
    motion: Motion,
    start: int,
    stop: int,
    curve: str = "linear",
    root: str = "linear",
    rotation: str = "slerp",
    *,
    joint: int = 0,
) -> Motion:
    """A copy of ``motion`` with frames ``start … stop-1`` recomputed from frames ``start-1`` and ``stop``.

    The frames in the gap may hold anything (NaN included); only the bounding frames and, for
    Hermite modes, their outer neighbours are read. The translation of ``joint`` (keyword-only;
    the root position for the default 0), the joint that carries the body
    (:func:`~.alignment.reference_joint`: the hips on rigs whose joint 0 the recording holds
    still), follows ``root``; every other per-joint translation (``local_pos``) is interpolated
    linearly.

    Raises
    ------
    ValueError unless the gap has a known frame on each side (1 <= start <= stop <= T-1), or for a
    ``joint`` other than 0 in a motion without ``local_pos``.
    """
    T = motion.num_frames
    if not (1 <= start <= stop <= T - 1):
        raise ValueError(f"a gap [{start}, {stop}) needs a known frame on each side in a {T}-frame motion")
    if joint != 0 and motion.local_pos is None:
        raise ValueError(f"joint={joint} carries the body only in a motion with per-joint translations (local_pos)")
    num = stop - start
    a, b = start - 1, stop
    vel_a, ang_a = _velocities(motion, a, forward=False, joint=joint)
    vel_b, ang_b = _velocities(motion, b, forward=True, joint=joint)
    path = motion.translations()[[a, b], joint]
    rot, pos = interpolate(
        motion.local_rot[a],
        path[0],
        motion.local_rot[b],
        path[1],
        num,
        curve=curve,
        root=root,
        rotation=rotation,
        vel_a=vel_a,
        vel_b=vel_b,
        ang_vel_a=ang_a,
        ang_vel_b=ang_b,
        horizon=ANGULAR_HORIZON * motion.fps,
    )
    out = motion.copy()
    out.local_rot[start:stop] = rot
    w = alphas(num, curve)[:, None, None]
    if out.local_pos is not None:
        out.local_pos[start:stop] = motion.local_pos[a] + w * (motion.local_pos[b] - motion.local_pos[a])
    if joint == 0:
        out.root_pos[start:stop] = pos
    else:
        out.root_pos[start:stop] = motion.root_pos[a] + w[:, 0] * (motion.root_pos[b] - motion.root_pos[a])
        out.local_pos[start:stop, joint] = pos
    return out


def inbetween(
    first: Motion,
    second: Motion,
    num: int,
    curve: str = "linear",
    root: str = "linear",
    rotation: str = "slerp",
    align: bool = True,
) -> Motion:
    """``first``, then ``num`` generated frames, then ``second``, as one motion.

    With ``align`` the second motion is first brought into the frame of the first (root
    alignment, eq. 3: a rotation about the vertical and a horizontal translation so that its
    first frame continues from the last frame of ``first``; see :mod:`.alignment`).

    Raises
    ------
    ValueError when the motions differ in skeleton or frame rate, or one has no frame.
    """
    if not first.skeleton.equals(second.skeleton):
        raise ValueError("both motions must use the same skeleton (names, parents and offsets)")
    if abs(first.fps - second.fps) > 1e-6 * first.fps:
        raise ValueError(f"both motions must share a frame rate, got {first.fps:g} and {second.fps:g} fps")
    if first.num_frames < 1 or second.num_frames < 1:
        raise ValueError("both motions need at least one frame")
    if align:
        second = alignment.align_to(second, first, frame=0, to_frame=-1)
    gap = second[:1].copy(
        local_rot=np.repeat(second.local_rot[:1], num, axis=0),
        root_pos=np.repeat(second.root_pos[:1], num, axis=0),
        local_pos=None if second.local_pos is None else np.repeat(second.local_pos[:1], num, axis=0),
    )
    joined = concatenate([first, gap, second])
    return fill_between(joined, first.num_frames, first.num_frames + num, curve=curve, root=root, rotation=rotation)


def concatenate(motions: list[Motion]) -> Motion:
    """Motions of one skeleton one after another (no alignment, no blending), at the first's fps.

    Raises
    ------
    ValueError for no motion, or motions of different skeletons.
    """
    if not motions:
        raise ValueError("nothing to concatenate")
    m0 = motions[0]
    for m in motions[1:]:
        if m.skeleton.names != m0.skeleton.names:
            raise ValueError(f"cannot concatenate {m.name!r}: another skeleton than {m0.name!r}")
    has_pos = any(m.local_pos is not None for m in motions)
    local_pos = np.concatenate([m.translations() for m in motions]) if has_pos else None
    return Motion(
        m0.skeleton,
        np.concatenate([m.local_rot for m in motions]),
        np.concatenate([m.root_pos for m in motions]),
        m0.fps,
        local_pos,
        m0.name,
    )
