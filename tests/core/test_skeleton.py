"""Tests for motionlab.core.skeleton.Skeleton: validation, geometry, derived skeletons."""

import numpy as np
import pytest

from motionlab.core.skeleton import Skeleton, SkeletonError
from motionlab.testing import random_skeleton


@pytest.fixture
def rng():
    return np.random.default_rng(99)


def small_body():
    """A 6-joint figure in metres: hips at 1 m, a spine and head, one leg with a foot."""
    names = ("Hips", "Spine", "Head", "LeftUpLeg", "LeftLeg", "LeftFoot")
    parents = [-1, 0, 1, 0, 3, 4]
    offsets = [
        [0.0, 1.0, 0.0],  # root: its rest position
        [0.0, 0.3, 0.0],
        [0.0, 0.4, 0.1],
        [0.1, 0.0, 0.0],
        [0.0, -0.45, 0.0],
        [0.0, -0.45, 0.05],
    ]
    return Skeleton(names, parents, offsets, end_sites={2: [0.0, 0.2, 0.0]})


# ----------------------------------------------------------------------------- validation
def test_parent_after_child_raises_naming_the_joint():
    with pytest.raises(SkeletonError, match=r"'b'.*parents must precede"):
        Skeleton(("a", "b", "c"), [-1, 2, 0], np.zeros((3, 3)))


def test_parent_index_out_of_range_raises():
    with pytest.raises(SkeletonError, match="'c'"):
        Skeleton(("a", "b", "c"), [-1, 0, 7], np.zeros((3, 3)))


def test_self_parent_raises():
    with pytest.raises(SkeletonError, match="'b'"):
        Skeleton(("a", "b"), [-1, 1], np.zeros((2, 3)))


def test_two_roots_raise_naming_the_second():
    with pytest.raises(SkeletonError, match=r"'c'.*second root"):
        Skeleton(("a", "b", "c"), [-1, 0, -1], np.zeros((3, 3)))


def test_root_must_come_first():
    with pytest.raises(SkeletonError, match=r"'a'.*root"):
        Skeleton(("a", "b"), [1, -1], np.zeros((2, 3)))


def test_duplicate_names_raise():
    with pytest.raises(SkeletonError, match=r"duplicate joint name 'b'.*1 and 2"):
        Skeleton(("a", "b", "b"), [-1, 0, 1], np.zeros((3, 3)))


@pytest.mark.parametrize("shape", [(2, 3), (3, 2), (3,), (3, 3, 1)])
def test_wrong_offsets_shape_raises(shape):
    with pytest.raises(SkeletonError, match=r"expected offsets of shape \(3, 3\)"):
        Skeleton(("a", "b", "c"), [-1, 0, 1], np.zeros(shape))


def test_wrong_parents_length_raises():
    with pytest.raises(SkeletonError, match="expected 3 parent indices"):
        Skeleton(("a", "b", "c"), [-1, 0], np.zeros((3, 3)))


def test_non_finite_offset_raises_naming_the_joint():
    offsets = np.zeros((3, 3))
    offsets[2, 1] = np.nan
    with pytest.raises(SkeletonError, match="'c'.*not finite"):
        Skeleton(("a", "b", "c"), [-1, 0, 1], offsets)


def test_empty_skeleton_raises():
    with pytest.raises(SkeletonError, match="at least one joint"):
        Skeleton((), [], np.zeros((0, 3)))


def test_bad_end_site_and_channels_raise():
    with pytest.raises(SkeletonError, match="end site"):
        Skeleton(("a", "b"), [-1, 0], np.zeros((2, 3)), end_sites={5: [0, 1, 0]})
    with pytest.raises(SkeletonError, match="channel layouts"):
        Skeleton(("a", "b"), [-1, 0], np.zeros((2, 3)), channels=(("Zrotation",),))


def test_skeleton_error_is_a_value_error():
    assert issubclass(SkeletonError, ValueError)


# ----------------------------------------------------------------------------- immutability
def test_skeleton_is_immutable_and_does_not_alias_inputs():
    parents = np.array([-1, 0, 1])
    offsets = np.array([[0.0, 1.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.5, 0.0]])
    tip = np.array([0.0, 0.1, 0.0])
    sk = Skeleton(("a", "b", "c"), parents, offsets, end_sites={2: tip})
    parents[2] = 0
    offsets[2] = 9.0
    tip[1] = 9.0
    np.testing.assert_array_equal(sk.parents, [-1, 0, 1])
    np.testing.assert_array_equal(sk.offsets[2], [0.0, 0.5, 0.0])
    np.testing.assert_array_equal(sk.end_sites[2], [0.0, 0.1, 0.0])
    assert parents.flags.writeable and offsets.flags.writeable  # the caller's arrays are untouched
    with pytest.raises(ValueError):
        sk.offsets[0, 0] = 1.0
    with pytest.raises(ValueError):
        sk.parents[1] = -1
    with pytest.raises(AttributeError):
        sk.names = ("x", "y", "z")


# ----------------------------------------------------------------------------- queries and geometry
def test_basic_queries():
    sk = small_body()
    assert sk.num_joints == len(sk) == 6
    assert sk.index("LeftLeg") == 4
    assert sk.children(0) == [1, 3]
    assert sk.children(5) == []
    np.testing.assert_array_equal(sk.depth(), [0, 1, 2, 1, 2, 3])
    np.testing.assert_array_equal(sk.subtree(0), [True] * 6)  # parents (-1, 0, 1, 0, 3, 4)
    np.testing.assert_array_equal(sk.subtree(3), [False, False, False, True, True, True])
    np.testing.assert_array_equal(sk.subtree(5), [False] * 5 + [True])
    assert "6 joints" in repr(sk) and "'Hips'" in repr(sk)


