"""The missing count alone, on the cuts of ``check_gaps`` (parts 2, 5, 6 and 7), at any commit.

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.interpolation.compare_counts [--quick] [--cuts 4]
    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.interpolation.compare_counts --families 150

The counts of ``motionlab fill-gaps`` without ``--times`` (:func:`motionlab.interpolation.detect.detect`,
the stream alone), nothing filled: a cheap check of a change to the count rules. The cuts are
``check_gaps``' (same files, seeds and order: part 2's CHOOSE and VALIDATE with seed 0, parts 5, 6
and 7 with seeds 5, 7 and 11, ``--cuts`` places per clip and count of 10, 20 and 30 frames), so
run at two commits it compares their counts on the same cuts. Prints per set: cuts, gaps found,
counts exact, counts within 10% or one frame, and the mean absolute difference from the truth.

``--families N``: instead, ``N`` seeded cuts of 1 to 30 frames per rig family (``FAMILIES``: held-out
takes, none in ``check_gaps``' CHOOSE set, on which the count rules were chosen), each at a random
place of a random take of the family (at least 20 frames left on each side). Per family, of the
gaps found: how often the count (:func:`motionlab.interpolation.detect.count_choice`), the stride
count and the local count (the stride count where it has none) are exact, and how often the range
that ``fill-gaps`` states without ``--times`` (:func:`motionlab.interpolation.detect.estimate_counts`,
for one gap without ``--takes`` that of ``count_choice``) holds the true count, and how wide it is; *wrong and unflagged* is a count that is not exact and
whose range does not hold the truth either. *Range open above* is a range that reaches the longest
size that fits beside its gap (``CountChoice.untried`` set: the warning names the sizes it could
not try), and *truth outside but not tried* a truth outside the range among those sizes.

``--in-place N``: the same for actions done in place (``IN_PLACE``: raising and waving hands,
bowing, kicking, punching, idles), and under each family's line how many of its gaps found are
where the body does not travel, and how often there the in-place count (``CountChoice.stride``)
and the step ratio it replaced (``CountChoice.ratio``) are within 10% or one frame.

``--held-out N``: the same for takes in neither of those sets (``HELD_OUT``: backward, sideways and
normal walks, left turns, Mixamo actions, runs and jumps), on which no count rule was chosen.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from experiments.interpolation import check_gaps, gap_eval
from motionlab.core import bvh
from motionlab.interpolation import detect


def _score(cuts) -> str:
    """One line of counts for ``cuts``: ``(motion, first removed frame, frames removed)``."""
    found = exact = near = 0
    off = []
    for m, s, n in cuts:
        est = dict(detect.detect(gap_eval.cut(m, s, n))).get(s - 1)
        if est is None:
            continue
        found += 1
        exact += est == n
        near += check_gaps.within(est, n)
        off.append(abs(est - n))
    mean = float(np.mean(off)) if off else float("nan")
    return f"{len(cuts)} cuts, {found} found; exact {exact}, within 10% or 1 frame {near} ({near / max(found, 1):.1%}); mean off {mean:.2f}"


def part2(root, quick: bool) -> dict[str, list]:
    """Part 2's cuts per set, as ``check_gaps.removed_frames`` draws them (one generator, seed 0)."""
    rng = np.random.default_rng(0)
    out = {}
    for name, files in check_gaps.sets(root, quick).items():
        cuts = []
        for f in files:
            m = bvh.load(f)
            for n in check_gaps.REMOVED:
                lo, hi = 20, m.num_frames - n - 20
                if hi > lo:
                    cuts.append((m, int(rng.integers(lo, hi)), n))
        out[name] = cuts
    return out


FAMILIES = {
    "Bandai Namco dataset-1 (walks, dashes, runs; 30 fps)": [
        "bandai_namco/dataset-1/walk/*.bvh",
        "bandai_namco/dataset-1/dash/*.bvh",
        "bandai_namco/dataset-1/run/*.bvh",
    ],
    "Bandai Namco dataset-2 (6 walk styles, runs, right turns; 30 fps)": [
        "bandai_namco/sessions/walk/dataset-2_walk_[!n]*_00[12].bvh",
        "bandai_namco/dataset-2/run/dataset-2_run_normal_00[23].bvh",
        "bandai_namco/dataset-2/walk-turn-right/*.bvh",
    ],
    "Xia (walks, runs; 120 fps)": ["xia/walk/*.bvh", "xia/run/*.bvh"],
    "CMU (start, walk, stop; 120 fps)": ["cmu/131/*.bvh"],
    "Mixamo (walks, an injured turning walk, quick steps; 60 fps)": [
        "mixamo/Aj/Catwalk_Walk.bvh",
        "mixamo_ganimator/*/Walk-In-Circle.bvh",
        "mixamo/*/Injured_Walk_Left_Turn.bvh",
        "mixamo/Aj/Quick_Steps.bvh",
    ],
}
"""Rig family -> held-out takes (globs under the data folder) for ``--families``."""


