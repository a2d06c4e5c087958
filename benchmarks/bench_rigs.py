"""Every ordered pair of rig families retargeted, with the plausibility measures of each output.

    MOTIONLAB_DATA=/path/to/data python benchmarks/bench_rigs.py [--seconds 3] [--pair bandai mixamo]
    MOTIONLAB_DATA=/path/to/data python benchmarks/bench_rigs.py --methods [--source-fps 60] [--pair xia cmu]

Prints, per (source, target) pair: the hip height ratio (B's median hip height over B's standing
hip height, and the same for A on A), the median foot height in A's contact frames (cm and /
B's leg length), foot skating (cm/s, B and A) and the output frame rate
(:mod:`motionlab.retargeting.rig_matrix`). Without MOTIONLAB_DATA only the synthetic character runs.
With ``--methods``: the planted-foot slide of each pair under the three methods (copy rotations,
the network alone, the full latent iteration), beside the source's own; ``--source-fps`` resamples
every source clip first.
"""

from __future__ import annotations

import argparse
import time

from motionlab import data, retargeting
from motionlab.core import humanoid, metrics
from motionlab.retargeting import rig_matrix
from motionlab.retargeting.pipeline import retarget, source_contacts

METHODS = ("copy", "network", "full")


def method_slides(clips, checkpoint, pairs=None) -> None:
    """Print B's planted-foot slide (cm/s, on A's contact frames) per pair and method, and A's own."""
    feet = [humanoid.JOINTS.index(f) for f in humanoid.FEET]
    print(f"{'source':<10} {'target':<10} " + " ".join(f"{m:>8}" for m in METHODS) + f" {'(source)':>9}")
    for a in clips:
        for b in clips:
            if a == b or (pairs is not None and (a, b) not in pairs):
                continue
            src = humanoid.to_canonical(clips[a])
            planted = source_contacts(src)
            slides = []
            for method in METHODS:
                res = retarget(clips[a], clips[b], checkpoint, method=method)
                n = min(len(planted), len(res.positions))
                slides.append(100 * metrics.planted_slide(res.positions[:n], feet, planted[:n], res.motion.fps))
            own = 100 * metrics.planted_slide(src.global_positions(), feet, planted, src.fps)
            print(f"{a:<10} {b:<10} " + " ".join(f"{v:>8.1f}" for v in slides) + f" {own:>9.1f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=3.0, help="seconds of each family's clip (default 3)")
    ap.add_argument("--pair", nargs=2, action="append", metavar=("SOURCE", "TARGET"), help="only these pairs")
    ap.add_argument("--methods", action="store_true", help="slide per method (copy, network, full) instead")
    ap.add_argument("--source-fps", type=float, help="with --methods: resample every source clip to this rate")
    args = ap.parse_args()
    root = data.data_root() if data.has_data() else None
    clips = rig_matrix.family_clips(root, args.seconds)
    start = time.perf_counter()
    pairs = {tuple(p) for p in args.pair} if args.pair else None
    if args.methods:
        if args.source_fps:
            clips = {name: clip.resample(args.source_fps) for name, clip in clips.items()}
        method_slides(clips, retargeting.load_default(), pairs)
        print(f"{time.perf_counter() - start:.0f} s")
        return
    rows = rig_matrix.pair_matrix(clips, retargeting.load_default(), pairs=pairs)
    print(rig_matrix.table(rows))
    print(f"{len(rows)} pairs, {sum(r['ok'] for r in rows)} plausible, {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
