"""The losses of paper A: L_recon for training, L_angle and L_foot for the latent iteration.

=====================  ===========================================================  ==========
loss                   formula                                                      unit
=====================  ===========================================================  ==========
``recon_loss``         λ/(3TJ) Σ_t Σ_j ‖p_t^j − p'_t^j‖₂, λ = 0.5 (eq. 8)           metres
``angle_loss``         1/(22T) Σ_t Σ_i ‖θ_i,t(A) − θ_i,t(B')‖₂, θ = joint angles      unitless
``direction_loss``     the same with θ = unit bone directions (from positions)      unitless
``foot_loss``          1/(4T) Σ_t Σ_{i ∈ feet} max(−y_i,t, 0)                       metres
``rotation_loss``      mean over frames and joints of 1 − ⟨q, q̂⟩²                   unitless
``contact_loss``       mean over planted frame pairs of fps·‖x_t+1 − x_t‖₂ (feet)   m/s
``floor_loss``         1/(18T) Σ_t Σ_{j ∉ feet} max(f_t,j − y_t,j, 0), f ≤ 0        metres
``clearance_loss``     1/(4T) Σ_t Σ_{i ∈ feet} max(c_t,i − y_t,i, 0), c ≥ 0         metres
=====================  ===========================================================  ==========

The iteration's terms (L_angle, L_foot, L_contact, L_floor, L_clear) are registered, with their weights,
in :mod:`motionlab.retargeting.terms`; the λ constants here are theirs.

**Our choice of θ (the paper leaves it open): the joint angles themselves**, i.e. each joint's
local rotation as a unit quaternion (the root's in the heading frame), compared up to sign:
``‖θ(A) − θ(B')‖ = min(‖q_A − q_B'‖, ‖q_A + q_B'‖) = 2 sin(α/4)``, where α is the angle of the
rotation that takes one to the other: about α/2 for small differences (not α, and not exactly
a half-angle either; 0.0175 ≈ 2°). The other natural choice — the unit direction of every bone
in the root-centred heading frame, computed from positions (:func:`direction_loss`) — meets a
difference between real rigs: they have *different rest poses* (a bone of B points elsewhere
than A's in the T-pose), so matching A's bone directions bends B away from what its animators
(and Mixamo's retargeter) do, which is to keep the local rotations. With joint angles,
copy-rotation has zero angle loss, and the foot term decides how far the pose moves from it.
``SolverConfig(theta="directions")`` keeps the other choice available.

``rotation_loss`` is *our addition* (weight 0.1 by default in :func:`~motionlab.retargeting.train.train`;
0 is the paper's setting): positions cannot see the rotation of a leaf joint (head, hands, toes)
nor a bone's twist, so without it those rotations drift freely and the BVH output looks wrong
even when every joint position is right.

``contact_loss`` is *our addition* to the iteration: on the frames where A's foot is planted
(:mod:`motionlab.retargeting.contacts`), B's foot joint should not move in the world.

``floor_loss`` is *our addition* too: L_foot only sees the feet, so a hand, knee or head may go
under the floor; L_floor keeps every joint at or above it, or no deeper than the source's own
joint went (scaled to B: :func:`motionlab.retargeting.pipeline.prepare_pair`).

``clearance_loss`` is *our addition* as well: while A's foot swings (not planted), B's foot joint
should be at least as high as A's, scaled to B (``c``, :func:`motionlab.retargeting.pipeline.prepare_pair`),
so that B's swinging feet clear the floor as A's do rather than skim it.

Paper: Wang, Li, Xie and Jia 2023, eq. (8) (L_recon) and eqs. (15)–(17) (the iteration's losses, §2.2). Taught in ``notebooks/03_latent_iteration.ipynb``.
"""

from __future__ import annotations

import torch

from motionlab.core import fk_torch, humanoid
from motionlab.retargeting import devices
from motionlab.retargeting.contacts import CONTACT_JOINTS

__all__ = [
    "LAMBDA_RECON",
    "LAMBDA_ANGLE",
    "LAMBDA_FOOT",
    "FOOT_JOINTS",
    "recon_loss",
    "bone_directions",
    "angle_loss",
    "direction_loss",
    "foot_loss",
    "rotation_loss",
    "contact_loss",
    "feet_in_world",
    "floor_loss",
    "LAMBDA_CONTACT",
    "LAMBDA_FLOOR",
    "FLOOR_DEFAULT",
    "clearance_loss",
    "LAMBDA_CLEARANCE",
    "frame_mean",
]

