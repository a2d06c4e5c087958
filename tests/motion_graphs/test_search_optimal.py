"""The walks through a pool are the cheapest over every jump, although the search tries the
cheapest jumps into each frame first: known answers from loops by hand on random pools (prices
drawn at random, as a search cost may give, and one price for all, as the default cost), and on
real takes."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from motionlab.motion_graphs import search
from tests.motion_graphs.conftest import session_walk_takes


def _pool(seed: int, uniform: bool):
    """A random pool whose walker tries the SPARSE_JUMPS cheapest jumps into each frame first,
    as the search's walkers do."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(8, 40))
    step = rng.random(n) < rng.uniform(0.5, 0.95)
    step[-1] = False
    e = int(rng.integers(n, 5 * n))
    src, dst = rng.integers(0, n, e), rng.integers(0, n, e)
    price = (np.full(e, float(search.JUMP_FRAMES)) if uniform else rng.uniform(0, 20, e)).astype(np.float32)
    few = search._cheapest_into(dst, (price, src), n, search.SPARSE_JUMPS)
    sparse = (src[few], dst[few], price[few])
    return rng, search.PoolWalker(0, n, step, src, dst, -1, -1, price=price, sparse=sparse)


def _least_prices(cw, start: int, rows: int) -> np.ndarray:
    """(rows, n): the least price of the jumps of a walk of c + 1 frames from ``start`` ending at
    each frame, by loops over the frames and over every jump."""
    src, dst, price = cw.loop_src, cw.loop_dst, cw.price.astype(np.float64)
    out = np.full((rows, cw.length), np.inf)
    out[0, start] = 0.0
    for c in range(1, rows):
        for f in range(1, cw.length):
            if cw.step[f - 1]:
                out[c, f] = out[c - 1, f - 1]
        for s, d, p in zip(src, dst, price):
            out[c, d] = min(out[c, d], out[c - 1, s] + p)
    return out


def _frames_and_price(cw, pieces) -> tuple[list[int], float]:
    """The pool frames of a walk (``pieces``: clip-local runs) and the price of its jumps, each
    move checked to be a step or a jump (the least price of the jumps that make it)."""
    offset = dict(zip(cw.clips.tolist(), cw.offsets.tolist()))
    frames = [offset[c] + f for c, a, b in pieces for f in range(a, b + 1)]
    paid = 0.0
    for a, b in zip(frames[:-1], frames[1:]):
        if b == a + 1 and cw.step[a]:
            continue
        made = (cw.loop_src == a) & (cw.loop_dst == b)
        assert made.any(), f"{a} -> {b} is neither a step nor a jump"
        paid += float(cw.price[made].min())
    return frames, paid


@pytest.mark.parametrize("uniform", [False, True])
@pytest.mark.parametrize("seed", range(30))
def test_a_segment_walk_is_the_cheapest_within_the_tolerance(seed, uniform):
    """Of the walks within the tolerance, the one whose jumps cost least plus one per frame off
    the request (the key :func:`search._walk` minimises), over every jump of the pool."""
    rng, cw = _pool(seed, uniform)
    start, need = int(rng.integers(0, cw.length)), int(rng.integers(4, 30))
    slack = search.tolerance_frames(need)
    least = _least_prices(cw, start, need + slack)
    want = min(least[k - 1].min() + abs(k - need) for k in range(max(need - slack, 1), need + slack + 1))
    if not np.isfinite(want):  # no walk within the tolerance: the nearest length, or none at all
        return
    pieces, _, played = search._walk(cw, start, [need], [-1], slack=slack)
    frames, paid = _frames_and_price(cw, pieces)
    assert frames[0] == start and len(frames) == played
    assert paid + abs(played - need) == pytest.approx(want, rel=1e-5, abs=1e-4)


@pytest.mark.parametrize("uniform", [False, True])
@pytest.mark.parametrize("seed", range(30))
def test_a_walk_to_an_exit_is_the_cheapest(seed, uniform):
    """The least frames plus price of its jumps, over every jump of the pool."""
    rng, cw = _pool(seed, uniform)
    start = int(rng.integers(0, cw.length))
    exits = rng.integers(0, cw.length, int(rng.integers(1, 4)))
    least = _least_prices(cw, start, cw.length)  # the cheapest walk visits no frame twice
    want = min(c + 1 + least[c, x] for c in range(cw.length) for x in exits)
    if not np.isfinite(want):
        with pytest.raises(search.SearchError):
            search.walk_to_exit(cw, start, exits.tolist())
        return
    pieces, r, played = search.walk_to_exit(cw, start, exits.tolist())
    frames, paid = _frames_and_price(cw, pieces)
    assert frames[0] == start and frames[-1] == exits[r] and len(frames) == played
    assert played + paid == pytest.approx(want, rel=1e-5, abs=1e-4)


