"""Exercises of notebook 06 (key-pose interpolation): α(k), the PPCA noise variance, the D > Δ rule."""

from __future__ import annotations

import numpy as np

from .core import Exercise, Mistake, Question

__all__ = ["ease", "sigma2", "jumps", "DELTA", "held_out_q", "Q_CHOICES", "HELD_OUT"]

DELTA = 2.5
"""Δ of exercise 3 (the same threshold as ``motionlab.interpolation.detect.DELTA``)."""


# --------------------------------------------------------------------------- exercise 1
def _ease_ref(num):
    from motionlab.interpolation import slerp

    return slerp.alphas(num, "ease")


def _ease_cases():
    return [(1,), (5,), (30,), (2,)]


def _cosine(u):
    return 0.5 * (1.0 - np.cos(np.pi * u))


ease = Exercise(
    "06 · exercise 1 (ease-in-out weights)",
    _ease_ref,
    _ease_cases,
    mistakes=[
        Mistake(
            lambda n: _cosine(np.arange(1, n + 1) / n),
            "the last weight is 1, so the last in-between frame repeats the key pose: divide k by N + 1.",
        ),
        Mistake(
            lambda n: _cosine(np.arange(n) / (n + 1)),
            "the first weight is 0, so the first in-between frame repeats the key pose: k runs from 1 to N.",
        ),
        Mistake(
            lambda n: np.arange(1, n + 1) / (n + 1), "those are the linear weights k/(N+1); ease-in-out uses a cosine."
        ),
        Mistake(
            lambda n: 1.0 - np.cos(np.pi * np.arange(1, n + 1) / (n + 1)),
            "your weights go beyond 1: look at the factor in front of the bracket.",
        ),
        Mistake(
            lambda n: 0.5 * (1.0 + np.cos(np.pi * np.arange(1, n + 1) / (n + 1))),
            "your weights decrease from 1 to 0; α(k) must grow with k.",
        ),
    ],
)


# --------------------------------------------------------------------------- exercise 2
def _sigma2_cases():
    rng = np.random.default_rng(600)
    n, d = 300, 12
    latent = rng.normal(size=(n, 3)) @ rng.normal(size=(3, d)) * 2.0  # three strong directions
    x = latent + rng.normal(scale=0.5, size=(n, d)) + rng.normal(size=d) * 3.0  # noise and a mean far from 0
    y = rng.normal(size=(80, 6)) * np.array([3.0, 2.0, 1.0, 0.5, 0.4, 0.3])
    return [(x, 3), (x, 5), (y, 2)]


def _sigma2_ref(X, q):
    from motionlab.interpolation.ppca import PPCA

    return PPCA(q).fit(X).sigma2


def _eig(X, centre: bool = True, ddof: int = 0):
    X = np.asarray(X, dtype=float)
    xc = X - X.mean(axis=0) if centre else X
    return np.linalg.eigvalsh(xc.T @ xc / (len(X) - ddof))  # increasing


sigma2 = Exercise(
    "06 · exercise 2 (PPCA noise variance)",
    _sigma2_ref,
    _sigma2_cases,
    atol=1e-9,
    mistakes=[
        Mistake(
            lambda X, q: _eig(X, ddof=1)[::-1][q:].mean(),
            "close, but the maximum-likelihood covariance S divides by N, not N − 1 (np.cov divides by N − 1).",
        ),
        Mistake(
            lambda X, q: _eig(X)[q:].mean(),
            "np.linalg.eigh and eigvalsh return the eigenvalues in *increasing* order: sort them largest first.",
        ),
        Mistake(
            lambda X, q: _eig(X)[::-1][:q].mean(),
            "σ² is the variance the q principal directions leave unexplained: the D − q *smallest* eigenvalues.",
        ),
        Mistake(
            lambda X, q: _eig(X)[::-1][q:].sum() / X.shape[1],
            "average over the D − q discarded eigenvalues, not over all D.",
        ),
        Mistake(
            lambda X, q: _eig(X, centre=False)[::-1][q:].mean(),
            "S is the covariance about the mean: subtract the mean of X first.",
        ),
    ],
)


# --------------------------------------------------------------------------- exercise 3
def _jumps_ref(steps):
    s = np.asarray(steps, dtype=float)
    return np.flatnonzero(s[1:-1] > DELTA * np.maximum(s[:-2], s[2:])) + 1


