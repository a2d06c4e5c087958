"""Checkpoints: save -> load round trips, and clear errors for other versions or damaged files."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from motionlab.retargeting import checkpoint


def test_save_load_round_trip(tmp_path, tiny_checkpoint):
    """checkpoint -> file -> checkpoint: same weights, statistics, skeleton and outputs."""
    path = checkpoint.save(tmp_path / "net.pt", tiny_checkpoint)
    back = checkpoint.load(path, device="cpu")
    for (k, a), b in zip(tiny_checkpoint.model.state_dict().items(), back.model.state_dict().values()):
        assert torch.equal(a.cpu(), b), k
    assert back.model.config == tiny_checkpoint.model.config
    np.testing.assert_array_equal(back.stats.mean, tiny_checkpoint.stats.mean)
    np.testing.assert_array_equal(back.stats.std, tiny_checkpoint.stats.std)
    assert back.skeleton.equals(tiny_checkpoint.skeleton, atol=0.0)
    assert back.skeleton.end_sites.keys() == tiny_checkpoint.skeleton.end_sites.keys()
    assert (back.fps, back.window) == (tiny_checkpoint.fps, tiny_checkpoint.window)
    assert back.info["final_loss"] == tiny_checkpoint.info["final_loss"]
    assert not back.model.training
    x = torch.randn(1, 30, 70, dtype=back.dtype)
    off = torch.tensor(back.skeleton.offsets, dtype=back.dtype)
    with torch.no_grad():
        np.testing.assert_array_equal(back.model(x, off).positions, tiny_checkpoint.model.cpu()(x, off).positions)


def test_no_silent_overwrite(tmp_path, tiny_checkpoint):
    path = checkpoint.save(tmp_path / "net.pt", tiny_checkpoint)
    with pytest.raises(FileExistsError, match="exists"):
        checkpoint.save(path, tiny_checkpoint, overwrite=False)


def test_other_version_is_a_clear_error(tmp_path, tiny_checkpoint):
    path = checkpoint.save(tmp_path / "net.pt", tiny_checkpoint)
    payload = torch.load(path, weights_only=True)
    payload["version"] = checkpoint.FORMAT_VERSION + 1
    torch.save(payload, path)
    with pytest.raises(
        checkpoint.CheckpointError,
        match=f"version {checkpoint.FORMAT_VERSION + 1}.*reads version {checkpoint.FORMAT_VERSION}",
    ):
        checkpoint.load(path)


def test_corrupt_and_foreign_files_are_clear_errors(tmp_path, tiny_checkpoint):
    good = checkpoint.save(tmp_path / "net.pt", tiny_checkpoint)
    bad = tmp_path / "cut.pt"
    bad.write_bytes(good.read_bytes()[:200])
    with pytest.raises(checkpoint.CheckpointError, match="not a readable"):
        checkpoint.load(bad)
    text = tmp_path / "notes.pt"
    text.write_text("hello")
    with pytest.raises(checkpoint.CheckpointError, match="not a readable"):
        checkpoint.load(text)
    other = tmp_path / "other.pt"
    torch.save({"weights": torch.zeros(3)}, other)
    with pytest.raises(checkpoint.CheckpointError, match="format tag"):
        checkpoint.load(other)
    payload = torch.load(good, weights_only=True)
    del payload["state_dict"]["f_qlinear.weight"]
    torch.save(payload, other)
    with pytest.raises(checkpoint.CheckpointError, match="damaged"):
        checkpoint.load(other)
    with pytest.raises(FileNotFoundError):
        checkpoint.load(tmp_path / "missing.pt")


def test_load_computes_in_the_asked_float_type(tmp_path, tiny_checkpoint):
    path = checkpoint.save(tmp_path / "net.pt", tiny_checkpoint)
    assert checkpoint.load(path, device="cpu").dtype == torch.float64  # the default
    single = checkpoint.load(path, device="cpu", dtype="float32")
    assert single.dtype == torch.float32
    for a, b in zip(tiny_checkpoint.model.state_dict().values(), single.model.state_dict().values()):
        assert torch.equal(a.cpu().float(), b)
    with pytest.raises(ValueError, match="dtype must be one of"):
        checkpoint.load(path, device="cpu", dtype="float16")
