"""Feet kept out of the floor across a filled gap by bending the legs, not by lifting the body.

SLERP between the two poses bounding a gap turns each leg joint at a constant rate, and half-way
the leg is longer, top to bottom, than either end pose holds it: the stance foot sinks into the
floor. :func:`.gaps.lift_above_floor` lifts the whole body out by that depth, which keeps the feet
dry but makes the hips hop where the walker's stay level (``docs/results_interpolation.md``,
``python -m experiments.interpolation.compare_feet``).

:func:`plant_feet` instead moves each foot that went below the floor straight up by its depth,
rigidly (the ankle's world rotation kept, so the toes follow), and bends that leg to reach it: the
hip → knee → ankle chain is solved in closed form (:func:`motionlab.synthetic.ik.two_bone`), the
knee bending the way it already bends (towards the toes where the leg is held straight), the hip
and knee joints turned by the shortest rotations that carry the old bones onto the new ones, and
the ankle's local rotation set so that its world rotation is what it was. Where a leg cannot reach
(folded as far as it goes), what is left is lifted by :func:`.gaps.lift_above_floor` as before.

The floor is the one :func:`.gaps.lift_above_floor` uses: the lower of the lowest joints (the root
left out) of the two known frames ``a`` and ``b``. The legs are found by the humanoid rig mapping
(:func:`motionlab.core.humanoid.find_mapping`); a rig it does not map has its body lifted only.
"""

from __future__ import annotations

import numpy as np

from motionlab.core import humanoid, quat
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.synthetic.ik import two_bone

__all__ = ["legs", "lowest_joints", "plant_feet"]

_SIDES = (("LeftUpLeg", "LeftLeg", "LeftFoot"), ("RightUpLeg", "RightLeg", "RightFoot"))


def legs(skeleton: Skeleton) -> list[tuple[int, int, int]]:
    """The ``(hip, knee, ankle)`` joint indices of each leg of a humanoid rig (left, right), or
    ``[]`` where :func:`~motionlab.core.humanoid.find_mapping` does not map the rig."""
    try:
        mapping = humanoid.find_mapping(skeleton)
    except humanoid.RigMappingError:
        return []
    out = []
    for names in _SIDES:
        hip, knee, ankle = (mapping.source[humanoid.JOINTS.index(n)] for n in names)
        if min(hip, knee, ankle) >= 0:
            out.append((int(hip), int(knee), int(ankle)))
    return out


def lowest_joints(motion: Motion, a: int, b: int) -> np.ndarray:
    """Height (b−a+1,), metres, of the lowest joint of each frame ``a … b``, the root left out: in
    rigs that carry the body with a hips channel (Bandai Namco) it is a marker lying on the floor,
    not a foot. A gap's floor is the lower of the two ends, ``min(low[0], low[-1])``."""
    height = motion[a : b + 1].global_positions()[..., 1]  # (b-a+1, J)
    return (height[:, 1:] if height.shape[1] > 1 else height).min(axis=-1)


def plant_feet(motion: Motion, a: int, b: int) -> Motion:
    """A copy of ``motion`` whose frames ``a+1 … b-1`` have every foot that went below the floor
    raised onto it by bending its leg (module docstring); other frames untouched.

    Parameters
    ----------
    motion : Motion whose frames ``a`` and ``b`` are known and ``a+1 … b-1`` filled (no NaN)
    a, b : int, the known frames bounding the gap

    Returns
    -------
    Motion, a copy; the same values where no foot is below the floor

    Raises
    ------
    ValueError unless 0 <= a < b < T and frames ``a … b`` are filled (no NaN).
    """
    a, b = int(a), int(b)
    if not 0 <= a < b < motion.num_frames:
        raise ValueError(
            f"clip {motion.name!r}: the known frames around a gap must satisfy 0 <= a < b < {motion.num_frames} "
            f"(its frame count), got a={a}, b={b}"
        )
    if not (np.all(np.isfinite(motion.local_rot[a : b + 1])) and np.all(np.isfinite(motion.root_pos[a : b + 1]))):
        raise ValueError(f"clip {motion.name!r}: frames {a} … {b} must be filled (no NaN) before the feet are planted")
    out = motion.copy()
    chains = legs(motion.skeleton)
    if b - a < 2 or not chains:
        return out
    low = lowest_joints(motion, a, b)
    floor = min(low[0], low[-1])
    frames = np.arange(a + 1, b)
    parents = motion.skeleton.parents
    for hip, knee, ankle in chains:  # two legs: a loop over legs, each vectorised over frames
        g_rot, g_pos = out[frames].fk()  # (F, J, 4), (F, J, 3)
        foot = motion.skeleton.subtree(ankle)
        depth = np.maximum(0.0, floor - g_pos[:, foot, 1].min(axis=1))  # (F,)
        sink = np.flatnonzero(depth > 0.0)
        if not sink.size:
            continue
        g_rot, g_pos = g_rot[sink], g_pos[sink]
        h, k, f = g_pos[:, hip], g_pos[:, knee], g_pos[:, ankle]  # (S, 3)
        target = f + depth[sink, None] * np.array([0.0, 1.0, 0.0])
        along = (f - h) / np.linalg.norm(f - h, axis=1, keepdims=True)
        pole = (k - h) - np.sum((k - h) * along, axis=1, keepdims=True) * along  # the knee's bend now,
        # off the hip-ankle line; a leg held straight bends towards the toes
        toes = g_pos[:, foot] - f[:, None]  # (S, n, 3): the foot's joints from the ankle
        toe = toes[np.arange(len(sink)), np.argmax(np.linalg.norm(toes, axis=-1), axis=1)]
        straight = np.linalg.norm(pole, axis=1) < 0.01 * np.linalg.norm(k - h, axis=1)
        pole[straight] = toe[straight]
        new_k, new_f = two_bone(h, target, np.linalg.norm(k - h, axis=1), np.linalg.norm(f - k, axis=1), pole)
        turn_hip = quat.between(k - h, new_k - h)  # (S, 4), world frame
        turn_knee = quat.between(quat.rotate(turn_hip, f - k), new_f - new_k)
        new_hip = quat.mul(turn_hip, g_rot[:, hip])
        # every joint from the hip down to the knee's parent turns with the hip, and from the knee
        # down to the ankle's parent with both
        knee_parent = quat.mul(turn_hip, g_rot[:, parents[knee]])
        new_knee = quat.mul(turn_knee, quat.mul(turn_hip, g_rot[:, knee]))
        ankle_parent = quat.mul(turn_knee, quat.mul(turn_hip, g_rot[:, parents[ankle]]))
        rows = frames[sink]
        out.local_rot[rows, hip] = quat.normalize(quat.mul(quat.inv(g_rot[:, parents[hip]]), new_hip))
        out.local_rot[rows, knee] = quat.normalize(quat.mul(quat.inv(knee_parent), new_knee))
        out.local_rot[rows, ankle] = quat.normalize(quat.mul(quat.inv(ankle_parent), g_rot[:, ankle]))
    return out
