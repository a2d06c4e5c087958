r"""Cutting a periodic clip into whole gait cycles, from foot contacts (paper B, the first step).

Paper B prepares each basic clip by keeping whole cycles: a walk cycle is a left step and a
right step, ending in (nearly) the pose it began with. The cycle boundaries come from foot
contacts:

* a foot *touches* the ground on frames where its ankle is less than ``height`` metres above
  the clip's ground level (the 5th percentile of that foot's height, so a clip recorded a
  little above or below ``y = 0`` needs no correction) and moves slower than ``speed`` m/s
  horizontally;
* runs of contact shorter than ``min_frames`` are noise and ignored; a *strike* is the first
  frame of a contact run;
* a cycle runs from one left strike to the next left strike, with exactly one right strike in
  between; frames before the first and after the last whole cycle are the start and stop
  parts (kept by the graph builder, where they serve as transitions in and out).

Everything is vectorised over frames (contact labels, strike detection by ``np.diff``).

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core import contacts as _contacts
from motionlab.core.motion import Motion

__all__ = ["Cycles", "Spans", "contacts", "strikes", "cycles_from_ankles", "segment_cycles", "FOOT_JOINTS"]

FOOT_JOINTS = ("LeftFoot", "RightFoot")
"""Ankle joints of the canonical humanoid whose contacts define the cycles."""


class Spans:
    """Whole pieces of a take (gait cycles or action segments), held as ``bounds``: int array,
    shape (K, 2), ``[first, stop)`` frames of each piece."""

    bounds: np.ndarray

    @property
    def count(self) -> int:
        """Number of whole pieces."""
        return int(self.bounds.shape[0])

    @property
    def span(self) -> tuple[int, int]:
        """``[first, stop)`` of the whole pieces together (``(0, 0)`` when there is none)."""
        if self.count == 0:
            return (0, 0)
        return int(self.bounds[0, 0]), int(self.bounds[-1, 1])

    def lengths(self) -> np.ndarray:
        """(K,) frames per piece."""
        return self.bounds[:, 1] - self.bounds[:, 0]


@dataclass(frozen=True)
class Cycles(Spans):
    """Gait cycles of one clip.

    Attributes
    ----------
    left, right : int arrays, strike frames of the left and right foot (ascending)
    bounds : int array, shape (C, 2), ``[first, stop)`` frames of each whole cycle (C may be 0)
    num_frames : frames of the clip

    ``count``, ``span`` and ``lengths()`` of the whole cycles come from :class:`Spans`.
    """

    left: np.ndarray
    right: np.ndarray
    bounds: np.ndarray
    num_frames: int


def contacts(pos, fps: float, feet=(0, 1), height: float = 0.06, speed: float = 0.6) -> np.ndarray:
    """Contact labels of the ``feet`` joints.

    Parameters
    ----------
    pos : ndarray, shape (T, F, 3) or (T, J, 3)   world positions, metres, Y up
    fps : frames per second
    feet : joint indices into ``pos`` (default: the first two, as in ``(T, 2, 3)`` input)
    height : metres above the clip's ground level (5th percentile of each foot's height)
    speed : horizontal speed limit, m/s

    Returns
    -------
    ndarray, shape (T, len(feet)), bool
    """
    p = np.asarray(pos, dtype=np.float64)[:, list(feet), :]
    if p.shape[0] < 2:
        return np.zeros(p.shape[:2], dtype=bool)
    ground = np.percentile(p[:, :, 1], 5, axis=0)
    return _contacts.low_and_slow(p, ground, height, speed, float(fps), horizontal=True)


def strikes(contact: np.ndarray, min_frames: int = 3) -> np.ndarray:
    """First frames of the contact runs of at least ``min_frames`` frames.

    Parameters
    ----------
    contact : ndarray, shape (T,), bool

    Returns
    -------
    int array of frames (a run already in contact at frame 0 is no strike)
    """
    c = np.asarray(contact, dtype=bool)
    edges = np.diff(np.concatenate([[False], c, [False]]).astype(np.int8))
    begin = np.flatnonzero(edges == 1)
    end = np.flatnonzero(edges == -1)
    keep = (end - begin >= min_frames) & (begin > 0)
    return begin[keep]


def segment_cycles(
    motion: Motion,
    height: float = 0.06,
    speed: float = 0.6,
    min_frames: int = 3,
    feet: tuple[str, str] = FOOT_JOINTS,
) -> Cycles:
    """Whole gait cycles of a clip (see the module docstring).

    Parameters
    ----------
    motion : a clip with joints named ``feet`` (the canonical humanoid has them)
    height, speed, min_frames : contact rule, metres, m/s and frames

    Returns
    -------
    :class:`Cycles`

    Raises
    ------
    ValueError naming the joint when the clip lacks an ankle joint.
    """
    names = list(motion.skeleton.names)
    missing = [f for f in feet if f not in names]
    if missing:
        raise ValueError(
            f"clip {motion.name!r} has no joint {missing[0]!r}; segment_cycles needs the ankles {feet} "
            "(reduce the clip with preprocess.prepare first)"
        )
    idx = [names.index(f) for f in feet]
    return cycles_from_ankles(motion.global_positions()[:, idx], motion.fps, height, speed, min_frames)


def as_ankles(ankles) -> np.ndarray:
    """``ankles`` as a float64 array of shape (T, 2, 3): left then right ankle, world positions.

    Raises
    ------
    ValueError when ``ankles`` is not (T, 2, 3).
    """
    ankles = np.asarray(ankles, dtype=np.float64)
    if ankles.ndim != 3 or ankles.shape[1:] != (2, 3):
        raise ValueError(f"expected ankle positions of shape (T, 2, 3), got {ankles.shape}")
    return ankles


def cycles_from_ankles(ankles, fps: float, height: float = 0.06, speed: float = 0.6, min_frames: int = 3) -> Cycles:
    """Whole gait cycles from ankle positions.

    Parameters
    ----------
    ankles : ndarray, shape (T, 2, 3)   left then right ankle, world positions, metres, Y up
    fps : frames per second
    height, speed, min_frames : contact rule, metres, m/s and frames (see :func:`contacts`)

    Returns
    -------
    :class:`Cycles`

    Raises
    ------
    ValueError when ``ankles`` is not (T, 2, 3).
    """
    ankles = as_ankles(ankles)
    c = contacts(ankles, fps, (0, 1), height, speed)
    left, right = strikes(c[:, 0], min_frames), strikes(c[:, 1], min_frames)
    if left.size >= 2:
        a, b = left[:-1], left[1:]
        # exactly one right strike inside [a, b)
        n_right = np.searchsorted(right, b) - np.searchsorted(right, a)
        bounds = np.stack([a, b], axis=1)[n_right == 1]
    else:
        bounds = np.zeros((0, 2), dtype=np.int64)
    return Cycles(left, right, bounds.astype(np.int64), int(ankles.shape[0]))
