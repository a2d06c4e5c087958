"""``motionlab fill-gaps``: find dropped frames in a BVH file and fill them.

Examples::

    motionlab fill-gaps take.bvh -o take_filled.bvh
    motionlab fill-gaps take.bvh -o out.bvh --method hermite --delta 3
    motionlab fill-gaps take_007.bvh -o out.bvh --takes take_001.bvh --takes take_002.bvh
    motionlab fill-gaps session/take_007.bvh -o out.bvh --takes session/
    motionlab fill-gaps take.bvh -o out.bvh --times take_times.txt
    motionlab fill-gaps take.bvh -o out.bvh --method graph \\
        --action run=Running.bvh --action walk=Walk.bvh --action stand=Idle.bvh \\
        --allow "run -> walk" --allow "walk -> stand"

Dropped frames are found with the ``D > Δ`` rule of :mod:`motionlab.interpolation.detect`: against
the action graph when ``--action`` clips are given (the stream tracked in the graph, §3.3), else
against the stream's own neighbouring steps. The missing count is estimated from the motion on
both sides (ground speed, travel direction, step phase) and, with ``--takes``, also from how long
other recordings of the action need between the poses at the gap's ends (the two averaged,
:mod:`motionlab.interpolation.recorded`); the frames are inserted and filled: by
default the whole body continues the recorded strides on both sides across the gap
(:mod:`motionlab.interpolation.stride`); where the motion does not repeat, or where SLERP fills
cuts of the gap's size near it better (:func:`motionlab.interpolation.gaps.fill`), SLERP with the root
given by ``--gap-root`` (``stride``: the strides' root path where one side repeats, else ``hermite``,
a Hermite curve with the velocities on both sides; ``linear``: the LaFAN1 baseline).
Where the capture logged each frame's time, ``--times FILE`` (one time in seconds per frame,
:func:`motionlab.interpolation.gaps.load_times`) gives the gaps and their counts exactly
(:func:`~motionlab.interpolation.gaps.timestamp_gaps`): no rule, no estimate. The times are
checked against the file's ``Frame Time`` first: times in another unit (milliseconds), times of
which no step is one Frame Time within :data:`RATE_AGREEMENT` and whose median step is not either
(another take's or rate's), or ones that would make the clip more than :data:`MAX_GROWTH` times
longer, are refused; the counts are read in the times' own frame period (the median of their
steps of one Frame Time). Without
``--times`` the counts are estimates (the motion cannot say how fast the body moved inside a gap),
and a warning on stderr says so, with the range each count is likely in
(:func:`motionlab.interpolation.detect.estimate_counts`) and, where too few frames beside a gap
let the range try longer gaps and it reaches the longest it could, the sizes it could not try.
A clean clip (nothing found) is copied byte for byte. A report lists every gap and how it was
filled.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from motionlab import cli_args
from motionlab.cli_args import CLIError, Stages

__all__ = ["register", "run_fill_gaps"]


def register(subparsers) -> None:
    with cli_args.command(subparsers, "fill-gaps", run_fill_gaps) as p:
        p.add_argument("input", help="BVH file with dropped frames")
        cli_args.add_output(p, "where to write the filled motion: .bvh, or .glb for binary glTF 2.0")
        p.add_argument("--method", choices=("stride", "slerp", "hermite", "graph"), default="stride",
                       help="stride: the strides on both sides continued (default; slerp where the motion does not "
                       "repeat or slerp fills cuts of the gap's size near it better); slerp: SLERP; hermite: "
                       "velocity-matched; graph: key-pose guided (needs --action)")  # fmt: skip
        p.add_argument("--curve", choices=("linear", "ease", "smoothstep"), default="linear",
                       help="α(k) curve of the blend weights across a gap")  # fmt: skip
        root = p.add_argument("--gap-root", dest="root", choices=("stride", "hermite", "linear"), default="stride",
                              help="root path across a gap: the strides on both sides continued (default; Hermite where "
                              "the motion does not repeat), Hermite with the velocities on both sides, or linear")  # fmt: skip
        cli_args.renamed(p, "--root", root)
        delta = p.add_argument("--delta", dest="delta", type=str, default=None, metavar="Δ",
                               help="Δ: a step this many times the typical step means dropped frames (a number above 1; "
                               "default 2.5, against the stream itself or, with --action, against the graph)")  # fmt: skip
        cli_args.renamed(p, "--threshold", delta)
        cli_args.renamed(p, "--factor", delta)
        p.add_argument("--action", action="append", default=[], metavar="NAME=FILE.bvh",
                       help="an action node of the graph and a clip of it (repeat)")  # fmt: skip
        p.add_argument("--allow", action="append", default=[], metavar="'A -> B'",
                       help="an allowed transition (repeat; default: every pair of actions, both ways)")  # fmt: skip
        p.add_argument("--takes", action="append", default=[], metavar="FILE.bvh|FOLDER",
                       help="another recording of the stream's action, or a folder of them (repeat; the input itself "
                       "is never used): the missing count also reads how long these take from the pose before a gap "
                       "to the pose after it; best with takes of the same session and style (docs/results_interpolation.md)")  # fmt: skip
        p.add_argument("--times", metavar="FILE", default=None,
                       help="the frames' capture times, one per line in seconds: the gaps and their counts are "
                       "read from them (exact), not detected or estimated")  # fmt: skip
        cli_args.add_force(p, "overwrite the output file if it exists")


def _graph(actions: list[str], allow: list[str], src: Path, motion):
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
        clip = bvh.load(path)
        _check_rig(f"--action {name}={path}", clip, src, motion)
        g.add_node(name.strip(), clip)
    try:
        if allow:
            g.allow(allow)
        else:
            names = list(g.nodes)
            g.allow([(a, b) for a in names for b in names if a != b])
    except GraphError as e:
        raise CLIError(str(e)) from None
    return g


def _takes(paths: list[str], src: Path, motion):
    """:class:`~.recorded.RecordedTakes` of the ``--takes`` files (none of them the input), each on
    the input ``motion``'s skeleton and frame rate."""
    from motionlab.core import bvh
    from motionlab.core.files import bvh_files
    from motionlab.interpolation.recorded import RecordedTakes

    files = []
    for path in paths:
        p = Path(path)
        if p.is_dir():  # a session's folder: every take in it but the input
            found = [f for f in bvh_files(p) if f.resolve() != src.resolve()]
            if not found:
                raise CLIError(f"--takes {path}: a folder without BVH files (other than the input)")
            files += found
            continue
        if not p.is_file():
            raise CLIError(f"--takes: no such file or folder {path!r}")
        if p.resolve() == src.resolve():
            raise CLIError(f"--takes {path}: the input itself cannot be one of the other recordings")
        files.append(p)
    clips = []
    unique: dict[Path, Path] = {}
    for f in files:  # a take named twice (a file and its folder) counts once
        unique.setdefault(f.resolve(), f)
    for p in unique.values():
        try:
            clips.append(bvh.load(p))
        except bvh.BVHError as e:
            raise CLIError(f"--takes {p}: {e}") from None
        _check_rig(f"--takes {p}", clips[-1], src, motion)
        _check_rate(p, clips[-1], src, motion)
    try:
        return RecordedTakes(clips)
    except ValueError as e:
        raise CLIError(f"--takes: {e}") from None


