"""Searching requests: lengths, edges, clear errors, the standard baseline."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab.motion_graphs import distance, graph, search, structured
from tests.motion_graphs.conftest import THRESHOLD

REQUEST = "walk:normal:200,walk:happy:240,run:normal:220,walk:normal:180,walk:happy:200"


def _within(result):
    for req, got in zip(result.requested, result.achieved):
        assert abs(got - req) <= max(2, search.TOLERANCE * req), result.report()


def test_request_is_met_along_edges(sgraph):
    r = search.search(sgraph, REQUEST)
    sgraph.check_path(r.pieces)
    assert r.num_frames == sum(r.achieved) + sum(r.passing)
    _within(r)
    assert [s.behaviour for s in r.segments] == ["walk", "walk", "run", "walk", "walk"]


@pytest.mark.parametrize(
    "request_text", ["walk:happy:38,walk:normal:40", "walk:normal:35,run:normal:40", "walk:normal:80,run:normal:40"]
)
def test_the_first_segment_may_begin_anywhere_in_its_pool(sgraph, request_text):
    """From its pool's first alive frame the first segment could only be 45, 64 or 90 frames
    long (the tolerance refused them); nothing fixes where a motion begins, so other alive frames
    of the pool are tried, and the path from one meets every count."""
    r = search.search(sgraph, request_text)
    sgraph.check_path(r.pieces)
    _within(r)


def test_long_segments_use_loops(sgraph):
    r = search.search(sgraph, [("walk", "happy", 700), ("run", "normal", 650)])
    sgraph.check_path(r.pieces)
    _within(r)


def test_missing_style_and_behaviour(sgraph):
    with pytest.raises(search.SearchError, match=r"no style 'sneaky' of behaviour 'walk'.*normal"):
        search.search(sgraph, "walk:sneaky:100")
    with pytest.raises(search.SearchError, match=r"no behaviour 'fly'"):
        search.search(sgraph, "walk:normal:100,fly:normal:100")


def test_no_transition_clip_is_named(library):
    g = structured.build_structured([m for m in library if "_to_" not in m.name], THRESHOLD)
    with pytest.raises(search.SearchError, match=r"from behaviour 'walk'.*'run'"):
        search.search(g, "walk:normal:100,run:normal:100")


def test_parse_request_errors():
    assert search.parse_request("walk:angry:300, run:normal:200")[1] == search.Segment("run", "normal", 200)
    for bad in ("walk:angry", "walk:angry:x", "walk:angry:0", ""):
        with pytest.raises(ValueError):
            search.parse_request(bad)


def test_loop_guard():
    import numpy as np

    # frames 0..9, one jump back 9 -> 4: from frame 5 the frames 0..3 can never be reached
    cw = search.PoolWalker(0, 10, np.array([True] * 9 + [False]), np.array([9]), np.array([4]), 9, 4)
    with pytest.raises(search.SearchError, match="loop guard"):
        search.walk_to_exit(cw, 5, [2], "clip")
    pieces, r, n = search.walk_to_exit(cw, 5, [2, 7], "clip")
    assert pieces == [(0, 5, 7)] and n == 3 and r == 1
    pieces, r, n = search.walk_to_exit(cw, 8, [5], "clip")  # the way round through the jump
    assert pieces == [(0, 8, 9), (0, 4, 5)] and n == 4


def test_standard_search_follows_edges(library):
    infos = [graph.ClipInfo(m.name, "clip", *m.name.split("_")[:2]) for m in library if "_to_" not in m.name]
    g = graph.build_standard([m for m in library if "_to_" not in m.name], THRESHOLD, infos=infos)
    present = {(c.behaviour, c.style) for c, n in zip(g.clips, range(len(g.clips))) if g.alive[c.start : c.stop].any()}
    req = [(b, s, 60) for b, s in sorted(present)][:2]
    r = search.search_standard(g, req)
    g.check_path(r.pieces)
    assert r.num_frames == sum(r.achieved) + sum(r.passing)


def test_search_crosses_three_styles():
    """happy -> sad has no interpolation space of its own (hub: normal): the path must pass
    through both spaces and the normal takes, and still meet the frame counts."""
    from motionlab.motion_graphs import clips

    styles = {"walk": {k: v for k, v in clips.SYNTHETIC_STYLES["walk"].items() if k in ("normal", "happy", "sad")}}
    g = structured.build_structured(clips.synthetic_library(fps=30.0, seconds=4.0, styles=styles), THRESHOLD)
    assert not any({tuple(l["from"]), tuple(l["to"])} == {("walk", "happy"), ("walk", "sad")} for l in g.table["links"])
    r = search.search(g, "walk:happy:150,walk:sad:150")
    g.check_path(r.pieces)
    _within(r)
    visited = [g.clips[c] for c, _, _ in r.pieces]
    assert {c.style for c in visited if c.kind == "basic"} == {"happy", "normal", "sad"}
    spaces = {c.style.split("@")[0] for c in visited if c.kind == "intermediate"}
    assert spaces == {"normal~happy", "normal~sad"}


def test_request_limit_is_named():
    with pytest.raises(ValueError, match=rf"limit is {search.MAX_FRAMES} frames"):
        search.parse_request("walk:angry:100000000")
    with pytest.raises(ValueError, match="MAX_FRAMES"):
        search.search(None, [("walk", "angry", search.MAX_FRAMES // 2 + 1)] * 2)
    assert search.parse_request(f"walk:angry:{search.MAX_FRAMES}")[0].frames == search.MAX_FRAMES


def test_long_request_is_fast(sgraph):
    import time

    t0 = time.perf_counter()
    r = search.search(sgraph, [("walk", "happy", 30_000), ("walk", "normal", 30_000)])
    assert time.perf_counter() - t0 < 5.0
    assert r.achieved == r.requested
    sgraph.check_path(r.pieces[:50])


def test_walk_takes_the_fewest_jumps():
    import numpy as np

    # two takes of 10 frames side by side (no step 9 -> 10); jumps 5->12, 3->15, 8->11, 2->3
    step = np.array([True] * 9 + [False] + [True] * 9 + [False])
    cw = search.PoolWalker(0, 20, step, np.array([5, 3, 8, 2]), np.array([12, 15, 11, 3]), -1, -1)
    pieces, _, n = search._walk(cw, 0, [15], [-1])
    assert n == 15 and pieces == [(0, 0, 8), (0, 11, 16)]  # one jump; 0..5 -> 12..19 is a frame short
    reach = search._reach(cw, 0, 15)  # the least price of the jumps: JUMP_FRAMES per jump
    assert reach[14].min() == search.JUMP_FRAMES and reach[5, 5] == 0 and reach[6, 12] == search.JUMP_FRAMES


def _reach_by_hand(step, src, dst, price, start, rows):
    n = step.size
    ref = np.full((rows, n), np.inf, dtype=np.float32)
    ref[0, start] = 0
    for c in range(1, rows):
        for f in range(n):
            best = ref[c - 1, f - 1] if f > 0 and step[f - 1] else np.inf
            for s, d, p in zip(src, dst, price):
                if d == f:
                    best = min(best, ref[c - 1, s] + p)
            ref[c, f] = best
    return ref


def test_reach_with_few_jumps_per_frame_matches_the_recursion():
    """The per-layer recursion (at most SPARSE_JUMPS jumps into a frame) and the grouped one
    (any number) both give the least price of the jumps of every walk length, as a loop by hand
    does (prices drawn at random, as a search cost may give)."""
    rng = np.random.default_rng(3)
    n = 30
    step = rng.random(n) < 0.8
    step[-1] = False
    src, dst = rng.integers(0, n, 40), rng.integers(0, n, 40)
    price = rng.uniform(0.5, 12.0, 40).astype(np.float32)
    order = np.argsort(dst, kind="stable")
    rank = np.arange(40) - np.searchsorted(dst[order], dst[order])
    few = order[rank < search.SPARSE_JUMPS]
    assert rank.max() >= search.SPARSE_JUMPS  # the full set takes the grouped path
    cw = search.PoolWalker(0, n, step, src, dst, -1, -1, price=price)
    for s, d, p in ((src[few], dst[few], price[few]), (src, dst, price)):
        got = search._reach(cw, 2, 25, (s, d, p))
        np.testing.assert_array_equal(got, _reach_by_hand(step, s, d, p, 2, 25))


def test_frames_through_other_styles_are_reported_apart(sgraph):
    r = search.search(sgraph, REQUEST)
    # walk/happy -> run/normal passes through other styles (no recorded clip leaves walk/happy)
    assert len(r.passing) == len(r.requested) and sum(r.passing) > 0
    assert r.num_frames == sum(r.achieved) + sum(r.passing)
    k = next(k for k, p in enumerate(r.passing) if p)
    assert f"then {r.passing[k]} frames through other styles" in r.report()
    assert r.pieces_per_second(sgraph.fps) == pytest.approx(len(r.pieces) * sgraph.fps / r.num_frames)


def test_fewest_jumps_within_the_tolerance():
    # frames 0..9, one jump back 9 -> 0: 12 frames from frame 0 need the jump, 10 frames do not
    cw = search.PoolWalker(0, 10, np.array([True] * 9 + [False]), np.array([9]), np.array([0]), 9, 0)
    pieces, _, n = search._walk(cw, 0, [12], [-1], slack=0)
    assert n == 12 and len(pieces) == 2
    pieces, _, n = search._walk(cw, 0, [12], [-1], slack=2)  # 2 frames short costs less than a jump
    assert n == 10 and pieces == [(0, 0, 9)]


def test_pool_walker_of_a_style(sgraph):
    cell = sgraph.table["behaviours"]["walk"]["normal"]
    cw = search.pool_walker(sgraph, "walk", "normal")
    assert cw.length == cell["frames"] and cw.alive.sum() == cell["alive"]
    with pytest.raises(search.SearchError, match="walk/sneaky"):
        search.pool_walker(sgraph, "walk", "sneaky")


def _without_jumps_inside(g, behaviour, style):
    """A copy of ``g`` without the edges inside one style's pool (its takes can only be played on)."""
    cw = search.pool_walker(g, behaviour, style)
    st = g.clips[int(cw.clips[0])].start
    inside = (g.src >= st) & (g.src < st + cw.length) & (g.dst >= st) & (g.dst < st + cw.length)
    out = g.copy()
    out.keep_edges(~inside)
    return out, ~inside


