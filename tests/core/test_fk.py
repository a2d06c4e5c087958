"""Tests for motionlab.core.fk and its torch twin motionlab.core.fk_torch."""

import numpy as np
import pytest
import torch

from motionlab.core import fk, fk_torch, quat
from motionlab.core.skeleton import Skeleton
from motionlab.testing import assert_quat_close, random_quat, random_skeleton

F64 = torch.float64


@pytest.fixture
def rng():
    return np.random.default_rng(7)


def rest_inputs(skeleton, leading=()):
    """Identity local rotations and the skeleton's offsets (root at its offset)."""
    J = skeleton.num_joints
    rot = np.broadcast_to(quat.IDENTITY, leading + (J, 4)).copy()
    pos = np.broadcast_to(skeleton.offsets, leading + (J, 3)).copy()
    return rot, pos


def chain3():
    """root at (1, 2, 3); two unit bones along +x."""
    return Skeleton(("root", "mid", "tip"), [-1, 0, 1], [[1.0, 2.0, 3.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])


# ----------------------------------------------------------------------------- known answers
@pytest.mark.parametrize("num_joints", [1, 2, 9, 25])
def test_rest_pose_gives_cumulative_offsets(rng, num_joints):
    sk = random_skeleton(rng, num_joints)
    rot, pos = rest_inputs(sk)
    global_rot, global_pos = fk.fk(rot, pos, sk.parents)
    np.testing.assert_allclose(global_pos, sk.rest_positions(), atol=1e-12)
    np.testing.assert_allclose(global_rot, rot, atol=0)
    # and the cumulative offsets by hand
    expected = sk.offsets.copy()
    for j in range(1, num_joints):
        expected[j] = expected[sk.parents[j]] + sk.offsets[j]
    np.testing.assert_allclose(global_pos, expected, atol=1e-12)


def test_three_joint_chain_with_90_degree_bend():
    sk = chain3()
    rot, pos = rest_inputs(sk)
    rot[1] = quat.from_axis_angle([0.0, 0.0, 1.0], np.pi / 2)  # bend the middle joint +90° about z
    global_rot, global_pos = fk.fk(rot, pos, sk.parents)
    np.testing.assert_allclose(global_pos, [[1, 2, 3], [2, 2, 3], [2, 3, 3]], atol=1e-12)
    assert_quat_close(global_rot[2], rot[1], atol=1e-12)


def test_three_joint_chain_with_root_and_joint_rotation():
    sk = chain3()
    rot, pos = rest_inputs(sk)
    rot[0] = quat.from_axis_angle([0.0, 1.0, 0.0], np.pi / 2)  # +90° about y: +x -> -z
    rot[1] = quat.from_axis_angle([0.0, 0.0, 1.0], np.pi / 2)  # then +x -> +y in the mid frame
    _, global_pos = fk.fk(rot, pos, sk.parents)
    # mid: root + Ry(+x) = (1,2,3) + (0,0,-1); tip: mid + Ry(Rz(+x)) = mid + Ry(+y) = mid + (0,1,0)
    np.testing.assert_allclose(global_pos, [[1, 2, 3], [1, 2, 2], [1, 3, 2]], atol=1e-12)


def test_root_rotation_moves_skeleton_rigidly(rng):
    sk = random_skeleton(rng, 12)
    rot, pos = rest_inputs(sk)
    q = random_quat(rng)
    rot[0] = q
    _, global_pos = fk.fk(rot, pos, sk.parents)
    rest = sk.rest_positions()
    np.testing.assert_allclose(global_pos - global_pos[0], quat.rotate(q, rest - rest[0]), atol=1e-12)


def test_bone_lengths_are_preserved(rng):
    sk = random_skeleton(rng, 15)
    rot = random_quat(rng, (4, 15))
    pos = np.broadcast_to(sk.offsets, (4, 15, 3))
    _, global_pos = fk.fk(rot, pos, sk.parents)
    lengths = np.linalg.norm(global_pos[:, 1:] - global_pos[:, sk.parents[1:]], axis=-1)
    np.testing.assert_allclose(lengths, np.broadcast_to(sk.bone_lengths()[1:], (4, 14)), atol=1e-12)


def test_root_only_skeleton(rng):
    rot = random_quat(rng, (5, 1))
    pos = rng.normal(size=(5, 1, 3))
    global_rot, global_pos = fk.fk(rot, pos, [-1])
    np.testing.assert_array_equal(global_rot, rot)
    np.testing.assert_array_equal(global_pos, pos)


# ----------------------------------------------------------------------------- batches and twins
def test_batched_fk_equals_frame_by_frame(rng):
    sk = random_skeleton(rng, 8)
    B, T, J = 2, 5, 8
    rot = random_quat(rng, (B, T, J))
    pos = np.broadcast_to(sk.offsets, (B, T, J, 3)).copy()
    pos[..., 0, :] = rng.normal(size=(B, T, 3))
    global_rot, global_pos = fk.fk(rot, pos, sk.parents)
    assert global_rot.shape == (B, T, J, 4)
    assert global_pos.shape == (B, T, J, 3)
    for b in range(B):
        for t in range(T):
            r1, p1 = fk.fk(rot[b, t], pos[b, t], sk.parents)
            np.testing.assert_allclose(global_rot[b, t], r1, atol=1e-14)
            np.testing.assert_allclose(global_pos[b, t], p1, atol=1e-14)


def test_local_pos_broadcasts_over_frames(rng):
    sk = random_skeleton(rng, 6)
    rot = random_quat(rng, (4, 6))
    _, broadcast = fk.fk(rot, sk.offsets, sk.parents)
    _, tiled = fk.fk(rot, np.tile(sk.offsets, (4, 1, 1)), sk.parents)
    np.testing.assert_allclose(broadcast, tiled, atol=0)
    assert fk.fk_positions(rot, sk.offsets, sk.parents).shape == (4, 6, 3)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_dtype_is_kept(rng, dtype):
    sk = random_skeleton(rng, 5)
    global_rot, global_pos = fk.fk(random_quat(rng, (3, 5)).astype(dtype), sk.offsets, sk.parents)
    assert global_rot.dtype == dtype
    assert global_pos.dtype == dtype


def test_numpy_fk_equals_torch_fk(rng):
    sk = random_skeleton(rng, 10)
    rot = random_quat(rng, (3, 4, 10))
    pos = np.broadcast_to(sk.offsets, (3, 4, 10, 3)).copy()
    pos[..., 0, :] = rng.normal(size=(3, 4, 3))
    ref_rot, ref_pos = fk.fk(rot, pos, sk.parents)
    t_rot, t_pos = fk_torch.fk(torch.tensor(rot), torch.tensor(pos), sk.parents)
    np.testing.assert_allclose(t_rot.numpy(), ref_rot, atol=1e-12)
    np.testing.assert_allclose(t_pos.numpy(), ref_pos, atol=1e-12)
    np.testing.assert_allclose(
        fk_torch.fk_positions(torch.tensor(rot), torch.tensor(pos), sk.parents).numpy(), ref_pos, atol=1e-12
    )
    # parents may also be given as a tensor
    t_rot2, _ = fk_torch.fk(torch.tensor(rot), torch.tensor(pos), torch.tensor(sk.parents))
    torch.testing.assert_close(t_rot2, t_rot)


def test_torch_local_to_global_and_bone_directions_match_numpy(rng):
    sk = random_skeleton(rng, 9)
    rot = random_quat(rng, (5, 9))
    np.testing.assert_allclose(
        fk_torch.local_to_global(torch.tensor(rot), sk.parents).numpy(), fk.local_to_global(rot, sk.parents), atol=1e-12
    )
    g = fk.local_to_global(rot, sk.parents)
    np.testing.assert_allclose(
        fk_torch.global_to_local(torch.tensor(g), sk.parents).numpy(), fk.global_to_local(g, sk.parents), atol=1e-12
    )
    _, pos = fk.fk(rot, sk.offsets, sk.parents)
    np.testing.assert_allclose(
        fk_torch.bone_directions(torch.tensor(pos), sk.parents).numpy(), fk.bone_directions(pos, sk.parents), atol=1e-12
    )


def test_torch_fk_gradients_finite_at_rest_and_random(rng):
    sk = random_skeleton(rng, 6)
    for rot in (np.tile(quat.IDENTITY, (2, 6, 1)), random_quat(rng, (2, 6))):
        r = torch.tensor(rot, dtype=F64, requires_grad=True)
        p = torch.tensor(np.broadcast_to(sk.offsets, (2, 6, 3)).copy(), dtype=F64, requires_grad=True)
        global_rot, global_pos = fk_torch.fk(r, p, sk.parents)
        gr, gp = torch.autograd.grad(global_pos.sum() + global_rot.sum(), (r, p))
        assert torch.isfinite(gr).all() and torch.isfinite(gp).all()
        assert gr.abs().sum() > 0


def test_torch_fk_gradcheck(rng):
    sk = random_skeleton(rng, 4)
    r = torch.tensor(random_quat(rng, (2, 4)), dtype=F64, requires_grad=True)
    p = torch.tensor(np.broadcast_to(sk.offsets, (2, 4, 3)).copy(), dtype=F64, requires_grad=True)
    assert torch.autograd.gradcheck(lambda a, b: fk_torch.fk(a, b, sk.parents), (r, p))


# ----------------------------------------------------------------------------- global <-> local
def test_global_to_local_inverts_local_to_global(rng):
    """local -> global -> local"""
    sk = random_skeleton(rng, 12)
    local = random_quat(rng, (3, 12))
    back = fk.global_to_local(fk.local_to_global(local, sk.parents), sk.parents)
    assert_quat_close(back, local, atol=1e-12)
    t_back = fk_torch.global_to_local(fk_torch.local_to_global(torch.tensor(local), sk.parents), sk.parents)
    assert_quat_close(t_back, local, atol=1e-12)


def test_local_to_global_inverts_global_to_local(rng):
    """global -> local -> global"""
    sk = random_skeleton(rng, 12)
    glob = random_quat(rng, (3, 12))
    assert_quat_close(fk.local_to_global(fk.global_to_local(glob, sk.parents), sk.parents), glob, atol=1e-12)


def test_local_to_global_is_the_rotation_half_of_fk(rng):
    sk = random_skeleton(rng, 7)
    local = random_quat(rng, (4, 7))
    np.testing.assert_allclose(fk.local_to_global(local, sk.parents), fk.fk(local, sk.offsets, sk.parents)[0], atol=0)


def test_fk_ik_fk_round_trip(rng):
    """fk -> ik (global_to_local of the global rotations) -> fk"""
    sk = random_skeleton(rng, 10)
    local = random_quat(rng, (6, 10))
    global_rot, global_pos = fk.fk(local, sk.offsets, sk.parents)
    local_again = fk.global_to_local(global_rot, sk.parents)
    global_rot2, global_pos2 = fk.fk(local_again, sk.offsets, sk.parents)
    np.testing.assert_allclose(global_pos2, global_pos, atol=1e-12)
    assert_quat_close(global_rot2, global_rot, atol=1e-12)


# ----------------------------------------------------------------------------- bones and angles
def test_bone_directions_unit_length(rng):
    sk = random_skeleton(rng, 14)
    _, pos = fk.fk(random_quat(rng, (5, 14)), sk.offsets, sk.parents)
    d = fk.bone_directions(pos, sk.parents)
    assert d.shape == (5, 14, 3)
    np.testing.assert_allclose(np.linalg.norm(d[:, 1:], axis=-1), 1.0, atol=1e-12)
    np.testing.assert_array_equal(d[:, 0], 0.0)
    bones = pos[:, 1:] - pos[:, sk.parents[1:]]
    np.testing.assert_allclose(d[:, 1:] * np.linalg.norm(bones, axis=-1, keepdims=True), bones, atol=1e-12)
    dt = fk_torch.bone_directions(torch.tensor(pos), sk.parents)
    np.testing.assert_allclose(dt.numpy(), d, atol=1e-12)


def test_bone_directions_zero_length_bone_is_zero():
    pos = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    d = fk.bone_directions(pos, [-1, 0, 1])
    np.testing.assert_array_equal(d, [[0, 0, 0], [0, 0, 0], [0, 1, 0]])


def test_joint_angles_straight_chain_is_zero():
    pos = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.5, 0.0, 0.0]])
    np.testing.assert_allclose(fk.joint_angles(pos, [-1, 0, 1, 2]), 0.0, atol=1e-7)


