"""Instructor's key for notebook 02 (the retargeting network and its training)."""

import torch

LAMBDA = 0.5


def my_recon_loss(pred, target):
    """Exercise 1: L_recon (eq. 8) of positions (..., T, J, 3), averaged over leading dimensions."""
    T, J = pred.shape[-3], pred.shape[-2]
    per_window = LAMBDA / (3 * T * J) * (pred - target).norm(dim=-1).sum(dim=(-2, -1))  # (...,)
    return per_window.mean()


def my_combine(q, q_delta):
    """Exercise 2: the Hamilton product q ⊗ q_Δ of (..., 4) quaternions (w, x, y, z), written out."""
    w1, v1 = q[..., :1], q[..., 1:]
    w2, v2 = q_delta[..., :1], q_delta[..., 1:]
    w = w1 * w2 - (v1 * v2).sum(dim=-1, keepdim=True)
    v = w1 * v2 + w2 * v1 + torch.linalg.cross(v1, v2, dim=-1)
    return torch.cat([w, v], dim=-1)


def my_rotations(net, phi):
    """Exercise 3: F_qlinear's output, (B, T, D) -> unit quaternions (B, T, 22, 4)."""
    raw = net.f_qlinear(phi)  # (B, T, 88)
    q = raw.reshape(phi.shape[0], phi.shape[1], 22, 4)
    return q / q.norm(dim=-1, keepdim=True)
