"""Scene building for any skeleton, non-blank rendering, cameras and foot contacts."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab.core import humanoid
from motionlab.core.motion import Motion
from motionlab.testing import random_quat, random_skeleton
from motionlab.viz import scene as scene_mod
from motionlab.viz.scene import BACKGROUND, Scene, contact_labels, foot_joints, world_pose
from tests.conftest import require_data
from tests.viz.conftest import standing_motion, stepping_motion

BG = np.round(np.array([int(BACKGROUND[i : i + 2], 16) for i in (1, 3, 5)]))


def _differs_from_background(image: np.ndarray) -> np.ndarray:
    return np.abs(image.astype(int) - BG).sum(axis=-1) > 30


def _pixel_near(image, xy, radius=2) -> bool:
    """Any non-background pixel within ``radius`` of pixel ``xy`` (column, row)."""
    x, y = np.round(xy).astype(int)
    patch = image[max(y - radius, 0) : y + radius + 1, max(x - radius, 0) : x + radius + 1]
    return bool(_differs_from_background(patch).any())


# ------------------------------------------------------------------ pure helpers
def test_foot_joints_canonical():
    sk = humanoid.canonical_skeleton()
    assert foot_joints(sk) == sorted(sk.index(n) for n in humanoid.FEET)


def test_foot_joints_by_name_for_unknown_rigs():
    sk = random_skeleton(np.random.default_rng(0), 5).renamed(["root", "hip", "knee", "ankle_l", "toe_l"])
    assert foot_joints(sk) == [3, 4]


def test_contact_labels_standing_and_jumping():
    still = standing_motion()
    pos = still.global_positions()
    labels = contact_labels(still.skeleton, pos, still.fps)
    feet = foot_joints(still.skeleton)
    assert labels[:, feet].all()
    assert not np.delete(labels, feet, axis=1).any()
    lifted = pos + np.array([0.0, 0.3, 0.0])  # 30 cm in the air
    assert not contact_labels(still.skeleton, lifted, still.fps).any()


def test_contact_labels_bad_shape():
    with pytest.raises(ValueError, match=r"expected positions of shape \(T, 22, 3\)"):
        contact_labels(humanoid.canonical_skeleton(), np.zeros((5, 21, 3)), 30.0)


def test_world_pose_end_sites_follow_rotation():
    m = standing_motion(2)
    joints, ends = world_pose(m)
    sites = sorted(m.skeleton.end_sites)
    assert ends.shape == (2, len(sites), 3)
    head = sites.index(m.skeleton.index("Head"))
    np.testing.assert_allclose(
        ends[0, head], joints[0, m.skeleton.index("Head")] + m.skeleton.end_sites[m.skeleton.index("Head")]
    )


# ------------------------------------------------------------------ scenes
def test_scene_geometry_canonical(can_render, small):
    m = stepping_motion(10)
    with Scene(m, **small) as sc:
        actor = sc.actors[0]
        J, E = m.skeleton.num_joints, len(m.skeleton.end_sites)
        assert actor._joint_points.n_points == J
        assert actor._bone_points.n_points == J + E
        assert actor._bone_points.n_lines == J - 1 + E
        assert sc.num_frames == 10
        sc.set_frame(7)
        np.testing.assert_allclose(actor._joint_points.points, m.global_positions()[7], atol=1e-6)


@pytest.mark.parametrize("num_joints", [1, 2, 9, 40])
def test_scene_any_skeleton(can_render, small, num_joints):
    rng = np.random.default_rng(num_joints)
    sk = random_skeleton(rng, num_joints)
    T = 4
    rot = random_quat(rng, (T, num_joints))
    root = np.column_stack([np.linspace(0, 1, T), np.full(T, 1.0), np.zeros(T)])
    m = Motion(sk, rot, root, 24.0)
    with Scene(m, trails=("root", "feet"), **small) as sc:
        img = sc.screenshot(T - 1)
        assert img.shape == (160, 200, 3)
        assert sc.actors[0]._joint_points.n_points == num_joints


def test_rendered_frames_are_not_blank_and_move(can_render):
    m = stepping_motion(30)
    with Scene(
        m, window_size=(240, 200), off_screen=True, ground=False, show_time=False, labels=[None], trails=()
    ) as sc:
        first = sc.screenshot(0)
        drawn = _differs_from_background(first)
        assert 0.01 < drawn.mean() < 0.5, "the character should cover a visible part of the picture"
        pix = sc.project(m.global_positions()[0])
        inside = (pix[:, 0] >= 0) & (pix[:, 0] < 240) & (pix[:, 1] >= 0) & (pix[:, 1] < 200)
        assert inside.all()
        assert all(_pixel_near(first, p) for p in pix), "every joint is drawn where it projects"
        later = sc.screenshot(15)
        assert _differs_from_background(later).mean() > 0.01
        assert np.abs(first.astype(int) - later).sum(axis=-1).astype(bool).mean() > 0.005, "frames must differ"


def test_follow_camera_keeps_the_walker_in_view(can_render, small):
    m = stepping_motion(90, speed=2.0)  # 6 m in 3 s
    with Scene(m, camera="follow", **small) as sc:
        for t in range(0, 90, 10):
            sc.set_frame(t, render=False)
            pix = sc.project(m.global_positions()[t])
            assert (pix[:, 0] > 0).all() and (pix[:, 0] < 200).all(), t
            assert (pix[:, 1] > 0).all() and (pix[:, 1] < 160).all(), t


def test_frame_camera_sees_the_whole_clip(can_render, small):
    m = stepping_motion(90, speed=2.0)
    with Scene(m, camera="frame", **small) as sc:
        pix = sc.project(m.global_positions().reshape(-1, 3))
        assert (pix >= 0).all() and (pix[:, 0] < 200).all() and (pix[:, 1] < 160).all()


def test_contacts_colour_the_feet(can_render, small):
    m = standing_motion(3)
    with Scene(m, **small) as sc:
        rgb = sc.actors[0]._joint_points.point_data["rgb"]
        red = np.round(scene_mod._rgb(scene_mod.CONTACT_COLOR) * 255)
        feet = foot_joints(m.skeleton)
        assert np.all(rgb[feet] == red)
        assert not np.any(np.all(rgb[[0, 13]] == red, axis=-1))


def test_motions_with_other_frame_rates_share_time(can_render, small):
    a = stepping_motion(30, fps=30.0)
    b = stepping_motion(60, fps=60.0)
    with Scene([a, b], offsets=[[0, 0, 0], [1, 0, 0]], **small) as sc:
        assert sc.num_frames == 30
        sc.set_frame(10)
        assert sc.actors[0].frame == 10 and sc.actors[1].frame == 20


def test_set_motion_new_proportions(can_render, small):
    m = stepping_motion(12)
    bigger = m.copy(skeleton=humanoid.scale_bones(m.skeleton, legs=1.3))
    with Scene(m, **small) as sc:
        sc.set_frame(5)
        sc.set_motion(0, bigger)
        assert sc.frame == 5
        np.testing.assert_allclose(sc.actors[0]._joint_points.points, bigger.global_positions()[5], atol=1e-6)


def test_scene_bad_input(can_render, small):
    m = stepping_motion(5)
    with pytest.raises(ValueError, match="camera must be"):
        Scene(m, camera="orbit", **small)
    with pytest.raises(ValueError, match=r"offsets of shape \(1, 3\)"):
        Scene(m, offsets=np.zeros((2, 3)), **small)
    with pytest.raises(ValueError, match="Motion"):
        Scene([], **small)
    with pytest.raises(ValueError, match="unknown trail"):
        Scene(m, trails=("hands",), **small)
    with Scene(m, **small) as sc, pytest.raises(ValueError, match=r"frames 0\.\.4"):
        sc.set_frame(5)


def test_scene_does_not_modify_the_motion(can_render, small):
    m = stepping_motion(6)
    before = (m.local_rot.copy(), m.root_pos.copy())
    with Scene(m, offsets=[[1.0, 0.0, 0.0]], **small) as sc:
        sc.screenshot(3)
    np.testing.assert_array_equal(m.local_rot, before[0])
    np.testing.assert_array_equal(m.root_pos, before[1])


def test_off_screen_from_environment(can_render, monkeypatch):
    monkeypatch.setenv("PYVISTA_OFF_SCREEN", "true")
    with Scene(standing_motion(2), window_size=(64, 64)) as sc:
        assert sc.off_screen


@pytest.mark.realdata
def test_full_mixamo_rig(can_render, small):
    from motionlab.core import bvh

    path = require_data("mixamo", "Aj", "Running.bvh")
    m = bvh.load(path)[:20]
    assert m.skeleton.num_joints > 22
    with Scene(m, camera="follow", trails=("root", "feet"), **small) as sc:
        assert sc.actors[0]._joint_points.n_points == m.skeleton.num_joints
        img = sc.screenshot(10)
        pix = sc.project(m.global_positions()[10])
        assert all(_pixel_near(img, p, 3) for p in pix[::7])
    with Scene(humanoid.to_canonical(m), **small) as sc:
        assert sc.actors[0]._joint_points.n_points == 22


def test_contact_labels_find_cmu_feet_whose_rest_pose_lies_flat():
    """CMU's rest foot lies flat, its standing ankles and toes do not: each joint's own clearance."""
    from motionlab.core import bvh

    clip = bvh.load(require_data("cmu", "131", "131_03.bvh"))
    labels = contact_labels(clip.skeleton, clip.global_positions(), clip.fps)
    feet = foot_joints(clip.skeleton)
    assert labels[:, feet].mean(axis=0).min() > 0.1
