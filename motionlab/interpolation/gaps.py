"""Detect missing frames in a motion stream and fill them (paper C, §3.3).

**Detection.** Missing frames show up in one of three ways:

* NaN rows (a capture system that knows it lost the markers): :func:`nan_gaps`;
* timestamps that jump by more than one frame period: :func:`timestamp_gaps`;
* nothing at all — the frames were just dropped, as in a BVH file with a constant frame time.
  Then the paper's rule ``D > Δ`` applies, the stream tracked in the action graph or against its
  own neighbouring steps, and the missing count comes from the motion on both sides: see
  :mod:`.detect`.

**Filling** (:func:`fill`). Each gap ``[start, stop)`` is bounded by known frames ``a = start − 1``
and ``b = stop``:

* *inside one action node* (or without a graph): interpolate between ``a`` and ``b`` — SLERP with
  linear root, or Hermite variants; or, in a gait, continue the recorded strides on both sides
  across the gap (``method="stride"``, :mod:`.stride`; what ``motionlab fill-gaps`` does by
  default); or, when an :class:`~.action_graph.ActionGraph` is given, the key-pose-guided
  filling of :mod:`.library` with the node's recordings;
* *across nodes*: find the path ``a's action → … → b's action`` in the graph, place one key pose of
  every intermediate action (its best transition frame from the previous action — a PPCA key frame,
  :meth:`~.action_graph.ActionGraph.best_transition` — root-aligned onto the straight line from
  ``a`` to ``b``) at evenly spaced frames inside the gap, and fill each piece between consecutive
  anchors with eq. 4's moving SLERP (:func:`moving_slerp`): the earlier node's clip running on
  from its frame at the first anchor, blended into the later node's clip running into its frame at
  the second.

Pieces filled one after another meet at the anchors with different velocities: the root path
would have corners there. With the graph, :func:`smooth_root` therefore bends the root through the
anchors onto a C1 curve (cubic Hermite, Catmull-Rom tangents, the measured velocities just outside
the gap at its ends) and keeps the per-frame detail of the recorded stretches in between.

Taught in ``notebooks/06_keypose_interpolation.ipynb``; the ``motionlab fill-gaps`` command uses it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from motionlab.core import quat
from motionlab.core.motion import Motion
from motionlab.interpolation import detect, inbetween
from motionlab.interpolation.action_graph import ActionGraph
from motionlab.interpolation.alignment import apply as apply_rigid
from motionlab.interpolation.alignment import carry_by_reference, reference_joint, reference_transform
from motionlab.interpolation.alignment import estimate as estimate_rigid
from motionlab.interpolation.features import pose_features
from motionlab.interpolation.footing import lowest_joints, plant_feet
from motionlab.interpolation.library import MotionLibrary
from motionlab.interpolation.slerp import alphas
from motionlab.interpolation.stride import SIDE_SECONDS, side_speeds, stride_fill, stride_path

__all__ = [
    "METHODS",
    "REHEARSALS",
    "ROOTS",
    "FEET",
    "FilledGap",
    "nan_gaps",
    "load_times",
    "timestamp_gaps",
    "insert_missing",
    "fill",
    "fill_rows",
    "smooth_root",
    "lift_above_floor",
    "moving_slerp",
]

METHODS = ("slerp", "hermite", "stride", "graph")

REHEARSALS = 8
"""The most cuts of a gap's size near it on which the stride fill is rehearsed against SLERP
(:func:`_stride_rehearsed`); each costs two fills."""
ROOTS = ("stride", "hermite", "linear")
FEET = ("plant", "lift")
"""How :func:`fill` keeps filled feet out of the floor: ``"plant"`` bends each sunk leg
(:func:`.footing.plant_feet`) and lifts the body by what the legs cannot reach, ``"lift"`` lifts
the body only (:func:`lift_above_floor`)."""


@dataclass
class FilledGap:
    """What :func:`fill` did for one gap.

    Attributes
    ----------
    start, stop : int     the filled frames are ``start … stop-1`` of the returned motion
    method : str          ``"slerp"``, ``"hermite"``, ``"stride"``, ``"library"`` or ``"graph"``
    path : list of str    actions from frame ``start-1`` to frame ``stop`` (graph methods)
    anchors : list of int frames where intermediate key poses were placed
    """

    start: int
    stop: int
    method: str
    path: list = field(default_factory=list)
    anchors: list = field(default_factory=list)

    def __str__(self) -> str:
        s = f"frames {self.start}-{self.stop - 1} ({self.stop - self.start} frames): {self.method}"
        if self.path:
            s += " via " + " -> ".join(self.path)
        if self.anchors:
            s += f", key poses at frames {self.anchors}"
        return s


# ---------------------------------------------------------------------------- detection
def nan_gaps(x) -> list[tuple[int, int]]:
    """Runs ``(start, stop)`` of rows (axis 0) holding any NaN in an array (T, ...)."""
    x = np.asarray(x, dtype=np.float64)
    bad = ~np.all(np.isfinite(x.reshape(len(x), -1)), axis=1)
    edges = np.diff(np.concatenate([[0], bad.astype(np.int8), [0]]))
    return [(int(a), int(b)) for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1))]


def _motion_nan_gaps(motion: Motion) -> list[tuple[int, int]]:
    parts = [motion.local_rot.reshape(motion.num_frames, -1), motion.root_pos]
    if motion.local_pos is not None:
        parts.append(motion.local_pos.reshape(motion.num_frames, -1))
    return nan_gaps(np.concatenate(parts, axis=1))


def load_times(path, frames: int | None = None) -> np.ndarray:
    """The frames' capture times (seconds) from a text file: one number per line, blank lines and
    lines starting with ``#`` skipped (as a capture system's frame log, or a column cut from one).

    Raises ``ValueError`` naming the file and the line: a line that is not one finite number, a
    time not after the one before it, or (``frames`` given) a count of times other than ``frames``.

    Returns
    -------
    ndarray, shape (T,), seconds, strictly increasing
    """
    times, lines = [], []
    with open(path, encoding="utf-8") as fh:
        for k, line in enumerate(fh, start=1):
            text = line.strip()
            if not text or text.startswith("#"):
                continue
            try:
                value = float(text)
            except ValueError:
                value = float("nan")
            if not np.isfinite(value):
                raise ValueError(f"{path} line {k}: expected one time in seconds, found {text[:40]!r}")
            if times and value <= times[-1]:
                raise ValueError(
                    f"{path} line {k}: {value:g} s is not after {times[-1]:g} s (line {lines[-1]}); "
                    "frame times must increase"
                )
            times.append(value)
            lines.append(k)
    if frames is not None and len(times) != frames:
        raise ValueError(f"{path}: {len(times)} frame times for {frames} frames; expected one time per frame")
    return np.asarray(times, dtype=np.float64)


def timestamp_gaps(times, fps: float) -> list[tuple[int, int]]:
    """Where frames are missing from timestamps (seconds): ``(after frame i, missing count)``, the
    count being the frame periods ``1/fps`` between two times, rounded, less one.

    Raises
    ------
    ValueError unless the timestamps are (T,) and strictly increasing and ``fps`` is a positive
    number.
    """
    t = np.asarray(times, dtype=np.float64)
    if t.ndim != 1 or not np.all(np.diff(t) > 0):
        raise ValueError("expected strictly increasing timestamps (T,) in seconds")
    if not (np.isfinite(fps) and fps > 0):
        raise ValueError(f"expected a frame rate of a positive number of frames per second, got {fps!r}")
    steps = np.rint(np.diff(t) * fps).astype(np.int64)
    return [(int(i), int(s - 1)) for i, s in enumerate(steps) if s > 1]


def insert_missing(motion: Motion, missing: list[tuple[int, int]]) -> tuple[Motion, list[tuple[int, int]]]:
    """Insert NaN frames: ``missing`` holds ``(after frame i, count)``; returns the longer motion
    and its gaps ``(start, stop)``.

    Raises
    ------
    ValueError unless every entry is two whole numbers, a count >= 0 after a frame ``i`` with
    0 <= i < T - 1, and no frame is named twice.
    """
    order = sorted(_whole(entry) for entry in missing)
    after = [i for i, n in order if n > 0]
    if len(set(after)) < len(after):
        twice = sorted({i for i in after if after.count(i) > 1})
        raise ValueError(f"frames missing after frame {twice[0]} are given twice; give one count per place")
    order = [(i, n) for i, n in order if n > 0]
    rot, root, lpos, gaps = [], [], [], []
    prev, shift = 0, 0
    J = motion.skeleton.num_joints
    for i, n in order:
        if not 0 <= i < motion.num_frames - 1:
            raise ValueError(f"frames can only go missing between frames 0 and {motion.num_frames - 1}, got after {i}")
        rot += [motion.local_rot[prev : i + 1], np.full((n, J, 4), np.nan)]
        root += [motion.root_pos[prev : i + 1], np.full((n, 3), np.nan)]
        if motion.local_pos is not None:
            lpos += [motion.local_pos[prev : i + 1], np.full((n, J, 3), np.nan)]
        gaps.append((i + 1 + shift, i + 1 + shift + n))
        shift += n
        prev = i + 1
    rot.append(motion.local_rot[prev:])
    root.append(motion.root_pos[prev:])
    if motion.local_pos is not None:
        lpos.append(motion.local_pos[prev:])
    out = Motion(motion.skeleton, np.concatenate(rot), np.concatenate(root), motion.fps,
                 np.concatenate(lpos) if lpos else None, motion.name)  # fmt: skip
    return out, gaps


def _whole(entry) -> tuple[int, int]:
    """``(after frame i, count)`` of an :func:`insert_missing` entry, both whole numbers, count >= 0."""
    try:
        i, n = entry
        ok = float(i).is_integer() and float(n).is_integer() and n >= 0
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"expected (after frame, count) as two whole numbers, the count >= 0, got {entry!r}")
    return int(i), int(n)


# ---------------------------------------------------------------------------- filling
def fill_rows(x, curve: str = "linear") -> np.ndarray:
    """Fill NaN rows of a plain array (T, D) by linear interpolation between bounding rows
    (α from ``curve``); leading/trailing NaN rows copy the nearest known row.

    Raises
    ------
    ValueError for an empty array or one whose every row is missing.
    """
    x = np.asarray(x, dtype=np.float64)
    if x.ndim < 1 or len(x) == 0:
        raise ValueError(f"expected a (T, ...) array, got shape {x.shape}")
    out = x.copy()
    for a, b in nan_gaps(x):
        if a == 0 and b == len(x):
            raise ValueError("every row is missing; nothing to interpolate from")
        if a == 0:
            out[:b] = out[b]
        elif b == len(x):
            out[a:] = out[a - 1]
        else:
            w = alphas(b - a, curve).reshape((-1,) + (1,) * (x.ndim - 1))
            out[a:b] = out[a - 1] + w * (out[b] - out[a - 1])
    return out


def _edge_fill(motion: Motion, a: int, b: int) -> Motion:
    """Leading/trailing gaps: hold the nearest known frame."""
    out = motion.copy()
    src = b if a == 0 else a - 1
    out.local_rot[a:b] = motion.local_rot[src]
    out.root_pos[a:b] = motion.root_pos[src]
    if out.local_pos is not None:
        out.local_pos[a:b] = motion.local_pos[src]
    return out


def _frame_features(motion: Motion, t: int, before: bool) -> np.ndarray:
    lo, hi = (t - 1, t + 1) if before else (t, t + 2)
    lo, hi = max(lo, 0), min(hi, motion.num_frames)
    seg = motion[lo:hi] if hi - lo >= 2 else motion[[t, t]]
    if not np.all(np.isfinite(seg.local_rot)):
        seg = motion[[t, t]]
    f = pose_features(seg)
    return f[-1] if before else f[0]


def _library_fill(out: Motion, a: int, b: int, lib: MotionLibrary, labels, prev_frame=None) -> bool:
    """Fill ``a+1 … b-1`` with the library; False when no stretch fits."""
    num = b - a - 1
    ctx = (
        prev_frame if prev_frame is not None else (a - 1 if a >= 1 and np.all(np.isfinite(out.local_rot[a - 1])) else a)
    )
    trans = out.translations()
    try:
        rot, tr, _ = lib.fill(
            out.local_rot[[ctx, a]][None], trans[[ctx, a]][None], out.local_rot[b][None], trans[b][None], num,
            k=1, allowed_labels=labels,
        )  # fmt: skip
    except ValueError:
        return False
    out.local_rot[a + 1 : b] = rot[0]
    out.root_pos[a + 1 : b] = tr[0, :, 0]
    if out.local_pos is not None:
        out.local_pos[a + 1 : b] = tr[0]
    return True


def _place_key_pose(out: Motion, slot: int, node_motion: Motion, frame: int, a: int, b: int, j: int) -> None:
    """Copy ``node_motion[frame]`` into ``out[slot]``, root-aligned (reference joint ``j``) onto the
    line from ``a`` to ``b``."""
    rot_ab, pos_ab = reference_transform(out, [a, b], joint=j)
    u = (slot - a) / (b - a)
    yaw_a, yaw_b = quat.yaw(rot_ab)
    yaw = yaw_a + u * float(np.angle(np.exp(1j * (yaw_b - yaw_a))))
    ground = (1 - u) * pos_ab[0] + u * pos_ab[1]
    key = node_motion[frame]
    krot, kpos = reference_transform(key, [0], joint=j)
    theta = yaw - float(quat.yaw(krot[0]))
    turn = quat.from_yaw(theta)
    shift = ground - quat.rotate(turn, kpos[0])
    shift[1] = 0.0
    out.local_rot[slot] = key.local_rot[0]
    out.local_rot[slot, 0] = quat.mul(turn, key.local_rot[0, 0])
    out.root_pos[slot] = quat.rotate(turn, key.root_pos[0]) + shift
    if out.local_pos is not None:
        out.local_pos[slot] = key.translations()[0]
        out.local_pos[slot, 0] = out.root_pos[slot]


def _node_frame(graph: ActionGraph, name: str, feats: np.ndarray) -> int:
    """The frame of node ``name``'s clip nearest to the feature row ``feats`` (D,)."""
    f = graph.nodes[name].features
    return int(np.argmin(np.sum((f - feats[None]) ** 2, axis=1)))


