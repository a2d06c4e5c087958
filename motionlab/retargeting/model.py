"""The retargeting network of paper A, one named piece per step.

Given a window ``X_A`` of source features (T frames × 70 numbers, see
:mod:`motionlab.core.preprocess`) and a target skeleton ``S̄`` (the T-pose bone offsets), the
network produces local joint rotations for that skeleton and puts them on it by FK::

    φ      = F_enc(X_A)                          (B, T, D)     eq. 1, encoder: temporal 1-D convolutions
    q      = F_qlinear(φ) / ‖·‖                  (B, T, J, 4)  eq. 2, per-joint, per-frame rotations
    S̄'     = F_skel(S̄) / ‖·‖                    (B, E)        eqs. 3–4, skeleton embedding (unit vector)
    q_Δ    = F_Δ(concat(φ, S̄')) / ‖·‖           (B, T, J, 4)  eq. 5, skeleton-conditioned correction
    q      ← q ⊗ q_Δ                                           eq. 6, Hamilton product
    P'     = FK(q, S̄)                           (B, T, J, 3)  eq. 7, root at the origin

Design choices the paper leaves open (documented here, shown in notebook 02):

* φ is a latent *per frame* (T frames × ``D`` numbers): the encoder is fully convolutional
  (``replicate`` padding, no down-sampling), so it runs on a clip of any length and the latent
  solver can optimise a whole clip at once, with no window seams.
* ``D = 128`` by default, more than the 88 numbers of 22 quaternions: F_qlinear can then reach
  any pose, which the latent iteration needs to match A's joint angles closely.
* F_qlinear and F_Δ act on each frame independently (linear layers), F_skel is a small MLP
  on the 21 bone offsets (metres, root excluded). F_Δ's last layer starts at zero weights with
  bias ``(1, 0, 0, 0)``, so an untrained correction is the identity rotation.
* The root rotation is expressed in the *heading frame* (the character faces +Z), like the
  input features; positions are root-relative. World placement is the job of
  :mod:`motionlab.retargeting.pipeline`.

Paper: "Skeletal motion generation by latent-space iteration" (Wang, Li, Xie and Jia 2023, DOI 10.3969/j.issn.1003-5060.2023.01.006), §2.2:
eqs. (1)–(7) for A's own skeleton (training), eqs. (10)–(14) for a target skeleton.
Taught in ``notebooks/02_training_autoencoder.ipynb``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import torch
from torch import nn

from motionlab.core import humanoid
from motionlab.core import quat_torch as tq
from motionlab.retargeting import devices

__all__ = ["ModelConfig", "RetargetNet", "Decoded", "skeleton_tensor", "unit", "fk_by_level", "summed_product"]

NUM_JOINTS = len(humanoid.JOINTS)
FEATURE_DIM = 3 * NUM_JOINTS + 4


@dataclass(frozen=True)
class ModelConfig:
    """Sizes of the network.

    Attributes
    ----------
    latent : int       D, channels of the per-frame latent φ
    hidden : int       channels of the encoder's hidden layers and of F_Δ / F_skel
    skel_embed : int   E, size of the skeleton embedding S̄'
    kernel : int       temporal kernel size of the encoder convolutions (odd)
    layers : int       number of encoder convolutions (≥ 1)
    """

    latent: int = 128
    hidden: int = 96
    skel_embed: int = 16
    kernel: int = 5
    layers: int = 3

    def __post_init__(self) -> None:
        for name in ("latent", "hidden", "skel_embed", "kernel", "layers"):
            value = getattr(self, name)
            if not isinstance(value, int) or value < 1:
                raise ValueError(f"ModelConfig.{name} must be a positive integer, got {value!r}")
        if self.kernel % 2 == 0:
            raise ValueError(f"ModelConfig.kernel must be odd (same-length convolutions), got {self.kernel}")

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass
class Decoded:
    """What the decoder returns for a batch of B windows of T frames.

    Attributes
    ----------
    local_rot : Tensor (B, T, J, 4)   final unit quaternions ``q ⊗ q_Δ`` (root: heading frame)
    positions : Tensor (B, T, J, 3)   FK on the skeleton, root at the origin, metres
    q         : Tensor (B, T, J, 4)   F_qlinear's rotations, before the correction
    q_delta   : Tensor (B, T, J, 4)   F_Δ's correction quaternions
    """

    local_rot: torch.Tensor
    positions: torch.Tensor
    q: torch.Tensor
    q_delta: torch.Tensor


def unit(v: torch.Tensor, eps: float = 1e-12) -> torch.Tensor:
    """``v / ‖v‖`` along the last axis (a sum-of-squares norm: much faster than ``Tensor.norm``
    on length-4 rows on the CPU; ``eps`` keeps the gradient finite at zero)."""
    return v * torch.rsqrt((v * v).sum(-1, keepdim=True) + eps)


def skeleton_tensor(offsets, dtype=torch.float32, device=None) -> torch.Tensor:
    """Bone offsets (J, 3) of a canonical skeleton as a tensor with the root offset zeroed.

    ``s̄_j = p̄_j − p̄_parent(j)`` in the T-pose, root at the origin (paper A, §2.2, eq. 3).
    Accepts a :class:`~motionlab.core.skeleton.Skeleton`, an array or a tensor (…, 22, 3).

    Raises
    ------
    ValueError when the skeleton is not the 22-joint canonical one, or the offsets not
    (..., 22, 3).
    """
    if hasattr(offsets, "offsets") and hasattr(offsets, "parents"):
        if not humanoid.is_canonical(offsets):
            raise ValueError(
                "the retargeting network needs a 22-joint canonical skeleton; use humanoid.to_canonical_skeleton"
            )
        offsets = offsets.offsets
    if not isinstance(offsets, torch.Tensor):
        offsets = np.array(offsets, dtype=np.float64)  # a writable copy (Skeleton arrays are read-only)
    t = torch.as_tensor(offsets, dtype=dtype, device=device).clone()
    if t.shape[-2:] != (NUM_JOINTS, 3):
        raise ValueError(f"expected skeleton offsets (..., {NUM_JOINTS}, 3), got {tuple(t.shape)}")
    t[..., 0, :] = 0.0
    return t


def _levels(parents) -> tuple[list[list[int]], list[list[int]], list[int]]:
    """Joints grouped by depth, each joint's parent as a position in the previous level, and the
    permutation that puts the concatenated levels back in joint order."""
    parents = [int(p) for p in parents]
    depth = [0] * len(parents)
    for j in range(1, len(parents)):
        depth[j] = depth[parents[j]] + 1
    levels = [[j for j in range(len(parents)) if depth[j] == d] for d in range(max(depth) + 1)]
    where = {}
    for lvl in levels:
        for i, j in enumerate(lvl):
            where[j] = i
    parent_pos = [[where[parents[j]] for j in lvl] if d else [] for d, lvl in enumerate(levels)]
    flat = [j for lvl in levels for j in lvl]
    order = [flat.index(j) for j in range(len(parents))]
    return levels, parent_pos, order


def _level_index(parents, device: torch.device) -> tuple[list[int], torch.Tensor, list[torch.Tensor], torch.Tensor]:
    """:func:`_levels` as index tensors on ``device`` (:func:`devices.index`): level sizes, the joints
    in level order, each level's parent positions, the permutation back."""
    levels, parent_pos, order = _levels(parents)
    flat = [j for lvl in levels for j in lvl]
    return (
        [len(lvl) for lvl in levels],
        devices.index(flat, device),
        [devices.index(pp, device) for pp in parent_pos],
        devices.index(order, device),
    )


