"""Instructor's key for notebook 07 (expanding a motion database).

The exercise is an experiment: the key retargets the clip onto a character with arms × 1.3 and
returns the floor test's measure, as the notebook's ``plausibility`` prints it.
"""

from motionlab.core import bvh, humanoid
from motionlab.retargeting.pipeline import retarget


def my_arm_length_experiment(clip_path, ckpt, solver_cfg):
    """Exercise 1: the lowest joint of the output, as a fraction of B's leg (negative: under the floor)."""
    arms_13 = humanoid.scale_bones(humanoid.canonical_skeleton(), arms=1.3)
    result = retarget(bvh.load(clip_path), arms_13, ckpt, solver=solver_cfg)
    print(result.plausibility)  # failed=() : not flagged
    return round(result.plausibility.lowest, 3)
