"""Which root rule holds on a character never seen? Whole-motion leave-one-character-out check.

    python -m experiments.retargeting.root_rules_loco                     # $MOTIONLAB_DATA/mixamo, Aj -> 6 targets
    python -m experiments.retargeting.root_rules_loco --checkpoint /tmp/motionlab_Aj.pt --animations Running Jumping

A root rule scales A's root trajectory by B/A of one skeleton measure on the ground plane and
one up (:mod:`motionlab.retargeting.pipeline`); it sees the two skeletons only. For every rule
and target character, the full method (latent iteration) and copied rotations run with that
root, and the whole-motion MSE/h² against the target's real Mixamo clip is printed beside the
plain baseline (copied rotations, root scaled by thigh + shin on every axis).

Leave one character out: for each target, a rule is chosen on the *other* targets only, by two
principles, and scored on the left-out one:

* **root** -- the rule whose root path is closest to the real (Mixamo) root paths of the others:
  what the ground truth's retargeter does with the root, no network involved;
* **whole** -- the rule with the lowest whole-motion MSE/h² of the full method on the others.

Last, every rule's worst case over the targets: the full method's MSE/h² divided by the better
of the two copy baselines (> 1: it loses to a baseline on that character).

The network is Aj's, trained by ``motionlab evaluate`` (it writes ``<tmp>/motionlab_Aj.pt``).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import tempfile
from functools import partial
from pathlib import Path

import numpy as np
import torch

from motionlab import data, retargeting
from motionlab.core import bvh, humanoid, metrics, preprocess
from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS, DEFAULT_SOURCE, DEFAULT_TARGETS
from motionlab.retargeting.pipeline import (
    PreparedPair,
    finish,
    hip_height,
    leg_chain,
    prepare_pair,
    prepare_source,
    sole_lift,
    solve_pair,
    target_skeleton,
)

RULES = {  # name -> (ground-plane measure, height measure)
    "stride": (leg_chain, hip_height),
    "hips": (hip_height, hip_height),
    "legs": (humanoid.leg_length, humanoid.leg_length),
    "ankle/hips": (partial(leg_chain, joints=("UpLeg", "Leg", "Foot")), hip_height),
    "legs/hips": (humanoid.leg_length, hip_height),
}
"""Skeleton-only root rules. ``stride`` is the pipeline's default; ``legs`` is the plain
baseline's root (thigh + shin on every axis); ``hips`` scales every axis by the hip height."""
PLAIN = "legs"


def with_root(pair: PreparedPair, rule: str) -> PreparedPair:
    """``pair`` with A's root trajectory scaled by ``rule``'s ratios instead."""
    sk_a, sk_b = pair.source.motion.skeleton, pair.target
    r = tuple(m(sk_b) / m(sk_a) for m in RULES[rule])
    lift = sole_lift(pair.source, sk_b, r[1])  # each rig on its own sole, as the pipeline
    root_pos = pair.source.motion.root_pos * np.array([r[0], r[1], r[0]]) + np.array([0.0, lift, 0.0])
    dtype, device = pair.offsets.dtype, pair.offsets.device
    return dataclasses.replace(
        pair,
        root_scale=r,
        root_pos=root_pos,
        root_height=torch.as_tensor(root_pos[:, 1], dtype=dtype)[None],
        root_xz=torch.as_tensor(root_pos[:, [0, 2]], dtype=dtype, device=device)[None],
    )


def full_method(ckpt, pair: PreparedPair) -> np.ndarray:
    """World joint positions (T, 22, 3) of the full method on ``pair`` (as :func:`pipeline.retarget`)."""
    return finish(pair, solve_pair(ckpt, pair).local_rot[0], "full").positions


