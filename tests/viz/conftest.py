"""Fixtures for the viz tests: a hand-made walking motion on the canonical skeleton."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab.core import humanoid, quat
from motionlab.core.motion import Motion

pytest.importorskip("pyvista")
pytest.importorskip("ipywidgets")


def stepping_motion(num_frames: int = 60, fps: float = 30.0, speed: float = 1.2) -> Motion:
    """A crude walk on the 22-joint humanoid: legs and arms swing, the root moves along +Z.

    The swing is a sine per frame (0.9 strides per second); the root's height puts the lowest
    joint on the ground in every frame. Not physically exact: enough to move every limb.
    """
    skeleton = humanoid.canonical_skeleton()
    t = np.arange(num_frames) / fps
    phase = 2 * np.pi * 0.9 * t
    J = skeleton.num_joints
    local = np.tile(quat.IDENTITY, (num_frames, J, 1)).astype(np.float64)
    x = np.array([1.0, 0.0, 0.0])
    z = np.array([0.0, 0.0, 1.0])

    def put(name, axis, angle):
        local[:, skeleton.index(name)] = quat.from_axis_angle(np.broadcast_to(axis, (num_frames, 3)), angle)

    put("LeftUpLeg", x, -0.45 * np.sin(phase))
    put("RightUpLeg", x, 0.45 * np.sin(phase))
    put("LeftLeg", x, 0.5 * (1 + np.sin(phase + 1.2)))
    put("RightLeg", x, 0.5 * (1 - np.sin(phase + 1.2)))
    put("LeftArm", z, -1.2 + 0.0 * phase)
    put("RightArm", z, 1.2 + 0.0 * phase)
    put("LeftShoulder", x, 0.3 * np.sin(phase))
    put("RightShoulder", x, -0.3 * np.sin(phase))
    root = np.zeros((num_frames, 3))
    root[:, 2] = speed * t
    motion = Motion(skeleton, local, root, fps, name="stepping")
    lowest = motion.global_positions()[:, :, 1].min(axis=1)  # per frame, with the root at y = 0
    root[:, 1] = -lowest  # the lower foot touches the ground in every frame
    return Motion(skeleton, local, root, fps, name="stepping")


@pytest.fixture
def walk() -> Motion:
    return stepping_motion()


def standing_motion(num_frames: int = 20, fps: float = 30.0) -> Motion:
    """The canonical skeleton standing still in its rest pose, feet on the ground."""
    skeleton = humanoid.canonical_skeleton()
    local = np.tile(quat.IDENTITY, (num_frames, skeleton.num_joints, 1)).astype(np.float64)
    root = np.tile(skeleton.offsets[0], (num_frames, 1))
    return Motion(skeleton, local, root, fps, name="standing")


@pytest.fixture(scope="session")
def can_render():
    """Skip unless VTK can render here (a display, or EGL/OSMesa for off-screen)."""
    from motionlab.viz import backend

    try:
        backend.import_pyvista()
    except backend.RenderingUnavailable as e:
        pytest.skip(str(e))
    return True


@pytest.fixture
def small() -> dict:
    """Scene options for quick test renders."""
    return {"window_size": (200, 160), "off_screen": True}
