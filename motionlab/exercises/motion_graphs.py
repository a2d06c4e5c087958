"""Exercises of notebook 05 (motion graphs): transition candidates and Kovar's frame distance."""

from __future__ import annotations

import numpy as np

from .core import Exercise, Mistake, Question

__all__ = ["local_minima", "distance_matrix", "vanishing_threshold", "style_frames_kept", "THRESHOLDS_CM"]


# --------------------------------------------------------------------------- exercise 1
def _minima_cases():
    rng = np.random.default_rng(500)
    return [
        (rng.random((7, 9)),),
        (rng.integers(0, 4, size=(6, 6)).astype(float),),  # ties: equal neighbours do not disqualify
        (rng.random((1, 8)),),  # one row: only left and right neighbours exist
        (rng.random((9, 5)),),
    ]


def _minima_ref(matrix):
    from motionlab.motion_graphs import distance

    return distance.local_minima(np.asarray(matrix, dtype=float))


def _minima_variant(mode: str):
    """Typical wrong local-minimum tests, written with padding and shifts."""

    def wrong(matrix):
        m = np.asarray(matrix, dtype=float)
        if mode == "wrap":  # np.roll: the borders wrap around
            neighbours = [np.roll(m, (di, dj), axis=(0, 1)) for di in (-1, 0, 1) for dj in (-1, 0, 1)]
            neighbours = [n for k, n in enumerate(neighbours) if k != 4]
            return np.all([m <= n for n in neighbours], axis=0)
        big = np.inf if mode != "maxima" else -np.inf
        p = np.pad(m, 1, constant_values=big)
        r, c = m.shape
        shifts = [(di, dj) for di in (0, 1, 2) for dj in (0, 1, 2) if (di, dj) != (1, 1)]
        if mode == "four":
            shifts = [(0, 1), (2, 1), (1, 0), (1, 2)]
        out = np.ones_like(m, dtype=bool)
        for di, dj in shifts:
            n = p[di : di + r, dj : dj + c]
            if mode == "strict":
                out &= m < n
            elif mode == "maxima":
                out &= m >= n
            else:
                out &= m <= n
        return out

    return wrong


local_minima = Exercise(
    "05 · exercise 1 (local minima)",
    _minima_ref,
    _minima_cases,
    mistakes=[
        Mistake(
            _minima_variant("strict"),
            "a cell equal to a neighbour is still a candidate: it must have no *smaller* neighbour "
            "(compare with <=, not <).",
        ),
        Mistake(
            _minima_variant("four"),
            "the diagonal neighbours count too: a cell has up to 8 neighbours.",
        ),
        Mistake(
            _minima_variant("wrap"),
            "at the border the cells outside the matrix do not exist; np.roll wraps the matrix "
            "around and compares the first row with the last.",
        ),
        Mistake(_minima_variant("maxima"), "those are the local maxima: a candidate is no larger than its neighbours."),
    ],
)


# --------------------------------------------------------------------------- exercise 2
def _distance_cases():
    from motionlab import synthetic
    from motionlab.core import quat

    walk = synthetic.generate("walk", None, 60, 30.0, seed=1).global_positions()
    other = synthetic.generate("walk", None, 60, 30.0, seed=2).global_positions()
    turned = quat.rotate(quat.from_yaw(1.2), walk) + np.array([0.7, 0.0, -1.5])  # same motion elsewhere
    return [(walk[:30], other[:40]), (walk[10:35], turned[:20]), (other[5:12], other[20:31])]


def _distance_ref(pos_a, pos_b):
    from motionlab.motion_graphs import distance

    return distance.distance_matrix(pos_a, pos_b)


def _distance_variant(mode: str):
    def wrong(pos_a, pos_b):
        from motionlab.motion_graphs import distance

        fa, fb = distance.cloud_features(pos_a), distance.cloud_features(pos_b)
        n = fa.height.shape[1]
        w = fa.weights
        ax, az, bx, bz = fa.centred[:, :n], fa.centred[:, n:], fb.centred[:, :n], fb.centred[:, n:]
        a = (ax * w) @ bx.T + (az * w) @ bz.T
        b = (ax * w) @ bz.T - (az * w) @ bx.T
        y = (fa.height * w) @ fb.height.T
        s = fa.self_term[:, None] + fb.self_term[None, :]
        if mode == "no turn":
            d = s - 2 * y - 2 * a
        elif mode == "no sqrt":
            d = s - 2 * y - 2 * (a * a + b * b)
        elif mode == "no y":
            d = s - 2 * np.sqrt(a * a + b * b)
        else:  # "plus": the cross terms added
            d = s + 2 * y + 2 * np.sqrt(a * a + b * b)
        return np.maximum(d, 0.0)

    return wrong


