"""Metrics on hand-made cases with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab.core import metrics


def test_mse_and_mpjpe_known_values():
    a = np.zeros((2, 3, 3))
    b = a.copy()
    b[..., 0] = 3.0
    b[..., 1] = 4.0  # every joint 5 units away
    assert metrics.mpjpe(a, b) == pytest.approx(5.0)
    assert metrics.mse(a, b) == pytest.approx((9 + 16 + 0) / 3)
    assert metrics.mse(a, b, height=2.0) == pytest.approx(25 / 3 / 4)
    assert metrics.mpjpe(a, b, height=2.0) == pytest.approx(2.5)
    assert metrics.mse(a, a) == 0.0


def test_shape_mismatch_is_an_error():
    with pytest.raises(ValueError, match="equal shape"):
        metrics.mse(np.zeros((2, 3, 3)), np.zeros((2, 4, 3)))


def test_smoothness_zero_for_constant_velocity_and_known_for_a_kick():
    t = np.arange(10.0)
    pos = np.zeros((10, 1, 3))
    pos[:, 0, 0] = 2.0 * t  # uniform motion
    assert metrics.smoothness(pos) == pytest.approx(0.0)
    pos[5, 0, 1] = 1.0  # one frame displaced by 1: accelerations 1, -2, 1 at frames 4, 5, 6
    assert metrics.smoothness(pos) == pytest.approx((1 + 2 + 1) / 8)
    with pytest.raises(ValueError, match="3 frames"):
        metrics.smoothness(pos[:2])


def test_foot_penetration_counts_only_depth_below_ground():
    pos = np.zeros((4, 2, 3))
    pos[:, 0, 1] = [0.1, -0.2, 0.0, -0.4]  # foot joint 0
    pos[:, 1, 1] = 0.5
    assert metrics.foot_penetration(pos, [0]) == pytest.approx(0.15)
    assert metrics.foot_penetration(pos, [0, 1]) == pytest.approx(0.075)
    assert metrics.foot_penetration(pos, [1]) == 0.0


def test_foot_skating_measures_sliding_only_in_contact():
    pos = np.zeros((5, 1, 3))
    pos[:, 0, 0] = np.arange(5) * 0.01  # slides 1 cm per frame on the ground
    assert metrics.foot_skating(pos, [0], fps=100) == pytest.approx(1.0)
    pos[:, 0, 1] = 1.0  # in the air: no contact, no skating
    assert metrics.foot_skating(pos, [0], fps=100) == 0.0


def test_planted_slide_uses_the_given_labels_not_the_height():
    pos = np.zeros((5, 2, 3))
    pos[:, 0, 0] = np.arange(5) * 0.01  # joint 0 slides 1 cm per frame
    pos[:, :, 1] = 1.0  # both float 1 m up: foot_skating sees no contact at all
    planted = np.zeros((5, 2), dtype=bool)
    planted[:, 0] = True
    assert metrics.foot_skating(pos, [0, 1], fps=100) == 0.0
    assert metrics.planted_slide(pos, [0, 1], planted, fps=100) == pytest.approx(1.0)
    planted[:, 1] = True  # a still planted joint halves the mean
    assert metrics.planted_slide(pos, [0, 1], planted, fps=100) == pytest.approx(0.5)
    # a pair counts only when planted in both frames: alternate labels give no pair
    planted[:] = np.arange(5)[:, None] % 2 == 0
    assert metrics.planted_slide(pos, [0, 1], planted, fps=100) == 0.0
    with pytest.raises(ValueError, match="planted"):
        metrics.planted_slide(pos, [0, 1], planted[:, :1], fps=100)


def test_foot_contacts():
    pos = np.zeros((5, 1, 3))
    pos[3:, 0, 1] = 1.0
    c = metrics.foot_contacts(pos, [0], fps=30)
    assert c.shape == (5, 1)
    assert c[:2, 0].all() and not c[3:, 0].any()


def test_bone_length_error():
    pos = np.zeros((3, 2, 3))
    pos[:, 1, 1] = 1.0
    assert metrics.bone_length_error(pos, [-1, 0]) == 0.0
    pos[:, 1, 1] = [1.0, 2.0, 3.0]
    assert metrics.bone_length_error(pos, [-1, 0]) == pytest.approx(np.std([1, 2, 3]) / 2)


def test_positions_that_are_not_finite_give_nan_not_a_perfect_score():
    pos = np.random.default_rng(0).normal(size=(10, 3, 3))
    pos[4, 1] = np.nan
    parents = np.array([-1, 0, 1])
    planted = np.ones((10, 2), bool)
    assert np.isnan(metrics.foot_skating(pos, [1, 2], 30.0, height_threshold=10.0))
    assert np.isnan(metrics.planted_slide(pos, [1, 2], planted, 30.0))
    assert np.isnan(metrics.bone_length_error(pos, parents))
    assert np.isnan(metrics.bone_length_error(np.full((4, 3, 3), np.nan), parents))


def test_metrics_refuse_no_frames_a_bad_height_and_a_parent_list_of_another_length():
    pos = np.zeros((5, 3, 3))
    for call in (
        lambda: metrics.foot_skating(np.zeros((0, 3, 3)), [1], 30.0),
        lambda: metrics.mse(np.zeros((0, 3, 3)), np.zeros((0, 3, 3))),
    ):
        with pytest.raises(ValueError, match="at least one frame"):
            call()
    for height in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="positive height"):
            metrics.mpjpe(pos, pos + 1, height=height)
    assert metrics.mse(pos, pos + 1, height=2.0) == pytest.approx(0.25)
    with pytest.raises(ValueError, match="one parent per joint"):
        metrics.bone_length_error(pos, [-1, 0])
