"""Gaps in a gait filled from the recorded strides on both sides (``fill(method="stride")``).

SLERP between the two frames bounding a gap in a walk swings the legs through a pose no walker
takes, and a smooth root curve misses the hips' bob and sway. Gaits repeat: frame ``a + k`` of a
gap looks like frame ``a + k − P`` one stride earlier and frame ``a + k + P`` one stride later.
So the gap is predicted from both sides and the two predictions are blended:

* the stride period ``P`` (frames, fractional) is read off the body poses on both sides
  (:func:`.detect._stride`: the first deep minimum of the pose difference over lags);
* **forward from before the gap** (known frames up to ``a``): the last recorded stride
  ``[a − P, a]`` is carried forward by the rigid motion that takes its start onto its end, turned
  by the change of heading over it, ``ψ = yaw(a) − yaw(a − P)``:
  ``T(q) = p(a) + R_y(ψ)(q − p(a − P))``. Frame ``a + k`` is the recorded frame
  ``a + k − mP`` (``m = ⌈k/P⌉`` strides back) moved by ``T^m`` — its reference joint moved and
  turned by ``mψ``, the joints above it (if any) left as recorded. A straight walk repeats its
  stride, a turning one keeps turning at its rate;
* **backward from after the gap** (known frames from ``b``): the same with the first stride
  ``[b, b + P]``, run backwards;
* each prediction is bent to meet **both** ends of the gap by a correction linear in time: the
  forward one by ``(k/N)`` of its miss at ``b`` (positions and rotations, the reference joint's
  included) and the pose difference between frame ``a`` and the frame one stride before it fading
  out (``1 − k/N``, rotations); the backward one mirrored. This absorbs a stride a little slower or
  faster than the gap's, a period read a few frames off, and a missing count off by a frame;
* the two are blended with weights ``1 − k/N`` and ``k/N`` (``N = b − a``): positions linearly,
  joint rotations by SLERP.

Where no stride is found (both sides shorter than ``MIN_STRIDES`` strides, a motion that does
not repeat) :func:`stride_fill` returns ``None`` and :func:`.gaps.fill` falls back to SLERP; it
also does where SLERP fills cuts of the gap's size near it better (``gaps.fill``'s rehearsal:
across a gap of a few frames the two ends say almost everything). Fractional frames are read linearly (positions) and by SLERP (rotations).

How it compares with SLERP and a Hermite root on the shared walks and runs:
``docs/results_interpolation.md`` (``python -m experiments.interpolation.check_gaps``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core import quat
from motionlab.core.motion import Motion
from motionlab.interpolation import detect
from motionlab.interpolation.alignment import reference_transform

__all__ = [
    "SIDE_SECONDS",
    "MIN_STRIDES",
    "known_side",
    "side_speeds",
    "stride_period",
    "sample_rows",
    "sample_rotations",
    "stride_path",
    "stride_fill",
]

SIDE_SECONDS = 3.0
"""How much of each side of a gap (seconds) the stride is read from."""


MIN_STRIDES = 1.5
"""A side lends its stride only if it holds this many strides: the stride and half of the one
before it, so a first stride from standing (not yet a repeat) is not carried across a gap."""


def known_side(motion: Motion, t: int, step: int, limit: int) -> np.ndarray:
    """Frames (increasing) of the run of finite frames from ``t`` away from the gap (``step = -1``:
    ``… t−1, t``; ``+1``: ``t, t+1 …``), at most ``limit`` of them."""
    idx = np.arange(t, -1, -1) if step < 0 else np.arange(t, motion.num_frames)
    idx = idx[:limit]
    finite = np.all(np.isfinite(motion.root_pos[idx]), axis=1) & np.all(np.isfinite(motion.local_rot[idx]), axis=(1, 2))
    bad = np.flatnonzero(~finite)
    return np.sort(idx[: bad[0]] if bad.size else idx)


def side_speeds(motion: Motion, a: int, b: int, joint: int, seconds: float = 1.0) -> tuple[float, float]:
    """Mean ground speeds (metres/frame) of the reference joint ``joint`` over the known frames of
    the last ``seconds`` before the gap ``a … b`` (ending at ``a``) and the first after it (from
    ``b``), as :func:`.detect.estimate_missing` measures them; ``nan`` for a side without a step."""
    limit = max(3, int(round(seconds * motion.fps))) + 1
    speeds = []
    for frames in (known_side(motion, a, -1, limit), known_side(motion, b, +1, limit)):
        _, pos = reference_transform(motion, frames, joint=joint)
        steps = np.linalg.norm(np.diff(pos[:, [0, 2]], axis=0), axis=1)
        speeds.append(float(steps.mean()) if steps.size else float("nan"))
    return speeds[0], speeds[1]


def stride_period(motion: Motion, a: int, b: int) -> tuple[float | None, np.ndarray, np.ndarray]:
    """The stride period (frames) read off both sides of the gap ``a … b`` (``None`` if none),
    and the known frames before (ending at ``a``) and after (starting at ``b``) it."""
    limit = max(2, int(round(SIDE_SECONDS * motion.fps)))
    before, after = known_side(motion, a, -1, limit), known_side(motion, b, +1, limit)
    poses = detect._body_pose(motion[np.concatenate([before, after])])
    return detect._stride([poses[: len(before)], poses[len(before) :]], motion.fps), before, after


def sample_rows(values: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``values`` (F, ...) read at fractional rows ``x`` (K,), linearly: (K, ...); rows outside
    ``0 … F-1`` read the nearest end row."""
    lo = np.clip(np.floor(x).astype(np.int64), 0, len(values) - 1)
    hi = np.minimum(lo + 1, len(values) - 1)
    f = (x - lo).reshape((-1,) + (1,) * (values.ndim - 1))
    return values[lo] + f * (values[hi] - values[lo])


