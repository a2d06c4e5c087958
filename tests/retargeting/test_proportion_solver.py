"""The bone-proportion sliders' solver: each release is a fresh retargeting of the same skeleton."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab import retargeting, synthetic
from motionlab.core import humanoid
from motionlab.retargeting.proportions import proportion_solver


def test_each_release_equals_a_fresh_full_retarget():
    """Notebook 04's editor (120-frame walk, 30 steps): two releases in a row, each the motion and
    loss history of ``retarget(..., "full")`` on that skeleton, to the last bit."""
    try:
        ckpt = retargeting.load_default("cpu")
    except (FileNotFoundError, retargeting.CheckpointError) as e:
        pytest.skip(f"no shipped retargeting network: {e}")
    skeleton = humanoid.canonical_skeleton()
    clip = synthetic.generate("walk", skeleton, num_frames=120, fps=30.0, seed=1)
    solve = proportion_solver(clip, max_steps=30)
    for legs in (1.3, 1.35):
        target = humanoid.scale_bones(skeleton, legs=legs, arms=0.8)
        motion, history = solve(target)
        fresh = retargeting.retarget(clip, target, ckpt, "full", solver=retargeting.SolverConfig(max_steps=30))
        np.testing.assert_array_equal(motion.global_positions(), fresh.motion.global_positions())
        assert history["loss"] == fresh.history["loss"]


def test_a_method_it_does_not_know_is_refused_before_the_network_loads():
    with pytest.raises(ValueError, match="method must be one of"):
        proportion_solver(synthetic.generate("walk", num_frames=10, fps=60), method="fulll")
