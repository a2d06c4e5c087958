"""Shared fixtures: a small procedural motion (no data needed) and a real clip when available."""

import numpy as np
import pytest

from motionlab import data
from motionlab.core import quat
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton

NO_DATA = f"needs real mocap: {data.HOW_TO}"


def toy_skeleton() -> Skeleton:
    """A 7-joint stick figure: hips, two 2-bone legs, a spine and a head (metres)."""
    names = ("Hips", "LUp", "LLow", "RUp", "RLow", "Spine", "Head")
    parents = [-1, 0, 1, 0, 3, 0, 5]
    offsets = [[0, 0.9, 0], [0.1, 0, 0], [0, -0.45, 0], [-0.1, 0, 0], [0, -0.45, 0], [0, 0.3, 0], [0, 0.3, 0]]
    return Skeleton(names, np.array(parents), np.array(offsets, dtype=float))


def toy_motion(num_frames: int = 90, fps: float = 30.0, speed: float = 1.2, phase: float = 0.0) -> Motion:
    """A walking-like motion: legs swing (sinusoids), root moves forward along +Z while turning."""
    sk = toy_skeleton()
    t = np.arange(num_frames) / fps
    w = 2 * np.pi * 1.0 * t + phase
    J = sk.num_joints
    angles = np.zeros((num_frames, J, 3))
    angles[:, 1, 0] = 0.5 * np.sin(w)
    angles[:, 3, 0] = -0.5 * np.sin(w)
    angles[:, 2, 0] = 0.4 * (1 + np.sin(w + 1.0))
    angles[:, 4, 0] = 0.4 * (1 - np.sin(w + 1.0))
    angles[:, 5, 2] = 0.1 * np.sin(2 * w)
    angles[:, 0, 1] = 0.3 * t  # slow turn (yaw)
    rot = quat.from_euler(angles, "xyz")
    heading = angles[:, 0, 1]
    step = speed / fps * np.stack([np.sin(heading), np.zeros_like(heading), np.cos(heading)], -1)
    root = np.cumsum(step, axis=0) + np.array([0.0, 0.9, 0.0]) + 0.02 * np.sin(2 * w)[:, None] * [0, 1, 0]
    return Motion(sk, rot, root, fps, name="toy")


@pytest.fixture
def toy():
    return toy_motion()


@pytest.fixture(scope="session")
def real_walk():
    if not data.has_data("bandai_namco", "dataset-2"):
        pytest.skip(NO_DATA)
    from motionlab.core import bvh

    return bvh.load(data.clip_path("bandai_namco", "dataset-2", "walk", "dataset-2_walk_normal_001"))
