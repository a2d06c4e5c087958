"""Detecting and filling missing frames, on NaN rows, timestamps and dropped BVH frames."""

import numpy as np
import pytest

from motionlab.core import humanoid, quat
from motionlab.core.motion import Motion
from motionlab.interpolation import footing, gaps, inbetween
from motionlab.interpolation.action_graph import ActionGraph

from .conftest import toy_motion


def _run_walk_stand():
    """An action graph run <-> walk <-> stand of toy clips, and the three clips."""
    g = ActionGraph()
    run, walk, stand = toy_motion(60, speed=3.0), toy_motion(60, speed=1.2, phase=1.0), toy_motion(60, speed=0.0)
    stand.local_rot[:] = stand.local_rot[:1]
    for name, clip in (("run", run), ("walk", walk), ("stand", stand)):
        g.add_node(name, clip)
    g.allow(["run -> walk", "walk -> stand"], both_ways=True)
    return g, run, walk, stand


def test_nan_and_timestamp_gaps():
    x = np.arange(20.0).reshape(10, 2)
    x[2:4, 0] = np.nan
    x[7, 1] = np.nan
    assert gaps.nan_gaps(x) == [(2, 4), (7, 8)]
    times = np.array([0, 1, 2, 5, 6, 8]) / 30
    assert gaps.timestamp_gaps(times, 30) == [(2, 2), (4, 1)]


def test_frame_times_file_skips_blank_lines_and_comments(tmp_path):
    path = tmp_path / "times.txt"
    path.write_text("# capture log\n0.000\n\n0.0333\n  0.1000  \n# dropped two\n0.1333\n")
    t = gaps.load_times(path, frames=4)
    np.testing.assert_allclose(t, [0.0, 0.0333, 0.1, 0.1333])
    assert gaps.timestamp_gaps(t, 30) == [(1, 1)]  # 0.0333 -> 0.1000: two periods, one frame missing


def test_fill_rows_linear_and_edges():
    x = np.arange(10.0)[:, None] * np.array([[1.0, -2.0]])
    broken = x.copy()
    broken[3:6] = np.nan
    np.testing.assert_allclose(gaps.fill_rows(broken), x)
    broken[:2] = np.nan
    assert np.all(np.isfinite(gaps.fill_rows(broken)))
    with pytest.raises(ValueError, match="every row"):
        gaps.fill_rows(np.full((3, 2), np.nan))


def test_detected_gap_is_inserted():
    from motionlab.interpolation import detect

    m = toy_motion(120)
    keep = np.r_[0:40, 48:120]
    found = detect.detect(m[keep])
    assert [i for i, _ in found] == [39]
    assert abs(found[0][1] - 8) <= 1
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
    g, run, walk, stand = _run_walk_stand()
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


def test_graph_fill_passes_through_the_key_pose_at_the_best_transition_frame():
    """Fails if the fill bypasses the key poses: the anchor holds the intermediate node's key frame,
    and moving that node's key frames moves what the fill inserts."""
    from motionlab.interpolation.inbetween import concatenate

    g, run, walk, stand = _run_walk_stand()
    joined, _ = gaps.insert_missing(concatenate([run[:30], stand[:20]]), [(29, 20)])
    out, report = gaps.fill(joined, method="graph", graph=g)
    (slot,) = report[0].anchors
    _, j, _ = g.best_transition("run", "walk")
    assert j in g.nodes["walk"].keys
    np.testing.assert_allclose(out.local_rot[slot, 1:], walk.local_rot[j, 1:])
    other = next(
        k for k in range(walk.num_frames) if k != j and not np.allclose(walk.local_rot[k, 1:], walk.local_rot[j, 1:])
    )
    g.nodes["walk"].keys = np.array([other])
    g._best.clear()
    out2, _ = gaps.fill(joined, method="graph", graph=g)
    np.testing.assert_allclose(out2.local_rot[slot, 1:], walk.local_rot[other, 1:])


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


# ---------------------------------------------------------------------------- C1 root through anchors
def _corner_motion():
    """A toy motion whose root runs straight at 0.04 m/frame, then is filled piece-wise linearly
    through anchors at frames 30, 40, 50, 60 (corners at every anchor), then runs along +X."""
    m = toy_motion(90)
    anchors = [30, 40, 50, 60]
    points = np.array([[0.0, 0.9, 1.2], [0.3, 0.97, 1.5], [0.1, 0.94, 2.0], [0.4, 0.9, 2.2]])
    t = np.arange(90)
    root = np.empty((90, 3))
    root[:31] = points[0] + (t[:31, None] - 30) * np.array([0.0, 0.0, 0.04])
    root[60:] = points[-1] + (t[60:, None] - 60) * np.array([0.03, 0.0, 0.0])
    for k in range(3):
        root[30:61, k] = np.interp(t[30:61], anchors, points[:, k])
    return m.copy(root_pos=root), anchors