def _jumps_cases():
    rng = np.random.default_rng(601)
    a = np.abs(rng.normal(1.0, 0.1, size=50))
    a[[7, 31]] = 9.0
    b = np.abs(rng.normal(1.0, 0.1, size=40))
    b[[0, 39, 20]] = 8.0  # the first and last steps are never flagged
    c = np.abs(rng.normal(1.0, 0.1, size=30))
    c[[12, 13]] = 6.0  # two large steps side by side: neither is isolated
    c[25] = 2.0  # twice its neighbours: below Δ
    c[5], c[6] = 3.0, 6.0  # 6 > Δ × the neighbours' mean, not Δ × the larger neighbour
    return [(a,), (b,), (c,)]


def _jumps_variant(mode: str):
    def wrong(steps):
        s = np.asarray(steps, dtype=float)
        if mode == "ends":
            p = np.concatenate([[0.0], s, [0.0]])
            return np.flatnonzero(p[1:-1] > DELTA * np.maximum(p[:-2], p[2:]))
        if mode == "min":
            return np.flatnonzero(s[1:-1] > DELTA * np.minimum(s[:-2], s[2:])) + 1
        if mode == "mean":
            return np.flatnonzero(s[1:-1] > DELTA * 0.5 * (s[:-2] + s[2:])) + 1
        return np.flatnonzero(s[1:-1] > DELTA * np.maximum(s[:-2], s[2:]))  # "shift"

    return wrong


jumps = Exercise(
    "06 · exercise 3 (the D > Δ rule)",
    _jumps_ref,
    _jumps_cases,
    mistakes=[
        Mistake(
            _jumps_variant("shift"),
            "your indices are one too small: s[1:-1] starts at t = 1, so shift the positions you find.",
        ),
        Mistake(_jumps_variant("ends"), "the first and the last step have only one neighbour and are never flagged."),
        Mistake(
            _jumps_variant("min"),
            "compare with the *larger* of the two neighbours: two large steps side by side are not an isolated jump.",
        ),
        Mistake(_jumps_variant("mean"), "compare with the larger of the two neighbours, not with their mean."),
    ],
)


# --------------------------------------------------------------------------- exercise 4 (experiment)
Q_CHOICES = (1, 2, 4, 8, 16, 32)
"""The latent sizes exercise 4 chooses among."""

HELD_OUT = 0.25
"""Exercise 4 holds out the last quarter of every clip's frames."""


def _best_q(clips, split: str = "tail", stats: str = "train") -> int:
    """The q of :data:`Q_CHOICES` with the highest PPCA log-likelihood per frame on the held-out frames.

    ``split``: ``"tail"`` (the last :data:`HELD_OUT` of each clip, the right way) or
    ``"interleaved"`` (every second frame); ``stats``: standardise with the training frames'
    mean and std (``"train"``) or all frames' (``"all"``).
    """
    from motionlab.interpolation import features
    from motionlab.interpolation.ppca import PPCA

    feats = [features.pose_features(c) for c in clips.values()]
    if split == "tail":
        cut = [len(f) - max(int(round(HELD_OUT * len(f))), 1) for f in feats]
        train = np.concatenate([f[:k] for f, k in zip(feats, cut)])
        test = np.concatenate([f[k:] for f, k in zip(feats, cut)])
    else:
        every = np.concatenate(feats)
        train, test = every[::2], every[1::2]
    basis = train if stats == "train" else np.concatenate(feats)
    mean, std = basis.mean(0), np.maximum(basis.std(0), 1e-6)
    scores = [PPCA(q).fit((train - mean) / std).log_likelihood((test - mean) / std) for q in Q_CHOICES]
    return int(Q_CHOICES[int(np.argmax(scores))])


held_out_q = Question(
    "06 · exercise 4 (experiment: q by held-out likelihood)",
    lambda clips: _best_q(clips),
    accept=[lambda clips: _best_q(clips, stats="all")],
    mistakes=[
        Mistake(
            lambda clips: _best_q(clips, split="interleaved"),
            "your test frames interleave the training frames (each sits between two frames the model "
            "was fitted on), so a larger q always looks better: hold out the *last quarter* of each clip.",
        ),
        Mistake(
            lambda clips: max(Q_CHOICES),
            "the largest q is the best only on frames the model has (nearly) seen: score frames held out "
            "in one block at the end of each clip.",
        ),
    ],
)
