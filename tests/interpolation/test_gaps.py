"""Detecting and filling missing frames, on NaN rows, timestamps and dropped BVH frames."""

import numpy as np
import pytest

from motionlab.interpolation import gaps
from motionlab.interpolation.action_graph import ActionGraph

from .conftest import toy_motion


def test_nan_and_timestamp_gaps():
    x = np.arange(20.0).reshape(10, 2)
    x[2:4, 0] = np.nan
    x[7, 1] = np.nan
    assert gaps.nan_gaps(x) == [(2, 4), (7, 8)]
    times = np.array([0, 1, 2, 5, 6, 8]) / 30
    assert gaps.timestamp_gaps(times, 30) == [(2, 2), (4, 1)]


def test_fill_rows_linear_and_edges():
    x = np.arange(10.0)[:, None] * np.array([[1.0, -2.0]])
    broken = x.copy()
    broken[3:6] = np.nan
    np.testing.assert_allclose(gaps.fill_rows(broken), x)
    broken[:2] = np.nan
    assert np.all(np.isfinite(gaps.fill_rows(broken)))
    with pytest.raises(ValueError, match="every row"):
        gaps.fill_rows(np.full((3, 2), np.nan))


def test_distance_rule_finds_dropped_frames():
    m = toy_motion(120)
    keep = np.r_[0:40, 48:120]
    found = gaps.distance_gaps(m[keep])
    assert [i for i, _ in found] == [39]
    assert abs(found[0][1] - 8) <= 2
    expanded, where = gaps.insert_missing(m[keep], found)
    assert where == [(40, 40 + found[0][1])]
    assert expanded.num_frames == len(keep) + found[0][1]


@pytest.mark.parametrize("method", ["slerp", "hermite"])
def test_fill_nan_frames(method):
    m = toy_motion(60)
    broken = m.copy()
    broken.local_rot[20:30] = np.nan
    broken.root_pos[20:30] = np.nan
    out, report = gaps.fill(broken, method=method)
    assert [(r.start, r.stop) for r in report] == [(20, 30)]
    assert np.all(np.isfinite(out.local_rot)) and np.all(np.isfinite(out.root_pos))
    np.testing.assert_array_equal(out.local_rot[:20], m.local_rot[:20])
    err = np.abs(out.global_positions() - m.global_positions()).max()
    assert err < 0.3


def test_graph_fill_across_actions_places_key_poses():
    g = ActionGraph()
    run, walk, stand = toy_motion(60, speed=3.0), toy_motion(60, speed=1.2, phase=1.0), toy_motion(60, speed=0.0)
    stand.local_rot[:] = stand.local_rot[:1]
    for name, clip in (("run", run), ("walk", walk), ("stand", stand)):
        g.add_node(name, clip)
    g.allow(["run -> walk", "walk -> stand"], both_ways=True)
    stream = run[:30].copy()
    gap = 20
    tail = stand[:20]
    from motionlab.interpolation.inbetween import concatenate

    joined, where = gaps.insert_missing(concatenate([stream, tail]), [(stream.num_frames - 1, gap)])
    assert where == [(30, 50)]
    out, report = gaps.fill(joined, method="graph", graph=g)
    assert report[0].path == ["run", "walk", "stand"]
    assert len(report[0].anchors) == 1 and 30 < report[0].anchors[0] < 50
    assert np.all(np.isfinite(out.local_rot))
    with pytest.raises(ValueError, match="ActionGraph"):
        gaps.fill(joined, method="graph")


@pytest.mark.realdata
@pytest.mark.parametrize("method", ["slerp", "hermite", "graph"])
def test_fill_gap_cut_from_a_real_clip(real_walk, method):
    m = real_walk
    start, stop = 100, 130
    broken = m.copy()
    broken.local_rot[start:stop] = np.nan
    broken.root_pos[start:stop] = np.nan
    if broken.local_pos is not None:
        broken.local_pos[start:stop] = np.nan
    graph = None
    if method == "graph":
        graph = ActionGraph()
        graph.add_node("walk", m[:90])  # the node's recording excludes the cut frames
        graph.add_node("walk-later", m[140:])
        graph.allow(["walk -> walk-later"], both_ways=True)
    out, report = gaps.fill(broken, method=method, graph=graph)
    assert out.num_frames == m.num_frames
    assert report[0].start == start and report[0].stop == stop
    assert np.all(np.isfinite(out.local_rot)) and np.all(np.isfinite(out.root_pos))
    np.testing.assert_allclose(np.linalg.norm(out.local_rot, axis=-1), 1.0, atol=1e-9)
    pos = out.global_positions()
    par = m.skeleton.parents
    # rigid bones: joints whose translation never changes (a moving hips channel is not a bone)
    rigid = np.flatnonzero(np.ptp(m.translations(), axis=0).max(axis=-1) < 1e-9)
    rigid = rigid[rigid > 0]
    bones = np.linalg.norm(pos[:, rigid] - pos[:, par[rigid]], axis=-1)
    np.testing.assert_allclose(bones, np.broadcast_to(m.skeleton.bone_lengths()[rigid], bones.shape), atol=1e-9)
    assert rigid.size >= m.skeleton.num_joints - 2
    err = np.linalg.norm(pos[start:stop] - m.global_positions()[start:stop], axis=-1).mean()
    assert err < 0.3  # metres: a plausible fill, not an exact one
