"""Tests for motionlab.core.quat_torch: agreement with NumPy, gradients, shapes, errors."""

import numpy as np
import pytest
import torch

from motionlab.core import quat
from motionlab.core import quat_torch as tq
from motionlab.testing import assert_quat_close, random_quat

F64 = torch.float64


@pytest.fixture
def rng():
    return np.random.default_rng(2024)


def t64(x):
    return torch.tensor(np.asarray(x), dtype=F64)


def identity(shape=(), requires_grad=True):
    q = tq.IDENTITY.to(F64).expand(*shape, 4).clone()
    return q.requires_grad_(requires_grad)


# ----------------------------------------------------------------------------- agreement with numpy
def test_same_public_names_as_numpy():
    for name in tq.__all__:
        assert hasattr(quat, name), name
    assert tq.EULER_ORDERS == quat.EULER_ORDERS
    np.testing.assert_array_equal(tq.IDENTITY.numpy(), quat.IDENTITY)


def test_elementwise_functions_agree_with_numpy(rng):
    a, b = random_quat(rng, (4, 5)), random_quat(rng, (4, 5))
    v = rng.normal(size=(4, 5, 3))
    t = rng.uniform(0, 1, size=(4, 5))
    scaled = 2.5 * a
    pairs = {
        "mul": (tq.mul(t64(a), t64(b)), quat.mul(a, b)),
        "conj": (tq.conj(t64(a)), quat.conj(a)),
        "inv": (tq.inv(t64(scaled)), quat.inv(scaled)),
        "normalize": (tq.normalize(t64(scaled)), quat.normalize(scaled)),
        "canonical": (tq.canonical(t64(a)), quat.canonical(a)),
        "rotate": (tq.rotate(t64(a), t64(v)), quat.rotate(a, v)),
        "from_axis_angle": (tq.from_axis_angle(t64(v), t64(t * 3)), quat.from_axis_angle(v, t * 3)),
        "to_matrix": (tq.to_matrix(t64(a)), quat.to_matrix(a)),
        "from_matrix": (tq.from_matrix(t64(quat.to_matrix(a))), quat.from_matrix(quat.to_matrix(a))),
        "slerp": (tq.slerp(t64(a), t64(b), t64(t)), quat.slerp(a, b, t)),
        "angle_between": (tq.angle_between(t64(a), t64(b)), quat.angle_between(a, b)),
        "yaw": (tq.yaw(t64(a)), quat.yaw(a)),
        "from_yaw": (tq.from_yaw(t64(t * 6 - 3)), quat.from_yaw(t * 6 - 3)),
    }
    for name, (ours, ref) in pairs.items():
        assert ours.dtype == F64, name
        np.testing.assert_allclose(ours.numpy(), ref, atol=1e-10, err_msg=name)
    axis_t, angle_t = tq.to_axis_angle(t64(a))
    axis_n, angle_n = quat.to_axis_angle(a)
    np.testing.assert_allclose(axis_t.numpy(), axis_n, atol=1e-10)
    np.testing.assert_allclose(angle_t.numpy(), angle_n, atol=1e-10)


@pytest.mark.parametrize("order", quat.EULER_ORDERS)
def test_euler_agrees_with_numpy(rng, order):
    angles = rng.uniform(-3, 3, size=(50, 3))
    angles[:, 1] = rng.uniform(-1.5, 1.5, size=50)
    np.testing.assert_allclose(tq.from_euler(t64(angles), order).numpy(), quat.from_euler(angles, order), atol=1e-12)
    q = random_quat(rng, (50,))
    np.testing.assert_allclose(tq.to_euler(t64(q), order).numpy(), quat.to_euler(q, order), atol=1e-10)


@pytest.mark.parametrize("order", quat.EULER_ORDERS)
def test_euler_at_gimbal_lock_agrees_and_reproduces(rng, order):
    angles = rng.uniform(-3, 3, size=(20, 3))
    angles[:10, 1] = np.pi / 2
    angles[10:, 1] = -np.pi / 2
    q = quat.from_euler(angles, order)
    back = tq.to_euler(t64(q), order)
    assert torch.isfinite(back).all()
    np.testing.assert_allclose(back.numpy(), quat.to_euler(q, order), atol=1e-10)
    assert_quat_close(tq.from_euler(back, order), q, atol=1e-9)


def test_slerp_tiny_angle_and_antipodal_agree_with_numpy(rng):
    a = random_quat(rng, (10,))
    b = quat.mul(a, quat.from_axis_angle([1.0, 2.0, 3.0], 1e-5))
    for other in (a, b, -a):
        out = tq.slerp(t64(a), t64(other), 0.3)
        assert torch.isfinite(out).all()
        np.testing.assert_allclose(out.numpy(), quat.slerp(a, other, 0.3), atol=1e-12)


