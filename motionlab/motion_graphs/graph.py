"""The motion graph: frames of clips joined by transitions; the standard (Kovar) construction.

Storage is flat NumPy, so a graph of 100,000 frames stays small and saves as arrays:

* every clip's frames are concatenated; frame ``f`` is *global*, ``clips[c].start`` is the
  global index of clip ``c``'s first frame;
* ``alive[f]`` says whether frame ``f`` is still in the graph (pruning removes frames);
* inside a clip, frame ``f`` is followed by ``f + 1`` when both are alive (the *clip edges*);
* a transition is an edge ``src → dst``: after playing ``src`` the motion continues at ``dst``.
  It comes from a pair of similar frames ``(i, j)`` (``D(i, j)`` small): playing ``i`` then
  continuing as if ``i`` were ``j`` means continuing at ``j + 1``, so ``src = i``,
  ``dst = j + 1``, and synthesis aligns frame ``dst - 1`` onto ``src``.

The **standard graph** (Kovar, Gleicher and Pighin 2002) compares every clip with every clip
(itself included), keeps the local minima of the frame distance below a threshold as
transitions, then prunes to the *largest strongly connected component* so that no walk gets
stuck. Components are computed on a compressed graph whose nodes are runs of frames between
transition points (networkx), not on single frames.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.motion_graphs import distance as _distance

if TYPE_CHECKING:
    import networkx as nx

__all__ = [
    "ClipInfo",
    "MotionGraph",
    "GraphError",
    "EDGE_KINDS",
    "build_standard",
    "check_motions",
]

EDGE_KINDS = ("transition", "loop", "bridge", "clip")
"""Edge kind codes: between clips, back into the same clip (self-loop), inside an
interpolation space, into/out of a recorded transition clip."""


class GraphError(ValueError):
    """An invalid graph operation or a path that does not follow the graph's edges."""


