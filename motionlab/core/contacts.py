"""Foot contacts: motionlab's one foot-contact detector (the home of the rule; every user calls it).

**The rule** (:func:`low_and_slow`): a foot joint touches the ground in frame ``t`` when its
height is less than its *contact height* plus a height tolerance and its speed is less than a
speed limit. Every part of the package uses it, each with thresholds it states:

* retargeting (the source's planted feet for the contact term, the plausibility tests and the
  skating flag, ``python -m experiments.retargeting.rigs --methods``) and :func:`motionlab.core.metrics.planted_slide`'s
  labels: :func:`detect_contacts` / :func:`of_motion`, thresholds from the rig (below);
* :func:`motionlab.core.metrics.foot_contacts`: contact height 0, thresholds given in the
  position unit;
* the gait cycles of motion graphs (:func:`motionlab.motion_graphs.cycles.contacts`): contact
  height = the clip's own ground level (5th percentile of each foot's height), horizontal speed;
* the 3-D viewer (:func:`motionlab.viz.scene.contact_labels`): contact height from the rig's rest
  pose, tolerances in body heights.

**The retargeting detector, per rig.** Paper A's iteration keeps the feet *above* the ground
(``L_foot``) but says nothing about feet that should stay *still*: a foot planted by the performer
may slide on the new character, and per-frame latent updates make it slide more. motionlab
therefore labels the frames where each foot joint of A is planted and asks B's foot to keep still
on those frames (:func:`motionlab.retargeting.losses.contact_loss`).

A foot joint is **planted** in frame ``t`` when, on A,

* it is low: its height is at most its *contact height* plus ``height_tol × h`` (``h``: A's
  22-joint rest height, so the rule does not depend on the character's size or the file's
  unit). A joint's contact height is its rest height above the lowest rest joint (the rig's
  own geometry), plus that joint's own clearance when it touches the ground, estimated as the
  least ``y − rest height`` the joint reaches in the clip (the source's own foot heights; never
  below 0): joints sit inside the foot, a few centimetres above the sole, and a rig's standing
  foot need not be the performer's (CMU's rest foot lies nearly flat, its planted ankle does
  not, so one clearance for all four joints, the lowest's, left CMU's ankles never low); and
* it is slow: its speed is below ``speed_tol × h`` per second,

and the label is kept only for runs of at least ``min_frames`` consecutive frames (a
one-frame touch is not a plant). The labels are frame indices, so they carry over to any
target: scaling to B happens because B's own foot positions are what the loss keeps still.

Defaults, chosen on motionlab's synthetic clips, whose contacts are known because the generator
plants the feet by IK (:func:`motionlab.synthetic.generate` with ``return_contacts=True``), never
on the evaluation clips: a 3 %·h height tolerance and an 8 %·h/s speed limit (≈ 0.11 m/s for a
1.42 m performer; slower limits miss real, slightly jittery plants, faster ones add heel-off
frames); ``tests/retargeting/test_contacts.py`` checks precision and recall ≥ 0.95 on walk, run,
jump and squat.

Taught in ``notebooks/03_latent_iteration.ipynb``; :mod:`motionlab.retargeting.contacts` re-exports it.
"""

from __future__ import annotations

import numpy as np

from motionlab.core import humanoid

__all__ = [
    "CONTACT_JOINTS",
    "HEIGHT_TOL",
    "SPEED_TOL",
    "MIN_FRAMES",
    "low_and_slow",
    "runs_at_least",
    "detect_contacts",
    "rest_heights",
    "of_motion",
    "planted_toe_heights",
]

CONTACT_JOINTS: tuple[int, ...] = tuple(humanoid.JOINTS.index(n) for n in humanoid.FEET)
"""LeftFoot, RightFoot, LeftToeBase, RightToeBase: the joints whose contacts are detected."""
HEIGHT_TOL = 0.03
"""Height above the joint's rest height, as a fraction of the character's height."""
SPEED_TOL = 0.08
"""Speed limit, as a fraction of the character's height per second."""
MIN_FRAMES = 3
"""Shortest run of frames that counts as a plant."""


def low_and_slow(feet, contact_height, height_tol: float, speed_tol: float, fps: float, horizontal: bool = False):
    """The contact rule: ``y − contact_height < height_tol`` and speed ``< speed_tol``.

    Parameters
    ----------
    feet : ndarray (..., T, F, 3)   positions of F foot joints (any unit), Y up
    contact_height : float or ndarray broadcastable to (..., T, F)   each joint's height when it touches
    height_tol : float              height tolerance, position unit
    speed_tol : float               speed limit, position unit per second
    fps : float                     frames per second
    horizontal : bool               speed on the ground plane only (default: 3-D speed)

    Returns
    -------
    ndarray of bool (..., T, F); speed is the central difference (one-sided at the ends), 0 for one frame.
    """
    p = np.asarray(feet, dtype=np.float64)
    moving = p[..., [0, 2]] if horizontal else p
    vel = np.gradient(moving, axis=-3) * fps if p.shape[-3] > 1 else np.zeros_like(moving)
    return (p[..., 1] - contact_height < height_tol) & (np.linalg.norm(vel, axis=-1) < speed_tol)


