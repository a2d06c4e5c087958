"""Instructor's key for notebook 01 (preprocessing)."""

import numpy as np

from motionlab.core import humanoid, preprocess


def my_hips_heading_experiment(world):
    """Exercise 1 (experiment): largest |ψ_hips − ψ| over the clip's frames, degrees, one decimal.

    ``world``: the clip's canonical joint positions (T, 22, 3), as in section 3.
    """
    ix = humanoid.JOINTS.index
    across = world[:, ix("LeftUpLeg")] - world[:, ix("RightUpLeg")]  # the hips only
    forward = np.cross(across, [0.0, 1.0, 0.0])
    psi_hips = np.arctan2(forward[:, 0], forward[:, 2])
    gap = np.angle(np.exp(1j * (psi_hips - preprocess.heading(world))))  # wrapped to (−π, π]
    return round(float(np.degrees(np.abs(gap).max())), 1)


def my_window_count(num_frames, window=120, stride=30):
    """Exercise 2: number of windows, the last one moved back to end on the last frame."""
    if num_frames <= window:
        return 1  # one (padded) window
    full = (num_frames - window) // stride + 1  # windows starting at 0, stride, 2·stride, ...
    left_over = (num_frames - window) % stride != 0
    return full + int(left_over)
