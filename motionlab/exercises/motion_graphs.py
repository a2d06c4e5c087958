"""Exercises of notebook 05 (motion graphs): transition candidates, how long a style change lasts,
the threshold at which a style leaves the standard graph, and what a recorded transition clip is
worth."""

from __future__ import annotations

import numpy as np

from .core import Exercise, Mistake, Question

__all__ = [
    "local_minima",
    "style_change",
    "style_change_frames",
    "gait_cycle_frames",
    "DWELLS",
    "vanishing_threshold",
    "style_frames_kept",
    "THRESHOLDS_CM",
    "transition_clip",
    "link_met",
    "LINK_THRESHOLDS_CM",
]


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


# --------------------------------------------------------------------------- exercise 2 (experiment)
DWELLS = (2, 4, 6, 8, 10, 12)
"""The values of ``dwell`` (fewest frames a route spends in each intermediate motion,
:func:`structured.build_structured`) exercise 2 moves through."""

_CHANGE: dict = {}


def style_change_frames(motions, request, dwell: int) -> int:
    """Frames the path of ``request`` spends in intermediate motions during its first style change.

    The structured graph of ``motions`` at 3 cm RMS (:func:`distance.threshold_from`) with the
    given ``dwell`` is searched for ``request`` (list of ``(behaviour, style, frames)``); the
    first run of pieces in intermediate motions is counted (0 when the path has none).
    """
    from motionlab.motion_graphs import distance, search, structured

    key = (tuple(id(m) for m in motions), tuple(map(tuple, request)), int(dwell))
    if key not in _CHANGE:
        g = structured.build_structured(motions, distance.threshold_from(0.03), dwell=int(dwell))
        frames, started = 0, False
        for c, a, b in search.search(g, request).pieces:
            inside = g.clips[c].kind == "intermediate"
            if started and not inside:
                break
            if inside:
                started, frames = True, frames + b - a + 1
        _CHANGE[key] = frames
    return _CHANGE[key]


def gait_cycle_frames(motions, style: str) -> float:
    """Median length (frames) of the whole gait cycles (:func:`cycles.segment_cycles`) of the
    takes named ``*_<style>_*``."""
    from motionlab.motion_graphs import cycles

    lengths = [cycles.segment_cycles(m).lengths() for m in motions if f"_{style}_" in f"_{m.name}_"]
    return float(np.median(np.concatenate(lengths)))


def _first_lasting(motions, request, frames_of=style_change_frames) -> float:
    """The smallest dwell of :data:`DWELLS` whose first style change lasts at least one gait cycle
    of the request's first style (0: none does)."""
    cycle = gait_cycle_frames(motions, request[0][1])
    for d in DWELLS:
        if frames_of(motions, request, d) >= cycle:
            return float(d)
    return 0.0


def _frames_at_answer(motions, request) -> float:
    d = _first_lasting(motions, request)
    return float(style_change_frames(motions, request, int(d))) if d else -1.0


def _by_lower_bound(motions, request) -> float:
    cycle = gait_cycle_frames(motions, request[0][1])
    return float(next((d for d in DWELLS if 4 * d >= cycle), 0))


def _both_changes(motions, request) -> float:
    """Counting every intermediate frame of the path (all style changes together)."""
    from motionlab.motion_graphs import distance, search, structured

    cycle = gait_cycle_frames(motions, request[0][1])
    for d in DWELLS:
        g = structured.build_structured(motions, distance.threshold_from(0.03), dwell=d)
        r = search.search(g, request)
        if sum(b - a + 1 for c, a, b in r.pieces if g.clips[c].kind == "intermediate") >= cycle:
            return float(d)
    return 0.0


style_change = Question(
    "05 · exercise 2 (experiment: how long a style change lasts)",
    _first_lasting,
    mistakes=[
        Mistake(
            _frames_at_answer,
            "that is a number of frames in the blends; the question asks for the dwell that gives them.",
        ),
        Mistake(
            _by_lower_bound,
            "that is where 4 × dwell reaches a gait cycle, a lower bound; measure the path the search "
            "returns, whose route may stay longer than dwell in a blend.",
        ),
        Mistake(
            _both_changes,
            "that counts the frames in the blends of every style change of the path; count only the "
            "first change, from the first style into the second.",
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


# --------------------------------------------------------------------------- exercise 4 (experiment)
LINK_THRESHOLDS_CM = (3, 5, 10, 15, 20, 25, 30, 40)
"""The RMS thresholds (cm) exercise 4 moves through, for the graph without its transition clip."""

_MET: dict = {}


def link_met(library, request: str, left_out: str | None, rms_cm: float) -> bool:
    """Whether ``search.search`` meets ``request`` on the structured graph of ``library`` without the
    clip named ``left_out`` (None: every clip), built at ``rms_cm`` cm RMS."""
    from motionlab.motion_graphs import distance, search, structured

    key = (tuple(id(m) for m in library), request, left_out, float(rms_cm))
    if key not in _MET:
        kept = [m for m in library if m.name != left_out]
        g = structured.build_structured(kept, distance.threshold_from(rms_cm / 100.0))
        try:
            search.search(g, request)
            _MET[key] = True
        except search.SearchError:
            _MET[key] = False
    return _MET[key]


def _first_met(library, request: str, left_out: str | None) -> float:
    """The smallest threshold of :data:`LINK_THRESHOLDS_CM` (cm) at which the request is met (0: at none)."""
    for cm in LINK_THRESHOLDS_CM:
        if link_met(library, request, left_out, cm):
            return float(cm)
    return 0.0


def _last_failed(library, request: str, left_out: str | None) -> float:
    """The largest threshold of :data:`LINK_THRESHOLDS_CM` at which the request still fails (0: none)."""
    failed = [cm for cm in LINK_THRESHOLDS_CM if not link_met(library, request, left_out, cm)]
    return float(max(failed)) if failed else 0.0


transition_clip = Question(
    "05 · exercise 4 (experiment: a graph without its transition clip)",
    _first_met,
    mistakes=[
        Mistake(
            lambda library, request, left_out: _first_met(library, request, None),
            "that graph still holds the recorded transition clip: leave the clip named by `trans_name` "
            "out of the library before building.",
        ),
        Mistake(
            _last_failed,
            "that is the largest threshold at which the search still fails; the question asks for the "
            "first threshold at which it succeeds.",
        ),
        Mistake(
            lambda library, request, left_out: _first_met(library, request, left_out) / 100.0,
            "answer in centimetres, as LINK_THRESHOLDS_CM lists them.",
        ),
    ],
)
"""Notebook 05, section 6: the first threshold (cm RMS) at which stance links alone join the two
behaviours the recorded transition clip joined (0 if none of :data:`LINK_THRESHOLDS_CM` does)."""
