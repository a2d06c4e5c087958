"""``motionlab graph-build``, ``graph-search`` and ``graph-info``.

::

    motionlab graph-build FOLDER -o walk.mlgraph [--report walk.json] [--distance-threshold 0.04] [--force]
                          [--backend ray] [--verbose]
    motionlab graph-search walk.mlgraph --request "walk:angry:300,run:normal:200" -o out.bvh
    motionlab graph-info walk.mlgraph

Clip names must say behaviour and style, optionally a take (see
:mod:`motionlab.motion_graphs.naming`); takes of one style are pooled. With ``--synthetic`` the
built-in synthetic clips are used instead of a folder. ``graph-build`` prints the build report
(:mod:`.report`) and ``--report`` writes it as JSON; the graph and the report are written
together, both or neither. A request may ask for at most
:data:`~motionlab.motion_graphs.search.MAX_FRAMES` frames in all.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from pathlib import Path

from motionlab import cli_args
from motionlab.cli_args import CLIError, check_outputs, non_negative_int, positive, positive_int
from motionlab.motion_graphs.distance import DEFAULT_THRESHOLD

__all__ = ["register", "DISTANCE_THRESHOLD"]

DISTANCE_THRESHOLD = DEFAULT_THRESHOLD
"""Default ``--distance-threshold`` of ``graph-build``: the library's
:data:`~motionlab.motion_graphs.distance.DEFAULT_THRESHOLD` (metres RMS)."""


def register(subparsers) -> None:
    with cli_args.command(subparsers, "graph-build", _build) as p:
        p.add_argument("folder", nargs="?", help="folder of BVH files named Behaviour_style / B1_s1_to_B2_s2")
        cli_args.add_output(p, "graph file to write (.mlgraph)")
        p.add_argument("--synthetic", action="store_true", help="use the built-in synthetic clips instead of a folder")
        p.add_argument("--standard", action="store_true", help="build Kovar's unstructured graph instead")
        cli_args.renamed(
            p,
            "--threshold",
            p.add_argument(
                "--distance-threshold",
                dest="threshold",
                type=positive,
                default=DISTANCE_THRESHOLD,
                metavar="M",
                help=f"largest frame distance of a transition, metres RMS (default {DISTANCE_THRESHOLD:g})",
            ),
        )
        p.add_argument(
            "--fps", type=cli_args.frame_rate, default=30.0, help="frame rate every clip is resampled to (default 30)"
        )
        p.add_argument(
            "--style-pairs",
            choices=("hub", "chain", "all"),
            default="hub",
            help="styles bridged by interpolation spaces: each to a hub, a chain, or all pairs",
        )
        p.add_argument(
            "--neighbours", type=positive_int, default=3, help="takes each take of a style is compared with (default 3)"
        )
        p.add_argument("--name-map", help="JSON file {clip stem: 'behaviour_style[_take]'} for names that do not parse")
        p.add_argument(
            "--behaviour-folders",
            action="store_true",
            help="each subfolder holds one behaviour's clips and is named after it; a file name then gives the "
            "style and take (Xia et al.'s run/angry_13_000.bvh: run, angry, take 13-000)",
        )
        p.add_argument("--report", help="also write the build report as JSON to this file")
        p.add_argument(
            "--backend",
            choices=("local", "ray"),
            default="local",
            help="where the comparisons inside each style run: this process, or Ray tasks (RAY_ADDRESS or a local "
            "Ray instance; same graph)",
        )
        p.add_argument(
            "--workers",
            type=positive_int,
            default=2,
            help="threads of the local build, or CPUs of a local Ray instance",
        )
        p.add_argument(
            "--verbose", action="store_true", help="print the seconds and peak memory of every stage of the build"
        )
        cli_args.add_force(p, "overwrite the output files")

    with cli_args.command(subparsers, "graph-search", _search) as p:
        p.add_argument("graph", help=".mlgraph file from graph-build")
        p.add_argument(
            "--request",
            required=True,
            help='segments "behaviour:style:frames,...", e.g. "walk:angry:300,run:normal:200" '
            "(at most 100000 frames in all); a segment's frames include the recorded route out of it "
            "(a blend of two styles or a transition clip) into the next",
        )
        cli_args.add_output(p, "motion file to write: .bvh, or .glb for binary glTF 2.0")
        p.add_argument(
            "--blend", type=non_negative_int, default=8, help="transition blend length in frames (default 8)"
        )
        p.add_argument(
            "--keep-misses",
            action="store_true",
            help="write the nearest path even where a segment's count misses its request by more than 5%% or 2 frames",
        )
        cli_args.add_force(p, "overwrite the output file")

    with cli_args.command(subparsers, "graph-info", _info) as p:
        p.add_argument("graph", help=".mlgraph file")


def _load_graph(path: str, verify: bool = True):
    from motionlab.motion_graphs import graph, io

    try:
        return io.load(path, verify=verify)
    except graph.GraphError as e:
        raise CLIError(str(e)) from None


@contextmanager
def _verified(path: str):
    """The graph at ``path``, loaded without its arrays' CRC-32s, which a thread checks meanwhile
    (:func:`motionlab.motion_graphs.io.verify`, on another core while the caller searches); on
    leaving, the check is awaited, and a damaged file raises :class:`CLIError` before anything
    made from it is written (also when the work inside failed: the damage is the cause named)."""
    from motionlab.motion_graphs import graph, io

    with ThreadPoolExecutor(1) as pool:
        checked = pool.submit(io.verify, path)
        try:
            yield _load_graph(path, verify=False)
        finally:
            try:
                checked.result()
            except graph.GraphError as e:
                raise CLIError(str(e)) from None


def _build_outputs(args: argparse.Namespace) -> tuple[Path, Path | None]:
    """The graph file and the report file, checked before any work."""
    cli_args.check_replaceable("-o", args.output)
    out = Path(args.output)
    if out.is_dir():  # before '.mlgraph' is added: -o FOLDER must not write FOLDER.mlgraph beside it
        raise CLIError(f"-o {out} is a folder; expected a graph file name, such as {out / 'graph.mlgraph'}")
    if out.suffix == "":
        out = out.with_suffix(".mlgraph")
    if out.suffix.lower() in (".bvh", ".glb", ".json"):  # a motion or report name: the graph would be taken for one
        raise CLIError(
            f"-o {out} names a {out.suffix} file; a graph is written as .mlgraph, such as {out.with_suffix('.mlgraph')}"
        )
    if args.report and args.standard:
        raise CLIError("--report needs a structured graph (leave out --standard, or leave out --report)")
    if not args.synthetic and not args.folder:
        raise CLIError("give a FOLDER of BVH clips or --synthetic")
    if args.synthetic and args.folder:
        raise CLIError(f"give a FOLDER of BVH clips or --synthetic, not both (FOLDER {args.folder} and --synthetic)")
    inputs = [("--name-map", args.name_map)]
    if args.folder and Path(args.folder).is_dir():  # a --report named like a clip must not replace it
        from motionlab.core import files

        inputs += [("input clip", p) for p in files.bvh_files(args.folder, recursive=True)]
    out, rep = check_outputs([("-o", out), ("--report", args.report)], args.force, inputs=inputs)
    return out, rep


def _load_clips(args: argparse.Namespace) -> list:
    from motionlab.motion_graphs import clips
    from motionlab.motion_graphs.naming import NamingError

    name_map = None
    if args.name_map:
        try:
            name_map = json.loads(Path(args.name_map).read_text())
        except (OSError, json.JSONDecodeError, UnicodeDecodeError) as e:
            raise CLIError(f"--name-map {args.name_map}: cannot read it as JSON ({e})") from None
        if not isinstance(name_map, dict):
            raise CLIError(f"--name-map {args.name_map}: expected a JSON object {{clip stem: 'behaviour_style'}}")
    if args.synthetic:
        motions = clips.synthetic_library(fps=args.fps)
        print(f"using {len(motions)} synthetic clips (no real data)")
        return motions
    _check_folder_size(args.folder, args.fps)
    try:
        motions = clips.load_folder(
            args.folder, args.fps, name_map, progress=not args.quiet, behaviour_folders=args.behaviour_folders
        )
    except NamingError as e:
        raise CLIError(str(e)) from None
    skipped = clips.unlabelled_files(args.folder, name_map, args.behaviour_folders)
    if skipped:
        names = ", ".join(p.name for p in skipped[:5]) + (f" and {len(skipped) - 5} more" if len(skipped) > 5 else "")
        hint = "" if args.behaviour_folders else ", or --behaviour-folders where each subfolder holds one behaviour"
        try:
            clips.file_label(skipped[0], args.folder, name_map, args.behaviour_folders)
        except NamingError as e:
            hint += f". The first: {e}"
        print(
            f"skipped {len(skipped)} of {len(skipped) + len(motions)} BVH files whose names give no behaviour_style "
            f"label ({names}); --name-map labels them{hint} (motionlab.motion_graphs.naming)",
            file=sys.stderr,
        )
    return motions


def _header_seconds(path: Path) -> float:
    """A BVH file's length in seconds from its ``Frames:`` and ``Frame Time:`` lines (0 when unreadable)."""
    frames = None
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            for line in f:
                key, _, value = line.strip().partition(":")
                if key == "Frames":
                    frames = float(value)
                elif key == "Frame Time" and frames is not None:
                    return frames * float(value)
    except (OSError, ValueError):
        pass
    return 0.0


