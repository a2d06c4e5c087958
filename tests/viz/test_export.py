"""GIF / MP4 / PNG export, off-screen, never overwriting by accident."""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np
import pytest

from motionlab.viz import export
from tests.viz.conftest import stepping_motion

SMALL = {"window_size": (160, 128), "off_screen": True}


def test_save_gif_frames_move(can_render, tmp_path):
    m = stepping_motion(24)
    path = export.save_gif(m, tmp_path / "walk.gif", stride=3, **SMALL)
    frames = iio.imread(path, index=None)
    assert frames.shape[0] == 8  # 24 frames, every 3rd
    assert frames.shape[1:3] == (128, 160)
    changed = [np.abs(frames[i].astype(int) - frames[i + 1]).sum() > 0 for i in range(len(frames) - 1)]
    assert all(changed), "consecutive GIF frames must differ (a moving character, a following camera)"


def test_gif_default_stride_keeps_about_15_fps(can_render, tmp_path):
    m = stepping_motion(20, fps=60.0)
    frames = iio.imread(export.save_gif(m, tmp_path / "a.gif", **SMALL), index=None)
    assert frames.shape[0] == 5  # stride 4


def test_never_overwrite_without_asking(can_render, tmp_path):
    m = stepping_motion(4)
    path = tmp_path / "clip.gif"
    path.write_bytes(b"keep me")
    with pytest.raises(FileExistsError, match="overwrite=True"):
        export.save_gif(m, path, **SMALL)
    assert path.read_bytes() == b"keep me"
    export.save_gif(m, path, overwrite=True, **SMALL)
    assert path.read_bytes()[:3] == b"GIF"


def test_bad_paths(can_render, tmp_path):
    m = stepping_motion(4)
    with pytest.raises(ValueError, match=r"\.gif"):
        export.save_gif(m, tmp_path / "clip.mp4", **SMALL)
    with pytest.raises(ValueError, match=r"\.gif or \.mp4"):
        export.save_movie(m, tmp_path / "clip.avi", **SMALL)
    with pytest.raises(FileNotFoundError, match="does not exist"):
        export.save_mp4(m, tmp_path / "missing" / "clip.mp4", **SMALL)


def test_save_mp4(can_render, tmp_path):
    import imageio_ffmpeg

    m = stepping_motion(16)
    path = export.save_movie(m, tmp_path / "walk.mp4", **SMALL)
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    frames = [np.frombuffer(f, np.uint8).reshape(meta["size"][1], meta["size"][0], 3) for f in reader]
    assert len(frames) == 16
    assert tuple(meta["size"]) == (160, 128)
    assert meta["fps"] == pytest.approx(30.0)
    assert np.abs(frames[0].astype(int) - frames[8]).mean() > 0.5
    assert not list(tmp_path.glob(".*partial*")), "no temporary file left behind"


def test_snapshot_and_filmstrip(can_render, tmp_path):
    m = stepping_motion(10)
    img = export.snapshot(m, tmp_path / "shot.png", frame=4, **SMALL)
    assert img.shape == (128, 160, 3) and img.dtype == np.uint8
    np.testing.assert_array_equal(iio.imread(tmp_path / "shot.png")[..., :3], img)
    strip = export.filmstrip(m, num=3, **SMALL)
    assert strip.shape == (128, 480, 3)
    assert np.abs(strip[:, :160].astype(int) - strip[:, 320:]).sum() > 0


def test_gif_frames_add_up_to_real_time_in_hundredths():
    """30 fps, every 2nd frame: 66.7 ms each, stored 70, 60, 70, 70, 60 ms (GIF counts hundredths)."""
    assert export.gif_durations(5, 2 / 30) == [70, 60, 70, 70, 60]
    assert sum(export.gif_durations(90, 4 / 59.9988)) == pytest.approx(90 * 4 / 59.9988 * 1000, abs=5)
    assert export._gif_stride(120.0, None) == 8
    with pytest.raises(ValueError, match="use a stride of 2 or more"):
        export._gif_stride(60.0, 1)


def test_the_gif_palette_keeps_the_contact_colour(can_render, tmp_path):
    from PIL import Image

    from motionlab.viz.scene import CONTACT_COLOR, _rgb

    grey = [Image.new("RGB", (8, 8), (90 + k, 90 + k, 90 + k)) for k in range(6)]
    red = tuple(int(round(255 * c)) for c in _rgb(CONTACT_COLOR))
    palette = export._palette(grey, 16)
    assert tuple(palette.getpalette()[45:48]) == red
    swatch = Image.new("RGB", (2, 2), red).quantize(palette=palette, dither=Image.Dither.NONE).convert("RGB")
    assert swatch.getpixel((0, 0)) == red
