"""Generation for a new skeleton by latent-space iteration (paper A, §3.3).

The network is frozen. Starting from ``φ = F_enc(X_A)``, only the latent ``φ`` is updated with
Adam so that the motion decoded on B's skeleton keeps A's joint angles and keeps its feet
above the ground::

    L_iter = λ_angle · L_angle(A, B') + λ_foot · L_foot(B'),    λ_angle = 0.3, λ_foot = 0.5

until ``L_iter`` drops below ``threshold``, stops improving (``patience`` steps without a
relative gain of ``min_delta``), or ``max_steps`` is reached. All sequences of a batch (e.g.
all windows of a clip, or several clips of equal length) are solved together: their losses are
averaged, so one Adam run moves every latent.

**Smooth latent updates (our addition).** The decoder works frame by frame, so per-frame
Adam steps on φ add frame-to-frame jitter (on the Mixamo data the mean acceleration tripled,
0.30 → 0.91 cm/frame²). We therefore write ``φ = φ₀ + G_σ * δ``, where ``G_σ`` is a fixed
Gaussian filter along time (σ = ``smooth_sigma`` frames) and optimise the free offset ``δ``:
still only the latent moves and the loss is unchanged, but every update is temporally smooth.
``smooth_sigma=0`` optimises φ directly, as the paper states.

θ, what "joint angles" means, is our choice: the local joint rotations (see
:mod:`motionlab.retargeting.losses` for why, and ``theta="directions"`` for the
position-based alternative). The foot loss needs world heights: ``y = root_height(t) + FK_y``, where ``root_height`` is the
target's root trajectory chosen by :mod:`motionlab.retargeting.pipeline` (the network only
produces root-relative poses).

Taught in ``notebooks/03_latent_iteration.ipynb``.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import torch
from tqdm.auto import tqdm

from motionlab.retargeting import losses
from motionlab.retargeting.model import Decoded, RetargetNet

__all__ = ["SolverConfig", "SolverResult", "iteration_loss", "solve"]


@dataclass
class SolverConfig:
    """Settings of the latent iteration.

    Attributes
    ----------
    max_steps : int        step limit
    lr : float             Adam step size on φ, relative to the spread of the starting latent:
                           the actual learning rate is ``lr · std(φ₀)``, so one setting suits
                           networks whose latents live at different scales
    threshold : float      stop when ``L_iter`` is below this
    patience : int         stop after this many steps without a relative improvement of
                           ``min_delta`` of the best loss (0: never)
    min_delta : float
    lambda_angle, lambda_foot : float   loss weights (paper: 0.3 and 0.5)
    theta : str            ``"rotations"`` (joint rotations, default) or ``"directions"``
                           (unit bone directions from positions)
    smooth_sigma : float   σ (frames) of the Gaussian that smooths latent updates over time; 0: off
    """

    max_steps: int = 100
    lr: float = 0.1
    threshold: float = 2e-3
    patience: int = 10
    min_delta: float = 1e-3
    lambda_angle: float = losses.LAMBDA_ANGLE
    lambda_foot: float = losses.LAMBDA_FOOT
    theta: str = "rotations"
    smooth_sigma: float = 3.0

    def __post_init__(self) -> None:
        if self.theta not in ("rotations", "directions"):
            raise ValueError(f"theta must be 'rotations' or 'directions', got {self.theta!r}")
        if not self.smooth_sigma >= 0:
            raise ValueError(f"smooth_sigma must be >= 0 frames, got {self.smooth_sigma}")
        if self.max_steps < 0 or self.patience < 0:
            raise ValueError(f"max_steps and patience must be >= 0, got {self.max_steps} and {self.patience}")
        if not self.lr > 0:
            raise ValueError(f"lr must be positive, got {self.lr}")


@dataclass
class SolverResult:
    """The outcome of :func:`solve` for a batch of N sequences of T frames.

    Attributes
    ----------
    local_rot : ndarray (N, T, 22, 4)   final local rotations (root in the heading frame)
    positions : ndarray (N, T, 22, 3)   FK on the target skeleton, root at the origin, metres
    phi : Tensor (N, T, D)              the optimised latent
    history : dict of lists             per evaluated step: ``loss`` (L_iter), ``angle`` (L_angle),
                                        ``foot`` (L_foot, metres); entry 0 is the starting point
    stop_reason : str                   ``"threshold"``, ``"plateau"`` or ``"max_steps"``
    best_step : int                     the step whose latent is returned: the lowest ``L_iter``
                                        seen (Adam may overshoot after it)
    steps : int                         Adam updates made
    seconds : float                     wall time of the iteration
    """

    local_rot: np.ndarray
    positions: np.ndarray
    phi: torch.Tensor
    history: dict = field(default_factory=dict)
    stop_reason: str = ""
    steps: int = 0
    seconds: float = 0.0
    best_step: int = 0


def _smoother(sigma: float, channels: int, dtype, device):
    """``δ ↦ G_σ * δ`` along time for latents (N, T, D); the identity when ``sigma == 0``."""
    if sigma <= 0:
        return lambda d: d
    radius = max(int(round(3 * sigma)), 1)
    t = torch.arange(-radius, radius + 1, dtype=dtype, device=device)
    kernel = torch.exp(-0.5 * (t / sigma) ** 2)
    kernel = (kernel / kernel.sum()).expand(channels, 1, -1).contiguous()

    def apply(d: torch.Tensor) -> torch.Tensor:
        padded = torch.nn.functional.pad(d.transpose(1, 2), (radius, radius), mode="replicate")
        return torch.nn.functional.conv1d(padded, kernel, groups=channels).transpose(1, 2)

    return apply


def iteration_loss(
    source: torch.Tensor,
    generated: Decoded,
    root_height: torch.Tensor,
    config: SolverConfig | None = None,
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """``(L_iter, L_angle, L_foot)``.

    ``source`` is A's local rotations (N, T, 22, 4) for ``theta="rotations"`` or A's root-relative
    heading-frame positions (N, T, 22, 3) for ``"directions"``; ``generated`` the decoder's output
    on B; ``root_height`` (N, T) B's root height above the ground, metres.
    """
    cfg = config or SolverConfig()
    if cfg.theta == "rotations":
        angle = losses.angle_loss(source, generated.local_rot)
    else:
        angle = losses.direction_loss(source, generated.positions)
    foot = losses.foot_loss(generated.positions[..., 1] + root_height[..., None])
    return cfg.lambda_angle * angle + cfg.lambda_foot * foot, angle, foot


def solve(
    model: RetargetNet,
    x: torch.Tensor,
    source: torch.Tensor,
    offsets: torch.Tensor,
    root_height: torch.Tensor,
    config: SolverConfig | None = None,
    callback: Callable[[int, dict], None] | None = None,
    progress: bool = False,
) -> SolverResult:
    """Optimise the latent of a frozen network for skeleton ``offsets``.

    Parameters
    ----------
    model : the trained network; its weights are not changed (gradients are switched off for
        the duration and restored afterwards)
    x : Tensor (N, T, 70)                 A's normalised features
    source : Tensor (N, T, 22, 4) or (N, T, 22, 3)   θ(A): A's local rotations (root in the heading
        frame) for ``theta="rotations"``, A's root-relative heading-frame positions for "directions"
    offsets : Tensor (22, 3) or (N, 22, 3)   B's bone offsets, metres
    root_height : Tensor (N, T)           B's root height above the ground, metres
    config : SolverConfig
    callback : called as ``callback(step, {"loss", "angle", "foot"})`` after each evaluation
    progress : tqdm bar with the loss

    Returns
    -------
    SolverResult
    """
    cfg = config or SolverConfig()
    last = 4 if cfg.theta == "rotations" else 3
    if x.ndim != 3 or source.shape != x.shape[:2] + (22, last) or root_height.shape != x.shape[:2]:
        raise ValueError(
            f"expected x (N, T, 70), source (N, T, 22, {last}) for theta={cfg.theta!r} and root_height (N, T), got "
            f"{tuple(x.shape)}, {tuple(source.shape)} and {tuple(root_height.shape)}"
        )
    device = next(model.parameters()).device
    x, src = x.to(device), source.to(device=device, dtype=x.dtype)
    offsets = torch.as_tensor(offsets, dtype=x.dtype, device=device)
    root_height = root_height.to(device=device, dtype=x.dtype)
    was_training = model.training
    flags = [p.requires_grad for p in model.parameters()]
    model.eval()
    for p in model.parameters():
        p.requires_grad_(False)
    history: dict[str, list[float]] = {"loss": [], "angle": [], "foot": []}
    start = time.perf_counter()
    try:
        with torch.no_grad():
            phi0 = model.encode(x)
        delta = torch.zeros_like(phi0, requires_grad=True)
        smooth = _smoother(cfg.smooth_sigma, phi0.shape[-1], x.dtype, device)
        scale = float(phi0.std()) if phi0.numel() > 1 else 1.0
        opt = torch.optim.Adam([delta], lr=cfg.lr * max(scale, 1e-6))
        best, since_best, steps, reason = float("inf"), 0, 0, "max_steps"
        best_value, best_out, best_phi, best_step = float("inf"), None, None, 0
        bar = tqdm(total=cfg.max_steps, desc="latent iteration", disable=not progress, leave=False)
        while True:
            phi = phi0 + smooth(delta)
            out = model.decode(phi, offsets)
            loss, angle, foot = iteration_loss(src, out, root_height, cfg)
            value = float(loss.detach())
            history["loss"].append(value)
            history["angle"].append(float(angle.detach()))
            history["foot"].append(float(foot.detach()))
            if callback is not None:
                callback(steps, {"loss": value, "angle": history["angle"][-1], "foot": history["foot"][-1]})
            if value < best_value:  # Adam can overshoot: keep the best iterate seen, not the last
                best_value, best_step = value, steps
                best_out = Decoded(out.local_rot.detach(), out.positions.detach(), out.q.detach(), out.q_delta.detach())
                best_phi = phi.detach()
            if value < best * (1.0 - cfg.min_delta):
                best, since_best = value, 0
            else:
                since_best += 1
            if value < cfg.threshold:
                reason = "threshold"
                break
            if cfg.patience and since_best >= cfg.patience:
                reason = "plateau"
                break
            if steps >= cfg.max_steps:
                break
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()
            steps += 1
            bar.update(1)
            bar.set_postfix(loss=f"{value:.4g}")
        bar.close()
    finally:
        for p, f in zip(model.parameters(), flags):
            p.requires_grad_(f)
        model.train(was_training)
    out, phi = best_out, best_phi
    return SolverResult(
        local_rot=out.local_rot.detach().cpu().numpy().astype(np.float64),
        positions=out.positions.detach().cpu().numpy().astype(np.float64),
        phi=phi.detach(),
        best_step=best_step,
        history=history,
        stop_reason=reason,
        steps=steps,
        seconds=time.perf_counter() - start,
    )