def _second_difference(p):
    """|p[t+1] - 2 p[t] + p[t-1]| (T-2,), centred on frames 1 … T-2 (index t-1 is frame t)."""
    return np.linalg.norm(np.diff(p, 2, axis=0), axis=-1)


def test_smooth_root_passes_through_anchors_without_corners():
    m, anchors = _corner_motion()
    out = gaps.smooth_root(m, anchors)
    a, b = anchors[0], anchors[-1]
    np.testing.assert_array_equal(out.root_pos[anchors], m.root_pos[anchors])
    np.testing.assert_array_equal(out.root_pos[: a + 1], m.root_pos[: a + 1])  # known frames untouched
    np.testing.assert_array_equal(out.root_pos[b:], m.root_pos[b:])
    np.testing.assert_array_equal(out.local_rot, m.local_rot)
    old, new = _second_difference(m.root_pos), _second_difference(out.root_pos)
    at = np.array(anchors) - 1
    assert old[at].min() > 0.02 and old[at - 1].max() < 1e-12  # the piece-wise linear path has corners
    assert np.all(new[at] < 0.5 * old[at])
    # no spike: at an anchor the curve bends about as much as on the frames around it
    assert np.all(new[at] <= 1.25 * np.maximum(new[at - 1], new[at + 1]))
    elsewhere = np.setdiff1d(np.arange(a, b - 1), at)  # frames a+1 … b-1 that are not anchors
    assert new[at].max() <= 1.25 * new[elsewhere].max()
    # the gap leaves a and reaches b with the velocities measured outside it
    np.testing.assert_allclose(out.root_pos[a + 1] - out.root_pos[a], [0.0, 0.0, 0.04], atol=0.008)
    np.testing.assert_allclose(out.root_pos[b] - out.root_pos[b - 1], [0.03, 0.0, 0.0], atol=0.008)


def test_smooth_root_keeps_detail_between_anchors():
    """A wiggle riding on a linear piece (as a recorded stretch brings) survives the smoothing, and
    its own slopes at the anchors do not survive as corners."""
    m, anchors = _corner_motion()
    t = np.arange(41, 50)
    wiggle = 0.03 * np.sin(3 * np.pi * (t - 40) / 10)  # zero at both anchors, 1.5 periods
    m.root_pos[t, 0] += wiggle
    plain = gaps.smooth_root(_corner_motion()[0], anchors).root_pos
    out = gaps.smooth_root(m, anchors).root_pos
    # the piece's own end slopes changed, so the result differs by a cubic; the wiggle's shape stays
    assert np.corrcoef(out[t, 0] - plain[t, 0], wiggle)[0, 1] > 0.9
    new = _second_difference(out)
    at = np.array(anchors[1:3]) - 1
    assert np.all(new[at] <= 1.25 * np.maximum(new[at - 1], new[at + 1]))


def test_smooth_root_never_pushes_feet_further_through_the_floor(monkeypatch):
    m, anchors = _corner_motion()
    # arrive at a falling fast: the smooth curve would dive below the anchors right after a
    m.root_pos[:30, 1] = 0.9 + 0.03 * (30 - np.arange(30))
    out = gaps.smooth_root(m, anchors)
    monkeypatch.setattr(gaps, "_floor_guard", lambda motion, a, b, drop: drop)
    unguarded = gaps.smooth_root(m, anchors)

    def lowest(motion):
        return motion.global_positions()[:, 1:, 1].min(axis=-1)  # the root joint is no foot

    before = lowest(m)
    allowed = np.minimum(before, min(before[30], before[60]))
    assert np.all(lowest(out) >= allowed - 1e-12)
    assert lowest(unguarded).min() < allowed.min() - 0.01  # without the guard the feet go through
    np.testing.assert_array_equal(out.root_pos[anchors], m.root_pos[anchors])
    np.testing.assert_array_equal(out.root_pos[:, [0, 2]], unguarded.root_pos[:, [0, 2]])  # only y held


