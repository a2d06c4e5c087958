"""k-means, label clean-up, segmentation into actions and key frames."""

import numpy as np
import pytest

from motionlab.interpolation import keyposes
from motionlab.interpolation.features import pose_features

from .conftest import toy_motion


def test_kmeans_separates_blobs():
    rng = np.random.default_rng(0)
    centres = np.array([[0, 0], [10, 0], [0, 10]], dtype=float)
    x = np.concatenate([c + rng.normal(size=(50, 2)) for c in centres])
    labels, found = keyposes.kmeans(x, 3, seed=1)
    truth = np.repeat([0, 1, 2], 50)
    assert keyposes.purity(labels, truth)[0] == 1.0
    assert np.sort(np.linalg.norm(found, axis=1)).round(0).tolist() == [0.0, 10.0, 10.0]


def test_runs_and_clean_labels():
    labels = np.array([0, 0, 0, 0, 1, 0, 0, 2, 2, 2, 2, 2])
    assert keyposes.runs(labels) == [(0, 4, 0), (4, 5, 1), (5, 7, 0), (7, 12, 2)]
    z = np.array([[0.0]] * 7 + [[5.0]] * 5)
    centres = np.array([[0.0], [0.2], [5.0]])
    cleaned = keyposes.clean_labels(labels, z, centres, min_length=3)
    assert cleaned.tolist() == [0] * 7 + [2] * 5


def test_segment_recovers_known_actions():
    walk = toy_motion(90, speed=1.2)
    stand = toy_motion(90, speed=0.0)
    stand.local_rot[:] = stand.local_rot[:1]  # a held pose
    stand.root_pos[:] = walk.root_pos[-1]
    feats = np.concatenate([pose_features(walk), pose_features(stand), pose_features(walk)])
    truth = np.repeat(["walk", "stand", "walk"], 90)
    seg = keyposes.segment(feats, k=2, q=4, min_length=10)
    score, mapping = keyposes.purity(seg.labels, truth)
    assert score > 0.95
    assert len(seg.segments) == 3
    assert seg.classify(feats[:5]).tolist() == seg.labels[:5].tolist()


def test_key_frames_are_sorted_members():
    z = np.linspace(0, 1, 40)[:, None] * np.array([[1.0, 2.0]])
    keys = keyposes.key_frames(z, 4)
    assert len(keys) == 4 and np.all(np.diff(keys) > 0) and keys.min() >= 0 and keys.max() < 40
    assert len(keyposes.key_frames(z[:2], 5)) <= 2


def test_bad_input():
    with pytest.raises(ValueError, match="k"):
        keyposes.kmeans(np.zeros((3, 2)), 5)
    with pytest.raises(ValueError, match="equal-length"):
        keyposes.purity([0, 1], [0])


def test_window_stats_known_values():
    z = np.array([[0.0], [0.0], [3.0], [0.0], [0.0]])
    s = keyposes.window_stats(z, 3)
    np.testing.assert_allclose(s[:, 0], [0, 1, 1, 1, 0])
    np.testing.assert_allclose(s[2, 1], np.sqrt(2.0))


def test_a_library_of_clips_shorter_than_the_gap_says_so():
    from motionlab.interpolation.library import MotionLibrary

    from .conftest import toy_motion

    lib = MotionLibrary([toy_motion(10)])
    with pytest.raises(ValueError, match="no library stretch is 21 frames long"):
        lib.search(np.zeros((1, 8)), 20)
