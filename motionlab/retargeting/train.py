"""Train the retargeting network on ONE character's clips with L_recon (paper A, eq. 8).

::

    data = training_set(motions)                  # windows of features, rotations, skeleton
    ckpt, history = train(data, TrainConfig(steps=2000, seed=0), callback=plot_live)
    checkpoint.save("aj.pt", ckpt)

Training is reproducible under ``TrainConfig.seed`` (weights, batch order, augmentation).

**Skeleton augmentation (our addition, on by default).** With one training character, F_skel
only ever sees one input, so what F_Δ does for another skeleton is undefined. Each training
window is therefore also decoded on a randomly re-proportioned copy of A's skeleton (legs,
arms, spine, neck and overall size scaled independently), with the target positions computed
by FK of A's own rotations on that skeleton. This uses A's data only and teaches F_Δ to leave
rotations alone when only proportions change; the latent iteration then adapts the motion.
``augment=False`` gives the paper's plain setting.

**Mirrored clips (our addition, on by default).** :func:`training_set` also adds every clip
mirrored left↔right (:func:`mirrored`): twice the poses from the same recording
(``benchmarks/bench_retarget.py`` prints its effect on held-back clips).

**Weights on a grid (``TrainConfig.grid``, on by default).** Another numeric back end adds in
another order, so gradients differ in their last bits, and Adam, which divides each gradient by
its own running size, lets such differences grow over a thousand steps. As in the latent
iteration (:func:`motionlab.retargeting.grid.step_grid`), the initial weights are rounded to
``step_grid(lr)`` and every parameter, after each Adam step, to ``step_grid(lr_t)`` (``lr_t`` the
step's learning rate: a power of two about 2⁻¹² of it), and the skeleton augmentation's scale
factors to :data:`DRAW_GRID`. Rare last-bit differences are then rounded away instead of growing;
a change of kernels (scalar against SIMD) differs too often over a training's updates, which is
why :func:`motionlab.retargeting.real.load_real` trains under one pinned back end
(``docs/reproducibility.md``, ``python -m experiments.retargeting.reproducibility --training``).

Taught in ``notebooks/02_training_autoencoder.ipynb``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass

import numpy as np
import torch
from tqdm.auto import tqdm

from motionlab.core import humanoid, preprocess
from motionlab.core import quat_torch as tq
from motionlab.core.motion import Motion
from motionlab.core.preprocess import NormStats
from motionlab.core.skeleton import Skeleton
from motionlab.retargeting import devices, losses
from motionlab.retargeting.checkpoint import DTYPES, Checkpoint
from motionlab.retargeting.features import clip_features
from motionlab.retargeting.grid import step_grid
from motionlab.retargeting.model import NUM_JOINTS, ModelConfig, RetargetNet

__all__ = [
    "TrainingSet",
    "training_set",
    "mirrored",
    "TrainConfig",
    "random_turns",
    "turned_window",
    "train",
    "pick_device",
    "DRAW_GRID",
    "snap",
]

DRAW_GRID = 2.0**-20
"""Spacing the skeleton augmentation's scale factors are rounded to (with ``TrainConfig.grid``):
``exp`` may differ in its last bit between SIMD widths; a factor on this grid does not."""

_DRAWS = {"dtype": torch.float32, "device": "cpu"}
"""Random draws (skeleton and pose augmentation) come from a CPU generator in float32, then move to
the training device: one seed gives the same batches on every device."""

_SWAP = [
    humanoid.JOINTS.index(n.replace("Left", "#").replace("Right", "Left").replace("#", "Right"))
    for n in humanoid.JOINTS
]


def mirrored(motion: Motion) -> Motion:
    """A canonical 22-joint motion reflected in the character's median plane (x → −x).

    Left and right joints swap; offsets and root positions get ``x`` negated; a rotation ``R``
    becomes ``M R M`` with ``M = diag(−1, 1, 1)``, i.e. the quaternion ``(w, x, y, z)`` becomes
    ``(w, x, −y, −z)``. FK of the result is the mirror image of FK of ``motion``.

    Raises
    ------
    ValueError when the motion is not on the 22-joint canonical skeleton.
    """
    if not humanoid.is_canonical(motion.skeleton):
        raise ValueError("mirrored needs a 22-joint canonical motion; call preprocess.prepare first")
    offsets = np.asarray(motion.skeleton.offsets)[_SWAP] * np.array([-1.0, 1.0, 1.0])
    rot = np.asarray(motion.local_rot)[:, _SWAP] * np.array([1.0, 1.0, -1.0, -1.0])
    root = np.asarray(motion.root_pos) * np.array([-1.0, 1.0, 1.0])
    name = f"{motion.name} (mirrored)" if motion.name else "mirrored"
    return Motion(motion.skeleton.with_offsets(offsets), rot, root, motion.fps, None, name)


def pick_device(device: str | torch.device | None = None) -> torch.device:
    """:func:`motionlab.retargeting.devices.pick`: ``device`` checked, else CUDA when available, else
    the CPU. Raises ``ValueError`` for a device this machine does not have."""
    return devices.pick(device)


@dataclass
class TrainingSet:
    """Windows of one character's clips.

    Attributes
    ----------
    x : ndarray (N, W, 70)            un-normalised features
    positions : ndarray (N, W, 22, 3) root-relative heading-frame positions, metres
    local_rot : ndarray (N, W, 22, 4) local rotations (root in the heading frame)
    skeleton : Skeleton               the character's canonical skeleton
    stats : NormStats                 fitted on all frames of all clips
    fps : float
    window : int
    names : list of str               clip names
    """

    x: np.ndarray
    positions: np.ndarray
    local_rot: np.ndarray
    skeleton: Skeleton
    stats: NormStats
    fps: float
    window: int
    names: list

    def __len__(self) -> int:
        return len(self.x)


def training_set(
    motions: Sequence[Motion],
    fps: float = 60.0,
    window: int = 120,
    stride: int = 30,
    progress: bool = True,
    mirror: bool = True,
) -> TrainingSet:
    """Reduce clips of one character to 22 joints at ``fps`` and cut them into windows.

    With ``mirror`` every clip is also added mirrored (:func:`mirrored`), so the set has twice
    the windows; the skeleton and statistics are those of the clips as given plus their mirrors.

    Raises ``ValueError`` when the clips are not all of the same character (canonical rest
    offsets differing by more than 2% of the height), when one is empty or has NaNs.
    """
    if not motions:
        raise ValueError("training_set needs at least one motion")
    feats, skeleton = [], None
    for m in tqdm(motions, desc="preprocessing", disable=not progress, leave=False):
        c = preprocess.prepare(m, fps)
        if skeleton is None:
            skeleton = c.skeleton
        else:
            dev = np.abs(c.skeleton.offsets[1:] - skeleton.offsets[1:]).max()
            if dev > 0.02 * skeleton.height():
                raise ValueError(
                    f"clip {m.name!r} is on another skeleton (offsets differ by {dev:.3f} m from {motions[0].name!r}); "
                    "train on one character's clips only"
                )
        feats.append(clip_features(c))
        if mirror:
            feats.append(clip_features(mirrored(c)))
    stats = NormStats.fit([f.x for f in feats])
    x, index = preprocess.window_stack([f.x for f in feats], window, stride)
    positions, _ = preprocess.window_stack([f.positions for f in feats], window, stride)
    local_rot, _ = preprocess.window_stack([f.local_rot for f in feats], window, stride)
    del index
    return TrainingSet(
        x.astype(np.float32),
        positions.astype(np.float32),
        local_rot.astype(np.float32),
        skeleton,
        stats,
        float(fps),
        int(window),
        [m.name for m in motions],
    )


@dataclass
class TrainConfig:
    """Training settings; the defaults train a useful model on a 2-core CPU in a few minutes.

    Attributes
    ----------
    steps : int             Adam steps
    batch_size : int        windows per step
    lr : float              initial learning rate (cosine decay to ``lr / 10``)
    seed : int              seeds weights, batch order and augmentation
    recon_weight : float    λ_recon of eq. (8)
    rot_weight : float      weight of the rotation regulariser (0 = paper; see :mod:`.losses`)
    augment : float         fraction of each batch decoded on a re-proportioned skeleton (0 = off)
    scale_range : float     bone-group scales drawn log-uniformly in [1/scale_range, scale_range]
    overall_range : float   overall size drawn log-uniformly in [1/overall_range, overall_range]
    pose_augment : float    fraction of each batch whose joint rotations are perturbed (0 = off):
                            every non-root joint turned by a random rotation, fixed over the window
    pose_noise : float      largest angle (radians) of those rotations
    log_every : int         steps between history entries / callback calls
    device : str or None    None: CUDA when available, else CPU
    dtype : str             ``"float64"`` (default: the same numbers on every CPU, to the digits
                            the notebooks print) or ``"float32"`` (faster on a GPU)
    grid : bool             round the initial weights and every parameter after each step to
                            ``step_grid(lr_t)``, and augmentation factors to :data:`DRAW_GRID`, so
                            that rare last-bit differences do not grow (see the module docstring)
    """

    steps: int = 1500
    batch_size: int = 32
    lr: float = 2e-3
    seed: int = 0
    recon_weight: float = losses.LAMBDA_RECON
    rot_weight: float = 0.1
    augment: float = 0.5
    scale_range: float = 1.5
    overall_range: float = 2.0
    pose_augment: float = 0.0
    pose_noise: float = 0.3
    log_every: int = 10
    device: str | None = None
    dtype: str = "float64"
    grid: bool = True

    def __post_init__(self) -> None:
        if self.dtype not in DTYPES:
            raise ValueError(f"dtype must be one of {tuple(DTYPES)}, got {self.dtype!r}")
        if self.steps < 1 or self.batch_size < 1 or self.log_every < 1:
            raise ValueError(
                f"steps, batch_size and log_every must be positive, got {self.steps}, {self.batch_size}, {self.log_every}"
            )
        if not self.lr > 0:
            raise ValueError(f"lr must be positive, got {self.lr}")
        if not 0.0 <= self.augment <= 1.0:
            raise ValueError(f"augment is a fraction in [0, 1], got {self.augment}")
        if not (0.0 <= self.pose_augment <= 1.0 and self.augment + self.pose_augment <= 1.0):
            raise ValueError(
                f"pose_augment is a fraction in [0, 1 - augment], got {self.pose_augment} (augment {self.augment})"
            )
        if not self.pose_noise >= 0:
            raise ValueError(f"pose_noise must be >= 0 radians, got {self.pose_noise}")
        if self.scale_range < 1.0 or self.overall_range < 1.0:
            raise ValueError("scale_range and overall_range must be >= 1")


def _group_index() -> tuple[list[str], np.ndarray]:
    """Which proportion group (index into the returned names) scales each joint's bone; -1: none."""
    groups = list(humanoid.BONE_GROUPS)
    idx = -np.ones(len(humanoid.JOINTS), dtype=np.int64)
    for g, names in enumerate(groups):
        for n in humanoid.BONE_GROUPS[names]:
            idx[humanoid.JOINTS.index(n)] = g
    return groups, idx


