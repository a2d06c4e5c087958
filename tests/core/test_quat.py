"""Tests for motionlab.core.quat (NumPy quaternions): properties, round trips, known answers."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from motionlab.core import quat
from motionlab.testing import assert_quat_close, random_quat

SHAPES = [(), (5,), (3, 4)]
DTYPES = [np.float32, np.float64]
TOL = {np.float32: 2e-5, np.float64: 1e-12}


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


# explicit rotation matrices, written out by hand (independent of the module under test)
def rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


ROT = {"x": rot_x, "y": rot_y, "z": rot_z}
AXES = {"x": [1.0, 0.0, 0.0], "y": [0.0, 1.0, 0.0], "z": [0.0, 0.0, 1.0]}


def random_euler(rng, n, margin=0.05):
    """Angles away from gimbal lock: first/third in (-π, π), middle in (-π/2, π/2) minus a margin."""
    a = rng.uniform(-np.pi + margin, np.pi - margin, size=(n, 3))
    a[:, 1] = rng.uniform(-np.pi / 2 + margin, np.pi / 2 - margin, size=n)
    return a


# ----------------------------------------------------------------------------- algebra
@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("dtype", DTYPES)
def test_q_times_inverse_is_identity(rng, shape, dtype):
    q = random_quat(rng, shape).astype(dtype)
    for inverse in (quat.inv(q), quat.conj(q)):
        assert_quat_close(quat.mul(q, inverse), quat.IDENTITY, atol=TOL[dtype] * 10)
        assert_quat_close(quat.mul(inverse, q), quat.IDENTITY, atol=TOL[dtype] * 10)


def test_inv_of_non_unit_quaternion(rng):
    q = 3.0 * random_quat(rng, (6,))
    np.testing.assert_allclose(quat.mul(q, quat.inv(q)), np.broadcast_to(quat.IDENTITY, (6, 4)), atol=1e-12)
    np.testing.assert_allclose(quat.inv(q), quat.conj(q) / 9.0, atol=1e-15)


def test_mul_is_associative(rng):
    a, b, c = (random_quat(rng, (20,)) for _ in range(3))
    np.testing.assert_allclose(quat.mul(quat.mul(a, b), c), quat.mul(a, quat.mul(b, c)), atol=1e-12)


def test_mul_is_not_commutative(rng):
    a, b = random_quat(rng, (20,)), random_quat(rng, (20,))
    diff = np.abs(quat.mul(a, b) - quat.mul(b, a)).max(axis=-1)
    assert np.all(diff > 1e-6)


@pytest.mark.parametrize("shape", SHAPES)
def test_product_stays_unit(rng, shape):
    a, b = random_quat(rng, shape), random_quat(rng, shape)
    np.testing.assert_allclose(np.linalg.norm(quat.mul(a, b), axis=-1), 1.0, atol=1e-12)


def test_mul_broadcasts(rng):
    a = random_quat(rng, (5, 1))
    b = random_quat(rng, (3,))
    out = quat.mul(a, b)
    assert out.shape == (5, 3, 4)
    np.testing.assert_allclose(out[2, 1], quat.mul(a[2, 0], b[1]), atol=1e-15)


def test_identity_is_neutral(rng):
    q = random_quat(rng, (10,))
    np.testing.assert_allclose(quat.mul(quat.IDENTITY, q), q, atol=0)
    np.testing.assert_allclose(quat.mul(q, quat.IDENTITY), q, atol=0)


def test_canonical_has_nonnegative_w_and_same_rotation(rng):
    q = random_quat(rng, (50,))
    c = quat.canonical(q)
    assert np.all(c[..., 0] >= 0)
    assert_quat_close(c, q, atol=0)


# ----------------------------------------------------------------------------- rotate / matrices
@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("dtype", DTYPES)
def test_rotate_equals_matrix_times_vector(rng, shape, dtype):
    q = random_quat(rng, shape).astype(dtype)
    v = rng.normal(size=shape + (3,)).astype(dtype)
    expected = np.einsum("...ij,...j->...i", quat.to_matrix(q), v)
    out = quat.rotate(q, v)
    assert out.shape == shape + (3,)
    assert out.dtype == dtype
    np.testing.assert_allclose(out, expected, atol=TOL[dtype] * 10)


def test_rotate_preserves_length_and_broadcasts(rng):
    q = random_quat(rng, (7, 1))
    v = rng.normal(size=(5, 3))
    out = quat.rotate(q, v)
    assert out.shape == (7, 5, 3)
    np.testing.assert_allclose(np.linalg.norm(out, axis=-1), np.broadcast_to(np.linalg.norm(v, axis=-1), (7, 5)))


def test_rotate_by_q_and_minus_q_agree(rng):
    q = random_quat(rng, (10,))
    v = rng.normal(size=(10, 3))
    np.testing.assert_allclose(quat.rotate(q, v), quat.rotate(-q, v), atol=1e-12)


def test_rotate_composes_like_mul(rng):
    a, b = random_quat(rng, (10,)), random_quat(rng, (10,))
    v = rng.normal(size=(10, 3))
    np.testing.assert_allclose(quat.rotate(quat.mul(a, b), v), quat.rotate(a, quat.rotate(b, v)), atol=1e-12)


@pytest.mark.parametrize("shape", SHAPES)
def test_to_matrix_of_product_is_matrix_product(rng, shape):
    a, b = random_quat(rng, shape), random_quat(rng, shape)
    np.testing.assert_allclose(quat.to_matrix(quat.mul(a, b)), quat.to_matrix(a) @ quat.to_matrix(b), atol=1e-12)


def test_to_matrix_is_a_rotation(rng):
    m = quat.to_matrix(random_quat(rng, (30,)))
    np.testing.assert_allclose(m @ np.swapaxes(m, -1, -2), np.broadcast_to(np.eye(3), (30, 3, 3)), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(m), 1.0, atol=1e-12)


def test_to_matrix_known_answers():
    for name, axis in AXES.items():
        for angle in (0.3, -1.2, np.pi):
            m = quat.to_matrix(quat.from_axis_angle(axis, angle))
            np.testing.assert_allclose(m, ROT[name](angle), atol=1e-12)


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("dtype", DTYPES)
def test_matrix_quat_matrix(rng, shape, dtype):
    """matrix -> quat -> matrix"""
    m = quat.to_matrix(random_quat(rng, shape)).astype(dtype)
    q = quat.from_matrix(m)
    assert q.shape == shape + (4,)
    assert q.dtype == dtype
    assert np.all(q[..., 0] >= 0)
    np.testing.assert_allclose(quat.to_matrix(q), m, atol=TOL[dtype] * 10)


def test_quat_matrix_quat(rng):
    """quat -> matrix -> quat (up to sign)"""
    q = random_quat(rng, (200,))
    assert_quat_close(quat.from_matrix(quat.to_matrix(q)), q, atol=1e-12)


@pytest.mark.parametrize("axis", [[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [1.0, -2.0, 0.5]])
@pytest.mark.parametrize("angle", [np.pi, np.pi - 1e-7, 1e-8, 0.0])
def test_from_matrix_at_180_degrees_and_near_identity(axis, angle):
    """Each branch of the stable matrix -> quaternion conversion (w≈0 at 180°, x/y/z largest)."""
    q = quat.from_axis_angle(axis, angle)
    assert_quat_close(quat.from_matrix(quat.to_matrix(q)), q, atol=1e-9)


# ----------------------------------------------------------------------------- axis-angle
@pytest.mark.parametrize("shape", SHAPES)
def test_axis_angle_round_trip(rng, shape):
    """quat -> axis-angle -> quat"""
    q = random_quat(rng, shape)
    axis, angle = quat.to_axis_angle(q)
    assert axis.shape == shape + (3,)
    assert angle.shape == shape
    assert np.all((angle >= 0) & (angle <= np.pi))
    np.testing.assert_allclose(np.linalg.norm(axis, axis=-1), 1.0, atol=1e-12)
    assert_quat_close(quat.from_axis_angle(axis, angle), q, atol=1e-12)


def test_axis_angle_known_values(rng):
    axis = rng.normal(size=(20, 3))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    angle = rng.uniform(0.01, np.pi - 0.01, size=20)
    axis_back, angle_back = quat.to_axis_angle(quat.from_axis_angle(axis, angle))
    np.testing.assert_allclose(angle_back, angle, atol=1e-12)
    np.testing.assert_allclose(axis_back, axis, atol=1e-12)


def test_from_axis_angle_normalises_axis():
    q = quat.from_axis_angle([0.0, 0.0, 5.0], np.pi / 2)
    np.testing.assert_allclose(q, [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)], atol=1e-15)


def test_axis_angle_of_identity_and_half_turn():
    axis, angle = quat.to_axis_angle(quat.IDENTITY)
    assert angle == 0.0
    np.testing.assert_array_equal(axis, [1.0, 0.0, 0.0])
    axis, angle = quat.to_axis_angle(quat.from_axis_angle([0.0, 1.0, 0.0], np.pi))
    assert angle == pytest.approx(np.pi)
    np.testing.assert_allclose(np.abs(axis), [0.0, 1.0, 0.0], atol=1e-12)


def test_axis_angle_angle_above_pi_wraps(rng):
    """A rotation by 3π/2 about z is the rotation by π/2 about -z."""
    axis, angle = quat.to_axis_angle(quat.from_axis_angle([0.0, 0.0, 1.0], 1.5 * np.pi))
    assert angle == pytest.approx(0.5 * np.pi)
    np.testing.assert_allclose(axis, [0.0, 0.0, -1.0], atol=1e-12)


def test_from_axis_angle_zero_axis_raises():
    with pytest.raises(ValueError, match="zero length"):
        quat.from_axis_angle([0.0, 0.0, 0.0], 1.0)


# ----------------------------------------------------------------------------- Euler
@pytest.mark.parametrize("order", quat.EULER_ORDERS)
def test_euler_meaning_against_explicit_matrices(rng, order):
    """from_euler(angles, order) is R_first(a0) @ R_second(a1) @ R_third(a2) (BVH, intrinsic)."""
    for a in random_euler(rng, 10, margin=0.0):
        expected = ROT[order[0]](a[0]) @ ROT[order[1]](a[1]) @ ROT[order[2]](a[2])
        np.testing.assert_allclose(quat.to_matrix(quat.from_euler(a, order)), expected, atol=1e-12)


@pytest.mark.parametrize("order", quat.EULER_ORDERS)
@pytest.mark.parametrize("slot", [0, 1, 2])
def test_euler_single_angle_is_rotation_about_that_axis(order, slot):
    """E.g. from_euler([a, 0, 0], "zxy") is the rotation by a about z."""
    angles = np.zeros(3)
    angles[slot] = 0.7
    expected = quat.from_axis_angle(AXES[order[slot]], 0.7)
    assert_quat_close(quat.from_euler(angles, order), expected, atol=1e-15)


def test_euler_zxy_known_answer():
    a = 0.4
    assert_quat_close(quat.from_euler([a, 0.0, 0.0], "zxy"), [np.cos(a / 2), 0.0, 0.0, np.sin(a / 2)], atol=1e-15)
    # R = Rx(90°) @ Ry(90°): the last-listed angle acts on the vector first.
    # Ry(90°) takes +z to +x, then Rx(90°) leaves +x alone.
    q = quat.from_euler([0.0, np.pi / 2, np.pi / 2], "zxy")
    np.testing.assert_allclose(quat.rotate(q, [0.0, 0.0, 1.0]), [1.0, 0.0, 0.0], atol=1e-12)


@pytest.mark.parametrize("order", quat.EULER_ORDERS)
def test_euler_round_trip(rng, order):
    """euler -> quat -> euler, away from gimbal lock"""
    angles = random_euler(rng, 200)
    back = quat.to_euler(quat.from_euler(angles, order), order)
    np.testing.assert_allclose(back, angles, atol=1e-10)


@pytest.mark.parametrize("order", quat.EULER_ORDERS)
def test_quat_euler_quat_round_trip(rng, order):
    """quat -> euler -> quat, for any rotation"""
    q = random_quat(rng, (200,))
    angles = quat.to_euler(q, order)
    assert np.all(np.abs(angles[:, 1]) <= np.pi / 2 + 1e-12)
    assert_quat_close(quat.from_euler(angles, order), q, atol=1e-10)


@settings(max_examples=60, deadline=None)
@given(
    order=st.sampled_from(quat.EULER_ORDERS),
    a0=st.floats(-3.1, 3.1),
    a1=st.floats(-1.5, 1.5),
    a2=st.floats(-3.1, 3.1),
)
def test_euler_round_trip_hypothesis(order, a0, a1, a2):
    """euler -> quat -> euler for arbitrary angles in the principal range"""
    angles = np.array([a0, a1, a2])
    np.testing.assert_allclose(quat.to_euler(quat.from_euler(angles, order), order), angles, atol=1e-9)


@pytest.mark.parametrize("order", quat.EULER_ORDERS)
@pytest.mark.parametrize("middle", [np.pi / 2, -np.pi / 2])
def test_gimbal_lock_gives_valid_angles(rng, order, middle):
    """At gimbal lock the triple is finite, the third angle is 0, and it reproduces the rotation."""
    angles = rng.uniform(-np.pi, np.pi, size=(50, 3))
    angles[:, 1] = middle
    q = quat.from_euler(angles, order)
    back = quat.to_euler(q, order)
    assert np.all(np.isfinite(back))
    np.testing.assert_allclose(back[:, 1], middle, atol=1e-6)
    np.testing.assert_allclose(back[:, 2], 0.0, atol=1e-12)
    assert_quat_close(quat.from_euler(back, order), q, atol=1e-9)


@pytest.mark.parametrize("order", quat.EULER_ORDERS)
@pytest.mark.parametrize("distance", [1e-10, 1e-8, 1e-6, 1e-5, 1e-4, 1e-3])
def test_near_gimbal_lock_reproduces_rotation(rng, order, distance):
    """Close to (but not at) gimbal lock the angles still rebuild the same rotation."""
    angles = rng.uniform(-np.pi, np.pi, size=(50, 3))
    angles[:, 1] = np.where(rng.random(50) < 0.5, 1.0, -1.0) * (np.pi / 2 - distance)
    q = quat.from_euler(angles, order)
    back = quat.to_euler(q, order)
    assert np.all(np.isfinite(back))
    # half-angle tolerance: 1e-7 rad of rotation is far below anything visible
    assert np.max(quat.angle_between(quat.from_euler(back, order), q)) < 1e-7


def test_euler_order_is_case_insensitive_and_checked():
    np.testing.assert_array_equal(quat.from_euler([0.1, 0.2, 0.3], "ZXY"), quat.from_euler([0.1, 0.2, 0.3], "zxy"))
    for bad in ("xyx", "abc", "xy"):
        with pytest.raises(ValueError, match="Euler order"):
            quat.from_euler([0.1, 0.2, 0.3], bad)
        with pytest.raises(ValueError, match="Euler order"):
            quat.to_euler(quat.IDENTITY, bad)


# ----------------------------------------------------------------------------- slerp
def test_slerp_endpoints(rng):
    a, b = random_quat(rng, (50,)), random_quat(rng, (50,))
    np.testing.assert_allclose(quat.slerp(a, b, 0.0), a, atol=1e-12)
    assert_quat_close(quat.slerp(a, b, 1.0), b, atol=1e-12)


def test_slerp_takes_shortest_arc(rng):
    a, b = random_quat(rng, (50,)), random_quat(rng, (50,))
    for t in (0.25, 0.5, 0.9):
        assert_quat_close(quat.slerp(a, -b, t), quat.slerp(a, b, t), atol=1e-12)
        # along the short arc, the rotation angle travelled is t times the angle between them
        np.testing.assert_allclose(quat.angle_between(a, quat.slerp(a, b, t)), t * quat.angle_between(a, b), atol=1e-7)


def test_slerp_antipodal_inputs_are_the_same_rotation(rng):
    a = random_quat(rng, (10,))
    for t in (0.0, 0.3, 1.0):
        out = quat.slerp(a, -a, t)
        assert np.all(np.isfinite(out))
        assert_quat_close(out, a, atol=1e-12)


def test_slerp_constant_angular_speed(rng):
    a, b = random_quat(rng, (20,)), random_quat(rng, (20,))
    t = np.linspace(0.0, 1.0, 11)
    out = quat.slerp(a[:, None], b[:, None], t[None, :])
    assert out.shape == (20, 11, 4)
    travelled = quat.angle_between(a[:, None], out)
    expected = t[None, :] * quat.angle_between(a, b)[:, None]
    np.testing.assert_allclose(travelled, expected, atol=1e-7)


@settings(max_examples=40, deadline=None)
@given(angle=st.floats(1e-3, np.pi - 1e-3), t=st.floats(0.0, 1.0), seed=st.integers(0, 2**31))
def test_slerp_about_one_axis_is_angle_times_t(angle, t, seed):
    """slerp(a, a·R(θ), t) = a·R(tθ), with any start a (left invariance) and any axis"""
    rng = np.random.default_rng(seed)
    a = random_quat(rng)
    axis = rng.normal(size=3)
    b = quat.mul(a, quat.from_axis_angle(axis, angle))
    assert_quat_close(quat.slerp(a, b, t), quat.mul(a, quat.from_axis_angle(axis, t * angle)), atol=1e-9)


def test_slerp_left_invariance(rng):
    a, b, c = (random_quat(rng, (20,)) for _ in range(3))
    assert_quat_close(quat.slerp(quat.mul(c, a), quat.mul(c, b), 0.3), quat.mul(c, quat.slerp(a, b, 0.3)), atol=1e-10)


@pytest.mark.parametrize("angle", [0.0, 1e-12, 1e-9, 1e-7])
def test_slerp_tiny_angle_is_finite(rng, angle):
    a = random_quat(rng, (10,))
    b = quat.mul(a, quat.from_axis_angle([0.3, -1.0, 0.2], angle))
    for t in (0.0, 0.5, 1.0):
        out = quat.slerp(a, b, t)
        assert np.all(np.isfinite(out))
        np.testing.assert_allclose(np.linalg.norm(out, axis=-1), 1.0, atol=1e-12)
        assert_quat_close(out, a, atol=1e-6)


def test_slerp_result_is_unit_and_dtype_kept(rng):
    a, b = random_quat(rng, (3, 4)), random_quat(rng, (3, 4))
    for dtype in DTYPES:
        out = quat.slerp(a.astype(dtype), b.astype(dtype), np.full((3, 4), 0.4))
        assert out.dtype == dtype
        assert out.shape == (3, 4, 4)
        np.testing.assert_allclose(np.linalg.norm(out, axis=-1), 1.0, atol=TOL[dtype] * 10)


# ----------------------------------------------------------------------------- angle_between
def test_angle_between_known_values():
    z = [0.0, 0.0, 1.0]
    assert quat.angle_between(quat.IDENTITY, quat.from_axis_angle(z, 0.5)) == pytest.approx(0.5)
    assert quat.angle_between(quat.IDENTITY, quat.from_axis_angle(z, np.pi)) == pytest.approx(np.pi)
    # 3π/2 one way is π/2 the other way
    assert quat.angle_between(quat.IDENTITY, quat.from_axis_angle(z, 1.5 * np.pi)) == pytest.approx(0.5 * np.pi)
    a = quat.from_axis_angle([1.0, 0.0, 0.0], 0.2)
    b = quat.from_axis_angle([1.0, 0.0, 0.0], -0.3)
    assert quat.angle_between(a, b) == pytest.approx(0.5)
    assert quat.angle_between(a, -a) == pytest.approx(0.0, abs=1e-7)


def test_angle_between_is_symmetric_and_invariant(rng):
    a, b, c = (random_quat(rng, (30,)) for _ in range(3))
    np.testing.assert_allclose(quat.angle_between(a, b), quat.angle_between(b, a), atol=1e-12)
    np.testing.assert_allclose(quat.angle_between(quat.mul(c, a), quat.mul(c, b)), quat.angle_between(a, b), atol=1e-7)
    _, angle = quat.to_axis_angle(quat.mul(quat.conj(a), b))
    np.testing.assert_allclose(quat.angle_between(a, b), angle, atol=1e-7)


# ----------------------------------------------------------------------------- normalize
def test_normalize_gives_unit_length(rng):
    q = rng.normal(size=(3, 4, 4)) * 7.0
    n = quat.normalize(q)
    np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-12)
    np.testing.assert_allclose(n * np.linalg.norm(q, axis=-1, keepdims=True), q, atol=1e-12)


def test_normalize_zero_quaternion_raises_not_nan():
    with pytest.raises(ValueError, match="zero-norm"):
        quat.normalize(np.zeros(4))
    batch = np.tile(quat.IDENTITY, (3, 1))
    batch[1] = 0.0
    with pytest.raises(ValueError, match=r"index \(1,\)"):
        quat.normalize(batch)
    with pytest.raises(ValueError):
        quat.normalize([np.nan, 0.0, 0.0, 0.0])


def test_inv_zero_quaternion_raises():
    with pytest.raises(ValueError, match="zero-norm"):
        quat.inv(np.zeros(4))


# ----------------------------------------------------------------------------- between, yaw, xyzw
def test_between_maps_u_onto_v(rng):
    u, v = rng.normal(size=(40, 3)), rng.normal(size=(40, 3))
    q = quat.between(u, v)
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-12)
    np.testing.assert_allclose(
        quat.rotate(q, u / np.linalg.norm(u, axis=-1, keepdims=True)),
        v / np.linalg.norm(v, axis=-1, keepdims=True),
        atol=1e-12,
    )


def test_between_parallel_and_antiparallel():
    assert_quat_close(quat.between([0.0, 2.0, 0.0], [0.0, 1.0, 0.0]), quat.IDENTITY, atol=1e-12)
    for u in ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.3, -0.2, 0.9]):
        u = np.array(u)
        q = quat.between(u, -u)
        np.testing.assert_allclose(quat.rotate(q, u), -u, atol=1e-12)
        assert quat.angle_between(quat.IDENTITY, q) == pytest.approx(np.pi)


def test_yaw_round_trip(rng):
    angle = rng.uniform(-np.pi + 1e-6, np.pi - 1e-6, size=30)
    np.testing.assert_allclose(quat.yaw(quat.from_yaw(angle)), angle, atol=1e-12)
    # a pitch (about x) after the heading does not change the heading, if it is not past vertical
    pitched = quat.mul(quat.from_yaw(angle), quat.from_axis_angle([1.0, 0.0, 0.0], 0.4))
    np.testing.assert_allclose(quat.yaw(pitched), angle, atol=1e-12)


def test_xyzw_round_trip(rng):
    q = random_quat(rng, (3, 4))
    np.testing.assert_array_equal(quat.from_xyzw(quat.to_xyzw(q)), q)
    np.testing.assert_array_equal(quat.to_xyzw(q)[..., 3], q[..., 0])


# ----------------------------------------------------------------------------- shapes, dtypes, errors
@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("dtype", DTYPES)
def test_batch_shapes_and_dtypes(rng, shape, dtype):
    q = random_quat(rng, shape).astype(dtype)
    r = random_quat(rng, shape).astype(dtype)
    e = rng.uniform(-1, 1, size=shape + (3,)).astype(dtype)
    t = np.full(shape, 0.3, dtype=dtype)
    outputs = {
        "mul": (quat.mul(q, r), shape + (4,)),
        "conj": (quat.conj(q), shape + (4,)),
        "inv": (quat.inv(q), shape + (4,)),
        "normalize": (quat.normalize(q), shape + (4,)),
        "canonical": (quat.canonical(q), shape + (4,)),
        "to_matrix": (quat.to_matrix(q), shape + (3, 3)),
        "from_matrix": (quat.from_matrix(quat.to_matrix(q)), shape + (4,)),
        "from_euler": (quat.from_euler(e, "zyx"), shape + (4,)),
        "to_euler": (quat.to_euler(q, "zyx"), shape + (3,)),
        "from_axis_angle": (quat.from_axis_angle(e + 2.0, t), shape + (4,)),
        "slerp": (quat.slerp(q, r, t), shape + (4,)),
        "angle_between": (quat.angle_between(q, r), shape),
        "yaw": (quat.yaw(q), shape),
        "xyzw": (quat.to_xyzw(q), shape + (4,)),
    }
    for name, (out, expected_shape) in outputs.items():
        assert out.shape == expected_shape, name
        assert out.dtype == dtype, name


def test_single_equals_batched(rng):
    q, r = random_quat(rng, (3, 4)), random_quat(rng, (3, 4))
    e = random_euler(rng, 12).reshape(3, 4, 3)
    v = rng.normal(size=(3, 4, 3))
    batched = {
        "mul": quat.mul(q, r),
        "rotate": quat.rotate(q, v),
        "to_matrix": quat.to_matrix(q),
        "from_euler": quat.from_euler(e, "yzx"),
        "to_euler": quat.to_euler(q, "yzx"),
        "slerp": quat.slerp(q, r, 0.7),
        "angle_between": quat.angle_between(q, r),
    }
    for i in range(3):
        for j in range(4):
            single = {
                "mul": quat.mul(q[i, j], r[i, j]),
                "rotate": quat.rotate(q[i, j], v[i, j]),
                "to_matrix": quat.to_matrix(q[i, j]),
                "from_euler": quat.from_euler(e[i, j], "yzx"),
                "to_euler": quat.to_euler(q[i, j], "yzx"),
                "slerp": quat.slerp(q[i, j], r[i, j], 0.7),
                "angle_between": quat.angle_between(q[i, j], r[i, j]),
            }
            for name, value in single.items():
                np.testing.assert_allclose(batched[name][i, j], value, atol=1e-14, err_msg=name)


def test_integer_input_is_promoted_to_float():
    out = quat.mul([1, 0, 0, 0], [0, 1, 0, 0])
    assert out.dtype == np.float64
    np.testing.assert_array_equal(out, [0.0, 1.0, 0.0, 0.0])


@pytest.mark.parametrize(
    "call",
    [
        lambda: quat.mul(np.zeros(3), quat.IDENTITY),
        lambda: quat.mul(quat.IDENTITY, np.zeros((5, 3))),
        lambda: quat.conj(np.zeros((2, 5))),
        lambda: quat.normalize(np.float64(1.0)),
        lambda: quat.rotate(quat.IDENTITY, np.zeros(4)),
        lambda: quat.rotate(np.zeros(3), np.zeros(3)),
        lambda: quat.to_matrix(np.zeros((4, 3))),
        lambda: quat.from_matrix(np.eye(4)),
        lambda: quat.from_matrix(np.zeros(3)),
        lambda: quat.from_euler(np.zeros(4), "xyz"),
        lambda: quat.to_euler(np.zeros(3), "xyz"),
        lambda: quat.slerp(np.zeros(3), quat.IDENTITY, 0.5),
        lambda: quat.angle_between(quat.IDENTITY, np.zeros(5)),
        lambda: quat.from_axis_angle(np.zeros(4), 0.5),
        lambda: quat.between(np.zeros(2), np.ones(3)),
        lambda: quat.to_xyzw(np.zeros(3)),
    ],
)
def test_bad_shapes_raise_value_error_with_message(call):
    with pytest.raises(ValueError, match=r"expected .*got shape"):
        call()


def test_error_message_shows_the_shape():
    with pytest.raises(ValueError, match=r"\(\.\.\., 4\).*\(5, 3\)"):
        quat.mul(np.zeros((5, 3)), quat.IDENTITY)


# ----------------------------------------------------------------------------- purity
def test_functions_do_not_modify_inputs(rng):
    q, r = random_quat(rng, (6,)), random_quat(rng, (6,))
    v, e = rng.normal(size=(6, 3)), random_euler(rng, 6)
    t = np.linspace(0, 1, 6)
    m = quat.to_matrix(q)
    inputs = [q, r, v, e, t, m]
    saved = [x.copy() for x in inputs]
    for x in inputs:
        x.setflags(write=False)  # an in-place write would raise
    quat.mul(q, r), quat.conj(q), quat.inv(q), quat.normalize(q), quat.canonical(q)
    quat.rotate(q, v), quat.to_matrix(q), quat.from_matrix(m), quat.to_axis_angle(q), quat.from_axis_angle(v, t)
    quat.from_euler(e, "zxy"), quat.to_euler(q, "zxy"), quat.slerp(q, r, t), quat.slerp(q, -q, t)
    quat.angle_between(q, r), quat.between(v, -v), quat.yaw(q), quat.from_yaw(t)
    quat.to_xyzw(q), quat.from_xyzw(q)
    for x, s in zip(inputs, saved):
        np.testing.assert_array_equal(x, s)


# ----------------------------------------------------------------------------- motionlab.testing helpers
def test_assert_quat_close_is_sign_agnostic_and_catches_differences(rng):
    q = random_quat(rng, (4,))
    assert_quat_close(q, -q, atol=0)
    assert_quat_close(q, np.concatenate([q[:2], -q[2:]]), atol=0)
    other = q.copy()
    other[2] = quat.mul(other[2], quat.from_axis_angle([0.0, 1.0, 0.0], 0.01))
    with pytest.raises(AssertionError, match="index"):
        assert_quat_close(q, other, atol=1e-4)
    with pytest.raises(AssertionError):
        assert_quat_close(q, np.full_like(q, np.nan))
    with pytest.raises(AssertionError, match="shapes"):
        assert_quat_close(q, q[:3])


def test_random_quat_is_unit_and_covers_both_hemispheres(rng):
    q = random_quat(rng, (2000,))
    assert q.shape == (2000, 4)
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-12)
    assert 0.4 < np.mean(q[:, 0] > 0) < 0.6
    # uniform on SO(3) means uniform on the unit 3-sphere, where the mean of |w| is 4/(3π) ≈ 0.424
    assert np.mean(np.abs(q[:, 0])) == pytest.approx(4 / (3 * np.pi), abs=0.02)
    assert random_quat(rng).shape == (4,)
    assert random_quat(rng, 3).shape == (3, 4)


def test_from_matrix_refuses_a_reflection_and_a_scaled_matrix():
    import torch

    from motionlab.core import quat_torch

    for m in (np.diag([1.0, 1.0, -1.0]), 2.0 * np.eye(3), -np.eye(3)):
        with pytest.raises(ValueError, match="rotation matrices"):
            quat.from_matrix(m)
        with pytest.raises(ValueError, match="rotation matrices"):
            quat_torch.from_matrix(torch.as_tensor(m))


def test_between_nearly_opposite_directions_and_small_angles_are_accurate():
    u = np.array([1.0, 0.0, 0.0])
    d = 3e-5
    v = np.array([-np.cos(d), np.sin(d), 0.0])
    np.testing.assert_allclose(quat.rotate(quat.between(u, v), u), v, atol=1e-10)  # was 4.5e-5 off
    a = quat.from_axis_angle(np.array([0.0, 1.0, 0.0], np.float32), np.float32(0.0))
    b = quat.from_axis_angle(np.array([0.0, 1.0, 0.0], np.float32), np.float32(1e-3))
    assert float(quat.angle_between(a, b)) == pytest.approx(1e-3, rel=1e-4)
