"""``motionlab retarget --npz`` and ``evaluate --csv``: outputs checked before work, written whole, never
overwritten without ``--force``; rig-mapping errors name the file at fault."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab import cli
from motionlab.core import bvh, humanoid
from motionlab.retargeting import checkpoint


@pytest.fixture(scope="module")
def inputs(tmp_path_factory, clips, tiny_checkpoint):
    d = tmp_path_factory.mktemp("cli_outputs")
    src = bvh.save(d / "source.bvh", clips[0])
    tgt = bvh.save(d / "target.bvh", clips[1].copy(skeleton=humanoid.scale_bones(clips[1].skeleton, legs=1.3)))
    ckpt = checkpoint.save(d / "tiny.pt", tiny_checkpoint)
    sk = clips[0].skeleton
    odd = clips[0].copy(skeleton=sk.renamed(["LeftKnee" if n == "LeftLeg" else n for n in sk.names]))
    bad_rig = bvh.save(d / "odd_rig.bvh", odd)
    return src, tgt, ckpt, bad_rig


def _run(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_npz_name_is_the_file_written_and_is_never_overwritten(inputs, tmp_path, capsys):
    src, tgt, ckpt, _ = inputs
    out = tmp_path / "out.bvh"
    # np.savez used to write NAME.npz after checking NAME: now the name must end in .npz
    code, _, err = _run(
        capsys, "retarget", src, "--target", tgt, "-o", out, "--method", "copy", "--npz", tmp_path / "arr"
    )
    assert code == 2 and "--npz" in err and ".npz" in err
    assert list(tmp_path.iterdir()) == []  # refused before anything was written
    npz = tmp_path / "arrays.npz"
    npz.write_bytes(b"mine")
    code, _, err = _run(capsys, "retarget", src, "--target", tgt, "-o", out, "--method", "copy", "--npz", npz)
    assert code == 2 and "arrays.npz exists" in err and "--force" in err
    assert npz.read_bytes() == b"mine" and not out.exists()  # no half result (the BVH was written before)
    code, _, err = _run(
        capsys, "retarget", src, "--target", tgt, "-o", out, "--method", "copy", "--npz", npz, "--force"
    )
    assert code == 0, err
    assert np.load(npz)["local_rot"].shape == (bvh.load(out).num_frames, 22, 4)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arrays.npz", "out.bvh"]  # no temporary files left


def test_npz_failure_leaves_no_bvh(inputs, tmp_path, capsys, monkeypatch):
    src, tgt, _, _ = inputs
    out = tmp_path / "out.bvh"

    def broken(f, **arrays):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(np, "savez", broken)
    code, _, err = _run(
        capsys, "retarget", src, "--target", tgt, "-o", out, "--method", "copy", "--npz", tmp_path / "a.npz"
    )
    assert code == 2 and "no space left" in err.lower()
    assert list(tmp_path.iterdir()) == []
    out.write_text("older result")  # with --force, a failing --npz keeps the old BVH as well
    code, _, err = _run(
        capsys, "retarget", src, "--target", tgt, "-o", out, "--method", "copy", "--npz", tmp_path / "a.npz", "--force"
    )
    assert code == 2 and out.read_text() == "older result"
    assert [p.name for p in tmp_path.iterdir()] == ["out.bvh"]


def test_rig_error_names_the_file_at_fault_and_no_python_option(inputs, tmp_path, capsys):
    src, tgt, _, bad_rig = inputs
    out = tmp_path / "x.bvh"
    code, _, err = _run(capsys, "retarget", bad_rig, "--target", tgt, "-o", out, "--method", "copy")
    assert code == 2 and f"source file {bad_rig}" in err and "LeftLeg" in err
    assert "profile=" not in err
    code, _, err = _run(capsys, "retarget", src, "--target", bad_rig, "-o", out, "--method", "copy")
    assert code == 2 and f"target file {bad_rig}" in err and "profile=" not in err
    assert not out.exists()


def test_evaluate_csv_needs_force_and_is_checked_before_work(tmp_path, capsys):
    csv = tmp_path / "records.csv"
    csv.write_text("mine")
    # the data folder does not exist: the CSV clash must be reported first (before any work)
    code, _, err = _run(capsys, "evaluate", "--data", tmp_path / "nowhere", "--csv", csv)
    assert code == 2 and "records.csv exists" in err and "--force" in err
    assert csv.read_text() == "mine"
    code, _, err = _run(capsys, "evaluate", "--data", tmp_path / "nowhere", "--csv", csv, "--force")
    assert code == 2 and "nowhere" in err  # --force accepted; now the missing folder is the problem
    assert csv.read_text() == "mine"
