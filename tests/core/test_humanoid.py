"""The canonical 22-joint humanoid, rig profiles and exact reduction."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab.core import humanoid, quat
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from tests.conftest import require_data


def _random_motion(skeleton: Skeleton, rng, frames: int = 20) -> Motion:
    rot = quat.normalize(np.array([1.0, 0, 0, 0]) + 0.3 * rng.normal(size=(frames, skeleton.num_joints, 4)))
    root = skeleton.offsets[0] + rng.normal(scale=0.1, size=(frames, 3))
    return Motion(skeleton, rot, root, fps=30)


def _mixamo_like(prefix: str = "mixamorig:") -> Skeleton:
    """A Mixamo rig with extra joints (Pelvis, a *_split, a finger, hair) around the 22."""
    base = humanoid.canonical_skeleton()
    names, parents, offsets = [], [], []

    def add(name, parent, offset):
        names.append(prefix + name)
        parents.append(-1 if parent is None else names.index(prefix + parent))
        offsets.append(offset)

    for j, name in enumerate(humanoid.JOINTS):
        p = humanoid.PARENTS[j]
        parent = None if p < 0 else humanoid.JOINTS[p]
        if name in ("LeftUpLeg", "RightUpLeg"):
            if prefix + "Pelvis" not in names:
                add("Pelvis", "Hips", np.zeros(3))
            parent = "Pelvis"
        if name == "Spine2":
            add("Spine1_split", "Spine1", np.zeros(3))
            parent = "Spine1_split"
        add(name, parent, base.offsets[j])
    add("LeftHandIndex1", "LeftHand", np.array([0.05, 0.0, 0.0]))
    add("HeadTop_End", "Head", np.array([0.0, 0.2, 0.0]))
    add("HairA", "Head", np.array([0.0, 0.1, -0.1]))
    return Skeleton(names, parents, offsets)


def test_canonical_tables_are_consistent():
    assert len(humanoid.JOINTS) == 22 == len(humanoid.PARENTS)
    sk = humanoid.canonical_skeleton()
    assert humanoid.is_canonical(sk)
    rest = sk.rest_positions()
    assert rest[:, 1].min() >= 0.0  # feet on or above the ground
    assert rest[sk.index("LeftHand"), 0] > 0 > rest[sk.index("RightHand"), 0]  # left is +X
    assert rest[sk.index("LeftToeBase"), 2] > rest[sk.index("LeftFoot"), 2]  # facing +Z


def test_canonical_height_scales():
    a, b = humanoid.canonical_skeleton(1.75), humanoid.canonical_skeleton(1.4)
    assert b.height() == pytest.approx(a.height() * 1.4 / 1.75)
    assert humanoid.leg_length(b) == pytest.approx(humanoid.leg_length(a) * 0.8)


def test_strip_prefix():
    assert humanoid.strip_prefix("mixamorig:LeftArm") == "LeftArm"
    assert humanoid.strip_prefix("newVegas:Hips") == "Hips"
    assert humanoid.strip_prefix("Hips") == "Hips"


@pytest.mark.parametrize("prefix", ["", "mixamorig:", "newVegas:", "mixamorig_", "Armature.mixamorig-"])
def test_mixamo_reduction_is_exact(prefix, rng):
    rig = _mixamo_like(prefix)
    mapping = humanoid.find_mapping(rig)
    assert mapping.profile == "mixamo"
    motion = _random_motion(rig, rng)
    # dropped joints between kept ones must not rotate for fixed offsets to be exact (as in Mixamo)
    for name in ("Pelvis", "Spine1_split"):
        motion.local_rot[:, rig.index(prefix + name)] = quat.IDENTITY
    reduced = humanoid.to_canonical(motion)
    assert reduced.skeleton.names == humanoid.JOINTS
    assert reduced.local_pos is None
    full = motion.global_positions()[:, list(mapping.source)]
    np.testing.assert_allclose(reduced.global_positions(), full, atol=1e-9)
    full_rot = motion.global_rotations()[:, list(mapping.source)]
    assert quat.angle_between(reduced.global_rotations(), full_rot).max() < 1e-6


def test_a_motion_without_frames_reduces_to_one_without_frames(rng):
    """``convert --canonical`` of a file with ``Frames: 0`` names what is wrong (no frames to
    write) instead of NumPy's "zero-size array to reduction operation maximum"."""
    rig = _mixamo_like()
    reduced = humanoid.to_canonical(_random_motion(rig, rng)[:0])
    assert (reduced.num_frames, reduced.skeleton.names) == (0, humanoid.JOINTS)


def test_rotating_dropped_joint_keeps_positions_exact(rng):
    rig = _mixamo_like()
    motion = _random_motion(rig, rng)  # Pelvis and Spine1_split rotate here
    reduced = humanoid.to_canonical(motion)
    assert reduced.local_pos is not None
    full = motion.global_positions()[:, list(humanoid.find_mapping(rig).source)]
    np.testing.assert_allclose(reduced.global_positions(), full, atol=1e-9)