LAMBDA_RECON = 0.5
"""λ_recon of eq. (8)."""
LAMBDA_ANGLE = 0.3
"""λ_angle of the iteration loss."""
LAMBDA_FOOT = 0.5
"""λ_foot of the iteration loss."""
LAMBDA_CONTACT = 0.5
"""Weight of the contact term (our addition), the same number as λ_foot; the term is a speed
(m/s), so a planted foot sliding at 2 cm/s costs as much as a foot 2 cm below the ground."""
LAMBDA_FLOOR = LAMBDA_FOOT * 18 / 4
"""The floor term's weight when it is switched on (our addition; ``--floor-weight 2.25``):
λ_foot × 18 / 4. L_foot is a mean over the 4 foot joints, L_floor over the other 18, so a joint
under the floor costs what a foot under the ground costs in the paper's L_foot. The registered
term's default weight is 0 (:data:`FLOOR_DEFAULT`)."""
FLOOR_DEFAULT = 0.0
"""The floor term's default weight: off. On the paper's Table 1 protocol it raises the full
method's pose error above copying rotations (docs/results_retargeting.md, "L_floor"), so it is
an opt-in (:data:`LAMBDA_FLOOR`)."""
LAMBDA_CLEARANCE = LAMBDA_FOOT
"""Weight of the clearance term (our addition): λ_foot, since both are a mean depth over the four
foot joints: a swinging foot 1 cm below A's (scaled) height costs what a foot 1 cm under the
ground does."""
FOOT_JOINTS: tuple[int, ...] = tuple(humanoid.JOINTS.index(n) for n in humanoid.FEET)
"""Indices of LeftFoot, RightFoot, LeftToeBase, RightToeBase in the canonical skeleton."""


_OTHER_JOINTS: tuple[int, ...] = tuple(j for j in range(len(humanoid.JOINTS)) if j not in FOOT_JOINTS)


