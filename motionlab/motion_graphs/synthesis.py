r"""From a graph path to one continuous motion.

A path is a list of runs ``(clip, first, last)``; consecutive runs are joined by transition
edges ``src → dst`` whose frame ``dst - 1`` resembles ``src``. Synthesis:

1. **Alignment.** Each run after a jump is turned about +Y so that its frame ``dst - 1`` faces
   where the previous run's last frame faces (heading from hips and shoulders), then shifted on
   the ground: ``align="root"`` puts its root exactly on the previous root; ``align="foot"``
   (default) puts its lowest foot joint on the previous frame's lowest foot joint, so the
   supporting foot stays planted (the root then moves by at most the small pose difference the
   threshold allowed). Either way the character never jumps in heading or position.
2. **Blending.** Over ``blend`` frames after each jump the new run is cross-faded with the
   continuation the old clip would have played (aligned the same way): local rotations by
   :math:`\mathrm{slerp}(q_\text{old}, q_\text{new}, \alpha_t)` with the smooth ramp
   :math:`\alpha_t = s\!\left(\tfrac{t+1}{k+1}\right)`, :math:`s(x) = 3x^2 - 2x^3`; root
   positions linearly with the same weights.
3. **Foot skating** near the jump: foot alignment (1) removes most of it (``python
   benchmarks/bench_motion_graphs.py`` prints how much). Optionally (``fix_feet=True``) the root is also
   shifted inside blend windows to pin a foot that is planted when the window starts, the
   last shift carried on; it helps with root alignment, not with foot alignment.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from motionlab.core import fk as _fk
from motionlab.core import humanoid, metrics, quat
from motionlab.core.motion import Motion
from motionlab.core.preprocess import heading
from motionlab.motion_graphs.graph import MotionGraph

__all__ = ["synthesize", "transition_quality", "DEFAULT_BLEND"]

DEFAULT_BLEND = 8
"""Frames over which each transition is cross-faded (≈ 0.27 s at 30 fps)."""

_FEET = [humanoid.JOINTS.index(n) for n in humanoid.FEET]


def _smooth(x: np.ndarray) -> np.ndarray:
    return x * x * (3.0 - 2.0 * x)


def _frames_pose(graph: MotionGraph, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return graph.local_rot[idx], graph.root_pos[idx]


def _place(rot: np.ndarray, pos: np.ndarray, yaw: float, shift: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Turn frames by ``yaw`` about +Y (through the origin), then shift on the ground."""
    q = quat.from_yaw(np.array(yaw))
    rot = rot.copy()
    rot[:, 0] = quat.mul(q, rot[:, 0])
    return rot, quat.rotate(q, pos) + shift


def _positions(graph: MotionGraph, rot: np.ndarray, pos: np.ndarray) -> np.ndarray:
    trans = np.broadcast_to(graph.skeleton.offsets, (len(rot), graph.skeleton.num_joints, 3)).copy()
    trans[:, 0] = pos
    return _fk.fk_positions(rot, trans, graph.skeleton.parents)


def _heading_of(graph: MotionGraph, rot: np.ndarray, pos: np.ndarray) -> np.ndarray:
    return heading(_positions(graph, rot, pos))


