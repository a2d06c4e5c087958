r"""Links between style pools where their poses match: stance to stance, a gait's double support.

Paper B joins behaviours only through recorded transition clips, and styles of one behaviour
through interpolation spaces. A recording session often holds no transition clip between two
behaviours (a walk, then a wave), and an interpolation space between two standing actions may
find no valid path. Yet a standing action begins and ends at rest, and a walk stands on both
feet for a moment at every step (and at its start and stop): where two pools' poses match,
Kovar's own transitions (local minima of the frame distance below the *same* threshold as every
other transition) can join them.

Only a pool's *ports* take part (:attr:`.segments.Segments.ports`: an action's boundary
stances; a gait's start, stop and frames with both feet planted) — the frames where a change of
style or behaviour looks natural — so the comparison is small. Inside one pool the same ports
join its takes stance to stance (:func:`link_within`). For two pools ``A`` and ``B`` the port frames of both are compared
once; a candidate ``(i, j)`` gives the edge ``A_i → B_{j+1}`` and the edge ``B_j → A_{i+1}``,
each kept only when it leaves an alive frame or a take's *lead-out* and enters an alive frame
or a take's *lead-in* (:func:`leads`: a start or stop that the pruning inside the style
removed, because nothing of the style enters a start); the lead frames it uses are brought
back. Each direction becomes a structure-table link
``{"from", "to", "via": "stance", "routes"}`` whose routes have no frames of their own (``exit``
in ``A``'s pool, ``enter`` in ``B``'s, ``pieces: []``, ``frames: 0``), so the search
(:mod:`.search`) uses them like any other link.

Which pools are compared (:func:`pool_pairs`): every two styles of one standing action (a
gait's styles meet in their interpolation space, as the paper prescribes), and the styles of
one name in two behaviours (every two styles when the behaviours share no style name) that no
recorded transition clip joins in that direction (recorded clips stay preferred, as the paper
prescribes). A search then changes style inside a behaviour, and behaviour within one style.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from motionlab.motion_graphs import distance as _distance
from motionlab.motion_graphs.graph import MotionGraph

__all__ = ["pool_pairs", "port_features", "leads", "link_within", "link_pools", "PORT_TAKES"]

Key = tuple[str, str]

PORT_TAKES = 128
"""Most takes of a pool (evenly spaced in take order) whose ports are compared: two thirds of a
second of ports per action take at 30 fps is 20 frames, so two pools compare at most 2560 × 2560
frames, whatever the session's size."""


def pool_pairs(
    keys: Sequence[Key], recorded: set[tuple[str, str]], kinds: Mapping[Key, str | None] | None = None
) -> list[tuple[Key, Key, bool, bool]]:
    """Pools to compare, as ``(a, b, a_to_b, b_to_a)`` (which directions may be linked).

    Parameters
    ----------
    keys : ``(behaviour, style)`` of every pool
    recorded : ordered behaviour pairs ``(b1, b2)`` that a recorded transition clip joins
    kinds : ``"gait"`` or ``"action"`` of every pool (default: all actions); two styles of one
        behaviour are compared only when both are actions (a gait's styles meet in their
        interpolation space, as the paper prescribes)

    Returns
    -------
    list of tuples, in a fixed order (sorted keys); pairs with no direction left are omitted
    """
    styles: dict[str, set[str]] = {}
    for b, s in keys:
        styles.setdefault(b, set()).add(s)
    out = []
    kinds = kinds or {}
    for a, b in itertools.combinations(sorted(keys), 2):
        same = a[0] == b[0]
        if same and "gait" in (kinds.get(a), kinds.get(b)):
            continue
        if not same and a[1] != b[1] and styles[a[0]] & styles[b[0]]:
            continue  # two behaviours that share style names are joined style by style
        fwd = same or (a[0], b[0]) not in recorded
        bwd = same or (b[0], a[0]) not in recorded
        if fwd or bwd:
            out.append((a, b, fwd, bwd))
    return out