def _matrices(q: torch.Tensor) -> torch.Tensor:
    """Rotation matrices (..., 3, 3) of unit quaternions (..., 4), in few tensor operations."""
    w, x, y, z = q.unbind(-1)
    xx, yy, zz, xy, xz, yz, wx, wy, wz = x * x, y * y, z * z, x * y, x * z, y * z, w * x, w * y, w * z
    m = torch.stack(
        [1 - 2 * (yy + zz), 2 * (xy - wz), 2 * (xz + wy),
         2 * (xy + wz), 1 - 2 * (xx + zz), 2 * (yz - wx),
         2 * (xz - wy), 2 * (yz + wx), 1 - 2 * (xx + yy)],
        dim=-1,
    )  # fmt: skip
    return m.reshape(q.shape[:-1] + (3, 3))


def summed_product(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """``a @ b`` for small matrices (..., n, k) @ (..., k, m) as a broadcast product (..., n, k, m)
    summed over ``k``: two elementwise kernels, however many matrices the batch holds. CUDA runs
    ``a @ b`` on tens of thousands of 3×3 matrices as GEMM kernels made for large ones, slowly."""
    return (a.unsqueeze(-1) * b.unsqueeze(-3)).sum(-2)


def fk_by_level(local_rot: torch.Tensor, local_pos: torch.Tensor, parents, product=None) -> torch.Tensor:
    """World joint positions (..., J, 3) by forward kinematics, one tree level at a time.

    The local rotations become 3×3 matrices once; then every level (all joints of one depth)
    takes its parents' world matrices and positions in one batched matrix product. This needs
    about ten times fewer tensor operations than a quaternion loop over the joints, which is
    what makes the latent iteration fast on a CPU.

    Parameters
    ----------
    local_rot : Tensor (..., J, 4)   unit quaternions relative to the parent
    local_pos : Tensor (..., J, 3)   offsets from the parent (root: its position), broadcast with local_rot
    parents   : sequence of int      parent indices, -1 for the root, parents[j] < j
    product   : callable or None     the matrix product ``(a, b) -> a @ b`` of each level; default
                                     :func:`summed_product` on CUDA, ``torch.matmul`` elsewhere
                                     (faster on a CPU)
    """
    if product is None:
        product = summed_product if local_rot.device.type == "cuda" else torch.matmul
    sizes, flat, parent_pos, order = _level_index(parents, local_rot.device)
    batch = torch.broadcast_shapes(local_rot.shape[:-2], local_pos.shape[:-2])
    local_pos = local_pos.to(local_rot.dtype)
    mats = _matrices(local_rot)
    mats = mats.index_select(-3, flat)
    offs = local_pos.index_select(-2, flat)[..., None]
    first = sizes[0]
    rot = mats[..., :first, :, :]
    pos = offs[..., :first, :, :].expand(batch + (first, 3, 1))
    all_pos = [pos]
    begin = first
    for size, pidx in zip(sizes[1:], parent_pos[1:]):
        stop = begin + size
        prot = rot.index_select(-3, pidx)
        pos = pos.index_select(-3, pidx) + product(prot, offs[..., begin:stop, :, :])
        rot = product(prot, mats[..., begin:stop, :, :])
        all_pos.append(pos)
        begin = stop
    return torch.cat(all_pos, dim=-3)[..., 0].index_select(-2, order)


class _Encoder(nn.Module):
    """F_enc: temporal 1-D convolutions, features (B, T, 70) → φ (B, T, D)."""

    def __init__(self, cfg: ModelConfig) -> None:
        super().__init__()
        blocks: list[nn.Module] = []
        channels = FEATURE_DIM
        for i in range(cfg.layers):
            out = cfg.latent if i == cfg.layers - 1 else cfg.hidden
            blocks.append(nn.Conv1d(channels, out, cfg.kernel, padding=cfg.kernel // 2, padding_mode="replicate"))
            if i < cfg.layers - 1:
                blocks.append(nn.LeakyReLU(0.2))
            channels = out
        self.net = nn.Sequential(*blocks)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.net(x.transpose(1, 2)).transpose(1, 2)


def _left_matrix(q: torch.Tensor) -> torch.Tensor:
    """L(q) (..., 4, 4): ``q ⊗ x = L(q) x`` for quaternions (..., 4), w first."""
    w, x, y, z = q.unbind(-1)
    return torch.stack([w, -x, -y, -z, x, w, -z, y, y, z, w, -x, z, -y, x, w], -1).reshape(q.shape + (4,))


def _right_matrix(p: torch.Tensor) -> torch.Tensor:
    """R(p) (..., 4, 4): ``x ⊗ p = R(p) x`` for quaternions (..., 4), w first."""
    w, x, y, z = p.unbind(-1)
    return torch.stack([w, -x, -y, -z, x, w, z, -y, y, -z, w, x, z, y, -x, w], -1).reshape(p.shape + (4,))


class RetargetNet(nn.Module):
    """F_enc, F_qlinear, F_skel and F_Δ, with the decoder that combines them (paper A, §2.2 and Fig. 3).

    Every step is its own method so notebooks can call and plot it alone:
    :meth:`encode`, :meth:`rotations`, :meth:`skeleton_embedding`, :meth:`correction`,
    :meth:`combine`, :meth:`forward_kinematics`, and :meth:`decode` which chains the last five.
    """

    def __init__(self, config: ModelConfig | None = None) -> None:
        super().__init__()
        cfg = config or ModelConfig()
        self.config = cfg
        self.use_correction = True
        """False replaces q_Δ by the identity (the ablation "without q_Δ"); not saved in checkpoints."""
        J = NUM_JOINTS
        self.f_enc = _Encoder(cfg)
        self.f_qlinear = nn.Linear(cfg.latent, 4 * J)
        self.f_skel = nn.Sequential(
            nn.Linear(3 * (J - 1), cfg.hidden), nn.LeakyReLU(0.2), nn.Linear(cfg.hidden, cfg.skel_embed)
        )
        self.f_delta = nn.Sequential(
            nn.Linear(cfg.latent + cfg.skel_embed, cfg.hidden), nn.LeakyReLU(0.2), nn.Linear(cfg.hidden, 4 * J)
        )
        with torch.no_grad():  # start as the identity correction
            last = self.f_delta[-1]
            last.weight.zero_()
            last.bias.copy_(tq.IDENTITY.repeat(J))
            self.f_qlinear.bias.copy_(tq.IDENTITY.repeat(J))

    # ------------------------------------------------------------------ the five steps
    def encode(self, x: torch.Tensor) -> torch.Tensor:
        """φ = F_enc(X): normalised features (B, T, 70) → per-frame latent (B, T, D), in the
        network's float type (``x`` is cast to it).

        Raises
        ------
        ValueError when ``x`` is not (B, T, 70).
        """
        if x.ndim != 3 or x.shape[-1] != FEATURE_DIM:
            raise ValueError(f"expected normalised features (B, T, {FEATURE_DIM}), got {tuple(x.shape)}")
        return self.f_enc(x.to(self.f_qlinear.weight.dtype))

    def rotations(self, phi: torch.Tensor) -> torch.Tensor:
        """q = F_qlinear(φ) / ‖·‖: latent (B, T, D) → unit quaternions (B, T, J, 4)."""
        raw = self.f_qlinear(phi)
        return unit(raw.reshape(raw.shape[:2] + (NUM_JOINTS, 4)))

    def skeleton_embedding(self, offsets: torch.Tensor) -> torch.Tensor:
        """S̄' = F_skel(S̄) / ‖·‖: bone offsets (B, J, 3) or (J, 3), metres → unit vectors (B, E)."""
        s = skeleton_tensor(offsets, dtype=self.f_qlinear.weight.dtype, device=self.f_qlinear.weight.device)
        if s.ndim == 2:
            s = s[None]
        e = self.f_skel(s[:, 1:].reshape(s.shape[0], -1))
        return unit(e)

    def correction(self, phi: torch.Tensor, embedding: torch.Tensor) -> torch.Tensor:
        """q_Δ = F_Δ(concat(φ, S̄')) / ‖·‖: (B, T, D) and (B or 1, E) → unit quaternions (B, T, J, 4).

        With ``use_correction = False`` (an ablation) q_Δ is the identity rotation.
        """
        if not self.use_correction:
            return tq.IDENTITY.to(phi).expand(phi.shape[:2] + (NUM_JOINTS, 4))
        emb = embedding[:, None, :].expand(phi.shape[0], phi.shape[1], -1)
        raw = self.f_delta(torch.cat([phi, emb], dim=-1))
        return unit(raw.reshape(raw.shape[:2] + (NUM_JOINTS, 4)))

    @staticmethod
    def combine(q: torch.Tensor, q_delta: torch.Tensor) -> torch.Tensor:
        """Fine-tune each rotation by its correction: the Hamilton product ``q ⊗ q_Δ``."""
        return tq.mul(q, q_delta)

    @staticmethod
    def forward_kinematics(local_rot: torch.Tensor, offsets: torch.Tensor) -> torch.Tensor:
        """P' = FK(q, S̄): local rotations (B, T, J, 4) on offsets (B, J, 3) or (J, 3), root at the origin.

        Same result as :func:`motionlab.core.fk_torch.fk_positions` (a test checks it), computed
        one tree *level* at a time (all joints of equal depth together: 8 steps instead of 21).
        """
        s = skeleton_tensor(offsets, dtype=local_rot.dtype, device=local_rot.device)
        if s.ndim == 3:
            s = s[:, None]
        return fk_by_level(local_rot, s, humanoid.PARENTS)

    def length_jacobian(self, phi: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Lengths ``‖r_j‖`` of F_qlinear's 22 raw quaternions ``r = W φ + b`` (before eq. 10's
        normalisation) and their Jacobian ``d‖r_j‖ = u_jᵀ W_j dφ`` (``u_j = r_j / ‖r_j‖``).

        The rotations do not depend on these lengths, but a short ``r_j`` makes its rotation turn
        fast under a small change of φ (``d unit(r) = (I − u uᵀ)/‖r‖ dr``).

        Parameters
        ----------
        phi : Tensor (M, D)         latents of M frames

        Returns
        -------
        lengths : Tensor (M, 22)
        jacobian : Tensor (M, 22, D)
        """
        M, D = phi.shape
        r = self.f_qlinear(phi).reshape(M, NUM_JOINTS, 4)
        length = torch.sqrt((r * r).sum(-1))
        u = r / length[..., None]
        return length, torch.einsum("mja,jad->mjd", u, self.f_qlinear.weight.reshape(NUM_JOINTS, 4, D))

    def rotation_jacobian(
        self, phi: torch.Tensor, embedding: torch.Tensor, tangent: bool = False
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """Per-frame decoded rotations ``q ⊗ q_Δ`` and their Jacobian with respect to the latent.

        Eqs. 10–13 act on each frame alone, so frame ``t``'s rotations depend on ``φ_t`` only and
        the Jacobian is a (88 × D) matrix per frame, written out by the chain rule (no autograd):
        ``d unit(r) = (I − q qᵀ)/‖r‖ dr`` for both normalisations, ``dr = W dφ`` for F_qlinear,
        ``ds = V diag(σ'(h)) U_φ dφ`` for F_Δ (``h`` its hidden layer), and
        ``d(q ⊗ p) = L(q) dp + R(p) dq`` for the Hamilton product (L, R: its 4×4 matrices).

        Each decoded quaternion ``o`` is a unit one, so ``oᵀ do = 0``: its 4 rows of the Jacobian
        hold 3 numbers' worth. ``tangent=True`` gives those 3 rows, the vector part of ``o* ⊗ do``
        (an orthonormal basis of the quaternions orthogonal to ``o``): 66 rows instead of 88, the
        same ``JᵀJ``.

        Parameters
        ----------
        phi : Tensor (M, D)         latents of M frames
        embedding : Tensor (M, E) or (1, E)   the skeleton embedding S̄' for each frame
        tangent : bool              the Jacobian in each quaternion's tangent basis (above)

        Returns
        -------
        rotations : Tensor (M, 22, 4)
        jacobian : Tensor (M, 88, D), or (M, 66, D) with ``tangent``
        """
        M, D = phi.shape
        eye = torch.eye(4, dtype=phi.dtype, device=phi.device)

        def tangent_map(u: torch.Tensor, length: torch.Tensor) -> torch.Tensor:
            # d unit(r) = (I − u uᵀ) / ‖r‖ dr, as (M, J, 4, 4) matrices
            return (eye - u[..., :, None] * u[..., None, :]) / length[..., None]

        r = self.f_qlinear(phi).reshape(M, NUM_JOINTS, 4)
        rlen = torch.sqrt((r * r).sum(-1, keepdim=True))
        q = r / rlen
        if self.use_correction:
            first, act, last = self.f_delta
            h = first(torch.cat([phi, embedding.expand(M, -1)], dim=-1))  # (M, H)
            s = last(act(h)).reshape(M, NUM_JOINTS, 4)
            slen = torch.sqrt((s * s).sum(-1, keepdim=True))
            p = s / slen
            slope = torch.where(h > 0, torch.ones_like(h), torch.full_like(h, act.negative_slope))  # σ'(h)
        else:
            p = tq.IDENTITY.to(phi).expand(M, NUM_JOINTS, 4)
        out = tq.mul(q, p)
        fq = _right_matrix(p) @ tangent_map(q, rlen)  # d(q ⊗ p) = fq dr + fp ds
        fp = _left_matrix(q) @ tangent_map(p, slen) if self.use_correction else None
        if tangent:  # the rows of L(o*) past the first: o* ⊗ do has no real part
            basis = _left_matrix(tq.conj(out))[..., 1:, :]
            fq, fp = basis @ fq, None if fp is None else basis @ fp
        rows = fq.shape[-2] * NUM_JOINTS
        # R(p) dq: the small factors multiplied first, then each joint's (4 × D) block of F_qlinear's weight
        jac = torch.einsum("mjab,jbd->mjad", fq, self.f_qlinear.weight.reshape(NUM_JOINTS, 4, D)).reshape(M * rows, D)
        if fp is not None:  # + L(q) dp = (L(q) T(p) V diag(σ'(h))) U_φ dφ, the last product one matrix product
            lv = torch.einsum("mjab,jbh->mjah", fp, last.weight.reshape(NUM_JOINTS, 4, -1))
            jac = torch.addmm(jac, (lv * slope[:, None, None, :]).reshape(M * rows, -1), first.weight[:, :D])
        return out, jac.reshape(M, rows, D)

    def decode(self, phi: torch.Tensor, offsets: torch.Tensor, embedding: torch.Tensor | None = None) -> Decoded:
        """The whole decoder on skeleton ``offsets`` (J, 3) or (B, J, 3) from the latent φ (B, T, D).

        ``embedding`` (B or 1, E): ``skeleton_embedding(offsets)`` when the caller already has it
        (the latent solver computes it once, not at every step).
        """
        q = self.rotations(phi)
        q_delta = self.correction(phi, self.skeleton_embedding(offsets) if embedding is None else embedding)
        local_rot = self.combine(q, q_delta)
        return Decoded(local_rot, self.forward_kinematics(local_rot, offsets), q, q_delta)

    def forward(self, x: torch.Tensor, offsets: torch.Tensor) -> Decoded:
        """``decode(encode(x), offsets)``."""
        return self.decode(self.encode(x), offsets)
