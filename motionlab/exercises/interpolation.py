"""Experiment exercises of notebook 06 (key-pose interpolation): each changes one parameter of an
experiment the notebook runs, and the check reruns the experiment on the notebook's own inputs.

1. :data:`held_out_q`: choose PPCA's q by the likelihood of frames held out in one block;
2. :data:`walk_spacing`: the paper's walk experiment (Fig. 6/7): how far apart key frames may be;
3. :data:`smallest_gap`: the fewest dropped frames the stream-against-itself rule finds;
4. :data:`key_frames`: what searching best transitions between key frames only costs.
"""

from __future__ import annotations

import numpy as np

from .core import Mistake, Question

__all__ = [
    "held_out_q",
    "Q_CHOICES",
    "HELD_OUT",
    "walk_spacing",
    "SPACINGS",
    "JOINT_LIMIT",
    "smallest_gap",
    "CUT_AT",
    "key_frames",
]


# --------------------------------------------------------------------------- exercise 1: q on held-out frames
Q_CHOICES = (1, 2, 4, 8, 16, 32)
"""The latent sizes exercise 1 chooses among."""

HELD_OUT = 0.25
"""Exercise 1 holds out the last quarter of every clip's frames."""


def _best_q(clips, split: str = "tail", stats: str = "train") -> int:
    """The q of :data:`Q_CHOICES` with the highest PPCA log-likelihood per frame on the held-out frames.

    ``split``: ``"tail"`` (the last :data:`HELD_OUT` of each clip, the right way) or
    ``"interleaved"`` (every second frame); ``stats``: standardise with the training frames'
    mean and std (``"train"``) or all frames' (``"all"``).
    """
    from motionlab.interpolation import features
    from motionlab.interpolation.ppca import PPCA

    feats = [features.pose_features(c) for c in clips.values()]
    if split == "tail":
        cut = [len(f) - max(int(round(HELD_OUT * len(f))), 1) for f in feats]
        train = np.concatenate([f[:k] for f, k in zip(feats, cut)])
        test = np.concatenate([f[k:] for f, k in zip(feats, cut)])
    else:
        every = np.concatenate(feats)
        train, test = every[::2], every[1::2]
    basis = train if stats == "train" else np.concatenate(feats)
    mean, std = basis.mean(0), np.maximum(basis.std(0), 1e-6)
    scores = [PPCA(q).fit((train - mean) / std).log_likelihood((test - mean) / std) for q in Q_CHOICES]
    return int(Q_CHOICES[int(np.argmax(scores))])


held_out_q = Question(
    "06 · exercise 1 (experiment: q by held-out likelihood)",
    lambda clips: _best_q(clips),
    mistakes=[
        Mistake(
            lambda clips: _best_q(clips, stats="all"),
            "your mean and std come from every frame, the held-out ones too: standardise with the "
            "training frames' alone, so that nothing of the held-out frames reaches the model.",
        ),
        Mistake(
            lambda clips: _best_q(clips, split="interleaved"),
            "your test frames interleave the training frames (each sits between two frames the model "
            "was fitted on), so a larger q always looks better: hold out the *last quarter* of each clip.",
        ),
        Mistake(
            lambda clips: max(Q_CHOICES),
            "the largest q is the best only on frames the model has (nearly) seen: score frames held out "
            "in one block at the end of each clip.",
        ),
    ],
)


# --------------------------------------------------------------------------- exercise 2: how far apart key frames may be
SPACINGS = (10, 15, 20, 30, 45, 60)
"""The key-frame spacings (frames) exercise 2 tries."""

JOINT_LIMIT = 6.0
"""Exercise 2's bound (degrees) on every walking joint's mean angle error (section 7's claim)."""


def _walk_error(
    walk, every: int = 60, first: int = 5, curve: str = "linear", unit: str = "deg", reduce=np.mean
) -> float:
    """Angle error (mean over the filled frames; ``reduce`` over :data:`motionlab.interpolation.demo.WALK_JOINTS`)
    when frames ``first, first+every, …`` of ``walk`` are kept and the rest filled by SLERP with a Hermite root."""
    from motionlab.core import quat
    from motionlab.interpolation import gaps
    from motionlab.interpolation.demo import WALK_JOINTS

    kept = np.arange(first, walk.num_frames, every)
    span = walk[first : kept[-1] + 1]
    holed, _ = gaps.insert_missing(span[kept - first], [(i, every - 1) for i in range(len(kept) - 1)])
    filled, _ = gaps.fill(holed, method="slerp", root="hermite", curve=curve)
    lost = np.setdiff1d(np.arange(span.num_frames), kept - first)
    idx = [list(walk.skeleton.names).index(n) for n in WALK_JOINTS]
    err = reduce(quat.angle_between(filled.local_rot[lost][:, idx], span.local_rot[lost][:, idx]).mean(axis=0))
    return float(np.degrees(err) if unit == "deg" else err)


