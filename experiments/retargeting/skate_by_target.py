"""Table 1's skating column per target character, beside each character's own Mixamo clips.

    motionlab evaluate --no-ablations --csv table1.csv
    MOTIONLAB_DATA=/path/to/data python -m experiments.retargeting.skate_by_target table1.csv

Reads the per-clip records ``motionlab evaluate --csv`` wrote and prints, per target, the mean
``skate`` (cm/s: horizontal speed of foot joints below 5 cm,
:func:`motionlab.core.metrics.foot_skating`) and ``slide`` (cm/s on the source's planted frames)
of each row, and the ground truth's ``skate`` (the character's own clips of the same animations at
the network's 60 fps, measured here as ``evaluate`` measures it) with each row's ratio to it.
"""

from __future__ import annotations

import argparse
import csv
from collections import defaultdict

import numpy as np

from motionlab import data
from motionlab.core import bvh, humanoid, metrics, preprocess


def ground_truth_skate(targets, animations, fps: float = 60.0) -> dict[str, float]:
    """Mean skating (cm/s) of each target's own clips of ``animations``."""
    feet = [humanoid.JOINTS.index(f) for f in humanoid.FEET]
    folder = data.data_root() / "mixamo"
    out = {}
    for target in targets:
        clips = [preprocess.prepare(bvh.load(folder / target / f"{a}.bvh"), fps) for a in animations]
        out[target] = float(np.mean([100.0 * metrics.foot_skating(c.global_positions(), feet, fps) for c in clips]))
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", help="per-clip records of `motionlab evaluate --csv`")
    args = ap.parse_args(argv)
    values, animations = defaultdict(list), defaultdict(set)
    with open(args.csv, newline="", encoding="utf-8") as f:
        for r in csv.DictReader(f):
            values[r["row"], r["target"], "skate"].append(float(r["skate"]))
            values[r["row"], r["target"], "slide"].append(float(r["slide"]))
            animations[r["target"]].add(r["animation"])
    targets = list(animations)
    rows = list(dict.fromkeys(row for row, _, _ in values))
    truth = ground_truth_skate(targets, sorted(set.union(*animations.values())))
    print(f"{'skate cm/s (x ground truth)':<36}" + "".join(f"{t[:14]:>16}" for t in targets))
    print(f"{'ground truth':<36}" + "".join(f"{truth[t]:>16.2f}" for t in targets))
    for row in rows:
        cells = [np.mean(values[row, t, "skate"]) for t in targets]
        print(f"{row:<36}" + "".join(f"{c:>9.2f} ({c / truth[t]:.2f})" for c, t in zip(cells, targets)))
    print(f"\n{'slide cm/s':<36}" + "".join(f"{t[:14]:>16}" for t in targets))
    for row in rows:
        print(f"{row:<36}" + "".join(f"{np.mean(values[row, t, 'slide']):>16.2f}" for t in targets))


if __name__ == "__main__":
    main()