def port_features(
    graph: MotionGraph,
    takes: Sequence[int],
    ports: Mapping[int, np.ndarray],
    features: Callable,
    max_takes: int = PORT_TAKES,
) -> tuple[_distance.CloudFeatures | None, np.ndarray]:
    """Cloud features of the usable port frames of one pool's takes: alive, or on a take's
    lead-in or lead-out (:func:`leads`).

    Parameters
    ----------
    graph : the graph holding the takes
    takes : clip indices of the pool's takes (in take order)
    ports : clip index → (frames,) bool port mask of that take
    features : clip index → :class:`~.distance.CloudFeatures` of the whole take
    max_takes : at most this many takes, evenly spaced in take order, offer ports

    Returns
    -------
    features : CloudFeatures of the port frames (``None`` when there is none)
    frames : int array, global frame index of each row
    """
    if len(takes) > max_takes:
        takes = [takes[k] for k in np.linspace(0, len(takes) - 1, max_takes).round().astype(int)]
    lead_in, lead_out = leads(graph)
    usable = graph.alive | lead_in | lead_out
    rows, frames = [], []
    for c in takes:
        clip = graph.clips[c]
        f = np.flatnonzero(ports[c] & usable[clip.start : clip.stop])
        if f.size:
            rows.append(features(c)[f])
            frames.append(clip.start + f)
    if not rows:
        return None, np.zeros(0, dtype=np.int64)
    first = rows[0]
    cat = _distance.CloudFeatures(
        np.concatenate([r.centred for r in rows]),
        np.concatenate([r.height for r in rows]),
        first.weights,
        np.concatenate([r.self_term for r in rows]),
        np.concatenate([r.mean_xz for r in rows]),
        first.unit_weights,
    )
    return cat, np.concatenate(frames)


def leads(graph: MotionGraph) -> tuple[np.ndarray, np.ndarray]:
    """(N,) bool masks of every clip's *lead-in* (the removed frames before its first alive frame)
    and *lead-out* (the removed frames after its last alive frame); empty for a clip with no
    alive frame. A take's start or stop is often removed by the pruning inside its style (no
    transition of the style enters a start); a link from another pool may enter a lead-in and
    step forward into the alive frames, or leave from a lead-out after stepping out of them."""
    n = graph.num_frames
    basic = [c for c in graph.clips if c.kind == "basic" and c.num_frames > 0]
    start = np.array([c.start for c in basic], dtype=np.int64)
    stop = np.array([c.stop for c in basic], dtype=np.int64)
    alive_at = np.flatnonzero(graph.alive)
    if alive_at.size == 0 or not basic:
        return np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
    k0 = np.searchsorted(alive_at, start)  # first alive frame at or after each clip's start
    k1 = np.searchsorted(alive_at, stop) - 1  # last alive frame before each clip's stop
    some = k1 >= k0
    first = np.where(some, alive_at[np.minimum(k0, alive_at.size - 1)], start)
    last = np.where(some, alive_at[np.maximum(k1, 0)], stop - 1)
    partial = some & ((k1 - k0 + 1) < (stop - start))
    return _ranges(n, start[partial], first[partial]), _ranges(n, last[partial] + 1, stop[partial])


