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
