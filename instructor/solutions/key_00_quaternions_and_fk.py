"""Instructor's key for notebook 00 (quaternions and forward kinematics)."""

import numpy as np

from motionlab.core import fk, quat


def my_conj(q):
    """Exercise 1: the conjugate (w, -x, -y, -z) of quaternions (..., 4)."""
    q = np.asarray(q, dtype=float)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def my_slerp(q0, q1, t):
    """Exercise 2: spherical linear interpolation of two unit quaternions (4,), short arc."""
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    d = float(np.dot(q0, q1))
    if d < 0:  # q1 and -q1 are the same rotation: take the shorter arc
        q1, d = -q1, -d
    omega = np.arccos(min(d, 1.0))
    if omega < 1e-9:  # the same rotation: nothing to interpolate
        return q0.copy()
    return (np.sin((1 - t) * omega) * q0 + np.sin(t * omega) * q1) / np.sin(omega)


def left_hand_height_with_arm_raised(skeleton):
    """Exercise 3: height (m) of the left hand with LeftArm rotated +90° about z."""
    rot = np.tile(quat.IDENTITY, (skeleton.num_joints, 1))
    rot[skeleton.index("LeftArm")] = quat.from_axis_angle([0, 0, 1], np.pi / 2)
    _, positions = fk.fk(rot, skeleton.offsets, skeleton.parents)
    return float(positions[skeleton.index("LeftHand"), 1])