def test_search_sees_edges_dropped_after_an_earlier_search(sgraph):
    """Issue 44: a planner kept in the graph answered from the edges of an earlier search."""
    g = sgraph.copy()
    before = search.search(g, "walk:normal:300")
    assert before.num_frames == 300
    fresh, keep = _without_jumps_inside(sgraph, "walk", "normal")
    g.keep_edges(keep)
    after = search.search(g, "walk:normal:300")
    assert after.pieces == search.search(fresh, "walk:normal:300").pieces
    assert after.num_frames < 300  # one take, no jump back: it ends before 300 frames
    g.check_path(after.pieces)


def test_a_planner_refuses_a_changed_graph(sgraph):
    g = sgraph.copy()
    planner = search.Planner(g)
    first = planner.search(REQUEST)
    assert planner.search(REQUEST).pieces == first.pieces == search.search(g, REQUEST).pieces
    g.drop_dead_edges()  # new edge arrays, even when no edge is dropped
    with pytest.raises(search.SearchError, match="graph changed since this Planner was made"):
        planner.search(REQUEST)


def test_standard_search_sees_edges_dropped_after_an_earlier_search(library):
    infos = [graph.ClipInfo(m.name, "clip", *m.name.split("_")[:2]) for m in library if "_to_" not in m.name]
    # at 0.05 m both walks survive the pruning, joined by transitions
    g = graph.build_standard([m for m in library if "_to_" not in m.name], distance.threshold_from(0.05), infos=infos)
    req = [("walk", "normal", 60), ("walk", "happy", 60)]
    search.search_standard(g, req)
    crossing = g.clip_of(g.src) != g.clip_of(g.dst)
    g.keep_edges(~crossing)  # no way left between clips
    with pytest.raises(search.SearchError, match=f"no path in the graph to {req[1][0]}/{req[1][1]}"):
        search.search_standard(g, req)


