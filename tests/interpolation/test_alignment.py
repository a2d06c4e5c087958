"""Root alignment (eq. 3) recovers known yaw and translation exactly."""

import numpy as np
import pytest

from motionlab.core import quat
from motionlab.interpolation import alignment
from motionlab.testing import assert_quat_close

from .conftest import toy_motion


@pytest.mark.parametrize("theta", [0.0, 0.7, -2.5, np.pi - 1e-3])
def test_estimate_recovers_known_yaw_and_translation(theta):
    m = toy_motion(30)
    known = alignment.RigidYaw(theta, np.array([1.5, 0.0, -4.0]))
    moved = alignment.apply(m, known)
    est = alignment.estimate(moved.local_rot[7, 0], moved.root_pos[7], m.local_rot[7, 0], m.root_pos[7])
    assert est.theta == pytest.approx(theta, abs=1e-12)
    np.testing.assert_allclose(est.translation, known.translation, atol=1e-12)
    back = alignment.apply(m, est)
    np.testing.assert_allclose(back.global_positions(), moved.global_positions(), atol=1e-12)


def test_align_to_continues_from_the_last_frame():
    a, b = toy_motion(40), toy_motion(40, phase=1.0)
    b = alignment.apply(b, alignment.RigidYaw(1.2, np.array([5.0, 0.0, 2.0])))
    out = alignment.align_to(b, a, frame=0, to_frame=-1)
    assert quat.yaw(out.local_rot[0, 0]) == pytest.approx(quat.yaw(a.local_rot[-1, 0]), abs=1e-12)
    np.testing.assert_allclose(out.root_pos[0, [0, 2]], a.root_pos[-1, [0, 2]], atol=1e-12)
    assert out.root_pos[0, 1] == pytest.approx(b.root_pos[0, 1])  # height kept


def test_fit_points_recovers_transform():
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(30, 3))
    known = alignment.RigidYaw(-1.1, np.array([0.3, 0.0, 2.0]))
    est = alignment.fit_points(known.apply_points(pts), pts)
    assert est.theta == pytest.approx(-1.1, abs=1e-12)
    np.testing.assert_allclose(est.translation, known.translation, atol=1e-12)


def test_inverse_round_trip():
    """T -> T⁻¹ -> identity"""
    t = alignment.RigidYaw(0.4, np.array([1.0, 0.5, -2.0]))
    p = np.random.default_rng(1).normal(size=(5, 3))
    np.testing.assert_allclose(t.inverse().apply_points(t.apply_points(p)), p, atol=1e-12)
    q = quat.from_yaw(0.3)
    assert_quat_close(t.inverse().apply_rotations(t.apply_rotations(q)), q, atol=1e-12)


def test_reference_joint_of_a_rig_with_fixed_root():
    m = toy_motion(10)
    assert alignment.reference_joint(m) == 0
    t = m.translations()
    t[:, 1] += m.root_pos - m.root_pos[:1]  # move the hips, pin the root
    fixed = m.copy(local_pos=t, root_pos=np.repeat(m.root_pos[:1], 10, axis=0))
    assert alignment.reference_joint(fixed) == 1


def test_bad_shapes():
    with pytest.raises(ValueError, match="one frame each"):
        alignment.estimate(np.zeros((2, 4)), np.zeros(3), quat.IDENTITY, np.zeros(3))
