"""Gap filling on every rig family of the shared data, through what ``motionlab fill-gaps`` does.

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.interpolation.bench_gap_rigs [--quick]

For each rig family (Bandai Namco ``dataset-1`` and ``dataset-2``, Mixamo, CMU, Xia) a few
locomotion takes (``TAKES``) get gaps of ``SECONDS`` (0.1, 0.2 and 0.4 s: 3-12 frames at 30 fps,
12-48 at 120 fps) cut at two places (``PLACES``: 35% and 60% into the take). Each cut is written
as a BVH file and filled by the command itself (``motionlab.cli.main(["fill-gaps", ...])``, the
default method), twice:

* with ``--times`` (the kept frames' times): the gaps and their counts are exact, so the filled
  frames can be compared one for one with the removed ones;
* without: the count is the command's own (frames in the output less frames in the input).

Printed per rig family:

* **joint 0**: whether the recording holds it still (Bandai Namco's ``joint_Root``) or it carries
  the body;
* **root error**: joint 0's world position in the filled frames against the removed frames, mean
  and worst (cm as loaded; Bandai Namco and Mixamo files load in metres, CMU and Xia at their
  files' scale, whose bodies are about 0.23 units high), and the worst also in % of the body
  height (:func:`motionlab.interpolation.detect.body_height`: the vertical extent of the
  reference joint's subtree, the body, median over the take). Where the recording holds joint 0
  still, the rule says it stays still: the error must be 0;
* **reference joint**: the same for the joint that carries the body (joint 0 where it moves, the
  hips of the Bandai Namco rigs), mean;
* **jump**: how much joint 0's step from the last filled frame into the next recorded frame
  differs from the recorded step, worst, cm and % of height;
* **max joint**: the largest world distance of any joint of any filled frame from the truth, cm
  and % of height;
* **count** without ``--times``: cuts whose frames inserted are the true count exactly, and within
  10% or one frame (``check_gaps``' tolerance), and the mean absolute difference.

The takes: no rule of the fill or the count was chosen on them. The fill's and count's rules were
chosen on ``check_gaps``' CHOOSE set (``sessions/walk`` ``normal`` takes, ``walk-turn-left``,
``dataset-2`` run 001); the ``dataset-2`` takes here are other styles and take numbers. The
joint-0 rule (:func:`motionlab.interpolation.alignment.carry_by_reference`) has no parameter.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from motionlab import data
from motionlab.cli import main as cli
from motionlab.core import bvh
from motionlab.interpolation import detect
from motionlab.interpolation.alignment import reference_joint

TAKES = {
    "Bandai Namco dataset-1": ["bandai_namco/dataset-1/walk/dataset-1_walk_normal_001.bvh",
                               "bandai_namco/dataset-1/walk/dataset-1_walk_proud_001.bvh",
                               "bandai_namco/dataset-1/run/dataset-1_run_feminine_001.bvh"],
    "Bandai Namco dataset-2": ["bandai_namco/sessions/walk/dataset-2_walk_active_001.bvh",
                               "bandai_namco/sessions/walk/dataset-2_walk_elderly_002.bvh",
                               "bandai_namco/dataset-2/run/dataset-2_run_normal_002.bvh"],
    "Mixamo": ["mixamo/Aj/Catwalk_Walk.bvh", "mixamo/Kaya/Injured_Walk_Left_Turn.bvh",
               "mixamo_ganimator/Joe/Walk-In-Circle.bvh"],
    "CMU": ["cmu/131/131_01.bvh", "cmu/131/131_02.bvh", "cmu/131/131_03.bvh"],
    "Xia": ["xia/walk/neutral_01_000.bvh", "xia/walk/sexy_01_000.bvh", "xia/run/depressed_13_000.bvh"],
}  # fmt: skip
"""Rig family -> takes (paths under the data folder)."""

SECONDS = (0.1, 0.2, 0.4)
"""Gap lengths, seconds (frames: rounded at the take's frame rate)."""

PLACES = (0.35, 0.6)
"""Where a gap starts, as a fraction of the take."""


@dataclass
class Cut:
    """One gap cut and filled (lengths in the take's units, metres as loaded)."""

    take: str
    start: int
    n: int
    height: float
    root_still: bool
    root_err: np.ndarray  # (n,) joint 0 in the filled frames
    ref_err: np.ndarray  # (n,) the reference joint
    jump: float  # |filled step into frame start+n| - |recorded step|, absolute
    joint_max: float  # worst joint of any filled frame
    counted: int  # frames inserted without --times


def _fill_gaps(gap: Path, out: Path, *extra: str) -> None:
    """``motionlab fill-gaps gap -o out`` with ``extra`` options, its output (and its warning that
    a count is estimated) swallowed."""
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = cli(["fill-gaps", str(gap), "-o", str(out), "--force", "-q", *extra])
    if code != 0:
        raise RuntimeError(f"fill-gaps {gap} {' '.join(extra)} exited {code}")


def run_cut(motion, take: str, start: int, n: int, folder: Path) -> Cut:
    """Cut frames ``start … start+n-1`` of ``motion``, fill them with and without ``--times``."""
    keep = np.r_[0:start, start + n : motion.num_frames]
    gap, times, out = folder / "gap.bvh", folder / "times.txt", folder / "out.bvh"
    bvh.save(gap, motion[keep], overwrite=True)
    np.savetxt(times, keep / motion.fps, fmt="%.9f")
    _fill_gaps(gap, out, "--times", str(times))
    filled = bvh.load(out)
    if filled.num_frames != motion.num_frames:
        raise RuntimeError(f"{take}: --times gave {filled.num_frames} frames, expected {motion.num_frames}")
    truth, pos = motion.global_positions(), filled.global_positions()
    inside = slice(start, start + n)
    ref = reference_joint(motion)
    err = np.linalg.norm(pos[inside] - truth[inside], axis=-1)  # (n, J)
    after = start + n
    jump = abs(
        np.linalg.norm(pos[after, 0] - pos[after - 1, 0]) - np.linalg.norm(truth[after, 0] - truth[after - 1, 0])
    )
    _fill_gaps(gap, out)
    counted = bvh.load(out).num_frames - len(keep)
    still = bool(np.ptp(motion.root_pos, axis=0).max() <= 1e-6)
    return Cut(
        take,
        start,
        n,
        detect.body_height(motion),
        still,
        err[:, 0],
        err[:, ref],
        float(jump),
        float(err.max()),
        counted,
    )


def family_cuts(root: Path, takes: list[str], seconds, places) -> list[Cut]:
    """Every cut of ``takes`` (paths under ``root``)."""
    cuts = []
    with tempfile.TemporaryDirectory() as tmp:
        for take in takes:
            motion = bvh.load(root / take)
            for s in seconds:
                n = max(1, int(round(s * motion.fps)))
                for q in places:
                    start = int(round(q * motion.num_frames))
                    cuts.append(run_cut(motion, Path(take).stem, start, n, Path(tmp)))
    return cuts


def row(name: str, cuts: list[Cut]) -> str:
    """One table row (see the module docstring for the columns)."""
    root = np.concatenate([c.root_err for c in cuts])
    root_rel = max(float(c.root_err.max()) / c.height for c in cuts)
    ref = np.concatenate([c.ref_err for c in cuts])
    jump, jump_rel = max(c.jump for c in cuts), max(c.jump / c.height for c in cuts)
    joint, joint_rel = max(c.joint_max for c in cuts), max(c.joint_max / c.height for c in cuts)
    exact = sum(c.counted == c.n for c in cuts)
    near = sum(abs(c.counted - c.n) <= max(1.0, 0.1 * c.n) for c in cuts)
    off = float(np.mean([abs(c.counted - c.n) for c in cuts]))
    still = {c.root_still for c in cuts}
    joint0 = "still" if still == {True} else "moves" if still == {False} else "mixed"
    return (
        f"| {name} | {len({c.take for c in cuts})} takes, {len(cuts)} cuts ({min(c.n for c in cuts)}-"
        f"{max(c.n for c in cuts)} frames) | {joint0} | {100 * root.mean():.2f}, {100 * root.max():.2f} "
        f"({100 * root_rel:.2f}%) | {100 * ref.mean():.2f} | {100 * jump:.2f} ({100 * jump_rel:.2f}%) | "
        f"{100 * joint:.1f} ({100 * joint_rel:.1f}%) | {exact}, {near} of {len(cuts)}; {off:.2f} |"
    )


HEADER = (
    "| rig family | cuts | joint 0 recorded | root error, cm: mean, worst (% of height) | reference joint, "
    "cm: mean | jump into the next frame, cm: worst (%) | max joint error, cm (%) | count without "
    "--times: exact, within 10% or 1 frame; mean off |\n|---|---|---|---|---|---|---|---|"
)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="one take per family, gaps of 0.1 and 0.2 s at one place")
    args = ap.parse_args(argv)
    if not data.has_data():
        print(f"needs real mocap: {data.HOW_TO}")
        return 1
    root = data.data_root()
    seconds, places = (SECONDS[:2], PLACES[:1]) if args.quick else (SECONDS, PLACES)
    print(HEADER)
    t0 = time.perf_counter()
    for name, takes in TAKES.items():
        cuts = family_cuts(root, takes[:1] if args.quick else takes, seconds, places)
        print(row(name, cuts), flush=True)
    print(f"\n({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
