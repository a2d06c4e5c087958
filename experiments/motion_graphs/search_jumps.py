"""What the search's paths cost on a recording session: jumps, frames off the request, time.

The search (:mod:`motionlab.motion_graphs.search`) chooses, in each pool, the walk whose jumps
cost least plus one per frame off the request (the default cost: ``search.JUMP_FRAMES`` per
jump). This study runs a fixed set of requests on the structured graph of the whole session
folder and prints, per request and in total, the jumps of the path (its pieces after the first),
the frames off the request, the frames through other styles, and the search's time (one
:class:`~motionlab.motion_graphs.search.Planner` for all requests; its first search also builds
the walkers). It reads the package only through its public API, so the same command run at two
commits compares their searches.

Requests: :data:`COUNT` random requests of one to three segments of 30–400 frames over the
session's styles (seed 0), drawn before any search.

Run::

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.motion_graphs.search_jumps
    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.motion_graphs.search_jumps --graph session.mlgraph
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

import numpy as np

from motionlab import data
from motionlab.motion_graphs import clips, distance, io, search, structured

COUNT = 40
"""Random requests."""


def requests(g, count: int = COUNT, seed: int = 0) -> list[str]:
    """``count`` requests of 1–3 segments of 30–400 frames over the graph's styles."""
    cells = g.table["behaviours"]
    keys = [(b, s) for b in sorted(cells) for s in sorted(cells[b])]
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        picked = [keys[j] for j in rng.integers(0, len(keys), int(rng.integers(1, 4)))]
        out.append(",".join(f"{b}:{s}:{int(rng.integers(30, 401))}" for b, s in picked))
    return out


def graph(path: str | None):
    """The graph of ``path``, or built from the session folder at the default threshold."""
    if path:
        try:
            return io.load(path)
        except (OSError, ValueError) as e:  # a missing or damaged file: its own message, no traceback
            sys.exit(str(e))
    folder = data.data_root() / "bandai_namco" / "sessions"
    if not folder.is_dir():
        sys.exit(f"needs real mocap ({folder}): {data.HOW_TO}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        motions = clips.load_folder(folder)
        return structured.build_structured(motions, distance.threshold_from(distance.DEFAULT_THRESHOLD))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--graph", help="a .mlgraph file (default: build the session folder's graph)")
    ap.add_argument("--count", type=int, default=COUNT, help=f"random requests (default {COUNT})")
    args = ap.parse_args(argv)
    g = graph(args.graph)
    planner = search.Planner(g)
    totals = np.zeros(4)
    print("request | jumps | frames off | passing | ms")
    for req in requests(g, args.count):
        t = time.perf_counter()
        try:
            r = planner.search(req)
        except search.SearchError as e:
            print(f"{req} | refused: {e}")
            continue
        ms = 1000 * (time.perf_counter() - t)
        row = (len(r.pieces) - 1, sum(abs(e) for e in r.errors), sum(r.passing), ms)
        totals += row
        print(f"{req} | {row[0]} | {row[1]} | {row[2]} | {ms:.0f}")
    jumps, off, passing, ms = totals
    cost = search.JUMP_FRAMES * jumps + off
    print(
        f"in all: {jumps:.0f} jumps, {off:.0f} frames off the requests, {passing:.0f} frames passing; "
        f"{search.JUMP_FRAMES} x jumps + frames off = {cost:.0f}; searches {ms / 1000:.1f} s "
        f"(machine: {os.cpu_count()} CPUs)"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
