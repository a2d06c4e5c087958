"""The build report's numbers against a small graph built by hand."""

from __future__ import annotations

import json

import numpy as np
import pytest

from motionlab.core import humanoid
from motionlab.motion_graphs import report
from motionlab.motion_graphs.graph import ClipInfo, MotionGraph


@pytest.fixture
def hand_graph():
    """walk/a: takes 1 (frames 0-9) and 2 (10-19, last two pruned); walk/b: one take (20-29).

    Edges: 9->0 (loop in a1), 5->12 (a1->a2), 17->3 (a2->a1), 29->25 (loop in b).
    Largest component of walk: a1 0-9 and a2 12-17 = 16 frames; a2 10-11 are entered by no edge.
    """
    sk = humanoid.canonical_skeleton()
    clips = [
        ClipInfo("walk_a_1", "basic", "walk", "a", start=0, num_frames=10, take="1"),
        ClipInfo("walk_a_2", "basic", "walk", "a", start=10, num_frames=10, take="2"),
        ClipInfo("walk_b_1", "basic", "walk", "b", start=20, num_frames=10, take="1"),
    ]
    n = 30
    rot = np.zeros((n, sk.num_joints, 4))
    rot[..., 0] = 1.0
    alive = np.ones(n, dtype=bool)
    alive[18:20] = False
    src, dst = np.array([9, 5, 17, 29]), np.array([0, 12, 3, 25])
    table = {
        "behaviours": {
            "walk": {
                "a": {"takes": [{"cycles": 2}, {"cycles": 1}]},
                "b": {"takes": [{"cycles": 3}]},
            }
        },
        "links": [],
    }
    info = {"conditions": {"take pruned": ["walk_x_9: example", "walk_y_9: other"]}}
    return MotionGraph(
        sk, 30.0, clips, rot, np.zeros((n, 3)), alive, src, dst, np.zeros(4), np.ones(4, np.int8), table, info
    )


def test_numbers(hand_graph):
    r = report.build_report(hand_graph)
    a, b = r["rows"]
    assert (a["style"], a["takes"], a["frames"], a["cycles"], a["transitions"]) == ("a", 2, 20, 3, 3)
    assert (a["in_largest"], a["in_largest_percent"], a["pruned"]) == (16, 80.0, 2)
    assert (b["style"], b["takes"], b["frames"], b["cycles"], b["transitions"]) == ("b", 1, 10, 3, 1)
    assert (b["in_largest"], b["in_largest_percent"], b["pruned"]) == (0, 0.0, 0)
    walk = r["behaviours"]["walk"]
    assert {k: walk[k] for k in ("frames", "largest_scc", "percent")} == {
        "frames": 30,
        "largest_scc": 16,
        "percent": 53.3,
    }
    # no take says its kind; no link joins a and b
    assert (walk["kind"], walk["styles"], walk["style_pairs"], walk["reachable_pairs"]) == ("-", 2, 2, 0)
    assert r["behaviour_links"] == []
    assert (r["recorded_frames"], r["largest_scc"], r["percent"]) == (30, 16, 53.3)
    assert r["conditions"] == {"take pruned": {"count": 2, "example": "walk_x_9: example"}}


def test_text_has_the_summary_lines(hand_graph):
    text = report.format_report(report.build_report(hand_graph))
    lines = text.splitlines()
    assert "largest strongly connected component: 16 frames (53.3%)" in lines
    assert "largest strongly connected component of walk: 16 frames (53.3%)" in lines
    assert "  take pruned: 2 (e.g. walk_x_9: example)" in lines
    assert lines[0].split() == [
        "behaviour",
        "style",
        "takes",
        "frames",
        "cycles",
        "transitions",
        "in",
        "largest",
        "pruned",
    ]
    assert lines[2].split() == ["walk", "a", "2", "20", "3", "3", "80.0%", "2"]


def test_json_round_trip_and_no_overwrite(hand_graph, tmp_path):
    r = report.build_report(hand_graph)
    path = report.write_report(tmp_path / "r.json", r)
    assert json.loads(path.read_text())["behaviours"]["walk"]["largest_scc"] == 16
    with pytest.raises(FileExistsError):
        report.write_report(path, r)
    assert [p.name for p in tmp_path.iterdir()] == ["r.json"]


def test_component_agrees_with_networkx():
    """The vectorised forward-backward search finds what networkx finds, on random graphs."""
    import networkx as nx

    rng = np.random.default_rng(0)
    sk = humanoid.canonical_skeleton()
    for trial in range(20):
        sizes = rng.integers(3, 12, size=4)
        starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
        n = int(sizes.sum())
        clips = [ClipInfo(f"c{k}", start=int(s), num_frames=int(m)) for k, (s, m) in enumerate(zip(starts, sizes))]
        e = int(rng.integers(0, 10))
        src, dst = rng.integers(0, n, e), rng.integers(0, n, e)
        alive = rng.random(n) > 0.1
        rot = np.zeros((n, sk.num_joints, 4))
        rot[..., 0] = 1
        g = MotionGraph(sk, 30.0, clips, rot, np.zeros((n, 3)), alive, src, dst, np.zeros(e), np.zeros(e, np.int8))
        ref = nx.DiGraph()
        ref.add_nodes_from(np.flatnonzero(alive).tolist())
        nxt = g.next_in_clip()
        ref.add_edges_from((int(f), int(f) + 1) for f in np.flatnonzero(nxt))
        ref.add_edges_from((int(a), int(b)) for a, b in zip(src, dst) if alive[a] and alive[b])
        comps = [c for c in nx.strongly_connected_components(ref) if len(c) > 1 or ref.has_edge(*(list(c) * 2))]
        best = max((len(c) for c in comps), default=0)
        assert g.largest_component().sum() == best, trial


def test_kinds_reachability_and_behaviour_links(hand_graph):
    """Kinds and segments come from the takes; reachability follows the behaviour's own links."""
    cells = hand_graph.table["behaviours"]["walk"]
    for cell in cells.values():
        for t in cell["takes"]:
            t.update(kind="action", segments=2)
    route = {"exit": 0, "enter": 0, "pieces": [], "frames": 0, "cost": 0.0}
    hand_graph.table["links"] = [
        {"from": ["walk", "a"], "to": ["walk", "b"], "via": "stance", "routes": [route]},
        {"from": ["walk", "b"], "to": ["wave", "a"], "via": "stance", "routes": [route]},
        {"from": ["walk", "b"], "to": ["wave", "b"], "via": "stance", "routes": [route]},
        {"from": ["wave", "a"], "to": ["walk", "a"], "via": "transition clip wave_a_to_walk_a", "routes": [route]},
    ]
    r = report.build_report(hand_graph)
    walk = r["behaviours"]["walk"]
    assert (walk["kind"], walk["segments"], walk["reachable_pairs"], walk["style_pairs"]) == ("action", 6, 1, 2)
    assert r["behaviour_links"] == [
        {"source": "walk", "target": "wave", "via": {"stance": 2}},
        {"source": "wave", "target": "walk", "via": {"transition clip wave_a_to_walk_a": 1}},
    ]
    text = report.format_report(r)
    assert "walk: action, 6 segments/cycles, 53.3%, 1/2 style pairs reachable" in text
    assert "walk -> wave: stance (2 style pairs)" in text
