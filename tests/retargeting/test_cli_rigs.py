"""``motionlab retarget`` across frame rates and rigs: resamples reported, implausible outputs refused."""

from __future__ import annotations

import pytest

from motionlab import synthetic
from motionlab.cli import main
from motionlab.core import bvh
from tests.conftest import require_data


@pytest.fixture
def walk30(tmp_path):
    path = tmp_path / "walk30.bvh"
    bvh.save(path, synthetic.dataset(1, seed=1, num_frames=30, fps=30)[0])
    return path


def test_output_at_the_source_rate_and_the_resample_is_printed_under_quiet(walk30, tmp_path, capsys):
    out = tmp_path / "out.bvh"
    assert main(["retarget", str(walk30), "--scale-legs", "1.2", "-o", str(out), "-q", "--steps", "3"]) == 0
    assert "resampled: source 30 fps -> network 60 fps -> output 30 fps" in capsys.readouterr().err
    assert bvh.load(out).fps == pytest.approx(30, rel=1e-4)
    out24 = tmp_path / "out24.bvh"
    assert main(["retarget", str(walk30), "--scale", "1.1", "-o", str(out24), "-q", "--steps", "3", "--fps", "24"]) == 0
    assert "output 24 fps" in capsys.readouterr().err and bvh.load(out24).fps == pytest.approx(24, rel=1e-4)


def test_implausible_output_is_refused_unless_kept(walk30, tmp_path, capsys):
    out = tmp_path / "sunk.bvh"
    argv = ["retarget", str(walk30), "--scale-legs", "0.3", "--root", "legs", "-o", str(out), "-q", "--steps", "3"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "IMPLAUSIBLE (foot" in err and "nothing written" in err and "--keep-implausible" in err
    assert not out.exists()
    assert main(argv + ["--keep-implausible"]) == 0
    assert out.is_file() and "warning" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.real_network
def test_bandai_onto_mixamo_and_back(tmp_path, capsys):
    """The issue's pair: feet on the floor, hips at a standing height, 30 fps kept."""
    bandai = require_data("bandai_namco", "dataset-1", "walk", "dataset-1_walk_normal_001.bvh")
    aj = require_data("mixamo", "Aj", "Catwalk_Idle_To_Walk_Forward.bvh")
    for src, tgt, fps in ((bandai, aj, 30), (aj, bandai, 60)):
        out = tmp_path / f"{src.stem}_on_{tgt.stem}.bvh"
        assert main(["retarget", str(src), "--target", str(tgt), "-o", str(out), "-q", "--steps", "20"]) == 0
        m = bvh.load(out)
        assert m.fps == pytest.approx(fps, rel=1e-4)
        pos = m.global_positions()
        assert pos[..., 1].min() > -0.05 and 0.5 < pos[:, 0, 1].mean() < 1.2  # metres