@pytest.mark.parametrize("uniform", [False, True])
@pytest.mark.parametrize("seed", range(30))
def test_a_segment_walk_to_given_exits_is_the_cheapest(seed, uniform):
    """Options that end at given frames (a segment followed by another pool's link): of the walks
    within the tolerance of an option's length ending at its exit, the cheapest key, over every
    jump (the tables over every jump are pruned by the jumps still needed to reach an exit)."""
    rng, cw = _pool(seed, uniform)
    start, k = int(rng.integers(0, cw.length)), int(rng.integers(1, 4))
    exits, needs = rng.integers(0, cw.length, k), rng.integers(4, 30, k)
    slack = search.tolerance_frames(int(needs.max()))
    least = _least_prices(cw, start, int(needs.max()) + slack)
    want = min(
        least[n - 1, x] + abs(n - need)
        for x, need in zip(exits, needs)
        for n in range(max(need - slack, 1), need + slack + 1)
    )
    if not np.isfinite(want):
        return
    pieces, r, played = search._walk(cw, start, needs.tolist(), exits.tolist(), slack=slack)
    frames, paid = _frames_and_price(cw, pieces)
    assert frames[0] == start and frames[-1] == exits[r] and len(frames) == played
    assert paid + abs(played - needs[r]) == pytest.approx(want, rel=1e-5, abs=1e-4)


@pytest.mark.parametrize("seed", range(20))
def test_the_fewest_jumps_to_an_exit_agree_with_loops(seed):
    """:func:`search._jumps_to`: the fewest jumps from each frame to one of the exits, steps
    free, against relaxing every move by hand until nothing changes."""
    rng, cw = _pool(seed, False)
    exits = rng.integers(0, cw.length, int(rng.integers(1, 4)))
    want = np.full(cw.length, np.inf)
    want[exits] = 0
    changed = True
    while changed:
        changed = False
        for f in range(cw.length - 1):
            if cw.step[f] and want[f + 1] < want[f]:
                want[f], changed = want[f + 1], True
        for s, d in zip(cw.loop_src, cw.loop_dst):
            if want[d] + 1 < want[s]:
                want[s], changed = want[d] + 1, True
    assert np.array_equal(search._jumps_to(cw, exits), want)


@pytest.mark.parametrize("seed", range(20))
def test_the_pruned_table_keeps_the_recursions_entries(seed):
    """:func:`search._reach_below` stores only the walks it keeps: each entry it has equals the
    full recursion's (:func:`search._reach`, every jump), read as the search reads a table (a row,
    one entry, rows by columns); with no bound it keeps them all; a walk cheaper than the bound
    that lasts to the table's last row is kept."""
    rng, cw = _pool(seed, bool(seed % 2))
    start, rows = int(rng.integers(0, cw.length)), int(rng.integers(2, 25))
    full = search._reach(cw, start, rows)
    everything = search._reach_below(cw, start, rows, np.inf)
    assert np.array_equal(everything[:, np.arange(cw.length)], full)
    assert all(np.array_equal(everything[c], full[c]) for c in range(rows))
    bound = float(np.quantile(full[np.isfinite(full)], 0.5)) + 1e-3
    kept = search._reach_below(cw, start, rows, bound, first_row=rows - 1)
    dense = kept[:, np.arange(cw.length)]
    on = np.isfinite(dense)
    assert np.array_equal(dense[on], full[on]) and (dense[on] < bound).all()
    assert all(kept[c, x] == dense[c, x] for c, x in zip(rng.integers(0, rows, 50), rng.integers(0, cw.length, 50)))
    last = np.isfinite(full[-1]) & (full[-1] < bound)
    assert on[-1][last].all()


@pytest.mark.realdata
def test_walks_through_real_takes_are_the_cheapest():
    """Three dataset-2 walk styles, eight takes each: every walk of two requested lengths from
    every 100th alive frame costs what the table over every jump says is least (the full table
    agrees with loops by hand in ``test_search.py``)."""
    from motionlab.motion_graphs import distance, structured

    ms = session_walk_takes(8)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g = structured.build_structured(ms, distance.threshold_from(distance.DEFAULT_THRESHOLD))
    checked = 0
    for style in ("normal", "elderly", "feminine"):
        cw = search.pool_walker(g, "walk", style)
        for start in np.flatnonzero(cw.alive)[::100]:
            for need in (90, 240):
                slack = search.tolerance_frames(need)
                table = search._reach(cw, int(start), need + slack)  # every jump
                want = min(table[k - 1].min() + abs(k - need) for k in range(need - slack, need + slack + 1))
                if not np.isfinite(want):  # (a frame near a take's end)
                    continue
                pieces, _, played = search._walk(cw, int(start), [need], [-1], slack=slack)
                _, paid = _frames_and_price(cw, pieces)
                assert paid + abs(played - need) == pytest.approx(float(want), abs=1e-3), (style, start, need)
                checked += 1
    assert checked >= 100  # walks were found, so the comparison says something