def synthesize(
    graph: MotionGraph,
    pieces: Sequence[tuple[int, int, int]],
    blend: int = DEFAULT_BLEND,
    fix_feet: bool = False,
    align: str = "foot",
    name: str = "motion graph path",
) -> Motion:
    """The motion of a path (see the module docstring).

    Parameters
    ----------
    graph : the graph the path walks
    pieces : ``(clip, first, last)`` runs, clip-local frames inclusive (``SearchResult.pieces``)
    blend : cross-fade length in frames (0: hard cuts, still aligned)
    fix_feet : also pin planted feet inside blend windows by shifting the root
    align : ``"foot"`` (default): after turning, shift so the lowest foot joint of the previous
        frame stays where it is; ``"root"``: shift so the root continues exactly

    Returns
    -------
    Motion on the graph's skeleton, ``sum(last - first + 1)`` frames.

    Raises
    ------
    ValueError for an empty path, a piece outside its clip, ``blend`` < 0 or an unknown
    ``align``.
    """
    if len(pieces) == 0:
        raise ValueError("empty path: nothing to synthesise")
    if blend < 0:
        raise ValueError(f"blend must be a non-negative number of frames, got {blend}")
    if align not in ("foot", "root"):
        raise ValueError(f"align must be 'foot' or 'root', got {align!r}")
    for n, (c, a, b) in enumerate(pieces):
        info = graph.clips[c]
        if not (0 <= a <= b < info.num_frames):
            raise ValueError(f"piece {n}: frames {a}..{b} outside clip {info.name!r} ({info.num_frames} frames)")
    stance = _FEET if humanoid.is_canonical(graph.skeleton) else []
    yaw_of = _source_headings(graph, pieces)
    rots, poss = [], []
    windows = []  # (output index of first blended frame, length)
    out_len = 0
    prev_end_rot = prev_end_pos = None
    prev_global = None
    for n, (c, a, b) in enumerate(pieces):
        info = graph.clips[c]
        idx = np.arange(info.start + a, info.start + b + 1)
        rot, pos = _frames_pose(graph, idx)
        if n == 0:
            rots.append(rot)
            poss.append(pos)
        else:
            anchor = info.start + a - 1 if a > 0 else info.start + a
            contiguous = prev_global is not None and prev_global + 1 == info.start + a
            dyaw, shift, yaw_prev = _placement(
                graph, anchor, yaw_of[anchor], prev_end_rot, prev_end_pos, stance if align == "foot" else []
            )
            rot, pos = _place(rot, pos, dyaw, shift)
            if blend > 0 and not contiguous:
                k = min(blend, len(idx))
                fade = (prev_global, yaw_of[prev_global])
                rot, pos = _cross_fade(graph, rot, pos, fade, prev_end_pos, yaw_prev, k)
                windows.append((out_len, k))
            rots.append(rot)
            poss.append(pos)
        out_len += len(idx)
        prev_end_rot, prev_end_pos = rots[-1][-1], poss[-1][-1]
        prev_global = info.start + b
    local_rot = np.concatenate(rots)
    root_pos = np.concatenate(poss)
    motion = Motion(graph.skeleton, quat.normalize(local_rot), root_pos, graph.fps, None, name)
    if fix_feet and windows and humanoid.is_canonical(graph.skeleton):
        motion = _fix_feet(motion, windows)
    return motion


def _source_headings(graph: MotionGraph, pieces: Sequence[tuple[int, int, int]]) -> dict[int, float]:
    """Heading (rad) of each graph frame that synthesis aligns or fades from, as it is in the
    graph: each run's anchor (the frame before its first, or its first) and each run's last
    frame; one forward-kinematics pass for all."""
    frames = set()
    for c, a, b in pieces:
        start = graph.clips[c].start
        frames.update((start + max(a - 1, 0), start + b))
    idx = np.array(sorted(frames))
    return dict(zip(idx.tolist(), _heading_of(graph, *_frames_pose(graph, idx)).tolist()))


def _placement(
    graph: MotionGraph, anchor: int, anchor_yaw: float, prev_rot: np.ndarray, prev_pos: np.ndarray, stance: list[int]
):
    """Turn about the vertical (rad) and ground shift (3,) that put global frame ``anchor`` (its
    heading ``anchor_yaw``, rad) where the previous run ends (pose ``prev_rot`` (J, 4), root
    ``prev_pos`` (3,)); with ``stance`` foot joints, the shift lands the anchor's foot under the
    previous pose's lowest foot instead of its root. Also returns the previous pose's heading (rad)."""
    a_rot, a_pos = _frames_pose(graph, np.array([anchor]))
    prev_pose = _positions(graph, prev_rot[None], prev_pos[None])[0]
    yaw_prev = float(heading(prev_pose))
    dyaw = float(yaw_prev - anchor_yaw)
    shift = prev_pos - quat.rotate(quat.from_yaw(np.array(dyaw)), a_pos[0])
    shift[1] = 0.0
    if stance:
        # move the anchor pose so its lowest foot joint lands on the previous pose's
        placed = _positions(graph, *_place(a_rot, a_pos, dyaw, shift))[0]
        foot = stance[int(np.argmin(prev_pose[stance, 1]))]
        shift = shift + (prev_pose[foot] - placed[foot]) * np.array([1.0, 0.0, 1.0])
    return dyaw, shift, yaw_prev


