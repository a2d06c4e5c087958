"""Exercises of notebooks 02 (the retargeting network), 03 (the latent iteration) and 07 (a database).

Most are experiments (:class:`~motionlab.exercises.core.Question`): the student changes one
parameter of a cell, runs it and types the number it gives; the check reruns the changed
experiment with the package on the notebook's own inputs (its network, clip and target), so one
key fits real and synthetic data. Each run is cached under a digest of what it depends on (the
network's weights, device and float type, the clip's numbers, the settings; a file's bytes), so a
check costs one decode (notebook 02) or one latent iteration (notebooks 03 and 07) at most, and
a changed input is never answered from the cache. The caller's network stays where it is (its
device and float type): the checks compute there.

``contact_loss`` asks for a function: its cases are small torch tensors drawn from a fixed seed (a
private generator: the notebook's own random state is left alone). torch is imported only when a
check runs.
"""

from __future__ import annotations

import numpy as np

from .core import Exercise, Mistake, Question

__all__ = [
    "q_delta_legs",
    "no_correction",
    "contact_loss",
    "encoder_start",
    "contact_weight",
    "foot_weight",
    "arm_length",
]


def _gen(seed: int):
    import torch

    return torch.Generator().manual_seed(seed)


def _feed(h, obj) -> None:
    """Add ``obj``'s contents to the hash ``h``: tensors and arrays by value (with dtype, shape and
    device), modules by their state, dataclasses, dicts and sequences item by item, paths by the
    file's bytes, anything else by ``repr``."""
    import dataclasses
    from pathlib import Path

    import torch

    if isinstance(obj, torch.nn.Module):
        obj = obj.state_dict()
    if isinstance(obj, torch.Tensor):
        h.update(f"tensor {obj.dtype} {tuple(obj.shape)} {obj.device}".encode())
        obj = obj.detach().cpu().numpy()
    if isinstance(obj, np.ndarray):
        h.update(f"array {obj.dtype} {obj.shape}".encode())
        h.update(np.ascontiguousarray(obj).tobytes())
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        h.update(type(obj).__name__.encode())
        for f in dataclasses.fields(obj):
            _feed(h, f.name)
            _feed(h, getattr(obj, f.name))
    elif isinstance(obj, dict):
        for k in sorted(obj, key=repr):
            _feed(h, k)
            _feed(h, obj[k])
    elif isinstance(obj, (list, tuple)):
        h.update(f"seq {len(obj)}".encode())
        for item in obj:
            _feed(h, item)
    elif isinstance(obj, Path):
        h.update(f"file {obj}".encode())
        h.update(obj.read_bytes())
    else:
        h.update(repr(obj).encode())


def _key(*inputs) -> str:
    """A digest of everything a cached run depends on (:func:`_feed`)."""
    import hashlib

    h = hashlib.sha256()
    for obj in inputs:
        _feed(h, obj)
    return h.hexdigest()


# --------------------------------------------------------------------------- notebook 02, experiments
_DECODED: dict = {}


def _decoded(checkpoint, clip, legs: float):
    """(features of the prepared clip, its offsets, the clip decoded on its own skeleton and on it with legs × ``legs``)."""
    import torch

    from motionlab.core import humanoid, preprocess
    from motionlab.retargeting.features import clip_features

    key = _key(checkpoint, clip, legs)
    if key not in _DECODED:
        prepared = preprocess.prepare(clip, checkpoint.fps)
        feats = clip_features(prepared)
        where = dict(dtype=checkpoint.dtype, device=checkpoint.device)
        x = torch.as_tensor(checkpoint.stats.normalize(feats.x), **where)[None]
        own = torch.tensor(prepared.skeleton.offsets, **where)
        other = torch.tensor(humanoid.scale_bones(prepared.skeleton, legs=legs).offsets, **where)
        model = checkpoint.model
        with torch.no_grad():
            phi = model.encode(x)
            _DECODED[key] = (feats, own, model.decode(phi, own), model.decode(phi, other))
    return _DECODED[key]


def _q_delta_change(checkpoint, clip, legs: float = 0.7, reduce=np.max, against_identity=False, degrees=True):
    """Largest (over joints) mean (over frames) angle between q_Δ on A's skeleton and on A with legs × ``legs``."""
    from motionlab.core import quat_torch as tq

    _, _, on_a, on_b = _decoded(checkpoint, clip, legs)
    other = tq.IDENTITY.to(on_a.q_delta) if against_identity else on_b.q_delta
    per_joint = tq.angle_between(on_a.q_delta, other).mean(dim=(0, 1)).cpu().numpy()  # (22,) radians
    value = float(reduce(per_joint))
    return float(np.degrees(value)) if degrees else value


