"""Motion files by name: the format an output file's suffix names, its length unit, and the writer.

One rule for every command that writes a motion (``convert``, ``synth``, ``retarget``,
``fill-gaps``, ``graph-search``, ``expand``):

* ``.bvh`` writes BVH text (:func:`motionlab.core.bvh.dumps`), in the length unit of the file the
  motion was read from, so a converted file keeps its numbers; a 22-joint humanoid (whose names
  read back as centimetres) is given in metres by its writer (:func:`in_metres`) and so written
  in centimetres;
* ``.glb`` writes binary glTF 2.0 (:func:`motionlab.core.gltf.dumps`), whose unit is the metre;
* any other suffix (``.gltf``, ``.fbx``, ``.txt``, none) is refused before any work.

Length units of BVH files. A BVH file does not say its unit; :func:`motionlab.core.bvh.load`
reads centimetres (its ``scale`` 0.01). The rig profile tells the unit where it is not the
centimetre: the CMU skeleton (profiles ``cmu``, ``cmu_max``: CMU's own converted files and the
Xia et al. clips retargeted onto it) keeps the CMU ASF length unit, ``1/0.45`` inch (the ASF
files' ``length 0.45``), :data:`ASF_UNIT` metres. :func:`file_unit` gives the unit of a skeleton
as read, and :func:`encode` makes a glTF file metres from it.
"""

from __future__ import annotations

import os
from pathlib import Path

from motionlab.core.motion import Motion

__all__ = ["SUFFIXES", "ASF_UNIT", "CM", "output_suffix", "file_unit", "in_metres", "load_metres", "encode", "save"]

SUFFIXES = {".bvh": "BVH text", ".glb": "binary glTF 2.0"}
"""The suffixes a motion is written to, and what each writes."""

_REFUSED = {
    ".gltf": "text glTF (.gltf) is not written; use .glb (binary glTF 2.0, which every glTF reader opens)",
    ".fbx": "FBX is not written (a closed format); use .glb, which Blender and game engines import, or .bvh",
}

CM = 0.01
"""Metres per centimetre: the unit :func:`motionlab.core.bvh.load` reads by default."""

ASF_UNIT = 0.0254 / 0.45
"""Metres per CMU ASF length unit (``length 0.45``: one unit is 1/0.45 inch)."""

_PROFILE_UNITS = {"cmu": ASF_UNIT, "cmu_max": ASF_UNIT}


def output_suffix(path: str | os.PathLike, option: str = "-o") -> str:
    """The suffix (``.bvh`` or ``.glb``, lower case) of the motion file ``path`` names.

    Raises
    ------
    ValueError
        ``path`` ends in another suffix or none; the message names ``option`` and what is written.
    """
    suffix = Path(path).suffix.lower()
    if suffix in SUFFIXES:
        return suffix
    known = ", ".join(f"{s} ({what})" for s, what in SUFFIXES.items())
    why = _REFUSED.get(suffix, f"a motion is written as {known}")
    ending = f"ends in {suffix}" if suffix else "has no suffix"
    raise ValueError(f"{option} {path} {ending}: {why}; choose a name ending in .bvh or .glb")


def file_unit(skeleton) -> float:
    """Metres per length unit of the BVH file ``skeleton`` was read from (its rig profile's unit,
    else the centimetre, :data:`CM`)."""
    from motionlab.core import humanoid

    try:
        profile = humanoid.find_mapping(skeleton).profile
    except humanoid.RigMappingError:
        return CM
    return _PROFILE_UNITS.get(profile, CM)


def in_metres(motion: Motion, unit: float = CM) -> Motion:
    """``motion`` (read from a file in ``unit`` metres per file unit, as centimetres) in metres."""
    factor = unit / CM
    if factor == 1.0:
        return motion
    local_pos = None if motion.local_pos is None else motion.local_pos * factor
    return motion.copy(skeleton=motion.skeleton.scaled(factor), root_pos=motion.root_pos * factor, local_pos=local_pos)


def load_metres(path: str | os.PathLike) -> Motion:
    """The BVH file ``path`` in metres: read (:func:`motionlab.core.bvh.load`) and scaled by its
    length unit (:func:`file_unit`), so that a CMU-skeleton file's lengths are metres too.

    Raises what :func:`motionlab.core.bvh.load` raises.
    """
    from motionlab.core import bvh

    motion = bvh.load(path)
    return in_metres(motion, file_unit(motion.skeleton))


def encode(motion: Motion, suffix: str, unit: float = CM) -> bytes:
    """The bytes of ``motion`` written as ``suffix`` names (:data:`SUFFIXES`).

    ``unit`` is the metres per unit of the file the motion was read from (:func:`file_unit`):
    BVH keeps that unit, glTF is written in metres.

    Raises
    ------
    ValueError
        ``suffix`` is not one of :data:`SUFFIXES`, or the motion cannot be written in it
        (non-finite values, values beyond float32 for glTF).
    """
    from motionlab.core import bvh, gltf

    if suffix == ".bvh":
        return bvh.dumps(motion).encode("utf-8")
    if suffix == gltf.SUFFIX:
        return gltf.dumps(in_metres(motion, unit))
    raise ValueError(f"cannot write a motion as {suffix!r}; expected one of {', '.join(SUFFIXES)}")


def save(
    path: str | os.PathLike, motion: Motion, overwrite: bool = False, unit: float = CM, what: str = "output"
) -> Path:
    """Write ``motion`` in the format ``path``'s suffix names (:func:`output_suffix`), atomically.

    Raises
    ------
    ValueError
        the suffix is refused, or the motion cannot be written (see :func:`encode`).
    OSError
        as :func:`motionlab.core.files.check_output` says for ``path``.
    """
    from motionlab.core import files

    suffix = output_suffix(path)
    files.check_output(path, overwrite, what)
    data = encode(motion, suffix, unit)
    return files.atomic_write(path, lambda f: f.write(data), overwrite=overwrite, binary=True, what=what)
