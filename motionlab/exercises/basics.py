"""Exercises of notebooks 00 (quaternions, FK), 01 (preprocessing) and 04 (playback)."""

from __future__ import annotations

import math

import numpy as np

from .core import Exercise, Mistake

__all__ = ["conj", "slerp", "hand_height", "heading", "window_count", "pose_error", "joint_speed"]


# --------------------------------------------------------------------------- notebook 00
def _quat_cases():
    rng = np.random.default_rng(100)
    from motionlab.core import quat

    unit = quat.normalize(rng.normal(size=(5, 4)))
    not_unit = rng.normal(size=(2, 3, 4)) * 2.0  # conj is defined for any quaternion
    return [(unit,), (quat.IDENTITY.copy(),), (not_unit,)]


def _conj_ref(q):
    from motionlab.core import quat

    return quat.conj(q)


conj = Exercise(
    "00 · exercise 1 (conjugate)",
    _conj_ref,
    _quat_cases,
    mistakes=[
        Mistake(
            lambda q: -np.asarray(q),
            "you changed the sign of all four components. That is the same rotation as q, "
            "not its conjugate: which part of (w, x, y, z) keeps its sign?",
        ),
        Mistake(lambda q: np.asarray(q), "your function returns q unchanged."),
        Mistake(
            lambda q: _conj_ref(q) / np.sum(np.asarray(q) ** 2, axis=-1, keepdims=True),
            "you divided by |q|²: that is the inverse q⁻¹. It equals the conjugate only for unit "
            "quaternions, and case 3 is not a unit quaternion.",
        ),
    ],
)


def _slerp_cases():
    rng = np.random.default_rng(101)
    from motionlab.core import quat

    cases = []
    for k in range(6):
        q0, q1 = quat.normalize(rng.normal(size=4)), quat.normalize(rng.normal(size=4))
        if k % 2 == 0 and np.dot(q0, q1) > 0:  # half of the pairs need the short-arc flip
            q1 = -q1
        if k % 2 == 1 and np.dot(q0, q1) < 0:
            q1 = -q1
        for t in (0.0, 0.25, 0.5, 1.0):
            cases.append((q0, q1, t))
    return cases


def _slerp_ref(q0, q1, t):
    from motionlab.core import quat

    return quat.slerp(q0, q1, t)


def _slerp_long_arc(q0, q1, t):
    om = math.acos(float(np.clip(np.dot(q0, q1), -1.0, 1.0)))
    if om < 1e-9:
        return np.asarray(q0, dtype=float)
    return (math.sin((1 - t) * om) * np.asarray(q0) + math.sin(t * om) * np.asarray(q1)) / math.sin(om)


def _nlerp(q0, q1, t):
    q1 = np.asarray(q1) if np.dot(q0, q1) >= 0 else -np.asarray(q1)
    q = (1 - t) * np.asarray(q0) + t * q1
    return q / np.linalg.norm(q)


slerp = Exercise(
    "00 · exercise 2 (slerp)",
    _slerp_ref,
    _slerp_cases,
    sign_free=True,
    mistakes=[
        Mistake(
            _slerp_long_arc,
            "right when q0·q1 > 0, wrong otherwise: q1 and -q1 are the same rotation, and "
            "slerp must take the shorter of the two arcs between q0 and ±q1.",
        ),
        Mistake(
            _nlerp,
            "right at t = 0, 0.5 and 1 only: normalising a straight-line blend follows the arc "
            "but not at constant angular speed. Weight q0 and q1 by sines of the angle.",
        ),
        Mistake(
            lambda q0, q1, t: _slerp_ref(q0, q1, 1 - t),
            "at t = 0 the answer must be q0 and at t = 1 it must be q1: yours is the other way round.",
        ),
    ],
)


def _hand_height_ref(skeleton):
    from motionlab.core import fk, quat

    rot = np.tile(quat.IDENTITY, (skeleton.num_joints, 1))
    rot[skeleton.index("LeftArm")] = quat.from_axis_angle([0, 0, 1], np.pi / 2)
    return float(fk.fk(rot, skeleton.offsets, skeleton.parents)[1][skeleton.index("LeftHand"), 1])


def _hand_height_with(joint: str, axis, angle: float, coord: int = 1):
    def wrong(skeleton):
        from motionlab.core import fk, quat

        rot = np.tile(quat.IDENTITY, (skeleton.num_joints, 1))
        rot[skeleton.index(joint)] = quat.from_axis_angle(axis, angle)
        return float(fk.fk(rot, skeleton.offsets, skeleton.parents)[1][skeleton.index("LeftHand"), coord])

    return wrong


