"""Generation for a new skeleton by latent-space iteration (paper A, §2.2, eqs. 9–17).

The network is frozen. Starting from ``φ = F_enc(X_A)`` (eq. 9), only the latent ``φ`` is
updated with Adam so that the motion decoded on B's skeleton (eqs. 10–14) keeps A's joint
angles and keeps its feet above the ground (eq. 15)::

    L_iter = Σ_k w_k · L_k = λ_angle · L_angle(A, B') + λ_foot · L_foot(B')
             [+ λ_contact · L_contact(B')] + λ_floor · L_floor(B') [+ any registered term]

with λ_angle = 0.3, λ_foot = 0.5 (paper), λ_contact = 0.5 and λ_floor = 0 (ours; 2.25 when
switched on, :data:`losses.LAMBDA_FLOOR`), until
``L_iter`` drops below ``threshold``, stops improving (``patience`` steps without a relative
gain of ``min_delta``), or ``max_steps`` is reached. :func:`solve` treats all sequences of a
batch (e.g. several clips of equal length) as one problem: their losses are averaged, so one
Adam run moves every latent. :func:`solve_many` runs the same loop on N independent problems
(one per sequence: own loss, step size, stopping rule and best iterate), which is how
:mod:`motionlab.retargeting.expand` solves many (clip, character) pairs at once; each sequence's
numbers do not depend on the rest of the batch, so its result equals :func:`solve` on it alone.

**Loss terms are named objects** (:mod:`motionlab.retargeting.terms`, the contract): each has a
name, a weight and a function of the decoded motion and its inputs; the iteration sums the
registered terms in order, and the history (``SolverResult.history``: ``loss`` and one list per
term), the callback, the plots, ``expand``'s manifest and the ``--NAME-weight`` options follow the
registry. A new term is one function and one :func:`terms.register`; its weight is set with
``SolverConfig(weights={name: w})`` and its per-sequence inputs passed as ``solve(..., inputs=)``.
Every tensor follows the network's device and float type (:mod:`motionlab.retargeting.devices`).

Further additions of motionlab (their ablations are on docs/results_retargeting.md):

**A Gauss–Newton start (``init="project"``; the default ``"auto"`` uses it).** The encoder
reproduces A's joint rotations only approximately on clips it was not trained on, and Adam on the
angle loss closes that gap slowly. ``F_qlinear`` is linear (eq. 10): ``q = unit(W φ + b)`` with
``W`` of shape (88, D), D ≥ 88, so the latent that makes ``q ⊗ q_Δ`` equal A's rotations can be
found by least squares, one frame at a time. This is a Gauss–Newton step on the angle term
(:func:`project_latent`; ``q_Δ`` depends on φ, hence ``project_iters`` rounds, each step smoothed
over time like the Adam updates below). It starts the iteration from ``L_angle ≈ 0``: the decoder
then says what the source says, and Adam only has to trade that against the foot terms.
In its smoothed rounds the same least squares also pulls each raw quaternion ``W φ + b``
towards its encoder-start length, at least 1, which the rotations do not see: a raw quaternion
shortened almost to zero makes its rotation swing under the smallest step of Adam (the exact
rounds fit the rotations alone and may shorten it again). ``init="encoder"`` starts from ``F_enc(X_A)`` as the paper does.

**Backtracking (``backtrack``).** A step that does not lower ``L_iter`` is undone, and Adam
starts again from the best iterate with half the step size; a step that does lowers it lets the
step grow by a tenth again, up to the configured one. Every iterate kept is better than the one
before, and the step size settles where the pair descends.

**Foot contacts (``lambda_contact``).** Where A's foot is planted
(:mod:`motionlab.retargeting.contacts`), B's foot should stay still in the world;
:func:`losses.contact_loss` measures how fast it moves (m/s). This needs B's world
positions, so :func:`solve` takes B's root trajectory, heading and the frame rate. The term is
a speed (m/s, not m/frame) so that its weight does not depend on the frame rate.

**Smooth latent updates (``smooth_sigma``).** The decoder works frame by frame, so per-frame
Adam steps on φ add frame-to-frame jitter. We therefore write ``φ = φ₀ + G_σ * δ``, where ``G_σ``
is a fixed Gaussian filter along time (σ = ``smooth_sigma`` frames) and optimise the free offset
``δ``: still only the latent moves and the loss is unchanged, but every update is temporally
smooth. ``smooth_sigma=0`` optimises φ directly, as the paper states.

**The same iterates on every CPU (``step_grid``).** The start and every Adam iterate are rounded
to a grid a four-thousandth of a step fine, so that last-bit differences between CPUs' kernels
cannot grow into other results or another stopping step. The network computes in float64.

**On a GPU the step is one CUDA graph** (:mod:`motionlab.retargeting.graphs`; switched off by
``MOTIONLAB_CUDA_GRAPHS=0``): the decoding, the terms and the gradient of every row, then the
stopping rule, backtracking and Adam's update as tensor operations
(:mod:`motionlab.retargeting.device_loop`), are recorded once and replayed at each step, rows
whose problem has stopped masked, so that the GPU does not wait for Python to launch hundreds of
small kernels, and the host reads one flag every few steps. Each problem's numbers are those of
the host loop below (a test runs both on the CPU). On the CPU a step decodes only the problems
still running and reads their losses back for the stopping rule.

θ, what "joint angles" means, is our choice: the local joint rotations (see
:mod:`motionlab.retargeting.losses` for why, and ``theta="directions"`` for the
position-based alternative). The foot loss needs world heights: ``y = root_height(t) + FK_y``,
where ``root_height`` is the target's root trajectory chosen by
:mod:`motionlab.retargeting.pipeline` (the network only produces root-relative poses).

Taught in ``notebooks/03_latent_iteration.ipynb``.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
import torch
from tqdm.auto import tqdm

from motionlab.core import quat_torch as tq
from motionlab.core import threads
from motionlab.retargeting import adam, device_loop, graphs, losses, terms
from motionlab.retargeting.contacts import CONTACT_JOINTS
from motionlab.retargeting.grid import step_grid
from motionlab.retargeting.model import NUM_JOINTS, Decoded, RetargetNet
from motionlab.retargeting.terms import TermInputs

__all__ = [
    "SolverConfig",
    "SolverResult",
    "step_grid",
    "smoother",
    "iteration_loss",
    "sequence_losses",
    "sequence_terms",
    "project_latent",
    "gauss_newton_step",
    "world_feet",
    "solve",
    "solve_many",
]

_LAMBDAS = {"angle": "lambda_angle", "foot": "lambda_foot", "contact": "lambda_contact"}
"""The terms whose weights are also :class:`SolverConfig` fields (the paper's two and L_contact)."""

PROJECT_DAMPING = {torch.float64: 1e-6, torch.float32: 1e-3}
"""Relative damping ``d`` of the Gauss–Newton start (:func:`project_latent`, ``μ = d × mean diag
JJᵀ``) per float type of the network. float64: the smallest of 1e-3, 1e-4, … whose damped normal
equations keep half of float64's digits (condition number ≤ 1/√ε ≈ 6.7e7) on every frame of the
Mixamo and Bandai Namco clips it was chosen on (``experiments/retargeting/gn_damping.py``,
``docs/rigs.md``). float32 keeps the earlier 1e-3: at 1e-6 its Cholesky factorisation fails."""

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
    lambda_contact : float weight of the contact term (ours; 0: off); used when :func:`solve`
                           is given contact labels. The paper's two losses alone also need
                           ``weights={"clearance": 0.0}`` (:mod:`.terms`)
    init : str             ``"project"`` (least-squares first step onto A's rotations) or
                           ``"encoder"`` (φ₀ = F_enc(X_A), the paper); ``"auto"`` (default): project
                           for ``theta="rotations"``, the encoder for ``"directions"``
    project_iters : int    Gauss–Newton rounds of the projection
    smooth_projection : bool  smooth each Gauss–Newton step over time with G_σ (below), so the
                           start latent is as smooth in time as the encoder's
    project_damping : float or None   relative damping of the Gauss–Newton rounds
                           (:func:`project_latent`); None: :data:`PROJECT_DAMPING` for the
                           network's float type
    project_lengths : bool the smoothed Gauss–Newton rounds (``smooth_projection``) also pull
                           F_qlinear's raw quaternions towards their start length, at least
                           :data:`MIN_RAW_LENGTH` (ours; :func:`project_latent`)
    project_exact : int    of the ``project_iters`` rounds, how many last ones are not smoothed
                           (they remove what the smoothed rounds leave of A's fastest details;
                           ``motionlab evaluate --exact-rounds K`` compares values)
    theta : str            ``"rotations"`` (joint rotations, default) or ``"directions"``
                           (unit bone directions from positions)
    smooth_sigma : float   σ (frames) of the Gaussian that smooths latent updates over time; 0: off
    backtrack : bool       a step that does not lower ``L_iter`` is undone: Adam restarts from the
                           best iterate with half the step size, which grows by a tenth after
                           each step that does (ours; False: plain Adam, which may wander above
                           its start and return it unchanged)
    weights : dict         weight of a registered loss term by name (:mod:`.terms`), overriding
                           the ``lambda_*`` fields and the term's default (:meth:`weight`)
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
    project_exact: int = 4
    project_damping: float | None = None
    project_lengths: bool = True
    backtrack: bool = True
    weights: dict = field(default_factory=dict)

    def weight(self, name: str) -> float:
        """The weight of loss term ``name``: ``weights[name]``, else the ``lambda_*`` field
        (angle, foot, contact), else the registered term's default (``KeyError`` if none)."""
        if name in self.weights:
            return float(self.weights[name])
        if name in _LAMBDAS:
            return getattr(self, _LAMBDAS[name])
        return terms.get(name).weight

    def __post_init__(self) -> None:
        bad = {k: v for k, v in self.weights.items() if not (isinstance(k, str) and _finite_at_least(v, 0))}
        if bad:
            raise ValueError(f"weights must map term names to finite numbers >= 0, got {bad}")
        for name in ("lambda_angle", "lambda_foot", "lambda_contact", "threshold", "min_delta"):
            if not _finite_at_least(getattr(self, name), 0):
                raise ValueError(f"{name} must be a finite number >= 0, got {getattr(self, name)!r}")
        if self.init not in INITS:
            raise ValueError(f"init must be one of {INITS}, got {self.init!r}")
        if self.init == "project" and self.theta != "rotations":
            raise ValueError("init='project' matches A's rotations, so it needs theta='rotations'; use init='encoder'")
        if self.project_iters < 1:
            raise ValueError(f"project_iters must be >= 1, got {self.project_iters}")
        if not 0 <= self.project_exact <= self.project_iters:
            raise ValueError(
                f"project_exact must be between 0 and project_iters ({self.project_iters}), got {self.project_exact}"
            )
        if self.project_damping is not None and not self.project_damping > 0:
            raise ValueError(f"project_damping must be positive, got {self.project_damping}")
        if self.theta not in ("rotations", "directions"):
            raise ValueError(f"theta must be 'rotations' or 'directions', got {self.theta!r}")
        if not self.smooth_sigma >= 0:
            raise ValueError(f"smooth_sigma must be >= 0 frames, got {self.smooth_sigma}")
        if self.max_steps < 0 or self.patience < 0:
            raise ValueError(f"max_steps and patience must be >= 0, got {self.max_steps} and {self.patience}")
        if not (_finite_at_least(self.lr, 0) and self.lr > 0):
            raise ValueError(f"lr must be a finite positive number, got {self.lr}")


def _finite_at_least(value, low: float) -> bool:
    """True for a real number, finite and >= ``low``."""
    try:
        return bool(np.isfinite(value) and value >= low)
    except TypeError:
        return False


@dataclass
class SolverResult:
    """The outcome of :func:`solve` for a batch of N sequences of T frames.

    Attributes
    ----------
    local_rot : ndarray (N, T, 22, 4)   final local rotations (root in the heading frame)
    positions : ndarray (N, T, 22, 3)   FK on the target skeleton, root at the origin, metres
    phi : Tensor (N, T, D)              the optimised latent
    history : dict of lists             per evaluated step: ``loss`` (L_iter), then one list per
                                        registered term (:mod:`.terms`): ``angle`` (L_angle),
                                        ``foot`` (L_foot, metres), ``contact`` (L_contact, m/s;
                                        0 without contact labels), ``floor`` (L_floor, metres)…
                                        (B's lengths at the network's character's scale with
                                        ``inputs[terms.LENGTH_SCALE]``);
                                        entry 0 is the starting point (after the projection, if any)
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
    """``(δ, index) ↦ G_σ * δ`` along time for latents (N, T, D); the identity when ``sigma == 0``.

    ``index`` (N, T) of int, optional: frame ``t`` of row ``n`` reads ``δ[n, index[n, t]]`` first;
    with ``index = min(t, length − 1)`` a row padded beyond its length is filtered exactly as the
    row alone (both ends replicate the end frame). The filter is one (T, T) matrix per length
    (:func:`_band`), the same for every channel: one matrix product, forward and backward.
    Raises ValueError where ``δ`` has not ``channels`` channels.
    """

    def gather(d: torch.Tensor, index: torch.Tensor | None = None) -> torch.Tensor:
        return d if index is None else d.gather(1, index[..., None].expand(-1, -1, d.shape[-1]))

    if sigma <= 0:
        return gather
    radius = max(int(round(3 * sigma)), 1)
    t = torch.arange(-radius, radius + 1, dtype=torch.float64, device="cpu")
    kernel = torch.exp(-0.5 * (t / sigma) ** 2)
    kernel = kernel / kernel.sum()
    bands: dict[int, torch.Tensor] = {}

    def apply(d: torch.Tensor, index: torch.Tensor | None = None) -> torch.Tensor:
        frames = d.shape[1]
        if d.shape[-1] != channels:
            raise ValueError(f"the smoother filters latents of {channels} channels, got shape {tuple(d.shape)}")
        if frames not in bands:  # made on the CPU, so that every device filters with the same numbers
            bands[frames] = _band(kernel, frames).to(device=device, dtype=dtype)
        return torch.matmul(bands[frames], gather(d, index))

    return apply


def _band(kernel: torch.Tensor, frames: int) -> torch.Tensor:
    """The (T, T) matrix of the filter ``kernel`` (2r+1,) along ``frames`` = T frames whose ends
    replicate the end frame: row ``t`` holds ``kernel[k]`` at column ``clamp(t + k − r, 0, T − 1)``,
    summed where columns coincide."""
    r = (kernel.shape[0] - 1) // 2
    rows = torch.arange(frames, device=kernel.device)[:, None].expand(-1, kernel.shape[0])
    cols = (rows + torch.arange(-r, r + 1, device=kernel.device)).clamp(0, frames - 1)
    band = torch.zeros(frames, frames, dtype=kernel.dtype, device=kernel.device)
    return band.index_put_((rows.reshape(-1), cols.reshape(-1)), kernel.repeat(frames), accumulate=True)


def smoother(sigma: float, channels: int, dtype=torch.float64, device="cpu") -> Callable[[torch.Tensor], torch.Tensor]:
    """The filter ``δ ↦ G_σ * δ`` along time that :func:`solve` applies to latent updates (N, T, D).

    Called as ``f(δ)``, or ``f(δ, index)`` for rows padded beyond their length (:func:`_smoother`).
    ``sigma`` in frames (``SolverConfig.smooth_sigma``; 0: the identity), ``channels`` = D. The
    same filter smooths the Gauss–Newton steps of :func:`project_latent` (its ``smooth`` argument).
    """
    return _smoother(sigma, channels, dtype, device)


def _summed(cfg: SolverConfig, decoded: Decoded, inputs: TermInputs, given: dict | None = None):
    """``(L_iter, [value of each registered term])`` for one problem: ``Σ weight · value`` over the
    terms whose inputs are there (in registration order); the others are 0. ``given`` holds values
    computed by the caller (by term name)."""
    total, values = None, []
    for term in terms.registered():
        if given and term.name in given:
            value = given[term.name]
        elif all(inputs.has(n) for n in term.needs):
            value = term.function(decoded, inputs)
            if not isinstance(value, torch.Tensor) or value.ndim != 0:
                shape = tuple(getattr(value, "shape", ()))
                raise ValueError(
                    f"loss term {term.name!r} returned {type(value).__name__} of shape {shape}; a term returns "
                    "one number, a 0-d tensor (terms module docstring)"
                )
        else:
            values.append(None)
            continue
        w = cfg.weight(term.name)
        total = w * value if total is None else total + w * value
        values.append(value)
    return total, [torch.zeros_like(total) if v is None else v for v in values]


def iteration_loss(
    source: torch.Tensor,
    generated: Decoded,
    root_height: torch.Tensor,
    config: SolverConfig | None = None,
    contact: torch.Tensor | None = None,
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """``(L_iter, L_angle, L_foot)`` (eqs. 15–17, and motionlab's terms).

    ``source`` is A's local rotations (N, T, 22, 4) for ``theta="rotations"`` or A's root-relative
    heading-frame positions (N, T, 22, 3) for ``"directions"``; ``generated`` the decoder's output
    on B; ``root_height`` (N, T) B's root height above the ground, metres. ``contact``, when
    given, is L_contact (:func:`losses.contact_loss`); ``λ_contact · contact`` is then part of L_iter.
    L_iter sums every registered term (:mod:`.terms`) these inputs allow, L_floor with the floor
    itself as the limit; :func:`sequence_terms` gives each term's value.
    """
    cfg = config or SolverConfig()
    given = {"contact": contact} if contact is not None else None
    total, values = _summed(cfg, generated, TermInputs(source, cfg.theta, root_height), given)
    names = [t.name for t in terms.registered()]
    return total, values[names.index("angle")], values[names.index("foot")]


def world_feet(positions: torch.Tensor, root_pos: torch.Tensor, yaw: torch.Tensor) -> torch.Tensor:
    """World positions (N, T, 4, 3) of the contact joints (:data:`contacts.CONTACT_JOINTS`):
    :func:`losses.feet_in_world`. ``positions`` (N, T, 22, 3) root-relative in the heading frame,
    ``root_pos`` (N, T, 3) the world root path, ``yaw`` (N, T) the heading, radians."""
    return losses.feet_in_world(positions, root_pos, yaw)


def project_latent(
    model: RetargetNet,
    phi: torch.Tensor,
    target_rot: torch.Tensor,
    offsets: torch.Tensor,
    iters: int = 4,
    damping: float | None = None,
    smooth=None,
    exact_rounds: int = 0,
    index: torch.Tensor | None = None,
    keep_lengths: bool = True,
) -> torch.Tensor:
    """The latent whose decoded rotations ``q ⊗ q_Δ`` match ``target_rot``: Gauss–Newton per frame.

    The decoder's rotations of frame ``t`` depend on that frame's latent ``φ_t`` alone (eqs. 10–13
    are per-frame layers), so the angle term can be solved frame by frame: with ``g(φ_t)`` the 88
    numbers of the 22 decoded quaternions and ``J_t`` its Jacobian (88 × D,
    :meth:`RetargetNet.rotation_jacobian`), each round takes the damped Gauss–Newton
    (Levenberg–Marquardt) step ``φ_t ← φ_t + (J_tᵀ J_t + μ I)⁻¹ J_tᵀ (q*_t − g(φ_t))``, where
    ``q*_t`` is the target with each quaternion's sign matched to the current output.
    ``μ = damping × mean diag(JJᵀ)`` (the mean over the 88 rows) keeps the step small where the
    decoder is insensitive. The step is solved in its dual form ``J_tᵀ (J_t J_tᵀ + μ I)⁻¹ r``, with
    ``J_t`` and ``r`` in each decoded quaternion's tangent basis (``rotation_jacobian(...,
    tangent=True)``): 66 × 66 instead of 88 × 88, the same step (the 22 rows left out are 0).

    Each row is solved as if alone: a row stops (keeps its latent) once all its residuals are
    below 1e-5 (≈ 0.001°), and the frames are computed in chunks (:data:`PROJECT_FRAMES` on the
    CPU; on a GPU as many as a quarter of its free memory holds, :data:`PROJECT_BYTES_PER_FRAME`).

    Parameters
    ----------
    model : the network (not modified)
    phi : Tensor (N, T, D)             starting latent
    target_rot : Tensor (N, T, 22, 4)  rotations to reproduce (root in the heading frame)
    offsets : Tensor (22, 3) or (N, 22, 3)   B's bone offsets, metres
    iters : int                        Gauss–Newton rounds
    damping : float or None            relative damping (``μ`` above); None: :data:`PROJECT_DAMPING`
                                       for ``phi``'s float type (1e-3 for another)
    smooth : callable or None          applied to each round's step (N, T, D), e.g. the Gaussian
        filter over time of :func:`solve`: exact per-frame steps make a latent that jumps from
        frame to frame (q_Δ reacts to it), so that later Adam steps add jitter; smoothed steps
        converge more slowly on the fastest details but keep the latent as smooth as the encoder's
    exact_rounds : int                 the last ``exact_rounds`` rounds are not smoothed, so the
        start still reaches the target's fastest details
    index : Tensor (N, T) of int, optional   for rows padded beyond their length: the frame each
        frame stands for (``min(t, length − 1)``), as in :func:`smoother`
    keep_lengths : bool                in the smoothed rounds, also pull each of F_qlinear's raw
        quaternions (before eq. 10's normalisation) towards its length in ``phi``, or towards
        :data:`MIN_RAW_LENGTH` where that is shorter: 22 more residuals per frame. The rotations do
        not see these lengths, and smoothed steps can shorten a raw quaternion almost to zero, where
        the next small change of φ turns its rotation far (a bad start for Adam). The exact rounds
        then fit the rotations alone (and may shorten it again)

    Returns
    -------
    Tensor (N, T, D)
    """
    N, T, D = phi.shape
    with torch.no_grad():
        emb = model.skeleton_embedding(offsets)
        emb = emb.expand(N, -1) if emb.shape[0] == 1 else emb
        damping = PROJECT_DAMPING.get(phi.dtype, 1e-3) if damping is None else damping
        out = phi.clone()
        if keep_lengths:
            lengths = model.f_qlinear(phi).unflatten(-1, (NUM_JOINTS, 4)).norm(dim=-1).clamp_min(MIN_RAW_LENGTH)
        alive = torch.arange(N, device=phi.device)
        for k in range(iters):
            smoothed = smooth is not None and k < iters - exact_rounds
            keep = lengths[alive] if keep_lengths and smoothed else None  # the exact rounds: rotations alone
            step, done = gauss_newton_step(model, out[alive], target_rot[alive], emb[alive], damping, keep)
            alive, step = alive[~done], step[~done]  # a row whose residuals are all tiny is finished
            if len(alive) == 0:
                break
            if smoothed:
                step = smooth(step, None if index is None else index[alive])
            out[alive] += step
    return out


MIN_RAW_LENGTH = 1.0
"""The shortest length the Gauss–Newton start's smoothed rounds ask of a raw quaternion
``r_j = W_j φ + b_j`` (F_qlinear before eq. 10's normalisation, ``keep_lengths``). A change ``dφ``
turns ``unit(r_j)`` by about ``‖W_j dφ‖ / ‖r_j‖`` radians, so at length ≥ 1 no faster than the
layer's own ``W_j dφ``, the unit the normalised output has. Not tuned: the length with that meaning."""

PROJECT_FRAMES = 32
"""Frames per chunk of :func:`project_latent`'s Jacobians on the CPU. Per-frame results do not
depend on the chunk; a small chunk keeps a chunk's Jacobians (66 × D per frame, 68 kB in float64
for D = 128) and the temporaries that build them in the processor's caches between one operation
and the next (``python benchmarks/bench_slider.py --chunks`` measures the choice, ``docs/performance.md``)."""

PROJECT_GPU_FRAMES = 2048
"""The fewest frames of a Gauss–Newton chunk on a GPU (see :data:`PROJECT_BYTES_PER_FRAME`)."""

PROJECT_BYTES_PER_FRAME = 1_000_000
"""Bytes one frame of a Gauss–Newton chunk may take in float64 (D = 128; half in float32), rounded
up from the tensors it builds. On a GPU a chunk takes up to a quarter of the free memory: fewer,
larger chunks keep the GPU busy instead of waiting for the host to launch the next one."""


def _chunk_frames(phi: torch.Tensor) -> int:
    """Frames per Gauss–Newton chunk for ``phi``'s device and float type: :data:`PROJECT_FRAMES` on
    the CPU, on a GPU at least :data:`PROJECT_GPU_FRAMES`."""
    if phi.device.type != "cuda":
        return PROJECT_FRAMES
    free, _ = torch.cuda.mem_get_info(phi.device)
    per_frame = PROJECT_BYTES_PER_FRAME * phi.element_size() // 8
    return max(PROJECT_GPU_FRAMES, int(0.25 * free // per_frame))


def gauss_newton_step(model, phi, target_rot, emb, damping, lengths=None) -> tuple[torch.Tensor, torch.Tensor]:
    """One damped Gauss–Newton step (N, T, D) of :func:`project_latent` for each row, unsmoothed,
    and which rows (N,) have every rotation residual below 1e-5 already (bool).

    ``phi`` (N, T, D) latents, ``target_rot`` (N, T, 22, 4) the rotations to decode, ``emb`` (N, E)
    the skeleton embeddings, ``damping`` the relative damping μ; ``lengths`` (N, T, 22), optional:
    the lengths F_qlinear's raw quaternions should have (:meth:`RetargetNet.length_jacobian`), 22
    more residuals per frame. Frames are solved in chunks of :data:`PROJECT_FRAMES` on the CPU
    (sized by free memory on a GPU), with the same result.
    """
    N, T, D = phi.shape
    flat, target = phi.reshape(N * T, D), target_rot.reshape(N * T, NUM_JOINTS, 4)
    lengths = None if lengths is None else lengths.reshape(N * T, NUM_JOINTS, 1)
    emb_frames = emb[:, None, :].expand(N, T, emb.shape[-1]).reshape(N * T, -1)
    eye = torch.eye((3 if lengths is None else 4) * NUM_JOINTS, dtype=phi.dtype, device=phi.device)
    step, worst = torch.empty_like(flat), torch.empty(N * T, dtype=phi.dtype, device=phi.device)
    chunk = _chunk_frames(phi)
    for c in range(0, N * T, chunk):
        part = slice(c, c + chunk)
        out, jac = model.rotation_jacobian(flat[part], emb_frames[part], tangent=True)  # (m, 66, D)
        goal = torch.where((out * target[part]).sum(-1, keepdim=True) < 0, -target[part], target[part])
        resid = goal - out
        worst[part] = resid.abs().amax(dim=(1, 2))
        # Jᵀ r with J in each quaternion's tangent basis: the same step (the rows left out are 0)
        resid = tq.mul(tq.conj(out), resid)[..., 1:].reshape(out.shape[0], -1, 1)
        # μ from the rotation rows alone: the mean of JJᵀ's diagonal over the 88 numbers of the rotations
        mu = damping * (jac.square().sum((1, 2)) / (4 * NUM_JOINTS)).clamp_min(1e-12)
        if lengths is not None:  # the lengths' rows: residual (wanted − current length), Jacobian uᵀ W
            length, ljac = model.length_jacobian(flat[part])
            jac = torch.cat([jac, ljac], 1)
            resid = torch.cat([resid, lengths[part] - length[..., None]], 1)
        # (JᵀJ + μI)⁻¹ Jᵀ r = Jᵀ (J Jᵀ + μI)⁻¹ r: a 66 × 66 (88 × 88) system per frame instead of D × D
        jjt = jac @ jac.transpose(1, 2)
        chol = torch.linalg.cholesky(jjt + mu[:, None, None] * eye)  # symmetric positive definite
        step[part] = (jac.transpose(1, 2) @ torch.cholesky_solve(resid, chol))[..., 0]
    return step.reshape(N, T, D), worst.reshape(N, T).amax(1) < 1e-5


def sequence_terms(
    source: torch.Tensor,
    generated: Decoded,
    root_height: torch.Tensor,
    config: SolverConfig | None = None,
    root_world: torch.Tensor | None = None,
    yaw: torch.Tensor | None = None,
    planted: torch.Tensor | None = None,
    fps: torch.Tensor | None = None,
    extra: dict | None = None,
    frames: torch.Tensor | None = None,
) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
    """``(L_iter (N,), {term name: value (N,)})``: every sequence on its own, every registered term.

    Each registered term (:mod:`.terms`) is mapped over the batch axis with ``torch.func.vmap``,
    so entry ``i`` is what sequence ``i`` gives alone. Inputs as :func:`iteration_loss`, (N, T, ...);
    with ``root_world`` (N, T, 3), ``yaw`` (N, T), ``planted`` (N, T, 4) and ``fps`` (N,) the
    contact term is evaluated (otherwise it is 0); ``extra`` holds other terms' inputs (N, T, ...);
    ``frames`` (N, T) of bool, optional: each sequence's real frames (:attr:`TermInputs.frames`).
    """
    cfg = config or SolverConfig()
    given = {"root_world": root_world, "yaw": yaw, "planted": planted}
    rows = {k: v for k, v in given.items() if v is not None and planted is not None}
    rate = {"fps": fps} if planted is not None else {}

    if frames is not None:
        rows["frames"] = frames

    def one(src, out, height, row, rate, more):
        decoded = Decoded(*(t[None] for t in out))
        inputs = TermInputs(
            src[None], cfg.theta, height[None], **{k: v[None] for k, v in row.items()}, **rate,
            extra={k: v[None] for k, v in more.items()},
        )  # fmt: skip
        return _summed(cfg, decoded, inputs)

    out = (generated.local_rot, generated.positions, generated.q, generated.q_delta)
    total, values = torch.func.vmap(one)(source, out, root_height, rows, rate, dict(extra or {}))
    return total, dict(zip([t.name for t in terms.registered()], values))


def sequence_losses(*args, **kwargs) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
    """``(L_iter, L_angle, L_foot, L_contact)``, each (N,): :func:`sequence_terms` (same parameters)
    reduced to the first three terms' values, as before the term registry."""
    total, values = sequence_terms(*args, **kwargs)
    return total, values["angle"], values["foot"], values["contact"]


def _in_model_type(model: RetargetNet, x: torch.Tensor) -> torch.Tensor:
    """``x`` on the network's device and in its float type: every tensor of the iteration follows ``x``."""
    weight = next(model.parameters())
    return torch.as_tensor(x, dtype=weight.dtype, device=weight.device)


def _check_inputs(x, source, offsets, root_height, cfg) -> None:
    last = 4 if cfg.theta == "rotations" else 3
    if x.ndim != 3 or source.shape != x.shape[:2] + (22, last) or root_height.shape != x.shape[:2]:
        raise ValueError(
            f"expected x (N, T, 70), source (N, T, 22, {last}) for theta={cfg.theta!r} and root_height (N, T), got "
            f"{tuple(x.shape)}, {tuple(source.shape)} and {tuple(root_height.shape)}"
        )
    shape = tuple(offsets.shape) if hasattr(offsets, "shape") else np.shape(offsets)
    if shape not in ((22, 3), (x.shape[0], 22, 3)):
        raise ValueError(f"expected offsets (22, 3) or ({x.shape[0]}, 22, 3), got {shape}")


def _contact_inputs(x, root_height, cfg, root_xz, yaw, planted, fps):
    """``(root_world (N, T, 3), yaw (N, T), planted (N, T, 4), fps (N,))`` for the contact term, or None when it is off."""
    if planted is None or cfg.weight("contact") <= 0:
        return None
    if root_xz is None or yaw is None or fps is None:
        raise ValueError(
            "the contact term needs B's root path and the frame rate: pass root_xz (N, T, 2), yaw (N, T) and fps with planted"
        )
    like = dict(dtype=x.dtype, device=x.device)  # every input on x's device, in x's float type
    rate = torch.as_tensor(fps, **like).reshape(-1).expand(x.shape[0]).clone()
    if not bool(torch.all(rate > 0)):
        raise ValueError(f"fps must be positive, got {fps}")
    if tuple(planted.shape) != x.shape[:2] + (len(CONTACT_JOINTS),) or tuple(root_xz.shape) != x.shape[:2] + (2,):
        raise ValueError(
            f"expected planted (N, T, 4) and root_xz (N, T, 2) for x {tuple(x.shape)}, got "
            f"{tuple(planted.shape)} and {tuple(root_xz.shape)}"
        )
    root_xz = torch.as_tensor(root_xz, **like)
    root_world = torch.stack([root_xz[..., 0], torch.as_tensor(root_height, **like), root_xz[..., 1]], dim=-1)
    planted = torch.as_tensor(planted, dtype=torch.bool, device=x.device)
    return root_world, torch.as_tensor(yaw, **like), planted, rate


def _extra_inputs(x: torch.Tensor, inputs: dict | None, cfg: SolverConfig) -> dict:
    """Other terms' inputs on ``x``'s device and float type, checked (N, T, ...); the weights' names checked."""
    names = [t.name for t in terms.registered()]
    unknown = sorted(set(cfg.weights) - set(names))
    if unknown:
        raise ValueError(f"SolverConfig.weights names {unknown}, which are not registered loss terms: {names}")
    out = {}
    for key, value in (inputs or {}).items():
        value = torch.as_tensor(value, dtype=x.dtype, device=x.device)
        if tuple(value.shape[:2]) != tuple(x.shape[:2]):
            raise ValueError(f"input {key!r}: expected ({x.shape[0]}, {x.shape[1]}, ...), got {tuple(value.shape)}")
        out[key] = value
    return out


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
    fps: float | torch.Tensor | None = None,
    inputs: dict | None = None,
) -> SolverResult:
    """Optimise the latent of a frozen network for skeleton ``offsets``.

    The N sequences form ONE problem: their losses are averaged, one Adam run moves every
    latent, and one stopping rule applies. :func:`solve_many` solves N independent problems
    with the same loop; for N = 1 the two are the same computation.

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
    callback : called as ``callback(step, {"loss": L_iter, term name: value, ...})`` after each evaluation
    progress : tqdm bar with the loss
    root_xz : Tensor (N, T, 2), optional  B's root position on the ground plane (x, z), metres
    yaw : Tensor (N, T), optional         A's (= B's) heading, radians
    planted : Tensor (N, T, 4) of bool, optional   A's foot contacts
        (:func:`motionlab.retargeting.contacts.detect_contacts`); with ``root_xz`` and ``yaw``
        they switch on the contact term (weight ``config.lambda_contact``)
    fps : float or Tensor (N,), optional  frame rate of the sequences (needed by the contact term)
    inputs : dict of Tensor (N, T, ...), optional   per-sequence inputs of registered terms
        (:attr:`terms.TermInputs.extra`), e.g. ``"floor"`` (N, T, 22): the lowest height each
        joint of B may reach, metres (without it L_floor keeps every joint above the floor),
        and ``terms.LENGTH_SCALE`` (N, T): the network's character's leg length / B's, the unit
        of the length-valued terms (without it: metres of B)

    Returns
    -------
    SolverResult

    Raises
    ------
    ValueError
        inputs of the wrong shape, contact labels without the root path or frame rate, a
        non-positive frame rate, or a weight for a term that is not registered.
    """
    problem = (model, x, source, offsets, root_height, config)
    return _solve(problem, True, callback, progress, root_xz, yaw, planted, fps, inputs)[0]


def solve_many(
    model: RetargetNet,
    x: torch.Tensor,
    source: torch.Tensor,
    offsets: torch.Tensor,
    root_height: torch.Tensor,
    config: SolverConfig | None = None,
    progress: bool = False,
    root_xz: torch.Tensor | None = None,
    yaw: torch.Tensor | None = None,
    planted: torch.Tensor | None = None,
    fps: float | torch.Tensor | None = None,
    inputs: dict | None = None,
    lengths: Sequence[int] | None = None,
) -> list[SolverResult]:
    """Solve N independent problems (one per sequence) in one batched latent iteration.

    Each sequence has its own loss, its own Adam step size (``lr · std(φ₀)`` of its own latent),
    its own stopping rule and its own best iterate, so result ``i`` is what :func:`solve` gives for
    sequence ``i`` alone (up to float rounding: batched matrix products may round differently).
    A sequence that has stopped leaves the batch, so later steps only compute the others (with
    the step as a CUDA graph, :mod:`.graphs`, every row is computed to the end).
    Typical use: many (clip, character) pairs (:mod:`motionlab.retargeting.expand`).

    Parameters are those of :func:`solve` (``offsets`` usually (N, 22, 3): one skeleton per
    sequence), and ``lengths`` (N,), optional: sequence ``i`` is its first ``lengths[i]`` frames,
    the rest of its row padding (any finite values; ``batching.solve_jobs`` repeats the last frame). Padded frames count in no term
    (:attr:`terms.TermInputs.frames`) and the smoothing filter treats a row's last real frame as
    its end, so a padded sequence gives the result it gives alone, cut to its length. Returns one
    :class:`SolverResult` per sequence, arrays with a leading axis of 1 and ``lengths[i]`` frames;
    ``seconds`` is the wall time of the whole batch.

    Raises
    ------
    ValueError
        as :func:`solve`; lengths outside 1..T; padding while a registered term does not honour
        padded frames (:func:`terms.unpadded`).
    """
    problem = (model, x, source, offsets, root_height, config)
    return _solve(problem, False, None, progress, root_xz, yaw, planted, fps, inputs, lengths)


def _solve(problem, joint, callback, progress, root_xz, yaw, planted, fps, inputs, lengths=None) -> list[SolverResult]:
    """:func:`solve` (``joint``: the N sequences are one problem) or :func:`solve_many` (N problems)
    of ``problem = (model, x, source, offsets, root_height, config)``; one result per problem."""
    model, x, source, offsets, root_height, config = problem
    cfg = config or SolverConfig()
    x = _in_model_type(model, x)
    _check_inputs(x, source, offsets, root_height, cfg)
    contact = _contact_inputs(x, root_height, cfg, root_xz, yaw, planted, fps)
    extra = _extra_inputs(x, inputs, cfg)
    sizes = [x.shape[0]] if joint else [1] * x.shape[0]
    frames = _padding(x, lengths)
    with threads.torch_threads(threads.threads_for(x.shape[0] * x.shape[1])):
        problem = _problem(model, x, source, offsets, root_height, cfg, sizes, contact, extra, frames)
        return _iterate(problem, callback, progress)


def _padding(x: torch.Tensor, lengths) -> np.ndarray | None:
    """Each row's length (N,) when some row is padded, else None; checked."""
    if lengths is None:
        return None
    n = np.asarray(lengths, dtype=np.int64).reshape(-1)
    N, T = x.shape[:2]
    if n.shape != (N,) or n.min(initial=1) < 1 or n.max(initial=1) > T:
        raise ValueError(f"lengths must be {N} numbers between 1 and {T} frames, got {list(lengths)}")
    if (n == T).all():
        return None
    if terms.unpadded():
        raise ValueError(
            f"sequences of other lengths cannot share a batch: terms {list(terms.unpadded())} do not honour padded frames (Term.padded)"
        )
    return n


@contextmanager
def _frozen(model: RetargetNet):
    """The network in eval mode with gradients off for its weights; both restored on exit."""
    was_training = model.training
    flags = [p.requires_grad for p in model.parameters()]
    model.eval()
    for p in model.parameters():
        p.requires_grad_(False)
    try:
        yield
    finally:
        for p, f in zip(model.parameters(), flags):
            p.requires_grad_(f)
        model.train(was_training)


@dataclass
class _Problem:
    """The fixed inputs of one batched latent iteration, on the network's device and float type.

    ``bounds`` (groups + 1,): row ranges of the groups; ``group_of_row`` (N,): each row's group;
    ``contact``: ``(root_world, yaw, planted, fps)`` of :func:`_contact_inputs`, or None;
    ``extra``: other terms' inputs (N, T, ...) by name; ``lengths`` (N,) each row's real frames,
    ``frames`` (N, T) the same as a mask and ``index`` (N, T) ``min(t, length − 1)`` when rows
    are padded, else None.
    """

    model: RetargetNet
    x: torch.Tensor
    src: torch.Tensor
    offsets: torch.Tensor
    root_height: torch.Tensor
    contact: tuple | None
    sizes: list
    bounds: np.ndarray
    group_of_row: torch.Tensor
    cfg: SolverConfig
    extra: dict = field(default_factory=dict)
    lengths: np.ndarray | None = None
    frames: torch.Tensor | None = None
    index: torch.Tensor | None = None

    @property
    def per_row_offsets(self) -> bool:
        return self.offsets.ndim == 3

    def rows(self, rows: torch.Tensor | None) -> dict:
        """The per-row inputs of the terms (:func:`sequence_terms`) for ``rows`` (None: all)."""
        pick = (lambda t: t) if rows is None else (lambda t: t[rows])
        given = dict(zip(("root_world", "yaw", "planted", "fps"), map(pick, self.contact))) if self.contact else {}
        frames = None if self.frames is None else pick(self.frames)
        return dict(given, extra={k: pick(v) for k, v in self.extra.items()}, frames=frames)


def _problem(model, x, source, offsets, root_height, cfg, sizes, contact, extra, lengths=None) -> _Problem:
    """Move every input onto the network's device (``x`` and ``source`` in ``x``'s float type)."""
    device = next(model.parameters()).device
    x, src = x.to(device), source.to(device=device, dtype=x.dtype)
    offsets = torch.as_tensor(offsets, dtype=x.dtype, device=device)
    root_height = root_height.to(device=device, dtype=x.dtype)
    group_of_row = torch.as_tensor(np.repeat(np.arange(len(sizes)), sizes), device=device)
    if contact is not None:
        contact = tuple(t.to(device) for t in contact)
    bounds = np.cumsum([0] + list(sizes))
    extra = {k: v.to(device=device, dtype=x.dtype) for k, v in (extra or {}).items()}
    p = _Problem(model, x, src, offsets, root_height, contact, list(sizes), bounds, group_of_row, cfg, extra, lengths)
    if lengths is not None:
        t = torch.arange(x.shape[1], device=device)
        last = torch.as_tensor(lengths, device=device)[:, None] - 1
        p.frames, p.index = t[None] <= last, torch.minimum(t[None], last)
    return p


def _start(p: _Problem):
    """φ₀ (N, T, D) (the encoder's, then the Gauss–Newton start where ``cfg`` asks for it), the
    skeleton embedding and the temporal smoother of the steps. The encoder runs one row at a time
    on the row's real frames, so that a row's numbers do not depend on the batch; padded frames
    repeat the last real one."""
    model, cfg, offsets, x = p.model, p.cfg, p.offsets, p.x
    lengths = [x.shape[1]] * x.shape[0] if p.lengths is None else p.lengths
    with torch.no_grad():
        phi0 = [model.encode(x[i : i + 1, :n]) for i, n in enumerate(lengths)]
        phi0 = torch.cat(
            [torch.nn.functional.pad(f, (0, 0, 0, x.shape[1] - f.shape[1]), mode="replicate") for f in phi0]
        )
        embedding = (
            model.skeleton_embedding(offsets)
            if offsets.ndim == 2
            else torch.cat([model.skeleton_embedding(o) for o in offsets])
        )
    smooth = _smoother(cfg.smooth_sigma, phi0.shape[-1], x.dtype, x.device)
    if cfg.init == "project" or (cfg.init == "auto" and cfg.theta == "rotations"):
        steps_filter = smooth if cfg.smooth_projection else None
        phi0 = project_latent(
            model, phi0, p.src, offsets, cfg.project_iters, cfg.project_damping, smooth=steps_filter,
            exact_rounds=cfg.project_exact, index=p.index, keep_lengths=cfg.project_lengths,
        )  # fmt: skip
    return phi0, embedding, smooth


@dataclass
class _Steps:
    """The latent offset δ (N, T, D) (φ = φ₀ + smooth(δ)) and Adam's state over it, written out
    so that every row has its own step size, grid and step count (a group's rows share them);
    with backtracking, the best iterate's δ and its gradient, to go back to."""

    delta: torch.Tensor
    lr: np.ndarray
    grid: torch.Tensor
    m: torch.Tensor
    v: torch.Tensor
    count: np.ndarray
    best_delta: torch.Tensor | None = None
    best_grad: torch.Tensor | None = None
    lr_max: np.ndarray | None = None


def _steps(phi0: torch.Tensor, p: _Problem) -> _Steps:
    """Per group: Adam's step size ``lr · std(φ₀)`` (real frames), its grid (:func:`step_grid`);
    φ₀ put on the grid in place."""
    N, bounds = phi0.shape[0], p.bounds
    lr, grid = np.empty(N), np.empty(N)
    for g in range(len(bounds) - 1):
        part = phi0[bounds[g] : bounds[g + 1]]
        real = part if p.frames is None else part[p.frames[bounds[g] : bounds[g + 1]]]
        scale = max(float(real.std()) if real.numel() > 1 else 1.0, 1e-6)
        with torch.no_grad():  # the start on the grid too (see step_grid)
            part.copy_(torch.round(part / step_grid(scale)) * step_grid(scale))
        lr[bounds[g] : bounds[g + 1]] = p.cfg.lr * scale
        grid[bounds[g] : bounds[g + 1]] = step_grid(p.cfg.lr * scale)
    like = dict(dtype=phi0.dtype, device=phi0.device)
    grid = torch.as_tensor(grid, **like)[:, None, None]
    zeros = torch.zeros_like(phi0)
    steps = _Steps(zeros.clone().requires_grad_(True), lr, grid, zeros.clone(), zeros, np.zeros(N, dtype=np.int64))
    if p.cfg.backtrack:
        steps.best_delta, steps.best_grad, steps.lr_max = torch.zeros_like(phi0), torch.zeros_like(phi0), lr.copy()
    return steps


def _host(values, device, dtype=None) -> torch.Tensor:
    """Host numbers (a list or array) as a tensor on ``device``. To a CUDA GPU the copy does not
    wait for the work already queued there: the iteration makes a few such tensors every step, and
    a waiting copy would stall the host until the device is idle."""
    device = torch.device(device)
    if device.type != "cuda":
        return torch.as_tensor(values, dtype=dtype, device=device)
    return torch.as_tensor(values, dtype=dtype, device="cpu").to(device, non_blocking=True)


def _rows_of(bounds: np.ndarray, groups: list) -> np.ndarray:
    """The batch rows (int64) of ``groups``, in order: ``bounds[g]:bounds[g + 1]`` for each."""
    groups = np.asarray(groups, dtype=np.int64)
    starts, sizes = bounds[groups], bounds[groups + 1] - bounds[groups]
    if (sizes == 1).all():
        return starts.astype(np.int64)
    return np.concatenate([np.arange(a, a + n) for a, n in zip(starts, sizes)]).astype(np.int64)


def _evaluate(p: _Problem, phi0, embedding, smooth, steps: _Steps, active: list):
    """Decode the active groups' latents; ``(out, phi, group_loss (active,), parts (active, 1 + terms))``
    where ``parts[k]`` is ``[L_iter, each registered term's value]`` of active group k (means over its rows)."""
    groups, bounds, device, dtype = len(p.sizes), p.bounds, phi0.device, phi0.dtype
    everyone = len(active) == groups
    rows = None if everyone else _host(_rows_of(bounds, active), device)
    pick = (lambda t: t) if everyone else (lambda t: None if t is None else t[rows])
    phi = pick(phi0) + smooth(pick(steps.delta), pick(p.index))
    offsets = p.offsets[rows] if p.per_row_offsets and not everyone else p.offsets
    out = p.model.decode(phi, offsets, pick(embedding) if p.per_row_offsets else embedding)
    given = p.rows(rows)
    loss, by_term = sequence_terms(pick(p.src), out, pick(p.root_height), p.cfg, **given)  # (rows,): each alone
    owner = pick(p.group_of_row)
    which = owner if everyone else torch.searchsorted(_host(active, device), owner)
    count = torch.zeros(len(active), dtype=dtype, device=device).index_add_(0, which, torch.ones_like(loss))
    parts = [
        torch.zeros(len(active), dtype=dtype, device=device).index_add_(0, which, v) / count
        for v in (loss, *by_term.values())
    ]
    return out, phi, parts[0], torch.stack([q.detach() for q in parts], 1)


def _losses(p: _Problem, phi0, embedding, smooth, steps: _Steps, active: list):
    """:func:`_evaluate` with ``values``, its parts as Python lists, in place of the parts."""
    out, phi, group_loss, parts = _evaluate(p, phi0, embedding, smooth, steps, active)
    return out, phi, group_loss, parts.tolist()


def _all_rows_step(p: _Problem, phi0, embedding, smooth, steps: _Steps) -> Callable[[], tuple]:
    """The first half of the step that :mod:`.device_loop` records: every group's losses
    ``(out, phi, parts)`` and the gradient of their sum in ``steps.delta.grad`` (each row's is its
    own group's)."""
    everyone = list(range(len(p.sizes)))

    def step() -> tuple:
        out, phi, group_loss, parts = _evaluate(p, phi0, embedding, smooth, steps, everyone)
        group_loss.sum().backward()
        return out, phi, parts

    return step


@dataclass
class _Track:
    """Per group: the loss history, the plateau rule's state, the stop reason and the best iterate
    (rows ``bounds[g]:bounds[g + 1]`` of ``best_rot``, ``best_pos``, ``best_phi``)."""

    keys: tuple
    histories: list
    best: list
    since_best: list
    reasons: list
    best_value: list
    best_step: list
    steps: list
    best_rot: torch.Tensor
    best_pos: torch.Tensor
    best_phi: torch.Tensor

    @classmethod
    def new(cls, phi0: torch.Tensor, groups: int) -> _Track:
        shape = phi0.shape[:2]
        keys = ("loss",) + tuple(t.name for t in terms.registered())
        return cls(
            keys,
            [{k: [] for k in keys} for _ in range(groups)],
            [float("inf")] * groups,  # best loss that counted as an improvement (plateau rule)
            [0] * groups,
            ["max_steps"] * groups,
            [float("inf")] * groups,
            [0] * groups,
            [0] * groups,
            torch.empty(shape + (22, 4), dtype=phi0.dtype, device=phi0.device),
            torch.empty(shape + (22, 3), dtype=phi0.dtype, device=phi0.device),
            torch.empty_like(phi0),
        )

    def record(self, p: _Problem, active: list, values: list, out, phi, callback) -> tuple[list[int], list[int]]:
        """Log one evaluation of the active groups, keep their best iterates; the indices into
        ``active`` of the groups that stop here, and of those whose ``L_iter`` is their lowest yet."""
        cfg, stopped, row, better, improved = p.cfg, [], 0, [], []
        full = out.local_rot.shape[0] == p.bounds[-1]  # out holds every row, not only the active ones
        for k, g in enumerate(active):
            value, n = values[k][0], p.sizes[g]
            row = p.bounds[g] if full else row
            for key, v in zip(self.keys, values[k]):
                self.histories[g][key].append(v)
            if callback is not None:
                callback(self.steps[g], dict(zip(self.keys, values[k])))
            if value < self.best_value[g]:  # Adam can overshoot: keep the best iterate seen, not the last
                self.best_value[g], self.best_step[g] = value, self.steps[g]
                better.append((row, p.bounds[g], n))
                improved.append(k)
            if value < self.best[g] * (1.0 - cfg.min_delta):
                self.best[g], self.since_best[g] = value, 0
            else:
                self.since_best[g] += 1
            row += n
            if value < cfg.threshold:
                self.reasons[g] = "threshold"
            elif cfg.patience and self.since_best[g] >= cfg.patience:
                self.reasons[g] = "plateau"
            elif self.steps[g] < cfg.max_steps:
                continue
            stopped.append(k)
        self._keep(better, out, phi)
        return stopped, improved

    def _keep(self, better: list, out, phi) -> None:
        """Copy the improved groups' rows ``(row in out, row in the batch, rows)`` into the best iterate."""
        if not better:
            return
        src = _host(np.concatenate([np.arange(r, r + n) for r, _, n in better]), phi.device)
        dst = _host(np.concatenate([np.arange(b, b + n) for _, b, n in better]), phi.device)
        self.best_rot[dst] = out.local_rot.detach()[src]
        self.best_pos[dst] = out.positions.detach()[src]
        self.best_phi[dst] = phi.detach()[src]

    def results(self, p: _Problem, seconds: float) -> list[SolverResult]:
        """Each group's best iterate. Raises ValueError for a group whose ``L_iter`` was never
        finite (no iterate to return), naming the terms that were not."""
        for g in range(len(p.bounds) - 1):
            if not np.isfinite(self.best_value[g]):
                terms_off = [k for k in self.keys[1:] if not all(np.isfinite(self.histories[g][k]))]
                raise ValueError(
                    f"L_iter was not finite at any step of sequence {g} (the terms {terms_off or 'none'} were not): "
                    "no iterate to return; check the weights and any term you registered"
                )
        rot = self.best_rot.cpu().numpy().astype(np.float64)
        pos = self.best_pos.cpu().numpy().astype(np.float64)
        bounds, T = p.bounds, rot.shape[1]
        ends = [T] * len(p.sizes) if p.lengths is None else [int(n) for n in p.lengths]
        return [
            SolverResult(
                local_rot=rot[bounds[g] : bounds[g + 1], : ends[g]],
                positions=pos[bounds[g] : bounds[g + 1], : ends[g]],
                phi=self.best_phi[bounds[g] : bounds[g + 1], : ends[g]],
                best_step=self.best_step[g],
                history=self.histories[g],
                stop_reason=self.reasons[g],
                steps=self.steps[g],
                seconds=seconds,
            )
            for g in range(len(bounds) - 1)
        ]


def _adam_step(
    p: _Problem, steps: _Steps, group_loss: torch.Tensor, active: list, stopped: list, improved: list
) -> list:
    """One Adam update (``torch.optim.Adam``'s arithmetic) of the groups still running, their δ put
    back on the grid; the groups left. A stopped group keeps its latent. With backtracking, a group
    whose last step did not lower its loss (not in ``improved``) goes back first (:func:`_backtrack`)."""
    keep = torch.ones(len(active), dtype=group_loss.dtype, device=group_loss.device)
    if stopped:
        keep[_host(stopped, keep.device)] = 0.0
    steps.delta.grad = None
    (group_loss * keep).sum().backward()
    stopped, improved = set(stopped), set(improved)  # membership per group: sets, not lists
    if p.cfg.backtrack:
        _backtrack(p, steps, [g for k, g in enumerate(active) if k in improved and k not in stopped],
                   [g for k, g in enumerate(active) if k not in improved and k not in stopped])  # fmt: skip
    active = [g for k, g in enumerate(active) if k not in stopped]
    rows = _rows_of(p.bounds, active)
    steps.count[rows] += 1
    like = dict(dtype=steps.m.dtype, device=steps.m.device)
    bias1, root2 = zip(*map(adam.bias_corrections, steps.count[rows]))
    step_size = _host([lr / b for lr, b in zip(steps.lr[rows], bias1)], **like)[:, None, None]
    root2 = _host(root2, **like)[:, None, None]
    index = _host(rows, steps.m.device)
    with torch.no_grad():
        m, v, delta = adam.update(
            steps.delta[index], steps.delta.grad[index], steps.m[index], steps.v[index], step_size, root2, steps.grid[index]
        )  # fmt: skip
        steps.m[index], steps.v[index], steps.delta[index] = m, v, delta
    return active


def _backtrack(p: _Problem, steps: _Steps, better: list, worse: list) -> None:
    """Groups ``better`` (their loss the lowest yet): remember δ and its gradient, step size × 1.1
    (at most the configured one). Groups ``worse``: back to the remembered δ and gradient, Adam's
    moments and step count reset, step size halved (:data:`.adam.GROW`, :data:`.adam.SHRINK`)."""
    device = steps.delta.device
    with torch.no_grad():
        if better:
            at = _rows_of(p.bounds, better)
            rows = _host(at, device)
            steps.best_delta[rows] = steps.delta[rows]
            steps.best_grad[rows] = steps.delta.grad[rows]
            _set_lr(steps, at, np.minimum(steps.lr[at] * adam.GROW, steps.lr_max[at]))
        if worse:
            at = _rows_of(p.bounds, worse)
            rows = _host(at, device)
            steps.delta[rows] = steps.best_delta[rows]
            steps.delta.grad[rows] = steps.best_grad[rows]
            steps.m[rows], steps.v[rows] = 0.0, 0.0
            steps.count[at] = 0
            _set_lr(steps, at, steps.lr[at] * adam.SHRINK)


def _set_lr(steps: _Steps, rows: np.ndarray, lr: np.ndarray) -> None:
    """Rows ``rows`` get Adam step size ``lr`` and its grid (:func:`step_grid`)."""
    steps.lr[rows] = lr
    grid = _host([step_grid(x) for x in lr], steps.grid.device, steps.grid.dtype)
    steps.grid[_host(rows, steps.grid.device)] = grid[:, None, None]


def _iterate(p: _Problem, callback, progress) -> list[SolverResult]:
    """The latent iteration for consecutive groups of sequences (``p.sizes`` rows each), each group
    an independent problem: group loss = mean of its sequences' losses, own step size and stop.
    On a GPU the whole step, rules included, is one CUDA graph (:mod:`.device_loop`)."""
    start = time.perf_counter()
    with _frozen(p.model):
        phi0, embedding, smooth = _start(p)
        steps = _steps(phi0, p)
        track = _Track.new(phi0, len(p.sizes))
        if graphs.enabled(phi0.device):
            step = _all_rows_step(p, phi0, embedding, smooth, steps)
            device_loop.iterate(p, step, steps, track, callback, progress)
        else:
            _iterate_here(p, phi0, embedding, smooth, steps, track, callback, progress)
    return track.results(p, time.perf_counter() - start)


def _iterate_here(p: _Problem, phi0, embedding, smooth, steps: _Steps, track: _Track, callback, progress) -> None:
    """The iteration with its rules on the host: each step decodes the running groups only, and
    the host reads their losses back for the stopping rule."""
    active = list(range(len(p.sizes)))
    bar = tqdm(total=p.cfg.max_steps, desc="latent iteration", disable=not progress, leave=False)
    while active:
        out, phi, group_loss, values = _losses(p, phi0, embedding, smooth, steps, active)
        stopped, improved = track.record(p, active, values, out, phi, callback)
        if len(stopped) == len(active):
            break
        active = _adam_step(p, steps, group_loss, active, stopped, improved)
        for g in active:
            track.steps[g] += 1
        bar.update(1)
        bar.set_postfix(loss=f"{np.mean([v[0] for v in values]):.4g}")  # values: already on the host
    bar.close()
