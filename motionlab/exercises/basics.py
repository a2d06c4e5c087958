"""Exercises of notebooks 00 (quaternions, FK), 00b (the BVH format), 01 (preprocessing) and 04 (playback)."""

from __future__ import annotations

import numpy as np

from .core import Exercise, Mistake, Question

__all__ = [
    "nlerp_turn",
    "euler_order",
    "hand_height",
    "hips_heading",
    "window_count",
    "shorter_legs",
    "joint_speed",
    "reader_order",
    "NLERP_LIMIT",
]


# --------------------------------------------------------------------------- notebook 00
def _nlerp_speed_ratio(turn_degrees: float, steps: int = 50, radians_typed: bool = False) -> float:
    """Fastest / slowest step of nlerp from the identity to a turn about y (section 4's experiment)."""
    from motionlab.core import quat

    angle = turn_degrees if radians_typed else np.radians(turn_degrees)  # the mistake passes 90 as radians
    q0, q1 = quat.IDENTITY, quat.from_axis_angle([0, 1, 0], angle)
    t = np.linspace(0, 1, steps)
    nlerp = quat.normalize((1 - t)[:, None] * q0 + t[:, None] * q1)
    step = np.diff(np.degrees(quat.angle_between(q0, nlerp)))
    return float(step.max() / step.min())


NLERP_LIMIT = 1.10
"""Exercise 1's bound on nlerp's fastest / slowest step (10% faster in the middle than at the ends)."""


def _largest_turn(limit: float = NLERP_LIMIT, first_above: bool = False) -> float:
    """The largest whole-degree turn (1…179°) whose nlerp ratio is at most ``limit`` (or, with
    ``first_above``, the smallest whose ratio exceeds it)."""
    turns = np.arange(1, 180)
    ok = np.array([_nlerp_speed_ratio(float(a)) <= limit for a in turns])
    return float(turns[~ok][0]) if first_above else float(turns[ok][-1])


nlerp_turn = Question(
    "00 · exercise 1 (experiment: how large a turn nlerp can take)",
    _largest_turn,
    atol=0.006,  # whole degrees; a radian answer typed with two decimals is still recognised
    mistakes=[
        Mistake(
            lambda: _largest_turn(first_above=True),
            "that is the first turn whose ratio is above 1.10; the question asks for the largest turn "
            "whose ratio is still at most 1.10.",
        ),
        Mistake(
            lambda: float(np.radians(_largest_turn())),
            "that is in radians; answer with the turn in whole degrees.",
        ),
        Mistake(
            lambda: round(_nlerp_speed_ratio(90.0), 2),
            "that is a ratio; the answer is a turn, in degrees.",
        ),
        Mistake(lambda: 179.0, "every turn passes with slerp (ratio 1.00); the question is about nlerp."),
    ],
)
"""Notebook 00, section 4: the largest whole-degree turn for which nlerp's fastest / slowest step
(50 steps) stays at most :data:`NLERP_LIMIT`."""

_EULER_ANGLES = (30.0, -20.0, 45.0)  # degrees, section 3's angles


def _order_gap(order: str = "xyz", degrees: bool = True, typed_degrees: bool = False) -> float:
    """Angle between section 3's rotation read as ``zxy`` and the same numbers read as ``order``."""
    from motionlab.core import quat

    angles = np.array(_EULER_ANGLES) if typed_degrees else np.radians(_EULER_ANGLES)
    gap = float(quat.angle_between(quat.from_euler(angles, "zxy"), quat.from_euler(angles, order)))
    return float(np.degrees(gap)) if degrees else gap


euler_order = Question(
    "00 · exercise 2 (experiment: the same angles in another channel order)",
    _order_gap,
    atol=0.06,  # an answer typed with one decimal passes
    mistakes=[
        Mistake(lambda: _order_gap(degrees=False), "that is in radians; the question asks for degrees."),
        Mistake(
            lambda: _order_gap(typed_degrees=True),
            "quat.from_euler takes radians: pass np.radians([30, -20, 45]), as section 3 does.",
        ),
        Mistake(lambda: 0.0, "you compared 'zxy' with itself: build the second rotation with order 'xyz'."),
        Mistake(
            lambda: _order_gap("zyx"),
            "that is the order 'zyx'; the question asks for 'xyz'.",
        ),
    ],
)
"""Notebook 00, section 3: degrees between (30°, −20°, 45°) read as ``zxy`` and as ``xyz``."""


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
def _heading_gap(world, across: str = "hips", reduce: str = "max", degrees: bool = True, flip: bool = False) -> float:
    """Largest (or mean) |ψ_across − ψ| over the frames of ``world`` (T, 22, 3), wrapped to ±180°.

    ``across``: ``"hips"`` (LeftUpLeg − RightUpLeg) or ``"shoulders"`` (LeftArm − RightArm);
    ψ is :func:`motionlab.core.preprocess.heading` (hips and shoulders together).
    """
    from motionlab.core import humanoid, preprocess

    p = np.asarray(world, dtype=np.float64)
    ix = humanoid.JOINTS.index
    left, right = ("LeftUpLeg", "RightUpLeg") if across == "hips" else ("LeftArm", "RightArm")
    vector = p[..., ix(left), :] - p[..., ix(right), :]
    up = np.array([0.0, 1.0, 0.0])
    forward = np.cross(up, vector) if flip else np.cross(vector, up)
    psi = np.arctan2(forward[..., 0], forward[..., 2])
    gap = np.abs((psi - preprocess.heading(p) + np.pi) % (2 * np.pi) - np.pi)
    value = float(gap.max() if reduce == "max" else gap.mean())
    return float(np.degrees(value)) if degrees else value