def _clip_run(clip: Motion, start: int, count: int, out: Motion, at: int, anchor: int, ref: int):
    """Frames ``start … start+count-1`` of ``clip`` (clamped to the clip: a run past its end holds
    the last frame), moved rigidly (eq. 3: yaw about +Y and a ground translation) so that clip frame
    ``anchor`` lands on frame ``at`` of ``out``. Returns rotations (count, J, 4) and translations
    (count, J, 3), metres."""
    idx = np.clip(np.arange(start, start + count), 0, clip.num_frames - 1)
    ra, pa = reference_transform(out, [at], joint=ref)
    rb, pb = reference_transform(clip, [anchor], joint=ref)
    seg = apply_rigid(clip[idx], estimate_rigid(ra[0], pa[0], rb[0], pb[0]))
    return seg.local_rot, seg.translations()


def moving_slerp(rot_a, trans_a, rot_b, trans_b, curve: str = "linear") -> tuple[np.ndarray, np.ndarray]:
    """Eq. 4 with its moving indices: a blend between two *running* sequences.

    ``s_k = slerp(q_A[m+k], q_B[n−L+k], α(k))``, ``k = 0 … L``: sequence A runs on from its
    transition frame ``A(m)`` while sequence B runs into its transition frame ``B(n)``, and the
    weight moves from A to B (``α(0) = 0``, ``α(L) = 1``; between them ``α`` from ``curve``). Both
    ends move, so the in-between keeps the motion of the two actions instead of sliding between
    two frozen poses; when each sequence holds one repeated frame it is plain SLERP. (The paper
    leaves the index directions open; this reading keeps both sequences in forward time.)

    Parameters
    ----------
    rot_a, rot_b : array (L+1, J, 4)      local rotations of A's frames m … m+L and B's n−L … n
    trans_a, trans_b : array (L+1, J, 3)  their translations (root: world position), metres,
                                          already root-aligned (:mod:`.alignment`)
    curve : α curve (:func:`~.slerp.alphas`)

    Returns
    -------
    rot : ndarray (L+1, J, 4), trans : ndarray (L+1, J, 3)

    Raises
    ------
    ValueError unless the sequences are two (L+1, J, 4) arrays with L >= 1.
    """
    rot_a, rot_b = quat.check(rot_a, "rot_a"), quat.check(rot_b, "rot_b")
    if rot_a.shape != rot_b.shape or rot_a.ndim != 3 or len(rot_a) < 2:
        raise ValueError(f"expected two (L+1, J, 4) sequences with L >= 1, got {rot_a.shape} and {rot_b.shape}")
    L = len(rot_a) - 1
    w = np.concatenate([[0.0], alphas(L - 1, curve), [1.0]])
    rot = quat.slerp(rot_a, rot_b, w[:, None])
    trans = np.asarray(trans_a) + w[:, None, None] * (np.asarray(trans_b) - np.asarray(trans_a))
    return rot, trans


