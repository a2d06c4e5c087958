"""The root across a stride fill where the body changes speed: the rules compared (README,
*Key-pose interpolation and gap filling*).

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.interpolation.compare_stride_root [--every 30] [--quick]

The stride fill (:mod:`motionlab.interpolation.stride`) carries each side's stride across the gap at
that side's speed. Where the walker speeds up or slows down across the gap, that speed is wrong
near one end. The rules, each filling the *same* counts (the detection runs once per cut):

* **the strides' own speed**: the strides' path as it comes;
* **end velocities swapped where the speed changes** (what ``gaps.fill`` does,
  ``gaps._follow_strides``): where :func:`motionlab.interpolation.detect.changes_speed` holds for
  the mean ground speeds over a second on each side, the path keeps the strides' bob and sway but
  leaves and reaches the gap at the velocities measured outside it (``gaps.smooth_root``);
* **swapped everywhere**;
* **SLERP and the Hermite root where the speed changes** (no strides there).

Cuts of 10, 20 and 30 frames: the CHOOSE and VALIDATE cases of ``experiments/interpolation/check_gaps.py`` (same
seed), and every walk take of ``bandai_namco/sessions/walk`` cut every ``EVERY`` frames from frame
20 (normal takes with CHOOSE, the six other styles with VALIDATE). Prints, per set and rule, the
mean and worst root error over the gap relative to the true displacement, and the cuts above 10%.
"""

from __future__ import annotations

import argparse
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from experiments.interpolation import check_gaps, gap_eval
from motionlab.core import bvh
from motionlab.interpolation import alignment, detect, gaps, stride

RULES = ("strides' own speed", "swapped where the speed changes", "swapped everywhere",
         "SLERP + Hermite root where the speed changes")  # fmt: skip


def cases(root: Path, every: int, quick: bool) -> dict[str, list[tuple[Path, int, int]]]:
    """(file, first removed frame, frames removed) per set, as ``check_gaps.py`` cuts them."""
    rng = np.random.default_rng(0)  # check_gaps.py part 2 draws its places in this order
    out: dict[str, list] = {}
    for name, files in check_gaps.sets(root, quick).items():
        out[name] = []
        for f in files:
            num = bvh.load(f).num_frames
            for n in check_gaps.REMOVED:
                if num - n - 20 > 20:
                    out[name].append((f, int(rng.integers(20, num - n - 20)), n))
    walks = sorted((root / "bandai_namco/sessions/walk").glob("*.bvh"))
    for name, normal in (("CHOOSE", True), ("VALIDATE", False)):
        takes = [f for f in walks if ("_normal_" in f.name) == normal][:: 6 if quick else 1]
        for f in takes:
            num = bvh.load(f).num_frames
            out[name] += [(f, s, n) for n in check_gaps.REMOVED for s in range(20, num - n - 20, every)]
    return out


@contextmanager
def speed_rule(rule):
    """``detect.changes_speed`` replaced by ``rule`` (the counts are already made)."""
    keep = detect.changes_speed
    detect.changes_speed = rule
    try:
        yield
    finally:
        detect.changes_speed = keep


def score(motion, s: int, n: int) -> list[float] | None:
    """The root error of each rule in ``RULES`` on one cut, or ``None`` when the gap is not found."""
    stream = gap_eval.cut(motion, s, n)
    found = detect.detect(stream)
    if (s - 1) not in dict(found):
        return None
    own = detect.changes_speed
    with speed_rule(lambda *v: False):
        plain = gap_eval.evaluate_cut(motion, s, n, found=found).root_rel
    chosen = gap_eval.evaluate_cut(motion, s, n, found=found).root_rel
    with speed_rule(lambda *v: True):
        everywhere = gap_eval.evaluate_cut(motion, s, n, found=found).root_rel
    shift = sum(c for t, c in found if t < s - 1)
    a = s - 1 + shift
    holed, _ = gaps.insert_missing(stream, found)
    ref = alignment.reference_joint(stream)  # the known frames of `holed`
    changes = own(*stride.side_speeds(holed, a, a + dict(found)[s - 1] + 1, ref))
    hermite = (
        gap_eval.evaluate_cut(motion, s, n, method="slerp", root="hermite", found=found).root_rel if changes else chosen
    )
    return [plain, chosen, everywhere, hermite]


def scored(cuts: list, score, desc: str, missed: list | None = None) -> list:
    """``score(motion, s, n)`` of every cut ``(file or loaded motion, s, n)`` whose gap was found
    (not ``None``), files loaded one at a time (cuts of one file come together); the cuts whose gap
    was not found are appended to ``missed`` as ``(motion, s, n)`` if it is given."""
    rows, loaded = [], {}
    for clip, s, n in tqdm(cuts, desc=desc, mininterval=5):
        if isinstance(clip, Path):
            if clip not in loaded:
                loaded = {clip: bvh.load(clip)}
            clip = loaded[clip]
        row = score(clip, s, n)
        if row is not None:
            rows.append(row)
        elif missed is not None:
            missed.append((clip, s, n))
    return rows


def print_missed(missed: list) -> None:
    """One line per cut ``(motion, s, n)`` whose gap the detection did not find, with the D/Δ of the
    step that hides it (:func:`motionlab.interpolation.detect.consecutive_ratio`)."""
    for motion, s, n in missed:
        ratio = detect.consecutive_ratio(gap_eval.cut(motion, s, n))[0][s - 1] / detect.DELTA
        print(f"   not found: {motion.name}@{s}, {n} frames cut (D/Δ {ratio:.2f})")


def each_set(cuts_by_set: dict, score):
    """Per set of cuts: ``(name, rows)``, the :func:`scored` rows of its found cuts, after printing
    how many were found and every one missed (:func:`print_missed`)."""
    for name, cuts in cuts_by_set.items():
        missed = []
        rows = scored(cuts, score, name, missed)
        print(f"{name}: {len(rows)} cuts found of {len(cuts)}; root error over the gap / true displacement")
        print_missed(missed)
        yield name, rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--every", type=int, default=30, help="a cut every EVERY frames of every walk take (default 30)")
    ap.add_argument("--quick", action="store_true", help="a sixth of the clips")
    args = ap.parse_args(argv)
    root = check_gaps.data_root()
    t0 = time.perf_counter()
    for _, rows in each_set(cases(root, args.every, args.quick), score):
        e = np.array(rows)
        for k, rule in enumerate(RULES):
            print(f"   {rule:46s} mean {e[:, k].mean():6.2%}, worst {e[:, k].max():6.2%}, "
                  f"above 10%: {int((e[:, k] > 0.1).sum())}")  # fmt: skip
    print(f"total time {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
