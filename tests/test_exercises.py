"""Every exercise check of notebooks 00, 01 and 04 against the instructor's key (must pass),
typical wrong answers written as a student would (must fail, with the matching hint), an
alternative correct answer where one exists (must pass), and an unattempted stub (must not raise).
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

from motionlab import exercises
from motionlab.core import fk, humanoid, quat

KEYS = Path(__file__).resolve().parents[1] / "notebooks" / "solutions"


def _key(name: str):
    spec = importlib.util.spec_from_file_location(name, KEYS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


K00 = _key("key_00_quaternions_and_fk")
K01 = _key("key_01_preprocessing")
K04 = _key("key_04_playback_and_bone_proportions")

# (exercise, the key's solution) for every exercise of the three notebooks
SOLUTIONS = {
    "conj": K00.my_conj,
    "slerp": K00.my_slerp,
    "hand_height": K00.left_hand_height_with_arm_raised,
    "heading": K01.my_heading,
    "window_count": K01.my_window_count,
    "pose_error": K04.my_pose_error,
    "joint_speed": K04.my_joint_speed,
}


def test_every_named_exercise_has_a_key():
    assert set(SOLUTIONS) == set(exercises.EXERCISES)


@pytest.mark.parametrize("name", sorted(SOLUTIONS))
def test_the_key_passes(name):
    result = exercises.EXERCISES[name].check(SOLUTIONS[name])
    assert result.passed and result.attempted, result.message
    assert result.message.startswith("✓")


@pytest.mark.parametrize("name", sorted(SOLUTIONS))
def test_an_unattempted_stub_says_so_and_does_not_raise(name):
    def stub(*args, **kwargs):
        raise NotImplementedError("Exercise: ...")

    result = exercises.EXERCISES[name].check(stub)
    assert not result.passed and not result.attempted
    assert "not written yet" in result.message and "goes on" in result.message


def test_a_crashing_answer_is_reported_not_raised():
    result = exercises.conj.check(lambda q: q[..., 5])
    assert not result.passed and result.attempted and "IndexError" in result.message


# ----------------------------------------------------------------------------- wrong answers
# Each wrong answer is written independently of the Mistake functions in motionlab.exercises,
# the way a student would get it wrong; the expected hint is matched by a phrase.


def _wrong_hand(joint="LeftArm", angle=np.pi / 2, coord=1):
    def answer(skeleton):
        rot = np.tile(quat.IDENTITY, (skeleton.num_joints, 1))
        rot[skeleton.index(joint)] = quat.from_axis_angle([0, 0, 1], angle)
        return fk.fk(rot, skeleton.offsets, skeleton.parents)[1][skeleton.index("LeftHand"), coord]

    return answer


def _slerp_without_flip(q0, q1, t):
    om = np.arccos(np.clip(np.dot(q0, q1), -1, 1))
    return (np.sin((1 - t) * om) * q0 + np.sin(t * om) * q1) / np.sin(om)


def _nlerp(q0, q1, t):
    q1 = q1 if np.dot(q0, q1) > 0 else -q1
    q = (1 - t) * q0 + t * q1
    return q / np.linalg.norm(q)


def _heading_swapped(pose):
    ix = humanoid.JOINTS.index
    across = pose[ix("LeftUpLeg")] - pose[ix("RightUpLeg")] + pose[ix("LeftArm")] - pose[ix("RightArm")]
    f = np.cross(across, [0, 1, 0])
    return np.arctan2(f[2], f[0])


def _heading_reversed_cross(pose):
    ix = humanoid.JOINTS.index
    across = pose[ix("LeftUpLeg")] - pose[ix("RightUpLeg")] + pose[ix("LeftArm")] - pose[ix("RightArm")]
    f = np.cross([0, 1, 0], across)
    return np.arctan2(f[0], f[2])


def _heading_hips(pose):
    ix = humanoid.JOINTS.index
    f = np.cross(pose[ix("LeftUpLeg")] - pose[ix("RightUpLeg")], [0, 1, 0])
    return np.arctan2(f[0], f[2])


def _speed_per_frame(motion):
    return np.linalg.norm(np.gradient(motion.global_positions(), axis=0), axis=-1)


def _speed_short(motion):
    return np.linalg.norm(np.diff(motion.global_positions(), axis=0), axis=-1) * motion.fps


def _pose_error_with_root(motion, reference):
    return np.linalg.norm(motion.global_positions() - reference.global_positions(), axis=-1).mean(axis=1)


def _pose_error_squared(motion, reference):
    a, b = motion.global_positions(), reference.global_positions()
    return (((a - a[:, :1]) - (b - b[:, :1])) ** 2).sum(-1).mean(1)


WRONG = [
    ("conj", lambda q: -q, "all four components"),
    ("conj", lambda q: quat.inv(q), "inverse"),
    ("slerp", _slerp_without_flip, "shorter of the two arcs"),
    ("slerp", _nlerp, "constant angular speed"),
    ("hand_height", _wrong_hand(angle=-np.pi / 2), "below the shoulder"),
    ("hand_height", _wrong_hand(angle=90), "radians"),
    ("hand_height", _wrong_hand(joint="LeftShoulder"), "collarbone"),
    ("hand_height", _wrong_hand(coord=0), "up axis"),
    ("heading", _heading_swapped, "atan2"),
    ("heading", _heading_reversed_cross, "half a turn"),
    ("heading", _heading_hips, "shoulders"),
    ("heading", lambda p: np.degrees(K01.my_heading(p)), "degrees"),
    ("window_count", lambda n, window=120, stride=30: (n - window) // stride + 1, "shorter than one window"),
    ("window_count", lambda n, window=120, stride=30: max(1, (n - window) // stride + 1), "moved back"),
    ("pose_error", _pose_error_with_root, "root position"),
    ("pose_error", _pose_error_squared, "squared"),
    ("joint_speed", _speed_per_frame, "metres per second"),
    ("joint_speed", _speed_short, "one frame fewer"),
    ("joint_speed", lambda m: np.gradient(m.global_positions(), axis=0) * m.fps, "velocity"),
]


@pytest.mark.parametrize(("name", "answer", "phrase"), WRONG, ids=[f"{w[0]}-{w[2]}" for w in WRONG])
def test_a_typical_wrong_answer_fails_with_its_hint(name, answer, phrase):
    result = exercises.EXERCISES[name].check(answer)
    assert not result.passed and result.attempted
    assert result.hint is not None and phrase in result.hint, result.message


def test_a_wrong_answer_without_a_known_mistake_still_fails_and_names_the_case():
    result = exercises.window_count.check(lambda n, window=120, stride=30: n // stride)
    assert not result.passed and result.hint is None and "case 1" in result.message


def test_the_hand_height_check_does_not_reveal_the_answer():
    """Notebook 00's old check printed its solution; the hint must not give the height away."""
    answer = exercises.hand_height.reference(humanoid.canonical_skeleton(1.75))
    for _, wrong, _ in [w for w in WRONG if w[0] == "hand_height"]:
        message = exercises.hand_height.check(wrong).message
        assert f"{answer:.3f}" not in message and f"{answer:.2f}" not in message, message