def _moving_piece(out: Motion, lo: int, hi: int, run_a, run_b, curve: str) -> None:
    """Fill ``out[lo+1 … hi-1]`` with :func:`moving_slerp` of the aligned runs, then blend the
    remaining mismatch at both ends away (as :class:`~.library.MotionLibrary` does), so the piece
    meets ``out[lo]`` and ``out[hi]`` exactly."""
    rot, trans = moving_slerp(run_a[0], run_a[1], run_b[0], run_b[1], curve)
    L = hi - lo
    u = np.arange(L + 1) / L
    t_all = out.translations()
    d_a = quat.mul(out.local_rot[lo], quat.conj(rot[0]))
    d_b = quat.mul(out.local_rot[hi], quat.conj(rot[L]))
    rot = quat.mul(quat.slerp(d_a[None], d_b[None], u[:, None]), rot)
    trans = trans + (1 - u)[:, None, None] * (t_all[lo] - trans[0]) + u[:, None, None] * (t_all[hi] - trans[L])
    out.local_rot[lo + 1 : hi] = rot[1:L]
    out.root_pos[lo + 1 : hi] = trans[1:L, 0]
    if out.local_pos is not None:
        out.local_pos[lo + 1 : hi] = trans[1:L]


def _known_reference_joint(motion: Motion) -> int:
    """:func:`~.alignment.reference_joint` judged on the known frames only (NaN rows would hide a
    moving hips channel and make every rig look root-driven)."""
    known = np.flatnonzero(np.all(np.isfinite(motion.root_pos), axis=1))
    return reference_joint(motion[known] if known.size else motion)


