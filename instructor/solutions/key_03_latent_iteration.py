"""Instructor's key for notebook 03 (the latent iteration)."""

import numpy as np
import torch

from motionlab.core import humanoid

FEET = [humanoid.JOINTS.index(n) for n in humanoid.FEET]  # as in the notebook


def my_foot_loss(world_y):
    """Exercise 1: L_foot (eq. 17), mean of |min(y, 0)| over frames and the four foot joints."""
    feet = world_y[..., FEET]  # (..., T, 4) metres
    return torch.clamp(feet, max=0.0).abs().mean()


def _leg_chain(skeleton):
    lengths = []
    for side in ("Left", "Right"):
        chain = [side + j for j in ("UpLeg", "Leg", "Foot", "ToeBase")]
        lengths.append(sum(np.linalg.norm(skeleton.offsets[skeleton.index(name)]) for name in chain))
    return np.mean(lengths)


def my_root_scale(source_skeleton, target_skeleton):
    """Exercise 2: r_xz, B's leg chain over A's (both legs averaged), from the bone offsets."""
    return _leg_chain(target_skeleton) / _leg_chain(source_skeleton)


def my_angle_loss(source_rot, generated_rot):
    """Exercise 3: L_angle, mean of min(‖q_A − q_B'‖, ‖q_A + q_B'‖) over frames and joints."""
    minus = (source_rot - generated_rot).norm(dim=-1)
    plus = (source_rot + generated_rot).norm(dim=-1)
    return torch.minimum(minus, plus).mean()


def my_foot_weight_experiment(source, target_rig, ckpt):
    """Exercise 4: the paper's set-up with λ_foot = 5; mean angle to A's rotations, degrees."""
    from motionlab import retargeting
    from motionlab.core import preprocess
    from motionlab.retargeting import plots
    from motionlab.retargeting.solver import SolverConfig

    cfg = SolverConfig(init="encoder", lambda_contact=0.0, lr=0.1, lambda_foot=5.0)
    run = retargeting.retarget(source, target_rig, ckpt, "full", cfg)
    src = preprocess.prepare(source, ckpt.fps)
    return plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean()