def _hand_height_cases():
    from motionlab.core import humanoid

    base = humanoid.canonical_skeleton(1.75)
    return [(base,), (humanoid.canonical_skeleton(1.60),), (humanoid.scale_bones(base, arms=1.2, legs=0.9),)]


hand_height = Exercise(
    "00 · exercise 3 (hand height)",
    _hand_height_ref,
    _hand_height_cases,
    mistakes=[
        Mistake(
            _hand_height_with("LeftArm", [0, 0, 1], -np.pi / 2),
            "your hand ends up below the shoulder. Which way does a positive rotation about +z "
            "turn the +x axis (right-hand rule)?",
        ),
        Mistake(
            _hand_height_with("LeftArm", [0, 0, 1], 90.0),
            "angles in motionlab are radians: 90 radians is not a quarter turn.",
        ),
        Mistake(
            _hand_height_with("LeftShoulder", [0, 0, 1], np.pi / 2),
            "you rotated LeftShoulder (the collarbone). The exercise rotates the shoulder joint, `LeftArm`.",
        ),
        Mistake(
            _hand_height_with("LeftArm", [0, 0, 1], np.pi / 2, coord=0),
            "that is the hand's x coordinate. Height is measured along the up axis: which axis is up?",
        ),
        Mistake(
            lambda s: float(s.rest_positions()[s.index("LeftHand"), 1]),
            "that is the hand's height in the rest pose: the arm has not been raised yet.",
        ),
    ],
)


# --------------------------------------------------------------------------- notebook 01
def _heading_cases():
    from motionlab import synthetic
    from motionlab.core import humanoid, quat

    walk = synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=40, fps=30, seed=3)
    pos = walk.global_positions()
    cases = []
    for k, yaw in enumerate(np.radians([0, 40, 100, 170, -135, -60])):  # every quadrant, both signs
        q = quat.from_axis_angle([0, 1, 0], yaw)
        cases.append((quat.rotate(q, pos[5 * k]),))
    return cases


def _heading_ref(pose):
    from motionlab.core import preprocess

    return preprocess.heading(pose)


def _heading_variant(mode: str):
    def wrong(pose):
        from motionlab.core import humanoid

        p = np.asarray(pose)
        ix = humanoid.JOINTS.index
        hips = p[ix("LeftUpLeg")] - p[ix("RightUpLeg")]
        shoulders = p[ix("LeftArm")] - p[ix("RightArm")]
        across = hips if mode == "hips only" else hips + shoulders
        up = np.array([0.0, 1.0, 0.0])
        f = np.cross(up, across) if mode == "up x across" else np.cross(across, up)
        if mode == "atan2(z, x)":
            return np.arctan2(f[2], f[0])
        if mode == "degrees":
            return np.degrees(np.arctan2(f[0], f[2]))
        return np.arctan2(f[0], f[2])

    return wrong


heading = Exercise(
    "01 · exercise 1 (heading)",
    _heading_ref,
    _heading_cases,
    period=2 * np.pi,
    atol=1e-6,
    mistakes=[
        Mistake(
            _heading_variant("up x across"),
            "off by half a turn: the cross product is not commutative. With the right-hand rule, "
            "which order of `across` and `up` points to the character's front?",
        ),
        Mistake(
            _heading_variant("atan2(z, x)"),
            "check the order of atan2's arguments: ψ = 0 means facing +z, and ψ grows from +z towards +x.",
        ),
        Mistake(_heading_variant("degrees"), "return radians, not degrees."),
        Mistake(
            _heading_variant("hips only"),
            "close but not equal: `across` uses the shoulders as well as the hips.",
        ),
    ],
)


def _window_count_ref(num_frames, window=120, stride=30):
    from motionlab.core import preprocess

    return len(preprocess.sliding_windows(num_frames, window, stride))


def _window_cases():
    return [(500,), (120,), (121,), (50,), (480,), (1000, 120, 60), (300, 64, 16)]


