"""How :func:`motionlab.interpolation.detect.track` matches the stream to the graph, against simpler matches.

    MOTIONLAB_DATA=/path/to/shared/data python -m experiments.interpolation.check_tracking_pose [--every N]

Every clean walk take of ``bandai_namco/sessions/walk`` but three (172 takes, seven styles) is
tracked in a graph of the three left out (``normal`` takes 1–3), and ``D > Δ`` asked for gaps:

* **clean**: false gaps on the takes as recorded;
* **moved**: the same takes with the body moved 3 m (x and z) in the capture volume, the origin
  marker ``joint_Root`` of the Bandai Namco rig left where it is: a take recorded elsewhere;
* **cut**: 10, 20 and 30 frames cut out of each take at random places (seeded), precision and
  recall of the cut's step.

Matches compared (the ``features``, ``context`` and ``rates`` of ``detect.track``):

* ``frame, every joint``: each frame alone (the better matched of the two frames beside the step),
  nearest graph frame by the heading-frame positions of every joint, the origin marker included:
  where the walker is in the capture volume then ties a frame to the graph frame at the same
  place on the session's path, which is what made single frames work at all;
* ``frame, body``: the same without the marker (the reference joint and the joints below it);
* ``frame, body+velocity``: with the weighted heading-frame velocities too;
* ``window, body``: 0.4 s windows, time-warped, positions only;
* ``window, body+velocity``: what ``detect.track`` does.

Then, with ``detect.track`` as it is, **other actions** (leave one take out: each take tracked in a
graph of the other takes of its action): the 18 runs of ``dataset-1/run`` and ``dataset-2/run``,
the two ``dataset-2`` walk-turns, the ``dataset-1`` dashes and walks (false gaps on the clean takes;
10 and 20 frames cut at seeded places), and the two ``dataset-1`` punches with a cut every 15
frames (10, 20, 30 frames), where the stream-against-itself rule and the single-frame match are
printed too.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

from experiments.interpolation import gap_eval
from motionlab.core import bvh
from motionlab.interpolation import detect
from motionlab.interpolation.action_graph import ActionGraph
from motionlab.interpolation.features import heading_frame


def every_joint(motion, ref, difference="central"):
    """Heading-frame positions of every joint, velocities zero: (T, J, 6)."""
    g_rot, g_pos = motion.fk()
    local, _, _ = heading_frame(g_rot, g_pos, ref)
    return np.concatenate([local, np.zeros_like(local)], axis=-1)


def positions_only(motion, ref, difference="central"):
    """:func:`motionlab.interpolation.detect.track_features` with the velocities zero: (T, J, 6)."""
    feat = detect.track_features(motion, ref, difference).copy()
    feat[..., 3:] = 0.0
    return feat


def _frames(features):
    return {"features": features, "context": 0.0, "rates": np.array([1.0])}


def _windows(features):
    return {"features": features, "context": detect.TRACK_CONTEXT, "rates": detect.TRACK_RATES}


VARIANTS = {  # keyword arguments of detect.track and detect.graph_gaps
    "frame, every joint": _frames(every_joint),
    "frame, body": _frames(positions_only),
    "frame, body+velocity": _frames(detect.track_features),
    "window, body": _windows(positions_only),
    "window, body+velocity": {},  # what detect.track does by default
}


def moved(motion, offset=(3.0, 0.0, 3.0)):
    """``motion`` with the body (the reference joint's translation) moved by ``offset`` metres."""
    lp = motion.translations().copy()
    lp[:, detect.reference_joint(motion)] += np.asarray(offset)
    return motion.copy(local_pos=lp)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--every", type=int, default=1, help="every N-th take only (default: all)")
    args = ap.parse_args(argv)
    if not os.environ.get("MOTIONLAB_DATA"):
        sys.exit("set MOTIONLAB_DATA to the shared data folder")
    walk = Path(os.environ["MOTIONLAB_DATA"]) / "bandai_namco/sessions/walk"
    graph = ActionGraph()
    graph_takes = [walk / f"dataset-2_walk_normal_{i:03d}.bvh" for i in (1, 2, 3)]
    for i, f in enumerate(graph_takes):
        graph.add_node(f"walk{i + 1}", bvh.load(f))
    streams = [f for f in sorted(walk.glob("*.bvh")) if f not in graph_takes][:: args.every]
    motions = [bvh.load(f) for f in streams]
    print(
        f"{len(streams)} clean walk takes tracked in a graph of {len(graph_takes)} normal takes (Δ = {detect.DELTA}):"
    )
    print(f"{'match':24s} {'clean':>6s} {'moved':>6s} {'largest D':>9s}   cut: precision, recall   takes flagged")
    for name, match in VARIANTS.items():
        rng = np.random.default_rng(1)
        clean = shifted = tp = fp = cases = 0
        largest, flagged = 0.0, set()
        for f, m in zip(streams, motions):
            tr = detect.track(m, graph, **match)
            clean += len(tr.gaps())
            largest = max(largest, float(tr.distance.max()))
            if tr.gaps():
                flagged.add(f.stem.split("_")[2])
            shifted += len(detect.graph_gaps(moved(m), graph, **match))
            hit, false, made = gap_eval.detection_counts(
                m, lambda c, kw=match: detect.graph_gaps(c, graph, **kw), (10, 20, 30), rng
            )
            tp, fp, cases = tp + hit, fp + false, cases + made
        print(f"{name:24s} {clean:6d} {shifted:6d} {largest:9.2f}   {cases} cut: {tp / max(tp + fp, 1):.3f}, "
              f"{tp / max(cases, 1):.3f}   {', '.join(sorted(flagged)) or '-'}", flush=True)  # fmt: skip
    other_actions(walk.parent.parent)
    return 0


def other_actions(bandai: Path) -> None:
    """Each take tracked in a graph of the other takes of its action (see the module docstring)."""
    groups = {
        "run": sorted((bandai / "dataset-1/run").glob("*.bvh")) + sorted((bandai / "dataset-2/run").glob("*.bvh")),
        "walk-turn": sorted((bandai / "dataset-2").glob("walk-turn-*/*.bvh")),
        "dataset-1 dash": sorted((bandai / "dataset-1/dash").glob("*.bvh")),
        "dataset-1 walk": sorted((bandai / "dataset-1/walk").glob("*.bvh")),
    }
    print("other actions, each take tracked in a graph of the other takes of its action:")
    rng = np.random.default_rng(2)
    for name, files in groups.items():
        motions = [bvh.load(f) for f in files]
        clean = tp = fp = cases = 0
        for i, m in enumerate(motions):
            graph = leave_out(motions, i)
            clean += len(detect.graph_gaps(m, graph))
            hit, false, made = gap_eval.detection_counts(m, lambda c, g=graph: detect.graph_gaps(c, g), (10, 20), rng)
            tp, fp, cases = tp + hit, fp + false, cases + made
        print(f"  {name:15s} {len(files):2d} takes: {clean} false gaps clean; {cases} cut: precision "
              f"{tp / max(tp + fp, 1):.3f}, recall {tp / max(cases, 1):.3f}")  # fmt: skip
    punches = [bvh.load(f) for f in sorted((bandai / "dataset-1/punch").glob("*.bvh"))]
    print("  dataset-1 punch, a cut every 15 frames (10/20/30 frames), recall and false gaps:")
    for label in ("window, body+velocity", "frame, every joint", "stream against itself"):
        match = VARIANTS.get(label)
        hit = false = cases = 0
        for i, m in enumerate(punches):
            graph = leave_out(punches, i)
            for s in range(20, m.num_frames - 40, 15):
                for n in (10, 20, 30):
                    c = gap_eval.cut(m, s, n)
                    found = detect.consecutive_gaps(c) if match is None else detect.graph_gaps(c, graph, **match)
                    h = (s - 1) in found
                    hit, false, cases = hit + h, false + len(found) - h, cases + 1
        print(f"    {label:24s} {cases} cuts: recall {hit / max(cases, 1):.3f}, {false} false gaps")


def leave_out(motions: list, i: int) -> ActionGraph:
    """An action graph of every motion but the ``i``-th, one node each."""
    graph = ActionGraph()
    for j, m in enumerate(motions):
        if j != i:
            graph.add_node(f"take{j}", m)
    return graph


if __name__ == "__main__":
    raise SystemExit(main())