def test_torch_slerp_endpoints_and_constant_speed(rng):
    a, b = t64(random_quat(rng, (10, 1))), t64(random_quat(rng, (10, 1)))
    t = torch.linspace(0, 1, 9, dtype=F64)
    out = tq.slerp(a, b, t)
    assert out.shape == (10, 9, 4)
    assert_quat_close(out[:, 0], a[:, 0], atol=1e-12)
    assert_quat_close(out[:, -1], b[:, 0], atol=1e-12)
    travelled = tq.angle_between(a, out)
    np.testing.assert_allclose(travelled.numpy(), (t * tq.angle_between(a, b)).numpy(), atol=1e-9)


def test_torch_algebra_properties(rng):
    a, b = t64(random_quat(rng, (30,))), t64(random_quat(rng, (30,)))
    assert_quat_close(tq.mul(a, tq.inv(a)), quat.IDENTITY, atol=1e-12)
    assert_quat_close(tq.mul(tq.conj(a), a), quat.IDENTITY, atol=1e-12)
    torch.testing.assert_close(tq.to_matrix(tq.mul(a, b)), tq.to_matrix(a) @ tq.to_matrix(b))
    v = t64(rng.normal(size=(30, 3)))
    torch.testing.assert_close(tq.rotate(a, v), (tq.to_matrix(a) @ v[..., None])[..., 0])


# ----------------------------------------------------------------------------- gradients
def _assert_finite_grads(out, *inputs):
    grads = torch.autograd.grad(out.sum(), inputs, allow_unused=False)
    for g in grads:
        assert g is not None
        assert torch.isfinite(g).all(), g


def test_gradients_finite_at_identity():
    v = torch.tensor([0.3, -1.0, 2.0], dtype=F64, requires_grad=True)
    a, b = identity(), identity()
    _assert_finite_grads(tq.mul(a, b), a, b)
    a = identity()
    _assert_finite_grads(tq.rotate(a, v), a, v)
    a = identity()
    _assert_finite_grads(tq.normalize(a), a)
    a = identity()
    _assert_finite_grads(tq.to_matrix(a), a)
    angles = torch.zeros(3, dtype=F64, requires_grad=True)
    _assert_finite_grads(tq.from_euler(angles, "zxy"), angles)


@pytest.mark.parametrize("t", [0.01, 0.5, 0.99])
def test_slerp_gradient_finite_when_inputs_are_equal(t):
    a, b = identity(), identity()
    _assert_finite_grads(tq.slerp(a, b, t), a, b)
    q = torch.tensor(random_quat(np.random.default_rng(1)), dtype=F64)
    a, b = q.clone().requires_grad_(), q.clone().requires_grad_()
    _assert_finite_grads(tq.slerp(a, b, t), a, b)


def test_slerp_gradient_with_respect_to_t_is_finite():
    a = identity(requires_grad=False)
    b = t64(quat.from_axis_angle([0.0, 1.0, 0.0], 1.0))
    t = torch.tensor(0.4, dtype=F64, requires_grad=True)
    _assert_finite_grads(tq.slerp(a, b, t), t)


def test_angle_between_gradient_finite_when_equal(rng):
    a, b = identity(), identity()
    _assert_finite_grads(tq.angle_between(a, b), a, b)
    q = torch.tensor(random_quat(rng, (5,)), dtype=F64)
    a, b = q.clone().requires_grad_(), q.clone().requires_grad_()
    _assert_finite_grads(tq.angle_between(a, b), a, b)
    _assert_finite_grads(tq.angle_between(a, -b), a, b)


def test_gradients_match_finite_differences(rng):
    """torch.autograd.gradcheck on random, well-conditioned inputs."""
    a = t64(random_quat(rng, (3,))).requires_grad_()
    b = t64(random_quat(rng, (3,))).requires_grad_()
    v = t64(rng.normal(size=(3, 3))).requires_grad_()
    e = t64(rng.uniform(-1, 1, size=(3, 3))).requires_grad_()
    assert torch.autograd.gradcheck(tq.mul, (a, b))
    assert torch.autograd.gradcheck(tq.rotate, (a, v))
    assert torch.autograd.gradcheck(tq.to_matrix, (a,))
    assert torch.autograd.gradcheck(tq.normalize, (a,))
    assert torch.autograd.gradcheck(lambda x: tq.from_euler(x, "zxy"), (e,))
    assert torch.autograd.gradcheck(lambda x, y: tq.slerp(x, y, 0.3), (a, b))
    assert torch.autograd.gradcheck(tq.angle_between, (a, b))