IN_PLACE = {
    "Bandai Namco dataset-2 in place (raise-up-both-hands, wave-both-hands; 30 fps)": [
        "bandai_namco/sessions/raise-up-both-hands/*.bvh",
        "bandai_namco/sessions/wave-both-hands/*.bvh",
    ],
    "Bandai Namco dataset-1 in place (bow, kick, punch; 30 fps)": [
        "bandai_namco/dataset-1/bow/*.bvh",
        "bandai_namco/dataset-1/kick/*.bvh",
        "bandai_namco/dataset-1/punch/*.bvh",
    ],
    "Xia in place (punch, jump; 120 fps)": ["xia/punch/*.bvh", "xia/jump/*.bvh"],
    "Mixamo Aj in place (idles, standing actions; 60 fps)": [
        "mixamo/Aj/*Idle*.bvh",
        "mixamo/Aj/*Standing*.bvh",
        "mixamo/Aj/Fist_Pump.bvh",
        "mixamo/Aj/Sitting*.bvh",
    ],
    "Mixamo other characters in place (punches, dances, standing; 60 fps)": [
        "mixamo/[!A]*/Body_Jab_Cross.bvh",
        "mixamo/[!A]*/Jazz_Dancing.bvh",
        "mixamo/[!A]*/Standing_*.bvh",
        "mixamo_ganimator/*/Gangnam-Style.bvh",
    ],
}
"""Actions done in place -> takes (globs under the data folder) for ``--in-place``."""


HELD_OUT = {
    "Bandai Namco dataset-1 backward and sideways walks (30 fps)": [
        "bandai_namco/dataset-1/walk-back/*.bvh",
        "bandai_namco/dataset-1/walk-left/*.bvh",
        "bandai_namco/dataset-1/walk-right/*.bvh",
    ],
    "Bandai Namco dataset-2 normal walks and left turns (30 fps)": [
        "bandai_namco/sessions/walk/dataset-2_walk_normal_*.bvh",
        "bandai_namco/dataset-2/walk-turn-left/*.bvh",
    ],
    "Mixamo Aj actions (pitching, hits, golf, punches, gestures; 60 fps)": [
        "mixamo/Aj/Baseball_Pitching.bvh",
        "mixamo/Aj/Hit_Reaction*.bvh",
        "mixamo/Aj/Golf_*.bvh",
        "mixamo/Aj/Combo_Punch.bvh",
        "mixamo/Aj/Taunt_Gesture.bvh",
        "mixamo/Aj/Pointing.bvh",
        "mixamo/Aj/Military_Signaling.bvh",
    ],
    "Mixamo other characters (runs, jumps, a start; 60 fps)": [
        "mixamo/[!A]*/Running.bvh",
        "mixamo/[!A]*/Jumping.bvh",
        "mixamo/[!A]*/Run_Arc_Left.bvh",
        "mixamo/[!A]*/Catwalk_Idle_To_Walk_Forward.bvh",
    ],
}
"""Takes in neither ``FAMILIES`` nor ``IN_PLACE`` -> globs for ``--held-out``: no rule was chosen on them."""


def family_cuts(root, patterns: list[str], cuts: int, rng):
    """``cuts`` seeded ``(motion, first removed frame, frames removed)``: 1 to 30 frames at a
    random place (20 frames kept on each side) of a random take matching ``patterns``."""
    files = sorted({f for p in patterns for f in root.glob(p)})
    loaded = {}
    out = []
    while files and len(out) < cuts:
        f = files[int(rng.integers(len(files)))]
        m = loaded.setdefault(f, bvh.load(f))
        n = int(rng.integers(1, 31))
        if m.num_frames - n - 20 > 20:
            out.append((m, int(rng.integers(20, m.num_frames - n - 20)), n))
    return out


