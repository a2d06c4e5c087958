"""Why ``detect._pose`` keeps Bandai Namco's origin marker: stream-vs-graph tracking with other poses.

    MOTIONLAB_DATA=/path/to/shared/data python scripts/check_tracking_pose.py

Part 3 of ``scripts/check_gaps.py`` (58 clean walk takes of ``sessions/walk`` tracked in a graph of
three normal takes, and 10/20/30 frames cut from each) run with the pose used for matching
replaced: ``current`` (every joint, the origin marker included), ``body`` (the reference joint and
the joints below it) and ``body+velocity`` (the same with weighted heading-frame velocities,
:func:`motionlab.interpolation.recorded.body_features`). Prints the false gaps on the clean takes
and precision / recall on the cut ones.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

from motionlab.core import bvh
from motionlab.interpolation import detect, gap_eval, recorded
from motionlab.interpolation.action_graph import ActionGraph


def body(motion, ref=None):
    f, _ = recorded.body_features(motion)
    return f.reshape(len(f), -1, 6)[:, :, :3].reshape(len(f), -1)


def body_velocity(motion, ref=None):
    return recorded.body_features(motion)[0]


def main() -> int:
    if not os.environ.get("MOTIONLAB_DATA"):
        sys.exit("set MOTIONLAB_DATA to the shared data folder")
    walk = Path(os.environ["MOTIONLAB_DATA"]) / "bandai_namco/sessions/walk"
    graph = ActionGraph()
    graph_takes = [walk / f"dataset-2_walk_normal_{i:03d}.bvh" for i in (1, 2, 3)]
    for i, f in enumerate(graph_takes):
        graph.add_node(f"walk{i + 1}", bvh.load(f))
    streams = [f for f in sorted(walk.glob("*.bvh")) if f not in graph_takes][::3]
    motions = [bvh.load(f) for f in streams]
    current = detect._pose
    try:
        for name, pose in (("current", current), ("body", body), ("body+velocity", body_velocity)):
            detect._pose = pose
            rng = np.random.default_rng(1)
            clean, flagged, tp, fp, cases = 0, [], 0, 0, 0
            for f, m in zip(streams, motions):
                found = detect.graph_gaps(m, graph)
                clean += len(found)
                if found:
                    flagged.append(f.stem)
                hit, false, made = gap_eval.detection_counts(
                    m, lambda c: detect.graph_gaps(c, graph), (10, 20, 30), rng
                )
                tp, fp, cases = tp + hit, fp + false, cases + made
            print(f"{name}: {clean} false gaps on {len(streams)} clean takes ({len(flagged)} takes: "
                  f"{', '.join(sorted(set(x.split('_')[2] for x in flagged))) or '-'}); "
                  f"{cases} cut: precision {tp / max(tp + fp, 1):.3f}, recall {tp / max(cases, 1):.3f}")  # fmt: skip
    finally:
        detect._pose = current
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