window_count = Exercise(
    "01 · exercise 2 (window count)",
    _window_count_ref,
    _window_cases,
    mistakes=[
        Mistake(
            lambda n, w=120, s=30: max(1, (n - w) // s + 1),
            "you counted the windows that start every `stride` frames, but not the extra one moved "
            "back to end on the last frame when frames are left over.",
        ),
        Mistake(
            lambda n, w=120, s=30: max(0, -(-(n - w) // s) + 1) if n >= w else 0,
            "a clip shorter than one window still gives one (padded) window.",
        ),
        Mistake(
            lambda n, w=120, s=30: (n - w) // s + 1,
            "a clip shorter than one window still gives one (padded) window, and look again at "
            "the last window when frames are left over.",
        ),
    ],
)


# --------------------------------------------------------------------------- notebook 04
def _pose_cases():
    from motionlab import synthetic
    from motionlab.core import humanoid, quat

    skeleton = humanoid.canonical_skeleton()
    walk = synthetic.generate("walk", skeleton, num_frames=30, fps=30.0, seed=0)
    other = synthetic.generate("run", skeleton, num_frames=30, fps=30.0, seed=1)
    turned = walk.copy(local_rot=quat.mul(quat.from_axis_angle([0, 1, 0], 0.3), walk.local_rot))
    return [(other, walk), (walk, walk), (turned, walk)]


def _pose_error_ref(motion, reference):
    from motionlab.viz import compare

    return compare.joint_errors(motion, reference, relative_to_root=True).mean(axis=1)


def _pose_error_variant(mode: str):
    def wrong(motion, reference):
        a, b = motion.global_positions(), reference.global_positions()
        if mode != "no root":
            a, b = a - a[:, :1], b - b[:, :1]
        d = np.linalg.norm(a - b, axis=-1)
        if mode == "squared":
            return (d**2).mean(axis=1)
        if mode == "over frames":
            return d.mean(axis=0)
        if mode == "components":
            return np.abs(a - b).mean(axis=(1, 2))
        return d.mean(axis=1)

    return wrong


pose_error = Exercise(
    "04 · exercise 1 (pose error)",
    _pose_error_ref,
    _pose_cases,
    mistakes=[
        Mistake(
            _pose_error_variant("no root"),
            "the two motions are compared as poses: subtract each motion's own root position from "
            "its joints first (frame by frame).",
        ),
        Mistake(_pose_error_variant("squared"), "average the distances, not the squared distances."),
        Mistake(
            _pose_error_variant("over frames"),
            "the result has one value per frame, shape (T,): which axis holds the joints?",
        ),
        Mistake(
            _pose_error_variant("components"),
            "the error of a joint is the length of the difference vector (a norm over x, y, z), "
            "not the mean of its coordinates' differences.",
        ),
    ],
)


def _speed_cases():
    from motionlab import synthetic
    from motionlab.core import humanoid

    skeleton = humanoid.canonical_skeleton()
    return [
        (synthetic.generate("walk", skeleton, num_frames=45, fps=30.0, seed=0),),
        (synthetic.generate("run", skeleton, num_frames=40, fps=60.0, seed=2),),
    ]


def _speed_central(motion):
    return np.linalg.norm(np.gradient(motion.global_positions(), axis=0), axis=-1) * motion.fps


def _speed_forward(motion):  # p[t+1] - p[t], the last frame repeats the one before it
    v = np.diff(motion.global_positions(), axis=0)
    v = np.concatenate([v, v[-1:]], axis=0)
    return np.linalg.norm(v, axis=-1) * motion.fps


def _speed_backward(motion):  # p[t] - p[t-1], the first frame repeats the one after it
    v = np.diff(motion.global_positions(), axis=0)
    v = np.concatenate([v[:1], v], axis=0)
    return np.linalg.norm(v, axis=-1) * motion.fps


joint_speed = Exercise(
    "04 · exercise 2 (joint speed)",
    _speed_central,
    _speed_cases,
    accept=[_speed_forward, _speed_backward],
    mistakes=[
        Mistake(
            lambda m: _speed_central(m) / m.fps,
            "your speeds are in metres per frame; the exercise asks for metres per second "
            "(a frame lasts 1/fps seconds).",
        ),
        Mistake(
            lambda m: _speed_forward(m) / m.fps,
            "your speeds are in metres per frame; the exercise asks for metres per second "
            "(a frame lasts 1/fps seconds).",
        ),
        Mistake(
            lambda m: _speed_central(m) / m.fps**2,
            "a frame lasts 1/fps seconds: do you multiply or divide by fps?",
        ),
        Mistake(
            lambda m: np.linalg.norm(np.diff(m.global_positions(), axis=0), axis=-1) * m.fps,
            "a finite difference has one frame fewer than the motion: return shape (T, J), e.g. by "
            "repeating the last difference (or use a central difference).",
        ),
        Mistake(
            lambda m: np.gradient(m.global_positions(), axis=0) * m.fps,
            "that is the velocity (T, J, 3); the speed is its length, shape (T, J).",
        ),
    ],
)