hips_heading = Question(
    "01 · exercise 1 (experiment: the heading from the hips alone)",
    _heading_gap,
    atol=0.06,  # an answer typed with one decimal passes
    rtol=0.002,
    mistakes=[
        Mistake(lambda w: _heading_gap(w, degrees=False), "that is in radians; the question asks for degrees."),
        Mistake(
            lambda w: _heading_gap(w, "shoulders"),
            "that is the shoulders' heading; the experiment keeps the hips (LeftUpLeg − RightUpLeg) only.",
        ),
        Mistake(
            lambda w: _heading_gap(w, reduce="mean"),
            "that is the mean over the frames; the question asks for the largest difference.",
        ),
        Mistake(
            lambda w: _heading_gap(w, flip=True),
            "off by about half a turn: forward = across × up, in that order (the cross product is not commutative).",
        ),
    ],
)
"""Notebook 01, section 3: the largest gap (degrees) between the hips-only heading and ψ on the clip."""


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
def _copied_error(walk, legs: float = 0.8, relative_to_root: bool = True) -> float:
    """Mean pose error (m) of ``walk`` copied by local rotations onto its skeleton with legs × ``legs``."""
    from motionlab.core import humanoid
    from motionlab.viz import compare, proportions

    copied = proportions.copy_rotation_solver(walk)(humanoid.scale_bones(walk.skeleton, legs=legs))
    return float(np.nanmean(compare.joint_errors(copied, walk, relative_to_root=relative_to_root)))


def _error_ratio(walk, inverse: bool = False) -> float:
    """Pose error of copying onto legs × 0.8 over the error onto legs × 1.25 (or the inverse)."""
    ratio = _copied_error(walk, 0.8) / _copied_error(walk, 1.25)
    return 1.0 / ratio if inverse else ratio


shorter_legs = Question(
    "04 · exercise 1 (experiment: does the copying error follow the leg change?)",
    _error_ratio,
    atol=0.006,  # an answer typed with two decimals passes
    rtol=0.005,
    mistakes=[
        Mistake(
            lambda walk: _copied_error(walk, 0.8),
            "that is the error on legs × 0.8 alone; divide it by the error on legs × 1.25.",
        ),
        Mistake(
            lambda walk: _error_ratio(walk, inverse=True),
            "that is the error on legs × 1.25 over the error on legs × 0.8; the question asks for the inverse.",
        ),
    ],
)
"""Notebook 04, section 4: the mean pose error (m) of the walk copied onto legs × 0.8 over the same
error onto legs × 1.25 (0.8 if the error grew in proportion to the change of leg length)."""


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


def _speed_central_second_order_ends(motion):  # np.gradient(..., edge_order=2)
    return np.linalg.norm(np.gradient(motion.global_positions(), axis=0, edge_order=2), axis=-1) * motion.fps


def _speed_central_held_ends(motion):  # (p[t+1] - p[t-1]) / 2 with the end frames repeated
    p = motion.global_positions()
    p = np.concatenate([p[:1], p, p[-1:]], axis=0)
    return np.linalg.norm(p[2:] - p[:-2], axis=-1) / 2 * motion.fps


joint_speed = Exercise(
    "04 · exercise 2 (joint speed)",
    _speed_central,
    _speed_cases,
    accept=[_speed_forward, _speed_backward, _speed_central_second_order_ends, _speed_central_held_ends],
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


# --------------------------------------------------------------------------- notebook 00b
def _reader_gap(path, degrees: bool = True, reduce=np.max, keep_order: bool = False) -> float:
    """Largest angle, over the joints, between frame 0 of ``path`` read with each joint's declared
    rotation order and with that order reversed (a reader that ignores ``CHANNELS``)."""
    from pathlib import Path

    from motionlab.core import bvh, quat

    channels = bvh.load(path).skeleton.channels
    lines = [line.strip() for line in Path(path).read_text().splitlines()]
    values = np.array(lines[lines.index("MOTION") + 3].split(), dtype=float)
    column, gaps = 0, []
    for chans in channels:
        v = values[column : column + len(chans)]
        column += len(chans)
        order = "".join(c[0].lower() for c in chans if c.endswith("rotation"))
        angles = np.radians([v[chans.index(a.upper() + "rotation")] for a in order])
        wrong_order = order if keep_order else order[::-1]
        wrong_angles = angles if keep_order else angles[::-1]
        gaps.append(quat.angle_between(quat.from_euler(angles, order), quat.from_euler(wrong_angles, wrong_order)))
    gap = float(reduce(gaps))
    return float(np.degrees(gap)) if degrees else gap


reader_order = Question(
    "00b · exercise 1 (experiment: a reader that ignores the channel order)",
    _reader_gap,
    atol=0.06,  # an answer typed with one decimal passes
    rtol=0.001,
    mistakes=[
        Mistake(lambda path: _reader_gap(path, degrees=False), "that is in radians; the question asks for degrees."),
        Mistake(
            lambda path: _reader_gap(path, reduce=np.mean),
            "that is the mean over the joints; the question asks for the largest angle.",
        ),
        Mistake(
            lambda path: 0.0,
            "the two readings agree only if you kept the declared order: reverse it (e.g. 'xyz' → 'zyx', "
            "each angle staying with its axis).",
        ),
    ],
)
"""Notebook 00b, section 3: the largest angle (degrees) between a joint's rotation in frame 0 read
in its declared channel order and in the reversed order."""
