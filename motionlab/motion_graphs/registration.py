r"""Registration of two clips and blends between them (the interpolation space).

Two styles of one behaviour (a normal and an angry walk) rarely have frames close enough for a
direct transition. Paper B therefore builds intermediate motions, as Zhao and Safonova do,
using *registration curves* (Kovar and Gleicher 2003):

1. **Time registration** by dynamic time warping over the frame distance :math:`D(i, j)` of
   :mod:`~motionlab.motion_graphs.distance` (which already aligns each pair on the ground):

   .. math:: A(i, j) = D(i, j) + \min\{A(i-1, j-1),\ A(i-1, j),\ A(i, j-1)\}.

   The path may start anywhere on the first row or column and end anywhere on the last row or
   column (the clips need not start in the same phase); among the ends, the one with the lowest
   *mean* cost per step over a path at least half as long as the shorter clip wins. The
   recursion runs along anti-diagonals, each one a vectorised NumPy step.
2. **Root alignment.** Each clip's root motion is expressed in its own heading frame: the
   ground velocity turned by :math:`-\text{heading}`, the heading's rate, the root height and
   the root rotation with its heading removed. These are comparable between clips wherever
   they were recorded.
3. **Blending** with weight :math:`w`: blended time :math:`u = (1-w)\,i + w\,j` along the
   path, resampled to whole frames; local joint rotations by :math:`\mathrm{slerp}(q_A, q_B, w)`;
   root velocity, heading rate and height linearly; the blended velocities are integrated back
   to a world trajectory.

Paper B uses :math:`w \in \{0.2, 0.4, 0.6, 0.8\}` (:data:`BLEND_WEIGHTS`).

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core import humanoid, quat
from motionlab.core.motion import Motion
from motionlab.core.preprocess import heading
from motionlab.motion_graphs import distance as _distance

__all__ = [
    "BLEND_WEIGHTS",
    "Registration",
    "dtw",
    "register",
    "blend",
    "RootTrack",
    "root_track",
    "interpolation_space",
]

BLEND_WEIGHTS = (0.2, 0.4, 0.6, 0.8)
"""Blend weights of the intermediate motions M1…M4 between two styles (paper B)."""


@dataclass
class Registration:
    """A time alignment of clips A and B.

    Attributes
    ----------
    path : int ndarray, shape (K, 2)   monotone frame pairs ``(i, j)``
    cost : float                       mean ``D`` along the path, m²
    """

    path: np.ndarray
    cost: float


def dtw(cost: np.ndarray, min_length: int | None = None) -> Registration:
    """Open-begin, open-end dynamic time warping over a cost matrix (Ta, Tb).

    See the module docstring. ``min_length``: shortest accepted path (default: half the shorter
    side, at least 2).

    Raises
    ------
    ValueError unless the cost matrix is 2-D with at least 2 rows and columns.
    """
    c = np.asarray(cost, dtype=np.float64)
    if c.ndim != 2 or min(c.shape) < 2:
        raise ValueError(f"expected a cost matrix with at least 2 rows and columns, got shape {c.shape}")
    ta, tb = c.shape
    acc = np.empty((ta, tb))
    length = np.empty((ta, tb), dtype=np.int64)
    step = np.zeros((ta, tb), dtype=np.int8)  # 0 start, 1 diagonal, 2 from (i-1, j), 3 from (i, j-1)
    acc[0], length[0] = c[0], 1
    cols = np.arange(tb)
    for i in range(1, ta):
        # best predecessor from the row above: diagonal (i-1, j-1) or straight up (i-1, j);
        # column 0 may start a new path (open begin), which costs nothing before it
        diag = np.concatenate([[0.0], acc[i - 1, :-1]])
        up = acc[i - 1]
        from_up = up < diag
        from_up[0] = False
        p = np.where(from_up, up, diag)
        p_len = np.where(from_up, length[i - 1], np.concatenate([[0], length[i - 1, :-1]]))
        # x_j = c_j + min(p_j, x_{j-1})  =  C_j + min_{k<=j} (p_k - C_{k-1}): a running minimum
        csum = np.cumsum(c[i])
        v = p - np.concatenate([[0.0], csum[:-1]])
        run = np.minimum.accumulate(v)
        k = np.maximum.accumulate(np.where(v <= run, cols, 0))
        acc[i] = csum + run
        length[i] = p_len[k] + 1 + (cols - k)
        step[i] = np.where(k < cols, 3, np.where(from_up, 2, 1))
        step[i, 0] = 0
    min_length = max(2, min(ta, tb) // 2) if min_length is None else min_length
    ends = np.concatenate(
        [np.stack([np.full(tb, ta - 1), np.arange(tb)], 1), np.stack([np.arange(ta - 1), np.full(ta - 1, tb - 1)], 1)]
    )
    mean = acc[ends[:, 0], ends[:, 1]] / length[ends[:, 0], ends[:, 1]]
    mean = np.where(length[ends[:, 0], ends[:, 1]] >= min_length, mean, np.inf)
    if not np.isfinite(mean).any():
        mean = acc[ends[:, 0], ends[:, 1]] / length[ends[:, 0], ends[:, 1]]
    i, j = (int(v) for v in ends[int(np.argmin(mean))])
    path = [(i, j)]
    while step[i, j] != 0:
        s = step[i, j]
        i, j = (i - 1, j - 1) if s == 1 else (i - 1, j) if s == 2 else (i, j - 1)
        path.append((i, j))
    path = np.array(path[::-1], dtype=np.int64)
    return Registration(path, float(np.mean(c[path[:, 0], path[:, 1]])))


def register(a: Motion, b: Motion, window: int = _distance.DEFAULT_WINDOW) -> Registration:
    """Time registration of two canonical clips through DTW on Kovar's frame distance."""
    return dtw(_distance.distance_matrix(a.global_positions(), b.global_positions(), window))


