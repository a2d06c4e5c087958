"""Table 1 machinery: clip selection and the copy-rotation baseline on the real Mixamo data."""

from __future__ import annotations

import pytest

from motionlab import data
from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS, Evaluation, evaluate, training_clips


def _mixamo():
    if not data.has_data("mixamo", "Aj"):
        pytest.skip(f"needs the shared Mixamo data: {data.HOW_TO}")
    return data.data_root() / "mixamo"


@pytest.mark.realdata
def test_training_clips_follow_the_manifest():
    clips = training_clips(_mixamo(), "Aj")
    stems = {p.stem for p in clips}
    assert len(clips) == 96
    assert not stems & set(DEFAULT_ANIMATIONS)
    assert all(p.parent.name == "Aj" for p in clips)


@pytest.mark.realdata
def test_copy_baseline_matches_the_data_notes_on_one_clip():
    """Aj → BigVegas "Jazz_Dancing" with copy-rotation: the real clip never penetrates, and the
    baseline's error is the order of magnitude the data notes report (MSE/h² ~ 1e-3)."""
    res = evaluate(
        _mixamo(), None, targets=["BigVegas"], animations=["Jazz_Dancing"],
        rows=[("copy", "copy", "legs")], progress=False,
    )  # fmt: skip
    s = res.summary()
    assert s["ground truth"]["pen"] < 0.01
    assert 1e-5 < s["copy"]["mse_h2"] < 1e-2
    assert "copy" in res.table()


def test_table_of_an_empty_evaluation_does_not_crash():
    assert "method" in Evaluation(rows=["x"]).table()


def test_missing_folders_are_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="Aj"):
        evaluate(tmp_path, None, rows=[("copy", "copy", "legs")])
    (tmp_path / "Aj").mkdir()
    with pytest.raises(FileNotFoundError, match="Kaya"):
        evaluate(tmp_path, None, targets=["Kaya"], rows=[("copy", "copy", "legs")])
    with pytest.raises(FileNotFoundError, match="no training clips"):
        training_clips(tmp_path, "Aj", [])


def test_a_clip_at_another_rate_than_the_network_is_scored_at_one_rate(tmp_path):
    """A 30 fps clip onto its own character: copying rotations is exact, at whatever rate it is scored."""
    import warnings

    from motionlab import retargeting, synthetic
    from motionlab.core import bvh

    walk = synthetic.dataset(1, seed=2, num_frames=30, fps=30)[0]
    for character in ("Src", "Tgt"):
        (tmp_path / character).mkdir()
        bvh.save(tmp_path / character / "walk.bvh", walk)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a frame-count mismatch warns
        res = evaluate(tmp_path, retargeting.load_default("cpu"), source="Src", targets=["Tgt"], animations=["walk"],
                       rows=[("copy", "copy", "hips")], progress=False)  # fmt: skip
    assert res.summary()["copy"]["mse_h2"] < 1e-6
