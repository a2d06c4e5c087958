r"""Gait or standing action, and the stance phases that cut a standing action into segments.

Paper B cuts every basic clip into whole gait cycles (:mod:`.cycles`). A *standing action*
(a wave, raising the hands) has no cycle: it is a one-shot between *stances*, phases where the
character stands with both feet planted and (almost) nothing moves. This module decides from
the motion alone — never from a clip's name — whether a take is a gait or an action, finds its
stance phases and cuts it at them, so that takes connect stance to stance.

Every threshold is relative to the body and the frame rate, so a smaller character or another
frame rate needs no new numbers. The body's size is its *leg length* ``L`` (thigh + shin, the
mean of both legs, from the skeleton's rest offsets):

* a foot is *planted* when its ankle is less than :data:`CONTACT_HEIGHT` ``· L`` above the
  clip's ground and moves slower than :data:`CONTACT_SPEED` ``· L`` per second horizontally
  (:func:`.cycles.contacts`; on a 0.8 m leg these are the 6 cm and 0.6 m/s the gait cycles use);
* a frame is *still* when every joint moves slower than :data:`STILL_SPEED` ``· L`` per second;
* a *stance* is a run of at least :data:`MIN_STANCE` seconds of frames that are still with both
  feet planted;
* a take is a *gait* when fewer than :data:`GAIT_SHARE` of its frames have both feet planted:
  walking spends about a fifth of its cycle in double support and running none, while a
  standing action keeps both feet down nearly all the time; the rule sits halfway between;
* a take of a standing action begins and ends at rest, but a session's takes are often cut so
  tightly around the action that the rest is shorter than a stance (or still settling): its
  first and last :data:`END_STANCE` seconds count as its *boundary stances*;
* an action's *segments* run from the middle frame of one stance to the middle frame of the
  next (boundary stances included), so every action take holds at least one;
* a take's *ports*, the frames where links to other styles and behaviours may begin or end, are
  an action's boundary stances (so that takes connect stance to stance; a hold inside the take
  cuts it but is no port) and, for a gait, its frames with both feet planted (double support)
  and its first and last :data:`END_STANCE` seconds (where it starts and stops).

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.motion_graphs import cycles as _cycles

__all__ = [
    "Segments",
    "leg_length",
    "planted",
    "stance_mask",
    "classify",
    "segments_from_positions",
    "segment_take",
    "CONTACT_HEIGHT",
    "CONTACT_SPEED",
    "STILL_SPEED",
    "MIN_STANCE",
    "GAIT_SHARE",
    "END_STANCE",
    "LEG_JOINTS",
]

CONTACT_HEIGHT = 0.075
"""Planted foot: ankle at most this many leg lengths above the clip's ground."""

CONTACT_SPEED = 0.75
"""Planted foot: ankle slower than this many leg lengths per second, horizontally."""

STILL_SPEED = 0.25
"""Still frame: every joint slower than this many leg lengths per second."""

MIN_STANCE = 0.1
"""Shortest stance, seconds."""

GAIT_SHARE = 0.5
"""A take is a gait when fewer than this share of its frames have both feet planted."""

END_STANCE = 1 / 3
"""Boundary stance of an action take: its first and last third of a second (two Kovar windows at 30 fps)."""

LEG_JOINTS = (("LeftLeg", "LeftFoot"), ("RightLeg", "RightFoot"))
"""Knee and ankle of each leg: their rest offsets are the thigh and the shin."""


@dataclass(frozen=True)
class Segments(_cycles.Spans):
    """What a take is and where it may be cut.

    Attributes
    ----------
    kind : ``"gait"`` or ``"action"``
    stances : int array, shape (S, 2), ``[first, stop)`` frames of each stance phase
    bounds : int array, shape (K, 2), ``[first, stop)`` of each whole segment (stance middle to
        the next stance middle; empty for a gait, whose cuts are its cycles)
    num_frames : frames of the take
    both_planted : share of the frames with both feet planted, in [0, 1]
    ports : bool array, shape (T,), frames where links to other styles and behaviours may
        begin or end (an action's boundary stances; a gait's start, stop and double support)

    ``count``, ``span`` and ``lengths()`` of the whole segments come from :class:`.cycles.Spans`.
    """

    kind: str
    stances: np.ndarray
    bounds: np.ndarray
    num_frames: int
    both_planted: float
    ports: np.ndarray

    def stance_frames(self) -> np.ndarray:
        """(T,) bool: frames inside a stance phase."""
        mask = np.zeros(self.num_frames, dtype=bool)
        for a, b in self.stances:
            mask[a:b] = True
        return mask


def leg_length(skeleton: Skeleton, legs=LEG_JOINTS) -> float:
    """Thigh + shin length, metres, the mean of both legs, from the rest offsets.

    Raises
    ------
    ValueError
        when a joint of ``legs`` is missing (reduce the clip with ``preprocess.prepare``).
    """
    names = list(skeleton.names)
    total = []
    for knee, ankle in legs:
        if knee not in names or ankle not in names:
            raise ValueError(f"skeleton has no joint {knee!r} or {ankle!r}; leg_length needs the canonical humanoid")
        total.append(sum(float(np.linalg.norm(skeleton.offsets[names.index(j)])) for j in (knee, ankle)))
    return float(np.mean(total))


