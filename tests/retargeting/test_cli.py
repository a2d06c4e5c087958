"""``motionlab retarget / train / evaluate``: help, outputs, and clear user errors."""

from __future__ import annotations

import numpy as np
import pytest

from motionlab import cli
from motionlab.core import bvh, humanoid
from motionlab.retargeting import checkpoint
from motionlab.retargeting.evaluate import ABLATIONS, ROWS


@pytest.fixture(scope="module")
def files(tmp_path_factory, clips, tiny_checkpoint):
    d = tmp_path_factory.mktemp("cli")
    src = bvh.save(d / "source.bvh", clips[0])
    big = humanoid.scale_bones(clips[1].skeleton, legs=1.3, overall=1.2)
    tgt = bvh.save(d / "target.bvh", clips[1].copy(skeleton=big))
    ckpt = checkpoint.save(d / "tiny.pt", tiny_checkpoint)
    return d, src, tgt, ckpt


def _run(capsys, *argv):
    try:
        code = cli.main([str(a) for a in argv])
    except SystemExit as e:  # refused by argparse (a number option's type), naming the option
        code = e.code
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.mark.parametrize("command", ["retarget", "train", "evaluate"])
def test_help(command, capsys):
    with pytest.raises(SystemExit) as e:
        cli.main([command, "--help"])
    assert e.value.code == 0
    assert "usage: motionlab " + command in capsys.readouterr().out


def test_retarget_writes_bvh_and_arrays(files, capsys):
    d, src, tgt, ckpt = files
    out, npz = d / "out.bvh", d / "out.npz"
    code, stdout, err = _run(
        capsys, "retarget", src, "--target", tgt, "-o", out, "--checkpoint", ckpt, "--steps", "3", "--npz", npz
    )
    assert code == 0, err
    assert "L_iter" in stdout
    m = bvh.load(out)
    assert m.num_frames == 120 and m.skeleton.num_joints == 22
    target = humanoid.to_canonical_skeleton(bvh.load(tgt).skeleton)
    np.testing.assert_allclose(m.skeleton.offsets[1:], target.offsets[1:], atol=1e-5)
    arrays = np.load(npz)
    np.testing.assert_allclose(arrays["positions"], m.global_positions(), atol=1e-4)
    # no silent overwrite
    code, _, err = _run(capsys, "retarget", src, "--target", tgt, "-o", out, "--checkpoint", ckpt)
    assert code == 2 and "--force" in err
    code, _, err = _run(capsys, "retarget", src, "--target", tgt, "-o", out, "--method", "copy", "--force", "-q")
    assert code == 0, err


def test_retarget_with_scaled_source_skeleton(files, capsys):
    d, src, _, ckpt = files
    out = d / "legs.bvh"
    code, _, err = _run(
        capsys, "retarget", src, "--scale-legs", "1.2", "-o", out, "--method", "network", "--checkpoint", ckpt, "-q"
    )
    assert code == 0, err
    m = bvh.load(out)
    base = humanoid.to_canonical_skeleton(bvh.load(src).skeleton)
    j = humanoid.JOINTS.index("LeftLeg")
    assert m.skeleton.bone_lengths()[j] == pytest.approx(1.2 * base.bone_lengths()[j], rel=1e-5)


def test_retarget_user_errors(files, capsys, clips):
    d, src, tgt, ckpt = files
    code, _, err = _run(capsys, "retarget", d / "missing.bvh", "--target", tgt, "-o", d / "x.bvh")
    assert code == 2 and "not found" in err
    code, _, err = _run(capsys, "retarget", src, "-o", d / "x.bvh")
    assert code == 2 and "--target" in err
    sk = clips[0].skeleton
    odd = clips[0].copy(skeleton=sk.renamed(["LeftKnee" if n == "LeftLeg" else n for n in sk.names]))
    bad = bvh.save(d / "odd.bvh", odd, overwrite=True)
    code, _, err = _run(capsys, "retarget", bad, "--target", tgt, "-o", d / "x.bvh", "--method", "copy")
    assert code == 2 and "LeftLeg" in err
    broken = d / "broken.pt"
    broken.write_text("nope")
    code, _, err = _run(capsys, "retarget", src, "--target", tgt, "-o", d / "x.bvh", "--checkpoint", broken)
    assert code == 2 and "checkpoint" in err
    code, _, err = _run(capsys, "retarget", src, "--target", tgt, "-o", d / "x.pt")
    assert code == 2 and ".bvh" in err


