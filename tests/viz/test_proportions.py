"""Bone-proportion sliders: the new skeleton has the requested bone lengths, feet stay above
the ground, and the view updates on release."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from motionlab.core import humanoid
from motionlab.viz.proportions import GROUPS, ProportionEditor, canonical_source, copy_rotation_solver, feet_height
from tests.viz.conftest import stepping_motion

VIEW = {"window_size": (200, 150), "off_screen": True, "backend": "static"}


@pytest.fixture
def editor(can_render):
    source = stepping_motion(30)
    ed = ProportionEditor(source, solve=copy_rotation_solver(source), **VIEW)
    yield ed
    ed.close()


def _bone(skeleton, name):
    return skeleton.bone_lengths()[skeleton.index(name)]


def test_slider_release_builds_the_requested_skeleton(editor):
    base = editor.base
    before = editor.player.view.value
    editor.sliders["legs"].value = 1.3  # a release: continuous_update=False sliders fire once
    sk = editor.skeleton
    for name in ("LeftLeg", "LeftFoot", "RightLeg", "RightFoot"):
        assert _bone(sk, name) == pytest.approx(1.3 * _bone(base, name))
    for name in ("LeftForeArm", "Spine1", "Neck"):
        assert _bone(sk, name) == pytest.approx(_bone(base, name))
    assert editor.motion.skeleton is sk
    assert editor.player.view.value != before, "the view shows the new character"
    assert set(editor.timings) == {"solve", "view", "total"}


def test_update_several_groups_and_feet_stay_above_ground(editor):
    motion = editor.update(arms=0.7, spine=1.2, neck=1.5, overall=0.9)
    sk, base = motion.skeleton, editor.base
    assert _bone(sk, "LeftForeArm") == pytest.approx(0.7 * 0.9 * _bone(base, "LeftForeArm"))
    assert _bone(sk, "Spine2") == pytest.approx(1.2 * 0.9 * _bone(base, "Spine2"))
    assert _bone(sk, "Head") == pytest.approx(1.5 * 0.9 * _bone(base, "Head"))
    assert feet_height(motion).min() >= -1e-6
    assert editor.motion.global_positions()[..., 1].min() >= -1e-6


def test_reset_restores_the_source_proportions(editor):
    editor.update(legs=1.5)
    editor.reset()
    assert editor.factors == dict.fromkeys(GROUPS, 1.0)
    np.testing.assert_allclose(editor.skeleton.offsets, humanoid.scale_bones(editor.base).offsets)


def test_update_is_fast_enough(editor):
    editor.update(legs=1.2)
    assert editor.timings["total"] < 2.0  # the target, with the stand-in solver


def test_solver_history_is_plotted(can_render):
    source = stepping_motion(12)
    base_solve = copy_rotation_solver(source)
    calls = []

    def solve(skeleton):
        calls.append(skeleton)
        return base_solve(skeleton), {"loss": [1.0, 0.5, 0.2]}

    ed = ProportionEditor(source, solve=solve, **VIEW)
    try:
        ed.update(arms=1.4)
        assert len(calls) == 2  # initial + one per update, not one per slider
        assert ed.history == {"loss": [1.0, 0.5, 0.2]}
        assert len(ed.figure().axes) == 2
        assert ed.plot.value[:4] == b"\x89PNG"
    finally:
        ed.close()


def test_bad_solver_and_names(can_render):
    source = stepping_motion(6)
    with pytest.raises(ValueError, match="must return a Motion"):
        ProportionEditor(source, solve=lambda sk: "nope", **VIEW)
    ed = ProportionEditor(source, solve=copy_rotation_solver(source), **VIEW)
    try:
        with pytest.raises(ValueError, match="unknown proportion"):
            ed.update(tail=2.0)
    finally:
        ed.close()


def test_copy_rotation_solver_keeps_feet_on_the_ground():
    source = stepping_motion(30)
    solve = copy_rotation_solver(source)
    for legs in (0.6, 1.0, 1.5):
        sk = humanoid.scale_bones(source.skeleton, legs=legs)
        out = solve(sk)
        assert out.skeleton is sk
        assert feet_height(out).min() == pytest.approx(max(feet_height(source).min(), 0.0), abs=1e-9)
        np.testing.assert_array_equal(out.local_rot, source.local_rot)


def test_the_editor_needs_no_retargeting_its_default_solver_copies_rotations(monkeypatch, can_render):
    import motionlab

    monkeypatch.setitem(sys.modules, "motionlab.retargeting", None)  # any import of it fails
    monkeypatch.delattr(motionlab, "retargeting", raising=False)
    source = stepping_motion(5)
    ed = ProportionEditor(source, **VIEW)
    out = ed.solve(humanoid.scale_bones(source.skeleton, legs=1.1))
    ed.close()
    assert out.num_frames == 5
    np.testing.assert_array_equal(out.local_rot, canonical_source(source).local_rot)


def test_the_latent_solver_is_injected_from_retargeting(can_render):
    retargeting = pytest.importorskip("motionlab.retargeting")
    try:
        retargeting.load_default()
    except (FileNotFoundError, retargeting.CheckpointError) as e:
        pytest.skip(f"no shipped retargeting network: {e}")
    source = stepping_motion(16)
    from motionlab.retargeting.proportions import proportion_solver

    solve = proportion_solver(source, max_steps=3)
    motion, history = solve(humanoid.scale_bones(source.skeleton, legs=1.2))
    assert motion.skeleton.bone_lengths()[motion.skeleton.index("LeftLeg")] == pytest.approx(
        1.2 * source.skeleton.bone_lengths()[source.skeleton.index("LeftLeg")]
    )
    assert len(history["loss"]) >= 1


def test_release_shows_the_preview_before_a_given_solver_runs(can_render):
    """A slow solver: the new skeleton is on screen (copied rotations) while it runs."""
    source = stepping_motion(12)
    base_solve = copy_rotation_solver(source)
    seen, editors = [], []

    def solve(skeleton):
        if editors:  # not the first solve, inside the constructor
            ed = editors[0]
            seen.append((ed.player.scene.actors[1].motion.skeleton, ed.player.view.value, ed.status.value))
        return base_solve(skeleton), {"loss": [1.0, 0.5]}

    ed = ProportionEditor(source, solve=solve, **VIEW)
    editors.append(ed)
    try:
        before = ed.player.view.value
        ed.sliders["legs"].value = 1.4  # a release
        ((shown_skeleton, shown_view, status),) = seen
        assert shown_skeleton is not ed.base
        assert _bone(shown_skeleton, "LeftLeg") == pytest.approx(1.4 * _bone(ed.base, "LeftLeg"))
        assert shown_view != before, "the preview picture was sent before the solver ran"
        assert "preview" in status
        assert set(ed.timings) == {"solve", "view", "total", "preview"}
        assert ed.motion.skeleton is ed.skeleton and "solved in" in ed.status.value
        seen.clear()
        ed.update(legs=0.8)  # from code: the solver's result only
        ((shown_skeleton, _, _),) = seen
        assert _bone(shown_skeleton, "LeftLeg") == pytest.approx(1.4 * _bone(ed.base, "LeftLeg"))
        assert "preview" not in ed.timings
    finally:
        ed.close()


def test_preview_can_be_switched_off(can_render):
    source = stepping_motion(6)
    base_solve = copy_rotation_solver(source)
    for kwargs in ({"solve": lambda sk: base_solve(sk), "preview": False}, {"solve": base_solve}, {}):
        ed = ProportionEditor(source, **kwargs, **VIEW)
        try:
            ed.sliders["legs"].value = 1.2
            assert set(ed.timings) == {"solve", "view", "total"}, kwargs
        finally:
            ed.close()


def test_update_refuses_values_its_sliders_would_clamp(editor):
    before = editor.factors
    for value in (0.0, -1.0, 2.0, float("nan")):
        with pytest.raises(ValueError, match="outside its slider's range"):
            editor.update(legs=value)
    assert editor.factors == before
    editor.update(legs=1.2)  # still works afterwards
    assert editor.factors["legs"] == pytest.approx(1.2)
