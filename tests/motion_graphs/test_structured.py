"""The structured graph: table, transition clips, interpolation space, local pruning."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab.motion_graphs import graph, structured
from tests.motion_graphs.conftest import THRESHOLD


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
    assert len(rows) == 3 and all(r["length"] > 0 for r in rows)


def test_no_dead_ends_and_cut_after_last_loop(sgraph):
    assert sgraph.dead_ends().size == 0
    for styles in sgraph.table["behaviours"].values():
        for e in styles.values():
            c = sgraph.clips[e["clip"]]
            alive = sgraph.alive[c.start : c.stop]
            assert alive[: e["length"]].all() and not alive[e["length"] :].any()
            # the last alive frame is a self-loop point
            loops = (sgraph.src == c.start + e["last_loop"]) & (sgraph.kind == graph.EDGE_KINDS.index("loop"))
            assert loops.any() and e["last_loop"] == e["length"] - 1
    assert np.all(sgraph.alive[sgraph.src] & sgraph.alive[sgraph.dst])


def test_original_clip_edges_are_kept(sgraph):
    e = sgraph.table["behaviours"]["walk"]["normal"]
    c = sgraph.clips[e["clip"]]
    assert all(sgraph.has_edge(f, f + 1) for f in range(c.start, c.start + e["length"] - 1))


def test_routes_follow_edges(sgraph):
    for link in sgraph.table["links"]:
        a = sgraph.table["behaviours"][link["from"][0]][link["from"][1]]["clip"]
        z = sgraph.table["behaviours"][link["to"][0]][link["to"][1]]["clip"]
        for r in link["routes"][:10]:
            pieces = [(a, r["exit"], r["exit"])] + [tuple(p) for p in r["pieces"]] + [(z, r["enter"], r["enter"])]
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
    assert any("run_normal" in line for line in g.info["unused"])
    assert g.dead_ends().size == 0


def test_duplicate_labels_rejected(library):
    with pytest.raises(graph.GraphError, match="two basic clips"):
        structured.build_structured([library[0], library[0]], THRESHOLD)
