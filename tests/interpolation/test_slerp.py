"""SLERP paths and α(k) curves: endpoints, unit norm, shortest arc, constant angular speed."""

import numpy as np
import pytest

from motionlab.core import quat
from motionlab.interpolation import slerp
from motionlab.testing import assert_quat_close, random_quat


@pytest.fixture
def rng():
    return np.random.default_rng(7)


@pytest.mark.parametrize("curve", slerp.CURVES)
def test_alphas_strictly_inside_and_increasing(curve):
    a = slerp.alphas(9, curve)
    assert a.shape == (9,)
    assert np.all((a > 0) & (a < 1))
    assert np.all(np.diff(a) > 0)
    np.testing.assert_allclose(a + a[::-1], 1.0, atol=1e-12)  # all three curves are symmetric


def test_alphas_linear_known_values():
    np.testing.assert_allclose(slerp.alphas(3), [0.25, 0.5, 0.75])
    assert slerp.alphas(0).shape == (0,)


def test_alphas_bad_input():
    with pytest.raises(ValueError, match="curve"):
        slerp.alphas(3, "cubic-ish")
    with pytest.raises(ValueError, match="non-negative"):
        slerp.alphas(-1)


def test_endpoints(rng):
    a, b = random_quat(rng, (5,)), random_quat(rng, (5,))
    path = slerp.slerp_path(a, b, np.array([0.0, 1.0]))
    assert path.shape == (5, 2, 4)
    assert_quat_close(path[:, 0], a, atol=1e-12)
    assert_quat_close(path[:, 1], b, atol=1e-12)


def test_unit_norm_and_batch_shape(rng):
    a, b = random_quat(rng, (3, 4)), random_quat(rng, (3, 4))
    path = slerp.slerp_path(a, b, 17, "ease")
    assert path.shape == (3, 4, 17, 4)
    np.testing.assert_allclose(np.linalg.norm(path, axis=-1), 1.0, atol=1e-12)


def test_shortest_arc(rng):
    a = random_quat(rng, (50,))
    b = random_quat(rng, (50,))
    path = slerp.slerp_path(a, -b, 11)  # -b is the same rotation as b
    total = quat.angle_between(a, b)
    steps = slerp.angular_speed(np.concatenate([a[:, None], path, b[:, None]], axis=1))
    np.testing.assert_allclose(steps.sum(axis=1), total, atol=1e-9)  # never the long way round
    assert np.all(total <= np.pi + 1e-12)


def test_constant_angular_speed(rng):
    a, b = random_quat(rng, (20,)), random_quat(rng, (20,))
    path = slerp.slerp_path(a, b, 9, "linear")
    full = np.concatenate([a[:, None], path, b[:, None]], axis=1)
    steps = slerp.angular_speed(full)
    np.testing.assert_allclose(steps, steps[:, :1].repeat(steps.shape[1], axis=1), atol=1e-9)


def test_ease_starts_and_ends_slower(rng):
    a, b = random_quat(rng), random_quat(rng)
    path = slerp.slerp_path(a, b, 20, "ease")
    full = np.concatenate([a[None], path, b[None]])
    steps = slerp.angular_speed(full)
    assert steps[0] < steps[10] and steps[-1] < steps[10]


def test_left_invariance(rng):
    a, b, g = random_quat(rng, (6,)), random_quat(rng, (6,)), random_quat(rng, (6,))
    left = slerp.slerp_path(quat.mul(g, a), quat.mul(g, b), 5)
    assert_quat_close(left, quat.mul(g[:, None], slerp.slerp_path(a, b, 5)), atol=1e-9)


def test_euler_lerp_detours_where_slerp_does_not():
    # two rotations 20° apart about x but on either side of the ±180° wrap of the first Euler angle
    a = quat.from_euler(np.array([np.radians(170.0), 0.0, 0.0]), "xyz")
    b = quat.from_euler(np.array([np.radians(-170.0), 0.0, 0.0]), "xyz")
    eul = slerp.euler_lerp_path(a, b, 9, order="xyz")
    sl = slerp.slerp_path(a, b, 9)
    full = lambda p: np.concatenate([a[None], p, b[None]])  # noqa: E731
    assert slerp.angular_speed(full(sl)).sum() == pytest.approx(np.radians(20.0), abs=1e-9)
    assert slerp.angular_speed(full(eul)).sum() > np.radians(300.0)  # the long way round


def test_inputs_not_modified(rng):
    a, b = random_quat(rng, (4,)), random_quat(rng, (4,))
    a0, b0 = a.copy(), b.copy()
    slerp.slerp_path(a, b, 5)
    np.testing.assert_array_equal(a, a0)
    np.testing.assert_array_equal(b, b0)
