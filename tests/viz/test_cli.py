"""``motionlab view``: movies off-screen, no silent overwrite, user errors as CLIError."""

from __future__ import annotations

import pytest

from motionlab.cli import main
from tests.viz.conftest import stepping_motion

bvh = pytest.importorskip("motionlab.core.bvh")


@pytest.fixture
def clip(tmp_path):
    path = tmp_path / "walk.bvh"
    bvh.save(path, stepping_motion(12))
    return path


FAST = ["--size", "96x80"]


def test_view_writes_a_movie_and_refuses_to_overwrite(can_render, clip, tmp_path, capsys):
    out = tmp_path / "walk.mp4"
    assert main(["view", str(clip), "-o", str(out), *FAST]) == 0
    assert out.stat().st_size > 0
    assert "wrote" in capsys.readouterr().out
    size = out.stat().st_size
    assert main(["view", str(clip), "-o", str(out), *FAST]) == 2
    assert "--force" in capsys.readouterr().err
    assert out.stat().st_size == size
    assert main(["view", str(clip), "-o", str(out), "--force", "--stop", "6", *FAST]) == 0


def test_view_gif(can_render, clip, tmp_path):
    out = tmp_path / "walk.gif"
    assert main(["view", str(clip), "-o", str(out), "--camera", "frame", *FAST]) == 0
    assert out.read_bytes()[:3] == b"GIF"


def test_view_prints_the_gifs_own_frame_count_and_length(can_render, clip, tmp_path, capsys):
    """Not the clip's frame count, nor the render time as the duration."""
    from motionlab.viz.export import gif_length

    out = tmp_path / "walk.gif"
    assert main(["view", str(clip), "-o", str(out), "--stride", "4", *FAST]) == 0
    frames, seconds = gif_length(out)
    assert frames == 3  # 12 frames, every 4th
    assert f"wrote {out}: {frames} frames, {seconds:.2f} s of" in capsys.readouterr().out


def test_view_without_display_needs_out_and_writes_nothing(clip, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("motionlab.viz.backend.has_display", lambda: False)
    assert main(["view", str(clip), "--stop", "4", *FAST]) == 2
    err = capsys.readouterr().err
    assert "no display" in err and "-o walk.mp4" in err
    assert not list(tmp_path.glob("*.mp4")) and not list(tmp_path.glob("*.gif"))  # nothing written here


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["missing.bvh", "-o", "x.mp4"], "not found"),
        (["{clip}", "-o", "x.avi"], ".mp4 or .gif"),
        (["{clip}", "-o", "nowhere/x.mp4"], "does not exist"),
        (["{clip}", "-o", "x.mp4", "--start", "-3"], "--start"),
    ],
)
def test_view_user_errors(clip, tmp_path, monkeypatch, capsys, args, message):
    monkeypatch.chdir(tmp_path)
    args = [a.replace("{clip}", str(clip)) for a in args]
    try:
        code = main(["view", *args])
    except SystemExit as e:  # refused by argparse, naming the option
        code = e.code
    assert code == 2
    assert message in capsys.readouterr().err


def test_view_bad_size_is_an_argparse_error(clip, capsys):
    with pytest.raises(SystemExit):
        main(["view", str(clip), "--size", "big"])
    assert "WIDTHxHEIGHT" in capsys.readouterr().err


def test_window_mode_when_a_display_exists(can_render, clip, monkeypatch):
    from motionlab.viz import cli as viz_cli

    shown = []
    monkeypatch.setattr("motionlab.viz.backend.has_display", lambda: True)
    monkeypatch.setattr(viz_cli, "_open_window", shown.append)  # no real window in a test
    assert main(["view", str(clip), "--size", "96x80", "--camera", "frame"]) == 0
    (scene,) = shown
    assert scene.num_frames == 12 and scene.camera_mode == "frame" and not scene.off_screen
    scene.close()


def test_open_window_adds_slider_and_timer(can_render):
    from motionlab.viz import cli as viz_cli
    from motionlab.viz.scene import Scene

    scene = Scene(stepping_motion(8), window_size=(96, 80), off_screen=True)
    calls = []
    scene.show = lambda **kw: calls.append(kw)
    viz_cli._open_window(scene)
    assert calls == [{"title": "motionlab view"}]
    assert len(scene.plotter.widgets.slider_widgets) == 1
    scene.close()


def test_view_refuses_a_clip_without_frames(tmp_path, capsys):
    from motionlab import cli

    src = tmp_path / "empty.bvh"
    src.write_text(
        "HIERARCHY\nROOT Hips\n{\n OFFSET 0 90 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
        "Yrotation\n End Site\n {\n  OFFSET 0 10 0\n }\n}\nMOTION\nFrames: 0\nFrame Time: 0.0333333\n"
    )
    assert cli.main(["view", str(src), "-o", str(tmp_path / "v.gif")]) == 2
    assert "no frames" in capsys.readouterr().err and sorted(tmp_path.iterdir()) == [src]
