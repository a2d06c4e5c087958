"""The plausibility check on retargeted outputs (:mod:`motionlab.retargeting.plausibility`)."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab import retargeting, synthetic
from motionlab.core import contacts, humanoid
from motionlab.retargeting import plausibility
from motionlab.retargeting.pipeline import retarget
from motionlab.retargeting.solver import SolverConfig

FAST = SolverConfig(max_steps=8)


@pytest.fixture(scope="module")
def walked():
    ckpt = retargeting.load_default("cpu")
    clip = synthetic.dataset(1, seed=1, num_frames=40)[0]
    target = humanoid.scale_bones(humanoid.canonical_skeleton(), legs=1.2)
    res = retarget(clip, target, ckpt, solver=FAST)
    from motionlab.retargeting.pipeline import prepare_source

    return res, prepare_source(clip, None, "copy").motion


def test_a_good_output_passes(walked):
    res, src = walked
    assert res.plausibility.ok, res.plausibility.describe()
    assert res.plausibility.bone_error < 1e-9


def test_lifted_sunk_stretched_outputs_fail(walked):
    res, src = walked
    leg = humanoid.leg_length(res.motion.skeleton)
    up = res.positions + [0.0, 0.5 * leg, 0.0]
    assert plausibility.check(up, res.motion.skeleton, src).failed == ("foot", "hips")
    down = res.positions - [0.0, 0.3 * leg, 0.0]
    assert set(plausibility.check(down, res.motion.skeleton, src).failed) == {"foot", "floor", "hips"}
    stretched = res.positions.copy()
    stretched[:, humanoid.JOINTS.index("LeftHand")] *= 1.1
    assert plausibility.check(stretched, res.motion.skeleton, src).failed == ("bones",)


def test_each_rig_s_feet_are_measured_on_its_own_sole(walked):
    """A rig whose takes stand higher above their floor (CMU's toes 0.08 leg, Bandai Namco's 0.05)
    is not a lifted foot: raised by its sole, B's feet measure as they did on the floor; the same
    raise with no sole given is a lifted foot."""
    res, src = walked
    leg = humanoid.leg_length(res.motion.skeleton)
    sole = 1.5 * plausibility.FOOT_TOL * leg
    planted = contacts.of_motion(src)
    on_floor = plausibility.check(res.positions, res.motion.skeleton, src, planted)
    raised = res.positions + [0.0, sole, 0.0]
    on_sole = plausibility.check(raised, res.motion.skeleton, src, planted, soles=(0.0, sole))
    assert on_sole.foot_height == pytest.approx(on_floor.foot_height) and "foot" not in on_sole.failed
    assert "foot" in plausibility.check(raised, res.motion.skeleton, src, planted).failed
    lifted_source = src.copy(root_pos=src.root_pos + [0.0, sole, 0.0])  # A on its own sole: the same measure
    both = plausibility.check(raised, res.motion.skeleton, lifted_source, planted, soles=(sole, sole))
    assert both.source_foot_height == pytest.approx(on_floor.source_foot_height)


def test_root_rule_that_sinks_short_legs_is_flagged():
    """Scaling the root by thigh + shin on a very short-legged character puts its feet in the floor."""
    ckpt = retargeting.load_default("cpu")
    clip = synthetic.dataset(1, seed=1, num_frames=40)[0]
    stubby = humanoid.scale_bones(humanoid.canonical_skeleton(), legs=0.3)
    assert retarget(clip, stubby, ckpt, solver=FAST).plausibility.ok
    bad = retarget(clip, stubby, ckpt, solver=FAST, root_mode="legs").plausibility
    assert "foot" in bad.failed and "IMPLAUSIBLE" in bad.describe()


def test_frames_must_match(walked):
    res, src = walked
    with pytest.raises(ValueError, match="frames"):
        plausibility.check(res.positions[:-1], res.motion.skeleton, src)
    assert np.isfinite(res.plausibility.hip_ratio)


def test_skating_is_planted_feet_sliding_not_low_feet_moving(walked):
    """Issue 41: the skating flag measures B's feet on A's stance frames (planted-foot slide): a
    planted foot that slides is flagged, a foot that moves fast while A's is in the air is not."""
    from motionlab.core import contacts

    res, src = walked
    planted = contacts.of_motion(src)
    assert planted.any() and not res.plausibility.skating
    t = np.arange(len(res.positions)) / src.fps
    limit = plausibility.SLIDE_TOL * res.motion.skeleton.height()  # per second
    feet = list(contacts.CONTACT_JOINTS)
    swing = res.positions.copy()
    swing[..., feet, 0] += np.where(planted, 0.0, 10 * limit * t[:, None])  # fast, but only when A's foot is up
    swung = plausibility.check(swing, res.motion.skeleton, src, planted)
    assert swung.slide == pytest.approx(res.plausibility.slide) and not swung.skating
    slid = res.positions.copy()
    slid[..., 0] += 2 * limit * t[:, None]  # the whole body drifts at twice the limit
    flagged = plausibility.check(slid, res.motion.skeleton, src, planted)
    assert flagged.skating and flagged.slide > limit and flagged.ok  # a flag, not a failed test
    assert "SKATING" in flagged.describe()


def test_held_out_walk_turn_on_a_mixamo_character_is_not_flagged():
    """The issue's false alarm: a Bandai Namco walk-turn take on Kaya was flagged skating (its feet
    below 5 cm moved at 55-59 cm/s); on the source's stance frames they move a few cm/s."""
    from motionlab.core import bvh
    from tests.conftest import require_data

    root = require_data("bandai_namco")
    kaya = require_data("mixamo", "Kaya", "Running.bvh")
    take = bvh.load(root / "dataset-2" / "walk-turn-right" / "dataset-2_walk-turn-right_normal_001.bvh")
    res = retarget(take, bvh.load(kaya), retargeting.load_default("cpu"))
    assert not res.plausibility.skating
    assert res.plausibility.slide < 0.5 * res.plausibility.slide_limit


def test_planted_labels_given_as_zeros_and_ones_mask_like_booleans():
    from motionlab.core import contacts

    m = synthetic.generate("walk", num_frames=60, fps=60)
    planted = contacts.of_motion(m)
    pos = m.global_positions()
    as_bool = plausibility.check(pos, m.skeleton, m, planted)
    as_int = plausibility.check(pos, m.skeleton, m, planted.astype(int))
    assert as_int.foot_height == as_bool.foot_height and np.isfinite(as_bool.foot_height)
    with pytest.raises(ValueError, match="booleans"):
        plausibility.check(pos, m.skeleton, m, planted.astype(int) * 2)
