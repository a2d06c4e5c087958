r"""Searching a motion graph for a requested sequence of behaviours.

A request is a list of segments ``(behaviour, style, frames)``: "300 frames of an angry walk,
then 200 frames of a normal run". The answer is a *path*: runs of frames
``(clip, first, last)`` joined by the graph's edges, and for every segment the number of
frames it got: the frames of its own style and of the recorded route out of it (an
interpolation space or a transition clip), so a transition counts towards the segment it
leaves. Frames spent in other styles on the way to the next segment (a style passed through
because no route joins the two directly) are counted apart (:attr:`SearchResult.passing`).

**Structured graph** (paper B). The structure table gives each segment's style pool (its
takes, side by side) and the recorded routes out of it, so the search never explores the whole
graph. Within a pool the walk from the entry frame ``e`` to an exit frame ``x`` steps along a
take or jumps (between takes, or back inside one); what each length costs is a recursion over
frame counts,

.. math:: P_{c+1}(f) = \min\bigl(P_c(f - 1),\ \min_{s \to f} P_c(s) + \mathrm{price}(s \to f)\bigr),
   \qquad P_0(e) = 0,

(``P_c(f)``: the least price of the jumps of a walk of ``c + 1`` frames from ``e`` that ends at
``f``; infinite where none does) run once per segment. A segment enters where the previous one's
route left it; the first enters at its pool's first alive frame, or where no walk from there
meets its count, at another alive frame (:data:`START_TRIES`). The exit whose route length ``r``
satisfies ``c + 1 + r = n`` wins; of the walks within :data:`TOLERANCE`, the one whose jumps
cost least plus one per frame off the request. The recursion runs first over the cheapest jumps
into each frame (:data:`SPARSE_JUMPS`), then, only where a walk through another jump could cost
less, over every jump, keeping only the walks that can still cost less: what the recursion
chooses is the cheapest over every jump. Long segments first take the shortest way to the pool's main cycle (its longest jump back inside
one take) and repeat it, so the recursion stays short: the *iterative choice of self-loop and
transition points*. Pools crossed on the way to the next segment are passed by the cheapest walk
to an exit, frames plus prices (:func:`walk_to_exit`); the **loop guard** stops it with an error once every frame
it can reach has been visited (paper B stops at the second pass of a clip's last self-loop
point; a pool of many takes has none). A request may ask for at most :data:`MAX_FRAMES` frames.

**Search cost** (the contract of the ``cost`` argument of :func:`search`, :class:`Planner`,
:func:`pool_walker` and :func:`search_standard`). A walk costs its frames plus a price for
every jump, in frames. The price is a function ``cost(graph, edges) -> (E,) float`` given the
graph and the indices ``edges`` of its jumps ``graph.src[edges] → graph.dst[edges]``; it may
read their pose distance ``graph.cost[edges]`` (m²), their ``graph.kind`` or the clips they join,
and returns one finite price >= 0 per edge (else ``ValueError``). The default,
:func:`default_cost`, prices every jump at :data:`JUMP_FRAMES` frames, since each jump is a
blend in the synthesised motion. The cost chooses among the walks of a segment (above) and the
walk through a pool to an exit (:func:`walk_to_exit`: least frames plus price); the way to a
pool's main cycle and the loop guard count frames only.

**No hidden state.** :func:`search` reads the graph afresh at every call; a :class:`Planner` keeps what it built
(each style's walker, the ways between styles) for many searches of one graph, and refuses a
graph that has changed since.

**Standard graph** (for comparison). Dijkstra's shortest path (in frames) on the compressed
graph from the current frame to any frame of the requested clip, then the same in-clip
recursion over the clip's self-loops. Its cost grows with the graph; the table lookup does not.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import re
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from motionlab.motion_graphs.graph import GraphError, MotionGraph

__all__ = [
    "Segment",
    "SearchResult",
    "parse_request",
    "search",
    "Planner",
    "default_cost",
    "JUMP_FRAMES",
    "search_standard",
    "SearchError",
    "RequestTooLong",
    "TOLERANCE",
    "tolerance_frames",
    "MAX_FRAMES",
    "START_TRIES",
    "PoolWalker",
    "pool_walker",
    "walk_to_exit",
]

MAX_FRAMES = 100_000
"""Longest request, frames in all segments together (55 minutes at 30 fps). The synthesised
motion is held in memory and written as one BVH file; longer requests are refused, naming this
limit, rather than running for minutes and filling the disk."""

START_TRIES = 32
"""A request's first segment walks from its pool's first alive frame (on the main cycle); where
that walk misses the segment's count by more than the tolerance, the walk is tried from up to
this many other alive frames of the pool, evenly spread, and the first that meets it is kept:
nothing fixes where a motion begins (:func:`_first_walk`)."""

TOLERANCE = 0.05
"""Documented accuracy: every reachable segment gets its requested length within
``max(2 frames, 5%)``; inside that band the walk through its pool whose jumps cost least plus one
per frame off the request wins, over every jump of the pool (with the default search cost, the
walk with the fewest jumps; checked against loops by hand in the tests). Each segment's walk is
the cheapest from where the previous one left off (a long segment first goes round its pool's
main cycle; the recursion chooses the rest); the request as a whole is not searched at once."""


def tolerance_frames(frames: int) -> int:
    """Frames a segment of ``frames`` requested frames may be off by: ``max(2, ⌊TOLERANCE·frames⌋)``."""
    return max(2, int(TOLERANCE * frames))


JUMP_FRAMES = 8
"""What a jump costs a walk through a pool in :func:`default_cost`, in frames: a pool of many
takes offers a jump almost everywhere, and the walk with the fewest frames can jump on every
frame; each jump is a blend (8 frames by default in :mod:`.synthesis`)."""


def default_cost(graph: MotionGraph, edges: np.ndarray) -> np.ndarray:
    """The default search cost: :data:`JUMP_FRAMES` frames for every jump, so a walk costs its
    frames plus ``JUMP_FRAMES`` per jump.

    A search cost is any function with this signature (see the module docstring).

    Parameters
    ----------
    graph : the graph searched
    edges : (E,) int   indices into ``graph.src``, ``graph.dst``, ``graph.cost``, ``graph.kind``

    Returns
    -------
    (E,) float   the price of each jump, frames (finite, >= 0)
    """
    return np.full(np.shape(edges), float(JUMP_FRAMES))


def _prices(graph: MotionGraph, edges: np.ndarray, cost) -> np.ndarray:
    """``cost(graph, edges)``, checked: one finite price >= 0 per edge, finite in float32 too (the
    search adds prices in float32; a larger one would read as a jump that cannot be taken)."""
    price = np.asarray(cost(graph, edges), dtype=np.float64)
    top = float(np.finfo(np.float32).max) / 1e6  # room for sums of many prices
    if price.shape != edges.shape or not np.all(np.isfinite(price)) or np.any(price < 0) or np.any(price > top):
        name = getattr(cost, "__name__", repr(cost))
        raise ValueError(
            f"search cost {name} must return one finite price >= 0 and at most {top:.3g} (frames) per edge, shape "
            f"{edges.shape}; got shape {price.shape}, min {price.min() if price.size else None}, "
            f"max {price.max() if price.size else None}"
        )
    return price.astype(np.float32)


class SearchError(GraphError):
    """A request the graph cannot satisfy; the message names what is missing."""


@dataclass(frozen=True)
class Segment:
    """One requested segment: behaviour, style and a frame count (> 0)."""

    behaviour: str
    style: str
    frames: int


@dataclass
class SearchResult:
    """A path and how well it meets the request.

    ``pieces``: list of ``(clip, first, last)`` (clip-local frames, inclusive); ``achieved``:
    frames given to each segment (its own style's frames and the recorded route out of it);
    ``requested``: the request's counts; ``passing``: frames after each segment spent in other
    styles on the way to the next one (empty: none), so that ``sum(achieved) + sum(passing)`` is
    the path's length; ``transitions``: index in the output of the first frame after each jump
    (for smoothness metrics).
    """

    pieces: list[tuple[int, int, int]]
    requested: list[int]
    achieved: list[int]
    segments: list[Segment] = field(default_factory=list)
    passing: list[int] = field(default_factory=list)

    @property
    def num_frames(self) -> int:
        return int(sum(b - a + 1 for _, a, b in self.pieces))

    def pieces_per_second(self, fps: float) -> float:
        """Pieces of the path (each after the first begins with a jump) per second at ``fps`` frames/s."""
        return len(self.pieces) * float(fps) / max(self.num_frames, 1)

    @property
    def errors(self) -> list[int]:
        return [a - r for a, r in zip(self.achieved, self.requested)]

    @property
    def misses(self) -> list[int]:
        """Indices of the segments whose frame count is off by more than :func:`tolerance_frames` allows (the
        graph has no walk of that length: the nearest was taken)."""
        return [k for k, (e, r) in enumerate(zip(self.errors, self.requested)) if abs(e) > tolerance_frames(r)]

    def transitions(self) -> list[int]:
        """Output frame index where each piece after the first begins."""
        out, t = [], 0
        for _, a, b in self.pieces[:-1]:
            t += b - a + 1
            out.append(t)
        return out

    def report(self) -> str:
        lines = []
        for k, (s, a) in enumerate(zip(self.segments, self.achieved)):
            off = f", outside the ±{tolerance_frames(s.frames)} allowed" if k in self.misses else ""
            lines.append(f"{s.behaviour}:{s.style}: requested {s.frames}, got {a} ({a - s.frames:+d}{off})")
            if k < len(self.passing) and self.passing[k]:
                lines.append(f"  then {self.passing[k]} frames through other styles on the way")
        return "\n".join(lines)


def parse_request(text: str) -> list[Segment]:
    """``"walk:angry:300,run:normal:200"`` → segments. Raises ValueError on bad syntax."""
    segs = []
    parts = [p.strip() for p in re.split(r"[,;]", text)]
    if len(parts) > 1 and not all(parts):
        raise ValueError(
            f"request segment {parts.index('') + 1} of {text!r} is empty; "
            "give segments like walk:angry:300,run:normal:200, one comma between two"
        )
    for part in [p for p in parts if p]:
        bits = part.split(":")
        if len(bits) != 3:
            raise ValueError(f"request segment {part!r} should be behaviour:style:frames, e.g. walk:angry:300")
        try:
            n = int(bits[2])
        except ValueError:
            raise ValueError(f"request segment {part!r}: frame count {bits[2]!r} is not a whole number") from None
        if n < 1:
            raise ValueError(f"request segment {part!r}: frame count must be positive")
        segs.append(Segment(bits[0].strip().lower(), bits[1].strip().lower(), n))
    if not segs:
        raise ValueError("empty request: give segments like walk:angry:300,run:normal:200")
    _check_total(segs)
    return segs


class RequestTooLong(ValueError):
    """A request for more than :data:`MAX_FRAMES` frames; ``total`` is what it asked for."""

    def __init__(self, message: str, total: int) -> None:
        super().__init__(message)
        self.total = total


def _check_total(segs: list[Segment]) -> None:
    total = sum(s.frames for s in segs)
    if total > MAX_FRAMES:
        raise RequestTooLong(
            f"the request asks for {total} frames in all; the limit is {MAX_FRAMES} frames "
            f"(search.MAX_FRAMES, {MAX_FRAMES / 30 / 60:.0f} minutes at 30 fps): split it into shorter requests",
            total,
        )


# ---------------------------------------------------------------------------- in-pool walks
@dataclass
class PoolWalker:
    """The walkable frames of one style's takes (a *pool*: a run of clips stored side by side).

    Frames are pool-local (``0 … length-1`` from the pool's first frame). ``step[f]``: f → f+1
    allowed (same take, both alive); jumps ``loop_src → loop_dst`` (transitions inside the pool,
    self-loops included); the *main cycle* ``cycle_dst … cycle_src`` is the longest jump back
    inside one take whose frames in between are all steps (``-1`` when there is none).
    ``price``: what each jump costs, frames on top of the frame it plays (``None``:
    :data:`JUMP_FRAMES` each, as :func:`default_cost`). ``sparse``: ``(src, dst, price)`` of the
    :data:`SPARSE_JUMPS` cheapest jumps into every frame (``None``: all jumps), which the search
    tries first (it must hold the cheapest jumps into each frame: the search's proof that no other
    jump gives a cheaper walk rests on it). A walker keeps what its searches derive from these arrays (its jumps by source
    and by destination): replace none of them once it has searched; make a new walker.
    """

    index: int
    length: int
    step: np.ndarray
    loop_src: np.ndarray
    loop_dst: np.ndarray
    last_src: int
    last_dst: int
    clips: np.ndarray = field(default_factory=lambda: np.zeros(1, dtype=np.int64))
    offsets: np.ndarray = field(default_factory=lambda: np.zeros(1, dtype=np.int64))
    alive: np.ndarray | None = None
    sparse: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    price: np.ndarray | None = None
    _out: tuple[np.ndarray, np.ndarray] | None = field(default=None, init=False, repr=False, compare=False)
    _prepared: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def jumps(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(src, dst, price)`` of every jump of the pool."""
        price = np.full(self.loop_src.shape, JUMP_FRAMES, np.float32) if self.price is None else self.price
        return self.loop_src, self.loop_dst, price

    def first_alive(self) -> int:
        """The first alive frame, preferring one on the main cycle."""
        if self.last_dst >= 0:
            return self.last_dst
        return int(np.argmax(self.alive)) if self.alive is not None else 0

    @property
    def cycle(self) -> int:
        return self.last_src - self.last_dst + 1

    def succ(self, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All (from, to) moves out of ``frames`` (steps and jumps): first the steps, in the
        order of ``frames``, then the jumps out of any of them, each once, in their order in
        ``loop_src``. Costs the moves found, not the pool's jumps."""
        frames = np.asarray(frames, dtype=np.int64)
        f = frames[self.step[frames]]
        order, head = self._by_source()
        if frames.size > 1 and not np.all(frames[1:] > frames[:-1]):
            frames = np.unique(frames)  # a frame given twice gives its jumps once
        jumps = order[_spans(head, frames)[0]]
        if jumps.size * 32 > order.size:  # in their stored order: a mark per jump beats a sort
            mark = np.zeros(order.size, dtype=bool)
            mark[jumps] = True
            jumps = np.flatnonzero(mark)
        else:
            jumps.sort()
        return np.concatenate([f, self.loop_src[jumps]]), np.concatenate([f + 1, self.loop_dst[jumps]])

    def _by_destination(self) -> tuple[np.ndarray, np.ndarray]:
        """``(order, head)``: the jumps ordered by destination frame (stable), those into frame
        ``f`` at ``order[head[f] : head[f + 1]]`` (made at the first call, then kept)."""
        if "by destination" not in self._prepared:
            order = np.argsort(self.loop_dst, kind="stable")
            head = np.zeros(self.length + 1, dtype=np.int64)
            np.cumsum(np.bincount(self.loop_dst, minlength=self.length), out=head[1:])
            self._prepared["by destination"] = (order, head)
        return self._prepared["by destination"]

    def _by_source(self) -> tuple[np.ndarray, np.ndarray]:
        """``(order, head)``: the jumps ordered by source frame, those out of frame ``f`` at
        ``order[head[f] : head[f + 1]]`` (made at the first call, then kept: the walker's jumps
        are not to be replaced)."""
        if self._out is None:
            order = np.argsort(self.loop_src, kind="stable")
            head = np.zeros(self.length + 1, dtype=np.int64)
            np.cumsum(np.bincount(self.loop_src, minlength=self.length), out=head[1:])
            self._out = (order, head)
        return self._out


def _pool_walker(graph: MotionGraph, clips: list[int], index: int = 0, cost=default_cost) -> PoolWalker:
    """Walker over the consecutive clips ``clips`` (one style's takes), its jumps priced by ``cost``."""
    first, last = graph.clips[clips[0]], graph.clips[clips[-1]]
    st, sp = first.start, last.stop
    step = graph.next_in_clip()[st:sp].copy()
    edges = _edges_within(graph, st, sp)
    src, dst = _take(graph.src, edges) - st, _take(graph.dst, edges) - st
    price = _prices(graph, edges, cost)
    # the main cycle: a jump back whose frames dst..src are all steps (one take, all alive)
    run = np.concatenate([[0], np.cumsum(step)])  # run[f] = steps among 0..f-1
    back = (dst <= src) & (run[src] - run[dst] == src - dst)
    if back.any():
        k = int(np.flatnonzero(back)[np.argmax((src - dst)[back])])
        last_src, last_dst = int(src[k]), int(dst[k])
    else:
        last_src, last_dst = -1, -1
    offsets = np.array([graph.clips[c].start - st for c in clips], dtype=np.int64)
    # the SPARSE_JUMPS cheapest jumps into every frame (ties: the nearer pose, then source)
    few = _cheapest_into(dst, (price, _take(graph.cost, edges), src), sp - st, SPARSE_JUMPS)
    return PoolWalker(
        index, sp - st, step, src, dst, last_src, last_dst, np.asarray(clips, dtype=np.int64), offsets,
        graph.alive[st:sp].copy(), (src[few], dst[few], price[few]), price,
    )  # fmt: skip


def _take(a: np.ndarray, index: np.ndarray) -> np.ndarray:
    """``a[index]``, read as a slice when ``index`` is a run of consecutive indices (a pool's
    edges usually are: a slice of a mapped file reads its pages in order)."""
    if index.size and index[-1] - index[0] + 1 == index.size:
        return np.asarray(a[index[0] : index[-1] + 1])
    return np.asarray(a[index])


def _cheapest_into(dst: np.ndarray, keys: tuple, length: int, k: int) -> np.ndarray:
    """Indices of the ``k`` least jumps into every frame, ordered by destination, then rank:
    what ``np.lexsort((*keys[::-1], dst))`` lists first for each destination.

    ``dst``: (E,) int in ``0 … length - 1``; ``keys``: (E,) arrays (no NaN), compared in turn,
    then the index. Each rank is found by keeping, key after key, the jumps that equal their
    destination's least value (one scatter per key, no sort of the E jumps).
    """
    index = np.arange(dst.size)
    keys = [key for key in keys if key.size and key.min() != key.max()]  # one value: no jump beats another
    left, picked = index, []
    for _ in range(k):
        cand, to = left, dst if left is index else dst[left]
        for key in (*keys, index):
            value = key if cand is index else key[cand]
            least = np.full(length, np.inf if key.dtype.kind == "f" else np.iinfo(key.dtype).max, dtype=key.dtype)
            np.minimum.at(least, to, value)
            keep = value == least[to]
            cand, to = cand[keep], to[keep]
        picked.append(cand)  # one jump per destination that has one left
        out = np.zeros(dst.size, dtype=bool)
        out[cand] = True
        left = np.flatnonzero(~out) if left is index else left[~out[left]]
    rank = np.concatenate([np.full(c.size, r) for r, c in enumerate(picked)])
    chosen = np.concatenate(picked)
    return chosen[np.lexsort((rank, dst[chosen]))]


def _edges_within(graph: MotionGraph, st: int, sp: int) -> np.ndarray:
    """Indices, ascending, of the edges between alive frames of ``st … sp - 1`` (global frames):
    one pass over the sources, then the few edges found are checked."""
    inside = (graph.src >= st) & (graph.src < sp)
    if not inside.any():
        return np.zeros(0, dtype=np.int64)
    a = int(inside.argmax())
    b = inside.size - int(inside[::-1].argmax())
    edges = np.arange(a, b) if inside[a:b].all() else a + np.flatnonzero(inside[a:b])  # often one run
    dst = _take(graph.dst, edges)
    edges, dst = edges[(dst >= st) & (dst < sp)], dst[(dst >= st) & (dst < sp)]
    return edges[graph.alive[_take(graph.src, edges)] & graph.alive[dst]]


def pool_walker(graph: MotionGraph, behaviour: str, style: str, cost=default_cost) -> PoolWalker:
    """The walker over one style's pool of a structured graph (its takes, from the structure
    table), its jumps priced by the search cost ``cost`` (:func:`default_cost`).

    Raises
    ------
    SearchError when the graph has no structure table or no such behaviour or style.
    """
    cells = graph.table.get("behaviours") if graph.table else None
    if not cells:
        raise SearchError("this graph has no structure table (a standard graph?)")
    if behaviour not in cells or style not in cells[behaviour]:
        raise SearchError(f"no style {behaviour}/{style} in the graph")
    return _pool_walker(graph, [t["clip"] for t in cells[behaviour][style]["takes"]], cost=cost)


def _clip_walker(graph: MotionGraph, c: int, cost=default_cost) -> PoolWalker:
    """Walker over one clip (the standard graph's search)."""
    return _pool_walker(graph, [c], c, cost)


def _distances(
    cw: PoolWalker, start: int, targets: np.ndarray | None = None, any_target: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Breadth-first search from ``start``: fewest moves to every frame (-1: unreachable) and
    the parent of each reached frame. Stops early once every frame of ``targets`` is reached
    (``any_target``: once any is; the nearest targets are then all reached, since a round
    reaches every frame at its distance, and the frames farther than them are left at -1).

    Vectorised over the frontier; the number of rounds is the depth of the search.
    """
    dist = np.full(cw.length, -1, dtype=np.int64)
    parent = np.full(cw.length, -1, dtype=np.int64)
    dist[start] = 0
    frontier = np.array([start], dtype=np.int64)
    d = 0
    while frontier.size:
        if targets is not None:
            hit = dist[targets] >= 0
            if hit.all() or (any_target and hit.any()):
                break
        a, b = cw.succ(frontier)
        new = dist[b] < 0
        a, b = a[new], b[new]
        b, first = _first_of_each(b, cw.length)
        d += 1
        dist[b] = d
        parent[b] = a[first]
        frontier = b
    return dist, parent


def _first_of_each(frames: np.ndarray, length: int) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(frames, return_index=True)`` for frames in ``0 … length - 1``: the distinct
    frames, ascending, and where each first occurs (one scatter, no sort)."""
    first = np.full(length, frames.size, dtype=np.int64)
    np.minimum.at(first, frames, np.arange(frames.size))
    seen = np.flatnonzero(first < frames.size)
    return seen, first[seen]


def _distinct(targets) -> tuple[np.ndarray, np.ndarray]:
    """The distinct frames of ``targets`` in the order they first occur, and where each first
    occurs: of tied targets, the first is the first of these."""
    frames, first = np.unique(np.asarray(targets, dtype=np.int64), return_index=True)
    order = np.argsort(first)
    return frames[order], first[order]


def _path(cw: PoolWalker, start: int, targets, name: str, distinct=None) -> tuple[list[int], int]:
    """Frames of a shortest walk from ``start`` to the nearest of ``targets`` (the ``r``-th, the
    first of the nearest). ``distinct``: ``_distinct(targets)``, when the caller keeps it.

    The *loop guard*: when the search has seen every frame reachable from ``start`` without
    meeting a target, it stops with an error instead of walking on for ever.
    """
    frames_of, first = _distinct(targets) if distinct is None else distinct
    dist, parent = _distances(cw, start, frames_of, any_target=True)
    d = np.where(dist[frames_of] >= 0, dist[frames_of], np.iinfo(np.int64).max)
    u = int(np.argmin(d))
    if dist[frames_of[u]] < 0:
        raise SearchError(
            f"loop guard: every frame of {name!r} reachable from frame {start} was visited "
            f"({int((dist >= 0).sum())} frames) without reaching the way on"
        )
    frames = [int(frames_of[u])]
    while frames[-1] != start:
        frames.append(int(parent[frames[-1]]))
    return frames[::-1], int(first[u])


def _runs(cw: PoolWalker | int, frames: list[int]) -> list[tuple[int, int, int]]:
    """Pool-local frames -> ``(clip, first, last)`` pieces in clip frames."""
    out = []
    a = prev = frames[0]
    for f in frames[1:]:
        if f != prev + 1:
            out.append((a, prev))
            a = f
        prev = f
    out.append((a, prev))
    if isinstance(cw, (int, np.integer)):
        return [(int(cw), x, y) for x, y in out]
    res = []
    for x, y in out:
        k = int(np.searchsorted(cw.offsets, x, side="right") - 1)
        res.append((int(cw.clips[k]), int(x - cw.offsets[k]), int(y - cw.offsets[k])))
    return res


_UNREACHED = np.float32(np.inf)
"""Entry of a walk table where no walk of that length ends (no price is that high)."""

SPARSE_JUMPS = 2
"""Jumps into each frame (the cheapest) that a walk through a pool tries first: a pool of many
takes holds dozens of jumps per frame, and the recursion's cost grows with them. A walk through
any other jump pays at least the least price of those jumps; where the walk found costs more,
every jump is tried, in tables that keep only the walks that can still cost less (so the walk
found is the cheapest through every jump; :data:`TOLERANCE`)."""

Jumps = tuple[np.ndarray, np.ndarray, np.ndarray]
"""``(src, dst, price)``: jumps between pool-local frames and what each costs, frames."""


class _Kept:
    """A walk table (see :func:`_reach`) that stores only its entries below ``inf``: ``frames[c]``
    (sorted) and ``values[c]``, row ``c``'s, for a table of ``n`` columns. Indexed as the dense
    table is where the search reads one: ``t[c]`` (a row), ``t[c, x]`` and ``t[rows, cols]``
    (arrays broadcast together; a slice of rows), ``t.shape``."""

    def __init__(self, frames: list[np.ndarray], values: list[np.ndarray], n: int) -> None:
        self.shape = (len(frames), n)
        count = [f.size for f in frames]
        self._head = np.concatenate([[0], np.cumsum(count)])  # row c at head[c] : head[c + 1]
        self._keys = np.repeat(np.arange(len(frames), dtype=np.int64), count) * n + np.concatenate(frames)
        self._values = np.concatenate(values).astype(np.float32)  # (keys sorted: by row, then frame)

    def __getitem__(self, key) -> np.ndarray:
        if not isinstance(key, tuple):  # one row, dense
            c, row = int(key), np.full(self.shape[1], _UNREACHED)
            at = slice(self._head[c], self._head[c + 1])
            row[self._keys[at] - c * self.shape[1]] = self._values[at]
            return row
        rows, cols = key
        if isinstance(rows, (int, np.integer)) and isinstance(cols, (int, np.integer)):  # one entry
            want = int(rows) * self.shape[1] + int(cols)
            at = min(int(self._keys.searchsorted(want)), self._keys.size - 1)
            return self._values[at] if self._keys[at] == want else _UNREACHED
        if isinstance(rows, slice):
            rows = np.arange(self.shape[0])[rows][:, None]
        rows, cols = np.broadcast_arrays(np.asarray(rows, dtype=np.int64), np.asarray(cols, dtype=np.int64))
        want = rows * self.shape[1] + cols
        at = np.minimum(np.searchsorted(self._keys, want), self._keys.size - 1)  # (row 0 is never empty)
        out = np.where(self._keys[at] == want, self._values[at], _UNREACHED)
        return out[()] if out.ndim == 0 else out


Table = np.ndarray | _Kept
"""A walk table: (rows, n) entries, dense (:func:`_reach`) or only those kept (:func:`_reach_below`)."""


def _reach(cw: PoolWalker, start: int, steps: int, jumps: Jumps | None = None) -> np.ndarray:
    """(steps, L) float32: the least price of the jumps of a walk of ``c + 1`` frames from
    ``start`` that ends at each frame (``inf`` where no walk of that length ends there).

    The reachability recursion with a price: ``P[c+1, f+1] = P[c, f]`` for a step,
    ``P[c+1, d] = min over jumps s → d of P[c, s] + price(s → d)``; the jump part is one
    ``np.minimum.reduceat`` over the jumps sorted by destination, so each row is vectorised.
    ``jumps``: the jumps to use (default: all the walker's).
    """
    step_ok = cw.step[:-1]
    prep = _prepare(cw, jumps)
    if prep[0] == "few":
        return _reach_few(max(steps, 1), cw.length, start, step_ok, prep[1], prep[2])
    _, src, price, heads, targets = prep
    out = np.full((max(steps, 1), cw.length), _UNREACHED, dtype=np.float32)
    out[0, start] = 0
    for c in range(1, steps):
        prev, cur = out[c - 1], out[c]
        cur[1:] = np.where(step_ok, prev[:-1], _UNREACHED)
        if src.size:
            via = np.minimum.reduceat(prev[src] + price, heads)
            cur[targets] = np.minimum(cur[targets], via)
    return out


def _prepare(cw: PoolWalker, jumps: Jumps | None) -> tuple:
    """What a row of :func:`_reach` gathers for ``jumps``: ``("few", src_of, price_of)``, the
    k-th jump into each frame (source ``n``, never reached, where there is none) when at most
    :data:`SPARSE_JUMPS` enter any frame, else ``("grouped", src, price, heads, targets)``, the
    jumps by destination. Kept in the walker for its own jump sets (all, or ``cw.sparse``)."""
    key = "all" if jumps is None else "sparse" if jumps is cw.sparse else None
    if key in cw._prepared:
        return cw._prepared[key]
    src, dst, price = cw.jumps() if jumps is None else jumps
    order = cw._by_destination()[0] if jumps is None else np.argsort(dst, kind="stable")
    src, dst, price = src[order], dst[order], price[order]
    rank = np.arange(dst.size) - np.searchsorted(dst, dst)  # k-th jump into its frame
    n = cw.length
    if rank.size == 0 or rank.max() < SPARSE_JUMPS:
        src_of, price_of = [], []
        for k in range(SPARSE_JUMPS):
            s = np.full(n, n)
            s[dst[rank == k]] = src[rank == k]
            p = np.zeros(n, dtype=np.float32)
            p[dst[rank == k]] = price[rank == k]
            src_of.append(s)
            price_of.append(p)
        prep = ("few", src_of, price_of)
    else:
        heads = np.flatnonzero(np.concatenate([[True], dst[1:] != dst[:-1]]))
        prep = ("grouped", src, price, heads, dst[heads])
    if key is not None:
        cw._prepared[key] = prep
    return prep


def _reach_few(steps: int, n: int, start: int, step_ok: np.ndarray, src_of: list, price_of: list) -> np.ndarray:
    """:func:`_reach` when few jumps enter each frame: ``src_of[k]``, ``price_of[k]``: the k-th
    jump into each frame (at most one per frame; source ``n`` where there is none), so a row is
    one gather per layer, with no grouping.

    Returns a (steps, n) view of an array with one more column, always ``inf``: the frame a
    missing jump comes from."""
    out = np.full((steps, n + 1), _UNREACHED, dtype=np.float32)
    out[0, start] = 0
    via, other = np.empty(n, dtype=np.float32), np.empty(n, dtype=np.float32)
    for c in range(1, steps):
        prev, cur = out[c - 1], out[c]
        np.copyto(cur[1:n], prev[: n - 1], where=step_ok)  # the row starts all inf
        np.add(np.take(prev, src_of[0]), price_of[0], out=via)
        for s, p in zip(src_of[1:], price_of[1:]):
            np.minimum(via, np.add(np.take(prev, s), p, out=other), out=via)
        np.minimum(cur[:n], via, out=cur[:n])
    return out[:, :n]


def _backtrack(cw: PoolWalker, reach: Table, c: int, x: int, jumps: Jumps | None = None) -> list[int]:
    """Frames of the cheapest walk reaching ``x`` after ``c + 1`` frames (reverse-engineered
    from ``reach``, see :func:`_reach`, made with the same ``jumps``)."""
    src, dst, price = cw.jumps() if jumps is None else jumps
    if jumps is None:
        order, head = cw._by_destination()
    else:
        order = np.argsort(dst, kind="stable")
        head = np.searchsorted(dst[order], np.arange(cw.length + 1))
    frames = [x]
    while c > 0:
        p = reach[c, x]
        if x > 0 and cw.step[x - 1] and reach[c - 1, x - 1] == p:
            x -= 1
        else:
            into = order[head[x] : head[x + 1]]  # the jumps into x, in their order
            cand = src[into][reach[c - 1, src[into]] + price[into] == p]
            if cand.size == 0:
                raise GraphError("internal: walk reconstruction failed")
            x = int(cand[0])
        frames.append(x)
        c -= 1
    return frames[::-1]


def _deltas(n: int):
    """0, +1, -1, +2, -2, … (longer before shorter at equal distance)."""
    yield 0
    for d in range(1, n):
        yield d
        yield -d


def _walk(
    cw: PoolWalker, start: int, need: list[int], exits: list[int], name: str = "clip", slack: int = 0
) -> tuple[list[tuple[int, int, int]], int, int]:
    """A walk from ``start`` of about ``need[r]`` frames ending at ``exits[r]`` (``-1``: any frame).

    Of the walks within ``slack`` frames of an option's length, the cheapest wins: the price of
    its jumps (the walker's search cost) plus one per frame off the request; when there is none,
    the walk nearest the requested length.
    Returns pieces, the chosen option ``r`` and the frames played.
    """
    pieces: list[tuple[int, int, int]] = []
    played = 0
    ex = np.array(exits)
    lo = min(need)
    if cw.last_src >= 0 and lo > 2 * (3 * cw.cycle + 2):  # (the budget below is at least this)
        fixed = ex[ex >= 0]
        dist, _ = _distances(cw, cw.last_dst, fixed if fixed.size else None)
        far = int(dist[fixed].max()) if fixed.size and (dist[fixed] >= 0).all() else 0
        budget = far + 3 * cw.cycle + 2
        if lo > 2 * budget:
            # long segment: the shortest way to the main cycle, then whole cycles
            frames, _ = _path(cw, start, [cw.last_src], name)
            pieces.extend(_runs(cw, frames))
            played += len(frames)
            reps = max(0, (lo - played - budget) // cw.cycle)
            pieces.extend(_runs(cw, list(range(cw.last_dst, cw.last_src + 1))) * reps)
            played += reps * cw.cycle
            start = cw.last_dst
    if len(need) == 1 and ex[0] < 0 and _straight(cw, start, need[0] - played):
        # a walk along the take with no jump at all: nothing costs less
        pieces.extend(_runs(cw, list(range(start, start + need[0] - played))))
        return pieces, 0, need[0]
    steps = max(n - played for n in need) + max(cw.cycle, 2)
    steps = max(steps, 2)
    need_c = np.array(need) - played - 1
    # first the cheapest jumps into each frame and just the rows the tolerance needs (a pool of
    # many takes holds dozens of jumps per frame, and the recursion's cost grows with them); a
    # walk through any other jump pays at least the least price of those jumps, so when the
    # walk found costs no more, it is the cheapest of all; else every jump, and when no walk
    # lies within the tolerance, the full width
    short = min(steps, int(need_c.max()) + slack + 2)
    jumps, reach = cw.sparse, _reach(cw, start, short, cw.sparse)
    best = _choose(reach, need_c, ex, short, slack, slack)
    if best is None:
        jumps, reach = None, _reach(cw, start, steps)
        best = _choose(reach, need_c, ex, steps, steps, slack)
    elif jumps is not None and best[3] > _least_beyond(cw):
        cheaper = _cheaper_walk(cw, start, short, need_c, ex, slack, best[3])
        if cheaper is not None:
            jumps, (reach, best) = None, cheaper
    if best is None:
        raise SearchError(f"{name}: no walk from frame {start} reaches any exit")
    r, c, x = best[:3]
    frames = _backtrack(cw, reach, c, x, jumps)
    pieces.extend(_runs(cw, frames))
    return pieces, r, played + c + 1


def _first_walk(cw: PoolWalker, start: int, need: list[int], exits: list[int], name: str, slack: int):
    """:func:`_walk` from ``start``, or where it misses its option's count by more than ``slack``,
    from the first of :data:`START_TRIES` other alive frames of the pool whose walk meets it (the
    one from ``start`` where none does)."""
    walk = _walk(cw, start, need, exits, name, slack)
    if abs(walk[2] - need[walk[1]]) <= slack:
        return walk
    alive = np.flatnonzero(cw.alive) if cw.alive is not None else np.arange(cw.length)
    for other in alive[np.unique(np.linspace(0, alive.size - 1, min(START_TRIES, alive.size)).astype(np.int64))]:
        try:
            tried = _walk(cw, int(other), need, exits, name, slack)
        except SearchError:  # no exit from there
            continue
        if abs(tried[2] - need[tried[1]]) <= slack:
            return tried
    return walk


def _cheaper_walk(cw: PoolWalker, start: int, rows: int, need_c: np.ndarray, ex: np.ndarray, slack: int, bound: float):
    """``(reach, choice)``: :func:`_choose`'s walk over every jump when it costs less than
    ``bound``, else ``None``. The tables (:func:`_reach_below`) are made for bounds doubling from
    twice the least price of a jump up to ``bound``: a walk cheaper than the table's bound costs
    no more than the walks it keeps, so the first table holding one holds the cheapest."""
    first_row = max(int(need_c.min()) - slack, 0)
    least = float(cw.jumps()[2].min())
    below = min(2 * least, bound) if least > 0 else bound
    while True:
        reach = _reach_below(cw, start, rows, below, first_row, ends=ex if (ex >= 0).all() else None)
        found = _choose(reach, need_c, ex, rows, slack, slack)
        if found is not None and found[3] < below:
            return reach, found
        if below >= bound:
            return None
        reach, below = None, min(2 * below, bound)  # (the table freed before the next is made)


def _reach_below(
    cw: PoolWalker,
    start: int,
    rows: int,
    bound: float,
    first_row: int = 0,
    exits: np.ndarray | None = None,
    ends: np.ndarray | None = None,
) -> _Kept:
    """:func:`_reach` over every jump, kept to the walks that can still cost less than ``bound``:
    a walk of ``c + 1`` frames ending at ``f`` is left out (``inf``) when its cost plus the
    least it must still pay is ``bound`` or more. The cost: the price of its jumps, and, with
    ``exits`` (a walk to one of them), one per frame. What it must still pay: the least price of
    a jump for each jump it must still make, the more of two counts: the jumps it needs to last
    until row ``first_row``, when after ``f``'s own run of steps each jump is followed by at most
    the pool's longest run, and the fewest jumps from ``f`` to one of ``exits`` or ``ends`` (the
    frames a segment's walk must end at; ``None``: any frame); with ``exits``, also one per move
    of the fewest moves from ``f`` to an exit. The entries of the walks kept equal
    :func:`_reach`'s; jumps are gathered from the frames kept, and only the entries kept are
    stored (:class:`_Kept`), so a tight bound makes the table small and its rows cheap."""
    src, dst, price = cw.jumps()
    order, head = cw._by_source()
    n, run = cw.length, _runs_of_steps(cw)
    longest, least = int(run.max()) + 1, float(price.min()) if price.size else 0.0
    per_frame, rest = (0.0, np.zeros(n)) if exits is None else (1.0, _moves_to(cw, exits))
    to_end = exits if exits is not None else ends
    hops = np.zeros(n) if to_end is None else _jumps_to(cw, to_end)

    to_pay = least * hops if least > 0 else np.where(np.isinf(hops), np.inf, 0.0)  # (inf: no end reached)
    settled = rest + to_pay  # what a walk pays from each frame on, its length aside

    def must(f: np.ndarray, c: int) -> np.ndarray:  # what a walk at f after c + 1 frames must still pay
        if c >= first_row:
            return settled[f]
        length = np.ceil(np.maximum(first_row - c - run[f], 0) / longest)
        return rest[f] + np.maximum(to_pay[f], least * length)

    prep = _prepare(cw, None)  # all jumps by destination, when more than a few enter a frame
    grouped = prep[1:] if prep[0] == "grouped" else None
    prev, cur = np.full(n, _UNREACHED), np.full(n, _UNREACHED)  # two rows in turn, inf but for the kept
    cur[start] = 0
    frames, values = [np.array([start])], [cur[[start]]]
    step_out = np.append(cw.step[:-1], False)  # a step leaves the frame
    for c in range(1, rows):
        prev, cur = cur, prev
        if c >= 2:
            cur[frames[c - 2]] = _UNREACHED
        limit = bound - per_frame * (c + 1)  # what the price of a walk of c + 1 frames must stay below
        a = frames[-1]
        stepped = a[step_out[a]]
        # a jump is one move, and one of the jumps still to make, nearer at most
        a = a[prev[a] + (rest[a] - per_frame) + np.maximum(to_pay[a], least) < limit]
        if grouped is not None and 4 * int((head[a + 1] - head[a]).sum()) > src.size:  # most jumps: all
            to, value = grouped[3], np.minimum.reduceat(prev[grouped[0]] + grouped[1], grouped[2])
        elif a.size:
            at = order[_spans(head, a)[0]]
            to, value = dst[at], prev[src[at]] + price[at]
        else:
            to, value = a, prev[a]  # (none)
        to, value = np.concatenate([stepped + 1, to]), np.concatenate([prev[stepped], value])
        keep = value + must(to, c) < limit  # (a step can take a walk past its exits)
        to, value = to[keep], value[keep]
        np.minimum.at(cur, to, value)
        frames.append(np.unique(to) if to.size * 256 < n else np.flatnonzero(cur < _UNREACHED))  # few: sorted
        values.append(cur[frames[-1]])
    return _Kept(frames, values, n)


def _spans(head: np.ndarray, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(at, count)``: the positions ``head[f] … head[f + 1] - 1`` of each of ``frames`` in turn
    (the jumps out of, or into, each frame of an ordering such as :meth:`PoolWalker._by_source`),
    and how many each frame has."""
    first, count = head[frames], head[frames + 1] - head[frames]
    return np.repeat(first - np.cumsum(count) + count, count) + np.arange(int(count.sum())), count


def _runs_of_steps(cw: PoolWalker) -> np.ndarray:
    """(n,) int: the steps a walk can take from each frame on without a jump (kept in the walker)."""
    if "runs of steps" not in cw._prepared:
        n = cw.length
        at_end = np.where(cw.step, n, np.arange(n))
        cw._prepared["runs of steps"] = np.minimum.accumulate(at_end[::-1])[::-1] - np.arange(n)
    return cw._prepared["runs of steps"]


def _moves_to(cw: PoolWalker, exits: np.ndarray) -> np.ndarray:
    """(n,) float: the fewest moves (steps and jumps) from each frame to one of ``exits``
    (``inf`` where none leads): a breadth-first search backwards (kept in the walker)."""
    frontier = np.unique(np.asarray(exits, dtype=np.int64))
    key = ("moves to", frontier.tobytes())
    if key in cw._prepared:
        return cw._prepared[key]
    order, head = cw._by_destination()
    moves = cw._prepared[key] = np.full(cw.length, np.inf)
    moves[frontier] = 0
    while frontier.size:
        g = frontier[frontier > 0]
        f = np.concatenate([g[cw.step[g - 1]] - 1, cw.loop_src[order[_spans(head, frontier)[0]]]])
        f = np.unique(f[np.isinf(moves[f])])
        moves[f] = moves[frontier[0]] + 1
        frontier = f
    return moves


def _jumps_to(cw: PoolWalker, ends: np.ndarray) -> np.ndarray:
    """(n,) float: the fewest jumps a walk makes from each frame to one of ``ends``, steps free
    (``inf`` where none leads): a breadth-first search backwards, one jump per level, each level
    closed under steps backwards (kept in the walker)."""
    reached = np.unique(np.asarray(ends, dtype=np.int64))
    key = ("jumps to", reached.tobytes())
    if key not in cw._prepared:
        n = cw.length
        run_of = np.concatenate([[0], np.cumsum(~cw.step[:-1])])  # frames joined by steps share a run
        order, head = cw._by_destination()
        hops = cw._prepared[key] = np.full(n, np.inf)
        level = 0
        while reached.size:
            last = np.full(int(run_of[-1]) + 1, -1)
            np.maximum.at(last, run_of[reached], reached)  # in each run, the last frame reached
            new = np.flatnonzero((np.arange(n) <= last[run_of]) & np.isinf(hops))  # steps lead there
            hops[new] = level
            source = np.zeros(n, dtype=bool)
            source[cw.loop_src[order[_spans(head, new)[0]]]] = True  # of the jumps into them
            reached, level = np.flatnonzero(source & np.isinf(hops)), level + 1
    return cw._prepared[key]


def _least_beyond(cw: PoolWalker) -> float:
    """The least price of the walker's jumps that ``cw.sparse`` leaves out (``inf``: none), given
    that ``cw.sparse`` holds the cheapest jumps into each frame: the price that follows them in
    each frame's jumps, sorted by price. Kept in the walker."""
    if "beyond" not in cw._prepared:
        src, dst, price = cw.jumps()
        kept = np.bincount(cw.sparse[1], minlength=cw.length) if cw.sparse is not None else np.zeros(cw.length, int)
        if price.size and price.min() == price.max():  # one price: any jump left out costs it
            left = np.bincount(dst, minlength=cw.length) > kept
            cw._prepared["beyond"] = float(price[0]) if left.any() else np.inf
        else:
            o = np.lexsort((price, dst))
            rank = np.arange(dst.size) - np.searchsorted(dst[o], dst[o])  # position among the jumps into dst
            left = rank >= kept[dst[o]]
            cw._prepared["beyond"] = float(price[o][left].min()) if left.any() else np.inf
    return cw._prepared["beyond"]


def _straight(cw: PoolWalker, start: int, frames: int) -> bool:
    """True when ``frames`` frames from ``start`` follow one another inside one take."""
    return frames >= 1 and start + frames <= cw.length and bool(cw.step[start : start + frames - 1].all())


def _choose(reach: Table, need_c: np.ndarray, ex: np.ndarray, steps: int, widest: int, slack: int = 0):
    """``(option, row, exit frame, key)``: of the walks within ``slack`` rows of an option's
    requested row, the cheapest, at the price of its jumps plus one per frame off the request
    (``key``; the nearer length on ties); when there is none, the walk nearest the requested
    length (``None``: none within ``widest`` rows of it)."""
    best, best_key = None, None
    for order, delta in enumerate(_deltas(widest + 1)):
        if best is not None and (abs(delta) > slack or abs(delta) >= best_key[0]):
            break
        found = _cheapest(reach, need_c + delta, ex, steps)
        if found is None:
            continue
        key = (found[3] + abs(delta), order)
        if best is None or key < best_key:
            best, best_key = (*found[:3], key[0]), key
    return best


def _cheapest(reach: Table, c: np.ndarray, ex: np.ndarray, steps: int):
    """``(option, row, frame, price)`` of the walk whose jumps cost least, ending in row ``c[r]``
    at option ``r``'s exit frame (or, ``-1``, at any frame); ``None`` when there is none."""
    ok = np.flatnonzero((c >= 0) & (c < steps))
    found = None
    for r in ok[ex[ok] < 0]:
        row = reach[c[r]]
        p = float(row.min())
        if p < _UNREACHED and (found is None or p < found[3]):
            found = (int(r), int(c[r]), int(np.argmin(row)), p)
    fixed = ok[ex[ok] >= 0]
    if fixed.size:
        prices = reach[c[fixed], ex[fixed]]
        k = int(np.argmin(prices))
        if prices[k] < _UNREACHED and (found is None or float(prices[k]) < found[3]):
            found = (int(fixed[k]), int(c[fixed[k]]), int(ex[fixed[k]]), float(prices[k]))
    return found


def walk_to_exit(
    cw: PoolWalker, start: int, exits: list[int], name: str = "pool"
) -> tuple[list[tuple[int, int, int]], int, int]:
    """The cheapest walk through a pool from ``start`` to one of ``exits`` (pool-local frames).

    Cost: frames plus the price of its jumps (the walker's search cost), over every jump of the
    pool; of equally cheap walks the shortest, then the first exit. The shortest walk (a
    breadth-first search) when none is cheaper.

    Returns
    -------
    pieces : list of ``(clip, first, last)``; r : index of the exit reached; frames : frames played

    Raises
    ------
    SearchError (the *loop guard*) when every frame reachable from ``start`` has been visited
    without meeting an exit. Paper B stops a search at the second pass of a clip's last
    self-loop point instead; a pool of many takes has no single last self-loop point.
    ValueError when ``start`` or an exit lies outside the pool, or ``exits`` is empty.
    """
    ex = np.asarray(exits, dtype=np.int64).reshape(-1)
    _check_exits(cw, start, ex)
    return _walk_to_exit(cw, start, _distinct(ex), name)


def _check_exits(cw: PoolWalker, start: int, ex: np.ndarray) -> None:
    if not ex.size or not (0 <= int(start) < cw.length and np.all((ex >= 0) & (ex < cw.length))):
        raise ValueError(f"expected a start and at least one exit in 0..{cw.length - 1}, got {start} and {ex.tolist()}")


def _walk_to_exit(
    cw: PoolWalker, start: int, distinct: tuple, name: str
) -> tuple[list[tuple[int, int, int]], int, int]:
    """:func:`walk_to_exit` to the exits ``distinct = _distinct(exits)`` (checked)."""
    frames, r = _path(cw, start, None, name, distinct)
    bound = len(frames) + _paid(cw, frames)  # what the shortest walk costs
    # a cheaper walk has fewer frames than ``bound`` (each frame costs one) and visits no frame
    # twice (a loop costs at least a frame), so it has at most ``cw.length`` frames. First the
    # cheapest jumps into each frame: a walk through another jump costs at least two frames and
    # that jump's price, so only when the walk found costs as much is every jump tried
    jumps, found = None, bound
    if cw.sparse is not None:
        jumps, reach = cw.sparse, _reach(cw, start, min(int(np.ceil(bound)), cw.length), cw.sparse)
        found = min(bound, _cheapest_exit(reach, distinct[0])[0])
    if cw.sparse is None or found >= 2 + _least_beyond(cw):  # the walks costing at most ``found``
        rows, below = min(int(np.ceil(found)), cw.length), found * (1 + 1e-6)
        jumps, reach = None, _reach_below(cw, start, rows, below, exits=distinct[0])
    cost, c, k = _cheapest_exit(reach, distinct[0])
    if cost < bound:
        return _runs(cw, _backtrack(cw, reach, c, int(distinct[0][k]), jumps)), int(distinct[1][k]), c + 1
    return _runs(cw, frames), r, len(frames)


def _cheapest_exit(reach: Table, ex: np.ndarray) -> tuple[float, int, int]:
    """``(cost, row, k)``: the walk of ``reach`` to an exit ``ex[k]`` that costs least, a frame
    costing one (the shortest first, then the first exit; ``inf`` cost when none)."""
    cost = np.arange(1, reach.shape[0] + 1)[:, None] + reach[:, ex].astype(np.float64)
    c, k = np.unravel_index(int(np.argmin(cost)), cost.shape)
    return float(cost[c, k]), int(c), int(k)


def _walks_to_exit(cw: PoolWalker, starts, distinct: tuple, name: str) -> dict:
    """What :func:`_walk_to_exit` gives from each of ``starts`` (to the exits ``distinct``,
    checked), without its pieces: ``start -> (r, frames)``, or the :class:`SearchError` it raises.

    The cheapest walks from all starts come from one search backwards from the exits
    (:func:`_back_costs`) instead of one reach table per start; each start's breadth-first walk
    (its bound) is walked forwards when the starts are few (at most one pass over the pool's
    frames each costs no more than one pass over its jumps), else bounded by one breadth-first
    search backwards (:func:`_nearest_back`) and walked only where the bounds do not decide.
    The backward searches add whole numbers, so they are used when the walker's prices are
    whole numbers whose sums float32 holds exactly (the reach table's sums then equal them);
    otherwise each start is walked as :func:`_walk_to_exit` does."""
    starts = list(dict.fromkeys(int(x) for x in starts))
    price = cw.jumps()[2]
    whole = not price.size or (np.all(price == np.round(price)) and float(price.max()) * cw.length < 2**24)
    if not whole:  # the reach table's own float sums decide
        return {s: _walk_or_error(cw, s, distinct, name) for s in starts}

    def forward(s):  # the breadth-first walk from s alone: (r, frames, bound), or its error
        try:
            frames, r = _path(cw, s, None, name, distinct)
        except SearchError as e:
            return e
        return r, len(frames), len(frames) + _paid(cw, frames)

    walked, nearest, bounds = {}, {}, {}
    if len(starts) * cw.length <= cw.loop_src.size:
        walked = {s: forward(s) for s in starts}
        for s, w in walked.items():
            if not isinstance(w, Exception):
                nearest[s], bounds[s] = w[:2], (w[2], w[2])
    else:
        moves, k_of, lo, hi = _nearest_back(cw, distinct[0], starts)
        for s in starts:
            if moves[s] >= 0:
                nearest[s] = (int(distinct[1][k_of[s]]), int(moves[s]) + 1)
                bounds[s] = (moves[s] + 1 + lo[s], moves[s] + 1 + hi[s])
    best = _back_costs(cw, distinct[0], list(bounds), max((b[1] for b in bounds.values()), default=0))
    out: dict = {}
    for s in starts:
        if s not in bounds:  # no exit reachable: the forward walk's loop-guard error
            out[s] = walked[s] if s in walked else forward(s)
            continue
        cost = best[s][0] + 1 if s in best else np.inf  # the cheapest walk's frames and prices
        cheapest = (int(distinct[1][best[s][2]]), best[s][1] + 1) if s in best else None
        if cost < bounds[s][0]:
            out[s] = cheapest
        elif cost >= bounds[s][1]:
            out[s] = nearest[s]
        else:  # the breadth-first walk's own price decides
            w = walked[s] if s in walked else forward(s)
            out[s] = cheapest if cost < w[2] else w[:2]
    return out


def _walk_or_error(cw: PoolWalker, s: int, distinct: tuple, name: str):
    """``_walk_to_exit(...)[1:]``, or the :class:`SearchError` it raises."""
    try:
        return _walk_to_exit(cw, s, distinct, name)[1:]
    except SearchError as e:
        return e


def _nearest_back(cw: PoolWalker, exits: np.ndarray, starts: list[int]):
    """A breadth-first search backwards from ``exits`` over all the walker's moves, until every
    frame of ``starts`` is reached: per frame (arrays over the pool) the fewest moves to an
    exit (-1: none, or not searched), the first of the nearest exits (index ``k`` into
    ``exits``), and the least and the most that a walk of that many moves to that exit pays
    for its jumps (:func:`_paid`'s price per move)."""
    n = cw.length
    if "into" not in cw._prepared:
        order, head = cw._by_destination()
        src = cw.loop_src[order]
        is_step = (cw.loop_dst[order] == src + 1) & cw.step[src]
        cw._prepared["into"] = (head, src, np.where(is_step, 0.0, _pair_least(cw)[order]))
    head, into, pay = cw._prepared["into"]
    moves, k_of = np.full(n, -1, dtype=np.int64), np.full(n, -1, dtype=np.int64)
    lo, hi = np.zeros(n), np.zeros(n)
    moves[exits], k_of[exits] = 0, np.arange(exits.size)
    frontier, want, d = exits.astype(np.int64), np.asarray(starts, dtype=np.int64), 0
    while frontier.size and (moves[want] < 0).any():
        g = frontier[frontier > 0]
        g = g[cw.step[g - 1]]
        at, count = _spans(head, frontier)
        f = np.concatenate([g - 1, into[at]])
        g = np.concatenate([g, np.repeat(frontier, count)])
        p = np.concatenate([np.zeros(f.size - at.size), pay[at]])
        new = moves[f] < 0
        f, g, p = f[new], g[new], p[new]
        d += 1
        k = np.full(n, exits.size, dtype=np.int64)
        np.minimum.at(k, f, k_of[g])
        on = k_of[g] == k[f]  # moves towards the first of the nearest exits
        f, low, high = f[on], p[on] + lo[g[on]], p[on] + hi[g[on]]
        frontier = np.unique(f)
        moves[frontier], k_of[frontier] = d, k[frontier]
        lo[frontier], hi[frontier] = np.inf, -np.inf
        np.minimum.at(lo, f, low)
        np.maximum.at(hi, f, high)
    return moves, k_of, lo, hi


def _pair_least(cw: PoolWalker) -> np.ndarray:
    """Per jump, the least price (float64) of the jumps with its source and destination (what
    :func:`_paid` charges for the move); kept in the walker."""
    if "pair_least" not in cw._prepared:
        src, dst, price = cw.jumps()
        least = np.zeros(src.size)
        if src.size and price.min() == price.max():
            least[:] = price[0]  # one price: every pair's least
        elif src.size:
            pair = src.astype(np.int64) * cw.length + dst
            o = np.lexsort((price, pair))
            head = np.concatenate([[True], pair[o][1:] != pair[o][:-1]])
            group = np.cumsum(head) - 1
            least[o] = price[o][head][group].astype(np.float64)
        cw._prepared["pair_least"] = least
    return cw._prepared["pair_least"]


def _back_costs(cw: PoolWalker, exits: np.ndarray, wanted, cutoff: float) -> dict:
    """Dijkstra's search backwards from ``exits`` over the steps and the walker's jumps (whole-number
    prices): ``frame -> (cost, moves, k)``, the least ``(cost, moves, k)`` (compared in that
    order) over the walks from the frame to exit ``exits[k]``, a move costing one plus its
    price. Stops once every frame of ``wanted`` is settled, or at costs of ``cutoff - 1`` and
    more (a frame not returned has no walk cheaper than that).

    The costs are whole numbers, so the frames are settled cost by cost (Dial's buckets), all
    frames of one cost at once: each takes the least ``(moves, k)`` among its moves into frames
    settled before."""
    src, _, price = cw.jumps()
    n = cw.length
    order, head = cw._by_destination()
    if "back" not in cw._prepared:  # the jumps into each frame
        cw._prepared["back"] = (src[order].astype(np.int64), price[order].astype(np.int64) + 1)
    into, weight = cw._prepared["back"]
    big = exits.size + 1  # (moves, k) as one number: moves * big + k
    settled = np.full(n, -1, dtype=np.int64)  # cost, -1 before settled
    key_of = np.zeros(n, dtype=np.int64)
    buckets: dict[int, list] = {0: [(exits.astype(np.int64), np.arange(exits.size, dtype=np.int64))]}
    want = np.asarray(list(wanted), dtype=np.int64)
    cost = 0
    while buckets and (settled[want] < 0).any() and cost + 1 < cutoff:
        cost = min(buckets)
        if cost + 1 >= cutoff:
            break
        f, key = (np.concatenate(x) for x in zip(*buckets.pop(cost)))
        new = settled[f] < 0
        f, key = f[new], key[new]
        if not f.size:
            continue
        least = np.full(n, np.iinfo(np.int64).max, dtype=np.int64)
        np.minimum.at(least, f, key)
        g = np.unique(f)
        settled[g], key_of[g] = cost, least[g]
        step_from = g[(g > 0)]
        step_from = step_from[cw.step[step_from - 1]]
        buckets.setdefault(cost + 1, []).append((step_from - 1, key_of[step_from] + big))
        at, count = _spans(head, g)
        w, k2 = weight[at], np.repeat(key_of[g], count) + big
        for level in np.unique(w).tolist():
            on = w == level
            buckets.setdefault(cost + level, []).append((into[at[on]], k2[on]))
    done = np.unique(want[settled[want] >= 0])
    return {
        int(f): (int(c), int(q // big), int(q % big))
        for f, c, q in zip(done.tolist(), settled[done].tolist(), key_of[done].tolist())
    }


def _paid(cw: PoolWalker, frames: list[int]) -> float:
    """The price of the jumps of a walk through ``frames`` (a move that is not a step is a
    jump; the cheapest of the jumps that make it)."""
    src, dst, price = cw.jumps()
    order, head = cw._by_source()
    paid = 0.0
    for a, b in zip(frames[:-1], frames[1:]):
        if not (b == a + 1 and cw.step[a]):
            out = order[head[a] : head[a + 1]]
            paid += float(price[out[dst[out] == b]].min())
    return paid


def _next(cw: PoolWalker, f: int) -> int:
    """A frame that may follow ``f`` (the next frame, or a jump)."""
    a, b = cw.succ(np.array([f]))
    if b.size == 0:
        raise SearchError(f"frame {f} has no successor (the graph was not pruned)")
    return int(b[0])


# ---------------------------------------------------------------------------- structured search
def _read_by_search(graph: MotionGraph) -> tuple:
    """The objects of ``graph`` a :class:`Planner` reads: its frames, edges, clips and table."""
    return (graph.alive, graph.src, graph.dst, graph.cost, graph.kind, graph.clips, graph.table)


class Planner:
    """A structured graph prepared for many searches under one search cost (``cost``, see the
    module docstring): each style's walker and the ways out of it, built the first time a
    request needs them and kept for the next requests.

    The planner is state the caller holds, not state hidden in the graph: :func:`search` makes a
    fresh one for every call (always up to date, slower on a large graph); make one yourself to
    search one graph many times. A planner belongs to the graph as it was when made: once the
    graph's frames, edges, clips or table are replaced (``keep_edges``, ``add_edges``, a new
    ``alive`` mask …), :meth:`search` raises :class:`SearchError`; make a new planner. (Arrays
    edited in place are not noticed: edit a graph through its methods, as the package does.)

    Raises
    ------
    SearchError when the graph has no structure table.
    """

    def __init__(self, graph: MotionGraph, cost=default_cost):
        """A planner for ``graph`` under the search ``cost`` (nothing is built yet).

        Raises
        ------
        SearchError when the graph has no structure table.
        """
        if not graph.table.get("behaviours"):
            raise SearchError("this graph has no structure table (a standard graph?); use search_standard")
        self.g = graph
        self.cost = cost
        self.reads = _read_by_search(graph)
        self.entries = graph.table["behaviours"]
        self.walkers: dict[tuple[str, str], PoolWalker] = {}
        self.links: dict[tuple[str, str], list[dict]] = {}
        self.memo: dict = {}
        self.exits: dict[int, tuple[np.ndarray, np.ndarray] | None] = {}
        self.walks: dict[tuple[int, int], tuple[int, int] | SearchError] = {}
        self.checked: set[int] = set()
        for link in graph.table["links"]:
            self.links.setdefault(tuple(link["from"]), []).append(link)

    def walker(self, key: tuple[str, str]) -> PoolWalker:
        if key not in self.walkers:
            cell = self.entries[key[0]][key[1]]
            self.walkers[key] = _pool_walker(self.g, [t["clip"] for t in cell["takes"]], cost=self.cost)
        return self.walkers[key]

    def check(self, seg: Segment) -> tuple[str, str]:
        """The ``(behaviour, style)`` key of a segment, checked against the graph.

        Raises
        ------
        SearchError naming the segment's behaviour or style when the graph lacks it or has no
        frame of it alive.
        """
        if seg.behaviour not in self.entries:
            raise SearchError(f"no behaviour {seg.behaviour!r} in the graph; behaviours: {sorted(self.entries)}")
        styles = self.entries[seg.behaviour]
        if seg.style not in styles:
            raise SearchError(
                f"no style {seg.style!r} of behaviour {seg.behaviour!r} in the graph; its styles: {sorted(styles)}"
            )
        if not styles[seg.style].get("alive", 1):
            raise SearchError(
                f"{seg.behaviour}/{seg.style} has no frame left alive in this graph (pruning kept none: no cycle of "
                "transitions joins its takes); build the graph with a larger --distance-threshold"
            )
        return (seg.behaviour, seg.style)

    def hops(self, a: tuple[str, str], b: tuple[str, str]) -> list[dict]:
        """Links from ``a`` to ``b`` through the structure table, fewest hops (BFS).

        Raises
        ------
        SearchError naming what is reachable from ``a`` when no link leads to ``b``.
        """
        prev: dict[tuple[str, str], tuple] = {a: None}
        queue = deque([a])
        while queue:
            u = queue.popleft()
            if u == b:
                break
            for link in self.links.get(u, []):
                v = tuple(link["to"])
                if v not in prev:
                    prev[v] = (u, link)
                    queue.append(v)
        if b not in prev:
            reach = sorted({f"{k[0]}/{k[1]}" for k in prev})
            behaviours = {k[0] for k in prev}
            if b[0] not in behaviours:
                why = (
                    f"neither a recorded transition clip nor a stance link (a pose the two share) leads from "
                    f"behaviour {a[0]!r} (or its styles) to {b[0]!r}"
                )
            else:
                why = f"no interpolation-space path between styles {a[1]!r} and {b[1]!r} of {b[0]!r}"
            raise SearchError(
                f"cannot go from {a[0]}/{a[1]} to {b[0]}/{b[1]}: {why}; reachable from {a[0]}/{a[1]}: {reach}"
            )
        out = []
        v = b
        while prev[v] is not None:
            u, link = prev[v]
            out.append(link)
            v = u
        return out[::-1]

    def options(self, plan: list[dict]):
        """Every way out along ``plan``: (route, its frames and those after it, final entry),
        the frames each spends after leaving the clip, and each exit frame (cached). The pieces
        after a route: :meth:`onward_pieces`."""
        key = tuple(id(h) for h in plan)
        if key not in self.memo:
            first, rest = plan[0], plan[1:]
            self._prefetch(rest, [route["enter"] for route in first["routes"]])
            seen, options = set(), []
            rest_key = tuple(id(h) for h in rest)  # onward's cache key, made once for every route
            for route in first["routes"]:
                got = self.memo.get((rest_key, route["enter"]))
                more_frames, final_enter = got if got is not None else self.onward(rest, route["enter"])
                sig = (route["exit"], route["frames"] + more_frames)
                if sig in seen:  # same exit, same length: one is enough (routes come best first)
                    continue
                seen.add(sig)
                options.append((route, more_frames, final_enter))
            spent = np.array([o[0]["frames"] + o[1] for o in options])
            exits = [o[0]["exit"] for o in options]
            self.memo[key] = (options, spent, exits)
        return self.memo[key]

    def _prefetch(self, hops: list[dict], enters) -> None:
        """The walks through the pool of ``hops[0]`` from all of ``enters`` at once
        (:func:`_walks_to_exit`), then those of the next hops from where they lead, kept for
        :meth:`onward`, which checks and raises in the order a walk per entry would."""
        if not hops:
            return
        link = hops[0]
        try:
            cw, ex = self.walker(tuple(link["from"])), self._exits(link)
        except ValueError:
            return  # (a bad search cost) onward raises it where a walk per entry would
        if ex is None:
            return  # the exits are out of the pool: onward raises
        todo = [
            e for e in dict.fromkeys(int(e) for e in enters) if 0 <= e < cw.length and (id(link), e) not in self.walks
        ]
        found = _walks_to_exit(cw, todo, ex, f"{link['from'][0]}/{link['from'][1]}")
        self.walks.update({(id(link), e): w for e, w in found.items()})
        nxt = [link["routes"][w[0]]["enter"] for w in found.values() if not isinstance(w, Exception)]
        self._prefetch(hops[1:], nxt)

    def _exits(self, link: dict):
        """``_distinct`` of the link's exit frames (``None`` when one lies outside its pool)."""
        if id(link) not in self.exits:
            ex = np.array([r["exit"] for r in link["routes"]], dtype=np.int64)
            cw = self.walker(tuple(link["from"]))
            self.exits[id(link)] = _distinct(ex) if ex.size and np.all((ex >= 0) & (ex < cw.length)) else None
        return self.exits[id(link)]

    def onward(self, hops: list[dict], enter: int) -> tuple[int, int]:
        """Pass through the basic clips between hops: the frames played after ``enter`` and the
        final entry (cached)."""
        key = (tuple(id(h) for h in hops), enter)
        if key not in self.memo:
            self.memo[key] = self._onward(hops, enter)
        return self.memo[key]

    def _onward(self, hops: list[dict], enter: int) -> tuple[int, int]:
        """The first hop (the walk through its pool to the best of its routes, and the route),
        then the rest through :meth:`onward`, so each (hops left, entry) is walked once.

        Raises
        ------
        SearchError (the loop guard) or ValueError (an entry or exit outside the pool), as
        :func:`walk_to_exit`.
        """
        if not hops:
            return 0, enter
        link = hops[0]
        key = tuple(link["from"])
        cw = self.walker(key)
        ex = self._exits(link)
        if ex is None or id(link) not in self.checked:  # the link's exits as recorded, first
            _check_exits(cw, enter, np.array([r["exit"] for r in link["routes"]], dtype=np.int64))
            self.checked.add(id(link))
        _check_exits(cw, enter, ex[0])
        if (id(link), enter) not in self.walks:
            self._prefetch(hops, [enter])
        walk = self.walks[(id(link), enter)]
        if isinstance(walk, Exception):
            raise walk
        r, n = walk
        route = link["routes"][r]
        more_frames, final_enter = self.onward(hops[1:], route["enter"])
        return n + route["frames"] + more_frames, final_enter

    def onward_pieces(self, hops: list[dict], enter: int) -> list[tuple[int, int, int]]:
        """The pieces of :meth:`onward`'s way: each hop's walk (:func:`walk_to_exit`), then its route.

        Raises
        ------
        GraphError (internal) when a walk disagrees with what :meth:`onward` counted.
        """
        out = []
        for link in hops:
            cw, ex = self.walker(tuple(link["from"])), self._exits(link)
            p, r, n = _walk_to_exit(cw, enter, ex, f"{link['from'][0]}/{link['from'][1]}")
            if (r, n) != self.walks[(id(link), enter)]:
                raise GraphError("internal: the walks from all entries disagree with the walk from one")
            route = link["routes"][r]
            out += [*p, *(tuple(x) for x in route["pieces"])]
            enter = route["enter"]
        return out

    def search(self, request, progress: bool = False) -> SearchResult:
        """Meet a request on the planner's graph (see :func:`search`).

        Raises
        ------
        SearchError naming a missing behaviour or style, or two behaviours with no transition
        clip, or when the graph changed since the planner was made.
        """
        if any(a is not b for a, b in zip(self.reads, _read_by_search(self.g))):
            raise SearchError(
                "the graph changed since this Planner was made (its frames, edges, clips or table "
                "were replaced); make a new search.Planner(graph)"
            )
        segs = _segments(request)
        keys = [self.check(s) for s in segs]
        plans = [self.hops(a, b) if a != b else [] for a, b in zip(keys[:-1], keys[1:])]
        pieces: list[tuple[int, int, int]] = []
        achieved: list[int] = []
        passing = [0] * len(segs)
        enter = self.walker(keys[0]).first_alive()
        bar = None
        if progress:
            from tqdm.auto import tqdm

            bar = tqdm(total=sum(s.frames for s in segs), desc="search", unit="frame", leave=False)
        for k, seg in enumerate(segs):
            if bar is not None:
                bar.update(seg.frames)
            cw = self.walker(keys[k])
            name = f"{seg.behaviour}/{seg.style}"
            slack = tolerance_frames(seg.frames)
            walk = _first_walk if k == 0 else _walk
            if k == len(segs) - 1 or not plans[k]:
                p, _, n = walk(cw, enter, [seg.frames], [-1], name, slack)
                pieces.extend(p)
                achieved.append(n)
                if k < len(segs) - 1:  # the same style again: continue from a frame that follows
                    c_last, f_last = p[-1][0], p[-1][2]
                    local = int(cw.offsets[np.flatnonzero(cw.clips == c_last)[0]]) + f_last
                    enter = _next(cw, local)
                continue
            options, _, exits = self.options(plans[k])
            own = np.array([seg.frames - o[0]["frames"] for o in options])  # the route out counts here
            p, r, n = walk(cw, enter, np.maximum(own, 1).tolist(), exits, name, slack)
            route, more_frames, enter = options[r]
            pieces.extend(p)
            pieces.extend(tuple(x) for x in route["pieces"])
            pieces.extend(self.onward_pieces(plans[k][1:], route["enter"]))
            achieved.append(n + route["frames"])
            passing[k] = more_frames
        if bar is not None:
            bar.close()
        return SearchResult(_merge(pieces), [s.frames for s in segs], achieved, segs, passing)


def search(graph: MotionGraph, request, progress: bool = False, cost=default_cost) -> SearchResult:
    """Meet a request on a structured graph (see the module docstring).

    A fresh :class:`Planner` answers it, so the search always sees the graph as it is now; to
    search one graph many times, make a planner once and call :meth:`Planner.search`.

    Parameters
    ----------
    graph : a graph from :func:`~motionlab.motion_graphs.structured.build_structured`
    request : list of :class:`Segment` / ``(behaviour, style, frames)`` tuples, or the text form
        ``"walk:angry:300,run:normal:200"``; at most :data:`MAX_FRAMES` frames in all
    progress : show a tqdm bar over the segments (Ctrl-C stops the search between steps)
    cost : the search cost, ``cost(graph, edges) -> (E,) float``: the price of each jump, frames
        (default :func:`default_cost`: :data:`JUMP_FRAMES` per jump; see the module docstring)

    Raises
    ------
    SearchError
        naming a missing behaviour or style, or two behaviours with no transition clip.
    ValueError
        (:class:`RequestTooLong`) for a request of more than :data:`MAX_FRAMES` frames, or when
        ``cost`` does not return one finite price >= 0 per edge.
    """
    segs = _segments(request)  # a bad request is refused before the graph is read
    return Planner(graph, cost).search(segs, progress)


def _segments(request) -> list[Segment]:
    if isinstance(request, str):
        return parse_request(request)
    out = []
    for s in request:
        s = s if isinstance(s, Segment) else Segment(str(s[0]).lower(), str(s[1]).lower(), int(s[2]))
        if s.frames < 1:
            raise ValueError(f"segment {s} asks for {s.frames} frames; ask for at least 1")
        out.append(s)
    if not out:
        raise ValueError("empty request")
    _check_total(out)
    return out


def _merge(pieces: list[tuple[int, int, int]]) -> list[tuple[int, int, int]]:
    out: list[tuple[int, int, int]] = []
    for c, a, b in pieces:
        if out and out[-1][0] == c and out[-1][2] + 1 == a:
            out[-1] = (c, out[-1][1], b)
        else:
            out.append((int(c), int(a), int(b)))
    return out


# ---------------------------------------------------------------------------- standard search
def search_standard(graph: MotionGraph, request, start_clip: int | None = None, cost=default_cost) -> SearchResult:
    """The comparison search on an unstructured graph: shortest paths between segments.

    Clips are matched to segments through their labels (``ClipInfo.behaviour/style``). The
    frames of the shortest path (Dijkstra, in frames) into the next clip count towards the
    segment being left; inside a clip the walk is priced by the search ``cost``, as in
    :func:`search`.

    Raises
    ------
    SearchError
        when no clip carries a segment's label or no path leads to it.
    ValueError
        for a bad request (see :func:`parse_request`) or a bad ``cost``.
    """
    import networkx as nx  # (imported here: the structured search does not need it)

    segs = _segments(request)
    g = graph.segment_graph()
    first, last, seg = graph.segments()
    label_clips: dict[tuple[str, str], list[int]] = {}
    for i, c in enumerate(graph.clips):
        if c.behaviour is not None:
            label_clips.setdefault((c.behaviour, c.style), []).append(i)
    pieces: list[tuple[int, int, int]] = []
    achieved: list[int] = []
    current = None  # global frame
    for s in segs:
        clips = [
            c
            for c in label_clips.get((s.behaviour, s.style), [])
            if graph.alive[graph.clips[c].start : graph.clips[c].stop].any()
        ]
        if not clips:
            raise SearchError(f"no clip labelled {s.behaviour}/{s.style} survives in the graph")
        lead = 0
        if current is None:
            c = clips[0]
            enter = int(np.argmax(graph.alive[graph.clips[c].start : graph.clips[c].stop]))
        else:
            targets = {
                int(n)
                for n in np.unique(
                    seg[np.concatenate([np.arange(graph.clips[c].start, graph.clips[c].stop) for c in clips])]
                )
                if n >= 0
            }
            src_node = int(seg[current])
            dist, paths = nx.single_source_dijkstra(g, src_node, weight=lambda u, v, d: g.nodes[v]["frames"])
            reachable = [t for t in targets if t in dist]
            if not reachable:
                raise SearchError(f"no path in the graph to {s.behaviour}/{s.style}")
            t = min(reachable, key=lambda n: dist[n])
            path = paths[t]
            # the frames after `current` in its segment, then the whole segments on the way
            cur_last = int(last[src_node])
            c0 = int(graph.clip_of(current))
            if cur_last > current:
                pieces.append((c0, current + 1 - graph.clips[c0].start, cur_last - graph.clips[c0].start))
                lead += cur_last - current
            for node in path[1:-1]:
                cn = g.nodes[node]
                st = graph.clips[cn["clip"]].start
                pieces.append((cn["clip"], cn["first"] - st, cn["last"] - st))
                lead += cn["frames"]
            achieved[-1] += lead
            c = g.nodes[t]["clip"]
            enter = g.nodes[t]["first"] - graph.clips[c].start
        cw = _clip_walker(graph, c, cost)
        p, _, n = _walk(cw, enter, [s.frames], [-1])
        pieces.extend(p)
        achieved.append(n)
        current = graph.clips[c].start + p[-1][2]
    return SearchResult(_merge(pieces), [s.frames for s in segs], achieved, segs)
