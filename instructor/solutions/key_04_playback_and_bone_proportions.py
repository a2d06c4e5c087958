"""Instructor's key for notebook 04 (playback and bone proportions)."""

import numpy as np

from motionlab.core import humanoid
from motionlab.viz import compare, proportions


def my_shorter_legs_experiment(walk):
    """Exercise 1 (experiment): section 4's comparison with legs × 0.8; mean pose error, m, as printed."""
    short_legs = humanoid.scale_bones(walk.skeleton, legs=0.8)
    copied = proportions.copy_rotation_solver(walk)(short_legs)
    err = compare.joint_errors(copied, walk, relative_to_root=True)
    return round(float(np.nanmean(err)), 3)


def my_joint_speed(motion):
    """Exercise 2: speed of every joint in every frame (T, J), m/s (central differences)."""
    velocity = np.gradient(motion.global_positions(), axis=0)  # m/frame
    return np.linalg.norm(velocity, axis=-1) * motion.fps
