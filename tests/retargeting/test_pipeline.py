"""End to end: a Motion onto another skeleton, with every method."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab import retargeting, synthetic
from motionlab.cli import main
from motionlab.core import bvh, contacts, humanoid, motion_files, preprocess, quat, rest_pose
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.retargeting import expand, pipeline
from motionlab.retargeting.pipeline import hip_height, leg_chain, retarget, root_scale
from motionlab.retargeting.solver import SolverConfig
from tests.conftest import require_data


@pytest.fixture(scope="module")
def target():
    return humanoid.scale_bones(humanoid.canonical_skeleton(), legs=1.3, arms=0.8, overall=1.1)


@pytest.mark.parametrize("method", ["copy", "network", "full"])
def test_every_method_gives_a_proper_motion(method, clips, target, tiny_checkpoint):
    src = clips[0]
    out = retarget(src, target, tiny_checkpoint, method, SolverConfig(max_steps=5))
    m = out.motion
    assert m.num_frames == src.num_frames and m.skeleton.num_joints == 22 and m.fps == 60
    assert m.skeleton.equals(target)
    np.testing.assert_allclose(np.linalg.norm(m.local_rot, axis=-1), 1.0, atol=1e-9)
    np.testing.assert_allclose(out.positions, m.global_positions())
    # bone lengths are exactly the target's, in every frame
    bones = np.linalg.norm(out.positions[:, 1:] - out.positions[:, humanoid.PARENTS[1:]], axis=-1)
    np.testing.assert_allclose(bones, np.broadcast_to(target.bone_lengths()[1:], bones.shape), atol=1e-9)
    assert (out.stop_reason != "") == (method == "full")


def test_copy_keeps_rotations_and_scales_the_root(clips, target):
    src = clips[0]
    out = retarget(src, target, None, "copy", root_mode="hips")
    r = hip_height(target) / hip_height(src.skeleton)
    assert out.root_scale == pytest.approx((r, r))
    np.testing.assert_allclose(out.motion.root_pos, src.root_pos * r + [0.0, _lift(src.skeleton, target, r), 0.0])
    np.testing.assert_allclose(out.motion.local_rot, src.local_rot)
    legs = retarget(src, target, None, "copy", root_mode="legs")
    r_legs = humanoid.leg_length(target) / humanoid.leg_length(src.skeleton)
    assert legs.root_scale == pytest.approx((r_legs, r_legs))
    assert retargeting.copy_rotation(src, target, "legs").root_pos == pytest.approx(legs.motion.root_pos)


def test_default_root_scales_ground_by_leg_chain_and_height_by_hips(clips, target):
    src = clips[0]
    out = retarget(src, target, None, "copy")
    r_xz = leg_chain(target) / leg_chain(src.skeleton)
    r_y = hip_height(target) / hip_height(src.skeleton)
    assert r_xz != pytest.approx(r_y, rel=1e-3)  # the test target has other leg proportions
    assert out.root_scale == pytest.approx((r_xz, r_y))
    np.testing.assert_allclose(out.motion.root_pos[:, [0, 2]], src.root_pos[:, [0, 2]] * r_xz)
    np.testing.assert_allclose(out.motion.root_pos[:, 1], src.root_pos[:, 1] * r_y + _lift(src.skeleton, target, r_y))


def _lift(a, b, r_y: float) -> float:
    """The root's raise d = s_B − r_y s_A (each rig's sole from its rest, pipeline's module docstring)."""
    return rest_pose.sole_height(b) - r_y * rest_pose.sole_height(a)


def test_a_source_whose_rest_says_nothing_has_the_sole_its_clip_plants_its_toes_on():
    """A rig whose rest root offset does not place it on the floor (CMU's: at the origin) takes
    its sole from the clip: the median height of its toe joints while planted."""
    walk = synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=120, fps=60, seed=0)
    assert pipeline.source_sole(walk, walk) == pytest.approx(0.01)  # from the rest offsets
    offsets = walk.skeleton.offsets.copy()
    offsets[0] = 0.0
    lost = walk.copy(skeleton=Skeleton(walk.skeleton.names, walk.skeleton.parents, offsets))
    assert rest_pose.sole_height(lost.skeleton) is None
    toes = contacts.planted_toe_heights(walk)
    planted = contacts.of_motion(walk)[:, 2:]  # the toe joints (CONTACT_JOINTS' last two)
    assert len(toes) == planted.sum() and np.allclose(
        toes, walk.global_positions()[:, list(contacts.CONTACT_JOINTS[2:]), 1][planted]
    )
    assert pipeline.source_sole(lost, lost) == pytest.approx(np.median(toes))
    raised = lost.copy(root_pos=lost.root_pos + [0.0, 0.03, 0.0])  # the take recorded 3 cm higher
    assert pipeline.source_sole(raised, raised) == pytest.approx(np.median(toes) + 0.03)