def runs_at_least(mask: np.ndarray, n: int) -> np.ndarray:
    """Keep only runs of ``True`` at least ``n`` frames long, along axis 0 of a (T, F) mask."""
    if n <= 1:
        return mask
    T = mask.shape[0]
    padded = np.concatenate([np.zeros((1,) + mask.shape[1:], bool), mask, np.zeros((1,) + mask.shape[1:], bool)])
    edges = np.diff(padded.astype(np.int8), axis=0)  # +1 at a run's start, -1 one past its end
    out = np.zeros_like(mask)
    for f in range(mask.shape[1]):  # a loop over the 4 feet, not over frames
        starts = np.flatnonzero(edges[:, f] == 1)
        stops = np.flatnonzero(edges[:, f] == -1)
        keep = (stops - starts) >= n
        counts = np.zeros(T + 1, np.int64)
        np.add.at(counts, starts[keep], 1)
        np.add.at(counts, stops[keep], -1)
        out[:, f] = np.cumsum(counts)[:T] > 0
    return out


def detect_contacts(
    positions: np.ndarray,
    rest_heights: np.ndarray,
    height: float,
    fps: float,
    height_tol: float = HEIGHT_TOL,
    speed_tol: float = SPEED_TOL,
    min_frames: int = MIN_FRAMES,
) -> np.ndarray:
    """Planted-foot labels of a motion (module docstring).

    Parameters
    ----------
    positions : ndarray (T, 22, 3)   world joint positions of the canonical skeleton, metres, Y up
    rest_heights : ndarray (4,)      rest-pose height above the lowest joint of each contact joint
                                     (:data:`CONTACT_JOINTS` order), metres
    height : float                   the character's 22-joint rest height, metres
    fps : float                      frames per second
    height_tol, speed_tol : float    fractions of ``height`` (metres and metres/second)
    min_frames : int                 shortest plant, frames

    Returns
    -------
    ndarray of bool, shape (T, 4), in :data:`CONTACT_JOINTS` order

    Raises
    ------
    ValueError unless the positions are (T, 22, 3), the rest heights (4,), and ``height``
    and ``fps`` positive.
    """
    pos = np.asarray(positions, dtype=np.float64)
    if pos.ndim != 3 or pos.shape[1:] != (len(humanoid.JOINTS), 3):
        raise ValueError(f"expected canonical world positions (T, 22, 3), got {pos.shape}")
    rest = np.asarray(rest_heights, dtype=np.float64)
    if rest.shape != (len(CONTACT_JOINTS),):
        raise ValueError(f"expected 4 rest heights (LeftFoot, RightFoot, LeftToeBase, RightToeBase), got {rest.shape}")
    if not (height > 0 and fps > 0):
        raise ValueError(f"height and fps must be positive, got {height} and {fps}")
    feet = pos[:, list(CONTACT_JOINTS)]
    clearance = np.maximum((feet[..., 1] - rest).min(axis=0), 0.0)  # (4,): each joint's own
    labels = low_and_slow(feet, rest + clearance, height_tol * height, speed_tol * height, fps)
    return runs_at_least(labels, min_frames)


def rest_heights(skeleton) -> np.ndarray:
    """Rest-pose heights (4,) of the contact joints above the skeleton's lowest rest joint, metres."""
    rest = skeleton.rest_positions()
    return rest[list(CONTACT_JOINTS), 1] - rest[:, 1].min()


def of_motion(motion) -> np.ndarray:
    """Planted feet (T, 4) of a motion on the canonical 22-joint humanoid (:func:`detect_contacts`
    with the skeleton's own rest heights and height)."""
    sk = motion.skeleton
    return detect_contacts(motion.global_positions(), rest_heights(sk), sk.height(), motion.fps)


def planted_toe_heights(motion) -> np.ndarray:
    """Heights (metres, 1-D) of a canonical motion's toe joints over the frames where
    :func:`of_motion` plants them: where the take's toes stand (its sole, :mod:`.rest_pose`)."""
    toes = [i for i, j in enumerate(CONTACT_JOINTS) if "Toe" in humanoid.JOINTS[j]]
    labels = of_motion(motion)[:, toes]
    return motion.global_positions()[:, [CONTACT_JOINTS[i] for i in toes], 1][labels]
