"""Tests for motionlab.core.motion.Motion: validation, slicing, kinematics, resampling."""

import numpy as np
import pytest

from motionlab import synthetic
from motionlab.core import fk, quat
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.testing import assert_quat_close, random_quat, random_skeleton


@pytest.fixture
def rng():
    return np.random.default_rng(31)


def make_motion(rng, T=10, J=5, fps=30.0, local_pos=False):
    sk = random_skeleton(rng, J)
    lp = np.broadcast_to(sk.offsets, (T, J, 3)) + 0.01 * rng.normal(size=(T, J, 3)) if local_pos else None
    return Motion(sk, random_quat(rng, (T, J)), rng.normal(size=(T, 3)), fps, local_pos=lp, name="clip")


def spinning_motion(fps, T, omega=2.0, axis=(0.3, 1.0, -0.2)):
    """One joint spinning at a constant omega rad/s about ``axis``; the root moves at constant speed."""
    sk = Skeleton(("root", "arm"), [-1, 0], [[0.0, 1.0, 0.0], [0.5, 0.0, 0.0]])
    times = np.arange(T) / fps
    rot = np.broadcast_to(quat.IDENTITY, (T, 2, 4)).copy()
    rot[:, 1] = quat.from_axis_angle(np.array(axis), omega * times)
    root = np.array([0.0, 1.0, 0.0]) + np.outer(times, [1.5, 0.0, -0.5])
    return Motion(sk, rot, root, fps)


# ----------------------------------------------------------------------------- validation
def test_valid_motion_basics(rng):
    m = make_motion(rng, T=10, J=5, fps=30)
    assert m.num_frames == len(m) == 10
    assert m.duration == pytest.approx(9 / 30)
    assert isinstance(m.fps, float)
    assert "10 frames @ 30 fps" in repr(m) and "'clip'" in repr(m)


@pytest.mark.parametrize(
    "rot_shape, root_shape, match",
    [
        ((10, 4, 4), (10, 3), r"local_rot of shape \(T, 5, 4\)"),
        ((10, 5, 3), (10, 3), r"\(\.\.\., 4\)"),
        ((5, 4), (10, 3), r"local_rot of shape \(T, 5, 4\)"),
        ((10, 5, 4), (9, 3), r"root_pos of shape \(10, 3\)"),
        ((10, 5, 4), (10, 2), r"root_pos of shape \(10, 3\)"),
    ],
)
def test_shape_validation(rng, rot_shape, root_shape, match):
    sk = random_skeleton(rng, 5)
    with pytest.raises(ValueError, match=match):
        Motion(sk, np.ones(rot_shape), np.zeros(root_shape), fps=30)


def test_local_pos_shape_validation(rng):
    sk = random_skeleton(rng, 5)
    with pytest.raises(ValueError, match=r"local_pos of shape \(10, 5, 3\)"):
        Motion(sk, random_quat(rng, (10, 5)), np.zeros((10, 3)), fps=30, local_pos=np.zeros((10, 4, 3)))


def test_fps_is_required(rng):
    sk = random_skeleton(rng, 2)
    with pytest.raises(TypeError):
        Motion(sk, random_quat(rng, (3, 2)), np.zeros((3, 3)))  # no silent default


@pytest.mark.parametrize("fps", [0, -30, np.nan, np.inf, None, "fast"])
def test_fps_must_be_positive(rng, fps):
    sk = random_skeleton(rng, 2)
    with pytest.raises(ValueError, match="fps must be a positive number"):
        Motion(sk, random_quat(rng, (3, 2)), np.zeros((3, 3)), fps=fps)


def test_construction_does_not_modify_inputs(rng):
    sk = random_skeleton(rng, 4)
    rot, root = random_quat(rng, (6, 4)), rng.normal(size=(6, 3))
    saved = rot.copy(), root.copy()
    rot.setflags(write=False)
    root.setflags(write=False)
    m = Motion(sk, rot, root, fps=30)
    m.fk(), m.resample(45), m[1:4], m.copy()
    np.testing.assert_array_equal(rot, saved[0])
    np.testing.assert_array_equal(root, saved[1])


# ----------------------------------------------------------------------------- slicing and copies
def test_slicing(rng):
    m = make_motion(rng, T=12, local_pos=True)
    part = m[3:7]
    assert part.num_frames == 4
    assert part.fps == m.fps and part.skeleton is m.skeleton and part.name == m.name
    np.testing.assert_array_equal(part.local_rot, m.local_rot[3:7])
    np.testing.assert_array_equal(part.root_pos, m.root_pos[3:7])
    np.testing.assert_array_equal(part.local_pos, m.local_pos[3:7])
    part.local_rot[0] = 0.0  # a copy, not a view
    assert np.all(np.linalg.norm(m.local_rot[3], axis=-1) > 0.5)


