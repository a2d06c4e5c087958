"""Structured motion graphs on a recording session: the threshold chosen on half of the takes,
checked on the other half and on all of them.

Data: ``MOTIONLAB_DATA/bandai_namco/sessions/<behaviour>/`` (Bandai Namco dataset-2, many takes
per style). Takes with odd numbers are the *pick* half, even numbers the *check* half.

Principle: the transition threshold is the **smallest** value of a grid (smaller = closer
poses at every transition) for which the pick half meets the connectivity goals: the largest
strongly connected component of the behaviour holds >= 90% of its frames, every style keeps
>= 80% of its own frames in it, and a search between every ordered pair of styles succeeds
with every segment within the documented tolerance (``search.TOLERANCE``). The chosen value is
then checked, untouched, on the check half and on all takes.

Run::

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.motion_graphs.sessions [--behaviour walk]

**Whole session** (``--session``): every behaviour folder under ``sessions/`` at once (gaits and
standing actions, :mod:`motionlab.motion_graphs.segments`). It prints, per take kind, the
share of frames with both feet planted (the gait/action rule) and a leave-one-style-out check of
it; the threshold is again the smallest of the grid for which the pick half meets the goals —
every behaviour's largest component >= 90% of its frames, every ordered style pair of each
behaviour joined by its links, and the request :data:`REQUEST` answered within the tolerance —
and it is then checked on the check half and on all takes. For all takes it prints the report,
the request's frame counts, the median search time over :data:`REPEATS` runs of the request and
of each behaviour's style pairs, and the build's seconds and peak memory (a fresh process)::

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.motion_graphs.sessions --session

**Behaviours left out** (``--leave-out``): the same rule run on two behaviours' pick half, the
chosen threshold checked on the third behaviour's takes (:func:`leave_out`).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import time

import numpy as np

from motionlab import data
from motionlab.motion_graphs import clips, distance, report, search, segments, structured

GRID = (0.015, 0.02, 0.025, 0.03, 0.04, 0.05)
"""Thresholds tried, metres RMS."""

GOAL_BEHAVIOUR = 90.0
GOAL_STYLE = 80.0
FRAMES = (150, 400)
"""Frames per segment of the pair searches (a short and a long request)."""


def pair_searches(g, behaviour: str, frames: int) -> tuple[int, int, float, list[str]]:
    """Search every ordered pair of styles; returns (ok, tried, worst relative error, failures)."""
    styles = sorted(g.table["behaviours"][behaviour])
    planner = search.Planner(g)  # one graph, many searches: its walkers are built once
    ok, tried, worst, fails = 0, 0, 0.0, []
    for a in styles:
        for b in styles:
            if a == b:
                continue
            tried += 1
            try:
                r = planner.search([(behaviour, a, frames), (behaviour, b, frames)])
                g.check_path(r.pieces)
            except search.SearchError as e:
                fails.append(f"{a}->{b}: {e}")
                continue
            err = max(abs(x - y) / y for x, y in zip(r.achieved, r.requested))
            within = all(abs(x - y) <= max(2, search.TOLERANCE * y) for x, y in zip(r.achieved, r.requested))
            worst = max(worst, err)
            if within:
                ok += 1
            else:
                fails.append(f"{a}->{b}: got {r.achieved} for {r.requested}")
    return ok, tried, worst, fails


def evaluate(motions, rms: float, behaviour: str) -> dict:
    t0 = time.perf_counter()
    g = structured.build_structured(motions, distance.threshold_from(rms))
    dt = time.perf_counter() - t0
    rep = report.build_report(g)
    beh = rep["behaviours"][behaviour]
    styles_min = min(r["in_largest_percent"] for r in rep["rows"] if r["behaviour"] == behaviour)
    out = dict(rms=rms, seconds=dt, percent=beh["percent"], style_min=styles_min, graph=g, report=rep)
    for n in FRAMES:
        ok, tried, worst, fails = pair_searches(g, behaviour, n)
        out[f"search{n}"] = (ok, tried, worst, fails)
    out["meets"] = (
        beh["percent"] >= GOAL_BEHAVIOUR
        and styles_min >= GOAL_STYLE
        and all(out[f"search{n}"][0] == out[f"search{n}"][1] for n in FRAMES)
    )
    return out


def line(name: str, e: dict) -> str:
    s = "  ".join(f"pairs@{n}: {e[f'search{n}'][0]}/{e[f'search{n}'][1]}" for n in FRAMES)
    return (
        f"{name:<6} {e['rms']:.3f} m  build {e['seconds']:5.1f} s  behaviour SCC {e['percent']:5.1f}%  "
        f"worst style {e['style_min']:5.1f}%  {s}  {'meets goals' if e['meets'] else 'misses goals'}"
    )


REQUEST = "walk:normal:100,wave-both-hands:normal:60,walk:normal:100"
"""The cross-behaviour request of the session goals (issue 32)."""

REPEATS = 9
"""Runs of each timed search (the median is printed)."""


def take_number(name: str) -> int:
    return int(re.search(r"_(\d+)$", name).group(1))


def kinds_check(motions) -> None:
    """The gait/action rule on every take, and a leave-one-style-out check of its boundary."""
    rows = []
    for m in motions:
        lab = m.name.split("_")
        rows.append((lab[0], lab[1], segments.segment_take(m)))
    for b in sorted({r[0] for r in rows}):
        mine = [r[2] for r in rows if r[0] == b]
        share = np.array([x.both_planted for x in mine])
        kinds = sorted({x.kind for x in mine})
        print(
            f"  {b}: {len(mine)} takes, kinds {kinds}, both feet planted {share.min():.2f}..{share.max():.2f} "
            f"of the frames, {sum(x.count for x in mine)} segments, {sum(x.stances.shape[0] for x in mine)} stances"
        )
    # leave one style out: the boundary fitted on the other styles (halfway between the largest
    # gait share and the smallest action share; the folder says which is which) classifies it alike
    gait = {b for b, _, x in rows if x.kind == "gait"}
    styles = sorted({r[1] for r in rows})
    agree = 0
    for s in styles:
        rest = [(b in gait, x.both_planted) for b, st, x in rows if st != s]
        cut = (max(v for g, v in rest if g) + min(v for g, v in rest if not g)) / 2 if len(gait) and len(rest) else 0.5
        held = [(b in gait, x.both_planted) for b, st, x in rows if st == s]
        agree += sum((v < cut) == g for g, v in held)
    print(f"  leave one style out: {agree}/{len(rows)} held-out takes classified as their folder says")


def session_goals(g, request: str = REQUEST) -> dict:
    rep = report.build_report(g)
    out = dict(report=rep, request=None, error=None)
    try:
        r = search.search(g, request)
        g.check_path(r.pieces)
        out["request"] = r
    except search.SearchError as e:
        out["error"] = str(e)
    beh = rep["behaviours"]
    within = out["request"] is not None and all(
        abs(a - q) <= max(2, search.TOLERANCE * q) for a, q in zip(out["request"].achieved, out["request"].requested)
    )
    out["meets"] = (
        all(v["percent"] >= GOAL_BEHAVIOUR for v in beh.values())
        and all(v["reachable_pairs"] == v["style_pairs"] for v in beh.values())
        and within
    )
    return out


def session_line(name: str, rms: float, seconds: float, e: dict) -> str:
    beh = e["report"]["behaviours"]
    shares = "  ".join(
        f"{b} {v['percent']:.1f}% {v['reachable_pairs']}/{v['style_pairs']}" for b, v in sorted(beh.items())
    )
    r = e["request"]
    req = f"request {'/'.join(map(str, r.achieved))} (+{sum(r.passing)} passing)" if r else "request fails"
    return f"{name:<6} {rms:.3f} m  build {seconds:5.1f} s  {shares}  {req}  {'meets goals' if e['meets'] else 'misses goals'}"


def build_only(folder, rms: float) -> int:
    """Load and build every take once; print seconds and this process's peak memory."""
    import resource

    motions = clips.load_folder(folder)
    t0 = time.perf_counter()
    graph = structured.build_structured(motions, distance.threshold_from(rms))
    dt = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2  # KiB -> GiB (Linux)
    print(
        f"build of {len(motions)} takes at {rms} m: {dt:.1f} s, {graph.num_frames} frames, "
        f"peak memory {peak:.2f} GiB (loading included)"
    )
    return 0


