"""The canonical standing rest pose (:mod:`motionlab.core.rest_pose`) on synthetic and real rigs."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab import synthetic
from motionlab.core import bvh, contacts, humanoid, preprocess, quat, rest_pose
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.retargeting import pipeline
from tests.conftest import require_data


def _walk(frames: int = 60) -> Motion:
    return synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=frames, fps=60, seed=0)


def _repose(motion: Motion, turn: np.ndarray) -> Motion:
    """The same world motion on rest offsets turned by ``turn`` (22, 4) per joint (a studio's own rest)."""
    sk, parents = motion.skeleton, humanoid.PARENTS
    offsets = sk.offsets.copy()
    offsets[1:] = quat.rotate(turn[parents[1:]], sk.offsets[1:])
    local = quat.mul(motion.local_rot, quat.conj(turn)[None])
    local[:, 1:] = quat.mul(turn[None, parents[1:]], local[:, 1:])
    return Motion(Skeleton(sk.names, parents, offsets), quat.normalize(local), motion.root_pos.copy(), motion.fps)


def _lying(motion: Motion) -> Motion:
    """Every bone along +X at rest, as Bandai Namco's rig: each joint's bones turned to +X."""
    turn = np.tile([1.0, 0, 0, 0], (22, 1))
    for c in range(1, 22):
        turn[humanoid.PARENTS[c]] = quat.between(motion.skeleton.offsets[c], np.array([1.0, 0.0, 0.0]))
    return _repose(motion, turn)


def test_t_pose_rig_is_left_as_it_is():
    walk = _walk()
    out, pose = rest_pose.standing(walk)
    assert out is walk and pose.source == "rest" and pose.straightened == ()


def test_lying_rest_stands_from_the_motion_with_world_positions_kept():
    walk = _walk()
    lying = _lying(walk)
    np.testing.assert_allclose(lying.global_positions(), walk.global_positions(), atol=1e-9)
    assert pipeline.hip_height(lying.skeleton) < 0.1  # the bug: a lying rest has no hip height
    out, pose = rest_pose.standing(lying)
    assert pose.source == "motion" and pose.frame >= 0
    np.testing.assert_allclose(out.global_positions(), walk.global_positions(), atol=1e-9)
    # legs straight below the hips: the standing hip height is the T-pose's within 3 % (the frame's
    # pelvis tilt and ankle angle stay)
    assert pipeline.hip_height(out.skeleton) == pytest.approx(pipeline.hip_height(walk.skeleton), rel=0.03)
    np.testing.assert_allclose(out.skeleton.bone_lengths(), walk.skeleton.bone_lengths(), atol=1e-9)


def test_arms_down_and_spread_legs_are_turned_onto_the_t_pose():
    walk = _walk()
    turn = np.tile([1.0, 0, 0, 0], (22, 1))
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        arm = quat.from_axis_angle([0.0, 0.0, 1.0], -sign * np.pi / 2)  # arms hang down
        turn[humanoid.JOINTS.index(f"{side}Arm")] = arm
        turn[humanoid.JOINTS.index(f"{side}ForeArm")] = arm
        turn[humanoid.JOINTS.index(f"{side}Hand")] = arm  # a leaf turns with its bone
        spread = quat.from_axis_angle([0.0, 0.0, 1.0], sign * np.radians(20))  # an A-stance
        turn[humanoid.JOINTS.index(f"{side}UpLeg")] = spread
        turn[humanoid.JOINTS.index(f"{side}Leg")] = spread
    out, pose = rest_pose.standing(_repose(walk, turn))
    assert pose.source == "rest"
    assert {"LeftForeArm", "LeftHand", "LeftLeg", "LeftFoot"} <= set(pose.straightened)
    np.testing.assert_allclose(out.skeleton.offsets[1:], walk.skeleton.offsets[1:], atol=1e-9)
    np.testing.assert_allclose(out.global_positions(), walk.global_positions(), atol=1e-9)
    same = np.abs((out.local_rot * walk.local_rot).sum(-1))  # |cos| of half the angle between them
    np.testing.assert_allclose(same, 1.0, atol=1e-9)


def _knee_bend(skeleton: Skeleton) -> float:
    """Largest angle (degrees) between thigh and shin at rest, of both legs."""
    rest, j = skeleton.rest_positions(), humanoid.JOINTS.index
    thighs = np.stack([rest[j(s + "Leg")] - rest[j(s + "UpLeg")] for s in ("Left", "Right")])
    shins = np.stack([rest[j(s + "Foot")] - rest[j(s + "Leg")] for s in ("Left", "Right")])
    cos = (thighs * shins).sum(-1) / np.linalg.norm(thighs, axis=-1) / np.linalg.norm(shins, axis=-1)
    return float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))).max())


