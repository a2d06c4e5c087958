"""Save and load a trained retargeting network with everything needed to use it.

A checkpoint holds the weights, the network's sizes, the normalisation statistics of the
input features, the training character's canonical skeleton (character A), the frame rate and
window length it was trained with, free-form training info (seed, steps, final loss) and
:data:`FORMAT_VERSION`. It is written with ``torch.save`` using plain types only, and read with
``weights_only=True`` (no arbitrary code runs on load). Loading a file of another format
version, or one that is not a checkpoint, raises :class:`CheckpointError` saying so.

Taught in ``notebooks/02_training_autoencoder.ipynb``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch

from motionlab.core import files
from motionlab.core.preprocess import NormStats
from motionlab.core.skeleton import Skeleton
from motionlab.retargeting import devices
from motionlab.retargeting.model import ModelConfig, RetargetNet

__all__ = ["FORMAT", "FORMAT_VERSION", "DTYPES", "CheckpointError", "Checkpoint", "save", "load"]

FORMAT = "motionlab-retargeting"
FORMAT_VERSION = 1

DTYPES = {"float64": torch.float64, "float32": torch.float32}
"""Float types a network computes in, by name. float64 is the default, so that the latent
iteration's losses and stopping step do not depend on the CPU (``docs/reproducibility.md``)."""


class CheckpointError(ValueError):
    """A file that is not a retargeting checkpoint of this version (or is damaged)."""


@dataclass
class Checkpoint:
    """A trained network and its context.

    Attributes
    ----------
    model : RetargetNet            the network (put in ``eval()`` mode by :func:`load`)
    stats : NormStats              mean/std of the 70 input features
    skeleton : Skeleton            the training character's canonical 22-joint skeleton
    fps : float                    frame rate of the training data
    window : int                   training window length, frames
    info : dict                    seed, steps, final loss, data description (plain JSON types)
    """

    model: RetargetNet
    stats: NormStats
    skeleton: Skeleton
    fps: float = 60.0
    window: int = 120
    info: dict = field(default_factory=dict)

    @property
    def device(self) -> torch.device:
        return next(self.model.parameters()).device

    @property
    def dtype(self) -> torch.dtype:
        """The float type the network computes in (inputs must be given in it)."""
        return next(self.model.parameters()).dtype

    def to(self, device) -> Checkpoint:
        """Move the network to ``device`` (in place); returns ``self``."""
        self.model.to(device)
        return self


def _skeleton_dict(sk: Skeleton) -> dict:
    return {
        "names": list(sk.names),
        "parents": [int(p) for p in sk.parents],
        "offsets": sk.offsets.tolist(),
        "end_sites": {str(j): o.tolist() for j, o in sk.end_sites.items()},
    }


def _skeleton_from(d: dict) -> Skeleton:
    return Skeleton(
        tuple(d["names"]),
        np.asarray(d["parents"]),
        np.asarray(d["offsets"], dtype=np.float64),
        {int(j): np.asarray(o) for j, o in d["end_sites"].items()},
    )


def _check_contents(path: Path, ckpt: Checkpoint) -> None:
    """Refuse a checkpoint that loads but cannot work: non-finite weights, statistics of the wrong
    size, or a stored skeleton that is not a 22-joint humanoid with finite bones."""
    from motionlab.core import humanoid
    from motionlab.retargeting.model import FEATURE_DIM

    for name, tensor in ckpt.model.state_dict().items():
        if tensor.is_floating_point() and not torch.isfinite(tensor).all():
            bad = int((~torch.isfinite(tensor)).sum())
            raise CheckpointError(f"{path}: damaged checkpoint: weight {name!r} has {bad} non-finite values (NaN/inf)")
    for name in ("mean", "std"):
        array = getattr(ckpt.stats, name)
        if array.shape != (FEATURE_DIM,):
            raise CheckpointError(
                f"{path}: damaged checkpoint: statistics {name!r} should have {FEATURE_DIM} values, got shape {array.shape}"
            )
        if not np.isfinite(array).all():
            raise CheckpointError(f"{path}: damaged checkpoint: statistics {name!r} hold non-finite values")
    if not (ckpt.stats.std > 0).all():
        raise CheckpointError(f"{path}: damaged checkpoint: statistics 'std' should be > 0 everywhere")
    sk = ckpt.skeleton
    if not humanoid.is_canonical(sk):
        raise CheckpointError(
            f"{path}: damaged checkpoint: the stored skeleton should be the {len(humanoid.JOINTS)}-joint humanoid "
            f"({', '.join(humanoid.JOINTS[:3])}, ...), got {sk.num_joints} joints ({', '.join(sk.names[:3])}, ...)"
        )
    if not np.isfinite(sk.offsets).all() or sk.height() <= 0:
        raise CheckpointError(f"{path}: damaged checkpoint: the stored skeleton has non-finite or zero bone offsets")
    if not (np.isfinite(ckpt.fps) and ckpt.fps > 0) or ckpt.window < 1:
        raise CheckpointError(
            f"{path}: damaged checkpoint: expected fps > 0 and window >= 1, got fps {ckpt.fps}, window {ckpt.window}"
        )


