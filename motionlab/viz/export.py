"""Off-screen export: GIF and MP4 movies, PNG snapshots and film strips.

Every function takes a Motion, a list of Motions (drawn side by side only if you pass
``offsets``; see :mod:`motionlab.viz.compare` for a ready layout) or an existing
:class:`~motionlab.viz.scene.Scene`, renders off-screen and never overwrites a file unless
``overwrite=True``. The camera follows the characters by default (``camera="follow"``), so a
walker never leaves the frame; ``camera="frame"`` keeps one view of the whole clip instead.

* GIF: frames are reduced to one shared 128-colour palette (fast, no flicker) and written by
  Pillow; GIF timing is in 1/100 s, so the default keeps about 15 frames per second.
* MP4: H.264 through the ffmpeg binary of ``imageio-ffmpeg`` (no system ffmpeg needed).

Taught in ``notebooks/04_playback_and_bone_proportions.ipynb``.
"""

from __future__ import annotations

import io
import os
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from motionlab.core.motion import Motion
from motionlab.viz.scene import Scene, build_scene

__all__ = [
    "render_frames",
    "save_gif",
    "save_mp4",
    "save_movie",
    "snapshot",
    "filmstrip",
    "to_png",
    "gif_length",
    "gif_durations",
    "GIF_MIN_DELAY",
    "MOVIE_SUFFIXES",
]

MOVIE_SUFFIXES = (".gif", ".mp4")


def _target(path, suffixes: Sequence[str], overwrite: bool) -> Path:
    path = Path(os.fspath(path)).expanduser()
    if path.suffix.lower() not in suffixes:
        raise ValueError(f"expected a file name ending in {' or '.join(suffixes)}, got {str(path)!r}")
    if path.exists() and not overwrite:
        from motionlab.core import files

        raise FileExistsError(files.exists_message("output", path))
    if not path.parent.exists():
        raise FileNotFoundError(f"folder {path.parent} does not exist (writing {path.name})")
    return path


def _scene(motions, scene_options: dict) -> tuple[Scene, bool]:
    """The Scene to render and whether we made it (and so must close it)."""
    if isinstance(motions, Scene):
        return build_scene(motions, **scene_options), False
    scene_options = {"camera": "follow", "off_screen": True, **scene_options}
    return build_scene(motions, **scene_options), True


def _frame_indices(scene: Scene, stride: int, start: int, stop: int | None) -> range:
    if int(stride) < 1:
        raise ValueError(f"stride must be a positive integer, got {stride}")
    stop = scene.num_frames if stop is None else min(int(stop), scene.num_frames)
    if not 0 <= start < stop:
        raise ValueError(f"no frames between start={start} and stop={stop} (the scene has {scene.num_frames})")
    return range(int(start), stop, int(stride))


def render_frames(motions: Motion | Sequence[Motion] | Scene, frames: Sequence[int] | None = None, **scene_options):
    """Render frames off-screen; yields images (H, W, 3) uint8.

    Parameters
    ----------
    motions : Motion, list of Motions, or a Scene
    frames : frame indices (default: every frame)
    **scene_options : passed to :class:`~motionlab.viz.scene.Scene` (camera, window_size, ...)
    """
    scene, own = _scene(motions, scene_options)
    try:
        yield from scene.frames(frames)
    finally:
        if own:
            scene.close()