# ---------------------------------------------------------------------------- search costs
def no_jump_price(graph, edges):
    """A search cost written outside the package: a jump costs nothing beyond its frame."""
    return np.zeros(len(edges))


def test_a_search_cost_from_outside_changes_the_path(sgraph):
    """Issue 44: a course tries a search cost without touching the package."""
    from motionlab import motion_graphs

    default = motion_graphs.search_path(sgraph, REQUEST)
    free = motion_graphs.search_path(sgraph, REQUEST, cost=no_jump_price)
    sgraph.check_path(free.pieces)
    # the default trades a few frames off the request for fewer jumps (8 frames each) ...
    assert default.achieved != default.requested
    # ... with jumps free, a frame off the request is the only cost: every length is met exactly
    assert free.achieved == free.requested
    assert len(free.pieces) > len(default.pieces)
    assert motion_graphs.Planner(sgraph, cost=no_jump_price).search(REQUEST).pieces == free.pieces


def test_the_default_cost_is_frames_and_jump_frames(sgraph):
    assert search.search(sgraph, REQUEST, cost=search.default_cost).pieces == search.search(sgraph, REQUEST).pieces
    edges = np.arange(5)
    np.testing.assert_array_equal(search.default_cost(sgraph, edges), np.full(5, search.JUMP_FRAMES))


