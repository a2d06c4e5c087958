"""One standing rest pose for every rig, so that measures and rotations mean the same.

A rig's rest pose (the pose with identity local rotations) is whatever its studio chose:
Mixamo and the synthetic character stand in a T-pose, CMU in an A-stance with the arms down,
and Bandai Namco's rest lays every bone along its parent's x axis (the body lies flat, hip
height 6.5 cm). Anything that measures a skeleton (hip height, leg chain, the root scale, the
network's offsets) or compares joint rotations across rigs needs one convention. The
**canonical standing pose** is built in two stages, on the 22 canonical joints:

1. **A standing pose.** A rig whose profile's rule (:data:`humanoid.STANDING`) is ``"tpose"``
   (Bandai Namco: its rest offsets carry bone lengths only) stands by that rule on any take
   (``source="profile"``): every bone along the T-pose's direction with the rig's own length,
   the joint frames (each bone's twist) from the take's most upright frame, so every take of the
   rig gets the same standing skeleton. Otherwise from the rest offsets when they describe one
   (``source="rest"``): thigh, shin and the Hips→Neck spine within :data:`TOLERANCE_DEG` of
   straight down / up. Otherwise from the motion (``source="motion"``): the frame of most upright
   stance, the one whose worst angle of thighs and shins to straight down and of the spine to
   straight up is least, turned to face +Z. Or from another take of the same rig
   (``reference=``, ``source="file"``, the command line's ``--rest-from FILE.bvh``). When the
   rest offsets fail and there is no motion, or no frame is upright within the tolerance,
   :class:`RestPoseError` names the joint, what was expected and :data:`REST_FROM_HINT`.
2. **The T-pose's bone directions** (:func:`motionlab.core.humanoid.canonical_skeleton`): every
   thigh and shin straight down, on every rig and from every source; each other bone of the spine
   and arms (:data:`STRAIGHTENED`) that points more than :data:`TOLERANCE_DEG` away from its
   T-pose direction is turned onto it, and bones within it keep the rig's own direction. A rig
   whose legs already point straight down and whose other bones lie within the tolerance is left
   exactly as it was.

The principle: the canonical standing pose is where identity rotations mean the same pose on
every rig. The network's character stands straight-legged, so a rotation copied or decoded from
another rig bends a leg by the same angle only when both rest legs are straight. A knee bent at
rest (or an A-stance's sideways spread) is a rigging choice, not the performer's stance: nothing
of the motion is lost by removing it, because the motion is re-expressed on the new rest with
its world positions unchanged.

**The sole.** A rig's lowest joint (a toe) sits inside the foot, above the floor by the foot's
own sole: :func:`sole_height`, read from the rest root offset where that places the rig on the
floor. The canonical standing pose keeps that height, so a standing skeleton's lowest joint is at
its sole height, and at 0 when the rest offsets do not say where the floor is. Where a take is
at hand the sole is then where its toes stand while planted (:func:`take_sole`): a take stood on
another's pose (:func:`on_reference`) and a retargeting target
(:func:`motionlab.retargeting.pipeline.target_skeleton`) stand on it.

The motion is re-expressed on the new rest offsets with world positions unchanged: with
``A_j`` the rotation that carries joint ``j``'s child offsets from the old rest to the new one,
``offset'_c = A_p offset_c`` and ``local_rot'_j = A_p local_rot_j A_j⁻¹`` (``p``: parent).
Retargeting (:func:`motionlab.retargeting.pipeline.retarget`, ``expand``, training) uses it
through ``preprocess.prepare(..., stand=True)`` and :func:`standing_skeleton`; ``docs/rigs.md``
shows it on every pair of the shared data's rig families.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from motionlab.core import contacts, humanoid, quat
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton

__all__ = [
    "TOLERANCE_DEG",
    "STRAIGHTENED",
    "REST_FROM_HINT",
    "RestPoseError",
    "StandingPose",
    "same_rig",
    "on_reference",
    "standing",
    "standing_skeleton",
    "sole_height",
    "on_sole",
    "SOLE_FPS",
    "take_sole",
]

TOLERANCE_DEG = 40.0
"""Largest angle (degrees) between a bone and its T-pose direction that still counts as that pose."""
STRAIGHTENED: tuple[str, ...] = (
    "LeftLeg", "LeftFoot", "RightLeg", "RightFoot", "Spine1", "Spine2",
    "LeftForeArm", "LeftHand", "RightForeArm", "RightHand",
)  # fmt: skip
"""Canonical joints whose incoming bone is turned onto the T-pose direction: thighs and shins always
(:data:`_LEGS`), the others when further away than :data:`TOLERANCE_DEG` (feet, clavicles and the
neck keep the rig's own shape)."""

_J = humanoid.JOINTS
_UPRIGHT = ("Neck", "LeftLeg", "LeftFoot", "RightLeg", "RightFoot")  # Hips→Neck up; thighs, shins down
_WHAT = ("Hips->Neck (spine) up", "LeftUpLeg->LeftLeg (thigh) down", "LeftLeg->LeftFoot (shin) down",
         "RightUpLeg->RightLeg (thigh) down", "RightLeg->RightFoot (shin) down")  # fmt: skip
_LEGS = ("LeftLeg", "LeftFoot", "RightLeg", "RightFoot")  # thighs and shins (incoming bones)


class RestPoseError(ValueError):
    """No standing pose can be derived: neither the rest offsets nor any frame of the motion stand."""


@dataclass(frozen=True)
class StandingPose:
    """How a rig's canonical standing pose was found.

    Attributes
    ----------
    source : str          ``"rest"`` (the rest offsets stand), ``"motion"`` (a frame of the motion),
                          ``"profile"`` (the rig profile's rule, :data:`humanoid.STANDING`) or
                          ``"file"`` (another take of the rig, ``reference``)
    frame : int           the frame used (``-1`` for ``"rest"``)
    straightened : tuple of str   canonical joints whose incoming bone was turned onto the T-pose
    worst_deg : float     the standing pose's worst leg/spine angle to vertical, degrees (before turning)
    family : str          the rig profile (``""`` when unknown)
    reference : str       name of the reference motion (``source="file"``)
    """

    source: str
    frame: int
    straightened: tuple[str, ...]
    worst_deg: float
    family: str = ""
    reference: str = ""

    def describe(self) -> str:
        """One line for ``motionlab info``: which pose was used and what was turned."""
        where = {
            "rest": "the rest offsets",
            "motion": f"frame {self.frame} of the motion (most upright)",
            "profile": f"the {self.family!r} rig profile (rest offsets lie flat: every bone along the T-pose, "
            f"joint frames from frame {self.frame})",
            "file": f"the file {self.reference or 'given'} (same rig)",
        }[self.source]
        if self.source in ("profile", "file"):
            turned = f"; {len(self.straightened)} bones turned onto the T-pose" if self.straightened else ""
            return f"standing pose from {where}{turned}"
        turned = f"; turned onto the T-pose: {', '.join(self.straightened)}" if self.straightened else ""
        return f"standing pose from {where}, legs/spine within {self.worst_deg:.0f} deg of vertical{turned}"


def _angle(v: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Angle (degrees) between vectors (..., 3) and ``ref`` (..., 3); 0 for zero-length vectors."""
    n = np.linalg.norm(v, axis=-1) * np.linalg.norm(ref, axis=-1)
    cos = np.where(n > 0, (v * ref).sum(-1) / np.where(n > 0, n, 1.0), 1.0)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def _uprightness(pos: np.ndarray, up=(0.0, 1.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """Worst angle (degrees) to vertical (``up``, +Y) of thighs, shins (down) and Hips→Neck (up),
    and which (index into :data:`_UPRIGHT`); pos (..., 22, 3)."""
    down = -np.asarray(up, dtype=np.float64)
    angles = [_angle(pos[..., _J.index("Neck"), :] - pos[..., 0, :], -down)]
    for name in _UPRIGHT[1:]:
        j = _J.index(name)
        angles.append(_angle(pos[..., j, :] - pos[..., humanoid.PARENTS[j], :], down))
    angles = np.stack(angles, axis=-1)
    return angles.max(axis=-1), angles.argmax(axis=-1)


_LEAD = {"Hips": ("Spine", "LeftUpLeg", "RightUpLeg"), "Spine2": ("Neck", "LeftShoulder", "RightShoulder")}
"""Branching joints: the child whose bone the turn lays on the T-pose's, and the left and right
children whose difference it turns into the T-pose's left-right plane."""


def _two_vector_turn(lead: np.ndarray, across: np.ndarray, lead_goal: np.ndarray, across_goal: np.ndarray):
    """The rotation (4,) taking ``lead`` onto ``lead_goal``'s direction and ``across`` (perpendicular
    part) into the half-plane of ``across_goal``."""

    def frame(a, b):
        e1 = a / np.linalg.norm(a)
        e2 = b - (b @ e1) * e1
        e2 /= np.linalg.norm(e2)
        return np.stack([e1, e2, np.cross(e1, e2)], axis=1)

    return quat.normalize(quat.from_matrix(frame(lead_goal, across_goal) @ frame(lead, across).T))


def _straighten(offsets: np.ndarray, every: bool = False) -> tuple[np.ndarray, tuple[str, ...]]:
    """Per-joint rotations (22, 4) turning bones onto the T-pose (module docstring, stage 2), and
    the names of the joints whose incoming bone turned; ``every``: every bone onto the T-pose's
    direction (a branching joint turns by its :data:`_LEAD` child's bone, its other children follow
    rigidly)."""
    ref = humanoid.canonical_skeleton().offsets.copy()
    turn = np.tile(quat.IDENTITY, (len(_J), 1))
    names = []
    for c in range(1, len(_J)):
        name, p = _J[c], humanoid.PARENTS[c]
        o, goal = offsets[c], ref[c]
        if np.linalg.norm(o) == 0 or (name not in STRAIGHTENED and not every):
            continue
        if every and _J[p] in _LEAD:
            lead, left, right = (_J.index(n) for n in _LEAD[_J[p]])
            if c == lead:
                across = offsets[left] - offsets[right]
                turn[p] = _two_vector_turn(o, across, goal, ref[left] - ref[right])
                names.append(name)
            continue
        if not every and name not in _LEGS and _angle(o, goal) <= TOLERANCE_DEG:
            goal = o
        if goal is not o and _angle(o, goal) > 1e-9:
            turn[p] = quat.between(o, goal)
            names.append(name)
    for c in range(1, len(_J)):  # leaves (head, hands, toes) turn with their parent's bone
        if c not in humanoid.PARENTS:
            turn[c] = turn[humanoid.PARENTS[c]]
    return turn, tuple(names)


def sole_height(skeleton: Skeleton) -> float | None:
    """Height (metres) of a canonical 22-joint skeleton's lowest rest joint above the floor, or None.

    The rest pose is placed by the root's rest offset, as a BVH file places it: a rig exported
    standing on the floor (Mixamo's) puts its lowest joint, a toe inside the foot, a sole's
    height above it. The height counts only when it could be the sole of a rig standing on its
    feet: below the knees (the Leg joints) above the lowest joint, and above minus the ankles
    (the foot joints) above it, so sunk in the floor, as the toes of a take planted under its
    floor are, by less than the ankles stand; within a micrometre under 0 it is 0 (a file's
    rounding). Otherwise (CMU's root offset at the origin, Bandai Namco's flat rest) the rest
    offsets do not say where the floor is: None.

    Raises ValueError when the skeleton is not canonical.
    """
    if not humanoid.is_canonical(skeleton):
        raise ValueError("sole_height() needs a 22-joint canonical skeleton (humanoid.to_canonical_skeleton)")
    y = skeleton.rest_positions()[:, 1]
    lowest = float(y.min())
    knees = float(y[[_J.index("LeftLeg"), _J.index("RightLeg")]].min()) - lowest
    ankles = float(y[[_J.index("LeftFoot"), _J.index("RightFoot")]].min()) - lowest
    if not -ankles < lowest < knees:
        return None
    return max(lowest, 0.0) if lowest >= -1e-6 else lowest


SOLE_FPS = 60.0
"""Rate (frames/s) at which :func:`take_sole` detects the planted toes: the retargeting networks'
own, so every method of a pair gets the same root; at 30 fps a run's stances are too short for
the detector (``docs/rigs.md``)."""


def take_sole(motion: Motion) -> float:
    """A rig's sole (metres) from a take on the canonical 22 joints: the median height of its toe
    joints over the frames where, at :data:`SOLE_FPS`, they are planted
    (:func:`contacts.planted_toe_heights`); 0 when none is."""
    clip = motion if motion.fps == SOLE_FPS else motion.resample(SOLE_FPS)
    heights = contacts.planted_toe_heights(clip)
    return float(np.median(heights)) if heights.size else 0.0


def on_sole(skeleton: Skeleton, sole: float) -> Skeleton:
    """``skeleton`` with its root's rest offset moved up or down so that its lowest rest joint stands
    ``sole`` metres above the floor; every other offset as it was. :func:`sole_height` reads ``sole``
    back when it can be a sole."""
    offsets = skeleton.offsets.copy()
    offsets[0, 1] += sole - skeleton.rest_positions()[:, 1].min()
    return Skeleton(skeleton.names, skeleton.parents, offsets, skeleton.end_sites)


def _apply(motion: Motion, turn: np.ndarray, sole: float = 0.0) -> Motion:
    """``motion`` on rest offsets turned by ``turn`` (22, 4) per joint, world positions unchanged;
    the new rest's lowest joint ``sole`` metres above the floor."""
    sk, parents = motion.skeleton, humanoid.PARENTS
    offsets = sk.offsets.copy()
    offsets[1:] = quat.rotate(turn[parents[1:]], sk.offsets[1:])
    offsets[0] = sk.offsets[0] * np.array([1.0, 0.0, 1.0])
    offsets[0, 1] = sole - Skeleton(sk.names, parents, offsets).rest_positions()[:, 1].min()
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


REST_FROM_HINT = (
    "take the standing pose from another take of the same rig that stands: --rest-from FILE.bvh "
    "(retarget, expand), rest_pose.standing(..., reference=) in Python"
)
"""How the refusal tells the user to give the standing pose of an unknown rig."""


def _standing_turn(motion: Motion, what: str, check: bool = True) -> tuple[np.ndarray, int, float]:
    """Rotations (22, 4) that make the most upright frame the rest pose, its index and worst angle;
    ``check``: raise :class:`RestPoseError` when that frame is not within :data:`TOLERANCE_DEG`."""
    g_rot, g_pos = motion.fk()
    score, which = _uprightness(g_pos)
    t = int(np.argmin(score))
    if check and not score[t] <= TOLERANCE_DEG:
        raise RestPoseError(
            f"{what}: no standing pose: the rest offsets do not stand and in no frame are thighs and shins within "
            f"{TOLERANCE_DEG:g} deg of straight down and Hips->Neck of straight up (most upright: frame {t}, where "
            f"{_WHAT[which[t]]} is {score[t]:.0f} deg off); {_other_up(g_pos)}{REST_FROM_HINT}"
        )

    yaw = humanoid.heading(g_pos[t])
    return quat.mul(quat.from_yaw(-yaw)[None], g_rot[t]), t, float(score[t])


_AXES = {
    "+Z": (0.0, 0.0, 1.0),
    "-Z": (0.0, 0.0, -1.0),
    "+X": (1.0, 0.0, 0.0),
    "-X": (-1.0, 0.0, 0.0),
    "-Y": (0.0, -1.0, 0.0),
}


def _other_up(g_pos: np.ndarray) -> str:
    """What to do when some frame of ``g_pos`` (T, 22, 3) stands upright about another world axis
    than +Y: a file exported with another up axis, or a take lying along that axis (then
    :data:`REST_FROM_HINT`, which follows, applies); else ``""``."""
    for name, axis in _AXES.items():
        score = _uprightness(g_pos, axis)[0]
        t = int(np.argmin(score))
        if score[t] <= TOLERANCE_DEG:
            return (
                f"but it stands with {name} up (frame {t}, within {score[t]:.0f} deg): a file exported with {name} up? "
                "motionlab reads BVH with +Y up, the format's convention: export it with Y up. If the take only "
                "lies or crawls, "
            )
    return ""


def _turned_offsets(offsets: np.ndarray, turn: np.ndarray) -> np.ndarray:
    """Rest offsets (22, 3) with each joint's child offsets turned by ``turn`` (22, 4), as :func:`_apply`."""
    out = offsets.copy()
    out[1:] = quat.rotate(turn[humanoid.PARENTS[1:]], offsets[1:])
    return out


def _pose_turn(motion: Motion, what: str, family: str | None) -> tuple[np.ndarray, StandingPose]:
    """Per-joint rotations (22, 4) from the rest pose to the canonical standing pose, and how it was found."""
    offsets = motion.skeleton.offsets
    if humanoid.STANDING.get(family or "", "rest") == "tpose":
        # the profile's rule: bone lengths from the rest offsets, every bone along the T-pose; the joint
        # frames (twist about each bone) from the most upright frame of this take, whatever its pose
        first, frame, worst = _standing_turn(motion, what, check=False)
        second, names = _straighten(_turned_offsets(offsets, first), every=True)
        return quat.mul(second, first), StandingPose("profile", frame, names, worst, family or "")
    worst = float(_uprightness(motion.skeleton.rest_positions())[0])
    first, source, frame = np.tile(quat.IDENTITY, (len(_J), 1)), "rest", -1
    if not worst <= TOLERANCE_DEG:
        first, frame, worst = _standing_turn(motion, what)
        source = "motion"
    second, names = _straighten(_turned_offsets(offsets, first))
    return quat.mul(second, first), StandingPose(source, frame, names, worst, family or "")


def same_rig(a: Skeleton, b: Skeleton, tolerance: float = 0.01) -> bool:
    """True when two canonical skeletons have the same rest offsets (each within ``tolerance`` × the
    larger leg length, :func:`humanoid.leg_length`): one rig, so one standing pose serves both."""
    scale = max(humanoid.leg_length(a), humanoid.leg_length(b))
    return bool(np.abs(a.offsets[1:] - b.offsets[1:]).max() <= tolerance * scale)


def standing(
    motion: Motion, what: str | None = None, family: str | None = None, reference: Motion | None = None
) -> tuple[Motion, StandingPose]:
    """The motion on its rig's canonical standing rest pose (module docstring).

    Parameters
    ----------
    motion : Motion on the 22 canonical joints (:func:`humanoid.to_canonical`), T frames
    what : how errors name the motion (default: its name)
    family : the rig profile it was mapped with (:func:`humanoid.family`); a profile whose rule
        in :data:`humanoid.STANDING` is ``"tpose"`` stands from its rest offsets on any take
    reference : another canonical Motion on the same rig (:func:`same_rig`) whose standing pose
        is used instead of this motion's own (``--rest-from``); the pose's ``source`` is ``"file"``

    Returns
    -------
    (Motion, StandingPose): the same T frames, fps and world positions (metres) on the new rest
    offsets — ``motion`` itself when the rest already stands and no bone is turned.

    Raises
    ------
    RestPoseError when neither the rest offsets nor any frame stand (see module docstring), naming
    :data:`REST_FROM_HINT`, or when ``reference`` is on another rig.
    ValueError when ``motion`` is not canonical.
    """
    if not humanoid.is_canonical(motion.skeleton):
        raise ValueError("standing() needs a 22-joint canonical motion; call humanoid.to_canonical first")
    what = what or motion.name or "motion"
    if reference is not None:
        if not humanoid.is_canonical(reference.skeleton) or not same_rig(reference.skeleton, motion.skeleton):
            raise RestPoseError(f"{what}: the standing pose's file {reference.name or ''} is on another rig")
        turn, pose = _pose_turn(reference, reference.name or "reference", family)
        pose = replace(pose, source="file", reference=reference.name or "")
    else:
        turn, pose = _pose_turn(motion, what, family)
    if pose.source == "rest" and not pose.straightened:
        return motion, pose
    sole = sole_height(motion.skeleton) if pose.source == "rest" else None
    return _apply(motion, turn, sole or 0.0), pose


def standing_skeleton(
    rig: Skeleton | Motion, what: str = "skeleton", reference: Motion | None = None
) -> tuple[Skeleton, StandingPose]:
    """A rig's canonical 22-joint skeleton in its standing rest pose (offsets in metres).

    ``rig`` is a Skeleton or a Motion on it (a frame of the motion is used when the rest offsets
    do not stand and its profile has no rule, :data:`humanoid.STANDING`); ``reference`` as in
    :func:`standing`. Raises :class:`RestPoseError` (naming ``what``, the joint and what was
    expected) and :class:`humanoid.RigMappingError`.
    """
    sk = rig.skeleton if isinstance(rig, Motion) else rig
    family = humanoid.family(sk)
    if isinstance(rig, Motion):
        motion = humanoid.to_canonical(rig)
    else:
        sk = humanoid.to_canonical_skeleton(rig)
        motion = Motion(sk, np.tile(quat.IDENTITY, (1, len(_J), 1)), sk.offsets[None, 0].copy(), 30.0)
        worst, which = _uprightness(sk.rest_positions())
        rule = humanoid.STANDING.get(family or "", "rest")
        if not worst <= TOLERANCE_DEG and rule != "tpose" and reference is None:
            raise RestPoseError(
                f"{what}: the rest offsets are not a standing pose ({_WHAT[int(which)]} is {float(worst):.0f} deg "
                f"off, at most {TOLERANCE_DEG:g} expected) and no motion was given to find one; "
                f"{_other_up(sk.rest_positions()[None])}{REST_FROM_HINT}"
            )
    out, pose = standing(motion, what, family, reference)
    return out.skeleton, pose


def on_reference(rig: Motion, reference: Motion | None, what: str = "motion") -> Motion:
    """``rig`` (a Motion on any mappable rig) on the 22 canonical joints in ``reference``'s standing
    pose when both are on one rig (:func:`same_rig`); ``rig`` itself otherwise or without a reference.

    ``reference`` is a Motion on any mappable rig (``--rest-from FILE.bvh``); the result's rest
    offsets stand, so retargeting uses them as they are, its lowest joint on the take's sole
    (:func:`take_sole`; 0 for a single frame). Raises
    :class:`RestPoseError` when the reference has no standing pose and :class:`humanoid.RigMappingError`.
    """
    if reference is None:
        return rig
    motion, ref = humanoid.to_canonical(rig), humanoid.to_canonical(reference)
    if not same_rig(motion.skeleton, ref.skeleton):
        return rig
    out = standing(motion, what, humanoid.family(rig.skeleton), reference=ref)[0]
    if out.num_frames < 2:
        return out
    return out.copy(skeleton=on_sole(out.skeleton, take_sole(out)))
