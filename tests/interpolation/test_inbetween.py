"""In-betweening: identity on a motion against itself, known linear answers, Hermite ends, errors."""

import numpy as np
import pytest

from motionlab.core import quat
from motionlab.interpolation import inbetween
from motionlab.testing import assert_quat_close, random_quat

from .conftest import toy_motion


def test_log_exp_round_trip():
    """q -> log -> exp -> q"""
    rng = np.random.default_rng(0)
    q = random_quat(rng, (100,))
    assert_quat_close(inbetween.exp(inbetween.log(q)), q, atol=1e-10)
    assert_quat_close(inbetween.exp(np.zeros(3)), quat.IDENTITY)


def test_interpolating_a_pose_against_itself_is_the_identity():
    m = toy_motion(10)
    for rotation, root in (("slerp", "linear"), ("hermite", "hermite")):
        rot, pos = inbetween.interpolate(
            m.local_rot[3], m.root_pos[3], m.local_rot[3], m.root_pos[3], 7,
            rotation=rotation, root=root, vel_a=np.zeros(3), vel_b=np.zeros(3), ang_vel_a=np.zeros((7, 3)),
        )  # fmt: skip
        assert rot.shape == (7, 7, 4) and pos.shape == (7, 3)
        assert_quat_close(rot, np.broadcast_to(m.local_rot[3], rot.shape), atol=1e-12)
        np.testing.assert_allclose(pos, np.broadcast_to(m.root_pos[3], pos.shape), atol=1e-12)


def test_inbetween_of_a_motion_with_itself_recovers_a_constant_pose():
    m = toy_motion(1)
    out = inbetween.inbetween(m, m, 5)
    assert out.num_frames == 7
    assert_quat_close(out.local_rot, np.broadcast_to(m.local_rot[0], out.local_rot.shape), atol=1e-12)
    np.testing.assert_allclose(out.root_pos, np.broadcast_to(m.root_pos[0], (7, 3)), atol=1e-12)


def test_fill_between_reproduces_a_slerp_motion_exactly():
    rng = np.random.default_rng(1)
    a, b = random_quat(rng, (5,)), random_quat(rng, (5,))
    w = np.arange(12) / 11
    from motionlab.core.motion import Motion
    from motionlab.testing import random_skeleton

    sk = random_skeleton(rng, 5)
    rot = quat.slerp(a[None], b[None], w[:, None])
    root = np.outer(1 - w, [0, 1, 0]) + np.outer(w, [2, 1, 3])
    m = Motion(sk, rot, root, 30.0)
    broken = m.copy()
    broken.local_rot[1:11] = np.nan
    broken.root_pos[1:11] = np.nan
    fixed = inbetween.fill_between(broken, 1, 11)
    assert_quat_close(fixed.local_rot, m.local_rot, atol=1e-10)
    np.testing.assert_allclose(fixed.root_pos, m.root_pos, atol=1e-12)


def test_hermite_root_meets_ends_and_start_velocity():
    pa, pb, va = np.zeros(3), np.array([3.0, 0.0, 0.0]), np.array([0.0, 0.0, 0.5])
    num = 99
    rot = random_quat(np.random.default_rng(2), (2,))
    _, pos = inbetween.interpolate(rot, pa, rot, pb, num, root="hermite", vel_a=va)
    full = np.concatenate([pa[None], pos, pb[None]])
    L = num + 1  # quadratic p(s) = p_a + v_a L s + (p_b - p_a - v_a L) s², s = k / L
    np.testing.assert_allclose(full[1] - full[0], va + (pb - pa - va * L) / L**2, atol=1e-12)
    np.testing.assert_allclose(full[1] - full[0], va, atol=6e-3)  # so the first step ≈ v_a
    _, pos2 = inbetween.interpolate(rot, pa, rot, pb, num, root="hermite", vel_a=va, vel_b=va)
    full2 = np.concatenate([pa[None], pos2, pb[None]])
    np.testing.assert_allclose(full2[-1] - full2[-2], va, atol=2e-2)  # O(1/L) from the curvature


def test_hermite_rotation_equals_slerp_when_velocity_is_the_chord():
    rng = np.random.default_rng(3)
    qa, qb = random_quat(rng, (4,)), random_quat(rng, (4,))
    num = 6
    chord = inbetween.log(quat.mul(quat.conj(qa), qb)) / (num + 1)
    r1, _ = inbetween.interpolate(qa, np.zeros(3), qb, np.zeros(3), num, rotation="hermite", ang_vel_a=chord)
    r2, _ = inbetween.interpolate(qa, np.zeros(3), qb, np.zeros(3), num)
    assert_quat_close(r1, r2, atol=1e-10)