# ----------------------------------------------------------------------------- alternative correct answers
def _conj_concat(q):
    q = np.asarray(q)
    return np.concatenate([q[..., :1], -q[..., 1:]], axis=-1)


def _slerp_by_power(q0, q1, t):
    """q0 ⊗ (q0* ⊗ q1)^t through axis-angle: the same rotation, computed another way."""
    rel = quat.mul(quat.conj(q0), q1)
    if rel[0] < 0:
        rel = -rel
    axis, angle = quat.to_axis_angle(rel)
    return quat.mul(q0, quat.from_axis_angle(axis, t * angle))


def _hand_height_by_offsets(skeleton):
    """Raised straight up, the arm adds its bones' lengths to the shoulder joint's height."""
    rest = skeleton.rest_positions()
    lengths = sum(np.linalg.norm(skeleton.offsets[skeleton.index(n)]) for n in ("LeftForeArm", "LeftHand"))
    return rest[skeleton.index("LeftArm"), 1] + lengths


def _heading_in_0_2pi(pose):
    return K01.my_heading(pose) % (2 * np.pi)


def _window_count_ceil(n, window=120, stride=30):
    return 1 if n <= window else math.ceil((n - window) / stride) + 1


def _pose_error_loop(motion, reference):
    a, b = motion.global_positions(), reference.global_positions()
    return np.array(
        [
            np.mean([np.linalg.norm((a[t, j] - a[t, 0]) - (b[t, j] - b[t, 0])) for j in range(a.shape[1])])
            for t in range(len(a))
        ]
    )