def test_single_frame_and_negative_index(rng):
    m = make_motion(rng, T=8)
    one = m[2]
    assert one.num_frames == 1
    np.testing.assert_array_equal(one.local_rot[0], m.local_rot[2])
    np.testing.assert_array_equal(m[-1].root_pos[0], m.root_pos[7])
    np.testing.assert_array_equal(m[-3].root_pos[0], m.root_pos[5])
    assert one.duration == 0.0
    for bad in (8, -9, 100):
        with pytest.raises(IndexError, match="out of range"):
            m[bad]


def test_slicing_with_a_step_divides_fps(rng):
    m = make_motion(rng, T=13, fps=60)
    every_other = m[::2]
    assert every_other.num_frames == 7
    assert every_other.fps == 30.0
    assert every_other.duration == pytest.approx(m.duration)
    np.testing.assert_array_equal(every_other.local_rot, m.local_rot[::2])
    assert m[[0, 3, 4]].fps == 60.0  # an index array keeps fps


def test_copy_is_deep_and_accepts_changes(rng):
    m = make_motion(rng, T=5)
    c = m.copy()
    c.root_pos[0] = 99.0
    assert m.root_pos[0, 0] != 99.0
    renamed = m.copy(name="other", fps=60)
    assert renamed.name == "other" and renamed.fps == 60.0
    np.testing.assert_array_equal(renamed.local_rot, m.local_rot)
    with pytest.raises(ValueError, match="root_pos"):
        m.copy(root_pos=np.zeros((4, 3)))


# ----------------------------------------------------------------------------- kinematics
def test_translations_use_root_pos_then_offsets(rng):
    m = make_motion(rng, T=6, J=4)
    t = m.translations()
    assert t.shape == (6, 4, 3)
    np.testing.assert_array_equal(t[:, 0], m.root_pos)
    np.testing.assert_array_equal(t[:, 1:], np.broadcast_to(m.skeleton.offsets[1:], (6, 3, 3)))


def test_translations_use_local_pos_when_given(rng):
    m = make_motion(rng, T=6, J=4, local_pos=True)
    t = m.translations()
    np.testing.assert_array_equal(t[:, 0], m.root_pos)
    np.testing.assert_array_equal(t[:, 1:], m.local_pos[:, 1:])


def test_motion_fk_equals_fk_module(rng):
    m = make_motion(rng, T=7, J=6)
    global_rot, global_pos = m.fk()
    ref_rot, ref_pos = fk.fk(m.local_rot, m.translations(), m.skeleton.parents)
    np.testing.assert_allclose(global_pos, ref_pos, atol=0)
    np.testing.assert_allclose(global_rot, ref_rot, atol=0)
    np.testing.assert_allclose(m.global_positions(), ref_pos, atol=0)
    np.testing.assert_allclose(m.global_rotations(), ref_rot, atol=1e-15)


def test_rest_motion_reproduces_rest_pose(rng):
    sk = random_skeleton(rng, 9)
    rot = np.broadcast_to(quat.IDENTITY, (3, 9, 4))
    m = Motion(sk, rot, np.broadcast_to(sk.offsets[0], (3, 3)), fps=24)
    np.testing.assert_allclose(m.global_positions(), np.broadcast_to(sk.rest_positions(), (3, 9, 3)), atol=1e-12)


def test_motion_array_motion_round_trip(rng):
    """Motion -> arrays -> Motion"""
    m = make_motion(rng, T=5, J=3, local_pos=True)
    again = Motion(m.skeleton, m.local_rot.copy(), m.root_pos.copy(), m.fps, m.local_pos.copy(), m.name)
    np.testing.assert_array_equal(again.global_positions(), m.global_positions())
    assert again.fps == m.fps and again.name == m.name


# ----------------------------------------------------------------------------- resampling
@pytest.mark.parametrize("T, expected", [(60, 30), (61, 31), (2, 1), (3, 2)])
def test_resample_60_to_30_halves_frames(rng, T, expected):
    m = make_motion(rng, T=T, fps=60)
    half = m.resample(30)
    assert half.fps == 30.0
    assert half.num_frames == expected
    # every new frame is an original even frame
    np.testing.assert_allclose(half.root_pos, m.root_pos[::2][:expected], atol=1e-12)
    assert_quat_close(half.local_rot, m.local_rot[::2][:expected], atol=1e-12)


def test_resample_to_same_fps_is_identity(rng):
    m = make_motion(rng, T=9, fps=30, local_pos=True)
    same = m.resample(30.0)
    assert same is not m
    np.testing.assert_array_equal(same.local_rot, m.local_rot)
    np.testing.assert_array_equal(same.root_pos, m.root_pos)
    np.testing.assert_array_equal(same.local_pos, m.local_pos)
    same.root_pos[0] = 7.0  # an independent copy
    assert m.root_pos[0, 0] != 7.0