def sample_rotations(rot: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Rotations (F, J, 4) unit quaternions (w, x, y, z) read at fractional rows ``x`` (K,) by SLERP
    between the two bounding rows: (K, J, 4)."""
    lo = np.clip(np.floor(x).astype(np.int64), 0, len(rot) - 1)
    hi = np.minimum(lo + 1, len(rot) - 1)
    return quat.slerp(rot[lo], rot[hi], np.broadcast_to((x - lo)[:, None], rot[lo].shape[:-1]))


def _turn_y(angle) -> np.ndarray:
    """Rotation matrices (..., 3, 3) about +Y by ``angle`` radians (sends +Z to ``(sin, 0, cos)``)."""
    c, s = np.cos(angle), np.sin(angle)
    z, o = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


@dataclass
class _Side:
    """One side's prediction at gap offsets ``k = 0 … N``: reference joint (N+1, 3), local
    rotations (N+1, J, 4) and per-joint translations (N+1, J, 3) or None."""

    path: np.ndarray
    rot: np.ndarray
    local_pos: np.ndarray | None


def _continue(motion: Motion, frames: np.ndarray, period: float, offsets: np.ndarray, joint: int) -> _Side:
    """The stride ending at the last of ``frames`` (in time order of the continuation) carried on
    by ``offsets`` (K,) frames (module docstring)."""
    end = len(frames) - 1
    g_rot, path = reference_transform(motion, frames, joint=joint)
    yaw = np.unwrap(quat.yaw(g_rot))
    m = np.ceil(offsets / period - 1e-9).astype(np.int64)
    x = end + offsets - m * period
    start = sample_rows(path, np.array([end - period]))[0]
    psi = float(yaw[end] - np.interp(end - period, np.arange(len(yaw)), yaw))
    q = sample_rows(path, x)
    turn = _turn_y(psi)
    for i in range(int(m.max(initial=0))):  # a few strides at most: a loop over strides, not frames
        moved = m > i
        q[moved] = path[end] + (q[moved] - start) @ turn.T
    rot = _turned(sample_rotations(motion.local_rot[frames], x), motion.skeleton.ancestors(joint), joint, m * psi)
    local_pos = None if motion.local_pos is None else sample_rows(motion.local_pos[frames], x)
    return _Side(q, rot, local_pos)


def _turned(rot: np.ndarray, chain: list[int], joint: int, yaw: np.ndarray) -> np.ndarray:
    """Local rotations ``rot`` (K, J, 4) with the world rotation of ``joint`` (below the joints
    ``chain``, joint 0 first) turned about +Y by ``yaw`` (K,) radians: the body turned by the joint
    that carries it, the joints above it untouched."""
    above = np.broadcast_to(quat.IDENTITY, rot[:, 0].shape)
    for k in chain:  # the few joints above the reference joint (none where it is joint 0)
        above = quat.mul(above, rot[:, k])
    rot[:, joint] = quat.mul(quat.inv(above), quat.mul(quat.from_yaw(yaw), quat.mul(above, rot[:, joint])))
    return rot


def _bend(side: _Side, motion: Motion, frames: np.ndarray, period: float, far: tuple, w: np.ndarray, poses: bool,
          joint: int):  # fmt: skip
    """Make a side's prediction meet both ends: its path by ``w`` (N+1,) times its miss at the far
    end (``far = (index into the prediction, reference joint position (3,), frame)``); with
    ``poses``, its rotations and translations by the difference between its own end frame and the
    frame one stride before it, fading as ``1 − w``, then by the difference between the far end's
    frame and the prediction there, growing as ``w`` (but for the reference joint ``joint``, whose
    heading :func:`_continue` turned, and the joints above it)."""
    end = len(frames) - 1
    side.path = side.path + w[:, None] * (far[1] - side.path[far[0]])
    if not poses:
        return side
    rot = motion.local_rot[frames]
    back = sample_rotations(rot, np.array([end - period]))[0]  # (J, 4)
    above = motion.skeleton.ancestors(joint)  # as recorded
    side.rot = _bent(side.rot, quat.mul(rot[end], quat.inv(back)), 1.0 - w, above + [joint])  # joint: turned
    side.rot = _bent(side.rot, quat.mul(motion.local_rot[far[2]], quat.inv(side.rot[far[0]])), w, above)
    if side.local_pos is not None:
        lp = motion.local_pos[frames]
        side.local_pos = side.local_pos + (1.0 - w)[:, None, None] * (
            lp[end] - sample_rows(lp, np.array([end - period]))[0]
        )
        side.local_pos = side.local_pos + w[:, None, None] * (motion.local_pos[far[2]] - side.local_pos[far[0]])
    return side


def _bent(rot: np.ndarray, diff: np.ndarray, weight: np.ndarray, carrier: list) -> np.ndarray:
    """Rotations ``rot`` (K, J, 4) turned by ``weight`` (K,) of the turns ``diff`` (J, 4), but the
    joints ``carrier``."""
    turn = quat.slerp(
        np.broadcast_to(quat.IDENTITY, diff.shape), diff, np.broadcast_to(weight[:, None], rot.shape[:-1])
    )
    turn[:, carrier] = quat.IDENTITY
    return quat.normalize(quat.mul(turn, rot))


def _predict(motion: Motion, a: int, b: int, joint: int, with_poses: bool):
    period, before, after = stride_period(motion, a, b)
    if period is None:
        return None
    n = b - a
    k = np.arange(n + 1, dtype=np.float64)
    w = k / n
    _, ends = reference_transform(motion, np.array([a, b]), joint=joint)
    sides = []
    for frames, offsets, far, weight in (
        (before, k, (-1, ends[1], b), w),
        (after[::-1], n - k, (0, ends[0], a), 1.0 - w),
    ):
        if len(frames) - 1 < MIN_STRIDES * period:
            sides.append(None)
            continue
        side = _continue(motion, frames, period, offsets, joint)
        sides.append(_bend(side, motion, frames, period, far, weight, with_poses, joint))
    fwd, back = sides
    if fwd is None and back is None:
        return None
    fwd, back = (back, back) if fwd is None else (fwd, fwd if back is None else back)
    path = (1.0 - w)[:, None] * fwd.path + w[:, None] * back.path
    if not with_poses:
        return path, None, None
    rot = quat.slerp(fwd.rot, back.rot, np.broadcast_to(w[:, None], fwd.rot.shape[:-1]))
    lp = None if fwd.local_pos is None else (1.0 - w)[:, None, None] * fwd.local_pos + w[:, None, None] * back.local_pos
    return path, rot, lp


def stride_path(motion: Motion, a: int, b: int, joint: int) -> np.ndarray | None:
    """The reference joint's path (b−a−1, 3), metres, at frames ``a+1 … b−1`` continued stride by
    stride from both sides of the gap (module docstring); ``None`` where no stride is found."""
    pred = _predict(motion, a, b, joint, with_poses=False)
    return None if pred is None else pred[0][1:-1]


def stride_fill(motion: Motion, a: int, b: int, joint: int) -> tuple[Motion, np.ndarray] | None:
    """Frames ``a+1 … b−1`` filled from the strides on both sides (module docstring).

    Returns the filled copy, whose root translation still has to be moved so that the reference
    joint follows the returned path (b−a−1, 3) (:func:`.gaps.fill` does this, with its floor
    guard), or ``None`` where no stride is found.
    """
    if b - a < 2:
        return None
    pred = _predict(motion, a, b, joint, with_poses=True)
    if pred is None:
        return None
    path, rot, lp = pred
    out = motion.copy()
    out.local_rot[a + 1 : b] = rot[1:-1]
    out.root_pos[a + 1 : b] = motion.root_pos[a] + (np.arange(1, b - a) / (b - a))[:, None] * (
        motion.root_pos[b] - motion.root_pos[a]
    )
    if lp is not None:
        out.local_pos[a + 1 : b] = lp[1:-1]
        out.local_pos[a + 1 : b, 0] = out.root_pos[a + 1 : b]
    return out, path[1:-1]
