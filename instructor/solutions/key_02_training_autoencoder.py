"""Instructor's key for notebook 02 (the retargeting network and its training).

Both exercises are experiments: the key reruns section 6's cell with the changed setting and
returns the number the cell prints. ``ckpt`` is the notebook's loaded checkpoint (``loaded``),
``held_out`` its held-out clip.
"""

import numpy as np
import torch

from motionlab.core import humanoid, preprocess
from motionlab.core import quat_torch as tq
from motionlab.retargeting.features import clip_features


def _encode(ckpt, held_out):
    clip = preprocess.prepare(held_out, ckpt.fps)
    feats = clip_features(clip)
    x_clip = torch.as_tensor(ckpt.stats.normalize(feats.x), dtype=ckpt.dtype)[None]
    clip_offsets = torch.tensor(clip.skeleton.offsets, dtype=ckpt.dtype)
    with torch.no_grad():
        phi_clip = ckpt.model.encode(x_clip)
    return clip, feats, phi_clip, clip_offsets


def my_q_delta_legs_experiment(ckpt, held_out):
    """Exercise 1: section 6's comparison with legs × 0.7; the largest change of q_Δ over all joints, degrees."""
    clip, _, phi_clip, clip_offsets = _encode(ckpt, held_out)
    short_legs = humanoid.scale_bones(clip.skeleton, legs=0.7)
    with torch.no_grad():
        on_a = ckpt.model.decode(phi_clip, clip_offsets)
        on_b = ckpt.model.decode(phi_clip, torch.tensor(short_legs.offsets, dtype=ckpt.dtype))
    change = np.degrees(tq.angle_between(on_a.q_delta, on_b.q_delta).mean(dim=(0, 1)).numpy())
    return round(float(change.max()), 3)


def my_no_correction_experiment(ckpt, held_out):
    """Exercise 2: the held-out clip decoded with q alone (no q_Δ) on A's skeleton; mean joint error, cm."""
    _, feats, phi_clip, clip_offsets = _encode(ckpt, held_out)
    with torch.no_grad():
        decoded = ckpt.model.decode(phi_clip, clip_offsets)
        positions = ckpt.model.forward_kinematics(decoded.q, clip_offsets)[0].numpy()
    err = 100 * np.linalg.norm(positions - feats.positions, axis=-1)
    return round(float(err.mean()), 2)
