"""Body: from a root path and foot targets to the local joint rotations of the 22-joint humanoid.

Built top-down, every step vectorised over frames:

1. **Pelvis.** Orientation = heading + hip twist (yaw), tilt with the lean, roll towards the
   stance leg. Position: over the feet when standing, on the planned path when walking, with
   the sideways weight shift, the vertical bounce and the jump/squat programmes. Its height is
   then *soft-clamped* so both ankles stay within 99 % of the leg's reach
   (``y = −k·log Σ exp(−yᵢ/k)``, always at or below every limit): the planted feet decide
   how high the pelvis can be, which gives walking its inverted-pendulum rise and fall.
2. **Legs.** Two-bone IK puts the knee (bending towards the foot's forward) so the ankle lands
   exactly on its target (a swinging foot out of reach is followed *softly*, so the knee never
   snaps straight); :func:`~.ik.aim` turns the points into thigh and shin rotations.
   The foot takes the planned yaw and pitch, the toes stay flat while the heel is up.
3. **Spine and head.** The chest target (heading, counter-rotated against the pelvis, leaning
   forward) is shared by the three spine joints; the head is kept level and looking ahead.
4. **Arms.** Swung about the chest's side axis opposite to the legs, always slightly abducted
   so the hands pass beside the body, elbows bending more on the forward swing.

Used by every notebook when ``MOTIONLAB_DATA`` is unset (see ``notebooks/01_preprocessing.ipynb``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core import quat
from motionlab.core.humanoid import JOINTS
from motionlab.core.skeleton import Skeleton
from motionlab.synthetic import ik
from motionlab.synthetic.footsteps import FootTracks, foot_pose
from motionlab.synthetic.timeline import Timeline, ease_track, smoothstep

__all__ = ["Geometry", "pose", "STAND_EXTENSION", "REACH"]

STAND_EXTENSION = 0.995
"""Hip-to-ankle distance when standing, as a fraction of thigh + shin (knees nearly straight)."""

REACH = 0.999
"""The pelvis is lowered so no heel-down ankle is farther than this fraction of thigh + shin."""

REACH_LIFTED = 0.96
"""The same for a foot with its heel up or in the air: the knee stays bent (and away from the
straight-leg singularity, where the knee would jump for a tiny move of the foot)."""

_SOFTMIN = 0.006  # metres: sharpness of the soft clamp on pelvis height
_SWING_SLACK = 0.15  # see _reach
_SOFT_KNEE = 0.03  # soft IK of a swinging leg starts this fraction short of full extension (→ 0 at touch-down)
_ANTICIPATE = 0.1  # seconds: the pelvis starts lowering this early for a foot that reaches far
_X = np.array([1.0, 0.0, 0.0])
_Y = np.array([0.0, 1.0, 0.0])
_Z = np.array([0.0, 0.0, 1.0])
_SIDES = ("Left", "Right")
_SIGN = np.array([1.0, -1.0])  # left is +X


def _j(name: str) -> int:
    return JOINTS.index(name)


@dataclass(frozen=True)
class Geometry:
    """The lengths of a character that the generator needs (metres); index 0 left, 1 right.

    Attributes
    ----------
    offsets : (22, 3) rest offsets       thigh, shin : (2,) bone lengths       leg : mean thigh + shin
    hip : (2, 3) hip joints from the pelvis          hip_width : distance between the hips
    toe, heel : (2, 3) toe joint / heel point from the ankle (rest foot frame)
    ankle_height : (2,) ankle height when the foot lies flat with its lowest joint on y = 0
    """

    offsets: np.ndarray
    thigh: np.ndarray
    shin: np.ndarray
    leg: float
    hip: np.ndarray
    hip_width: float
    toe: np.ndarray
    heel: np.ndarray
    ankle_height: np.ndarray

    @classmethod
    def from_skeleton(cls, skeleton: Skeleton) -> Geometry:
        off = np.asarray(skeleton.offsets, dtype=np.float64)
        lengths = np.linalg.norm(off, axis=-1)
        thigh = np.array([lengths[_j(f"{s}Leg")] for s in _SIDES])
        shin = np.array([lengths[_j(f"{s}Foot")] for s in _SIDES])
        hip = np.stack([off[_j(f"{s}UpLeg")] for s in _SIDES])
        toe = np.stack([off[_j(f"{s}ToeBase")] for s in _SIDES])
        ankle_height = np.maximum(0.0, -toe[:, 1])
        foot_length = np.maximum(np.abs(toe[:, 2]), 0.3 * np.linalg.norm(toe, axis=-1))
        heel = np.stack([np.array([0.0, -ankle_height[f], -0.35 * foot_length[f]]) for f in (0, 1)])
        return cls(
            off,
            thigh,
            shin,
            float(np.mean(thigh + shin)),
            hip,
            float(abs(hip[0, 0] - hip[1, 0])),
            toe,
            heel,
            ankle_height,
        )

    def stand_height(self, step_width) -> np.ndarray:
        """Pelvis height (...) over flat feet ``step_width`` hip-widths apart, knees nearly straight."""
        heights = []
        for f in (0, 1):
            lateral = 0.5 * self.hip_width * (np.asarray(step_width) - 1.0)
            reach = STAND_EXTENSION * (self.thigh[f] + self.shin[f])
            vertical = np.sqrt(np.maximum(reach**2 - lateral**2 - self.hip[f, 2] ** 2, 1e-6))
            heights.append(self.ankle_height[f] + vertical - self.hip[f, 1])
        return 0.5 * (heights[0] + heights[1])

    def rise_on_toes(self, pitch: float) -> float:
        """Pelvis rise (metres) above standing with both heels up by ``pitch`` radians on the toes
        and the legs at the :data:`REACH_LIFTED` limit less a margin (a jump's take-off/touch-down)."""
        lifted = [foot_pose(np.zeros(3), 0.0, pitch, self.toe[f], self.heel[f])[1] for f in (0, 1)]
        bend = (STAND_EXTENSION - (REACH_LIFTED - 0.01)) * (self.thigh + self.shin)
        return float(np.mean(lifted) - np.mean(bend))


def _rx(angle) -> np.ndarray:
    return quat.from_axis_angle(_X, angle)


def _rz(angle) -> np.ndarray:
    return quat.from_axis_angle(_Z, angle)


def _fraction(q: np.ndarray, weight: float) -> np.ndarray:
    """The rotation ``q`` (..., 4) scaled to ``weight`` of its angle about the same axis."""
    axis, angle = quat.to_axis_angle(q)
    return quat.from_axis_angle(axis, weight * angle)


def _reach(track: FootTracks) -> np.ndarray:
    """Fraction (N,) of thigh + shin the hip may be from this foot's ankle target.

    Heel down: :data:`REACH`. Heel up (toes planted, or flying in a jump): :data:`REACH_LIFTED`.
    During a step's swing it goes from a lenient ``REACH_LIFTED + slack`` at lift-off (a foot
    left behind may trail out of reach, the leg pointing at it, rather than drag the pelvis
    down) to what the touch-down will need.
    """
    u = smoothstep(np.clip(track.swing, 0.0, 1.0))
    touchdown = np.where(track.lands_heel, REACH, REACH_LIFTED)
    swinging = REACH_LIFTED + _SWING_SLACK + (touchdown - REACH_LIFTED - _SWING_SLACK) * u
    return np.where(track.heel_down, REACH, np.where(track.swing >= 0.0, swinging, REACH_LIFTED))


def _softmin(*values: np.ndarray, k: float = _SOFTMIN) -> np.ndarray:
    stack = np.stack(values)
    low = stack.min(axis=0)
    return low - k * np.log(np.sum(np.exp(-(stack - low) / k), axis=0))


def _smooth_floor(values: np.ndarray, fps: float) -> np.ndarray:
    """A smooth curve (N,) never above ``values``: a moving minimum, then a moving average.

    Each output sample averages minima over windows that all contain the sample itself, so it
    stays at or below it; a limit that drops quickly (a foot reaching far ahead) is met early
    and gently instead of abruptly.
    """
    half = max(int(round(_ANTICIPATE * fps)), 1)
    padded = np.pad(values, half, mode="edge")
    low = np.lib.stride_tricks.sliding_window_view(padded, 2 * half + 1).min(axis=-1)
    kernel = np.hanning(2 * half + 3)[1:-1]
    return np.convolve(np.pad(low, half, mode="edge"), kernel / kernel.sum(), mode="valid")


def _ground(v2: np.ndarray) -> np.ndarray:
    """(..., 2) ground-plane (x, z) vectors as (..., 3) with y = 0."""
    return np.stack([v2[..., 0], np.zeros(v2.shape[:-1]), v2[..., 1]], axis=-1)


@dataclass
class _Drive:
    """Per-frame quantities (N,) that several stages of :func:`pose` read; angles in radians."""

    P: dict[str, np.ndarray]  # blended style parameters
    heading: np.ndarray
    phase: np.ndarray
    gait: np.ndarray  # weight of stepping locomotion
    stand: np.ndarray  # 1 - gait
    cycle: np.ndarray  # 2π phase
    midstance: np.ndarray  # 2π (phase - duty / 2)
    fwd2: np.ndarray  # (N, 2) ground-plane forward
    left2: np.ndarray  # (N, 2) ground-plane left
    lean: np.ndarray
    twist: np.ndarray  # pelvis yaw about the heading


def _drive(tl: Timeline, heading: np.ndarray, phase: np.ndarray, extra: dict[str, np.ndarray]) -> _Drive:
    P = tl.params
    gait = tl.gait
    cycle = 2.0 * np.pi * phase
    return _Drive(
        P=P,
        heading=heading,
        phase=phase,
        gait=gait,
        stand=1.0 - gait,
        cycle=cycle,
        midstance=2.0 * np.pi * (phase - 0.5 * P["duty"]),
        fwd2=np.stack([np.sin(heading), np.cos(heading)], axis=-1),
        left2=np.stack([np.cos(heading), -np.sin(heading)], axis=-1),
        lean=P["lean"] + extra["lean"],
        twist=-P["hip_twist"] * np.cos(cycle),
    )


def _pelvis_position(geo, tl, d: _Drive, q_pelvis, base, feet, extra, noise) -> tuple[np.ndarray, list[np.ndarray]]:
    """Root positions (N, 3) and the hips relative to the root [(N, 3), (N, 3)] (see the module's step 1)."""
    P, leg, gait, stand = d.P, geo.leg, d.gait, d.stand
    feet_mid = 0.5 * (feet[0].ankle[:, [0, 2]] + feet[1].ankle[:, [0, 2]])
    shift = P["sway"] * leg * (gait * np.cos(d.midstance) + stand * noise["sway"])
    xz = gait[:, None] * base + stand[:, None] * feet_mid
    xz = xz + shift[:, None] * d.left2 - extra["back"][:, None] * d.fwd2
    y = (
        geo.stand_height(P["step_width"])
        - P["crouch"] * leg
        + P["bounce"] * leg * np.cos(2.0 * d.midstance)
        + extra["dy"]
        + 0.004 * leg * stand * noise["breath"]
    )
    hips_rel = [quat.rotate(q_pelvis, geo.hip[f]) for f in (0, 1)]
    limits = []
    for f in (0, 1):
        ankle = feet[f].ankle
        d2 = np.sum((xz + hips_rel[f][:, [0, 2]] - ankle[:, [0, 2]]) ** 2, axis=-1)
        reach = _reach(feet[f]) * (geo.thigh[f] + geo.shin[f])
        limits.append(ankle[:, 1] + np.sqrt(np.maximum(reach**2 - d2, 0.0)) - hips_rel[f][:, 1])
    limit = np.minimum(*limits)
    # a jump already plans its own ballistic path; elsewhere meet a falling limit in good time
    jumping = np.zeros(len(d.heading))
    for jump in tl.jumps:
        inside = ease_track(tl.time, [jump.crouch - 0.15, jump.crouch, jump.recover, jump.recover + 0.15], [0, 1, 1, 0])
        jumping = np.maximum(jumping, inside)
    y = _softmin(y, jumping * limit + (1.0 - jumping) * _smooth_floor(limit, tl.fps))
    return np.stack([xz[:, 0], y, xz[:, 1]], axis=-1), hips_rel


def _pose_legs(local, geo, d: _Drive, q_pelvis, root, hips_rel, feet) -> None:
    """Hip, knee, ankle and toe rotations into ``local`` by two-bone IK onto the foot tracks."""
    off = geo.offsets
    pelvis_fwd = quat.rotate(quat.from_yaw(d.heading + d.twist), _Z)
    for f, side in enumerate(_SIDES):
        track = feet[f]
        hip = root + hips_rel[f]
        foot_fwd = quat.rotate(quat.from_yaw(track.yaw), _Z)
        pole = foot_fwd + pelvis_fwd + 0.1 * _SIGN[f] * _ground(d.left2)
        # a swinging foot out of reach is followed softly (no knee snap); planted ones exactly
        soft = np.where(track.swing >= 0.0, _SOFT_KNEE * (1.0 - track.swing) * (geo.thigh[f] + geo.shin[f]), 0.0)
        knee, ankle = ik.two_bone(hip, track.ankle, geo.thigh[f], geo.shin[f], pole, soft)
        g_thigh = ik.aim(off[_j(f"{side}Leg")], _Z, knee - hip, pole)
        g_shin = ik.aim(off[_j(f"{side}Foot")], _Z, ankle - knee, pole)
        g_foot = quat.mul(quat.from_yaw(track.yaw), _rx(track.pitch))
        local[:, _j(f"{side}UpLeg")] = quat.mul(quat.conj(q_pelvis), g_thigh)
        local[:, _j(f"{side}Leg")] = quat.mul(quat.conj(g_thigh), g_shin)
        local[:, _j(f"{side}Foot")] = quat.mul(quat.conj(g_shin), g_foot)
        local[:, _j(f"{side}ToeBase")] = _rx(track.toe_bend)


def _pose_spine_and_head(local, d: _Drive, q_pelvis, noise) -> np.ndarray:
    """Spine, neck and head rotations into ``local``; returns the chest's world rotation (N, 4)."""
    chest_yaw = d.heading + 0.7 * d.P["hip_twist"] * np.cos(d.cycle)
    q_chest = quat.mul(quat.from_yaw(chest_yaw), _rx(d.lean))
    bend = quat.mul(quat.conj(q_pelvis), q_chest)
    for name, weight in (("Spine", 0.3), ("Spine1", 0.35), ("Spine2", 0.35)):
        local[:, _j(name)] = _fraction(bend, weight)
    look_pitch = 0.08 + 0.3 * np.maximum(d.lean - 0.1, 0.0)
    q_head = quat.mul(quat.from_yaw(d.heading + 0.3 * d.stand * noise["look"]), _rx(look_pitch))
    nod = quat.mul(quat.conj(q_chest), q_head)
    local[:, _j("Neck")] = _fraction(nod, 0.5)
    local[:, _j("Head")] = _fraction(nod, 0.5)
    return q_chest


def _pose_arms(local, geo, d: _Drive, q_chest, extra, noise) -> None:
    """Clavicle, shoulder and elbow rotations into ``local``: a swing against the legs, elbows bent."""
    P, off = d.P, geo.offsets
    swing = P["arm_swing"] * (1.0 + 0.1 * noise["arm"]) * np.cos(2.0 * np.pi * (d.phase - 0.03))
    idle_arm = 0.04 * d.stand * noise["sway"]
    for f, side in enumerate(_SIDES):
        theta = -_SIGN[f] * swing + extra["arm"] + idle_arm
        elbow = np.maximum(P["elbow"] + extra["elbow"] + 0.3 * np.maximum(theta, 0.0), 0.03)
        clavicle = _rz(_SIGN[f] * 0.25 * np.maximum(theta - 1.2, 0.0))
        g_shoulder = quat.mul(q_chest, clavicle)
        q_arm = quat.mul(_rx(-theta), _rz(_SIGN[f] * P["arm_out"]))
        upper = quat.rotate(q_arm, -_Y)
        bend_dir = quat.rotate(q_arm, _Z)
        c, s = np.cos(elbow)[:, None], np.sin(elbow)[:, None]
        fore = c * upper + s * bend_dir
        fore_bend = -s * upper + c * bend_dir
        g_arm = ik.aim(off[_j(f"{side}ForeArm")], _Z, quat.rotate(q_chest, upper), quat.rotate(q_chest, bend_dir))
        g_fore = ik.aim(off[_j(f"{side}Hand")], _Z, quat.rotate(q_chest, fore), quat.rotate(q_chest, fore_bend))
        local[:, _j(f"{side}Shoulder")] = clavicle
        local[:, _j(f"{side}Arm")] = quat.mul(quat.conj(g_shoulder), g_arm)
        local[:, _j(f"{side}ForeArm")] = quat.mul(quat.conj(g_arm), g_fore)


def pose(
    geo: Geometry,
    tl: Timeline,
    heading: np.ndarray,
    phase: np.ndarray,
    base: np.ndarray,
    feet: list[FootTracks],
    extra: dict[str, np.ndarray],
    noise: dict[str, np.ndarray],
) -> tuple[np.ndarray, np.ndarray]:
    """Local rotations (N, 22, 4) and root positions (N, 3) for every frame of the grid.

    Parameters
    ----------
    geo : Geometry                    the character
    tl : Timeline                     blended style parameters
    heading : (N,) radians            travel direction
    phase : (N,) cycles               gait clock (left foot lands at integers)
    base : (N, 2) metres              planned (x, z) path
    feet : [left, right] FootTracks   ankle targets and foot angles
    extra : dict of (N,) curves       jump/squat programmes (see ``actions.curves``)
    noise : dict of (N,) curves       slow random signals in [-1, 1]: ``sway``, ``look``,
                                      ``arm``, ``breath``
    """
    d = _drive(tl, heading, phase, extra)
    roll = 0.4 * d.P["hip_twist"] * np.cos(d.midstance)
    q_pelvis = quat.mul(quat.mul(quat.from_yaw(heading + d.twist), _rx(0.35 * d.lean)), _rz(roll))
    root, hips_rel = _pelvis_position(geo, tl, d, q_pelvis, base, feet, extra, noise)
    local = np.tile(quat.IDENTITY, (len(heading), len(JOINTS), 1))
    local[:, 0] = q_pelvis
    _pose_legs(local, geo, d, q_pelvis, root, hips_rel, feet)
    q_chest = _pose_spine_and_head(local, d, q_pelvis, noise)
    _pose_arms(local, geo, d, q_chest, extra, noise)
    return local, root
