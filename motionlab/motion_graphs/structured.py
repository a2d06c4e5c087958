r"""The structured motion graph of paper B: a structure table of pooled takes, transition clips
and an interpolation space, pruned while it is built.

**Structure table.** Two levels: behaviour → style → where the style's material lies in the
graph. A style is the *pool* of all its takes (a recording session gives many; a take number
never makes a new style, see :mod:`.naming`): the cell records the pool's first frame and size
and, per take, its clip index, take name, span (offset and frames), alive frames and whole
gait cycles. Beside it, *links* between cells, each with the recorded *routes* a search may
take (exit frame in the source pool, the pieces of frames in between, entry frame in the target
pool, frame count; pool frames count from the pool's first frame).

**Within a style** every take is compared with itself (jumps at least ``min_loop`` frames away)
and with its ``neighbours`` next takes in take order, cyclically (:func:`_ring_pairs`), so the
work grows linearly with the number of takes and the ring joins them all; takes of one style are
similar by construction, so they meet at many frames.

**Between behaviours** recorded transition clips ``B1_s1_to_B2_s2`` come first. A
transition clip is compared with the takes of its two endpoint styles only (never with
everything, as a standard graph would): entries ``A_i → T_{j+1}`` into the first half of ``T``,
exits ``T_k → B_{l+1}`` from the second half, so a route always plays the recorded change.
Where no clip records a change, *stance links* (:mod:`.stance_links`) join two behaviours
wherever their stances match, under the same threshold.

**Gaits and standing actions.** Every take is classified from its motion (:mod:`.segments`):
a gait is cut into whole cycles, a standing action into segments between its stances, and the
ends of every take of a style are compared with the ends of every other take of it, so that
takes connect stance to stance. The styles of a standing action meet at their stances (stance
links); a gait's styles meet in their interpolation space.

**Between styles of one behaviour** an interpolation space bridges the gap
(:mod:`~motionlab.motion_graphs.registration`), built from *representative cycles*: the take
with most whole cycles (:mod:`.cycles`; whole segments for a standing action) represents its
style, the same number of whole cycles of both styles (at most ``rep_cycles``, from the middle
of the take) are registered by DTW and
blended into intermediate motions M1…M4 at weights 0.2…0.8, and transitions are searched only
between neighbours S1–M1, M1–M2, …, M4–S2. Which style pairs are bridged is a choice
(``style_pairs``): ``"hub"`` links every style with the reference style (default ``normal``),
``"chain"`` links styles in name order, ``"all"`` every pair, ``"none"`` builds no space.

**Pruning during construction** (local: one style at a time, never the whole graph):

* each style keeps the largest strongly connected part of its takes (frames, steps and jumps
  inside the pool); the rest is cut and counted in the build report, so a search can never get
  stuck inside a style; a style with no cycle at all under the threshold gets its best jump
  back (counted as ``forced``);
* in an interpolation space, a path that enters M1 but cannot reach the target pool through
  M2…M4 is disabled by removing its first edge; every valid path is recorded in the table, in
  both directions;
* frames of intermediate and transition clips that lie on no recorded route are removed.

``prune=False`` skips all three (every frame and every candidate edge stays; the table still
records the routes), so the pruning's effect can be measured on its own.

Conditions met on the way (a take pruned, a forced pair, a missing link, an unused transition
clip) are collected in ``info["conditions"]`` and counted once in the build report
(:mod:`.report`).

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import functools
import itertools
import time
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from motionlab.core import fk as _fk
from motionlab.core.motion import Motion
from motionlab.motion_graphs import cycles as _cycles
from motionlab.motion_graphs import distance as _distance
from motionlab.motion_graphs import registration as _registration
from motionlab.motion_graphs import report as _report
from motionlab.motion_graphs import segments as _segments
from motionlab.motion_graphs import stance_links as _stance_links
from motionlab.motion_graphs.graph import EDGE_KINDS, ClipInfo, GraphError, MotionGraph, check_motions, pair_edges
from motionlab.motion_graphs.naming import ClipLabel, label_name, parse_name

Key = tuple[str, str]

__all__ = [
    "build_structured",
    "build_wcmg",
    "structure_rows",
    "positions",
    "pool_pair_candidates",
    "style_task",
    "STYLE_PAIRS",
    "BACKENDS",
]

STYLE_PAIRS = ("hub", "chain", "all", "none")

BACKENDS = ("local", "ray")
"""Where the comparisons inside each style run (:func:`build_structured`'s ``backend``)."""

NEIGHBOURS = 3
"""Takes of one style each compared with the next 3 takes (cyclically, in take order)."""

REP_CYCLES = 4
"""Whole cycles of each representative take registered and blended into an interpolation space
(fewer when one of the two takes has fewer)."""


def _style_pairs(
    styles: Sequence[str], how: str, reference: str, lengths: Mapping[str, int], min_frames: int
) -> list[tuple[str, str]]:
    styles = sorted(styles)
    if how == "hub":
        # the reference style is the hub unless its clip is too short to loop; then the longest
        hub = (
            reference
            if reference in styles and lengths[reference] >= min_frames
            else max(styles, key=lambda s: lengths[s])
        )
        return [(hub, s) for s in styles if s != hub]
    if how == "chain":
        return list(zip(styles[:-1], styles[1:]))
    if how == "all":
        return list(itertools.combinations(styles, 2))
    if how == "none":
        return []
    raise ValueError(f"style_pairs must be one of {STYLE_PAIRS}, got {how!r}")


class _Notes:
    """Build conditions, each kind counted once with its examples (for the build report)."""

    def __init__(self):
        self.lines: dict[str, list[str]] = {}

    def add(self, kind: str, text: str) -> None:
        self.lines.setdefault(kind, []).append(text)


def _progress(iterable, desc: str, total: int | None = None, enabled: bool = False):
    if not enabled:
        return iterable
    from tqdm.auto import tqdm

    return tqdm(iterable, desc=desc, total=total, leave=False)


def _ring_pairs(n: int, neighbours: int) -> list[tuple[int, int]]:
    """Pairs of takes compared within one style: each take with the next ``neighbours`` takes
    (cyclically), so the work grows linearly with the number of takes; all pairs when few."""
    if n <= neighbours + 1:
        return list(itertools.combinations(range(n), 2))
    out = set()
    for a in range(n):
        for d in range(1, neighbours + 1):
            b = (a + d) % n
            out.add((min(a, b), max(a, b)))
    return sorted(out)


def _best_only(i, j, cost):
    if cost.size == 0:
        return i, j, cost
    k = int(np.argmin(cost))
    return i[k : k + 1], j[k : k + 1], cost[k : k + 1]


@dataclass
class _Options:
    """The build's settings (see :func:`build_structured`), resolved to numbers."""

    threshold: float
    window: int
    min_loop: int
    weights: tuple[float, ...]
    style_pairs: str
    reference_style: str
    force: bool
    dwell: int
    neighbours: int
    rep_cycles: int
    progress: bool
    prune: bool = True
    workers: int = 1


@dataclass
class _Arranged:
    """The clips in graph order: each style's takes side by side (by take), transition clips last.

    ``order[n]``: input index of graph clip ``n``; ``pools``: key → graph clip indices of its
    takes; ``transitions``: graph clip indices of the transition clips."""

    motions: list[Motion]
    labels: list[ClipLabel]
    order: list[int]
    pools: dict[Key, list[int]]
    transitions: list[int]


def _arrange(motions: Sequence[Motion], labels: Sequence[ClipLabel]) -> _Arranged:
    pools_in: dict[Key, list[int]] = {}
    for k, lab in enumerate(labels):
        if lab.kind == "basic":
            pools_in.setdefault(lab.key, []).append(k)
    for key in pools_in:
        pools_in[key].sort(key=lambda k: (labels[k].take or "", k))
    order = [k for key in sorted(pools_in) for k in pools_in[key]]
    order += [k for k, lab in enumerate(labels) if lab.kind == "transition"]
    where = {k: n for n, k in enumerate(order)}  # input index -> graph clip index
    return _Arranged(
        [motions[k] for k in order],
        [labels[k] for k in order],
        order,
        {key: [where[k] for k in ks] for key, ks in pools_in.items()},
        [where[k] for k, lab in enumerate(labels) if lab.kind == "transition"],
    )


@dataclass
class _Cuts:
    """Per take its gait cycles and segments (``None`` where they cannot be cut), the cuts that
    represent it (segments of an action, cycles of a gait) and each style's representative take."""

    cyc: dict
    seg: dict
    cuts: dict
    rep: dict[Key, int]
    take_frames: list[int]

    def rep_span(self, key: Key, n: int) -> tuple[int, int]:
        """``n`` whole cycles (or segments) from the middle of the representative take (all of it without)."""
        cy = self.cuts[self.rep[key]]
        if cy is None or cy.count == 0:
            return (0, self.take_frames[self.rep[key]])
        n = min(n, cy.count)
        mid = (cy.count - n) // 2
        return int(cy.bounds[mid, 0]), int(cy.bounds[mid + n - 1, 1])

    def rep_count(self, key: Key, rep_cycles: int) -> int:
        cy = self.cuts[self.rep[key]]
        return rep_cycles if cy is None or cy.count == 0 else min(rep_cycles, cy.count)


def _cut_takes(arr: _Arranged, notes: _Notes, progress: bool) -> _Cuts:
    """Stage 1: cycles and segments of every take, and the representative take of every style."""
    cyc, seg, cuts = {}, {}, {}
    for _key, ks in _progress(sorted(arr.pools.items()), "cycles", enabled=progress):
        for c, pos in zip(ks, positions([arr.motions[c] for c in ks])):
            try:
                cyc[c], seg[c] = _cut_one(arr.motions[c], pos)
            except ValueError:
                cyc[c] = seg[c] = None
            # a gait is cut into whole cycles, a standing action into segments between stances
            cuts[c] = seg[c] if seg[c] is not None and seg[c].kind == "action" else cyc[c]
    rep: dict[Key, int] = {}
    for key, ks in arr.pools.items():
        # the take with the most whole cycles or segments (ties: the first take) represents the style
        rep[key] = max(ks, key=lambda c: (cuts[c].count if cuts[c] is not None else -1, -c))
        if cuts[rep[key]] is None or cuts[rep[key]].count == 0:
            notes.add("no whole cycle", f"{arr.motions[rep[key]].name}: the whole take represents its style")
    return _Cuts(cyc, seg, cuts, rep, [m.num_frames for m in arr.motions])


def positions(motions: Sequence[Motion]) -> list[np.ndarray]:
    """World joint positions (T, J, 3) of each clip, by one forward-kinematics pass over all of
    them when they share a joint hierarchy (FK works frame by frame, so every value equals the
    clip's own :meth:`Motion.global_positions`); each clip keeps its own bone offsets."""
    if not motions:
        return []
    parents = motions[0].skeleton.parents
    if any(not np.array_equal(m.skeleton.parents, parents) for m in motions):
        return [m.global_positions() for m in motions]
    rot = np.concatenate([m.local_rot for m in motions])
    trans = np.concatenate([m.translations() for m in motions])
    pos = _fk.fk(rot, trans, parents)[1]
    return np.split(pos, np.cumsum([m.num_frames for m in motions])[:-1])


def _cut_one(motion: Motion, pos: np.ndarray):
    """:func:`.cycles.segment_cycles` and :func:`.segments.segment_take` of one take from its
    world positions ``pos``. Raises ``ValueError`` as they do (a joint missing)."""
    names = list(motion.skeleton.names)
    missing = [f for f in _cycles.FOOT_JOINTS if f not in names]
    if missing:
        raise ValueError(f"clip {motion.name!r} has no joint {missing[0]!r}")
    idx = tuple(names.index(f) for f in _cycles.FOOT_JOINTS)
    cyc = _cycles.cycles_from_ankles(pos[:, list(idx)], motion.fps)
    return cyc, _segments.segments_from_positions(pos, idx, motion.fps, _segments.leg_length(motion.skeleton))


def _interpolation_spaces(arr: _Arranged, cuts: _Cuts, opt: _Options) -> tuple[list[Motion], list[ClipInfo], list]:
    """Stage 2: intermediate motions between representative cycles of styles of one behaviour.

    Returns the intermediate motions, their clip infos and the spaces
    ``(behaviour, s1, s2, [graph clip indices of the intermediates])``."""
    by_behaviour: dict[str, list[str]] = {}
    for b, s in arr.pools:
        by_behaviour.setdefault(b, []).append(s)
    extra: list[Motion] = []
    extra_infos: list[ClipInfo] = []
    spaces = []
    pairs_todo = []
    for b, styles in sorted(by_behaviour.items()):
        lengths = {s: arr.motions[cuts.rep[(b, s)]].num_frames for s in styles}
        pairs_todo += [(b, s1, s2) for s1, s2 in _style_pairs(styles, opt.style_pairs, opt.reference_style, lengths, 0)]
    for b, s1, s2 in _progress(pairs_todo, "interpolation spaces", enabled=opt.progress):
        # the same number of whole cycles of both styles, so registration pairs cycle with cycle
        n = min(cuts.rep_count((b, s1), opt.rep_cycles), cuts.rep_count((b, s2), opt.rep_cycles))
        cut = []
        for key in ((b, s1), (b, s2)):
            f0, f1 = cuts.rep_span(key, n)
            m = arr.motions[cuts.rep[key]][f0:f1]
            pos = m.global_positions()
            cut.append((m, pos, _registration.root_track(m, pos)))
        (m1, p1, r1), (m2, p2, r2) = cut
        # the registration must cover (nearly) both spans: 90% of the longer one
        reg = _registration.dtw(_distance.distance_matrix(p1, p2, opt.window), int(0.9 * max(len(p1), len(p2))))
        ids = []
        for w in opt.weights:
            mid = _registration.blend(m1, m2, reg, w, name=f"{b}_{s1}~{s2}@{w:g}", tracks=(r1, r2))
            if mid.num_frames < 3:
                continue
            ids.append(len(arr.motions) + len(extra))
            extra.append(mid)
            extra_infos.append(ClipInfo(mid.name, "intermediate", b, f"{s1}~{s2}@{w:g}", b, s2))
        spaces.append((b, s1, s2, ids))
    return extra, extra_infos, spaces


class _Compare:
    """Transition candidates between clips of one graph (:func:`distance.candidates`), with the
    clips' point-cloud features cached and the cells compared counted."""

    def __init__(self, graph: MotionGraph, threshold: float, window: int):
        self.graph, self.threshold, self.window = graph, threshold, window
        self.cache: dict[int, _distance.CloudFeatures] = {}
        self.comparisons = 0

    def motion(self, c: int) -> Motion:
        """Clip ``c`` of the graph as a Motion on the graph's skeleton (views of its arrays)."""
        g, info = self.graph, self.graph.clips[c]
        st, sp = info.start, info.stop
        return Motion(g.skeleton, g.local_rot[st:sp], g.root_pos[st:sp], g.fps, None, info.name)

    def feats(self, c: int) -> _distance.CloudFeatures:
        if c not in self.cache:
            self.cache[c] = _distance.cloud_features(self.motion(c).global_positions(), self.window)
        return self.cache[c]

    def load(self, ks: Sequence[int]) -> None:
        """Cache the features of clips ``ks`` (one style's takes) from one FK pass (:func:`positions`)."""
        todo = [c for c in ks if c not in self.cache]
        for c, pos in zip(todo, positions([self.motion(c) for c in todo])):
            self.cache[c] = _distance.cloud_features(pos, self.window)

    def __call__(self, x: int, y: int | None, rows=None, cols=None, thr=None, min_gap=0):
        """Candidates ``(i, j, cost)`` of clip ``x`` (``rows``) against clip ``y`` (``cols``; ``None``:
        against itself), below ``thr`` (default: the graph threshold)."""
        fa, fb = self.feats(x), (None if y is None else self.feats(y))
        r = rows or slice(0, len(fa))
        cl = cols or slice(0, len(fb if fb is not None else fa))
        self.comparisons += (r.stop - r.start) * (cl.stop - cl.start)
        thr = self.threshold if thr is None else thr
        return _distance.candidates(fa, fb, thr, self.window, min_gap, r, cl)


def pool_pair_candidates(feats: Sequence[_distance.CloudFeatures], pairs: Sequence[tuple[int, int]], threshold: float,
                         window: int, min_loop: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:  # fmt: skip
    """Transition candidates inside one style: every take with itself (``min_loop`` frames apart
    at least), then each pair ``(x, y)`` of ``pairs`` (indices into ``feats``).

    Returns ``(i, j, cost)`` take-local arrays (:func:`.distance.candidates`): one per take, then
    one per pair. A pure function of its arguments, so the local and the Ray backends share it."""
    out = [_distance.candidates(f, None, threshold, window, min_loop) for f in feats]
    out += [_distance.candidates(feats[x], feats[y], threshold, window) for x, y in pairs]
    return out


def style_task(skeleton, rot, root, fps: float, lengths, pairs, threshold: float, window: int, min_loop: int):
    """One style's :func:`pool_pair_candidates` from its frames alone (``rot`` (N, J, 4), ``root``
    (N, 3): the takes side by side, ``lengths`` frames each), for the Ray backend's tasks."""
    bounds = np.cumsum([0, *lengths])
    motions = [Motion(skeleton, rot[a:b], root[a:b], fps, None, "") for a, b in zip(bounds[:-1], bounds[1:])]
    feats = [_distance.cloud_features(p, window) for p in positions(motions)]
    return pool_pair_candidates(feats, pairs, threshold, window, min_loop)


class _LocalPools:
    """The local backend: ``run(key, takes, pairs)`` gives :func:`pool_pair_candidates` of one
    style and its takes' port rows (:class:`_PortRows`). With ``workers > 1`` threads compute the
    next styles ahead (at most ``workers`` at once); answers are taken in build order. Only port
    rows outlive a task, so memory holds at most ``workers`` styles' point clouds."""

    def __init__(self, cmp: _Compare, opt: _Options, pools: list, workers: int, port_masks: dict):
        self.cmp, self.opt, self.todo, self.pending = cmp, opt, list(pools), {}
        self.workers, self.port_masks = workers, port_masks
        self.pool = ThreadPoolExecutor(workers) if workers > 1 else None

    def _task(self, ks: list[int]):
        motions = [self.cmp.motion(c) for c in ks]
        feats = [_distance.cloud_features(p, self.opt.window) for p in positions(motions)]
        pairs = _ring_pairs(len(ks), self.opt.neighbours)
        found = pool_pair_candidates(feats, pairs, self.opt.threshold, self.opt.window, self.opt.min_loop)
        return found, {c: _PortRows(f, self.port_masks[c]) for c, f in zip(ks, feats)}

    def _submit(self) -> None:
        while self.todo and len(self.pending) < self.workers:
            key, ks = self.todo.pop(0)
            self.pending[key] = self.pool.submit(self._task, ks)

    def __call__(self, key, ks, pairs):
        if self.pool is None:
            return self._task(ks)
        self._submit()
        out = self.pending.pop(key).result()
        self._submit()
        return out

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown(cancel_futures=True)


def _link_takes(graph: MotionGraph, cmp: _Compare, arr: _Arranged, port_masks: dict, opt: _Options, notes: _Notes,
                clock: _report.StageClock, pool_candidates):  # fmt: skip
    """Stage 3: within each style, every take with itself, its neighbouring takes and (port to
    port) every other take; then the style keeps its largest strongly connected part.

    ``port_masks``: clip index → (frames,) bool ports of each take; ``pool_candidates(key,
    takes, pairs)``: the candidates of one style and its port rows or ``None``
    (:class:`_LocalPools` or :func:`.ray_backend.pool_candidates`). Returns the ports of every pool
    (:func:`.stance_links.port_features`, after pruning)."""
    ports: dict = {}
    for key, ks in _progress(sorted(arr.pools.items()), "takes", enabled=opt.progress):
        with clock("distances"):
            ring = _ring_pairs(len(ks), opt.neighbours)
            found, port_rows = pool_candidates(key, ks, ring)
            edges = _pool_edges(graph, ks, ring, found, cmp)
            if port_rows is None:  # the remote backend sent candidates only
                cmp.load(ks)
                port_rows = {c: _PortRows(cmp.feats(c), port_masks[c]) for c in ks}
                for c in ks:
                    cmp.cache.pop(c, None)
            # takes connect stance to stance: every take's ports with every other take's
            port = _stance_links.port_features(graph, ks, port_masks, port_rows.get)
            cmp.comparisons += 0 if port[0] is None else len(port[1]) ** 2
            edges["transition"].append(_stance_links.link_within(graph, port, opt.threshold, opt.min_loop, opt.window))
            for kind, parts in edges.items():
                if parts:
                    graph.add_edges(*(np.concatenate(p) for p in zip(*parts)), kind)
        if opt.prune:
            with clock("pruning"):
                _prune_pool(graph, cmp, ks, opt, notes)
        ports[key] = _stance_links.port_features(graph, ks, port_masks, port_rows.get)
    with clock("pruning"):
        graph.drop_dead_edges()
    return ports


def _pool_edges(graph: MotionGraph, ks: list[int], ring: list, found: list, cmp: _Compare) -> dict:
    """Loop and transition edges (global) of one style from :func:`pool_pair_candidates`'s
    answer ``found``; counts the cells compared in ``cmp.comparisons``."""
    clips = graph.clips
    out = {"loop": [], "transition": []}  # (src, dst, cost) global, added at once
    for c, (i, j, cost) in zip(ks, found):
        ok = j + 1 < clips[c].num_frames
        out["loop"].append((clips[c].start + i[ok], clips[c].start + j[ok] + 1, cost[ok]))
        cmp.comparisons += clips[c].num_frames ** 2
    for (x, y), (i, j, cost) in zip(ring, found[len(ks) :]):
        a, z = ks[x], ks[y]
        src, dst, which = pair_edges(i, j, clips[a].start, clips[z].start, clips[z].num_frames,
                                     clips[a].num_frames, False)  # fmt: skip
        out["transition"].append((src, dst, cost[which]))
        cmp.comparisons += clips[a].num_frames * clips[z].num_frames
    return out


class _PortRows:
    """The features of a take's port frames only, indexed by the take's frame numbers (the rows
    :func:`.stance_links.port_features` reads), so a pool's full features need not be kept."""

    def __init__(self, feats: _distance.CloudFeatures, ports: np.ndarray):
        self.rows = feats[np.flatnonzero(ports)]
        self.where = np.cumsum(ports) - 1

    def __getitem__(self, frames) -> _distance.CloudFeatures:
        return self.rows[self.where[frames]]


def _prune_pool(graph: MotionGraph, cmp: _Compare, ks: list[int], opt: _Options, notes: _Notes) -> None:
    """Keep the largest strongly connected part of one style's takes (with ``force``, a style
    with no cycle under the threshold first gets its best jump back inside a take)."""
    clips = graph.clips
    st, sp = clips[ks[0]].start, clips[ks[-1]].stop
    mask = np.zeros(graph.num_frames, dtype=bool)
    mask[st:sp] = True
    keep = graph.largest_component(mask)
    if not keep[st:sp].any() and opt.force:
        best = None
        for c in ks:
            i, j, cost = cmp(c, None, thr=np.inf, min_gap=opt.min_loop)
            ok = (j < i) & (j + 1 < clips[c].num_frames)
            if ok.any():
                k = int(np.argmin(np.where(ok, cost, np.inf)))
                if best is None or cost[k] < best[2]:
                    best = (clips[c].start + int(i[k]), clips[c].start + int(j[k]) + 1, float(cost[k]), c)
        if best is not None:
            graph.add_edges([best[0]], [best[1]], [best[2]], "loop")
            notes.add("forced", f"{clips[best[3]].name}: no loop under the threshold, best jump back used")
            keep = graph.largest_component(mask)
    graph.alive[st:sp] = keep[st:sp]
    for c in ks:
        if not graph.alive[clips[c].start : clips[c].stop].any():
            notes.add("take pruned", f"{clips[c].name}: no transition under the threshold joins it to its style")


def _structure_table(graph: MotionGraph, arr: _Arranged, cuts: _Cuts, opt: _Options) -> dict:
    """Stage 4: the structure table's cells (behaviour → style → takes, spans and counts)."""
    clips = graph.clips
    table: dict = {"behaviours": {}, "links": []}
    for (b, s), ks in sorted(arr.pools.items()):
        st, sp = clips[ks[0]].start, clips[ks[-1]].stop
        takes = [_take_row(graph, c, st, cuts) for c in ks]
        kinds = [t["kind"] for t in takes if t["kind"] is not None]
        table["behaviours"].setdefault(b, {})[s] = {
            "kind": max(sorted(set(kinds)), key=kinds.count) if kinds else None,
            "start": st,
            "frames": sp - st,
            "takes": takes,
            "representative": cuts.rep[(b, s)],
            "representative_cycles": list(cuts.rep_span((b, s), opt.rep_cycles)),
            "synthetic": bool(any(clips[c].synthetic for c in ks)),
        }
    _count_cells(graph, table)
    return table


def _count_cells(graph: MotionGraph, table: dict) -> None:
    """Set each cell's (and take's) ``alive`` frames and the cell's ``transitions`` and ``loops``
    (alive edges inside the cell) from the graph as it now stands."""
    loop_kind = EDGE_KINDS.index("loop")
    live = graph.alive[graph.src] & graph.alive[graph.dst]
    for cell in (c for styles in table["behaviours"].values() for c in styles.values()):
        st, sp = cell["start"], cell["start"] + cell["frames"]
        inside = live & (graph.src >= st) & (graph.src < sp) & (graph.dst >= st) & (graph.dst < sp)
        cell.update(
            alive=int(graph.alive[st:sp].sum()),
            transitions=int(inside.sum()),
            loops=int((inside & (graph.kind == loop_kind)).sum()),
        )
        for take in cell["takes"]:
            ci = graph.clips[take["clip"]]
            take["alive"] = int(graph.alive[ci.start : ci.stop].sum())


def _take_row(graph: MotionGraph, c: int, st: int, cuts: _Cuts) -> dict:
    ci, cy, sg = graph.clips[c], cuts.cyc[c], cuts.seg[c]
    return {
        "clip": c,
        "name": ci.name,
        "take": ci.take,
        "offset": ci.start - st,
        "frames": ci.num_frames,
        "cycles": 0 if cy is None else cy.count,
        "cycle_span": [0, 0] if cy is None else list(cy.span),
        "kind": None if sg is None else sg.kind,
        "segments": 0 if sg is None else sg.count,
        "stances": 0 if sg is None else int(sg.stances.shape[0]),
    }


def _neighbour_edges(graph: MotionGraph, cmp: _Compare, x: int, y: int, force: bool, notes: _Notes):
    """Candidates between two neighbours of an interpolation space whose both ends are alive (with
    ``force`` and none under the threshold: the best pair above it)."""
    cx, cy = graph.clips[x], graph.clips[y]

    def alive_pairs(thr=None):
        i, j, cost = cmp(x, y, thr=thr)
        ok = graph.alive[cx.start + i] & graph.alive[cy.start + j]
        return i[ok], j[ok], cost[ok]

    i, j, cost = alive_pairs()
    if i.size == 0 and force:
        i, j, cost = alive_pairs(np.inf)
        if i.size:
            i, j, cost = _best_only(i, j, cost)
            notes.add("forced", f"{cx.name} -> {cy.name}: best pair above threshold")
    return i, j, cost


def _link_styles(graph, cmp, spaces, cuts, pool_start, opt: _Options, notes: _Notes, table: dict, on_route) -> None:
    """Stage 5: transitions between neighbours S1–M1–…–M4–S2 of every interpolation space; the
    valid paths through it become routes of the table, in both directions."""
    clips = graph.clips
    for b, s1, s2, ids in _progress(spaces, "style links", enabled=opt.progress):
        if not ids:
            notes.add("missing link", f"{b}: {s1} <-> {s2} (no intermediate motion)")
            continue
        chain = [cuts.rep[(b, s1)], *ids, cuts.rep[(b, s2)]]
        fwd, bwd = [], []  # per neighbour pair: (src, dst, cost) global
        for x, y in zip(chain[:-1], chain[1:]):
            cx, cy_ = clips[x], clips[y]
            i, j, cost = _neighbour_edges(graph, cmp, x, y, opt.force, notes)
            ok = (j + 1 < cy_.num_frames) & graph.alive[np.minimum(cy_.start + j + 1, cy_.stop - 1)]
            fwd.append((cx.start + i[ok], cy_.start + j[ok] + 1, cost[ok]))
            ok = (i + 1 < cx.num_frames) & graph.alive[np.minimum(cx.start + i + 1, cx.stop - 1)]
            bwd.append((cy_.start + j[ok], cx.start + i[ok] + 1, cost[ok]))
        for direction, edges, seq in (("forward", fwd, chain), ("backward", list(reversed(bwd)), chain[::-1])):
            sa, sz = (s1, s2) if direction == "forward" else (s2, s1)
            routes, kept = _bridge_routes(graph, seq, edges, opt.dwell, pool_start((b, sa)), pool_start((b, sz)))
            for src, dst, cost in kept if opt.prune else edges:  # unpruned: invalid paths' first edges too
                graph.add_edges(src, dst, cost, "bridge")
            for r in routes:
                for clip, f0, f1 in r["pieces"]:
                    st = clips[clip].start
                    on_route[st + f0 : st + f1 + 1] = True
            if routes:
                table["links"].append({"from": [b, sa], "to": [b, sz], "via": "interpolation", "routes": routes})
            else:
                notes.add("missing link", f"{b}: {sa} -> {sz} ({direction}: no valid path through the space)")


def _clip_ends(graph, cmp, k: int, pool: list[int], p0: int, entries: bool, thr=None):
    """Candidates between transition clip ``k`` and the takes ``pool`` of one endpoint style.

    ``entries``: take frames into the first half of ``k``, as (pool-local exit frame, clip frame
    entered, cost); else the second half of ``k`` into the takes, as (clip frame left, pool-local
    frame entered, cost)."""
    c = graph.clips[k]
    half = c.num_frames // 2
    parts = []
    for a in pool:
        ca = graph.clips[a]
        if entries:
            i, j, cost = cmp(a, k, cols=slice(0, half), thr=thr)
            ok = graph.alive[ca.start + i]
            parts.append((ca.start + i[ok] - p0, j[ok] + 1, cost[ok]))
        else:
            i, j, cost = cmp(k, a, rows=slice(half, c.num_frames), cols=slice(0, ca.num_frames - 1), thr=thr)
            ok = graph.alive[ca.start + j + 1]
            parts.append((i[ok], ca.start + j[ok] + 1 - p0, cost[ok]))
    return tuple(np.concatenate(x) for x in zip(*parts))


def _link_transition_clips(graph, cmp, arr: _Arranged, pool_start, opt: _Options, notes: _Notes, table, on_route):
    """Stage 6: each recorded transition clip compared with the takes of its two endpoint styles
    only; entries into its first half, exits from its second half (paper B §3.2)."""
    clips = graph.clips
    clip_edges: list[tuple[int, int, float]] = []
    for k in _progress(arr.transitions, "transition clips", enabled=opt.progress):
        c, lab = clips[k], arr.labels[k]
        if lab.key not in arr.pools or lab.to_key not in arr.pools:
            missing = lab.key if lab.key not in arr.pools else lab.to_key
            notes.add("unused transition clip", f"{c.name}: no basic clip {missing[0]}_{missing[1]}")
            graph.alive[c.start : c.stop] = False
            continue
        p0, p1 = pool_start(lab.key), pool_start(lab.to_key)
        ends, forced = [], False
        for entries, key, p in ((True, lab.key, p0), (False, lab.to_key, p1)):
            e = _clip_ends(graph, cmp, k, arr.pools[key], p, entries)
            if opt.force and e[0].size == 0:
                e, forced = _best_only(*_clip_ends(graph, cmp, k, arr.pools[key], p, entries, np.inf)), True
            ends.append(e)
        (ei, ej, ec), (xi, xj, xc) = ends
        if ei.size == 0 or xi.size == 0:
            notes.add("unused transition clip", f"{c.name}: no entry or exit frames")
            graph.alive[c.start : c.stop] = False
            continue
        if forced:
            notes.add("forced", f"{c.name}: entry or exit above threshold")
        routes = _clip_routes(k, c.start, (ei, ej, ec), (xi, xj, xc), p0, p1, clip_edges, on_route)
        if not routes:
            notes.add("unused transition clip", f"{c.name}: every entry lies after the last exit")
            continue
        link = {"from": list(lab.key), "to": list(lab.to_key), "via": f"transition clip {c.name}", "clip": k}
        table["links"].append({**link, "routes": routes, "forced": forced})
    if clip_edges:
        src, dst, cost = (np.array(x) for x in zip(*clip_edges))
        graph.add_edges(src, dst, cost, "clip")


def _clip_routes(k: int, start: int, ent, ext, p0: int, p1: int, clip_edges: list, on_route) -> list[dict]:
    """Routes through transition clip ``k`` (first frame ``start``): each entry to the first exit
    at or after it; appends the entry and exit edges and marks the frames played."""
    ei, ej, ec = ent
    srt = np.argsort(ext[0], kind="stable")
    xi, xj, xc = (x[srt] for x in ext)
    routes = []
    for ii, first, cc in zip(ei.tolist(), ej.tolist(), ec.tolist()):
        e = int(np.searchsorted(xi, first))  # first exit at or after the entry frame
        if e >= xi.size:
            continue
        last = int(xi[e])
        routes.append({"exit": ii, "enter": int(xj[e]), "pieces": [[k, first, last]], "frames": last - first + 1,
                       "cost": float(max(cc, xc[e]))})  # fmt: skip
        clip_edges.append((p0 + ii, start + first, cc))
        clip_edges.append((start + last, p1 + int(xj[e]), float(xc[e])))
        on_route[start + first : start + last + 1] = True
    routes.sort(key=lambda r: r["cost"])
    return routes


def _link_stances(graph: MotionGraph, arr: _Arranged, table: dict, ports: dict, pool_start, opt: _Options) -> int:
    """Stage 7: stance links (:mod:`.stance_links`) between pools no recorded clip joins.
    Returns the cells compared."""
    recorded = {(link["from"][0], link["to"][0]) for link in table["links"] if link["via"] != "interpolation"}
    kinds = {(b, s): cell["kind"] for b, cells in table["behaviours"].items() for s, cell in cells.items()}
    pairs = _stance_links.pool_pairs(list(arr.pools), recorded, kinds)
    links, (src, dst, cost), n_cmp = _stance_links.link_pools(graph, pairs, ports, pool_start, opt.threshold,
                                                              opt.window, opt.workers)  # fmt: skip
    graph.add_edges(src, dst, cost, "transition")
    table["links"].extend(links)
    return n_cmp


def build_structured(
    motions: Sequence[Motion],
    threshold: float,
    name_map=None,
    labels: Sequence[ClipLabel] | None = None,
    window: int = _distance.DEFAULT_WINDOW,
    min_loop: int | None = None,
    weights: Sequence[float] = _registration.BLEND_WEIGHTS,
    style_pairs: str = "hub",
    reference_style: str = "normal",
    force: bool = True,
    synthetic: Sequence[bool] | None = None,
    dwell: int | None = None,
    neighbours: int = NEIGHBOURS,
    rep_cycles: int = REP_CYCLES,
    progress: bool = False,
    prune: bool = True,
    backend: str = "local",
    ray_address: str | None = None,
    workers: int = 1,
) -> MotionGraph:
    """Build the structured motion graph (see the module docstring).

    Parameters
    ----------
    motions : canonical clips (22 joints, one fps), named ``Behaviour_style[_take]`` or
        ``B1_s1_to_B2_s2`` (or through ``name_map`` / ``labels``); clips with one label are
        takes of one style and are pooled
    threshold : largest frame distance of a transition, m² (:func:`distance.threshold_from`)
    name_map : ``{clip name: label text}`` or a callable, see :func:`.naming.parse_name`
    labels : one :class:`ClipLabel` per clip, instead of parsing names
    window : frames per point cloud; min_loop : shortest jump back within one take, frames (default: 0.5 s)
    weights : blend weights of the intermediate motions
    style_pairs : ``"hub"`` (with ``reference_style``), ``"chain"``, ``"all"`` or ``"none"``: which
        styles get an interpolation space
    force : accept the best local minimum when nothing passes the threshold inside an
        interpolation space or a transition clip (counted as ``forced``)
    synthetic : per clip, True if it is a synthetic stand-in (shown in tables)
    dwell : fewest frames a style route spends in each intermediate motion (default fps/5)
    neighbours : each take is compared with itself and the next ``neighbours`` takes of its style
    rep_cycles : whole cycles of each representative take that the interpolation space blends
    progress : show a tqdm bar per stage; prune : ``False`` skips every pruning step (for paper B's ablation)
    backend : ``"local"`` (this process, ``workers`` threads) or ``"ray"``: the comparisons inside
        each style run as Ray tasks (:mod:`.ray_backend`); ``ray_address`` names a running cluster
        (default: ``RAY_ADDRESS``, else a local instance with ``workers`` CPUs). The graph does
        not depend on the backend or the workers

    Returns
    -------
    MotionGraph with ``table`` (structure table and links) and ``info`` (timings, counts,
    ``conditions``, ``stages``: seconds and memory per stage, :class:`.report.StageClock`);
    clips stored style by style, each style's takes side by side.

    Raises
    ------
    GraphError when the clips do not share one skeleton and fps, or ``labels`` does not match them;
    ValueError for an unknown ``backend``; ImportError for ``"ray"`` without Ray installed.
    """
    t0 = time.perf_counter()
    _, fps = check_motions(motions)
    labels = list(labels) if labels is not None else [parse_name(m.name, name_map) for m in motions]
    if len(labels) != len(motions):
        raise GraphError(f"got {len(labels)} labels for {len(motions)} clips")
    opt = _Options(float(threshold), window, int(round(fps / 2)) if min_loop is None else int(min_loop),
                   tuple(weights), style_pairs, reference_style, force,
                   max(1, int(round(fps / 5)) if dwell is None else int(dwell)), neighbours, rep_cycles, progress,
                   prune)  # fmt: skip
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {BACKENDS}, got {backend!r}")
    opt.workers = max(1, int(workers))
    graph = _build(_arrange(motions, labels), opt, synthetic, backend, ray_address)
    graph.info.update(input_clips=len(motions), build_seconds=time.perf_counter() - t0)
    return graph


def _build(arr: _Arranged, opt: _Options, synthetic, backend: str, ray_address) -> MotionGraph:
    """The stages of :func:`build_structured` on the arranged clips, each timed (``info["stages"]``)."""
    notes, seconds, clock = _Notes(), {}, _report.StageClock()
    with _timer(seconds, "cycles_seconds"), clock("cycles"):
        cuts = _cut_takes(arr, notes, opt.progress)
    with _timer(seconds, "registration_seconds"), clock("interpolation spaces"):
        extra, extra_infos, spaces = _interpolation_spaces(arr, cuts, opt)
    graph = MotionGraph.from_motions(arr.motions + extra, _clip_infos(arr, synthetic) + extra_infos)
    arr.motions = []  # the graph holds the frames now
    cmp = _Compare(graph, opt.threshold, opt.window)
    pool_start = functools.partial(_pool_start, graph, arr)
    port_masks = {
        c: s.ports if s is not None else np.zeros(graph.clips[c].num_frames, bool) for c, s in cuts.seg.items()
    }
    with _timer(seconds, "takes_seconds"), _backend(backend, cmp, arr, opt, ray_address, port_masks) as run:
        ports = _link_takes(graph, cmp, arr, port_masks, opt, notes, clock, run)
    table = _structure_table(graph, arr, cuts, opt)
    on_route = np.zeros(graph.num_frames, dtype=bool)
    with _timer(seconds, "links_seconds"), clock("links"):
        _link_styles(graph, cmp, spaces, cuts, pool_start, opt, notes, table, on_route)
        _link_transition_clips(graph, cmp, arr, pool_start, opt, notes, table, on_route)
    with _timer(seconds, "stance_seconds"), clock("links"):
        cmp.comparisons += _link_stances(graph, arr, table, ports, pool_start, opt)
    with clock("pruning"):
        _finish(graph, table, on_route if opt.prune else None)
    graph.info = _info(opt, cmp.comparisons, 0, seconds, len(extra), notes)
    graph.info.update(stages=clock.rows, backend=backend)
    return graph


@contextmanager
def _backend(backend: str, cmp: _Compare, arr: _Arranged, opt: _Options, address: str | None, port_masks: dict):
    """The candidates of every style: :class:`_LocalPools` (``opt.workers`` threads), or for
    ``"ray"`` :func:`.ray_backend.pool_candidates`, every style submitted at once (Ray is started
    here and shut down after, unless running)."""
    if backend == "local":
        local = _LocalPools(cmp, opt, sorted(arr.pools.items()), opt.workers, port_masks)
        try:
            yield local
        finally:
            local.close()
        return
    from motionlab.motion_graphs import ray_backend

    with ray_backend.session(address, opt.workers):
        yield ray_backend.pool_candidates(cmp.graph, sorted(arr.pools.items()), _ring_pairs, opt, style_task)


def _info(opt: _Options, comparisons: int, n_input: int, seconds: dict, n_extra: int, notes: _Notes) -> dict:
    """The build's ``info``: settings, counts, stage seconds and conditions."""
    return dict(
        kind="structured", threshold=opt.threshold, window=opt.window, min_loop=opt.min_loop, dwell=opt.dwell,
        style_pairs=opt.style_pairs, weights=list(opt.weights), neighbours=opt.neighbours,
        rep_cycles=opt.rep_cycles, prune=opt.prune, comparisons=comparisons, input_clips=n_input, **seconds,
        intermediates=n_extra, conditions=notes.lines,
    )  # fmt: skip


def _clip_infos(arr: _Arranged, synthetic: Sequence[bool] | None) -> list[ClipInfo]:
    """One :class:`ClipInfo` per clip in graph order (``synthetic``: per input clip, or ``None``)."""
    return [
        ClipInfo(m.name or label_name(lab), lab.kind, lab.behaviour, lab.style, lab.to_behaviour, lab.to_style,
                 synthetic=bool(synthetic[k]) if synthetic is not None else False, take=lab.take)
        for k, m, lab in zip(arr.order, arr.motions, arr.labels)
    ]  # fmt: skip


def _pool_start(graph: MotionGraph, arr: _Arranged, key: Key) -> int:
    """Global index of the first frame of style ``key``'s pool (route frames count from it)."""
    return graph.clips[arr.pools[key][0]].start


def _finish(graph: MotionGraph, table: dict, on_route: np.ndarray | None) -> None:
    """Intermediate and transition frames live only on recorded routes (all of them when ``on_route``
    is ``None``: no pruning); dead and repeated edges go."""
    for c in graph.clips if on_route is not None else ():
        if c.kind in ("intermediate", "transition"):
            graph.alive[c.start : c.stop] &= on_route[c.start : c.stop]
    graph.drop_dead_edges()
    _dedupe(graph)
    _count_cells(graph, table)
    graph.table = table


@contextmanager
def _timer(seconds: dict, key: str):
    t = time.perf_counter()
    try:
        yield
    finally:
        seconds[key] = time.perf_counter() - t


def _dedupe(graph: MotionGraph) -> None:
    key = graph.src * (graph.num_frames + 1) + graph.dst
    _, first = np.unique(key, return_index=True)
    mask = np.zeros(key.size, dtype=bool)
    mask[first] = True
    graph.keep_edges(mask)


def _bridge_routes(
    graph: MotionGraph, order: list[int], edges: list, dwell: int = 1, s0: int | None = None, t0: int | None = None
):
    """Valid paths through one direction of an interpolation space (paper B §3.3).

    ``order``: clip indices source, M…, target; ``edges[k]``: (src, dst, cost) global arrays from
    ``order[k]`` to ``order[k+1]``; ``s0``, ``t0``: global frames that route exits and entries
    count from (default: the first frames of the source and target clips).

    Returns the routes (best first) and, per ``edges[k]``, the edges kept: those whose
    destination can reach the target (the paper's "remove the first edge of an invalid path").
    """
    costs, choice, kept = _bridge_costs(graph, order, edges, dwell)
    # entries from the source clip
    src, dst, cost = edges[0]
    first_mid = order[1]
    ok = np.isfinite(costs[first_mid][dst - graph.clips[first_mid].start])
    kept[0] = (src[ok], dst[ok], cost[ok])
    s0 = graph.clips[order[0]].start if s0 is None else s0  # exits count from here (the style's first take)
    t0 = graph.clips[order[-1]].start if t0 is None else t0
    routes = [_trace_route(graph, order, edges, choice, int(e), s0, t0) for e in np.flatnonzero(ok)]
    routes.sort(key=lambda r: r["cost"])  # best first: the search keeps the first of equals
    return routes, kept


def _bridge_costs(graph: MotionGraph, order: list[int], edges: list, dwell: int):
    """For every frame of each intermediate clip the fewest frames to reach the target (``inf``
    if it cannot), computed back to front:

    ``cost[f] = min_{f' >= f} (f' - f + 1 + after[f'])``, a reverse running minimum, where
    ``after[f']`` is 0 for an exit into the target and ``cost_next[g]`` for a link to the next
    intermediate frame ``g``; exits count only ``dwell`` frames or more after entering, so a
    route never rushes through the space.

    Returns ``costs`` and ``choice`` (per intermediate clip: the exit frame taken from each frame
    and the edge used at each exit frame), and the edges kept between intermediates.
    """
    n_mid = len(order) - 2
    costs: dict[int, np.ndarray] = {}
    choice: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    kept = [None] * len(edges)
    for pos in range(n_mid, 0, -1):
        clip, nxt = order[pos], order[pos + 1]
        n = graph.clips[clip].num_frames
        src, dst, cost = edges[pos]
        after = np.zeros(src.size) if pos == n_mid else costs[nxt][dst - graph.clips[nxt].start]
        ok = np.isfinite(after)
        kept[pos] = (src[ok], dst[ok], cost[ok])
        local = src[ok] - graph.clips[clip].start
        best_exit = np.full(n, np.inf)
        best_edge = np.full(n, -1, dtype=np.int64)
        for e in np.argsort(after[ok] + 1.0, kind="stable")[::-1]:  # cheapest written last
            best_exit[local[e]] = after[ok][e] + 1.0
            best_edge[local[e]] = np.flatnonzero(ok)[e]
        f = np.arange(n)
        val = f + best_exit  # (f' + 1 + after[f']) - 1 ... minus f below
        run = np.minimum.accumulate(val[::-1])[::-1]
        # index of the exit reached first at the minimum: last position where val equals run, scanning back
        idx = np.where(val == run, f, n)
        exit_at = np.minimum.accumulate(idx[::-1])[::-1]
        # stay at least `dwell` frames in every intermediate motion: exits from f + dwell - 1 on
        later = f + dwell - 1
        inside = later < n
        later = np.minimum(later, n - 1)
        costs[clip] = np.where(inside, run[later] - f, np.inf)
        choice[clip] = (exit_at[later], best_edge)
    return costs, choice, kept


def _trace_route(graph: MotionGraph, order: list[int], edges: list, choice: dict, e: int, s0: int, t0: int) -> dict:
    """The route that enters the space through entry edge ``e`` (of ``edges[0]``)."""
    src, dst, cost = edges[0]
    pieces, worst = [], float(cost[e])
    g = int(dst[e])
    for pos in range(1, len(order) - 1):
        clip = order[pos]
        f = g - graph.clips[clip].start
        exit_at, best_edge = choice[clip]
        x = int(exit_at[f])
        pieces.append([clip, f, x])
        ed = int(best_edge[x])
        _, d_, c_ = edges[pos]
        worst = max(worst, float(c_[ed]))
        g = int(d_[ed])
    return {
        "exit": int(src[e]) - s0,
        "enter": g - t0,
        "pieces": pieces,
        "frames": int(sum(p[2] - p[1] + 1 for p in pieces)),
        "cost": worst,
    }


_LINK_WORDS = {"interpolation": "interp.", "stance": "stance"}
"""How :func:`structure_rows` names a link's kind (else a recorded transition ``clip``)."""


def structure_rows(graph: MotionGraph) -> list[dict]:
    """The structure table as rows (behaviour, style, takes, first frame, frames, alive, links out)."""
    links_out: dict[tuple[str, str], list[str]] = {}
    for link in graph.table.get("links", []):
        links_out.setdefault(tuple(link["from"]), []).append(
            f"{link['to'][0]}/{link['to'][1]} ({_LINK_WORDS.get(link['via'], 'clip')}, {len(link['routes'])})"
        )
    rows = []
    for b, styles in sorted(graph.table.get("behaviours", {}).items()):
        for s, e in sorted(styles.items()):
            rows.append(
                dict(
                    behaviour=b,
                    style=s + (" (synthetic)" if e.get("synthetic") else ""),
                    takes=len(e["takes"]),
                    start=e["start"],
                    frames=e["frames"],
                    alive=e["alive"],
                    links=", ".join(links_out.get((b, s), [])) or "-",
                )
            )
    return rows


def build_wcmg(
    motions: Sequence[Motion],
    threshold: float,
    name_map: Mapping[str, str] | None = None,
    style_pairs: str = "all",
    weights: Sequence[float] = _registration.BLEND_WEIGHTS,
    window: int = _distance.DEFAULT_WINDOW,
) -> MotionGraph:
    """An interpolation-space graph *without* structure or pruning, in the spirit of Zhao and
    Safonova's well-connected motion graphs (wcMG): the basic clips plus their intermediate
    motions, every clip compared with every clip (:func:`graph.build_standard`, ``prune=False``).

    Transition clips are left out (a wcMG has no notion of them). For the connectivity
    comparison of paper B's experiments.

    Raises
    ------
    GraphError when two basic clips share one behaviour and style (takes): a wcMG has one clip per style.
    """
    from motionlab.motion_graphs.graph import build_standard

    t0 = time.perf_counter()
    labels = [parse_name(m.name, name_map) for m in motions]
    keys = [lab.key for lab in labels if lab.kind == "basic"]
    if len(set(keys)) < len(keys):
        twice = sorted({f"{b}_{s}" for b, s in keys if keys.count((b, s)) > 1})
        raise GraphError(f"build_wcmg takes one clip per style; several clips of {', '.join(twice)}")
    basics = {lab.key: m for lab, m in zip(labels, motions) if lab.kind == "basic"}
    by_behaviour: dict[str, list[str]] = {}
    for b, s in basics:
        by_behaviour.setdefault(b, []).append(s)
    all_motions = list(basics.values())
    infos = [ClipInfo(m.name, "basic", b, s) for (b, s), m in basics.items()]
    for b, styles in sorted(by_behaviour.items()):
        lengths = {s: basics[(b, s)].num_frames for s in styles}
        for s1, s2 in _style_pairs(styles, style_pairs, "normal", lengths, 0):
            mids, _ = _registration.interpolation_space(basics[(b, s1)], basics[(b, s2)], weights, window)
            for w, mid in zip(weights, mids):
                if mid.num_frames >= 3:
                    all_motions.append(mid)
                    infos.append(ClipInfo(mid.name, "intermediate", b, f"{s1}~{s2}@{w:g}"))
    g = build_standard(all_motions, threshold, window, prune=False, infos=infos)
    g.info.update(kind="wcmg", intermediates=len(all_motions) - len(basics), build_seconds=time.perf_counter() - t0)
    return g