def frame_mean(values: torch.Tensor, frames: torch.Tensor | None = None) -> torch.Tensor:
    """Mean of ``values`` (..., T, ...) over every entry of the frames that count.

    ``frames`` (..., T) of bool marks the real frames of a padded sequence (its shape is a prefix
    of ``values``'); None: every frame counts (the plain mean). Padded frames add nothing to the
    value or its gradient.
    """
    if frames is None:
        return values.mean()
    w = frames.to(values.dtype).reshape(frames.shape + (1,) * (values.ndim - frames.ndim))
    return (values * w).sum() / (w.sum() * (values.numel() // frames.numel())).clamp_min(1.0)


def _same_shape(a: torch.Tensor, b: torch.Tensor, what: str) -> None:
    if a.shape != b.shape or a.shape[-1] != 3:
        raise ValueError(
            f"{what}: expected two (..., T, J, 3) position tensors of equal shape, got {tuple(a.shape)} and {tuple(b.shape)}"
        )


def recon_loss(pred: torch.Tensor, target: torch.Tensor, weight: float = LAMBDA_RECON) -> torch.Tensor:
    """Eq. (8): ``λ/(3TJ) Σ ‖p − p'‖₂`` averaged over the batch; positions (..., T, J, 3), metres."""
    _same_shape(pred, target, "recon_loss")
    return weight * (pred - target).norm(dim=-1).mean() / 3.0


def bone_directions(positions: torch.Tensor) -> torch.Tensor:
    """θ: unit parent→joint directions (..., T, 22, 3) of root-centred heading-frame positions.

    Raises
    ------
    ValueError when ``positions`` is not (..., 22, 3).
    """
    if positions.shape[-2:] != (len(humanoid.JOINTS), 3):
        raise ValueError(f"expected canonical positions (..., 22, 3), got {tuple(positions.shape)}")
    return fk_torch.bone_directions(positions, humanoid.PARENTS)


def angle_loss(
    source_rot: torch.Tensor, generated_rot: torch.Tensor, frames: torch.Tensor | None = None
) -> torch.Tensor:
    """L_angle with θ = joint rotations (eq. 16): mean over frames and joints of ``min(‖q_A − q_B'‖, ‖q_A + q_B'‖)``.

    For unit quaternions that distance is ``2 sin(α/4)`` with α the angle between the two
    rotations (so ≈ α/2 for small α, in radians).

    Both inputs are local rotations (..., T, 22, 4) (unit quaternions; the root's in the heading
    frame); ``frames`` (..., T) of bool, optional: the frames that count (:func:`frame_mean`).

    Raises
    ------
    ValueError unless the two rotation tensors are (..., T, J, 4) of equal shape.
    """
    if source_rot.shape != generated_rot.shape or source_rot.shape[-1] != 4:
        raise ValueError(
            f"angle_loss: expected two (..., T, J, 4) rotation tensors of equal shape, got {tuple(source_rot.shape)} and {tuple(generated_rot.shape)}"
        )
    diff = torch.minimum(_length(source_rot - generated_rot), _length(source_rot + generated_rot))
    return frame_mean(diff, frames)


def _length(v: torch.Tensor) -> torch.Tensor:
    """Euclidean length along the last axis with a finite gradient at zero."""
    return torch.sqrt((v * v).sum(-1) + 1e-12)


def direction_loss(
    source_positions: torch.Tensor, generated_positions: torch.Tensor, frames: torch.Tensor | None = None
) -> torch.Tensor:
    """L_angle with θ = unit bone directions: mean over frames and the 22 joints of ‖θ(A) − θ(B')‖₂.

    Both inputs are root-centred heading-frame positions (..., T, 22, 3); their bone lengths may
    differ (that is the point).
    """
    _same_shape(source_positions, generated_positions, "angle_loss")
    diff = (bone_directions(source_positions) - bone_directions(generated_positions)).norm(dim=-1)
    return frame_mean(diff, frames)


def foot_loss(world_y: torch.Tensor, frames: torch.Tensor | None = None) -> torch.Tensor:
    """L_foot (eq. 17): mean of ``|min(y, 0)|`` over frames and the four foot joints.

    Parameters
    ----------
    world_y : Tensor (..., T, 22) heights of all joints above the ground, or (..., T, 4) of the
        feet only (LeftFoot, RightFoot, LeftToeBase, RightToeBase), metres.

    Raises
    ------
    ValueError when the heights are neither (..., T, 22) nor (..., T, 4).
    """
    if world_y.shape[-1] == len(humanoid.JOINTS):
        world_y = world_y.index_select(-1, devices.index(FOOT_JOINTS, world_y.device))
    elif world_y.shape[-1] != len(FOOT_JOINTS):
        raise ValueError(f"expected heights (..., T, 22) or (..., T, 4), got {tuple(world_y.shape)}")
    return frame_mean(torch.relu(-world_y), frames)


def rotation_loss(local_rot: torch.Tensor, target_rot: torch.Tensor) -> torch.Tensor:
    """Mean of ``1 − ⟨q, q̂⟩²`` (0 for equal rotations, sign-agnostic) over (..., J, 4) quaternions.

    Raises
    ------
    ValueError unless the two tensors are (..., 4) of equal shape.
    """
    if local_rot.shape != target_rot.shape or local_rot.shape[-1] != 4:
        raise ValueError(
            f"rotation_loss: expected two (..., 4) tensors of equal shape, got {tuple(local_rot.shape)} and {tuple(target_rot.shape)}"
        )
    return (1.0 - (local_rot * target_rot).sum(-1) ** 2).mean()


def contact_loss(feet: torch.Tensor, planted: torch.Tensor, fps: float | torch.Tensor) -> torch.Tensor:
    """Mean speed (metres per second) of planted feet: ``fps`` × their motion between consecutive frames.

    A speed, not a distance per frame, so its weight means the same at every frame rate.

    Parameters
    ----------
    feet : Tensor (..., T, F, 3)     world positions of F foot joints, metres
    planted : Tensor (..., T, F) of bool   contact labels; a frame pair counts when the joint
        is planted in both frames
    fps : frames per second of ``feet`` (a number or a 0-d tensor)

    Returns 0 (with a gradient path) when no foot is ever planted.

    Raises
    ------
    ValueError unless ``feet`` is (..., T, F, 3) and ``planted`` (..., T, F).
    """
    if feet.shape[-1] != 3 or planted.shape != feet.shape[:-1]:
        raise ValueError(
            f"contact_loss: expected feet (..., T, F, 3) and planted (..., T, F), got {tuple(feet.shape)} and {tuple(planted.shape)}"
        )
    both = (planted[..., 1:, :] & planted[..., :-1, :]).to(dtype=feet.dtype, device=feet.device)
    step = _length(feet[..., 1:, :, :] - feet[..., :-1, :, :])
    return fps * (step * both).sum() / both.sum().clamp_min(1.0)


def feet_in_world(positions: torch.Tensor, root_pos: torch.Tensor, yaw: torch.Tensor) -> torch.Tensor:
    """World positions (..., T, 4, 3) of the contact joints (:data:`contacts.CONTACT_JOINTS`).

    ``positions`` (..., T, 22, 3) are root-relative in the heading frame (the decoder's output),
    ``root_pos`` (..., T, 3) the world root path and ``yaw`` (..., T) the heading, radians: a point
    ``p`` of the heading frame is ``R_y(yaw) p + root`` in the world.
    """
    feet = positions.index_select(-2, devices.index(CONTACT_JOINTS, positions.device))
    c, s = torch.cos(yaw)[..., None], torch.sin(yaw)[..., None]
    x, y, z = feet.unbind(-1)
    return torch.stack([c * x + s * z, y, -s * x + c * z], dim=-1) + root_pos[..., None, :]


def floor_loss(
    heights: torch.Tensor, allowed: torch.Tensor | None = None, frames: torch.Tensor | None = None
) -> torch.Tensor:
    """L_floor: mean over frames and the 18 joints other than the feet of ``max(allowed − y, 0)``, metres.

    The four foot joints are L_foot's (:func:`foot_loss`); this term sees every other joint.

    Parameters
    ----------
    heights : Tensor (..., T, 22)    every joint's height above the floor, metres
    allowed : Tensor (..., T, 22) or None   the lowest height each joint may reach (<= 0: the
        source's own depth there, scaled); None: 0, the floor itself
    frames : Tensor (..., T) of bool, optional   the frames that count (:func:`frame_mean`)

    Exactly 0, with a zero gradient, where every joint is above its allowed height.

    Raises
    ------
    ValueError unless ``heights`` has 22 joints on its last axis.
    """
    if heights.shape[-1] != len(humanoid.JOINTS):
        raise ValueError(f"floor_loss: expected heights (..., T, 22), got {tuple(heights.shape)}")
    if allowed is not None and allowed.shape != heights.shape:
        raise ValueError(
            f"floor_loss: expected allowed {tuple(heights.shape)} like heights, got {tuple(allowed.shape)}"
        )
    depth = -heights if allowed is None else allowed - heights
    return frame_mean(torch.relu(depth.index_select(-1, devices.index(_OTHER_JOINTS, depth.device))), frames)


def clearance_loss(feet_y: torch.Tensor, allowed: torch.Tensor, frames: torch.Tensor | None = None) -> torch.Tensor:
    """L_clear: mean over frames and the four foot joints of ``max(allowed − y, 0)``, metres.

    Parameters
    ----------
    feet_y : Tensor (..., T, 4)    heights of LeftFoot, RightFoot, LeftToeBase, RightToeBase above
        the floor, metres
    allowed : Tensor (..., T, 4)   the lowest height each may reach (>= 0: A's own height, scaled,
        while A's foot swings; 0 where it is planted)
    frames : Tensor (..., T) of bool, optional   the frames that count (:func:`frame_mean`)

    Exactly 0, with a zero gradient, where every foot joint is at or above its allowed height.

    Raises
    ------
    ValueError unless both are (..., T, 4) of the same shape.
    """
    if feet_y.shape[-1] != len(FOOT_JOINTS) or allowed.shape != feet_y.shape:
        raise ValueError(
            f"clearance_loss: expected feet_y and allowed (..., T, 4), got {tuple(feet_y.shape)} and {tuple(allowed.shape)}"
        )
    return frame_mean(torch.relu(allowed - feet_y), frames)