def test_every_method_gets_the_same_sole_at_any_source_rate(tiny_checkpoint):
    """The clip's sole is found at the networks' rate: copying (which keeps a 30 fps source's rate)
    and the full method (which runs at the checkpoint's) put B's root at the same height."""
    walk = synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=60, fps=30, seed=0)
    offsets = walk.skeleton.offsets.copy()
    offsets[0] = 0.0  # the rest says nothing: the sole comes from the clip
    lifted = walk.root_pos + [0.0, 0.03, 0.0]  # a take recorded with its floor 3 cm low
    walk = walk.copy(skeleton=Skeleton(walk.skeleton.names, walk.skeleton.parents, offsets), root_pos=lifted)
    copy = pipeline.prepare_source(walk, None, "copy")
    full = pipeline.prepare_source(walk, tiny_checkpoint, "full")
    assert copy.motion.fps == 30 and full.motion.fps == tiny_checkpoint.fps == 60
    assert copy.sole == full.sole == pytest.approx(0.03, abs=0.002)


def test_a_target_stands_on_its_own_sole():
    """B's root is raised by B's sole less A's scaled one: a standing frame puts B's lowest joint
    at B's sole height, whatever A's, and a target with A's sole on longer legs is raised by
    the difference."""
    a = humanoid.canonical_skeleton()
    s_a = rest_pose.sole_height(a)
    assert s_a > 0  # the synthetic character's toe sits 1 cm above the floor
    stand = Motion(a, np.tile(quat.IDENTITY, (4, 22, 1)), np.tile(a.offsets[0], (4, 1)), 60.0)
    for legs in (0.5, 1.0, 1.6):
        b = humanoid.scale_bones(a, legs=legs)  # keeps the lowest joint's height: the same sole
        out = retarget(stand, b, None, "copy")
        assert rest_pose.sole_height(b) == pytest.approx(s_a)
        assert out.positions[..., 1].min() == pytest.approx(s_a, abs=1e-12)
        assert out.motion.root_pos[0, 1] == pytest.approx(
            out.root_scale[1] * a.offsets[0, 1] + (1 - out.root_scale[1]) * s_a
        )


@pytest.mark.parametrize("dy", [0.03, -0.005], ids=["above", "under"])
def test_a_take_copied_onto_its_own_rig_stays_where_it_was(tmp_path, dy):
    """B's sole comes from B's take when its rest says nothing (CMU, Bandai Namco), as A's does:
    a take copied onto its own rig keeps every joint where it was. A bare skeleton of that rig
    has no floor to go by: its lowest joint stands at 0, the take lowered by its sole."""
    walk = synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=120, fps=60, seed=0)
    offsets = walk.skeleton.offsets.copy()
    offsets[0] = 0.0  # the rest says nothing of the floor
    lost = walk.copy(skeleton=Skeleton(walk.skeleton.names, walk.skeleton.parents, offsets))
    lost = lost.copy(root_pos=lost.root_pos + [0.0, dy, 0.0])  # a take recorded higher, or under its floor
    sole = pipeline.source_sole(lost, lost)
    assert sole == pytest.approx(dy, abs=0.002)
    assert rest_pose.sole_height(pipeline.target_skeleton(lost)) == pytest.approx(sole)
    np.testing.assert_allclose(retarget(lost, lost, None, "copy").positions, lost.global_positions(), atol=1e-12)
    bare = retarget(lost, lost.skeleton, None, "copy")
    np.testing.assert_allclose(bare.positions, lost.global_positions() - [0.0, sole, 0.0], atol=1e-12)
    check = bare.plausibility  # each rig's feet on its own sole: A's on 3 cm, B's on 0, the same feet
    assert check.foot_height == pytest.approx(check.source_foot_height, abs=1e-12)
    path = tmp_path / "lost.bvh"
    bvh.save(path, lost)
    (character,) = expand.characters(str(path))  # expand's targets read the sole as retarget does
    assert rest_pose.sole_height(character.skeleton) == pytest.approx(sole, abs=1e-4)
    other = lost.copy(local_rot=lost.local_rot[::-1].copy())  # --rest-from: another take of the rig
    stood = rest_pose.on_reference(lost, other)
    assert rest_pose.sole_height(stood.skeleton) == pytest.approx(sole)  # the take's own sole, not 0
    np.testing.assert_allclose(retarget(stood, stood, None, "copy").positions, lost.global_positions(), atol=1e-12)


