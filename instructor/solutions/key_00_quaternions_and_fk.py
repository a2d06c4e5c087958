"""Instructor's key for notebook 00 (quaternions and forward kinematics).

Exercises 1 and 2 are experiments: the key reruns the notebook's cell with the changed parameter
and returns the number a student reads off and types (as printed).
"""

import numpy as np

from motionlab.core import fk, quat


def my_nlerp_turn_experiment():
    """Exercise 1: section 4's cell with a 90° turn; nlerp's fastest / slowest step, as printed."""
    q0 = quat.IDENTITY
    q1 = quat.from_axis_angle([0, 1, 0], np.radians(90))
    t = np.linspace(0, 1, 50)
    nlerp = quat.normalize((1 - t)[:, None] * q0 + t[:, None] * q1)
    steps = np.diff(np.degrees(quat.angle_between(q0, nlerp)))
    return round(float(steps.max() / steps.min()), 2)


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
