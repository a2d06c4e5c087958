"""Fixtures of the retargeting tests: tiny networks and short synthetic clips (fast on a 2-core CPU)."""

from __future__ import annotations

import pytest
import torch

from motionlab import synthetic
from motionlab.retargeting.model import ModelConfig
from motionlab.retargeting.train import TrainConfig, train, training_set

TINY = ModelConfig(latent=8, hidden=16, skel_embed=4, kernel=3, layers=2)


@pytest.fixture(scope="session")
def clips():
    """Two 120-frame synthetic clips of the default character at 60 fps."""
    return synthetic.dataset(2, seed=0, num_frames=120)


@pytest.fixture(scope="session")
def data(clips):
    return training_set(clips, window=60, stride=30, progress=False)


@pytest.fixture(scope="session")
def tiny_checkpoint(data):
    """A tiny network trained for a few steps (the solver and pipeline need *a* trained network)."""
    torch.manual_seed(0)
    ckpt, _ = train(data, TrainConfig(steps=40, batch_size=4, lr=5e-3, device="cpu"), TINY, progress=False)
    return ckpt
