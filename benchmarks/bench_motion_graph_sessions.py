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

    MOTIONLAB_DATA=/path/to/shared/data python benchmarks/bench_motion_graph_sessions.py [--behaviour walk]
"""

from __future__ import annotations

import argparse
import re
import sys
import time

import numpy as np

from motionlab import data
from motionlab.motion_graphs import clips, distance, report, search, structured

GRID = (0.015, 0.02, 0.025, 0.03, 0.04, 0.05)
"""Thresholds tried, metres RMS."""

GOAL_BEHAVIOUR = 90.0
GOAL_STYLE = 80.0
FRAMES = (150, 400)
"""Frames per segment of the pair searches (a short and a long request)."""


def pair_searches(g, behaviour: str, frames: int) -> tuple[int, int, float, list[str]]:
    """Search every ordered pair of styles; returns (ok, tried, worst relative error, failures)."""
    styles = sorted(g.table["behaviours"][behaviour])
    ok, tried, worst, fails = 0, 0, 0.0, []
    for a in styles:
        for b in styles:
            if a == b:
                continue
            tried += 1
            try:
                r = search.search(g, [(behaviour, a, frames), (behaviour, b, frames)])
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


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--behaviour", default="walk")
    args = ap.parse_args(argv)
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