def test_batched_equals_single():
    rng = np.random.default_rng(4)
    qa, qb = random_quat(rng, (3, 5)), random_quat(rng, (3, 5))
    pa, pb = rng.normal(size=(3, 3)), rng.normal(size=(3, 3))
    rot, pos = inbetween.interpolate(qa, pa, qb, pb, 4)
    for i in range(3):
        r, p = inbetween.interpolate(qa[i], pa[i], qb[i], pb[i], 4)
        np.testing.assert_allclose(rot[i], r, atol=1e-14)
        np.testing.assert_allclose(pos[i], p, atol=1e-14)


def test_bad_input():
    q = np.tile(quat.IDENTITY, (3, 1))
    with pytest.raises(ValueError, match="root positions"):
        inbetween.interpolate(q, np.zeros(2), q, np.zeros(3), 3)
    with pytest.raises(ValueError, match="root interpolation"):
        inbetween.interpolate(q, np.zeros(3), q, np.zeros(3), 3, root="spline")
    with pytest.raises(ValueError, match="known frame on each side"):
        inbetween.fill_between(toy_motion(10), 0, 3)


def test_inputs_not_modified():
    m = toy_motion(20)
    before = m.copy()
    inbetween.fill_between(m, 5, 9, root="hermite", rotation="hermite")
    np.testing.assert_array_equal(m.local_rot, before.local_rot)
    np.testing.assert_array_equal(m.root_pos, before.root_pos)


def test_two_sided_hermite_rotation_known_answers():
    """Both end slopes the chord: SLERP; the curve's end steps are the end velocities (horizon = the gap)."""
    rng = np.random.default_rng(5)
    qa, qb = random_quat(rng, (4,)), random_quat(rng, (4,))
    num = 30
    chord = inbetween.log(quat.mul(quat.conj(qa), qb)) / (num + 1)
    args = (qa, np.zeros(3), qb, np.zeros(3), num)
    r1, _ = inbetween.interpolate(*args, rotation="hermite", ang_vel_a=chord, ang_vel_b=chord)
    assert_quat_close(r1, inbetween.interpolate(*args)[0], atol=1e-10)
    w0, w1 = 0.01 * rng.normal(size=(4, 3)), 0.01 * rng.normal(size=(4, 3))
    qb = quat.mul(qa, inbetween.exp(0.2 * rng.normal(size=(4, 3))))  # a small d: the curvature is O(|d|/L²)
    rot, _ = inbetween.interpolate(
        qa, np.zeros(3), qb, np.zeros(3), num, rotation="hermite", ang_vel_a=w0, ang_vel_b=w1
    )
    first = inbetween.log(quat.mul(quat.conj(qa), rot[0]))
    last = inbetween.log(quat.mul(quat.conj(rot[-1]), qb))
    np.testing.assert_allclose(first, w0, atol=4e-3)  # off by O(|ω|/L + |d|/L²)
    np.testing.assert_allclose(last, w1, atol=4e-3)


def test_hermite_rotation_stays_near_its_key_poses_across_a_long_gap():
    """A joint turning at 0.1 rad per frame on both sides of an 80-frame gap with equal key poses:
    r(s) = (h10 + h11)(s) ω H = (2s³ − 3s² + s) ω H, whose largest value is √3/18 ω H."""
    q = np.tile(quat.IDENTITY, (1, 1))
    w = np.array([[0.1, 0.0, 0.0]])
    args = (q, np.zeros(3), q, np.zeros(3), 80)

    def swing(**kw):
        rot, _ = inbetween.interpolate(*args, rotation="hermite", ang_vel_a=w, ang_vel_b=w, **kw)
        return float(np.max(np.linalg.norm(inbetween.log(rot), axis=-1)))

    peak = np.sqrt(3) / 18 * 0.1
    assert swing() == pytest.approx(peak * 81, rel=1e-3)  # H = L: 0.78 rad from both key poses
    assert swing(horizon=14) == pytest.approx(peak * 14, rel=1e-3)
    with pytest.raises(ValueError, match="horizon"):
        swing(horizon=0)
    with pytest.raises(ValueError, match="ang_vel_b of shape"):
        inbetween.interpolate(*args, rotation="hermite", ang_vel_a=w, ang_vel_b=np.zeros((2, 3)))
    with pytest.raises(ValueError, match="vel_b of shape"):
        inbetween.interpolate(*args, root="hermite", vel_a=np.zeros(3), vel_b=np.zeros((7, 3)))