def _check_folder_size(folder: str, fps: float) -> None:
    """Refuse, before loading, a folder whose clips at ``--fps`` would be more frames than
    :func:`motionlab.cli_args.check_size` allows (read from the files' headers)."""
    from motionlab.core import files

    folder_path = Path(folder)
    if folder_path.is_dir():
        seconds = sum(_header_seconds(p) for p in files.bvh_files(folder_path, recursive=True))
        cli_args.check_size(f"--fps {fps:g} over the {seconds:.0f} s of clips in {folder}", seconds * fps, 22)


def _build_graph(args: argparse.Namespace, motions: list):
    from motionlab.motion_graphs import distance, graph, structured
    from motionlab.motion_graphs.naming import parse_name

    thr = distance.threshold_from(args.threshold)
    try:
        if args.standard:
            labels = [parse_name(m.name) for m in motions]
            infos = [
                graph.ClipInfo(m.name, "clip", *(lab.key if lab.kind == "basic" else (None, None)))
                for m, lab in zip(motions, labels)
            ]
            return graph.build_standard(motions, thr, infos=infos)
        return structured.build_structured(
            motions,
            thr,
            style_pairs=args.style_pairs,
            synthetic=[args.synthetic] * len(motions),
            neighbours=args.neighbours,
            progress=not args.quiet,
            backend=args.backend,
            workers=args.workers,
        )
    except graph.GraphError as e:
        raise CLIError(str(e)) from None
    except ImportError as e:  # --backend ray without Ray: the message says how to install it
        raise CLIError(str(e)) from None


