"""Exercises of notebooks 02 (the retargeting network) and 03 (the latent iteration).

The cases are small torch tensors drawn from a fixed seed (a private generator: the notebook's
own random state is left alone), so every check is deterministic and takes milliseconds. torch
is imported only when a check runs.
"""

from __future__ import annotations

import numpy as np

from .core import Exercise, Mistake, Question

__all__ = ["recon_loss", "combine", "rotations", "foot_loss", "root_scale", "angle_loss", "foot_weight"]


def _gen(seed: int):
    import torch

    return torch.Generator().manual_seed(seed)


def _unit_quats(shape: tuple, seed: int):
    import torch

    q = torch.randn(*shape, 4, generator=_gen(seed))
    return q / q.norm(dim=-1, keepdim=True)


# --------------------------------------------------------------------------- notebook 02
def _recon_cases():
    import torch

    g = _gen(200)
    return [
        (torch.randn(2, 120, 22, 3, generator=g), torch.randn(2, 120, 22, 3, generator=g)),
        (0.1 * torch.randn(30, 22, 3, generator=g), torch.zeros(30, 22, 3)),  # no batch dimension
        (torch.randn(3, 4, 10, 5, 3, generator=g), torch.randn(3, 4, 10, 5, 3, generator=g)),  # two batch dims
    ]


def _recon_ref(pred, target):
    from motionlab.retargeting import losses

    return losses.recon_loss(pred, target)


def _distances(pred, target):
    return (pred - target).norm(dim=-1)  # (..., T, J)


recon_loss = Exercise(
    "02 · exercise 1 (L_recon)",
    _recon_ref,
    _recon_cases,
    atol=1e-6,
    mistakes=[
        Mistake(
            lambda p, t: 0.5 * ((p - t) ** 2).sum(-1).mean() / 3,
            "eq. 8 sums Euclidean distances ‖p − p'‖₂, not squared distances.",
        ),
        Mistake(
            lambda p, t: 0.5 * (p - t).abs().mean(),
            "the distance between two joints is the length of the difference vector (a norm over "
            "x, y, z), not the sum of its coordinates' absolute values.",
        ),
        Mistake(lambda p, t: _distances(p, t).mean() / 3, "you left out λ_recon = 0.5."),
        Mistake(
            lambda p, t: 0.5 * _distances(p, t).mean(),
            "look again at the normalisation: eq. 8 divides by 3TJ, not by TJ.",
        ),
        Mistake(
            lambda p, t: 0.5 * _distances(p, t).sum() / (3 * p.shape[-3] * p.shape[-2]),
            "right for one window only: average over the batch (any leading dimensions), do not sum over it.",
        ),
    ],
)


def _combine_cases():
    return [
        (_unit_quats((5,), 201), _unit_quats((5,), 202)),
        (_unit_quats((2, 3, 22), 203), _unit_quats((2, 3, 22), 204)),
    ]


def _combine_ref(q, q_delta):
    from motionlab.retargeting.model import RetargetNet

    return RetargetNet.combine(q, q_delta)


def _hamilton(q, p, cross_sign: float = 1.0, dot_sign: float = -1.0):
    import torch

    w1, v1, w2, v2 = q[..., :1], q[..., 1:], p[..., :1], p[..., 1:]
    w = w1 * w2 + dot_sign * (v1 * v2).sum(-1, keepdim=True)
    v = w1 * v2 + w2 * v1 + cross_sign * torch.linalg.cross(v1, v2, dim=-1)
    return torch.cat([w, v], dim=-1)


combine = Exercise(
    "02 · exercise 2 (Hamilton correction)",
    _combine_ref,
    _combine_cases,
    atol=1e-6,
    mistakes=[
        Mistake(
            lambda q, d: _hamilton(q, d, cross_sign=-1.0),
            "the order of the factors matters (the product is not commutative): look at the sign "
            "of the cross-product term, v₁ × v₂ is not v₂ × v₁.",
        ),
        Mistake(
            lambda q, d: _hamilton(q, d, dot_sign=1.0),
            "check the sign of the scalar part: w₁w₂ and v₁·v₂ do not simply add.",
        ),
        Mistake(
            lambda q, d: _hamilton(q, d, cross_sign=0.0),
            "the vector part has three terms; one of them is a cross product.",
        ),
        Mistake(lambda q, d: q * d, "that is the component-wise product, not the Hamilton product."),
    ],
)


def _small_net():
    """A small RetargetNet whose F_qlinear has seeded random weights (the default init is the identity)."""
    import torch

    from motionlab.retargeting.model import ModelConfig, RetargetNet

    net = RetargetNet(ModelConfig(latent=16, hidden=16, skel_embed=4)).eval()
    g = _gen(205)
    with torch.no_grad():
        net.f_qlinear.weight.copy_(0.3 * torch.randn(net.f_qlinear.weight.shape, generator=g))
        net.f_qlinear.bias.copy_(0.3 * torch.randn(net.f_qlinear.bias.shape, generator=g))
    return net


