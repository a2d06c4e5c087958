"""A foot that a fill swings into the floor: the body lifted out, or the leg bent (README,
*Key-pose interpolation and gap filling*).

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.interpolation.compare_feet [--every 90] [--quick]

Two ways to keep filled frames out of the floor, each on the *same* counts (the detection runs once
per cut) and the same fill otherwise:

* **body lifted** (``gaps.fill(..., feet="lift")``): every filled frame raised by how far its
  lowest joint went below the floor (:func:`motionlab.interpolation.gaps.lift_above_floor`);
* **leg bent** (what ``gaps.fill`` does by default, ``feet="plant"``): each sunk foot moved up
  onto the floor by bending its leg (:func:`motionlab.interpolation.footing.plant_feet`), the
  body lifted only by what the legs cannot reach.

Cuts of 10, 20 and 30 frames: the CHOOSE and VALIDATE cases of ``experiments/interpolation/check_gaps.py`` part 2
(same seed) with every walk take of ``bandai_namco/sessions/walk`` cut every ``EVERY`` frames
(as ``experiments/interpolation/compare_stride_root.py`` makes them), and the cuts of parts 5, 6 and 7 (same seeds).
Prints, per set and rule, the mean and worst root error over the gap relative to the true
displacement, the cuts above 10%, the lowest filled foot below the clip's floor and the mean joint
error about the root; and every cut whose gap the detection did not find, with its D/Δ.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from experiments.interpolation import check_gaps, gap_eval
from experiments.interpolation.compare_stride_root import cases, each_set
from motionlab.interpolation import detect

RULES = {"body lifted": "lift", "leg bent": "plant"}  # printed name: ``feet`` of ``gaps.fill``


def score(motion, s: int, n: int) -> list[gap_eval.CutResult] | None:
    """Each rule's result on one cut (``RULES`` order), or ``None`` when the gap is not found."""
    found = detect.detect(gap_eval.cut(motion, s, n))
    if (s - 1) not in dict(found):
        return None
    return [gap_eval.evaluate_cut(motion, s, n, found=found, feet=feet) for feet in RULES.values()]


def all_cuts(root: Path, every: int, quick: bool) -> dict[str, list]:
    """(file or loaded motion, first removed frame, frames removed) per set: files for CHOOSE and
    VALIDATE (loaded one at a time), motions for parts 5-7 (as ``check_gaps.source_cuts`` gives them)."""
    out = dict(cases(root, every, quick))
    parts = (("part 5", 5, check_gaps.OTHER_SOURCES), ("part 6", 7, check_gaps.FRESH_SOURCES),
             ("part 7", 11, check_gaps.UNSCORED_SOURCES))  # fmt: skip
    for name, seed, sources in parts:  # check_gaps.py main(): one generator per part
        rng = np.random.default_rng(seed)
        out[name] = [cut for patterns in sources.values()
                     for cut in check_gaps.source_cuts(root, rng, 1 if quick else 4, patterns)]  # fmt: skip
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--every", type=int, default=90, help="a cut every EVERY frames of every walk take (default 90)")
    ap.add_argument("--quick", action="store_true", help="a sixth of the Bandai Namco clips, one cut per held-out clip")
    args = ap.parse_args(argv)
    root = check_gaps.data_root()
    t0 = time.perf_counter()
    for _, rows in each_set(all_cuts(root, args.every, args.quick), score):  # files or loaded motions
        for k, rule in enumerate(RULES):
            rel = np.array([r[k].root_rel for r in rows])
            below = 1000 * max(r[k].below for r in rows)
            pose = np.mean([r[k].pose_cm for r in rows])
            print(f"   {rule:12s} mean {rel.mean():6.2%}, worst {rel.max():6.2%}, above 10%: {int((rel > 0.1).sum()):3d}; "
                  f"lowest foot below the floor {below:.1f} mm; joints about the root {pose:.2f} cm off")  # fmt: skip
    print(f"total time {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
