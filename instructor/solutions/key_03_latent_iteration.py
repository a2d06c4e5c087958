"""Instructor's key for notebook 03 (the latent iteration)."""

import torch

from motionlab.core import humanoid

FEET = [humanoid.JOINTS.index(n) for n in humanoid.FEET]  # as in the notebook


def my_contact_loss(feet, planted, fps):
    """Exercise 1: L_contact, the mean speed (m/s) of the foot joints over the steps t -> t + 1 where
    A's foot is planted in both frames; 0 when it never is."""
    step = (feet[..., 1:, :, :] - feet[..., :-1, :, :]).norm(dim=-1)  # (..., T-1, 4) metres per frame
    both = planted[..., 1:, :] & planted[..., :-1, :]
    if not both.any():
        return torch.zeros(())
    return fps * step[both].mean()


def _full_method(source, target_rig, ckpt, cfg):
    """(the full method's result, A prepared) for one solver configuration."""
    from motionlab import retargeting
    from motionlab.core import preprocess

    run = retargeting.retarget(source, target_rig, ckpt, "full", cfg)
    return run, preprocess.prepare(source, ckpt.fps, stand=True)


def my_encoder_start_experiment(source, target_rig, ckpt):
    """Exercise 2: motionlab's settings with the encoder's start; mean angle to A's rotations, degrees."""
    from motionlab.retargeting import plots
    from motionlab.retargeting.solver import SolverConfig

    run, src = _full_method(source, target_rig, ckpt, SolverConfig(init="encoder"))
    return round(float(plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean()), 2)


def my_contact_weight_experiment(source, target_rig, ckpt):
    """Exercise 3: λ_contact = 0.1; speed of A's planted feet on B, cm/s, as section 5 measures it."""
    from motionlab.core import metrics
    from motionlab.retargeting import pipeline
    from motionlab.retargeting.solver import SolverConfig

    run, src = _full_method(source, target_rig, ckpt, SolverConfig(lambda_contact=0.1))
    planted_a = pipeline.source_contacts(src)
    return round(100 * float(metrics.planted_slide(run.positions, FEET, planted_a, ckpt.fps)), 2)


def my_foot_weight_experiment(source, target_rig, ckpt):
    """Exercise 4: the paper-like set-up with λ_foot = 5; mean angle to A's rotations, degrees."""
    from motionlab import retargeting
    from motionlab.core import preprocess
    from motionlab.retargeting import plots
    from motionlab.retargeting.solver import SolverConfig

    paper_only = {"contact": 0.0, "clearance": 0.0}  # section 5's paper-like row: L_angle and L_foot alone
    cfg = SolverConfig(init="encoder", lr=0.1, lambda_foot=5.0, weights=paper_only)
    run = retargeting.retarget(source, target_rig, ckpt, "full", cfg)
    src = preprocess.prepare(source, ckpt.fps, stand=True)
    return plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean()


def my_theta_directions_experiment(source, target_rig, ckpt):
    """Exercise 5: the full method with θ = bone directions; mean angle to A's rotations, degrees."""
    from motionlab import retargeting
    from motionlab.core import preprocess
    from motionlab.retargeting import plots
    from motionlab.retargeting.solver import SolverConfig

    run = retargeting.retarget(source, target_rig, ckpt, "full", SolverConfig(theta="directions"))
    src = preprocess.prepare(source, ckpt.fps, stand=True)
    return round(float(plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean()), 2)
