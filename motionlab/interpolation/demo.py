"""Clips for notebook 06: real mocap when ``MOTIONLAB_DATA`` is set, synthetic motion otherwise.

:func:`behaviours`, :func:`walk_clip` and :func:`paper_walk` return canonical 22-joint motions and
say where they came from, so a notebook cell can print its data source; :func:`load_clips` loads
any BVH files the same way; :func:`fig8_graph` and :func:`run_squat_gap` set up the paper's Fig. 8.
Nothing is downloaded.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from motionlab import data
from motionlab.core.motion import Motion
from motionlab.interpolation import detect

__all__ = [
    "BEHAVIOUR_CLIPS",
    "trim_frozen",
    "behaviours",
    "walk_clip",
    "walk_takes",
    "paper_walk",
    "WALK_JOINTS",
    "fig8_graph",
    "run_squat_gap",
    "load_clips",
]

BEHAVIOUR_CLIPS = {
    "run": "mixamo/Aj/Run_Arc_Left",
    "walk": "mixamo/Aj/Catwalk_Walk",
    "stand": "mixamo/Aj/Ready_Idle",
    "squat": "mixamo/Aj/Standing_To_Crouched",
}
"""The real clips (Mixamo Aj, one skeleton) used for each action when data is available, chosen by
content (:func:`motionlab.interpolation.labels.check`), not by file name: ``Running.bvh`` is a dive
roll (hips at 9% of standing height) and ``Idle.bvh`` a crouched idle (58%); ``behaviours()``
checks every clip against its label and refuses a mismatch."""

_SYNTHETIC = {"run": "run", "walk": "walk", "stand": "idle", "squat": "squat"}


def trim_frozen(motion: Motion) -> Motion:
    """``motion`` without the trailing frames that repeat the frame before them
    (:func:`.detect.held_steps`: some Mixamo exports pad a clip with its last pose; ``Run_Arc_Left``
    stops moving after 33 of its 60 frames)."""
    moving = np.flatnonzero(~detect.held_steps(motion))
    last = int(moving[-1]) + 2 if moving.size else 1
    return motion[: max(last, 2)] if last < motion.num_frames else motion


def _load(rel: str, fps: float) -> Motion:
    from motionlab.core import bvh, humanoid

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        m = humanoid.to_canonical(bvh.load(data.clip_path(*rel.split("/"))))
    return trim_frozen(m).resample(fps)


def behaviours(fps: float = 30.0, frames: int = 90, seed: int = 0) -> tuple[dict[str, Motion], str]:
    """``({action: Motion}, source)`` for run, walk, stand and squat.

    Real: the Mixamo Aj clips of :data:`BEHAVIOUR_CLIPS`. Synthetic: :func:`motionlab.synthetic.generate`
    with ``frames`` frames each.
    """
    if data.has_data("mixamo", "Aj"):
        from motionlab.interpolation import labels

        clips = {k: _load(v, fps) for k, v in BEHAVIOUR_CLIPS.items()}
        for k, m in clips.items():
            labels.check(m, k)
        return clips, "real: Mixamo Aj clips " + ", ".join(v.split("/")[-1] for v in BEHAVIOUR_CLIPS.values())
    from motionlab import synthetic

    clips = {k: synthetic.generate(b, None, frames, fps, seed=seed + i) for i, (k, b) in enumerate(_SYNTHETIC.items())}
    for k, m in clips.items():
        m.name = k
    return clips, "synthetic: motionlab.synthetic.generate (set MOTIONLAB_DATA for real mocap)"


def walk_clip(fps: float = 30.0, frames: int = 240) -> tuple[Motion, str]:
    """A long walk: Bandai Namco dataset-2 walk 001 (real) or a synthetic walk."""
    rel = "bandai_namco/dataset-2/walk/dataset-2_walk_normal_001"
    if data.has_data(*rel.split("/")[:-1]):
        return _load(rel, fps), f"real: {rel}.bvh"
    from motionlab import synthetic

    m = synthetic.generate("walk", None, frames, fps, seed=1)
    return m, "synthetic walk (set MOTIONLAB_DATA for real mocap)"


def load_clips(paths: Sequence[str | Path], fps: float = 30.0, canonical: bool = True) -> list[Motion]:
    """Load BVH files (or every ``*.bvh`` under folders), reduce to 22 joints, resample to ``fps``.

    Files that fail to load or map are skipped with a warning naming them.

    Raises
    ------
    FileNotFoundError for a path that is neither a BVH file nor a folder.
    """
    from motionlab.core import bvh, humanoid

    files: list[Path] = []
    for p in paths:
        p = Path(p)
        if p.is_dir():
            files.extend(sorted(p.rglob("*.bvh")))
        elif p.is_file():
            files.append(p)
        else:
            raise FileNotFoundError(f"{p} is neither a BVH file nor a folder")
    out = []
    for f in files:
        try:
            m = bvh.load(f)
            if canonical:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", UserWarning)
                    m = humanoid.to_canonical(m)
            if fps is not None:
                m = m.resample(fps)
            out.append(m)
        except (ValueError, KeyError) as e:
            warnings.warn(f"skipping {f}: {e}", UserWarning, stacklevel=2)
    return out


def walk_takes(takes=(4, 5, 6), style: str = "normal", fps: float = 30.0) -> list[Motion]:
    """Walk takes of ``bandai_namco/sessions/walk`` (canonical, at ``fps``), other recordings than
    :func:`walk_clip`'s; an empty list without real data."""
    if not data.has_data("bandai_namco", "sessions", "walk"):
        return []
    return [_load(f"bandai_namco/sessions/walk/dataset-2_walk_{style}_{t:03d}", fps) for t in takes]


