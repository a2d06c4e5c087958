"""The structured graph: pooled takes, table, transition clips, interpolation space, pruning."""

from __future__ import annotations

import numpy as np

from motionlab.motion_graphs import graph, structured
from motionlab.motion_graphs.naming import ClipLabel
from tests.motion_graphs.conftest import THRESHOLD


def _pool_clip(g, key):
    b, s = key
    return g.table["behaviours"][b][s]["start"]


def test_structure_table(sgraph):
    beh = sgraph.table["behaviours"]
    assert set(beh) == {"walk", "run"}
    assert set(beh["walk"]) == {"normal", "happy"}
    links = {(tuple(l["from"]), tuple(l["to"]), l["via"].split()[0]) for l in sgraph.table["links"]}
    assert (("walk", "normal"), ("walk", "happy"), "interpolation") in links
    assert (("walk", "happy"), ("walk", "normal"), "interpolation") in links
    assert (("walk", "normal"), ("run", "normal"), "transition") in links
    assert (("run", "normal"), ("walk", "normal"), "transition") in links
    # no direct link between behaviours except through transition clips
    for l in sgraph.table["links"]:
        if l["from"][0] != l["to"][0]:
            assert l["via"].startswith("transition clip")
    rows = structured.structure_rows(sgraph)
    assert len(rows) == 3 and all(r["alive"] > 0 for r in rows)


def test_two_takes_pool_into_one_style(library):
    """Two takes of walk/normal make one style whose cell records both takes' spans."""
    from motionlab import synthetic

    # two recordings of one walk: same style, another seed (other noise, other start)
    walk = synthetic.generate("walk", None, 120, 30.0, None, 1).copy(name="walk_normal_001")
    other = synthetic.generate("walk", None, 150, 30.0, None, 2).copy(name="walk_normal_002")
    takes = [other, walk]  # input order does not matter: takes are stored in take order
    g = structured.build_structured(takes, THRESHOLD)
    assert list(g.table["behaviours"]) == ["walk"] and list(g.table["behaviours"]["walk"]) == ["normal"]
    cell = g.table["behaviours"]["walk"]["normal"]
    assert [t["take"] for t in cell["takes"]] == ["001", "002"]
    assert [t["frames"] for t in cell["takes"]] == [walk.num_frames, other.num_frames]
    # spans: side by side in the graph, in take order, covering the cell's frames
    assert cell["takes"][0]["offset"] == 0 and cell["takes"][1]["offset"] == walk.num_frames
    assert cell["frames"] == walk.num_frames + other.num_frames
    for t in cell["takes"]:
        c = g.clips[t["clip"]]
        assert c.start == cell["start"] + t["offset"] and c.take == t["take"] and c.style == "normal"
        np.testing.assert_allclose(g.root_pos[c.start : c.stop], (walk if t["take"] == "001" else other).root_pos)
    assert g.info["conditions"] == {}
    # the takes are joined: transitions both ways between them
    c0, c1 = (g.clips[t["clip"]] for t in cell["takes"])
    a_to_b = (g.src >= c0.start) & (g.src < c0.stop) & (g.dst >= c1.start) & (g.dst < c1.stop)
    b_to_a = (g.src >= c1.start) & (g.src < c1.stop) & (g.dst >= c0.start) & (g.dst < c0.stop)
    assert a_to_b.any() and b_to_a.any()


def test_labels_pool_without_take_numbers(library):
    walk = next(m for m in library if m.name == "walk_normal")
    labels = [ClipLabel("basic", "walk", "normal")] * 3
    g = structured.build_structured([walk, walk, walk], THRESHOLD, labels=labels)
    assert len(g.table["behaviours"]["walk"]["normal"]["takes"]) == 3


def test_no_dead_ends_and_each_style_strongly_connected(sgraph):
    assert sgraph.dead_ends().size == 0
    for styles in sgraph.table["behaviours"].values():
        for e in styles.values():
            mask = np.zeros(sgraph.num_frames, dtype=bool)
            mask[e["start"] : e["start"] + e["frames"]] = True
            comp = sgraph.largest_component(mask)
            assert comp.sum() == e["alive"] > 0  # every alive frame of the style lies in one component
    assert np.all(sgraph.alive[sgraph.src] & sgraph.alive[sgraph.dst])


