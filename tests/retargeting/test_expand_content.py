"""``expand`` reuses an output only when its content is unchanged, and flags implausible outputs.

Resumption is keyed on the SHA-256 of the source file, of the character (file bytes or preset
factors) and of every option that changes the result; each kind of change is redone, with the
reason counted in the summary. A run mixing plausible and implausible pairs flags only the
implausible ones (manifest ``flag``) and exits 1 unless ``--keep-implausible``.
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from motionlab import retargeting, synthetic
from motionlab.cli import main
from motionlab.core import bvh
from motionlab.core.motion import Motion
from motionlab.retargeting import expand as ex
from motionlab.retargeting.solver import SolverConfig

FAST = SolverConfig(max_steps=4)


@pytest.fixture(scope="module")
def ckpt():
    return retargeting.load_default("cpu")


@pytest.fixture
def lib(tmp_path):
    """One 30-frame clip and one character rig as files the test may change."""
    (tmp_path / "clips").mkdir()
    bvh.save(tmp_path / "clips" / "walk.bvh", synthetic.dataset(1, seed=1, num_frames=30)[0])
    (tmp_path / "rigs").mkdir()
    _rig(tmp_path / "rigs" / "hero.bvh", seed=5)
    return tmp_path


def _rig(path, seed):
    c = synthetic.character_set(1, seed=seed)[0]
    bvh.save(path, Motion(c, np.tile([1.0, 0, 0, 0], (2, 22, 1)), np.tile([0, 1.0, 0], (2, 1)), 60.0), overwrite=True)


def _run(lib, ckpt, solver=FAST, **kw):
    chars = ex.characters(str(lib / "rigs" / "hero.bvh"), presets=["tall"])
    return ex.expand([str(lib / "clips" / "walk.bvh")], chars, lib / "out", ckpt, solver, **kw)


def test_unchanged_is_reused_with_its_hashes(lib, ckpt):
    first = _run(lib, ckpt)
    assert first.done == 2 and all(r["source_sha256"] and r["options_sha256"] for r in first.rows)
    again = _run(lib, ckpt)
    assert again.done == 0 and again.skipped == 2 and again.redone == {}


def test_changed_character_file_under_the_same_name_is_redone(lib, ckpt):
    _run(lib, ckpt)
    _rig(lib / "rigs" / "hero.bvh", seed=9)
    job = _run(lib, ckpt)
    assert job.done == 1 and job.skipped == 1 and job.redone == {"character changed": 1}
    assert "1 redone: 1 character changed" in job.summary()
    row = next(r for r in job.rows if r["character"] == "hero")
    assert row["character_sha256"] == ex.characters(str(lib / "rigs" / "hero.bvh"))[0].digest


def test_changed_source_with_the_same_file_name_is_redone(lib, ckpt):
    _run(lib, ckpt)
    bvh.save(lib / "clips" / "walk.bvh", synthetic.dataset(1, seed=7, num_frames=30)[0], overwrite=True)
    job = _run(lib, ckpt)
    assert job.done == 2 and job.redone == {"source changed": 2}


@pytest.mark.parametrize(
    "change",
    [{"solver": SolverConfig(max_steps=5)}, {"root_mode": "hips"}, {"fps": 30.0}],
    ids=["steps", "root", "fps"],
)
def test_changed_option_is_redone(lib, ckpt, change):
    _run(lib, ckpt)
    job = _run(lib, ckpt, **change)
    assert job.done == 2 and job.redone == {"options changed": 2}
    assert _run(lib, ckpt, **change).skipped == 2  # and then kept


def test_another_motionlab_redoes_what_an_older_one_wrote(lib, ckpt, monkeypatch):
    """An upgrade may write other outputs (stop 66 raised every Bandai Namco target by its sole):
    its rows are redone, not kept."""
    _run(lib, ckpt)
    assert _run(lib, ckpt).skipped == 2
    monkeypatch.setattr(ex, "code_digest", lambda: b"another motionlab")
    job = _run(lib, ckpt)
    assert job.done == 2 and job.redone == {"options changed": 2}


def test_missing_file_and_old_manifest_are_redone(lib, ckpt):
    _run(lib, ckpt)
    (lib / "out" / "hero" / "walk.bvh").unlink()
    assert _run(lib, ckpt).redone == {"file missing": 1}
    # a manifest written before the content keys: its rows have no hashes, so all are redone
    text = (lib / "out" / ex.MANIFEST).read_text().splitlines()
    old = [",".join(line.split(",")[: len(ex.COLUMNS) - 4]) for line in text]
    (lib / "out" / ex.MANIFEST).write_text("\n".join(old) + "\n")
    assert _run(lib, ckpt).redone == {"source changed": 2}


def test_mixed_run_flags_only_the_implausible_pairs(lib, ckpt, capsys):
    """Root scaled by thigh + shin sinks a very short-legged character's feet into the floor."""
    shutil.rmtree(lib / "out", ignore_errors=True)
    chars = ex.characters(str(lib / "rigs" / "hero.bvh"), presets=["stubby:legs=0.3"])
    job = ex.expand([str(lib / "clips" / "walk.bvh")], chars, lib / "out", ckpt, FAST, root_mode="legs")
    flags = {r["character"]: r["flag"] for r in job.rows}
    assert "implausible_foot" in flags["stubby"] and "implausible" not in flags["hero"]
    assert job.implausible == 1 and "1 implausible" in job.summary()
    argv = ["expand", str(lib / "clips" / "walk.bvh"), "--characters", str(lib / "rigs" / "hero.bvh")]
    argv += ["--preset", "stubby:legs=0.3", "--root", "legs", "--steps", "4", "-q", "--force"]
    assert main(argv + ["-o", str(lib / "cli")]) == 1
    assert "failed the plausibility check" in capsys.readouterr().err
    assert main(argv + ["-o", str(lib / "cli"), "--keep-implausible"]) == 0
    assert (lib / "cli" / "stubby" / "walk.bvh").is_file()  # written and flagged either way


