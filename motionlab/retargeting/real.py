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
wait for the first one's training instead of training again. Training runs on the CPU, in a child
process under one pinned numeric back end (:data:`PINNED_BACK_END`), so the cached network is the
same on every machine and whatever device it is loaded on (``docs/reproducibility.md``).

**Which network for which source** (:func:`choose`): the network trained on motion of the source's
kind — the real network for real mocap when the course data is there, the shipped one for
motionlab's synthetic motion or when the course data is missing (``docs/rigs.md``).
"""

from __future__ import annotations

import contextlib
import csv
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
    "DEFAULT_SOURCE",
    "DEFAULT_ANIMATIONS",
    "training_clips",
    "NETWORKS",
    "PINNED_BACK_END",
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
    "any_real_file",
    "for_source",
]

CACHE_ENV = "MOTIONLAB_CACHE"
DEFAULT_SOURCE = "Aj"
"""The character whose clips train the real network: the source of Table 1."""
DEFAULT_ANIMATIONS = (
    "Running", "Jumping", "Body_Jab_Cross", "Standing_To_Crouch", "Catwalk_Idle_To_Walk_Forward",
    "Run_Arc_Left", "Injured_Walk_Left_Turn", "Standing_Turn_Right_90", "Jazz_Dancing",
    "Standing_Land_To_Standing_Idle",
)  # fmt: skip
"""The 10 ``retarget_gt`` animations of the shared Mixamo data."""

PINNED_BACK_END = {
    "ATEN_CPU_CAPABILITY": "avx2",
    "MKL_CBWR": "COMPATIBLE",
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "OPENBLAS_CORETYPE": "Haswell",
    "NPY_DISABLE_CPU_FEATURES": "X86_V4 AVX512_ICL AVX512_SPR",
}
"""The numeric back end the cached network is trained under (a child process): torch's AVX2
kernels, MKL's compatible code path (the one branch MKL takes alike on Intel and AMD
processors), OpenBLAS's Haswell kernels, numpy without AVX-512, one thread; CI's pinned test pass
uses the same settings. ``docs/reproducibility.md`` compares the weights of other back ends."""
NETWORKS = ("auto", "real", "synthetic")
"""The choices of :func:`choose` (and the CLI's ``--network``)."""
TRAINING_CODE = (
    "retargeting/train.py",
    "retargeting/model.py",
    "retargeting/losses.py",
    "retargeting/features.py",
    "retargeting/grid.py",
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


def training_clips(
    folder: str | Path, source: str = DEFAULT_SOURCE, exclude: Sequence[str] = DEFAULT_ANIMATIONS
) -> list[Path]:
    """A's training clips in ``folder``.

    If a ``manifest.csv`` with ``path``, ``purpose`` and ``subject`` columns sits in the folder or
    its parent (the shared data does), the rows with ``purpose == "train_character"`` and
    ``subject == source`` inside ``folder`` are used; otherwise every ``<source>/*.bvh`` whose
    stem is not in ``exclude``. Evaluated animations are always excluded.

    Raises
    ------
    FileNotFoundError when the source's folder is missing or holds no training clip.
    """
    folder = Path(folder)
    excluded = {e.lower() for e in exclude}
    for manifest in (folder / "manifest.csv", folder.parent / "manifest.csv"):
        if manifest.is_file():
            with open(manifest, newline="") as f:
                rows = list(csv.DictReader(f))
            if rows and {"path", "purpose", "subject"} <= set(rows[0]):
                paths = [
                    (manifest.parent / r["path"]).resolve()
                    for r in rows
                    if r["purpose"] == "train_character" and r["subject"] == source
                ]
                paths = [
                    p for p in paths
                    if p.is_file() and p.is_relative_to(folder.resolve()) and p.stem.lower() not in excluded
                ]  # fmt: skip
                if paths:
                    return sorted(paths)
    src = folder / source
    if not src.is_dir():
        raise FileNotFoundError(f"no folder {src} (expected <Character>/<Animation>.bvh under {folder})")
    paths = sorted(p for p in src.glob("*.bvh") if p.stem.lower() not in excluded)
    if not paths:
        raise FileNotFoundError(f"no training clips for {source!r} in {src} (all excluded or none present)")
    return paths


def training_paths() -> list[Path]:
    """Aj's Mixamo clips in ``MOTIONLAB_DATA`` but Table 1's 10 (:func:`training_clips`).

    Raises
    ------
    motionlab.data.DataNotFound (a FileNotFoundError) naming ``MOTIONLAB_DATA`` when the course
    data or Aj's clips are missing.
    """
    from motionlab import data

    root = data.data_root()  # raises DataNotFound with the how-to
    if not (root / "mixamo" / DEFAULT_SOURCE).is_dir():
        raise data.DataNotFound(
            f"the network for real motion is trained on {DEFAULT_SOURCE}'s Mixamo clips, but {root / 'mixamo' / DEFAULT_SOURCE} "
            f"is missing: {data.HOW_TO}"
        )
    return training_clips(root / "mixamo", DEFAULT_SOURCE, DEFAULT_ANIMATIONS)


def train_config(**changes):
    """The :class:`.train.TrainConfig` of the real network (and of ``motionlab evaluate``): the
    defaults, seed 0, on the CPU; ``changes`` replace fields (``steps=``, ``seed=``, ``grid=``)."""
    from motionlab.retargeting.train import TrainConfig

    return TrainConfig(**{"seed": 0, "device": "cpu", **changes})


def cache_key(paths: Sequence[str | os.PathLike], config, model_config: ModelConfig | None = None) -> str:
    """SHA-256 (hex) of what the trained network depends on: each clip's name and bytes (in
    order), ``config`` and ``model_config`` (defaults if None), the source of :data:`TRAINING_CODE`,
    torch's version and :data:`PINNED_BACK_END`. Raises ``FileNotFoundError`` for a missing clip."""
    h = hashlib.sha256()
    settings = {
        "train": asdict(config),
        "model": (model_config or ModelConfig()).to_dict(),
        "torch": torch.__version__,
        "back end": PINNED_BACK_END,
    }
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


def cached_path(key: str, name: str = DEFAULT_SOURCE) -> Path:
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


def _train_and_save(paths, config, model_config, path: Path, key: str, progress: bool) -> None:
    """Train on ``paths`` and write the checkpoint to ``path`` (atomic; refuses an existing file)."""
    from motionlab.core import bvh
    from motionlab.retargeting.train import train

    ckpt, _ = train([bvh.load(p) for p in paths], config, model_config, progress=progress)
    ckpt.info["source"] = [Path(p).name for p in paths]
    ckpt.info["cache_key"] = key
    ck.save(path, ckpt, overwrite=False)


def _train_pinned(paths, config, model_config, path: Path, key: str, progress: bool) -> None:
    """:func:`_train_and_save` in a child process under :data:`PINNED_BACK_END`.

    Raises
    ------
    RuntimeError with the child's last error lines when it fails.
    """
    import subprocess

    job = {
        "paths": [str(p) for p in paths],
        "config": asdict(config),
        "model": (model_config or ModelConfig()).to_dict(),
        "path": str(path),
        "key": key,
        "progress": progress,
    }
    env = dict(os.environ, **PINNED_BACK_END)
    code = "import sys; from motionlab.retargeting import real; real._child(sys.stdin.read())"
    errors = None if progress else subprocess.PIPE  # with progress the child's bar shows as it runs
    done = subprocess.run([sys.executable, "-c", code], input=json.dumps(job), env=env, stderr=errors, text=True)
    if done.returncode:
        said = (done.stderr or "")[-3000:]
        raise RuntimeError(f"training the network failed (exit status {done.returncode}); {said or 'see above'}")


def _child(text: str) -> None:
    """The child process of :func:`_train_pinned`: ``text`` is its job as JSON."""
    from motionlab.retargeting.train import TrainConfig

    job = json.loads(text)
    model = ModelConfig(**job["model"])
    config = TrainConfig(**job["config"])
    _train_and_save(job["paths"], config, model, Path(job["path"]), job["key"], job["progress"])


def trained(
    paths: Sequence[str | os.PathLike],
    config=None,
    model_config: ModelConfig | None = None,
    device=None,
    dtype: str = "float64",
    progress: bool = True,
    name: str = DEFAULT_SOURCE,
    pinned: bool = True,
) -> Checkpoint:
    """The network trained on the clips ``paths`` (one character) with ``config``: from the cache
    when :func:`cache_key` has it, else trained (under a lock), cached atomically, and returned.

    ``device`` and ``dtype`` are where and how the returned network computes
    (:func:`.checkpoint.load`); the training runs on ``config.device``, with ``pinned`` in a child
    process under :data:`PINNED_BACK_END` (the same weights on every x86 CPU with AVX2). With
    ``progress`` a line says that it trains once and where it caches, and a bar shows the training.

    Raises
    ------
    FileNotFoundError for a missing clip; CheckpointError naming a damaged cached file;
    RuntimeError when the pinned child process fails.
    """
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
        (_train_pinned if pinned else _train_and_save)(paths, config, model_config, path, key, progress)
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

    return data.has_data("mixamo", DEFAULT_SOURCE)


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

        raise data.DataNotFound(f"the real network is trained on {DEFAULT_SOURCE}'s Mixamo clips: {data.HOW_TO}")
    if network != "auto":
        return network
    return "real" if real_source and available() else "synthetic"


def is_real_rig(skeleton) -> bool:
    """True for a recorded clip's rig: any rig but the 22-joint canonical one, which is the rig of
    motionlab's synthetic motion (and of motionlab's own outputs)."""
    from motionlab.core import humanoid

    return not humanoid.is_canonical(skeleton)


def any_real_file(paths: Sequence[str | os.PathLike]) -> bool:
    """True when one of the BVH files ``paths`` is a recorded clip (:func:`is_real_rig`) whose rig
    maps onto the humanoid; files that cannot be read or mapped do not count. Reads the files in
    order and stops at the first such clip."""
    from motionlab.core import bvh, humanoid

    for p in paths:
        try:
            skeleton = bvh.load(p).skeleton
            humanoid.find_mapping(skeleton)
        except (OSError, ValueError):  # BVHError and RigMappingError are ValueErrors
            continue
        if is_real_rig(skeleton):
            return True
    return False


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
        line = f"network: trained on {DEFAULT_SOURCE}'s real clips, cached in {cache_dir()} ({why})"
        return ckpt, line
    from motionlab.retargeting import load_default

    if network != "auto":
        why = "asked for"
    elif real_source:
        from motionlab import data

        why = f"real mocap source, but {data.ENV_VAR} does not hold the course data's mixamo/{DEFAULT_SOURCE}"
    else:
        why = "source on motionlab's synthetic (canonical 22-joint) rig"
    return load_default(device, dtype), f"network: the shipped one, trained on motionlab's synthetic motion ({why})"
