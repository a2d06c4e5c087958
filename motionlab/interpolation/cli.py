"""``motionlab fill-gaps``: find dropped frames in a BVH file and fill them.

Examples::

    motionlab fill-gaps take.bvh -o take_filled.bvh
    motionlab fill-gaps take.bvh -o out.bvh --method hermite --factor 5
    motionlab fill-gaps take.bvh -o out.bvh --method graph \\
        --action run=Running.bvh --action walk=Walk.bvh --action stand=Idle.bvh \\
        --allow "run -> walk" --allow "walk -> stand"

Dropped frames are found with the ``D > Δ`` rule (:func:`motionlab.interpolation.gaps.distance_gaps`),
the missing count is estimated from the size of the jump, and the frames are inserted and filled.
A report lists every gap and how it was filled.
"""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["register", "run_fill_gaps"]


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "fill-gaps",
        help="detect dropped frames in a BVH file and fill them (SLERP, Hermite or action-graph guided)",
        description="Detect frames missing from a BVH stream (distance D > Δ between consecutive frames), "
        "insert the estimated number of frames and fill them.",
    )
    p.add_argument("input", help="BVH file with dropped frames")
    p.add_argument("-o", "--output", required=True, help="where to write the filled BVH file")
    p.add_argument("--method", choices=("slerp", "hermite", "graph"), default="slerp",
                   help="slerp: SLERP + linear root; hermite: velocity-matched; graph: key-pose guided (needs --action)")  # fmt: skip
    p.add_argument("--curve", choices=("linear", "ease", "smoothstep"), default="linear", help="α(k) curve")
    p.add_argument("--factor", type=float, default=4.0, help="Δ = factor × median frame distance (default 4)")
    p.add_argument("--threshold", type=float, default=None, help="absolute Δ instead of --factor")
    p.add_argument("--action", action="append", default=[], metavar="NAME=FILE.bvh",
                   help="an action node of the graph and a clip of it (repeat)")  # fmt: skip
    p.add_argument("--allow", action="append", default=[], metavar="'A -> B'",
                   help="an allowed transition (repeat; default: every pair of actions, both ways)")  # fmt: skip
    p.add_argument("--force", action="store_true", help="overwrite the output file if it exists")
    p.set_defaults(func=run_fill_gaps)


def _graph(actions: list[str], allow: list[str]):
    from motionlab.cli import CLIError
    from motionlab.core import bvh
    from motionlab.interpolation.action_graph import ActionGraph, GraphError

    if not actions:
        raise CLIError("--method graph needs at least one --action NAME=FILE.bvh")
    g = ActionGraph()
    for item in actions:
        if "=" not in item:
            raise CLIError(f"--action expects NAME=FILE.bvh, got {item!r}")
        name, path = item.split("=", 1)
        if not Path(path).is_file():
            raise CLIError(f"--action {name}: no such file {path!r}")
        g.add_node(name.strip(), bvh.load(path))
    try:
        if allow:
            g.allow(allow)
        else:
            names = list(g.nodes)
            g.allow([(a, b) for a in names for b in names if a != b])
    except GraphError as e:
        raise CLIError(str(e)) from None
    return g


def run_fill_gaps(args: argparse.Namespace) -> int:
    from motionlab.cli import CLIError
    from motionlab.core import bvh
    from motionlab.interpolation import gaps

    src, dst = Path(args.input), Path(args.output)
    if not src.is_file():
        raise CLIError(f"input file {src} does not exist")
    if dst.exists() and not args.force:
        raise CLIError(f"{dst} exists; pass --force to overwrite it")
    if dst.resolve() == src.resolve():
        raise CLIError("the output must not be the input file")
    try:
        motion = bvh.load(src)
    except bvh.BVHError as e:
        raise CLIError(str(e)) from None
    graph = _graph(args.action, args.allow) if args.method == "graph" else None
    missing = gaps.distance_gaps(motion, factor=args.factor, threshold=args.threshold)
    expanded, _ = gaps.insert_missing(motion, missing)
    try:
        filled, report = gaps.fill(expanded, method=args.method, graph=graph, curve=args.curve)
    except ValueError as e:
        raise CLIError(str(e)) from None
    bvh.save(dst, filled, overwrite=args.force)
    print(f"{src}: {motion.num_frames} frames at {motion.fps:g} fps")
    if not report:
        print("no dropped frames found (D > Δ nowhere); wrote an unchanged copy")
    else:
        total = sum(r.stop - r.start for r in report)
        print(f"filled {len(report)} gap(s), {total} frame(s) in all (method: {args.method}):")
        for r in report:
            print(f"  {r}")
    print(f"wrote {dst} ({filled.num_frames} frames)")
    return 0
