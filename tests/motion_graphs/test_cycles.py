"""Gait cycles from foot contacts, on walks whose steps are known."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab import synthetic
from motionlab.motion_graphs import cycles


def _ankles(left_down, right_down, T=120):
    """(T, 2, 3) ankles: on the ground (y=0.02, still) on the given frames, else lifted and moving."""
    pos = np.zeros((T, 2, 3))
    for f, down in enumerate((left_down, right_down)):
        mask = np.zeros(T, dtype=bool)
        for a, b in down:
            mask[a:b] = True
        pos[:, f, 1] = np.where(mask, 0.02, 0.15)
        # moving forward 1.2 m/s while in the air, still on the ground
        step = np.where(mask, 0.0, 1.2 / 30)
        pos[:, f, 2] = np.cumsum(step)
    return pos


def test_known_steps():
    left = [(10, 25), (40, 55), (70, 85), (100, 115)]
    right = [(0, 10), (25, 40), (55, 70), (85, 100)]
    c = cycles.contacts(_ankles(left, right), 30.0)
    np.testing.assert_array_equal(cycles.strikes(c[:, 0]), [10, 40, 70, 100])
    np.testing.assert_array_equal(cycles.strikes(c[:, 1]), [25, 55, 85])  # frame 0 is no strike
    # a contact run shorter than min_frames is noise
    assert cycles.strikes(np.array([0, 1, 1, 0, 0, 1, 1, 1, 1, 0], bool), min_frames=3).tolist() == [5]


def test_cycles_need_one_right_step():
    left = [(10, 25), (40, 55), (70, 85)]
    right = [(25, 40)]  # no right step between 40 and 70: only the first cycle is whole
    got = cycles.cycles_from_ankles(_ankles(left, right, 100), 30.0)
    assert got.bounds.tolist() == [[10, 40]]
    assert got.span == (10, 40) and got.count == 1


def test_synthetic_walk_cycle_length():
    fps = 30.0
    for cadence in (1.6, 2.2):  # steps per second: a cycle is two steps
        m = synthetic.generate("walk", None, 240, fps, {"cadence": cadence}, 0)
        c = cycles.segment_cycles(m)
        assert c.count >= 4
        assert np.median(c.lengths()) == pytest.approx(2 * fps / cadence, abs=1.5)


def test_needs_ankles():
    m = synthetic.generate("walk", None, 30, 30.0, None, 0)
    with pytest.raises(ValueError, match="no joint 'Ankle'"):
        cycles.segment_cycles(m, feet=("Ankle", "RightFoot"))
