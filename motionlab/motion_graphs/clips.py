"""Clip sets for motion graphs: real mocap through ``MOTIONLAB_DATA``, synthetic otherwise.

Every clip is read in metres (:func:`motionlab.core.motion_files.load_metres`: a CMU-skeleton
file's unit is not the centimetre, and the graph's thresholds are metres), reduced to the
22-joint humanoid and one frame rate with :func:`motionlab.core.preprocess.prepare`, so all rigs
are handled the same way, and renamed to
its label (``walk_angry``, ``idle_normal_to_walk_catwalk``) so that graph tables read well.

* :func:`bandai_styles` — Bandai Namco dataset-1 walk/run/dash in 15 styles (30 fps);
* :func:`mixamo_aj` — Mixamo Aj clips with recorded transitions (idle → walk, land → idle);
* :func:`synthetic_library` — procedural stand-ins from :mod:`motionlab.synthetic`: styles of
  idle, walk and run, and transition clips between them;
* :func:`load_folder` — every BVH file under a folder (used by ``motionlab graph-build``).

Taught in ``notebooks/05_motion_graphs.ipynb``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

from motionlab import data as _data
from motionlab.core import files, motion_files, preprocess
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.motion_graphs.naming import MIXAMO_AJ, NamingError, label_name, parse_name

__all__ = [
    "prepare",
    "load_folder",
    "unlabelled_files",
    "file_label",
    "bandai_styles",
    "mixamo_aj",
    "synthetic_library",
    "BANDAI_STYLES",
    "SYNTHETIC_STYLES",
]

BANDAI_STYLES = (
    "normal", "happy", "sad", "angry", "proud", "not-confident", "masculinity", "feminine",
    "childish", "old", "tired", "active", "musical", "giant", "chimpira",
)  # fmt: skip
"""The 15 style labels of Bandai Namco dataset-1."""

SYNTHETIC_STYLES: dict[str, dict[str, dict[str, float]]] = {
    "idle": {"normal": {}},
    "walk": {
        "normal": {},
        "happy": {"stride": 0.95, "cadence": 2.1, "bounce": 0.035, "arm_swing": 0.5},
        "sad": {"stride": 0.55, "cadence": 1.5, "lean": 0.25, "arm_swing": 0.08},
        "proud": {"stride": 0.85, "cadence": 1.8, "lean": -0.08, "arm_swing": 0.35},
    },
    "run": {
        "normal": {},
        "tired": {"stride": 1.1, "cadence": 2.4, "lean": 0.2, "arm_swing": 0.3},
    },
}
"""Style overrides (:class:`motionlab.synthetic.Style` fields) of the synthetic stand-ins."""

SYNTHETIC_TRANSITIONS = (("idle", "walk"), ("walk", "run"), ("run", "walk"), ("walk", "idle"))


def prepare(motion: Motion, fps: float) -> Motion:
    """22-joint version of ``motion`` at ``fps`` (no resampling when the rate already matches)."""
    same = abs(motion.fps - fps) <= 1e-3 * fps
    out = preprocess.prepare(motion, None if same else fps)
    return out.copy(fps=float(fps)) if same else out


def file_label(path: Path, folder: str | os.PathLike, name_map=None, behaviour_folders: bool = False):
    """The label of the BVH file ``path`` under ``folder`` (:func:`.naming.parse_name`; with
    ``behaviour_folders``, a file in a subfolder takes that folder's name as its behaviour).

    Raises :class:`.naming.NamingError` naming what the file's name lacks."""
    behaviour = path.parent.name if behaviour_folders and path.parent != Path(folder) else None
    return parse_name(path.stem, name_map, behaviour)


def unlabelled_files(folder: str | os.PathLike, name_map=None, behaviour_folders: bool = False) -> list[Path]:
    """The BVH files under ``folder`` (recursively) whose names give no label
    (:func:`.naming.parse_name`): :func:`load_folder` skips them."""
    out = []
    for path in files.bvh_files(folder, recursive=True):
        try:
            file_label(path, folder, name_map, behaviour_folders)
        except NamingError:
            out.append(path)
    return out


def load_folder(
    folder: str | os.PathLike,
    fps: float = 30.0,
    name_map=None,
    strict: bool = False,
    progress: bool = False,
    behaviour_folders: bool = False,
) -> list[Motion]:
    """Every BVH file under ``folder`` (recursively, ``.bvh`` in any case), reduced, resampled and named by label
    (``walk_angry_001``: behaviour, style and take, see :mod:`.naming`).

    ``name_map``: ``{stem: label text}`` or a callable (:func:`.naming.parse_name`). Files whose
    names give no label are skipped, or raise with ``strict=True``. ``progress``: a tqdm bar.
    ``behaviour_folders``: each subfolder holds the clips of one behaviour, its name (Xia et al.'s
    ``run/angry_13_000.bvh``; :mod:`.naming`).

    Raises
    ------
    FileNotFoundError when ``folder`` is not a folder or holds no BVH file with a
    behaviour_style name.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise FileNotFoundError(f"{folder} is not a folder of BVH files")
    out, first_error = [], None
    paths = files.bvh_files(folder, recursive=True)
    if progress:
        from tqdm.auto import tqdm

        paths = tqdm(paths, desc="loading", unit="file", leave=False)
    for path in paths:
        try:
            label = file_label(path, folder, name_map, behaviour_folders)
        except NamingError as e:
            if strict:
                raise
            first_error = first_error or f"{path}: {e}"
            continue
        motion = motion_files.load_metres(path)
        if motion.num_frames == 0:
            raise ValueError(f"{path} has no frames (its MOTION block says Frames: 0); a clip of a graph needs some")
        out.append(prepare(motion, fps).copy(name=label_name(label)))
    if not out:
        why = f"; the first: {first_error}" if first_error else ""
        raise FileNotFoundError(
            f"no BVH file under {folder} has a behaviour_style name (see motionlab.motion_graphs.naming){why}"
        )
    return out


def bandai_styles(
    behaviours: Sequence[str] = ("walk", "run", "dash"), styles: Sequence[str] | None = None, fps: float = 30.0
) -> list[Motion]:
    """Bandai Namco dataset-1 clips (take 1) from ``MOTIONLAB_DATA/bandai_namco/dataset-1``.

    Raises :class:`motionlab.data.DataNotFound` when the data is not there.
    """
    root = _data.data_root() / "bandai_namco" / "dataset-1"
    if not root.is_dir():
        raise _data.DataNotFound(f"{root} does not exist: {_data.HOW_TO}")
    out = []
    for b in behaviours:
        for s in styles or BANDAI_STYLES:
            path = root / b / f"dataset-1_{b}_{s}_001.bvh"
            if path.is_file():
                out.append(prepare(motion_files.load_metres(path), fps).copy(name=f"{b}_{s}"))
    if not out:
        raise _data.DataNotFound(f"no dataset-1 clips for {list(behaviours)} under {root}")
    return out


def mixamo_aj(fps: float = 30.0, name_map: Mapping[str, str] = MIXAMO_AJ) -> list[Motion]:
    """Mixamo Aj clips named in ``name_map`` (basic and transition clips), labelled.

    Raises
    ------
    DataNotFound when none of the clips is found.
    """
    root = _data.data_root() / "mixamo" / "Aj"
    out = []
    for stem, text in name_map.items():
        path = root / f"{stem}.bvh"
        if path.is_file():
            out.append(prepare(motion_files.load_metres(path), fps).copy(name=text))
    if not out:
        raise _data.DataNotFound(f"none of {sorted(name_map)} under {root}")
    return out


def synthetic_library(
    skeleton: Skeleton | None = None,
    fps: float = 30.0,
    seconds: float = 6.0,
    transitions: bool = True,
    styles: Mapping[str, Mapping[str, Mapping[str, float]]] | None = None,
    seed: int = 0,
) -> list[Motion]:
    """Synthetic stand-in clips: ``behaviour_style`` basics and ``b_normal_to_b2_normal``
    transition clips (``seconds`` long each; transitions half of it on each side)."""
    from motionlab import synthetic

    styles = SYNTHETIC_STYLES if styles is None else styles
    n = max(int(round(seconds * fps)), 10)
    out = []
    for k, (b, table) in enumerate(sorted(styles.items())):
        for j, (s, over) in enumerate(sorted(table.items())):
            m = synthetic.generate(b, skeleton, n, fps, dict(over) or None, seed + 10 * k + j)
            out.append(m.copy(name=f"{b}_{s}"))
    if transitions:
        for k, (a, b) in enumerate(SYNTHETIC_TRANSITIONS):
            if a in styles and b in styles:
                m = synthetic.sequence([(a, n // 2), (b, n // 2)], skeleton, fps, seed + 100 + k)
                out.append(m.copy(name=f"{a}_normal_to_{b}_normal"))
    return out
