"""Instructor's key for notebook 00 (quaternions and forward kinematics).

Exercises 1 and 2 are experiments: the key reruns the notebook's cell with the changed parameters
and returns the number a student reads off and types (as printed).
"""

import numpy as np

from motionlab.core import fk, quat


def my_nlerp_turn_experiment():
    """Exercise 1: the largest whole-degree turn whose nlerp fastest / slowest step (50 steps, as in
    section 4) is at most 1.10."""
    q0 = quat.IDENTITY
    t = np.linspace(0, 1, 50)
    largest = None
    for turn in range(1, 180):
        q1 = quat.from_axis_angle([0, 1, 0], np.radians(turn))
        nlerp = quat.normalize((1 - t)[:, None] * q0 + t[:, None] * q1)
        steps = np.diff(np.degrees(quat.angle_between(q0, nlerp)))
        if steps.max() / steps.min() <= 1.10:
            largest = turn
    return largest


def my_euler_order_experiment():
    """Exercise 2: degrees between (30°, −20°, 45°) read as 'zxy' and as 'xyz'."""
    angles = np.radians([30.0, -20.0, 45.0])
    gap = quat.angle_between(quat.from_euler(angles, "zxy"), quat.from_euler(angles, "xyz"))
    return round(float(np.degrees(gap)), 1)


def left_hand_height_with_arm_raised(skeleton):
    """Exercise 3: height (m) of the left hand with LeftArm rotated +90° about z."""
    rot = np.tile(quat.IDENTITY, (skeleton.num_joints, 1))
    rot[skeleton.index("LeftArm")] = quat.from_axis_angle([0, 0, 1], np.pi / 2)
    _, positions = fk.fk(rot, skeleton.offsets, skeleton.parents)
    return float(positions[skeleton.index("LeftHand"), 1])
