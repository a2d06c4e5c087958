"""Every ordered pair of rig families retargeted, with the plausibility measures of each output.

    MOTIONLAB_DATA=/path/to/data python benchmarks/bench_rigs.py [--seconds 3] [--pair bandai mixamo]

Prints, per (source, target) pair: the hip height ratio (B's median hip height over B's standing
hip height, and the same for A on A), the median foot height in A's contact frames (cm and /
B's leg length), foot skating (cm/s, B and A) and the output frame rate
(:mod:`motionlab.retargeting.rig_matrix`). Without MOTIONLAB_DATA only the synthetic character runs.
"""

from __future__ import annotations

import argparse
import time

from motionlab import data, retargeting
from motionlab.retargeting import rig_matrix


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=3.0, help="seconds of each family's clip (default 3)")
    ap.add_argument("--pair", nargs=2, action="append", metavar=("SOURCE", "TARGET"), help="only these pairs")
    args = ap.parse_args()
    root = data.data_root() if data.has_data() else None
    clips = rig_matrix.family_clips(root, args.seconds)
    start = time.perf_counter()
    pairs = {tuple(p) for p in args.pair} if args.pair else None
    rows = rig_matrix.pair_matrix(clips, retargeting.load_default(), pairs=pairs)
    print(rig_matrix.table(rows))
    print(f"{len(rows)} pairs, {sum(r['ok'] for r in rows)} plausible, {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
