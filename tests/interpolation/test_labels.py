"""Action clips are checked by content (hip height, speed, flight), not by file name."""

import numpy as np
import pytest

from motionlab import synthetic
from motionlab.core import quat
from motionlab.interpolation import demo, labels
from tests.conftest import require_data


def test_synthetic_actions_pass_their_rules():
    for label, behaviour in (("run", "run"), ("walk", "walk"), ("stand", "idle"), ("squat", "squat")):
        labels.check(synthetic.generate(behaviour, None, 90, 30.0, seed=0), label)


def test_a_run_with_its_hips_near_the_ground_is_refused():
    run = synthetic.generate("run", None, 90, 30.0, seed=0)
    rolled = run.copy()  # a dive roll: the body lies along the floor for ten frames, hips 15 cm up
    rolled.local_rot[40:50, 0] = quat.mul(quat.from_axis_angle([1.0, 0.0, 0.0], np.pi / 2), run.local_rot[40:50, 0])
    rolled.root_pos[40:50, 1] = 0.15
    with pytest.raises(labels.LabelError, match="labelled 'run'.*hip_min"):
        labels.check(rolled, "run")
    with pytest.raises(labels.LabelError, match="speed"):
        labels.check(run, "walk")
    with pytest.raises(ValueError, match="no rule"):
        labels.check(run, "fly")


@pytest.mark.realdata
def test_real_behaviour_clips_match_their_labels():
    require_data("mixamo", "Aj")
    clips, source = demo.behaviours()
    assert source.startswith("real")
    for label, clip in clips.items():
        m = labels.check(clip, label)
        if label == "run":
            assert m.hip_min > 0.65 and m.flight > 0.0
    # the clip the old graph called "run" is a dive roll: its hips drop near the ground
    with pytest.raises(labels.LabelError, match="hip_min is 0.0"):
        labels.check(demo._load("mixamo/Aj/Running", 30.0), "run")
