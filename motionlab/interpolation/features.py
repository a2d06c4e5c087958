"""Pose features and a simple frame distance for key poses, the action graph and gap detection.

Two frames are compared after removing what does not matter for "is this the same pose": where
the character stands on the floor and which way it faces. Every joint position is expressed
relative to the reference joint's ground point and turned so the reference joint faces +Z (the
*heading frame*). Velocities (same frame, metres per second) are appended with a weight ``w``
(seconds), so a standing pose and a mid-stride pose with the same shape still differ:

.. math::  f(t) = \\big[\\, R_{-\\psi(t)} (p_j(t) - g(t)) ,\\; w\\, R_{-\\psi(t)} \\dot p_j(t) \\,\\big]_{j=1..J},
           \\qquad D(t, u) = \\lVert f(t) - f(u) \\rVert_2 .

This is the paper's inter-frame distance (eq. 2) made yaw- and translation-invariant. The motion
graph part of motionlab has a richer distance (Kovar et al.); this module is deliberately small and
self-contained (the three parts of motionlab do not depend on each other).

Taught in ``notebooks/06_keypose_interpolation.ipynb``.
"""

from __future__ import annotations

import numpy as np

from motionlab.core import quat
from motionlab.core.fk import fk
from motionlab.core.motion import Motion
from motionlab.interpolation.alignment import reference_joint

__all__ = ["VELOCITY_WEIGHT", "heading_frame", "pose_features", "window_features", "distance_matrix"]

VELOCITY_WEIGHT = 0.1
"""Default weight (seconds) of joint velocities against positions in :func:`pose_features`."""


def heading_frame(global_rot, global_pos, ref: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint positions relative to the reference joint's ground point, turned to face +Z.

    Parameters
    ----------
    global_rot : array (..., J, 4)    global joint rotations
    global_pos : array (..., J, 3)    global joint positions, metres
    ref : int                         reference joint (heading = its yaw; ground point = its x, z)

    Returns
    -------
    local : ndarray (..., J, 3)   positions in the heading frame, metres
    yaw : ndarray (...)           heading, radians
    ground : ndarray (..., 3)     the reference joint's ground point ``(x, 0, z)``
    """
    global_rot, global_pos = np.asarray(global_rot), np.asarray(global_pos, dtype=np.float64)
    yaw = quat.yaw(global_rot[..., ref, :])
    ground = global_pos[..., ref, :] * np.array([1.0, 0.0, 1.0])
    local = quat.rotate(quat.from_yaw(-yaw)[..., None, :], global_pos - ground[..., None, :])
    return local, yaw, ground


def window_features(
    local_rot, translations, parents, fps: float, ref: int = 0, velocity_weight: float = VELOCITY_WEIGHT
):
    """:func:`pose_features` for raw arrays ``(..., T, J, 4)`` and ``(..., T, J, 3)``: (..., T, 6J).

    Velocities are central differences (one-sided at the ends); ``T`` must be at least 2.

    Raises
    ------
    ValueError for fewer than 2 frames.
    """
    g_rot, g_pos = fk(local_rot, translations, parents)
    local, yaw, _ = heading_frame(g_rot, g_pos, ref)
    if g_pos.shape[-3] < 2:
        raise ValueError(f"pose features need at least 2 frames for velocities, got {g_pos.shape[-3]}")
    vel = np.gradient(g_pos, axis=-3) * fps
    vel = quat.rotate(quat.from_yaw(-yaw)[..., None, :], vel)
    shape = local.shape[:-2] + (-1,)
    return np.concatenate([local.reshape(shape), velocity_weight * vel.reshape(shape)], axis=-1)


def pose_features(motion: Motion, velocity_weight: float = VELOCITY_WEIGHT) -> np.ndarray:
    """Per-frame features (T, 6J) of a motion: heading-frame positions and weighted velocities.

    Raises
    ------
    ValueError for fewer than 2 frames.
    """
    if motion.num_frames < 2:
        raise ValueError(f"pose features need at least 2 frames, got {motion.num_frames}")
    return window_features(
        motion.local_rot,
        motion.translations(),
        motion.skeleton.parents,
        motion.fps,
        reference_joint(motion),
        velocity_weight,
    )


def distance_matrix(features_a, features_b=None) -> np.ndarray:
    """Euclidean distances (Ta, Tb) between the rows of two feature arrays (Ta, D), (Tb, D).

    Raises
    ------
    ValueError unless ``a`` and ``b`` are (Ta, D) and (Tb, D) with the same D.
    """
    a = np.asarray(features_a, dtype=np.float64)
    b = a if features_b is None else np.asarray(features_b, dtype=np.float64)
    if a.ndim != 2 or b.ndim != 2 or a.shape[1] != b.shape[1]:
        raise ValueError(f"expected (Ta, D) and (Tb, D) feature arrays, got {a.shape} and {b.shape}")
    d2 = np.sum(a * a, axis=1)[:, None] + np.sum(b * b, axis=1)[None, :] - 2.0 * a @ b.T
    return np.sqrt(np.maximum(d2, 0.0))
