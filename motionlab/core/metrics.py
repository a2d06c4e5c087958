"""Motion quality metrics, each with its unit stated.

All functions take world joint positions ``pos`` of shape (..., T, J, 3) in metres (or any unit:
results are in that unit), Y up, ground at y = 0. Errors compare two motions frame by frame.

========================  ==========================================================  ==========
metric                    formula                                                     unit
========================  ==========================================================  ==========
``mse``                   mean over frames, joints and axes of (p - p̂)²               m²
``mpjpe``                 mean over frames and joints of ‖p - p̂‖                      m
``mse / height²``         :func:`mse` with ``height=h``                               unitless
``smoothness``            mean over frames, joints of ‖p[t+1] - 2 p[t] + p[t-1]‖      m/frame²
``foot_penetration``      mean over frames and foot joints of max(0, -y)              m
``foot_skating``          mean horizontal foot speed over frames in ground contact    m/s
``planted_slide``         mean horizontal foot speed where given labels say planted   m/s
``bone_length_error``     mean over bones of std_t(length) / mean_t(length)           unitless
========================  ==========================================================  ==========

Taught in ``notebooks/01_preprocessing.ipynb``; used by the retargeting evaluation (Table 1).
"""

from __future__ import annotations

import numpy as np

from motionlab.core import contacts

__all__ = [
    "mse",
    "mpjpe",
    "smoothness",
    "foot_penetration",
    "foot_contacts",
    "planted_slide",
    "foot_skating",
    "bone_length_error",
]


def _pair(pred, target) -> tuple[np.ndarray, np.ndarray]:
    pred, target = np.asarray(pred, dtype=np.float64), np.asarray(target, dtype=np.float64)
    if pred.shape != target.shape or pred.shape[-1:] != (3,):
        raise ValueError(
            f"expected two (..., T, J, 3) position arrays of equal shape, got {pred.shape} and {target.shape}"
        )
    if pred.size == 0:
        raise ValueError(f"expected positions of at least one frame and joint, got shape {pred.shape}")
    return pred, target


def _pos(pos, name: str = "pos") -> np.ndarray:
    pos = np.asarray(pos, dtype=np.float64)
    if pos.ndim < 3 or pos.shape[-1] != 3:
        raise ValueError(f"expected {name} of shape (..., T, J, 3), got {pos.shape}")
    if pos.shape[-3] == 0:
        raise ValueError(f"expected {name} of at least one frame, got shape {pos.shape}")
    return pos


def _height(height: float | None) -> float:
    """The length an error is divided by: ``height``, or 1 for None. Raises ValueError for a height
    that is not a positive number."""
    if height is None:
        return 1.0
    if not (np.isfinite(height) and height > 0):
        raise ValueError(f"expected a positive height to normalise by, got {height!r}")
    return float(height)


def mse(pred, target, height: float | None = None) -> float:
    """Mean squared joint-position error over frames, joints and axes.

    With ``height``, the error is divided by ``height²`` (the unitless retargeting-literature
    metric). Unit: (position unit)², or none when normalised.
    """
    pred, target = _pair(pred, target)
    err = float(np.mean((pred - target) ** 2))
    return err / _height(height) ** 2


def mpjpe(pred, target, height: float | None = None) -> float:
    """Mean per-joint position error: mean Euclidean distance (position unit; ÷ height if given)."""
    pred, target = _pair(pred, target)
    err = float(np.mean(np.linalg.norm(pred - target, axis=-1)))
    return err / _height(height)


def smoothness(pos) -> float:
    """Mean acceleration magnitude ``‖p[t+1] − 2p[t] + p[t−1]‖`` over frames and joints.

    Unit: position unit per frame² (lower is smoother). Needs at least 3 frames.

    Raises
    ------
    ValueError for fewer than 3 frames.
    """
    pos = _pos(pos)
    if pos.shape[-3] < 3:
        raise ValueError(f"smoothness needs at least 3 frames, got {pos.shape[-3]}")
    acc = pos[..., 2:, :, :] - 2 * pos[..., 1:-1, :, :] + pos[..., :-2, :, :]
    return float(np.mean(np.linalg.norm(acc, axis=-1)))


