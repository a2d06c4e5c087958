"""Every exercise check of notebooks 00 to 07 against the instructor's key (must pass),
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
from tests.conftest import require_data

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
K07 = _key("key_07_expanding_a_database")
K00B = _key("key_00b_bvh_file_format")

# (exercise, the key's solution) for every exercise of the notebooks
SOLUTIONS = {
    "hand_height": K00.left_hand_height_with_arm_raised,
    "window_count": K01.my_window_count,
    "joint_speed": K04.my_joint_speed,
    "contact_loss": K03.my_contact_loss,
    "local_minima": K05.my_local_minima,
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
    result = exercises.hand_height.check(lambda skeleton: skeleton.offsets[99])
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


def _speed_per_frame(motion):
    return np.linalg.norm(np.gradient(motion.global_positions(), axis=0), axis=-1)


def _speed_short(motion):
    return np.linalg.norm(np.diff(motion.global_positions(), axis=0), axis=-1) * motion.fps


# notebooks 03, 05, 06
def _contact_per_frame(feet, planted, fps):
    both = planted[..., 1:, :] & planted[..., :-1, :]
    return torch.diff(feet, dim=-3).norm(dim=-1)[both].mean() if both.any() else torch.zeros(())


def _contact_start_frame_only(feet, planted, fps):
    step, start = torch.diff(feet, dim=-3).norm(dim=-1), planted[..., :-1, :]
    return fps * step[start].mean() if start.any() else torch.zeros(())


def _contact_horizontal(feet, planted, fps):
    both = planted[..., 1:, :] & planted[..., :-1, :]
    step = torch.diff(feet[..., [0, 2]], dim=-3).norm(dim=-1)
    return fps * step[both].mean() if both.any() else torch.zeros(())


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


WRONG = [
    ("hand_height", _wrong_hand(angle=-np.pi / 2), "below the shoulder"),
    ("hand_height", _wrong_hand(angle=90), "radians"),
    ("hand_height", _wrong_hand(joint="LeftShoulder"), "collarbone"),
    ("hand_height", _wrong_hand(coord=0), "up axis"),
    ("window_count", lambda n, window=120, stride=30: (n - window) // stride + 1, "shorter than one window"),
    ("window_count", lambda n, window=120, stride=30: max(1, (n - window) // stride + 1), "moved back"),
    ("joint_speed", _speed_per_frame, "metres per second"),
    ("joint_speed", _speed_short, "one frame fewer"),
    ("joint_speed", lambda m: np.gradient(m.global_positions(), axis=0) * m.fps, "velocity"),
    ("contact_loss", _contact_per_frame, "m/s"),
    ("contact_loss", _contact_start_frame_only, "both"),
    ("contact_loss", _contact_horizontal, "3-D step"),
    ("local_minima", _minima_strict, "<="),
    ("local_minima", _minima_four, "diagonal"),
    ("local_minima", _minima_roll, "np.roll"),
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
def _hand_height_by_offsets(skeleton):
    """Raised straight up, the arm adds its bones' lengths to the shoulder joint's height."""
    rest = skeleton.rest_positions()
    lengths = sum(np.linalg.norm(skeleton.offsets[skeleton.index(n)]) for n in ("LeftForeArm", "LeftHand"))
    return rest[skeleton.index("LeftArm"), 1] + lengths


def _window_count_ceil(n, window=120, stride=30):
    return 1 if n <= window else math.ceil((n - window) / stride) + 1


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


def _contact_numpy(feet, planted, fps):
    """Frame pair by frame pair, in numpy."""
    f, p = feet.numpy(), planted.numpy()
    speeds = [
        fps * np.linalg.norm(f[..., t + 1, j, :] - f[..., t, j, :], axis=-1)[p[..., t, j] & p[..., t + 1, j]]
        for t in range(f.shape[-3] - 1)
        for j in range(4)
    ]
    speeds = np.concatenate(speeds)
    return float(speeds.mean()) if speeds.size else 0.0


def _minima_loop(m):
    r, c = m.shape
    out = np.zeros((r, c), bool)
    for i in range(r):
        for j in range(c):
            block = m[max(i - 1, 0) : i + 2, max(j - 1, 0) : j + 2]
            out[i, j] = m[i, j] <= block.min()
    return out


ALTERNATIVES = [
    ("hand_height", _hand_height_by_offsets),
    ("window_count", _window_count_ceil),
    ("joint_speed", _speed_forward),
    ("joint_speed", _speed_backward),
    ("contact_loss", _contact_numpy),
    ("local_minima", _minima_loop),
]


@pytest.mark.parametrize(("name", "answer"), ALTERNATIVES, ids=[a[1].__name__ for a in ALTERNATIVES])
def test_an_alternative_correct_answer_passes(name, answer):
    result = exercises.EXERCISES[name].check(answer)
    assert result.passed, result.message


def test_the_forward_difference_is_accepted_where_the_old_check_rejected_it():
    result = exercises.joint_speed.check(_speed_forward)
    assert result.passed and "accepted variant" in result.message


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


EXPERIMENT_NAMES = {"nlerp_turn", "euler_order", "reader_order", "hips_heading", "shorter_legs"}  # 00, 00b, 01, 04
EXPERIMENT_NAMES |= {"q_delta_legs", "no_correction", "arm_length"}  # notebooks 02, 07
EXPERIMENT_NAMES |= {"encoder_start", "contact_weight", "foot_weight", "theta_directions"}  # notebook 03
EXPERIMENT_NAMES |= {"vanishing_threshold", "style_change", "transition_clip"}  # notebook 05
EXPERIMENT_NAMES |= {"held_out_q", "walk_spacing", "smallest_gap", "key_frames"}  # notebook 06


def test_every_experiment_is_listed():
    assert set(exercises.EXPERIMENTS) == EXPERIMENT_NAMES


def test_every_experiment_is_checked_in_a_notebook():
    notebooks = "".join(p.read_text(encoding="utf-8") for p in NOTEBOOKS.glob("*.ipynb"))
    for name in exercises.EXPERIMENTS:
        assert f"exercises.{name}.check(" in notebooks, f"{name} is checked nowhere"


@pytest.mark.parametrize("name", sorted(EXPERIMENT_NAMES))
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
    src = preprocess.prepare(source, ckpt.fps, stand=True)

    def angle(cfg):
        run = retargeting.retarget(source, target, ckpt, "full", cfg)
        return plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean()

    wrong = {  # value -> a phrase of the hint it must get
        "0.5": angle(SolverConfig(init="encoder", lr=0.1, weights={"contact": 0.0, "clearance": 0.0})),
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


@pytest.fixture(scope="module")
def running_pair():
    """A run onto short legs: unlike the walk, the iteration runs and the contact weight matters."""
    from motionlab import retargeting, synthetic

    source = synthetic.generate("run", humanoid.canonical_skeleton(), num_frames=60, seed=7)
    target = synthetic.random_character(5, name="short-legged B", legs=(0.75, 0.8))
    return source, target, retargeting.load_default()


def _full_method_numbers(source, target, ckpt, **settings):
    """(mean angle to A °, planted-foot slide cm/s, skating cm/s, steps) of the full method, as a student measures them."""
    from motionlab import retargeting
    from motionlab.core import metrics, preprocess
    from motionlab.retargeting import pipeline, plots
    from motionlab.retargeting.solver import SolverConfig

    run = retargeting.retarget(source, target, ckpt, "full", SolverConfig(**settings))
    src = preprocess.prepare(source, ckpt.fps, stand=True)
    feet = [humanoid.JOINTS.index(n) for n in humanoid.FEET]
    angle = float(plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean())
    slide = 100 * float(metrics.planted_slide(run.positions, feet, pipeline.source_contacts(src), ckpt.fps))
    return angle, slide, 100 * float(metrics.foot_skating(run.positions, feet, ckpt.fps)), run.steps


def _check_wrong(q, answer, wrong, inputs):
    """Every wrong value fails with a hint, and with its own hint where no other wrong value coincides."""

    def close(a, b):
        return abs(a - b) <= q.atol + q.rtol * abs(b)

    for phrase, value in wrong.items():
        if close(value, answer):
            continue  # on this small case the wrong experiment happens to give the right number
        result = q.check(value, *inputs)
        assert not result.passed and result.attempted and result.hint is not None, (phrase, result.message)
        if not any(close(value, other) for p, other in wrong.items() if p != phrase):
            assert phrase in result.hint, (phrase, result.message)


@pytest.mark.slow
def test_encoder_start_experiment(running_pair):
    q = exercises.encoder_start
    answer = K03.my_encoder_start_experiment(*running_pair)
    assert q.check(answer, *running_pair).passed
    angle, _, _, steps = _full_method_numbers(*running_pair, init="encoder")
    assert q.check(angle, *running_pair).passed  # unrounded
    default_angle = _full_method_numbers(*running_pair)[0]
    assert angle > default_angle + 0.1, "without the Gauss-Newton start the result ends further from A's angles"
    wrong = {
        "lr=0.1": _full_method_numbers(*running_pair, init="encoder", lr=0.1)[0],
        "paper-like set-up": _full_method_numbers(*running_pair, **exercises.retargeting.PAPER)[0],
        "default run": default_angle,
        "radians": np.radians(angle),
    }
    _check_wrong(q, answer, wrong, running_pair)
    assert not q.check(answer + 5.0, *running_pair).passed


@pytest.mark.slow
def test_contact_weight_experiment(running_pair):
    q = exercises.contact_weight
    answer = K03.my_contact_weight_experiment(*running_pair)
    assert q.check(answer, *running_pair).passed
    _, slide, skating, _ = _full_method_numbers(*running_pair, lambda_contact=0.1)
    assert q.check(slide, *running_pair).passed  # unrounded
    no_contact, default = (_full_method_numbers(*running_pair, lambda_contact=w)[1] for w in (0.0, 0.5))
    assert default < slide < no_contact, "a fifth of the weight removes part of the sliding, the default more"
    wrong = {"λ_contact = 0.5": default, "λ_contact = 0)": no_contact, "skating": skating, "m/s": slide / 100}
    _check_wrong(q, answer, wrong, running_pair)
    assert not q.check(answer + 1.0, *running_pair).passed


@pytest.fixture(scope="module")
def decoded_clip():
    """The shipped network and a synthetic run on its own character (notebook 02's held-out clip, synthetic)."""
    from motionlab import retargeting, synthetic

    ckpt = retargeting.load_default()
    return ckpt, synthetic.generate("run", ckpt.skeleton, num_frames=60, seed=123)


def _decode_as_a_student(ckpt, clip, legs):
    """(true positions, decoded on A, decoded with legs × ``legs``, A's offsets), written from section 6's cell."""
    from motionlab.core import preprocess
    from motionlab.retargeting.features import clip_features

    prepared = preprocess.prepare(clip, ckpt.fps)
    feats = clip_features(prepared)
    x = torch.as_tensor(ckpt.stats.normalize(feats.x), dtype=ckpt.dtype)[None]
    own = torch.tensor(prepared.skeleton.offsets, dtype=ckpt.dtype)
    other = torch.tensor(humanoid.scale_bones(prepared.skeleton, legs=legs).offsets, dtype=ckpt.dtype)
    with torch.no_grad():
        phi = ckpt.model.encode(x)
        return feats.positions, ckpt.model.decode(phi, own), ckpt.model.decode(phi, other), own


def test_q_delta_legs_experiment(decoded_clip):
    from motionlab.core import quat

    q = exercises.q_delta_legs
    answer = K02.my_q_delta_legs_experiment(*decoded_clip)
    assert q.check(answer, *decoded_clip).passed

    def per_joint(legs, identity=False):  # degrees, mean over frames, with numpy's quaternions (the alternative)
        _, on_a, on_b, _ = _decode_as_a_student(*decoded_clip, legs)
        a = on_a.q_delta[0].numpy()
        b = np.broadcast_to(quat.IDENTITY, a.shape) if identity else on_b.q_delta[0].numpy()
        return np.degrees(quat.angle_between(a, b)).mean(axis=0)

    assert q.check(per_joint(0.7).max(), *decoded_clip).passed
    wrong = {
        "1.3": per_joint(1.3).max(),
        "mean over the joints": per_joint(0.7).mean(),
        "size of q_Δ": per_joint(0.7, identity=True).max(),
        "radians": np.radians(per_joint(0.7).max()),
    }
    _check_wrong(q, answer, wrong, decoded_clip)
    assert not q.check(answer + 1.0, *decoded_clip).passed


def test_no_correction_experiment(decoded_clip):
    q = exercises.no_correction
    answer = K02.my_no_correction_experiment(*decoded_clip)
    assert q.check(answer, *decoded_clip).passed
    truth, on_a, _, own = _decode_as_a_student(*decoded_clip, 0.7)

    def error_m(local_rot):
        return float(np.linalg.norm(ckpt_fk(local_rot, own) - truth, axis=-1).mean())

    def ckpt_fk(local_rot, offsets):
        return decoded_clip[0].model.forward_kinematics(local_rot, offsets)[0].numpy()

    assert q.check(100 * error_m(on_a.q), *decoded_clip).passed  # unrounded
    with_correction = 100 * error_m(on_a.local_rot)
    assert 100 * error_m(on_a.q) > with_correction, "dropping q_Δ makes A's own reconstruction worse"
    wrong = {"with the correction": with_correction, "metres": error_m(on_a.q)}
    _check_wrong(q, answer, wrong, decoded_clip)
    assert not q.check(answer + 1.0, *decoded_clip).passed


@pytest.fixture(scope="module")
def squat_file(tmp_path_factory):
    """A synthetic squat saved as BVH (notebook 07 checks a clip by its path), the shipped network, a short solve."""
    from motionlab import retargeting, synthetic
    from motionlab.core import bvh
    from motionlab.retargeting.solver import SolverConfig

    clip = synthetic.generate("squat", humanoid.canonical_skeleton(), num_frames=60, seed=3)
    path = bvh.save(tmp_path_factory.mktemp("clips") / "squat.bvh", clip)
    return str(path), retargeting.load_default("cpu"), SolverConfig(max_steps=5)


def test_arm_length_experiment(squat_file):
    from motionlab.core import bvh
    from motionlab.retargeting.pipeline import retarget

    q = exercises.arm_length
    answer = K07.my_arm_length_experiment(*squat_file)
    assert q.check(answer, *squat_file).passed
    clip_path, ckpt, cfg = squat_file

    def result(arms):  # as a student runs it
        return retarget(
            bvh.load(clip_path), humanoid.scale_bones(humanoid.canonical_skeleton(), arms=arms), ckpt, solver=cfg
        )

    arms_13 = result(1.3)
    assert q.check(arms_13.plausibility.lowest, *squat_file).passed  # unrounded
    lowest_m = float(arms_13.positions[..., 1].min())
    assert abs(arms_13.plausibility.lowest - lowest_m / humanoid.leg_length(arms_13.motion.skeleton)) < 1e-6
    wrong = {
        "1.35": result(1.35).plausibility.lowest,
        "source_lowest": arms_13.plausibility.source_lowest,
        "centimetres": 100 * lowest_m,
        "metres": lowest_m,
    }
    _check_wrong(q, answer, wrong, squat_file)
    assert not q.check(answer + 0.5, *squat_file).passed


def test_held_out_q_experiment(behaviour_clips):
    q = exercises.held_out_q
    answer = K06.my_held_out_q(behaviour_clips)
    assert answer in exercises.interpolation.Q_CHOICES
    assert q.check(answer, behaviour_clips).passed
    assert q.check(float(answer), behaviour_clips).passed
    # wrong: standardised with all frames' statistics (the held-out frames leak into the model)
    alt = exercises.interpolation._best_q(behaviour_clips, stats="all")
    if alt != answer:
        res = q.check(alt, behaviour_clips)
        assert not res.passed and "training frames' alone" in res.hint
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


def _walk_error(walk, every, curve="linear", degrees=True, per_joint=False):
    """The walk experiment written independently of the key: frames 5, 5+every, … kept, the rest filled."""
    from motionlab.core import quat
    from motionlab.interpolation import demo, gaps

    kept = np.arange(5, walk.num_frames, every)
    span = walk[5 : kept[-1] + 1]
    holed, _ = gaps.insert_missing(span[kept - 5], [(i, every - 1) for i in range(len(kept) - 1)])
    filled, _ = gaps.fill(holed, method="slerp", root="hermite", curve=curve)
    lost = np.setdiff1d(np.arange(span.num_frames), kept - 5)
    idx = [walk.skeleton.index(n) for n in demo.WALK_JOINTS]
    e = quat.angle_between(filled.local_rot[lost][:, idx], span.local_rot[lost][:, idx]).mean(axis=0)
    e = e if per_joint else e.mean()
    return np.degrees(e) if degrees else e


@pytest.mark.slow  # a spacing sweep over a whole walk: over 10 s
def test_walk_spacing_experiment(walk_120):
    q = exercises.walk_spacing
    answer = K06.my_walk_spacing(walk_120)
    per_joint = {every: _walk_error(walk_120, every, per_joint=True) for every in (10, 15, 20, 30, 45, 60)}
    assert answer in per_joint and per_joint[answer].max() < 6.0  # every joint under 6° at the answer
    assert all(per_joint[e].max() >= 6.0 for e in per_joint if e > answer)
    assert q.check(answer, walk_120).passed
    assert q.check(float(answer), walk_120).passed  # typed as a float
    by_mean = max(e for e in per_joint if per_joint[e].mean() < 6.0)  # the mean over joints under 6°
    if by_mean != answer:
        result = q.check(by_mean, walk_120)
        assert not result.passed and "every joint" in result.hint
    first_failing = min(e for e in per_joint if per_joint[e].max() >= 6.0)
    result = q.check(first_failing, walk_120)
    assert not result.passed and "largest that stays under" in result.hint
    assert not q.check(answer + 1, walk_120).passed


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


# notebooks 00, 01 and 04: each wrong experiment is written as a student would run it


def _nlerp_ratio(angle_radians, steps=50):
    q1 = quat.from_axis_angle([0, 1, 0], angle_radians)
    t = np.linspace(0, 1, steps)
    angles = np.degrees(
        quat.angle_between(quat.IDENTITY, quat.normalize((1 - t)[:, None] * quat.IDENTITY + t[:, None] * q1))
    )
    return np.diff(angles).max() / np.diff(angles).min()


def test_nlerp_turn_experiment():
    q = exercises.nlerp_turn
    answer = K00.my_nlerp_turn_experiment()
    assert _nlerp_ratio(np.radians(answer)) <= 1.10 < _nlerp_ratio(np.radians(answer + 1))
    assert 1 < answer < 170  # nlerp cannot take the page's half turn at nearly constant speed
    assert q.check(answer).passed and q.check(float(answer)).passed
    wrong = {  # the first turn above the bound, radians, the ratio of a 90° turn, slerp's "every turn"
        "first turn whose ratio is above": answer + 1,
        "radians": round(float(np.radians(answer)), 2),
        "ratio": round(_nlerp_ratio(np.pi / 2), 2),
        "slerp": 179,
    }
    for phrase, value in wrong.items():
        result = q.check(value)
        assert not result.passed and result.attempted and phrase in result.hint, result.message
    assert not q.check(answer - 5).passed


def test_euler_order_experiment():
    q = exercises.euler_order
    answer = K00.my_euler_order_experiment()
    assert q.check(answer).passed
    angles = np.radians([30.0, -20.0, 45.0])
    exact = np.degrees(quat.angle_between(quat.from_euler(angles, "zxy"), quat.from_euler(angles, "xyz")))
    assert q.check(round(float(exact), 2)).passed
    # the alternative: the same gap from the rotation matrices' relative rotation
    R = quat.to_matrix(quat.from_euler(angles, "zxy")).T @ quat.to_matrix(quat.from_euler(angles, "xyz"))
    assert q.check(np.degrees(np.arccos((np.trace(R) - 1) / 2))).passed
    zyx = np.degrees(quat.angle_between(quat.from_euler(angles, "zxy"), quat.from_euler(angles, "zyx")))
    typed = quat.angle_between(quat.from_euler([30.0, -20.0, 45.0], "zxy"), quat.from_euler([30.0, -20.0, 45.0], "xyz"))
    wrong = {"radians": np.radians(exact), "np.radians": np.degrees(typed), "itself": 0.0, "'zyx'": zyx}
    for phrase, value in wrong.items():
        result = q.check(value)
        assert not result.passed and result.attempted and phrase in result.hint, result.message
    assert not q.check(answer + 5).passed


@pytest.fixture(scope="module")
def run_positions():
    from motionlab import synthetic

    return synthetic.generate("run", humanoid.canonical_skeleton(), num_frames=120, fps=60.0, seed=1).global_positions()


def _heading_of(world, left, right, flip=False):
    ix = humanoid.JOINTS.index
    across = world[:, ix(left)] - world[:, ix(right)]
    f = np.cross([0, 1, 0], across) if flip else np.cross(across, [0, 1, 0])
    return np.arctan2(f[:, 0], f[:, 2])


def test_hips_heading_experiment(run_positions):
    from motionlab.core import preprocess

    q, world = exercises.hips_heading, run_positions
    answer = K01.my_hips_heading_experiment(world)
    assert answer > 1.0  # the hips alone swing away from the heading while running
    assert q.check(answer, world).passed
    psi = preprocess.heading(world)

    def gap(psi_other, reduce=np.max):
        return float(np.degrees(reduce(np.abs(np.angle(np.exp(1j * (psi_other - psi)))))))

    assert q.check(round(gap(_heading_of(world, "LeftUpLeg", "RightUpLeg")), 2), world).passed
    wrong = {
        "radians": np.radians(answer),
        "shoulders": gap(_heading_of(world, "LeftArm", "RightArm")),
        "mean": gap(_heading_of(world, "LeftUpLeg", "RightUpLeg"), np.mean),
        "half a turn": gap(_heading_of(world, "LeftUpLeg", "RightUpLeg", flip=True)),
    }
    for phrase, value in wrong.items():
        result = q.check(value, world)
        assert not result.passed and result.attempted and phrase in result.hint, (phrase, result.message)
    assert not q.check(answer + 3, world).passed


def test_shorter_legs_experiment():
    from motionlab import synthetic
    from motionlab.viz import compare, proportions

    skeleton = humanoid.canonical_skeleton()
    walk = synthetic.generate("walk", skeleton, num_frames=60, fps=30.0, seed=0)
    q = exercises.shorter_legs
    answer = K04.my_shorter_legs_experiment(walk)
    assert q.check(answer, walk).passed

    def error(legs):
        copied = proportions.copy_rotation_solver(walk)(humanoid.scale_bones(skeleton, legs=legs))
        return float(np.nanmean(compare.joint_errors(copied, walk, relative_to_root=True)))

    exact = error(0.8) / error(1.25)
    assert 0 < exact < 1.5 and abs(answer - exact) < 0.006  # a change of 0.2 against one of 0.25
    assert q.check(exact, walk).passed and q.check(round(exact, 3), walk).passed  # more decimals: also right
    wrong = {
        "alone": error(0.8),
        "inverse": round(1 / exact, 2),
    }
    for phrase, value in wrong.items():
        result = q.check(value, walk)
        assert not result.passed and result.attempted and phrase in result.hint, (phrase, result.message)
    assert not q.check(answer * 1.5, walk).passed


def test_style_change_experiment(style_takes):
    q = exercises.style_change
    request = [("walk", "normal", 150), ("walk", "happy", 150), ("walk", "sad", 150)]
    answer = K05.my_style_change(style_takes, request)
    assert answer in exercises.motion_graphs.DWELLS
    assert q.check(answer, style_takes, request).passed
    assert q.check(float(answer), style_takes, request).passed
    frames = exercises.motion_graphs.style_change_frames(style_takes, request, answer)
    assert frames >= exercises.motion_graphs.gait_cycle_frames(style_takes, "normal")
    if frames != answer:
        result = q.check(frames, style_takes, request)
        assert not result.passed and "dwell" in result.hint
    result = q.check(None, style_takes, request)
    assert not result.passed and not result.attempted and "not answered yet" in result.message
    assert not q.check(answer + 100, style_takes, request).passed


# new experiments of issue 42: 00b reader order, 03 θ, 05 transition clip, 06 key frames


def test_reader_order_experiment(tmp_path):
    from motionlab import synthetic
    from motionlab.core import bvh

    walk = synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=30, fps=30, seed=0)
    path = tmp_path / "walk.bvh"
    bvh.save(path, walk)  # 00b's file without the course data
    channels = bvh.load(path).skeleton.channels
    q = exercises.reader_order
    answer = K00B.my_reader_order_experiment(path, channels)
    assert answer > 1.0  # reversing the order changes a real pose
    assert q.check(answer, path).passed
    # a different, independently written reading: Euler angles of bvh.load's rotations, reversed order
    motion = bvh.load(path)
    gaps = []
    for j, chans in enumerate(channels):
        order = "".join(c[0].lower() for c in chans if c.endswith("rotation"))
        angles = quat.to_euler(motion.local_rot[0, j], order)
        gaps.append(quat.angle_between(motion.local_rot[0, j], quat.from_euler(angles[::-1], order[::-1])))
    assert q.check(float(np.degrees(max(gaps))), path).passed
    wrong = {"radians": np.radians(answer), "mean over the joints": np.degrees(np.mean(gaps)), "reverse it": 0.0}
    for phrase, value in wrong.items():
        result = q.check(value, path)
        assert not result.passed and result.attempted and phrase in result.hint, (phrase, result.message)