def _check_rig(what: str, clip, src: Path, motion) -> None:
    """Refuse a clip (``what``: the option and file that named it) on another rig than the input."""

    if tuple(clip.skeleton.names) != tuple(motion.skeleton.names):
        sk, mine = clip.skeleton, motion.skeleton
        raise CLIError(
            f"{what}: another rig than the input {src} (root {sk.names[0]!r}, {sk.num_joints} joints; "
            f"the input: root {mine.names[0]!r}, {mine.num_joints} joints); give clips recorded on the input's rig"
        )


def _check_rate(path: Path, take, src: Path, motion) -> None:
    """Refuse a ``--takes`` file at another frame rate than the input."""

    if abs(take.fps - motion.fps) > 1e-6 * motion.fps:
        raise CLIError(
            f"--takes {path} is at {take.fps:g} fps, the input {src} at {motion.fps:g} fps; give takes at "
            f"{motion.fps:g} fps (`motionlab convert {path} -o OUT.bvh --fps {motion.fps:g}` resamples one)"
        )


PROGRESS_FRAMES = 2000
"""Inputs of at least this many frames show a progress bar of the stages (unless ``--quiet``)."""

MAX_GROWTH = 10
"""``--times`` may at most make the clip this many times longer: more means wrong times."""

RATE_AGREEMENT = 0.01
"""``--times`` must step one Frame Time within this fraction (the median of the steps that do, or
of all steps where none does): NTSC's 29.97 fps is 0.1 % from 30, and the nearest two common
rates, 24 and 25 fps, are 4 % apart."""


