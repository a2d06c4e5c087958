"""fk_fast: the blocked / compiled FK gives the same positions as fk_torch and fk (NumPy)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import torch

from motionlab.core import fk, fk_fast, fk_torch, humanoid

PARENTS = tuple(int(p) for p in humanoid.PARENTS)  # 22 joints, branching at hips and chest
J = len(PARENTS)


def _random_quats(rng, shape):
    q = rng.normal(size=shape + (4,))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def _data(rng, batch, num_joints=J, dtype=np.float32):
    rot = _random_quats(rng, batch + (num_joints,)).astype(dtype)
    pos = rng.normal(scale=0.3, size=batch + (num_joints, 3)).astype(dtype)
    return rot, pos


def _t(*arrays):
    return tuple(torch.from_numpy(np.ascontiguousarray(a)) for a in arrays)


# ---------------------------------------------------------------------------------- eager path
@pytest.mark.parametrize("batch, chunk", [((1000,), 256), ((3, 37), 64), ((5,), 16), ((1,), 4096)])
def test_eager_matches_fk_torch_per_frame_local_pos(rng, batch, chunk):
    rot, pos = _t(*_data(rng, batch))
    expected = fk_torch.fk_positions(rot, pos, PARENTS)
    got = fk_fast.fk_positions_fast(rot, pos, PARENTS, chunk=chunk, compile=False)
    assert got.shape == batch + (J, 3)
    assert got.dtype == torch.float32
    torch.testing.assert_close(got, expected, atol=1e-5, rtol=0)


def test_eager_shared_offsets_and_root_pos(rng):
    batch = (4, 53)
    rot, _ = _t(*_data(rng, batch))
    offsets = torch.from_numpy(rng.normal(scale=0.2, size=(J, 3)).astype(np.float32))
    root = torch.from_numpy(rng.normal(size=batch + (3,)).astype(np.float32))
    full = offsets.expand(batch + (J, 3)).clone()
    full[..., 0, :] = root
    expected = fk_torch.fk_positions(rot, full, PARENTS)
    got = fk_fast.fk_positions_fast(rot, offsets, PARENTS, root_pos=root, compile=False)
    torch.testing.assert_close(got, expected, atol=1e-5, rtol=0)
    # the same with per-frame local_pos whose root gets replaced by root_pos
    got_full = fk_fast.fk_positions_fast(
        rot, torch.zeros(batch + (J, 3)) + offsets, PARENTS, root_pos=root, compile=False
    )
    torch.testing.assert_close(got_full, expected, atol=1e-5, rtol=0)


def test_offsets_alone_put_the_root_at_offset_zero(rng):
    rot, _ = _t(*_data(rng, (40,)))
    offsets = torch.from_numpy(rng.normal(size=(J, 3)).astype(np.float32))
    got = fk_fast.fk_positions_fast(rot, offsets, PARENTS, compile=False)
    expected = fk_torch.fk_positions(rot, offsets.expand(40, J, 3), PARENTS)
    torch.testing.assert_close(got, expected, atol=1e-5, rtol=0)
    torch.testing.assert_close(got[:, 0], offsets[0].expand(40, 3))


def test_identity_rotations_give_rest_pose():
    skeleton = humanoid.canonical_skeleton()
    rot = torch.zeros(7, J, 4, dtype=torch.float64)
    rot[..., 0] = 1.0
    got = fk_fast.fk_positions_fast(rot, torch.tensor(skeleton.offsets), skeleton.parents, compile=False)
    np.testing.assert_allclose(got.numpy(), np.broadcast_to(skeleton.rest_positions(), (7, J, 3)), atol=1e-12)


def test_float64_is_exact(rng):
    rot, pos = _t(*_data(rng, (300,), dtype=np.float64))
    got = fk_fast.fk_positions_fast(rot, pos, PARENTS, chunk=128, compile=False)
    assert got.dtype == torch.float64
    torch.testing.assert_close(got, fk_torch.fk_positions(rot, pos, PARENTS), atol=1e-12, rtol=0)


def test_out_is_filled_and_returned(rng):
    rot, pos = _t(*_data(rng, (2, 30)))
    out = torch.full((2, 30, J, 3), float("nan"))
    got = fk_fast.fk_positions_fast(rot, pos, PARENTS, out=out, compile=False)
    assert got is out
    torch.testing.assert_close(out, fk_torch.fk_positions(rot, pos, PARENTS), atol=1e-5, rtol=0)
    with pytest.raises(ValueError, match="out"):
        fk_fast.fk_positions_fast(rot, pos, PARENTS, out=torch.empty(60, J, 3), compile=False)


def test_inputs_are_not_modified(rng):
    rot, pos = _t(*_data(rng, (50,)))
    root = torch.ones(50, 3)
    copies = [t.clone() for t in (rot, pos, root)]
    fk_fast.fk_positions_fast(rot, pos, PARENTS, root_pos=root, chunk=32, compile=False)
    for before, after in zip(copies, (rot, pos, root)):
        assert torch.equal(before, after)


def test_empty_batch():
    got = fk_fast.fk_positions_fast(torch.zeros(0, J, 4), torch.zeros(0, J, 3), PARENTS, compile=False)
    assert got.shape == (0, J, 3)


def test_gradients_fall_back_to_fk_torch(rng):
    rot, pos = _t(*_data(rng, (6,)))
    rot.requires_grad_(True)
    got = fk_fast.fk_positions_fast(rot, pos, PARENTS)
    assert got.requires_grad
    got.sum().backward()
    assert rot.grad is not None and torch.isfinite(rot.grad).all()
    torch.testing.assert_close(got.detach(), fk_torch.fk_positions(rot.detach(), pos, PARENTS), atol=1e-6, rtol=0)


@pytest.mark.parametrize(
    "rot_shape, pos_shape, parents, chunk, match",
    [
        ((10, J, 3), (10, J, 3), PARENTS, 64, "local_rot"),
        ((10, J, 4), (10, J - 1, 3), PARENTS, 64, "local_pos"),
        ((10, J, 4), (10, J, 3), PARENTS[:-1], 64, "parent indices"),
        ((10, J, 4), (10, J, 3), (0,) + PARENTS[1:], 64, "root"),
        ((10, J, 4), (10, J, 3), PARENTS[:5] + (7,) + PARENTS[6:], 64, "precede"),
        ((10, J, 4), (10, J, 3), PARENTS, 40, "multiple of 16"),
        ((10, J, 4), (7, J, 3), PARENTS, 64, "broadcast"),
    ],
)
def test_bad_input_raises_value_error(rot_shape, pos_shape, parents, chunk, match):
    with pytest.raises(ValueError, match=match):
        fk_fast.fk_positions_fast(torch.zeros(rot_shape), torch.zeros(pos_shape), parents, chunk=chunk, compile=False)


def test_numpy_arrays_are_refused_with_a_pointer_to_the_numpy_version():
    with pytest.raises(ValueError, match="fk_positions_fast_np"):
        fk_fast.fk_positions_fast(np.zeros((3, J, 4)), np.zeros((3, J, 3)), PARENTS)


# ---------------------------------------------------------------------------------- NumPy twin
@pytest.mark.parametrize("batch, chunk", [((1000,), 300), ((3, 37), 8192), ((1,), 1)])
def test_numpy_matches_fk(rng, batch, chunk):
    rot, pos = _data(rng, batch)
    got = fk_fast.fk_positions_fast_np(rot, pos, PARENTS, chunk=chunk)
    assert got.shape == batch + (J, 3) and got.dtype == np.float32
    np.testing.assert_allclose(got, fk.fk_positions(rot, pos, PARENTS), atol=1e-5, rtol=0)


def test_numpy_shared_offsets_and_root_pos(rng):
    rot, _ = _data(rng, (2, 45), dtype=np.float64)
    offsets = rng.normal(size=(J, 3))
    root = rng.normal(size=(2, 45, 3))
    full = np.broadcast_to(offsets, (2, 45, J, 3)).copy()
    full[..., 0, :] = root
    got = fk_fast.fk_positions_fast_np(rot, offsets, PARENTS, root_pos=root, chunk=32)
    np.testing.assert_allclose(got, fk.fk_positions(rot, full, PARENTS), atol=1e-12)


@pytest.mark.parametrize(
    "rot_shape, pos_shape, parents, match",
    [
        ((10, J, 3), (10, J, 3), PARENTS, "local_rot"),
        ((10, J, 4), (10, 3), PARENTS, "local_pos"),
        ((10, J, 4), (10, J, 3), PARENTS[1:], "parent indices"),
        ((10, J, 4), (9, J, 3), PARENTS, "broadcast"),
    ],
)
def test_numpy_bad_input_raises_value_error(rot_shape, pos_shape, parents, match):
    with pytest.raises(ValueError, match=match):
        fk_fast.fk_positions_fast_np(np.zeros(rot_shape), np.zeros(pos_shape), parents)


# ---------------------------------------------------------------------------------- compiled path
SMALL_PARENTS = (-1, 0, 1, 2, 1, 4, 0)  # 7 joints with a branch: compiles in seconds, not a minute


@pytest.mark.slow
def test_compiled_matches_fk_torch_with_tail_and_leading_dims(rng):
    """Both compiled variants on a small tree; 3 x 45 = 135 frames is not a multiple of 32."""
    batch, chunk = (3, 45), 32
    rot, pos = _t(*_data(rng, batch, num_joints=len(SMALL_PARENTS)))
    root = pos[..., 0, :].clone()
    offsets = pos[0, 0]
    full = offsets.expand(batch + (len(SMALL_PARENTS), 3)).clone()
    full[..., 0, :] = root
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # a fallback to eager would warn
        got = fk_fast.fk_positions_fast(rot, pos, SMALL_PARENTS, chunk=chunk)
        got_shared = fk_fast.fk_positions_fast(rot, offsets, SMALL_PARENTS, root_pos=root, chunk=chunk)
    assert fk_fast.is_compiled(SMALL_PARENTS, chunk=chunk)
    assert fk_fast.is_compiled(SMALL_PARENTS, chunk=chunk, shared_offsets=True)
    assert 0.0 <= fk_fast.warmup(SMALL_PARENTS, chunk=chunk) < 5.0  # already compiled: one chunk of FK
    torch.testing.assert_close(got, fk_torch.fk_positions(rot, pos, SMALL_PARENTS), atol=1e-5, rtol=0)
    torch.testing.assert_close(got_shared, fk_torch.fk_positions(rot, full, SMALL_PARENTS), atol=1e-5, rtol=0)


def _fresh_state(monkeypatch):
    monkeypatch.setattr(fk_fast, "_kernels", {})
    monkeypatch.setattr(fk_fast, "_warned", False)


def test_failing_torch_compile_warns_once_and_falls_back(rng, monkeypatch):
    _fresh_state(monkeypatch)

    def broken_compile(*args, **kwargs):
        raise RuntimeError("no C++ compiler")

    monkeypatch.setattr(torch, "compile", broken_compile)
    rot, pos = _t(*_data(rng, (70,)))
    with pytest.warns(RuntimeWarning, match="no C\\+\\+ compiler"):
        got = fk_fast.fk_positions_fast(rot, pos, PARENTS, chunk=32)
    torch.testing.assert_close(got, fk_torch.fk_positions(rot, pos, PARENTS), atol=1e-5, rtol=0)
    assert not fk_fast.is_compiled(PARENTS, chunk=32)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # only one warning per session
        fk_fast.fk_positions_fast(rot, pos, PARENTS, chunk=64)


def test_kernel_failing_on_first_call_falls_back(rng, monkeypatch):
    _fresh_state(monkeypatch)

    def compile_that_fails_later(fn, **kwargs):
        def run(*args):
            raise RuntimeError("inductor exploded")

        return run

    monkeypatch.setattr(torch, "compile", compile_that_fails_later)
    rot, pos = _t(*_data(rng, (2, 50)))
    with pytest.warns(RuntimeWarning, match="inductor exploded"):
        got = fk_fast.fk_positions_fast(rot, pos, PARENTS, chunk=32)
    torch.testing.assert_close(got, fk_torch.fk_positions(rot, pos, PARENTS), atol=1e-5, rtol=0)