def _rotations_cases():
    import torch

    net, g = _small_net(), _gen(206)
    return [(net, torch.randn(2, 30, 16, generator=g)), (net, torch.randn(1, 5, 16, generator=g))]


def _rotations_ref(net, phi):
    import torch

    with torch.no_grad():
        return net.rotations(phi)


def _raw(net, phi):
    import torch

    with torch.no_grad():
        return net.f_qlinear(phi)


rotations = Exercise(
    "02 · exercise 3 (F_qlinear)",
    _rotations_ref,
    _rotations_cases,
    atol=1e-5,
    mistakes=[
        Mistake(
            lambda n, phi: _raw(n, phi).reshape(*phi.shape[:2], 22, 4),
            "the shape is right but the quaternions are not unit length: divide each by its norm.",
        ),
        Mistake(
            lambda n, phi: (_raw(n, phi) / _raw(n, phi).norm(dim=-1, keepdim=True)).reshape(*phi.shape[:2], 22, 4),
            "you normalised the 88 numbers of a frame together; each joint's 4 numbers must have length 1.",
        ),
        Mistake(
            lambda n, phi: _unit_last(_raw(n, phi).reshape(*phi.shape[:2], 4, 22).transpose(-1, -2)),
            "the 88 outputs are 22 groups of 4 consecutive numbers (joint by joint): reshape to (B, T, 22, 4) directly.",
        ),
    ],
)


def _unit_last(x):
    return x / x.norm(dim=-1, keepdim=True)


# --------------------------------------------------------------------------- notebook 03
def _foot_cases():
    import torch

    g = _gen(300)
    return [
        (0.05 * torch.randn(3, 50, 22, generator=g),),
        (0.05 * torch.randn(40, 22, generator=g) - 0.02,),  # no batch dimension, mostly below ground
        (torch.rand(20, 22, generator=g) + 0.01,),  # every joint above ground: L_foot = 0
    ]


def _foot_ref(world_y):
    from motionlab.retargeting import losses

    return losses.foot_loss(world_y)


def _feet(world_y):
    from motionlab.retargeting import losses

    return world_y[..., list(losses.FOOT_JOINTS)]


foot_loss = Exercise(
    "03 · exercise 1 (L_foot)",
    _foot_ref,
    _foot_cases,
    atol=1e-7,
    mistakes=[
        Mistake(
            lambda y: _feet(y).clamp(max=0).mean(),
            "your loss is negative: a foot below the floor must cost a positive amount (the depth |min(y, 0)|).",
        ),
        Mistake(
            lambda y: y.clamp(max=0).abs().mean(),
            "only the four foot joints (FEET: both ankles and toes) count, not all 22 joints.",
        ),
        Mistake(
            lambda y: _feet(y).abs().mean(),
            "a foot above the floor costs nothing: only heights below y = 0 enter the loss.",
        ),
        Mistake(
            lambda y: (_feet(y).clamp(max=0) ** 2).mean(),
            "eq. 17 averages the depths |min(y, 0)| themselves, not their squares.",
        ),
        Mistake(
            lambda y: _feet(y).clamp(max=0).abs().sum(-1).mean(),
            "average over the four feet too, not only over the frames.",
        ),
    ],
)


def _root_cases():
    from motionlab import synthetic
    from motionlab.core import humanoid

    base = humanoid.canonical_skeleton(1.75)
    return [
        (base, humanoid.scale_bones(base, legs=1.3)),
        (base, synthetic.random_character(5, legs=(0.75, 0.8))),
        (humanoid.canonical_skeleton(1.60), base),
        (base, humanoid.scale_bones(base, arms=1.4)),  # arms only: the legs, and r_xz, do not change
    ]


def _root_ref(source_skeleton, target_skeleton):
    from motionlab.retargeting import pipeline

    return pipeline.root_scale(source_skeleton, target_skeleton)[0]


def _ratio_of(measure):
    def wrong(a, b):
        return measure(b) / measure(a)

    return wrong


def _hip_height(sk):
    from motionlab.retargeting import pipeline

    return pipeline.hip_height(sk)


def _thigh_shin(sk):
    from motionlab.core import humanoid

    return humanoid.leg_length(sk)


def _height(sk):
    return sk.height()