def test_joint_angles_right_angle_and_fold():
    pos = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    angles = fk.joint_angles(pos, [-1, 0, 1, 2])
    # index 2 measures the bend at joint 1 (bones 0→1 and 1→2); index 3 the fold at joint 2
    np.testing.assert_allclose(angles, [0.0, 0.0, np.pi / 2, np.pi], atol=1e-12)


def test_joint_angles_from_fk():
    """Bending the middle joint of a straight chain by θ gives joint angle θ at the tip."""
    sk = chain3()
    theta = np.linspace(0.0, 3.0, 7)
    rot = np.broadcast_to(quat.IDENTITY, (7, 3, 4)).copy()
    rot[:, 1] = quat.from_axis_angle([0.0, 0.0, 1.0], theta)
    _, pos = fk.fk(rot, sk.offsets, sk.parents)
    np.testing.assert_allclose(fk.joint_angles(pos, sk.parents)[:, 2], theta, atol=1e-7)


# ----------------------------------------------------------------------------- errors and purity
@pytest.mark.parametrize(
    "parents, match",
    [
        ([-1, 0], "3 parent indices"),
        ([-1, 2, 0], r"parents\[1\] = 2"),
        ([-1, 0, -1], r"parents\[2\] = -1"),
        ([0, 0, 1], r"parents\[0\] = 0"),
        ([-1, 0, 5], r"parents\[2\] = 5"),
    ],
)
def test_bad_parents_raise(parents, match):
    rot = np.tile(quat.IDENTITY, (2, 3, 1))
    pos = np.zeros((2, 3, 3))
    with pytest.raises(ValueError, match=match):
        fk.fk(rot, pos, parents)
    with pytest.raises(ValueError, match=match):
        fk.local_to_global(rot, parents)
    with pytest.raises(ValueError, match=match):
        fk_torch.fk(torch.tensor(rot), torch.tensor(pos), parents)


