"""Clips: a varied set of synthetic clips on one character (training data, no downloads).

Each clip is either one behaviour or a sequence of two to four behaviours with transitions,
every segment with its own jittered :func:`~.style.random_style` (stride, cadence, lean, arm
swing, turning, jump height, squat depth, …) and its own seed.

Used by every notebook when ``MOTIONLAB_DATA`` is unset (see ``notebooks/01_preprocessing.ipynb``).
"""

from __future__ import annotations

import numpy as np

from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.synthetic.gaits import sequence
from motionlab.synthetic.style import BEHAVIOURS, random_style

__all__ = ["dataset"]

_ODDS = {"idle": 0.08, "walk": 0.32, "run": 0.25, "jump": 0.15, "squat": 0.2}
_MIN_SEGMENT = 45  # frames


def _split(rng: np.random.Generator, total: int, parts: int) -> list[int]:
    parts = max(1, min(parts, total // _MIN_SEGMENT))
    if parts == 1:
        return [total]
    slack = total - parts * _MIN_SEGMENT  # frames left after every part got its minimum
    if slack >= parts - 1:  # distinct cut points (the stream the shipped checkpoint was trained on)
        cuts = np.sort(rng.choice(np.arange(1, slack + 1), parts - 1, replace=False))
    else:  # too little slack for distinct cuts: parts may share it unevenly
        cuts = np.sort(rng.integers(0, slack + 1, size=parts - 1))
    sizes = np.diff(np.concatenate([[0], cuts, [slack]])) + _MIN_SEGMENT
    return [int(s) for s in sizes]


def dataset(
    num_clips: int,
    seed: int = 0,
    skeleton: Skeleton | None = None,
    fps: float = 60.0,
    num_frames: int = 240,
) -> list[Motion]:
    """``num_clips`` clips of ``num_frames`` frames each, on ``skeleton``.

    Parameters
    ----------
    num_clips : int        how many clips
    seed : int             everything is deterministic under this seed
    skeleton : canonical 22-joint Skeleton; ``None``: ``canonical_skeleton()``
    fps : float            frames per second
    num_frames : int       frames per clip (>= 1)

    Returns
    -------
    list of Motion, named ``"clip003:walk>run"``

    Raises
    ------
    ValueError when a count is not an integer or below its minimum.
    """
    for label, value, low in (("num_clips", num_clips, 0), ("num_frames", num_frames, 1)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
            raise ValueError(f"{label} must be an integer >= {low}, got {value!r}")
    rng = np.random.default_rng(seed)
    names = list(BEHAVIOURS)
    odds = np.array([_ODDS[b] for b in names])
    clips = []
    for k in range(int(num_clips)):
        parts = 1 if rng.random() < 0.35 else int(rng.integers(2, 5))
        sizes = _split(rng, int(num_frames), parts)
        behaviours: list[str] = []
        for _ in sizes:
            p = odds.copy()
            if behaviours:  # no behaviour twice in a row
                p[names.index(behaviours[-1])] = 0.0
            behaviours.append(names[int(rng.choice(len(names), p=p / p.sum()))])
        segments = [(b, n, random_style(b, rng)) for b, n in zip(behaviours, sizes)]
        motion = sequence(segments, skeleton, fps, seed=int(rng.integers(2**31)))
        clips.append(motion.copy(name=f"clip{k:03d}:{motion.name}"))
    return clips
