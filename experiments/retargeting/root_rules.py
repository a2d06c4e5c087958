"""Which leg measure should scale the root trajectory? Measured against Mixamo's own retargets.

    python -m experiments.retargeting.root_rules                          # $MOTIONLAB_DATA/mixamo, Aj -> 6 targets
    python -m experiments.retargeting.root_rules path/to/folder --source Aj --targets BigVegas Kaya

The paper leaves B's root motion open. All three retargeting methods share it, and on the
shared Mixamo data it carries most of the error, so the choice is measured here, with no
network involved: A's root trajectory is scaled about the origin by B/A of a leg measure and
compared with B's real root trajectory (the error of the root alone, as MSE/h² over the three
axes, h = B's rig height). The ground plane (x, z) and the height (y) are scored separately.

Printed: the per-character scale Mixamo used (least squares over all clips), each measure's
ratio and root error, and a leave-one-character-out check: for every target, the measure
that is best on the *other* targets, and its error on the held-out one. The pipeline's
default (``root_mode="stride"``) is the outcome: leg chain on the ground, hip height up.
"""

from __future__ import annotations

import argparse
import sys
from functools import partial
from pathlib import Path

import numpy as np

from motionlab import data
from motionlab.core import bvh, humanoid, preprocess
from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS, DEFAULT_SOURCE, DEFAULT_TARGETS
from motionlab.retargeting.pipeline import contact_stride, hip_height, leg_chain

MEASURES = {
    "hip height": hip_height,
    "thigh+shin": humanoid.leg_length,
    "thigh+shin+foot": partial(leg_chain, joints=("Leg", "Foot", "ToeBase")),
    "hip..ankle chain": partial(leg_chain, joints=("UpLeg", "Leg", "Foot")),
    "leg chain (hip..toe)": leg_chain,
}
"""Candidate leg measures (metres) of a canonical skeleton; ``leg chain`` is :func:`pipeline.leg_chain`."""
CONTACTS = "contacts (per clip)"
"""The ground-plane ratio that keeps A's planted feet still on B's legs (:func:`pipeline.contact_stride`),
per clip; the leg chain where a clip has no steps. Scored on the ground plane only."""


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder", nargs="?", help="<Character>/<Animation>.bvh folder (default: $MOTIONLAB_DATA/mixamo)")
    ap.add_argument("--source", default=DEFAULT_SOURCE)
    ap.add_argument("--targets", nargs="+", default=list(DEFAULT_TARGETS))
    ap.add_argument("--animations", nargs="+", default=list(DEFAULT_ANIMATIONS))
    args = ap.parse_args(argv)
    try:
        folder = Path(args.folder) if args.folder else data.data_root() / "mixamo"
    except data.DataNotFound as e:
        sys.exit(f"root_rules: {e}")
    if not (folder / args.source).is_dir():
        sys.exit(f"no folder {folder / args.source}: set MOTIONLAB_DATA to the shared data (see README) or pass FOLDER")

    src = {a: preprocess.prepare(bvh.load(folder / args.source / f"{a}.bvh"), 60) for a in args.animations}
    sk_a = next(iter(src.values())).skeleton
    names = list(MEASURES) + [CONTACTS]
    err = {ax: {t: {} for t in args.targets} for ax in ("xz", "y")}  # axis -> target -> measure -> mean error
    print(f"Root trajectory of {args.source} scaled onto each target vs the target's real Mixamo root ({folder})")
    print(f"{len(args.animations)} animations; error = mean over frames of |root - real root|^2 / 3 / h^2\n")
    head = f"{'target':<14} {'Mixamo xz':>9} {'Mixamo y':>8}  " + "  ".join(f"{n:>20}" for n in names)
    print("ratio B/A of each measure next to the scale Mixamo used (least squares over the clips)")
    print(head)
    for t in args.targets:
        rigs = [bvh.load(folder / t / f"{a}.bvh") for a in args.animations]
        clips = [preprocess.prepare(rig, 60) for rig in rigs]
        heights = [rig.skeleton.height() for rig in rigs]
        sk_b = clips[0].skeleton
        a_xz = np.concatenate([src[a].root_pos[:, [0, 2]] for a in args.animations])
        b_xz = np.concatenate([c.root_pos[:, [0, 2]] for c in clips])
        a_y = np.concatenate([src[a].root_pos[:, 1] for a in args.animations])
        b_y = np.concatenate([c.root_pos[:, 1] for c in clips])
        fit_xz = float((a_xz * b_xz).sum() / (a_xz * a_xz).sum())
        fit_y = float((a_y * b_y).sum() / (a_y * a_y).sum())
        ratios = {n: MEASURES[n](sk_b) / MEASURES[n](sk_a) for n in MEASURES}
        per_clip = [contact_stride(src[a], sk_b) for a in args.animations]
        fallback = ratios["leg chain (hip..toe)"]
        ratios[CONTACTS] = float(np.mean([r if r is not None else fallback for r in per_clip]))
        print(f"{t:<14} {fit_xz:9.3f} {fit_y:8.3f}  " + "  ".join(f"{ratios[n]:20.3f}" for n in names))
        for n in names:
            per_xz, per_y = {}, {}
            for i, (a, c, h) in enumerate(zip(args.animations, clips, heights, strict=True)):
                r = ratios[n] if n != CONTACTS else (per_clip[i] if per_clip[i] is not None else fallback)
                ra = src[a].root_pos
                per_xz[a] = ((ra[:, [0, 2]] * r - c.root_pos[:, [0, 2]]) ** 2).sum(1).mean() / 3 / h**2
                per_y[a] = ((ra[:, 1] * r - c.root_pos[:, 1]) ** 2).mean() / 3 / h**2
            err["xz"][t][n], err["y"][t][n] = per_xz, per_y

    first, second = args.animations[::2], args.animations[1::2]

    def mean_err(ax, targets, anims, n):
        return float(np.mean([err[ax][t][n][a] for t in targets for a in anims]))

    for ax, what in (("xz", "ground plane (x, z)"), ("y", "height (y)")):
        cands = names if ax == "xz" else list(MEASURES)
        print(f"\nroot error of the {what}, MSE/h^2")
        print(f"{'target':<14} " + "  ".join(f"{n:>20}" for n in cands))
        for t in args.targets:
            print(f"{t:<14} " + "  ".join(f"{mean_err(ax, [t], args.animations, n):20.2e}" for n in cands))
        means = {n: mean_err(ax, args.targets, args.animations, n) for n in cands}
        print(f"{'mean':<14} " + "  ".join(f"{means[n]:20.2e}" for n in cands))
        if len(args.targets) > 1:
            held, picks = [], []
            for t in args.targets:  # leave one character AND half the animations out
                others = [u for u in args.targets if u != t]
                for chosen_on, tested_on in ((first, second), (second, first)):
                    best = min(cands, key=lambda n, o=others, c=chosen_on: mean_err(ax, o, c, n))
                    picks.append(best)
                    held.append(mean_err(ax, [t], tested_on, best))
            print(
                f"leave one character and half the animations out ({len(held)} splits): picks "
                + ", ".join(f"{n} x{picks.count(n)}" for n in sorted(set(picks)))
                + f"; held-out error {np.mean(held):.2e} (best measure on all: {min(means, key=means.get)})"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