def test_index_of_unknown_name_suggests_close_names():
    with pytest.raises(KeyError, match=r"'Leg'.*LeftUpLeg"):
        small_body().index("Leg")


def test_rest_positions_known_values():
    expected = [
        [0.0, 1.0, 0.0],
        [0.0, 1.3, 0.0],
        [0.0, 1.7, 0.1],
        [0.1, 1.0, 0.0],
        [0.1, 0.55, 0.0],
        [0.1, 0.10, 0.05],
    ]
    np.testing.assert_allclose(small_body().rest_positions(), expected, atol=1e-12)


def test_bone_lengths_known_values():
    expected = [0.0, 0.3, np.hypot(0.4, 0.1), 0.1, 0.45, np.hypot(0.45, 0.05)]
    np.testing.assert_allclose(small_body().bone_lengths(), expected, atol=1e-12)


def test_height_known_value():
    # highest joint: Head at y = 1.7; lowest: LeftFoot at y = 0.10 (end sites not counted)
    assert small_body().height() == pytest.approx(1.6)


def test_root_only_skeleton():
    sk = Skeleton(("root",), [-1], [[0.0, 0.9, 0.0]])
    np.testing.assert_array_equal(sk.rest_positions(), [[0.0, 0.9, 0.0]])
    np.testing.assert_array_equal(sk.bone_lengths(), [0.0])
    assert sk.height() == 0.0
    assert sk.children(0) == []


# ----------------------------------------------------------------------------- derived skeletons
def test_subset_keeps_rest_positions_of_kept_joints(rng):
    sk = random_skeleton(rng, 20)
    keep = [0, 3, 4, 7, 11, 12, 19]
    sub, kept = sk.subset(keep)
    np.testing.assert_array_equal(kept, keep)
    assert sub.names == tuple(sk.names[j] for j in keep)
    np.testing.assert_allclose(sub.rest_positions(), sk.rest_positions()[keep], atol=1e-12)
    # each kept joint hangs from its nearest kept ancestor
    for new_j, old_j in enumerate(kept[1:], start=1):
        ancestor = sk.parents[old_j]
        while ancestor not in keep:
            ancestor = sk.parents[ancestor]
        assert kept[sub.parents[new_j]] == ancestor


def test_subset_sums_offsets_along_removed_chain():
    sub, _ = small_body().subset([0, 1, 3, 5])  # drop Head and LeftLeg
    assert sub.names == ("Hips", "Spine", "LeftUpLeg", "LeftFoot")
    np.testing.assert_array_equal(sub.parents, [-1, 0, 0, 2])
    np.testing.assert_allclose(sub.offsets[3], [0.0, -0.9, 0.05], atol=1e-12)
    assert sub.end_sites == {}  # Head's end site went with Head


def test_subset_ignores_order_and_duplicates_and_needs_the_root():
    sk = small_body()
    a, kept = sk.subset([5, 0, 3, 3])
    np.testing.assert_array_equal(kept, [0, 3, 5])
    assert a.names == ("Hips", "LeftUpLeg", "LeftFoot")
    with pytest.raises(SkeletonError, match="root"):
        sk.subset([1, 2])
    with pytest.raises(SkeletonError, match="root"):
        sk.subset([])


def test_scaled_scales_positions_height_and_end_sites():
    sk = small_body()
    big = sk.scaled(2.0)
    np.testing.assert_allclose(big.rest_positions(), 2.0 * sk.rest_positions())
    assert big.height() == pytest.approx(2.0 * sk.height())
    np.testing.assert_allclose(big.end_sites[2], [0.0, 0.4, 0.0])
    np.testing.assert_allclose(sk.offsets[1], [0.0, 0.3, 0.0])  # original untouched


def test_with_offsets_and_equals():
    sk = small_body()
    new = sk.offsets.copy()
    new[2] *= 3.0
    other = sk.with_offsets(new)
    assert other.names == sk.names
    np.testing.assert_array_equal(other.parents, sk.parents)
    np.testing.assert_allclose(other.end_sites[2], 3.0 * sk.end_sites[2])  # end site scales with its bone
    assert not other.equals(sk)
    assert sk.equals(small_body())
    assert sk.equals(sk.with_offsets(sk.offsets + 1e-12))
    with pytest.raises(SkeletonError):
        sk.with_offsets(np.zeros((2, 3)))


def test_renamed():
    sk = small_body().renamed(["a", "b", "c", "d", "e", "f"])
    assert sk.names[4] == "e"
    with pytest.raises(SkeletonError, match="duplicate"):
        small_body().renamed(["a"] * 6)


# ----------------------------------------------------------------------------- testing helper
@pytest.mark.parametrize("num_joints", [1, 2, 30])
def test_random_skeleton_is_valid(rng, num_joints):
    sk = random_skeleton(rng, num_joints)
    assert sk.num_joints == num_joints
    assert sk.parents[0] == -1
    assert all(0 <= sk.parents[j] < j for j in range(1, num_joints))
    assert len(set(sk.names)) == num_joints
    with pytest.raises(ValueError):
        random_skeleton(rng, 0)


def test_random_skeleton_is_reproducible():
    a = random_skeleton(np.random.default_rng(3), 10)
    b = random_skeleton(np.random.default_rng(3), 10)
    assert a.equals(b, atol=0)


def test_ancestors_run_from_the_root_down_to_the_parent():
    sk = Skeleton(("root", "hips", "spine", "leg", "head"), np.array([-1, 0, 1, 1, 2]), np.zeros((5, 3)))
    assert sk.ancestors(0) == []
    assert sk.ancestors(1) == [0]
    assert sk.ancestors(4) == [0, 1, 2]
    assert sk.ancestors(3) == [0, 1]