def timed(planner, request) -> tuple[float, object]:
    """Median milliseconds of :data:`REPEATS` searches by one planner, after a first search that
    builds the walkers it needs (as a session that searches one graph many times)."""
    times, r = [], planner.search(request)
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        r = planner.search(request)
        times.append(time.perf_counter() - t0)
    return 1000 * float(np.median(times)), r


def session(folder) -> int:
    import subprocess

    motions = clips.load_folder(folder)
    pick = [m for m in motions if take_number(m.name) % 2 == 1]
    check = [m for m in motions if take_number(m.name) % 2 == 0]
    print(f"session {folder}: {len(motions)} takes; pick half (odd takes) {len(pick)}, check half {len(check)}")
    print("kinds from the motion (folder names only check them):")
    kinds_check(motions)
    print(f"goals: every behaviour SCC >= {GOAL_BEHAVIOUR}%, every style pair joined, {REQUEST} within tolerance")
    chosen = None
    for rms in GRID:
        t0 = time.perf_counter()
        g = structured.build_structured(pick, distance.threshold_from(rms))
        e = session_goals(g)
        print(session_line("pick", rms, time.perf_counter() - t0, e))
        if e["meets"]:
            chosen = rms
            break
    if chosen is None:
        print("no threshold of the grid meets the goals on the pick half")
        return 1
    print(f"chosen threshold (smallest meeting the goals on the pick half): {chosen} m")
    print(
        f"the library's and graph-build's default threshold (distance.DEFAULT_THRESHOLD): {distance.DEFAULT_THRESHOLD} m"
    )
    for name, ms in (("check", check), ("all", motions)):
        t0 = time.perf_counter()
        g = structured.build_structured(ms, distance.threshold_from(chosen))
        e = session_goals(g)
        print(session_line(name, chosen, time.perf_counter() - t0, e))
    print(report.format_report(e["report"]))
    if e["request"] is not None:
        r = e["request"]
        print(f"request {REQUEST}:")
        print(r.report())
        print(
            f"path: {r.num_frames} frames in {len(r.pieces)} pieces, "
            f"{r.pieces_per_second(g.fps):.2f} pieces per second ({r.num_frames / len(r.pieces):.1f} frames per piece)"
        )
    else:
        print(f"request {REQUEST} fails: {e['error']}")
    planner = search.Planner(g)
    ms_req, _ = timed(planner, REQUEST) if e["request"] is not None else (float("nan"), None)
    pair_times = []
    for b, cells in sorted(g.table["behaviours"].items()):
        styles = sorted(cells)
        for a, c in zip(styles, styles[1:] + styles[:1]):
            pair_times.append(timed(planner, f"{b}:{a}:150,{b}:{c}:150")[0])
    print(
        f"search median over {REPEATS} runs: request {ms_req:.1f} ms; style pairs (each style to the next, "
        f"{len(pair_times)} requests) median {np.median(pair_times):.1f} ms, worst {max(pair_times):.1f} ms"
    )
    subprocess.run(
        [
            sys.executable,
            "-m",
            "experiments.motion_graphs.sessions",
            "--build-only",
            str(chosen),
            "--folder",
            str(folder),
        ],
        check=True,
        cwd=os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
    )
    return 0