def _largest_spacing(walk, reduce=np.max, curve: str = "linear", first_failing: bool = False) -> float:
    """The largest spacing of :data:`SPACINGS` whose error (``reduce`` over the joints) stays below
    :data:`JOINT_LIMIT` (0: none does); with ``first_failing``, the smallest that does not."""
    ok = [_walk_error(walk, every, curve=curve, reduce=reduce) < JOINT_LIMIT for every in SPACINGS]
    if first_failing:
        return float(next((s for s, good in zip(SPACINGS, ok) if not good), 0))
    return float(max((s for s, good in zip(SPACINGS, ok) if good), default=0))


walk_spacing = Question(
    "06 · exercise 2 (experiment: how far apart key frames may be)",
    lambda walk: _largest_spacing(walk),
    mistakes=[
        Mistake(
            lambda walk: _largest_spacing(walk, reduce=np.mean),
            "that spacing keeps the *mean over the joints* under 6°; the question asks that every joint stays under it.",
        ),
        Mistake(
            lambda walk: _largest_spacing(walk, first_failing=True),
            "that is the first spacing at which a joint reaches 6°; the question asks for the largest that stays under.",
        ),
    ],
)
"""Exercise 2: the largest spacing of :data:`SPACINGS` (frames) at which the walk experiment keeps
every walking joint's mean angle error under :data:`JOINT_LIMIT`."""


# --------------------------------------------------------------------------- exercise 3: the smallest gap found
CUT_AT = 100
"""Exercise 3 removes frames from ``CUT_AT`` on."""


def _smallest_gap(walk, at: int = CUT_AT, largest: int = 8, rule: str = "flagged") -> int:
    """The fewest frames (1 … ``largest``) removed from frame ``at`` on whose gap
    :func:`motionlab.interpolation.detect.consecutive_gaps` flags; ``largest + 1`` if none."""
    from motionlab.interpolation import detect

    for n in range(1, largest + 1):
        cut = walk[np.r_[0:at, at + n : walk.num_frames]]
        if rule == "flagged" and at - 1 in detect.consecutive_gaps(cut):
            return n
        if rule == "any" and detect.consecutive_gaps(cut):
            return n
    return largest + 1


smallest_gap = Question(
    "06 · exercise 3 (experiment: the smallest gap found)",
    lambda walk: _smallest_gap(walk),
    mistakes=[
        Mistake(
            lambda walk: 1,
            "one missing frame makes a step about twice its neighbours (D ≈ 2): is that above Δ = 2.5?",
        ),
        Mistake(
            lambda walk: _smallest_gap(walk) - 1,
            "that many removed frames are not flagged yet: the answer is the fewest that are.",
        ),
    ],
)
"""Exercise 3: the fewest frames removed from frame :data:`CUT_AT` on that ``detect.consecutive_gaps`` flags."""


# --------------------------------------------------------------------------- exercise 4: transitions between key frames only
def _key_cost(clips, a: str = "walk", b: str = "stand", num_keys: int = 5, inverse: bool = False) -> float:
    """D of the best transition ``a → b`` searched between ``num_keys`` key frames per node (§3.1),
    over the smallest D between any two frames of the two clips."""
    from motionlab.interpolation.action_graph import ActionGraph
    from motionlab.interpolation.features import distance_matrix, pose_features

    graph = ActionGraph()
    for name in (a, b):
        graph.add_node(name, clips[name], num_keys=num_keys)
    keyed = graph.best_transition(a, b)[2]
    every = float(distance_matrix(pose_features(clips[a]), pose_features(clips[b])).min())
    return every / keyed if inverse else keyed / every


key_frames = Question(
    "06 · exercise 4 (experiment: transitions between key frames only)",
    lambda clips: _key_cost(clips),
    atol=0.006,  # an answer typed with two decimals passes
    rtol=0.002,
    mistakes=[
        Mistake(
            lambda clips: _key_cost(clips, inverse=True),
            "that is D over all frames divided by D between key frames; the question asks for the inverse (a number ≥ 1).",
        ),
        Mistake(
            lambda clips: _key_cost(clips, num_keys=1),
            "that uses one key frame per node; keep section 6's num_keys=5.",
        ),
    ],
)
"""Exercise 4: D of walk → stand's best transition between 5 key frames per node over the smallest D
between any frames of the two clips (1: the key frames lose nothing)."""