def _build(args: argparse.Namespace) -> int:
    """build a motion graph from a folder of BVH clips

    Build a structured motion graph (behaviours, styles, takes, recorded transition clips and interpolation spaces
    between styles) or, with --standard, Kovar's graph, from a folder of BVH clips; write it to a .mlgraph file and
    print its structure table.
    """
    from motionlab.core import files
    from motionlab.motion_graphs import io, report

    out, report_path = _build_outputs(args)
    if args.standard and args.backend != "local":
        raise CLIError("--backend ray builds structured graphs only (leave out --standard)")
    clock = report.StageClock()
    with clock("load"):
        motions = _load_clips(args)
    t0 = time.perf_counter()
    g = _build_graph(args, motions)
    dt = time.perf_counter() - t0
    if not g.alive.any():
        raise CLIError(
            f"pruning left none of the {g.num_frames} frames of the {len(motions)} clips alive (no cycle of "
            f"transitions joins them at --fps {args.fps:g}): the graph could play nothing; raise --fps or --distance-threshold"
        )
    clock.extend(g.info.get("stages", []))
    g.info["input_clips"] = len(motions)
    with clock("report"):
        rep = report.build_report(g) if g.table.get("behaviours") else None
        s = g.summary()
    outputs = [(out, io.writer(g, s), True, "graph (-o)")]
    if report_path is not None:
        if rep is None:
            raise CLIError("--report needs a structured graph, and these clips gave none; leave out --report")
        outputs.append((report_path, lambda f: f.write(report.to_json(rep)), False, "report (--report)"))
    with clock("save"):
        files.atomic_write_all(outputs, overwrite=args.force)  # both files or neither
    styles = sum(len(v) for v in g.table.get("behaviours", {}).values())
    n_trans = sum(c.kind == "transition" for c in g.clips)
    pooled = f" ({len(motions) - n_trans} takes of {styles} styles, {n_trans} transition clips)" if styles else ""
    print(
        f"built {g.info['kind']} graph from {len(motions)} clips{pooled} in {dt:.2f} s: {_alive_text(g)}, "
        f"{s['transitions']} transitions -> {out}"
    )
    if rep is not None:
        print(report.format_report(rep))
        if report_path is not None:
            print(f"report -> {report_path}")
    else:
        print(f"largest strongly connected component: {s['largest_scc']} frames")
    if args.verbose:
        print(report.format_stages(clock.rows))
    return 0


