"""Side-by-side comparison and per-frame joint errors."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab.viz.compare import joint_errors, side_by_side, side_by_side_offsets
from tests.viz.conftest import standing_motion, stepping_motion


def test_joint_errors_known_answer():
    m = stepping_motion(10)
    shifted = m.copy(root_pos=m.root_pos + np.array([0.1, 0.0, 0.0]))
    np.testing.assert_allclose(joint_errors(m, m), 0.0, atol=1e-12)
    np.testing.assert_allclose(joint_errors(shifted, m), 0.1, atol=1e-9)
    np.testing.assert_allclose(joint_errors(shifted, m, relative_to_root=True), 0.0, atol=1e-9)


def test_joint_errors_match_names_and_time():
    m = stepping_motion(20, fps=30.0)
    prefixed = m.copy(skeleton=m.skeleton.renamed([f"mixamorig:{n}" for n in m.skeleton.names]))
    np.testing.assert_allclose(joint_errors(prefixed, m), 0.0, atol=1e-12)
    double_rate = stepping_motion(40, fps=60.0)  # same walk sampled twice as often
    err = joint_errors(m, double_rate)
    assert err.shape == (20, 22)
    np.testing.assert_allclose(err, 0.0, atol=1e-9)


def test_joint_errors_missing_joints_are_nan():
    m = stepping_motion(5)
    sub, keep = m.skeleton.subset(range(0, 14))
    partial = m.copy(skeleton=sub, local_rot=m.local_rot[:, keep])
    err = joint_errors(m, partial)
    assert np.isnan(err[:, 14:]).all() and np.isfinite(err[:, :14]).all()


def test_joint_errors_no_common_joints():
    m = stepping_motion(3)
    other = m.copy(skeleton=m.skeleton.renamed([f"j{i}" for i in range(22)]))
    with pytest.raises(ValueError, match="no joint names in common"):
        joint_errors(m, other)


def test_side_by_side_offsets_spread_along_x():
    a, b, c = stepping_motion(3), standing_motion(3), stepping_motion(3)
    off = side_by_side_offsets([a, b, c], spacing=1.0)
    np.testing.assert_allclose(np.diff(off[:, 0] + [a.root_pos[0, 0], b.root_pos[0, 0], c.root_pos[0, 0]]), 1.0)
    np.testing.assert_allclose(off[:, 1], 0.0)


def test_side_by_side_scene(can_render):
    ref = stepping_motion(12)
    gen = ref.copy(root_pos=ref.root_pos + np.array([0.0, 0.05, 0.0]), name="generated")
    with side_by_side([ref, gen], window_size=(200, 150), off_screen=True) as sc:
        assert sc.actors[0].joint_values is None
        np.testing.assert_allclose(sc.actors[1].joint_values, 0.05, atol=1e-9)
        sc.set_frame(6)
        np.testing.assert_allclose(sc.actors[1]._joint_points.point_data["value"], 0.05, atol=1e-9)
        gap = sc.actors[1].joints[0, 0] - sc.actors[0].joints[0, 0]
        assert gap[0] > 0.5  # next to each other, not on top
        assert sc.screenshot().std() > 5