def _outside_velocity(motion: Motion, t: int, step: int, joint: int) -> np.ndarray | None:
    """Velocity (3,) of the reference joint at known frame ``t``, metres/frame, from the frames on
    the far side of ``t`` (``step = -1``: ``t-1, t-2``; ``step = +1``: ``t+1, t+2``).

    Three-point one-sided difference ``±(3p_t − 4p_{t∓1} + p_{t∓2}) / 2`` when both neighbours
    are known, two-point ``±(p_t − p_{t∓1})`` with one, ``None`` with none.
    """
    frames = [f for f in (t, t + step, t + 2 * step) if 0 <= f < motion.num_frames]
    _, pos = reference_transform(motion, frames, joint=joint)
    ok = np.all(np.isfinite(pos), axis=1)
    if len(pos) < 2 or not ok[1]:
        return None
    if len(pos) == 3 and ok[2]:
        return -step * (3.0 * pos[0] - 4.0 * pos[1] + pos[2]) / 2.0
    return -step * (pos[0] - pos[1])


def _own_velocities(path: np.ndarray, knots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The filled path's own one-sided velocities at the anchors, metres/frame.

    ``path`` (F, 3) holds the reference joint at frames ``knots[0] … knots[-1]`` (index 0 is
    ``knots[0]``); ``knots`` (K,) are the anchor frames, increasing. Returns ``leave`` (K-1, 3), the
    velocity leaving anchor ``i`` into piece ``i``, and ``arrive`` (K-1, 3), the velocity arriving at
    anchor ``i+1`` from piece ``i``: three-point differences inside a piece of two or more steps
    (the same scheme as :func:`_outside_velocity`), else the chord.
    """
    k = knots - knots[0]
    lo, hi = k[:-1], k[1:]
    long_piece = (hi - lo >= 2)[:, None]
    three_point_leave = (-3.0 * path[lo] + 4.0 * path[lo + 1] - path[np.minimum(lo + 2, hi)]) / 2.0
    three_point_arrive = (3.0 * path[hi] - 4.0 * path[hi - 1] + path[np.maximum(hi - 2, lo)]) / 2.0
    leave = np.where(long_piece, three_point_leave, path[lo + 1] - path[lo])
    arrive = np.where(long_piece, three_point_arrive, path[hi] - path[hi - 1])
    return leave, arrive


def _catmull_rom_tangents(knots: np.ndarray, points: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Tangents (K, 3) at ``knots`` (K,) through ``points`` (K, 3), per frame: the given ``start``
    and ``end`` (3,) at the ends, ``(P_{i+1} − P_{i−1}) / (t_{i+1} − t_{i−1})`` in between."""
    m = np.empty_like(points)
    m[1:-1] = (points[2:] - points[:-2]) / (knots[2:] - knots[:-2])[:, None]
    m[0], m[-1] = start, end
    return m


def _pieces(knots: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For frames ``knots[0]+1 … knots[-1]-1`` (F of them): the piece ``i`` (F,) each lies in
    (between anchors ``i`` and ``i+1``), its length ``h`` (F, 1) in frames and ``s = (t − t_i) / h``
    (F, 1), in (0, 1] (``s = 1`` at an inner anchor, which ends its piece)."""
    t = np.arange(knots[0] + 1, knots[-1])
    i = np.searchsorted(knots, t, side="left") - 1
    h = (knots[i + 1] - knots[i]).astype(np.float64)[:, None]
    return i, h, (t - knots[i])[:, None] / h


def _tangent_swap(knots: np.ndarray, new: np.ndarray, leave: np.ndarray, arrive: np.ndarray) -> np.ndarray:
    """Displacements (F, 3) for frames ``knots[0]+1 … knots[-1]-1`` that turn a path leaving/arriving
    at the anchors with velocities ``leave``/``arrive`` (K-1, 3) into one with tangents ``new`` (K, 3).

    On piece ``i`` (length ``h``, ``s = (t − t_i) / h``) it is the difference of two cubic Hermite
    segments with the same end points, ``h·[h10(s)(m_i − leave_i) + h11(s)(m_{i+1} − arrive_i)]``
    with ``h10 = s(1−s)²`` and ``h11 = s²(s−1)``: zero at every anchor, slope ``m − old`` there.
    """
    i, h, s = _pieces(knots)
    h10, h11 = s * (1.0 - s) ** 2, s * s * (s - 1.0)
    return h * (h10 * (new[i] - leave[i]) + h11 * (new[i + 1] - arrive[i]))


def _floor_guard(motion: Motion, a: int, b: int, drop: np.ndarray) -> np.ndarray:
    """``drop`` (F,) — vertical root displacements for frames ``a+1 … b-1`` — limited so that no
    foot goes through the floor: a frame whose lowest joint is at ``g`` in ``motion`` may end at
    ``min(g, floor)``, no lower, ``floor`` being the lower of the lowest joints of frames ``a`` and
    ``b``. A foot above the floor does not go through it; one already below does not sink further.
    The root joint is left out (:func:`.footing.lowest_joints`).

    The limit is per frame, so where it acts the path follows the fill's own height (which the
    recorded pose put on the floor) instead of the smooth curve: a floor contact outranks C1 there
    (a C1 bump that vanishes at the anchors would lift a whole piece to cover contact next to one).
    """
    low = lowest_joints(motion, a, b)
    return np.maximum(drop, np.minimum(0.0, min(low[0], low[-1]) - low[1:-1]))


def lift_above_floor(motion: Motion, a: int, b: int) -> Motion:
    """A copy of ``motion`` whose frames ``a+1 … b-1`` are raised (root translation, +Y) just enough
    that no joint but the root goes below the floor of the gap's known ends ``a`` and ``b`` (the
    lower of their lowest joints).

    SLERP between two strides can swing a leg through the floor half-way; lifting the whole body
    by the overshoot keeps the feet on the floor at the cost of a small vertical bob, which the
    eye forgives far more readily than a foot in the ground. Frames already above the floor are untouched.
    """
    out = motion.copy()
    if b - a < 2:
        return out
    low = lowest_joints(motion, a, b)
    lift = np.maximum(0.0, min(low[0], low[-1]) - low[1:-1])
    out.root_pos[a + 1 : b, 1] += lift
    if out.local_pos is not None:
        out.local_pos[a + 1 : b, 0] = out.root_pos[a + 1 : b]
    return out


def _feet_on_floor(motion: Motion, a: int, b: int) -> Motion:
    """Frames ``a+1 … b-1`` with every foot that went below the floor raised onto it by bending its
    leg (:func:`.footing.plant_feet`), and the body lifted by whatever the legs could not reach
    (:func:`lift_above_floor`)."""
    return lift_above_floor(plant_feet(motion, a, b), a, b)


def _floor_rule(feet: str):
    """The function ``(motion, a, b) -> Motion`` of the :data:`FEET` choice ``feet``."""
    return _feet_on_floor if feet == "plant" else lift_above_floor


def smooth_root(motion: Motion, anchors, joint: int | None = None) -> Motion:
    """A copy of ``motion`` whose root path through ``anchors`` is C1 (no corners).

    ``anchors`` (K >= 2 increasing frames ``a = t_0 < … < t_{K-1} = b``) are known frames or placed
    key poses; the frames strictly between them were filled piece by piece, each piece meeting its
    two anchors with its own velocities, so the path has corners at the anchors. The reference
    joint's path ``p`` (world positions, see :func:`~.alignment.reference_joint`) becomes

    .. math::  p^*(t) = p(t) + S(t) - H(t)

    on every piece: ``S`` is the cubic Hermite spline through the anchor points ``P_i`` with
    tangents ``m_i`` — at ``a`` and ``b`` the velocity measured just outside the gap (frames
    ``a-1, a-2`` and ``b+1, b+2``), Catmull-Rom ``(P_{i+1} − P_{i−1}) / (t_{i+1} − t_{i−1})`` at
    inner anchors — and ``H`` is the cubic Hermite segment with the same end points but the
    piece's *own* velocities at its ends. ``S − H`` is zero at every anchor, so ``p*`` still passes
    exactly through the anchors, and it swaps the piece's end velocities for ``m_i``, so both sides
    of an anchor leave it at ``m_i``; what the piece does in between — the bob and sway of a
    recorded stretch — is kept. Velocities on both sides are three-point one-sided differences:
    two-point ones describe the half-frame before (after) the anchor and would force zero
    acceleration across it, a bias that a long gap spreads into centimetres.

    Alternatives rejected on real data (Bandai Namco walks cut and refilled from other walks, and
    notebook 06's run → squat): ``p* = S`` (a pure spline) loses the recorded detail and lands
    furthest from the truth; ``p* = S + (p − L)`` with
    ``L`` the chord-wise linear path keeps the pieces' corners, since a recorded stretch does not
    leave its anchor along the chord. For a piece filled linearly (SLERP fallback) all three
    agree: ``p = L = H``.

    The displacement is added to the root translation, which moves the reference joint (and every
    other joint) by the same amount; where it would push a foot through the floor it is held back
    (:func:`_floor_guard`). Where a velocity outside the gap cannot be measured (first/last frame,
    NaN neighbours) that end keeps the fill's own velocity.

    Parameters
    ----------
    motion : Motion, finite at frames ``a … b`` (frames outside may hold NaN)
    anchors : sequence of int, increasing; the path changes only strictly between ``a`` and ``b``
    joint : the reference joint; default :func:`~.alignment.reference_joint` of the known frames

    Raises
    ------
    ValueError unless ``anchors`` are two or more increasing frames of the motion whose
    root path between them is filled.
    """
    knots = np.asarray(anchors, dtype=np.int64)
    if knots.ndim != 1 or knots.size < 2 or np.any(np.diff(knots) < 1):
        raise ValueError(f"expected two or more increasing anchor frames, got {list(anchors)}")
    a, b = int(knots[0]), int(knots[-1])
    if a < 0 or b >= motion.num_frames:
        raise ValueError(f"anchors {list(anchors)} lie outside the {motion.num_frames}-frame motion")
    out = motion.copy()
    if b - a < 2:
        return out
    j = _known_reference_joint(motion) if joint is None else int(joint)
    _, path = reference_transform(motion, np.arange(a, b + 1), joint=j)  # (F, 3), path[0] is frame a
    if not np.all(np.isfinite(path)):
        raise ValueError(f"frames {a}…{b} must be filled before the root through them can be smoothed")
    leave, arrive = _own_velocities(path, knots)
    v_a = _outside_velocity(motion, a, -1, j)
    v_b = _outside_velocity(motion, b, +1, j)
    start = leave[0] if v_a is None else v_a
    end = arrive[-1] if v_b is None else v_b
    tangents = _catmull_rom_tangents(knots.astype(np.float64), path[knots - a], start, end)
    delta = _tangent_swap(knots, tangents, leave, arrive)
    delta[:, 1] = _floor_guard(motion, a, b, delta[:, 1])
    out.root_pos[a + 1 : b] += delta
    if out.local_pos is not None:
        out.local_pos[a + 1 : b, 0] = out.root_pos[a + 1 : b]
    return out


def _follow(motion: Motion, a: int, b: int, joint: int, target: np.ndarray) -> Motion:
    """A copy of ``motion`` whose reference joint follows ``target`` (b−a−1, 3) over frames
    ``a+1 … b-1``, moved by the root translation and held back from the floor as in
    :func:`smooth_root`."""
    _, path = reference_transform(motion, np.arange(a + 1, b), joint=joint)
    delta = target - path
    delta[:, 1] = _floor_guard(motion, a, b, delta[:, 1])
    out = motion.copy()
    out.root_pos[a + 1 : b] += delta
    if out.local_pos is not None:
        out.local_pos[a + 1 : b, 0] = out.root_pos[a + 1 : b]
    return out


def _follow_strides(motion: Motion, a: int, b: int, joint: int, target: np.ndarray) -> Motion:
    """:func:`_follow` the strides' path ``target``; where the body speeds up or slows down across
    the gap (:func:`.detect.changes_speed` of the mean ground speeds over a second on each side),
    the path's end velocities are then swapped for the ones measured outside the gap
    (:func:`smooth_root`), keeping the strides' bob and sway in between.

    The strides carry the speed of the side they come from across the gap; where only one side
    holds a stride (:data:`.stride.MIN_STRIDES`) and the other is a start from standing, that speed
    is wrong near the other end, which the measured end velocities correct. The rules compared:
    ``docs/results_interpolation.md`` (``python -m experiments.interpolation.compare_stride_root``)."""
    out = _follow(motion, a, b, joint, target)
    if detect.changes_speed(*side_speeds(motion, a, b, joint)):
        out = smooth_root(out, [a, b], joint=joint)
    return out


def _stride_root(motion: Motion, a: int, b: int, joint: int) -> Motion:
    """:func:`.stride.stride_path` for the reference joint over frames ``a+1 … b-1``, followed as
    in :func:`_follow_strides` (or :func:`smooth_root` through ``[a, b]`` where no stride is
    found)."""
    target = stride_path(motion, a, b, joint) if b - a >= 2 else None
    return smooth_root(motion, [a, b], joint=joint) if target is None else _follow_strides(motion, a, b, joint, target)


def fill(
    motion: Motion,
    method: str = "slerp",
    graph: ActionGraph | None = None,
    curve: str = "linear",
    root: str = "linear",
    *,
    feet: str = "plant",
) -> tuple[Motion, list[FilledGap]]:
    """Fill every NaN frame of ``motion``; returns the filled copy and a report per gap.

    Raises ``ValueError`` for an unknown ``method``, ``root`` or ``feet``, a ``"graph"`` fill
    without a graph or with one on another skeleton, or a motion with every frame missing.

    Every rule moves the body by the joint that carries it, the reference joint of the known
    frames (:func:`~.alignment.reference_joint`): on a rig whose joint 0 the recording holds still
    while a joint below it moves (Bandai Namco's ``joint_Root`` and hips), the joints above the
    reference joint keep the recorded values between each gap's ends
    (:func:`~.alignment.carry_by_reference`), never a path of their own.

    Parameters
    ----------
    motion : Motion with NaN rows where frames are missing (see :func:`insert_missing`)
    method : ``"slerp"`` (SLERP + linear root), ``"hermite"`` (Hermite root and rotations from the
        velocities around the gap), ``"stride"`` (the whole body continued from the recorded
        strides on both sides, :mod:`.stride`, the root leaving and reaching the gap at the
        velocities measured outside it where the two sides' speeds differ,
        :func:`.detect.changes_speed`; SLERP with ``root`` where no stride is found, or where
        SLERP fills up to :data:`REHEARSALS` cuts of the gap's size in the known frames within
        :data:`.detect.REHEARSAL_SECONDS` of it nearer the truth) or
        ``"graph"`` (needs ``graph``: key-pose-guided filling within
        an action, key poses of intermediate actions across actions; the root through the gap's
        ends and key poses is then made C1 by :func:`smooth_root`)
    graph : ActionGraph whose node clips use ``motion``'s skeleton
    curve : α(k) curve for the interpolated parts
    root : for ``"slerp"``/``"hermite"``, the reference joint's path across each gap:
        ``"linear"`` (the LaFAN1 baseline); ``"hermite"``, the cubic Hermite curve whose end
        tangents are the velocities measured just outside the gap (:func:`smooth_root` with the
        gap's two ends as anchors), so a walking character keeps walking through it at the speed
        it had on both sides; or ``"stride"``, the recorded strides on both sides continued across
        the gap (turned with the walker's heading) and blended (``_stride_root``; the Hermite
        curve where no stride can be read), which keeps the hips' bob and sway. The
        foot-through-floor guard of :func:`smooth_root` applies to both. (The ``"graph"`` method
        always uses the Hermite curve through its key poses.)
    feet : keyword-only; how every filled gap between known frames (not a leading or trailing
        one) is kept out of the floor of its two known ends (:data:`FEET`): ``"plant"`` (default)
        bends the leg of each foot that went below it (:func:`.footing.plant_feet`) and lifts the
        body by what the legs cannot reach; ``"lift"`` lifts the body only
        (:func:`lift_above_floor`).

    """
    _check_fill(motion, method, graph, root, feet)
    out = motion.copy()
    report = []
    T = motion.num_frames
    ref = _known_reference_joint(motion)
    for start, stop in _motion_nan_gaps(motion):
        if start == 0 or stop == T:
            if start == 0 and stop == T:
                raise ValueError("every frame is missing; nothing to fill from")
            out = _edge_fill(out, start, stop)
            report.append(FilledGap(start, stop, "hold"))
            continue
        if method == "graph":
            out, gap = _fill_through_graph(out, start, stop, graph, curve, ref, feet)
        else:
            out, gap = _fill_inside(out, start, stop, method, curve, root, ref, feet, rehearse=motion)
        out = carry_by_reference(out, start - 1, stop, ref)  # the joints above the reference joint as recorded
        report.append(gap)
    return out, report


def _check_fill(motion: Motion, method: str, graph: ActionGraph | None, root: str, feet: str) -> None:
    """The ``ValueError`` of :func:`fill` for an unknown method, root mode or floor rule, or a
    graph that is missing, empty, or on another skeleton or frame rate than ``motion``."""
    if method not in METHODS:
        raise ValueError(f"unknown filling method {method!r}; expected one of {METHODS}")
    if root not in ROOTS:
        raise ValueError(f"unknown root mode {root!r}; expected one of {ROOTS}")
    if feet not in FEET:
        raise ValueError(f"unknown floor rule feet={feet!r}; expected one of {FEET}")
    if method == "graph":
        if graph is None or not graph.nodes:
            raise ValueError("method='graph' needs an ActionGraph with at least one action")
        clip = next(iter(graph.nodes.values())).motion
        if clip.skeleton.names != motion.skeleton.names:
            raise ValueError("the action graph's clips use another skeleton than the motion to fill")
        if abs(clip.fps - motion.fps) > 1e-6 * motion.fps:
            raise ValueError(
                f"the action graph's clips are at {clip.fps:g} fps, the motion to fill at {motion.fps:g}: "
                "resample one (Motion.resample)"
            )


def _fill_inside(out: Motion, start: int, stop: int, method: str, curve: str, root: str, ref: int, feet: str,
                 rehearse: Motion | None = None):  # fmt: skip
    """One gap ``[start, stop)`` with known frames on both sides, filled without a graph (methods
    ``"slerp"``, ``"hermite"``, ``"stride"`` of :func:`fill`; with ``rehearse``, the motion as
    recorded, its gaps NaN, a stride fill only where it passes the rehearsal on it,
    :func:`_stride_rehearsed`) and kept out of the floor by the :data:`FEET` rule ``feet``; returns
    the filled motion and its :class:`FilledGap`."""
    a, b = start - 1, stop
    if method == "stride":
        strided = stride_fill(out, a, b, ref)
        if strided is not None and (
            rehearse is None or _stride_rehearsed(rehearse, start, stop, (curve, root, ref, feet))
        ):
            out = _floor_rule(feet)(_follow_strides(strided[0], a, b, ref, strided[1]), a, b)
            return out, FilledGap(start, stop, "stride")
    mode = "hermite" if method == "hermite" else "linear"  # stride: SLERP where no stride is found
    out = inbetween.fill_between(out, start, stop, curve=curve, root=mode, joint=ref,
                                 rotation="hermite" if method == "hermite" else "slerp")  # fmt: skip
    if root == "stride":
        out = _stride_root(out, a, b, ref)
    elif root == "hermite":
        out = smooth_root(out, [a, b], joint=ref)
    out = _floor_rule(feet)(out, a, b)
    return out, FilledGap(start, stop, "slerp" if method == "stride" else method)


def _rehearsal_cuts(motion: Motion, start: int, stop: int) -> list[int]:
    """Starts of at most :data:`REHEARSALS` cuts of the gap's size (``stop − start`` frames) in the
    known frames within :data:`.detect.REHEARSAL_SECONDS` of the gap, a known frame on each side of
    each cut, evenly spread over both sides."""
    n, reach = stop - start, int(round(detect.REHEARSAL_SECONDS * motion.fps))
    known = np.isfinite(motion.local_rot).all(axis=(1, 2)) & np.isfinite(motion.root_pos).all(axis=1)
    ok = np.convolve(known, np.ones(n + 2), "valid") == n + 2  # ok[c - 1]: frames c-1 … c+n known
    first, last = max(1, start - reach), min(stop + reach, motion.num_frames - 1) - n  # cut and frame after it
    places = first + np.flatnonzero(ok[first - 1 : max(last, first - 1)])
    if len(places) > REHEARSALS:
        places = places[np.linspace(0, len(places) - 1, REHEARSALS).round().astype(int)]
    return [int(c) for c in places]


def _stride_rehearsed(motion: Motion, start: int, stop: int, how: tuple) -> bool:
    """Whether the stride fill keeps the gap ``[start, stop)``: it does unless the fill used where
    no stride is found (SLERP) comes nearer the truth on the rehearsal cuts
    (:func:`_rehearsal_cuts`; every joint's world position, mean over the cuts' frames): each gap
    gets the fill that did better on the stream itself, near it. ``motion``: as recorded, its
    gaps NaN (a gap filled before is no truth to rehearse on); ``how``: ``(curve, root, reference
    joint, feet)`` of :func:`_fill_inside`."""
    n, reach = stop - start, int(np.ceil((detect.REHEARSAL_SECONDS + SIDE_SECONDS) * motion.fps)) + 2
    lo = max(0, start - reach)  # what a cut's fills read: its strides, within SIDE_SECONDS of it
    motion, start, stop = motion[lo : stop + reach], start - lo, stop - lo
    truth = motion.global_positions()
    error = {"stride": 0.0, "slerp": 0.0}
    for c in _rehearsal_cuts(motion, start, stop):
        holed = motion.copy()
        for values in (holed.local_rot, holed.root_pos, holed.local_pos):
            if values is not None:
                values[c : c + n] = np.nan
        for method in error:
            filled, _ = _fill_inside(holed, c, c + n, method, *how)
            error[method] += float(
                np.linalg.norm(filled[c : c + n].global_positions() - truth[c : c + n], axis=-1).mean()
            )
    return error["stride"] <= error["slerp"]


def _place_path(out: Motion, a: int, b: int, graph: ActionGraph, ref: int):
    """The graph stage of :func:`fill` before the pieces: the path from ``a``'s action to ``b``'s,
    the key pose of every intermediate action placed (in ``out``, in place) at evenly spaced
    frames, and ``{anchor frame: (action, frame of its clip)}`` for ``a``, the key poses and ``b``.

    Returns ``(path, inner, slots, placed)``; ``inner`` and ``slots`` are empty where the gap is
    too short to hold the intermediate key poses (then the gap is filled without them).
    """
    node_a = graph.classify(_frame_features(out, a, before=True)[None])[0]
    node_b = graph.classify(_frame_features(out, b, before=False)[None])[0]
    path = graph.path(node_a, node_b)
    inner = path[1:-1]
    slots = [a + int(round((i + 1) * (b - a) / (len(inner) + 1))) for i in range(len(inner))]
    slots = [s for s in slots if a < s < b]
    if len(slots) < len(inner) or len(set(slots)) < len(slots):
        inner, slots = [], []  # gap too short for the intermediate key poses: plain filling
    prev = path[0]
    placed = {a: (path[0], _node_frame(graph, path[0], _frame_features(out, a, before=True)))}
    for name, slot in zip(inner, slots):
        _, j, _ = graph.best_transition(prev, name)
        _place_key_pose(out, slot, graph.nodes[name].motion, j, a, b, ref)
        placed[slot] = (name, j)
        prev = name
    placed[b] = (path[-1], _node_frame(graph, path[-1], _frame_features(out, b, before=False)))
    return path, inner, slots, placed


def _fill_through_graph(
    out: Motion, start: int, stop: int, graph: ActionGraph, curve: str, ref: int, feet: str
) -> tuple[Motion, FilledGap]:
    """One gap ``[start, stop)`` filled through ``graph`` (method ``"graph"`` of :func:`fill`):
    across actions, eq. 4 between consecutive key poses; inside one action, the node's recordings
    (:mod:`.library`, SLERP where none fits); the root then C1 through the anchors, and the feet
    kept out of the floor by the :data:`FEET` rule ``feet``. Returns the filled motion and its
    :class:`FilledGap`."""
    a, b = start - 1, stop
    path, inner, slots, placed = _place_path(out, a, b, graph, ref)
    lib = graph.library()
    anchors = [a] + slots + [b]
    used = "library"
    for lo, hi in zip(anchors[:-1], anchors[1:]):
        if hi - lo < 2:
            continue
        if inner:  # across nodes: eq. 4, node lo's clip running on, node hi's clip running in
            (na, m), (nb, n) = placed[lo], placed[hi]
            L = hi - lo
            run_a = _clip_run(graph.nodes[na].motion, m, L + 1, out, lo, m, ref)
            run_b = _clip_run(graph.nodes[nb].motion, n - L, L + 1, out, hi, n, ref)
            _moving_piece(out, lo, hi, run_a, run_b, curve)
            continue
        ok = _library_fill(out, lo, hi, lib, sorted(set(path)), prev_frame=None if lo == a else lo)
        if not ok:
            out = inbetween.fill_between(out, lo + 1, hi, curve=curve)
            used = "graph+slerp"
    out = _floor_rule(feet)(smooth_root(out, anchors, joint=ref), a, b)
    return out, FilledGap(start, stop, "graph" if inner else used, path, slots)
