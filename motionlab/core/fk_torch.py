"""Forward kinematics in torch: the differentiable twin of :mod:`motionlab.core.fk`.

Same names, shapes and conventions; used inside the retargeting network and its losses.
"""

from __future__ import annotations

import torch

from motionlab.core import quat_torch as tq

__all__ = ["fk", "fk_positions", "global_to_local", "local_to_global", "bone_directions"]


def _parents_list(parents, num_joints: int) -> list[int]:
    parents = [int(p) for p in (parents.tolist() if hasattr(parents, "tolist") else parents)]
    if len(parents) != num_joints:
        raise ValueError(f"expected {num_joints} parent indices, got {len(parents)}")
    for j, p in enumerate(parents):
        if (j == 0 and p != -1) or (j > 0 and not 0 <= p < j):
            raise ValueError(f"expected parents[0] == -1 and 0 <= parents[j] < j, got parents[{j}] = {p}")
    return parents


def fk(local_rot: torch.Tensor, local_pos: torch.Tensor, parents) -> tuple[torch.Tensor, torch.Tensor]:
    """Forward kinematics, differentiable.

    Parameters
    ----------
    local_rot : Tensor, shape (..., J, 4)   unit quaternions (w, x, y, z) relative to the parent
    local_pos : Tensor, shape (..., J, 3)   offsets from the parent (root: world position), metres;
                                            leading shapes broadcast with ``local_rot``
    parents   : sequence of int, length J   parent index, -1 for the root, parents[j] < j

    Returns
    -------
    global_rot : Tensor, shape (..., J, 4)
    global_pos : Tensor, shape (..., J, 3)

    Raises
    ------
    ValueError when ``local_rot`` is not (..., J, 4) or ``local_pos`` not (..., J, 3) for the
    same J.
    """
    if (
        local_rot.ndim < 2
        or local_pos.ndim < 2
        or local_rot.shape[-1] != 4
        or local_pos.shape[-2:] != (local_rot.shape[-2], 3)
    ):
        raise ValueError(
            f"expected local_rot (..., J, 4) and local_pos (..., J, 3), got {tuple(local_rot.shape)} "
            f"and {tuple(local_pos.shape)}"
        )
    parents = _parents_list(parents, local_rot.shape[-2])
    batch = torch.broadcast_shapes(local_rot.shape[:-2], local_pos.shape[:-2])
    local_rot = local_rot.expand(batch + local_rot.shape[-2:])
    local_pos = local_pos.expand(batch + local_pos.shape[-2:]).to(local_rot.dtype)
    rots = [local_rot[..., 0, :]]
    poss = [local_pos[..., 0, :]]
    for j in range(1, len(parents)):
        p = parents[j]
        rots.append(tq.mul(rots[p], local_rot[..., j, :]))
        poss.append(poss[p] + tq.rotate(rots[p], local_pos[..., j, :]))
    return torch.stack(rots, dim=-2), torch.stack(poss, dim=-2)


def fk_positions(local_rot: torch.Tensor, local_pos: torch.Tensor, parents) -> torch.Tensor:
    """World joint positions (..., J, 3) only; see :func:`fk`."""
    return fk(local_rot, local_pos, parents)[1]


def local_to_global(local_rot: torch.Tensor, parents) -> torch.Tensor:
    """Global rotations (..., J, 4) from local ones."""
    parents = _parents_list(parents, local_rot.shape[-2])
    rots = [local_rot[..., 0, :]]
    for j in range(1, len(parents)):
        rots.append(tq.mul(rots[parents[j]], local_rot[..., j, :]))
    return torch.stack(rots, dim=-2)


def global_to_local(global_rot: torch.Tensor, parents) -> torch.Tensor:
    """Local rotations (..., J, 4): ``global[parent]⁻¹ ⊗ global[j]``; the root is unchanged."""
    parents = _parents_list(parents, global_rot.shape[-2])
    idx = torch.tensor(parents[1:], device=global_rot.device)
    rest = tq.mul(tq.conj(global_rot[..., idx, :]), global_rot[..., 1:, :])
    return torch.cat([global_rot[..., :1, :], rest], dim=-2)


def bone_directions(global_pos: torch.Tensor, parents, eps: float = 1e-8) -> torch.Tensor:
    """Unit vectors (..., J, 3) from each joint's parent to the joint (root: 0)."""
    parents = _parents_list(parents, global_pos.shape[-2])
    idx = torch.tensor([max(p, 0) for p in parents], device=global_pos.device)
    bones = global_pos - global_pos[..., idx, :]
    n = bones.norm(dim=-1, keepdim=True)
    d = bones / n.clamp_min(eps)
    mask = torch.ones(len(parents), 1, dtype=d.dtype, device=d.device)
    mask[0] = 0.0
    return d * mask