def random_offsets(base: torch.Tensor, batch: int, cfg: TrainConfig, generator: torch.Generator) -> torch.Tensor:
    """``batch`` re-proportioned copies (batch, 22, 3) of the offsets ``base`` (22, 3)."""
    groups, idx = _group_index()
    log_s = math.log(cfg.scale_range)
    log_o = math.log(cfg.overall_range)
    g = (torch.rand(batch, len(groups), generator=generator, **_DRAWS) * 2 - 1) * log_s
    overall = (torch.rand(batch, 1, generator=generator, **_DRAWS) * 2 - 1) * log_o
    per_joint = torch.zeros(batch, len(humanoid.JOINTS), **_DRAWS)
    mask = torch.as_tensor(idx >= 0, device="cpu")
    per_joint[:, mask] = g[:, torch.as_tensor(idx[idx >= 0], device="cpu")]
    factor = torch.exp(per_joint + overall)
    if cfg.grid:  # exp's last bit differs between SIMD widths; the rounded factor does not
        factor = torch.round(factor / DRAW_GRID) * DRAW_GRID
    return base[None] * factor[..., None].to(base)


def random_turns(batch: int, cfg: TrainConfig, generator: torch.Generator) -> torch.Tensor:
    """``batch`` sets (batch, 22, 4) of random rotations, uniform axis, angle uniform in
    [0, ``cfg.pose_noise``]; the root's is the identity."""
    axis = torch.randn(batch, len(humanoid.JOINTS), 3, generator=generator, **_DRAWS)
    axis = axis / axis.norm(dim=-1, keepdim=True).clamp_min(1e-9)
    angle = torch.rand(batch, len(humanoid.JOINTS), generator=generator, **_DRAWS) * cfg.pose_noise
    angle[:, 0] = 0.0
    return torch.cat([torch.cos(angle / 2)[..., None], torch.sin(angle / 2)[..., None] * axis], dim=-1)


