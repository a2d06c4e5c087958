"""The retargeting network trained on real motion: trained from the course data on first use, then cached.

Paper A trains its network on the source character's own motion. motionlab's shipped network
(:func:`motionlab.retargeting.load_default`) is trained on its synthetic motion, because the
licences of the course data (Mixamo's clips, ``docs/rigs.md``) do not allow shipping weights
trained on them. So the network for real motion is trained on the user's machine, once, from
``MOTIONLAB_DATA``: Aj's Mixamo clips except Table 1's 10 evaluated animations
(:func:`training_paths`), with :func:`train_config` — the same clips and settings as
``motionlab evaluate``'s network, so Table 1's network and this one are one network.

::

    ckpt = retargeting.load_real()          # trains once, then loads from the cache

**Cache.** The checkpoint lies in :func:`cache_dir` (``$MOTIONLAB_CACHE``, else
``~/.cache/motionlab``) under a name holding :func:`cache_key`: a SHA-256 of the training clips'
names and bytes, the training and network settings, the source of the modules that compute the
training, and torch's version. A changed clip, setting or training code is a new key, never an
old network. It is written atomically, and a lock file (POSIX ``flock``) makes a second process
wait for the first one's training instead of training again. With :attr:`TrainConfig.grid` the
weights are the same on every CPU (``docs/reproducibility.md``); training always runs on the CPU,
so the cached network is the same whatever device it is loaded on.

**Which network for which source** (:func:`choose`): the network trained on motion of the source's
kind — the real network for real mocap when the course data is there, the shipped one for
motionlab's synthetic motion or when the course data is missing (``docs/rigs.md``).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import sys
from collections.abc import Callable, Sequence
from dataclasses import asdict
from pathlib import Path

import torch

from motionlab.retargeting import checkpoint as ck
from motionlab.retargeting.checkpoint import Checkpoint
from motionlab.retargeting.model import ModelConfig

__all__ = [
    "CACHE_ENV",
    "SOURCE",
    "NETWORKS",
    "cache_dir",
    "training_paths",
    "train_config",
    "cache_key",
    "cached_path",
    "trained",
    "load_real",
    "available",
    "choose",
    "is_real_rig",
    "is_real_file",
    "for_source",
]

CACHE_ENV = "MOTIONLAB_CACHE"
SOURCE = "Aj"
"""The character whose clips train the real network (the source of Table 1)."""
NETWORKS = ("auto", "real", "synthetic")
"""The choices of :func:`choose` (and the CLI's ``--network``)."""
TRAINING_CODE = (
    "retargeting/train.py",
    "retargeting/model.py",
    "retargeting/losses.py",
    "retargeting/features.py",
    "retargeting/solver.py",
    "core/preprocess.py",
    "core/quat_torch.py",
    "core/humanoid.py",
    "core/bvh.py",
)
"""Modules (relative to the package) whose source is part of :func:`cache_key`."""
_PACKAGE = Path(__file__).resolve().parent.parent


def cache_dir() -> Path:
    """``$MOTIONLAB_CACHE`` when set, else ``~/.cache/motionlab`` (not created here)."""
    value = os.environ.get(CACHE_ENV, "").strip()
    return Path(value).expanduser() if value else Path.home() / ".cache" / "motionlab"


def training_paths() -> list[Path]:
    """Aj's Mixamo clips in ``MOTIONLAB_DATA`` but Table 1's 10 (:func:`.evaluate.training_clips`).

    Raises
    ------
    motionlab.data.DataNotFound (a FileNotFoundError) naming ``MOTIONLAB_DATA`` when the course
    data or Aj's clips are missing.
    """
    from motionlab import data
    from motionlab.retargeting.evaluate import DEFAULT_ANIMATIONS, training_clips

    root = data.data_root()  # raises DataNotFound with the how-to
    if not (root / "mixamo" / SOURCE).is_dir():
        raise data.DataNotFound(
            f"the network for real motion is trained on {SOURCE}'s Mixamo clips, but {root / 'mixamo' / SOURCE} "
            f"is missing: {data.HOW_TO}"
        )
    return training_clips(root / "mixamo", SOURCE, DEFAULT_ANIMATIONS)


def train_config(**changes):
    """The :class:`.train.TrainConfig` of the real network (and of ``motionlab evaluate``): the
    defaults, seed 0, on the CPU; ``changes`` replace fields (``steps=``, ``seed=``, ``grid=``)."""
    from motionlab.retargeting.train import TrainConfig

    return TrainConfig(**{"seed": 0, "device": "cpu", **changes})


def cache_key(paths: Sequence[str | os.PathLike], config, model_config: ModelConfig | None = None) -> str:
    """SHA-256 (hex) of what the trained network depends on: each clip's name and bytes (in
    order), ``config`` and ``model_config`` (defaults if None), the source of :data:`TRAINING_CODE`
    and torch's version. Raises ``FileNotFoundError`` for a missing clip."""
    h = hashlib.sha256()
    settings = {"train": asdict(config), "model": (model_config or ModelConfig()).to_dict(), "torch": torch.__version__}
    h.update(json.dumps(settings, sort_keys=True).encode())
    for name in TRAINING_CODE:
        h.update(name.encode() + b"\0" + (_PACKAGE / name).read_bytes())
    for p in paths:
        p = Path(p)
        h.update(p.name.encode() + b"\0" + hashlib.sha256(p.read_bytes()).digest())
    return h.hexdigest()


_KEYS: dict = {}


def _memo_key(paths, config, model_config) -> str:
    """:func:`cache_key`, remembered in this process while no clip's size or modification time changes."""
    stamp = tuple((str(p), os.stat(p).st_mtime_ns, os.stat(p).st_size) for p in paths)
    memo = (stamp, repr(config), repr(model_config))
    if memo not in _KEYS:
        _KEYS[memo] = cache_key(paths, config, model_config)
    return _KEYS[memo]


def cached_path(key: str, name: str = SOURCE) -> Path:
    """Where the network of ``key`` is cached: ``cache_dir()/retarget_<name>_<key[:16]>.pt``."""
    return cache_dir() / f"retarget_{name.lower()}_{key[:16]}.pt"


@contextlib.contextmanager
def _locked(path: Path, say: Callable[[str], None]):
    """Hold an exclusive lock on ``path`` (created if missing) for the block; where ``fcntl`` is
    missing (Windows) no lock is taken."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    with open(path, "a") as f:
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            say(f"another process is training this network ({path}); waiting for it")
            fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)


def _load_cached(path: Path, device, dtype: str) -> Checkpoint:
    try:
        return ck.load(path, device, dtype)
    except ck.CheckpointError as e:
        raise ck.CheckpointError(f"{e}; delete {path} and it is trained again") from None


def trained(
    paths: Sequence[str | os.PathLike],
    config=None,
    model_config: ModelConfig | None = None,
    device=None,
    dtype: str = "float64",
    progress: bool = True,
    name: str = SOURCE,
) -> Checkpoint:
    """The network trained on the clips ``paths`` (one character) with ``config``: from the cache
    when :func:`cache_key` has it, else trained (under a lock), cached atomically, and returned.

    ``device`` and ``dtype`` are where and how the returned network computes
    (:func:`.checkpoint.load`); the training runs on ``config.device``. With ``progress`` a line
    says that it trains once and where it caches, and a bar shows the training.

    Raises
    ------
    FileNotFoundError for a missing clip; CheckpointError naming a damaged cached file.
    """
    from motionlab.core import bvh
    from motionlab.retargeting.train import train

    config = config or train_config()
    key = _memo_key(paths, config, model_config)
    path = cached_path(key, name)
    if path.is_file():
        return _load_cached(path, device, dtype)
    say = (lambda m: print(m, file=sys.stderr, flush=True)) if progress else (lambda m: None)
    path.parent.mkdir(parents=True, exist_ok=True)
    with _locked(path.with_suffix(".lock"), say):
        if path.is_file():  # trained by the process we waited for
            return _load_cached(path, device, dtype)
        say(
            f"training the retargeting network on {len(paths)} clips of {name} once ({config.steps} steps on the "
            f"{config.device or 'default device'}, minutes); it is cached in {path}"
        )
        ckpt, _ = train([bvh.load(p) for p in paths], config, model_config, progress=progress)
        ckpt.info["source"] = [Path(p).name for p in paths]
        ckpt.info["cache_key"] = key
        ck.save(path, ckpt, overwrite=False)
    return _load_cached(path, device, dtype)


def load_real(device=None, dtype: str = "float64", progress: bool = True) -> Checkpoint:
    """The network trained on real motion (:func:`training_paths`, :func:`train_config`), from
    the cache or trained now (see :func:`trained`), on ``device`` computing in ``dtype``.

    Raises
    ------
    motionlab.data.DataNotFound naming ``MOTIONLAB_DATA`` when the course data is missing.
    """
    return trained(training_paths(), train_config(), device=device, dtype=dtype, progress=progress)


def available() -> bool:
    """True when the course data holds the clips :func:`load_real` trains on."""
    from motionlab import data

    return data.has_data("mixamo", SOURCE)


def choose(network: str = "auto", real_source: bool = True) -> str:
    """``"real"`` or ``"synthetic"``: which network retargets a source.

    ``network`` is one of :data:`NETWORKS`; ``"auto"`` picks the network trained on motion of the
    source's kind (paper A trains on the source character's own motion): ``"real"`` when
    ``real_source`` (a recorded clip, not motionlab's synthetic motion) and the course data is
    there (:func:`available`), else ``"synthetic"`` (the shipped network).

    Raises
    ------
    ValueError for another ``network``; motionlab.data.DataNotFound for ``"real"`` without the
    course data.
    """
    if network not in NETWORKS:
        raise ValueError(f"network must be one of {NETWORKS}, got {network!r}")
    if network == "real" and not available():
        from motionlab import data

        raise data.DataNotFound(f"the real network is trained on {SOURCE}'s Mixamo clips: {data.HOW_TO}")
    if network != "auto":
        return network
    return "real" if real_source and available() else "synthetic"


def is_real_rig(skeleton) -> bool:
    """True for a recorded clip's rig: any rig but the 22-joint canonical one, which is the rig of
    motionlab's synthetic motion (and of motionlab's own outputs)."""
    from motionlab.core import humanoid

    return not humanoid.is_canonical(skeleton)


def is_real_file(path: str | os.PathLike) -> bool:
    """:func:`is_real_rig` of a BVH file's rig, from the joint names of its HIERARCHY alone.

    Raises
    ------
    OSError when the file cannot be read.
    """
    from motionlab.core import humanoid

    names = []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            words = line.split()
            if words and words[0] == "MOTION":
                break
            if len(words) >= 2 and words[0] in ("ROOT", "JOINT"):
                names.append(humanoid.strip_prefix(words[1]))
    return tuple(names) != humanoid.JOINTS


def for_source(
    real_source: bool, network: str = "auto", device=None, dtype: str = "float64", progress: bool = True
) -> tuple[Checkpoint, str]:
    """The network for a source (:func:`choose`; ``real_source``: :func:`is_real_rig` of its rig)
    and one line saying which it is and why.

    Raises
    ------
    ValueError for an unknown ``network``; motionlab.data.DataNotFound for ``"real"`` without the
    course data.
    """
    which = choose(network, real_source)
    if which == "real":
        ckpt = load_real(device, dtype, progress)
        why = "real mocap source" if network == "auto" else "asked for"
        line = f"network: trained on {SOURCE}'s real clips, cached in {cache_dir()} ({why})"
        return ckpt, line
    from motionlab.retargeting import load_default

    if network != "auto":
        why = "asked for"
    elif real_source:
        why = f"real mocap source, but no course data: {CACHE_ENV.replace('CACHE', 'DATA')} is not set"
    else:
        why = "source on motionlab's synthetic (canonical 22-joint) rig"
    return load_default(device, dtype), f"network: the shipped one, trained on motionlab's synthetic motion ({why})"
