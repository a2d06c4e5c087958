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

Conditions met on the way (a take pruned, a forced pair, a missing link, an unused transition
clip) are collected in ``info["conditions"]`` and counted once in the build report
(:mod:`.report`).

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Mapping, Sequence

import numpy as np

from motionlab.core.motion import Motion
from motionlab.motion_graphs import cycles as _cycles
from motionlab.motion_graphs import distance as _distance
from motionlab.motion_graphs import registration as _registration
from motionlab.motion_graphs import segments as _segments
from motionlab.motion_graphs import stance_links as _stance_links
from motionlab.motion_graphs.graph import EDGE_KINDS, ClipInfo, GraphError, MotionGraph, check_motions, pair_edges
from motionlab.motion_graphs.naming import ClipLabel, label_name, parse_name

__all__ = ["build_structured", "build_wcmg", "structure_rows", "STYLE_PAIRS"]

STYLE_PAIRS = ("hub", "chain", "all", "none")

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
    window : frames per point cloud
    min_loop : shortest jump back within one take, frames (default: half a second)
    weights : blend weights of the intermediate motions
    style_pairs : ``"hub"``, ``"chain"``, ``"all"`` or ``"none"`` (which styles get an interpolation space)
    reference_style : the hub style
    force : accept the best local minimum when nothing passes the threshold inside an
        interpolation space or a transition clip (counted as ``forced``)
    synthetic : per clip, True if it is a synthetic stand-in (shown in tables)
    dwell : fewest frames a style route spends in each intermediate motion (default fps/5)
    neighbours : each take is compared with itself and the next ``neighbours`` takes of its style
    rep_cycles : whole cycles of each representative take that the interpolation space blends
    progress : show a tqdm bar per stage

    Returns
    -------
    MotionGraph with ``table`` (structure table and links) and ``info`` (timings, counts,
    ``conditions``). Clips are stored style by style, each style's takes side by side (their
    order in the graph is not the input order).
    """
    t0 = time.perf_counter()
    skeleton, fps = check_motions(motions)
    labels = list(labels) if labels is not None else [parse_name(m.name, name_map) for m in motions]
    if len(labels) != len(motions):
        raise GraphError(f"got {len(labels)} labels for {len(motions)} clips")
    synthetic = list(synthetic) if synthetic is not None else [False] * len(motions)
    min_loop = int(round(fps / 2)) if min_loop is None else int(min_loop)
    dwell = max(1, int(round(fps / 5)) if dwell is None else int(dwell))
    notes = _Notes()

    # ---- pools: the takes of each (behaviour, style), stored side by side
    pools_in: dict[tuple[str, str], list[int]] = {}
    for k, lab in enumerate(labels):
        if lab.kind == "basic":
            pools_in.setdefault(lab.key, []).append(k)
    for key in pools_in:
        pools_in[key].sort(key=lambda k: (labels[k].take or "", k))
    order = [k for key in sorted(pools_in) for k in pools_in[key]]
    order += [k for k, lab in enumerate(labels) if lab.kind == "transition"]
    where = {k: n for n, k in enumerate(order)}  # input index -> graph clip index
    pools = {key: [where[k] for k in ks] for key, ks in pools_in.items()}
    transitions = [where[k] for k, lab in enumerate(labels) if lab.kind == "transition"]
    glabels = [labels[k] for k in order]
    gmotions = [motions[k] for k in order]
    take_frames = [m.num_frames for m in gmotions]

    # ---- cycles and representative cycles of every style
    t_cyc = time.perf_counter()
    cyc, seg, cuts = {}, {}, {}
    for _key, ks in _progress(sorted(pools.items()), "cycles", enabled=progress):
        for c in ks:
            try:
                cyc[c] = _cycles.segment_cycles(gmotions[c])
                seg[c] = _segments.segment_take(gmotions[c])
            except ValueError:
                cyc[c] = seg[c] = None
            # a gait is cut into whole cycles, a standing action into segments between stances
            cuts[c] = seg[c] if seg[c] is not None and seg[c].kind == "action" else cyc[c]
    rep: dict[tuple[str, str], int] = {}
    for key, ks in pools.items():
        # the take with the most whole cycles or segments (ties: the first take) represents the style
        rep[key] = max(ks, key=lambda c: (cuts[c].count if cuts[c] is not None else -1, -c))
        if cuts[rep[key]] is None or cuts[rep[key]].count == 0:
            notes.add("no whole cycle", f"{gmotions[rep[key]].name}: the whole take represents its style")

    def rep_span(key, n: int) -> tuple[int, int]:
        """``n`` whole cycles (or segments) from the middle of the representative take (all of it without)."""
        cy = cuts[rep[key]]
        if cy is None or cy.count == 0:
            return (0, take_frames[rep[key]])
        n = min(n, cy.count)
        mid = (cy.count - n) // 2
        return int(cy.bounds[mid, 0]), int(cy.bounds[mid + n - 1, 1])

    def rep_count(key) -> int:
        cy = cuts[rep[key]]
        return rep_cycles if cy is None or cy.count == 0 else min(rep_cycles, cy.count)

    t_cyc = time.perf_counter() - t_cyc

    # ---- interpolation spaces between representative cycles of styles of one behaviour
    t_reg = time.perf_counter()
    by_behaviour: dict[str, list[str]] = {}
    for b, s in pools:
        by_behaviour.setdefault(b, []).append(s)
    extra: list[Motion] = []
    extra_infos: list[ClipInfo] = []
    spaces = []  # (behaviour, s1, s2, [intermediate clip indices])
    n_input = len(gmotions)
    pairs_todo = []
    for b, styles in sorted(by_behaviour.items()):
        lengths = {s: gmotions[rep[(b, s)]].num_frames for s in styles}
        pairs_todo += [(b, s1, s2) for s1, s2 in _style_pairs(styles, style_pairs, reference_style, lengths, 0)]
    for b, s1, s2 in _progress(pairs_todo, "interpolation spaces", enabled=progress):
        # the same number of whole cycles of both styles, so registration pairs cycle with cycle
        n = min(rep_count((b, s1)), rep_count((b, s2)))
        cut = []
        for key in ((b, s1), (b, s2)):
            f0, f1 = rep_span(key, n)
            m = gmotions[rep[key]][f0:f1]
            pos = m.global_positions()
            cut.append((m, pos, _registration.root_track(m, pos)))
        (m1, p1, r1), (m2, p2, r2) = cut
        # the registration must cover (nearly) both spans: 90% of the longer one
        reg = _registration.dtw(_distance.distance_matrix(p1, p2, window), int(0.9 * max(len(p1), len(p2))))
        ids = []
        for w in weights:
            mid = _registration.blend(m1, m2, reg, w, name=f"{b}_{s1}~{s2}@{w:g}", tracks=(r1, r2))
            if mid.num_frames < 3:
                continue
            ids.append(n_input + len(extra))
            extra.append(mid)
            extra_infos.append(ClipInfo(mid.name, "intermediate", b, f"{s1}~{s2}@{w:g}", b, s2))
        spaces.append((b, s1, s2, ids))
    t_reg = time.perf_counter() - t_reg

    infos = [
        ClipInfo(m.name or label_name(lab), lab.kind, lab.behaviour, lab.style, lab.to_behaviour, lab.to_style,
                 synthetic=bool(synthetic[k]), take=lab.take)
        for k, m, lab in zip(order, gmotions, glabels)
    ]  # fmt: skip
    graph = MotionGraph.from_motions(gmotions + extra, infos + extra_infos)
    del gmotions
    clips = graph.clips
    comparisons = 0
    feats_cache: dict[int, _distance.CloudFeatures] = {}

    def feats(c: int) -> _distance.CloudFeatures:
        if c not in feats_cache:
            st, sp = clips[c].start, clips[c].stop
            m = Motion(graph.skeleton, graph.local_rot[st:sp], graph.root_pos[st:sp], graph.fps, None, clips[c].name)
            feats_cache[c] = _distance.cloud_features(m.global_positions(), window)
        return feats_cache[c]

    def cands(x, y, rows=None, cols=None, thr=None, min_gap=0):
        nonlocal comparisons
        fa, fb = feats(x), (None if y is None else feats(y))
        r = rows or slice(0, len(fa))
        cl = cols or slice(0, len(fb if fb is not None else fa))
        comparisons += (r.stop - r.start) * (cl.stop - cl.start)
        return _distance.candidates(fa, fb, threshold if thr is None else thr, window, min_gap, r, cl)

    # ---- within each style: every take with itself and its neighbouring takes
    t_pool = time.perf_counter()
    table: dict = {"behaviours": {}, "links": []}
    loop_kind = EDGE_KINDS.index("loop")
    ports: dict = {}
    port_masks = {c: (s.ports if s is not None else np.zeros(clips[c].num_frames, dtype=bool)) for c, s in seg.items()}
    for key, ks in _progress(sorted(pools.items()), "takes", enabled=progress):
        found = {"loop": [], "transition": []}  # (src, dst, cost) global, added at once
        for c in ks:
            i, j, cost = cands(c, None, min_gap=min_loop)
            ok = j + 1 < clips[c].num_frames
            found["loop"].append((clips[c].start + i[ok], clips[c].start + j[ok] + 1, cost[ok]))
        for x, y in _ring_pairs(len(ks), neighbours):
            a, z = ks[x], ks[y]
            i, j, cost = cands(a, z)
            src, dst, which = pair_edges(i, j, clips[a].start, clips[z].start, clips[z].num_frames,
                                         clips[a].num_frames, False)  # fmt: skip
            found["transition"].append((src, dst, cost[which]))
        # takes connect stance to stance: every take's ports with every other take's
        found["transition"].append(
            _stance_links.link_within(graph, _stance_links.port_features(graph, ks, port_masks, feats), threshold,
                                      min_loop, window)
        )  # fmt: skip
        for kind, parts in found.items():
            if parts:
                graph.add_edges(*(np.concatenate(p) for p in zip(*parts)), kind)
        for c in ks:
            if c != rep[key]:
                feats_cache.pop(c, None)
        # pruning: keep the largest strongly connected part of the style's takes
        st, sp = clips[ks[0]].start, clips[ks[-1]].stop
        mask = np.zeros(graph.num_frames, dtype=bool)
        mask[st:sp] = True
        keep = graph.largest_component(mask)
        if not keep[st:sp].any() and force:
            # no cycle under the threshold: the best jump back inside a take (a forced loop)
            best = None
            for c in ks:
                i, j, cost = cands(c, None, thr=np.inf, min_gap=min_loop)
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
        ports[key] = _stance_links.port_features(graph, ks, port_masks, feats)
    graph.drop_dead_edges()
    t_pool = time.perf_counter() - t_pool

    def pool_start(key) -> int:
        return clips[pools[key][0]].start

    for (b, s), ks in sorted(pools.items()):
        st, sp = clips[ks[0]].start, clips[ks[-1]].stop
        live = graph.alive[graph.src] & graph.alive[graph.dst]
        inside = live & (graph.src >= st) & (graph.src < sp) & (graph.dst >= st) & (graph.dst < sp)
        takes = []
        for c in ks:
            ci, cy = clips[c], cyc[c]
            takes.append(
                {
                    "clip": c,
                    "name": ci.name,
                    "take": ci.take,
                    "offset": ci.start - st,
                    "frames": ci.num_frames,
                    "alive": int(graph.alive[ci.start : ci.stop].sum()),
                    "cycles": 0 if cy is None else cy.count,
                    "cycle_span": [0, 0] if cy is None else list(cy.span),
                    "kind": None if seg[c] is None else seg[c].kind,
                    "segments": 0 if seg[c] is None else seg[c].count,
                    "stances": 0 if seg[c] is None else int(seg[c].stances.shape[0]),
                }
            )
        kinds = [t["kind"] for t in takes if t["kind"] is not None]
        table["behaviours"].setdefault(b, {})[s] = {
            "kind": max(sorted(set(kinds)), key=kinds.count) if kinds else None,
            "start": st,
            "frames": sp - st,
            "alive": int(graph.alive[st:sp].sum()),
            "takes": takes,
            "representative": rep[(b, s)],
            "representative_cycles": list(rep_span((b, s), rep_cycles)),
            "transitions": int(inside.sum()),
            "loops": int((inside & (graph.kind == loop_kind)).sum()),
            "synthetic": bool(any(clips[c].synthetic for c in ks)),
        }

    # ---- interpolation spaces: neighbours only, validity, recorded routes in both directions
    t_links = time.perf_counter()
    on_route = np.zeros(graph.num_frames, dtype=bool)
    for b, s1, s2, ids in _progress(spaces, "style links", enabled=progress):
        k1, k2 = rep[(b, s1)], rep[(b, s2)]
        if not ids:
            notes.add("missing link", f"{b}: {s1} <-> {s2} (no intermediate motion)")
            continue
        chain = [k1, *ids, k2]
        fwd, bwd = [], []  # per neighbour pair: (src, dst, cost) global
        for x, y in zip(chain[:-1], chain[1:]):
            cx, cy_ = clips[x], clips[y]
            i, j, cost = cands(x, y)
            # both ends must be alive frames of the (pruned) style takes
            ok = graph.alive[cx.start + i] & graph.alive[cy_.start + j]
            i, j, cost = i[ok], j[ok], cost[ok]
            if i.size == 0 and force:
                i, j, cost = cands(x, y, thr=np.inf)
                ok = graph.alive[cx.start + i] & graph.alive[cy_.start + j]
                i, j, cost = i[ok], j[ok], cost[ok]
                if i.size:
                    i, j, cost = _best_only(i, j, cost)
                    notes.add("forced", f"{cx.name} -> {cy_.name}: best pair above threshold")
            ok = (j + 1 < cy_.num_frames) & graph.alive[np.minimum(cy_.start + j + 1, cy_.stop - 1)]
            fwd.append((cx.start + i[ok], cy_.start + j[ok] + 1, cost[ok]))
            ok = (i + 1 < cx.num_frames) & graph.alive[np.minimum(cx.start + i + 1, cx.stop - 1)]
            bwd.append((cy_.start + j[ok], cx.start + i[ok] + 1, cost[ok]))
        for direction, edges, seq in (("forward", fwd, chain), ("backward", list(reversed(bwd)), chain[::-1])):
            sa, sz = (s1, s2) if direction == "forward" else (s2, s1)
            routes, kept = _bridge_routes(graph, seq, edges, dwell, pool_start((b, sa)), pool_start((b, sz)))
            for src, dst, cost in kept:
                graph.add_edges(src, dst, cost, "bridge")
            for r in routes:
                for clip, f0, f1 in r["pieces"]:
                    st = clips[clip].start
                    on_route[st + f0 : st + f1 + 1] = True
            if routes:
                table["links"].append({"from": [b, sa], "to": [b, sz], "via": "interpolation", "routes": routes})
            else:
                notes.add("missing link", f"{b}: {sa} -> {sz} ({direction}: no valid path through the space)")

    # ---- transition clips: compared with the takes of their two endpoint styles only
    clip_edges: list[tuple[int, int, float]] = []
    for k in _progress(transitions, "transition clips", enabled=progress):
        c, lab = clips[k], glabels[k]
        if lab.key not in pools or lab.to_key not in pools:
            missing = lab.key if lab.key not in pools else lab.to_key
            notes.add("unused transition clip", f"{c.name}: no basic clip {missing[0]}_{missing[1]}")
            graph.alive[c.start : c.stop] = False
            continue
        half = c.num_frames // 2
        forced = False
        ent = []  # (pool-local exit frame, transition frame entered, cost)
        for a in pools[lab.key]:
            i, j, cost = cands(a, k, cols=slice(0, half))
            ok = graph.alive[clips[a].start + i]
            ent.append((clips[a].start + i[ok] - pool_start(lab.key), j[ok] + 1, cost[ok]))
        ei, ej, ec = (np.concatenate(x) for x in zip(*ent))
        ext = []  # (transition frame left, pool-local target frame entered, cost)
        for z in pools[lab.to_key]:
            cz = clips[z]
            i, j, cost = cands(k, z, rows=slice(half, c.num_frames), cols=slice(0, cz.num_frames - 1))
            ok = graph.alive[cz.start + j + 1]
            ext.append((i[ok], cz.start + j[ok] + 1 - pool_start(lab.to_key), cost[ok]))
        xi, xj, xc = (np.concatenate(x) for x in zip(*ext))
        if force and ei.size == 0:
            ent = []
            for a in pools[lab.key]:
                i, j, cost = cands(a, k, cols=slice(0, half), thr=np.inf)
                ok = graph.alive[clips[a].start + i]
                ent.append((clips[a].start + i[ok] - pool_start(lab.key), j[ok] + 1, cost[ok]))
            ei, ej, ec = _best_only(*(np.concatenate(x) for x in zip(*ent)))
            forced = True
        if force and xi.size == 0:
            ext = []
            for z in pools[lab.to_key]:
                cz = clips[z]
                i, j, cost = cands(k, z, rows=slice(half, c.num_frames), cols=slice(0, cz.num_frames - 1), thr=np.inf)
                ok = graph.alive[cz.start + j + 1]
                ext.append((i[ok], cz.start + j[ok] + 1 - pool_start(lab.to_key), cost[ok]))
            xi, xj, xc = _best_only(*(np.concatenate(x) for x in zip(*ext)))
            forced = True
        if ei.size == 0 or xi.size == 0:
            notes.add("unused transition clip", f"{c.name}: no entry or exit frames")
            graph.alive[c.start : c.stop] = False
            continue
        if forced:
            notes.add("forced", f"{c.name}: entry or exit above threshold")
        srt = np.argsort(xi, kind="stable")
        xi, xj, xc = xi[srt], xj[srt], xc[srt]
        p0, p1 = pool_start(lab.key), pool_start(lab.to_key)
        routes = []
        for ii, first, cc in zip(ei.tolist(), ej.tolist(), ec.tolist()):
            e = int(np.searchsorted(xi, first))  # first exit at or after the entry frame
            if e >= xi.size:
                continue
            routes.append(
                {
                    "exit": ii,
                    "enter": int(xj[e]),
                    "pieces": [[k, first, int(xi[e])]],
                    "frames": int(xi[e]) - first + 1,
                    "cost": float(max(cc, xc[e])),
                }
            )
            clip_edges.append((p0 + ii, c.start + first, cc))
            clip_edges.append((c.start + int(xi[e]), p1 + int(xj[e]), float(xc[e])))
            on_route[c.start + first : c.start + int(xi[e]) + 1] = True
        if not routes:
            notes.add("unused transition clip", f"{c.name}: every entry lies after the last exit")
            continue
        routes.sort(key=lambda r: r["cost"])
        table["links"].append(
            {
                "from": list(lab.key),
                "to": list(lab.to_key),
                "via": f"transition clip {c.name}",
                "clip": k,
                "routes": routes,
                "forced": forced,
            }
        )
    if clip_edges:
        src, dst, cost = (np.array(x) for x in zip(*clip_edges))
        graph.add_edges(src, dst, cost, "clip")
    t_links = time.perf_counter() - t_links

    # ---- stance links: Kovar transitions between the ports of styles and behaviours
    t_stance = time.perf_counter()
    recorded = {(link["from"][0], link["to"][0]) for link in table["links"] if link["via"] != "interpolation"}
    kinds = {(b, s): cell["kind"] for b, cells in table["behaviours"].items() for s, cell in cells.items()}
    pairs = _stance_links.pool_pairs(list(pools), recorded, kinds)
    links, (src, dst, cost), n_cmp = _stance_links.link_pools(graph, pairs, ports, pool_start, threshold, window)
    comparisons += n_cmp
    graph.add_edges(src, dst, cost, "transition")
    table["links"].extend(links)
    del ports
    t_stance = time.perf_counter() - t_stance

    # ---- intermediate and transition frames live only on recorded routes
    for c in clips:
        if c.kind in ("intermediate", "transition"):
            graph.alive[c.start : c.stop] &= on_route[c.start : c.stop]
    graph.drop_dead_edges()
    _dedupe(graph)
    graph.table = table
    graph.info = dict(
        kind="structured",
        threshold=float(threshold),
        window=window,
        min_loop=min_loop,
        dwell=dwell,
        style_pairs=style_pairs,
        weights=list(weights),
        neighbours=neighbours,
        rep_cycles=rep_cycles,
        comparisons=comparisons,
        input_clips=len(motions),
        cycles_seconds=t_cyc,
        registration_seconds=t_reg,
        takes_seconds=t_pool,
        links_seconds=t_links,
        stance_seconds=t_stance,
        intermediates=len(extra),
        conditions=notes.lines,
        build_seconds=time.perf_counter() - t0,
    )
    return graph


def _dedupe(graph: MotionGraph) -> None:
    key = graph.src * (graph.num_frames + 1) + graph.dst
    _, first = np.unique(key, return_index=True)
    mask = np.zeros(key.size, dtype=bool)
    mask[first] = True
    graph.keep_edges(mask)


def _bridge_routes(
    graph: MotionGraph, order: list[int], edges: list, dwell: int = 1, s0: int | None = None, t0: int | None = None
):
    """Valid paths through one direction of an interpolation space.

    ``order``: clip indices source, M…, target; ``edges[k]``: (src, dst, cost) global arrays from
    ``order[k]`` to ``order[k+1]``. For every frame of an intermediate clip the fewest frames
    to reach the target (``inf`` if it cannot) are computed back to front:

    ``cost[f] = min_{f' >= f} (f' - f + 1 + after[f'])``, a reverse running minimum, where
    ``after[f']`` is 0 for an exit into the target and ``cost_next[g]`` for a link to the next
    intermediate frame ``g``; exits count only ``dwell`` frames or more after entering, so a
    route never rushes through the space. Links whose destination cannot reach the target are dropped; an
    entry from the source survives only if its destination can (the paper's "remove the first
    edge of an invalid path").
    """
    n_mid = len(order) - 2
    costs: dict[int, np.ndarray] = {}
    choice: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    kept = [None] * len(edges)
    for pos in range(n_mid, 0, -1):
        clip = order[pos]
        c = graph.clips[clip]
        n = c.num_frames
        src, dst, cost = edges[pos]
        nxt = order[pos + 1]
        if pos == n_mid:
            after = np.zeros(src.size)
        else:
            after = costs[nxt][dst - graph.clips[nxt].start]
        ok = np.isfinite(after)
        kept[pos] = (src[ok], dst[ok], cost[ok])
        local = src[ok] - c.start
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
    # entries from the source clip
    src, dst, cost = edges[0]
    first_mid = order[1]
    reach = costs[first_mid][dst - graph.clips[first_mid].start]
    ok = np.isfinite(reach)
    kept[0] = (src[ok], dst[ok], cost[ok])
    routes = []
    s0 = graph.clips[order[0]].start if s0 is None else s0  # exits count from here (the style's first take)
    t0 = graph.clips[order[-1]].start if t0 is None else t0
    for e in np.flatnonzero(ok):
        pieces, worst = [], float(cost[e])
        g = int(dst[e])
        pos = 1
        while pos <= n_mid:
            clip = order[pos]
            c = graph.clips[clip]
            f = g - c.start
            exit_at, best_edge = choice[clip]
            x = int(exit_at[f])
            pieces.append([clip, f, x])
            ed = int(best_edge[x])
            s_, d_, c_ = edges[pos]
            worst = max(worst, float(c_[ed]))
            g = int(d_[ed])
            pos += 1
        routes.append(
            {
                "exit": int(src[e]) - s0,
                "enter": g - t0,
                "pieces": pieces,
                "frames": int(sum(p[2] - p[1] + 1 for p in pieces)),
                "cost": worst,
            }
        )
    routes.sort(key=lambda r: r["cost"])  # best first: the search keeps the first of equals
    return routes, kept


def structure_rows(graph: MotionGraph) -> list[dict]:
    """The structure table as rows (behaviour, style, takes, first frame, frames, alive, links out)."""
    links_out: dict[tuple[str, str], list[str]] = {}
    for link in graph.table.get("links", []):
        links_out.setdefault(tuple(link["from"]), []).append(
            f"{link['to'][0]}/{link['to'][1]} ({'interp.' if link['via'] == 'interpolation' else 'clip'}, {len(link['routes'])})"
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
    """
    from motionlab.motion_graphs.graph import build_standard

    t0 = time.perf_counter()
    labels = [parse_name(m.name, name_map) for m in motions]
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