@dataclass
class RootTrack:
    """A canonical clip's root motion in its own heading frame (see the module docstring).

    Attributes
    ----------
    yaw : (T,) unwrapped heading, radians        ground : (T, 3) root on the ground (y = 0), m
    height : (T,) root height, m                 root_rot : (T, 4) root rotation, heading removed
    """

    yaw: np.ndarray
    ground: np.ndarray
    height: np.ndarray
    root_rot: np.ndarray


def root_track(motion: Motion, global_pos: np.ndarray | None = None) -> RootTrack:
    """Heading-frame description of a canonical motion's root (see :class:`RootTrack`).

    Raises
    ------
    ValueError when the motion is not on the 22-joint canonical skeleton.
    """
    if not humanoid.is_canonical(motion.skeleton):
        raise ValueError("registration needs 22-joint canonical motions; reduce them with preprocess.prepare first")
    pos = motion.global_positions() if global_pos is None else global_pos
    yaw = np.unwrap(heading(pos))
    ground = motion.root_pos * np.array([1.0, 0.0, 1.0])
    root_rot = quat.mul(quat.from_yaw(-yaw), motion.local_rot[:, 0])
    return RootTrack(yaw, ground, motion.root_pos[:, 1].copy(), root_rot)


def _sample(x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Linear interpolation of (T, ...) arrays at fractional frames ``t``."""
    i0 = np.clip(np.floor(t).astype(np.int64), 0, len(x) - 1)
    i1 = np.minimum(i0 + 1, len(x) - 1)
    a = (t - i0).reshape((-1,) + (1,) * (x.ndim - 1))
    return x[i0] * (1 - a) + x[i1] * a


def _sample_rot(q: np.ndarray, t: np.ndarray) -> np.ndarray:
    i0 = np.clip(np.floor(t).astype(np.int64), 0, len(q) - 1)
    i1 = np.minimum(i0 + 1, len(q) - 1)
    a = t - i0
    return quat.slerp(q[i0], q[i1], a.reshape((-1,) + (1,) * (q.ndim - 2)))


def blend(
    a: Motion,
    b: Motion,
    reg: Registration,
    weight: float,
    name: str | None = None,
    tracks: tuple[RootTrack, RootTrack] | None = None,
) -> Motion:
    """The blend of two registered canonical clips with weight ``weight`` on ``b``.

    Returns a Motion of about ``(1-w)·len_A + w·len_B`` frames over the registered part,
    starting at A's first registered frame's position and heading. ``tracks``: the clips'
    :func:`root_track` if already computed.

    Raises
    ------
    ValueError when ``weight`` is outside [0, 1] or the clips differ in joint count.
    """
    if not 0.0 <= weight <= 1.0:
        raise ValueError(f"blend weight must lie in [0, 1], got {weight}")
    if a.skeleton.num_joints != b.skeleton.num_joints:
        raise ValueError("cannot blend clips with different joint counts")
    path = reg.path.astype(np.float64)
    u = (1 - weight) * path[:, 0] + weight * path[:, 1]
    u = u - u[0]
    keep = np.concatenate([[True], np.diff(u) > 1e-9])
    u, path = u[keep], path[keep]
    n = int(np.floor(u[-1])) + 1
    grid = np.arange(n, dtype=np.float64)
    ti = np.interp(grid, u, path[:, 0])
    tj = np.interp(grid, u, path[:, 1])
    ra, rb = tracks if tracks is not None else (root_track(a), root_track(b))
    rot_a, rot_b = _sample_rot(a.local_rot, ti), _sample_rot(b.local_rot, tj)
    local = quat.slerp(rot_a, rot_b, np.full(rot_a.shape[:2], weight))
    deheaded = quat.slerp(_sample_rot(ra.root_rot, ti), _sample_rot(rb.root_rot, tj), np.full(n, weight))

    def increments(track: RootTrack, t: np.ndarray):
        yaw = _sample(track.yaw, t)
        ground = _sample(track.ground, t)
        step = np.diff(ground, axis=0)
        local_step = quat.rotate(quat.from_yaw(-yaw[:-1]), step)
        return np.diff(yaw), local_step, _sample(track.height, t)

    dyaw_a, step_a, h_a = increments(ra, ti)
    dyaw_b, step_b, h_b = increments(rb, tj)
    dyaw = (1 - weight) * dyaw_a + weight * dyaw_b
    step = (1 - weight) * step_a + weight * step_b
    height = (1 - weight) * h_a + weight * h_b
    yaw0 = float(_sample(ra.yaw, ti[:1])[0])
    yaw = yaw0 + np.concatenate([[0.0], np.cumsum(dyaw)])
    world_step = quat.rotate(quat.from_yaw(yaw[:-1]), step)
    ground = _sample(ra.ground, ti[:1])[0] + np.concatenate([np.zeros((1, 3)), np.cumsum(world_step, axis=0)])
    root_pos = ground + height[:, None] * np.array([0.0, 1.0, 0.0])
    local[:, 0] = quat.normalize(quat.mul(quat.from_yaw(yaw), deheaded))
    label = name if name is not None else f"{a.name}~{b.name}@{weight:g}"
    return Motion(a.skeleton, local, root_pos, a.fps, None, label)


def interpolation_space(
    a: Motion, b: Motion, weights=BLEND_WEIGHTS, window: int = _distance.DEFAULT_WINDOW
) -> tuple[list[Motion], Registration]:
    """The intermediate motions M1…Mk between ``a`` and ``b`` (one per weight) and the registration."""
    reg = register(a, b, window)
    tracks = (root_track(a), root_track(b))
    return [blend(a, b, reg, w, tracks=tracks) for w in weights], reg
