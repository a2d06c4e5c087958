"""Missing counts read off other recordings of the action (:mod:`motionlab.interpolation.recorded`)."""

import numpy as np
import pytest

from motionlab.core import bvh, quat
from motionlab.core.motion import Motion
from motionlab.interpolation import detect, recorded
from tests.conftest import require_data

from .conftest import toy_skeleton

FPS = 30.0


def slowing_walk(num_frames: int, slow_at: float, tempo: float = 1.0, slow: float = 0.5) -> Motion:
    """A straight toy walk whose cadence (1 Hz × ``tempo``) drops to ``slow`` of it for 1.2 s from
    ``slow_at`` seconds (smoothly); the step length stays, so the speed drops with the cadence."""
    t = np.arange(num_frames) / FPS
    dip = 0.5 * (np.tanh((t - slow_at) / 0.1) - np.tanh((t - slow_at - 1.2) / 0.1))  # 0 … 1 … 0
    cadence = tempo * (1.0 - (1.0 - slow) * dip)  # Hz
    phase = np.concatenate([[0.0], np.cumsum(0.5 * (cadence[1:] + cadence[:-1]) / FPS)])  # cycles
    w = 2 * np.pi * phase
    sk = toy_skeleton()
    angles = np.zeros((num_frames, sk.num_joints, 3))
    angles[:, 1, 0], angles[:, 3, 0] = 0.5 * np.sin(w), -0.5 * np.sin(w)
    angles[:, 2, 0], angles[:, 4, 0] = 0.4 * (1 + np.sin(w + 1.0)), 0.4 * (1 - np.sin(w + 1.0))
    angles[:, 5, 2] = 0.1 * np.sin(2 * w)
    root = np.stack([np.zeros_like(t), 0.9 + 0.02 * np.sin(2 * w), 1.2 * phase], axis=-1)  # 1.2 m a cycle
    return Motion(sk, quat.from_euler(angles, "xyz"), root, FPS, name=f"slowing {slow_at} {tempo}")


def test_a_slowdown_hidden_entirely_in_the_gap_is_not_observable():
    # the stream slows to half its cadence for 1.2 s and exactly that stretch is cut out: its sides
    # walk like any regular stretch of the recorded takes, so nothing at the gap's ends says where
    # in a take the gap lies; the recordings give the regular-gait count, as the distance does
    stream = slowing_walk(270, slow_at=4.0)
    s, n = 117, 42
    cut = stream[np.r_[0:s, s + n : stream.num_frames]]
    takes = recorded.RecordedTakes([slowing_walk(240, a, tempo) for a, tempo in ((3.0, 0.95), (3.5, 1.05))])
    (alone,) = detect.estimate_missing(cut, [s - 1])
    count, _ = recorded.recorded_missing(cut, s - 1, takes, float(alone))
    assert alone < 0.7 * n and count < 0.7 * n


@pytest.mark.parametrize("tempi", [(1.2, 1.25, 1.3, 1.35, 1.4), (0.7, 0.75, 0.8, 0.85)])
def test_takes_at_other_tempi_give_the_stream_count(tempi):
    # every recorded take walks 20-40% faster (or 15-30% slower) than the stream: the frames
    # between the matched poses, read without time scaling, would be 20-40% off
    stream = slowing_walk(240, slow_at=100.0)  # no slowdown
    s, n = 100, 20
    cut = stream[np.r_[0:s, s + n : stream.num_frames]]
    takes = recorded.RecordedTakes([slowing_walk(240, 100.0, tempo) for tempo in tempi])
    count, _ = recorded.recorded_missing(cut, s - 1, takes, 18.0)
    assert abs(count - n) <= 1.0


@pytest.mark.realdata
def test_a_left_turn_that_slows_is_counted_from_the_mirrored_right_turn():
    # the walker slows inside the turn (0.97 m/s against 1.05 and 1.13 on the sides): the distance
    # rule counts 26 of 30; the other recording, the right turn mirrored, knows the turn's timing
    b = require_data("bandai_namco", "dataset-2")
    left = bvh.load(b / "walk-turn-left" / "dataset-2_walk-turn-left_normal_001.bvh")
    right = bvh.load(b / "walk-turn-right" / "dataset-2_walk-turn-right_normal_001.bvh")
    s, n = 43, 30  # the cut of experiments/interpolation/check_gaps.py (seeded)
    cut = left[np.r_[0:s, s + n : left.num_frames]]
    (alone,) = detect.estimate_missing(cut, [s - 1])
    (both,) = detect.estimate_missing(cut, [s - 1], takes=recorded.RecordedTakes([right]))
    assert abs(alone - n) > 0.1 * n and abs(both - n) <= 0.1 * n


def test_mirror_index_pairs_left_and_right():
    bandai = ("joint_Root", "Hips", "UpperLeg_L", "Foot_L", "UpperLeg_R", "Foot_R")
    assert recorded.mirror_index(bandai).tolist() == [0, 1, 4, 5, 2, 3]
    mixamo = ("Hips", "LeftUpLeg", "RightUpLeg", "Spine")
    assert recorded.mirror_index(mixamo).tolist() == [0, 2, 1, 3]
    assert recorded.mirror_index(("Hips", "LeftUpLeg", "Spine")) is None  # no partner
    assert recorded.mirror_index(toy_skeleton().names) is None  # no joint named left or right


def test_takes_on_another_skeleton_or_rate_are_refused():
    a = slowing_walk(60, 100.0)
    other = Motion(a.skeleton.with_offsets(a.skeleton.offsets), a.local_rot, a.root_pos, 60.0, name="fast")
    with pytest.raises(ValueError, match="fps"):
        recorded.RecordedTakes([a, other])
    takes = recorded.RecordedTakes([a])
    with pytest.raises(ValueError, match="fps"):
        recorded.recorded_missing(other, 30, takes, 5.0)
    with pytest.raises(ValueError, match="at least one"):
        recorded.RecordedTakes([])


def test_one_sided_velocities_never_difference_across_a_gap():
    """Cut frames out after t: the backward features up to t, and the forward ones from t+1, stay as
    they were; the central ones at t change (they see the jump)."""
    from .conftest import toy_motion

    m = toy_motion(80)
    back, _ = recorded.body_features(m, difference="backward")
    fwd, _ = recorded.body_features(m, difference="forward")
    cut = m[np.r_[0:40, 55:80]]
    np.testing.assert_allclose(recorded.body_features(cut, difference="backward")[0][:40], back[:40], atol=1e-9)
    np.testing.assert_allclose(recorded.body_features(cut, difference="forward")[0][40:], fwd[55:], atol=1e-9)
    central = recorded.body_features(cut)[0]
    assert not np.allclose(central[39], recorded.body_features(m)[0][39])
    with pytest.raises(ValueError, match="backward"):
        recorded.body_features(m, difference="sideways")
