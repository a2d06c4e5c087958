"""Gap detection, missing counts and the root across gaps, measured on the shared real mocap.

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.interpolation.check_gaps [--quick] [--parts 1,2,3]

1. **False gaps**: every clean BVH under ``$MOTIONLAB_DATA`` through the detector that
   ``motionlab fill-gaps`` uses without a graph (:func:`motionlab.interpolation.detect.consecutive_gaps`);
   prints how many files get a gap flagged (should be 0) and the largest ``D/Δ``.
2. **Removed frames**: real walks and runs with 10, 20 or 30 frames cut out at a random place
   (seeded; at least 20 frames left on each side). For each case: was the gap found, and only it
   (precision, recall), the estimated missing count against the truth (within 10% or one frame?),
   and after filling (the body continued from the strides on both sides, what ``fill-gaps`` does) the mean root
   position error over the gap relative to the true root displacement across it, and the lowest
   foot against the clip's own floor; the root error also with ``--method slerp --root hermite`` (SLERP and a Hermite root) for
   comparison.
   The missing count also **with the other recordings of the action** (``motionlab fill-gaps
   --takes``, :mod:`motionlab.interpolation.recorded`): every other take of the same action
   (``sessions/walk``; the two ``walk-turn`` takes, each the other's mirror image; the 18 runs of
   ``dataset-1/run`` and ``dataset-2/run``), never the take being scored (leave one take out).
3. **Stream against the graph** (§3.3): walk takes of one style tracked in an action graph built
   from *other* takes (normal style, takes 1–3), precision and recall.
4. (``--dense EVERY``) every walk take of ``sessions/walk``, a cut every ``EVERY`` frames.
5. **Other sources** (``OTHER_SOURCES``): the walks and runs of Xia (120 fps), Mixamo and
   GANimator's Mixamo clips (60 fps), other studios and rigs than everything above. For Xia's
   walks and runs (and part 7's Bandai Namco ``dataset-1`` clips) the count is also made with the
   source's other clips, other styles of the action, as recordings (``SAME_ACTION``; leave one
   clip out).
6. **Starts, stops and padded clips** (``FRESH_SOURCES``): Mixamo runs and backward clips padded
   with a held pose, idle-to-walk starts, CMU start-walk-stop takes. Where a cut takes frames of a
   held pose, the count is also scored against the frames that are not copies of a kept one
   (:func:`experiments.interpolation.gap_eval.countable`).
7. **Other locomotion** (``UNSCORED_SOURCES``): Bandai Namco ``dataset-1`` walks, dashes and side
   steps, and Mixamo clips of other locomotion.

Parts 2 and 4 report two sets separately:

* CHOOSE: ``bandai_namco/sessions/walk`` takes of style ``normal`` and
  ``bandai_namco/dataset-2/walk-turn-left``, ``dataset-2/run/…_001``;
* VALIDATE: every other style's walk takes in ``sessions/walk`` (every 4th take), the 15
  ``dataset-1/run`` styles, ``dataset-2/run/…_002, 003`` and ``dataset-2/walk-turn-right``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from experiments.interpolation import gap_eval
from motionlab.core import bvh, humanoid
from motionlab.interpolation import detect
from motionlab.interpolation.action_graph import ActionGraph
from motionlab.interpolation.recorded import RecordedTakes

REMOVED = (10, 20, 30)


def sets(root: Path, quick: bool) -> dict[str, list[Path]]:
    walks = sorted((root / "bandai_namco/sessions/walk").glob("*.bvh"))
    choose = [f for f in walks if "_normal_" in f.name]
    choose += sorted((root / "bandai_namco/dataset-2/walk-turn-left").glob("*.bvh"))
    choose += [root / "bandai_namco/dataset-2/run/dataset-2_run_normal_001.bvh"]
    validate = [f for f in walks if "_normal_" not in f.name][::4]
    validate += sorted((root / "bandai_namco/dataset-1/run").glob("*.bvh"))
    validate += [root / f"bandai_namco/dataset-2/run/dataset-2_run_normal_00{i}.bvh" for i in (2, 3)]
    validate += sorted((root / "bandai_namco/dataset-2/walk-turn-right").glob("*.bvh"))
    if quick:
        choose, validate = choose[::6], validate[::6]
    return {"CHOOSE": choose, "VALIDATE": validate}


def action_groups(root: Path) -> dict[str, list[Path]]:
    """The takes of each action (a take's recordings are the others of its group)."""
    b = root / "bandai_namco"
    return {
        "walk": sorted((b / "sessions/walk").glob("*.bvh")),
        "walk-turn": sorted((b / "dataset-2/walk-turn-left").glob("*.bvh"))
        + sorted((b / "dataset-2/walk-turn-right").glob("*.bvh")),
        "run": sorted((b / "dataset-1/run").glob("*.bvh")) + sorted((b / "dataset-2/run").glob("*.bvh")),
    }


class OtherTakes:
    """Every other take of a file's action as ``RecordedTakes`` (features computed once per action)."""

    def __init__(self, root: Path) -> None:
        self.groups = action_groups(root)
        self._all: dict[str, RecordedTakes] = {}

    def __call__(self, f: Path) -> RecordedTakes | None:
        action = next((a for a, g in self.groups.items() if f in g), None)
        if action is None:
            return None
        if action not in self._all:
            self._all[action] = RecordedTakes([bvh.load(x) for x in self.groups[action]])
        return self._all[action].without(bvh.load(f).name)  # leave the scored take out


def count_with_takes(motion, start: int, n: int, takes) -> int | None:
    """The missing count ``motionlab fill-gaps --takes`` gives a cut of ``n`` frames at ``start``."""
    found = dict(detect.detect(gap_eval.cut(motion, start, n), takes=takes))
    return found.get(start - 1)


def within(estimate, n: int) -> bool:
    return estimate is not None and abs(estimate - n) <= max(1.0, 0.1 * n)


def false_gaps(root: Path) -> None:
    files = sorted(root.rglob("*.bvh"))
    flagged, worst = [], (0.0, "")
    for f in files:
        m = bvh.load(f)
        ratio, _ = detect.consecutive_ratio(m)
        hits = detect.consecutive_gaps(m)
        if hits:
            flagged.append((f, hits))
        r = float(ratio.max(initial=0.0)) / detect.DELTA
        if r > worst[0]:
            worst = (r, str(f.relative_to(root)))
    print(f"1. false gaps: {len(flagged)} of {len(files)} clean BVH files flagged (Δ = {detect.DELTA});")
    print(f"   largest D/Δ {worst[0]:.2f} ({worst[1]})")
    for f, hits in flagged:
        print(f"   FLAGGED {f}: steps {hits}")


def removed_frames(name: str, files: list[Path], rng, other_takes: OtherTakes) -> list:
    results, cases = [], []
    for f in files:
        m = bvh.load(f)
        for n in REMOVED:
            lo, hi = 20, m.num_frames - n - 20
            if hi <= lo:
                continue
            results.append(gap_eval.evaluate_cut(m, int(rng.integers(lo, hi)), n))
            cases.append((f, results[-1]))
    s = gap_eval.summary(results)
    print(f"   {name}: {len(files)} clips, {s['cases']} cases (10/20/30 frames removed)")
    print(f"     detection precision {s['precision']:.3f}, recall {s['recall']:.3f}")
    ok = sum(r.count_ok for r in results)
    counted = sum(r.estimate is not None for r in results)
    print(f"     missing count within 10% (or one frame): {ok} of {counted} ({s['count_ok']:.1%})")
    bad = [f"{r.name} {r.n}->{r.estimate}" for r in results if r.estimate is not None and not r.count_ok]
    if bad:
        print("     outside: " + ", ".join(bad))
    with_takes = []
    for f in files:
        takes = other_takes(f)
        m = bvh.load(f)
        for g, r in cases:
            if g == f and r.hit:
                with_takes.append((r, count_with_takes(m, r.start, r.n, takes)))
    ok_t = sum(within(e, r.n) for r, e in with_takes)
    print(f"     with the other takes of the action (--takes, leave one take out): {ok_t} of {len(with_takes)} "
          f"({ok_t / max(len(with_takes), 1):.1%})")  # fmt: skip
    bad = [f"{r.name} {r.n}->{e}" for r, e in with_takes if not within(e, r.n)]
    if bad:
        print("       outside: " + ", ".join(bad))
    walks = [r for r in results if "walk" in r.name and "turn" not in r.name]
    for label, sub in (("straight walks", walks), ("all", results)):
        w = gap_eval.summary(sub)
        print(f"     {label}: mean root error over the gap / true displacement: mean {w['root_rel_mean']:.1%}, "
              f"worst {w['root_rel_max']:.1%}; lowest foot below the clip's floor by at most "
              f"{1000 * w['below_max']:.1f} mm; joints about the root {w['pose_cm_mean']:.1f} cm off")  # fmt: skip
    worst = max((r for r in walks if r.root_rel is not None), key=lambda r: r.root_rel, default=None)
    if worst is not None:
        print(f"     worst straight walk: {worst.name} {worst.n} frames at {worst.start}")
    hermite = [gap_eval.evaluate_cut(bvh.load(f), r.start, r.n, method="slerp", root="hermite") for f, r in cases]
    for label, sub in (("straight walks", [h for h in hermite if "walk" in h.name and "turn" not in h.name]),
                       ("all", hermite)):  # fmt: skip
        w = gap_eval.summary(sub)
        print(
            f"     (for comparison, --method slerp --root hermite, same cases) {label}: mean {w['root_rel_mean']:.1%}, worst {w['root_rel_max']:.1%}, "
            f"joints about the root {w['pose_cm_mean']:.1f} cm off"
        )
    return results


def dense(root: Path, every: int, other_takes: OtherTakes | None = None) -> None:
    """Every walk take, a cut every ``every`` frames (normal style: CHOOSE, the rest: VALIDATE):
    detection, missing count, root error and floor, as in part 2; with ``other_takes`` also the
    count with the other takes of the action (leave one take out)."""
    walks = sorted((root / "bandai_namco/sessions/walk").glob("*.bvh"))
    groups = {"CHOOSE (normal)": [f for f in walks if "_normal_" in f.name],
              "VALIDATE (6 other styles)": [f for f in walks if "_normal_" not in f.name]}  # fmt: skip
    print(f"4. every walk take of sessions/walk, 10/20/30 frames cut every {every} frames (from frame 20):")
    for name, files in groups.items():
        results, with_takes = [], []
        for f in files:
            m = bvh.load(f)
            takes = other_takes(f) if other_takes is not None else None
            for n in REMOVED:
                results.extend(gap_eval.evaluate_cut(m, s, n) for s in range(20, m.num_frames - n - 20, every))
                if takes is not None:
                    with_takes.extend(
                        (f.stem, s, n, count_with_takes(m, s, n, takes))
                        for s in range(20, m.num_frames - n - 20, every)
                    )
        s = gap_eval.summary(results)
        ok = sum(r.count_ok for r in results)
        print(f"   {name}: {len(results)} cases; recall {s['recall']:.4f}, precision {s['precision']:.4f}")
        print(f"     missing count within 10% (or one frame): {ok} of {len(results)} ({ok / len(results):.2%})")
        off = sorted((r for r in results if r.estimate is not None), key=lambda r: -abs(r.estimate - r.n) / r.n)
        print("     farthest off: " + ", ".join(f"{r.name}@{r.start} {r.n}->{r.estimate}" for r in off[:5]))
        if with_takes:
            ok_t = sum(within(e, n) for *_, n, e in with_takes)
            print(f"     with the other takes of the action (--takes): {ok_t} of {len(with_takes)} "
                  f"({ok_t / len(with_takes):.2%})")  # fmt: skip
            off = sorted((w for w in with_takes if w[3] is not None), key=lambda w: -abs(w[3] - w[2]) / w[2])
            print("       farthest off: " + ", ".join(f"{a}@{s} {n}->{e}" for a, s, n, e in off[:5]))
        print(f"     root error / displacement: mean {s['root_rel_mean']:.1%}, worst {s['root_rel_max']:.1%}, "
              f"share above 10%: {np.mean([r.root_rel > 0.1 for r in results if r.root_rel is not None]):.2%}; "
              f"lowest foot below the floor by at most {1000 * s['below_max']:.1f} mm")  # fmt: skip


OTHER_SOURCES = {
    "xia walk (120 fps)": ["xia/walk/*.bvh"],
    "xia run (120 fps)": ["xia/run/*.bvh"],
    "mixamo walks (60 fps)": [
        "mixamo/*/Catwalk_Walk.bvh",
        "mixamo/*/Catwalk_Walk_Forward_Arc_90L.bvh",
        "mixamo_ganimator/*/Walk-In-Circle.bvh",
    ],
    "mixamo injured walk, turning (60 fps, 7 characters)": ["mixamo/*/Injured_Walk_Left_Turn.bvh"],
}
"""Walks and runs from other studios, rigs and frame rates than the Bandai Namco takes (part 5)."""


FRESH_SOURCES = {
    "mixamo run, turning (60 fps, 7 characters)": ["mixamo/*/Run_Arc_Left.bvh"],
    "mixamo idle to walk (60 fps, 7 characters)": ["mixamo/*/Catwalk_Idle_To_Walk_Forward.bvh"],
    "mixamo backward walk and run, turning (60 fps)": [
        "mixamo/Aj/Pistol_Walk_Backward_Arc.bvh",
        "mixamo/Aj/Pistol_Run_Backward_Arc.bvh",
    ],
    "cmu start, walk, stop (120 fps)": ["cmu/131/*.bvh"],
}
"""Starts, stops, turns and clips padded with a held pose (part 6)."""


UNSCORED_SOURCES = {
    "bandai dataset-1 walks (30 fps, 16 styles)": ["bandai_namco/dataset-1/walk/*.bvh"],
    "bandai dataset-1 dashes (30 fps, 15 styles)": ["bandai_namco/dataset-1/dash/*.bvh"],
    "bandai side steps, left and right (30 fps)": [
        "bandai_namco/dataset-1/walk-left/*.bvh",
        "bandai_namco/dataset-1/walk-right/*.bvh",
    ],
    "mixamo catwalk turns, quick steps, wheelbarrow walk (60 fps)": [
        "mixamo/Aj/Catwalk_Twist_R_To_Walk_180.bvh",
        "mixamo/Aj/Catwalk_Walk_Start_Turn_180_Right.bvh",
        "mixamo/Aj/Quick_Steps.bvh",
        "mixamo/Aj/Wheelbarrow_Walk_Turn.bvh",
    ],
}
"""Other locomotion: Bandai Namco ``dataset-1`` walks, dashes and side steps, and Mixamo clips (part 7)."""


SAME_ACTION = (
    "xia walk (120 fps)",
    "xia run (120 fps)",
    "bandai dataset-1 walks (30 fps, 16 styles)",
    "bandai dataset-1 dashes (30 fps, 15 styles)",
    "bandai side steps, left and right (30 fps)",
)
"""Sources of parts 5 and 7 whose clips are takes of one action from one studio and rig, in other
styles: each cut is also counted with the source's other clips as ``--takes`` (leave one out). Not
the Mixamo sources: one animation on seven characters has one timing, so the other characters
would time a cut exactly, which says nothing of other recordings."""


def source_cuts(root: Path, rng, cuts: int, patterns: list[str]):
    """``(motion, first removed frame, frames removed)`` for the clips matching ``patterns``:
    ``cuts`` seeded places per clip and count of ``REMOVED`` (parts 5–7; the places drawn from
    ``rng`` in this order)."""
    for f in sorted({f for p in patterns for f in root.glob(p)}):
        m = bvh.load(f)
        for n in REMOVED:
            if m.num_frames - n - 20 <= 20:
                continue
            yield from ((m, int(s), n) for s in rng.integers(20, m.num_frames - n - 20, cuts))


def other_sources(root: Path, rng, cuts: int = 4, sources: dict | None = None, label: str = "") -> None:
    """The walks and runs of ``sources`` (default ``OTHER_SOURCES``), ``cuts`` seeded cuts of 10,
    20 and 30 frames per clip: detection, missing count (the stream alone; for the ``SAME_ACTION``
    sources also with the source's other clips as recordings), root error."""
    print(label or f"5. other sources, {cuts} cuts of 10/20/30 frames per clip:")
    for name, patterns in (OTHER_SOURCES if sources is None else sources).items():
        files = sorted({f for p in patterns for f in root.glob(p)})
        takes = RecordedTakes([bvh.load(f) for f in files]) if name in SAME_ACTION and len(files) > 1 else None
        results, with_takes, legs = [], [], []
        for m, s, n in source_cuts(root, rng, cuts, patterns):
            results.append(gap_eval.evaluate_cut(m, s, n))
            legs.append(humanoid.leg_length(m.skeleton))
            if takes is not None:
                with_takes.append(within(count_with_takes(m, s, n, takes.without(m.name)), n))
        if not results:
            continue
        s = gap_eval.summary(results)
        ok = sum(r.count_ok for r in results)
        print(f"   {name}: {len(files)} clips, {len(results)} cases; precision {s['precision']:.3f}, "
              f"recall {s['recall']:.3f}; count within 10% (or one frame) {ok} of {len(results)} "
              f"({ok / len(results):.0%}); root error / displacement mean {s['root_rel_mean']:.1%}, "
              f"worst {s['root_rel_max']:.1%}")  # fmt: skip
        print(f"     worst root: {worst_root(results, legs)}")
        if with_takes:
            print(f"     count with the source's other clips as --takes (leave one out): {sum(with_takes)} of "
                  f"{len(with_takes)} ({np.mean(with_takes):.0%})")  # fmt: skip
        held = sum(r.countable != r.n for r in results)
        if held:
            ok = sum(r.countable_ok for r in results)
            print(f"     {held} cuts took frames of a held pose (exact copies of a kept frame, which no stream "
                  f"can count): count within 10% (or one frame) of the countable frames {ok} of "
                  f"{len(results)} ({ok / len(results):.0%})")  # fmt: skip


def worst_root(results: list, legs: list[float]) -> str:
    """The cut whose root is farthest off relative to its displacement, also in centimetres as
    loaded and in leg lengths (thigh + shin, ``legs``: one per result): a large share of a small
    displacement is a small error. Leg lengths compare rigs whose files use other length units (the
    Xia and CMU files load with legs of 14–15 "cm")."""
    scored = [k for k, r in enumerate(results) if r.root_rel is not None]
    if not scored:
        return "none (no gap found)"
    k = max(scored, key=lambda k: results[k].root_rel)
    r, leg = results[k], legs[k]
    err = r.root_rel * r.displacement
    return (f"{r.name}@{r.start}, {r.n} frames cut: {100 * err:.1f} cm off over a {100 * r.displacement:.1f} cm "
            f"displacement ({r.root_rel:.1%}); in leg lengths {err / leg:.3f} over {r.displacement / leg:.3f}")  # fmt: skip


def graph_tracking(root: Path, quick: bool, rng) -> None:
    walk_dir = root / "bandai_namco/sessions/walk"
    graph = ActionGraph()
    graph_takes = [walk_dir / f"dataset-2_walk_normal_{i:03d}.bvh" for i in (1, 2, 3)]
    for i, f in enumerate(graph_takes):
        graph.add_node(f"walk{i + 1}", bvh.load(f))
    streams = [f for f in sorted(walk_dir.glob("*.bvh")) if f not in graph_takes][:: 12 if quick else 3]
    tp = fp = cases = clean_fp = 0
    for f in streams:
        m = bvh.load(f)
        clean_fp += len(detect.graph_gaps(m, graph))
        hit, false, made = gap_eval.detection_counts(m, lambda c: detect.graph_gaps(c, graph), REMOVED, rng)
        tp, fp, cases = tp + hit, fp + false, cases + made
    tr = detect.track(m, graph)
    print(f"3. stream tracked in an action graph of {len(graph_takes)} normal walk takes (Δ = {tr.delta:.2f}):")
    print(f"   {len(streams)} other walk takes, clean: {clean_fp} false gaps")
    print(f"   {cases} cases with 10/20/30 frames removed: precision {tp / max(tp + fp, 1):.3f}, recall {tp / max(cases, 1):.3f}")  # fmt: skip


def data_root() -> Path:
    """The shared data folder ``$MOTIONLAB_DATA``; exits with how to set it when it is not set."""
    if not os.environ.get("MOTIONLAB_DATA"):
        sys.exit("set MOTIONLAB_DATA to the shared data folder (e.g. export MOTIONLAB_DATA=/path/to/shared/data)")
    return Path(os.environ["MOTIONLAB_DATA"])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="a sixth of the clips (for CI-sized runs)")
    ap.add_argument("--dense", type=int, metavar="EVERY", default=0,
                    help="also every walk take, a cut every EVERY frames (e.g. 30; minutes)")  # fmt: skip
    ap.add_argument("--dense-takes", action="store_true",
                    help="in --dense, also the count with the other takes of the action (several more minutes)")  # fmt: skip
    ap.add_argument("--parts", default="1,2,3,4,5,6,7",
                    help="which parts, comma-separated (default: all; part 4 only with --dense)")  # fmt: skip
    args = ap.parse_args(argv)
    wanted = set(args.parts.split(","))
    root = data_root()
    t0 = time.perf_counter()
    if "1" in wanted:
        false_gaps(root)
    other_takes = OtherTakes(root)
    if "2" in wanted:
        print("2. frames removed from real walks and runs (detector and fill of `motionlab fill-gaps`):")
        rng = np.random.default_rng(0)
        for name, files in sets(root, args.quick).items():
            removed_frames(name, files, rng, other_takes)
    if "3" in wanted:
        graph_tracking(root, args.quick, np.random.default_rng(1))
    if args.dense and "4" in wanted:
        dense(root, args.dense, other_takes if args.dense_takes else None)
    cuts = 1 if args.quick else 4
    if "5" in wanted:
        other_sources(root, np.random.default_rng(5), cuts)
    if "6" in wanted:
        other_sources(root, np.random.default_rng(7), cuts, FRESH_SOURCES,
                      f"6. starts, stops and padded clips, {cuts} cuts of 10/20/30 frames per clip:")  # fmt: skip
    if "7" in wanted:
        other_sources(root, np.random.default_rng(11), cuts, UNSCORED_SOURCES,
                      f"7. other locomotion, {cuts} cuts of 10/20/30 frames per clip:")  # fmt: skip
    print(f"total time {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
