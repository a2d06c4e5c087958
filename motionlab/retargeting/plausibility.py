"""Is a retargeted clip physically plausible on its target? Checked on every output.

A retargeted clip of B is **plausible** when, with ``leg`` = B's thigh + shin
(:func:`motionlab.core.humanoid.leg_length`) and ``hip`` = B's standing hip height
(:func:`motionlab.retargeting.pipeline.hip_height` of the standing rest pose,
:mod:`motionlab.core.rest_pose`):

* **feet on the floor** (``foot``): on the frames where A's foot joints are planted
  (:func:`pipeline.source_contacts`), the median height of B's same joints above their own
  contact height (rest height above the lowest rest joint, :func:`contacts.rest_heights`) on B's
  own sole (the height its lowest joint stands at, :func:`pipeline.target_sole`), as a
  fraction of ``leg``, is within :data:`FOOT_TOL` of the same measure of A on A's legs and sole
  (:func:`pipeline.source_sole`) — a
  tenth of the leg is a few centimetres on a human and still tells a planted foot from a lifted
  one. The test is against A's own value so that a source recorded a little above its floor
  (mocap markers, a rig's foot joints off the sole) does not condemn every output: it flags
  what the retargeting did;
* **nothing deep under the floor** (``floor``): no joint in any frame lower than
  :data:`FOOT_TOL` × ``leg`` below ``y = 0`` or below A's own lowest joint (as a fraction of A's
  leg; a source whose toes dip under its floor passes that on);
* **hips at a standing height for B's legs** (``hips``): B's median root height as a fraction of
  ``hip`` differs from A's median root height as a fraction of A's standing hip height by at most
  :data:`HIP_TOL` (a crouch stays a crouch, a stand a stand, whatever the legs);
* **B's bone lengths** (``bones``): every bone of every frame within :data:`BONE_TOL` of B's
  rest length (relative).

The thresholds are fractions of the target's own leg length or standing height, set by these
principles, never fitted to clips, so they hold for any size or file unit. A clip without
planted frames skips the foot test.

Beside the tests, a **skating** flag (:attr:`Plausibility.skating`, ``expand``'s ``skating``):
the planted-foot slide, the mean horizontal speed of B's foot joints on the frames where A's are
planted (:func:`motionlab.core.metrics.planted_slide`, as ``python -m experiments.retargeting.rigs --methods`` prints it), is
more than :data:`SLIDE_TOL` × B's 22-joint height per second, the speed under which the contact
detector (:mod:`motionlab.core.contacts`) counts a foot as planted: B's feet then move, on
average, faster than any foot the detector would call planted on B. A low swinging foot does not
count (it is not planted on A), a planted foot that floats does. It is a flag, not a failed test.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.core import contacts, humanoid, metrics
from motionlab.core.motion import Motion

__all__ = ["FOOT_TOL", "HIP_TOL", "BONE_TOL", "SLIDE_TOL", "Plausibility", "check"]

FOOT_TOL = 0.10
"""Foot height in contact frames and depth under the floor allowed, as a fraction of B's leg length."""
HIP_TOL = 0.20
"""Allowed difference of the median hip height, as a fraction of the standing hip height (B's vs A's)."""
BONE_TOL = 0.01
"""Allowed relative deviation of a bone's length from B's rest length."""
SLIDE_TOL = contacts.SPEED_TOL
"""Planted-foot slide above which a clip is flagged ``skating``, in B's heights per second: the
contact detector's own speed limit (:data:`motionlab.core.contacts.SPEED_TOL`)."""


@dataclass(frozen=True)
class Plausibility:
    """The plausibility measures of one retargeted clip and the tests it failed.

    Attributes
    ----------
    foot_height : float     median height of B's planted foot joints above contact height on B's sole, / leg
                            (nan: no contacts)
    source_foot_height : float   the same for A, / A's leg
    lowest : float          lowest joint height over the clip, / leg (negative: under the floor)
    source_lowest : float   the same for A, / A's leg
    hip_ratio : float       B's median root height / B's standing hip height
    source_hip_ratio : float   the same for A on A
    bone_error : float      largest relative bone-length deviation
    failed : tuple of str   names of the failed tests: ``foot``, ``floor``, ``hips``, ``bones``
    slide : float           B's planted-foot slide on A's contact frames, position unit per second
    source_slide : float    the same for A on A
    slide_limit : float     :data:`SLIDE_TOL` × B's height, per second (``skating`` above it)
    """

    foot_height: float
    source_foot_height: float
    lowest: float
    source_lowest: float
    hip_ratio: float
    source_hip_ratio: float
    bone_error: float
    failed: tuple[str, ...]
    slide: float = 0.0
    source_slide: float = 0.0
    slide_limit: float = float("inf")

    @property
    def ok(self) -> bool:
        """True when every test passed."""
        return not self.failed

    @property
    def skating(self) -> bool:
        """True when B's planted feet slide faster than :attr:`slide_limit` (module docstring)."""
        return self.slide > self.slide_limit

    def describe(self) -> str:
        """One line: the measures and, when some failed, which."""
        verdict = "plausible" if self.ok else "IMPLAUSIBLE (" + ", ".join(self.failed) + ")"
        return (
            f"{verdict}: hip height {self.hip_ratio:.2f} of standing (source {self.source_hip_ratio:.2f}), "
            f"foot in contact {self.foot_height:+.3f} leg (source {self.source_foot_height:+.3f}), lowest joint {self.lowest:+.3f} leg (source {self.source_lowest:+.3f}), "
            f"bone lengths within {100 * self.bone_error:.2g} %, planted-foot slide {self.slide / self.slide_limit:.2f} "
            f"of the contact speed limit{' (SKATING)' if self.skating else ''}"
        )


