"""In-betweening benchmark on LaFAN1's protocol, one skeleton at a time.

    python -m experiments.interpolation.bench_inbetween                # the two groups below, from $MOTIONLAB_DATA
    python -m experiments.interpolation.bench_inbetween --k 1

LaFAN1 itself is not in the shared data (see its README), so two stand-in groups are scored, each
on its own skeleton, each with its L2P statistics from a fixed set of clips of that skeleton kept
apart from the scored windows (LaFAN1 uses its training subjects):

* **Bandai Namco** (proportion-aligned 22-joint rig, 30 fps): scored = ``bandai_namco/dataset-2``
  (the 8 ``inbetween_test`` clips); apart = the normal-style clips of ``dataset-1`` and the normal
  walk takes 4–12 of ``sessions/walk`` (takes 1–3 are the scored walks);
* **Mixamo Aj** (60 fps resampled to 30): scored = the 9 Aj behaviour clips; apart = every third
  of the other Aj clips (sorted by name).

Rows: zero-velocity, interpolation (SLERP + linear root, LaFAN1's baseline), Hermite root + SLERP,
and motionlab's key-pose-guided filling (MotionLibrary over the scored and the apart clips,
leave-one-clip-out: a window is never filled from its own clip; Bandai: only recordings of the
window's own action), without and with a matching-cost limit above which a gap is filled by a
simple method instead; the limit and that fallback (interpolation or Hermite root + SLERP) are
chosen together on the apart clips' own windows (:func:`choose_fill`), never on the scored ones. Columns: transition lengths 5, 15, 30, 45. Outputs are made sign-continuous
with the last context frame before FK; nothing is flipped at scoring. NOT LaFAN1 numbers.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from experiments.interpolation import benchmark as bm
from motionlab.interpolation.library import MotionLibrary

AJ_SCORED = [
    f"mixamo/Aj/{c}.bvh"
    for c in ("Running", "Jumping", "Body_Jab_Cross", "Standing_To_Crouch", "Catwalk_Idle_To_Walk_Forward",
              "Injured_Walk_Left_Turn", "Idle", "Combo_Punch", "Standing_To_Crouched")
]  # fmt: skip


def groups(root: Path) -> list[tuple[str, list[Path], list[Path], bool]]:
    """``(name, scored files, apart files, same_action)`` per skeleton."""
    d1 = root / "bandai_namco/dataset-1"
    bandai_scored = sorted((root / "bandai_namco/dataset-2").rglob("*.bvh"))
    bandai_apart = sorted(d1.rglob("*_normal_*.bvh"))
    bandai_apart += [root / f"bandai_namco/sessions/walk/dataset-2_walk_normal_{i:03d}.bvh" for i in range(4, 13)]
    aj_scored = [root / p for p in AJ_SCORED]
    skip = {p.name for p in aj_scored} | {"std_bvh.bvh"}
    aj_apart = [p for p in sorted((root / "mixamo/Aj").glob("*.bvh")) if p.name not in skip][::3]
    out = [("Bandai Namco", bandai_scored, bandai_apart, True), ("Mixamo Aj", aj_scored, aj_apart, False)]
    return [(n, [p for p in sc if p.exists()], [p for p in ap if p.exists()], same) for n, sc, ap, same in out]


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


def run_group(name, scored, apart, same_action, k, fps):
    clips = bm.load_clips(scored, fps=fps)
    held = bm.load_clips(apart, fps=fps)
    windows = bm.make_windows(clips)
    stats = bm.position_stats(held)
    everything = clips + held
    lib = MotionLibrary(everything, labels=[bm.action_label(c.name) for c in everything])
    key = f"motionlab key-pose (k={k})"
    apart_windows = bm.make_windows(held)
    simple = {"interpolation (SLERP+lin)": bm.method_interpolation, "Hermite root + SLERP": bm.method_hermite}
    fallback, max_cost, totals = bm.choose_fill(apart_windows, lib, stats, simple, k=k, same_action=same_action)
    methods = {
        "zero-velocity": bm.method_zero_velocity,
        **simple,
        f"key-pose, no cost limit (k={k})": bm.method_library(lib, k=k, same_action=same_action),
        key: bm.method_library(lib, k=k, same_action=same_action, max_cost=max_cost, fallback=simple[fallback]),
    }
    res = bm.evaluate(windows, methods, stats)
    frames = sum(c.num_frames for c in clips)
    print(f"--- {name}: {len(clips)} scored clips, {frames} frames at {fps:g} fps, {len(windows)} windows;")
    print(f"    L2P statistics from {len(held)} clips kept apart ({sum(c.num_frames for c in held)} frames); "
          f"library: both sets ({lib.num_frames} frames), leave-one-clip-out"
          + (", same action only" if same_action else ""))  # fmt: skip
    print(f"    fallback and cost limit chosen on the {len(apart_windows)} windows of the apart clips (gaps 15, 30;")
    print("    summed L2P with each fallback at its best limit: "
          + ", ".join(f"{n} {t:.2f}" for n, t in totals.items()) + ")")  # fmt: skip
    print(f"    -> above cost {max_cost:.3g} (no recording matches the gap's ends) a gap is filled by {fallback}")
    print("    scored: " + ", ".join(c.name for c in clips))
    print("    apart:  " + ", ".join(c.name for c in held))
    print()
    print(bm.format_table(res))
    for gap in (15, 30):
        a, b = res[("interpolation (SLERP+lin)", "L2P", gap)], res[(key, "L2P", gap)]
        qa, qb = res[("interpolation (SLERP+lin)", "L2Q", gap)], res[(key, "L2Q", gap)]
        print(f"gap {gap}: L2P key-pose {b:.3f} vs interpolation {a:.3f} ({100 * (1 - b / a):+.0f}% lower: "
              f"{'ahead' if b < a else 'tied' if b == a else 'BEHIND'}); L2Q {qb:.3f} vs {qa:.3f} "
              f"({'match or beat' if qb <= qa else 'WORSE'})")  # fmt: skip
    print()
    return windows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--k", type=int, default=3, help="library stretches averaged per gap (default 3)")
    ap.add_argument("--fps", type=float, default=30.0)
    args = ap.parse_args(argv)
    root = os.environ.get("MOTIONLAB_DATA")
    if not root:
        sys.exit("set MOTIONLAB_DATA to the shared data folder (e.g. export MOTIONLAB_DATA=/path/to/shared/data)")
    t0 = time.perf_counter()
    print("In-betweening benchmark, LaFAN1 protocol (windows of 65 frames every 40, 10 context frames, target =")
    print("first frame after the gap; outputs sign-continuous with the last context frame before FK, no flip at")
    print("scoring; L2P statistics from clips kept apart, one skeleton at a time). NOT LaFAN1 data.\n")
    windows = None
    for name, scored, apart, same in groups(Path(root)):
        if not scored or not apart:
            print(f"--- {name}: skipped (files missing under {root})")
            continue
        windows = run_group(name, scored, apart, same, args.k, args.fps)
    if windows is not None:
        print(f"plain interpolation throughput: {throughput(windows):,.0f} filled frames/s (gap 30, batched)")
    print(f"total time {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
