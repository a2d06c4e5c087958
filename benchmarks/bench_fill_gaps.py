"""How long ``gaps.fill`` (what ``motionlab fill-gaps`` runs) takes on a long stream with many gaps.

    MOTIONLAB_DATA=/path/to/shared/data python benchmarks/bench_fill_gaps.py [--copies 40] [--gaps 20]

The stream is ``--copies`` copies of the Bandai Namco walk ``dataset-2_walk_normal_001`` one after
another (a synthetic walk without the data), with ``--gaps`` gaps of ``--frames`` frames evenly
spread; each is filled with its true count by the default method (``stride``, each gap's fill
rehearsed on cuts near it) and by ``slerp``. Prints the stream's length and each fill's time; the
fills run once, so the times move with the machine's load.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from motionlab import data, synthetic
from motionlab.core import bvh
from motionlab.interpolation import gaps, inbetween

TAKE = ("bandai_namco", "dataset-2", "walk", "dataset-2_walk_normal_001")


def stream(copies: int):
    """The walk repeated ``copies`` times, and where it came from."""
    if data.has_data(*TAKE[:-1]):
        take, source = bvh.load(data.clip_path(*TAKE)), "/".join(TAKE) + ".bvh"
    else:
        take, source = synthetic.generate("walk", None, 270, 30.0, seed=0), "a synthetic walk"
    return inbetween.concatenate([take] * copies), source


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--copies", type=int, default=40)
    ap.add_argument("--gaps", type=int, default=20)
    ap.add_argument("--frames", type=int, default=3, help="frames missing in each gap")
    args = ap.parse_args(argv)
    long, source = stream(args.copies)
    places = np.linspace(100, long.num_frames - 100, args.gaps).astype(int)
    holed, _ = gaps.insert_missing(long, [(int(p), args.frames) for p in places])
    print(f"{source} x {args.copies}: {long.num_frames} frames, {args.gaps} gaps of {args.frames} frames")
    for method in ("stride", "slerp"):
        t0 = time.perf_counter()
        _, report = gaps.fill(holed, method=method)
        used = sorted({r.method for r in report})
        print(f"  fill(method={method!r}): {time.perf_counter() - t0:6.1f} s (gaps filled by {', '.join(used)})")


if __name__ == "__main__":
    main()