def test_smooth_root_without_outside_neighbours_keeps_the_fill_ends():
    m, anchors = _corner_motion()
    m.root_pos[61:] = np.nan  # the next gap starts right after b: no velocity there
    m.local_rot[61:] = np.nan
    out = gaps.smooth_root(m, anchors)
    assert np.all(np.isfinite(out.root_pos[:61]))
    np.testing.assert_array_equal(out.root_pos[anchors], m.root_pos[anchors])
    end = out.root_pos[60] - out.root_pos[59]
    np.testing.assert_allclose(end, m.root_pos[60] - m.root_pos[59], atol=0.005)
    with pytest.raises(ValueError, match="increasing"):
        gaps.smooth_root(m, [40, 30])
    with pytest.raises(ValueError, match="filled"):
        gaps.smooth_root(m, [30, 70])


def test_graph_fill_root_is_c1_through_key_poses(monkeypatch):
    """run -> walk -> stand across a 20-frame gap: the key pose of 'walk' sits inside the gap."""
    g, run, walk, stand = _run_walk_stand()
    from motionlab.interpolation.inbetween import concatenate

    joined, where = gaps.insert_missing(concatenate([run[:30], stand[:20]]), [(29, 20)])
    out, report = gaps.fill(joined, method="graph", graph=g)
    monkeypatch.setattr(gaps, "smooth_root", lambda motion, anchors, joint=None: motion.copy())
    corner, _ = gaps.fill(joined, method="graph", graph=g)  # the same fill without the smoothing
    anchors = [29] + report[0].anchors + [50]
    assert len(anchors) == 3
    np.testing.assert_array_equal(out.root_pos[anchors], corner.root_pos[anchors])
    np.testing.assert_array_equal(out.root_pos[:30], joined.root_pos[:30])
    np.testing.assert_array_equal(out.root_pos[50:], joined.root_pos[50:])
    np.testing.assert_array_equal(out.local_rot, corner.local_rot)  # only the root moves
    old, new = _second_difference(corner.root_pos), _second_difference(out.root_pos)
    at = np.array(anchors) - 1
    inside = np.setdiff1d(np.arange(29, 50), at)
    assert old[at].max() > 3.0 * np.median(old[inside])  # the unsmoothed fill has corners
    assert new[at].max() < 0.5 * old[at].max()
    assert np.all(new[at] <= 1.25 * np.maximum(new[at - 1], new[at + 1]))


def test_moving_slerp_ends_and_frozen_case():
    from motionlab.core import quat

    rng = np.random.default_rng(1)
    a = quat.normalize(rng.normal(size=(6, 3, 4)))
    b = quat.normalize(rng.normal(size=(6, 3, 4)))
    ta, tb = rng.normal(size=(6, 3, 3)), rng.normal(size=(6, 3, 3))
    rot, trans = gaps.moving_slerp(a, ta, b, tb)
    np.testing.assert_allclose(rot[0], a[0])
    np.testing.assert_allclose(np.abs(np.sum(rot[-1] * b[-1], axis=-1)), 1.0)
    np.testing.assert_allclose(trans[[0, -1]], [ta[0], tb[-1]])
    frozen, _ = gaps.moving_slerp(np.repeat(a[:1], 6, 0), ta, np.repeat(b[:1], 6, 0), tb)
    plain = quat.slerp(a[0][None], b[0][None], (np.arange(6) / 5)[:, None])
    np.testing.assert_allclose(np.abs(np.sum(frozen * plain, axis=-1)), 1.0, atol=1e-12)


def test_across_nodes_pieces_move_rather_than_slide_between_two_poses():
    """Fails if the pieces between anchors were plain SLERP between the anchor poses."""
    from motionlab.interpolation.inbetween import concatenate, fill_between

    g, run, walk, stand = _run_walk_stand()
    joined, _ = gaps.insert_missing(concatenate([run[:30], stand[:20]]), [(29, 20)])
    out, report = gaps.fill(joined, method="graph", graph=g)
    (slot,) = report[0].anchors
    plain = fill_between(out, 30, slot)
    assert not np.allclose(out.local_rot[30:slot, 1:], plain.local_rot[30:slot, 1:], atol=1e-3)