GOAL_HELD_OUT = 95.0
"""Share of a left-out behaviour's frames its largest component must hold (issue 43's goal)."""


def leave_out(folder) -> int:
    """The threshold rule checked on behaviours it never saw: for each behaviour, the rule (the
    smallest threshold of the grid for which every behaviour of the pick half holds >= 90% of its
    frames in its largest component and joins every ordered style pair) is run on the pick half
    of the *other* behaviours only; the left-out behaviour's takes (all of them) are then built
    at the chosen threshold and must keep >= 95% of their frames in the largest component, with
    every style pair joined."""
    motions = clips.load_folder(folder)
    behaviours = sorted({m.name.split("_")[0] for m in motions})
    print(f"session {folder}: behaviours {behaviours}; goal for the left-out behaviour >= {GOAL_HELD_OUT}%")
    ok = True
    for held in behaviours:
        pick = [m for m in motions if m.name.split("_")[0] != held and take_number(m.name) % 2 == 1]
        chosen = None
        for rms in GRID:
            rep = report.build_report(structured.build_structured(pick, distance.threshold_from(rms)))
            beh = rep["behaviours"]
            if all(v["percent"] >= GOAL_BEHAVIOUR and v["reachable_pairs"] == v["style_pairs"] for v in beh.values()):
                chosen = rms
                break
        if chosen is None:
            print(f"  {held} left out: no threshold of the grid meets the goals on the others")
            ok = False
            continue
        mine = [m for m in motions if m.name.split("_")[0] == held]
        v = report.build_report(structured.build_structured(mine, distance.threshold_from(chosen)))["behaviours"][held]
        met = v["percent"] >= GOAL_HELD_OUT and v["reachable_pairs"] == v["style_pairs"]
        ok &= met
        print(
            f"  {held} left out: chosen on {', '.join(b for b in behaviours if b != held)} (pick half): {chosen} m; "
            f"{held} (all {len(mine)} takes) at {chosen} m: {v['percent']:.1f}% in its largest component, "
            f"{v['reachable_pairs']}/{v['style_pairs']} style pairs: {'met' if met else 'NOT met'}"
        )
    return 0 if ok else 1


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--behaviour", default="walk")
    ap.add_argument("--session", action="store_true", help="every behaviour of the session at once")
    ap.add_argument("--build-only", type=float, help="only time one build of all takes at this threshold (m)")
    ap.add_argument("--leave-out", action="store_true", help="the threshold rule checked on each behaviour left out")
    ap.add_argument("--folder", help="session folder (default MOTIONLAB_DATA/bandai_namco/sessions)")
    args = ap.parse_args(argv)
    if args.session or args.build_only or args.leave_out:
        folder = args.folder or data.data_root() / "bandai_namco" / "sessions"
        if not (data.data_root() / "bandai_namco" / "sessions").is_dir() and not args.folder:
            print(f"needs {folder}: {data.HOW_TO}")
            return 1
        if args.leave_out:
            return leave_out(folder)
        return build_only(folder, args.build_only) if args.build_only else session(folder)
    folder = data.data_root() / "bandai_namco" / "sessions" / args.behaviour
    if not folder.is_dir():
        print(f"needs {folder}: {data.HOW_TO}")
        return 1
    motions = clips.load_folder(folder)
    take = [int(re.search(r"_(\d+)$", m.name).group(1)) for m in motions]
    pick = [m for m, t in zip(motions, take) if t % 2 == 1]
    check = [m for m, t in zip(motions, take) if t % 2 == 0]
    print(
        f"{args.behaviour}: {len(motions)} takes, {sum(m.num_frames for m in motions)} frames; "
        f"pick half (odd takes) {len(pick)}, check half (even takes) {len(check)}"
    )
    print(f"goals: behaviour SCC >= {GOAL_BEHAVIOUR}%, every style >= {GOAL_STYLE}%, every style pair searched")
    chosen = None
    for rms in GRID:
        e = evaluate(pick, rms, args.behaviour)
        print(line("pick", e))
        if e["meets"] and chosen is None:
            chosen = rms
    if chosen is None:
        print("no threshold of the grid meets the goals on the pick half")
        return 1
    print(f"chosen threshold (smallest meeting the goals on the pick half): {chosen} m")
    print("the check half at every threshold of the grid (shown, not used to choose):")
    for rms in GRID:
        print(line("check", evaluate(check, rms, args.behaviour)))
    for name, ms in (("check", check), ("all", motions)):
        e = evaluate(ms, chosen, args.behaviour)
        print(line(name, e))
        for n in FRAMES:
            ok, tried, worst, fails = e[f"search{n}"]
            print(f"  {name}: {ok}/{tried} style pairs at {n}+{n} frames, worst segment error {100 * worst:.1f}%")
            for f in fails[:5]:
                print(f"    {f}")
    print(report.format_report(e["report"]))
    costs = distance.rms(e["graph"].cost)
    print(
        f"transition distance on all takes: median {np.median(costs):.4f} m, 95th percentile {np.percentile(costs, 95):.4f} m"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
