"""Does a clip show what its label says? Root height, speed and foot contacts, not the file name.

An action node is only as good as its clip. Mixamo's ``Running.bvh`` for Aj is a dive roll and
``Idle.bvh`` a crouched idle; named by file, they would teach run → walk → stand → squat wrongly. :func:`measure` reads three things off the motion
(22-joint canonical skeleton, :func:`motionlab.core.humanoid.to_canonical`):

* **hip height**: the hips' height above the clip's floor (its lowest foot or toe) over their
  height in the rest pose above the rest pose's lowest joint — 1 standing straight, about 0.5 in
  a deep crouch, near 0 lying or rolling;
* **speed**: the hips' median ground speed in leg lengths (thigh + shin + foot) per second —
  about 1 for a walk, 2.5–5 for a run, near 0 standing;
* **flight**: the fraction of frames with both feet off the floor (each foot's lowest joint
  more than 5% of the leg length above the floor) — 0 for walking and standing, above 0 for
  running (both feet leave the ground in every stride).

:data:`RULES` states each action's ranges; :func:`check` raises :class:`LabelError` naming the
clip, the label and the measure that is out of range.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core import humanoid
from motionlab.core.motion import Motion

__all__ = ["LabelError", "ActionMeasures", "RULES", "measure", "check"]


class LabelError(ValueError):
    """A clip's content does not match its action label."""


@dataclass(frozen=True)
class ActionMeasures:
    """What :func:`measure` reads off a clip.

    Attributes
    ----------
    hip_min, hip_median : float   hip height over rest hip height (dimensionless)
    speed : float                 median hips ground speed, leg lengths per second
    flight : float                fraction of frames with both feet off the floor
    """

    hip_min: float
    hip_median: float
    speed: float
    flight: float

    def __str__(self) -> str:
        return (
            f"hips min {self.hip_min:.2f} / median {self.hip_median:.2f} of standing height, "
            f"speed {self.speed:.2f} leg lengths/s, both feet off the floor in {self.flight:.0%} of frames"
        )


RULES = {
    "run": {"hip_min": (0.65, None), "speed": (2.0, None), "flight": (0.01, None)},
    "walk": {"hip_min": (0.65, None), "speed": (0.4, 2.5), "flight": (None, 0.05)},
    "stand": {"hip_median": (0.8, None), "speed": (None, 0.3), "flight": (None, 0.05)},
    "squat": {"hip_min": (None, 0.7), "speed": (None, 0.6), "flight": (None, 0.05)},
}
"""Allowed ``(low, high)`` range of each measure per action (``None``: open). A run must keep its hips
well off the ground, move fast and have flight phases; a squat must bring the hips down."""


def measure(motion: Motion) -> ActionMeasures:
    """:class:`ActionMeasures` of a clip on the 22-joint canonical skeleton (any frame rate, >= 2 frames).

    Raises
    ------
    ValueError for fewer than 2 frames or a skeleton that is not the canonical 22 joints.
    """
    if motion.num_frames < 2:
        raise ValueError(f"clip {motion.name!r}: need at least 2 frames to measure speed, got {motion.num_frames}")
    names = list(motion.skeleton.names)
    missing = [n for n in ("Hips", "LeftFoot", "RightFoot", "LeftToeBase", "RightToeBase") if n not in names]
    if missing:
        raise ValueError(f"clip {motion.name!r}: expected the canonical 22-joint skeleton, no joint(s) {missing}")
    pos = motion.global_positions()  # (T, J, 3)
    rest = motion[:1].copy(local_rot=np.tile([1.0, 0.0, 0.0, 0.0], (1, motion.skeleton.num_joints, 1)))
    rest_pos = rest.global_positions()[0]
    hips = names.index("Hips")
    left = [names.index("LeftFoot"), names.index("LeftToeBase")]
    right = [names.index("RightFoot"), names.index("RightToeBase")]
    floor = float(pos[:, left + right, 1].min())
    rest_hip = max(float(rest_pos[hips, 1] - rest_pos[:, 1].min()), 1e-6)
    hip = (pos[:, hips, 1] - floor) / rest_hip
    leg = humanoid.leg_length(motion.skeleton)
    speed = np.linalg.norm(np.diff(pos[:, hips, [0, 2]], axis=0), axis=1) * motion.fps / leg
    lifted = 0.05 * leg
    off = (pos[:, left, 1].min(axis=1) - floor > lifted) & (pos[:, right, 1].min(axis=1) - floor > lifted)
    return ActionMeasures(float(hip.min()), float(np.median(hip)), float(np.median(speed)), float(off.mean()))


def check(motion: Motion, label: str) -> ActionMeasures:
    """The clip's :class:`ActionMeasures`, or :class:`LabelError` if they break ``RULES[label]``.

    Raises
    ------
    ValueError for an action with no rule; LabelError when a measure breaks the label's rule.
    """
    if label not in RULES:
        raise ValueError(f"no rule for action {label!r}; known: {sorted(RULES)}")
    m = measure(motion)
    for key, (lo, hi) in RULES[label].items():
        v = getattr(m, key)
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            want = f">= {lo}" if hi is None else f"<= {hi}" if lo is None else f"in [{lo}, {hi}]"
            raise LabelError(
                f"clip {motion.name!r} is labelled {label!r} but its {key} is {v:.2f} (expected {want}): {m}"
            )
    return m