def _speed_forward(motion):
    p = motion.global_positions()
    v = np.zeros_like(p)
    v[:-1] = p[1:] - p[:-1]
    v[-1] = v[-2]
    return np.linalg.norm(v, axis=-1) * motion.fps


def _speed_backward(motion):
    p = motion.global_positions()
    v = np.empty_like(p)
    v[1:] = p[1:] - p[:-1]
    v[0] = v[1]
    return np.linalg.norm(v, axis=-1) * motion.fps


ALTERNATIVES = [
    ("conj", _conj_concat),
    ("slerp", _slerp_by_power),
    ("hand_height", _hand_height_by_offsets),
    ("heading", _heading_in_0_2pi),
    ("window_count", _window_count_ceil),
    ("pose_error", _pose_error_loop),
    ("joint_speed", _speed_forward),
    ("joint_speed", _speed_backward),
]


@pytest.mark.parametrize(("name", "answer"), ALTERNATIVES, ids=[a[1].__name__ for a in ALTERNATIVES])
def test_an_alternative_correct_answer_passes(name, answer):
    result = exercises.EXERCISES[name].check(answer)
    assert result.passed, result.message


def test_the_forward_difference_is_accepted_where_the_old_check_rejected_it():
    result = exercises.joint_speed.check(_speed_forward)
    assert result.passed and "accepted variant" in result.message


def test_the_pose_error_reference_is_the_viewer_s_metric():
    """The check's reference is compare.joint_errors; the key recomputes it from positions."""
    for case in exercises.pose_error._cases():
        np.testing.assert_allclose(K04.my_pose_error(*case), exercises.pose_error.reference(*case), atol=1e-12)


# ----------------------------------------------------------------------------- the generic check
def test_generic_check_passes_fails_and_hints_without_raising():
    cases = [(np.arange(5.0),), (np.ones(3),)]
    ok = exercises.check(lambda x: 2 * x, lambda x: x + x, cases)
    assert ok.passed and repr(ok).startswith("✓")
    hint = exercises.Mistake(lambda x: x, "you forgot to double")
    bad = exercises.check(lambda x: x, lambda x: 2 * x, cases, mistakes=[hint])
    assert not bad.passed and bad.hint == "you forgot to double" and "case 1" in bad.message
    shape = exercises.check(lambda x: x[:-1], lambda x: x, cases)
    assert not shape.passed and "shape" in shape.message


def test_generic_check_compares_quaternions_up_to_sign_and_angles_up_to_turns():
    q = quat.normalize(np.random.default_rng(0).normal(size=(4, 4)))
    assert exercises.check(lambda q: -q, lambda q: q, [(q,)], sign_free=True).passed
    assert not exercises.check(lambda q: -q, lambda q: q, [(q,)]).passed
    a = np.linspace(-3, 3, 7)
    assert exercises.check(lambda a: a + 2 * np.pi, lambda a: a, [(a,)], period=2 * np.pi).passed