q_delta_legs = Question(
    "02 · exercise 1 (experiment: q_Δ on shorter legs)",
    lambda checkpoint, clip: _q_delta_change(checkpoint, clip, 0.7),
    atol=0.0006,  # an answer typed with three decimals, as section 6 prints it, passes
    rtol=0.005,
    mistakes=[
        Mistake(
            lambda checkpoint, clip: _q_delta_change(checkpoint, clip, 1.3),
            "that is section 6's experiment, legs × 1.3; the exercise asks for legs × 0.7.",
        ),
        Mistake(
            lambda checkpoint, clip: _q_delta_change(checkpoint, clip, 0.7, np.mean),
            "that is the mean over the joints; report the largest change over all joints, as section 6 prints it.",
        ),
        Mistake(
            lambda checkpoint, clip: _q_delta_change(checkpoint, clip, 0.7, against_identity=True),
            "that is the size of q_Δ itself (its angle to the identity); the question is how much q_Δ "
            "*changes* between A's legs and the shorter legs.",
        ),
        Mistake(
            lambda checkpoint, clip: _q_delta_change(checkpoint, clip, 0.7, degrees=False),
            "that number is in radians; section 6 prints degrees.",
        ),
    ],
)


def _joint_error_cm(checkpoint, clip, correction: bool = False, centimetres: bool = True):
    """Mean joint error of the clip decoded on its own skeleton, with or without the correction q_Δ."""
    from motionlab.retargeting.model import RetargetNet

    feats, offsets, on_a, _ = _decoded(checkpoint, clip, 0.7)
    positions = on_a.positions if correction else RetargetNet.forward_kinematics(on_a.q, offsets)
    err = np.linalg.norm(positions[0].cpu().numpy() - feats.positions, axis=-1).mean()
    return float(100 * err if centimetres else err)


no_correction = Question(
    "02 · exercise 2 (experiment: decoding without q_Δ)",
    lambda checkpoint, clip: _joint_error_cm(checkpoint, clip),
    atol=0.006,  # an answer typed with two decimals passes
    rtol=0.005,
    mistakes=[
        Mistake(
            lambda checkpoint, clip: _joint_error_cm(checkpoint, clip, correction=True),
            "that is section 6's error, with the correction; decode with q alone: FK of `decoded.q`, not "
            "of `decoded.local_rot` (= q ⊗ q_Δ).",
        ),
        Mistake(
            lambda checkpoint, clip: _joint_error_cm(checkpoint, clip, centimetres=False),
            "that number is in metres; section 6 prints centimetres.",
        ),
    ],
)


# --------------------------------------------------------------------------- notebook 03
def _contact_cases():
    import torch

    g = _gen(300)

    def walk(*shape):  # positions that move a few centimetres per frame, metres
        return torch.cumsum(0.02 * torch.randn(*shape, 4, 3, generator=g, dtype=torch.float32, device="cpu"), dim=-3)

    def labels(*shape):
        return torch.rand(*shape, 4, generator=g, dtype=torch.float32, device="cpu") < 0.6

    return [
        (walk(2, 30), labels(2, 30), 60.0),
        (walk(25), labels(25), 30.0),  # no batch dimension, another frame rate
        (walk(1, 12), torch.zeros(1, 12, 4, dtype=torch.bool, device="cpu"), 60.0),  # never planted: 0
    ]


def _contact_ref(feet, planted, fps):
    from motionlab.retargeting import losses

    return losses.contact_loss(feet, planted, fps)


def _steps(feet, horizontal=False):
    d = feet[..., 1:, :, :] - feet[..., :-1, :, :]
    if horizontal:
        d = d[..., [0, 2]]
    return d.norm(dim=-1)  # (..., T-1, 4)


def _mean_over(values, mask):
    mask = mask.to(values.dtype)
    return (values * mask).sum() / mask.sum().clamp_min(1.0)


def _both(planted):
    return planted[..., 1:, :] & planted[..., :-1, :]


contact_loss = Exercise(
    "03 · exercise 1 (L_contact)",
    _contact_ref,
    _contact_cases,
    atol=1e-6,
    mistakes=[
        Mistake(
            lambda f, p, fps: _mean_over(_steps(f), _both(p)),
            "that is a distance per frame; L_contact is a speed in m/s (a frame lasts 1 / fps seconds).",
        ),
        Mistake(
            lambda f, p, fps: fps * _mean_over(_steps(f), p[..., :-1, :]),
            "a step from frame t to t + 1 counts only when the foot is planted in *both* frames (a foot "
            "that lifts off or lands moves legitimately).",
        ),
        Mistake(
            lambda f, p, fps: fps * (_steps(f) * _both(p)).mean(),
            "average over the planted steps only: dividing by every step (planted or not) makes the "
            "loss depend on how often the foot is planted.",
        ),
        Mistake(
            lambda f, p, fps: fps * _mean_over(_steps(f, horizontal=True), _both(p)),
            "a planted foot should not move in the world at all: measure the whole 3-D step, not only x and z.",
        ),
    ],
)