def _hip_ratio(positions: np.ndarray, skeleton) -> float:
    rest = skeleton.rest_positions()
    standing = rest[0, 1] - rest[:, 1].min()
    return float(np.median(positions[:, 0, 1]) / standing) if standing > 0 else float("nan")


def _foot_height(positions: np.ndarray, skeleton, planted: np.ndarray, sole: float) -> float:
    """Median height of the planted foot joints above their contact height on the rig's ``sole``
    (metres), / leg (nan: none planted)."""
    if not np.any(planted):
        return float("nan")
    heights = positions[:, list(contacts.CONTACT_JOINTS), 1] - contacts.rest_heights(skeleton)[None] - sole
    return float(np.median(heights[planted]) / humanoid.leg_length(skeleton))


def check(
    positions: np.ndarray, target, source: Motion, planted: np.ndarray | None = None, soles: tuple = (0.0, 0.0)
) -> Plausibility:
    """The plausibility tests of the module docstring.

    Parameters
    ----------
    positions : ndarray (T, 22, 3)   B's world joint positions, metres
    target : Skeleton                B's canonical skeleton in its standing rest pose
    source : Motion                  A on the canonical 22 joints in its standing rest pose, T frames
    planted : ndarray (T, 4) of bool, optional   A's planted foot joints (default: detected on ``source``)
    soles : (float, float)           A's and B's soles, metres (:func:`pipeline.source_sole`,
                                     :func:`pipeline.target_sole`): each rig's feet are measured
                                     on its own sole (default: both on the floor)
    (``positions`` are at ``source.fps``: the slide is per second of it)

    Returns
    -------
    Plausibility

    Raises
    ------
    ValueError when ``positions`` and ``source`` differ in frames.
    """
    positions = np.asarray(positions, dtype=np.float64)
    if positions.shape[0] != source.num_frames:
        raise ValueError(f"{positions.shape[0]} retargeted frames but {source.num_frames} source frames")
    if planted is None:
        planted = contacts.of_motion(source)
    planted = np.asarray(planted)
    if planted.dtype != bool:  # 0/1 integers would index rows instead of masking them
        if not np.isin(planted, (0, 1)).all():
            raise ValueError(f"expected planted as booleans (or 0/1), got values {np.unique(planted)[:5]}")
        planted = planted.astype(bool)
    leg = humanoid.leg_length(target)
    foot = _foot_height(positions, target, planted, soles[1])
    src_pos = source.global_positions()
    src_foot = _foot_height(src_pos, source.skeleton, planted, soles[0])
    lowest = float(positions[..., 1].min() / leg)
    src_lowest = float(src_pos[..., 1].min() / humanoid.leg_length(source.skeleton))
    hip, src_hip = _hip_ratio(positions, target), _hip_ratio(src_pos, source.skeleton)
    bones = np.linalg.norm(positions[:, 1:] - positions[:, humanoid.PARENTS[1:]], axis=-1)
    rest = target.bone_lengths()[1:]
    long = rest > 1e-9
    bone_error = float(np.abs(bones[:, long] / rest[long] - 1.0).max()) if long.any() else 0.0
    failed = []
    if not abs(foot - src_foot) <= FOOT_TOL and not np.isnan(foot - src_foot):
        failed.append("foot")
    if not lowest >= min(0.0, src_lowest) - FOOT_TOL:
        failed.append("floor")
    if not abs(hip - src_hip) <= HIP_TOL:
        failed.append("hips")
    if not bone_error <= BONE_TOL:
        failed.append("bones")
    slide = metrics.planted_slide(positions, contacts.CONTACT_JOINTS, planted, source.fps)
    src_slide = metrics.planted_slide(src_pos, contacts.CONTACT_JOINTS, planted, source.fps)
    limit = SLIDE_TOL * target.height()
    return Plausibility(
        foot, src_foot, lowest, src_lowest, hip, src_hip, bone_error, tuple(failed), slide, src_slide, limit
    )
