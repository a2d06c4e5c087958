"""Analytic inverse kinematics for limbs: the two-bone solver and frame-to-frame rotations.

A leg (hip → knee → ankle) or an arm (shoulder → elbow → wrist) is a chain of two rigid bones.
Given where the chain starts, where its end should go and a *pole* direction saying which way
the middle joint bends, the law of cosines places the middle joint in closed form::

    d = |target − start|,   x = (a² − b² + d²) / (2d),   h = √(a² − x²)
    mid = start + x·u + h·n          u = (target − start)/d,  n = pole ⟂ u, normalised

Targets out of reach are clamped: farther than ``a + b`` the chain straightens along the
target direction (optionally *softly*, approaching full extension exponentially so the middle
joint never snaps); nearer than ``|a − b|`` it folds completely.

:func:`aim` then turns joint *positions* into joint *rotations*: it is the rotation taking a
rest frame (bone direction + a second direction, e.g. "the knee points forward") onto the
posed frame. Every function is vectorised over any leading shape ``...`` (frames, batches).

Used by every notebook when ``MOTIONLAB_DATA`` is unset (see ``notebooks/01_preprocessing.ipynb``).
"""

from __future__ import annotations

import numpy as np

from motionlab.core import quat

__all__ = ["two_bone", "aim", "frame_matrix"]

_EPS = 1e-9


def _vec(x, name: str) -> np.ndarray:
    x = np.asarray(x, dtype=np.float64)
    if x.ndim == 0 or x.shape[-1] != 3:
        raise ValueError(f"expected {name} as (..., 3) vectors, got shape {x.shape}")
    return x


def _normalise(v: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    ok = n > _EPS
    return np.where(ok, v / np.where(ok, n, 1.0), fallback)


def _perpendicular(v: np.ndarray) -> np.ndarray:
    """Some unit vector perpendicular to each unit vector ``v`` (..., 3)."""
    helper = np.where(np.abs(v[..., :1]) < 0.9, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    return _normalise(np.cross(v, helper), np.array([0.0, 0.0, 1.0]))


def two_bone(start, target, upper, lower, pole, soft=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Place the middle joint of a two-bone chain so that its end reaches ``target``.

    Parameters
    ----------
    start : array, shape (..., 3)    position of the chain's first joint (hip, shoulder), metres
    target : array, shape (..., 3)   where the end joint (ankle, wrist) should be, metres
    upper : float or array (...)     length of the first bone (thigh), metres, > 0
    lower : float or array (...)     length of the second bone (shin), metres, > 0
    pole : array, shape (..., 3)     direction the middle joint bends towards (the knee's
        forward); only its part perpendicular to ``target − start`` matters.
    soft : float or array (...)      metres, >= 0 (default 0: exact). Targets farther than
        ``a + b − soft`` are approached exponentially, ``d' = a + b − soft·exp(−(d − a − b + soft)/soft)``,
        so the chain never snaps straight (the middle joint's speed ∝ 1/√(a + b − d) blows up
        at full extension); nearer targets are still reached exactly.

    Returns
    -------
    mid : ndarray, shape (..., 3)    middle joint position, ``|mid − start| = upper``
    end : ndarray, shape (..., 3)    end joint position, ``|end − mid| = lower``; equal to
        ``target`` when ``|a − b| <= |target − start| <= a + b − soft``, otherwise the nearest
        point the chain reaches along the direction ``start → target``.

    Raises
    ------
    ValueError unless the bone lengths are > 0 and ``soft`` >= 0.
    """
    start, target, pole = _vec(start, "start"), _vec(target, "target"), _vec(pole, "pole")
    upper = np.asarray(upper, dtype=np.float64)
    lower = np.asarray(lower, dtype=np.float64)
    if np.any(~(upper > 0)) or np.any(~(lower > 0)):
        raise ValueError(f"bone lengths must be positive, got upper={upper}, lower={lower}")
    upper, lower = upper[..., None], lower[..., None]
    delta = target - start
    dist = np.linalg.norm(delta, axis=-1, keepdims=True)
    pole_unit = _normalise(pole, np.array([0.0, 0.0, 1.0]))
    # a target on top of the start has no direction: fold towards the pole's perpendicular
    direction = _normalise(delta, _perpendicular(pole_unit))
    soft = np.asarray(soft, dtype=np.float64)[..., None] if np.ndim(soft) else np.float64(soft)
    if np.any(~(soft >= 0)):
        raise ValueError(f"soft must be a non-negative distance, got {soft}")
    knee = upper + lower - soft  # where softening starts
    safe_soft = np.maximum(soft, _EPS)
    softened = upper + lower - soft * np.exp(-np.maximum(dist - knee, 0.0) / safe_soft)
    reach = np.where(dist > knee, softened, dist)
    reach = np.clip(reach, np.abs(upper - lower), upper + lower)
    along = (upper**2 - lower**2 + reach**2) / (2.0 * np.maximum(reach, _EPS))
    height = np.sqrt(np.maximum(upper**2 - along**2, 0.0))
    bend = pole_unit - np.sum(pole_unit * direction, axis=-1, keepdims=True) * direction
    bend = _normalise(bend, _perpendicular(direction))
    mid = start + along * direction + height * bend
    end = start + reach * direction
    return mid, end


def frame_matrix(primary, secondary) -> np.ndarray:
    """Right-handed orthonormal frames (..., 3, 3) with columns ``[p, s', p × s']``.

    ``p`` is ``primary`` normalised and ``s'`` the part of ``secondary`` perpendicular to it
    (any perpendicular when the two are parallel).
    """
    primary, secondary = _vec(primary, "primary"), _vec(secondary, "secondary")
    primary, secondary = np.broadcast_arrays(primary, secondary)
    p = _normalise(primary, np.array([1.0, 0.0, 0.0]))
    s = secondary - np.sum(secondary * p, axis=-1, keepdims=True) * p
    s = _normalise(s, _perpendicular(p))
    return np.stack([p, s, np.cross(p, s)], axis=-1)


def aim(rest_dir, rest_up, direction, up) -> np.ndarray:
    """Rotation taking the rest frame ``(rest_dir, rest_up)`` onto ``(direction, up)``.

    The result maps ``rest_dir`` exactly onto the direction of ``direction``; the twist about
    it is chosen so that ``rest_up`` goes as close as possible to ``up``.

    Parameters
    ----------
    rest_dir, rest_up : array, shape (..., 3)    a bone's direction and a second direction at rest
    direction, up : array, shape (..., 3)        the same two directions when posed

    Returns
    -------
    ndarray, shape (..., 4)   unit quaternions (w, x, y, z)
    """
    rest = frame_matrix(rest_dir, rest_up)
    posed = frame_matrix(direction, up)
    return quat.from_matrix(posed @ np.swapaxes(rest, -1, -2))
