"""Pins for the package-wide conventions (docs/conventions.md).

If one of these fails, a convention changed: every module, notebook and the conventions page
must change with it.
"""

import numpy as np
import pytest
import torch

from motionlab.core import fk, quat
from motionlab.core import quat_torch as tq
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.testing import assert_quat_close

I = np.array([0.0, 1.0, 0.0, 0.0])
J = np.array([0.0, 0.0, 1.0, 0.0])
K = np.array([0.0, 0.0, 0.0, 1.0])


def test_identity_is_w_first():
    np.testing.assert_array_equal(quat.IDENTITY, [1.0, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(tq.IDENTITY.numpy(), [1.0, 0.0, 0.0, 0.0])


def test_to_xyzw_of_identity():
    np.testing.assert_array_equal(quat.to_xyzw(quat.IDENTITY), [0.0, 0.0, 0.0, 1.0])
    np.testing.assert_array_equal(quat.from_xyzw([0.0, 0.0, 0.0, 1.0]), quat.IDENTITY)


def test_hamilton_i_times_j_is_k():
    np.testing.assert_array_equal(quat.mul(I, J), K)
    np.testing.assert_array_equal(quat.mul(J, K), I)
    np.testing.assert_array_equal(quat.mul(K, I), J)
    # anti-commutative: j i = -k
    np.testing.assert_array_equal(quat.mul(J, I), -K)


def test_hamilton_ijk_is_minus_one():
    np.testing.assert_array_equal(quat.mul(quat.mul(I, J), K), -quat.IDENTITY)
    for unit in (I, J, K):
        np.testing.assert_array_equal(quat.mul(unit, unit), -quat.IDENTITY)


def test_torch_hamilton_matches():
    ti, tj, tk = (torch.tensor(x) for x in (I, J, K))
    np.testing.assert_array_equal(tq.mul(ti, tj).numpy(), K)
    np.testing.assert_array_equal(tq.mul(tq.mul(ti, tj), tk).numpy(), -quat.IDENTITY)


def test_plus_90_about_z_maps_x_to_y():
    """Active rotation, right-handed: +90° about z takes +x to +y (and +y to -x)."""
    q = quat.from_axis_angle([0.0, 0.0, 1.0], np.pi / 2)
    np.testing.assert_allclose(quat.rotate(q, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(quat.rotate(q, [0.0, 1.0, 0.0]), [-1.0, 0.0, 0.0], atol=1e-12)
    qt = tq.from_axis_angle(
        torch.tensor([0.0, 0.0, 1.0], dtype=torch.float64), torch.tensor(np.pi / 2, dtype=torch.float64)
    )
    np.testing.assert_allclose(tq.rotate(qt, torch.tensor([1.0, 0.0, 0.0], dtype=torch.float64)), [0, 1, 0], atol=1e-12)


def test_column_vectors():
    """to_matrix acts on columns: R @ v, and its first column is the image of +x."""
    q = quat.from_axis_angle([0.0, 0.0, 1.0], np.pi / 2)
    m = quat.to_matrix(q)
    np.testing.assert_allclose(m, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12)
    np.testing.assert_allclose(m[:, 0], quat.rotate(q, [1.0, 0.0, 0.0]), atol=1e-12)


def test_mul_applies_right_factor_first():
    """mul(a, b) rotates by b first: rotate(mul(a, b), v) == rotate(a, rotate(b, v))."""
    a = quat.from_axis_angle([0.0, 0.0, 1.0], np.pi / 2)  # z 90°
    b = quat.from_axis_angle([1.0, 0.0, 0.0], np.pi / 2)  # x 90°
    v = np.array([0.0, 1.0, 0.0])
    # b takes +y to +z, then a leaves +z alone
    np.testing.assert_allclose(quat.rotate(quat.mul(a, b), v), [0.0, 0.0, 1.0], atol=1e-12)
    # the other order: a takes +y to -x, then b leaves x alone
    np.testing.assert_allclose(quat.rotate(quat.mul(b, a), v), [-1.0, 0.0, 0.0], atol=1e-12)


def test_euler_order_is_bvh_intrinsic():
    """order="zxy" means R = Rz(a0) @ Rx(a1) @ Ry(a2), angles listed in the order's order."""
    az, ax, ay = 0.3, -0.7, 1.1
    rz = quat.to_matrix(quat.from_axis_angle([0, 0, 1.0], az))
    rx = quat.to_matrix(quat.from_axis_angle([1.0, 0, 0], ax))
    ry = quat.to_matrix(quat.from_axis_angle([0, 1.0, 0], ay))
    np.testing.assert_allclose(quat.to_matrix(quat.from_euler([az, ax, ay], "zxy")), rz @ rx @ ry, atol=1e-12)


def test_y_is_up_for_yaw():
    """Heading is a rotation about +Y; from_yaw(a) turns +Z towards +X."""
    q = quat.from_yaw(np.pi / 2)
    np.testing.assert_allclose(quat.rotate(q, [0.0, 0.0, 1.0]), [1.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(quat.rotate(q, [0.0, 1.0, 0.0]), [0.0, 1.0, 0.0], atol=1e-12)
    assert quat.yaw(q) == pytest.approx(np.pi / 2)


def test_global_is_parent_times_local():
    """FK composes global = parent_global ⊗ local (parent on the left)."""
    parent = quat.from_axis_angle([0, 0, 1.0], 0.4)
    child = quat.from_axis_angle([1.0, 0, 0], 0.9)
    g, _ = fk.fk(np.stack([parent, child]), np.zeros((2, 3)), [-1, 0])
    assert_quat_close(g[1], quat.mul(parent, child), atol=1e-12)


def test_root_position_is_absolute():
    """The root's local_pos is its world position: the skeleton's root offset is not added."""
    sk = Skeleton(("root", "child"), [-1, 0], [[5.0, 5.0, 5.0], [0.0, 1.0, 0.0]])
    m = Motion(sk, np.tile(quat.IDENTITY, (1, 2, 1)), [[0.0, 0.9, 0.0]], fps=30)
    np.testing.assert_allclose(m.global_positions()[0], [[0.0, 0.9, 0.0], [0.0, 1.9, 0.0]])