root_scale = Exercise(
    "03 · exercise 2 (root scale r_xz)",
    _root_ref,
    _root_cases,
    atol=1e-6,
    mistakes=[
        Mistake(
            _ratio_of(_hip_height),
            "that is r_y, the ratio of the hip heights. r_xz sums the lengths of the leg's bones.",
        ),
        Mistake(
            _ratio_of(_thigh_shin),
            "thigh + shin is not the whole chain: it starts with the bone into UpLeg (the hip "
            "offset) and ends with the bone into ToeBase.",
        ),
        Mistake(
            _ratio_of(_height),
            "that is the ratio of the whole heights; r_xz compares the legs only (try a character with longer arms).",
        ),
        Mistake(
            lambda a, b: _root_ref(b, a),
            "upside down: the ratio is B's leg chain over A's (a longer leg takes a longer stride).",
        ),
    ],
)


def _angle_cases():
    import torch

    qa = _unit_quats((1, 40, 22), 301)
    near = qa + 0.05 * torch.randn(qa.shape, generator=_gen(302))
    near = near / near.norm(dim=-1, keepdim=True)
    flip = torch.where(torch.rand(qa.shape[:-1] + (1,), generator=_gen(303)) < 0.5, -1.0, 1.0)
    return [
        (qa, _unit_quats((1, 40, 22), 304)),
        (qa, near * flip),  # half of the quaternions negated: the same rotations
        (_unit_quats((2, 10, 22), 305), _unit_quats((2, 10, 22), 306)),
    ]


def _angle_ref(source_rot, generated_rot):
    from motionlab.retargeting import losses

    return losses.angle_loss(source_rot, generated_rot)


def _angle_between(a, b):
    import torch

    return 2 * torch.arccos((a * b).sum(-1).abs().clamp(max=1.0))


angle_loss = Exercise(
    "03 · exercise 3 (L_angle)",
    _angle_ref,
    _angle_cases,
    atol=1e-5,
    mistakes=[
        Mistake(
            lambda a, b: (a - b).norm(dim=-1).mean(),
            "q and −q are the same rotation: take the smaller of ‖q_A − q_B'‖ and ‖q_A + q_B'‖.",
        ),
        Mistake(
            lambda a, b: (a - b).norm(dim=-1).maximum((a + b).norm(dim=-1)).mean(),
            "q and −q are the same rotation, so the distance is the *smaller* of the two norms.",
        ),
        Mistake(
            lambda a, b: ((a - b).norm(dim=-1) ** 2).minimum((a + b).norm(dim=-1) ** 2).mean(),
            "eq. 16 averages the norms themselves, not their squares.",
        ),
        Mistake(
            lambda a, b: _angle_between(a, b).mean(),
            "that is the rotation angle α; L_angle uses the length of the quaternions' difference (2 sin(α/4)).",
        ),
    ],
)


# --------------------------------------------------------------------------- notebook 03, experiment
_RUNS: dict = {}


def _paper_angle(source, target, checkpoint, lambda_foot: float = 5.0, paper: bool = True, degrees: bool = True):
    """Mean angle (over joints and frames) between A's rotations and the full method's, in the
    paper's set-up (encoder start, no contact term, lr 0.1) or motionlab's, for ``lambda_foot``."""
    from motionlab import retargeting
    from motionlab.core import preprocess
    from motionlab.retargeting import plots
    from motionlab.retargeting.solver import SolverConfig

    key = (id(source), id(target), id(checkpoint), lambda_foot, paper)
    if key not in _RUNS:
        if paper:
            cfg = SolverConfig(init="encoder", lambda_contact=0.0, lr=0.1, lambda_foot=lambda_foot)
        else:
            cfg = SolverConfig(lambda_foot=lambda_foot)
        run = retargeting.retarget(source, target, checkpoint, "full", cfg)
        src = preprocess.prepare(source, checkpoint.fps)
        _RUNS[key] = float(plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean())
    value = _RUNS[key]
    return value if degrees else float(np.radians(value))


foot_weight = Question(
    "03 · exercise 4 (experiment: λ_foot in the paper's set-up)",
    lambda source, target, ckpt: _paper_angle(source, target, ckpt, 5.0),
    atol=0.006,  # an answer typed with two decimals passes
    rtol=0.005,
    mistakes=[
        Mistake(
            lambda source, target, ckpt: _paper_angle(source, target, ckpt, 0.5),
            "that is the result with the paper's weight λ_foot = 0.5; the exercise asks for λ_foot = 5.",
        ),
        Mistake(
            lambda source, target, ckpt: _paper_angle(source, target, ckpt, 5.0, paper=False),
            "that is motionlab's set-up (Gauss–Newton start, contact term); the paper's is "
            "SolverConfig(init='encoder', lambda_contact=0.0, lr=0.1, lambda_foot=5.0).",
        ),
        Mistake(
            lambda source, target, ckpt: _paper_angle(source, target, ckpt, 5.0, degrees=False),
            "that number is in radians; plots.joint_angle_errors gives degrees.",
        ),
    ],
)