@pytest.mark.parametrize("src, dst", [(60, 30), (60, 25), (30, 120), (24, 30), (50, 50 / 3)])
def test_resampled_constant_spin_stays_on_its_curve(src, dst):
    """A constant-angular-velocity rotation resampled at any rate is the same rotation at the new times."""
    m = spinning_motion(src, T=int(src) + 1)  # one second
    r = m.resample(dst)
    new_times = np.arange(r.num_frames) / dst
    assert new_times[-1] <= m.duration + 1e-9
    assert m.duration - new_times[-1] < 1.0 / dst
    expected = spinning_motion(dst, T=r.num_frames)
    assert_quat_close(r.local_rot, expected.local_rot, atol=1e-9)
    np.testing.assert_allclose(r.root_pos, expected.root_pos, atol=1e-12)  # root moves linearly


def test_resample_root_is_linear_between_frames():
    sk = Skeleton(("root",), [-1], [[0.0, 0.0, 0.0]])
    root = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 0.0], [1.0, 2.0, 4.0]])
    m = Motion(sk, np.tile(quat.IDENTITY, (3, 1, 1)), root, fps=10)
    up = m.resample(40)
    assert up.num_frames == 9
    np.testing.assert_allclose(up.root_pos[1], [0.25, 0.5, 0.0])
    np.testing.assert_allclose(up.root_pos[4], [1.0, 2.0, 0.0])
    np.testing.assert_allclose(up.root_pos[6], [1.0, 2.0, 2.0])


def test_resample_local_pos_and_unit_quaternions(rng):
    m = make_motion(rng, T=11, fps=30, local_pos=True)
    r = m.resample(48)
    assert r.local_pos.shape == (r.num_frames, 5, 3)
    np.testing.assert_allclose(r.local_pos[0], m.local_pos[0])
    np.testing.assert_allclose(np.linalg.norm(r.local_rot, axis=-1), 1.0, atol=1e-12)


def test_resample_one_frame_clip_and_bad_fps(rng):
    one = make_motion(rng, T=1, fps=30)
    r = one.resample(60)
    assert r.num_frames == 1 and r.fps == 60.0
    m = make_motion(rng, T=5)
    for bad in (0, -1, np.nan, None):
        with pytest.raises(ValueError, match="fps"):
            m.resample(bad)


def test_resample_keeps_dtype(rng):
    m = make_motion(rng, T=8)
    m32 = Motion(m.skeleton, m.local_rot.astype(np.float32), m.root_pos, fps=30)
    r = m32.resample(20)
    assert r.local_rot.dtype == np.float32
    assert m32.root_pos.dtype == np.float32


def test_check_one_rig_names_the_odd_clip(rng):
    from motionlab.core.motion import check_one_rig

    a = make_motion(rng)
    check_one_rig([a, a.copy()])  # same skeleton and rate: accepted
    faster = Motion(a.skeleton, a.local_rot, a.root_pos, 60.0, name="other")
    with pytest.raises(ValueError, match="clip 'other' is at 60 fps, the library at 30"):
        check_one_rig([a, faster], group="the library")
    with pytest.raises(ValueError, match="clip 'other' is at 60 fps, 'clip' at 30"):
        check_one_rig([a, faster])
    odd = Motion(make_motion(rng, J=4).skeleton, a.local_rot[:, :4], a.root_pos, 30.0, name="odd")
    with pytest.raises(ValueError, match="clip 'odd' uses another skeleton than 'clip'"):
        check_one_rig([a, odd])


def test_resample_to_a_frame_count_holds_the_last_pose():
    m = synthetic.generate("walk", num_frames=20, fps=120)
    half = m.resample(60)
    assert half.num_frames == 10  # frames 0, 2, ..., 18 of the source: it ends before frame 19
    back = half.resample(120, frames=20)
    assert back.num_frames == 20
    np.testing.assert_allclose(back.root_pos[:19], m.root_pos[:19], atol=0.02)
    np.testing.assert_array_equal(back.root_pos[19], back.root_pos[18])
    assert half.resample(120).num_frames == 19


def test_a_motion_refuses_rotations_that_are_not_unit_but_keeps_unknown_frames():
    m = synthetic.generate("walk", num_frames=5, fps=30)
    rot = m.local_rot.copy()
    rot[3, 7] *= 1.1
    with pytest.raises(ValueError, match=r"local_rot\[3, 7\] \(joint '\w+', frame 3\) has norm 1.1"):
        m.copy(local_rot=rot)
    rot[3] = np.nan  # a dropped frame, as gap filling marks it
    assert np.isnan(m.copy(local_rot=rot).local_rot[3]).all()
    with pytest.raises(ValueError, match="whole number >= 0"):
        m.resample(60, frames=-1)
