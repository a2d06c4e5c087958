"""One standing rest pose for every rig, so that measures and rotations mean the same.

A rig's rest pose (the pose with identity local rotations) is whatever its studio chose:
Mixamo and the synthetic character stand in a T-pose, CMU in an A-stance with the arms down,
and Bandai Namco's rest lays every bone along its parent's x axis (the body lies flat, hip
height 6.5 cm). Anything that measures a skeleton (hip height, leg chain, the root scale, the
network's offsets) or compares joint rotations across rigs needs one convention. The
**canonical standing pose** is built in two stages, on the 22 canonical joints:

1. **A standing pose.** From the rest offsets when they describe one (``source="rest"``): thigh,
   shin and the Hips→Neck spine within :data:`TOLERANCE_DEG` of straight down / up.
   Otherwise from the motion (``source="motion"``): the frame of most upright stance, the one
   whose worst angle of thighs and shins to straight down and of the spine to straight up is
   least, turned to face +Z. When the rest offsets fail and there is no motion, or no frame is
   upright within the tolerance, :class:`RestPoseError` names the joint and what was expected.
2. **The T-pose's bone directions** (:func:`motionlab.core.humanoid.canonical_skeleton`) for
   each bone of the legs, spine and arms (:data:`STRAIGHTENED`) that points more than
   :data:`TOLERANCE_DEG` away from them; bones within it keep the rig's own direction, so
   a T- or near-T-pose rig (every Mixamo character) is left exactly as it was. Then the legs
   stand straight below the hips: a pose taken from the motion gets thighs and shins straight
   down (a frame's stride is not a stance); rest offsets lose only a sideways spread of more
   than :data:`SPREAD_DEG` (an A-stance is a rigging convention, not how the performer stands),
   and keep a bend of the knees forward or back, which is the character's own stance.

The motion is re-expressed on the new rest offsets with world positions unchanged: with
``A_j`` the rotation that carries joint ``j``'s child offsets from the old rest to the new one,
``offset'_c = A_p offset_c`` and ``local_rot'_j = A_p local_rot_j A_j⁻¹`` (``p``: parent).
Retargeting (:func:`motionlab.retargeting.pipeline.retarget`, ``expand``, training) uses it
through ``preprocess.prepare(..., stand=True)`` and :func:`standing_skeleton`; ``docs/rigs.md``
shows it on every pair of the shared data's rig families.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core import humanoid, quat
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton

__all__ = [
    "TOLERANCE_DEG",
    "SPREAD_DEG",
    "STRAIGHTENED",
    "RestPoseError",
    "StandingPose",
    "standing",
    "standing_skeleton",
]

TOLERANCE_DEG = 40.0
"""Largest angle (degrees) between a bone and its T-pose direction that still counts as that pose."""
STRAIGHTENED: tuple[str, ...] = (
    "LeftLeg", "LeftFoot", "RightLeg", "RightFoot", "Spine1", "Spine2",
    "LeftForeArm", "LeftHand", "RightForeArm", "RightHand",
)  # fmt: skip
"""Canonical joints whose incoming bone is turned onto the T-pose direction when it is further away
than :data:`TOLERANCE_DEG` (feet, clavicles and the neck keep the rig's own shape)."""

_J = humanoid.JOINTS
_UPRIGHT = ("Neck", "LeftLeg", "LeftFoot", "RightLeg", "RightFoot")  # Hips→Neck up; thighs, shins down
_WHAT = ("Hips->Neck (spine) up", "LeftUpLeg->LeftLeg (thigh) down", "LeftLeg->LeftFoot (shin) down",
         "RightUpLeg->RightLeg (thigh) down", "RightLeg->RightFoot (shin) down")  # fmt: skip


SPREAD_DEG = 10.0
"""Largest sideways spread (degrees from vertical, in the left-right plane) of a rest thigh or shin that is kept."""
_LEGS = ("LeftLeg", "LeftFoot", "RightLeg", "RightFoot")  # thighs and shins (incoming bones)


class RestPoseError(ValueError):
    """No standing pose can be derived: neither the rest offsets nor any frame of the motion stand."""


@dataclass(frozen=True)
class StandingPose:
    """How a rig's canonical standing pose was found.

    Attributes
    ----------
    source : str          ``"rest"`` (the rest offsets stand) or ``"motion"`` (a frame of the motion)
    frame : int           the frame used (``-1`` for ``"rest"``)
    straightened : tuple of str   canonical joints whose incoming bone was turned onto the T-pose
    worst_deg : float     the standing pose's worst leg/spine angle to vertical, degrees
    """

    source: str
    frame: int
    straightened: tuple[str, ...]
    worst_deg: float

    def describe(self) -> str:
        """One line for ``motionlab info``: which pose was used and what was turned."""
        where = "the rest offsets" if self.source == "rest" else f"frame {self.frame} of the motion (most upright)"
        turned = f"; turned onto the T-pose: {', '.join(self.straightened)}" if self.straightened else ""
        return f"standing pose from {where}, legs/spine within {self.worst_deg:.0f} deg of vertical{turned}"


def _angle(v: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Angle (degrees) between vectors (..., 3) and ``ref`` (..., 3); 0 for zero-length vectors."""
    n = np.linalg.norm(v, axis=-1) * np.linalg.norm(ref, axis=-1)
    cos = np.where(n > 0, (v * ref).sum(-1) / np.where(n > 0, n, 1.0), 1.0)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def _uprightness(pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Worst angle (degrees) to vertical of thighs, shins (down) and Hips→Neck (up), and which
    (index into :data:`_UPRIGHT`); pos (..., 22, 3)."""
    down = np.array([0.0, -1.0, 0.0])
    angles = [_angle(pos[..., _J.index("Neck"), :] - pos[..., 0, :], -down)]
    for name in _UPRIGHT[1:]:
        j = _J.index(name)
        angles.append(_angle(pos[..., j, :] - pos[..., humanoid.PARENTS[j], :], down))
    angles = np.stack(angles, axis=-1)
    return angles.max(axis=-1), angles.argmax(axis=-1)


def _straighten(offsets: np.ndarray, legs_down: bool) -> tuple[np.ndarray, tuple[str, ...]]:
    """Per-joint rotations (22, 4) turning bones onto the T-pose (module docstring, stage 2), and
    the names of the joints whose incoming bone turned; ``legs_down``: thighs and shins straight down."""
    ref = humanoid.canonical_skeleton().offsets.copy()
    turn = np.tile(quat.IDENTITY, (len(_J), 1))
    names = []
    for name in STRAIGHTENED:
        c = _J.index(name)
        o, goal = offsets[c], ref[c]
        if np.linalg.norm(o) == 0:
            continue
        if name in _LEGS and not legs_down and _angle(o, ref[c]) <= TOLERANCE_DEG:
            spread = np.degrees(np.arctan2(abs(o[0]), -o[1]))
            goal = o * np.array([0.0, 1.0, 1.0]) if spread > SPREAD_DEG else o
        elif not (name in _LEGS and legs_down) and _angle(o, ref[c]) <= TOLERANCE_DEG:
            goal = o
        if goal is not o:
            turn[humanoid.PARENTS[c]] = quat.between(o, goal)
            names.append(name)
    for c in range(1, len(_J)):  # leaves (head, hands, toes) turn with their parent's bone
        if c not in humanoid.PARENTS:
            turn[c] = turn[humanoid.PARENTS[c]]
    return turn, tuple(names)


def _apply(motion: Motion, turn: np.ndarray) -> Motion:
    """``motion`` on rest offsets turned by ``turn`` (22, 4) per joint, world positions unchanged."""
    sk, parents = motion.skeleton, humanoid.PARENTS
    offsets = sk.offsets.copy()
    offsets[1:] = quat.rotate(turn[parents[1:]], sk.offsets[1:])
    offsets[0] = sk.offsets[0] * np.array([1.0, 0.0, 1.0])
    offsets[0, 1] = -Skeleton(sk.names, parents, offsets).rest_positions()[:, 1].min()  # lowest joint on y = 0
    ends = {j: quat.rotate(turn[j], e) for j, e in sk.end_sites.items()}
    inv = quat.conj(turn)
    local = quat.mul(motion.local_rot, inv[None])
    local[:, 1:] = quat.mul(turn[None, parents[1:]], local[:, 1:])
    local_pos = None
    if motion.local_pos is not None:
        local_pos = motion.local_pos.copy()
        local_pos[:, 1:] = quat.rotate(turn[None, parents[1:]], motion.local_pos[:, 1:])
    skeleton = Skeleton(sk.names, parents, offsets, ends)
    return Motion(skeleton, quat.normalize(local), motion.root_pos.copy(), motion.fps, local_pos, motion.name)


def _standing_turn(motion: Motion, what: str) -> tuple[np.ndarray, int, float]:
    """Rotations (22, 4) that make the most upright frame the rest pose, its index and worst angle."""
    g_rot, g_pos = motion.fk()
    score, which = _uprightness(g_pos)
    t = int(np.argmin(score))
    if not score[t] <= TOLERANCE_DEG:
        raise RestPoseError(
            f"{what}: no standing pose: the rest offsets do not stand and in no frame are thighs and shins within "
            f"{TOLERANCE_DEG:g} deg of straight down and Hips->Neck of straight up (most upright: frame {t}, where "
            f"{_WHAT[which[t]]} is {score[t]:.0f} deg off)"
        )

    yaw = humanoid.heading(g_pos[t])
    return quat.mul(quat.from_yaw(-yaw)[None], g_rot[t]), t, float(score[t])


def standing(motion: Motion, what: str | None = None) -> tuple[Motion, StandingPose]:
    """The motion on its rig's canonical standing rest pose (module docstring).

    Parameters
    ----------
    motion : Motion on the 22 canonical joints (:func:`humanoid.to_canonical`), T frames
    what : how errors name the motion (default: its name)

    Returns
    -------
    (Motion, StandingPose): the same T frames, fps and world positions (metres) on the new rest
    offsets — ``motion`` itself when the rest already stands and no bone is turned.

    Raises
    ------
    RestPoseError when neither the rest offsets nor any frame stand (see module docstring).
    ValueError when ``motion`` is not canonical.
    """
    if not humanoid.is_canonical(motion.skeleton):
        raise ValueError("standing() needs a 22-joint canonical motion; call humanoid.to_canonical first")
    what = what or motion.name or "motion"
    worst = float(_uprightness(motion.skeleton.rest_positions())[0])
    source, frame = "rest", -1
    if not worst <= TOLERANCE_DEG:
        turn, frame, worst = _standing_turn(motion, what)
        motion, source = _apply(motion, turn), "motion"
    turn, names = _straighten(motion.skeleton.offsets, legs_down=source == "motion")
    if names:
        motion = _apply(motion, turn)
    return motion, StandingPose(source, frame, names, worst)


def standing_skeleton(rig: Skeleton | Motion, what: str = "skeleton") -> tuple[Skeleton, StandingPose]:
    """A rig's canonical 22-joint skeleton in its standing rest pose (offsets in metres).

    ``rig`` is a Skeleton (its rest offsets must stand) or a Motion on it (a frame of the
    motion is used when they do not). Raises :class:`RestPoseError` (naming ``what``, the
    joint and what was expected) and :class:`humanoid.RigMappingError`.
    """
    if isinstance(rig, Motion):
        motion = humanoid.to_canonical(rig)
    else:
        sk = humanoid.to_canonical_skeleton(rig)
        motion = Motion(sk, np.tile(quat.IDENTITY, (1, len(_J), 1)), sk.offsets[None, 0].copy(), 30.0)
        worst, which = _uprightness(sk.rest_positions())
        if not worst <= TOLERANCE_DEG:
            raise RestPoseError(
                f"{what}: the rest offsets are not a standing pose ({_WHAT[int(which)]} is {float(worst):.0f} deg "
                f"off, at most {TOLERANCE_DEG:g} expected) and no motion was given to find one"
            )
    out, pose = standing(motion, what)
    return out.skeleton, pose
