"""Preprocessing as in the retargeting paper: resample, reduce to 22 joints, features, windows.

Per frame ``t`` the network sees ``p_t = [22 joint positions, v_t]`` (66 + 4 = 70 numbers):

* **joint positions** relative to the root, in the *heading frame*: the root's ground position
  is subtracted and the frame is turned about +Y so the character faces +Z (heading
  normalisation). The root itself therefore sits at the origin.
* **v_t ∈ R⁴, the root motion** — our documented choice:
  ``(v_x, v_z, ω, h)``: the root's ground velocity in the heading frame of frame ``t``
  (metres per frame), the heading's angular velocity about +Y (radians per frame), and the
  root height above the ground (metres). The last frame repeats the previous velocities.

The heading is read from positions alone (hips and shoulders: left-right axis × up), so every
rig, real or synthetic, gets the same definition. :func:`to_global` integrates ``v_t`` back to
world positions, exactly inverting :func:`features` (up to the start position and heading).

Taught in ``notebooks/01_preprocessing.ipynb``.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from motionlab.core import humanoid, quat, rest_pose
from motionlab.core.motion import Motion

__all__ = [
    "prepare",
    "heading",
    "Features",
    "features",
    "to_global",
    "sliding_windows",
    "NormStats",
]


def prepare(motion: Motion, fps: float | None = 60.0, profile=None, stand: bool = False) -> Motion:
    """Reduce a motion to the 22-joint humanoid and resample it to ``fps`` (``None``: keep).

    ``stand=True`` also brings the rig to its canonical standing rest pose
    (:func:`motionlab.core.rest_pose.standing` with the rig's profile; world positions unchanged), as retargeting
    does, and raises :class:`~motionlab.core.rest_pose.RestPoseError` when there is none.
    """
    out = humanoid.to_canonical(motion, profile)
    if stand:
        out = rest_pose.standing(out, family=humanoid.family(motion.skeleton, profile))[0]
    if fps is not None:
        out = out.resample(fps)
    bad = ~np.isfinite(out.local_rot).all(axis=(1, 2)) | ~np.isfinite(out.root_pos).all(axis=1)
    if np.any(bad):
        raise ValueError(f"{motion.name or 'motion'}: frame {int(np.argmax(bad))} has NaN or infinite values")
    return out


heading = humanoid.heading  # the facing angle of canonical poses, used throughout this module


@dataclass
class Features:
    """The per-frame representation of one clip.

    Attributes
    ----------
    positions : ndarray, shape (T, 22, 3)   root-relative joint positions in the heading frame, m
    root      : ndarray, shape (T, 4)       ``v_t = (v_x, v_z, ω, h)``: m/frame, m/frame, rad/frame, m
    start     : ndarray, shape (3,)         world position of the root's ground point at frame 0
    start_heading : float                   heading at frame 0, radians
    """

    positions: np.ndarray
    root: np.ndarray
    start: np.ndarray
    start_heading: float

    def flat(self) -> np.ndarray:
        """``p_t`` as one (T, 70) array: 66 position numbers then ``v_t``."""
        return np.concatenate([self.positions.reshape(len(self.positions), -1), self.root], axis=-1)


def features(motion: Motion) -> Features:
    """Features of a canonical (22-joint) motion; see the module docstring.

    Raises
    ------
    ValueError when the motion is not on the 22-joint canonical skeleton.
    """
    if not humanoid.is_canonical(motion.skeleton):
        raise ValueError("features() needs a 22-joint canonical motion; call prepare(motion) first")
    pos = motion.global_positions()
    return features_from_positions(pos)


def features_from_positions(pos: np.ndarray) -> Features:
    """Features from world positions (T, 22, 3); see :func:`features`.

    Raises
    ------
    ValueError for fewer than 2 frames.
    """
    pos = np.asarray(pos, dtype=np.float64)
    T = pos.shape[0]
    if T < 2:
        raise ValueError(f"a clip needs at least 2 frames for root velocities, got {T}")
    yaw = np.unwrap(heading(pos))
    root = pos[:, 0]
    inv_heading = quat.from_yaw(-yaw)  # (T, 4)
    ground = root * np.array([1.0, 0.0, 1.0])
    local = quat.rotate(inv_heading[:, None], pos - ground[:, None])
    local[:, 0, [0, 2]] = 0.0
    vel = np.diff(ground, axis=0)
    vel = np.concatenate([vel, vel[-1:]], axis=0)
    vel_local = quat.rotate(inv_heading, vel)
    omega = np.diff(yaw)
    omega = np.concatenate([omega, omega[-1:]])
    v = np.stack([vel_local[:, 0], vel_local[:, 2], omega, root[:, 1]], axis=-1)
    return Features(local, v, ground[0].copy(), float(yaw[0]))


def to_global(positions: np.ndarray, root: np.ndarray, start=(0.0, 0.0, 0.0), start_heading: float = 0.0) -> np.ndarray:
    """Integrate root motion back to world positions.

    Parameters
    ----------
    positions : (..., T, 22, 3)  root-relative heading-frame positions (root entry ignored in x/z)
    root      : (..., T, 4)      ``v_t = (v_x, v_z, ω, h)``
    start, start_heading         ground position and heading of frame 0

    Returns
    -------
    ndarray (..., T, 22, 3) world positions, metres
    """
    positions, root = np.asarray(positions, dtype=np.float64), np.asarray(root, dtype=np.float64)
    yaw = start_heading + np.concatenate(
        [np.zeros(root.shape[:-2] + (1,)), np.cumsum(root[..., :-1, 2], axis=-1)], axis=-1
    )
    rot = quat.from_yaw(yaw)  # (..., T, 4)
    vel = np.stack([root[..., 0], np.zeros_like(root[..., 0]), root[..., 1]], axis=-1)
    vel_world = quat.rotate(rot, vel)
    ground = np.asarray(start, dtype=np.float64) * np.array([1.0, 0.0, 1.0]) + np.concatenate(
        [np.zeros(vel_world.shape[:-2] + (1, 3)), np.cumsum(vel_world[..., :-1, :], axis=-2)], axis=-2
    )
    local = positions.copy()
    local[..., 0, 0] = 0.0
    local[..., 0, 2] = 0.0
    return quat.rotate(rot[..., None, :], local) + ground[..., None, :]


def sliding_windows(length_total: int, window: int = 120, stride: int = 60) -> list[tuple[int, int]]:
    """``(start, stop)`` frame ranges of windows covering ``length_total`` frames.

    Windows are ``window`` long, ``stride`` apart; the last one is moved back to end on the last
    frame so every frame is covered. A clip shorter than one window gives one range
    ``(0, length_total)`` (callers pad it, see :func:`pad_to`).

    Raises
    ------
    ValueError when ``window`` or ``stride`` is < 1.
    """
    if window < 1 or stride < 1:
        raise ValueError(f"window and stride must be positive, got {window} and {stride}")
    if length_total <= window:
        return [(0, length_total)]
    starts = list(range(0, length_total - window + 1, stride))
    if starts[-1] + window < length_total:
        starts.append(length_total - window)
    return [(s, s + window) for s in starts]


def pad_to(x: np.ndarray, length: int, axis: int = 0) -> np.ndarray:
    """Pad along ``axis`` to ``length`` by repeating the last frame (no-op if long enough)."""
    n = x.shape[axis]
    if n >= length:
        return x
    reps = np.take(x, [-1], axis=axis).repeat(length - n, axis=axis)
    return np.concatenate([x, reps], axis=axis)


@dataclass
class NormStats:
    """Per-dimension mean and standard deviation for z-normalising features.

    ``std`` is floored at ``eps`` so constant dimensions (the root's x/z, always 0) stay finite.
    """

    mean: np.ndarray
    std: np.ndarray

    @classmethod
    def fit(cls, arrays: Iterable[np.ndarray], eps: float = 1e-3) -> NormStats:
        """Statistics over all frames of (T, D) arrays.

        Raises
        ------
        ValueError when there is no data.
        """
        data = np.concatenate([np.asarray(a, dtype=np.float64) for a in arrays], axis=0)
        if data.size == 0:
            raise ValueError("cannot fit normalisation statistics on no data")
        return cls(data.mean(axis=0), np.maximum(data.std(axis=0), eps))

    def normalize(self, x):
        return (x - self.mean) / self.std

    def denormalize(self, x):
        return x * self.std + self.mean

    def to_dict(self) -> dict:
        return {"mean": self.mean.tolist(), "std": self.std.tolist()}

    @classmethod
    def from_dict(cls, d: dict) -> NormStats:
        return cls(np.asarray(d["mean"], dtype=np.float64), np.asarray(d["std"], dtype=np.float64))

    def save(self, path: str | Path) -> None:
        Path(path).write_text(json.dumps(self.to_dict()))

    @classmethod
    def load(cls, path: str | Path) -> NormStats:
        return cls.from_dict(json.loads(Path(path).read_text()))


def window_stack(
    arrays: Sequence[np.ndarray], window: int, stride: int
) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """Cut each (T, ...) array into windows and stack them: returns (N, window, ...) and, for
    each window, ``(clip index, start, stop)`` (short clips are edge-padded to ``window``).

    Raises
    ------
    ValueError when there are no clips to cut.
    """
    out, index = [], []
    for i, a in enumerate(arrays):
        for s, e in sliding_windows(len(a), window, stride):
            out.append(pad_to(a[s:e], window))
            index.append((i, s, e))
    if not out:
        raise ValueError("no clips to cut into windows")
    return np.stack(out), index
