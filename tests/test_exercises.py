"""Every exercise check of notebooks 00, 01, 02, 03, 04, 05 and 06 against the instructor's key (must pass),
typical wrong answers written as a student would (must fail, with the matching hint), an
alternative correct answer where one exists (must pass), and an unattempted stub (must not raise).
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest
import torch

from motionlab import exercises
from motionlab.core import fk, humanoid, quat

ROOT = Path(__file__).resolve().parents[1]
KEYS = ROOT / "instructor" / "solutions"  # the instructor's key, outside the students' notebooks/
NOTEBOOKS = ROOT / "notebooks"


def _key(name: str):
    spec = importlib.util.spec_from_file_location(name, KEYS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


K00 = _key("key_00_quaternions_and_fk")
K01 = _key("key_01_preprocessing")
K04 = _key("key_04_playback_and_bone_proportions")
K02 = _key("key_02_training_autoencoder")
K03 = _key("key_03_latent_iteration")
K05 = _key("key_05_motion_graphs")
K06 = _key("key_06_keypose_interpolation")

# (exercise, the key's solution) for every exercise of the notebooks
SOLUTIONS = {
    "conj": K00.my_conj,
    "slerp": K00.my_slerp,
    "hand_height": K00.left_hand_height_with_arm_raised,
    "heading": K01.my_heading,
    "window_count": K01.my_window_count,
    "pose_error": K04.my_pose_error,
    "joint_speed": K04.my_joint_speed,
    "recon_loss": K02.my_recon_loss,
    "combine": K02.my_combine,
    "rotations": K02.my_rotations,
    "foot_loss": K03.my_foot_loss,
    "root_scale": K03.my_root_scale,
    "angle_loss": K03.my_angle_loss,
    "local_minima": K05.my_local_minima,
    "distance_matrix": K05.my_distance_matrix,
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


# notebooks 02, 03, 05, 06
def _recon_squared(pred, target):
    return 0.5 * ((pred - target) ** 2).sum(-1).mean() / 3


def _recon_summed_batch(pred, target):
    T, J = pred.shape[-3], pred.shape[-2]
    return 0.5 / (3 * T * J) * torch.sqrt(((pred - target) ** 2).sum(-1)).sum()


def _combine_reversed(q, d):
    return K02.my_combine(d, q)


def _combine_plus_dot(q, d):
    w = q[..., :1] * d[..., :1] + (q[..., 1:] * d[..., 1:]).sum(-1, keepdim=True)
    v = q[..., :1] * d[..., 1:] + d[..., :1] * q[..., 1:] + torch.cross(q[..., 1:], d[..., 1:], dim=-1)
    return torch.cat([w, v], -1)


def _rotations_unnormalised(net, phi):
    return net.f_qlinear(phi).reshape(phi.shape[0], phi.shape[1], 22, 4)


def _rotations_whole_frame(net, phi):
    raw = net.f_qlinear(phi)
    raw = raw / torch.linalg.norm(raw, dim=-1, keepdim=True)
    return raw.reshape(phi.shape[0], phi.shape[1], 22, 4)


def _foot_all_joints(world_y):
    return torch.relu(-world_y).mean()


def _foot_signed(world_y):
    return torch.minimum(world_y[..., K03.FEET], torch.zeros(())).mean()


def _foot_abs(world_y):
    return world_y[..., K03.FEET].abs().mean()


def _root_hip_ratio(a, b):
    return (b.rest_positions()[0, 1] - b.rest_positions()[:, 1].min()) / (
        a.rest_positions()[0, 1] - a.rest_positions()[:, 1].min()
    )


def _root_thigh_shin(a, b):
    def legs(s):
        return sum(np.linalg.norm(s.offsets[s.index(n)]) for n in ("LeftLeg", "LeftFoot"))

    return legs(b) / legs(a)


def _angle_no_sign(a, b):
    return torch.linalg.norm(a - b, dim=-1).mean()


def _angle_radians(a, b):
    return (2 * torch.acos(torch.clamp(torch.abs((a * b).sum(-1)), max=1.0))).mean()


def _minima_strict(m):
    p = np.pad(m, 1, constant_values=np.inf)
    r, c = m.shape
    return np.all(
        [m < p[1 + i : 1 + i + r, 1 + j : 1 + j + c] for i in (-1, 0, 1) for j in (-1, 0, 1) if i or j], axis=0
    )


def _minima_four(m):
    p = np.pad(m, 1, constant_values=np.inf)
    return (m <= p[:-2, 1:-1]) & (m <= p[2:, 1:-1]) & (m <= p[1:-1, :-2]) & (m <= p[1:-1, 2:])


def _minima_roll(m):
    out = np.ones(m.shape, bool)
    for i in (-1, 0, 1):
        for j in (-1, 0, 1):
            if i or j:
                out &= m <= np.roll(np.roll(m, i, 0), j, 1)
    return out


def _distance_without_turn(pos_a, pos_b):
    from motionlab.motion_graphs import distance

    fa, fb = distance.cloud_features(pos_a), distance.cloud_features(pos_b)
    w2 = np.concatenate([fa.weights, fa.weights])
    a = (fa.centred * w2) @ fb.centred.T
    y = (fa.height * fa.weights) @ fb.height.T
    return np.maximum(fa.self_term[:, None] + fb.self_term[None, :] - 2 * y - 2 * a, 0)


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
    ("recon_loss", _recon_squared, "not squared distances"),
    ("recon_loss", _recon_summed_batch, "average over the batch"),
    ("combine", _combine_reversed, "not commutative"),
    ("combine", _combine_plus_dot, "scalar part"),
    ("rotations", _rotations_unnormalised, "divide each by its norm"),
    ("rotations", _rotations_whole_frame, "each joint's 4 numbers"),
    ("foot_loss", _foot_all_joints, "four foot joints"),
    ("foot_loss", _foot_signed, "negative"),
    ("foot_loss", _foot_abs, "costs nothing"),
    ("root_scale", _root_hip_ratio, "r_y"),
    ("root_scale", _root_thigh_shin, "thigh + shin"),
    ("root_scale", lambda a, b: K03.my_root_scale(b, a), "upside down"),
    ("angle_loss", _angle_no_sign, "smaller of"),
    ("angle_loss", _angle_radians, "rotation angle"),
    ("local_minima", _minima_strict, "<="),
    ("local_minima", _minima_four, "diagonal"),
    ("local_minima", _minima_roll, "np.roll"),
    ("distance_matrix", _distance_without_turn, "square-root term"),
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


def _recon_numpy_style(pred, target):
    return 0.5 * torch.sqrt(((pred - target) ** 2).sum(-1)).mean() / 3


def _combine_by_matrix(q, d):
    """q ⊗ p as the 4x4 left-multiplication matrix of q applied to p."""
    w, x, y, z = q.unbind(-1)
    rows = [
        torch.stack([w, -x, -y, -z], -1),
        torch.stack([x, w, -z, y], -1),
        torch.stack([y, z, w, -x], -1),
        torch.stack([z, -y, x, w], -1),
    ]
    return (torch.stack(rows, -2) @ d[..., None])[..., 0]


def _rotations_functional(net, phi):
    raw = torch.nn.functional.linear(phi, net.f_qlinear.weight, net.f_qlinear.bias)
    return torch.nn.functional.normalize(raw.view(*phi.shape[:-1], 22, 4), dim=-1)


def _foot_relu(world_y):
    return torch.relu(-world_y[..., K03.FEET]).mean()


def _root_from_rest_positions(a, b):
    def chain(s):
        p = s.rest_positions()
        total = 0.0
        for side in ("Left", "Right"):
            names = ["Hips"] + [side + j for j in ("UpLeg", "Leg", "Foot", "ToeBase")]
            total += sum(np.linalg.norm(p[s.index(n)] - p[s.index(m)]) for m, n in zip(names[:-1], names[1:]))
        return total / 2

    return chain(b) / chain(a)


def _angle_by_stack(a, b):
    return torch.stack([(a - b).norm(dim=-1), (a + b).norm(dim=-1)]).min(dim=0).values.mean()


def _minima_loop(m):
    r, c = m.shape
    out = np.zeros((r, c), bool)
    for i in range(r):
        for j in range(c):
            block = m[max(i - 1, 0) : i + 2, max(j - 1, 0) : j + 2]
            out[i, j] = m[i, j] <= block.min()
    return out


def _distance_by_alignment(pos_a, pos_b):
    """Another way: the optimal turn and shift of every pair, then the weighted squared distance."""
    from motionlab.core import quat
    from motionlab.motion_graphs import distance

    fa, fb = distance.cloud_features(pos_a), distance.cloud_features(pos_b)
    h = distance.DEFAULT_WINDOW // 2
    clouds = [
        p[np.clip(np.arange(len(p))[:, None] + np.arange(-h, h + 1), 0, len(p) - 1)].reshape(len(p), -1, 3)
        for p in (pos_a, pos_b)
    ]
    i, j = np.meshgrid(np.arange(len(pos_a)), np.arange(len(pos_b)), indexing="ij")
    theta, shift = distance.alignment(fa, fb, i, j)
    moved = quat.rotate(quat.from_yaw(theta)[..., None, :], clouds[1][j]) + shift[..., None, :]
    return np.sum(fa.weights * np.sum((clouds[0][i] - moved) ** 2, axis=-1), axis=-1)


ALTERNATIVES = [
    ("conj", _conj_concat),
    ("slerp", _slerp_by_power),
    ("hand_height", _hand_height_by_offsets),
    ("heading", _heading_in_0_2pi),
    ("window_count", _window_count_ceil),
    ("pose_error", _pose_error_loop),
    ("joint_speed", _speed_forward),
    ("joint_speed", _speed_backward),
    ("recon_loss", _recon_numpy_style),
    ("combine", _combine_by_matrix),
    ("rotations", _rotations_functional),
    ("foot_loss", _foot_relu),
    ("root_scale", _root_from_rest_positions),
    ("angle_loss", _angle_by_stack),
    ("local_minima", _minima_loop),
    ("distance_matrix", _distance_by_alignment),
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


# ----------------------------------------------------------------------------- the notebooks use them
def test_every_named_exercise_is_checked_in_a_notebook_and_no_cell_expects_an_error():
    """The notebooks check each exercise by name and run top to bottom: no cell is allowed to raise."""
    notebooks = {p.stem: p.read_text(encoding="utf-8") for p in NOTEBOOKS.glob("*.ipynb")}
    for name in exercises.EXERCISES:
        assert any(f"exercises.{name}.check(" in text for text in notebooks.values()), f"{name} is checked nowhere"
    for stem, text in notebooks.items():
        assert "NBVAL_RAISES_EXCEPTION" not in text, f"{stem}: a cell is expected to raise"
        assert "exercises.check(" not in text, f"{stem}: an ad-hoc check; use a named exercise with a key"


# ----------------------------------------------------------------------------- experiments
# Each experiment exercise (a Question) is checked on small synthetic inputs: the key's number must
# pass, a rounded form of it too (what a student types), the typical wrong experiments must fail with
# their hint, and `...` must say "not answered yet".


@pytest.fixture(scope="module")
def retarget_pair():
    from motionlab import retargeting, synthetic

    source = synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=60, seed=7)
    target = synthetic.random_character(5, name="short-legged B", legs=(0.75, 0.8))
    return source, target, retargeting.load_default()


@pytest.fixture(scope="module")
def behaviour_clips():
    from motionlab import synthetic

    return {b: synthetic.generate(b, None, 120, 30.0, seed=k) for k, b in enumerate(("run", "walk", "idle", "squat"))}


@pytest.fixture(scope="module")
def style_takes():
    from motionlab import synthetic
    from motionlab.motion_graphs import clips

    styles = clips.SYNTHETIC_STYLES["walk"]
    return [
        synthetic.generate("walk", None, 150, 30.0, styles[s] or None, seed).copy(name=f"walk_{s}_{seed}")
        for s in ("normal", "happy", "sad")
        for seed in (1, 2, 3)
    ]


def test_every_experiment_is_listed():
    assert set(exercises.EXPERIMENTS) == {
        "foot_weight",
        "held_out_q",
        "walk_spacing",
        "smallest_gap",
        "vanishing_threshold",
    }


@pytest.mark.parametrize("name", ["foot_weight", "held_out_q", "walk_spacing", "smallest_gap", "vanishing_threshold"])
def test_an_unanswered_experiment_says_so(name):
    result = exercises.EXPERIMENTS[name].check(..., None)
    assert not result.passed and not result.attempted and "not answered yet" in result.message


def test_foot_weight_experiment(retarget_pair):
    q = exercises.foot_weight
    answer = K03.my_foot_weight_experiment(*retarget_pair)
    assert q.check(answer, *retarget_pair).passed
    assert q.check(round(float(answer), 2), *retarget_pair).passed  # typed with two decimals
    # wrong: the paper's weight left at 0.5; motionlab's set-up; radians
    from motionlab import retargeting
    from motionlab.core import preprocess
    from motionlab.retargeting import plots
    from motionlab.retargeting.solver import SolverConfig

    source, target, ckpt = retarget_pair
    src = preprocess.prepare(source, ckpt.fps)

    def angle(cfg):
        run = retargeting.retarget(source, target, ckpt, "full", cfg)
        return plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean()

    wrong = {  # value -> a phrase of the hint it must get
        "0.5": angle(SolverConfig(init="encoder", lambda_contact=0.0, lr=0.1)),
        "motionlab's set-up": angle(SolverConfig(lambda_foot=5.0)),
        "radians": np.radians(answer),
    }

    def close(a, b):
        return abs(a - b) <= q.atol + q.rtol * abs(b)

    for phrase, value in wrong.items():
        if close(value, answer):
            continue  # on this small case the wrong experiment happens to give the right number
        result = q.check(value, *retarget_pair)
        assert not result.passed and result.attempted and result.hint is not None, result.message
        if not any(close(value, other) for p, other in wrong.items() if p != phrase):
            assert phrase in result.hint, (phrase, result.message)
    assert not q.check(answer + 10.0, *retarget_pair).passed


def test_held_out_q_experiment(behaviour_clips):
    q = exercises.held_out_q
    answer = K06.my_held_out_q(behaviour_clips)
    assert answer in exercises.interpolation.Q_CHOICES
    assert q.check(answer, behaviour_clips).passed
    assert q.check(float(answer), behaviour_clips).passed
    # alternative: standardised with all frames' statistics (also accepted)
    alt = exercises.interpolation._best_q(behaviour_clips, stats="all")
    assert q.check(alt, behaviour_clips).passed
    # wrong: every second frame held out (interleaved)
    from motionlab.interpolation import features
    from motionlab.interpolation.ppca import PPCA

    every = np.concatenate([features.pose_features(c) for c in behaviour_clips.values()])
    train, test = every[::2], every[1::2]
    mean, std = train.mean(0), np.maximum(train.std(0), 1e-6)
    interleaved = max(
        (1, 2, 4, 8, 16, 32), key=lambda k: PPCA(k).fit((train - mean) / std).log_likelihood((test - mean) / std)
    )
    if interleaved != answer:
        result = q.check(interleaved, behaviour_clips)
        assert not result.passed and "interleave" in result.hint
    result = q.check(32 if answer != 32 else 1, behaviour_clips)
    assert not result.passed and result.attempted
    assert not q.check("two", behaviour_clips).passed


@pytest.fixture(scope="module")
def walk_120():
    from motionlab import synthetic

    return synthetic.generate("walk", None, 360, 120.0, seed=3)  # notebook 06's walk without real data


def _walk_error(walk, every, curve="linear", degrees=True):
    """The walk experiment written independently of the key: frames 5, 5+every, … kept, the rest filled."""
    from motionlab.core import quat
    from motionlab.interpolation import demo, gaps

    kept = np.arange(5, walk.num_frames, every)
    span = walk[5 : kept[-1] + 1]
    holed, _ = gaps.insert_missing(span[kept - 5], [(i, every - 1) for i in range(len(kept) - 1)])
    filled, _ = gaps.fill(holed, method="slerp", root="hermite", curve=curve)
    lost = np.setdiff1d(np.arange(span.num_frames), kept - 5)
    idx = [walk.skeleton.index(n) for n in demo.WALK_JOINTS]
    e = quat.angle_between(filled.local_rot[lost][:, idx], span.local_rot[lost][:, idx]).mean()
    return np.degrees(e) if degrees else e


def test_walk_spacing_experiment(walk_120):
    q = exercises.walk_spacing
    answer = K06.my_walk_spacing(walk_120)
    assert q.check(answer, walk_120).passed
    assert q.check(round(float(answer), 1), walk_120).passed  # typed with one decimal
    assert q.check(_walk_error(walk_120, 60, curve="ease"), walk_120).passed  # an eased α(k): accepted
    result = q.check(_walk_error(walk_120, 30), walk_120)  # the notebook's spacing left at 30
    assert not result.passed and "every = 60" in result.hint
    result = q.check(_walk_error(walk_120, 60, degrees=False), walk_120)
    assert not result.passed and "radians" in result.hint
    assert not q.check(answer * 2, walk_120).passed


def test_smallest_gap_experiment():
    from motionlab.interpolation import demo

    walk, _ = demo.walk_clip()  # the notebook's walk (real or synthetic)
    q = exercises.smallest_gap
    answer = K06.my_smallest_gap(walk)
    assert answer > 1
    assert q.check(answer, walk).passed
    assert q.check(float(answer), walk).passed
    result = q.check(1, walk)  # "any missing frame is found"
    assert not result.passed and "D ≈ 2" in result.hint
    result = q.check(answer - 1, walk)
    assert not result.passed and result.hint is not None
    assert not q.check(answer + 3, walk).passed


def test_vanishing_threshold_experiment(style_takes):
    q = exercises.vanishing_threshold
    lost = [s for s in ("normal", "happy", "sad") if exercises.motion_graphs.style_frames_kept(style_takes, s, 3) == 0]
    assert lost, "a style is lost by the pruned standard graph at 3 cm"
    style = lost[0]
    answer = K05.my_vanishing_threshold(style_takes, style)
    assert answer > 3
    assert q.check(answer, style_takes, style).passed
    assert q.check(float(answer), style_takes, style).passed
    result = q.check(3, style_takes, style)  # the unpruned graph keeps the style at 3 cm already
    assert not result.passed and "prune" in result.hint
    result = q.check(answer / 100, style_takes, style)
    assert not result.passed and "centimetres" in result.hint
    assert not q.check(answer + 100, style_takes, style).passed