def planted(ankles, fps: float, leg: float) -> np.ndarray:
    """Planted labels of the two feet (module docstring).

    Parameters
    ----------
    ankles : ndarray, shape (T, 2, 3)   left then right ankle, world positions, metres, Y up
    fps : frames per second
    leg : leg length, metres

    Returns
    -------
    ndarray, shape (T, 2), bool

    Raises
    ------
    ValueError when ``ankles`` is not (T, 2, 3).
    """
    return _cycles.contacts(_cycles.as_ankles(ankles), fps, (0, 1), CONTACT_HEIGHT * leg, CONTACT_SPEED * leg)


def _runs(mask: np.ndarray, min_frames: int) -> np.ndarray:
    """``[first, stop)`` of the runs of True at least ``min_frames`` long, shape (R, 2)."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    begin, end = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    keep = end - begin >= min_frames
    return np.stack([begin[keep], end[keep]], axis=1).astype(np.int64)


def stance_mask(pos, feet: tuple[int, int], fps: float, leg: float) -> np.ndarray:
    """Frames inside a stance phase (boundary stances of an action included, module docstring).

    Parameters and errors as :func:`segments_from_positions`, of which this is ``.stance_frames()``.

    Returns
    -------
    ndarray, shape (T,), bool
    """
    return segments_from_positions(pos, feet, fps, leg).stance_frames()


def classify(both_planted_share: float) -> str:
    """``"gait"`` when fewer than :data:`GAIT_SHARE` of the frames have both feet planted, else ``"action"``."""
    return "gait" if float(both_planted_share) < GAIT_SHARE else "action"


def segments_from_positions(pos, feet: tuple[int, int], fps: float, leg: float) -> Segments:
    """Kind, stance phases and segments of a take (see the module docstring).

    Parameters
    ----------
    pos : ndarray, shape (T, J, 3)   world joint positions, metres, Y up
    feet : indices of the left and right ankle in ``pos``
    fps : frames per second
    leg : leg length, metres (:func:`leg_length`)

    Returns
    -------
    :class:`Segments`

    Raises
    ------
    ValueError
        for a bad shape, a foot index out of range or a leg length that is not positive.
    """
    pos = np.asarray(pos, dtype=np.float64)
    if pos.ndim != 3 or pos.shape[-1] != 3 or pos.shape[0] < 1:
        raise ValueError(f"expected positions of shape (T, J, 3), got {pos.shape}")
    if not (0 <= feet[0] < pos.shape[1] and 0 <= feet[1] < pos.shape[1]):
        raise ValueError(f"foot indices {feet} out of range for {pos.shape[1]} joints")
    if not leg > 0:
        raise ValueError(f"leg length must be positive metres, got {leg}")
    T = pos.shape[0]
    both = planted(pos[:, list(feet)], fps, leg).all(axis=1)
    share = float(both.mean())
    speed = np.linalg.norm(np.gradient(pos, axis=0), axis=-1).max(axis=1) * fps if T > 1 else np.zeros(T)
    min_frames = max(1, int(round(MIN_STANCE * fps)))
    stances = _runs(both & (speed < STILL_SPEED * leg), min_frames)
    kind = classify(share)
    end = min(max(1, int(round(END_STANCE * fps))), T)
    if kind == "gait":
        ports = both.copy()
        ports[:end] = ports[-end:] = True  # where the take starts and stops
        return Segments(kind, stances, np.zeros((0, 2), dtype=np.int64), T, share, ports)
    still = np.zeros(T, dtype=bool)
    for a, b in stances:
        still[a:b] = True
    still[:end] = still[-end:] = True  # the boundary stances
    stances = _runs(still, 1)
    mids = (stances[:, 0] + stances[:, 1] - 1) // 2
    bounds = np.stack([mids[:-1], mids[1:]], axis=1) if mids.size >= 2 else np.zeros((0, 2), dtype=np.int64)
    ports = np.zeros(T, dtype=bool)
    ports[:end] = ports[-end:] = True  # the boundary stances: takes connect stance to stance
    return Segments(kind, stances, bounds.astype(np.int64), T, share, ports)


def segment_take(motion: Motion, feet: tuple[str, str] = _cycles.FOOT_JOINTS) -> Segments:
    """:func:`segments_from_positions` of a clip with the canonical humanoid's joint names.

    Raises
    ------
    ValueError
        when the clip lacks the ankles ``feet`` or the leg joints (reduce it with
        ``preprocess.prepare`` first).
    """
    names = list(motion.skeleton.names)
    missing = [f for f in feet if f not in names]
    if missing:
        raise ValueError(f"clip {motion.name!r} has no joint {missing[0]!r}; segment_take needs the ankles {feet}")
    idx = (names.index(feet[0]), names.index(feet[1]))
    return segments_from_positions(motion.global_positions(), idx, motion.fps, leg_length(motion.skeleton))