def foot_penetration(pos, feet, ground: float = 0.0) -> float:
    """Mean depth below the ground, ``max(0, ground − y)``, over frames and the ``feet`` joints.

    ``feet``: joint indices (e.g. both feet and toes). Unit: position unit.
    """
    pos = _pos(pos)
    y = pos[..., list(feet), 1]
    return float(np.mean(np.maximum(0.0, ground - y)))


def foot_contacts(pos, feet, fps: float, height_threshold: float = 0.05, speed_threshold: float = 0.5) -> np.ndarray:
    """Boolean ground-contact labels (..., T, F) for the ``feet`` joints: below
    ``height_threshold`` (position unit) and slower than ``speed_threshold`` (units/s) —
    :func:`motionlab.core.contacts.low_and_slow` with contact height 0.
    """
    pos = _pos(pos)
    return contacts.low_and_slow(pos[..., list(feet), :], 0.0, height_threshold, speed_threshold, fps)


def foot_skating(pos, feet, fps: float, height_threshold: float = 0.05) -> float:
    """Mean horizontal speed (units/s) of the ``feet`` joints over the frames where they touch
    the ground (height below ``height_threshold``); 0 when no foot ever touches it, NaN when a
    foot position is not finite.
    """
    pos = _pos(pos)
    p = pos[..., list(feet), :]
    if not np.all(np.isfinite(p)):
        return float("nan")
    if p.shape[-3] < 2:
        return 0.0
    speed = np.linalg.norm(np.diff(p[..., [0, 2]], axis=-3), axis=-1) * fps  # (..., T-1, F)
    contact = (p[..., 1:, :, 1] < height_threshold) & (p[..., :-1, :, 1] < height_threshold)
    if not np.any(contact):
        return 0.0
    return float(np.mean(speed[contact]))


def planted_slide(pos, feet, planted, fps: float) -> float:
    """Mean horizontal speed (units/s) of the ``feet`` joints over the frame pairs where ``planted``
    (T, F) marks them planted in both frames; 0 when none is.

    Unlike :func:`foot_skating`, which decides contact by a height threshold on the motion itself,
    the labels come from elsewhere (e.g. the source's contacts in retargeting), so a foot that
    floats while it should stand still counts too, and a low swinging foot does not. NaN when a
    foot position is not finite.

    Raises
    ------
    ValueError when ``planted`` is not (T, feet) for the positions given.
    """
    pos = _pos(pos)
    planted = np.asarray(planted, dtype=bool)
    p = pos[..., list(feet), :]
    if planted.shape != p.shape[-3:-1]:
        raise ValueError(f"planted_slide: expected planted of shape {p.shape[-3:-1]} (T, feet), got {planted.shape}")
    if not np.all(np.isfinite(p)):
        return float("nan")
    if p.shape[-3] < 2:
        return 0.0
    speed = np.linalg.norm(np.diff(p[..., [0, 2]], axis=-3), axis=-1) * fps  # (..., T-1, F)
    both = planted[1:] & planted[:-1]
    if not np.any(both):
        return 0.0
    return float(np.mean(speed[..., both]))


def bone_length_error(pos, parents) -> float:
    """How much bones stretch over time: mean over bones of std_t(length) / mean_t(length) (bones
    of no length left out; NaN when a position is not finite).

    Raises
    ------
    ValueError when ``parents`` is not one parent index per joint of ``pos``.
    """
    pos = _pos(pos)
    parents = np.asarray(parents)
    if parents.shape != pos.shape[-2:-1]:
        raise ValueError(f"expected one parent per joint, {pos.shape[-2]}, got parents of shape {parents.shape}")
    if not np.all(np.isfinite(pos)):
        return float("nan")
    child = np.flatnonzero(parents >= 0)
    lengths = np.linalg.norm(pos[..., child, :] - pos[..., parents[child], :], axis=-1)
    mean = lengths.mean(axis=-2)
    ok = mean > 1e-9
    return float(np.mean(lengths.std(axis=-2)[ok] / mean[ok])) if np.any(ok) else 0.0
