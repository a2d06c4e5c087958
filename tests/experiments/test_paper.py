"""The paper's experiments (§4): the walk with every 30th frame kept, and run -> squat through the graph."""

import numpy as np
import pytest

from experiments.interpolation import paper
from motionlab import synthetic
from motionlab.interpolation import demo
from tests.conftest import require_data


def test_walk_experiment_keeps_the_kept_frames_and_measures_13_joints():
    walk = synthetic.generate("walk", None, 200, 120.0, seed=0)
    res = paper.walk_experiment(walk, first=5, every=30)
    np.testing.assert_array_equal(res.kept[:2], [5, 35])
    kept = res.kept - 5
    np.testing.assert_allclose(res.filled.local_rot[kept], res.truth.local_rot[kept])
    assert len(res.angle_error) == 13 and "LeftUpLeg" in res.angle_error
    assert res.hip_true.shape == res.hip_filled.shape == (res.truth.num_frames, 3)
    with pytest.raises(ValueError, match="every"):
        paper.walk_experiment(walk, first=5, every=1)


@pytest.mark.realdata
def test_real_walk_and_run_to_squat():
    require_data("xia", "walk")
    require_data("mixamo", "Aj")
    walk, _ = demo.paper_walk()
    res = paper.walk_experiment(walk)
    assert np.mean(list(res.angle_error.values())) < 6.0
    clips, _ = demo.behaviours()
    rs = paper.run_to_squat(clips, missing=10)
    assert rs.path == ["run", "walk", "stand", "squat"]
    assert [a - rs.first + 1 for a in rs.anchors] == [5, 8]
    assert all(is_key for _, _, is_key in rs.keys)
    assert rs.speeds.min() > 0.1 * rs.run_speed and rs.below == 0.0


def test_walk_experiment_agrees_with_the_construction_of_notebook_06():
    """Notebook 06 (and its exercise 2) keeps the frames with gaps.insert_missing instead of
    blanking the others with NaN: the same fill, the same errors."""
    from motionlab import exercises

    walk = synthetic.generate("walk", None, 360, 120.0, seed=3)
    res = paper.walk_experiment(walk, first=5, every=30)
    mean = float(np.mean(list(res.angle_error.values())))
    assert exercises.interpolation._walk_error(walk, every=30) == pytest.approx(mean, rel=1e-12)
