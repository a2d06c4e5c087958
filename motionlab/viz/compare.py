"""Several motions side by side, in sync, with the per-frame joint error shown as colour.

Typical use: the source clip, the retargeted clip and the ground truth next to each other; the
generated skeletons' joints are coloured by how far each joint is from the reference's joint of
the same name in that frame (metres), so errors are seen where and when they happen.

Taught in ``notebooks/04_playback_and_bone_proportions.ipynb``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from motionlab.core import humanoid
from motionlab.core.motion import Motion
from motionlab.viz.scene import Scene

__all__ = ["joint_errors", "side_by_side_offsets", "side_by_side"]


def _frames_at(motion: Motion, times: np.ndarray) -> np.ndarray:
    return np.clip(np.round(times * motion.fps).astype(np.int64), 0, motion.num_frames - 1)


def joint_errors(motion: Motion, reference: Motion, relative_to_root: bool = False) -> np.ndarray:
    """Distance of each joint from the reference's joint of the same name, every frame.

    Parameters
    ----------
    motion : the generated motion, T frames, J joints
    reference : the motion to compare with; joints are matched by name (namespace prefixes such
        as ``mixamorig:`` ignored) and frames by time (nearest frame)
    relative_to_root : compare poses only (subtract each motion's root position first)

    Returns
    -------
    ndarray, shape (T, J), metres; NaN for joints the reference lacks.

    Raises
    ------
    ValueError for arguments that are not Motions or share no joint name.
    """
    if not isinstance(motion, Motion) or not isinstance(reference, Motion):
        raise ValueError(f"expected two Motions, got {type(motion).__name__} and {type(reference).__name__}")
    ref_index = {humanoid.strip_prefix(n).lower(): j for j, n in enumerate(reference.skeleton.names)}
    match = np.array([ref_index.get(humanoid.strip_prefix(n).lower(), -1) for n in motion.skeleton.names])
    if not np.any(match >= 0):
        raise ValueError(
            f"no joint names in common between {motion.name or 'the motion'} ({motion.skeleton.names[0]!r}, ...) "
            f"and the reference ({reference.skeleton.names[0]!r}, ...)"
        )
    pos = motion.global_positions()
    times = np.arange(motion.num_frames) / motion.fps
    ref = reference.global_positions()[_frames_at(reference, times)]
    if relative_to_root:
        pos = pos - pos[:, :1]
        ref = ref - ref[:, :1]
    err = np.full(pos.shape[:2], np.nan)
    ok = match >= 0
    err[:, ok] = np.linalg.norm(pos[:, ok] - ref[:, match[ok]], axis=-1)
    return err


def side_by_side_offsets(motions: Sequence[Motion], spacing: float | None = None, align: bool = True) -> np.ndarray:
    """World offsets (K, 3) that place the motions next to each other along X (the side axis).

    ``spacing``: metres between neighbours (default 0.6 × the tallest character's height,
    at least the widest rest pose plus a margin). ``align``: first move every motion so its
    root starts at the same ground point (x, z), then spread them out.

    Raises
    ------
    ValueError unless ``spacing`` is a finite number >= 0.
    """
    K = len(motions)
    heights = [m.skeleton.height() for m in motions]
    widths = [float(np.ptp(m.skeleton.rest_positions()[:, 0])) for m in motions]
    if spacing is None:
        spacing = max(0.6 * max(heights), 1.1 * max(widths) + 0.1 * max(heights))
    if not (np.isfinite(spacing) and spacing >= 0):
        raise ValueError(f"spacing must be a non-negative number of metres, got {spacing}")
    offsets = np.zeros((K, 3))
    offsets[:, 0] = (np.arange(K) - (K - 1) / 2) * spacing
    if align:
        for k, m in enumerate(motions):
            offsets[k, [0, 2]] -= m.root_pos[0, [0, 2]]
    return offsets


def side_by_side(
    motions: Sequence[Motion],
    labels: Sequence[str] | None = None,
    reference: int | None = 0,
    error: bool = True,
    relative_to_root: bool = False,
    spacing: float | None = None,
    align: bool = True,
    clim: tuple[float, float] | None = None,
    **scene_options,
) -> Scene:
    """A :class:`~motionlab.viz.scene.Scene` of ``motions`` next to each other, in sync.

    Parameters
    ----------
    motions : two or more Motions (any rigs)
    labels : legend text per motion (default: the motions' names)
    reference : index of the reference motion; with ``error=True`` every *other* motion's joints
        are coloured by :func:`joint_errors` against it (shared colour range ``clim``, default
        0 .. the largest error). ``None``: no error colouring.
    relative_to_root : colour by pose error only (root positions subtracted)
    spacing, align : layout, see :func:`side_by_side_offsets`
    **scene_options : camera, window_size, trails, off_screen, ... (see Scene)

    Raises
    ------
    ValueError for no Motion, or a ``reference`` index out of range.
    """
    motions = list(motions)
    if len(motions) < 1 or not all(isinstance(m, Motion) for m in motions):
        raise ValueError("expected a sequence of Motions")
    if reference is not None and not -len(motions) <= reference < len(motions):
        raise ValueError(f"reference index {reference} out of range for {len(motions)} motions")
    values: list[np.ndarray | None] = [None] * len(motions)
    if error and reference is not None and len(motions) > 1:
        ref = motions[reference]
        for k, m in enumerate(motions):
            if k != reference % len(motions):
                values[k] = joint_errors(m, ref, relative_to_root=relative_to_root)
        if clim is None:
            finite = np.concatenate([v[np.isfinite(v)] for v in values if v is not None])
            high = float(finite.max()) if finite.size else 1.0
            clim = (0.0, high if high > 0 else 1.0)
    if labels is None:
        labels = [m.name or f"motion {k}" for k, m in enumerate(motions)]
    offsets = side_by_side_offsets(motions, spacing=spacing, align=align)
    scene_options.setdefault("value_title", "pose error (m)" if relative_to_root else "error (m)")
    return Scene(motions, offsets=offsets, labels=labels, joint_values=values, clim=clim, **scene_options)