def _family_line(cuts) -> str:
    """Counts and ranges of one family's ``cuts`` (the gaps found), one line."""
    rows = []
    for m, s, n in cuts:
        g = gap_eval.cut(m, s, n)
        if s - 1 not in detect.consecutive_gaps(g):
            continue
        c = detect.count_choice(g, s - 1)  # one gap, no takes: the count and range of estimate_counts
        local = c.stride if c.local is None else c.local
        untried = np.inf if c.untried is None else c.untried
        rows.append((n, max(1, round(c.count)), max(1, round(c.stride)), max(1, round(local)), c.low, c.high, untried))
    x = np.array(rows, dtype=np.float64).reshape(-1, 7)
    n, count, stride, local, low, high, untried = x.T
    inside = (low <= n) & (n <= high)
    told = ~inside & (n >= untried)  # outside the range, and a size the warning says was not tried
    share = lambda a: f"{np.mean(a):.1%}" if len(a) else "-"  # noqa: E731
    return (
        f"{len(cuts)} cuts, {len(x)} found; exact: count {share(count == n)}, stride count {share(stride == n)}, "
        f"local count {share(local == n)}; within 10% or 1 frame {share(np.abs(count - n) <= np.maximum(1, 0.1 * n))}; "
        f"range holds the truth {share(inside)}, mean width {np.mean(high - low + 1) if len(x) else 0:.1f} frames; "
        f"wrong and unflagged {share((count != n) & ~inside)}; "
        f"range open above (sizes not tried) {share(np.isfinite(untried))}, "
        f"truth outside but not tried {share(told)}"
    )


def _in_place_line(cuts) -> str:
    """Of ``cuts``' gaps found where the body does not travel: the in-place count against the step ratio."""
    rows = []
    for m, s, n in cuts:
        g = gap_eval.cut(m, s, n)
        if s - 1 in detect.consecutive_gaps(g) and (c := detect.count_choice(g, s - 1)).ratio is not None:
            rows.append((n, max(1, round(c.stride)), max(1, round(c.ratio))))
    n, fitted, ratio = np.array(rows, dtype=np.float64).reshape(-1, 3).T
    near = lambda a: f"{np.mean(np.abs(a - n) <= np.maximum(1, 0.1 * n)):.1%}" if len(a) else "-"  # noqa: E731
    return f"{len(n)} in place; within 10% or 1 frame: in-place count {near(fitted)}, step ratio {near(ratio)}"


def families(root, cuts: int, table: dict | None = None, seed: int = 39) -> None:
    """``--families``: one line per rig family of ``table`` (default ``FAMILIES``; one generator)."""
    rng = np.random.default_rng(seed)
    for label, patterns in (table or FAMILIES).items():
        chosen = family_cuts(root, patterns, cuts, rng)
        print(f"{label}: {_family_line(chosen)}", flush=True)
        if table is IN_PLACE:
            print(f"    {_in_place_line(chosen)}", flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="a sixth of part 2's clips, one place per clip in parts 5-7")
    ap.add_argument("--cuts", type=int, default=4, help="places per clip and count in parts 5-7 (check_gaps: 4)")
    ap.add_argument("--parts", default="2,5,6,7", help="which parts, comma-separated (default: all four)")
    ap.add_argument("--families", type=int, default=0, metavar="N",
                    help="instead: N cuts of 1-30 frames per rig family, counts and their ranges")  # fmt: skip
    ap.add_argument("--in-place", type=int, default=0, metavar="N",
                    help="instead: N cuts of 1-30 frames per action done in place (IN_PLACE)")  # fmt: skip
    ap.add_argument("--held-out", type=int, default=0, metavar="N",
                    help="instead: N cuts of 1-30 frames per set of takes no rule was chosen on (HELD_OUT)")  # fmt: skip
    args = ap.parse_args(argv)
    wanted = set(args.parts.split(","))
    root = check_gaps.data_root()
    t0 = time.perf_counter()
    if args.families or args.in_place or args.held_out:
        if args.families:
            families(root, args.families)
        if args.in_place:
            families(root, args.in_place, IN_PLACE, seed=41)
        if args.held_out:
            families(root, args.held_out, HELD_OUT, seed=43)
        wanted = set()
    for name, cuts in part2(root, args.quick).items() if "2" in wanted else ():
        print(f"part 2 {name}: {_score(cuts)}", flush=True)
    cuts = 1 if args.quick else args.cuts
    parts = (
        ("5", 5, check_gaps.OTHER_SOURCES),
        ("6", 7, check_gaps.FRESH_SOURCES),
        ("7", 11, check_gaps.UNSCORED_SOURCES),
    )
    for part, seed, sources in (p for p in parts if p[0] in wanted):
        rng = np.random.default_rng(seed)
        for label, patterns in sources.items():
            print(f"part {part} {label}: {_score(list(check_gaps.source_cuts(root, rng, cuts, patterns)))}", flush=True)
    print(f"({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
