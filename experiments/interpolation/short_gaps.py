"""The default fill (``stride``) against SLERP on gaps of 1 to 30 frames, with exact counts.

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.interpolation.short_gaps

For each clip of ``CLIPS`` (locomotion of every rig family; none of them in ``check_gaps``'
CHOOSE set, on which the fill's rules were chosen), ``PLACES`` cuts of each size in ``SIZES``
frames at seeded places between 20% and 80% of the clip. Each cut is filled with its true count
(:func:`motionlab.interpolation.gaps.insert_missing`), so only the fill differs, by

* ``stride``: ``gaps.fill(method="stride", root="stride")``, what ``motionlab fill-gaps`` does;
* ``slerp``: ``gaps.fill(method="slerp", root="hermite")``, SLERP of the joint rotations with the
  Hermite root, the simple baseline.

Printed per family and size: the mean world distance of every joint of the filled frames from the
removed frames, in % of the body height (:func:`motionlab.interpolation.detect.body_height`), for
both fills, and the cuts each fill wins (nearer by any amount; where ``stride`` finds no stride it
is SLERP, and neither wins).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from motionlab import data
from motionlab.core import motion_files
from motionlab.interpolation import detect, gaps

CLIPS = {
    "bandai dataset-1 walk": [f"bandai_namco/dataset-1/walk/dataset-1_walk_{s}_001.bvh" for s in ("proud", "tired", "old")],
    "bandai dataset-1 run": [f"bandai_namco/dataset-1/run/dataset-1_run_{s}_001.bvh" for s in ("normal", "happy")],
    "xia walk": ["xia/walk/neutral_01_000.bvh", "xia/walk/sexy_01_000.bvh"],
    "cmu start-walk-stop": ["cmu/131/131_02.bvh"],
    "mixamo walk": ["mixamo_ganimator/Joe/Walk-In-Circle.bvh", "mixamo/Aj/Catwalk_Walk.bvh"],
}  # fmt: skip
HELD_OUT = {
    "bandai dataset-1 walk": [f"bandai_namco/dataset-1/walk/dataset-1_walk_{s}_001.bvh" for s in ("angry", "happy", "sad")],
    "bandai dataset-1 run": [f"bandai_namco/dataset-1/run/dataset-1_run_{s}_001.bvh" for s in ("angry", "active")],
    "mixamo walk": ["mixamo/Aj/Catwalk_Walk_Forward_Arc_90L.bvh", "mixamo/Kaya/Injured_Walk_Left_Turn.bvh"],
}  # fmt: skip
"""Clips the rehearsal's rule (the summed error, not the count's sign test) was not chosen on: ``--held-out``."""
SIZES = (1, 2, 3, 5, 10, 20, 30)
PLACES = 6
FILLS = {"stride": {"method": "stride", "root": "stride"}, "slerp": {"method": "slerp", "root": "hermite"}}


def cut_error(motion, start: int, n: int, height: float, fill: dict) -> float:
    """Mean joint distance (fraction of ``height``) of ``n`` frames cut at ``start`` and filled by ``fill``."""
    stream = motion[np.r_[0:start, start + n : motion.num_frames]]
    holed, _ = gaps.insert_missing(stream, [(start - 1, n)])
    filled, _ = gaps.fill(holed, **fill)
    got = filled[start : start + n].global_positions()
    want = motion[start : start + n].global_positions()
    return float(np.linalg.norm(got - want, axis=-1).mean()) / height


def family_rows(name: str, paths: list, rng: np.random.Generator) -> None:
    """Print one line per size: both fills' mean error and the cuts each wins."""
    clips = [motion_files.load_metres(data.data_root() / p) for p in paths]
    for n in SIZES:
        errors = {k: [] for k in FILLS}
        for m in clips:
            height = detect.body_height(m)
            lo, hi = int(0.2 * m.num_frames), int(0.8 * m.num_frames) - n
            if hi <= lo:  # a clip too short for this size
                continue
            for start in rng.integers(lo, hi, PLACES):
                for k, fill in FILLS.items():
                    errors[k].append(cut_error(m, int(start), n, height, fill))
        e = {k: np.array(v) for k, v in errors.items()}
        wins = int(np.sum(e["stride"] < e["slerp"])), int(np.sum(e["slerp"] < e["stride"]))
        print(
            f"{name:<22} {n:>4} {len(e['stride']):>5} {100 * e['stride'].mean():>9.2f} {100 * e['slerp'].mean():>9.2f}"
            f" {wins[0]:>6} {wins[1]:>6}"
        )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--held-out", action="store_true", help="the clips of HELD_OUT instead of CLIPS")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rng = np.random.default_rng(args.seed)
    print(f"{'family':<22} {'size':>4} {'cuts':>5} {'stride %h':>9} {'slerp %h':>9} {'stride':>6} {'slerp':>6}")
    print(f"{'':<22} {'':>4} {'':>5} {'':>9} {'':>9} {'wins':>6} {'wins':>6}")
    for name, paths in (HELD_OUT if args.held_out else CLIPS).items():
        family_rows(name, paths, rng)
    print(f"{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
