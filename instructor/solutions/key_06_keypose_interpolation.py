"""Instructor's key for notebook 06 (key-pose interpolation and gap filling)."""

import numpy as np


def my_ease(num):
    """Exercise 1: ease-in-out weights α(k) = ½(1 − cos(πk/(N+1))), k = 1..N."""
    k = np.arange(1, num + 1)
    return 0.5 * (1.0 - np.cos(np.pi * k / (num + 1)))


def my_sigma2(X, q):
    """Exercise 2: closed-form PPCA noise variance, the mean of the D − q smallest eigenvalues of S."""
    xc = X - X.mean(axis=0)
    S = xc.T @ xc / len(X)  # maximum-likelihood covariance (divides by N)
    lam = np.sort(np.linalg.eigvalsh(S))[::-1]  # largest first
    return lam[q:].mean()


def my_jumps(steps):
    """Exercise 3: indices t (not first or last) with s(t) > 2.5 max(s(t-1), s(t+1))."""
    s = np.asarray(steps)
    t = np.arange(1, len(s) - 1)
    return t[s[t] > 2.5 * np.maximum(s[t - 1], s[t + 1])]


def my_held_out_q(clips):
    """Exercise 4: q in (1, 2, 4, 8, 16, 32) with the best likelihood on the last quarter of every clip."""
    from motionlab.interpolation import features
    from motionlab.interpolation.ppca import PPCA

    train, test = [], []
    for clip in clips.values():
        f = features.pose_features(clip)
        k = len(f) - max(int(round(0.25 * len(f))), 1)
        train.append(f[:k])
        test.append(f[k:])
    train, test = np.concatenate(train), np.concatenate(test)
    mean, std = train.mean(axis=0), np.maximum(train.std(axis=0), 1e-6)
    best = max((1, 2, 4, 8, 16, 32), key=lambda q: PPCA(q).fit((train - mean) / std).log_likelihood((test - mean) / std))
    return best
