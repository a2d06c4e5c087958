"""Reproduce the experiments of the key-pose paper (Yang et al. 2019, §4) on the shared real mocap.

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.interpolation.reproduce_keypose_paper [--figure PATH]

1. **Walk inside one node (Fig. 6/7, Table 1).** The paper's 495-frame CMU walk at 120 Hz is not in
   the shared data; the nearest real walk is ``xia/walk/normal_ganimator.bvh`` (CMU skeleton,
   120 Hz, 360 frames, all walking). Frames 5, 35, 65, … are kept and every other frame removed
   ("at regular intervals"); each gap is filled inside the walk node (SLERP of rotations, Hermite
   root). Printed: the angle error per joint of the 13 walking joints, the joint position error,
   and L2P with statistics from the *other* Xia walks (kept apart). Figure: left hip (lThigh)
   angles, true dashed against filled solid, as the paper's Fig. 7.
2. **run → walk → stand → squat with 10 missing frames (Fig. 8).** Mixamo Aj clips checked by
   content (run = ``Run_Arc_Left``; ``Running.bvh`` is a dive roll), graph run ↔ walk ↔ stand ↔
   squat; frame 1 runs, frame 12 squats, frames 2–11 are missing. Printed: the path, where the key
   poses went (paper frames 5 and 8), which key frames they are, the root speed through the gap
   and the lowest foot against the floor. Figure: the 12 frames side by side.

The figure is written to ``docs/media/keypose_paper.png`` by default (the README shows it).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

from experiments.interpolation import benchmark, paper
from motionlab.interpolation import demo, labels

WALK = "xia/walk/normal_ganimator.bvh"
OTHER_WALKS = ["xia/walk/neutral_01_000.bvh", "xia/walk/sexy_01_000.bvh", "xia/walk/strutting_01_000.bvh"]


def walk_part(root: Path):
    walk = benchmark.load_clips([root / WALK], fps=None)[0]
    res = paper.walk_experiment(walk, first=5, every=30)
    lin = paper.walk_experiment(walk, first=5, every=30, root="linear")
    print(f"1. walk within one node: {WALK}, {walk.num_frames} frames at {walk.fps:g} Hz (paper: 495 CMU frames)")
    print(f"   kept frames {res.kept[:4].tolist()} … every 30 ({len(res.kept)} kept, "
          f"{res.truth.num_frames - len(res.kept)} filled)")  # fmt: skip
    print("   mean angle error of the filled frames per joint (degrees), the 13 walking joints:")
    for name, err in res.angle_error.items():
        tag = "  <- the paper's lThigh" if name == "LeftUpLeg" else ""
        print(f"     {name:<13} {err:5.2f}{tag}")
    print(f"   mean over the 13: {np.mean(list(res.angle_error.values())):.2f} degrees")
    print(f"   mean joint position error / body height: {res.position_error:.4f} (Hermite root), "
          f"{lin.position_error:.4f} (linear root)")  # fmt: skip
    others = benchmark.load_clips([root / p for p in OTHER_WALKS], fps=None)
    mean, std = benchmark.position_stats(others)
    lost = np.setdiff1d(np.arange(res.truth.num_frames), res.kept - res.kept[0])
    _, tp = res.truth.fk()
    _, fp = res.filled.fk()
    l2p = benchmark.l2p(fp[lost][None], tp[lost][None], mean, std)
    print(f"   L2P of the filled frames (statistics from {len(others)} other Xia walks): {l2p:.3f}")
    return res


def run_squat_part():
    clips, source = demo.behaviours()
    if not source.startswith("real"):
        sys.exit("the run -> squat experiment needs the Mixamo Aj clips in MOTIONLAB_DATA")
    print("2. run -> walk -> stand -> squat with 10 missing frames (Fig. 8)")
    print(f"   {source}")
    for k, m in clips.items():
        print(f"   {k:<6} {m.num_frames:4d} frames: {labels.check(m, k)}")
    res = paper.run_to_squat(clips, missing=10)
    paper_frames = [a - res.first + 1 for a in res.anchors]
    print(f"   path {' -> '.join(res.path)}; key poses inserted at paper frames {paper_frames} (paper: 5 and 8)")
    for (node, frame, is_key), pf in zip(res.keys, paper_frames):
        print(f"     frame {pf}: {node} clip frame {frame} ({'a PPCA key frame' if is_key else 'NOT a key frame'})")
    sp = ", ".join(f"{v:.2f}" for v in res.speeds)
    print(f"   root ground speed per step, frame 1 -> 12 (m/s): {sp}")
    print(f"   run speed before the gap {res.run_speed:.2f} m/s; distance covered across the gap {res.travel:.2f} m; "
          f"slowest step {res.speeds.min():.2f} m/s")  # fmt: skip
    print(f"   lowest foot of the filled frames below the floor by {1000 * res.below:.1f} mm")
    return res


def figure(walk, rs, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from motionlab.core.plot import plot_pose

    fig, ax = plt.subplots(2, 1, figsize=(9, 5.6), gridspec_kw={"height_ratios": [1.1, 1]})
    stop = min(walk.truth.num_frames, 181)
    for i, lab in enumerate(("z", "y", "x")):
        (line,) = ax[0].plot(walk.hip_filled[:stop, i], "-", lw=1.5, label=f"{lab} filled")
        ax[0].plot(walk.hip_true[:stop, i], "--", color=line.get_color(), lw=1.2, label=f"{lab} true")
    kept = walk.kept - walk.kept[0]
    ax[0].plot(kept[kept < stop], walk.hip_true[kept[kept < stop], 0], "ko", ms=3, label="kept frames")
    ax[0].set_title(
        "left hip (lThigh) angles, Xia/CMU walk at 120 Hz, every 30th frame kept (paper Fig. 7)", fontsize=9
    )
    ax[0].set_xlabel("frame (0 = the paper's frame 5)", fontsize=8)
    ax[0].set_ylabel("degrees", fontsize=8)
    ax[0].legend(ncol=7, fontsize=6, loc="upper right")
    m = rs.motion
    pos = m.global_positions()
    frames = range(rs.first, rs.first + 12)
    base = pos[rs.first, 0]
    colors = {0: "C3", 11: "C2"}
    for k, t in enumerate(frames):
        p = pos[t] - base * np.array([1.0, 0.0, 1.0])
        p = p.copy()
        p[:, 2] = p[:, 2] - p[0, 2] + 0.6 * k  # spread the frames along the page
        c = colors.get(k, "C0" if t in rs.anchors else "0.55")
        plot_pose(p, m.skeleton.parents, ax=ax[1], view="side", color=c, joints=False)
        ax[1].text(0.6 * k, -0.12, str(k + 1), ha="center", fontsize=7)
    ax[1].set_title("run (1) -> walk (5) -> stand (8) -> squat (12): red/green known, blue key poses, grey interpolated "
                    "(paper Fig. 8)", fontsize=9)  # fmt: skip
    ax[1].set_xticks([])
    ax[1].set_xlabel("")
    ax[1].set_ylabel("")
    ax[1].set_yticks([])
    ax[1].set_ylim(-0.2, None)
    fig.tight_layout()
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=80)
    os.replace(tmp, path)
    print(f"wrote {path} ({path.stat().st_size // 1024} KiB)")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--figure", default="docs/media/keypose_paper.png", help="where to write the figure")
    ap.add_argument("--no-figure", action="store_true")
    args = ap.parse_args(argv)
    if not os.environ.get("MOTIONLAB_DATA"):
        sys.exit("set MOTIONLAB_DATA to the shared data folder (e.g. export MOTIONLAB_DATA=/path/to/shared/data)")
    root = Path(os.environ["MOTIONLAB_DATA"])
    walk = walk_part(root)
    rs = run_squat_part()
    if not args.no_figure:
        figure(walk, rs, Path(args.figure))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
