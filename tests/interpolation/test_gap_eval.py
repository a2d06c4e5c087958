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
