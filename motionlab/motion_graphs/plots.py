"""Pictures of motion graphs: the structure table, the graph, the distance matrix.

matplotlib (and networkx drawing) are imported inside the functions, so importing
:mod:`motionlab.motion_graphs` never needs a display. Every function returns the matplotlib
Axes (or the text) it drew.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import numpy as np

from motionlab.motion_graphs.graph import EDGE_KINDS, MotionGraph
from motionlab.motion_graphs.structured import structure_rows

__all__ = ["structure_table_text", "plot_structure_table", "plot_graph", "plot_distance", "plot_transition_counts"]

_COLUMNS = ("behaviour", "style", "takes", "start", "frames", "alive", "links")


def structure_table_text(graph: MotionGraph) -> str:
    """The structure table as aligned plain text (one row per behaviour/style)."""
    rows = structure_rows(graph)
    if not rows:
        return "(no structure table: a standard graph)"
    cells = [list(_COLUMNS)] + [[str(r[c]) for c in _COLUMNS] for r in rows]
    widths = [max(len(row[i]) for row in cells) for i in range(len(_COLUMNS))]
    lines = ["  ".join(v.ljust(w) for v, w in zip(row, widths)).rstrip() for row in cells]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def plot_structure_table(graph: MotionGraph, ax=None):
    """The structure table drawn with ``matplotlib.table``."""
    import matplotlib.pyplot as plt

    rows = structure_rows(graph)
    if ax is None:
        _, ax = plt.subplots(figsize=(12, 0.35 * (len(rows) + 2)))
    ax.axis("off")
    cols = [c for c in _COLUMNS if c != "links"]
    table = ax.table(cellText=[[str(r[c]) for c in cols] for r in rows], colLabels=cols, loc="center")
    table.auto_set_font_size(False)
    table.set_fontsize(8)
    return ax


def plot_graph(graph: MotionGraph, ax=None, by: str = "clip"):
    """The compressed graph (one node per run of frames between transition points).

    Nodes are coloured by clip and sized by frame count; transition edges are drawn, clip
    edges faintly. ``by="clip"`` lays clips out on a circle.
    """
    import matplotlib.pyplot as plt
    import networkx as nx

    g = graph.segment_graph()
    if ax is None:
        _, ax = plt.subplots(figsize=(8, 8))
    clips = sorted({d["clip"] for _, d in g.nodes(data=True)})
    angle = {c: 2 * np.pi * k / max(len(clips), 1) for k, c in enumerate(clips)}
    pos = {}
    for n, d in g.nodes(data=True):
        info = graph.clips[d["clip"]]
        frac = (d["first"] - info.start) / max(info.num_frames, 1)
        r = 1.0 + 0.6 * frac
        a = angle[d["clip"]] + 0.25 * frac
        pos[n] = (r * np.cos(a), r * np.sin(a))
    cmap = plt.get_cmap("tab20")
    colours = [cmap(clips.index(d["clip"]) % 20) for _, d in g.nodes(data=True)]
    sizes = [5 + 0.5 * d["frames"] for _, d in g.nodes(data=True)]
    clip_edges = [(u, v) for u, v, d in g.edges(data=True) if d.get("kind") == "clip"]
    jumps = [(u, v) for u, v, d in g.edges(data=True) if d.get("kind") in EDGE_KINDS]
    nx.draw_networkx_nodes(g, pos, ax=ax, node_size=sizes, node_color=colours)
    nx.draw_networkx_edges(g, pos, edgelist=clip_edges, ax=ax, alpha=0.3, arrows=False)
    nx.draw_networkx_edges(g, pos, edgelist=jumps, ax=ax, alpha=0.25, width=0.5, edge_color="crimson", arrowsize=4)
    for c in clips:
        a = angle[c]
        ax.text(1.9 * np.cos(a), 1.9 * np.sin(a), graph.clips[c].name, fontsize=7, ha="center")
    ax.set_title(f"{len(clips)} clips, {g.number_of_nodes()} segments, {len(jumps)} transitions")
    ax.set_aspect("equal")
    ax.axis("off")
    return ax


def plot_distance(matrix: np.ndarray, i=None, j=None, ax=None, title: str = "frame distance (RMS, m)"):
    """The distance matrix as an image (RMS metres) with chosen transitions ``(i, j)`` marked."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(6, 5))
    # nearest: one flat block per frame pair (no smoothing between cells; also a far smaller PNG)
    rms = np.sqrt(np.maximum(matrix, 0.0))
    im = ax.imshow(rms, origin="lower", cmap="viridis", aspect="auto", interpolation="nearest")
    plt.colorbar(im, ax=ax)
    if i is not None and len(i):
        ax.scatter(np.asarray(j), np.asarray(i), s=12, facecolors="none", edgecolors="red", label="transitions")
        ax.legend(loc="upper right", fontsize=8)
    ax.set_xlabel("frame of B")
    ax.set_ylabel("frame of A")
    ax.set_title(title)
    return ax


def plot_transition_counts(graph: MotionGraph, ax=None, title: str | None = None):
    """Transitions between clips as a matrix: row = clip left, column = clip entered.

    Counts the graph's live jump edges (frame-level, both ends alive) by the clips they join;
    the diagonal holds the jumps back into the same clip. A readable alternative to drawing
    every edge: which takes, styles and blends are joined, and how densely.
    """
    import matplotlib.pyplot as plt

    live = graph.alive[graph.src] & graph.alive[graph.dst]
    a, b = graph.clip_of(graph.src[live]), graph.clip_of(graph.dst[live])
    n = len(graph.clips)
    counts = np.zeros((n, n), dtype=int)
    np.add.at(counts, (a, b), 1)
    names = [c.name for c in graph.clips]
    if ax is None:
        _, ax = plt.subplots(figsize=(1.2 + 0.42 * n, 0.8 + 0.36 * n))
    shown = np.ma.masked_equal(counts, 0)
    im = ax.imshow(np.ma.log10(shown), cmap="Blues", vmin=-0.3, vmax=np.log10(max(counts.max(), 10)))
    for (r, c), v in np.ndenumerate(counts):
        if v:
            dark = np.log10(v) > 0.6 * np.log10(max(counts.max(), 10))
            ax.text(c, r, str(v), ha="center", va="center", fontsize=6.5, color="white" if dark else "black")
    ax.set_xticks(range(n), names, rotation=60, ha="right", fontsize=7)
    ax.set_yticks(range(n), names, fontsize=7)
    ax.set_xlabel("clip entered")
    ax.set_ylabel("clip left")
    ax.set_title(title or f"transitions between the {n} clips (empty: none)", fontsize=10)
    plt.colorbar(im, ax=ax, fraction=0.04, pad=0.02, label="log₁₀ transitions")
    return ax
