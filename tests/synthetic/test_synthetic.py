"""The built-in synthetic motion: two-bone IK, gaits, transitions, characters and the dataset."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest

from motionlab import testing
from motionlab.core import quat
from motionlab.core.humanoid import FEET, JOINTS, PARENTS, canonical_skeleton, is_canonical, leg_length
from motionlab.core.skeleton import Skeleton
from motionlab.synthetic import (
    BEHAVIOURS,
    Character,
    Style,
    character_set,
    dataset,
    default_style,
    generate,
    ik,
    random_character,
    sequence,
)
from motionlab.synthetic.characters import RANGES, stature

FPS = 60.0
FOOT = [JOINTS.index(n) for n in FEET]  # LeftFoot, RightFoot, LeftToeBase, RightToeBase
SPINE = [JOINTS.index(n) for n in ("Hips", "Spine", "Spine1", "Spine2", "Neck", "Head")]
HANDS = [JOINTS.index(n) for n in ("LeftHand", "RightHand", "LeftForeArm", "RightForeArm")]


@pytest.fixture(scope="module")
def cast() -> list[Skeleton]:
    """The default adult and three random characters with other proportions."""
    return [canonical_skeleton()] + list(character_set(3, seed=11))


@pytest.fixture(scope="module")
def clips(cast):
    """Every behaviour on every character of the cast: {(behaviour, k): (motion, contacts)}."""
    return {
        (b, k): generate(b, sk, 180, FPS, seed=k, return_contacts=True) for b in BEHAVIOURS for k, sk in enumerate(cast)
    }


def _segment_distance(p, a, b):
    ab = b - a
    t = np.clip(np.sum((p - a) * ab, -1) / np.maximum(np.sum(ab * ab, -1), 1e-12), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def _flat_ankle_height(skeleton: Skeleton) -> np.ndarray:
    toe = skeleton.offsets[[JOINTS.index("LeftToeBase"), JOINTS.index("RightToeBase")], 1]
    return np.maximum(0.0, -toe)


# ---------------------------------------------------------------------------------------- IK
def test_two_bone_reaches_reachable_targets_exactly():
    rng = np.random.default_rng(0)
    n = 500
    upper, lower = rng.uniform(0.2, 0.6, n), rng.uniform(0.2, 0.6, n)
    start = rng.normal(size=(n, 3))
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
    reach = rng.uniform(np.abs(upper - lower) + 1e-3, upper + lower - 1e-3)
    target = start + reach[:, None] * direction
    pole = rng.normal(size=(n, 3))
    mid, end = ik.two_bone(start, target, upper, lower, pole)
    np.testing.assert_allclose(end, target, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(mid - start, axis=-1), upper, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(end - mid, axis=-1), lower, atol=1e-9)
    # the middle joint bends towards the pole
    perp = pole - np.sum(pole * direction, -1, keepdims=True) * direction
    assert np.all(np.sum((mid - start) * perp, -1) > 0)


def test_two_bone_clamps_unreachable_targets():
    start = np.zeros((2, 3))
    target = np.array([[0.0, -3.0, 0.0], [0.3, 0.0, 0.0]])  # far away / nearer than |a - b|
    mid, end = ik.two_bone(start, target, 0.5, 0.2, np.array([0.0, 0.0, 1.0]))
    np.testing.assert_allclose(end[0], [0.0, -0.7, 0.0], atol=1e-12)  # straight along the direction
    np.testing.assert_allclose(mid[0], [0.0, -0.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(end[1], [0.3, 0.0, 0.0], atol=1e-12)  # folded: |end| = a − b
    np.testing.assert_allclose(np.linalg.norm(mid[1]), 0.5, atol=1e-12)


def test_two_bone_single_equals_batched_and_rejects_bad_lengths():
    rng = np.random.default_rng(1)
    start, target, pole = rng.normal(size=(3, 4, 3))
    mid, end = ik.two_bone(start, target, 0.8, 0.9, pole)
    mid0, end0 = ik.two_bone(start[2], target[2], 0.8, 0.9, pole[2])
    np.testing.assert_allclose(mid[2], mid0)
    np.testing.assert_allclose(end[2], end0)
    with pytest.raises(ValueError, match="positive"):
        ik.two_bone(start, target, -1.0, 0.5, pole)
    with pytest.raises(ValueError, match=r"\(\.\.\., 3\)"):
        ik.two_bone(start[:, :2], target, 1.0, 0.5, pole)


def test_aim_recovers_a_rotation():
    """rotation -> (direction, up) -> aim -> rotation"""
    rng = np.random.default_rng(2)
    q = testing.random_quat(rng, (50,))
    rest_dir, rest_up = np.array([0.0, -1.0, 0.0]), np.array([0.0, 0.0, 1.0])
    got = ik.aim(rest_dir, rest_up, quat.rotate(q, rest_dir), quat.rotate(q, rest_up))
    testing.assert_quat_close(got, q, atol=1e-9)


# ---------------------------------------------------------------------------------------- output
def test_shapes_units_and_start_pose():
    sk = canonical_skeleton()
    m, contacts = generate("walk", sk, 120, FPS, seed=0, return_contacts=True)
    assert m.local_rot.shape == (120, 22, 4) and m.root_pos.shape == (120, 3) and m.fps == FPS
    assert m.skeleton is sk and m.name == "walk"
    assert contacts.shape == (120, 4) and contacts.dtype == bool
    np.testing.assert_allclose(np.linalg.norm(m.local_rot, axis=-1), 1.0, atol=1e-12)
    p = m.global_positions()
    # metres and Y up: the pelvis is about a leg length above the ground, the head above it
    assert 0.8 * leg_length(sk) < p[0, 0, 1] < 1.2 * leg_length(sk)
    assert np.all(p[:, JOINTS.index("Head"), 1] > p[:, 0, 1])
    # starts at the origin facing +Z (left hip on +X), and walks towards +Z
    np.testing.assert_allclose(m.root_pos[0, [0, 2]], 0.0, atol=1e-12)
    left = p[0, JOINTS.index("LeftUpLeg")] - p[0, JOINTS.index("RightUpLeg")]
    forward = np.cross(left, [0.0, 1.0, 0.0])
    assert forward[2] / np.linalg.norm(forward) > np.cos(np.radians(10))
    assert m.root_pos[-1, 2] > 1.0


def test_deterministic_under_seed():
    segments = [("idle", 30), ("walk", 60), ("jump", 70)]
    a, b = sequence(segments, seed=5), sequence(segments, seed=5)
    np.testing.assert_array_equal(a.local_rot, b.local_rot)
    np.testing.assert_array_equal(a.root_pos, b.root_pos)
    c = sequence(segments, seed=6)
    assert not np.allclose(a.global_positions(), c.global_positions(), atol=1e-3)


def test_one_frame_and_other_frame_rates():
    assert generate("run", num_frames=1).num_frames == 1
    m30 = generate("walk", num_frames=60, fps=30.0, seed=1)
    assert m30.fps == 30.0 and m30.num_frames == 60


# ---------------------------------------------------------------------------------------- plausibility
@pytest.mark.parametrize("behaviour", BEHAVIOURS)
def test_feet_on_the_ground_and_planted(clips, cast, behaviour):
    for k, sk in enumerate(cast):
        m, contacts = clips[(behaviour, k)]
        p = m.global_positions()
        feet = p[:, FOOT]
        assert feet[..., 1].min() > -1e-3, f"{behaviour} on character {k}: a foot goes below the floor"
        # planted toes touch the floor; planted ankles sit at their flat-foot height
        toe_y = feet[:, 2:, 1][contacts[:, 2:]]
        assert np.abs(toe_y).max(initial=0.0) < 3e-3
        ankle_y = feet[:, :2, 1] - _flat_ankle_height(sk)
        assert np.abs(ankle_y[contacts[:, :2]]).max(initial=0.0) < 3e-3
        # whenever a foot joint is in contact, its lowest point is the floor: no hovering
        in_contact = contacts.any(axis=1)
        assert np.all(np.abs(feet[in_contact][:, 2:, 1].min(axis=1)) < 3e-3)
        # no foot skating: horizontal speed of a planted joint (frame to frame)
        speed = np.linalg.norm(np.diff(feet[..., [0, 2]], axis=0), axis=-1) * m.fps
        both = contacts[1:] & contacts[:-1]
        assert speed[both].max(initial=0.0) < 0.02, f"{behaviour} on character {k}: feet slide"


@pytest.mark.parametrize("behaviour", BEHAVIOURS)
def test_bones_rigid_and_hands_beside_the_body(clips, cast, behaviour):
    for k, sk in enumerate(cast):
        m, _ = clips[(behaviour, k)]
        p = m.global_positions()
        bones = np.linalg.norm(p[:, 1:] - p[:, PARENTS[1:]], axis=-1)
        np.testing.assert_allclose(bones, np.broadcast_to(sk.bone_lengths()[1:], bones.shape), atol=1e-9)
        shoulder = np.linalg.norm(
            sk.rest_positions()[JOINTS.index("LeftArm")] - sk.rest_positions()[JOINTS.index("Spine2")]
        )
        for h in HANDS:
            d = np.min([_segment_distance(p[:, h], p[:, a], p[:, b]) for a, b in zip(SPINE[:-1], SPINE[1:])], axis=0)
            assert d.min() > 0.6 * shoulder, f"{JOINTS[h]} comes within {d.min():.3f} m of the spine ({behaviour}, {k})"


def test_walk_and_run_gait_structure(clips, cast):
    for k, sk in enumerate(cast):
        leg = leg_length(sk)
        walk, wc = clips[("walk", k)]
        run, rc = clips[("run", k)]
        toes_w, toes_r = wc[:, 2:], rc[:, 2:]
        assert np.any(toes_w.all(axis=1)), "walking has double support"
        assert not np.any(~toes_w.any(axis=1)), "walking never leaves the ground"
        assert np.mean(~toes_r.any(axis=1)) > 0.05, "running has flight phases"
        # speeds follow stride x leg x cadence
        for m, name in ((walk, "walk"), (run, "run")):
            st = default_style(name)
            speed = np.linalg.norm(m.root_pos[-1, [0, 2]] - m.root_pos[0, [0, 2]]) / m.duration
            assert speed == pytest.approx(st.stride * leg * st.cadence, rel=0.15)


def test_jump_has_a_flight_phase(clips, cast):
    for k, sk in enumerate(cast):
        m, contacts = clips[("jump", k)]
        p = m.global_positions()
        airborne = p[:, FOOT, 1].min(axis=1) > 0.02
        assert airborne.sum() >= 6, "both feet leave the ground for a tenth of a second"
        assert not np.any(contacts[airborne])
        rise = p[:, 0, 1].max() - p[0, 0, 1]
        assert rise > 0.5 * default_style("jump").jump_height * leg_length(sk)


def test_squat_lowers_the_hips_with_heels_planted(clips, cast):
    for k, sk in enumerate(cast):
        m, contacts = clips[("squat", k)]
        drop = m.root_pos[0, 1] - m.root_pos[:, 1].min()
        assert drop > 0.3 * leg_length(sk)
        assert contacts.all(), "heels and toes stay down"


def test_turning_follows_turn_rate():
    m = generate("walk", num_frames=240, style={"turn_rate": 0.5}, seed=0)
    p = m.global_positions()
    left = p[:, JOINTS.index("LeftUpLeg")] - p[:, JOINTS.index("RightUpLeg")]
    heading = np.arctan2(-left[:, 2], left[:, 0])  # left = (cos h, 0, -sin h)
    turned = np.unwrap(heading)[-30:].mean() - np.unwrap(heading)[:30].mean()
    assert turned == pytest.approx(0.5 * (m.duration - 0.5), abs=0.2)


# ---------------------------------------------------------------------------------------- transitions
def _frame_changes(motion):
    p = motion.global_positions()
    relative = np.linalg.norm(np.diff(p - p[:, :1], axis=0), axis=-1).max()
    accel = np.linalg.norm(np.diff(p, 2, axis=0), axis=-1).max()
    root_accel = np.linalg.norm(np.diff(p[:, 0], 2, axis=0), axis=-1).max()
    return np.array([relative, accel, root_accel])


def test_transitions_are_continuous(cast):
    for k, sk in enumerate(cast[:3]):
        steady = np.max([_frame_changes(generate(b, sk, 150, FPS, seed=k)) for b in BEHAVIOURS], axis=0)
        for segments in (
            [("walk", 90), ("run", 90)],
            [("run", 90), ("idle", 90)],
            [("idle", 60), ("walk", 120), ("run", 120), ("jump", 60), ("squat", 90)],
        ):
            m, contacts = sequence(segments, sk, FPS, seed=k, return_contacts=True)
            changes = _frame_changes(m)
            # no joint jumps further per frame than in the steady behaviours; accelerations may
            # grow (a jump squeezed into a short segment pushes off harder) but stay bounded
            assert np.all(changes <= np.array([1.2, 2.0, 2.0]) * steady), f"{segments} on {k}: {changes} vs {steady}"
            p = m.global_positions()
            assert p[:, FOOT, 1].min() > -1e-3
            speed = np.linalg.norm(np.diff(p[:, FOOT][..., [0, 2]], axis=0), axis=-1) * m.fps
            assert speed[contacts[1:] & contacts[:-1]].max(initial=0.0) < 0.02
            assert m.root_pos[:, 1].min() > 0.5 * leg_length(sk), "the pelvis never collapses"


def test_walk_to_run_root_is_smooth():
    m = sequence([("walk", 120), ("run", 120)], seed=3)
    step = np.linalg.norm(np.diff(m.root_pos, axis=0), axis=-1)
    assert step.max() < 0.08  # metres per frame at 60 fps: under 4.8 m/s
    assert np.abs(np.diff(step)).max() < 0.01  # no jolt in the root speed


# ---------------------------------------------------------------------------------------- styles and errors
def test_style_overrides_change_the_motion():
    base = generate("walk", num_frames=120, seed=0)
    longer = generate("walk", num_frames=120, style={"stride": 1.0}, seed=0)
    assert longer.root_pos[-1, 2] > 1.15 * base.root_pos[-1, 2]
    style = default_style("squat").replace(squat_depth=0.2)
    shallow = generate("squat", num_frames=150, style=style, seed=0)
    deep = generate("squat", num_frames=150, seed=0)
    assert shallow.root_pos[:, 1].min() > deep.root_pos[:, 1].min() + 0.1


def test_bad_input_raises_and_inputs_are_unchanged():
    with pytest.raises(ValueError, match="unknown behaviour"):
        generate("dance")
    with pytest.raises(ValueError, match="unknown style fields"):
        generate("walk", style={"speed": 2.0})
    with pytest.raises(ValueError, match="'stride' must lie in"):
        generate("walk", style={"stride": -1.0})
    with pytest.raises(ValueError, match="num_frames must be a positive integer"):
        generate("walk", num_frames=0)
    with pytest.raises(ValueError, match="fps"):
        generate("walk", fps=0.0)
    with pytest.raises(ValueError, match="canonical 22-joint"):
        generate("walk", testing.random_skeleton(np.random.default_rng(0), 5))
    with pytest.raises(ValueError, match="non-empty list"):
        sequence([])
    overrides = {"stride": 0.9}
    sk = canonical_skeleton()
    offsets = sk.offsets.copy()
    generate("walk", sk, 30, style=overrides)
    assert overrides == {"stride": 0.9}
    np.testing.assert_array_equal(sk.offsets, offsets)
    assert isinstance(default_style("run"), Style) and dataclasses.is_dataclass(Style)


# ---------------------------------------------------------------------------------------- characters
def test_random_characters_are_plausible_and_deterministic():
    cast = character_set(20, seed=4)
    again = character_set(20, seed=4)
    assert [c.name for c in cast] == [f"char{i:02d}" for i in range(20)]
    for a, b in zip(cast, again):
        assert isinstance(a, Character) and isinstance(a, Skeleton) and is_canonical(a)
        np.testing.assert_array_equal(a.offsets, b.offsets)
        for key, (lo, hi) in RANGES.items():
            assert lo <= a.proportions[key] <= hi
        assert stature(a) == pytest.approx(a.proportions["height"], rel=1e-9)
    legs = np.array([leg_length(c) / stature(c) for c in cast])
    assert legs.max() > 1.3 * legs.min(), "proportions really differ"
    assert not np.allclose(character_set(3, seed=5)[0].offsets, cast[0].offsets)
    assert random_character(7).equals(random_character(np.random.default_rng(7)))
    with pytest.raises(ValueError, match="unknown proportion"):
        random_character(0, tail=(1.0, 2.0))


def test_dataset_is_varied_fast_and_deterministic():
    start = time.perf_counter()
    clips = dataset(8, seed=1, num_frames=120)
    elapsed = time.perf_counter() - start
    assert len(clips) == 8 and all(c.num_frames == 120 and c.fps == FPS for c in clips)
    assert elapsed < 4.0
    names = {c.name.split(":")[1] for c in clips}
    assert len(names) > 3
    assert all(c.skeleton.equals(canonical_skeleton()) for c in clips)
    again = dataset(8, seed=1, num_frames=120)
    for a, b in zip(clips, again):
        np.testing.assert_array_equal(a.local_rot, b.local_rot)