def test_a_rig_whose_names_no_profile_knows_is_not_given_a_closest_profile():
    """Every profile misses every joint of it: naming the one with the fewest joints to miss
    (Bandai Namco's, whose Spine2 is None) as "closest" misled."""
    sk = humanoid.canonical_skeleton()
    odd = sk.renamed([f"bone{j:02d}" for j in range(sk.num_joints)])
    with pytest.raises(humanoid.RigMappingError, match="no profile finds any of its joints") as e:
        humanoid.find_mapping(odd)
    assert "closest" not in str(e.value)


def test_unmappable_rig_names_missing_joints():
    sk = humanoid.canonical_skeleton()
    names = list(sk.names)
    names[names.index("LeftToeBase")] = "LeftToe_End_Thing"
    with pytest.raises(humanoid.RigMappingError, match="LeftToeBase"):
        humanoid.find_mapping(sk.renamed(names))


def test_custom_mapping():
    sk = humanoid.canonical_skeleton()
    names = [n.replace("Left", "L_") for n in sk.names]
    renamed = sk.renamed(names)
    custom = {j: j.replace("Left", "L_") for j in humanoid.JOINTS if j.startswith("Left")}
    mapping = humanoid.find_mapping(renamed, custom)
    assert mapping.source == tuple(range(22))


def test_scale_bones_changes_only_its_group():
    sk = humanoid.canonical_skeleton()
    new = humanoid.scale_bones(sk, legs=1.3, arms=0.8)
    lengths, new_lengths = sk.bone_lengths(), new.bone_lengths()
    for j, name in enumerate(humanoid.JOINTS):
        if name in humanoid.BONE_GROUPS["legs"]:
            assert new_lengths[j] == pytest.approx(1.3 * lengths[j])
        elif name in humanoid.BONE_GROUPS["arms"]:
            assert new_lengths[j] == pytest.approx(0.8 * lengths[j])
        elif j > 0:
            assert new_lengths[j] == pytest.approx(lengths[j])
    assert humanoid.leg_length(new) == pytest.approx(1.3 * humanoid.leg_length(sk))
    assert new.rest_positions()[:, 1].min() == pytest.approx(sk.rest_positions()[:, 1].min())


def test_scale_bones_overall_and_errors():
    sk = humanoid.canonical_skeleton()
    assert humanoid.scale_bones(sk, overall=0.5).height() == pytest.approx(0.5 * sk.height())
    with pytest.raises(ValueError, match="legs"):
        humanoid.scale_bones(sk, legs=0.0)


@pytest.mark.slow
@pytest.mark.realdata
def test_every_real_rig_reduces_with_positions_preserved():
    """Every BVH under MOTIONLAB_DATA maps onto the 22 joints with world positions kept to 1e-4·height."""
    from motionlab.core import bvh

    root = require_data()
    files = sorted(root.rglob("*.bvh"))
    assert files
    for path in files:
        motion = bvh.load(path)
        mapping = humanoid.find_mapping(motion.skeleton)
        reduced = humanoid.to_canonical(motion)
        idx = np.array(mapping.source)
        for c in range(22):  # synthesised joints (Bandai's Spine2) sit on their parent
            if idx[c] < 0:
                idx[c] = idx[humanoid.PARENTS[c]]
        err = np.abs(reduced.global_positions() - motion.global_positions()[:, idx]).max()
        assert err <= 1e-4 * motion.skeleton.height(), f"{path}: {err} m"


@pytest.mark.realdata
def test_mixamo_heights_match_the_paper():
    """The paper quotes Aj at 141.97 cm: the 22-joint rest height of the shared Aj rig."""
    from motionlab.core import bvh

    path = require_data("mixamo", "Aj", "Running.bvh")
    aj = humanoid.to_canonical_skeleton(bvh.load(path).skeleton)
    assert aj.height() == pytest.approx(1.4197, abs=5e-4)


def test_a_custom_profile_with_an_unknown_joint_or_no_root_is_refused():
    sk = humanoid.canonical_skeleton()
    with pytest.raises(humanoid.RigMappingError, match="'LeftUpleg'"):
        humanoid.find_mapping(sk, {"LeftUpleg": "LeftUpLeg"})
    with pytest.raises(humanoid.RigMappingError, match="the root"):
        humanoid.find_mapping(sk, {"Hips": None})


def test_a_prefixed_humanoid_is_not_taken_for_the_canonical_one():
    sk = humanoid.canonical_skeleton()
    prefixed = Skeleton(tuple(f"mixamorig:{n}" for n in sk.names), sk.parents, sk.offsets, sk.end_sites)
    assert not humanoid.is_canonical(prefixed)
    assert humanoid.leg_length(prefixed) == pytest.approx(humanoid.leg_length(sk))
    assert humanoid.is_canonical(humanoid.scale_bones(prefixed, legs=1.1))
