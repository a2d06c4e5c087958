"""Instructor's key for notebook 04 (playback and bone proportions)."""

import numpy as np

from motionlab.core import humanoid
from motionlab.viz import compare, proportions


def my_shorter_legs_experiment(walk):
    """Exercise 1 (experiment): section 4's comparison on legs × 0.8 and on legs × 1.25; the first
    mean pose error over the second, as a student types it (two decimals)."""

    def mean_pose_error(legs):
        copied = proportions.copy_rotation_solver(walk)(humanoid.scale_bones(walk.skeleton, legs=legs))
        return float(np.nanmean(compare.joint_errors(copied, walk, relative_to_root=True)))

    return round(mean_pose_error(0.8) / mean_pose_error(1.25), 2)


def my_joint_speed(motion):
    """Exercise 2: speed of every joint in every frame (T, J), m/s (central differences)."""
    velocity = np.gradient(motion.global_positions(), axis=0)  # m/frame
    return np.linalg.norm(velocity, axis=-1) * motion.fps
