"""``motionlab retarget -o X.glb`` and ``expand --format glb``: the glTF file holds the same motion as
the BVH path would write, read back by the tests' independent reader (``tests/gltf_reader.py``)."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab import cli, retargeting, synthetic
from motionlab.core import bvh, humanoid
from motionlab.core.motion import Motion
from motionlab.core.skeleton import Skeleton
from motionlab.retargeting import expand as ex
from motionlab.retargeting.pipeline import retarget
from motionlab.retargeting.solver import SolverConfig
from tests.gltf_reader import assert_glb_matches

FAST = SolverConfig(max_steps=4)


def _run(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture(scope="module")
def source(tmp_path_factory, clips):
    d = tmp_path_factory.mktemp("gltf_outputs")
    return bvh.save(d / "source.bvh", clips[0][:40])


def test_retarget_writes_glb_with_the_npz_motion(source, tmp_path, capsys):
    out, npz = tmp_path / "long_legs.glb", tmp_path / "long_legs.npz"
    code, _, err = _run(
        capsys, "retarget", source, "--scale-legs", "1.3", "-o", out, "--npz", npz, "--method", "copy", "-q"
    )
    assert code == 0, err
    arrays = np.load(npz)
    skeleton = Skeleton(humanoid.JOINTS, arrays["parents"], arrays["offsets"])
    motion = Motion(skeleton, arrays["local_rot"], arrays["root_pos"], float(arrays["fps"]))
    assert_glb_matches(out, motion, frames=range(0, motion.num_frames, 5))
    np.testing.assert_allclose(motion.global_positions(), arrays["positions"], atol=1e-6)


def test_retarget_refuses_other_suffixes_before_work(source, tmp_path, capsys):
    code, _, err = _run(capsys, "retarget", source, "--scale-legs", "1.3", "-o", tmp_path / "x.fbx", "--method", "copy")
    assert code == 2 and "choose a name ending in .bvh or .glb" in err
    assert list(tmp_path.iterdir()) == []


def test_expand_glb_outputs_match_the_single_pair_path(tmp_path):
    ckpt = retargeting.load_default("cpu")
    clip = synthetic.dataset(1, seed=2, num_frames=30)[0]
    (tmp_path / "clips").mkdir()
    bvh.save(tmp_path / "clips" / "short.bvh", clip)
    targets = ex.characters(presets=["long_legs"])
    out = tmp_path / "out"
    job = ex.expand([str(tmp_path / "clips")], targets, out, ckpt, FAST, output_format="glb")
    assert job.done == 1 and job.failed == 0
    assert [r["output"] for r in job.rows] == ["long_legs/short.glb"]
    single = retarget(bvh.load(tmp_path / "clips" / "short.bvh"), targets[0].skeleton, ckpt, solver=FAST)
    assert_glb_matches(out / "long_legs" / "short.glb", single.motion, frames=range(0, 30, 6))
    assert sorted(p.name for p in (out / "long_legs").iterdir()) == ["short.glb"]  # no temporary files
    again = ex.expand([str(tmp_path / "clips")], targets, out, ckpt, FAST, output_format="glb")
    assert again.skipped == 1 and again.done == 0
    with pytest.raises(ValueError, match="output_format must be one of"):
        ex.expand([str(tmp_path / "clips")], targets, out, ckpt, FAST, output_format="fbx")


def test_expand_cli_has_a_format_option(tmp_path, capsys):
    with pytest.raises(SystemExit):
        cli.main(["expand", "x.bvh", "--preset", "tall", "-o", str(tmp_path), "--format", "fbx"])
    assert "invalid choice: 'fbx'" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