def test_original_clip_edges_are_kept(sgraph):
    e = sgraph.table["behaviours"]["walk"]["normal"]
    st = e["start"]
    alive = np.flatnonzero(sgraph.alive[st : st + e["frames"]]) + st
    runs = np.split(alive, np.flatnonzero(np.diff(alive) > 1) + 1)
    longest = max(runs, key=len)
    assert all(sgraph.has_edge(int(f), int(f) + 1) for f in longest[:-1])


def test_routes_follow_edges(sgraph):
    def at(key, f):
        cell = sgraph.table["behaviours"][key[0]][key[1]]
        for t in cell["takes"]:
            if t["offset"] <= f < t["offset"] + t["frames"]:
                return (t["clip"], f - t["offset"], f - t["offset"])
        raise AssertionError(f)

    for link in sgraph.table["links"]:
        for r in link["routes"][:10]:
            pieces = [at(link["from"], r["exit"])] + [tuple(p) for p in r["pieces"]] + [at(link["to"], r["enter"])]
            sgraph.check_path(pieces)
            assert r["frames"] == sum(p[2] - p[1] + 1 for p in r["pieces"])


def test_interpolation_only_between_neighbours(sgraph):
    bridge = sgraph.kind == graph.EDGE_KINDS.index("bridge")
    ca, cb = sgraph.clip_of(sgraph.src[bridge]), sgraph.clip_of(sgraph.dst[bridge])
    for x, y in set(zip(ca.tolist(), cb.tolist())):
        wx = sgraph.clips[x].style.split("@")
        wy = sgraph.clips[y].style.split("@")
        weight = lambda w, clip: float(w[1]) if len(w) == 2 else (0.0 if clip.style == "normal" else 1.0)  # noqa: E731
        assert abs(weight(wx, sgraph.clips[x]) - weight(wy, sgraph.clips[y])) <= 0.2 + 1e-9


def test_transition_clip_without_endpoint_is_unused(library):
    keep = [m for m in library if m.name != "run_normal"]
    g = structured.build_structured(keep, THRESHOLD)
    assert any("run_normal" in line for line in g.info["conditions"]["unused transition clip"])
    assert g.dead_ends().size == 0


def test_ring_pairs_grow_linearly():
    assert structured._ring_pairs(3, 3) == [(0, 1), (0, 2), (1, 2)]
    pairs = structured._ring_pairs(40, 3)
    assert len(pairs) == 40 * 3
    # the ring joins every take to the next: one connected cycle
    assert all((k, k + 1) in pairs for k in range(39)) and (0, 39) in pairs


def test_prune_false_keeps_every_frame_and_edge(library, sgraph):
    """``prune=False`` (paper B's ablation) skips every pruning step: the same frames and the
    pruned graph's edges plus the ones pruning removed; dead ends (the clips' last frames) remain."""
    raw = structured.build_structured(library, THRESHOLD, prune=False)
    assert raw.info["prune"] is False and sgraph.info["prune"] is True
    assert raw.num_frames == sgraph.num_frames and raw.num_alive == raw.num_frames > sgraph.num_alive
    assert raw.dead_ends().size > 0 == sgraph.dead_ends().size
    key = lambda g: set(zip(g.src.tolist(), g.dst.tolist()))  # noqa: E731
    assert key(sgraph) < key(raw)  # pruning only removes edges
    assert {(tuple(x["from"]), tuple(x["to"])) for x in raw.table["links"]} == {
        (tuple(x["from"]), tuple(x["to"])) for x in sgraph.table["links"]
    }


def test_wcmg_refuses_several_takes_of_a_style(library):
    """A wcMG has one clip per style: several takes of one style are refused by name, not
    silently reduced to the last take."""
    import pytest

    walk = next(m for m in library if m.name == "walk_normal")
    with pytest.raises(graph.GraphError, match="walk_normal"):
        structured.build_wcmg([walk.copy(name="walk_normal_001"), walk.copy(name="walk_normal_002")], THRESHOLD)
    g = structured.build_wcmg([m for m in library if m.name in ("walk_normal", "walk_happy")], THRESHOLD)
    assert g.info["kind"] == "wcmg" and g.info["intermediates"] == 4
