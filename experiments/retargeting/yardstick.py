"""The yardstick: Table 1's 60 pairs, Mixamo's own clips and motionlab's, under one plausibility check.

    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.yardstick [--checkpoint PATH]

For each of Table 1's 10 animations (:data:`motionlab.retargeting.evaluate.DEFAULT_ANIMATIONS`)
and 6 target characters (:data:`~motionlab.retargeting.evaluate.DEFAULT_TARGETS`), checks with
:func:`motionlab.retargeting.plausibility.check` against Aj's source clip (standing, at the
network's rate, its planted frames):

* the **ground truth**: the character's own Mixamo clip of the animation (its standing canonical
  skeleton, at the network's rate; both clips cut to the frames they share);
* **motionlab**: the full method's output of the same pair (:func:`pipeline.retarget`, Table 1's
  protocol: the target's skeleton alone, the default root), whose check the pipeline made.

Prints the failing share of each (overall and per character) with the failing checks named, the
knee bend and foot pitch of each character's own rest pose (the canonical standing pose,
:mod:`motionlab.core.rest_pose`, turns the legs straight down), and the pairs that fail.
``--checkpoint`` picks the network (default: the shipped one; Table 1's is ``motionlab
evaluate``'s, trained on Aj's other clips).
"""

from __future__ import annotations

import argparse
import time
from collections import Counter

import numpy as np

from motionlab import data, retargeting
from motionlab.core import bvh, humanoid, preprocess
from motionlab.retargeting import checkpoint as ckpt_io
from motionlab.retargeting import evaluate, losses, pipeline, plausibility
from motionlab.retargeting.solver import SolverConfig


def _cut(motion, n: int):
    return motion.copy(
        local_rot=motion.local_rot[:n],
        root_pos=motion.root_pos[:n],
        local_pos=None if motion.local_pos is None else motion.local_pos[:n],
    )


def check_pair(ckpt, source, src: pipeline.PreparedSource, gt_rig, solver=None) -> tuple:
    """(ground truth's Plausibility, motionlab's Plausibility, motionlab's deepest joint) of one pair."""
    gt = preprocess.prepare(gt_rig, ckpt.fps, stand=True)
    n = min(gt.num_frames, src.motion.num_frames)
    planted = src.planted[0].cpu().numpy()[:n]
    soles = (src.sole, pipeline.target_sole(gt.skeleton))  # each rig on its own sole, as the pipeline checks
    truth = plausibility.check(gt.global_positions()[:n], gt.skeleton, _cut(src.motion, n), planted, soles)
    out = retargeting.retarget(source, gt_rig.skeleton, ckpt, "full", solver)
    deepest = humanoid.JOINTS[int(np.argmin(out.positions[..., 1].min(axis=0)))]
    return truth, out.plausibility, deepest


def rest_angles(skeleton) -> tuple[float, float]:
    """A canonical skeleton's rest knee bend (angle between thigh and shin) and the foot's pitch
    (ankle → toe below the horizontal), degrees, mean of both legs."""
    rest, j = skeleton.rest_positions(), humanoid.JOINTS.index
    knee, pitch = [], []
    for side in ("Left", "Right"):
        thigh = rest[j(side + "Leg")] - rest[j(side + "UpLeg")]
        shin = rest[j(side + "Foot")] - rest[j(side + "Leg")]
        foot = rest[j(side + "ToeBase")] - rest[j(side + "Foot")]
        knee.append(np.arccos(np.clip(thigh @ shin / np.linalg.norm(thigh) / np.linalg.norm(shin), -1, 1)))
        pitch.append(np.arcsin(np.clip(-foot[1] / np.linalg.norm(foot), -1, 1)))
    return float(np.degrees(np.mean(knee))), float(np.degrees(np.mean(pitch)))


def _share(checks: list) -> str:
    failed = [c for c in checks if not c.ok]
    names = Counter(name for c in failed for name in c.failed)
    named = ", ".join(f"{k} {v}" for k, v in sorted(names.items())) or "-"
    return f"{len(failed):>3}/{len(checks):<3} ({named})"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--checkpoint", help="network (default: the shipped one)")
    ap.add_argument("--targets", nargs="+", default=list(evaluate.DEFAULT_TARGETS))
    ap.add_argument("--animations", nargs="+", default=list(evaluate.DEFAULT_ANIMATIONS))
    ap.add_argument("--foot-weight", type=float, help=f"λ_foot of the full method (default {losses.LAMBDA_FOOT})")
    args = ap.parse_args(argv)
    solver = None if args.foot_weight is None else SolverConfig(lambda_foot=args.foot_weight)
    start = time.perf_counter()
    ckpt = ckpt_io.load(args.checkpoint) if args.checkpoint else retargeting.load_default()
    folder = data.data_root() / "mixamo"
    results = {}  # (target, animation) -> (truth, ours, motionlab's deepest joint)
    shares = {}
    for anim in args.animations:
        source = bvh.load(folder / evaluate.DEFAULT_SOURCE / f"{anim}.bvh")
        src = pipeline.prepare_source(source, ckpt, "full")
        for target in args.targets:
            rig = bvh.load(folder / target / f"{anim}.bvh")
            results[target, anim] = check_pair(ckpt, source, src, rig, solver)
            shares[target] = rest_angles(humanoid.to_canonical_skeleton(rig.skeleton))
        shares[evaluate.DEFAULT_SOURCE] = rest_angles(humanoid.to_canonical_skeleton(source.skeleton))
    print(
        f"network: {args.checkpoint or 'shipped default'}"
        + ("" if solver is None else f"; lambda_foot {args.foot_weight}")
    )
    print(f"{'character':<14} {'ground truth fails':<34} {'motionlab fails':<34} own rest: knee bend, foot pitch (deg)")
    for target in args.targets + ["all"]:
        pairs = [v for (t, _), v in results.items() if target in ("all", t)]
        knee, pitch = shares.get(target, shares[evaluate.DEFAULT_SOURCE])
        share = f"{knee:5.1f} {pitch:5.1f}" + ("" if target in shares else f" ({evaluate.DEFAULT_SOURCE}'s)")
        print(f"{target:<14} {_share([p[0] for p in pairs]):<34} {_share([p[1] for p in pairs]):<34} {share}")
    print("\nfailing pairs: ground truth | motionlab (lowest joint / leg, source's, motionlab's deepest; hips; foot)")
    for (target, anim), (truth, ours, deepest) in results.items():
        if truth.ok and ours.ok:
            continue
        print(
            f"{target:<13} {anim:<31} {','.join(truth.failed) or 'ok':<10} | {','.join(ours.failed) or 'ok':<10}"
            f" lowest {truth.lowest:+.3f} / {ours.lowest:+.3f} (A {ours.source_lowest:+.3f}) {deepest};"
            f" hips {truth.hip_ratio:.2f} / {ours.hip_ratio:.2f} (A {ours.source_hip_ratio:.2f});"
            f" foot {truth.foot_height:+.3f} / {ours.foot_height:+.3f} (A {ours.source_foot_height:+.3f})"
        )
    print(f"{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