def test_theta_directions_experiment(retarget_pair):
    from motionlab import retargeting
    from motionlab.core import preprocess
    from motionlab.retargeting import plots
    from motionlab.retargeting.solver import SolverConfig

    q = exercises.theta_directions
    answer = K03.my_theta_directions_experiment(*retarget_pair)
    assert q.check(answer, *retarget_pair).passed

    def angle(cfg):
        run = retargeting.retarget(*retarget_pair[:2], retarget_pair[2], "full", cfg)
        src = preprocess.prepare(retarget_pair[0], retarget_pair[2].fps)
        return float(plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean())

    assert q.check(angle(SolverConfig(theta="directions")), *retarget_pair).passed  # unrounded: also right
    default = angle(SolverConfig())
    assert abs(default - answer) > 0.05  # bone directions move the rotations away from A's
    result = q.check(default, *retarget_pair)
    assert not result.passed and "theta='directions'" in result.hint
    result = q.check(float(np.radians(answer)), *retarget_pair)
    assert not result.passed and "radians" in result.hint


def test_transition_clip_experiment():
    from motionlab.motion_graphs import clips

    library = clips.synthetic_library(seconds=4.0)  # notebook 05's library without the course data
    request, left_out = "idle:normal:60,walk:normal:120", "idle_normal_to_walk_normal"
    q = exercises.transition_clip
    answer = K05.my_transition_clip(library, request, left_out)
    assert answer in exercises.motion_graphs.LINK_THRESHOLDS_CM
    assert q.check(answer, library, request, left_out).passed
    assert q.check(float(answer), library, request, left_out).passed
    with_clip = exercises.motion_graphs.link_met(library, request, None, 3)
    assert with_clip and answer > 3  # the recorded clip joins at 3 cm; stance links need a looser threshold
    result = q.check(3, library, request, left_out)
    assert not result.passed and "still holds the recorded transition clip" in result.hint
    earlier = max(cm for cm in exercises.motion_graphs.LINK_THRESHOLDS_CM if cm < answer)
    result = q.check(earlier, library, request, left_out)
    assert not result.passed and "still fails" in result.hint
    result = q.check(answer / 100, library, request, left_out)
    assert not result.passed and "centimetres" in result.hint


