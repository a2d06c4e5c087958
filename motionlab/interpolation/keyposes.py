"""Key poses: segment a long recording into action nodes by clustering in PPCA latent space.

The paper (Yang, Su, Yan, Li and Liu 2019, key-pose-constrained interpolation of human motion sequences) projects poses with PPCA and clusters them; each cluster that
forms a contiguous stretch of the recording is an *action node* (stand, walk, run, squat …)
holding a short sequence of key frames ``M_i = [m_0 … m_t]``. Our recipe:

1. features ``f(t)`` (:mod:`.features`: heading-frame positions + weighted velocities), z-scored;
2. PPCA to ``q`` dimensions; the latent ``z(t) = E[z | f(t)]``;
3. single frames do not tell actions apart — a walk cycle draws a loop in latent space that passes
   right through the standing pose — so each frame is described by the *mean and standard
   deviation of z over a window* of ``window`` frames around it (what the pose is, and how much
   it moves);
4. ``k``-means on those (k-means++ start, several restarts, vectorised), then a temporal clean-up:
   runs shorter than ``min_length`` frames join the neighbouring run whose centre is closer, so a
   single odd frame does not open a new node;
5. key frames of a segment: ``n`` frames chosen by k-means *inside* the segment's latent
   trajectory, each the medoid of its sub-cluster, sorted by time.

Taught in ``notebooks/06_keypose_interpolation.ipynb``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motionlab.interpolation.ppca import PPCA

__all__ = [
    "kmeans",
    "clean_labels",
    "runs",
    "window_stats",
    "Segmentation",
    "segment",
    "node_key_frames",
    "key_frames",
    "purity",
]


def window_stats(z, window: int) -> np.ndarray:
    """Mean and standard deviation of ``z`` (T, q) over a centred window: (T, 2q).

    The window is centred, so ``2⌊window/2⌋ + 1`` frames wide (an even ``window`` gains a frame;
    edges padded by repeating the end frames); computed with cumulative sums, no loop over frames.

    Raises
    ------
    ValueError when ``z`` is not (T, q).
    """
    z = np.asarray(z, dtype=np.float64)
    if z.ndim != 2:
        raise ValueError(f"expected a (T, q) latent trajectory, got shape {z.shape}")
    half = max(int(window), 1) // 2
    pad = np.concatenate([np.repeat(z[:1], half, axis=0), z, np.repeat(z[-1:], half, axis=0)])
    width = 2 * half + 1
    c1 = np.concatenate([np.zeros((1, z.shape[1])), np.cumsum(pad, axis=0)])
    c2 = np.concatenate([np.zeros((1, z.shape[1])), np.cumsum(pad * pad, axis=0)])
    mean = (c1[width:] - c1[:-width]) / width
    var = (c2[width:] - c2[:-width]) / width - mean * mean
    return np.concatenate([mean, np.sqrt(np.maximum(var, 0.0))], axis=1)


def kmeans(x, k: int, seed: int = 0, iters: int = 100, restarts: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """k-means with k-means++ seeding; the best of ``restarts`` runs.

    Parameters
    ----------
    x : array (N, D)
    k : int  (1 <= k <= N)

    Returns
    -------
    labels : ndarray (N,) of int
    centres : ndarray (k, D)

    Raises
    ------
    ValueError unless ``x`` is (N, D) and 1 <= k <= N.
    """
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or not 1 <= k <= len(x):
        raise ValueError(f"expected (N, D) data with 1 <= k <= N, got shape {x.shape} and k={k}")
    rng = np.random.default_rng(seed)
    x2 = np.sum(x * x, axis=1)
    best = (np.inf, None, None)
    for _ in range(max(1, restarts)):
        centres = [x[rng.integers(len(x))]]
        d2 = np.sum((x - centres[0]) ** 2, axis=1)
        for _ in range(1, k):
            p = d2 / d2.sum() if d2.sum() > 0 else np.full(len(x), 1.0 / len(x))
            centres.append(x[rng.choice(len(x), p=p)])
            d2 = np.minimum(d2, np.sum((x - centres[-1]) ** 2, axis=1))
        c = np.array(centres)
        labels = np.zeros(len(x), dtype=np.int64)
        for it in range(iters):
            dist = x2[:, None] + np.sum(c * c, axis=1)[None, :] - 2 * x @ c.T
            new = np.argmin(dist, axis=1)
            if it > 0 and np.array_equal(new, labels):
                break
            labels = new
            counts = np.bincount(labels, minlength=k)
            sums = np.zeros_like(c)
            np.add.at(sums, labels, x)
            empty = counts == 0
            c = np.where(empty[:, None], c, sums / np.maximum(counts, 1)[:, None])
        inertia = float(np.sum((x - c[labels]) ** 2))
        if inertia < best[0]:
            best = (inertia, labels.copy(), c.copy())
    return best[1], best[2]


def runs(labels) -> list[tuple[int, int, int]]:
    """Maximal constant stretches ``(start, stop, label)`` of a label sequence."""
    labels = np.asarray(labels)
    if labels.size == 0:
        return []
    cut = np.flatnonzero(labels[1:] != labels[:-1]) + 1
    starts = np.concatenate([[0], cut])
    stops = np.concatenate([cut, [len(labels)]])
    return [(int(a), int(b), int(labels[a])) for a, b in zip(starts, stops)]


def clean_labels(labels, z, centres, min_length: int) -> np.ndarray:
    """Merge runs shorter than ``min_length`` into a neighbouring run (the one whose centre is
    nearer to the short run's mean latent), shortest first, until none is left."""
    labels = np.asarray(labels).copy()
    z = np.asarray(z, dtype=np.float64)
    while True:
        r = runs(labels)
        if len(r) <= 1:
            return labels
        lengths = [b - a for a, b, _ in r]
        i = int(np.argmin(lengths))
        if lengths[i] >= min_length:
            return labels
        a, b, _ = r[i]
        options = [r[j][2] for j in (i - 1, i + 1) if 0 <= j < len(r)]
        mean = z[a:b].mean(axis=0)
        pick = min(options, key=lambda lab: float(np.sum((centres[lab] - mean) ** 2)))
        labels[a:b] = pick


@dataclass
class Segmentation:
    """The result of :func:`segment`.

    Attributes
    ----------
    labels : ndarray (T,) of int           cluster of each frame after clean-up
    segments : list of (start, stop, label) contiguous action stretches
    latent : ndarray (T, q)                PPCA posterior means
    centres : ndarray (k, 2q)              cluster centres (windowed mean and std of the latent)
    model : PPCA                           fitted on the z-scored features
    mean, std : ndarray (D,)               the z-scoring
    """

    labels: np.ndarray
    segments: list
    latent: np.ndarray
    centres: np.ndarray
    model: PPCA
    mean: np.ndarray
    std: np.ndarray
    window: int = 15

    def project(self, features) -> np.ndarray:
        """Latent coordinates (N, q) of new feature rows (N, D)."""
        return self.model.transform((np.asarray(features, dtype=np.float64) - self.mean) / self.std)

    def classify(self, features) -> np.ndarray:
        """Nearest cluster (N,) of the frames of a new feature sequence (N, D)."""
        z = window_stats(self.project(features), self.window)
        d = np.sum((z[:, None, :] - self.centres[None]) ** 2, axis=-1)
        return np.argmin(d, axis=1)


def segment(
    features,
    k: int,
    q: int = 8,
    min_length: int = 15,
    window: int = 15,
    seed: int = 0,
    method: str = "closed",
) -> Segmentation:
    """Segment a recording into action stretches (see the module docstring).

    Parameters
    ----------
    features : array (T, D)   per-frame features, e.g. :func:`motionlab.interpolation.features.pose_features`
    k : int                   number of clusters (actions)
    q : int                   PPCA latent size
    min_length : int          shortest allowed segment, frames
    window : int              width of the window of latent statistics, frames

    Raises
    ------
    ValueError unless the features are (T, D) with at least ``k`` frames.
    """
    f = np.asarray(features, dtype=np.float64)
    if f.ndim != 2 or len(f) < k:
        raise ValueError(f"expected (T, D) features with at least k={k} frames, got {f.shape}")
    mean = f.mean(axis=0)
    std = np.maximum(f.std(axis=0), 1e-6)
    zs = (f - mean) / std
    model = PPCA(min(q, f.shape[1] - 1), method=method, seed=seed).fit(zs)
    z = model.transform(zs)
    stats = window_stats(z, window)
    labels, centres = kmeans(stats, k, seed=seed)
    labels = clean_labels(labels, stats, centres, min_length)
    return Segmentation(labels, runs(labels), z, centres, model, mean, std, window)


def node_key_frames(features, n: int = 5, q: int = 4, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Key frames of one action node's clip: z-score its features, project them with :class:`PPCA`
    (the one implementation used for segmentation too) and take :func:`key_frames` of the latent.

    Parameters
    ----------
    features : array (T, D)   per-frame features of the node's clip (:func:`~.features.pose_features`)
    n : int                   key frames wanted
    q : int                   PPCA latent size (capped at ``D-1`` and ``T-1``)

    Returns
    -------
    keys : ndarray (<= n,) of int   frame indices into the clip, increasing
    latent : ndarray (T, q)         the PPCA posterior means

    Raises
    ------
    ValueError unless the features are (T, D) with at least 2 frames.
    """
    f = np.asarray(features, dtype=np.float64)
    if f.ndim != 2 or len(f) < 2:
        raise ValueError(f"expected (T, D) features of at least 2 frames, got shape {f.shape}")
    zs = (f - f.mean(axis=0)) / np.maximum(f.std(axis=0), 1e-6)
    q = max(1, min(int(q), f.shape[1] - 1, len(f) - 1))
    latent = PPCA(q, seed=seed).fit(zs).transform(zs)
    return key_frames(latent, n, seed=seed), latent


def key_frames(latent, n: int, seed: int = 0) -> np.ndarray:
    """``n`` key frames of one segment's latent trajectory (T, q): medoids of ``n`` sub-clusters,
    sorted by time. Returns frame indices (n,) into the segment (fewer if T < n).

    Raises
    ------
    ValueError unless ``z`` is a non-empty (T, q) array.
    """
    z = np.asarray(latent, dtype=np.float64)
    if z.ndim != 2 or len(z) == 0:
        raise ValueError(f"expected a non-empty (T, q) latent trajectory, got shape {z.shape}")
    n = min(int(n), len(z))
    labels, centres = kmeans(z, n, seed=seed, restarts=2)
    picks = []
    for c in range(n):
        members = np.flatnonzero(labels == c)
        if members.size:
            picks.append(int(members[np.argmin(np.sum((z[members] - centres[c]) ** 2, axis=1))]))
    return np.array(sorted(set(picks)), dtype=np.int64)


def purity(predicted, truth) -> tuple[float, dict]:
    """How well clusters match known actions: each cluster votes for its majority action.

    Returns the fraction of frames whose cluster's majority action is their true action, and
    ``{cluster: majority action}``.

    Raises
    ------
    ValueError when the label arrays differ in shape.
    """
    predicted, truth = np.asarray(predicted), np.asarray(truth)
    if predicted.shape != truth.shape:
        raise ValueError(f"expected equal-length label arrays, got {predicted.shape} and {truth.shape}")
    mapping, correct = {}, 0
    for c in np.unique(predicted):
        vals, counts = np.unique(truth[predicted == c], return_counts=True)
        mapping[int(c)] = vals[np.argmax(counts)].item()
        correct += int(counts.max())
    return correct / max(len(truth), 1), mapping