@pytest.mark.parametrize(
    "rot_shape, pos_shape",
    [((2, 3, 4), (2, 2, 3)), ((2, 3, 4), (2, 3, 4)), ((2, 3, 4), (3,)), ((4,), (1, 3)), ((2, 3, 3), (2, 3, 3))],
)
def test_bad_shapes_raise(rot_shape, pos_shape):
    rot = np.zeros(rot_shape)
    pos = np.zeros(pos_shape)
    with pytest.raises(ValueError, match="expected"):
        fk.fk(rot, pos, [-1, 0, 1])
    with pytest.raises(ValueError, match="expected"):
        fk_torch.fk(torch.tensor(rot), torch.tensor(pos), [-1, 0, 1])


def test_fk_does_not_modify_inputs(rng):
    sk = random_skeleton(rng, 6)
    rot = random_quat(rng, (3, 6))
    pos = np.broadcast_to(sk.offsets, (3, 6, 3)).copy()
    parents = sk.parents.copy()
    saved = [rot.copy(), pos.copy(), parents.copy()]
    for x in (rot, pos, parents):
        x.setflags(write=False)
    global_rot, global_pos = fk.fk(rot, pos, parents)
    fk.local_to_global(rot, parents)
    fk.global_to_local(global_rot, parents)
    fk.bone_directions(global_pos, parents)
    fk.joint_angles(global_pos, parents)
    for x, s in zip((rot, pos, parents), saved):
        np.testing.assert_array_equal(x, s)
    trot, tpos = torch.tensor(rot), torch.tensor(pos)
    fk_torch.fk(trot, tpos, parents)
    fk_torch.global_to_local(trot, parents)
    fk_torch.bone_directions(tpos, parents)
    np.testing.assert_array_equal(trot.numpy(), saved[0])
    np.testing.assert_array_equal(tpos.numpy(), saved[1])


