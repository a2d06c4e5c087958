"""Instructor's key for notebook 00b (the BVH file format)."""

import numpy as np

from motionlab.core import quat


def my_reader_order_experiment(path, channels):
    """Exercise 1: frame 0 of ``path`` read in each joint's declared rotation order and in the reversed
    order (each angle staying with its axis); the largest angle between the two, degrees, over the joints.

    ``channels``: the per-joint channel lists (section 1's parser, or ``bvh.load(path).skeleton.channels``).
    """
    lines = [line.strip() for line in path.read_text().splitlines()]
    values = np.array(lines[lines.index("MOTION") + 3].split(), dtype=float)
    column, largest = 0, 0.0
    for chans in channels:
        v = values[column : column + len(chans)]
        column += len(chans)
        axes = [c[0].lower() for c in chans if c.endswith("rotation")]
        angles = np.radians([v[chans.index(a.upper() + "rotation")] for a in axes])
        right = quat.from_euler(angles, "".join(axes))
        wrong = quat.from_euler(angles[::-1], "".join(axes[::-1]))
        largest = max(largest, float(np.degrees(quat.angle_between(right, wrong))))
    return round(largest, 1)