def score(folder: Path, ckpt, source: str, targets, animations) -> dict:
    """``err[kind][rule][target]``: mean over animations of MSE/h² (``root``: root only; ``copy``, ``full``)."""
    err = {k: {r: {t: [] for t in targets} for r in RULES} for k in ("root", "copy", "full")}
    for anim in animations:
        prep = prepare_source(bvh.load(folder / source / f"{anim}.bvh"), ckpt, "full")
        for t in targets:
            gt_rig = bvh.load(folder / t / f"{anim}.bvh")
            gt = preprocess.prepare(gt_rig, ckpt.fps)
            gt_pos, h = gt.global_positions(), gt.skeleton.height()
            base = prepare_pair(prep, target_skeleton(gt_rig.skeleton), "stride")
            for rule in RULES:
                pair = with_root(base, rule)
                n = min(len(gt_pos), len(pair.root_pos))
                err["root"][rule][t].append(metrics.mse(pair.root_pos[:n], gt.root_pos[:n], height=h))
                for kind, pos in (("copy", finish(pair, None, "copy").positions), ("full", full_method(ckpt, pair))):
                    err[kind][rule][t].append(metrics.mse(pos[:n], gt_pos[:n], height=h))
        print(f"  {anim}: done", file=sys.stderr, flush=True)
    return {k: {r: {t: float(np.mean(v)) for t, v in d.items()} for r, d in per.items()} for k, per in err.items()}


def print_tables(err: dict, targets) -> None:
    """Per rule and target: whole-motion MSE/h² of the full method and of copied rotations."""
    for kind, what in (("full", "full method"), ("copy", "copy rotations, same root"), ("root", "root alone")):
        print(f"\nwhole-motion MSE/h^2, {what}" if kind != "root" else "\nroot trajectory alone, MSE/h^2")
        print(f"{'rule':<12} " + " ".join(f"{t[:12]:>12}" for t in targets) + f" {'mean':>10}")
        for rule in RULES:
            vals = [err[kind][rule][t] for t in targets]
            print(f"{rule:<12} " + " ".join(f"{v:12.2e}" for v in vals) + f" {np.mean(vals):10.2e}")


def leave_one_out(err: dict, targets) -> None:
    """For each left-out target: each principle's pick on the others, scored on the left-out one."""
    print("\nleave one character out: rule chosen on the other targets, whole-motion MSE/h^2 on the left-out one")
    head = f"{'left out':<13} {'by':<6} {'rule':<11} {'full':>9} {'copy same':>9} {'plain':>9}  beats both"
    print(head)
    worst = {}
    for by, kind in (("root", "root"), ("whole", "full")):
        losses = []
        for t in targets:
            others = [u for u in targets if u != t]
            rule = min(RULES, key=lambda r, o=others, k=kind: np.mean([err[k][r][u] for u in o]))
            full, copy, plain = err["full"][rule][t], err["copy"][rule][t], err["copy"][PLAIN][t]
            ok = full < copy and full < plain
            losses.append(full / min(copy, plain))
            print(f"{t:<13} {by:<6} {rule:<11} {full:9.2e} {copy:9.2e} {plain:9.2e}  {'yes' if ok else 'NO'}")
        worst[by] = max(losses)
    print(
        "worst full / better baseline over left-out targets: " + ", ".join(f"by {b} {w:.3f}" for b, w in worst.items())
    )
    print("\nevery rule's worst case over the targets (full / better of the two copy baselines; > 1 loses)")
    for rule in RULES:
        ratios = [err["full"][rule][t] / min(err["copy"][rule][t], err["copy"][PLAIN][t]) for t in targets]
        print(f"{rule:<12} worst {max(ratios):.3f} ({targets[int(np.argmax(ratios))]}), mean {np.mean(ratios):.3f}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder", nargs="?", help="<Character>/<Animation>.bvh folder (default: $MOTIONLAB_DATA/mixamo)")
    ap.add_argument("--source", default=DEFAULT_SOURCE)
    ap.add_argument("--targets", nargs="+", default=list(DEFAULT_TARGETS))
    ap.add_argument("--animations", nargs="+", default=list(DEFAULT_ANIMATIONS))
    ap.add_argument("--checkpoint", help="Aj's network (default: <tmp>/motionlab_<source>.pt, from motionlab evaluate)")
    args = ap.parse_args(argv)
    try:
        folder = Path(args.folder) if args.folder else data.data_root() / "mixamo"
    except data.DataNotFound as e:
        sys.exit(f"root_rules_loco: {e}")
    path = Path(args.checkpoint or Path(tempfile.gettempdir()) / f"motionlab_{args.source}.pt")
    if not path.is_file():
        sys.exit(f"no checkpoint {path}: run `motionlab evaluate` first (it trains {args.source}'s network there)")
    ckpt = retargeting.load(str(path))
    print(f"{args.source} -> {len(args.targets)} targets, {len(args.animations)} animations, network {path}")
    err = score(folder, ckpt, args.source, args.targets, args.animations)
    print_tables(err, args.targets)
    leave_one_out(err, args.targets)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
