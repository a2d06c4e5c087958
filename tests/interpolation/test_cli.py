"""``motionlab fill-gaps``: fills dropped frames, reports them, never overwrites without --force."""

import numpy as np
import pytest

from motionlab.cli import main
from motionlab.core import bvh

from .conftest import toy_motion


@pytest.fixture
def dropped(tmp_path):
    m = toy_motion(120)
    keep = np.r_[0:50, 58:120]
    path = tmp_path / "dropped.bvh"
    bvh.save(path, m[keep])
    return path


def test_fill_gaps_writes_filled_file(dropped, tmp_path, capsys):
    out = tmp_path / "out.bvh"
    assert main(["fill-gaps", str(dropped), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "filled 1 gap(s)" in text and "frames 50-" in text
    filled = bvh.load(out)
    assert filled.num_frames > 112
    assert np.all(np.isfinite(filled.local_rot))


def test_fill_gaps_refuses_to_overwrite(dropped, tmp_path, capsys):
    out = tmp_path / "out.bvh"
    out.write_text("keep me")
    assert main(["fill-gaps", str(dropped), "-o", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert out.read_text() == "keep me"
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--force", "--method", "hermite"]) == 0


def test_fill_gaps_user_errors(dropped, tmp_path, capsys):
    assert main(["fill-gaps", str(tmp_path / "nope.bvh"), "-o", str(tmp_path / "o.bvh")]) == 2
    assert main(["fill-gaps", str(dropped), "-o", str(tmp_path / "o.bvh"), "--method", "graph"]) == 2
    assert "--action" in capsys.readouterr().err


def test_fill_gaps_with_graph(dropped, tmp_path, capsys):
    clip = tmp_path / "walk.bvh"
    bvh.save(clip, toy_motion(80, phase=0.7))
    out = tmp_path / "g.bvh"
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--method", "graph", "--action", f"walk={clip}"]) == 0
    assert "via walk" in capsys.readouterr().out


@pytest.mark.parametrize("flag", ["--threshold", "--delta", "--factor"])
@pytest.mark.parametrize("value", ["-1", "0", "nan"])
def test_fill_gaps_refuses_nonsense_delta(dropped, tmp_path, capsys, flag, value):
    out = tmp_path / "o.bvh"
    assert main(["fill-gaps", str(dropped), "-o", str(out), flag, value]) == 2
    assert "--delta (--threshold) must be a finite number above 1" in capsys.readouterr().err
    assert not out.exists()


def test_fill_gaps_on_a_clean_clip_writes_an_unchanged_copy(tmp_path, capsys):
    clean = tmp_path / "clean.bvh"
    bvh.save(clean, toy_motion(120))
    out = tmp_path / "copy.bvh"
    assert main(["fill-gaps", str(clean), "-o", str(out)]) == 0
    assert "unchanged copy" in capsys.readouterr().out
    assert out.read_bytes() == clean.read_bytes()


def test_fill_gaps_continues_the_strides_by_default(tmp_path, capsys):
    m = toy_motion(240)  # one stride a second, 1.5 strides known on both sides of the cut
    path = tmp_path / "walk.bvh"
    bvh.save(path, m[np.r_[0:100, 112:240]])
    out = tmp_path / "out.bvh"
    assert main(["fill-gaps", str(path), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "(method: stride)" in text and ": stride" in text
    assert abs(bvh.load(out).num_frames - m.num_frames) <= 1  # 12 frames missing, counted to one


def test_fill_gaps_with_other_takes(dropped, tmp_path, capsys):
    other = tmp_path / "other.bvh"
    bvh.save(other, toy_motion(150, phase=0.7, speed=1.1))
    out = tmp_path / "out.bvh"
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--takes", str(other)]) == 0
    assert "filled 1 gap(s)" in capsys.readouterr().out
    assert abs(bvh.load(out).num_frames - 120) <= 1
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--force", "--takes", str(dropped)]) == 2
    assert "the input itself" in capsys.readouterr().err
    assert main(["fill-gaps", str(dropped), "-o", str(out), "--force", "--takes", str(tmp_path / "no.bvh")]) == 2
    assert "no such file" in capsys.readouterr().err
