"""Standing pose of every Bandai Namco dataset-2 take, and the run hip heights across rigs.

    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.standing

Part 1 runs only the retargeting's preparation of each take (reduction to the 22 canonical joints
and the canonical standing pose, :func:`motionlab.core.preprocess.prepare` with ``stand=True``)
on every dataset-2 take in the data (``bandai_namco/sessions/*/`` and ``bandai_namco/dataset-2/*/``)
and prints how many are refused, per behaviour, and the spread of the standing hip height the takes
give the one rig. ``--old`` also prints what a take's own most upright frame gives (the rule before
the rig profile's). Part 2 prints, for the run clips of Mixamo's Aj and of Bandai Namco, the median
hip height over the standing hip height (the plausibility check's ``hips`` measure) and the median
knee bend on the frames with a planted foot (contacts at the network's 60 fps), and the same ratio of the clip retargeted onto the
Bandai Namco rig (copying rotations: the root, hence the hips, is the same for every method).
``--soles`` adds part 3: for the CMU and Xia takes and every tenth Bandai Namco take, the sole each
take plants its toes on (:func:`motionlab.core.rest_pose.take_sole`, as a fraction of the leg) and
how many of them the take's own target skeleton keeps (:func:`pipeline.target_skeleton`).
"""

from __future__ import annotations

import argparse
import time
from collections import Counter

import numpy as np

from motionlab import data
from motionlab.core import bvh, humanoid, preprocess, rest_pose
from motionlab.retargeting import contacts, pipeline

MIXAMO_RUNS = ("Running", "Run_Arc_Left", "Pistol_Run_Backward_Arc")


def dataset2_takes(root) -> list:
    """Every Bandai Namco dataset-2 BVH file in the data, sorted."""
    base = root / "bandai_namco"
    return sorted([*base.glob("sessions/*/*.bvh"), *base.glob("dataset-2/*/*.bvh")])


def refusals(files, old: bool) -> None:
    """Print refused takes per behaviour and the spread of the rig's standing hip height."""
    refused, total, heights, old_heights = Counter(), Counter(), [], []
    for f in files:
        behaviour = f.parent.name
        total[behaviour] += 1
        motion = bvh.load(f)
        try:
            heights.append(pipeline.hip_height(preprocess.prepare(motion, None, stand=True).skeleton))
        except rest_pose.RestPoseError:
            refused[behaviour] += 1
        if old:
            try:  # no rig profile: the take's own most upright frame
                old_heights.append(pipeline.hip_height(rest_pose.standing(humanoid.to_canonical(motion))[0].skeleton))
            except rest_pose.RestPoseError:
                refused[f"{behaviour} (take's own frame)"] += 1
    for b in sorted(total):
        print(
            f"{b:<22} {total[b]:4d} takes, {refused[b]:3d} refused"
            + (f" ({refused[b + ' (take' + chr(39) + 's own frame)']} by the take's own frame)" if old else "")
        )
    print(
        f"{'all':<22} {sum(total.values()):4d} takes, {sum(v for k, v in refused.items() if '(' not in k):3d} refused"
    )
    for label, h in (("rig profile", heights), ("take's own frame", old_heights)):
        if h:
            h = np.array(h)
            print(
                f"standing hip height, {label}: {h.min():.4f}-{h.max():.4f} m (median {np.median(h):.4f}) over {len(h)} takes"
            )


def _knee_bend(motion) -> float:
    """Median knee bend (degrees, 0 = straight) on the frames where that foot is planted."""
    pos = motion.global_positions()
    planted = contacts.of_motion(motion)
    bends = []
    for k, side in enumerate(("Left", "Right")):
        a, b, c = (pos[:, humanoid.JOINTS.index(side + n)] for n in ("UpLeg", "Leg", "Foot"))
        u, v = b - a, c - b
        cos = (u * v).sum(-1) / (np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1))
        bends.append(np.degrees(np.arccos(np.clip(cos, -1, 1)))[planted[:, k]])
    bends = np.concatenate(bends)
    return float(np.median(bends)) if len(bends) else float("nan")


def run_heights(root) -> None:
    """Print hip height / standing hip height and knee bend of Mixamo's and Bandai Namco's runs."""
    files = [root / "mixamo" / "Aj" / f"{n}.bvh" for n in MIXAMO_RUNS]
    files += sorted((root / "bandai_namco" / "dataset-2" / "run").glob("*.bvh"))
    files += sorted((root / "bandai_namco" / "dataset-1" / "run").glob("*_normal_*.bvh"))
    bandai = bvh.load(files[-1])
    print(
        f"\n{'run clip':<36} {'standing hip m':>14} {'hips / standing':>15} {'planted knee deg':>16} {'on Bandai rig':>13}"
    )
    for f in files:
        motion = bvh.load(f)
        m = preprocess.prepare(motion, 60.0, stand=True)  # at the network's rate, as retargeting labels contacts
        ratio = float(np.median(m.root_pos[:, 1])) / pipeline.hip_height(m.skeleton)
        out = pipeline.retarget(motion, bandai, method="copy")  # the root, hence the hips, is every method's
        on_b = float(np.median(out.positions[:, 0, 1])) / pipeline.hip_height(out.motion.skeleton)
        print(
            f"{f.stem:<36} {pipeline.hip_height(m.skeleton):>14.3f} {ratio:>15.2f} {_knee_bend(m):>16.0f} {on_b:>13.2f}"
        )


def soles(root) -> None:
    """Print, per rig family, the range of the takes' soles / leg and how many targets keep theirs."""
    families = {
        "cmu": sorted(root.glob("cmu/*/*.bvh")),
        "xia": sorted(root.glob("xia/*/*.bvh")),
        "bandai": sorted(root.glob("bandai_namco/**/*.bvh"))[::10],
    }
    print(f"\n{'family':<8} {'takes':>5} {'sole / leg':>17} {'kept as target':>15}")
    for family, files in families.items():
        ratios, kept = [], 0
        for f in files:
            motion = bvh.load(f)
            sole = rest_pose.take_sole(preprocess.prepare(motion, None, stand=True))
            target = pipeline.target_skeleton(motion)
            ratios.append(sole / humanoid.leg_length(target))
            kept += abs(pipeline.target_sole(target) - sole) <= 1e-9
        if files:
            print(f"{family:<8} {len(files):>5} {min(ratios):>+8.4f}..{max(ratios):>+7.4f} {kept:>15}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old", action="store_true", help="also the take's own most upright frame (no rig profile)")
    ap.add_argument("--soles", action="store_true", help="also each rig family's take soles (part 3)")
    args = ap.parse_args(argv)
    if not data.has_data():
        raise SystemExit("needs MOTIONLAB_DATA")
    root = data.data_root()
    start = time.perf_counter()
    refusals(dataset2_takes(root), args.old)
    run_heights(root)
    if args.soles:
        soles(root)
    print(f"{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
