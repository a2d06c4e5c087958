"""Instructor's key for notebook 04 (playback and bone proportions)."""

import numpy as np


def my_pose_error(motion, reference):
    """Exercise 1: per-frame mean joint distance (T,), metres, after removing each root."""
    a = motion.global_positions()
    b = reference.global_positions()
    a = a - a[:, :1]
    b = b - b[:, :1]
    return np.linalg.norm(a - b, axis=-1).mean(axis=1)


def my_joint_speed(motion):
    """Exercise 2: speed of every joint in every frame (T, J), m/s (central differences)."""
    velocity = np.gradient(motion.global_positions(), axis=0)  # m/frame
    return np.linalg.norm(velocity, axis=-1) * motion.fps