def test_a_knee_bent_at_rest_stands_straight_legged():
    """A rest knee bend within the tolerance (Goblin_m's kind) is a rigging choice: the standing
    pose has thighs and shins straight down; a rig whose legs already are is left as it is."""
    walk = _walk()
    turn = np.tile([1.0, 0, 0, 0], (22, 1))
    for side in ("Left", "Right"):
        turn[humanoid.JOINTS.index(f"{side}UpLeg")] = quat.from_axis_angle([1.0, 0.0, 0.0], np.radians(15))
        turn[humanoid.JOINTS.index(f"{side}Leg")] = quat.from_axis_angle([1.0, 0.0, 0.0], -np.radians(15))
    bent = _repose(walk, turn)
    assert _knee_bend(bent.skeleton) == pytest.approx(30.0)
    out, pose = rest_pose.standing(bent)
    assert pose.source == "rest" and {"LeftLeg", "LeftFoot", "RightLeg", "RightFoot"} <= set(pose.straightened)
    assert _knee_bend(out.skeleton) < 1e-6
    np.testing.assert_allclose(out.skeleton.offsets[1:], walk.skeleton.offsets[1:], atol=1e-9)
    np.testing.assert_allclose(out.global_positions(), walk.global_positions(), atol=1e-9)
    for character in synthetic.character_set(3, seed=1):  # straight legs at rest: untouched
        motion = synthetic.generate("walk", character, num_frames=10, fps=60, seed=0)
        assert rest_pose.standing(motion)[0] is motion


def test_goblin_stands_straight_legged_with_its_motion_kept():
    """Goblin_m's rest bends the knee about 43 deg; its standing pose does not, and the world motion stays."""
    motion = humanoid.to_canonical(bvh.load(require_data("mixamo", "Goblin_m", "Jumping.bvh")))
    assert _knee_bend(motion.skeleton) > 40.0
    out, pose = rest_pose.standing(motion, family=humanoid.family(motion.skeleton))
    assert pose.source == "rest" and _knee_bend(out.skeleton) < 1e-6
    np.testing.assert_allclose(out.skeleton.bone_lengths(), motion.skeleton.bone_lengths(), atol=1e-9)
    np.testing.assert_allclose(out.global_positions(), motion.global_positions(), atol=1e-6)


def test_no_standing_pose_is_a_named_error():
    lying = _lying(_walk(10))
    crawl = lying.copy(local_rot=np.tile(quat.normalize(lying.local_rot[:1] * 0 + [1.0, 0, 0, 0]), (10, 1, 1)))
    with pytest.raises(rest_pose.RestPoseError, match=r"crawl.bvh: no standing pose.*(thigh|shin|Hips->Neck)"):
        rest_pose.standing(crawl, "crawl.bvh")
    with pytest.raises(rest_pose.RestPoseError, match=r"rig.bvh: the rest offsets are not a standing pose.*no motion"):
        rest_pose.standing_skeleton(lying.skeleton, "rig.bvh")


def test_a_file_exported_with_z_up_is_named_so():
    """A walk turned as a whole onto +Z up (offsets, root path and rotations; as a Z-up exporter
    writes it) cannot stand about +Y: the refusal says which axis it stands about and how to fix it;
    a take lying along that axis (the same numbers) needs --rest-from, which the message gives too;
    a take that stands about no axis gets the --rest-from hint alone."""
    walk, up = _walk(20), quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.pi / 2)  # +Y onto +Z
    sk = walk.skeleton
    zup = Motion(
        Skeleton(sk.names, sk.parents, quat.rotate(up, sk.offsets)),
        quat.mul(quat.mul(up, walk.local_rot), quat.conj(up)),
        quat.rotate(up, walk.root_pos),
        walk.fps,
    )
    np.testing.assert_allclose(zup.global_positions(), quat.rotate(up, walk.global_positions()), atol=1e-9)
    with pytest.raises(
        rest_pose.RestPoseError, match=r"zup.bvh: no standing pose.*stands with \+Z up.*export it with Y up"
    ) as err:
        rest_pose.standing(zup, "zup.bvh")
    assert "If the take only lies or crawls, take the standing pose from another take" in str(err.value)
    with pytest.raises(rest_pose.RestPoseError, match=r"rig.bvh: the rest offsets are not a standing pose.*\+Z up"):
        rest_pose.standing_skeleton(zup.skeleton, "rig.bvh")  # a Z-up rig given without motion
    lying = _lying(_walk(10))
    crawl = lying.copy(local_rot=np.tile(quat.normalize(lying.local_rot[:1] * 0 + [1.0, 0, 0, 0]), (10, 1, 1)))
    with pytest.raises(rest_pose.RestPoseError, match="--rest-from FILE.bvh") as err:
        rest_pose.standing(crawl, "crawl.bvh")
    assert "stands with" not in str(err.value)


