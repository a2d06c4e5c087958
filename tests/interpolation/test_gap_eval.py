"""Cut, detect, fill, compare: the measurement behind scripts/check_gaps.py."""

import pytest

from motionlab.interpolation import gap_eval

from .conftest import toy_motion


def test_evaluate_cut_on_a_toy_walk():
    m = toy_motion(150)
    res = gap_eval.evaluate_cut(m, 60, 12)
    assert res.hit and res.false == 0 and res.count_ok
    assert 0.0 <= res.root_rel < 0.1 and res.below == 0.0
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