def test_resample_is_reported_also_under_quiet(lib, capsys):
    bvh.save(lib / "clips" / "slow.bvh", synthetic.dataset(1, seed=1, num_frames=20, fps=30)[0])
    argv = ["expand", str(lib / "clips" / "slow.bvh"), "--preset", "tall", "-o", str(lib / "o30"), "-q"]
    assert main(argv + ["--steps", "2"]) == 0
    err = capsys.readouterr().err
    assert "slow.bvh: resampled: source 30 fps -> network 60 fps -> output 30 fps" in err
    assert bvh.load(lib / "o30" / "tall" / "slow.bvh").fps == pytest.approx(30, rel=1e-4)


def test_a_source_rate_the_network_cannot_hit_keeps_every_frame(lib, capsys):
    """120 fps with an even count: the network's 60 fps ends half a frame early; the output keeps all 20."""
    bvh.save(lib / "clips" / "fast.bvh", synthetic.dataset(1, seed=1, num_frames=20, fps=120)[0])
    argv = ["expand", str(lib / "clips" / "fast.bvh"), "--preset", "tall", "-o", str(lib / "o120"), "-q"]
    assert main(argv + ["--steps", "2"]) == 0
    assert bvh.load(lib / "o120" / "tall" / "fast.bvh").num_frames == 20
    out = lib / "r120.bvh"
    assert (
        main(["retarget", str(lib / "clips" / "fast.bvh"), "--scale", "1.1", "-o", str(out), "-q", "--steps", "2"]) == 0
    )
    assert bvh.load(out).num_frames == 20


def test_sources_of_one_name_in_folders_of_one_name_are_all_expanded(tmp_path):
    clip = synthetic.dataset(1, seed=1, num_frames=20, fps=60)[0]
    for folder in ("a/take", "b/take"):
        (tmp_path / folder).mkdir(parents=True)
        bvh.save(tmp_path / folder / "Run.bvh", clip)
    (tmp_path / "c").mkdir()
    bvh.save(tmp_path / "c" / "Walk.BVH", clip)
    specs = [str(tmp_path / "a/take/Run.bvh"), str(tmp_path / "b/take/Run.bvh"), str(tmp_path / "c")]
    found = ex.find_sources([*specs, str(tmp_path / "a/take/../take/Run.bvh")])  # one file by two paths: once
    assert [name for name, _ in found] == ["a_take_Run", "b_take_Run", "Walk"]
    with pytest.raises(ValueError, match="manifest"):
        ex.characters(f"{ex.MANIFEST}={tmp_path / 'c' / 'Walk.BVH'}")
