"""The action graph: edges from data and from a user list, shortest paths, best transition frames."""

import numpy as np
import pytest

from motionlab.interpolation.action_graph import ActionGraph, GraphError, parse_transition
from motionlab.interpolation.features import distance_matrix

from .conftest import toy_motion


@pytest.fixture
def graph():
    g = ActionGraph()
    g.add_node("run", toy_motion(40, speed=3.0))
    g.add_node("walk", toy_motion(40, speed=1.2, phase=0.5))
    g.add_node("stand", toy_motion(40, speed=0.0))
    g.add_node("squat", toy_motion(40, speed=0.0, phase=2.0))
    return g


def test_parse_transition():
    assert parse_transition(" walk ->stand ") == ("walk", "stand")
    with pytest.raises(GraphError, match="from -> to"):
        parse_transition("walk to stand")


def test_edges_from_data_and_user_list(graph):
    found = graph.add_transitions_from(["run", "run", "walk", "walk", "stand", "unknown", "squat"])
    assert found == [("run", "walk"), ("walk", "stand"), ("stand", "squat")]
    graph.allow(["squat -> stand"])
    graph.forbid([("run", "walk")])
    assert ("run", "walk") not in graph.edges and ("squat", "stand") in graph.edges
    with pytest.raises(GraphError, match="unknown action"):
        graph.allow(["fly -> run"])


def test_path_is_shortest_chain(graph):
    graph.allow(["run -> walk", "walk -> stand", "stand -> squat"], both_ways=True)
    assert graph.path("run", "squat") == ["run", "walk", "stand", "squat"]
    graph.allow(["run -> squat"])
    assert graph.path("run", "squat") == ["run", "squat"]
    assert graph.path("squat", "run") == ["squat", "stand", "walk", "run"]
    graph.forbid(["stand -> walk"])
    with pytest.raises(GraphError, match="no chain"):
        graph.path("squat", "run")


def test_best_transition_is_the_minimum_distance_between_key_frames(graph):
    i, j, d = graph.best_transition("run", "walk")
    ka, kb = graph.nodes["run"].keys, graph.nodes["walk"].keys
    assert i in ka and j in kb
    full = distance_matrix(graph.nodes["run"].features, graph.nodes["walk"].features)
    assert d == pytest.approx(full[np.ix_(ka, kb)].min())
    assert full[i, j] == pytest.approx(d)
    assert graph.best_transition("run", "walk") == (i, j, d)  # cached


def test_key_frames_come_from_ppca(monkeypatch):
    """add_node's key frames are the PPCA latent's medoids: swapping PPCA out changes nothing else."""
    from motionlab.interpolation import keyposes

    calls = []

    class Spy(keyposes.PPCA):
        def fit(self, x):
            calls.append(np.shape(x))
            return super().fit(x)

    monkeypatch.setattr(keyposes, "PPCA", Spy)
    g = ActionGraph()
    node = g.add_node("walk", toy_motion(40))
    assert calls and calls[0] == node.features.shape
    keys, latent = keyposes.node_key_frames(node.features, 5)
    np.testing.assert_array_equal(node.keys, keys)


def test_classify_frames_of_known_nodes(graph):
    f = graph.nodes["run"].features[10:13]
    assert graph.classify(f) == ["run"] * 3
    assert len(graph.nodes["walk"].keys) == 5


def test_allow_adds_all_or_none_and_a_clip_of_another_rate_is_refused(graph):
    before = set(graph.edges)
    with pytest.raises(GraphError, match="'zzz'"):
        graph.allow([("walk", "run"), ("walk", "zzz")])
    assert graph.edges == before
    with pytest.raises(ValueError, match="at 120 fps"):
        graph.add_node("jog", toy_motion(40, fps=120.0))
    assert "jog" not in graph.nodes