def test_bandai_namco_stands_like_a_mixamo_character():
    """The issue's bug: Bandai's rest hip height was 0.065 m; its standing pose gives a human one."""
    root = require_data("bandai_namco")
    motion = bvh.load(root / "dataset-1" / "walk" / "dataset-1_walk_normal_001.bvh")
    sk, pose = rest_pose.standing_skeleton(motion, "bandai")
    assert pose.source == "profile" and pose.family == "bandai_namco"
    leg = humanoid.leg_length(sk)
    assert 1.0 < pipeline.hip_height(sk) / leg < 1.3  # hips above straight legs plus the foot
    aj = require_data("mixamo", "Aj", "Running.bvh")
    r = pipeline.root_scale(pipeline.target_skeleton(bvh.load(aj)), sk)
    assert 0.8 < r[1] < 1.3  # was 0.063 (and 15.9 the other way)


def test_info_says_which_pose_it_used(tmp_path, capsys):
    from motionlab.cli import main

    bvh.save(tmp_path / "tpose.bvh", _walk(20))
    bvh.save(tmp_path / "lying.bvh", _lying(_walk(20)))
    assert main(["info", str(tmp_path / "tpose.bvh")]) == 0
    assert "rest      standing pose from the rest offsets" in capsys.readouterr().out
    assert main(["info", str(tmp_path / "lying.bvh")]) == 0
    assert "standing pose from frame" in capsys.readouterr().out


def test_every_bandai_take_stands_in_the_one_pose_of_its_rig():
    """Issue 41 item 4: a run whose no frame stands was refused; the rig profile's rule (bone lengths
    from the rest offsets, every bone along the T-pose) gives every take of the rig one standing pose."""
    root = require_data("bandai_namco")
    run = bvh.load(root / "dataset-2" / "run" / "dataset-2_run_normal_001.bvh")
    walk = bvh.load(root / "dataset-1" / "walk" / "dataset-1_walk_normal_001.bvh")
    with pytest.raises(rest_pose.RestPoseError, match="--rest-from"):  # without the profile's rule: refused
        rest_pose.standing(humanoid.to_canonical(run))
    out, pose = rest_pose.standing(humanoid.to_canonical(run), family="bandai_namco")
    assert pose.source == "profile"
    np.testing.assert_allclose(out.global_positions(), humanoid.to_canonical(run).global_positions(), atol=1e-6)
    sk_run = preprocess.prepare(run, None, stand=True).skeleton
    sk_walk = rest_pose.standing_skeleton(walk)[0]
    np.testing.assert_allclose(sk_run.offsets[1:], sk_walk.offsets[1:], atol=1e-6)  # one pose whatever the take
    assert pipeline.hip_height(sk_run) == pytest.approx(pipeline.hip_height(sk_walk), abs=1e-6)
    np.testing.assert_allclose(sk_run.bone_lengths(), humanoid.to_canonical_skeleton(run.skeleton).bone_lengths())


def test_an_unknown_rig_stands_from_another_file():
    """A rig with no profile rule whose take never stands takes the pose from another take (--rest-from)."""
    walk = _lying(_walk(30))
    crawl = walk.copy(local_rot=np.tile(quat.normalize(walk.local_rot[:1] * 0 + [1.0, 0, 0, 0]), (30, 1, 1)))
    with pytest.raises(rest_pose.RestPoseError, match="--rest-from FILE.bvh"):
        rest_pose.standing(crawl, "crawl.bvh")
    out, pose = rest_pose.standing(crawl, "crawl.bvh", reference=walk)
    assert pose.source == "file"
    np.testing.assert_allclose(out.skeleton.offsets, rest_pose.standing(walk)[0].skeleton.offsets, atol=1e-12)
    np.testing.assert_allclose(out.global_positions(), crawl.global_positions(), atol=1e-9)
    other = _lying(
        _repose(_walk(30), np.tile([1.0, 0, 0, 0], (22, 1))).copy(
            skeleton=humanoid.scale_bones(humanoid.canonical_skeleton(), legs=1.3)
        )
    )
    with pytest.raises(rest_pose.RestPoseError, match="another rig"):
        rest_pose.standing(crawl, "crawl.bvh", reference=other)
    assert rest_pose.on_reference(crawl, other) is crawl  # another rig's file is not this rig's pose


def test_retarget_takes_the_standing_pose_from_rest_from(tmp_path, capsys):
    from motionlab.cli import main

    walk = _lying(_walk(30))
    crawl = walk.copy(local_rot=np.tile(quat.normalize(walk.local_rot[:1] * 0 + [1.0, 0, 0, 0]), (30, 1, 1)))
    for name, m in (("walk.bvh", walk), ("crawl.bvh", crawl), ("tpose.bvh", _walk(10))):
        bvh.save(tmp_path / name, m)
    args = ["retarget", str(tmp_path / "crawl.bvh"), "--target", str(tmp_path / "tpose.bvh"), "--method", "copy"]
    assert main([*args, "-o", str(tmp_path / "a.bvh"), "-q"]) != 0
    assert "--rest-from FILE.bvh" in capsys.readouterr().err
    out = tmp_path / "b.bvh"
    main([*args, "-o", str(out), "-q", "--keep-implausible", "--rest-from", str(tmp_path / "walk.bvh")])
    assert out.is_file()


