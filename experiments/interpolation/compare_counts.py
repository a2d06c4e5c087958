"""The missing count alone, on the cuts of ``check_gaps`` (parts 2, 5, 6 and 7), at any commit.

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.interpolation.compare_counts [--quick] [--cuts 4]

The counts of ``motionlab fill-gaps`` without ``--times`` (:func:`motionlab.interpolation.detect.detect`,
the stream alone), nothing filled: a cheap check of a change to the count rules. The cuts are
``check_gaps``' (same files, seeds and order: part 2's CHOOSE and VALIDATE with seed 0, parts 5, 6
and 7 with seeds 5, 7 and 11, ``--cuts`` places per clip and count of 10, 20 and 30 frames), so
run at two commits it compares their counts on the same cuts. Prints per set: cuts, gaps found,
counts exact, counts within 10% or one frame, and the mean absolute difference from the truth.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from experiments.interpolation import check_gaps, gap_eval
from motionlab.core import bvh
from motionlab.interpolation import detect


def _score(cuts) -> str:
    """One line of counts for ``cuts``: ``(motion, first removed frame, frames removed)``."""
    found = exact = near = 0
    off = []
    for m, s, n in cuts:
        est = dict(detect.detect(gap_eval.cut(m, s, n))).get(s - 1)
        if est is None:
            continue
        found += 1
        exact += est == n
        near += check_gaps.within(est, n)
        off.append(abs(est - n))
    mean = float(np.mean(off)) if off else float("nan")
    return f"{len(cuts)} cuts, {found} found; exact {exact}, within 10% or 1 frame {near} ({near / max(found, 1):.1%}); mean off {mean:.2f}"


def part2(root, quick: bool) -> dict[str, list]:
    """Part 2's cuts per set, as ``check_gaps.removed_frames`` draws them (one generator, seed 0)."""
    rng = np.random.default_rng(0)
    out = {}
    for name, files in check_gaps.sets(root, quick).items():
        cuts = []
        for f in files:
            m = bvh.load(f)
            for n in check_gaps.REMOVED:
                lo, hi = 20, m.num_frames - n - 20
                if hi > lo:
                    cuts.append((m, int(rng.integers(lo, hi)), n))
        out[name] = cuts
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="a sixth of part 2's clips, one place per clip in parts 5-7")
    ap.add_argument("--cuts", type=int, default=4, help="places per clip and count in parts 5-7 (check_gaps: 4)")
    ap.add_argument("--parts", default="2,5,6,7", help="which parts, comma-separated (default: all four)")
    args = ap.parse_args(argv)
    wanted = set(args.parts.split(","))
    root = check_gaps.data_root()
    t0 = time.perf_counter()
    for name, cuts in part2(root, args.quick).items() if "2" in wanted else ():
        print(f"part 2 {name}: {_score(cuts)}", flush=True)
    cuts = 1 if args.quick else args.cuts
    parts = (
        ("5", 5, check_gaps.OTHER_SOURCES),
        ("6", 7, check_gaps.FRESH_SOURCES),
        ("7", 11, check_gaps.UNSCORED_SOURCES),
    )
    for part, seed, sources in (p for p in parts if p[0] in wanted):
        rng = np.random.default_rng(seed)
        for label, patterns in sources.items():
            print(f"part {part} {label}: {_score(list(check_gaps.source_cuts(root, rng, cuts, patterns)))}", flush=True)
    print(f"({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
