"""Measuring gap detection and filling on clips with frames removed on purpose.

A clean clip has its frames ``start … start+n-1`` cut out; the shortened stream goes through what
``motionlab fill-gaps`` does (:func:`.detect.detect`, :func:`.gaps.insert_missing`,
:func:`.gaps.fill` with SLERP rotations and, by default, the stride-continued root) and is compared with the clip:

* **detection**: was the step ``start-1 → start`` flagged, and was anything else flagged;
* **count**: the estimated missing count against ``n`` (within 10% or one frame is the goal), and
  against the *countable* frames: those of the ``n`` that are not exact copies of a frame kept
  beside the gap (a clip padded with its last pose, :data:`.detect.HELD`, loses frames there that
  nothing in the stream can count);
* **root**: the reference joint's path over the gap, the filled one resampled at the true frames'
  fractions of the gap (the counts may differ), mean distance to the true path, relative to the
  true displacement across the gap;
* **floor**: how far the lowest non-root joint of the filled frames goes below the clip's floor;
* **pose**: the mean distance of every joint, taken about the reference joint, from the truth
  (resampled the same way), centimetres.

Used by ``experiments/interpolation/check_gaps.py`` and notebook 06.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core.motion import Motion
from motionlab.interpolation import detect, gaps
from motionlab.interpolation.alignment import reference_joint, reference_transform
from motionlab.interpolation.inbetween import concatenate
from motionlab.interpolation.stride import sample_rotations, sample_rows

__all__ = ["CutResult", "cut", "retimed", "countable", "evaluate_cut", "summary", "detection_counts"]


@dataclass
class CutResult:
    """One clip with ``n`` frames cut at ``start`` (see the module docstring).

    Attributes
    ----------
    name : str
    n, start : int
    hit : bool                  the gap's step was flagged
    false : int                 other steps flagged
    countable : int             the removed frames that are not copies of a kept frame beside
                                the gap (:func:`countable`; ``n`` but in held poses)
    estimate : int or None      missing count (None when the gap was not found)
    root_rel : float or None    mean root error over the gap / true displacement
    displacement : float or None  the true displacement across the gap, metres (the root error
                                in metres is ``root_rel * displacement``)
    below : float or None       lowest filled foot below the clip's floor, metres (>= 0)
    pose_cm : float or None     mean joint position error about the reference joint, centimetres
                                (the body's shape, the root error left out)
    """

    name: str
    n: int
    start: int
    hit: bool
    false: int
    countable: int
    estimate: int | None = None
    root_rel: float | None = None
    displacement: float | None = None
    below: float | None = None
    pose_cm: float | None = None

    @property
    def count_ok(self) -> bool:
        """The count is within 10% (or one frame) of the frames removed."""
        return self.estimate is not None and abs(self.estimate - self.n) <= max(1.0, 0.1 * self.n)

    @property
    def countable_ok(self) -> bool:
        """The count is within 10% (or one frame) of the countable frames removed."""
        m = self.countable
        return self.estimate is not None and abs(self.estimate - m) <= max(1.0, 0.1 * m)


def cut(motion: Motion, start: int, n: int) -> Motion:
    """``motion`` without frames ``start … start+n-1`` (at least one frame kept on each side)."""
    _check_cut(motion, start, n)
    return motion[np.r_[0:start, start + n : motion.num_frames]]


def retimed(motion: Motion, start: int, n: int, m: int) -> Motion:
    """``motion`` with its frames ``start … start+n-1`` replayed over ``m`` frames: the same stretch
    of motion, from frame ``start-1`` to frame ``start+n-1``, at another pace (``m > n``: slower),
    read between the frames linearly (positions) and by SLERP (rotations); every other frame unchanged.

    Cut ``m`` frames at ``start`` from it, and the stream is exactly the one cut ``n`` frames at
    ``start`` from ``motion`` (:func:`cut`): how many frames a gap held, and how fast the body moved
    in it, does not show outside the gap. (T + m − n frames.)"""
    _check_cut(motion, start, n)
    if m < 1:
        raise ValueError(f"cannot replay {n} frames over {m}: expected at least one frame")
    frames = np.arange(start - 1, start + n)  # n steps, from the frame kept before
    x = np.arange(1, m + 1) * (n / m)  # m new frames, at fractional rows of ``frames``; the last is row n
    local_pos = None if motion.local_pos is None else sample_rows(motion.local_pos[frames], x)
    middle = Motion(motion.skeleton, sample_rotations(motion.local_rot[frames], x), sample_rows(motion.root_pos[frames], x),
                    motion.fps, local_pos, motion.name)  # fmt: skip
    return concatenate([motion[:start], middle, motion[start + n :]])


def _check_cut(motion: Motion, start: int, n: int) -> None:
    if not (start >= 1 and start + n < motion.num_frames and n >= 1):
        raise ValueError(
            f"cannot cut {n} frames at {start} from {motion.name!r}, a {motion.num_frames}-frame motion "
            "(at least one frame must be kept on each side)"
        )


def countable(motion: Motion, start: int, n: int) -> int:
    """How many of the frames ``start … start+n-1`` of ``motion`` are not exact copies of frame
    ``start-1`` or ``start+n`` (the frames kept beside the cut): copies differ by at most
    :data:`.detect.HELD` of the body height (RMS over the joints), as held poses do. A stream
    cut there cannot show how many copies it lost."""
    _check_cut(motion, start, n)
    pos = motion.global_positions()
    held = detect.HELD * detect.body_height(motion)
    inside = pos[start : start + n]
    copy = np.zeros(n, dtype=bool)
    for kept in (pos[start - 1], pos[start + n]):  # the two frames beside the cut
        copy |= np.sqrt(np.mean(np.sum((inside - kept) ** 2, axis=-1), axis=-1)) <= held
    return int(n - copy.sum())


def detection_counts(motion: Motion, find, removed, rng: np.random.Generator, margin: int = 20) -> tuple[int, int, int]:
    """Detection on cuts of ``motion``: for each ``n`` in ``removed``, frames ``s … s+n-1`` removed at
    a random ``s`` (``margin`` frames from either end; skipped when the clip is too short) and
    ``find(stream)`` asked for the steps that hide missing frames.

    Returns ``(hits, false_flags, cases)``: cuts whose step ``s-1 → s`` was flagged, other steps
    flagged, and cuts made.
    """
    hits = false = cases = 0
    for n in removed:
        if motion.num_frames - n - 2 * margin <= margin:
            continue
        s = int(rng.integers(margin, motion.num_frames - n - margin))
        found = find(cut(motion, s, n))
        hit = int((s - 1) in found)
        hits, false, cases = hits + hit, false + len(found) - hit, cases + 1
    return hits, false, cases


def evaluate_cut(
    motion: Motion,
    start: int,
    n: int,
    graph=None,
    method: str = "stride",
    root: str = "stride",
    takes=None,
    found: list[tuple[int, int]] | None = None,
    *,
    feet: str = "plant",
) -> CutResult:
    """Cut, detect (against ``graph`` if given, else the stream itself; counts also from the other
    recordings ``takes`` if given, :class:`.recorded.RecordedTakes`, never holding ``motion``), fill
    (``method``, ``root`` and ``feet`` of :func:`.gaps.fill`; by default what ``motionlab fill-gaps``
    does), compare. ``found``: the detection's ``(step, count)`` pairs of the cut stream, if already made
    (to compare fills on the same counts)."""
    stream = cut(motion, start, n)
    if found is None:
        found = detect.detect(stream, graph=graph, takes=takes)
    steps = [t for t, _ in found]
    hit = (start - 1) in steps
    res = CutResult(motion.name, n, start, hit, len(steps) - int(hit), countable(motion, start, n))
    if not hit:
        return res
    est = dict(found)[start - 1]
    filled, _ = gaps.fill(gaps.insert_missing(stream, found)[0], method=method, root=root, feet=feet)
    shift = sum(c for t, c in found if t < start - 1)  # frames inserted before this gap
    a = start - 1 + shift
    ref = reference_joint(motion)
    _, truth = reference_transform(motion, joint=ref)
    _, path = reference_transform(filled, np.arange(a, a + est + 2), joint=ref)
    u = np.arange(1, n + 1) / (n + 1)
    at = np.stack([np.interp(u, np.linspace(0.0, 1.0, est + 2), path[:, k]) for k in range(3)], axis=1)
    err = float(np.linalg.norm(at - truth[start : start + n], axis=1).mean())
    disp = float(np.linalg.norm(truth[start + n] - truth[start - 1]))
    true_pos = motion.global_positions()
    floor = float(true_pos[:, 1:, 1].min())
    filled_pos = filled[a : a + est + 2].global_positions()  # (est+2, J, 3), frame a first
    low = float(filled_pos[1:-1, 1:, 1].min())
    below = floor - low  # rounding below a nanometre is not a foot in the floor
    x = u * (est + 1)  # the true frames' places among the filled ones
    lo = np.minimum(np.floor(x).astype(np.int64), est)
    f = (x - lo)[:, None, None]
    body = (1.0 - f) * filled_pos[lo] + f * filled_pos[lo + 1] - at[:, None, :]  # joints about the root
    true_body = true_pos[start : start + n] - truth[start : start + n, None, :]
    res.pose_cm = float(100.0 * np.linalg.norm(body - true_body, axis=-1).mean())
    res.estimate, res.root_rel, res.below = int(est), err / max(disp, 1e-9), below if below > 1e-9 else 0.0
    res.displacement = disp
    return res


def summary(results: list[CutResult]) -> dict:
    """Precision, recall, fraction of counts within tolerance, root and floor figures of many cuts."""
    tp = sum(r.hit for r in results)
    fp = sum(r.false for r in results)
    counted = [r for r in results if r.estimate is not None]
    rel = np.array([r.root_rel for r in counted]) if counted else np.zeros(0)
    below = np.array([r.below for r in counted]) if counted else np.zeros(0)
    return {
        "cases": len(results),
        "precision": tp / max(tp + fp, 1),
        "recall": tp / max(len(results), 1),
        "count_ok": float(np.mean([r.count_ok for r in counted])) if counted else 0.0,
        "countable_ok": float(np.mean([r.countable_ok for r in counted])) if counted else 0.0,
        "root_rel_mean": float(rel.mean()) if rel.size else float("nan"),
        "root_rel_max": float(rel.max()) if rel.size else float("nan"),
        "below_max": float(below.max()) if below.size else float("nan"),
        "pose_cm_mean": float(np.mean([r.pose_cm for r in counted])) if counted else float("nan"),
    }