# --------------------------------------------------------------------------- notebook 03, experiments
_RUNS: dict = {}
PAPER = {"init": "encoder", "lr": 0.1, "weights": {"contact": 0.0, "clearance": 0.0}}
"""The paper-like set-up in :class:`~motionlab.retargeting.solver.SolverConfig` terms (section 5 of notebook 03)."""


def _measure(source, target, checkpoint, what: str, **settings) -> float:
    """One number of the full method's result on (source, target) with ``SolverConfig(**settings)``.

    ``what``: ``"angle"`` (mean angle to A's local rotations, degrees), ``"slide"`` (speed of A's
    planted feet on B, cm/s), ``"skating"`` (foot speed near the ground, cm/s) or ``"steps"``.
    """
    from motionlab import retargeting
    from motionlab.core import humanoid, metrics, preprocess
    from motionlab.retargeting import pipeline, plots
    from motionlab.retargeting.solver import SolverConfig

    key = _key(source, target, checkpoint, settings)
    if key not in _RUNS:
        run = retargeting.retarget(source, target, checkpoint, "full", SolverConfig(**settings))
        src = preprocess.prepare(source, checkpoint.fps, stand=True)  # A as section 5 measures it
        feet = [humanoid.JOINTS.index(n) for n in humanoid.FEET]
        n = min(len(run.positions), src.num_frames)
        planted = pipeline.source_contacts(src)[:n]
        _RUNS[key] = {
            "angle": float(plots.joint_angle_errors(run.motion.local_rot, src.local_rot).mean()),
            "slide": 100 * float(metrics.planted_slide(run.positions[:n], feet, planted, checkpoint.fps)),
            "skating": 100 * float(metrics.foot_skating(run.positions, feet, checkpoint.fps)),
            "steps": float(run.steps),
        }
    return _RUNS[key][what]


def _paper_angle(source, target, checkpoint, lambda_foot: float = 5.0, paper: bool = True, degrees: bool = True):
    """Mean angle (degrees) between A's rotations and the full method's, in the paper-like set-up
    (encoder start, no foot terms of motionlab's, lr 0.1) or motionlab's, for ``lambda_foot``."""
    settings = dict(PAPER, lambda_foot=lambda_foot) if paper else {"lambda_foot": lambda_foot}
    value = _measure(source, target, checkpoint, "angle", **settings)
    return value if degrees else float(np.radians(value))


encoder_start = Question(
    "03 · exercise 2 (experiment: motionlab without the Gauss–Newton start)",
    lambda source, target, ckpt: _measure(source, target, ckpt, "angle", init="encoder"),
    atol=0.006,  # an answer typed with two decimals passes
    rtol=0.005,
    mistakes=[
        Mistake(
            lambda source, target, ckpt: _measure(source, target, ckpt, "angle", init="encoder", lr=0.1),
            "that is section 5's row 'encoder start + foot terms', which also sets lr=0.1; change "
            "only the start: SolverConfig(init='encoder').",
        ),
        Mistake(
            lambda source, target, ckpt: _measure(source, target, ckpt, "angle", **PAPER),
            "that is the paper-like set-up (no foot terms, lr=0.1); keep motionlab's other settings.",
        ),
        Mistake(
            lambda source, target, ckpt: _measure(source, target, ckpt, "angle"),
            "that is the default run (the Gauss–Newton start); set init='encoder'.",
        ),
        Mistake(
            lambda source, target, ckpt: float(np.radians(_measure(source, target, ckpt, "angle", init="encoder"))),
            "that number is in radians; plots.joint_angle_errors gives degrees.",
        ),
    ],
)