@pytest.mark.parametrize(
    "parts",
    [
        ("bandai_namco", "dataset-2", "run", "dataset-2_run_normal_001.bvh"),  # its rest lies flat
        ("cmu", "131", "131_01.bvh"),  # its root at the origin; toes planted higher than its rest ankles
    ],
)
def test_a_real_take_copied_onto_its_own_rig_stays_where_it_was(tmp_path, parts):
    """The real cases: rests that say nothing of a floor, takes whose joints stand above it."""
    take = require_data(*parts)
    out = tmp_path / "out.bvh"
    assert main(["retarget", str(take), "--target", str(take), "--method", "copy", "-o", str(out), "-q"]) == 0
    source = preprocess.prepare(motion_files.load_metres(take), None, stand=True).global_positions()
    rig = pipeline.target_skeleton(motion_files.load_metres(take))
    assert np.median(source[..., 1].min(axis=1)) > 0.05 * humanoid.leg_length(rig)
    # the 22 joints are written in centimetres, whatever the take's unit (CMU's is 1/0.45 inch)
    np.testing.assert_allclose(bvh.load(out).global_positions(), source, atol=1e-4)  # BVH's printed digits


def test_leg_chain_is_the_summed_leg_bones():
    sk = humanoid.canonical_skeleton()
    lengths = np.linalg.norm(sk.offsets, axis=1)
    left = sum(lengths[sk.index(f"Left{j}")] for j in ("UpLeg", "Leg", "Foot", "ToeBase"))
    right = sum(lengths[sk.index(f"Right{j}")] for j in ("UpLeg", "Leg", "Foot", "ToeBase"))
    assert leg_chain(sk) == pytest.approx((left + right) / 2)
    assert leg_chain(humanoid.scale_bones(sk, overall=2.0)) == pytest.approx(2 * leg_chain(sk))
    longer = humanoid.scale_bones(sk, legs=1.5)  # thigh, shin and foot; the hip offset stays
    hip_offset = (lengths[sk.index("LeftUpLeg")] + lengths[sk.index("RightUpLeg")]) / 2
    assert leg_chain(longer) == pytest.approx(hip_offset + 1.5 * (leg_chain(sk) - hip_offset))


def test_cli_root_modes_match_the_pipeline():
    from motionlab.retargeting import cli, pipeline

    assert cli.ROOT_MODES == pipeline.ROOT_MODES


def test_network_on_its_own_skeleton_reconstructs(clips, tiny_checkpoint):
    """Without iteration, on the training skeleton, the output approximates the input."""
    src = clips[0]
    out = retarget(src, src.skeleton, tiny_checkpoint, "network")
    err = np.linalg.norm(out.positions - src.global_positions(), axis=-1).mean()
    assert err < 0.3  # tiny net after 40 steps; the real one is checked in the benchmark


def test_target_may_be_a_full_rig_motion(clips, target, tiny_checkpoint):
    from motionlab.core.motion import Motion

    rig = Motion(target, clips[1].local_rot, clips[1].root_pos, 60.0)
    out = retarget(clips[0], rig, tiny_checkpoint, "copy")
    assert out.motion.skeleton.equals(target)


def test_nan_and_empty_motions_are_refused(clips, target, tiny_checkpoint):
    bad = clips[0].copy()
    bad.root_pos[7, 1] = np.nan
    with pytest.raises(ValueError, match="frame 7 has NaN"):
        retarget(bad, target, tiny_checkpoint)
    with pytest.raises(ValueError, match="at least 2"):
        retarget(clips[0][:1], target, tiny_checkpoint)
    with pytest.raises(ValueError, match="method"):
        retarget(clips[0], target, tiny_checkpoint, "magic")
    with pytest.raises(ValueError, match="root_mode"):
        root_scale(target, target, "arms")


def test_unmappable_target_names_the_missing_joints(clips, tiny_checkpoint):
    sk = clips[0].skeleton
    renamed = sk.renamed([("LeftElbow" if n == "LeftForeArm" else n) for n in sk.names])
    with pytest.raises(humanoid.RigMappingError, match="LeftForeArm"):
        retarget(clips[0], renamed, tiny_checkpoint, "copy")


def test_input_is_not_modified(clips, target, tiny_checkpoint):
    src = clips[0]
    rot, root = src.local_rot.copy(), src.root_pos.copy()
    retarget(src, target, tiny_checkpoint, "full", SolverConfig(max_steps=2))
    np.testing.assert_array_equal(src.local_rot, rot)
    np.testing.assert_array_equal(src.root_pos, root)


def test_default_checkpoint_loads_and_runs(clips, target):
    if not retargeting.DEFAULT_CHECKPOINT.is_file():
        pytest.skip("no shipped checkpoint yet")
    assert retargeting.DEFAULT_CHECKPOINT.stat().st_size < 3_000_000
    ckpt = retargeting.load_default("cpu")
    out = retarget(clips[0][:60], target, ckpt, "network")
    assert np.isfinite(out.positions).all()
