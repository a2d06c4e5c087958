"""Single cases that show where counting and filling dropped frames is hard, on the shared real mocap.

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.interpolation.gap_cases

Each case prints what it measured and checks the sentence ``docs/results_interpolation.md``
says about it (section *Hard cases, one at a time*); a case whose data is missing is skipped.

1. **turn**: a walker who slows down inside a left turn, counted from the sides alone and with the
   mirrored right turn as another recording (``detect.estimate_missing(takes=...)``);
2. **retimed**: the same stream from three walkers who held the gap's stretch for 20, 30 or 14
   frames; the count from the stream against the count from the frame times;
3. **root**: two walkers whose true root paths across one stream's gap lie apart;
4. **xia**: a 120 fps walk where the local count wins the rehearsal (``detect.count_choice``);
5. **start**: a walker setting off from standing (the two sides' speeds differ);
6. **padded**: a clip padded with its last pose (``detect.HELD``);
7. **foot**: a foot that SLERP swings into the floor, lifted out or planted by bending the leg.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from experiments.interpolation import gap_eval
from motionlab import data
from motionlab.core import bvh
from motionlab.interpolation import alignment, detect, footing, gaps, inbetween, recorded, stride
from motionlab.interpolation.demo import walk_clip


def turn() -> None:
    root = data.data_root() / "bandai_namco" / "dataset-2"
    left = bvh.load(root / "walk-turn-left" / "dataset-2_walk-turn-left_normal_001.bvh")
    right = bvh.load(root / "walk-turn-right" / "dataset-2_walk-turn-right_normal_001.bvh")
    s, n = 43, 30  # 30 frames removed from frame 43 on
    cut = left[np.r_[0:s, s + n : left.num_frames]]
    (alone,) = detect.estimate_missing(cut, [s - 1])
    (with_takes,) = detect.estimate_missing(cut, [s - 1], takes=recorded.RecordedTakes([right]))
    print(
        f"turn: {n} removed from a left turn: counted {alone} from the sides alone, {with_takes} with the mirrored right turn"
    )
    assert abs(alone - n) > 0.1 * n and abs(with_takes - n) <= 0.1 * n


def retimed(walk) -> None:
    s, n = 100, 20  # 20 frames removed from frame 100 on
    stream = gap_eval.cut(walk, s, n)
    (counted,) = detect.detect(stream)
    for m in (n, 30, 14):  # the truth: the same stretch held n, 30 or 14 frames
        other = gap_eval.retimed(walk, s, n, m)
        same = gap_eval.cut(other, s, m)
        identical = np.array_equal(same.local_rot, stream.local_rot) and np.array_equal(same.root_pos, stream.root_pos)
        times = np.r_[0:s, s + m : other.num_frames] / other.fps  # when the kept frames were captured
        (from_times,) = gaps.timestamp_gaps(times, other.fps)
        print(f"retimed: {m:2d} frames missing: the same stream as the cut of {n}: {identical}; "
              f"counted from the stream {detect.detect(same)[0][1]}, from the frame times {from_times[1]}")  # fmt: skip
        assert identical and detect.detect(same) == [counted] and from_times == (s - 1, m)
    assert abs(counted[1] - n) <= max(1, 0.1 * n)  # right for the walker who kept the pace


def root_apart(walk) -> None:
    s = 100
    stream = gap_eval.cut(walk, s, 20)
    early = gap_eval.retimed(walk, s, 10, 30)  # the gap's first 10 frames at a third of the pace
    late = gap_eval.retimed(walk, s + 10, 10, 30)  # or its last 10: either way 40 frames are missing
    for m in (early, late):
        same = gap_eval.cut(m, s, 40)
        assert np.array_equal(same.local_rot, stream.local_rot) and np.array_equal(same.root_pos, stream.root_pos)
    ref = alignment.reference_joint(walk)

    def path(m):
        return alignment.reference_transform(m, joint=ref)[1]

    apart = np.linalg.norm(path(early)[s : s + 40] - path(late)[s : s + 40], axis=1).mean()
    disp = np.linalg.norm(path(early)[s + 40] - path(early)[s - 1])
    given = {
        name: gap_eval.evaluate_cut(m, s, 40, found=[(s - 1, 40)]) for name, m in (("early", early), ("late", late))
    }
    print(f"root: the two true root paths lie {apart / disp:.1%} of the displacement apart, so any fill of the "
          f"one stream is at least {apart / disp / 2:.1%} off on one of them")  # fmt: skip
    print(
        "root: the stride fill, told the true count (40): "
        + ", ".join(f"{k} {r.root_rel:.1%}" for k, r in given.items())
    )
    assert apart / disp / 2 > 0.10  # above the 10% goal for every fill
    assert max(r.root_rel for r in given.values()) >= apart / disp / 2 - 1e-9  # one fill, two truths


def xia() -> None:
    clip = bvh.load(data.data_root() / "xia" / "walk" / "strutting_01_000.bvh")
    s, n = 212, 10  # 10 frames removed from frame 212 on
    c = detect.count_choice(clip[np.r_[0:s, s + n : clip.num_frames]], s - 1)
    print(f"xia: {n} removed at {clip.fps:.0f} fps: stride count {c.stride:.1f}, local count {c.local:.1f}; "
          f"rehearsal: {c.local_only} cuts only the local count got right, {c.stride_only} only the stride count "
          f"(sign test p = {c.p:.1g}) -> count {c.count:.1f}")  # fmt: skip
    assert abs(round(c.stride) - n) > 1 and abs(round(c.count) - n) <= 1


def start() -> None:
    first = bvh.load(data.data_root() / "bandai_namco" / "sessions" / "walk" / "dataset-2_walk_normal_001.bvh")
    s, n = 20, 10  # 10 frames removed from frame 20 on, the first step
    missing = detect.detect(first[np.r_[0:s, s + n : first.num_frames]])
    holed = gaps.insert_missing(first[np.r_[0:s, s + n : first.num_frames]], missing)[0]
    ref = alignment.reference_joint(first)
    v_before, v_after = stride.side_speeds(holed, s - 1, s + missing[0][1], ref)
    r = gap_eval.evaluate_cut(first, s, n)
    print(f"start: {n} removed, counted {missing[0][1]}; ground speed a second before the gap "
          f"{v_before * first.fps:.2f} m/s, after {v_after * first.fps:.2f} m/s; "
          f"mean root error over the gap {r.root_rel:.1%} of the true displacement")  # fmt: skip
    assert detect.changes_speed(v_before, v_after) and v_before < 0.5 * v_after
    assert r.root_rel <= 0.10 and r.below == 0.0


def padded() -> None:
    run = bvh.load(data.clip_path("mixamo", "Aj", "Run_Arc_Left"))
    held = detect.held_steps(run)
    s, n = 26, 10  # 10 frames removed from frame 26 on
    (count,) = detect.estimate_missing(run[np.r_[0:s, s + n : run.num_frames]], [s - 1])
    moving = gap_eval.countable(run, s, n)
    print(f"padded: {run.name}: {held.sum()} of {run.num_frames - 1} steps repeat their frame, from step "
          f"{np.argmax(held)} on; {n} removed: {moving} of them move, counted {count}")  # fmt: skip
    assert held[32:].all() and not held[:32].any()
    assert abs(count - moving) <= 1


def foot() -> None:
    proud = bvh.load(data.clip_path("bandai_namco", "dataset-1", "walk", "dataset-1_walk_proud_001"))
    s, n = 211, 10  # 10 frames removed from frame 211 on
    a, b = s - 1, s + n
    holed = gaps.insert_missing(proud[np.r_[0:s, s + n : proud.num_frames]], [(a, n)])[0]
    ref = alignment.reference_joint(proud)
    slerped = gaps.smooth_root(inbetween.fill_between(holed, s, b), [a, b], joint=ref)  # SLERP, Hermite root
    fills = {"body lifted": gaps.lift_above_floor(slerped, a, b), "leg bent": footing.plant_feet(slerped, a, b)}
    floor = min(proud.global_positions()[[a, b], 1:, 1].min(axis=1))

    def hips(m):
        return 100 * alignment.reference_transform(m, np.arange(a - 10, b + 11), joint=ref)[1][:, 1]

    def lowest(m):
        return round(100 * (m.global_positions()[a + 1 : b, 1:, 1].min() - floor), 3) + 0.0

    print(f"foot: SLERP alone: lowest foot {lowest(slerped):.1f} cm against the floor")
    for label, m in fills.items():
        print(
            f"foot: {label}: lowest foot {lowest(m):.1f} cm, hips up to {(hips(m) - hips(proud)).max():.1f} cm above the true ones"
        )
    assert lowest(slerped) < -3.0  # SLERP sinks the stance foot
    assert all(lowest(m) >= 0.0 for m in fills.values())  # both fixes keep it on the floor
    assert (hips(fills["body lifted"]) - hips(proud)).max() > 3.0  # lifting the body makes the hips hop
    assert np.abs(hips(fills["leg bent"]) - hips(proud)).max() < 1.0  # bending the leg keeps them level


CASES = {
    "turn": (("bandai_namco", "dataset-2"), lambda walk: turn()),
    "retimed": (("bandai_namco", "dataset-2"), retimed),
    "root": (("bandai_namco", "dataset-2"), root_apart),
    "xia": (("xia", "walk"), lambda walk: xia()),
    "start": (("bandai_namco", "sessions", "walk"), lambda walk: start()),
    "padded": (("mixamo", "Aj"), lambda walk: padded()),
    "foot": (("bandai_namco", "dataset-1"), lambda walk: foot()),
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("cases", nargs="*", metavar="CASE", help=f"cases to run, of {', '.join(CASES)} (default: all)")
    args = ap.parse_args(argv)
    unknown = sorted(set(args.cases) - set(CASES))
    if unknown:
        ap.error(f"unknown case(s) {', '.join(unknown)}; known: {', '.join(CASES)}")
    walk, _ = walk_clip()  # notebook 06's walk (canonical, 30 fps)
    for name in args.cases or list(CASES):
        needs, run = CASES[name]
        if not data.has_data(*needs):
            print(f"{name}: skipped (no {'/'.join(needs)} under MOTIONLAB_DATA)")
            continue
        run(walk)
    return 0


if __name__ == "__main__":
    sys.exit(main())
