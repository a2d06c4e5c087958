"""The standard (Kovar) graph: clip edges, pruning, no dead ends."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab.motion_graphs import graph
from tests.motion_graphs.conftest import THRESHOLD


@pytest.fixture(scope="module")
def basics(library):
    return [m for m in library if "_to_" not in m.name]


def test_unpruned_keeps_every_clip_edge(basics):
    g = graph.build_standard(basics, THRESHOLD, prune=False)
    assert g.num_alive == sum(len(m) for m in basics)
    for c in g.clips:
        for f in range(c.start, c.stop - 1):
            assert g.has_edge(f, f + 1)
        if c.stop < g.num_frames:  # no clip edge runs into the next clip
            assert not g.next_in_clip()[c.stop - 1]
    assert g.num_transitions > 0
    # transitions come from similar frames: dst - 1 resembles src
    assert np.all(g.cost <= THRESHOLD)


def test_pruning_leaves_one_component_without_dead_ends(basics):
    g = graph.build_standard(basics, THRESHOLD)
    assert g.num_alive > 0
    assert g.dead_ends().size == 0
    assert g.largest_component().sum() == g.num_alive
    assert np.all(g.alive[g.src] & g.alive[g.dst])
    # clip edges inside alive runs are still there
    f = int(
        np.flatnonzero(
            g.alive[:-1]
            & g.alive[1:]
            & (g.clip_of(np.arange(g.num_frames - 1)) == g.clip_of(np.arange(1, g.num_frames)))
        )[0]
    )
    assert g.has_edge(f, f + 1)


def test_segments_cover_alive_frames(basics):
    g = graph.build_standard(basics, THRESHOLD)
    first, last, seg = g.segments()
    assert np.all(last >= first)
    assert int(np.sum(last - first + 1)) == g.num_alive
    assert np.all((seg >= 0) == g.alive)


def test_mixed_rates_are_rejected(basics):
    with pytest.raises(graph.GraphError, match="fps"):
        graph.build_standard([basics[0], basics[1].resample(60.0)], THRESHOLD)


def test_check_path_rejects_jumps(basics):
    g = graph.build_standard(basics, THRESHOLD, prune=False)
    g.check_path([(0, 0, 10), (0, 11, 20)])
    with pytest.raises(graph.GraphError, match="no edge"):
        g.check_path([(0, 0, 10), (1, 50, 60)])
