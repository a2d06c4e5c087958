"""Instructor's key for notebook 05 (motion graphs)."""

import numpy as np

from motionlab.motion_graphs import distance


def my_local_minima(matrix):
    """Exercise 1: True where no one of the (up to) 8 neighbours is smaller."""
    m = np.asarray(matrix, dtype=float)
    rows, cols = m.shape
    padded = np.pad(m, 1, constant_values=np.inf)  # outside the matrix: never smaller
    mask = np.ones((rows, cols), dtype=bool)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            if di or dj:
                mask &= m <= padded[1 + di : 1 + di + rows, 1 + dj : 1 + dj + cols]
    return mask


def my_distance_matrix(pos_a, pos_b):
    """Exercise 2: D = S_A + S_B − 2Y − 2√(a² + b²) for every frame pair, (Ta, Tb) m²."""
    fa, fb = distance.cloud_features(pos_a), distance.cloud_features(pos_b)
    n = fa.height.shape[1]
    w = fa.weights
    xa, za = fa.centred[:, :n], fa.centred[:, n:]
    xb, zb = fb.centred[:, :n], fb.centred[:, n:]
    a = (xa * w) @ xb.T + (za * w) @ zb.T
    b = (xa * w) @ zb.T - (za * w) @ xb.T
    y = (fa.height * w) @ fb.height.T
    d = fa.self_term[:, None] + fb.self_term[None, :] - 2 * y - 2 * np.sqrt(a**2 + b**2)
    return np.maximum(d, 0.0)  # rounding can leave tiny negative values


THRESHOLDS_CM = (3, 4, 5, 6, 8, 10)  # as in the notebook (exercises.THRESHOLDS_CM)


def my_vanishing_threshold(motions, style):
    """Exercise 3: the first threshold (cm) at which ``style`` keeps frames in the pruned standard graph."""
    from motionlab.motion_graphs import graph

    for cm in THRESHOLDS_CM:
        g = graph.build_standard(motions, distance.threshold_from(cm / 100.0), prune=True)
        kept = sum(int(g.alive[c.start : c.stop].sum()) for c in g.clips if f"_{style}_" in f"_{c.name}_")
        if kept:
            return cm
    return 0