def _scissor_gap():
    """A canonical humanoid whose straight legs swap a 30° scissor for the opposite one across
    frames 1-5 (missing), the feet on the floor at frames 0 and 6: SLERP swings both legs through
    the vertical, below that floor. Returns the motion with the gap, and the legs."""
    sk = humanoid.canonical_skeleton()
    legs = footing.legs(sk)
    rot = np.tile([1.0, 0.0, 0.0, 0.0], (7, sk.num_joints, 1))
    for (hip, _, _), sign in zip(legs, (1.0, -1.0)):
        rot[0, hip] = quat.from_axis_angle([1.0, 0.0, 0.0], sign * np.pi / 6)
        rot[6, hip] = quat.from_axis_angle([1.0, 0.0, 0.0], -sign * np.pi / 6)
    m = Motion(sk, rot, np.tile([0.0, 1.0, 0.0], (7, 1)), 30.0)
    m.local_rot[1:6] = np.nan
    m.root_pos[1:6] = np.nan
    return m, legs


def test_fill_keeps_feet_out_of_the_floor_by_the_chosen_rule():
    m, legs = _scissor_gap()
    plant, _ = gaps.fill(m)
    lift, _ = gaps.fill(m, feet="lift")
    default_twin, _ = gaps.fill(m, feet="plant")
    np.testing.assert_array_equal(plant.local_rot, default_twin.local_rot)
    np.testing.assert_array_equal(plant.root_pos, default_twin.root_pos)
    plain = inbetween.fill_between(m, 1, 6, root="linear")  # SLERP, nothing kept out of the floor
    low = footing.lowest_joints(plain, 0, 6)
    floor = min(low[0], low[-1])
    assert low[1:-1].min() < floor - 0.05  # the legs swing through the floor half-way
    for out in (plant, lift):
        assert footing.lowest_joints(out, 0, 6).min() >= floor - 1e-9
    # "lift": the SLERP pose, the body raised; "plant": the legs bent, the body raised less
    np.testing.assert_array_equal(lift.local_rot, plain.local_rot)
    assert np.all(lift.root_pos[1:6, 1] > plain.root_pos[1:6, 1])
    leg_joints = [j for leg in legs for j in leg]
    assert not np.allclose(plant.local_rot[1:6][:, leg_joints], plain.local_rot[1:6][:, leg_joints])
    assert np.all(plant.root_pos[1:6, 1] < lift.root_pos[1:6, 1])


def test_fill_refuses_an_unknown_floor_rule():
    m, _ = _scissor_gap()
    with pytest.raises(ValueError, match="feet='hover'"):
        gaps.fill(m, feet="hover")


# ---------------------------------------------------------------------------- the joint that carries the body
def _marker_rig(m: Motion) -> Motion:
    """``m`` on a rig with a marker joint 0 held at the origin above its root, which now moves by
    its own translation channels (as Bandai Namco's ``joint_Root`` above the hips): the same world
    motion for every joint of ``m``."""
    from motionlab.core.skeleton import Skeleton

    sk = m.skeleton
    parents = np.concatenate([[-1], sk.parents + 1])
    parents[1] = 0
    rig = Skeleton(("Marker",) + tuple(sk.names), parents, np.concatenate([np.zeros((1, 3)), sk.offsets]))
    T = m.num_frames
    rot = np.concatenate([np.broadcast_to(quat.IDENTITY, (T, 1, 4)), m.local_rot], axis=1)
    local_pos = np.concatenate([np.zeros((T, 1, 3)), m.translations()], axis=1)
    return Motion(rig, rot, np.zeros((T, 3)), m.fps, local_pos, m.name)


@pytest.mark.parametrize(("method", "root"), [("stride", "stride"), ("slerp", "hermite"), ("slerp", "stride"),
                                              ("slerp", "linear"), ("hermite", "linear")])  # fmt: skip
def test_a_still_joint_zero_stays_still_and_the_joint_below_it_carries_the_fill(method, root):
    walk = toy_motion(150)  # a turning walk, long enough for the stride fill
    marked = _marker_rig(walk)
    missing = [(69, 8)]  # frames 70 … 77 dropped
    keep = np.r_[0:70, 78:150]
    filled, report = gaps.fill(gaps.insert_missing(walk[keep], missing)[0], method=method, root=root)
    filled_marked, report_marked = gaps.fill(gaps.insert_missing(marked[keep], missing)[0], method=method, root=root)
    assert report_marked[0].method == report[0].method == ("stride" if method == "stride" else method)
    pos = filled_marked.global_positions()
    np.testing.assert_allclose(pos[:, 0], 0.0, atol=1e-12)  # the marker never leaves the origin
    np.testing.assert_allclose(filled_marked.local_rot[:, 0], np.broadcast_to(quat.IDENTITY, (150, 4)), atol=1e-12)
    # the body is filled as on the rig that carries it by joint 0, to rounding
    np.testing.assert_allclose(pos[:, 1:], filled.global_positions(), atol=1e-9)