contact_weight = Question(
    "03 · exercise 3 (experiment: a fifth of the contact weight)",
    lambda source, target, ckpt: _measure(source, target, ckpt, "slide", lambda_contact=0.1),
    atol=0.006,  # an answer typed with two decimals passes
    rtol=0.005,
    mistakes=[
        Mistake(
            lambda source, target, ckpt: _measure(source, target, ckpt, "slide"),
            "that is the default weight's slide (λ_contact = 0.5, the full method); set lambda_contact=0.1.",
        ),
        Mistake(
            lambda source, target, ckpt: _measure(source, target, ckpt, "slide", lambda_contact=0.0),
            "that is the run without the contact term (λ_contact = 0); set lambda_contact=0.1.",
        ),
        Mistake(
            lambda source, target, ckpt: _measure(source, target, ckpt, "skating", lambda_contact=0.1),
            "that is the skating (any foot near the ground); the slide counts A's planted feet only "
            "(metrics.planted_slide with pipeline.source_contacts(src)).",
        ),
        Mistake(
            lambda source, target, ckpt: _measure(source, target, ckpt, "slide", lambda_contact=0.1) / 100,
            "that number is in m/s; section 5 prints cm/s.",
        ),
    ],
)


foot_weight = Question(
    "03 · exercise 4 (experiment: λ_foot in the paper-like set-up)",
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
            "that is motionlab's set-up (Gauss–Newton start, foot terms); the paper's is section 5's "
            "SolverConfig(init='encoder', lr=0.1, weights=paper_only) with lambda_foot=5.0.",
        ),
        Mistake(
            lambda source, target, ckpt: _paper_angle(source, target, ckpt, 5.0, degrees=False),
            "that number is in radians; plots.joint_angle_errors gives degrees.",
        ),
    ],
)


# --------------------------------------------------------------------------- notebook 07, experiment
_PLAUSIBILITY: dict = {}


def _arms_plausibility(clip_path, checkpoint, solver, arms: float = 1.3):
    """The plausibility of ``clip_path`` retargeted onto the canonical character with arms × ``arms``."""
    from pathlib import Path

    from motionlab.core import bvh, humanoid
    from motionlab.retargeting.pipeline import retarget

    key = _key(Path(clip_path), checkpoint, solver, arms)
    if key not in _PLAUSIBILITY:
        target = humanoid.scale_bones(humanoid.canonical_skeleton(), arms=arms)
        result = retarget(bvh.load(clip_path), target, checkpoint, solver=solver)
        _PLAUSIBILITY[key] = (result.plausibility, float(result.positions[..., 1].min()))
    return _PLAUSIBILITY[key]


arm_length = Question(
    "07 · exercise 1 (experiment: how long may the arms be?)",
    lambda clip_path, ckpt, solver: _arms_plausibility(clip_path, ckpt, solver)[0].lowest,
    atol=0.0006,  # an answer typed with three decimals passes
    rtol=0.005,
    mistakes=[
        Mistake(
            lambda clip_path, ckpt, solver: _arms_plausibility(clip_path, ckpt, solver, 1.35)[0].lowest,
            "that is the `long_arms` preset (arms × 1.35); the exercise asks for arms × 1.3.",
        ),
        Mistake(
            lambda clip_path, ckpt, solver: _arms_plausibility(clip_path, ckpt, solver)[0].source_lowest,
            "that is A's lowest joint in the source (`source_lowest`); report B's, `plausibility.lowest`.",
        ),
        Mistake(
            lambda clip_path, ckpt, solver: 100 * _arms_plausibility(clip_path, ckpt, solver)[1],
            "that is the lowest joint's height in centimetres; the floor test measures it as a fraction "
            "of B's leg length (`plausibility.lowest`).",
        ),
        Mistake(
            lambda clip_path, ckpt, solver: _arms_plausibility(clip_path, ckpt, solver)[1],
            "that is the lowest joint's height in metres; the floor test measures it as a fraction of "
            "B's leg length (`plausibility.lowest`).",
        ),
    ],
)


# --------------------------------------------------------------------------- notebook 03, exercise 5 (experiment)
__all__ += ["theta_directions"]

theta_directions = Question(
    "03 · exercise 5 (experiment: θ as bone directions)",
    lambda source, target, ckpt: _measure(source, target, ckpt, "angle", theta="directions"),
    atol=0.006,  # an answer typed with two decimals passes
    rtol=0.005,
    mistakes=[
        Mistake(
            lambda source, target, ckpt: _measure(source, target, ckpt, "angle"),
            "that is the default run (θ = local rotations); set theta='directions'.",
        ),
        Mistake(
            lambda source, target, ckpt: _measure(source, target, ckpt, "angle", theta="directions", **PAPER),
            "that run also takes the paper's other settings (no contact term, lr=0.1); change only theta.",
        ),
        Mistake(
            lambda source, target, ckpt: float(np.radians(_measure(source, target, ckpt, "angle", theta="directions"))),
            "that number is in radians; plots.joint_angle_errors gives degrees.",
        ),
    ],
)
"""Notebook 03: the mean angle (degrees) between A's local rotations and the full method's with
θ = unit bone directions (``SolverConfig(theta="directions")``), every other setting at its default."""