def _ranges(n: int, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(n,) bool, True on every ``lo[k] <= f < hi[k]`` (ranges that do not overlap)."""
    mark = np.zeros(n + 1, dtype=np.int64)
    np.add.at(mark, lo, 1)
    np.add.at(mark, hi, -1)
    return np.cumsum(mark[:n]) > 0


def _direction(graph: MotionGraph, lead: tuple, src: np.ndarray, dst: np.ndarray, cost: np.ndarray):
    """Edges ``src → dst + 1`` (same clip) that leave an alive or lead-out frame and enter an
    alive or lead-in frame (``lead``: :func:`leads`)."""
    lead_in, lead_out = lead
    nxt = np.minimum(dst + 1, graph.num_frames - 1)
    ok = (graph.clip_of(nxt) == graph.clip_of(dst)) & (dst + 1 < graph.num_frames)
    ok &= (graph.alive[src] | lead_out[src]) & (graph.alive[nxt] | lead_in[nxt])
    return src[ok], dst[ok] + 1, cost[ok]


def _revive(graph: MotionGraph, lead: tuple, src: np.ndarray, dst: np.ndarray) -> None:
    """Bring back the lead-in frames from each entry ``dst`` up to the clip's first alive frame,
    and the lead-out frames from the clip's last alive frame up to each exit ``src``."""
    lead_in, lead_out = lead
    for f in np.unique(dst[lead_in[dst]]):
        c = graph.clips[int(graph.clip_of(f))]
        first = c.start + int(np.argmax(graph.alive[c.start : c.stop] & ~lead_in[c.start : c.stop]))
        graph.alive[f:first] = True
    for f in np.unique(src[lead_out[src]]):
        c = graph.clips[int(graph.clip_of(f))]
        last = c.stop - 1 - int(np.argmax((graph.alive & ~lead_out)[c.start : c.stop][::-1]))
        graph.alive[last + 1 : f + 1] = True


def _routes(src, dst, cost, s0: int, t0: int) -> list[dict]:
    order = np.lexsort((dst, src, cost))  # best first; ties in a fixed order
    return [
        {"exit": int(src[k]) - s0, "enter": int(dst[k]) - t0, "pieces": [], "frames": 0, "cost": float(cost[k])}
        for k in order
    ]


def link_within(
    graph: MotionGraph, port: tuple, threshold: float, min_gap: int, window: int = _distance.DEFAULT_WINDOW
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Kovar transitions between the ports of one pool's takes: one take's end stance into
    another's start stance (and back inside one take, at least ``min_gap`` frames away).

    Parameters
    ----------
    graph : the graph holding the pool
    port : ``(CloudFeatures or None, global frames)`` from :func:`port_features`
    threshold : largest frame distance, m²
    min_gap : fewest frames between the two ends of a jump inside one take

    Returns
    -------
    src, dst, cost : global arrays of the edges ``i → j + 1``
    """
    fp, frames = port
    if fp is None:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0)
    i, j, cost = _distance.candidates(fp, None, threshold, window)
    gi, gj = frames[i], frames[j]
    ok = (graph.clip_of(gi) != graph.clip_of(gj)) | (np.abs(gi - gj) >= min_gap)
    none = np.zeros(graph.num_frames, dtype=bool)
    return _direction(graph, (none, none), gi[ok], gj[ok], cost[ok])


def link_pools(
    graph: MotionGraph,
    pairs: Sequence[tuple[Key, Key, bool, bool]],
    port_feats: Mapping[Key, tuple],
    pool_start: Callable[[Key], int],
    threshold: float,
    window: int = _distance.DEFAULT_WINDOW,
    workers: int = 1,
) -> tuple[list[dict], tuple[np.ndarray, np.ndarray, np.ndarray], int]:
    """Kovar transitions between the ports of pool pairs (see the module docstring).

    Parameters
    ----------
    graph : the graph (its ``alive`` frames decide which edges are kept)
    pairs : from :func:`pool_pairs`
    port_feats : key → ``(CloudFeatures or None, global frames)`` from :func:`port_features`
    pool_start : key → global index of the pool's first frame (routes count from it)
    threshold : largest frame distance, m² (the graph's transition threshold)
    window : frames per point cloud
    workers : threads comparing pool pairs at once (the answer does not depend on it)

    Returns
    -------
    links : structure-table links (``via: "stance"``), one per linked direction
    edges : ``(src, dst, cost)`` global arrays of every linked direction
    comparisons : cells of the distance matrices computed
    """
    links, parts, comparisons = [], [], 0
    lead = leads(graph)
    pairs = [p for p in pairs if port_feats[p[0]][0] is not None and port_feats[p[1]][0] is not None]

    def compare(pair):
        return _distance.candidates(port_feats[pair[0]][0], port_feats[pair[1]][0], threshold, window)

    if workers > 1:
        with ThreadPoolExecutor(workers) as pool:
            found = list(pool.map(compare, pairs))
    else:
        found = [compare(p) for p in pairs]
    for (a, b, fwd, bwd), (i, j, cost) in zip(pairs, found):
        (fa, ga), (fb, gb) = port_feats[a], port_feats[b]
        comparisons += len(fa) * len(fb)
        for ok, (x, y, sx, sy) in ((fwd, (ga[i], gb[j], a, b)), (bwd, (gb[j], ga[i], b, a))):
            if not ok:
                continue
            src, dst, c = _direction(graph, lead, x, y, cost)
            if src.size == 0:
                continue
            parts.append((src, dst, c))
            routes = _routes(src, dst, c, pool_start(sx), pool_start(sy))
            links.append({"from": list(sx), "to": list(sy), "via": "stance", "routes": routes})
    if parts:
        edges = tuple(np.concatenate(p) for p in zip(*parts))
        _revive(graph, lead, edges[0], edges[1])
    else:
        edges = (np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0))
    return links, edges, comparisons
