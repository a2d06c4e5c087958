"""What the retargeting network reads and is compared with, for one canonical clip.

:func:`clip_features` turns a 22-joint motion into arrays the network uses:

* ``x``: the paper's per-frame ``p_t`` = 66 root-relative heading-frame joint coordinates +
  ``v_t = (v_x, v_z, ω, h)`` (see :mod:`motionlab.core.preprocess`), shape (T, 70);
* ``positions``: joint positions relative to the root, in the heading frame (T, 22, 3) — the
  reconstruction target and the source of the angle loss' bone directions;
* ``local_rot``: the clip's local rotations with the root rotation expressed in the heading
  frame (T, 22, 4), so that ``FK(local_rot, offsets)`` equals ``positions`` exactly.

Taught in ``notebooks/02_training_autoencoder.ipynb``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core import humanoid, preprocess, quat
from motionlab.core.motion import Motion

__all__ = ["ClipFeatures", "clip_features", "check_motion"]


@dataclass
class ClipFeatures:
    """Network-side view of one canonical clip (T frames).

    Attributes
    ----------
    x : ndarray (T, 70)             un-normalised features ``[positions (66), v_t (4)]``
    positions : ndarray (T, 22, 3)  root-relative, heading-frame joint positions, metres
    local_rot : ndarray (T, 22, 4)  local rotations, root rotation in the heading frame
    root : ndarray (T, 4)           ``v_t = (v_x, v_z, ω, h)``: m/frame, m/frame, rad/frame, m
    root_pos : ndarray (T, 3)       world root position, metres
    yaw : ndarray (T,)              unwrapped heading angle, radians
    """

    x: np.ndarray
    positions: np.ndarray
    local_rot: np.ndarray
    root: np.ndarray
    root_pos: np.ndarray
    yaw: np.ndarray


def check_motion(motion: Motion, what: str = "motion") -> None:
    """Refuse empty motions and NaN/infinite values with a clear ``ValueError``.

    Raises
    ------
    ValueError for something other than a Motion, fewer than 2 frames, or NaN/infinite
    values (naming the frame).
    """
    if not isinstance(motion, Motion):
        raise ValueError(f"expected a motionlab Motion as {what}, got {type(motion).__name__}")
    label = f"{what} {motion.name!r}" if motion.name else what
    if motion.num_frames < 2:
        raise ValueError(f"{label} has {motion.num_frames} frame(s); retargeting needs at least 2")
    bad = ~np.isfinite(motion.local_rot).all(axis=(1, 2)) | ~np.isfinite(motion.root_pos).all(axis=1)
    if motion.local_pos is not None:
        bad |= ~np.isfinite(motion.local_pos).all(axis=(1, 2))
    if np.any(bad):
        raise ValueError(f"{label}: frame {int(np.argmax(bad))} has NaN or infinite values")


def clip_features(motion: Motion) -> ClipFeatures:
    """Features of a canonical (22-joint) motion; see the module docstring.

    Raises
    ------
    ValueError when the motion is not on the 22-joint canonical skeleton.
    """
    check_motion(motion)
    if not humanoid.is_canonical(motion.skeleton):
        raise ValueError("clip_features needs a 22-joint canonical motion; call preprocess.prepare(motion) first")
    global_pos = motion.global_positions()
    feats = preprocess.features_from_positions(global_pos)
    yaw = np.unwrap(preprocess.heading(global_pos))
    local_rot = motion.local_rot.copy()
    local_rot[:, 0] = quat.mul(quat.from_yaw(-yaw), local_rot[:, 0])
    positions = feats.positions - feats.positions[:, :1]
    return ClipFeatures(
        x=feats.flat(),
        positions=positions,
        local_rot=local_rot,
        root=feats.root,
        root_pos=motion.root_pos.copy(),
        yaw=yaw,
    )
