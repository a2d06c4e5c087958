"""How many frames a gap hides, read off other recordings of the same action (paper C, §3.3).

The paper tracks the incoming stream in an action graph built from recordings of the same
actions. Those recordings also say *how long* a body takes to go from one pose to another: a
walker who slows down inside a turn is matched by other turns that slow down too; a start from
standing by other starts. For a gap between stream frames ``t`` and ``t+1``:

1. **Match both ends.** The ``K`` known frames up to ``t`` (``t-K+1 … t``) are compared with every
   run of ``K`` frames in the recorded takes, ending at frame ``i``; the ``K`` frames from ``t+1``
   with every run starting at frame ``j``. Frames are compared by the joints of the body (the
   reference joint and the joints below it), their heading-frame positions and weighted
   heading-frame velocities (as in :mod:`.features`), mean squared difference per joint:

   .. math::  c_b(i) = \\tfrac{1}{K J}\\sum_{k<K} \\lVert f(t-k) - f_c(i-k\\rho) \\rVert^2, \\qquad
              c_a(j) = \\tfrac{1}{K J}\\sum_{k<K} \\lVert f(t+1+k) - f_c(j+k\\rho) \\rVert^2 .

   Takes are recorded at other tempi, so each window is matched time-scaled: stream frame ``t-k``
   against the take at ``i − k·ρ`` for ``ρ`` in ``RATES`` (take frames per stream frame, 2/3 … 3/2,
   5% apart), the squared distances to the two take frames around that point blended linearly;
   each ``i`` (``j``) keeps its best ``ρ_b`` (``ρ_a``).
2. **Read the duration.** In a take, ``L = j - i`` frames lead from the matched pose before the
   gap to the matched pose after it; the stream needs ``n + 1 = L / ρ``, ``ρ = (ρ_b + ρ_a)/2``.
   For each take, ``L`` runs over the local minima (in ``L``) of ``min_i c_b(i) + c_a(i+L)``: in a
   gait those lie a stride apart (the same pair of poses comes back every stride), and the one
   whose count is nearest the distance estimate ``guess`` (:func:`~.detect.estimate_missing`) is
   kept: the recordings fix the phase, the distance only the number of whole strides.
3. **Combine.** The ``BEST`` takes with the lowest matching cost vote; the count is their median.
   The match quality is that median cost over the stream's own squared pace (RMS heading-frame
   joint displacement per frame) at the gap: below 1, the recordings hold both ends of the gap
   closer than the stream's next frame is to its last. It is reported, not used to decide.

Every take is also used mirrored (left and right joints swapped, lateral axis negated), so a left
turn can be read off recorded right turns. The take being scored must never be among the
recordings.

Taught in ``notebooks/06_keypose_interpolation.ipynb``; used by :func:`~.detect.estimate_missing`
when recordings are given.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np

from motionlab.core import quat
from motionlab.core.motion import Motion, check_one_rig
from motionlab.interpolation.alignment import reference_joint
from motionlab.interpolation.features import VELOCITY_WEIGHT, heading_frame

__all__ = ["CONTEXT", "BEST", "MAX_SECONDS", "RecordedTakes", "mirror_index", "body_features", "recorded_missing"]

CONTEXT = 0.4
"""Seconds of known frames matched on each side of a gap (``K`` = 12 frames at 30 fps)."""

BEST = 9
"""How many takes vote (those with the lowest matching costs)."""

RATES = np.geomspace(2.0 / 3.0, 1.5, 17)
"""Time scales ``ρ`` (take frames per stream frame) tried when matching a window (5% apart)."""

MAX_SECONDS = 3.0
"""Longest stretch ``L`` (seconds) searched in a take."""


def mirror_index(names: Sequence[str]) -> np.ndarray | None:
    """For each joint, its mirror joint (left ↔ right by name; a middle joint is its own), or
    ``None`` where a left or right joint has no partner or no joint is named left or right. Recognises ``Left``/``Right``, ``left``/``right`` and ``_L``/``_R``,
    ``.L``/``.R``, ``L_``/``R_`` affixes."""
    pairs = [("Left", "Right"), ("left", "right")]

    def swap(name: str) -> str:
        for a, b in pairs:
            if a in name:
                return name.replace(a, b)
            if b in name:
                return name.replace(b, a)
        m = re.fullmatch(r"(.*[_.])([LR])", name) or re.fullmatch(r"([LR])(_.*)", name)
        if m:
            head, tail = m.group(1), m.group(2)
            if head in ("L", "R"):
                return {"L": "R", "R": "L"}[head] + tail
            return head + {"L": "R", "R": "L"}[tail]
        return name

    index = {n: k for k, n in enumerate(names)}
    out = np.asarray([index.get(swap(n), -1) for n in names])
    return None if out.min() < 0 or np.array_equal(out, np.arange(len(out))) else out


def _body(motion: Motion, ref: int | None = None) -> tuple[int, np.ndarray]:
    """Reference joint (``ref``, else :func:`~.alignment.reference_joint`) and a mask (J,) of it and
    the joints below it."""
    j = reference_joint(motion) if ref is None else int(ref)
    return j, motion.skeleton.subtree(j)


def body_features(
    motion: Motion,
    mirror: bool = False,
    ref: int | None = None,
    velocity_weight: float = VELOCITY_WEIGHT,
    difference: str = "central",
):
    """Per-frame features of the body and its pose pace.

    ``ref``: the reference joint (default :func:`~.alignment.reference_joint`); the takes of a
    :class:`RecordedTakes` and the stream use one, so their features line up. ``difference``: the
    velocity at frame ``t`` from ``t-1 … t+1`` (``"central"``), ``t-1 … t`` (``"backward"``) or
    ``t … t+1`` (``"forward"``; one-sided at the clip's ends in every case). A window that ends just
    before a gap (or starts just after it) takes one-sided velocities, so none differences across it.

    Returns
    -------
    feat : ndarray (T, 6K)   heading-frame positions (metres) and ``velocity_weight`` × heading-frame
                             velocities (m/s) of the reference joint and the K-1 joints below it
    pace : ndarray (T,)      RMS over those joints of the heading-frame position change into each
                             frame (frame 0: into frame 1), metres per frame

    Raises
    ------
    ValueError for an unknown ``difference``, or (mirrored) a left or right joint with no
    partner by name.
    """
    g_rot, g_pos = motion.fk()
    j, inside = _body(motion, ref)
    local, yaw, _ = heading_frame(g_rot, g_pos, j)
    if difference not in ("central", "backward", "forward"):
        raise ValueError(f"difference must be 'central', 'backward' or 'forward', got {difference!r}")
    if difference == "central" or len(g_pos) < 2:
        delta = np.gradient(g_pos, axis=0) if len(g_pos) > 1 else np.zeros_like(g_pos)
    else:
        step = np.diff(g_pos, axis=0)  # (T-1, J, 3): frame t to t+1
        delta = np.concatenate([step[:1], step]) if difference == "backward" else np.concatenate([step, step[-1:]])
    vel = quat.rotate(quat.from_yaw(-yaw)[:, None], delta * motion.fps)
    if mirror:
        swap = mirror_index(motion.skeleton.names)
        if swap is None:
            raise ValueError(f"clip {motion.name!r}: cannot mirror, a left or right joint has no partner by name")
        flip = np.array([-1.0, 1.0, 1.0])
        local, vel = local[:, swap] * flip, vel[:, swap] * flip
    local, vel = local[:, inside], vel[:, inside]
    step = np.sqrt(np.mean(np.sum(np.diff(local, axis=0) ** 2, axis=-1), axis=-1))
    pace = np.concatenate([step[:1], step]) if len(step) else np.zeros(1)
    feat = np.concatenate([local, velocity_weight * vel], axis=-1).reshape(len(local), -1)
    return feat, pace


class RecordedTakes:
    """Other recordings of the stream's actions, indexed for :func:`recorded_missing`.

    Parameters
    ----------
    motions : sequence of Motion, or an :class:`~.action_graph.ActionGraph` (its nodes' clips)
        on one skeleton and frame rate; never the take being filled
    mirror : bool   also use every take mirrored (needs left/right joint names, :func:`mirror_index`)
    """

    def __init__(self, motions, mirror: bool = True) -> None:
        """Per-frame features of the takes, ready to be read off.

        Raises
        ------
        ValueError for no clip, or only clips shorter than two frames.
        """
        if hasattr(motions, "nodes"):
            motions = [node.motion for node in motions.nodes.values()]
        motions = list(motions)
        if not motions:
            raise ValueError("recorded takes: need at least one clip")
        check_one_rig(motions)
        first = motions[0]
        mirror = bool(mirror) and mirror_index(first.skeleton.names) is not None
        refs = [reference_joint(m) for m in motions]  # one body for all: the takes' usual reference joint
        self.ref = int(np.bincount(refs).argmax())
        feats, paces, clip, owner = [], [], [], []
        for c, m in enumerate(motions):
            if m.num_frames < 2:
                continue
            for flip in (False, True) if mirror else (False,):
                f, p = body_features(m, flip, self.ref)
                feats.append(f)
                paces.append(p)
                clip.append(np.full(len(f), 2 * c + int(flip)))
                owner.append(np.full(len(f), c))
        if not feats:
            raise ValueError("recorded takes: every clip is shorter than two frames")
        self.takes = [m.name for m in motions]
        self.owner = np.concatenate(owner)  # (N,) index into ``takes`` (a take and its mirror image)
        self.names = list(first.skeleton.names)
        self.fps = float(first.fps)
        self.feat = np.concatenate(feats)  # (N, D)
        self.pace = np.concatenate(paces)  # (N,)
        self.clip = np.concatenate(clip)  # (N,) take (2c, or 2c+1 mirrored)
        self.frame = np.concatenate([np.arange(len(f)) for f in feats])
        self.length = np.concatenate([np.full(len(f), len(f)) for f in feats])
        self._sq = np.sum(self.feat**2, axis=1)  # (N,) |F[i]|²

    def without(self, name: str) -> RecordedTakes:
        """These takes less every take named ``name`` (and its mirror image): leave one take out.

        Raises
        ------
        ValueError when no take would be left.
        """
        keep = np.array([n != name for n in self.takes])[self.owner]
        if not keep.any():
            raise ValueError(f"recorded takes: nothing left without {name!r}")
        out = object.__new__(RecordedTakes)
        out.__dict__.update(self.__dict__)
        for attr in ("feat", "pace", "clip", "frame", "length", "owner", "_sq"):
            setattr(out, attr, getattr(self, attr)[keep])
        return out

    def _window_costs(self, q: np.ndarray, ending: bool, rates: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Best time-scaled match of the ``k`` stream frames ``q`` (k, D) at every take frame.

        Stream frame ``a`` of the window is compared with the take at ``i − (k−1−a)·ρ`` (window
        ending at take frame ``i``, ``ending``) or ``j + a·ρ`` (starting at ``j``), the squared
        feature distances to the two take frames around that point blended linearly, for every
        rate ``ρ`` in ``rates`` (take frames per stream frame).

        Returns
        -------
        cost : ndarray (N,)  mean squared feature difference per joint at the best rate; inf where
                             the run would leave its take
        rate : ndarray (N,)  that rate
        """
        k = len(q)
        d2 = np.sum(q**2, axis=1)[:, None] + self._sq[None, :] - 2.0 * q @ self.feat.T  # (k, N)
        d2 = np.maximum(d2, 0.0)
        n = len(self.frame)
        start = np.arange(n) - self.frame  # first row of each frame's take
        best, best_rate = np.full(n, np.inf), np.ones(n)
        joints = self.feat.shape[1] / 6.0
        for rho in rates:  # loops over rates and context frames, vectorised over the take frames
            cost = np.zeros(n)
            for a in range(k):
                off = -(k - 1 - a) * rho if ending else a * rho
                x = self.frame + off  # position in the take
                lo = np.floor(x)
                w = x - lo
                lo = np.clip(lo, 0, self.length - 1).astype(np.int64)
                hi = np.minimum(lo + 1, self.length - 1)
                cost += (1.0 - w) * d2[a, start + lo] + w * d2[a, start + hi]
            span = (k - 1) * rho
            ok = (self.frame - span >= 0) if ending else (self.frame + span <= self.length - 1)
            cost = np.where(ok, cost / (k * joints), np.inf)
            better = cost < best
            best, best_rate = np.where(better, cost, best), np.where(better, rho, best_rate)
        return best, best_rate


def recorded_missing(
    motion: Motion,
    t: int,
    takes: RecordedTakes,
    guess: float,
    start: int = 0,
    stop: int | None = None,
) -> tuple[float, float] | None:
    """The missing count at step ``t → t+1`` read off ``takes``, and its match quality.

    Parameters
    ----------
    motion : Motion, the stream (frames missing, nothing inserted), the takes' skeleton and fps
    t : int, the step that hides the gap
    takes : :class:`RecordedTakes`
    guess : float, the distance estimate of the count (picks the number of whole strides)
    start, stop : the known frames around the gap are ``start … t`` and ``t+1 … stop``

    Returns
    -------
    (count, quality) or None
        count : float, frames missing (``n``, not ``n+1``)
        quality : float, the voting takes' median matching cost over the stream's squared pace at
        the gap (dimensionless; below 1 is a match closer than one frame of the stream's motion)
        ``None`` when no take holds both ends.

    Raises
    ------
    ValueError when the stream's skeleton or frame rate differs from the takes'.
    """
    if tuple(motion.skeleton.names) != tuple(takes.names):
        raise ValueError("the stream uses another skeleton than the recorded takes")
    if abs(motion.fps - takes.fps) > 1e-6 * takes.fps:
        raise ValueError(f"the stream is at {motion.fps:g} fps, the recorded takes at {takes.fps:g}")
    stop = motion.num_frames - 1 if stop is None else int(stop)
    k = max(2, int(round(CONTEXT * motion.fps)))
    kb, ka = min(k, t - start + 1), min(k, stop - t)
    if kb < 2 or ka < 2:
        return None
    # each side on its own: a velocity must not difference across the gap
    fb, pb = body_features(motion[t - kb + 1 : t + 1], ref=takes.ref)
    fa, pa = body_features(motion[t + 1 : t + 1 + ka], ref=takes.ref)
    cb, rb = takes._window_costs(fb, ending=True, rates=RATES)  # (N,) a take run ending at i
    ca, ra = takes._window_costs(fa, ending=False, rates=RATES)  # (N,) a take run starting at j
    n_all = len(cb)
    max_len = int(round(MAX_SECONDS * motion.fps))
    lags = np.arange(1, max_len + 1)
    j = np.arange(n_all)[:, None] + lags[None, :]  # (N, L)
    inside = j < n_all
    jj = np.minimum(j, n_all - 1)
    same = inside & (takes.clip[jj] == takes.clip[:, None])
    cost = np.where(same, cb[:, None] + ca[jj], np.inf)  # (N, L)
    stream_pace = float(np.mean(np.r_[pb[1:], pa[1:]]))
    if not stream_pace > 0:
        return None
    # per take: the best pair for each L, its local minima in L, the one nearest the guess
    uniq = np.unique(takes.clip)
    votes = []
    for c in uniq:  # a loop over takes, vectorised over frames and lags inside
        rows = np.flatnonzero(takes.clip == c)
        block = cost[rows]  # (n_c, L)
        best_i = np.argmin(block, axis=0)  # (L,)
        m = block[best_i, np.arange(len(lags))]
        fin = np.isfinite(m)
        if fin.sum() < 3:
            continue
        mm = np.where(fin, m, np.inf)
        left = np.concatenate([[np.inf], mm[:-1]])
        right = np.concatenate([mm[1:], [np.inf]])
        minima = np.flatnonzero(fin & (mm <= left) & (mm <= right))
        if not minima.size:
            continue
        i0 = rows[best_i[minima]]
        j0 = i0 + lags[minima]
        counts = lags[minima] / (0.5 * (rb[i0] + ra[j0])) - 1.0  # take frames → stream frames
        pick = int(np.argmin(np.abs(counts - guess)))
        votes.append((float(mm[minima[pick]]), float(counts[pick])))
    return _combine(votes, stream_pace)


def _combine(votes: list, stream_pace: float) -> tuple[float, float] | None:
    """Median count and quality of the ``BEST`` lowest-cost votes ``(cost, count)``."""
    if not votes:
        return None
    votes = sorted(votes)
    top = np.array(votes[:BEST])
    quality = float(np.median(top[:, 0])) / stream_pace**2
    return float(np.median(top[:, 1])), quality
