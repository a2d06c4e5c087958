"""``motionlab info / convert / synth``: nonsense numbers refused by option, file problems as one-line
errors (exit 2, no traceback), never a half-written or silently replaced output."""

from __future__ import annotations

import os

import numpy as np
import pytest

from motionlab import cli, synthetic
from motionlab.core import bvh, humanoid


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    d = tmp_path_factory.mktemp("foundation")
    motion = synthetic.generate("walk", humanoid.canonical_skeleton(), num_frames=30, fps=30, seed=0)
    return bvh.save(d / "walk.bvh", motion)


def _run(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def _argparse_error(capsys, *argv) -> str:
    with pytest.raises(SystemExit) as e:
        cli.main([str(a) for a in argv])
    assert e.value.code == 2
    return capsys.readouterr().err


@pytest.mark.parametrize(
    ("option", "value"),
    [("--height", "-1.7"), ("--height", "0"), ("--fps", "0"), ("--seconds", "-1"), ("--legs", "nan")],
)
def test_synth_refuses_nonsense_numbers(tmp_path, capsys, option, value):
    err = _argparse_error(capsys, "synth", "walk", "-o", tmp_path / "x.bvh", option, value)
    assert option in err and ("positive" in err or " from " in err) and value in err
    assert list(tmp_path.iterdir()) == []


def test_synth_refuses_less_than_a_frame(tmp_path, capsys):
    code, _, err = _run(capsys, "synth", "walk", "-o", tmp_path / "x.bvh", "--seconds", "0.001")
    assert code == 2 and "--seconds" in err and "one frame" in err
    assert list(tmp_path.iterdir()) == []


def test_synth_writes_an_upright_skeleton(tmp_path, capsys):
    code, _, err = _run(capsys, "synth", "walk", "-o", tmp_path / "w.bvh", "--height", "1.6", "--seconds", "0.5")
    assert code == 0, err
    m = bvh.load(tmp_path / "w.bvh")
    head = humanoid.JOINTS.index("Head")
    assert m.global_positions()[0, head, 1] > m.global_positions()[0, 0, 1]


@pytest.mark.parametrize("value", ["0", "-30", "inf"])
def test_convert_refuses_a_zero_or_negative_fps(clip, tmp_path, capsys, value):
    err = _argparse_error(capsys, "convert", clip, "-o", tmp_path / "x.bvh", "--fps", value)
    assert "--fps" in err and "from 1 to 1000" in err
    assert list(tmp_path.iterdir()) == []


def test_convert_resamples(clip, tmp_path, capsys):
    code, _, err = _run(capsys, "convert", clip, "-o", tmp_path / "x.bvh", "--fps", "15")
    assert code == 0, err
    assert bvh.load(tmp_path / "x.bvh").fps == 15


def test_convert_to_an_existing_folder_is_a_named_error(clip, tmp_path, capsys, monkeypatch):
    (tmp_path / "sub").mkdir()
    code, _, err = _run(capsys, "convert", clip, "-o", tmp_path / "sub", "--force")
    assert code == 2 and "is a folder" in err and "Traceback" not in err
    monkeypatch.chdir(tmp_path)
    code, _, err = _run(capsys, "convert", clip, "-o", ".", "--force")
    assert code == 2 and "is a folder" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sub"]


def test_a_folder_as_input_is_not_reported_missing(tmp_path, capsys):
    code, _, err = _run(capsys, "info", tmp_path)
    assert code == 2 and "is a folder; expected a file" in err and "not found" not in err
    code, _, err = _run(capsys, "convert", tmp_path, "-o", tmp_path / "x.bvh")
    assert code == 2 and "is a folder" in err


def test_missing_output_folder_and_existing_output(clip, tmp_path, capsys):
    code, _, err = _run(capsys, "convert", clip, "-o", tmp_path / "no" / "x.bvh")
    assert code == 2 and "does not exist" in err
    (tmp_path / "x.bvh").write_text("mine")
    code, _, err = _run(capsys, "synth", "walk", "-o", tmp_path / "x.bvh")
    assert code == 2 and "--force" in err
    assert (tmp_path / "x.bvh").read_text() == "mine"


def test_os_errors_are_one_line_errors(clip, tmp_path, capsys, monkeypatch):
    """An unreadable input (or any OSError while working) ends as `motionlab: error:`, exit 2."""

    def denied(path, *a, **k):
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(bvh, "load", denied)
    code, _, err = _run(capsys, "info", clip)
    assert code == 2
    assert err.strip() == f"motionlab: error: {clip}: permission denied"


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads and writes everything: permissions cannot be tested")
def test_real_permissions(clip, tmp_path, capsys):
    locked = tmp_path / "locked.bvh"
    locked.write_bytes(clip.read_bytes())
    locked.chmod(0)
    code, _, err = _run(capsys, "info", locked)
    assert code == 2 and "not readable" in err
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    code, _, err = _run(capsys, "convert", clip, "-o", ro / "x.bvh")
    assert code == 2 and "permission denied" in err
    ro.chmod(0o700)


def test_info_rig_error_has_no_python_hint(tmp_path, capsys):
    sk = humanoid.canonical_skeleton()
    odd = sk.renamed(["Knee" if n == "LeftLeg" else n for n in sk.names])
    path = bvh.save(tmp_path / "odd.bvh", synthetic.generate("idle", sk, num_frames=5, seed=0).copy(skeleton=odd))
    code, out, err = _run(capsys, "info", path)
    assert code == 0 and "LeftLeg" in out and "profile=" not in out
    code, _, err = _run(capsys, "convert", path, "-o", tmp_path / "c.bvh", "--canonical")
    assert code == 2 and f"input file {path}" in err and "profile=" not in err
    assert not (tmp_path / "c.bvh").exists()


def test_convert_output_is_not_the_input(clip, tmp_path, capsys):
    copy = tmp_path / "c.bvh"
    copy.write_bytes(clip.read_bytes())
    code, _, err = _run(capsys, "convert", copy, "-o", copy, "--force", "--fps", "10")
    assert code == 2 and "is the input" in err
    np.testing.assert_array_equal(
        np.frombuffer(copy.read_bytes(), np.uint8), np.frombuffer(clip.read_bytes(), np.uint8)
    )


def test_convert_to_glb_chooses_the_format_by_suffix(clip, tmp_path, capsys):
    from tests.gltf_reader import assert_glb_matches

    code, out, err = _run(capsys, "convert", clip, "-o", tmp_path / "x.glb", "--fps", "15")
    assert code == 0 and "wrote" in out, err
    assert (tmp_path / "x.glb").read_bytes()[:4] == b"glTF"
    assert_glb_matches(tmp_path / "x.glb", bvh.load(clip).resample(15))
    code, _, err = _run(capsys, "convert", clip, "-o", tmp_path / "x.glb")
    assert code == 2 and "--force" in err


def _glb_height(path) -> float:
    """Highest minus lowest node at the first keyframe, metres."""
    from tests.gltf_reader import read, world_matrices

    y = world_matrices(read(path), 0)[:, 1, 3]
    return float(y.max() - y.min())


def test_a_cmu_clip_keeps_its_size_through_a_canonical_bvh(tmp_path, capsys):
    """--canonical writes centimetres: the 22 joints' names read back as centimetres, not CMU units."""
    from tests.conftest import require_data

    src = require_data("cmu", "131", "131_01.bvh")
    canon = tmp_path / "canon.bvh"
    for argv in (
        (src, "-o", tmp_path / "direct.glb", "--canonical"),
        (src, "-o", canon, "--canonical"),
        (canon, "-o", tmp_path / "two_steps.glb"),
    ):
        code, _, err = _run(capsys, "convert", *argv)
        assert code == 0, err
    direct, two_steps = _glb_height(tmp_path / "direct.glb"), _glb_height(tmp_path / "two_steps.glb")
    assert 1.0 < direct < 2.0
    assert abs(two_steps - direct) < 1e-4 * direct


@pytest.mark.parametrize(
    "clip", ["bandai_namco/dataset-1/walk/dataset-1_walk_active_001.bvh", "cmu/131/131_01.bvh", "mixamo/Aj/Running.bvh"]
)
def test_a_canonical_file_stands_in_its_rigs_standing_pose(tmp_path, capsys, clip):
    """The 22 joints rest in the standing pose retargeting reads off the rig: Bandai Namco's rest
    offsets lie flat, and a canonical file that kept them read as a Mixamo rig standing 2.7 cm
    taller than its source (the most upright frame's pose). Every joint stays where it was."""
    from motionlab.core import motion_files, rest_pose
    from tests.conftest import require_data

    src = require_data(*clip.split("/"))
    out = tmp_path / "canon.bvh"
    code, _, err = _run(capsys, "convert", src, "-o", out, "--canonical", "-q")
    assert code == 0, err
    source = motion_files.load_metres(src)
    canon = bvh.load(out)
    standing = rest_pose.standing(humanoid.to_canonical(source), family=humanoid.family(source.skeleton))[0]
    assert canon.skeleton.height() == pytest.approx(standing.skeleton.height(), abs=1e-5)
    assert rest_pose.standing(canon)[0].skeleton.height() == pytest.approx(standing.skeleton.height(), abs=1e-4)
    want = humanoid.to_canonical(source).global_positions()
    np.testing.assert_allclose(canon.global_positions(), want, atol=1e-5 * np.abs(want).max())


def test_info_gives_a_cmu_rig_in_metres(capsys):
    from tests.conftest import require_data

    src = require_data("cmu", "131", "131_01.bvh")
    code, out, err = _run(capsys, "info", src)
    assert code == 0, err
    height = float(out.split("height")[1].split()[0])
    assert "m per file unit" in out and 1.0 < height < 2.0


def test_synth_mix_is_the_same_motion_at_any_frame_rate(tmp_path, capsys):
    seconds = []
    for fps in (24, 60):
        code, _, err = _run(capsys, "synth", "mix", "-o", tmp_path / f"m{fps}.bvh", "--fps", fps)
        assert code == 0, err
        seconds.append(bvh.load(tmp_path / f"m{fps}.bvh").duration)
    assert abs(seconds[0] - seconds[1]) <= 7 / 24  # a frame per segment at most


def test_synth_rounds_seconds_to_the_nearest_frame(tmp_path, capsys):
    code, _, err = _run(capsys, "synth", "walk", "-o", tmp_path / "w.bvh", "--seconds", "0.29", "--fps", "100")
    assert code == 0, err
    assert bvh.load(tmp_path / "w.bvh").num_frames == 29
