"""The Motion: a skeleton animated over time.

A Motion holds, for T frames, the local rotation of every joint, the root's world position and
the frame rate. Joints that translate on their own (BVH position channels on a non-root joint)
keep per-frame translations in ``local_pos``; otherwise their rest offsets are used.

Taught in ``notebooks/00_quaternions_and_fk.ipynb`` and ``01_preprocessing.ipynb``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from motionlab.core import fk as _fk
from motionlab.core import quat
from motionlab.core.skeleton import Skeleton

__all__ = ["Motion", "check_one_rig", "resampled_frames"]


def _check_fps(fps) -> float:
    try:
        value = float(fps)
    except (TypeError, ValueError):
        value = float("nan")
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"fps must be a positive number, got {fps!r}")
    return value


def _nominal(fps: float) -> float:
    """``fps`` snapped to the nearest whole number when within 1e-4 relative of it."""
    r = round(fps)
    return float(r) if r > 0 and abs(fps - r) < 1e-4 * fps else float(fps)


def resampled_frames(frames: int, fps: float, new_fps: float) -> int:
    """How many frames :meth:`Motion.resample` gives a motion of ``frames`` frames at ``fps`` when
    resampled to ``new_fps``. Raises ``ValueError`` for a rate that is not a positive number."""
    src, new = _nominal(_check_fps(fps)), _nominal(_check_fps(new_fps))
    if abs(new - src) < 1e-9 * src or frames < 2:
        return frames
    return int(np.floor((frames - 1) * new / src + 1e-6)) + 1


UNIT_TOLERANCE = 1e-3
"""How far from 1 a rotation's quaternion norm may be (a frame that is not known, NaN, is let be)."""


def _check_unit(local_rot: np.ndarray, names) -> None:
    """Raise ValueError naming the first frame and joint whose quaternion is finite but not a unit
    quaternion (FK would scale the bones by its squared norm)."""
    sq = np.einsum("...i,...i->...", local_rot, local_rot)
    bad = np.abs(sq - 1.0) > 2 * UNIT_TOLERANCE  # |q|² − 1 ≈ 2 (|q| − 1)
    if np.any(bad):
        t, j = np.argwhere(bad)[0]
        raise ValueError(
            f"local_rot[{t}, {j}] (joint {names[j]!r}, frame {t}) has norm {np.sqrt(sq[t, j]):.6g}, not 1: "
            "rotations are unit quaternions (normalise them first, e.g. motionlab.core.quat.normalize)"
        )


