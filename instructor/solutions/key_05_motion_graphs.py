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


DWELLS = (2, 4, 6, 8, 10, 12)  # as in the notebook (exercises.motion_graphs.DWELLS)


def my_style_change(motions, request):
    """Exercise 2: the smallest dwell at which the first style change lasts one gait cycle."""
    from motionlab.motion_graphs import cycles, search, structured

    style = request[0][1]
    cycle = np.median(np.concatenate([cycles.segment_cycles(m).lengths() for m in motions if f"_{style}_" in m.name]))
    for dwell in DWELLS:
        g = structured.build_structured(motions, distance.threshold_from(0.03), dwell=dwell)
        kinds = [(g.clips[c].kind, b - a + 1) for c, a, b in search.search(g, request).pieces]
        first = next(k for k, (kind, _) in enumerate(kinds) if kind == "intermediate")
        end = next((k for k in range(first, len(kinds)) if kinds[k][0] != "intermediate"), len(kinds))
        if sum(n for _, n in kinds[first:end]) >= cycle:
            return dwell
    return 0


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


LINK_THRESHOLDS_CM = (3, 5, 10, 15, 20, 25, 30, 40)  # as in the notebook (exercises.motion_graphs.LINK_THRESHOLDS_CM)


def my_transition_clip(library, request, trans_name):
    """Exercise 4: the first threshold (cm) at which the graph without the recorded transition clip
    still meets the request (0 if none does)."""
    from motionlab.motion_graphs import search, structured

    without = [m for m in library if m.name != trans_name]
    for cm in LINK_THRESHOLDS_CM:
        g = structured.build_structured(without, distance.threshold_from(cm / 100.0))
        try:
            search.search(g, request)
            return cm
        except search.SearchError:
            pass
    return 0
