r"""The structured motion graph of paper B: a structure table, transition clips and an
interpolation space, pruned while it is built.

**Structure table.** Two levels: behaviour → style → where the clip lies in the graph (its
clip index, global start frame, usable length, self-loops). Beside it, *links* between table
entries, each with the recorded *routes* a search may take (exit frame in the source clip,
the pieces of frames in between, entry frame in the target clip, frame count).

**Between behaviours** only recorded transition clips ``B1_s1_to_B2_s2`` are used. A
transition clip is compared with its two endpoint clips only (never with everything, as a
standard graph would): entries ``A_i → T_{j+1}`` from the first half of ``T``, exits
``T_k → B_{l+1}`` from the second half, so a route always plays the recorded change.

**Between styles of one behaviour** an interpolation space bridges the gap
(:mod:`~motionlab.motion_graphs.registration`): intermediate motions M1…M4 at blend weights
0.2…0.8, and transitions searched only between neighbours S1–M1, M1–M2, …, M4–S2. Which style
pairs are bridged is a choice (``style_pairs``): ``"hub"`` links every style with the
reference style (default ``normal``; the longest clip if that one is too short to loop),
``"chain"`` links styles in name order, ``"all"`` every pair, ``"none"`` builds no
interpolation space (as in the paper's build-time experiment).

**Pruning during construction** (local and fast, no global component search):

* every basic clip first gets its *self-loop points* (transitions back to an earlier frame of
  the same clip, at least ``min_loop`` frames back); the part after the *last* self-loop point
  is cut and every edge into the cut frames is removed, so no walk in a basic clip gets stuck;
* in an interpolation space, a path that enters M1 but cannot reach the target clip through
  M2…M4 is disabled by removing its first edge (and dead links inside are removed); every valid
  path is recorded in the table, in both directions;
* frames of intermediate and transition clips that lie on no recorded route are removed.

When a basic clip has no self-loop under the threshold, the best local minimum is used and the
table marks it ``forced`` (likewise for a transition clip without entries or exits); a clip
with no loop at all is dropped, and ``info["dropped"]`` says why.

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Mapping, Sequence

import numpy as np

from motionlab.core.motion import Motion
from motionlab.motion_graphs import distance as _distance
from motionlab.motion_graphs import registration as _registration
from motionlab.motion_graphs.graph import ClipInfo, GraphError, MotionGraph, check_motions
from motionlab.motion_graphs.naming import ClipLabel, label_name, parse_name

__all__ = ["build_structured", "build_wcmg", "structure_rows", "STYLE_PAIRS"]

STYLE_PAIRS = ("hub", "chain", "all", "none")


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


class _Builder:
    def __init__(self, graph: MotionGraph, feats: list, threshold: float, window: int, dtype):
        self.g = graph
        self.feats = feats
        self.threshold = threshold
        self.window = window
        self.dtype = dtype
        self.comparisons = 0

    def cands(
        self, a: int, b: int | None, rows: int, cols: int | None = None, threshold=None, min_gap=0, row0=0, col0=0
    ):
        fa = self.feats[a]
        fb = None if b is None else self.feats[b]
        cols = rows if cols is None else cols
        self.comparisons += (rows - row0) * (cols - col0)
        return _distance.candidates(
            fa,
            fb,
            self.threshold if threshold is None else threshold,
            self.window,
            min_gap=min_gap,
            rows=slice(row0, rows),
            cols=slice(col0, cols),
        )


def build_structured(
    motions: Sequence[Motion],
    threshold: float,
    name_map: Mapping[str, str] | None = None,
    labels: Sequence[ClipLabel] | None = None,
    window: int = _distance.DEFAULT_WINDOW,
    min_loop: int | None = None,
    weights: Sequence[float] = _registration.BLEND_WEIGHTS,
    style_pairs: str = "hub",
    reference_style: str = "normal",
    force: bool = True,
    synthetic: Sequence[bool] | None = None,
    dwell: int | None = None,
    dtype=np.float64,
) -> MotionGraph:
    """Build the structured motion graph (see the module docstring).

    Parameters
    ----------
    motions : canonical clips (22 joints, one fps), named ``Behaviour_style`` or
        ``B1_s1_to_B2_s2`` (or through ``name_map`` / ``labels``)
    threshold : largest frame distance of a transition, m² (:func:`distance.threshold_from`)
    name_map : ``{clip name: label text}`` for names that do not parse, see :mod:`.naming`
    labels : one :class:`ClipLabel` per clip, instead of parsing names
    window : frames per point cloud
    min_loop : shortest self-loop, frames (default: half a second)
    weights : blend weights of the intermediate motions
    style_pairs : ``"hub"``, ``"chain"``, ``"all"`` or ``"none"`` (which styles get an interpolation space)
    reference_style : the hub style
    force : accept the best local minimum when nothing passes the threshold (marked ``forced``)
    synthetic : per clip, True if it is a synthetic stand-in (shown in tables)
    dwell : fewest frames a style route spends in each intermediate motion (default fps/5)
    dtype : float type of the distance products

    Returns
    -------
    MotionGraph with ``table`` (structure table and links) and ``info`` (timings, counts).
    """
    t0 = time.perf_counter()
    skeleton, fps = check_motions(motions)
    labels = list(labels) if labels is not None else [parse_name(m.name, name_map) for m in motions]
    if len(labels) != len(motions):
        raise GraphError(f"got {len(labels)} labels for {len(motions)} clips")
    synthetic = list(synthetic) if synthetic is not None else [False] * len(motions)
    min_loop = int(round(fps / 2)) if min_loop is None else int(min_loop)
    dwell = max(1, int(round(fps / 5)) if dwell is None else int(dwell))

    basics: dict[tuple[str, str], int] = {}
    for k, lab in enumerate(labels):
        if lab.kind == "basic":
            if lab.key in basics:
                raise GraphError(
                    f"two basic clips are labelled {label_name(lab)}: {motions[basics[lab.key]].name!r} and "
                    f"{motions[k].name!r}; rename one (e.g. a second take as style 'normal-2')"
                )
            basics[lab.key] = k
    transitions = [k for k, lab in enumerate(labels) if lab.kind == "transition"]

    # ---- interpolation spaces: intermediate motions between styles of one behaviour
    t_reg = time.perf_counter()
    by_behaviour: dict[str, list[str]] = {}
    for b, s in basics:
        by_behaviour.setdefault(b, []).append(s)
    extra: list[Motion] = []
    extra_infos: list[ClipInfo] = []
    spaces = []  # (behaviour, s1, s2, [intermediate indices into the final clip list])
    n_input = len(motions)
    positions = {k: motions[k].global_positions() for k in basics.values()}
    tracks: dict[int, _registration.RootTrack] = {}
    for b, styles in sorted(by_behaviour.items()):
        lengths = {s: motions[basics[(b, s)]].num_frames for s in styles}
        for s1, s2 in _style_pairs(styles, style_pairs, reference_style, lengths, 4 * min_loop):
            k1, k2 = basics[(b, s1)], basics[(b, s2)]
            m1, m2 = motions[k1], motions[k2]
            for k in (k1, k2):
                if k not in tracks:
                    tracks[k] = _registration.root_track(motions[k], positions[k])
            reg = _registration.dtw(_distance.distance_matrix(positions[k1], positions[k2], window))
            ids = []
            for w in weights:
                mid = _registration.blend(m1, m2, reg, w, name=f"{b}_{s1}~{s2}@{w:g}", tracks=(tracks[k1], tracks[k2]))
                if mid.num_frames < 3:
                    continue
                ids.append(n_input + len(extra))
                extra.append(mid)
                extra_infos.append(ClipInfo(mid.name, "intermediate", b, f"{s1}~{s2}@{w:g}", b, s2))
            spaces.append((b, s1, s2, ids))
    t_reg = time.perf_counter() - t_reg

    infos = []
    for m, lab, syn in zip(motions, labels, synthetic):
        infos.append(
            ClipInfo(
                m.name or label_name(lab),
                lab.kind,
                lab.behaviour,
                lab.style,
                lab.to_behaviour,
                lab.to_style,
                synthetic=syn,
            )
        )
    all_motions = list(motions) + extra
    graph = MotionGraph.from_motions(all_motions, infos + extra_infos)
    feats = [
        _distance.cloud_features(positions[k] if k in positions else m.global_positions(), window, dtype=dtype)
        for k, m in enumerate(all_motions)
    ]
    bld = _Builder(graph, feats, threshold, window, dtype)
    table: dict = {"behaviours": {}, "links": []}
    info: dict = {"forced": [], "dropped": [], "unused": [], "missing_links": []}
    length: dict[int, int] = {}

    # ---- basic clips: self-loop points, cut after the last one
    for (b, s), k in sorted(basics.items()):
        c = graph.clips[k]
        n = c.num_frames
        i, j, cost = bld.cands(k, None, n, min_gap=min_loop)
        back = j < i
        i, j, cost = i[back], j[back], cost[back]
        forced = False
        if i.size == 0 and force:
            i, j, cost = bld.cands(k, None, n, threshold=np.inf, min_gap=min_loop)
            back = j < i
            i, j, cost = i[back], j[back], cost[back]
            if i.size:
                best = int(np.argmin(cost))
                i, j, cost = i[best : best + 1], j[best : best + 1], cost[best : best + 1]
                forced = True
        if i.size == 0:
            graph.alive[c.start : c.stop] = False
            info["dropped"].append(f"{c.name}: no self-loop point (clip too short for a loop of {min_loop} frames)")
            continue
        last = int(i.max())
        graph.alive[c.start + last + 1 : c.stop] = False
        length[k] = last + 1
        graph.add_edges(c.start + i, c.start + j + 1, cost, "loop")
        if forced:
            info["forced"].append(f"{c.name}: self-loop {last}->{int(j[i == last][0]) + 1} above threshold")
        table["behaviours"].setdefault(b, {})[s] = {
            "clip": k,
            "name": c.name,
            "start": c.start,
            "length": last + 1,
            "last_loop": last,
            "loops": int(i.size),
            "forced": forced,
            "synthetic": bool(c.synthetic),
        }

    # ---- interpolation spaces: neighbours only, validity, recorded routes in both directions
    on_route = np.zeros(graph.num_frames, dtype=bool)
    for b, s1, s2, ids in spaces:
        k1, k2 = basics[(b, s1)], basics[(b, s2)]
        if k1 not in length or k2 not in length or not ids:
            info["missing_links"].append(f"{b}: {s1} <-> {s2} (a clip was dropped)")
            continue
        chain = [k1, *ids, k2]
        fwd, bwd = [], []  # per neighbour pair: (src, dst, cost) global
        for x, y in zip(chain[:-1], chain[1:]):
            nx_, ny_ = length.get(x, graph.clips[x].num_frames), length.get(y, graph.clips[y].num_frames)
            i, j, cost = bld.cands(x, y, nx_, ny_)
            if i.size == 0 and force:
                i, j, cost = bld.cands(x, y, nx_, ny_, threshold=np.inf)
                if i.size:
                    best = int(np.argmin(cost))
                    i, j, cost = i[best : best + 1], j[best : best + 1], cost[best : best + 1]
                    info["forced"].append(f"{graph.clips[x].name} -> {graph.clips[y].name}: best pair above threshold")
            cx, cy = graph.clips[x], graph.clips[y]
            ok = j + 1 < ny_
            fwd.append((cx.start + i[ok], cy.start + j[ok] + 1, cost[ok]))
            ok = i + 1 < nx_
            bwd.append((cy.start + j[ok], cx.start + i[ok] + 1, cost[ok]))
        for direction, edges, order in (("forward", fwd, chain), ("backward", [e for e in reversed(bwd)], chain[::-1])):
            routes, kept = _bridge_routes(graph, order, edges, dwell)
            for src, dst, cost in kept:
                graph.add_edges(src, dst, cost, "bridge")
            a, z = order[0], order[-1]
            for r in routes:
                for clip, f0, f1 in r["pieces"]:
                    st = graph.clips[clip].start
                    on_route[st + f0 : st + f1 + 1] = True
            link = {
                "from": [graph.clips[a].behaviour, graph.clips[a].style],
                "to": [graph.clips[z].behaviour, graph.clips[z].style],
                "via": "interpolation",
                "routes": routes,
            }
            if routes:
                table["links"].append(link)
            else:
                info["missing_links"].append(
                    f"{b}: {graph.clips[a].style} -> {graph.clips[z].style} ({direction}: no valid path)"
                )

    # ---- transition clips: compared with their two endpoint clips only
    for k in transitions:
        c, lab = graph.clips[k], labels[k]
        a, z = basics.get(lab.key), basics.get(lab.to_key)
        if a is None or z is None or a not in length or z not in length:
            missing = (
                label_name(ClipLabel("basic", *lab.key))
                if a is None or a not in length
                else label_name(ClipLabel("basic", *lab.to_key))
            )
            info["unused"].append(f"{c.name}: no basic clip {missing}")
            graph.alive[c.start : c.stop] = False
            continue
        half = c.num_frames // 2
        forced = False
        # entries: A_i ~ T_j, j in the first half
        i, j, cost = bld.cands(a, k, length[a], half)
        if i.size == 0 and force:
            i, j, cost = bld.cands(a, k, length[a], half, threshold=np.inf)
            if i.size:
                best = int(np.argmin(cost))
                i, j, cost = i[best : best + 1], j[best : best + 1], cost[best : best + 1]
                forced = True
        # exits: T_k ~ B_l, k in the second half, l + 1 inside B's usable frames
        ti, tl, tcost = bld.cands(k, z, c.num_frames, length[z] - 1, row0=half)
        if ti.size == 0 and force:
            ti, tl, tcost = bld.cands(k, z, c.num_frames, length[z] - 1, threshold=np.inf, row0=half)
            if ti.size:
                best = int(np.argmin(tcost))
                ti, tl, tcost = ti[best : best + 1], tl[best : best + 1], tcost[best : best + 1]
                forced = True
        if i.size == 0 or ti.size == 0:
            info["unused"].append(f"{c.name}: no entry or exit frames")
            graph.alive[c.start : c.stop] = False
            continue
        if forced:
            info["forced"].append(f"{c.name}: entry or exit above threshold")
        order = np.argsort(ti, kind="stable")
        ti, tl, tcost = ti[order], tl[order], tcost[order]
        ca, cz = graph.clips[a], graph.clips[z]
        routes = []
        for ii, jj, cc in zip(i.tolist(), j.tolist(), cost.tolist()):
            first = jj + 1
            e = int(np.searchsorted(ti, first))  # first exit at or after the entry frame
            if e >= ti.size:
                continue
            routes.append(
                {
                    "exit": ii,
                    "enter": int(tl[e]) + 1,
                    "pieces": [[k, first, int(ti[e])]],
                    "frames": int(ti[e]) - first + 1,
                    "cost": float(max(cc, tcost[e])),
                }
            )
            graph.add_edges([ca.start + ii], [c.start + first], [cc], "clip")
            graph.add_edges([c.start + int(ti[e])], [cz.start + int(tl[e]) + 1], [tcost[e]], "clip")
            on_route[c.start + first : c.start + int(ti[e]) + 1] = True
        if not routes:
            info["unused"].append(f"{c.name}: every entry lies after the last exit")
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

    # ---- intermediate and transition frames live only on recorded routes
    for c in graph.clips:
        if c.kind in ("intermediate", "transition"):
            graph.alive[c.start : c.stop] &= on_route[c.start : c.stop]
    graph.drop_dead_edges()
    # the same pair found twice (e.g. two routes through one exit) is one edge
    _dedupe(graph)
    graph.table = table
    info.update(
        kind="structured",
        threshold=float(threshold),
        window=window,
        min_loop=min_loop,
        dwell=dwell,
        style_pairs=style_pairs,
        weights=list(weights),
        comparisons=bld.comparisons,
        registration_seconds=t_reg,
        intermediates=len(extra),
        build_seconds=time.perf_counter() - t0,
    )
    graph.info = info
    return graph


def _dedupe(graph: MotionGraph) -> None:
    key = graph.src * (graph.num_frames + 1) + graph.dst
    _, first = np.unique(key, return_index=True)
    mask = np.zeros(key.size, dtype=bool)
    mask[first] = True
    graph.keep_edges(mask)


def _bridge_routes(graph: MotionGraph, order: list[int], edges: list, dwell: int = 1):
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
    s0 = graph.clips[order[0]].start
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
        tgt = graph.clips[order[-1]]
        routes.append(
            {
                "exit": int(src[e]) - s0,
                "enter": g - tgt.start,
                "pieces": pieces,
                "frames": int(sum(p[2] - p[1] + 1 for p in pieces)),
                "cost": worst,
            }
        )
    routes.sort(key=lambda r: r["cost"])  # best first: the search keeps the first of equals
    return routes, kept


def structure_rows(graph: MotionGraph) -> list[dict]:
    """The structure table as rows (behaviour, style, clip, start, length, loops, links out)."""
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
                    style=s,
                    clip=e["name"] + (" (synthetic)" if e.get("synthetic") else ""),
                    start=e["start"],
                    length=e["length"],
                    loops=e["loops"],
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
    dtype=np.float64,
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
    g = build_standard(all_motions, threshold, window, prune=False, infos=infos, dtype=dtype)
    g.info.update(kind="wcmg", intermediates=len(all_motions) - len(basics), build_seconds=time.perf_counter() - t0)
    return g
