"""The network's pieces: shapes, unit quaternions, the Hamilton correction and FK."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from motionlab import testing
from motionlab.core import fk, fk_torch, humanoid
from motionlab.core import quat_torch as tq
from motionlab.retargeting.model import ModelConfig, RetargetNet, fk_by_level, skeleton_tensor

TINY = ModelConfig(latent=8, hidden=16, skel_embed=4, kernel=3, layers=2)

B, T, J = 3, 24, 22


@pytest.fixture
def net():
    torch.manual_seed(0)
    return RetargetNet(TINY)


@pytest.fixture
def x():
    return torch.randn(B, T, 70, generator=torch.Generator().manual_seed(1))


def _unit(q, atol=1e-5):
    np.testing.assert_allclose(q.norm(dim=-1).detach().numpy(), 1.0, atol=atol)


def test_every_quaternion_output_has_shape_and_unit_norm(net, x):
    offsets = torch.tensor(humanoid.canonical_skeleton().offsets, dtype=torch.float32)
    phi = net.encode(x)
    assert phi.shape == (B, T, TINY.latent)
    q = net.rotations(phi)
    emb = net.skeleton_embedding(offsets)
    dq = net.correction(phi, emb)
    assert q.shape == dq.shape == (B, T, J, 4)
    assert emb.shape == (1, TINY.skel_embed)
    _unit(q), _unit(dq), _unit(emb)
    out = net.decode(phi, offsets)
    assert out.local_rot.shape == (B, T, J, 4) and out.positions.shape == (B, T, J, 3)
    _unit(out.local_rot), _unit(out.q), _unit(out.q_delta)


def test_per_sample_skeletons_broadcast(net, x):
    base = torch.tensor(humanoid.canonical_skeleton().offsets, dtype=torch.float32)
    offsets = torch.stack([base, base * 1.2, base * 0.8])
    out = net(x, offsets)
    assert out.positions.shape == (B, T, J, 3)
    assert net.skeleton_embedding(offsets).shape == (B, TINY.skel_embed)


def test_encoder_is_fully_convolutional(net):
    """Any clip length works, and a frame's latent only depends on nearby frames."""
    long = torch.randn(1, 200, 70)
    phi = net.encode(long)
    assert phi.shape == (1, 200, TINY.latent)
    reach = TINY.layers * (TINY.kernel // 2)
    changed = long.clone()
    changed[:, 150:] += 1.0
    np.testing.assert_allclose(
        net.encode(changed)[:, : 150 - reach].detach(), phi[:, : 150 - reach].detach(), atol=1e-6
    )


def test_identity_correction_leaves_q_unchanged(net, x):
    q = net.rotations(net.encode(x))
    identity = tq.IDENTITY.expand_as(q)
    testing.assert_quat_close(net.combine(q, identity), q, atol=1e-6)


def test_untrained_correction_is_identity(net, x):
    """F_Δ starts at zero weights with bias (1, 0, 0, 0): the identity for any skeleton."""
    dq = net.correction(net.encode(x), net.skeleton_embedding(torch.randn(22, 3)))
    testing.assert_quat_close(dq, tq.IDENTITY.expand_as(dq), atol=1e-6)


def test_combine_is_the_hamilton_product(net):
    g = torch.Generator().manual_seed(3)
    a, b = tq.normalize(torch.randn(5, 4, generator=g)), tq.normalize(torch.randn(5, 4, generator=g))
    testing.assert_quat_close(net.combine(a, b), tq.mul(a, b))
    # rotating by q ⊗ qΔ = rotating by qΔ first, then q
    v = torch.randn(5, 3, generator=g)
    np.testing.assert_allclose(tq.rotate(net.combine(a, b), v), tq.rotate(a, tq.rotate(b, v)), atol=1e-5)


def test_decoder_fk_equals_the_foundation_fk(net, x):
    skeleton = humanoid.scale_bones(humanoid.canonical_skeleton(), legs=1.3, arms=0.8)
    offsets = skeleton_tensor(skeleton)
    out = net.decode(net.encode(x), offsets)
    ref = fk_torch.fk_positions(out.local_rot, offsets, humanoid.PARENTS)
    np.testing.assert_allclose(out.positions.detach(), ref.detach(), atol=1e-5)
    ref_np = fk.fk_positions(out.local_rot.detach().double().numpy(), offsets.double().numpy(), humanoid.PARENTS)
    np.testing.assert_allclose(out.positions.detach().numpy(), ref_np, atol=1e-5)
    np.testing.assert_allclose(out.positions[..., 0, :].detach(), 0.0)  # root at the origin


def test_fk_by_level_on_a_random_tree_float64():
    rng = np.random.default_rng(0)
    sk = testing.random_skeleton(rng, 9) if hasattr(testing, "random_skeleton") else None
    parents = sk.parents if sk is not None else np.array([-1, 0, 1, 0, 3, 4, 1, 6, 2])
    q = tq.normalize(torch.randn(4, len(parents), 4, dtype=torch.float64))
    off = torch.randn(len(parents), 3, dtype=torch.float64)
    np.testing.assert_allclose(fk_by_level(q, off, parents), fk_torch.fk_positions(q, off, parents), atol=1e-12)


def test_fk_by_level_with_the_gpus_summed_products_equals_it_with_matmul():
    """On CUDA FK composes its 3×3 products as broadcast sums (``model.summed_product``); run here
    on the CPU, they give the same positions and gradients, offsets broadcast over the batch."""
    from motionlab.retargeting.model import summed_product

    parents = humanoid.PARENTS
    gen = torch.Generator().manual_seed(1)
    q0 = tq.normalize(torch.randn(3, 5, len(parents), 4, dtype=torch.float64, generator=gen))
    off = torch.randn(len(parents), 3, dtype=torch.float64, generator=gen)
    results = []
    for product in (None, summed_product):  # None: the CPU's default, torch.matmul
        q = q0.clone().requires_grad_()
        pos = fk_by_level(q, off, parents, product=product)
        pos.square().sum().backward()
        results.append((pos.detach(), q.grad))
    (pos_mm, grad_mm), (pos_sum, grad_sum) = results
    assert pos_sum.shape == (3, 5, len(parents), 3)
    np.testing.assert_allclose(pos_sum, pos_mm, rtol=0, atol=1e-12)
    np.testing.assert_allclose(grad_sum, grad_mm, rtol=0, atol=1e-11)
    a, b = torch.randn(7, 3, 3, dtype=torch.float64), torch.randn(7, 3, 1, dtype=torch.float64)
    np.testing.assert_allclose(summed_product(a, b), a @ b, rtol=0, atol=1e-14)


def test_gradients_are_finite(net, x):
    out = net(x, torch.tensor(humanoid.canonical_skeleton().offsets, dtype=torch.float32))
    out.positions.square().sum().backward()
    assert all(torch.isfinite(p.grad).all() for p in net.parameters() if p.grad is not None)


def test_bad_inputs_are_refused(net):
    with pytest.raises(ValueError, match="70"):
        net.encode(torch.randn(2, 10, 69))
    with pytest.raises(ValueError, match="22, 3"):
        skeleton_tensor(np.zeros((21, 3)))
    with pytest.raises(ValueError, match="kernel"):
        ModelConfig(kernel=4)