# ----------------------------------------------------------------------------- shapes, dtypes, errors
@pytest.mark.parametrize("shape", [(), (5,), (3, 4)])
@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_batch_shapes_and_dtypes(rng, shape, dtype):
    q = torch.tensor(random_quat(rng, shape), dtype=dtype)
    r = torch.tensor(random_quat(rng, shape), dtype=dtype)
    v = torch.tensor(rng.normal(size=shape + (3,)), dtype=dtype)
    t = torch.full(shape, 0.3, dtype=dtype)
    outputs = {
        "mul": (tq.mul(q, r), shape + (4,)),
        "normalize": (tq.normalize(q), shape + (4,)),
        "rotate": (tq.rotate(q, v), shape + (3,)),
        "to_matrix": (tq.to_matrix(q), shape + (3, 3)),
        "from_matrix": (tq.from_matrix(tq.to_matrix(q)), shape + (4,)),
        "from_euler": (tq.from_euler(v, "xzy"), shape + (4,)),
        "to_euler": (tq.to_euler(q, "xzy"), shape + (3,)),
        "slerp": (tq.slerp(q, r, t), shape + (4,)),
        "angle_between": (tq.angle_between(q, r), shape),
        "yaw": (tq.yaw(q), shape),
    }
    for name, (out, expected_shape) in outputs.items():
        assert tuple(out.shape) == expected_shape, name
        assert out.dtype == dtype, name


def test_single_equals_batched(rng):
    q, r = t64(random_quat(rng, (3, 4))), t64(random_quat(rng, (3, 4)))
    v = t64(rng.normal(size=(3, 4, 3)))
    batched = (tq.mul(q, r), tq.rotate(q, v), tq.to_euler(q, "zyx"), tq.slerp(q, r, 0.6))
    for i in range(3):
        for j in range(4):
            single = (
                tq.mul(q[i, j], r[i, j]),
                tq.rotate(q[i, j], v[i, j]),
                tq.to_euler(q[i, j], "zyx"),
                tq.slerp(q[i, j], r[i, j], 0.6),
            )
            for bat, sin in zip(batched, single):
                torch.testing.assert_close(bat[i, j], sin, atol=1e-14, rtol=0)


def test_normalize_zero_raises_unless_unchecked():
    with pytest.raises(ValueError, match="zero-norm"):
        tq.normalize(torch.zeros(2, 4))
    out = tq.normalize(torch.zeros(2, 4), check_zero=False)
    assert torch.isfinite(out).all()
    with pytest.raises(ValueError, match="zero-norm"):
        tq.inv(torch.zeros(4))


@pytest.mark.parametrize(
    "call",
    [
        lambda: tq.mul(torch.zeros(3), tq.IDENTITY),
        lambda: tq.conj(torch.zeros(5, 3)),
        lambda: tq.rotate(tq.IDENTITY, torch.zeros(4)),
        lambda: tq.to_matrix(torch.zeros(4, 3)),
        lambda: tq.from_matrix(torch.eye(4)),
        lambda: tq.from_euler(torch.zeros(4), "xyz"),
        lambda: tq.slerp(torch.zeros(3), tq.IDENTITY, 0.5),
        lambda: tq.angle_between(tq.IDENTITY, torch.zeros(5)),
        lambda: tq.normalize(torch.tensor(1.0)),
    ],
)
def test_bad_shapes_raise_value_error(call):
    with pytest.raises(ValueError, match=r"expected .*got shape"):
        call()


def test_bad_euler_order_raises():
    with pytest.raises(ValueError, match="Euler order"):
        tq.from_euler(torch.zeros(3), "xxz")


def test_functions_do_not_modify_inputs(rng):
    q, r = t64(random_quat(rng, (6,))), t64(random_quat(rng, (6,)))
    v = t64(rng.normal(size=(6, 3)))
    m = tq.to_matrix(q)
    inputs = [q, r, v, m]
    saved = [x.clone() for x in inputs]
    tq.mul(q, r), tq.conj(q), tq.inv(q), tq.normalize(q), tq.canonical(q), tq.rotate(q, v)
    tq.from_matrix(m), tq.to_axis_angle(q), tq.from_axis_angle(v, v[:, 0]), tq.from_euler(v, "zxy")
    tq.to_euler(q, "zxy"), tq.slerp(q, r, 0.5), tq.angle_between(q, r), tq.yaw(q)
    for x, s in zip(inputs, saved):
        torch.testing.assert_close(x, s, atol=0, rtol=0)


def test_integer_tensors_are_read_as_floats():
    out = tq.slerp(torch.tensor([1, 0, 0, 0]), torch.tensor([0, 0, 0, 1]), 0.5)
    torch.testing.assert_close(out, torch.tensor([0.5**0.5, 0.0, 0.0, 0.5**0.5]))
