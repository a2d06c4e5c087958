"""Small matplotlib helpers the notebooks share (matplotlib is imported lazily).

For 3D playback with widgets see :mod:`motionlab.viz`; these draw quick static figures that work
everywhere, including headless CI.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["plot_pose", "plot_poses", "plot_trajectory", "plot_curves"]

_VIEWS = {"front": (0, 1), "side": (2, 1), "top": (0, 2)}
_LABELS = {0: "x (m)", 1: "y (m)", 2: "z (m)"}


def _axes(ax, figsize=(4, 4)):
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=figsize)
    return ax


def plot_pose(positions, parents, ax=None, view: str = "side", color="C0", joints: bool = True, label=None, **kw):
    """Draw one pose (J, 3) as a stick figure projected on a plane.

    ``view``: ``"front"`` (x–y), ``"side"`` (z–y) or ``"top"`` (x–z). Returns the axes.

    Raises
    ------
    ValueError for an unknown ``view``.
    """
    if view not in _VIEWS:
        raise ValueError(f"view must be one of {sorted(_VIEWS)}, got {view!r}")
    pos = np.asarray(positions)
    a, b = _VIEWS[view]
    ax = _axes(ax)
    for j, p in enumerate(parents):
        if p >= 0:
            ax.plot(pos[[p, j], a], pos[[p, j], b], color=color, lw=2, solid_capstyle="round", **kw)
    if joints:
        ax.scatter(pos[:, a], pos[:, b], s=10, color=color, zorder=3, label=label)
    ax.set_aspect("equal")
    ax.set_xlabel(_LABELS[a])
    ax.set_ylabel(_LABELS[b])
    return ax


def plot_poses(positions, parents, frames: Sequence[int], ax=None, view: str = "side", cmap: str = "viridis"):
    """Overlay several frames of (T, J, 3) positions, coloured from early to late."""
    import matplotlib.pyplot as plt

    ax = _axes(ax, figsize=(8, 3))
    colors = plt.get_cmap(cmap)(np.linspace(0, 1, len(frames)))
    for c, t in zip(colors, frames):
        plot_pose(positions[t], parents, ax=ax, view=view, color=c, joints=False)
    ax.axhline(0.0, color="0.6", lw=1)
    return ax


def plot_trajectory(positions, joint: int = 0, ax=None, **kw):
    """Top view (x–z) of one joint's path over time, from (T, J, 3) positions."""
    pos = np.asarray(positions)
    ax = _axes(ax)
    ax.plot(pos[:, joint, 0], pos[:, joint, 2], **kw)
    ax.scatter(pos[:1, joint, 0], pos[:1, joint, 2], marker="o", color="k", zorder=3, label="start")
    # equal scales, but a straight path must not shrink the panel to zero width: widen the limits
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    return ax


def plot_curves(curves: dict, fps: float | None = None, ax=None, ylabel: str = "", title: str = ""):
    """Plot named 1-D series against frames (or seconds when ``fps`` is given)."""
    ax = _axes(ax, figsize=(7, 3))
    for name, y in curves.items():
        y = np.asarray(y)
        x = np.arange(len(y)) / fps if fps else np.arange(len(y))
        ax.plot(x, y, label=name)
    ax.set_xlabel("time (s)" if fps else "frame")
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    if len(curves) > 1:
        ax.legend()
    return ax