def test_expand_takes_the_standing_pose_from_rest_from(tmp_path):
    from motionlab.retargeting import expand

    walk = _lying(_walk(30))
    crawl = walk.copy(local_rot=np.tile(quat.normalize(walk.local_rot[:1] * 0 + [1.0, 0, 0, 0]), (30, 1, 1)))
    bvh.save(tmp_path / "crawl.bvh", crawl)
    (bad,) = expand.characters(str(tmp_path / "crawl.bvh"))
    assert bad.skeleton is None and "--rest-from" in bad.error
    (good,) = expand.characters(str(tmp_path / "crawl.bvh"), rest_from=walk)
    np.testing.assert_allclose(good.skeleton.offsets, rest_pose.standing(walk)[0].skeleton.offsets, atol=1e-6)


def _raised(skeleton: Skeleton, dy: float) -> Skeleton:
    offsets = skeleton.offsets.copy()
    offsets[0, 1] += dy
    return Skeleton(skeleton.names, skeleton.parents, offsets)


def test_sole_height_is_the_lowest_rest_joint_above_the_floor_when_it_can_be_a_sole():
    """Read from the rest root offset: the synthetic character's toe 1 cm up; a rig with its ankles
    under the floor (CMU's root at the origin) or its toes above its knees' height says nothing."""
    sk = humanoid.canonical_skeleton()
    assert rest_pose.sole_height(sk) == pytest.approx(0.01)
    assert rest_pose.sole_height(_raised(sk, 0.02)) == pytest.approx(0.03)
    assert rest_pose.sole_height(_raised(sk, -0.02)) == pytest.approx(-0.01)  # toes in the floor, ankles not
    assert rest_pose.sole_height(_raised(sk, -0.08)) is None  # the ankles (0.06 up) in the floor too
    assert rest_pose.sole_height(_raised(sk, -sk.offsets[0, 1])) is None  # the root at the origin
    assert rest_pose.sole_height(_raised(sk, 0.1)) == pytest.approx(0.11)  # above the ankles (0.06), as CMU's takes
    assert rest_pose.sole_height(_raised(sk, 0.46)) is None  # above the knees (0.47): not standing on its feet
    with pytest.raises(ValueError, match="canonical"):
        rest_pose.sole_height(bvh.load(require_data("cmu", "131", "131_01.bvh")).skeleton)


def test_the_standing_pose_keeps_the_rigs_sole():
    """Turning the rest onto the standing pose puts the lowest joint at the rig's sole, not at 0."""
    walk = _walk()
    turn = np.tile([1.0, 0, 0, 0], (22, 1))
    for side in ("Left", "Right"):  # arms down: the rest is turned, the legs are not
        turn[humanoid.JOINTS.index(f"{side}Arm")] = quat.from_axis_angle([0.0, 0.0, 1.0], np.radians(-70))
    for dy, sole in ((0.0, 0.01), (0.015, 0.025), (-0.03, -0.02), (-0.1, 0.0)):
        moved = _repose(walk, turn)
        moved = Motion(_raised(moved.skeleton, dy), moved.local_rot, moved.root_pos, moved.fps)
        out, pose = rest_pose.standing(moved)
        assert pose.source == "rest" and pose.straightened
        assert out.skeleton.rest_positions()[:, 1].min() == pytest.approx(sole)
        assert (rest_pose.sole_height(out.skeleton) or 0.0) == pytest.approx(sole)


def test_a_mixamo_rigs_sole_is_where_its_own_clips_plant_the_toe():
    """Known answer from the studio's data: each Mixamo character's sole (its rest root offset)
    is the median height of its toe joints while planted in its own clips, within 3 mm."""
    folder = require_data("mixamo")
    for character in sorted(p for p in folder.iterdir() if p.is_dir()):
        clips = sorted(character.glob("*.bvh"))[:3]
        sole = rest_pose.sole_height(pipeline.target_skeleton(bvh.load(clips[0]).skeleton))
        raw = rest_pose.sole_height(humanoid.to_canonical_skeleton(bvh.load(clips[0]).skeleton))
        assert sole == pytest.approx(raw, abs=1e-9)  # the standing pose keeps it
        planted = [contacts.planted_toe_heights(preprocess.prepare(bvh.load(p), 60, stand=True)) for p in clips]
        assert abs(np.median(np.concatenate(planted)) - sole) < 0.003, character.name
