"""Cut, detect, fill, compare: the measurement behind experiments/interpolation/check_gaps.py."""

import numpy as np
import pytest

from experiments.interpolation import gap_eval
from motionlab.interpolation.alignment import reference_joint, reference_transform
from tests.interpolation.conftest import toy_motion


def test_evaluate_cut_on_a_toy_walk():
    m = toy_motion(150)
    res = gap_eval.evaluate_cut(m, 60, 12)
    assert res.hit and res.false == 0 and res.count_ok
    assert 0.0 <= res.root_rel < 0.1 and res.below == 0.0
    _, truth = reference_transform(m, joint=reference_joint(m))
    assert res.displacement == pytest.approx(np.linalg.norm(truth[72] - truth[59]))  # frames 59 and 72 kept
    s = gap_eval.summary([res])
    assert s["precision"] == s["recall"] == 1.0
    with pytest.raises(ValueError, match="cannot cut"):
        gap_eval.cut(m, 140, 20)


def test_pose_error_is_zero_for_the_truth_and_smaller_with_strides():
    m = toy_motion(240)  # periodic: the strides on both sides are the truth
    strided = gap_eval.evaluate_cut(m, 100, 12)
    slerped = gap_eval.evaluate_cut(m, 100, 12, method="slerp", root="hermite")
    assert strided.estimate == slerped.estimate == 12  # same count: the errors compare the fills
    assert strided.pose_cm < 0.05 < slerped.pose_cm  # centimetres
    assert gap_eval.summary([strided, slerped])["pose_cm_mean"] == pytest.approx(
        (strided.pose_cm + slerped.pose_cm) / 2
    )


def test_detection_counts_scores_hits_and_false_flags():
    import numpy as np

    from motionlab.interpolation import detect

    m = toy_motion(150)
    hits, false, cases = gap_eval.detection_counts(m, detect.consecutive_gaps, (10, 20), np.random.default_rng(0))
    assert (hits, false, cases) == (2, 0, 2)
    # a finder that flags one wrong step per stream: no hit, one false flag per cut
    hits, false, cases = gap_eval.detection_counts(m, lambda s: [0], (10, 20, 30), np.random.default_rng(0))
    assert (hits, false, cases) == (0, 3, 3)
    # too short for the cut and its margins: no case
    assert gap_eval.detection_counts(toy_motion(60), lambda s: [], (30,), np.random.default_rng(0)) == (0, 0, 0)


def test_counts_given_are_the_counts_filled():
    # found= skips the detection: the same count gives the same result, another count another fill
    m = toy_motion(150)
    detected = gap_eval.evaluate_cut(m, 60, 12)
    assert gap_eval.evaluate_cut(m, 60, 12, found=[(59, detected.estimate)]) == detected
    other = gap_eval.evaluate_cut(m, 60, 12, found=[(59, 20)])
    assert other.estimate == 20 and not other.count_ok and other.root_rel != detected.root_rel


def test_countable_leaves_out_copies_of_the_kept_frames():
    """The toy walk moves for 60 frames, then holds frame 59 for 30 (known construction)."""
    padded = toy_motion(60)[np.r_[0:60, np.full(30, 59)]]
    assert gap_eval.countable(padded, 20, 10) == 10  # all moving
    assert gap_eval.countable(padded, 55, 10) == 4  # 55 … 58 move; 59 … 64 are copies of frame 65
    assert gap_eval.countable(padded, 70, 10) == 0  # inside the hold
    r = gap_eval.evaluate_cut(padded, 55, 10)
    assert r.countable == 4 and r.countable_ok and not r.count_ok

    for start, n in ((0, 10), (85, 10), (20, 0)):  # no kept frame before / after, nothing cut
        with pytest.raises(ValueError, match=r"cannot cut .* from 'toy', a 90-frame motion"):
            gap_eval.countable(padded, start, n)


def test_retimed_gap_leaves_the_same_stream():
    """Known construction: 12 frames replayed over 18 (slower) or 8 (faster); cut them, and the stream
    is the one cut 12 frames from the clip, bit for bit, so a count read from it is the same."""
    from motionlab.interpolation import detect, gaps

    m = toy_motion(150)
    stream = gap_eval.cut(m, 60, 12)
    for k in (18, 8, 12):
        other = gap_eval.retimed(m, 60, 12, k)
        assert other.num_frames == 150 + k - 12
        assert np.array_equal(other.local_rot[:60], m.local_rot[:60])
        assert np.array_equal(other.root_pos[60 + k :], m.root_pos[72:])
        assert np.allclose(other.root_pos[60 + k - 1], m.root_pos[71])  # the stretch ends where it did
        cut = gap_eval.cut(other, 60, k)
        assert np.array_equal(cut.local_rot, stream.local_rot) and np.array_equal(cut.root_pos, stream.root_pos)
        assert detect.detect(cut) == detect.detect(stream)
        # the frames' capture times tell the three apart
        times = np.r_[0:60, 60 + k : other.num_frames] / other.fps
        assert gaps.timestamp_gaps(times, other.fps) == [(59, k)]
    # the toy walks at a constant pace: replayed over 18 frames, each step is 12/18 of one
    _, p = reference_transform(m, joint=reference_joint(m))
    _, q = reference_transform(gap_eval.retimed(m, 60, 12, 18), joint=reference_joint(m))
    step, slow = np.linalg.norm(np.diff(p[59:72], axis=0), axis=1), np.linalg.norm(np.diff(q[59:78], axis=0), axis=1)
    assert slow.mean() == pytest.approx(step.mean() * 12 / 18, rel=0.02)
    with pytest.raises(ValueError, match="expected at least one frame"):
        gap_eval.retimed(m, 60, 12, 0)
    with pytest.raises(ValueError, match="cannot cut 20 frames at 140 from 'toy'"):
        gap_eval.retimed(m, 140, 20, 30)