def to_png(image: np.ndarray) -> bytes:
    """PNG file bytes of an image (H, W, 3) or (H, W, 4), uint8."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image)).save(buf, format="PNG")
    return buf.getvalue()


def _write_atomically(path: Path, write) -> None:
    """Call ``write(tmp_path)`` then move the finished file into place (no half-written files):
    :func:`motionlab.core.files.atomic_write_file` (``path`` was checked by :func:`_target`)."""
    from motionlab.core import files

    files.atomic_write_file(path, write, overwrite=True, what=path.suffix.lstrip(".").upper() or "output")


def save_gif(
    motions: Motion | Sequence[Motion] | Scene,
    path,
    stride: int | None = None,
    start: int = 0,
    stop: int | None = None,
    colors: int = 128,
    loop: bool = True,
    overwrite: bool = False,
    **scene_options,
) -> Path:
    """Write an animated GIF.

    Parameters
    ----------
    motions : Motion, list of Motions, or a Scene (rendered as it is set up)
    path : output file, ``.gif``
    stride : keep every ``stride``-th frame; default: about 15 frames per second (a GIF frame is
        shown at least :data:`GIF_MIN_DELAY`; the frames' display times add up to real time)
    start, stop : frame range (stop excluded; default: the whole clip)
    colors : palette size (3..256), shared by all frames, the contact colour kept
    loop : play forever
    overwrite : replace an existing file
    **scene_options : passed to :class:`~motionlab.viz.scene.Scene`, e.g. ``camera="frame"``,
        ``window_size=(480, 360)``, ``trails=("root", "feet")``, ``anti_aliasing=True``

    Returns
    -------
    The path written.

    Raises
    ------
    ValueError unless 3 <= ``colors`` <= 256, or for a ``stride`` shorter than :data:`GIF_MIN_DELAY`.
    """
    from PIL import Image

    path = _target(path, (".gif",), overwrite)
    if not 3 <= int(colors) <= 256:
        raise ValueError(f"colors must be between 3 and 256, got {colors}")
    scene, own = _scene(motions, scene_options)
    try:
        stride = _gif_stride(scene.fps, stride)
        frames = [Image.fromarray(img) for img in scene.frames(_frame_indices(scene, stride, start, stop))]
    finally:
        if own:
            scene.close()
    palette = _palette(frames, int(colors))
    indexed = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in frames]
    looping = {"loop": 0} if loop else {}  # without the key Pillow writes no loop block: play once
    duration = gif_durations(len(frames), stride / scene.fps)

    def write(tmp: Path) -> None:
        indexed[0].save(
            tmp, format="GIF", save_all=True, append_images=indexed[1:], duration=duration, disposal=1, **looping
        )

    _write_atomically(path, write)
    return path


GIF_MIN_DELAY = 0.02
"""Shortest time a GIF frame is shown, seconds: GIF counts in hundredths of a second, and browsers
show a frame of 0 or 0.01 s for 0.1 s."""


def _gif_stride(fps: float, stride: int | None) -> int:
    """The frame stride of a GIF: ``stride``, or about 15 frames per second when None.

    Raises
    ------
    ValueError when ``stride`` would show a frame for less than :data:`GIF_MIN_DELAY`.
    """
    if stride is None:
        return max(1, int(round(fps / 15)), int(np.ceil(GIF_MIN_DELAY * fps - 1e-9)))
    if stride / fps < GIF_MIN_DELAY - 1e-9:
        least = int(np.ceil(GIF_MIN_DELAY * fps - 1e-9))
        raise ValueError(
            f"a GIF shows a frame for at least {GIF_MIN_DELAY:g} s, and stride {stride} at {fps:g} fps asks for "
            f"{stride / fps:.4g} s (browsers would play it slowly): use a stride of {least} or more, or an MP4"
        )
    return int(stride)


def gif_durations(frames: int, seconds: float) -> list[int]:
    """Display times (milliseconds, whole hundredths of a second, as GIF stores them) of ``frames``
    frames meant to last ``seconds`` each: each ends at its true time rounded to the hundredth, so
    the movie plays in real time whatever the frame rate (30 fps: 30, 40, 30, 30, 40, ... ms)."""
    ends = np.round(np.arange(1, frames + 1) * seconds * 100.0).astype(np.int64)
    return (10 * np.diff(ends, prepend=0)).tolist()


def _palette(frames: list, colors: int):
    """One palette for every frame (so colours do not flicker): the median cut of a few frames side
    by side, its last entry the contact colour (a contact shown in none of those frames stays red)."""
    from PIL import Image

    from motionlab.viz.scene import CONTACT_COLOR, _rgb

    picks = frames[:: max(1, len(frames) // 6)][:6]
    sample = Image.new("RGB", (picks[0].width * len(picks), picks[0].height))
    for i, im in enumerate(picks):
        sample.paste(im, (i * im.width, 0))
    palette = sample.quantize(colors=colors - 1, method=Image.Quantize.MEDIANCUT)
    red = [int(round(255 * c)) for c in _rgb(CONTACT_COLOR)]
    entries = palette.getpalette()[: 3 * (colors - 1)]
    entries += [0] * (3 * (colors - 1) - len(entries)) + red
    palette.putpalette(entries)
    return palette


def gif_length(path) -> tuple[int, float]:
    """``(frames, seconds)`` of a GIF file as a viewer plays it: the frames stored in the file
    (Pillow merges identical neighbours) and their display times summed, seconds."""
    from PIL import Image

    with Image.open(os.fspath(path)) as image:
        frames = int(getattr(image, "n_frames", 1))
        milliseconds = 0
        for k in range(frames):
            image.seek(k)
            milliseconds += int(image.info.get("duration", 0))
    return frames, milliseconds / 1000.0


def save_mp4(
    motions: Motion | Sequence[Motion] | Scene,
    path,
    stride: int = 1,
    start: int = 0,
    stop: int | None = None,
    quality: float = 7.0,
    overwrite: bool = False,
    **scene_options,
) -> Path:
    """Write an H.264 MP4 movie (plays in browsers and notebooks).

    Parameters
    ----------
    motions : Motion, list of Motions, or a Scene
    path : output file, ``.mp4``
    stride : keep every ``stride``-th frame (the movie's rate is the motion's fps / stride)
    start, stop : frame range (stop excluded)
    quality : 0 (smallest) .. 10 (best), imageio-ffmpeg's scale
    overwrite : replace an existing file
    **scene_options : passed to :class:`~motionlab.viz.scene.Scene`

    Returns
    -------
    The path written.

    Raises
    ------
    ValueError unless 0 <= ``quality`` <= 10.
    """
    import imageio_ffmpeg

    path = _target(path, (".mp4",), overwrite)
    if not 0 <= quality <= 10:
        raise ValueError(f"quality must be between 0 and 10, got {quality}")
    scene, own = _scene(motions, scene_options)
    try:
        indices = _frame_indices(scene, stride, start, stop)
        width, height = scene.plotter.window_size
        width, height = width - width % 2, height - height % 2  # yuv420p needs even sizes

        def write(tmp: Path) -> None:
            writer = imageio_ffmpeg.write_frames(
                str(tmp),
                (width, height),
                fps=scene.fps / stride,
                quality=quality,
                codec="libx264",
                macro_block_size=2,
                output_params=["-movflags", "+faststart"],
            )
            writer.send(None)
            try:
                for img in scene.frames(indices):
                    writer.send(np.ascontiguousarray(img[:height, :width]))
            finally:
                writer.close()

        _write_atomically(path, write)
    finally:
        if own:
            scene.close()
    return path


def save_movie(motions: Motion | Sequence[Motion] | Scene, path, **options) -> Path:
    """:func:`save_gif` or :func:`save_mp4`, chosen by the file name's suffix.

    Raises
    ------
    ValueError for a file name that ends neither in .gif nor in .mp4.
    """
    suffix = Path(os.fspath(path)).suffix.lower()
    if suffix == ".gif":
        return save_gif(motions, path, **options)
    if suffix == ".mp4":
        return save_mp4(motions, path, **options)
    raise ValueError(f"expected a movie file name ending in .gif or .mp4, got {os.fspath(path)!r}")


def snapshot(
    motions: Motion | Sequence[Motion] | Scene,
    path=None,
    frame: int = 0,
    overwrite: bool = False,
    **scene_options,
) -> np.ndarray:
    """Render one frame; returns the image (H, W, 3) uint8 and writes it as PNG when ``path``
    is given."""
    target = _target(path, (".png",), overwrite) if path is not None else None
    scene, own = _scene(
        motions, {"camera": "frame", **scene_options} if not isinstance(motions, Scene) else scene_options
    )
    try:
        image = scene.screenshot(int(frame))
    finally:
        if own:
            scene.close()
    if target is not None:
        _write_atomically(target, lambda tmp: tmp.write_bytes(to_png(image)))
    return image


def filmstrip(
    motions: Motion | Sequence[Motion] | Scene,
    num: int = 5,
    path=None,
    frames: Sequence[int] | None = None,
    overwrite: bool = False,
    **scene_options,
) -> np.ndarray:
    """Several frames side by side in one image (H, num·W, 3): a static stand-in for the player.

    ``frames`` defaults to ``num`` frames evenly spread over the clip. Written as PNG when
    ``path`` is given. The default window is 320 x 400 pixels per frame.

    Raises
    ------
    ValueError when ``num`` < 1.
    """
    target = _target(path, (".png",), overwrite) if path is not None else None
    if not isinstance(motions, Scene):
        scene_options = {"camera": "frame", "window_size": (320, 400), "show_time": True, **scene_options}
    scene, own = _scene(motions, scene_options)
    try:
        if frames is None:
            if int(num) < 1:
                raise ValueError(f"num must be at least 1, got {num}")
            frames = np.linspace(0, scene.num_frames - 1, int(num)).round().astype(int)
        images = list(scene.frames([int(f) for f in frames]))
    finally:
        if own:
            scene.close()
    strip = np.concatenate(images, axis=1)
    if target is not None:
        _write_atomically(target, lambda tmp: tmp.write_bytes(to_png(strip)))
    return strip


def timed(function, *args, **kwargs) -> tuple[object, float]:
    """``(function(*args, **kwargs), seconds)``: for the timings shown in notebook 04."""
    start = time.perf_counter()
    result = function(*args, **kwargs)
    return result, time.perf_counter() - start