def test_carry_by_reference_keeps_the_body_and_interpolates_the_joints_above():
    from motionlab.interpolation.alignment import carry_by_reference

    marked = _marker_rig(toy_motion(40))
    moved = marked.copy()
    moved.root_pos[11:19] += np.array([0.3, 0.0, -1.2])  # a fill that carried the body by joint 0
    moved.local_pos[11:19, 0] = moved.root_pos[11:19]
    moved.local_pos[11:19, 1] -= np.array([0.3, 0.0, -1.2])
    moved.local_rot[11:19, 0] = quat.from_yaw(0.4)
    out = carry_by_reference(moved, 10, 19)
    np.testing.assert_allclose(out.root_pos, 0.0, atol=1e-12)
    np.testing.assert_allclose(out.global_positions()[:, 1:], moved.global_positions()[:, 1:], atol=1e-12)
    np.testing.assert_allclose(quat.mul(out.global_rotations()[:, 1:], quat.inv(moved.global_rotations()[:, 1:]))[..., 0],
                               1.0, atol=1e-12)  # fmt: skip
    plain = toy_motion(40)
    np.testing.assert_array_equal(carry_by_reference(plain, 10, 19).root_pos, plain.root_pos)  # joint 0 carries
    with pytest.raises(ValueError, match="0 <= a < b"):
        carry_by_reference(moved, 19, 10)


@pytest.mark.realdata
def test_fill_gaps_leaves_the_bandai_root_marker_at_the_origin(tmp_path, capsys):
    """Issue 39: ``dataset-1_walk_normal_001`` with frames 40–45 dropped; the filled frames moved
    ``joint_Root`` 120 … 20 cm off the origin and frame 46 snapped it back."""
    from motionlab.cli import main
    from motionlab.core import bvh
    from tests.conftest import require_data

    src = require_data("bandai_namco", "dataset-1", "walk", "dataset-1_walk_normal_001.bvh")
    m = bvh.load(src)
    keep = np.r_[0:40, 46 : m.num_frames]
    bvh.save(tmp_path / "gap.bvh", m[keep])
    np.savetxt(tmp_path / "times.txt", keep / m.fps)
    out = tmp_path / "out.bvh"
    assert main(["fill-gaps", str(tmp_path / "gap.bvh"), "-o", str(out), "--times", str(tmp_path / "times.txt")]) == 0
    f = bvh.load(out)
    assert f.num_frames == m.num_frames
    truth, pos = m.global_positions(), f.global_positions()
    np.testing.assert_allclose(pos[:, 0], truth[:, 0], atol=1e-6)  # joint_Root as recorded: at the origin
    hips = np.linalg.norm(pos[40:46, 1] - truth[40:46, 1], axis=-1)
    assert hips.max() < 0.02  # metres: the hips, which carry the walker, follow their path
    capsys.readouterr()


def test_insert_missing_refuses_fractions_negatives_and_a_place_given_twice():
    m = toy_motion(20)
    for missing, message in (
        ([(3, 2.7)], "two whole numbers"),
        ([(3.5, 2)], "two whole numbers"),
        ([(3, -1)], "the count >= 0"),
        ([(5, 2), (5, 3)], "after frame 5 are given twice"),
    ):
        with pytest.raises(ValueError, match=message):
            gaps.insert_missing(m, missing)
    out, holes = gaps.insert_missing(m, [(5.0, 2), (9, 0)])
    assert holes == [(6, 8)] and out.num_frames == 22
    for fps in (0.0, float("nan")):
        with pytest.raises(ValueError, match="frame rate"):
            gaps.timestamp_gaps([0.0, 0.1, 0.3], fps)


def test_graph_fill_refuses_clips_at_another_rate():
    g = ActionGraph()
    g.add_node("walk", toy_motion(40, fps=120.0))
    holed, _ = gaps.insert_missing(toy_motion(40), [(20, 4)])
    with pytest.raises(ValueError, match="at 120 fps, the motion to fill at 30"):
        gaps.fill(holed, method="graph", graph=g)
    with pytest.raises(ValueError, match="local_pos"):
        inbetween.fill_between(toy_motion(20).copy(local_pos=None), 5, 9, joint=1)