@dataclass
class ClipInfo:
    """One clip of a graph.

    ``kind``: ``"clip"`` (standard graph), ``"basic"``, ``"transition"`` or ``"intermediate"``.
    ``start``: global index of the first frame; ``num_frames``: frames stored (alive or not).
    ``synthetic``: True when the clip came from :mod:`motionlab.synthetic`, not mocap.
    """

    name: str
    kind: str = "clip"
    behaviour: str | None = None
    style: str | None = None
    to_behaviour: str | None = None
    to_style: str | None = None
    start: int = 0
    num_frames: int = 0
    synthetic: bool = False
    take: str | None = None

    @property
    def stop(self) -> int:
        return self.start + self.num_frames

    def to_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class MotionGraph:
    """Frames, alive mask and transition edges (see the module docstring).

    Attributes
    ----------
    skeleton : the 22-joint skeleton every clip uses
    fps : frames per second
    clips : list of ClipInfo
    local_rot : (N, J, 4), root_pos : (N, 3)   all frames, concatenated
    alive : (N,) bool
    src, dst : (E,) int   transition edges (global frames)
    cost : (E,) float     frame distance of the pair, m²
    kind : (E,) int8      index into :data:`EDGE_KINDS`
    table : dict          structure table (structured graphs), else empty
    info : dict           build statistics (times, counts, threshold …)
    """

    skeleton: Skeleton
    fps: float
    clips: list[ClipInfo]
    local_rot: np.ndarray
    root_pos: np.ndarray
    alive: np.ndarray
    src: np.ndarray
    dst: np.ndarray
    cost: np.ndarray
    kind: np.ndarray
    table: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_motions(cls, motions: Sequence[Motion], infos: Sequence[ClipInfo]) -> MotionGraph:
        """Frames of ``motions`` (checked by :func:`check_motions`) with no transitions yet."""
        skeleton, fps = check_motions(motions)
        clips, start = [], 0
        for m, info in zip(motions, infos):
            clips.append(replace(info, start=start, num_frames=m.num_frames))
            start += m.num_frames
        empty = np.zeros(0, dtype=np.int64)
        return cls(
            skeleton,
            fps,
            clips,
            np.concatenate([m.local_rot for m in motions]),
            np.concatenate([m.root_pos for m in motions]),
            np.ones(start, dtype=bool),
            empty,
            empty.copy(),
            np.zeros(0),
            np.zeros(0, dtype=np.int8),
        )

    def add_edges(self, src, dst, cost, kind: str) -> None:
        """Append transition edges (global frames)."""
        src, dst = np.asarray(src, dtype=np.int64), np.asarray(dst, dtype=np.int64)
        self.src = np.concatenate([self.src, src])
        self.dst = np.concatenate([self.dst, dst])
        self.cost = np.concatenate([self.cost, np.asarray(cost, dtype=np.float64)])
        self.kind = np.concatenate([self.kind, np.full(src.shape, EDGE_KINDS.index(kind), dtype=np.int8)])

    def keep_edges(self, mask: np.ndarray) -> None:
        """Drop the edges where ``mask`` is False."""
        self.src, self.dst, self.cost, self.kind = self.src[mask], self.dst[mask], self.cost[mask], self.kind[mask]

    def drop_dead_edges(self) -> None:
        """Drop edges that start or end at a removed frame."""
        self.keep_edges(self.alive[self.src] & self.alive[self.dst])

    # ------------------------------------------------------------------ queries
    @property
    def num_frames(self) -> int:
        """Frames stored (N), alive or not."""
        return int(self.alive.size)

    @property
    def num_alive(self) -> int:
        return int(self.alive.sum())

    @property
    def num_transitions(self) -> int:
        """Transition edges (self-loops included) between alive frames."""
        return int(np.sum(self.alive[self.src] & self.alive[self.dst]))

    def starts(self) -> np.ndarray:
        return np.array([c.start for c in self.clips], dtype=np.int64)

    def clip_of(self, frames) -> np.ndarray:
        """Clip index of global frames."""
        return np.searchsorted(self.starts(), np.asarray(frames), side="right") - 1

    def clip_index(self, name: str) -> int:
        """Index of the clip called ``name``.

        Raises
        ------
        GraphError when no clip has that name.
        """
        for i, c in enumerate(self.clips):
            if c.name == name:
                return i
        raise GraphError(f"no clip named {name!r} in the graph; clips: {[c.name for c in self.clips][:10]} …")

    def clip_motion(self, c: int, alive_only: bool = False) -> Motion:
        """Clip ``c`` as a Motion (all stored frames, or only the alive prefix)."""
        info = self.clips[c]
        stop = info.stop
        if alive_only:
            stop = info.start + self.alive_length(c)
        return Motion(
            self.skeleton,
            self.local_rot[info.start : stop].copy(),
            self.root_pos[info.start : stop].copy(),
            self.fps,
            None,
            info.name,
        )

    def alive_length(self, c: int) -> int:
        """Length of the alive run at the start of clip ``c`` (0 if its first frame is removed)."""
        info = self.clips[c]
        a = self.alive[info.start : info.stop]
        return int(np.argmin(a)) if not a.all() else info.num_frames

    def next_in_clip(self, alive: np.ndarray | None = None) -> np.ndarray:
        """(N,) bool: frame ``f`` is followed by ``f + 1`` (same clip, both alive).

        ``alive``: use this (N,) mask instead of the graph's own (for sub-graphs)."""
        alive = self.alive if alive is None else alive
        ok = np.zeros(self.num_frames, dtype=bool)
        ok[:-1] = alive[:-1] & alive[1:]
        last = np.array([c.stop - 1 for c in self.clips if c.num_frames > 0], dtype=np.int64)
        ok[last] = False
        return ok

    def out_degree(self) -> np.ndarray:
        """Number of alive successors of every frame (clip edge + transitions)."""
        live = self.alive[self.src] & self.alive[self.dst]
        deg = np.bincount(self.src[live], minlength=self.num_frames)
        return deg + self.next_in_clip()

    def dead_ends(self) -> np.ndarray:
        """Alive frames with no alive successor (global indices)."""
        return np.flatnonzero(self.alive & (self.out_degree() == 0))

    def has_edge(self, a: int, b: int) -> bool:
        """True when ``b`` may follow ``a`` (clip edge or transition)."""
        if not (0 <= a < self.num_frames and 0 <= b < self.num_frames and self.alive[a] and self.alive[b]):
            return False
        if b == a + 1 and self.next_in_clip()[a]:
            return True
        return bool(np.any((self.src == a) & (self.dst == b)))

    # ------------------------------------------------------------------ compressed graph
    def segments(self, alive: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Runs of alive frames between transition points.

        ``alive``: an (N,) mask of the frames taking part (default: the graph's alive frames);
        only edges between such frames count.

        Returns ``first`` and ``last`` global frame of each segment (S,) and ``seg`` (N,): the
        segment of every frame (-1 if removed).
        """
        alive = self.alive if alive is None else alive
        n = self.num_frames
        live = alive[self.src] & alive[self.dst]
        begin = np.zeros(n + 1, dtype=bool)
        begin[self.starts()] = True
        begin[1:n] |= ~alive[:-1]
        begin[self.dst[live]] = True
        begin[self.src[live] + 1] = True
        begin = begin[:n] & alive
        seg = np.cumsum(begin) - 1
        seg = np.where(alive, seg, -1)
        first = np.flatnonzero(begin)
        nxt = self.next_in_clip(alive)
        # a segment ends where the next frame begins another segment or does not follow
        end = alive & ~(nxt & np.concatenate([~begin[1:], [False]]))
        last = np.flatnonzero(end)
        return first, last, seg

    def segment_graph(self, alive: np.ndarray | None = None) -> nx.DiGraph:
        """The compressed graph: one node per segment (attributes clip, first, last, frames)."""
        import networkx as nx  # (imported here: a search or a load does not need it, and it takes a while)

        alive = self.alive if alive is None else alive
        first, last, seg = self.segments(alive)
        g = nx.DiGraph()
        clip = self.clip_of(first)
        for k in range(first.size):
            g.add_node(k, clip=int(clip[k]), first=int(first[k]), last=int(last[k]), frames=int(last[k] - first[k] + 1))
        nxt = self.next_in_clip(alive)
        follow = nxt[last]
        g.add_edges_from(zip(np.flatnonzero(follow).tolist(), seg[last[follow] + 1].tolist()), kind="clip")
        live = alive[self.src] & alive[self.dst]
        for s, d, k in zip(seg[self.src[live]].tolist(), seg[self.dst[live]].tolist(), self.kind[live].tolist()):
            g.add_edge(s, d, kind=EDGE_KINDS[k])
        return g

    def largest_component(self, mask: np.ndarray | None = None) -> np.ndarray:
        """(N,) bool: frames of the largest strongly connected component (by frame count).

        ``mask``: (N,) bool, look only at the sub-graph of these (alive) frames and the edges
        between them (e.g. one behaviour, or one style's takes).

        Forward-backward search on frames: the component of a seed frame is the set of frames
        it reaches and that reach it, two breadth-first searches vectorised over their
        frontiers. Seeds are drawn from the frames not yet placed until no remaining set can
        hold a larger component; a component of more than half the frames is found at the first
        seed it contains. Runs of a single frame with no edge back to themselves do not count.
        """
        alive = self.alive if mask is None else self.alive & mask
        live = alive[self.src] & alive[self.dst]
        step = np.flatnonzero(self.next_in_clip(alive))
        src = np.concatenate([step, self.src[live]])
        dst = np.concatenate([step + 1, self.dst[live]])
        n = self.num_frames
        fwd, bwd = _csr(src, dst, n), _csr(dst, src, n)
        remaining = alive.copy()
        best = np.zeros(n, dtype=bool)
        best_size = 0
        while int(remaining.sum()) > best_size:
            seed = int(np.argmax(remaining))
            start = np.zeros(n, dtype=bool)
            start[seed] = True
            comp = _reach(fwd, start, remaining) & _reach(bwd, start, remaining)
            size = int(comp.sum())
            if size == 1 and not np.any((src == seed) & (dst == seed)):
                size = 0  # a frame on no cycle
            if size > best_size:
                best, best_size = comp, size
            remaining &= ~comp
        return best

    def prune_to_largest_component(self) -> MotionGraph:
        """Kovar's pruning: keep only the largest strongly connected component (a new graph)."""
        out = self.copy()
        out.alive = self.largest_component()
        out.drop_dead_edges()
        return out

    def copy(self) -> MotionGraph:
        return replace(
            self,
            clips=[replace(c) for c in self.clips],
            alive=self.alive.copy(),
            src=self.src.copy(),
            dst=self.dst.copy(),
            cost=self.cost.copy(),
            kind=self.kind.copy(),
            table=dict(self.table),
            info=dict(self.info),
        )

    # ------------------------------------------------------------------ paths
    def check_path(self, pieces: Sequence[tuple[int, int, int]]) -> None:
        """Raise :class:`GraphError` unless ``pieces`` — ``(clip, first, last)`` frame runs, clip
        frame numbers, inclusive — is a walk along the graph's edges.

        Raises
        ------
        GraphError naming the first piece outside its clip, over removed frames, or with no
        edge from the piece before.
        """
        prev = None
        for n, (c, a, b) in enumerate(pieces):
            info = self.clips[c]
            if not (0 <= a <= b < info.num_frames):
                raise GraphError(f"piece {n}: frames {a}..{b} outside clip {info.name!r} ({info.num_frames} frames)")
            g0, g1 = info.start + a, info.start + b
            if not self.alive[g0 : g1 + 1].all():
                raise GraphError(f"piece {n}: clip {info.name!r} frames {a}..{b} include removed frames")
            if prev is not None and not self.has_edge(prev, g0):
                pc = int(self.clip_of(prev))
                raise GraphError(
                    f"piece {n}: no edge from {self.clips[pc].name!r} frame {prev - self.clips[pc].start} "
                    f"to {info.name!r} frame {a}"
                )
            prev = g1

    def summary(self) -> dict:
        """Counts for tables: clips (the recorded clips the graph was built from), intermediate
        clips (made by the build), frames, alive frames, transitions, largest component."""
        comp = self.largest_component()
        kinds = {
            k: int(np.sum((self.kind == i) & self.alive[self.src] & self.alive[self.dst]))
            for i, k in enumerate(EDGE_KINDS)
        }
        recorded = [c for c in self.clips if c.kind != "intermediate"]
        return dict(
            clips=int(self.info.get("input_clips", len(recorded))),
            intermediate_clips=len(self.clips) - len(recorded),
            frames=self.num_frames,
            alive=self.num_alive,
            transitions=self.num_transitions,
            by_kind=kinds,
            largest_scc=int(comp.sum()),
            dead_ends=int(self.dead_ends().size),
        )


def _csr(src: np.ndarray, dst: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Adjacency of directed edges as (indptr (n+1,), indices (E,)), sorted by source."""
    order = np.argsort(src, kind="stable")
    indptr = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(src, minlength=n), out=indptr[1:])
    return indptr, dst[order]


def _reach(adj: tuple[np.ndarray, np.ndarray], start: np.ndarray, allowed: np.ndarray) -> np.ndarray:
    """(N,) bool: frames reachable from ``start`` through ``allowed`` frames (breadth-first,
    one vectorised step per round)."""
    indptr, indices = adj
    seen = start & allowed
    frontier = np.flatnonzero(seen)
    while frontier.size:
        lo, hi = indptr[frontier], indptr[frontier + 1]
        counts = hi - lo
        total = int(counts.sum())
        if total == 0:
            break
        offs = np.repeat(lo - np.cumsum(counts) + counts, counts) + np.arange(total)
        nb = indices[offs]
        nb = np.unique(nb[allowed[nb] & ~seen[nb]])
        seen[nb] = True
        frontier = nb
    return seen


def check_motions(motions: Sequence[Motion]) -> tuple[Skeleton, float]:
    """All clips must share joint count and frame rate; returns the first skeleton and fps.

    Raises
    ------
    GraphError naming the clip when there is none, or clips differ in joint count, frame
    rate or bone offsets, or one has fewer than 3 frames.
    """
    if len(motions) == 0:
        raise GraphError("a motion graph needs at least one clip")
    first = motions[0]
    for m in motions:
        if m.skeleton.num_joints != first.skeleton.num_joints:
            raise GraphError(
                f"clip {m.name!r} has {m.skeleton.num_joints} joints, {first.name!r} has {first.skeleton.num_joints}; "
                "reduce every clip with preprocess.prepare(motion, fps) first"
            )
        if abs(m.fps - first.fps) > 1e-3 * first.fps:
            raise GraphError(
                f"clip {m.name!r} runs at {m.fps:g} fps, {first.name!r} at {first.fps:g}; resample them to one rate"
            )
        if m.num_frames < 3:
            raise GraphError(f"clip {m.name!r} has {m.num_frames} frames; a graph clip needs at least 3")
        bones = np.abs(m.skeleton.offsets[1:] - first.skeleton.offsets[1:]).max()
        if bones > 0.01:
            raise GraphError(
                f"clip {m.name!r} has other bone offsets than {first.name!r} (up to {bones:.3f} m apart): "
                "one graph holds clips of one character"
            )
    return first.skeleton, first.fps


def pair_edges(i, j, start_a: int, start_b: int, len_b: int, len_a: int, same: bool):
    """Edges from similar-frame pairs ``(i, j)`` of clips A, B: A_i → B_{j+1} and B_j → A_{i+1}.

    Returns global ``src, dst`` and the index of the pair each edge came from.
    """
    i, j = np.asarray(i), np.asarray(j)
    ok1 = j + 1 < len_b
    src = [start_a + i[ok1]]
    dst = [start_b + j[ok1] + 1]
    which = [np.flatnonzero(ok1)]
    if not same:
        ok2 = i + 1 < len_a
        src.append(start_b + j[ok2])
        dst.append(start_a + i[ok2] + 1)
        which.append(np.flatnonzero(ok2))
    return np.concatenate(src), np.concatenate(dst), np.concatenate(which)


def build_standard(
    motions: Sequence[Motion],
    threshold: float,
    window: int = _distance.DEFAULT_WINDOW,
    min_gap: int | None = None,
    prune: bool = True,
    infos: Sequence[ClipInfo] | None = None,
) -> MotionGraph:
    """Kovar's unstructured motion graph: every clip against every clip.

    Parameters
    ----------
    motions : canonical clips (same joint count and fps)
    threshold : largest frame distance of a transition, m² (:func:`distance.threshold_from`)
    window : frames per point cloud
    min_gap : within one clip, ignore pairs closer than this many frames (default: 1/3 s)
    prune : keep only the largest strongly connected component
    infos : optional ClipInfo per clip (labels); default: names only

    Returns
    -------
    MotionGraph with ``info["build_seconds"]``, ``info["comparisons"]`` (frame pairs compared).
    """
    t0 = time.perf_counter()
    infos = list(infos) if infos is not None else [ClipInfo(m.name or f"clip{k}") for k, m in enumerate(motions)]
    graph = MotionGraph.from_motions(motions, infos)
    min_gap = int(round(graph.fps / 3)) if min_gap is None else min_gap
    feats = [_distance.cloud_features(m.global_positions(), window) for m in motions]
    pairs = 0
    for a in range(len(motions)):
        for b in range(a, len(motions)):
            same = a == b
            i, j, c = _distance.candidates(
                feats[a], None if same else feats[b], threshold, window, min_gap=min_gap if same else 0
            )
            pairs += len(feats[a]) * len(feats[b])
            ca, cb = graph.clips[a], graph.clips[b]
            src, dst, which = pair_edges(i, j, ca.start, cb.start, cb.num_frames, ca.num_frames, same)
            graph.add_edges(src, dst, c[which], "loop" if same else "transition")
    graph.info.update(kind="standard", threshold=float(threshold), window=window, min_gap=min_gap, comparisons=pairs)
    graph.info["transitions_before_pruning"] = graph.num_transitions
    if prune:
        graph = graph.prune_to_largest_component()
    graph.info["build_seconds"] = time.perf_counter() - t0
    return graph
