"""Preprocessing: features, their inverse, windows, statistics and the torch dataset."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab.core import humanoid, preprocess, quat
from motionlab.core.dataset import MotionDataset
from motionlab.core.motion import Motion
from tests.conftest import require_data


def _walker(frames: int = 90, fps: float = 30.0, turn: float = 0.02, seed: int = 0, wobble: float = 0.05) -> Motion:
    """The canonical skeleton sliding forward while turning, with some joint wobble."""
    rng = np.random.default_rng(seed)
    sk = humanoid.canonical_skeleton()
    t = np.arange(frames)
    yaw = 0.3 + turn * t
    rot = np.tile(quat.IDENTITY, (frames, 22, 1))
    rot[:, 0] = quat.from_yaw(yaw)
    rot[:, 1:] = quat.normalize(rot[:, 1:] + wobble * rng.normal(size=(frames, 21, 4)))
    step = np.stack([np.sin(yaw), np.zeros(frames), np.cos(yaw)], -1) * 0.02
    root = sk.offsets[0] + np.cumsum(step, axis=0) + np.array([1.0, 0.0, -2.0])
    return Motion(sk, rot, root, fps)


def test_heading_of_the_rest_pose_is_zero_and_follows_yaw():
    sk = humanoid.canonical_skeleton()
    assert preprocess.heading(sk.rest_positions()) == pytest.approx(0.0, abs=1e-12)
    m = _walker(wobble=0.005)
    np.testing.assert_allclose(
        np.unwrap(preprocess.heading(m.global_positions())), 0.3 + 0.02 * np.arange(90), atol=0.05
    )


def test_features_shape_and_heading_normalisation():
    f = preprocess.features(_walker())
    assert f.positions.shape == (90, 22, 3) and f.root.shape == (90, 4)
    assert f.flat().shape == (90, 70)
    np.testing.assert_allclose(f.positions[:, 0, [0, 2]], 0.0)
    # the character faces +Z in its own frame: its heading there is 0
    np.testing.assert_allclose(preprocess.heading(f.positions), 0.0, atol=1e-9)
    # walking straight ahead: forward velocity along +Z
    assert np.all(f.root[:-1, 1] > 0.015) and np.all(np.abs(f.root[:-1, 0]) < 0.01)


def test_to_global_inverts_features():
    m = _walker()
    pos = m.global_positions()
    f = preprocess.features(m)
    back = preprocess.to_global(f.positions, f.root, f.start, f.start_heading)
    np.testing.assert_allclose(back, pos, atol=1e-9)


def test_features_need_canonical_motion():
    m = _walker()
    sk = m.skeleton.renamed([f"x{i}" for i in range(22)])
    with pytest.raises(ValueError, match="canonical"):
        preprocess.features(m.copy(skeleton=sk))


def test_sliding_windows_cover_every_frame():
    assert preprocess.sliding_windows(100, 120, 60) == [(0, 100)]
    w = preprocess.sliding_windows(300, 120, 60)
    assert w[0] == (0, 120) and w[-1][1] == 300
    covered = np.zeros(300, bool)
    for s, e in w:
        assert e - s == 120
        covered[s:e] = True
    assert covered.all()
    with pytest.raises(ValueError):
        preprocess.sliding_windows(10, 0, 5)


def test_norm_stats_round_trip(tmp_path):
    x = np.random.default_rng(0).normal(size=(50, 4)) * [1, 2, 0, 4] + [0, 1, 2, 3]
    s = preprocess.NormStats.fit([x])
    np.testing.assert_allclose(s.denormalize(s.normalize(x)), x)
    assert np.all(np.isfinite(s.normalize(x)))  # the constant column does not divide by zero
    s.save(tmp_path / "stats.json")
    s2 = preprocess.NormStats.load(tmp_path / "stats.json")
    np.testing.assert_allclose(s2.mean, s.mean)


def test_prepare_resamples_and_refuses_nan():
    m = _walker(frames=61, fps=60)
    out = preprocess.prepare(m, fps=30)
    assert out.num_frames == 31 and out.fps == 30
    bad = m.copy()
    bad.local_rot[5, 3] = np.nan
    with pytest.raises(ValueError, match="frame 5"):
        preprocess.prepare(bad, fps=None)


def test_dataset_items_and_save_load(tmp_path):
    motions = [_walker(150, 60, seed=s) for s in range(3)]
    ds = MotionDataset.from_motions(motions, fps=60, window=120, stride=60, progress=False)
    assert len(ds) == 6  # 150 frames → windows at 0 and 30 (moved back to the end)
    item = ds[0]
    assert item["x"].shape == (120, 70) and item["positions"].shape == (120, 22, 3)
    assert item["offsets"].shape == (22, 3)
    np.testing.assert_allclose(ds.stats.denormalize(item["x"].numpy()), ds.x[0], atol=1e-4)
    path = ds.save(tmp_path / "windows.npz")
    ds2 = MotionDataset.load(path)
    np.testing.assert_array_equal(ds2.x, ds.x)
    assert ds2.index == ds.index and ds2.window == 120
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="not a motionlab windows dataset"):
        MotionDataset.load(tmp_path / "junk.npz")


@pytest.mark.realdata
def test_real_mixamo_clip_features():
    from motionlab.core import bvh

    path = require_data("mixamo", "Aj", "Running.bvh")
    m = preprocess.prepare(bvh.load(path), fps=60)
    f = preprocess.features(m)
    back = preprocess.to_global(f.positions, f.root, f.start, f.start_heading)
    np.testing.assert_allclose(back, m.global_positions(), atol=1e-6)
    assert 0.5 < np.median(f.root[:, 3]) < 1.2  # the hips are about a metre up