def save(path: str | os.PathLike, checkpoint: Checkpoint, overwrite: bool = True) -> Path:
    """Write ``checkpoint`` to ``path`` atomically (temporary file, then rename).

    Raises ``FileExistsError`` when ``path`` exists and ``overwrite`` is False.
    """
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(files.exists_message("checkpoint", path))
    payload = {
        "format": FORMAT,
        "version": FORMAT_VERSION,
        "config": checkpoint.model.config.to_dict(),
        "state_dict": {k: v.detach().cpu().clone() for k, v in checkpoint.model.state_dict().items()},
        "stats": checkpoint.stats.to_dict(),
        "skeleton": _skeleton_dict(checkpoint.skeleton),
        "fps": float(checkpoint.fps),
        "window": int(checkpoint.window),
        "info": dict(checkpoint.info),
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    return files.atomic_write(path, lambda f: torch.save(payload, f), overwrite, binary=True, what="checkpoint")


def load(path: str | os.PathLike, device: str | torch.device | None = None, dtype: str = "float64") -> Checkpoint:
    """Read a checkpoint written by :func:`save`; the network is in ``eval()`` mode on ``device``
    (default: CUDA when available, else CPU; :func:`motionlab.retargeting.devices.pick`) and computes
    in ``dtype`` (a key of :data:`DTYPES`, whatever type its weights were stored in).

    Raises
    ------
    FileNotFoundError when there is no file; CheckpointError naming ``path`` when it is not
    a readable checkpoint of this format version; ValueError for an unknown ``dtype`` or a
    ``device`` this machine does not have.
    """
    if dtype not in DTYPES:
        raise ValueError(f"dtype must be one of {tuple(DTYPES)}, got {dtype!r}")
    devices.pick(device)  # a device that is not there fails before the file is read
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"checkpoint {path} not found")
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as e:  # torch raises many kinds for a damaged or foreign file
        raise CheckpointError(
            f"{path}: not a readable motionlab retargeting checkpoint ({type(e).__name__}: {e})"
        ) from None
    if not isinstance(payload, dict) or payload.get("format") != FORMAT:
        raise CheckpointError(f"{path}: not a motionlab retargeting checkpoint (no {FORMAT!r} format tag)")
    version = payload.get("version")
    if version != FORMAT_VERSION:
        raise CheckpointError(
            f"{path}: checkpoint format version {version}, but this motionlab reads version {FORMAT_VERSION}; "
            "re-train it with `motionlab train` (or load it with the motionlab release that wrote it)"
        )
    try:
        model = RetargetNet(ModelConfig(**payload["config"])).to(DTYPES[dtype])
        model.load_state_dict(payload["state_dict"])  # copies the stored weights into dtype
        ckpt = Checkpoint(
            model=model,
            stats=NormStats.from_dict(payload["stats"]),
            skeleton=_skeleton_from(payload["skeleton"]),
            fps=float(payload["fps"]),
            window=int(payload["window"]),
            info=dict(payload.get("info", {})),
        )
    except (KeyError, TypeError, RuntimeError, ValueError) as e:
        raise CheckpointError(f"{path}: damaged retargeting checkpoint ({type(e).__name__}: {e})") from None
    _check_contents(path, ckpt)
    model.to(devices.pick(device)).eval()
    return ckpt