def _distance_no_clamp(pos_a, pos_b):  # rounding can leave -1e-17 where D is 0: both are accepted
    from motionlab.motion_graphs import distance

    fa, fb = distance.cloud_features(pos_a), distance.cloud_features(pos_b)
    n = fa.height.shape[1]
    w2 = np.concatenate([fa.weights, fa.weights])
    a = (fa.centred * w2) @ fb.centred.T
    b = (fa.centred * w2) @ np.concatenate([fb.centred[:, n:], -fb.centred[:, :n]], axis=1).T
    y = (fa.height * fa.weights) @ fb.height.T
    return fa.self_term[:, None] + fb.self_term[None, :] - 2 * y - 2 * np.sqrt(a * a + b * b)


distance_matrix = Exercise(
    "05 · exercise 2 (closed-form distance)",
    _distance_ref,
    _distance_cases,
    # the package rounds points to distance.GRID (≈ 3.8 µm) so that its sums are exact: an answer
    # computed from the raw positions may differ by 2·√D·e + e² (e = 2·√3·GRID), a few 1e-6 m² here
    atol=2e-5,
    accept=[_distance_no_clamp],
    mistakes=[
        Mistake(
            _distance_variant("no turn"),
            "right only where the two clouds face the same way: the minimum over the turn θ of "
            "a cos θ + b sin θ is what gives the square-root term.",
        ),
        Mistake(_distance_variant("no sqrt"), "the last term is 2 √(a² + b²): the square root is missing."),
        Mistake(
            _distance_variant("no y"),
            "the heights are not turned or shifted, but they still differ: the −2Y term is missing.",
        ),
        Mistake(
            _distance_variant("plus"),
            "D is a squared distance, ‖p − p'‖² = ‖p‖² + ‖p'‖² − 2 p·p': the cross terms are subtracted.",
        ),
    ],
)


# --------------------------------------------------------------------------- exercise 3 (experiment)
THRESHOLDS_CM = (3, 4, 5, 6, 8, 10)
"""The RMS thresholds (cm, :func:`distance.threshold_from`) exercise 3 moves through."""

_KEPT: dict = {}


def style_frames_kept(motions, style: str, rms_cm: float, prune: bool = True) -> int:
    """Frames of the takes named ``*_<style>_*`` alive in the standard graph at ``rms_cm`` cm RMS.

    The standard graph (:func:`graph.build_standard`) of all ``motions``, pruned to its largest
    strongly connected component when ``prune``.
    """
    from motionlab.motion_graphs import distance, graph

    key = (tuple(id(m) for m in motions), style, float(rms_cm), bool(prune))
    if key not in _KEPT:
        g = graph.build_standard(motions, distance.threshold_from(rms_cm / 100.0), prune=prune)
        _KEPT[key] = int(sum(g.alive[c.start : c.stop].sum() for c in g.clips if f"_{style}_" in f"_{c.name}_"))
    return _KEPT[key]


def _first_keeping(motions, style: str, prune: bool = True) -> float:
    """The smallest threshold of :data:`THRESHOLDS_CM` at which ``style`` keeps frames (0: at none)."""
    for cm in THRESHOLDS_CM:
        if style_frames_kept(motions, style, cm, prune) > 0:
            return float(cm)
    return 0.0


def _last_losing(motions, style: str) -> float:
    """The largest threshold of :data:`THRESHOLDS_CM` at which ``style`` has no frame left (0: none)."""
    lost = [cm for cm in THRESHOLDS_CM if style_frames_kept(motions, style, cm) == 0]
    return float(max(lost)) if lost else 0.0


vanishing_threshold = Question(
    "05 · exercise 3 (experiment: the threshold and a lost style)",
    _first_keeping,
    mistakes=[
        Mistake(
            lambda motions, style: _first_keeping(motions, style, prune=False),
            "that is the unpruned graph, which keeps every frame: build it with prune=True (the "
            "largest strongly connected component) and count the style's frames that stay alive.",
        ),
        Mistake(
            _last_losing,
            "that is the largest threshold at which the style is still lost; the question asks for the "
            "first threshold at which it keeps frames.",
        ),
        Mistake(
            lambda motions, style: _first_keeping(motions, style) / 100.0,
            "answer in centimetres, as THRESHOLDS_CM lists them.",
        ),
    ],
)