def test_key_frames_experiment(behaviour_clips):
    from motionlab.interpolation import features
    from motionlab.interpolation.action_graph import ActionGraph

    clips = dict(behaviour_clips, stand=behaviour_clips["idle"])  # notebook 06 names the standing node "stand"
    q = exercises.key_frames
    answer = K06.my_key_frames(clips)
    assert answer >= 1.0  # searching key frames only can never find a closer pair than all frames
    assert q.check(answer, clips).passed
    graph = ActionGraph()
    for name in ("walk", "stand"):
        graph.add_node(name, clips[name], num_keys=5)
    every = features.distance_matrix(features.pose_features(clips["walk"]), features.pose_features(clips["stand"]))
    exact = graph.best_transition("walk", "stand")[2] / every.min()
    assert q.check(float(exact), clips).passed
    result = q.check(round(1 / exact, 3), clips)
    assert not result.passed and "inverse" in result.hint
    assert not q.check(exact + 0.5, clips).passed


@pytest.mark.slow
def test_the_angle_checks_measure_as_notebook_03_does():
    """03's checks compare with A on its standing rest pose (``src`` of section 1, ``stand=True``):
    on Aj, whose rest knees bend, the angle measured on the raw rest differs, and a student who
    measured as section 5 does was told wrong."""
    from motionlab import data, retargeting
    from motionlab.core import bvh, preprocess
    from motionlab.interpolation import demo
    from motionlab.retargeting import plots
    from motionlab.retargeting.solver import SolverConfig

    require_data("mixamo", "Aj")
    source = demo.trim_frozen(bvh.load(data.clip_path("mixamo", "Aj", "Run_Arc_Left")))
    target = bvh.load(data.clip_path("mixamo", "Mousey_m", "Run_Arc_Left")).skeleton
    ckpt = retargeting.load_default()
    run = retargeting.retarget(
        source, target, ckpt, "full", SolverConfig(**dict(exercises.retargeting.PAPER, lambda_foot=5.0))
    )
    src = preprocess.prepare(source, ckpt.fps, stand=True)  # notebook 03, section 1
    as_section_5 = float(plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean())
    assert exercises.foot_weight.check(as_section_5, source, target, ckpt).passed


