"""``motionlab view``: play a BVH file in a 3D window, or write it to a movie.

Examples::

    motionlab view $MOTIONLAB_DATA/mixamo/Aj/Running.bvh                 # window (needs a display)
    motionlab view Running.bvh -o running.mp4 --camera follow          # movie, off-screen
    motionlab view Running.bvh -o running.gif --size 480x360 --force   # replace an old GIF

Without a display, ``-o`` is needed (nothing is written that was not asked for). Existing
files are never overwritten without ``--force``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from motionlab import cli_args
from motionlab.cli_args import CLIError, check_outputs, non_negative_int, positive, positive_int, rig_error

__all__ = ["register"]


MAX_SIZE = 4096
"""Largest picture side in pixels: what an off-screen OpenGL framebuffer gives everywhere
(larger ones abort the renderer instead of failing)."""


def _size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT in pixels (e.g. 640x480), got {text!r}") from None
    if not (16 <= width <= MAX_SIZE and 16 <= height <= MAX_SIZE):
        raise argparse.ArgumentTypeError(f"expected 16 to {MAX_SIZE} pixels a side, got {text!r}")
    return width, height


def _open_window(scene) -> None:
    """Interactive window: a frame slider, space bar plays/pauses, the clip loops."""
    state = {"playing": True, "frame": 0}
    slider = {}

    def on_slider(value: float) -> None:
        state["frame"] = int(round(value))
        scene.set_frame(state["frame"])

    def on_tick(_step: int) -> None:
        if state["playing"]:
            state["frame"] = (state["frame"] + 1) % scene.num_frames
            scene.set_frame(state["frame"], render=False)
            if "widget" in slider:
                slider["widget"].GetRepresentation().SetValue(state["frame"])
            scene.plotter.render()

    def toggle() -> None:
        state["playing"] = not state["playing"]

    slider["widget"] = scene.plotter.add_slider_widget(
        on_slider,
        [0, scene.num_frames - 1],
        value=0,
        title="frame (space: play/pause)",
        pointa=(0.35, 0.08),
        pointb=(0.95, 0.08),
        style="modern",
        fmt="%.0f",
        interaction_event="always",
    )
    scene.plotter.add_key_event("space", toggle)
    scene.plotter.add_timer_event(max_steps=10**9, duration=max(int(1000 / scene.fps), 10), callback=on_tick)
    scene.show(title="motionlab view")


def _cmd_view(args) -> int:
    """play a BVH file in 3D, or write it to an MP4/GIF movie

    Play FILE.bvh in a 3D window (where a display exists) or render it off-screen to a movie with -o (needed where
    there is no display). Foot contacts light up red.
    """
    from motionlab.core import bvh, files, motion_files
    from motionlab.viz import backend
    from motionlab.viz.export import MOVIE_SUFFIXES, save_movie
    from motionlab.viz.scene import Scene

    source = files.check_input(args.file, "BVH")
    out = Path(args.output) if args.output else None
    if out is None and not backend.has_display():  # never write into the current folder unasked
        raise CLIError(
            f"no display found to open a window for {source}; write a movie instead with -o {source.stem}.mp4"
        )
    if out is not None:
        if out.suffix.lower() not in MOVIE_SUFFIXES:
            raise CLIError(f"-o must end in .mp4 or .gif, got {str(out)!r}")
        check_outputs([("-o", args.output)], args.force, inputs=[("input", source)])
    try:
        motion = bvh.load(source, scale=args.unit_scale or bvh.DEFAULT_SCALE)
    except bvh.BVHError as e:
        raise CLIError(str(e)) from None
    if motion.num_frames == 0:
        raise CLIError(f"{source} has no frames to play (its MOTION block says Frames: 0)")
    if args.unit_scale is None:
        motion = motion_files.in_metres(motion, motion_files.file_unit(motion.skeleton))
    if args.canonical:
        from motionlab.core import humanoid

        try:
            motion = humanoid.to_canonical(motion)
        except humanoid.RigMappingError as e:
            raise rig_error(e, "input", source) from None
    if args.start or args.stop is not None:
        motion = _frames(motion, args.start, args.stop, source)
    trails = tuple(t for t, on in (("root", not args.no_trail), ("feet", args.feet_trails)) if on)
    options = dict(camera=args.camera, window_size=args.size, trails=trails, contacts=not args.no_contacts)
    if out is None:
        scene = Scene(motion, off_screen=False, **options)
        _open_window(scene)
        return 0
    try:
        backend.import_pyvista()
    except backend.RenderingUnavailable as e:
        raise CLIError(str(e)) from None
    start = time.perf_counter()
    kwargs = {"stride": args.stride} if args.stride else {}
    save_movie(motion, out, overwrite=args.force, off_screen=True, anti_aliasing=args.smooth, **kwargs, **options)
    seconds = time.perf_counter() - start
    frames, length = _movie_length(out, motion, args.stride)
    if not args.quiet:
        print(
            f"wrote {out}: {frames} frames, {length:.2f} s of {motion.name or source.name} "
            f"({motion.num_frames} frames at {motion.fps:g} fps; rendered in {seconds:.1f} s)"
        )
    return 0


def _frames(motion, start: int, stop: int | None, source: Path):
    """Frames ``start`` up to ``stop`` (``None``: the end) of ``motion``, or a CLIError naming the options."""
    if start >= motion.num_frames:
        raise CLIError(f"--start {start} is past the last frame of {source} ({motion.num_frames} frames: 0 to "
                     f"{motion.num_frames - 1})")  # fmt: skip
    if stop is not None and stop <= start:
        raise CLIError(f"--stop {stop} must be after --start {start}")
    return motion[start:stop]


def _movie_length(out: Path, motion, stride: int | None) -> tuple[int, float]:
    """``(frames, seconds)`` of the movie written: read from a GIF, from the stride for an MP4."""
    from motionlab.viz.export import gif_length

    if out.suffix.lower() == ".gif":
        return gif_length(out)
    frames = len(range(0, motion.num_frames, stride or 1))
    return frames, frames * (stride or 1) / motion.fps


def register(subparsers) -> None:
    """Add ``view`` to the ``motionlab`` command."""
    with cli_args.command(subparsers, "view", _cmd_view) as p:
        p.add_argument("file", help="BVH file to play")
        cli_args.renamed(
            p,
            "--out",
            cli_args.add_output(
                p, "write a movie instead of opening a window (.mp4 or .gif)", required=False, metavar="MOVIE"
            ),
        )
        cli_args.add_force(p, "overwrite an existing movie")
        p.add_argument(
            "--camera",
            choices=("follow", "frame"),
            default="follow",
            help="follow the character (default) or frame the whole clip from one place",
        )
        p.add_argument(
            "--size", type=_size, default=(640, 480), metavar="WxH", help="picture size in pixels (default 640x480)"
        )
        cli_args.renamed(
            p,
            "--scale",
            p.add_argument(
                "--unit-scale",
                type=positive,
                default=None,
                help="BVH units to metres (default: the rig profile's unit, CMU's for CMU and Xia rigs, else 0.01 for "
                "centimetres)",
            ),
        )
        p.add_argument("--start", type=non_negative_int, default=0, help="first frame")
        p.add_argument(
            "--stop", type=positive_int, default=None, help="frame to stop before, 1 or more (default: the end)"
        )
        p.add_argument(
            "--stride", type=positive_int, default=None, help="movie: keep every N-th frame (GIF default: ~15 fps)"
        )
        p.add_argument("--canonical", action="store_true", help="show the 22-joint humanoid instead of the full rig")
        p.add_argument("--no-trail", action="store_true", help="do not draw the root's path on the ground")
        p.add_argument("--feet-trails", action="store_true", help="draw the feet's paths")
        p.add_argument("--no-contacts", action="store_true", help="do not highlight foot contacts")
        p.add_argument("--smooth", action="store_true", help="anti-aliased movie (slower in software rendering)")