def _alive_text(g) -> str:
    """Alive frames, the recorded clips' apart from those of the clips the build made (interpolation)."""
    import numpy as np

    made = np.array([c.kind == "intermediate" for c in g.clips], dtype=bool)[g.clip_of(np.arange(g.num_frames))]
    text = f"{int(g.alive[~made].sum())} of {int((~made).sum())} recorded frames alive"
    if made.any():
        clips = sum(c.kind == "intermediate" for c in g.clips)
        text += f" (and {int(g.alive[made].sum())} frames of {clips} clips made between styles)"
    return text


def _search(args: argparse.Namespace) -> int:
    """synthesise a motion for a request from a graph

    Search a graph from graph-build for a path that meets a request of behaviour, style and frame count per segment,
    and write the synthesised motion as BVH or, when OUTPUT ends in .glb, binary glTF 2.0.
    """
    from motionlab.core import motion_files
    from motionlab.motion_graphs import search, synthesis

    cli_args.motion_output("-o", args.output)
    (out,) = check_outputs([("-o", args.output)], args.force, inputs=[("graph", args.graph)])
    try:
        segs = search.parse_request(args.request)
    except search.RequestTooLong as e:
        raise CLIError(
            f"--request asks for {e.total} frames in all; at most {search.MAX_FRAMES} frames are accepted "
            "(about 55 minutes at 30 fps): split it into several graph-search runs"
        ) from None
    except ValueError as e:
        raise CLIError(f"--request: {e}") from None
    with _verified(args.graph) as g:
        try:
            t0 = time.perf_counter()
            if g.table.get("behaviours"):
                result = search.search(g, segs, progress=not args.quiet)
            else:
                result = search.search_standard(g, segs)
            dt = time.perf_counter() - t0
        except search.SearchError as e:
            raise CLIError(str(e)) from None
        _check_misses(result, args.keep_misses)
        motion = synthesis.synthesize(g, result.pieces, blend=args.blend)
    motion_files.save(out, motion, overwrite=args.force, unit=motion_files.file_unit(motion.skeleton))
    print(f"found a {result.num_frames}-frame path ({len(result.pieces)} pieces) in {dt * 1000:.1f} ms -> {out}")
    print(result.report())
    return 0


def _check_misses(result, keep: bool) -> None:
    """Refuse a path whose segments miss their counts by more than the tolerance, unless ``keep``."""
    from motionlab.motion_graphs import search

    misses = result.misses
    if not misses:
        return
    text = "; ".join(
        f"{s.behaviour}:{s.style} asks for {s.frames} frames, and the nearest walk this graph has gives {a} "
        f"(±{search.tolerance_frames(s.frames)} allowed)"
        for k, (s, a) in enumerate(zip(result.segments, result.achieved))
        if k in misses
    )
    if not keep:
        raise CLIError(f"{text}; ask for other counts, or --keep-misses writes the nearest path anyway")
    print(f"warning: {text}; written as asked by --keep-misses", file=sys.stderr)


def _info(args: argparse.Namespace) -> int:
    """print a graph's structure table and counts

    Print the structure table (behaviours, styles, frames) and the counts of a .mlgraph file.
    """
    from motionlab.motion_graphs import graph, io, plots

    g = _load_graph(args.graph)
    print(plots.structure_table_text(g))
    try:
        summary = io.read_meta(args.graph).get("summary") or g.summary()  # version 2 files hold none
    except graph.GraphError as e:
        raise CLIError(str(e)) from None
    print(json.dumps(summary, indent=1))
    return 0
