"""Feet kept out of the floor by bending the legs (motionlab.interpolation.footing)."""

import numpy as np
import pytest

from experiments.interpolation import gap_eval
from motionlab.core import bvh, humanoid, quat
from motionlab.core.motion import Motion
from motionlab.interpolation import footing, inbetween
from tests.conftest import require_data
from tests.interpolation.conftest import toy_motion


def _slerp_gap(m, a, b):
    """``m`` with frames ``a+1 … b-1`` replaced by SLERP and a linear root (no floor handling)."""
    broken = m.copy()
    broken.local_rot[a + 1 : b] = np.nan
    broken.root_pos[a + 1 : b] = np.nan
    if broken.local_pos is not None:
        broken.local_pos[a + 1 : b] = np.nan
    return inbetween.fill_between(broken, a + 1, b, root="linear")


def _lowest_foot(m, legs):
    """The lowest joint of either foot (the ankles and everything below them), per frame."""
    feet = np.zeros(m.skeleton.num_joints, dtype=bool)
    for _, _, ankle in legs:
        feet |= m.skeleton.subtree(ankle)
    return m.global_positions()[:, feet, 1].min(axis=1)


def test_a_rig_without_legs_is_left_alone():
    m = toy_motion(40)  # joints named LUp, LLow, ...: no humanoid mapping
    assert footing.legs(m.skeleton) == []
    out = footing.plant_feet(m, 10, 20)
    np.testing.assert_array_equal(out.local_rot, m.local_rot)
    np.testing.assert_array_equal(out.root_pos, m.root_pos)


@pytest.mark.realdata
def test_sunk_feet_are_raised_onto_the_floor_by_the_legs_alone(real_walk):
    m = real_walk
    legs = footing.legs(m.skeleton)
    assert [m.skeleton.names[h] for h, _, _ in legs] == ["UpperLeg_L", "UpperLeg_R"]
    # a gap where SLERP sinks a foot into the floor
    for a in range(60, m.num_frames - 40, 7):
        b = a + 16
        filled = _slerp_gap(m, a, b)
        floor = min(footing.lowest_joints(filled, a, b)[[0, -1]])
        if _lowest_foot(filled[a + 1 : b], legs).min() < floor - 0.01:
            break
    else:
        pytest.fail("no 15-frame SLERP gap of the walk sank a foot by a centimetre")
    out = footing.plant_feet(filled, a, b)
    inside = slice(a + 1, b)
    assert _lowest_foot(out[inside], legs).min() >= floor - 1e-9  # on the floor, not in it
    np.testing.assert_array_equal(out.root_pos, filled.root_pos)  # the hips are not lifted
    leg_joints = {j for leg in legs for j in leg}
    others = [j for j in range(m.skeleton.num_joints) if j not in leg_joints]
    np.testing.assert_array_equal(out.local_rot[:, others], filled.local_rot[:, others])
    np.testing.assert_array_equal(out.local_rot[: a + 1], filled.local_rot[: a + 1])
    np.testing.assert_array_equal(out.local_rot[b:], filled.local_rot[b:])
    g_new, p_new = out[inside].fk()
    g_old, p_old = filled[inside].fk()
    ankles = [ankle for _, _, ankle in legs]
    # each foot moved rigidly: its world rotation kept, its joints all moved straight up by one amount
    np.testing.assert_allclose(np.abs(np.sum(g_new[:, ankles] * g_old[:, ankles], axis=-1)), 1.0, atol=1e-9)
    for ankle in ankles:
        foot = m.skeleton.subtree(ankle)
        shift = p_new[:, foot] - p_old[:, foot]
        np.testing.assert_allclose(shift[..., [0, 2]], 0.0, atol=1e-9)
        np.testing.assert_allclose(shift[..., 1], shift[:, :1, 1].repeat(foot.sum(), axis=1), atol=1e-9)
        assert np.all(shift[..., 1] >= -1e-12)
    par = m.skeleton.parents
    bones = np.arange(1, m.skeleton.num_joints)
    np.testing.assert_allclose(np.linalg.norm(p_new[:, bones] - p_new[:, par[bones]], axis=-1),
                               np.linalg.norm(p_old[:, bones] - p_old[:, par[bones]], axis=-1), atol=1e-9)  # fmt: skip
    assert np.all(np.isclose(np.linalg.norm(out.local_rot, axis=-1), 1.0))
    assert not np.allclose(quat.canonical(out.local_rot[inside]), quat.canonical(filled.local_rot[inside]))


@pytest.mark.realdata
def test_a_slow_walk_gap_keeps_the_hips_level_instead_of_hopping():
    """Bandai Namco's ``dataset-1`` ``proud`` walk is too slow for a stride to be read on 3 s sides,
    so a 10-frame gap at 211 is filled by SLERP; the stance foot sank 4 cm there, and lifting the
    body out made the hips rise 4.5 cm where the walker's rose 0.5 cm (11.6% of the root's
    displacement across the gap). Bending the leg keeps the hips on their path."""
    m = bvh.load(require_data("bandai_namco", "dataset-1", "walk", "dataset-1_walk_proud_001.bvh"))
    bent = gap_eval.evaluate_cut(m, 211, 10, found=[(210, 10)])
    assert bent.below == 0.0 and bent.root_rel < 0.05
    lifted = gap_eval.evaluate_cut(m, 211, 10, found=[(210, 10)], feet="lift")  # the body lifted instead
    assert lifted.below == 0.0 and lifted.root_rel > 0.10


def test_a_straight_leg_bends_its_knee_towards_the_toes():
    """Straight legs (the canonical rest pose) give the knee no bend to keep: turned to face +X and
    lowered 5 cm into the floor, the body's legs fold forward, where the toes point, not sideways,
    and the feet end on the floor."""
    sk = humanoid.canonical_skeleton()
    root = np.tile([0.0, 0.9, 0.0], (7, 1))
    root[1:6, 1] -= 0.05  # frames 1-5 sink 5 cm
    rot = np.tile([1.0, 0.0, 0.0, 0.0], (7, sk.num_joints, 1))
    rot[:, 0] = quat.from_yaw(np.full(7, np.pi / 2))  # +Z (the toes in the rest pose) turned to +X
    m = Motion(sk, rot, root, 30.0)
    legs = footing.legs(sk)
    out = footing.plant_feet(m, 0, 6)
    floor = min(footing.lowest_joints(m, 0, 6)[[0, -1]])
    np.testing.assert_allclose(_lowest_foot(out[1:6], legs), floor, atol=1e-9)
    np.testing.assert_array_equal(out.root_pos, m.root_pos)
    knees = [k for _, k, _ in legs]
    moved = out.global_positions()[1:6, knees] - m.global_positions()[1:6, knees]
    toes = m.global_positions()[0, [sk.names.index("LeftToeBase")]] - m.global_positions()[0, [legs[0][2]]]
    assert toes[0, 0] > 0.1 and abs(toes[0, 2]) < 1e-9  # the toes point along +X
    assert np.all(moved[..., 0] > 0.05)  # the knees go forward, by centimetres
    np.testing.assert_allclose(moved[..., 2], 0.0, atol=1e-9)  # not sideways


def test_plant_feet_refuses_gap_ends_outside_the_clip_or_unfilled_frames():
    m = toy_motion(20)
    with pytest.raises(ValueError, match=r"'toy'.*0 <= a < b < 20.*a=12, b=20"):
        footing.plant_feet(m, 12, 20)
    holed = m.copy()
    holed.local_rot[5] = np.nan
    with pytest.raises(ValueError, match=r"'toy'.*frames 3 … 8 must be filled"):
        footing.plant_feet(holed, 3, 8)