def _two_characters(tmp_path, clips):
    """``<tmp>/chars/{A,B}/anim<i>.bvh``: the clips on their own skeleton (A) and with 1.2x legs (B)."""
    root = tmp_path / "chars"
    big = humanoid.scale_bones(clips[0].skeleton, legs=1.2)
    for name, sk in (("A", clips[0].skeleton), ("B", big)):
        (root / name).mkdir(parents=True)
        for i, c in enumerate(clips):
            bvh.save(root / name / f"anim{i}.bvh", c.copy(skeleton=sk))
    return root


def test_train_and_evaluate_on_a_small_folder(tmp_path, clips, capsys):
    """Train on one synthetic character, evaluate against a re-proportioned copy of it."""
    root = _two_characters(tmp_path, clips)
    ck = tmp_path / "a.pt"
    code, stdout, err = _run(
        capsys,
        "train",
        root / "A" / "anim0.bvh",
        "-o",
        ck,
        "--train-steps",
        "3",
        "--latent",
        "8",
        "--hidden",
        "16",
        "-q",
    )
    assert code == 0, err
    assert checkpoint.load(ck).info["train_config"]["steps"] == 3
    code, _, err = _run(capsys, "train", root / "A" / "anim0.bvh", "-o", ck)
    assert code == 2 and "--force" in err
    before = ck.read_bytes()
    code, _, err = _run(capsys, "train", root / "A" / "anim0.bvh", "-o", ck, "--force", "--pose-augment", "0.9")
    assert code == 2 and "--pose-augment" in err and "0.9" in err
    assert ck.read_bytes() == before  # refused before any work: the checkpoint is untouched
    code, stdout, err = _run(
        capsys, "evaluate", "--data", root, "--source", "A", "--targets", "B", "--animations", "anim1",
        "--checkpoint", ck, "--steps", "2", "-q", "--csv", tmp_path / "rec.csv",
    )  # fmt: skip
    assert code == 0, err
    for row in ("copy rotations, our root", "no iteration", "full method", "ground truth", "MSE/h²"):
        assert row in stdout
    assert (tmp_path / "rec.csv").read_text().count("\n") == 1 + len(ROWS) + len(ABLATIONS)
    assert "full, paper's two losses" in stdout and "mse_h2 by target" in stdout
    code, stdout, err = _run(
        capsys, "evaluate", "--data", root, "--source", "A", "--targets", "B", "--animations", "anim1",
        "--checkpoint", ck, "--steps", "2", "-q", "--root", "hips",
    )  # fmt: skip
    assert code == 0, err
    assert "copy rotations, root hips" in stdout and "root x leg length" in stdout
    code, _, err = _run(capsys, "evaluate", "--data", root, "--source", "Nobody", "--checkpoint", ck)
    assert code == 2 and "Nobody" in err


@pytest.mark.slow
def test_evaluate_leaves_animations_out_by_folds(tmp_path, clips, capsys):
    """--folds 2: each animation is evaluated by a network trained without it (one checkpoint per fold)."""
    root = _two_characters(tmp_path, clips)
    ck = tmp_path / "a.pt"
    code, stdout, err = _run(
        capsys, "evaluate", "--data", root, "--source", "A", "--targets", "B", "--all-animations", "--folds", "2",
        "--checkpoint", ck, "--train-steps", "2", "--steps", "1", "--no-ablations",
    )  # fmt: skip
    assert code == 0, err
    assert "leave-animations-out: 2 folds" in stdout and "over 2 clips" in stdout
    for k in (1, 2):
        info = checkpoint.load(tmp_path / f"a_fold{k}of2.pt").info
        assert info["clips"] == 1  # trained on the other animation only
    assert not ck.exists()
    code, _, err = _run(capsys, "evaluate", "--data", root, "--source", "A", "--targets", "B", "--folds", "0")
    assert code == 2 and "--folds" in err


@pytest.mark.parametrize(
    "option, value",
    [
        ("--contact-weight", "-1"),
        ("--lr", "nan"),
        ("--lr", "0"),
        ("--steps", "-3"),
        ("--stop-loss", "-1"),
        ("--threshold", "-1"),
        ("--exact-rounds", "9"),
    ],
)
def test_solver_options_refuse_nonsense_by_name(tmp_path, clips, capsys, option, value):
    src = bvh.save(tmp_path / "a.bvh", clips[0])
    code, _, err = _run(capsys, "retarget", src, "--target", src, "-o", tmp_path / "out.bvh", option, value)
    assert code == 2 and option in err and value in err
    assert not (tmp_path / "out.bvh").exists()
