"""Generation for a new skeleton by latent-space iteration (paper A, §2.2, eqs. 9–17).

The network is frozen. Starting from ``φ = F_enc(X_A)`` (eq. 9), only the latent ``φ`` is
updated with Adam so that the motion decoded on B's skeleton (eqs. 10–14) keeps A's joint
angles and keeps its feet above the ground (eq. 15)::

    L_iter = λ_angle · L_angle(A, B') + λ_foot · L_foot(B')  [+ λ_contact · L_contact(B')]

with λ_angle = 0.3, λ_foot = 0.5 (paper) and λ_contact = 0.5 (ours, see below), until
``L_iter`` drops below ``threshold``, stops improving (``patience`` steps without a relative
gain of ``min_delta``), or ``max_steps`` is reached. All sequences of a batch (e.g. several
clips of equal length) are solved together: their losses are averaged, so one Adam run moves
every latent.

Three additions of motionlab, each measured in the README's Table 1 (ablation rows):

**A least-squares first step (``init="project"``, default).** The encoder reproduces A's joint
rotations only approximately on clips it was not trained on (13° median on Aj's held-back
clips), and Adam on the angle loss closes that gap slowly. ``F_qlinear`` is linear (eq. 10):
``q = unit(W φ + b)`` with ``W`` of shape (88, D), D ≥ 88, so the latent that makes ``q ⊗ q_Δ``
equal A's rotations can be found by least squares, one frame at a time.
This is a Gauss–Newton step on the angle term (:func:`project_latent`; ``q_Δ`` depends on φ,
hence ``project_iters`` rounds, each step smoothed over time like the Adam updates below). It
starts the iteration from ``L_angle ≈ 0``: the decoder then says what the source says, and
Adam only has to trade that against the foot terms. ``init="encoder"`` starts from ``F_enc(X_A)`` as the paper does.

**Foot contacts (``lambda_contact``).** Where A's foot is planted
(:mod:`motionlab.retargeting.contacts`), B's foot should stay still in the world;
:func:`losses.contact_loss` measures how far it moves per frame. This needs B's world
positions, so :func:`solve` takes B's root trajectory and heading.

**Smooth latent updates (``smooth_sigma``).** The decoder works frame by frame, so per-frame
Adam steps on φ add frame-to-frame jitter (on the Mixamo data the mean acceleration tripled,
0.30 → 0.91 cm/frame²). We therefore write ``φ = φ₀ + G_σ * δ``, where ``G_σ`` is a fixed
Gaussian filter along time (σ = ``smooth_sigma`` frames) and optimise the free offset ``δ``:
still only the latent moves and the loss is unchanged, but every update is temporally smooth.
``smooth_sigma=0`` optimises φ directly, as the paper states.

θ, what "joint angles" means, is our choice: the local joint rotations (see
:mod:`motionlab.retargeting.losses` for why, and ``theta="directions"`` for the
position-based alternative). The foot loss needs world heights: ``y = root_height(t) + FK_y``,
where ``root_height`` is the target's root trajectory chosen by
:mod:`motionlab.retargeting.pipeline` (the network only produces root-relative poses).

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
from motionlab.retargeting.contacts import CONTACT_JOINTS
from motionlab.retargeting.model import NUM_JOINTS, Decoded, RetargetNet

__all__ = ["SolverConfig", "SolverResult", "iteration_loss", "project_latent", "world_feet", "solve"]

INITS = ("auto", "project", "encoder")
"""How the iteration starts: least-squares projection onto A's rotations, or ``F_enc(X_A)``;
``auto`` projects when θ is the rotations and starts from the encoder otherwise."""


@dataclass
class SolverConfig:
    """Settings of the latent iteration.

    Attributes
    ----------
    max_steps : int        step limit
    lr : float             Adam step size on φ, relative to the spread of the starting latent:
                           the actual learning rate is ``lr · std(φ₀)``, so one setting suits
                           networks whose latents live at different scales. The projected start
                           is already at the angle term's optimum, so the steps are small (0.02);
                           from the encoder's start (``init="encoder"``) 0.1 was the setting
    threshold : float      stop when ``L_iter`` is below this
    patience : int         stop after this many steps without a relative improvement of
                           ``min_delta`` of the best loss (0: never)
    min_delta : float
    lambda_angle, lambda_foot : float   loss weights (paper: 0.3 and 0.5)
    lambda_contact : float weight of the contact term (ours; 0: the paper's two losses); used
                           when :func:`solve` is given contact labels
    init : str             ``"project"`` (least-squares first step onto A's rotations) or
                           ``"encoder"`` (φ₀ = F_enc(X_A), the paper); ``"auto"`` (default): project
                           for ``theta="rotations"``, the encoder for ``"directions"``
    project_iters : int    Gauss–Newton rounds of the projection
    smooth_projection : bool  smooth each Gauss–Newton step over time with G_σ (below), so the
                           start latent is as smooth in time as the encoder's
    theta : str            ``"rotations"`` (joint rotations, default) or ``"directions"``
                           (unit bone directions from positions)
    smooth_sigma : float   σ (frames) of the Gaussian that smooths latent updates over time; 0: off
    """

    max_steps: int = 100
    lr: float = 0.02
    threshold: float = 2e-3
    patience: int = 10
    min_delta: float = 1e-3
    lambda_angle: float = losses.LAMBDA_ANGLE
    lambda_foot: float = losses.LAMBDA_FOOT
    lambda_contact: float = losses.LAMBDA_CONTACT
    init: str = "auto"
    project_iters: int = 8
    theta: str = "rotations"
    smooth_sigma: float = 3.0
    smooth_projection: bool = True

    def __post_init__(self) -> None:
        if self.init not in INITS:
            raise ValueError(f"init must be one of {INITS}, got {self.init!r}")
        if self.init == "project" and self.theta != "rotations":
            raise ValueError("init='project' matches A's rotations, so it needs theta='rotations'; use init='encoder'")
        if self.project_iters < 1:
            raise ValueError(f"project_iters must be >= 1, got {self.project_iters}")
        if not self.lambda_contact >= 0:
            raise ValueError(f"lambda_contact must be >= 0, got {self.lambda_contact}")
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
                                        ``foot`` (L_foot, metres), ``contact`` (L_contact, metres
                                        per frame; 0 without contact labels); entry 0 is the
                                        starting point (after the projection, if any)
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
    contact: torch.Tensor | None = None,
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """``(L_iter, L_angle, L_foot)`` (eqs. 15–17).

    ``source`` is A's local rotations (N, T, 22, 4) for ``theta="rotations"`` or A's root-relative
    heading-frame positions (N, T, 22, 3) for ``"directions"``; ``generated`` the decoder's output
    on B; ``root_height`` (N, T) B's root height above the ground, metres. ``contact``, when
    given, is L_contact (:func:`losses.contact_loss`); ``λ_contact · contact`` is then part of L_iter.
    """
    cfg = config or SolverConfig()
    if cfg.theta == "rotations":
        angle = losses.angle_loss(source, generated.local_rot)
    else:
        angle = losses.direction_loss(source, generated.positions)
    foot = losses.foot_loss(generated.positions[..., 1] + root_height[..., None])
    total = cfg.lambda_angle * angle + cfg.lambda_foot * foot
    if contact is not None:
        total = total + cfg.lambda_contact * contact
    return total, angle, foot


def world_feet(positions: torch.Tensor, root_pos: torch.Tensor, yaw: torch.Tensor) -> torch.Tensor:
    """World positions (N, T, 4, 3) of the contact joints (:data:`contacts.CONTACT_JOINTS`).

    ``positions`` (N, T, 22, 3) are root-relative in the heading frame (the decoder's output),
    ``root_pos`` (N, T, 3) the world root path and ``yaw`` (N, T) the heading, radians: a point
    ``p`` of the heading frame is ``R_y(yaw) p + root`` in the world.
    """
    feet = positions[..., list(CONTACT_JOINTS), :]
    c, s = torch.cos(yaw)[..., None], torch.sin(yaw)[..., None]
    x, y, z = feet.unbind(-1)
    return torch.stack([c * x + s * z, y, -s * x + c * z], dim=-1) + root_pos[..., None, :]


def project_latent(
    model: RetargetNet,
    phi: torch.Tensor,
    target_rot: torch.Tensor,
    offsets: torch.Tensor,
    iters: int = 4,
    damping: float = 1e-3,
    smooth=None,
) -> torch.Tensor:
    """The latent whose decoded rotations ``q ⊗ q_Δ`` match ``target_rot``: Gauss–Newton per frame.

    The decoder's rotations of frame ``t`` depend on that frame's latent ``φ_t`` alone (eqs. 10–13
    are per-frame layers), so the angle term can be solved frame by frame: with ``g(φ_t)`` the 88
    numbers of the 22 decoded quaternions and ``J_t`` its Jacobian (88 × D,
    :meth:`RetargetNet.rotation_jacobian`), each round takes the damped Gauss–Newton (Levenberg–Marquardt) step (solved in its
    88 × 88 dual form)
    ``φ_t ← φ_t + (J_tᵀ J_t + μ I)⁻¹ J_tᵀ (q*_t − g(φ_t))``, where ``q*_t`` is the target with
    each quaternion's sign matched to the current output. ``μ = damping × mean diag(JᵀJ)`` keeps
    the step small where the decoder is insensitive.

    Parameters
    ----------
    model : the network (not modified)
    phi : Tensor (N, T, D)             starting latent
    target_rot : Tensor (N, T, 22, 4)  rotations to reproduce (root in the heading frame)
    offsets : Tensor (22, 3) or (N, 22, 3)   B's bone offsets, metres
    iters : int                        Gauss–Newton rounds
    damping : float                    relative damping μ
    smooth : callable or None          applied to each round's step (N, T, D), e.g. the Gaussian
        filter over time of :func:`solve`: exact per-frame steps make a latent that jumps from
        frame to frame (q_Δ reacts to it), so that later Adam steps add jitter (measured: mean
        acceleration 0.41 vs 0.28 cm/frame² on the Mixamo data); smoothed steps converge more
        slowly on the fastest details but keep the latent as smooth as the encoder's

    Returns
    -------
    Tensor (N, T, D)
    """
    N, T, D = phi.shape
    with torch.no_grad():
        emb = model.skeleton_embedding(offsets)
        emb = emb.expand(N, -1) if emb.shape[0] == 1 else emb
        emb_frames = emb[:, None, :].expand(N, T, emb.shape[-1]).reshape(N * T, -1)
        target = target_rot.reshape(N * T, NUM_JOINTS, 4)
        flat = phi.reshape(N * T, D)

        eye = torch.eye(4 * NUM_JOINTS, dtype=phi.dtype, device=phi.device)
        for _ in range(iters):
            out, jac = model.rotation_jacobian(flat, emb_frames)
            goal = torch.where((out * target).sum(-1, keepdim=True) < 0, -target, target)
            resid = (goal - out).reshape(N * T, -1, 1)
            if float(resid.abs().max()) < 1e-5:  # already there (≈ 0.001°)
                break
            # (JᵀJ + μI)⁻¹ Jᵀ r = Jᵀ (J Jᵀ + μI)⁻¹ r: an 88 × 88 system per frame instead of D × D
            jjt = jac @ jac.transpose(1, 2)
            mu = damping * jjt.diagonal(dim1=1, dim2=2).mean(-1).clamp_min(1e-12)
            chol = torch.linalg.cholesky(jjt + mu[:, None, None] * eye)  # symmetric positive definite
            step = (jac.transpose(1, 2) @ torch.cholesky_solve(resid, chol))[..., 0]
            if smooth is not None:
                step = smooth(step.reshape(N, T, D)).reshape(N * T, D)
            flat = flat + step
    return flat.reshape(N, T, D)


def solve(
    model: RetargetNet,
    x: torch.Tensor,
    source: torch.Tensor,
    offsets: torch.Tensor,
    root_height: torch.Tensor,
    config: SolverConfig | None = None,
    callback: Callable[[int, dict], None] | None = None,
    progress: bool = False,
    root_xz: torch.Tensor | None = None,
    yaw: torch.Tensor | None = None,
    planted: torch.Tensor | None = None,
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
    callback : called as ``callback(step, {"loss", "angle", "foot", "contact"})`` after each evaluation
    progress : tqdm bar with the loss
    root_xz : Tensor (N, T, 2), optional  B's root position on the ground plane (x, z), metres
    yaw : Tensor (N, T), optional         A's (= B's) heading, radians
    planted : Tensor (N, T, 4) of bool, optional   A's foot contacts
        (:func:`motionlab.retargeting.contacts.detect_contacts`); with ``root_xz`` and ``yaw``
        they switch on the contact term (weight ``config.lambda_contact``)

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
    use_contact = planted is not None and cfg.lambda_contact > 0
    if use_contact:
        if root_xz is None or yaw is None:
            raise ValueError("the contact term needs B's root path: pass root_xz (N, T, 2) and yaw (N, T) with planted")
        if tuple(planted.shape) != x.shape[:2] + (len(CONTACT_JOINTS),) or tuple(root_xz.shape) != x.shape[:2] + (2,):
            raise ValueError(
                f"expected planted (N, T, 4) and root_xz (N, T, 2) for x {tuple(x.shape)}, got "
                f"{tuple(planted.shape)} and {tuple(root_xz.shape)}"
            )
        root_xz = root_xz.to(device=device, dtype=x.dtype)
        root_world = torch.stack([root_xz[..., 0], root_height, root_xz[..., 1]], dim=-1)
        yaw = torch.as_tensor(yaw, device=device, dtype=x.dtype)
        planted = planted.to(device=device, dtype=torch.bool)
    was_training = model.training
    flags = [p.requires_grad for p in model.parameters()]
    model.eval()
    for p in model.parameters():
        p.requires_grad_(False)
    history: dict[str, list[float]] = {"loss": [], "angle": [], "foot": [], "contact": []}
    start = time.perf_counter()
    try:
        with torch.no_grad():
            phi0 = model.encode(x)
        if cfg.init == "project" or (cfg.init == "auto" and cfg.theta == "rotations"):
            smooth_steps = (
                _smoother(cfg.smooth_sigma, phi0.shape[-1], x.dtype, device) if cfg.smooth_projection else None
            )
            phi0 = project_latent(model, phi0, src, offsets, cfg.project_iters, smooth=smooth_steps)
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
            contact = losses.contact_loss(world_feet(out.positions, root_world, yaw), planted) if use_contact else None
            loss, angle, foot = iteration_loss(src, out, root_height, cfg, contact)
            value = float(loss.detach())
            history["loss"].append(value)
            history["angle"].append(float(angle.detach()))
            history["foot"].append(float(foot.detach()))
            history["contact"].append(float(contact.detach()) if contact is not None else 0.0)
            if callback is not None:
                callback(steps, {k: v[-1] for k, v in history.items()})
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
