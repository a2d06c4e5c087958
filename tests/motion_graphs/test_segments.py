"""Gait or standing action from the motion, stance phases and segments, stance links between pools."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab import synthetic
from motionlab.motion_graphs import search, segments, stance_links, structured
from tests.motion_graphs.conftest import THRESHOLD

FPS = 30.0
LEG = 0.8


def _standing_action(hold: int = 0) -> tuple[np.ndarray, list[list[int]]]:
    """Positions (T, 4, 3) of a hand-built standing action and its true stance frames.

    Joints: left ankle, right ankle, hips, hand. Both feet stay planted; the hand rests for 20
    frames, rises at 1 m/s for 15 frames, holds ``hold`` frames, comes down for 15 frames and
    rests for 30 frames. With ``hold=0`` the turn at the top lasts a single frame (no stance).
    """
    up = np.linspace(0.0, 0.5, 16)[1:]  # 15 frames at 1/30 m per frame = 1 m/s
    hand_y = np.concatenate([np.zeros(20), up, np.full(hold, 0.5), up[::-1][1:], [0.0], np.zeros(29)])
    T = hand_y.size
    pos = np.zeros((T, 4, 3))
    pos[:, 0] = [0.1, 0.08, 0.0]
    pos[:, 1] = [-0.1, 0.08, 0.0]
    pos[:, 2] = [0.0, 0.9, 0.0]
    pos[:, 3] = np.stack([np.full(T, 0.3), 0.8 + hand_y, np.zeros(T)], axis=1)
    # still: every joint below STILL_SPEED * LEG = 0.2 m/s; np.gradient gives 0.5 m/s on the frame
    # next to a move (a central difference), so a rest loses its frame beside the move
    top, down = 20 + 15, 20 + 15 + hold
    truth = [[0, 19]] + ([[top, top + hold - 1]] if hold else []) + [[down + 15, T]]
    return pos, truth


def test_standing_action_stances_and_segments():
    pos, truth = _standing_action()
    seg = segments.segments_from_positions(pos, (0, 1), FPS, LEG)
    assert seg.kind == "action" and seg.both_planted == 1.0
    assert seg.stances.tolist() == truth
    # one segment, from the middle of the first stance to the middle of the last
    assert seg.bounds.tolist() == [[9, (truth[1][0] + truth[1][1] - 1) // 2]]


def test_a_hold_is_a_stance_that_cuts_the_action():
    pos, truth = _standing_action(hold=12)
    seg = segments.segments_from_positions(pos, (0, 1), FPS, LEG)
    assert seg.stances.tolist() == truth
    mids = [(a + b - 1) // 2 for a, b in truth]
    assert seg.bounds.tolist() == [[mids[0], mids[1]], [mids[1], mids[2]]]
    # ports are the boundary stances only (a third of a second at each end)
    assert np.flatnonzero(seg.ports).tolist() == list(range(10)) + list(range(len(pos) - 10, len(pos)))


def test_stances_scale_with_the_body_and_frame_rate():
    """Twice the size and twice the frame rate: the same stances, in the same seconds."""
    pos, truth = _standing_action(hold=12)
    big = segments.segments_from_positions(2.0 * pos, (0, 1), FPS, 2.0 * LEG)
    assert big.stances.tolist() == truth
    fast = np.repeat(pos, 2, axis=0)  # every frame twice: the same motion at 60 fps (half the per-frame speed)
    seg = segments.segments_from_positions(fast, (0, 1), 2 * FPS, LEG)
    assert seg.kind == "action" and seg.stances.shape == (3, 2)


def test_bad_input():
    pos, _ = _standing_action()
    with pytest.raises(ValueError, match="shape"):
        segments.segments_from_positions(pos[:, :, :2], (0, 1), FPS, LEG)
    with pytest.raises(ValueError, match="out of range"):
        segments.segments_from_positions(pos, (0, 9), FPS, LEG)
    with pytest.raises(ValueError, match="positive"):
        segments.segments_from_positions(pos, (0, 1), FPS, 0.0)


@pytest.mark.parametrize(
    ("behaviour", "kind"), [("walk", "gait"), ("run", "gait"), ("idle", "action"), ("squat", "action")]
)
def test_gait_or_action_from_motion_not_name(behaviour, kind):
    """The kind comes from the feet, whatever the clip is called."""
    m = synthetic.generate(behaviour, None, 120, FPS).copy(name="wave_normal_001" if kind == "gait" else "walk_normal")
    seg = segments.segment_take(m)
    assert seg.kind == kind
    assert (seg.both_planted < segments.GAIT_SHARE) == (kind == "gait")


def test_leg_length_of_the_canonical_humanoid():
    m = synthetic.generate("idle", None, 10, FPS)
    leg = segments.leg_length(m.skeleton)
    pos = m.global_positions()[0]
    names = list(m.skeleton.names)
    knee, ankle, hip = (pos[names.index(n)] for n in ("LeftLeg", "LeftFoot", "LeftUpLeg"))
    assert leg == pytest.approx(np.linalg.norm(knee - hip) + np.linalg.norm(ankle - knee), rel=0.02)


def test_pool_pairs_prefer_recorded_transitions():
    keys = [("walk", "normal"), ("walk", "sad"), ("wave", "normal"), ("wave", "sad")]
    pairs = {(a, b): (f, r) for a, b, f, r in stance_links.pool_pairs(keys, {("walk", "wave")})}
    assert pairs[(("walk", "normal"), ("walk", "sad"))] == (True, True)  # styles of one behaviour
    assert pairs[(("walk", "normal"), ("wave", "normal"))] == (False, True)  # walk -> wave is recorded
    assert (("walk", "normal"), ("wave", "sad")) not in pairs  # across behaviours: style by style
    kinds = {k: ("gait" if k[0] == "walk" else "action") for k in keys}
    pairs = {(a, b) for a, b, _, _ in stance_links.pool_pairs(keys, set(), kinds)}
    assert (("walk", "normal"), ("walk", "sad")) not in pairs  # a gait's styles meet by interpolation
    assert (("wave", "normal"), ("wave", "sad")) in pairs and (("walk", "sad"), ("wave", "sad")) in pairs


@pytest.fixture(scope="module")
def idle_and_squat():
    """A standing action (squat between two rests) and standing still, with no transition clip."""
    clips = []
    for k in range(2):
        clips.append(synthetic.sequence([("idle", 30), ("squat", 60), ("idle", 30)], None, FPS, k).copy(
            name=f"squat_normal_{k + 1:03d}"))  # fmt: skip
        clips.append(synthetic.generate("idle", None, 90, FPS, None, 10 + k).copy(name=f"stand_normal_{k + 1:03d}"))
    return structured.build_structured(clips, THRESHOLD)


def test_cross_behaviour_link_at_matching_stances(idle_and_squat):
    g = idle_and_squat
    cells = g.table["behaviours"]
    assert cells["squat"]["normal"]["kind"] == "action"
    assert all(t["segments"] >= 1 for t in cells["squat"]["normal"]["takes"])
    links = [link for link in g.table["links"] if link["from"][0] != link["to"][0]]
    assert {(link["from"][0], link["to"][0]) for link in links} == {("squat", "stand"), ("stand", "squat")}
    for link in links:
        assert link["via"] == "stance" and link["routes"]
        r = link["routes"][0]
        src = cells[link["from"][0]][link["from"][1]]["start"] + r["exit"]
        dst = cells[link["to"][0]][link["to"][1]]["start"] + r["enter"]
        assert g.has_edge(src, dst) and r["cost"] <= THRESHOLD
    res = search.search(g, "stand:normal:40,squat:normal:60,stand:normal:40")
    g.check_path(res.pieces)
    assert all(abs(a - r) <= max(2, search.TOLERANCE * r) for a, r in zip(res.achieved, res.requested))
