"""The ipywidgets player in its static (image) mode, as used in CI and nbval."""

from __future__ import annotations

import pytest

from motionlab.viz.player import Player, encode_image, play
from tests.viz.conftest import stepping_motion


@pytest.fixture
def player(can_render):
    p = play(stepping_motion(20), backend="static", window_size=(200, 150), off_screen=True)
    yield p
    p.close()


def test_static_view_shows_jpeg_and_follows_the_slider(player):
    first = player.view.value
    assert first[:2] == b"\xff\xd8"  # JPEG
    player.slider.value = 10  # what the Play widget does through jslink
    assert player.scene.frame == 10
    assert player.view.value != first
    assert "0.33 s" in player.label.value


def test_playback_keeps_real_time(player):
    period_ms = 1000 / player.scene.fps
    assert player.play.interval == pytest.approx(player.play.step * period_ms, abs=15)
    assert player.play.max == player.slider.max == 19


def test_mimebundle_has_widget_and_still(player):
    bundle = player._repr_mimebundle_()
    assert "application/vnd.jupyter.widget-view+json" in bundle
    assert bundle["image/png"]  # base64 PNG for front ends without widgets


def test_refresh_after_new_motion(player):
    player.scene.set_motion(0, stepping_motion(30))
    player.refresh()
    assert player.slider.max == 29


def test_encode_image_rejects_unknown_format():
    import numpy as np

    with pytest.raises(ValueError, match="jpeg"):
        encode_image(np.zeros((4, 4, 3), np.uint8), "bmp")


def test_unknown_backend(can_render):
    with pytest.raises(ValueError, match="unknown Jupyter backend"):
        Player(stepping_motion(3), backend="vr", window_size=(64, 64))
