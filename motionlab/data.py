"""Real motion-capture data, reached through one setting: the ``MOTIONLAB_DATA`` variable.

Point it at a folder of BVH files laid out as ``<Character or group>/<Clip>.bvh`` (any depth),
for example the course's shared data::

    export MOTIONLAB_DATA=/path/to/shared/data

Nothing here downloads anything. Without the variable, every function that needs real data
raises :class:`DataNotFound` with a message saying how to set it, and the tests that need real
data skip with that message; the rest of motionlab runs on :mod:`motionlab.synthetic`.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = [
    "ENV_VAR",
    "DataNotFound",
    "HOW_TO",
    "data_root",
    "has_data",
    "list_characters",
    "list_clips",
    "clip_path",
]

ENV_VAR = "MOTIONLAB_DATA"
HOW_TO = (
    f"set {ENV_VAR} to a folder of BVH files, e.g. `export {ENV_VAR}=/path/to/shared/data` "
    "(the course's shared data: Mixamo, Bandai Namco, Xia and CMU clips)"
)


class DataNotFound(FileNotFoundError):
    """Real data was asked for but ``MOTIONLAB_DATA`` is unset, missing or empty."""


def data_root(required: bool = True) -> Path | None:
    """The folder ``MOTIONLAB_DATA`` points at.

    Returns ``None`` when unset and ``required`` is False; otherwise raises
    :class:`DataNotFound` explaining what to do.
    """
    value = os.environ.get(ENV_VAR, "").strip()
    if not value:
        if required:
            raise DataNotFound(f"{ENV_VAR} is not set: {HOW_TO}")
        return None
    root = Path(value).expanduser()
    if not root.is_dir():
        if required:
            raise DataNotFound(f"{ENV_VAR}={value!r} is not a folder: {HOW_TO}")
        return None
    if not any(root.rglob("*.bvh")):
        if required:
            raise DataNotFound(f"{ENV_VAR}={value!r} holds no .bvh files: {HOW_TO}")
        return None
    return root


def has_data(*parts: str) -> bool:
    """True when ``MOTIONLAB_DATA`` is usable (and, if given, the sub-path exists)."""
    root = data_root(required=False)
    return root is not None and root.joinpath(*parts).exists()


def _folder(subdir: str) -> Path:
    """The folder ``MOTIONLAB_DATA/subdir``; :class:`DataNotFound` when it does not exist."""
    root = data_root()
    base = root / subdir
    if not base.is_dir():
        raise DataNotFound(f"{base} does not exist in {ENV_VAR}={root}")
    return base


def list_clips(subdir: str = "", pattern: str = "*.bvh") -> list[Path]:
    """All BVH files under ``MOTIONLAB_DATA/subdir`` (recursively), sorted.

    Raises
    ------
    DataNotFound when the folder does not exist under ``MOTIONLAB_DATA``.
    """
    return sorted(_folder(subdir).rglob(pattern))


def list_characters(subdir: str = "mixamo") -> dict[str, list[str]]:
    """``{character: [clip stems]}`` for a folder laid out as ``<Character>/<Clip>.bvh``.

    Raises
    ------
    DataNotFound when the folder does not exist under ``MOTIONLAB_DATA``.
    """
    base = _folder(subdir)
    out = {}
    for d in sorted(p for p in base.iterdir() if p.is_dir()):
        clips = sorted(f.stem for f in d.glob("*.bvh"))
        if clips:
            out[d.name] = clips
    return out


def clip_path(*parts: str) -> Path:
    """Path of one file under ``MOTIONLAB_DATA`` (``.bvh`` added if missing); clear error if absent.

    Raises
    ------
    DataNotFound when the file does not exist under ``MOTIONLAB_DATA``.
    """
    root = data_root()
    path = root.joinpath(*parts)
    if path.suffix != ".bvh":
        path = path.with_suffix(".bvh")
    if not path.is_file():
        raise DataNotFound(f"{path} not found under {ENV_VAR}={root}")
    return path