def test_a_cost_reads_the_jumps_it_prices(sgraph):
    seen = []

    def by_pose_distance(graph, edges):
        seen.append(edges)
        return 2.0 + 1e4 * graph.cost[edges]  # m² -> frames: closer poses are cheaper jumps

    r = search.search(sgraph, REQUEST, cost=by_pose_distance)
    sgraph.check_path(r.pieces)
    _within(r)
    edges = np.concatenate(seen)
    assert edges.size and edges.min() >= 0 and edges.max() < sgraph.src.size


@pytest.mark.parametrize(
    "bad",
    [lambda g, e: -np.ones(len(e)), lambda g, e: np.full(len(e), np.nan), lambda g, e: np.zeros(len(e) + 1)],
)
def test_a_bad_cost_is_named(sgraph, bad):
    with pytest.raises(ValueError, match="search cost .* one finite price >= 0"):
        search.search(sgraph, REQUEST, cost=bad)


def test_a_jump_price_below_one_frame_off_meets_the_length():
    # frames 0..9, one jump back 9 -> 0 (the loop-guard walker): 12 frames from frame 0
    step = np.array([True] * 9 + [False])
    for price, frames in ((search.JUMP_FRAMES, 10), (1.0, 12)):
        cw = search.PoolWalker(0, 10, step, np.array([9]), np.array([0]), 9, 0, price=np.float32([price]))
        _, _, n = search._walk(cw, 0, [12], [-1], slack=2)
        assert n == frames  # 2 frames short cost less than a jump of 8, more than one of 1


def test_a_price_beyond_float32_is_refused_not_read_as_no_jump(sgraph):
    with pytest.raises(ValueError, match="finite price >= 0 and at most"):
        search.search(sgraph, "walk:normal:60", cost=lambda g, e: np.full(np.shape(e), 1e39))