def _times_gaps(path: str, src: Path, motion) -> list[tuple[int, int]]:
    """The gaps ``(after frame i, count)`` that the ``--times`` file gives, checked against the
    input's Frame Time (times in another unit than seconds are refused, never filled)."""
    import numpy as np

    from motionlab.interpolation import gaps

    try:
        times = gaps.load_times(path, motion.num_frames)
    except OSError as e:
        raise CLIError(f"--times: {e}") from None
    except ValueError as e:
        raise CLIError(f"--times: {e}") from None
    period = 1.0 / motion.fps
    steps = np.diff(times)
    one = steps[np.abs(steps / period - 1.0) <= RATE_AGREEMENT]  # the capture period where frames follow
    step = float(np.median(one if one.size else steps)) if len(times) > 1 else period
    units = {"milliseconds": 1e3, "microseconds": 1e6, "nanoseconds": 1e9}
    hint = next((f"; they look like {u}: divide them by {f:.0f}" for u, f in units.items()
                 if 0.5 <= step / period / f < 2.0), "")  # fmt: skip
    if hint:
        raise CLIError(
            f"--times {path}: consecutive times are {step:g} apart (median), but the Frame Time of {src} is "
            f"{period:g} s; expected one time per frame in seconds{hint}"
        )
    if abs(step / period - 1.0) > RATE_AGREEMENT:
        raise CLIError(
            f"--times {path}: consecutive times are {step:g} s apart (median; {1 / step:.4g} fps), but the Frame "
            f"Time of {src} is {period:g} s ({motion.fps:.4g} fps), and no two frames are one Frame Time apart; "
            f"expected one time per frame of this file, within {RATE_AGREEMENT:.0%}: are they the times of "
            "another take or rate?"
        )
    missing = gaps.timestamp_gaps(times, 1.0 / step)  # counted in the capture's own frame period
    added = sum(n for _, n in missing)
    if added > (MAX_GROWTH - 1) * motion.num_frames:
        raise CLIError(
            f"--times {path}: the times span {times[-1] - times[0]:g} s, {added} frames more than the "
            f"{motion.num_frames} in {src} (at most {MAX_GROWTH} times the recorded frames can be filled); "
            "check that the times are in seconds, one per frame"
        )
    return missing


def _copy(src: Path, dst: Path, motion, force: bool) -> None:
    """Copy ``src`` to ``dst`` byte for byte, atomically (a ``.glb`` output: ``motion`` written as glTF)."""
    from motionlab.core import files, motion_files

    if dst.suffix.lower() != ".bvh":
        motion_files.save(dst, motion, overwrite=force, unit=motion_files.file_unit(motion.skeleton), what="-o file")
        return
    data = src.read_bytes()
    files.atomic_write(dst, lambda f: f.write(data), overwrite=force, binary=True, what="-o file")


def _check_args(args: argparse.Namespace):
    """``(delta, src, dst)`` after checking the options and every output before any work."""
    from motionlab.cli_args import check_outputs
    from motionlab.core import files
    from motionlab.interpolation import detect

    delta = None
    if args.delta is not None:
        try:
            delta = detect.check_delta(args.delta, name="--delta")
        except ValueError as e:
            raise CLIError(str(e)) from None
    if args.times is not None and (args.takes or delta is not None):
        raise CLIError(
            "--times gives the gaps and their counts, so --takes and --delta would not be used; "
            "give --times alone, or leave it out"
        )
    if args.allow and not args.action:
        raise CLIError("--allow names transitions between --action clips; give the --action NAME=FILE.bvh clips too")
    if args.action and args.times is not None and args.method != "graph":
        raise CLIError(
            "--action builds the action graph that finds the gaps (or, with --method graph, fills them); --times "
            "gives the gaps, so the graph would not be used: leave out --action, or add --method graph"
        )
    src = files.check_input(args.input)
    inputs = [("input", src), ("--times", args.times)] + [("--takes", t) for t in args.takes]
    inputs += [("--action", a.split("=", 1)[1]) for a in args.action if "=" in a]
    cli_args.motion_output("-o", args.output)
    (dst,) = check_outputs([("-o", args.output)], args.force, inputs=inputs)
    return delta, src, dst


