"""A torch ``Dataset`` of 120-frame windows of one or more characters' clips.

Build it from motions (any supported rig: they are reduced to 22 joints and resampled), keep the
normalisation statistics with it, save it to one ``.npz`` file and load it back::

    ds = MotionDataset.from_motions(motions, fps=60, window=120, stride=60)
    ds.save("aj_windows.npz")
    item = ds[0]   # {"x": (120, 70) normalised features, "positions": (120, 22, 3), "offsets": (22, 3)}

Taught in ``notebooks/01_preprocessing.ipynb``.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import torch
from torch.utils.data import Dataset
from tqdm.auto import tqdm

from motionlab.core import files
from motionlab.core.motion import Motion
from motionlab.core.preprocess import NormStats, features, prepare, window_stack

__all__ = ["MotionDataset"]

FORMAT = "motionlab-windows-1"


class MotionDataset(Dataset):
    """Windows of features with the statistics that normalise them.

    Attributes
    ----------
    x        : ndarray (N, W, 70)      un-normalised features ``[positions (66), v_t (4)]``
    offsets  : ndarray (C, 22, 3)      rest offsets of each character (metres)
    character: ndarray (N,) of int     which character each window belongs to
    index    : list of (clip, start, stop) where each window comes from
    names    : list of str             clip names
    stats    : NormStats               fitted on ``x`` over all frames
    fps, window, stride
    """

    def __init__(self, x, offsets, character, index, names, stats: NormStats, fps: float, window: int, stride: int):
        self.x = np.asarray(x, dtype=np.float32)
        self.offsets = np.asarray(offsets, dtype=np.float32)
        self.character = np.asarray(character, dtype=np.int64)
        self.index = [tuple(int(v) for v in i) for i in index]
        self.names = list(names)
        self.stats = stats
        self.fps, self.window, self.stride = float(fps), int(window), int(stride)

    @classmethod
    def from_motions(
        cls,
        motions: Sequence[Motion],
        fps: float = 60.0,
        window: int = 120,
        stride: int = 60,
        stats: NormStats | None = None,
        progress: bool = True,
    ) -> MotionDataset:
        """Reduce, resample and window ``motions``; fit statistics unless ``stats`` is given.

        Clips on skeletons with different rest offsets become different characters.

        Raises
        ------
        ValueError when ``motions`` is empty.
        """
        if not motions:
            raise ValueError("from_motions needs at least one motion")
        feats, char_of_clip, offsets = [], [], []
        for m in tqdm(motions, desc="preprocessing", disable=not progress or len(motions) < 8):
            c = prepare(m, fps)
            f = features(c).flat()
            key = next((i for i, o in enumerate(offsets) if np.allclose(o, c.skeleton.offsets[1:], atol=1e-6)), None)
            if key is None:
                offsets.append(c.skeleton.offsets[1:].copy())
                key = len(offsets) - 1
            feats.append(f)
            char_of_clip.append(key)
        x, index = window_stack(feats, window, stride)
        stats = stats or NormStats.fit(feats)
        full_offsets = [np.concatenate([np.zeros((1, 3)), o]) for o in offsets]
        character = [char_of_clip[i] for i, _, _ in index]
        return cls(x, full_offsets, character, index, [m.name for m in motions], stats, fps, window, stride)

    def __len__(self) -> int:
        return len(self.x)

    def __getitem__(self, i: int) -> dict[str, torch.Tensor]:
        x = self.x[i]
        return {
            "x": torch.from_numpy(self.stats.normalize(x).astype(np.float32)),
            "positions": torch.from_numpy(x[:, :66].reshape(-1, 22, 3).copy()),
            "offsets": torch.from_numpy(self.offsets[self.character[i]]),
        }

    def save(self, path: str | Path) -> Path:
        """Write everything to one ``.npz`` (atomically: temporary file, then rename)."""
        path = Path(path)
        meta = {
            "format": FORMAT,
            "fps": self.fps,
            "window": self.window,
            "stride": self.stride,
            "names": self.names,
            "index": self.index,
            "stats": self.stats.to_dict(),
        }
        arrays = dict(x=self.x, offsets=self.offsets, character=self.character, meta=json.dumps(meta))
        return files.atomic_write(path, lambda f: np.savez_compressed(f, **arrays), True, binary=True, what="dataset")

    @classmethod
    def load(cls, path: str | Path) -> MotionDataset:
        """Read a dataset written by :meth:`save`; a clear error for other files.

        Raises
        ------
        ValueError naming ``path`` when it is not a motionlab windows dataset (unreadable, or
        another format).
        """
        try:
            with np.load(path, allow_pickle=False) as z:
                meta = json.loads(str(z["meta"]))
                x, offsets, character = z["x"], z["offsets"], z["character"]
        except (OSError, KeyError, ValueError) as e:
            raise ValueError(f"{path}: not a motionlab windows dataset ({e})") from None
        if meta.get("format") != FORMAT:
            raise ValueError(f"{path}: format {meta.get('format')!r}, expected {FORMAT!r}")
        return cls(
            x, offsets, character, meta["index"], meta["names"], NormStats.from_dict(meta["stats"]),
            meta["fps"], meta["window"], meta["stride"],
        )  # fmt: skip