def _cross_fade(graph: MotionGraph, rot, pos, fade: tuple[int, float], prev_end_pos, yaw_prev: float, k: int):
    """The first ``k`` frames of a placed run (``rot`` (n, J, 4), ``pos`` (n, 3)) cross-faded from
    what the previous clip would have played after global frame ``fade[0]`` (its heading in the
    graph ``fade[1]``, rad), placed like the previous run; new arrays."""
    prev_global, yaw_src = fade
    pinfo = graph.clips[int(graph.clip_of(prev_global))]
    cont = np.clip(np.arange(prev_global + 1, prev_global + 1 + k), pinfo.start, pinfo.stop - 1)
    c_rot, c_pos = _frames_pose(graph, cont)
    p_pos = graph.root_pos[[prev_global]]
    # map source frames of the previous clip onto the output through its last frame
    c_rot, c_pos = _place(c_rot, c_pos, float(yaw_prev - yaw_src), np.zeros(3))
    p_pos_placed = quat.rotate(quat.from_yaw(np.array(float(yaw_prev - yaw_src))), p_pos[0])
    c_pos = c_pos + (prev_end_pos - p_pos_placed) * np.array([1.0, 0.0, 1.0])
    alpha = _smooth((np.arange(k) + 1.0) / (k + 1.0))
    rot, pos = rot.copy(), pos.copy()
    rot[:k] = quat.slerp(c_rot, rot[:k], np.broadcast_to(alpha[:, None], rot[:k].shape[:2]))
    pos[:k] = c_pos * (1 - alpha[:, None]) + pos[:k] * alpha[:, None]
    return rot, pos


def _fix_feet(motion: Motion, windows: list[tuple[int, int]]) -> Motion:
    """Shift the root so feet planted inside blend windows stay put (see the module docstring)."""
    pos = motion.global_positions()
    feet = pos[:, _FEET]  # (T, 4, 3)
    low = feet[..., 1] < np.percentile(feet[..., 1], 20, axis=0) + 0.03
    speed = np.linalg.norm(np.gradient(feet[..., [0, 2]], axis=0), axis=-1) * motion.fps
    planted = low & (speed < 1.0)
    offset = np.zeros((motion.num_frames, 3))
    carried = np.zeros(3)
    T = motion.num_frames
    for w0, k in windows:
        s, e = max(w0 - 1, 0), min(w0 + k + 2, T)
        corr = np.zeros((e - s, 3))
        for f in range(4):
            p = planted[s:e, f]
            if p[0] and p.sum() > 1:
                run = np.cumprod(p).astype(bool)  # planted from the window start on
                drift = feet[s:e, f] - feet[s, f]
                corr[run, 0] -= drift[run, 0]
                corr[run, 2] -= drift[run, 2]
        n_feet = max(1, int(planted[s, :].sum()))
        corr /= n_feet
        # hold the last correction after the foot lifts, then carry it on
        filled = np.maximum.accumulate(np.where(np.any(corr != 0, axis=1), np.arange(e - s), 0))
        corr = corr[filled]
        offset[s:e] = carried + corr
        carried = carried + corr[-1]
        if e < T:
            offset[e:] = carried
    root = motion.root_pos + offset
    return motion.copy(root_pos=root)


def transition_quality(motion: Motion, transitions: Sequence[int], half_window: int = 5) -> dict:
    """Smoothness metrics around jumps of a synthesised motion.

    Returns ``smoothness`` (mean acceleration ‖p[t+1] − 2p[t] + p[t−1]‖ in windows of
    ``±half_window`` frames around each jump, m/frame², via :func:`metrics.smoothness`),
    ``max_jump`` (largest joint displacement between consecutive frames in those windows, m),
    the same two numbers over the whole motion for reference, and ``foot_skating`` (m/s) in
    the windows.
    """
    pos = motion.global_positions()
    T = len(pos)
    idx = sorted({f for t in transitions for f in range(max(t - half_window, 0), min(t + half_window, T))})
    whole_jump = float(np.linalg.norm(np.diff(pos, axis=0), axis=-1).max()) if T > 1 else 0.0
    out = {"smoothness_all": metrics.smoothness(pos) if T >= 3 else 0.0, "max_jump_all": whole_jump}
    if not transitions or len(idx) < 3:
        out.update(smoothness=float("nan"), max_jump=float("nan"), foot_skating=float("nan"))
        return out
    wins = [pos[max(t - half_window, 0) : min(t + half_window, T)] for t in transitions]
    wins = [w for w in wins if len(w) >= 3]
    out["smoothness"] = float(np.mean([metrics.smoothness(w) for w in wins]))
    out["max_jump"] = float(max(np.linalg.norm(np.diff(w, axis=0), axis=-1).max() for w in wins))
    feet = _FEET if humanoid.is_canonical(motion.skeleton) else []
    out["foot_skating"] = (
        float(np.mean([metrics.foot_skating(w, feet, motion.fps) for w in wins])) if feet else float("nan")
    )
    return out