def test_an_answer_that_changes_its_inputs_changes_neither_the_reference_nor_the_next_check():
    def zero_the_roots(motion):  # wrong, and it writes into the case it is given
        motion.root_pos[:] = 0.0
        return exercises.basics._speed_central(motion)

    ex = exercises.joint_speed
    before = [c[0].root_pos.copy() for c in ex._cases()]
    assert not ex.check(zero_the_roots).passed
    for case, root in zip(ex._cases(), before):
        np.testing.assert_array_equal(case[0].root_pos, root)
    for variant in (exercises.basics._speed_central_second_order_ends, exercises.basics._speed_central_held_ends):
        assert ex.check(variant).passed
    res = ex.check(lambda motion: None)
    assert not res.passed and "is a `return` missing?" in res.message


def test_an_answer_nearer_a_listed_mistake_is_that_mistake():
    from motionlab.exercises import Mistake, Question

    q = Question("q", lambda: 13.834, mistakes=[Mistake(lambda: 13.867, "the mistake")], atol=0.006, rtol=0.005)
    assert q.check(13.83).passed and q.check(13.834).passed
    res = q.check(13.87)
    assert not res.passed and res.hint == "the mistake"
    close = Question("q", lambda: -0.0003, mistakes=[Mistake(lambda: 0.0002, "the mistake")], atol=0.0006)
    assert close.check(-0.0).passed  # the two differ by less than the digits typed: not told apart
