"""Training on one character: overfitting, reproducibility, callbacks, data checks."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from motionlab import synthetic
from motionlab.core import humanoid
from motionlab.retargeting.model import ModelConfig, RetargetNet
from motionlab.retargeting.train import (
    TrainConfig,
    TrainingSet,
    random_offsets,
    random_turns,
    train,
    training_set,
    turned_window,
)

TINY = ModelConfig(latent=8, hidden=16, skel_embed=4, kernel=3, layers=2)


def _one_window(data: TrainingSet) -> TrainingSet:
    return TrainingSet(
        data.x[:1], data.positions[:1], data.local_rot[:1], data.skeleton, data.stats, data.fps, data.window, data.names
    )


def test_training_set_shapes(data):
    n, w = data.x.shape[:2]
    assert w == 60 and n >= 6
    assert data.positions.shape == (n, w, 22, 3) and data.local_rot.shape == (n, w, 22, 4)
    # FK of the heading-frame rotations on the skeleton gives the target positions
    pos = RetargetNet.forward_kinematics(
        torch.from_numpy(data.local_rot[:2]), torch.tensor(np.array(data.skeleton.offsets), dtype=torch.float32)
    )
    np.testing.assert_allclose(pos.numpy(), data.positions[:2], atol=1e-5)


def test_overfits_one_tiny_batch_quickly(data):
    one = _one_window(data)
    cfg = TrainConfig(steps=150, batch_size=1, lr=1e-2, augment=0.0, rot_weight=0.0, log_every=1, device="cpu")
    _, history = train(one, cfg, TINY, progress=False)
    first, last = history[0]["recon"], history[-1]["recon"]
    assert last < 0.1 * first
    assert last * 6 < 0.01  # mean joint error below 1 cm


def test_fixed_seed_reproduces_and_other_seed_differs(data):
    cfg = TrainConfig(steps=5, batch_size=2, seed=7, device="cpu")
    a, ha = train(data, cfg, TINY, progress=False)
    b, hb = train(data, cfg, TINY, progress=False)
    c, _ = train(data, TrainConfig(steps=5, batch_size=2, seed=8, device="cpu"), TINY, progress=False)
    assert [h["loss"] for h in ha] == [h["loss"] for h in hb]
    for (k, va), vb in zip(a.model.state_dict().items(), b.model.state_dict().values()):
        assert torch.equal(va, vb), k
    assert not all(torch.equal(va, vc) for va, vc in zip(a.model.state_dict().values(), c.model.state_dict().values()))


def test_callback_sees_every_logged_step(data):
    seen = []
    _, history = train(
        data,
        TrainConfig(steps=6, batch_size=2, log_every=2, device="cpu"),
        TINY,
        callback=lambda s, r: seen.append((s, r["loss"])),
        progress=False,
    )
    assert [s for s, _ in seen] == [2, 4, 6]
    assert len(history) == 3 and {"step", "loss", "recon", "rot", "lr", "seconds"} <= set(history[0])


def test_random_offsets_keep_directions_and_stay_in_range():
    base = torch.tensor(humanoid.canonical_skeleton().offsets, dtype=torch.float32)
    base[0] = 0
    cfg = TrainConfig(scale_range=1.5, overall_range=2.0)
    out = random_offsets(base, 50, cfg, torch.Generator().manual_seed(0))
    ratio = out[:, 1:].norm(dim=-1) / base[1:].norm(dim=-1)
    assert float(ratio.min()) >= 1 / 3.0 - 1e-6 and float(ratio.max()) <= 3.0 + 1e-6
    cos = (torch.nn.functional.normalize(out[:, 1:], dim=-1) * torch.nn.functional.normalize(base[1:], dim=-1)).sum(-1)
    np.testing.assert_allclose(cos.numpy(), 1.0, atol=1e-5)


def test_turned_windows_are_the_features_of_the_turned_motion(data):
    """Pose augmentation: identity turns give back the stored features; real turns give the
    features that preprocessing computes from the turned motion (positions by FK, root unchanged)."""
    x = torch.from_numpy((data.x[:3] - data.stats.mean) / data.stats.std).float()
    rot = torch.from_numpy(data.local_rot[:3])
    offsets = torch.tensor(np.array(data.skeleton.offsets), dtype=torch.float32).expand(3, -1, -1)
    ident = torch.zeros(3, 22, 4)
    ident[..., 0] = 1.0
    same, rot0, pos0 = turned_window(x, rot, offsets, ident, data.stats.mean, data.stats.std)
    torch.testing.assert_close(same, x, atol=1e-4, rtol=0)
    np.testing.assert_allclose(pos0.numpy(), data.positions[:3], atol=1e-5)
    turns = random_turns(3, TrainConfig(pose_noise=0.4), torch.Generator().manual_seed(0))
    angle = 2 * torch.arccos(turns[..., 0].clamp(-1, 1))
    assert torch.all(angle[:, 0] == 0) and angle.max() <= 0.4 + 1e-6 and angle.max() > 0.1
    x2, rot2, pos2 = turned_window(x, rot, offsets, turns, data.stats.mean, data.stats.std)
    np.testing.assert_allclose(pos2.numpy(), RetargetNet.forward_kinematics(rot2, offsets).numpy(), atol=1e-6)
    raw = x2.numpy() * data.stats.std + data.stats.mean
    np.testing.assert_allclose(raw[..., 66:], data.x[:3, :, 66:], atol=1e-4)  # the root's motion is kept
    lifted = pos2.numpy() + np.stack([0 * raw[..., -1], raw[..., -1], 0 * raw[..., -1]], -1)[..., None, :]
    np.testing.assert_allclose(raw[..., :66], lifted.reshape(3, -1, 66), atol=1e-4)
    assert np.abs(raw[..., :66] - data.x[:3, :, :66]).max() > 0.01  # and the pose did change


def test_training_with_pose_augmentation_runs_and_is_seeded(data):
    cfg = TrainConfig(steps=3, batch_size=4, augment=0.25, pose_augment=0.5, log_every=1, device="cpu")
    _, h1 = train(data, cfg, TINY, progress=False)
    _, h2 = train(data, cfg, TINY, progress=False)
    assert all(np.isfinite(r["loss"]) for r in h1)
    assert [r["loss"] for r in h1] == [r["loss"] for r in h2]


def test_mixed_characters_and_bad_config_are_refused(clips):
    other = synthetic.dataset(
        1, seed=1, num_frames=120, skeleton=humanoid.scale_bones(humanoid.canonical_skeleton(), legs=1.4)
    )
    with pytest.raises(ValueError, match="one character"):
        training_set([clips[0], other[0]], progress=False)
    with pytest.raises(ValueError, match="at least one"):
        training_set([], progress=False)
    with pytest.raises(ValueError, match="augment"):
        TrainConfig(augment=2.0)
    with pytest.raises(ValueError, match="pose_augment"):
        TrainConfig(augment=0.5, pose_augment=0.75)


def _nudged_training(data, grid: bool, nudge: bool, monkeypatch):
    """Trained weights, the loss scaled by 1 + 2⁻⁴⁸ when ``nudge``: gradients that differ in their
    last bits, as another CPU's kernels give."""
    from motionlab.retargeting import losses

    recon = losses.recon_loss
    factor = 1.0 + 2.0**-48 if nudge else 1.0
    monkeypatch.setattr(losses, "recon_loss", lambda *a, **k: recon(*a, **k) * factor)
    cfg = TrainConfig(steps=20, batch_size=2, seed=3, device="cpu", grid=grid)
    ckpt, _ = train(data, cfg, TINY, progress=False)
    return ckpt.model.state_dict()


@pytest.mark.slow
def test_the_grid_rounds_last_bit_differences_away(data, monkeypatch):
    from motionlab.retargeting.solver import step_grid

    plain, nudged = (_nudged_training(data, True, n, monkeypatch) for n in (False, True))
    for k in plain:
        assert torch.equal(plain[k], nudged[k]), k
    g = step_grid(TrainConfig().lr / 10)  # the cosine schedule's floor: every step's grid is a multiple of it
    for k, v in plain.items():
        assert torch.equal(torch.round(v / g) * g, v), k
    plain, nudged = (_nudged_training(data, False, n, monkeypatch) for n in (False, True))
    assert any(not torch.equal(plain[k], nudged[k]) for k in plain)  # without the grid they differ
