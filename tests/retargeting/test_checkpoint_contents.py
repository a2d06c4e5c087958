"""A checkpoint that unpickles but cannot work is refused at load, naming what is wrong."""

from __future__ import annotations

import pytest
import torch

from motionlab.retargeting import checkpoint


@pytest.fixture
def payload(tmp_path, tiny_checkpoint):
    path = checkpoint.save(tmp_path / "net.pt", tiny_checkpoint)
    return path, torch.load(path, weights_only=True)


def _load_changed(path, payload, change):
    change(payload)
    torch.save(payload, path)
    return checkpoint.load(path, "cpu")


def test_nan_weight_is_named(payload):
    path, p = payload
    name = next(k for k, v in p["state_dict"].items() if v.is_floating_point() and v.numel() > 1)

    def change(p):
        p["state_dict"][name].view(-1)[0] = float("nan")

    with pytest.raises(checkpoint.CheckpointError, match=f"weight '{name}'.*non-finite"):
        _load_changed(path, p, change)


def test_short_statistics_are_named(payload):
    path, p = payload

    def change(p):
        p["stats"]["mean"] = p["stats"]["mean"][:10]

    with pytest.raises(checkpoint.CheckpointError, match="statistics 'mean' should have 70 values, got shape"):
        _load_changed(path, p, change)


def test_zero_std_is_refused(payload):
    path, p = payload

    def change(p):
        p["stats"]["std"] = [0.0] * len(p["stats"]["std"])

    with pytest.raises(checkpoint.CheckpointError, match="'std' should be > 0"):
        _load_changed(path, p, change)


def test_stored_skeleton_must_be_the_22_joint_humanoid(payload):
    path, p = payload

    def change(p):
        sk = p["skeleton"]
        sk["names"], sk["parents"], sk["offsets"] = sk["names"][:5], sk["parents"][:5], sk["offsets"][:5]
        sk["end_sites"] = {}

    with pytest.raises(checkpoint.CheckpointError, match="22-joint humanoid.*got 5 joints"):
        _load_changed(path, p, change)
