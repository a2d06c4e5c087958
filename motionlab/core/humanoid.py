"""The canonical 22-joint humanoid and the mapping of real rigs onto it.

The retargeting paper reduces every character to 22 joints::

    Hips ─┬─ LeftUpLeg ─ LeftLeg ─ LeftFoot ─ LeftToeBase        (and Right…)
          └─ Spine ─ Spine1 ─ Spine2 ─┬─ Neck ─ Head
                                      ├─ LeftShoulder ─ LeftArm ─ LeftForeArm ─ LeftHand
                                      └─ RightShoulder ─ …

Real rigs name and nest their joints differently. A *rig profile* maps each canonical joint to
a joint of the rig (matched case-insensitively after stripping namespace prefixes such as
``mixamorig:`` or ``newVegas:``), or to ``None`` for a zero-length joint the rig lacks (Bandai
Namco has one chest joint where Mixamo has two). Reduction keeps the kept joints' world
positions and rotations: local rotations are recomputed from the full rig's FK, so joints that
are dropped (``Pelvis``, ``*_split``, fingers, hair, CMU's ``LHipJoint``) fold into their
children. Offsets come from the rest pose; when a dropped joint sits between two kept ones and
rotates, no fixed offset can be exact, and :func:`to_canonical` reports the deviation.

Taught in ``notebooks/01_preprocessing.ipynb``.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass

import numpy as np

from motionlab.core import fk as _fk
from motionlab.core import quat
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton

__all__ = [
    "JOINTS",
    "heading",
    "PARENTS",
    "FEET",
    "PROFILES",
    "STANDING",
    "family",
    "RigMappingError",
    "RigMapping",
    "strip_prefix",
    "canonical_skeleton",
    "find_mapping",
    "to_canonical",
    "to_canonical_skeleton",
    "leg_length",
    "BONE_GROUPS",
    "scale_bones",
    "is_canonical",
]

JOINTS: tuple[str, ...] = (
    "Hips",
    "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase",
    "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase",
    "Spine", "Spine1", "Spine2", "Neck", "Head",
    "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand",
    "RightShoulder", "RightArm", "RightForeArm", "RightHand",
)  # fmt: skip
"""Names of the 22 canonical joints, in topological order."""

PARENTS = np.array([-1, 0, 1, 2, 3, 0, 5, 6, 7, 0, 9, 10, 11, 12, 11, 14, 15, 16, 11, 18, 19, 20])
"""Parent index of each canonical joint."""

FEET: tuple[str, ...] = ("LeftFoot", "RightFoot", "LeftToeBase", "RightToeBase")
"""The four foot joints of the foot-contact loss (paper A, eq. L_foot)."""


class RigMappingError(ValueError):
    """A skeleton that cannot be mapped onto the 22-joint humanoid.

    Attributes
    ----------
    reason : str   what is wrong, without the hint on how to fix it from Python (the command
                   line shows this and its own hint)
    """

    def __init__(self, reason: str, hint: str = "") -> None:
        super().__init__(f"{reason} {hint}".strip())
        self.reason = reason

    def for_file(self, role: str, path) -> str:
        """The reason in a command-line user's words: which file (``role``: source, target, input,
        character) does not map, the profiles a rig must follow, and how to list its joints."""
        return (
            f"{role} file {path}: {self.reason} Its joint names must follow one of the rig profiles "
            f"{', '.join(PROFILES)}; `motionlab info {path} --joints` lists its joints."
        )


def strip_prefix(name: str) -> str:
    """Joint name without a namespace prefix: ``"mixamorig:LeftArm"`` → ``"LeftArm"``."""
    return re.split(r"[:|]", name)[-1].strip()


def _profile(**renames: str | None) -> dict[str, str | None]:
    table = {j: j for j in JOINTS}
    table.update(renames)
    return table


def _sides(template: dict[str, str | None]) -> dict[str, str | None]:
    """Expand ``{"{S}UpLeg": "{S}Hip"}``-style templates for S in Left/Right, L/R, _L/_R."""
    out: dict[str, str | None] = {}
    for key, value in template.items():
        for side, short in (("Left", "L"), ("Right", "R")):
            out[key.replace("{S}", side)] = (
                None
                if value is None
                else value.replace("{S}", side).replace("{s}", short).replace("{sl}", short.lower())
            )
    return out


PROFILES: dict[str, dict[str, str | None]] = {
    # Mixamo (any prefix), also Aberman et al.'s exports with Pelvis and *_split joints.
    "mixamo": _profile(),
    # CMU converted by cgspeed for Daz/MotionBuilder (also Xia et al. retargeted to CMU):
    # Hips-LowerBack-Spine-Spine1-Neck-Neck1-Head; Head is dropped (it is a leaf) so every
    # kept position stays exact: canonical Neck = CMU Neck, canonical Head = CMU Neck1.
    "cmu": _profile(
        Spine="LowerBack", Spine1="Spine", Spine2="Spine1", Neck="Neck", Head="Neck1",
    ),
    # CMU converted by cgspeed for 3ds Max (e.g. subject 131): LeftHip/LeftKnee/LeftAnkle naming.
    "cmu_max": _profile(
        Spine="lowerback", Spine1="Chest", Spine2="Chest2", Neck="lowerneck", Head="Neck",
        **_sides({
            "{S}UpLeg": "{S}Hip", "{S}Leg": "{S}Knee", "{S}Foot": "{S}Ankle", "{S}ToeBase": "{S}Toe",
            "{S}Shoulder": "{S}Collar", "{S}Arm": "{S}Shoulder", "{S}ForeArm": "{S}Elbow", "{S}Hand": "{S}Wrist",
        }),
    ),
    # Bandai Namco Research Motion Dataset: joint_Root-Hips-Spine-Chest-Neck-Head, *_L/*_R limbs.
    "bandai_namco": _profile(
        Spine1="Chest", Spine2=None,
        **_sides({
            "{S}UpLeg": "UpperLeg_{s}", "{S}Leg": "LowerLeg_{s}", "{S}Foot": "Foot_{s}", "{S}ToeBase": "Toes_{s}",
            "{S}Shoulder": "Shoulder_{s}", "{S}Arm": "UpperArm_{s}", "{S}ForeArm": "LowerArm_{s}", "{S}Hand": "Hand_{s}",
        }),
    ),
}  # fmt: skip
"""Rig profiles: canonical joint → rig joint name (``None``: a zero-length joint the rig lacks)."""

STANDING: dict[str, str] = {
    "mixamo": "rest",  # a T-pose at rest
    "cmu": "rest",  # an A-stance at rest: arms down, legs spread 20 deg
    "cmu_max": "rest",
    "bandai_namco": "tpose",  # every bone along its parent's x axis at rest: the body lies flat
}
"""How each rig profile's canonical standing pose is found (:mod:`motionlab.core.rest_pose`):
``"rest"``, the rest offsets stand (a rig of a known family whose offsets do not falls back to its
motion's most upright frame); ``"tpose"``, the rest offsets carry the bone lengths only, and the
standing pose is every bone along the T-pose's direction (:func:`canonical_skeleton`), whatever the take.
A profile missing here (a custom mapping) counts as ``"rest"``."""


def family(skeleton: Skeleton, profile=None) -> str | None:
    """Name of the rig profile that maps ``skeleton`` (see :func:`find_mapping`); ``None`` for a
    skeleton that already is the canonical humanoid (its family is unknown). Raises
    :class:`RigMappingError` as :func:`find_mapping` does."""
    if is_canonical(skeleton):
        return None
    return find_mapping(skeleton, profile).profile


@dataclass(frozen=True)
class RigMapping:
    """Where each canonical joint lives in a rig.

    Attributes
    ----------
    profile : str               name of the matched profile (or ``"custom"``)
    source : tuple of int       index of each canonical joint in the rig, ``-1`` if synthesised
    """

    profile: str
    source: tuple[int, ...]


def find_mapping(skeleton: Skeleton, profile: str | dict[str, str | None] | None = None) -> RigMapping:
    """Match a rig to the canonical humanoid.

    Parameters
    ----------
    skeleton : the full rig
    profile : a name in :data:`PROFILES`, a custom ``{canonical: rig name}`` dict, or ``None``
        to try every profile and take the first that matches.

    Raises
    ------
    RigMappingError naming the canonical joints that could not be found.
    """
    bare = [strip_prefix(n) for n in skeleton.names]
    shared = _shared_prefix(bare)
    lookup: dict[str, int] = {}
    for i, n in enumerate(bare):
        lookup.setdefault(n.lower(), i)
        lookup.setdefault(n[len(shared) :].lower(), i)
    if isinstance(profile, dict):
        _check_custom(profile)
        candidates = {"custom": {**_profile(), **profile}}
    elif profile is not None:
        if profile not in PROFILES:
            raise RigMappingError(f"unknown rig profile {profile!r}; known: {sorted(PROFILES)}")
        candidates = {profile: PROFILES[profile]}
    else:
        candidates = PROFILES
    best: tuple[int, str, list[str]] | None = None
    for pname, table in candidates.items():
        source, missing = [], []
        for joint in JOINTS:
            rig_name = table[joint]
            if rig_name is None:
                source.append(-1)
            elif rig_name.lower() in lookup:
                source.append(lookup[rig_name.lower()])
            else:
                source.append(-2)
                missing.append(f"{joint} (as {rig_name!r})")
        if not missing:
            mapping = RigMapping(pname, tuple(source))
            _check_ancestry(skeleton, mapping)
            return mapping
        found = sum(i >= 0 for i in source)
        if best is None or (found, -len(missing)) > best[0]:
            best = ((found, -len(missing)), pname, missing)
    assert best is not None
    closest = (
        f"closest profile {best[1]!r} misses {', '.join(best[2])}"
        if best[0][0]
        else f"no profile finds any of its joints (its names: {', '.join(skeleton.names[:4])}, …)"
    )
    raise RigMappingError(
        f"skeleton with root {skeleton.names[0]!r} ({skeleton.num_joints} joints) does not map onto the "
        f"22-joint humanoid: {closest}.",
        "Pass profile={canonical: rig name} to map it by hand.",
    )


def _shared_prefix(names: list[str]) -> str:
    """The prefix every joint name shares, up to its last ``_``, ``.`` or ``-`` (``mixamorig_``,
    where an exporter replaced the namespace's colon), else ``""``: it names no joint."""
    prefix = os.path.commonprefix(names) if len(names) > 1 else ""
    cut = max(prefix.rfind(c) for c in "_.-")
    return prefix[: cut + 1]


def _check_custom(profile: dict) -> None:
    """Refuse a custom profile that names a joint the humanoid has not (a typo would leave the
    default name in its place) or leaves out the root."""
    unknown = sorted(set(profile) - set(JOINTS))
    if unknown:
        raise RigMappingError(
            f"custom rig profile names {', '.join(map(repr, unknown))}, not joints of the 22-joint humanoid; "
            f"its keys are {', '.join(JOINTS)}"
        )
    if JOINTS[0] in profile and profile[JOINTS[0]] is None:
        raise RigMappingError(f"custom rig profile maps {JOINTS[0]!r}, the root, to no joint; it must map to one")


def _check_ancestry(skeleton: Skeleton, mapping: RigMapping) -> None:
    """Every mapped joint must descend from the joint its canonical parent maps to."""
    for c in range(1, len(JOINTS)):
        s = mapping.source[c]
        pc = PARENTS[c]
        while pc >= 0 and mapping.source[pc] < 0:
            pc = PARENTS[pc]
        ps = mapping.source[pc]
        if s < 0:
            continue
        a = skeleton.parents[s]
        while a >= 0 and a != ps:
            a = skeleton.parents[a]
        if a != ps:
            raise RigMappingError(
                f"rig joint {skeleton.names[s]!r} (canonical {JOINTS[c]}) is not below "
                f"{skeleton.names[ps]!r} (canonical {JOINTS[pc]}); check the joint mapping"
            )


def is_canonical(skeleton: Skeleton) -> bool:
    """True when the skeleton already is the 22-joint humanoid (names, without a prefix, and parents):
    what code that looks joints up by :data:`JOINTS` names may read as it is."""
    return tuple(skeleton.names) == JOINTS and np.array_equal(skeleton.parents, PARENTS)


def _reduced_offsets(rest: np.ndarray, source: tuple[int, ...]) -> np.ndarray:
    pos = np.array([rest[s] if s >= 0 else np.nan * np.ones(3) for s in source])
    for c in range(len(JOINTS)):  # synthesised joints sit on their parent
        if source[c] < 0:
            pos[c] = pos[PARENTS[c]]
    offsets = np.empty_like(pos)
    offsets[0] = pos[0]
    offsets[1:] = pos[1:] - pos[PARENTS[1:]]
    return offsets


def _end_sites(skeleton: Skeleton, source: tuple[int, ...], rest: np.ndarray) -> dict[int, np.ndarray]:
    """End sites of the canonical leaves (head, hands, toes), for drawing and BVH export.

    A leaf's own BVH ``End Site`` wins; otherwise the tip of a descendant named as an end
    (``HeadTop_End``, ``LeftToe_End``, ``…Middle4``); accessories such as hair, hats or shoe
    tongues are ignored, so a leaf without either gets no end site.
    """
    leaves = {"Head": ("headtop", "head_end", "headend"), "LeftHand": ("middle4", "hand_end", "handend"),
              "RightHand": ("middle4", "hand_end", "handend"), "LeftToeBase": ("toe_end", "toeend", "toe_end_end"),
              "RightToeBase": ("toe_end", "toeend", "toe_end_end")}  # fmt: skip
    children: dict[int, list[int]] = {}
    for j in range(1, skeleton.num_joints):
        children.setdefault(int(skeleton.parents[j]), []).append(j)
    out = {}
    for name, keys in leaves.items():
        c, s = JOINTS.index(name), source[JOINTS.index(name)]
        if s < 0:
            continue
        if s in skeleton.end_sites:
            out[c] = skeleton.end_sites[s].copy()
            continue
        stack, tips = list(children.get(s, [])), []
        while stack:
            j = stack.pop()
            base = strip_prefix(skeleton.names[j]).lower()
            if any(k in base for k in keys):
                tips.append(rest[j] + skeleton.end_sites.get(j, np.zeros(3)) - rest[s])
            stack.extend(children.get(j, []))
        if tips:
            tips = np.array(tips)
            out[c] = tips[np.argmax(np.linalg.norm(tips, axis=1))]
    return out


def to_canonical_skeleton(skeleton: Skeleton, profile=None) -> Skeleton:
    """The rig's rest skeleton reduced to the 22 canonical joints (rest positions kept)."""
    if is_canonical(skeleton):
        return Skeleton(JOINTS, PARENTS, skeleton.offsets, skeleton.end_sites)
    mapping = find_mapping(skeleton, profile)
    rest = skeleton.rest_positions()
    return Skeleton(JOINTS, PARENTS, _reduced_offsets(rest, mapping.source), _end_sites(skeleton, mapping.source, rest))


def to_canonical(motion: Motion, profile=None, tolerance: float = 1e-4) -> Motion:
    """Reduce a motion on any supported rig to the 22-joint humanoid.

    Global rotations and positions of the kept joints are those of the full rig's FK. The
    reduced skeleton uses rest-pose offsets. If the motion's own bone vectors deviate from them by
    more than ``tolerance`` × height (a dropped joint between two kept ones rotates, as CMU's
    ``LHipJoint`` does in Xia's data, or position channels stretch bones), the result keeps
    per-frame translations in ``Motion.local_pos`` so world positions stay exact.

    Parameters
    ----------
    motion : Motion on a rig that :func:`find_mapping` recognises
    profile : optional profile name or mapping, see :func:`find_mapping`
    tolerance : allowed position deviation, as a fraction of the rig's rest height

    Returns
    -------
    Motion with 22 joints, the same frames, fps and name.
    """
    skeleton = motion.skeleton
    if is_canonical(skeleton):
        return motion.copy(skeleton=Skeleton(JOINTS, PARENTS, skeleton.offsets, skeleton.end_sites))
    mapping = find_mapping(skeleton, profile)
    src = np.array(mapping.source)
    g_rot, g_pos = motion.fk()
    # synthesised joints copy their canonical parent's transform
    idx = src.copy()
    for c in range(len(JOINTS)):
        if idx[c] < 0:
            idx[c] = idx[PARENTS[c]]
    rot = g_rot[:, idx]
    pos = g_pos[:, idx]
    local_rot = _fk.global_to_local(rot, PARENTS)
    local_rot = quat.normalize(local_rot)
    rest = skeleton.rest_positions()
    offsets = _reduced_offsets(rest, mapping.source)
    height = max(skeleton.height(), 1e-9)

    bone = pos[:, 1:] - pos[:, PARENTS[1:]]
    local_bones = quat.rotate(quat.conj(rot[:, PARENTS[1:]]), bone)  # (T, 21, 3) in the parent frame
    deviation = np.linalg.norm(local_bones - offsets[1:], axis=-1).max(axis=0, initial=0.0)  # 0 frames: 0
    local_pos = None
    if deviation.max() > tolerance * height:
        # a dropped joint between two kept ones rotates (e.g. CMU's LHipJoint in Xia's data), or
        # position channels stretch bones: keep positions exact with per-frame translations
        local_pos = np.concatenate([pos[:, :1], local_bones], axis=1)
    reduced = Skeleton(JOINTS, PARENTS, offsets, _end_sites(skeleton, mapping.source, rest))
    return Motion(reduced, local_rot, pos[:, 0].copy(), motion.fps, local_pos, motion.name)


# ---------------------------------------------------------------------------- proportions
def leg_length(skeleton: Skeleton) -> float:
    """Thigh + shin length (metres), averaged over both legs, of a canonical or mappable rig."""
    sk = skeleton if is_canonical(skeleton) else to_canonical_skeleton(skeleton)
    lengths = sk.bone_lengths()
    total = [lengths[sk.index(f"{s}Leg")] + lengths[sk.index(f"{s}Foot")] for s in ("Left", "Right")]
    return float(np.mean(total))


BONE_GROUPS: dict[str, tuple[str, ...]] = {
    "legs": ("LeftLeg", "LeftFoot", "LeftToeBase", "RightLeg", "RightFoot", "RightToeBase"),
    "arms": ("LeftForeArm", "LeftHand", "RightForeArm", "RightHand"),
    "spine": ("Spine", "Spine1", "Spine2"),
    "neck": ("Neck", "Head"),
}
"""Canonical joints whose incoming bone each proportion slider scales (``overall`` scales all)."""


def scale_bones(
    skeleton: Skeleton,
    legs: float = 1.0,
    arms: float = 1.0,
    spine: float = 1.0,
    neck: float = 1.0,
    overall: float = 1.0,
) -> Skeleton:
    """A new character: the canonical skeleton with bone groups lengthened or shortened.

    ``legs`` scales thigh, shin and foot; ``arms`` upper arm and forearm; ``spine`` the three
    spine bones; ``neck`` the neck and head (and the head's end site); ``overall`` every offset
    afterwards. The root's rest height is moved so the lowest joint stays where it was relative to
    the ground (scaled by ``overall``). Factors must be positive.

    Raises
    ------
    ValueError when a scale factor is not a finite number > 0.
    """
    factors = {"legs": legs, "arms": arms, "spine": spine, "neck": neck, "overall": overall}
    for k, f in factors.items():
        if not (np.isfinite(f) and f > 0):
            raise ValueError(f"bone scale {k!r} must be a positive number, got {f}")
    sk = skeleton if is_canonical(skeleton) else to_canonical_skeleton(skeleton)
    offsets = sk.offsets.copy()
    end_sites = {j: o.copy() for j, o in sk.end_sites.items()}
    for group, names in BONE_GROUPS.items():
        for n in names:
            j = sk.index(n)
            offsets[j] *= factors[group]
            if j in end_sites and group in ("legs", "arms", "neck"):
                end_sites[j] *= factors[group]
    lowest_before = sk.rest_positions()[:, 1].min()
    new = Skeleton(sk.names, sk.parents, offsets, end_sites)
    lowest_after = new.rest_positions()[:, 1].min()
    offsets[0, 1] += lowest_before - lowest_after
    offsets *= overall
    end_sites = {j: o * overall for j, o in end_sites.items()}
    return Skeleton(sk.names, sk.parents, offsets, end_sites)


def canonical_skeleton(height: float = 1.75) -> Skeleton:
    """A plain human T-pose on the 22 canonical joints, Y up, facing +Z, feet on the ground.

    Proportions are those of an average adult; ``height`` (metres, top of the head) scales them.
    The character's left is +X.
    """
    h = height / 1.75
    o = {
        "Hips": (0.0, 0.96, 0.0),
        "LeftUpLeg": (0.09, -0.06, 0.0), "LeftLeg": (0.0, -0.42, 0.0),
        "LeftFoot": (0.0, -0.41, 0.0), "LeftToeBase": (0.0, -0.06, 0.13),
        "Spine": (0.0, 0.10, 0.0), "Spine1": (0.0, 0.12, 0.0), "Spine2": (0.0, 0.12, 0.0),
        "Neck": (0.0, 0.16, 0.0), "Head": (0.0, 0.09, 0.0),
        "LeftShoulder": (0.05, 0.11, 0.0), "LeftArm": (0.12, 0.0, 0.0),
        "LeftForeArm": (0.28, 0.0, 0.0), "LeftHand": (0.25, 0.0, 0.0),
    }  # fmt: skip
    offsets = []
    for name in JOINTS:
        mirrored = name.replace("Right", "Left")
        x, y, z = o[mirrored]
        offsets.append((-x if name.startswith("Right") else x, y, z))
    ends = {
        JOINTS.index("Head"): (0.0, 0.20, 0.03),
        JOINTS.index("LeftHand"): (0.18, 0.0, 0.0),
        JOINTS.index("RightHand"): (-0.18, 0.0, 0.0),
        JOINTS.index("LeftToeBase"): (0.0, 0.0, 0.07),
        JOINTS.index("RightToeBase"): (0.0, 0.0, 0.07),
    }
    return Skeleton(JOINTS, PARENTS, np.array(offsets) * h, {j: np.array(v) * h for j, v in ends.items()})


def heading(global_pos: np.ndarray) -> np.ndarray:
    """Facing angle about +Y (radians, 0 = facing +Z) of canonical poses (..., 22, 3).

    Forward is ``across × up`` where ``across`` averages the right→left hip and shoulder vectors.

    Raises
    ------
    ValueError when ``pos`` is not (..., 22, 3).
    """
    pos = np.asarray(global_pos)
    if pos.shape[-2:] != (len(JOINTS), 3):
        raise ValueError(f"expected canonical positions (..., 22, 3), got {pos.shape}")
    hips, shoulders = (
        [JOINTS.index(n) for n in ("LeftUpLeg", "RightUpLeg")],
        [JOINTS.index(n) for n in ("LeftArm", "RightArm")],
    )
    across = (pos[..., hips[0], :] - pos[..., hips[1], :]) + (pos[..., shoulders[0], :] - pos[..., shoulders[1], :])
    forward = np.cross(across, np.array([0.0, 1.0, 0.0]))
    return np.arctan2(forward[..., 0], forward[..., 2])