SHOWN_RANGES = 5
"""How many gaps' count ranges the warning of an estimated count lists by name."""


def _range_words(c) -> str:
    """A count's range in words, and the sizes it could not try (:class:`~.detect.MissingCount`)."""
    words = f"likely {c.low} to {c.high}"
    if c.untried is not None:
        words += f"; gaps of {c.untried} or more frames could not be tried beside it"
    return words


def _warn_estimated(src, counted) -> None:
    """On stderr: the missing counts were estimated from the motion, each with the range it is
    likely in (:func:`motionlab.interpolation.detect.estimate_counts`), and how to get them exact.
    ``counted``: ``(after frame t, MissingCount)`` pairs; past :data:`SHOWN_RANGES` of them, how many
    more, and how many of those have sizes their range could not try."""
    if not counted:
        return
    shown = [f"{c.count} frames after frame {t} ({_range_words(c)})" for t, c in counted[:SHOWN_RANGES]]
    if len(counted) > SHOWN_RANGES:
        rest = [c for _, c in counted[SHOWN_RANGES:]]
        opened = sum(c.untried is not None for c in rest)
        shown.append(
            f"and {len(rest)} more gaps" + (f" ({opened} with sizes that could not be tried)" if opened else "")
        )
    print(
        f"warning: {src}: how many frames are missing is estimated from the motion, which cannot tell it "
        f"exactly: {', '.join(shown)}; pass --times FILE (the capture's frame times) for exact counts",
        file=sys.stderr,
    )


def run_fill_gaps(args: argparse.Namespace) -> int:
    """detect dropped frames in a BVH file and fill them (SLERP, Hermite or action-graph guided)

    Detect frames missing from a BVH stream (distance D > Δ between consecutive frames), insert the estimated number
    of frames and fill them.

    Raises
    ------
    CLIError carrying the message of a BVH file that cannot be read or of a value the fill
    refuses.
    """
    from motionlab.core import bvh, motion_files
    from motionlab.interpolation import detect, gaps

    delta, src, dst = _check_args(args)
    try:
        motion = bvh.load(src)
    except bvh.BVHError as e:
        raise CLIError(str(e)) from None
    bar = Stages(("find gaps", "fill", "write"), "fill-gaps", disable=args.quiet or motion.num_frames < PROGRESS_FRAMES)
    bar.start("find gaps")
    graph = _graph(args.action, args.allow, src, motion) if args.method == "graph" or args.action else None
    if args.times is not None:
        missing = _times_gaps(args.times, src, motion)
    else:
        takes = _takes(args.takes, src, motion) if args.takes else None
        try:
            counted = detect.detect_counts(motion, graph=graph, delta=delta, takes=takes)
        except ValueError as e:
            raise CLIError(str(e)) from None
        missing = [(t, c.count) for t, c in counted]
        _warn_estimated(src, counted)
    if not args.quiet:
        print(f"{src}: {motion.num_frames} frames at {motion.fps:g} fps")
    used = detect.DELTA if delta is None else delta
    nothing = (
        f"no dropped frames in the times of {args.times}"
        if args.times
        else f"no dropped frames found (D > Δ = {used:g} nowhere; one dropped frame doubles a step, D about 2, "
        "which only a --delta below 2 flags, fast motion too; --times FILE gives every gap exactly)"
    )
    if not missing:
        bar.close()
        _copy(src, dst, motion, args.force)
        print(f"{nothing}; wrote an unchanged copy")
        if not args.quiet:
            print(f"wrote {dst} ({motion.num_frames} frames)")
        return 0
    bar.start("fill")
    expanded, _ = gaps.insert_missing(motion, missing)
    try:
        filled, report = gaps.fill(expanded, method=args.method, graph=graph, curve=args.curve, root=args.root)
    except ValueError as e:
        raise CLIError(str(e)) from None
    bar.start("write")
    motion_files.save(dst, filled, overwrite=args.force, unit=motion_files.file_unit(motion.skeleton))
    bar.close()
    if not report:
        print(f"{nothing}; wrote an unchanged copy")
    else:
        total = sum(r.stop - r.start for r in report)
        print(f"filled {len(report)} gap(s), {total} frame(s) in all (method: {args.method}):")
        for r in report:
            print(f"  {r}")
    if not args.quiet:
        print(f"wrote {dst} ({filled.num_frames} frames)")
    return 0
