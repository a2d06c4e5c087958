"""In-betweening benchmark, LaFAN1 protocol, on any folder(s) of BVH files.

    python benchmarks/bench_inbetween.py                       # inbetween_test + behaviours in $MOTIONLAB_DATA
    python benchmarks/bench_inbetween.py path/to/folder [more folders or files] [--k 3]

Rows: zero-velocity, interpolation (SLERP + linear root, the LaFAN1 baseline), Hermite root, and
motionlab's key-pose-guided filling (MotionLibrary, leave-one-clip-out: a window is never filled
from its own clip). Columns: transition lengths 5, 15, 30 frames at 30 fps. The numbers are NOT
LaFAN1 numbers: the data used is printed with the table. Also measures the throughput of the
plain interpolation (filled frames per second, batched over windows).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from motionlab.interpolation import benchmark as bm
from motionlab.interpolation.library import MotionLibrary

BEHAVIOURS = [
    "bandai_namco/dataset-1/walk/dataset-1_walk_normal_002.bvh",
    "bandai_namco/dataset-1/walk-back/dataset-1_walk-back_normal_001.bvh",
    "bandai_namco/dataset-1/walk-left/dataset-1_walk-left_normal_001.bvh",
    "bandai_namco/dataset-1/walk-right/dataset-1_walk-right_normal_001.bvh",
    "bandai_namco/dataset-1/kick/dataset-1_kick_normal_001.bvh",
    "bandai_namco/dataset-1/punch/dataset-1_punch_normal_001.bvh",
    "bandai_namco/dataset-1/punch/dataset-1_punch_normal_002.bvh",
    "bandai_namco/dataset-1/bow/dataset-1_bow_normal_001.bvh",
    "mixamo_ganimator/Joe/Walk-In-Circle.bvh",
] + [
    f"mixamo/Aj/{c}.bvh"
    for c in ("Running", "Jumping", "Body_Jab_Cross", "Standing_To_Crouch", "Catwalk_Idle_To_Walk_Forward",
              "Injured_Walk_Left_Turn", "Idle", "Combo_Punch", "Standing_To_Crouched")
]  # fmt: skip


def default_paths() -> list[Path]:
    root = os.environ.get("MOTIONLAB_DATA")
    if not root:
        sys.exit("give BVH folders/files, or set MOTIONLAB_DATA (e.g. export MOTIONLAB_DATA=/path/to/shared/data)")
    root = Path(root)
    return [root / "bandai_namco/dataset-2"] + [root / p for p in BEHAVIOURS if (root / p).exists()]


def throughput(windows: bm.Windows, gap: int = 30, repeat: int = 5, target: int = 2000) -> float:
    reps = max(1, target // len(windows))
    big = bm.Windows(np.repeat(windows.local_rot, reps, 0), np.repeat(windows.trans, reps, 0),
                     np.repeat(windows.clip, reps), np.repeat(windows.start, reps), windows.parents, windows.names)  # fmt: skip
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        bm.method_interpolation(big, bm.N_PAST, gap)
        best = min(best, time.perf_counter() - t0)
    return len(big) * gap / best


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("paths", nargs="*", help="BVH files or folders (default: inbetween_test + behaviours)")
    ap.add_argument("--k", type=int, default=3, help="library stretches averaged per gap (default 3)")
    ap.add_argument("--fps", type=float, default=30.0)
    args = ap.parse_args(argv)
    paths = [Path(p) for p in args.paths] or default_paths()
    t0 = time.perf_counter()
    clips = bm.load_clips(paths, fps=args.fps)
    if not clips:
        sys.exit(f"no usable BVH clips under {[str(p) for p in paths]}")
    windows = bm.make_windows(clips)
    stats = bm.position_stats(clips)
    lib = MotionLibrary(clips, labels=[bm.action_label(c.name) for c in clips])
    methods = {
        "zero-velocity": bm.method_zero_velocity,
        "interpolation (SLERP+lin)": bm.method_interpolation,
        "Hermite root + SLERP": bm.method_hermite,
        f"motionlab key-pose (k={args.k})": bm.method_library(lib, k=args.k),
    }
    res = bm.evaluate(windows, methods, stats)
    elapsed = time.perf_counter() - t0
    print("In-betweening benchmark, LaFAN1 protocol (windows of 65 frames every 40, 10 context frames,")
    print("target = first frame after the gap). NOT LaFAN1 data; computed on:")
    for p in paths:
        print(f"  {p}")
    frames = sum(c.num_frames for c in clips)
    print(f"{len(clips)} clips, {frames} frames at {args.fps:g} fps, {len(windows)} windows, 22-joint skeleton;")
    print("L2P normalised with mean/std of these clips' global positions. motionlab row: leave-one-clip-out,")
    print("searching only other recordings of the same action (label from the file name); gaps whose action")
    print("has no other recording fall back to plain interpolation.")
    labels = sorted({bm.action_label(c.name) for c in clips})
    print(f"actions: {', '.join(labels)}\n")
    print(bm.format_table(res))
    for gap in (15, 30):
        a, b = res[("interpolation (SLERP+lin)", "L2P", gap)], res[(list(methods)[-1], "L2P", gap)]
        print(f"L2P at {gap}: motionlab {b:.3f} vs interpolation {a:.3f} ({100 * (1 - b / a):+.0f}% lower)")
    print(f"\nplain interpolation throughput: {throughput(windows):,.0f} filled frames/s (gap 30, batched)")
    print(f"total time {elapsed:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
