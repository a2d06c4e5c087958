"""The rest knee bend of every rig in the shared data, before and after its canonical standing pose.

    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.rest_knees

For each Mixamo character (one clip each, ``mixamo/`` and ``mixamo_ganimator/``), the CMU, Xia and
Bandai Namco clips of the rig matrix (:data:`experiments.retargeting.rig_matrix.FAMILY_CLIPS`, and
a dataset-2 take) and synthetic characters, prints the knee bend (angle between thigh and shin,
largest of both legs) and the largest angle of a thigh or shin to straight down, of the rig's own
rest (its 22 canonical joints) and of its canonical standing pose
(:func:`motionlab.core.rest_pose.standing_skeleton`), where the pose came from, and the bones it
turned. Without MOTIONLAB_DATA only the synthetic characters run.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from experiments.retargeting import rig_matrix
from motionlab import data, synthetic
from motionlab.core import bvh, humanoid, rest_pose


def _angle(u: np.ndarray, v: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(u @ v / np.linalg.norm(u) / np.linalg.norm(v), -1.0, 1.0))))


def leg_angles(skeleton) -> tuple[float, float]:
    """(knee bend, worst thigh or shin angle to straight down) of a canonical skeleton at rest, degrees."""
    rest, j = skeleton.rest_positions(), humanoid.JOINTS.index
    down = np.array([0.0, -1.0, 0.0])
    knee, vertical = [], []
    for side in ("Left", "Right"):
        thigh = rest[j(side + "Leg")] - rest[j(side + "UpLeg")]
        shin = rest[j(side + "Foot")] - rest[j(side + "Leg")]
        knee.append(_angle(thigh, shin))
        vertical += [_angle(thigh, down), _angle(shin, down)]
    return float(max(knee)), float(max(vertical))


def rigs(root: Path | None) -> dict:
    """Name -> Motion: one clip per rig of the data (none without ``root``), and synthetic characters."""
    paths = {}
    if root is not None:
        for folder in ("mixamo", "mixamo_ganimator"):
            for character in sorted(p for p in (root / folder).iterdir() if p.is_dir()):
                paths[f"{folder}/{character.name}"] = sorted(character.glob("*.bvh"))[0]
        for family in ("cmu", "xia", "bandai"):
            paths[family] = root / rig_matrix.FAMILY_CLIPS[family]
        paths["bandai dataset-2"] = sorted((root / "bandai_namco" / "dataset-2").glob("*/*.bvh"))[0]
    out = {name: bvh.load(path) for name, path in paths.items()}
    characters = [humanoid.canonical_skeleton(), *synthetic.character_set(4, seed=0)]
    for i, character in enumerate(characters):
        out[f"synthetic {i}"] = synthetic.generate("walk", character, num_frames=30, fps=60, seed=0)
    return out


def main(argv=None) -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args(argv)
    root = data.data_root() if data.has_data() else None
    print(
        f"{'rig':<28} {'own rest: knee':>14} {'leg/vertical':>12} {'standing: knee':>14} {'leg/vertical':>12}  source   turned"
    )
    for name, motion in rigs(root).items():
        own = leg_angles(humanoid.to_canonical_skeleton(motion.skeleton))
        skeleton, pose = rest_pose.standing_skeleton(motion, name)
        new = leg_angles(skeleton)
        turned = ",".join(pose.straightened) or "-"
        print(f"{name:<28} {own[0]:>14.1f} {own[1]:>12.1f} {new[0]:>14.1f} {new[1]:>12.1f}  {pose.source:<8} {turned}")


if __name__ == "__main__":
    main()