def test_blocked_fk_matches_the_per_joint_definition_across_block_borders():
    """fk works on blocks of frames laid out component by component; the result must not notice."""
    from motionlab.core import fk as fk_module

    rng = np.random.default_rng(3)
    parents = np.array([-1, 0, 1, 1, 3, 0, 5])
    n = 2 * fk_module._CHUNK + 17
    local_rot = quat.normalize(rng.normal(size=(n, 7, 4)))
    local_pos = rng.normal(size=(n, 7, 3))
    g_rot, g_pos = fk_module.fk(local_rot, local_pos, parents)
    ref_rot, ref_pos = local_rot.copy(), local_pos.copy()
    for j in range(1, 7):  # the definition, one joint at a time
        p = parents[j]
        ref_rot[:, j] = quat.mul(ref_rot[:, p], local_rot[:, j])
        ref_pos[:, j] = ref_pos[:, p] + quat.rotate(ref_rot[:, p], local_pos[:, j])
    np.testing.assert_allclose(g_rot, ref_rot, atol=1e-12)
    np.testing.assert_allclose(g_pos, ref_pos, atol=1e-12)
    # leading batch shapes and shared offsets broadcast as before
    b_rot, b_pos = fk_module.fk(local_rot[:12].reshape(3, 4, 7, 4), local_pos[0], parents)
    s_rot, s_pos = fk_module.fk(local_rot[:12], np.broadcast_to(local_pos[0], (12, 7, 3)), parents)
    np.testing.assert_allclose(b_pos.reshape(12, 7, 3), s_pos, atol=1e-12)
    np.testing.assert_allclose(b_rot.reshape(12, 7, 4), s_rot, atol=1e-12)


def test_bone_directions_and_angles_keep_nan():
    pos = np.array([[[0.0, 0, 0], [0, 1, 0], [np.nan, 2, 0], [0, 3, 0]]])
    parents = [-1, 0, 1, 2]
    d = fk.bone_directions(pos, parents)
    assert np.isnan(d[0, 2]).any() and np.isnan(d[0, 3]).any()
    np.testing.assert_allclose(d[0, 1], [0, 1, 0])
    angles = fk.joint_angles(pos, parents)
    assert np.isnan(angles[0, 2]) and np.isnan(angles[0, 3]) and angles[0, 1] == 0.0