@torch.no_grad()
def turned_window(
    x: torch.Tensor, local_rot: torch.Tensor, offsets: torch.Tensor, turns: torch.Tensor, mean, std
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Windows with every joint turned by ``turns``: new features, rotations and positions.

    ``x`` (n, W, 70) normalised features, ``local_rot`` (n, W, 22, 4), ``offsets`` (n, 22, 3),
    ``turns`` (n, 22, 4) (applied on the right, ``q ⊗ turn``, the same in every frame), ``mean`` and
    ``std`` (70,) the normalisation. The features' joint positions (the first 66 numbers: FK in the
    heading frame, lifted by the root height) are recomputed; the root's motion (v_x, v_z, ω, h)
    is unchanged. Returns ``(x', local_rot', positions')``, positions root-relative (n, W, 22, 3).
    """
    mean, std = torch.as_tensor(mean).to(x), torch.as_tensor(std).to(x)
    cols = slice(0, 3 * NUM_JOINTS)
    turned = tq.normalize(tq.mul(local_rot, turns[:, None]))
    pos = RetargetNet.forward_kinematics(turned, offsets)
    height = x[..., -1] * std[-1] + mean[-1]  # the root height, metres
    lifted = pos + torch.stack([torch.zeros_like(height), height, torch.zeros_like(height)], -1)[..., None, :]
    out = x.clone()
    out[..., cols] = (lifted.flatten(-2) - mean[cols]) / std[cols]
    return out, turned, pos


@dataclass
class _Windows:
    """The training windows as tensors: normalised features x (W, T, 70), FK positions (W, T, 22, 3)
    and local rotations (W, T, 22, 4) on the device; A's offsets ``base`` (22, 3), root offset zeroed,
    and the feature statistics ``mean``, ``std`` (70,) on the CPU."""

    x: torch.Tensor
    positions: torch.Tensor
    local_rot: torch.Tensor
    base: torch.Tensor
    mean: torch.Tensor
    std: torch.Tensor

    def __len__(self) -> int:
        return len(self.x)


def _windows(data: TrainingSet, dtype: torch.dtype, device: torch.device) -> _Windows:
    cpu = dict(dtype=dtype, device="cpu")
    mean = torch.as_tensor(data.stats.mean, **cpu)
    std = torch.as_tensor(data.stats.std, **cpu)
    x_all = ((torch.as_tensor(data.x, device="cpu").to(dtype) - mean) / std).to(device)
    pos_all = torch.as_tensor(data.positions, device=device).to(dtype)
    rot_all = torch.as_tensor(data.local_rot, device=device).to(dtype)
    base = torch.tensor(data.skeleton.offsets, **cpu)
    base[0] = 0.0
    return _Windows(x_all, pos_all, rot_all, base, mean, std)


def _batch(w: _Windows, cfg: TrainConfig, gen: torch.Generator):
    """One batch ``(x, local_rot, target positions, offsets)``: windows drawn with ``gen``; the first
    ``augment`` of them on re-proportioned skeletons (targets by FK of A's rotations), the last
    ``pose_augment`` with joints turned and features recomputed."""
    device, dtype = w.x.device, w.x.dtype
    n_aug = int(round(cfg.augment * cfg.batch_size))
    n_pose = min(int(round(cfg.pose_augment * cfg.batch_size)), cfg.batch_size - n_aug)
    idx = torch.randint(len(w), (cfg.batch_size,), generator=gen, device="cpu").to(device)
    offsets = w.base[None].repeat(cfg.batch_size, 1, 1)
    if n_aug:
        offsets[:n_aug] = random_offsets(w.base, n_aug, cfg, gen)
    offsets = offsets.to(device)
    x, rot = w.x[idx], w.local_rot[idx]
    target = w.positions[idx]
    if n_aug:
        with torch.no_grad():
            target = target.clone()
            target[:n_aug] = RetargetNet.forward_kinematics(rot[:n_aug], offsets[:n_aug])
    if n_pose:  # the last n_pose rows: A's skeleton, joints turned, features recomputed
        rows = slice(cfg.batch_size - n_pose, None)
        x, rot, target = x.clone(), rot.clone(), target.clone()
        turns = random_turns(n_pose, cfg, gen).to(device=device, dtype=dtype)
        x[rows], rot[rows], target[rows] = turned_window(x[rows], rot[rows], offsets[rows], turns, w.mean, w.std)
    return x, rot, target, offsets


@torch.no_grad()
def snap(model: torch.nn.Module, lr: float) -> None:
    """Round every parameter of ``model``, in place, to the grid ``step_grid(lr)`` (see the module docstring)."""
    g = step_grid(lr)
    for p in model.parameters():
        p.copy_(torch.round(p / g) * g)


def _initial_model(model_config: ModelConfig | None, cfg: TrainConfig, device: torch.device) -> RetargetNet:
    """The untrained network in training mode on ``device``, its weights drawn on the CPU (one seed,
    one network on every device) and, with ``cfg.grid``, rounded to ``step_grid(cfg.lr)``."""
    with torch.device("cpu"):
        model = RetargetNet(model_config)
    model = model.to(device=device, dtype=DTYPES[cfg.dtype])
    model.train()
    if cfg.grid:
        snap(model, cfg.lr)
    return model


def train(
    data: TrainingSet | Sequence[Motion],
    config: TrainConfig | None = None,
    model_config: ModelConfig | None = None,
    callback: Callable[[int, dict], None] | None = None,
    progress: bool = True,
) -> tuple[Checkpoint, list[dict]]:
    """Train a :class:`RetargetNet` on one character.

    Parameters
    ----------
    data : a :class:`TrainingSet`, or motions of one character (passed to :func:`training_set`)
    config, model_config : training and network settings (defaults if None)
    callback : called as ``callback(step, record)`` every ``log_every`` steps, where ``record``
        holds ``step``, ``loss``, ``recon``, ``rot``, ``lr`` and ``seconds`` (for live plots)
    progress : show a tqdm bar with the current loss

    Returns
    -------
    checkpoint : Checkpoint with the trained network (eval mode), statistics and skeleton
    history : list of the ``record`` dicts
    """
    cfg = config or TrainConfig()
    device = pick_device(cfg.device)  # a device that is not there fails before any work
    if not isinstance(data, TrainingSet):
        data = training_set(data, progress=progress)
    torch.manual_seed(cfg.seed)
    gen = torch.Generator().manual_seed(cfg.seed)
    dtype = DTYPES[cfg.dtype]
    model = _initial_model(model_config, cfg, device)
    windows = _windows(data, dtype, device)
    opt = torch.optim.Adam(model.parameters(), lr=cfg.lr)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, cfg.steps, eta_min=cfg.lr / 10)
    history: list[dict] = []
    start = time.perf_counter()
    bar = tqdm(range(1, cfg.steps + 1), desc="training", disable=not progress)
    running = None
    for step in bar:
        x, rot, target, offsets = _batch(windows, cfg, gen)
        out = model(x, offsets)
        recon = losses.recon_loss(out.positions, target, cfg.recon_weight)
        rot_l = (
            losses.rotation_loss(out.local_rot, rot)
            if cfg.rot_weight > 0
            else torch.zeros((), dtype=dtype, device=device)
        )
        loss = recon + cfg.rot_weight * rot_l
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        if cfg.grid:
            snap(model, opt.param_groups[0]["lr"])
        sched.step()
        with torch.no_grad():  # on the device: no host sync but at the logged steps
            running = loss.detach() if running is None else 0.95 * running + 0.05 * loss.detach()
        if step % cfg.log_every == 0 or step == cfg.steps:
            record = {
                "step": step,
                "loss": loss.item(),
                "recon": recon.item(),
                "rot": rot_l.item(),
                "lr": opt.param_groups[0]["lr"],
                "seconds": time.perf_counter() - start,
            }
            history.append(record)
            err_cm = 100 * 3 * record["recon"] / cfg.recon_weight if cfg.recon_weight else float("nan")
            bar.set_postfix(loss=f"{float(running):.4g}", err_cm=f"{err_cm:.2f}")
            if callback is not None:
                callback(step, record)
    model.eval()
    info = {
        "train_config": asdict(cfg),
        "clips": len(data.names),
        "windows": len(data),
        "final_loss": history[-1]["loss"],
        "final_recon": history[-1]["recon"],
        "seconds": time.perf_counter() - start,
    }
    return Checkpoint(model, data.stats, data.skeleton, data.fps, data.window, info), history
