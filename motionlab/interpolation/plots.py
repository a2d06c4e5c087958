"""Matplotlib figures for notebook 06 (matplotlib is imported only when a function is called).

Every function takes an optional ``ax`` and returns it, so figures compose.
"""

from __future__ import annotations

import numpy as np

from motionlab.core import quat

__all__ = ["draw_action_graph", "plot_segmentation", "plot_joint_angles", "plot_rotation_paths", "plot_latent"]


def _axes(ax, projection=None, figsize=(6, 4)):
    import matplotlib.pyplot as plt

    if ax is None:
        fig = plt.figure(figsize=figsize)
        ax = fig.add_subplot(111, projection=projection)
    return ax


def draw_action_graph(graph, ax=None, highlight=()):
    """Nodes on a circle, arrows for allowed transitions; edges along ``highlight`` (a path) in red."""
    ax = _axes(ax, figsize=(5, 5))
    names = list(graph.nodes)
    ang = np.pi / 2 - 2 * np.pi * np.arange(len(names)) / max(len(names), 1)
    xy = {n: np.array([np.cos(a), np.sin(a)]) for n, a in zip(names, ang)}
    on_path = set(zip(highlight[:-1], highlight[1:]))
    for a, b in sorted(graph.edges):
        pa, pb = xy[a], xy[b]
        d = pb - pa
        normal = np.array([-d[1], d[0]]) * 0.06  # offset so a->b and b->a do not overlap
        colour = "tab:red" if (a, b) in on_path else "0.4"
        ax.annotate("", xy=pb - 0.18 * d + normal, xytext=pa + 0.18 * d + normal,
                    arrowprops=dict(arrowstyle="->", color=colour, lw=2 if (a, b) in on_path else 1))  # fmt: skip
    for n in names:
        keys = len(graph.nodes[n].keys)
        ax.text(*xy[n], f"{n}\n({keys} keys)", ha="center", va="center",
                bbox=dict(boxstyle="round", fc="lightyellow", ec="0.3"))  # fmt: skip
    ax.set_xlim(-1.4, 1.4)
    ax.set_ylim(-1.4, 1.4)
    ax.set_aspect("equal")
    ax.axis("off")
    ax.set_title("action graph")
    return ax


def plot_segmentation(predicted, truth=None, ax=None, fps: float | None = None):
    """Colour bands of cluster labels over time, with the known actions above them."""
    ax = _axes(ax, figsize=(9, 2.2))
    predicted = np.asarray(predicted)
    t = np.arange(len(predicted)) / (fps or 1.0)
    ax.scatter(t, np.zeros_like(t), c=predicted, cmap="tab10", marker="|", s=400)
    if truth is not None:
        truth = np.asarray(truth)
        names = list(dict.fromkeys(truth.tolist()))
        codes = np.array([names.index(v) for v in truth])
        ax.scatter(t, np.ones_like(t), c=codes, cmap="Set2", marker="|", s=400)
        cut = np.flatnonzero(truth[1:] != truth[:-1]) + 1
        for a, b in zip(np.r_[0, cut], np.r_[cut, len(truth)]):
            ax.text(t[(a + b - 1) // 2], 1.45, str(truth[a]), ha="center", fontsize=8)
    ax.set_yticks([0, 1], ["clusters", "true actions"])
    ax.set_ylim(-0.6, 1.9)
    ax.set_xlabel("time (s)" if fps else "frame")
    return ax


def plot_joint_angles(true_angles, filled_angles, gaps=(), ax=None, labels=("x", "y", "z"), title="left hip"):
    """The paper's Fig. 7: joint angles (T, 3), degrees, true (dashed) against filled (solid)."""
    ax = _axes(ax, figsize=(8, 3.5))
    true_angles, filled_angles = np.asarray(true_angles), np.asarray(filled_angles)
    for i, lab in enumerate(labels):
        (line,) = ax.plot(filled_angles[:, i], "-", label=f"{lab} filled")
        ax.plot(true_angles[:, i], "--", color=line.get_color(), label=f"{lab} true")
    for a, b in gaps:
        ax.axvspan(a - 0.5, b - 0.5, color="0.85", zorder=0)
    ax.set_xlabel("frame")
    ax.set_ylabel("angle (degrees)")
    ax.set_title(title)
    ax.legend(ncol=3, fontsize=7)
    return ax


def plot_rotation_paths(paths: dict, vector=(0.0, 0.0, 1.0), ax=None):
    """Where each rotation path ``{label: (N, 4)}`` sends ``vector``: curves on the unit sphere."""
    ax = _axes(ax, projection="3d", figsize=(5, 5))
    u, v = np.mgrid[0 : 2 * np.pi : 30j, 0 : np.pi : 15j]
    ax.plot_wireframe(np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v), color="0.85", lw=0.5)
    for label, q in paths.items():
        p = quat.rotate(np.asarray(q), np.asarray(vector, dtype=np.float64))
        ax.plot(p[:, 0], p[:, 1], p[:, 2], ".-", label=label, ms=3)
    ax.legend(fontsize=8)
    ax.set_box_aspect((1, 1, 1))
    return ax


def plot_latent(z, labels=None, ax=None, title="PPCA latent space"):
    """The first two latent coordinates of frames (T, q), coloured by label."""
    ax = _axes(ax, figsize=(5, 4))
    z = np.asarray(z)
    if labels is None:
        ax.plot(z[:, 0], z[:, 1], ".", ms=3)
    else:
        labels = np.asarray(labels)
        for lab in dict.fromkeys(labels.tolist()):
            sel = labels == lab
            ax.plot(z[sel, 0], z[sel, 1], ".", ms=3, label=str(lab))
        ax.legend(fontsize=8)
    ax.set_xlabel("$z_1$")
    ax.set_ylabel("$z_2$")
    ax.set_title(title)
    return ax