def paper_walk() -> tuple[Motion, str]:
    """The walk of the paper's Fig. 6/7 experiment: ``xia/walk/normal_ganimator.bvh`` (CMU skeleton,
    120 Hz, 360 frames: the nearest real walk to the paper's 495 CMU frames), or a synthetic 120 Hz
    walk of the same length."""
    rel = "xia/walk/normal_ganimator"
    if data.has_data("xia", "walk"):
        return _load(rel, 120.0), f"real: {rel}.bvh (120 Hz)"
    from motionlab import synthetic

    return synthetic.generate(
        "walk", None, 360, 120.0, seed=3
    ), "synthetic 120 Hz walk (set MOTIONLAB_DATA for real mocap)"


WALK_JOINTS = ("Hips", "Spine", "Neck", "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg", "LeftFoot", "RightFoot",
               "LeftArm", "RightArm", "LeftForeArm", "RightForeArm")  # fmt: skip
"""The 13 walking joints of the paper's Table 1 (its list is not in the text), read as the CMU
skeleton's hips, lower spine, neck, thighs, shins, feet, upper arms and forearms, canonical names;
``LeftUpLeg`` is the paper's ``lThigh``."""


def fig8_graph(clips: dict[str, Motion]):
    """The action graph of the paper's Fig. 8: nodes run, walk, stand and squat (the clips of
    :func:`behaviours`), transitions run ↔ walk ↔ stand ↔ squat; returns an
    :class:`~motionlab.interpolation.action_graph.ActionGraph`."""
    from motionlab.interpolation.action_graph import ActionGraph

    g = ActionGraph()
    for name in ("run", "walk", "stand", "squat"):
        g.add_node(name, clips[name])
    g.allow(["run -> walk", "walk -> stand", "stand -> squat"], both_ways=True)
    return g


def run_squat_gap(clips: dict[str, Motion], missing: int = 10, context: int = 10) -> tuple[Motion, tuple[int, int]]:
    """The stream of the paper's Fig. 8: the last ``context`` frames of ``clips["run"]``, ``missing``
    NaN frames, then ``clips["squat"]`` from two frames before its deepest crouch.

    The squat faces the run's last heading and stands ahead of the last run frame by the distance
    the runner covers slowing uniformly to rest over the gap (half the run's mean ground speed ×
    ``missing + 1`` frames); the paper does not say where its squat stands.

    Returns
    -------
    stream : Motion     ``context + missing + len(squat part)`` frames
    gap : (int, int)    the NaN frames ``start … stop-1`` (:func:`.gaps.insert_missing`)
    """
    from motionlab.core import quat
    from motionlab.interpolation import gaps
    from motionlab.interpolation.alignment import align_to, reference_joint, reference_transform
    from motionlab.interpolation.inbetween import concatenate

    run, squat = clips["run"], clips["squat"]
    head = run[run.num_frames - context :]
    low = int(np.argmin(squat.global_positions()[:, 0, 1]))  # the deepest crouch
    tail = squat[max(0, low - 2) : min(squat.num_frames, low + context)]
    ref = reference_joint(run)
    _, path = reference_transform(head, joint=ref)
    v = np.linalg.norm(np.diff(path[:, [0, 2]], axis=0), axis=1).mean()
    tail = align_to(tail, head, frame=0, to_frame=-1)
    rot, _ = reference_transform(head, [-1], joint=ref)
    fwd = quat.rotate(quat.from_yaw(float(quat.yaw(rot[0]))), np.array([0.0, 0.0, 1.0]))
    expected = float(v * (missing + 1) * 0.5)  # slowing from a run to rest: half the run speed on average
    tail = tail.copy(root_pos=tail.root_pos + expected * fwd)
    joined, where = gaps.insert_missing(concatenate([head, tail]), [(head.num_frames - 1, missing)])
    return joined, where[0]
