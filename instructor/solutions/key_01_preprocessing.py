"""Instructor's key for notebook 01 (preprocessing)."""

import numpy as np

from motionlab.core import humanoid


def my_heading(pose):
    """Exercise 1: facing angle (radians, 0 = +z) of one canonical pose (22, 3)."""
    p = np.asarray(pose, dtype=float)
    ix = humanoid.JOINTS.index
    across = (p[ix("LeftUpLeg")] - p[ix("RightUpLeg")]) + (p[ix("LeftArm")] - p[ix("RightArm")])
    forward = np.cross(across, [0.0, 1.0, 0.0])
    return float(np.arctan2(forward[0], forward[2]))


def my_window_count(num_frames, window=120, stride=30):
    """Exercise 2: number of windows, the last one moved back to end on the last frame."""
    if num_frames <= window:
        return 1  # one (padded) window
    full = (num_frames - window) // stride + 1  # windows starting at 0, stride, 2·stride, ...
    left_over = (num_frames - window) % stride != 0
    return full + int(left_over)
