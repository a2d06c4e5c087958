"""The network trained on real motion: cache hits and misses, keys, the lock, missing data, the auto rule."""

from __future__ import annotations

import threading
import time

import pytest
import torch

from motionlab import data, synthetic
from motionlab.core import bvh
from motionlab.retargeting import checkpoint as ck
from motionlab.retargeting import real
from motionlab.retargeting.model import ModelConfig
from motionlab.retargeting.train import TrainConfig
from tests.conftest import require_data
from tests.retargeting.conftest import TINY

FAST = TrainConfig(steps=2, batch_size=2, device="cpu")


@pytest.fixture
def clips(tmp_path, monkeypatch):
    """Two synthetic clips of one character as BVH files, and an empty cache folder."""
    monkeypatch.setenv(real.CACHE_ENV, str(tmp_path / "cache"))
    paths = []
    for i, m in enumerate(synthetic.dataset(2, seed=0, num_frames=150)):
        paths.append(tmp_path / f"clip{i}.bvh")
        bvh.save(paths[-1], m)
    return paths


@pytest.fixture
def trainings(monkeypatch):
    """Counts the trainings :func:`real.trained` runs."""
    import importlib

    train_module = importlib.import_module("motionlab.retargeting.train")
    calls = []
    original = train_module.train

    def counted(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(train_module, "train", counted)
    return calls


def _same_weights(a, b) -> bool:
    sa, sb = a.model.state_dict(), b.model.state_dict()
    return all(torch.equal(sa[k], sb[k]) for k in sa)


def test_a_miss_trains_and_caches_a_hit_loads(clips, trainings, tmp_path):
    first = real.trained(clips, FAST, TINY, progress=False, pinned=False)
    path = real.cached_path(real.cache_key(clips, FAST, TINY))
    assert trainings == [1] and path.is_file() and path.parent == tmp_path / "cache"
    assert first.info["cache_key"] == real.cache_key(clips, FAST, TINY)
    second = real.trained(clips, FAST, TINY, progress=False, pinned=False)
    assert trainings == [1]  # no second training
    assert _same_weights(first, second)


def test_the_key_changes_with_clips_settings_and_network(clips, monkeypatch):
    key = real.cache_key(clips, FAST, TINY)
    assert real.cache_key(clips, FAST, TINY) == key
    with monkeypatch.context() as m:  # another back end trains other weights (docs/reproducibility.md)
        m.setitem(real.PINNED_BACK_END, "MKL_CBWR", "AVX2")
        assert real.cache_key(clips, FAST, TINY) != key
    assert real.cache_key(clips, TrainConfig(steps=3, batch_size=2, device="cpu"), TINY) != key
    assert real.cache_key(clips, FAST, ModelConfig()) != key
    assert real.cache_key(clips[::-1], FAST, TINY) != key
    clips[0].write_bytes(clips[0].read_bytes().replace(b"Frame Time", b"Frame  Time"))  # same motion, other bytes
    assert real.cache_key(clips, FAST, TINY) != key


def test_a_changed_clip_is_trained_again(clips, trainings):
    real.trained(clips, FAST, TINY, progress=False, pinned=False)
    text = clips[1].read_text().rstrip("\n").rsplit("\n", 1)[0] + "\n"  # one frame fewer
    clips[1].write_text(text.replace("Frames: 150", "Frames: 149"))
    real.trained(clips, FAST, TINY, progress=False, pinned=False)
    assert trainings == [1, 1]


def test_a_second_process_waits_for_the_first_and_does_not_train(clips, trainings):
    import fcntl

    path = real.cached_path(real.cache_key(clips, FAST, TINY))
    path.parent.mkdir(parents=True)
    got = {}
    with open(path.with_suffix(".lock"), "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # "the first process", training
        waiter = threading.Thread(
            target=lambda: got.update(ckpt=real.trained(clips, FAST, TINY, progress=False, pinned=False))
        )
        waiter.start()
        time.sleep(1.0)
        assert waiter.is_alive() and not got  # it waits for the lock
        from motionlab.retargeting.train import train as plain_train

        done, _ = plain_train([bvh.load(p) for p in clips], FAST, TINY, progress=False)
        ck.save(path, done)  # the first process's result
        trainings.clear()
        fcntl.flock(lock, fcntl.LOCK_UN)
    waiter.join(60)
    assert not waiter.is_alive() and trainings == []  # it loaded the first one's network
    assert _same_weights(got["ckpt"], done)


@pytest.mark.slow
def test_pinned_training_runs_in_a_child_and_gives_the_same_weights_again(clips, tmp_path, monkeypatch):
    first = real.trained(clips, FAST, TINY, progress=False)
    assert first.info["cache_key"] == real.cache_key(clips, FAST, TINY)
    monkeypatch.setenv(real.CACHE_ENV, str(tmp_path / "another_cache"))
    again = real.trained(clips, FAST, TINY, progress=False)
    assert _same_weights(first, again)


def test_a_failing_child_is_reported(clips, monkeypatch):
    monkeypatch.setattr(real.sys, "executable", real.sys.executable + "-missing")
    with pytest.raises(OSError):  # no such interpreter: nothing cached
        real.trained(clips, FAST, TINY, progress=False)
    assert not real.cached_path(real.cache_key(clips, FAST, TINY)).exists()


def test_a_damaged_cache_file_is_named(clips):
    path = real.cached_path(real.cache_key(clips, FAST, TINY))
    path.parent.mkdir(parents=True)
    path.write_bytes(b"not a checkpoint")
    with pytest.raises(ck.CheckpointError, match="delete .* and it is trained again"):
        real.trained(clips, FAST, TINY, progress=False, pinned=False)


def test_without_the_course_data_load_real_names_motionlab_data(tmp_path, monkeypatch):
    monkeypatch.setenv(data.ENV_VAR, str(tmp_path / "nowhere"))
    with pytest.raises(data.DataNotFound, match=data.ENV_VAR):
        real.load_real()
    with pytest.raises(data.DataNotFound, match=data.ENV_VAR):
        real.choose("real")
    assert real.choose("auto", real_source=True) == "synthetic"  # the shipped network, no error


def test_the_cli_refuses_network_real_without_data(tmp_path, monkeypatch, capsys):
    from motionlab import cli

    monkeypatch.setenv(data.ENV_VAR, str(tmp_path / "nowhere"))
    src = tmp_path / "walk.bvh"
    bvh.save(src, synthetic.dataset(1, seed=0, num_frames=60)[0])
    code = cli.main(["retarget", str(src), "--scale-legs", "1.2", "-o", str(tmp_path / "out.bvh"), "--network", "real"])
    assert code != 0 and data.ENV_VAR in capsys.readouterr().err
    assert not (tmp_path / "out.bvh").exists()


def test_the_auto_rule(tmp_path):
    assert real.choose("synthetic", real_source=True) == "synthetic"
    assert real.choose("auto", real_source=False) == "synthetic"
    with pytest.raises(ValueError, match="network must be one of"):
        real.choose("shipped")
    m = synthetic.dataset(1, seed=0, num_frames=30)[0]
    bvh.save(tmp_path / "synthetic.bvh", m)
    (tmp_path / "garbage.bvh").write_text("HIERARCHY\nROOT Hips\n{\n")  # unreadable: not a recorded clip
    assert not real.is_real_rig(m.skeleton)
    assert not real.any_real_file([tmp_path / "garbage.bvh", tmp_path / "synthetic.bvh", tmp_path / "missing.bvh"])
    aj = require_data("mixamo", "Aj", "Running.bvh")
    assert real.is_real_rig(bvh.load(aj).skeleton) and real.any_real_file([tmp_path / "garbage.bvh", aj])
    assert real.choose("auto", real_source=True) == "real"


def test_evaluate_and_load_real_train_one_network(monkeypatch):
    """``motionlab evaluate`` without --checkpoint asks the cache for the same clips and settings as load_real."""
    from motionlab.retargeting.cli import _fold_checkpoint
    from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS

    folder = require_data("mixamo")
    asked = {}

    def fake_trained(paths, config, *args, **kwargs):
        asked["key"] = real.cache_key(paths, config)
        return "network"

    from motionlab import cli

    args = cli.build_parser().parse_args(["evaluate"])
    monkeypatch.setattr(real, "trained", fake_trained)
    assert _fold_checkpoint(args, folder, None, list(DEFAULT_ANIMATIONS)) == "network"
    assert asked["key"] == real.cache_key(real.training_paths(), real.train_config())


@pytest.mark.slow
@pytest.mark.real_network
def test_the_real_network_reconstructs_held_out_real_clips_better_than_the_shipped_one():
    """Trained once per cache (minutes the first time): on Aj's 10 clips it never saw, the
    reconstruction error is below the shipped synthetic-motion network's."""
    from experiments.retargeting.reproducibility import _held_out_error
    from motionlab.retargeting import load_default
    from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS

    require_data("mixamo", "Aj")
    held = [bvh.load(data.clip_path("mixamo", "Aj", a)) for a in DEFAULT_ANIMATIONS]
    ours, shipped = real.load_real("cpu", progress=False), load_default("cpu")
    assert not any(p.stem in DEFAULT_ANIMATIONS for p in real.training_paths())
    assert _held_out_error(ours, held) < 0.5 * _held_out_error(shipped, held)


def test_the_cli_says_which_network_it_uses(tmp_path, capsys):
    from motionlab import cli

    src = tmp_path / "walk.bvh"
    bvh.save(src, synthetic.dataset(1, seed=0, num_frames=60)[0])
    argv = ["retarget", str(src), "--scale-legs", "1.2", "-o", str(tmp_path / "out.bvh"), "--steps", "2"]
    assert cli.main(argv) == 0
    assert "network: the shipped one" in capsys.readouterr().out  # a source on motionlab's synthetic rig
    assert cli.main(argv + ["--force", "--checkpoint", str(tmp_path / "none.pt"), "--network", "synthetic"]) != 0
    assert "not both" in capsys.readouterr().err
