"""The web player's data and HTML (the browser side is checked by tests/browser/check_docs_site.py)."""

from __future__ import annotations

import base64
import json
import re

import numpy as np
import pytest

from motionlab import synthetic
from motionlab.core import humanoid
from motionlab.viz import web
from motionlab.viz.scene import PALETTE


@pytest.fixture(scope="module")
def walks():
    sk = humanoid.canonical_skeleton(1.75)
    a = synthetic.generate("walk", sk, num_frames=40, fps=30, seed=0)
    b = synthetic.generate("walk", humanoid.scale_bones(sk, legs=1.3), num_frames=25, fps=60, seed=1)
    a.name = "short legs"
    return a, b


def _data(fragment: str) -> dict:
    match = re.search(r'<script type="application/json" class="motionlab-data">(.*?)</script>', fragment, re.S)
    return json.loads(match.group(1))


def test_positions_are_fk_in_millimetres(walks):
    a, b = walks
    data = web.player_data([a, b], spacing=1.5)
    assert [s["color"] for s in data["skeletons"]] == list(PALETTE[:2])
    assert [s["name"] for s in data["skeletons"]] == ["short legs", b.name or "motion 1"]
    for i, (m, s) in enumerate(zip(walks, data["skeletons"])):
        root = np.array(s["root"]).reshape(m.num_frames, 1, 3)
        rel = np.frombuffer(base64.b64decode(s["joints"]), dtype="<i2").reshape(m.num_frames, 22, 3)
        pos = (root + rel) / 1000.0
        np.testing.assert_allclose(pos, m.global_positions() + [1.5 * i, 0, 0], atol=1e-3 + 1e-12)
        assert s["parents"] == m.skeleton.parents.tolist() and s["fps"] == m.fps
    assert data["fps"] == 60 and data["duration"] == pytest.approx(a.duration)


def test_long_motions_keep_every_sth_frame(walks):
    a, _ = walks
    s = web.player_data(a, max_frames=15)["skeletons"][0]
    assert len(s["root"]) == 14 * 3 and s["fps"] == pytest.approx(10.0)  # 40 frames, step 3


def test_html_holds_data_script_and_unique_ids(walks):
    one, two = web.player_html(walks[0]), web.player_html(walks[0])
    ids = [re.search(r'id="(motionlab-player-[0-9a-f]+-[0-9]+)"', h).group(1) for h in (one, two)]
    assert ids[0] != ids[1] and f'document.getElementById("{ids[0]}")' in one
    assert "__PLAYER_ID__" not in one and "window.THREE" in one
    assert _data(one)["skeletons"][0]["name"] == "short legs" and _data(one)["autoplay"] is False
    assert "</script>" not in json.dumps(_data(one))


def test_three_js_is_embedded_only_when_asked(walks, tmp_path):
    lib = tmp_path / "three.js"
    lib.write_text("var THREE = {marker: 1};")
    assert "marker" not in web.player_html(walks[0])
    assert "var THREE = {marker: 1};" in web.player_html(walks[0], three_js=lib)
    with pytest.raises(FileNotFoundError, match="nope.js not found"):
        web.player_html(walks[0], three_js=tmp_path / "nope.js")


def test_bad_input_is_named(walks):
    a, b = walks
    with pytest.raises(ValueError, match="at least one Motion"):
        web.player_data([])
    with pytest.raises(TypeError, match="got ndarray at position 1"):
        web.player_data([a, a.local_rot])
    with pytest.raises(ValueError, match="expected 2 colors"):
        web.player_data([a, b], colors=["red"])
    with pytest.raises(ValueError, match="height must be"):
        web.player_html(a, height=0)
    rot = a.local_rot.copy()
    rot[2, 3] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        web.player_data(a.copy(local_rot=rot))


def test_player_is_a_notebook_output(walks):
    out = web.player(walks[0], autoplay=True)
    assert "motionlab-player" in out._repr_html_() and _data(out.data)["autoplay"] is True


def test_the_camera_frames_the_motion_not_its_rest_pose(walks):
    a, b = walks
    data = web.player_data([a, b])
    extent = max(np.ptp(m.global_positions()[..., 1], axis=-1).max() for m in walks)
    assert data["height"] == pytest.approx(extent)  # the tallest frame, as the figure moves
    lowest = min(m.global_positions()[..., 1].min() for m in walks)
    highest = max(m.global_positions()[..., 1].max() for m in walks)
    assert data["middle"] == pytest.approx(0.5 * (lowest + highest))


def test_a_folded_rest_pose_is_framed_as_the_figure_stands():
    from tests.conftest import require_data

    root = require_data("bandai_namco")
    from motionlab.core import bvh

    walk = humanoid.to_canonical(bvh.load(root / "dataset-1/walk/dataset-1_walk_normal_001.bvh"))
    assert walk.skeleton.height() < 0.2  # Bandai Namco's rest pose is folded up (notebook 01)
    data = web.player_data(walk)
    standing = np.ptp(walk.global_positions()[..., 1], axis=-1).max()
    assert standing > 1.0 and data["height"] == pytest.approx(standing)
    assert data["distance"] > 2.2 * standing  # far enough back to show the whole walker


def test_a_notebook_player_embeds_three_js_once_per_kernel(walks, tmp_path, monkeypatch):
    lib = tmp_path / "three.js"
    lib.write_text("var THREE = {marker: 1};")
    monkeypatch.setenv(web.THREE_JS_ENV, str(lib))
    monkeypatch.setitem(web._EMBEDDED, "done", False)
    first, second = web.player(walks[0]).data, web.player(walks[1]).data
    assert "marker" in first and "marker" not in second  # the second waits for the first's THREE
    assert "marker" in web.player(walks[0], three_js=True).data  # asked for: embedded every time
    monkeypatch.setitem(web._EMBEDDED, "done", False)
    monkeypatch.setenv(web.EMBED_ENV, "0")
    assert "marker" not in web.player(walks[0]).data  # turned off (stored outputs for the docs site)


def test_without_a_vendored_three_js_the_notebook_player_still_renders(walks, tmp_path, monkeypatch):
    monkeypatch.setenv(web.THREE_JS_ENV, str(tmp_path / "missing.js"))
    monkeypatch.setitem(web._EMBEDDED, "done", False)
    if web.Path(web.__file__).resolve().parents[2].joinpath("build", "web", "three.min.js").is_file():
        pytest.skip("this checkout has a vendored three.js")
    out = web.player(walks[0]).data
    assert "motionlab-player" in out and "var THREE" not in out
    assert "not trusted" in out  # the line shown where no script runs (a reopened notebook)
    assert 'start("canvas")' in out  # without three.js it draws on the 2D canvas (checked in a browser by
    # tests/browser/check_docs_site.py, "player_without_three_js")