@dataclass(eq=False)
class Motion:
    """A skeleton's animation.

    Attributes
    ----------
    skeleton  : Skeleton with J joints
    local_rot : ndarray, shape (T, J, 4)   unit quaternions (w, x, y, z) relative to the parent
                                           (within :data:`UNIT_TOLERANCE`, else ValueError; NaN
                                           marks a frame that is not known)
    root_pos  : ndarray, shape (T, 3)      world position of the root joint, metres
    fps       : float                      frames per second (required: no silent default)
    local_pos : ndarray, shape (T, J, 3), or None
        Per-frame translation of every joint relative to its parent, for rigs whose non-root
        joints are animated in position; ``None`` means the skeleton's rest offsets.
    name      : str                        a label (file stem when loaded from BVH)
    """

    skeleton: Skeleton
    local_rot: np.ndarray
    root_pos: np.ndarray
    fps: float
    local_pos: np.ndarray | None = None
    name: str = ""

    def __post_init__(self) -> None:
        self.local_rot = quat.check(self.local_rot, "local_rot")
        self.root_pos = np.asarray(self.root_pos, dtype=self.local_rot.dtype)
        J = self.skeleton.num_joints
        if self.local_rot.ndim != 3 or self.local_rot.shape[1] != J:
            raise ValueError(
                f"expected local_rot of shape (T, {J}, 4) for a {J}-joint skeleton, got {self.local_rot.shape}"
            )
        T = self.local_rot.shape[0]
        if self.root_pos.shape != (T, 3):
            raise ValueError(f"expected root_pos of shape ({T}, 3), got {self.root_pos.shape}")
        if self.local_pos is not None:
            self.local_pos = np.asarray(self.local_pos, dtype=self.local_rot.dtype)
            if self.local_pos.shape != (T, J, 3):
                raise ValueError(f"expected local_pos of shape ({T}, {J}, 3), got {self.local_pos.shape}")
        _check_unit(self.local_rot, self.skeleton.names)
        self.fps = _check_fps(self.fps)

    # ------------------------------------------------------------------ basics
    @property
    def num_frames(self) -> int:
        """Number of frames T."""
        return int(self.local_rot.shape[0])

    def __len__(self) -> int:
        return self.num_frames

    @property
    def duration(self) -> float:
        """Length in seconds, ``(T - 1) / fps``."""
        return max(self.num_frames - 1, 0) / self.fps

    def __repr__(self) -> str:
        label = f"{self.name!r}, " if self.name else ""
        return f"Motion({label}{self.num_frames} frames @ {self.fps:g} fps, {self.skeleton.num_joints} joints)"

    def __getitem__(self, frames) -> Motion:
        """Frames ``frames`` (an int, a slice or an index array) as a new Motion.

        An int gives a one-frame Motion. A slice with a step ``s`` keeps every ``s``-th frame,
        so the frame rate becomes ``fps / |s|`` (playback speed is unchanged); index arrays keep ``fps``.
        """
        fps = self.fps
        if isinstance(frames, (int, np.integer)):
            k = int(frames) + (self.num_frames if frames < 0 else 0)
            if not 0 <= k < self.num_frames:
                raise IndexError(f"frame {int(frames)} is out of range for a {self.num_frames}-frame motion")
            frames = slice(k, k + 1)
        elif isinstance(frames, slice) and frames.step is not None:
            fps = self.fps / abs(int(frames.step))
        return Motion(
            self.skeleton,
            self.local_rot[frames].copy(),
            self.root_pos[frames].copy(),
            fps,
            None if self.local_pos is None else self.local_pos[frames].copy(),
            self.name,
        )

    def copy(self, **changes) -> Motion:
        """A deep copy, with any field replaced by ``changes``."""
        fields = dict(
            skeleton=self.skeleton,
            local_rot=self.local_rot.copy(),
            root_pos=self.root_pos.copy(),
            fps=self.fps,
            local_pos=None if self.local_pos is None else self.local_pos.copy(),
            name=self.name,
        )
        fields.update(changes)
        return Motion(**fields)

    # ------------------------------------------------------------------ kinematics
    def translations(self) -> np.ndarray:
        """Local translations (T, J, 3): the root's world position, then each joint's offset."""
        if self.local_pos is not None:
            t = self.local_pos.copy()
        else:
            t = np.broadcast_to(
                self.skeleton.offsets.astype(self.local_rot.dtype), (self.num_frames, self.skeleton.num_joints, 3)
            ).copy()
        t[:, 0] = self.root_pos
        return t

    def fk(self) -> tuple[np.ndarray, np.ndarray]:
        """Global rotations (T, J, 4) and positions (T, J, 3)."""
        return _fk.fk(self.local_rot, self.translations(), self.skeleton.parents)

    def global_positions(self) -> np.ndarray:
        """World joint positions (T, J, 3), metres."""
        return self.fk()[1]

    def global_rotations(self) -> np.ndarray:
        """World joint rotations (T, J, 4)."""
        return _fk.local_to_global(self.local_rot, self.skeleton.parents)

    # ------------------------------------------------------------------ time
    def resample(self, fps: float, frames: int | None = None) -> Motion:
        """The motion at another frame rate: SLERP for rotations, linear for positions.

        The first frame is kept; the last new frame is the last one at or before the end, or, with
        ``frames``, there are that many new frames and those after the end hold the last pose.
        Frame rates within 1e-4 (relative) of a whole number count as that number: BVH files
        write ``Frame Time: 0.0333333``, which means 30 fps, not 30.0000003.

        Raises
        ------
        ValueError for a rate that is not a positive number, or ``frames`` not a whole number >= 0.
        """
        fps = _check_fps(fps)
        src = _nominal(self.fps)
        if frames is not None and not (float(frames).is_integer() and frames >= 0):
            raise ValueError(f"expected frames as a whole number >= 0, got {frames!r}")
        n_new = resampled_frames(self.num_frames, self.fps, fps) if frames is None else int(frames)
        if (abs(_nominal(fps) - src) < 1e-9 * src or self.num_frames < 2) and n_new == self.num_frames:
            return self.copy(fps=float(fps))
        t = np.arange(n_new) * (src / _nominal(fps))  # in source frames
        i0 = np.clip(np.floor(t).astype(np.int64), 0, self.num_frames - 1)
        i1 = np.clip(i0 + 1, 0, self.num_frames - 1)
        alpha = t - i0
        rot = quat.slerp(self.local_rot[i0], self.local_rot[i1], alpha[:, None])
        lerp = lambda x: x[i0] + (x[i1] - x[i0]) * alpha.reshape((-1,) + (1,) * (x.ndim - 1))  # noqa: E731
        return Motion(
            self.skeleton,
            rot,
            lerp(self.root_pos),
            float(fps),
            None if self.local_pos is None else lerp(self.local_pos),
            self.name,
        )


def check_one_rig(motions: Sequence[Motion], group: str | None = None) -> None:
    """Refuse clips that do not share the first clip's skeleton (joint names and parents) and frame rate.

    Parameters
    ----------
    motions : sequence of Motion, at least one
    group : how the frame-rate message names what the clips must match (default: the first clip's name)

    Raises
    ------
    ValueError
        naming the first clip on another skeleton or at another frame rate (1e-6 relative).
    """
    first = motions[0]
    for m in motions[1:]:
        if m.skeleton.names != first.skeleton.names or not np.array_equal(m.skeleton.parents, first.skeleton.parents):
            raise ValueError(f"clip {m.name!r} uses another skeleton than {first.name!r}")
        if abs(m.fps - first.fps) > 1e-6 * first.fps:
            raise ValueError(f"clip {m.name!r} is at {m.fps:g} fps, {group or repr(first.name)} at {first.fps:g}")
