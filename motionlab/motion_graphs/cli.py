"""``motionlab graph-build``, ``graph-search`` and ``graph-info``.

::

    motionlab graph-build FOLDER -o walk.mlgraph [--report walk.json] [--threshold 0.03] [--force]
    motionlab graph-search walk.mlgraph --request "walk:angry:300,run:normal:200" -o out.bvh
    motionlab graph-info walk.mlgraph

Clip names must say behaviour and style, optionally a take (see
:mod:`motionlab.motion_graphs.naming`); takes of one style are pooled. With ``--synthetic`` the
built-in synthetic clips are used instead of a folder. ``graph-build`` prints the build report
(:mod:`.report`) and ``--report`` writes it as JSON. A request may ask for at most
:data:`~motionlab.motion_graphs.search.MAX_FRAMES` frames in all.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from motionlab.cli import CLIError

__all__ = ["register"]


def register(subparsers) -> None:
    p = subparsers.add_parser("graph-build", help="build a motion graph from a folder of BVH clips")
    p.add_argument("folder", nargs="?", help="folder of BVH files named Behaviour_style / B1_s1_to_B2_s2")
    p.add_argument("-o", "--output", required=True, help="graph file to write (.mlgraph)")
    p.add_argument("--synthetic", action="store_true", help="use the built-in synthetic clips instead of a folder")
    p.add_argument("--standard", action="store_true", help="build Kovar's unstructured graph instead")
    p.add_argument("--threshold", type=float, default=0.03, help="transition threshold, metres RMS (default 0.03)")
    p.add_argument("--fps", type=float, default=30.0, help="frame rate every clip is resampled to (default 30)")
    p.add_argument(
        "--style-pairs", choices=("hub", "chain", "all"), default="hub", help="styles bridged by interpolation"
    )
    p.add_argument("--neighbours", type=int, default=3, help="takes each take of a style is compared with (default 3)")
    p.add_argument("--name-map", help="JSON file {clip stem: 'behaviour_style[_take]'} for names that do not parse")
    p.add_argument("--report", help="also write the build report as JSON to this file")
    p.add_argument("--force", action="store_true", help="overwrite the output files")
    p.set_defaults(func=_build)

    p = subparsers.add_parser("graph-search", help="synthesise a motion for a request from a graph")
    p.add_argument("graph", help=".mlgraph file from graph-build")
    p.add_argument(
        "--request",
        required=True,
        help='segments "behaviour:style:frames,...", e.g. "walk:angry:300,run:normal:200" '
        "(at most 100000 frames in all)",
    )
    p.add_argument("-o", "--output", required=True, help="BVH file to write")
    p.add_argument("--blend", type=int, default=8, help="transition blend length in frames (default 8)")
    p.add_argument("--force", action="store_true", help="overwrite the output file")
    p.set_defaults(func=_search)

    p = subparsers.add_parser("graph-info", help="print a graph's structure table and counts")
    p.add_argument("graph", help=".mlgraph file")
    p.set_defaults(func=_info)


def _load_graph(path: str):
    from motionlab.motion_graphs import graph, io

    try:
        return io.load(path)
    except graph.GraphError as e:
        raise CLIError(str(e)) from None


def _build(args: argparse.Namespace) -> int:
    from motionlab.motion_graphs import clips, distance, graph, io, report, structured
    from motionlab.motion_graphs.naming import NamingError, parse_name

    out = Path(args.output)
    if out.suffix == "":
        out = out.with_suffix(".mlgraph")
    if out.exists() and not args.force:
        raise CLIError(f"{out} exists; pass --force to overwrite it")
    if args.report and Path(args.report).exists() and not args.force:
        raise CLIError(f"--report {args.report} exists; pass --force to overwrite it")
    if args.threshold <= 0:
        raise CLIError(f"--threshold must be positive metres, got {args.threshold}")
    if args.neighbours < 1:
        raise CLIError(f"--neighbours must be at least 1, got {args.neighbours}")
    name_map = None
    if args.name_map:
        try:
            name_map = json.loads(Path(args.name_map).read_text())
        except (OSError, json.JSONDecodeError) as e:
            raise CLIError(f"cannot read name map {args.name_map}: {e}") from None
    if args.synthetic:
        motions = clips.synthetic_library(fps=args.fps)
        print(f"using {len(motions)} synthetic clips (no real data)")
    else:
        if not args.folder:
            raise CLIError("give a FOLDER of BVH clips or --synthetic")
        try:
            motions = clips.load_folder(args.folder, args.fps, name_map, progress=True)
        except NamingError as e:
            raise CLIError(str(e)) from None
    thr = distance.threshold_from(args.threshold)
    t0 = time.perf_counter()
    try:
        if args.standard:
            labels = [parse_name(m.name) for m in motions]
            infos = [
                graph.ClipInfo(m.name, "clip", *(lab.key if lab.kind == "basic" else (None, None)))
                for m, lab in zip(motions, labels)
            ]
            g = graph.build_standard(motions, thr, infos=infos)
        else:
            g = structured.build_structured(
                motions,
                thr,
                style_pairs=args.style_pairs,
                synthetic=[args.synthetic] * len(motions),
                neighbours=args.neighbours,
                progress=True,
            )
    except graph.GraphError as e:
        raise CLIError(str(e)) from None
    dt = time.perf_counter() - t0
    g.info["input_clips"] = len(motions)
    io.save(out, g, overwrite=args.force)
    s = g.summary()
    styles = sum(len(v) for v in g.table.get("behaviours", {}).values())
    n_trans = sum(c.kind == "transition" for c in g.clips)
    pooled = f" ({len(motions) - n_trans} takes of {styles} styles, {n_trans} transition clips)" if styles else ""
    print(
        f"built {g.info['kind']} graph from {len(motions)} clips{pooled} in {dt:.2f} s: {s['alive']} frames alive, "
        f"{s['transitions']} transitions -> {out}"
    )
    if g.table.get("behaviours"):
        rep = report.build_report(g)
        print(report.format_report(rep))
        if args.report:
            report.write_report(args.report, rep, overwrite=args.force)
            print(f"report -> {args.report}")
    else:
        print(f"largest strongly connected component: {s['largest_scc']} frames")
        if args.report:
            raise CLIError("--report needs a structured graph (leave out --standard)")
    return 0


def _search(args: argparse.Namespace) -> int:
    from motionlab.core import bvh
    from motionlab.motion_graphs import search, synthesis

    out = Path(args.output)
    if out.exists() and not args.force:
        raise CLIError(f"{out} exists; pass --force to overwrite it")
    try:
        segs = search.parse_request(args.request)
    except ValueError as e:
        raise CLIError(f"--request: {e}") from None
    g = _load_graph(args.graph)
    try:
        t0 = time.perf_counter()
        if g.table.get("behaviours"):
            result = search.search(g, segs, progress=True)
        else:
            result = search.search_standard(g, segs)
        dt = time.perf_counter() - t0
    except search.SearchError as e:
        raise CLIError(str(e)) from None
    motion = synthesis.synthesize(g, result.pieces, blend=args.blend)
    bvh.save(out, motion, overwrite=args.force)
    print(f"found a {result.num_frames}-frame path ({len(result.pieces)} pieces) in {dt * 1000:.1f} ms -> {out}")
    print(result.report())
    return 0


def _info(args: argparse.Namespace) -> int:
    from motionlab.motion_graphs import plots

    g = _load_graph(args.graph)
    print(plots.structure_table_text(g))
    print(json.dumps(g.summary(), indent=1))
    return 0
